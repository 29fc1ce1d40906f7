// run_task: one expert episode of a ManiSoft task (include/manisoft/task/: TaskEnv + Expert).
//   run_task --task COLL|ALN|STK|ARR --setting clean|randomized --index I --seed S
//            [--split train|eval] [--scene scene.json] [--trace out.csv] [--quiet]
// Samples the scene (or reads --scene), prints the instruction and each waypoint as it is
// reached, and ends its output with one line of JSON:
//   {"task":..., "setting":..., "index":..., "seed":..., "success":true|false, "steps":N,
//    "failure":null|"reason", "expert":null|"why it gave up", "cpu_s":...}
// --trace writes one CSV row per control step (step, phase, S, end-effector position, the goal
// objects' positions). Exit 0 whether or not the episode succeeds; 1 on an error (a malformed
// scene file, no valid scene), 2 on bad flags.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <string>

#include "manisoft/language/library.hpp"
#include "manisoft/scene/scene_instructions.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/task_env.hpp"

namespace scene = manisoft::scene;
namespace task = manisoft::task;

int main(int argc, char** argv) {
  CLI::App app{"Run the expert on one ManiSoft task episode"};
  std::string task_name = "COLL", setting = "clean", split = "train", scene_file, trace_file;
  std::uint64_t index = 0, seed = 0;
  bool quiet = false;
  app.add_option("--task", task_name, "COLL, ALN, STK or ARR")->check(CLI::IsMember({"COLL", "ALN", "STK", "ARR"}));
  app.add_option("--setting", setting, "clean or randomized")->check(CLI::IsMember({"clean", "randomized"}));
  app.add_option("--index", index, "scene index (>= 0)");
  app.add_option("--seed", seed, "dataset seed (>= 0)");
  app.add_option("--split", split, "train (default) or eval")->check(CLI::IsMember({"train", "eval"}));
  app.add_option("--scene", scene_file, "scene JSON to run instead of sampling one")->check(CLI::ExistingFile);
  app.add_option("--trace", trace_file, "CSV file: one row per control step");
  app.add_flag("--quiet", quiet, "print only the JSON line");
  CLI11_PARSE(app, argc, argv);
  try {
    const std::clock_t c0 = std::clock();
    scene::SceneSampler sampler;
    scene::SceneSpec spec;
    if (!scene_file.empty()) {
      spec = scene::load_scene(scene_file, sampler.library());
    } else {
      const std::map<std::string, scene::Task> tasks{{"COLL", scene::Task::coll}, {"ALN", scene::Task::aln}, {"STK", scene::Task::stk}, {"ARR", scene::Task::arr}};
      scene::SampleRequest q;
      q.task = tasks.at(task_name);
      q.setting = setting == "clean" ? scene::Setting::clean : scene::Setting::randomized;
      q.split = split == "train" ? scene::Split::train : scene::Split::eval;
      q.index = index;
      q.seed = seed;
      spec = sampler.sample(q);
      scene::describe(spec, sampler.library(), manisoft::language::Library::load_default(), seed);
    }
    task::TaskEnv env(sampler.library());
    task::Expert expert(env);
    const std::clock_t c1 = std::clock();
    env.reset(spec);
    expert.reset();
    if (!quiet) {
      std::printf("%s %s scene %llu (seed %llu): %zu objects, %zu obstacles\n", std::string(scene::to_string(spec.task)).c_str(),
                  std::string(scene::to_string(spec.setting)).c_str(), static_cast<unsigned long long>(spec.index),
                  static_cast<unsigned long long>(spec.seed), spec.objects.size(), spec.obstacles.size());
      std::printf("instruction: %s\n", spec.instruction.empty() ? "(none)" : spec.instruction.c_str());
    }
    std::ofstream trace;
    if (!trace_file.empty()) {
      trace.open(trace_file);
      if (!trace) manisoft::detail::fail("run_task: cannot write ", trace_file);
      trace << "step,phase,S,ee_x,ee_y,ee_z";
      for (int i : scene::goal_objects(spec)) trace << ",obj" << i << "_x,obj" << i << "_y,obj" << i << "_z";
      trace << "\n";
    }
    task::TaskEnv::Array3 torques;
    int s = 0;
    std::size_t printed = 0;
    while (!env.done()) {
      expert.act(torques, s);
      env.step(torques, s);
      for (; printed < expert.events().size(); ++printed) {
        const auto& e = expert.events()[printed];
        if (!quiet)
          std::printf("  step %4ld  move %d  %-8s  end-effector (%.3f, %.3f, %.3f)\n", e.step, e.move, std::string(task::to_string(e.phase)).c_str(),
                      e.position.x(), e.position.y(), e.position.z());
      }
      if (trace.is_open()) {
        const auto p = env.world().soft().end_effector_frame().position;
        trace << env.info().step << ',' << task::to_string(expert.phase()) << ',' << s << ',' << p.x() << ',' << p.y() << ',' << p.z();
        for (int i : scene::goal_objects(spec)) {
          const auto& o = env.snapshot().objects[static_cast<std::size_t>(i)].center_of_mass;
          trace << ',' << o.x() << ',' << o.y() << ',' << o.z();
        }
        trace << "\n";
      }
    }
    if (trace.is_open()) {
      trace.close();
      if (!trace) manisoft::detail::fail("run_task: writing ", trace_file, " failed");
    }
    const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC, episode_cpu = double(std::clock() - c1) / CLOCKS_PER_SEC;
    const auto& info = env.info();
    if (!quiet)
      std::printf("%s after %ld control steps (%.2f s simulated), episode CPU %.3f s\n", info.success ? "SUCCESS" : "FAILURE", info.step,
                  double(info.step) * env.control_dt(), episode_cpu);
    std::string failure = info.success ? "null" : "\"" + std::string(task::to_string(info.failure)) + "\"";
    std::string why = expert.failure()[0] ? "\"" + std::string(expert.failure()) + "\"" : "null";
    std::printf("{\"task\":\"%s\",\"setting\":\"%s\",\"index\":%llu,\"seed\":%llu,\"success\":%s,\"success_at_end\":%s,\"steps\":%ld,\"failure\":%s,"
                "\"expert\":%s,\"cpu_s\":%.3f,\"episode_cpu_s\":%.3f}\n",
                std::string(scene::to_string(spec.task)).c_str(), std::string(scene::to_string(spec.setting)).c_str(),
                static_cast<unsigned long long>(spec.index), static_cast<unsigned long long>(spec.seed), info.success ? "true" : "false",
                env.success_at_end() ? "true" : "false", info.step, failure.c_str(), why.c_str(), cpu, episode_cpu);
  } catch (const manisoft::Error& e) {
    std::fprintf(stderr, "run_task: %s\n", e.what());
    return 1;
  }
  return 0;
}
