// One episode of an environment driven by a policy (an executor, a learned policy, a scripted
// controller): reset(seed), then act/step until the environment says done. The loop every
// evaluation program, test and benchmark runs, written once.
//
//   const auto record = env::rollout(env, executor, seed);       // record.info: the last step's info
//   env::rollout(env, executor, seed, [&](const auto& step) {...});  // also sees every step
//
// Environment: reset(seed) -> const Observation&; step(action) -> {observation, reward, done,
// info}; action_space().rows(); typename Env::Info. Policy: reset(); act(observation, action)
// writing an action_space().rows() x 3 action. The policy's act() is timed (wall clock) so
// programs can report its cost; no allocation happens in the loop after the first step.
#pragma once

#include <Eigen/Core>

#include <chrono>
#include <cstdint>
#include <ctime>

namespace manisoft::env {

/// What one episode produced.
template <typename Info>
struct EpisodeRecord {
  std::uint64_t seed = 0;
  Info info{};               ///< of the last step
  int steps = 0;             ///< control steps taken
  double total_reward = 0;
  double first_act_seconds = 0;  ///< wall time of the policy's first act() (its set-up)
  double first_act_cpu_seconds = 0;  ///< process CPU time of the first act() (std::clock)
  double act_seconds = 0;        ///< wall time of the other act() calls, summed
};

/// What a per-step observer sees.
template <typename Result>
struct RolloutStep {
  int step = 0;                 ///< 0-based control step just taken
  const Result& result;         ///< the environment's step result
  double act_seconds = 0;       ///< wall time of this step's act()
};

struct NoStepObserver {
  template <typename Step>
  void operator()(const Step&) const {}
};

template <typename Env, typename Policy, typename Observer = NoStepObserver>
EpisodeRecord<typename Env::Info> rollout(Env& env, Policy& policy, std::uint64_t seed, Observer&& observe = {}) {
  using Clock = std::chrono::steady_clock;
  EpisodeRecord<typename Env::Info> record;
  record.seed = seed;
  Eigen::Matrix<double, Eigen::Dynamic, 3> action = Eigen::Matrix<double, Eigen::Dynamic, 3>::Zero(env.action_space().rows(), 3);
  const auto* observation = &env.reset(seed);
  policy.reset();
  for (bool done = false; !done;) {
    const std::clock_t c0 = record.steps == 0 ? std::clock() : 0;
    const auto t0 = Clock::now();
    policy.act(*observation, action);
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (record.steps == 0) record.first_act_cpu_seconds = double(std::clock() - c0) / CLOCKS_PER_SEC;
    (record.steps == 0 ? record.first_act_seconds : record.act_seconds) += seconds;
    const auto result = env.step(action);
    observe(RolloutStep<decltype(result)>{record.steps, result, seconds});
    ++record.steps;
    record.total_reward += result.reward;
    record.info = result.info;
    observation = &result.observation;
    done = result.done;
  }
  return record;
}

}  // namespace manisoft::env
