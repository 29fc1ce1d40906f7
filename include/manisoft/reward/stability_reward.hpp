// The stability reward of the paper, section 3.4:
//   R_s = -sgn(dd/dt) beta   when d <= D,   0 otherwise,
// which rewards a shrinking pose distance d near the target and penalises a growing one.
// Defaults are the paper's best values: beta = 1, D = 0.3, with alpha = 0.2 for d.
//
// dd/dt is the backward difference (d - d_previous) / dt over the last control step, so the term
// keeps the previous distance as state: the first step after reset() has no rate and returns 0.
// Only the sign of the rate matters, so an unchanged d gives 0.
#pragma once

#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/reward/pose_distance.hpp"
#include "manisoft/reward/reward_term.hpp"

namespace manisoft::reward {

template <typename Scalar>
struct StabilityRewardParameters {
  Scalar alpha = Scalar(0.2);              ///< m/rad, weight of the rotation in d (> 0)
  Scalar beta = Scalar(1);                 ///< size of the reward (>= 0)
  Scalar distance_threshold = Scalar(0.3); ///< D: active while d <= D (>= 0)
};

template <std::floating_point ScalarType = double>
class StabilityReward {
 public:
  using Scalar = ScalarType;
  using Parameters = StabilityRewardParameters<Scalar>;

  StabilityReward() : StabilityReward(Parameters{}) {}
  explicit StabilityReward(const Parameters& parameters) : parameters_(parameters) {
    manisoft::detail::require_positive("StabilityReward alpha", parameters.alpha);
    manisoft::detail::require_non_negative("StabilityReward beta", parameters.beta);
    manisoft::detail::require_non_negative("StabilityReward distance_threshold", parameters.distance_threshold);
  }

  /// Forgets the previous distance (call at the start of each episode).
  void reset() { has_previous_ = false; }

  /// R_s for this step. input.dt must be > 0. When the state is not finite it returns 0 and
  /// keeps the previous distance.
  TermResult<Scalar> evaluate(const RewardInput<Scalar>& input) {
    manisoft::detail::require_positive("RewardInput dt", input.dt);
    if (!state_is_finite(input)) return {};
    detail::require_finite_target(input);
    const Scalar d = pose_error(input.end_effector, input.target, parameters_.alpha).distance;
    Scalar value(0);
    if (has_previous_ && d <= parameters_.distance_threshold) {
      const Scalar rate = (d - previous_distance_) / input.dt;
      const Scalar sign = rate > Scalar(0) ? Scalar(1) : (rate < Scalar(0) ? Scalar(-1) : Scalar(0));
      value = -sign * parameters_.beta;
    }
    previous_distance_ = d;
    has_previous_ = true;
    return {value, false};
  }

  const Parameters& parameters() const { return parameters_; }

 private:
  Parameters parameters_;
  Scalar previous_distance_ = Scalar(0);
  bool has_previous_ = false;
};

}  // namespace manisoft::reward
