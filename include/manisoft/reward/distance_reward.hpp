// The pose-difference reward of the paper, section 3.4 (adapted from Elastica-RL-Control):
//   R_d = -d + k1 1{d < d1} + k2 1{d < d2},   d1 = 0.1 / lambda,   d2 = 0.05 / lambda,
// with d the SE(3) pose distance of pose_distance.hpp. Defaults are the paper's best values:
// alpha = 0.2, lambda = 1, k1 = 0.5, k2 = 1.5.
#pragma once

#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/reward/pose_distance.hpp"
#include "manisoft/reward/reward_term.hpp"

namespace manisoft::reward {

template <typename Scalar>
struct DistanceRewardParameters {
  Scalar alpha = Scalar(0.2);  ///< m/rad, weight of the rotation in d (> 0)
  Scalar lambda = Scalar(1);   ///< scale of the bonus thresholds (> 0)
  Scalar k1 = Scalar(0.5);     ///< bonus once d < d1
  Scalar k2 = Scalar(1.5);     ///< further bonus once d < d2
};

template <std::floating_point ScalarType = double>
class DistanceReward {
 public:
  using Scalar = ScalarType;
  using Parameters = DistanceRewardParameters<Scalar>;

  DistanceReward() : DistanceReward(Parameters{}) {}
  explicit DistanceReward(const Parameters& parameters) : parameters_(parameters) {
    manisoft::detail::require_positive("DistanceReward alpha", parameters.alpha);
    manisoft::detail::require_positive("DistanceReward lambda", parameters.lambda);
    manisoft::detail::require_finite("DistanceReward k1", parameters.k1);
    manisoft::detail::require_finite("DistanceReward k2", parameters.k2);
  }

  void reset() {}

  /// R_d for the input's poses; 0 when the state is not finite (see state_is_finite).
  TermResult<Scalar> evaluate(const RewardInput<Scalar>& input) const {
    if (!state_is_finite(input)) return {};
    detail::require_finite_target(input);
    const Scalar d = pose_error(input.end_effector, input.target, parameters_.alpha).distance;
    Scalar value = -d;
    if (d < first_threshold()) value += parameters_.k1;
    if (d < second_threshold()) value += parameters_.k2;
    return {value, false};
  }

  const Parameters& parameters() const { return parameters_; }
  Scalar first_threshold() const { return Scalar(0.1) / parameters_.lambda; }    ///< d1
  Scalar second_threshold() const { return Scalar(0.05) / parameters_.lambda; }  ///< d2

 private:
  Parameters parameters_;
};

}  // namespace manisoft::reward
