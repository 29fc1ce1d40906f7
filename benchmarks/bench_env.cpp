// Reach environment throughput: control steps per second of the batched reach environment
// (env/batched_reach_env.hpp) as the batch grows (1, 8, 64, 256 arms) on 1 and 2 threads, beside
// one ReachEnv stepped alone, and the cost of a reset (the target's draw with its inverse statics
// and the new world). The step benchmarks run in steady state (the horizon is never reached);
// an episode of 1500 control steps adds one reset per arm.
// Wall-clock time (the batch runs on several threads); items_per_second counts control steps,
// steps_per_minute is the same rate times 60.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "manisoft/env/batched_reach_env.hpp"
#include "manisoft/env/reach_env.hpp"

namespace {

using Damping = manisoft::rod::damping::AnalyticalLinear<double>;
using Batch = manisoft::env::BatchedReachEnv<>;
using Array3 = Batch::Env::Array3;

manisoft::env::ReachEnvConfig steady_config() {
  manisoft::env::ReachEnvConfig config;
  config.horizon = 1 << 30;  // steady state: no episode ends while timed
  return config;
}

/// A fixed mild action of arm i: a few N m, varying along the arm.
double mild_action(int arm, int row, int column) { return 3.0 * std::sin(0.7 * arm + 0.5 * row + 1.3 * column); }

void set_rates(benchmark::State& state, int steps_per_iteration) {
  state.SetItemsProcessed(state.iterations() * steps_per_iteration);
  state.counters["steps_per_minute"] = benchmark::Counter(60.0 * steps_per_iteration, benchmark::Counter::kIsIterationInvariantRate);
}

/// One batched control step of B arms (argument 0) on T threads (argument 1).
void BM_BatchedReachStep(benchmark::State& state) {
  const int batch_size = int(state.range(0));
  Batch batch(batch_size, int(state.range(1)), steady_config(), Damping(0.1));
  std::vector<std::uint64_t> seeds;
  for (int i = 0; i < batch_size; ++i) seeds.push_back(std::uint64_t(i + 1));
  batch.reset(seeds);
  const int rows = batch.action_rows();
  std::vector<double> actions;
  for (int i = 0; i < batch_size; ++i)
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < 3; ++c) actions.push_back(mild_action(i, r, c));
  for (auto _ : state) {
    batch.step(actions);
    benchmark::DoNotOptimize(batch.rewards().data());
  }
  set_rates(state, batch_size);
}
BENCHMARK(BM_BatchedReachStep)
    ->ArgsProduct({{1, 8, 64, 256}, {1, 2}})
    ->ArgNames({"arms", "threads"})
    ->UseRealTime()
    ->MinTime(1.0)
    ->Unit(benchmark::kMicrosecond);

/// One ReachEnv alone, no batch: the per-arm cost the batch distributes.
void BM_ReachEnvStep(benchmark::State& state) {
  manisoft::env::ReachEnv<> env(steady_config(), Damping(0.1));
  env.reset(1);
  Array3 action(env.action_space().rows(), 3);
  for (int r = 0; r < action.rows(); ++r)
    for (int c = 0; c < 3; ++c) action(r, c) = mild_action(0, r, c);
  for (auto _ : state) benchmark::DoNotOptimize(env.step(action).reward);
  set_rates(state, 1);
}
BENCHMARK(BM_ReachEnvStep)->UseRealTime()->MinTime(1.0)->Unit(benchmark::kMicrosecond);

/// One arm's reset: a table target drawn (inverse statics) and a new world built.
void BM_ReachEnvReset(benchmark::State& state) {
  manisoft::env::ReachEnv<> env({}, Damping(0.1));
  std::uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(&env.reset(seed++));
}
BENCHMARK(BM_ReachEnvReset)->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
