// Scene sampling benchmark (target: sampling plus validation of one scene at most 50 ms on
// average): SceneSampler::sample for each task and setting, cycling through scene indices (one
// iteration = one accepted scene with all its redraws and checks: consistency, inverse-statics
// reachability of grasps and goals, interpenetration, 0.5 s of settling in the rigid world).
// Also the parts: validation alone, the JSON round trip, the sampler's set-up (asset catalogue,
// inverse-statics start library).
// Run: bench_scene --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_sampler.hpp"

namespace {

using namespace manisoft::scene;

SceneSampler& shared_sampler() {
  static SceneSampler s;
  return s;
}

void sample(benchmark::State& state, Task task, Setting setting) {
  SceneSampler& sampler = shared_sampler();
  std::uint64_t index = 0;
  long redraws = 0, scenes = 0;
  for (auto _ : state) {
    SampleRequest q;
    q.task = task;
    q.setting = setting;
    q.index = index++;
    const SceneSpec s = sampler.sample(q);
    redraws += s.sampling.redraws;
    ++scenes;
    benchmark::DoNotOptimize(s.objects.data());
  }
  state.counters["redraws_per_scene"] = double(redraws) / double(scenes);
}

void validate_only(benchmark::State& state) {
  SceneSampler& sampler = shared_sampler();
  SampleRequest q;
  q.task = Task::coll;
  q.setting = Setting::randomized;
  const SceneSpec s = sampler.sample(q);
  for (auto _ : state) benchmark::DoNotOptimize(sampler.validator().check(s).valid);
}

void json_round_trip(benchmark::State& state) {
  SceneSampler& sampler = shared_sampler();
  SampleRequest q;
  q.task = Task::arr;
  q.setting = Setting::randomized;
  const SceneSpec s = sampler.sample(q);
  for (auto _ : state) {
    const SceneSpec b = parse_scene(to_json_string(s), "bench");
    benchmark::DoNotOptimize(b.objects.data());
  }
}

void setup(benchmark::State& state) {
  for (auto _ : state) {
    SceneSampler s;
    benchmark::DoNotOptimize(&s);
  }
}

}  // namespace

BENCHMARK_CAPTURE(sample, COLL_clean, Task::coll, Setting::clean)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, COLL_randomized, Task::coll, Setting::randomized)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, ALN_clean, Task::aln, Setting::clean)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, ALN_randomized, Task::aln, Setting::randomized)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, STK_clean, Task::stk, Setting::clean)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, STK_randomized, Task::stk, Setting::randomized)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, ARR_clean, Task::arr, Setting::clean)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(sample, ARR_randomized, Task::arr, Setting::randomized)->Unit(benchmark::kMillisecond);
BENCHMARK(validate_only)->Unit(benchmark::kMillisecond);
BENCHMARK(json_round_trip)->Unit(benchmark::kMicrosecond);
BENCHMARK(setup)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
