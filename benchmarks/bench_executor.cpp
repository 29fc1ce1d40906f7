// Executor compute: the model executor's per-control-step cost (feedback, ramp,
// stiffness estimate and outer-loop re-solves amortized as they occur), the per-target set-up
// (cold inverse statics from the start library) on both target sets, and its one-time
// construction. The step benchmark runs on both action spaces (element torques; 8 B-spline
// control values per direction through ProjectedExecutor's least-squares projection), and the
// path set-up of trajectory tracking (track_line) on the pick-and-place paths.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>
#include <vector>

#include "manisoft/control/mlp_executor.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/control/projected_executor.hpp"
#include "manisoft/env/reach_env.hpp"
#include "manisoft/task/pick_place.hpp"

namespace {

using Env = manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear>;
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// Per control step over whole episodes: the executor is timed, the simulation is not.
template <template <class> class ActionPolicy>
void BM_ModelExecutorStep(benchmark::State& state) {
  manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear, ActionPolicy> env({}, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  manisoft::control::ProjectedExecutor executor(manisoft::control::ModelExecutor<double>(env.nominal_model(), env.config().limits),
                                                env.action_space());
  Array3 action = Array3::Zero(env.action_space().rows(), 3);
  std::uint64_t seed = 1;
  const auto* observation = &env.reset(seed);
  executor.reset();
  executor.act(*observation, action);  // set-up outside the timed loop
  int t = 0;
  for (auto _ : state) {
    executor.act(*observation, action);
    benchmark::DoNotOptimize(action.data());
    state.PauseTiming();
    observation = &env.step(action).observation;
    if (++t == env.config().horizon) {
      t = 0;
      observation = &env.reset(++seed);
      executor.reset();
      executor.act(*observation, action);
    }
    state.ResumeTiming();
  }
}
BENCHMARK(BM_ModelExecutorStep<manisoft::control::ElementTorqueAction>)->Unit(benchmark::kMicrosecond)->Iterations(15000);
BENCHMARK(BM_ModelExecutorStep<manisoft::control::BsplineMuscleAction>)->Unit(benchmark::kMicrosecond)->Iterations(15000);

/// Per target: the set-up of a new target (argument 0: table, 1: equilibria): cold inverse
/// statics from the start library and the ramp's path sampling. Also reports the slowest single set-up seen (max_us, wall time;
/// on a shared machine it includes waits for the CPU).
void BM_ModelExecutorSetup(benchmark::State& state) {
  manisoft::env::ReachEnvConfig config;
  config.target_set = state.range(0) == 0 ? manisoft::env::TargetSet::table : manisoft::env::TargetSet::equilibria;
  state.SetLabel(state.range(0) == 0 ? "table" : "equilibria");
  Env env(config, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  std::vector<manisoft::math::Pose<double>> targets;
  for (std::uint64_t s = 0; s < 100; ++s) targets.push_back(env.draw_target(s));
  manisoft::control::ModelExecutor<double> executor(env.nominal_model(), env.config().limits);
  std::size_t i = 0;
  double slowest = 0;
  for (auto _ : state) {
    executor.reset();
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(executor.set_target(targets[i++ % targets.size()]));
    slowest = std::max(slowest, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["max_us"] = slowest;
}
BENCHMARK(BM_ModelExecutorSetup)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->Iterations(300);

/// Path set-up (track_line): the pick-and-place lines of 50 drawn cube scenes (pre-grasp, grasp,
/// carry, place; task/pick_place.hpp), each planned from the end of the one before, the first from
/// the task environment's settled home shape, with the cube's payload from the carry on. The
/// knots' inverse statics (with actuator relief) and the continuity checks. Also reports the
/// slowest single set-up (max_cpu_us, process CPU time: a preempted set-up does not count its wait).
void BM_TrackLineSetup(benchmark::State& state) {
  namespace task = manisoft::task;
  const manisoft::scene::AssetLibrary library;
  manisoft::scene::SceneValidator validator(library);
  task::TaskEnv env(library, task::pick_place_env_config());
  task::Expert expert(env, task::pick_place_expert_config());
  const double mass = library.get(task::pick_place_asset(task::PickPlaceObject::cube), "bench").mass;
  std::vector<std::array<manisoft::math::Pose<double>, 4>> paths;
  std::vector<Eigen::Vector3d> in_hand;
  for (std::uint64_t s = 0; s < 50; ++s) {
    const auto draw = task::draw_pick_place(validator, expert, env, task::PickPlaceObject::cube, 100000 + s);
    const Eigen::Vector3d half_up(0, 0, 0.0285);  // the grasp centre at the cube's centre
    const auto grasp = env.tool_down(draw.object + half_up, draw.object_yaw), place = env.tool_down(draw.place + half_up, draw.object_yaw);
    auto above = [](manisoft::math::Pose<double> p, double dz) {
      p.translation.z() += dz;
      return p;
    };
    paths.push_back({above(grasp, 0.06), grasp, above(place, 0.05), above(place, 0.008)});
    in_hand.push_back(grasp.rotation.transpose() * (draw.object + half_up - grasp.translation));
  }
  manisoft::control::ModelExecutor<double> executor = env.home_executor();
  std::size_t i = 0;
  double slowest = 0;
  for (auto _ : state) {
    const std::size_t task = (i / 4) % paths.size(), leg = i % 4;
    if (leg == 0 || leg == 2) {
      state.PauseTiming();
      if (leg == 0) executor = env.home_executor();
      if (leg == 2) executor.set_payload(mass, in_hand[task]);
      state.ResumeTiming();
    }
    const std::clock_t t0 = std::clock();
    benchmark::DoNotOptimize(executor.track_line(paths[task][leg], 100));
    slowest = std::max(slowest, 1e6 * double(std::clock() - t0) / CLOCKS_PER_SEC);
    executor.complete_path();
    ++i;
  }
  state.counters["max_cpu_us"] = slowest;
}
BENCHMARK(BM_TrackLineSetup)->Unit(benchmark::kMicrosecond)->Iterations(800);

/// One-time construction of the model executor (its inverse statics builds the start library).
void BM_ModelExecutorConstruct(benchmark::State& state) {
  Env env({}, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  for (auto _ : state) {
    manisoft::control::ModelExecutor<double> executor(env.nominal_model(), env.config().limits);
    benchmark::DoNotOptimize(&executor);
  }
}
BENCHMARK(BM_ModelExecutorConstruct)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
