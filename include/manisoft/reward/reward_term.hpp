// The reward-term interface (paper section 3.4): the input every term sees, the result it
// returns, and the RewardTerm concept that reward::Sum composes at compile time.
#pragma once

#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"

namespace manisoft::reward {

/// What a reward term sees at one control step.
template <typename Scalar>
struct RewardInput {
  math::Pose<Scalar> end_effector;  ///< current end-effector pose P (world frame)
  math::Pose<Scalar> target;        ///< target pose P_hat (world frame)
  Scalar dt = Scalar(0);            ///< time since the previous evaluation (control period), s
  bool state_is_finite = true;      ///< false once the simulated state holds a NaN or an inf
};

/// What a reward term returns: its (unweighted) value and whether it ends the episode.
template <typename Scalar>
struct TermResult {
  Scalar value = Scalar(0);
  bool done = false;
};

/// A reward term: names its Scalar, can be reset at the start of an episode, and evaluates one
/// step. Terms may keep state between steps (reset() clears it).
template <typename T>
concept RewardTerm =
    requires { typename T::Scalar; } && std::floating_point<typename T::Scalar> &&
    requires(T& term, const RewardInput<typename T::Scalar>& input) {
      { term.reset() } -> std::same_as<void>;
      { term.evaluate(input) } -> std::same_as<TermResult<typename T::Scalar>>;
    };

/// True when the simulated state is usable: the caller's flag is set and the end-effector pose
/// holds no NaN or inf. Terms that measure the pose return 0 otherwise (NonFinitePenalty
/// is the term that reacts to it).
template <typename Scalar>
bool state_is_finite(const RewardInput<Scalar>& input) {
  return input.state_is_finite && input.end_effector.is_finite();
}

namespace detail {

/// A non-finite target is a caller bug, not a diverged simulation: refuse it.
template <typename Scalar>
void require_finite_target(const RewardInput<Scalar>& input) {
  math::require_valid_pose(input.target, "reward input target");
}

}  // namespace detail
}  // namespace manisoft::reward
