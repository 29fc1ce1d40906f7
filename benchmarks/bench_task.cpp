// Expert episode benchmark (target: one expert episode, planning and simulation, no rendering,
// at most 0.1 s of CPU on average): TaskEnv::reset + the expert until the episode ends, for
// each task in clean scenes, cycling through train indices 0-24 (seed 0; scenes sampled once,
// outside the timing). One iteration = one whole episode, whatever its outcome (a timeout runs all
// 1,500 control steps). Counters: success rate and mean control steps over the iterations.
// control_step: one TaskEnv::step with a given action (the expert's recorded actions of COLL clean
// train scene 3, replayed; reset outside the timing when the episode ends): the C++ side of the
// Python module's overhead (benchmarks/python_env_step.py times the same steps through Python).
// Run: bench_task --benchmark_repetitions=3
#include <benchmark/benchmark.h>

#include <vector>

#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/task_env.hpp"

namespace {

using namespace manisoft;

scene::SceneSampler& shared_sampler() {
  static scene::SceneSampler s;
  return s;
}

void episode(benchmark::State& state, scene::Task task) {
  scene::SceneSampler& sampler = shared_sampler();
  std::vector<scene::SceneSpec> scenes;
  for (std::uint64_t i = 0; i < 25; ++i) {
    scene::SampleRequest q;
    q.task = task;
    q.index = i;
    scenes.push_back(sampler.sample(q));
  }
  task::TaskEnv env(sampler.library());
  task::Expert expert(env);
  task::TaskEnv::Array3 torques;
  std::size_t next = 0;
  long episodes = 0, successes = 0, steps = 0;
  for (auto _ : state) {
    env.reset(scenes[next]);
    next = (next + 1) % scenes.size();
    expert.reset();
    int s = 0;
    while (!env.done()) {
      expert.act(torques, s);
      env.step(torques, s);
    }
    ++episodes;
    successes += env.info().success;
    steps += env.info().step;
  }
  state.counters["success"] = double(successes) / double(episodes);
  state.counters["steps"] = double(steps) / double(episodes);
}

/// The expert's actions on COLL clean train scene 3 (the scene benchmarks/python_env_step.py uses).
std::vector<std::pair<task::TaskEnv::Array3, int>> recorded_actions(task::TaskEnv& env, const scene::SceneSpec& spec) {
  task::Expert expert(env);
  env.reset(spec);
  expert.reset();
  std::vector<std::pair<task::TaskEnv::Array3, int>> actions;
  task::TaskEnv::Array3 torques;
  int s = 0;
  while (!env.done()) {
    expert.act(torques, s);
    env.step(torques, s);
    actions.emplace_back(torques, s);
  }
  return actions;
}

void control_step(benchmark::State& state) {
  scene::SampleRequest q;
  q.index = 3;
  const scene::SceneSpec spec = shared_sampler().sample(q);
  task::TaskEnv env(shared_sampler().library());
  const auto actions = recorded_actions(env, spec);
  env.reset(spec);
  std::size_t k = 0;
  for (auto _ : state) {
    if (env.done()) {
      state.PauseTiming();
      env.reset(spec);
      k = 0;
      state.ResumeTiming();
    }
    env.step(actions[k].first, actions[k].second);
    ++k;
  }
}

}  // namespace

BENCHMARK_CAPTURE(episode, COLL_clean, scene::Task::coll)->Unit(benchmark::kMillisecond)->Iterations(25);
BENCHMARK_CAPTURE(episode, ALN_clean, scene::Task::aln)->Unit(benchmark::kMillisecond)->Iterations(25);
BENCHMARK_CAPTURE(episode, STK_clean, scene::Task::stk)->Unit(benchmark::kMillisecond)->Iterations(25);
BENCHMARK_CAPTURE(episode, ARR_clean, scene::Task::arr)->Unit(benchmark::kMillisecond)->Iterations(25);

BENCHMARK(control_step)->Unit(benchmark::kMicrosecond)->MinTime(2.0);
BENCHMARK_MAIN();
