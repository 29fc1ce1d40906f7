// A weighted sum of reward terms composed at compile time (paper section 3.4: R = R_d + R_s):
//   total = sum_i weight_i * value_i,   done = any term's done.
// Every term is evaluated at every step, also after one reports done, so stateful terms stay
// consistent. Example:
//   using Reward = manisoft::reward::Sum<DistanceReward<>, StabilityReward<>, NonFinitePenalty<>>;
//   Reward reward;                                  // all weights 1
//   Reward weighted({1.0, 0.5, 1.0}, DistanceReward<>{}, StabilityReward<>{}, NonFinitePenalty<>{});
#pragma once

#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <tuple>
#include <utility>

#include "manisoft/core/error.hpp"
#include "manisoft/reward/reward_term.hpp"

namespace manisoft::reward {

template <RewardTerm... Terms>
  requires(sizeof...(Terms) > 0)
class Sum {
 public:
  using Scalar = typename std::tuple_element_t<0, std::tuple<Terms...>>::Scalar;
  static_assert((std::same_as<typename Terms::Scalar, Scalar> && ...),
                "reward::Sum: every term must use the same Scalar");

  static constexpr std::size_t size = sizeof...(Terms);
  using Weights = std::array<Scalar, size>;

  struct Result {
    Scalar total = Scalar(0);           ///< sum_i weights[i] * values[i]
    std::array<Scalar, size> values{};  ///< each term's unweighted value, in template order
    bool done = false;                  ///< true when any term ends the episode
  };

  /// Default-constructed terms, all weights 1.
  Sum() : Sum(Terms{}...) {}
  /// The given terms, all weights 1.
  explicit Sum(Terms... terms) : terms_(std::move(terms)...) { weights_.fill(Scalar(1)); }
  /// The given weights and terms.
  Sum(const Weights& weights, Terms... terms) : terms_(std::move(terms)...), weights_(weights) {
    for (std::size_t i = 0; i < size; ++i) {
      if (!std::isfinite(weights_[i])) {
        manisoft::detail::fail("reward::Sum weight[", i, "] = ", weights_[i], " is invalid: it must be finite");
      }
    }
  }

  /// Resets every term (call at the start of each episode).
  void reset() {
    std::apply([](auto&... term) { (term.reset(), ...); }, terms_);
  }

  Result evaluate(const RewardInput<Scalar>& input) {
    Result result;
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (evaluate_term<I>(input, result), ...);
    }(std::make_index_sequence<size>{});
    return result;
  }

  template <std::size_t I>
  auto& term() {
    return std::get<I>(terms_);
  }
  template <std::size_t I>
  const auto& term() const {
    return std::get<I>(terms_);
  }
  const Weights& weights() const { return weights_; }

 private:
  template <std::size_t I>
  void evaluate_term(const RewardInput<Scalar>& input, Result& result) {
    const TermResult<Scalar> term_result = std::get<I>(terms_).evaluate(input);
    result.values[I] = term_result.value;
    result.total += weights_[I] * term_result.value;
    result.done = result.done || term_result.done;
  }

  std::tuple<Terms...> terms_;
  Weights weights_{};
};

}  // namespace manisoft::reward
