// Ends the episode with a fixed penalty once the simulated state is not finite (a diverged rod),
// as Elastica-RL-Control does (penalty -1000, done). It complements the paper's reward terms of
// section 3.4, which return 0 on such a state.
#pragma once

#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/reward/reward_term.hpp"

namespace manisoft::reward {

template <std::floating_point ScalarType = double>
class NonFinitePenalty {
 public:
  using Scalar = ScalarType;

  NonFinitePenalty() = default;
  explicit NonFinitePenalty(Scalar penalty) : penalty_(penalty) {
    manisoft::detail::require_finite("NonFinitePenalty penalty", penalty);
  }

  void reset() {}

  /// {penalty, done = true} when input.state_is_finite is false or the end-effector pose holds
  /// a NaN or inf; {0, false} otherwise.
  TermResult<Scalar> evaluate(const RewardInput<Scalar>& input) const {
    if (state_is_finite(input)) return {};
    return {penalty_, true};
  }

  Scalar penalty() const { return penalty_; }

 private:
  Scalar penalty_ = Scalar(-1000);
};

}  // namespace manisoft::reward
