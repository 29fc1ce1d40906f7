// run_task: one expert episode of a ManiSoft task (include/manisoft/task/: TaskEnv + Expert).
//   run_task --task COLL|ALN|STK|ARR --setting clean|randomized --index I --seed S
//            [--split train|eval] [--scene scene.json] [--save-scene out.json] [--trace out.csv] [--quiet]
//            [--torque-noise SIGMA --noise-hold K] [--expert-config expert.json]
//            [--path-speed V] [--carry-speed V] [--max-retries N] [--no-arm-check]
// Samples the scene (or reads --scene), prints the instruction and each waypoint as it is
// reached, and ends its output with one line of JSON:
//   {"task":..., "setting":..., "index":..., "seed":..., "success":true|false, "steps":N,
//    "failure":null|"reason", "expert":null|"why it gave up", "torque_noise", "noise_hold", "cpu_s":..., "object": the target
//    object's asset id, "relation", "instruction", "unmet": the predicate's conditions that did
//    not hold at the end}
// --trace writes one CSV row per control step, step 0 the state after reset, in world_demo's layout
// (render_scene --scene S --trace T replays it): step, time, phase (the expert's phase: 0 approach,
// 1 descend, 2 close, 3 carry, 4 lower, 5 open, 6 retract, 7 idle, 8 failed), S, finger width,
// held (object index or -1), gripper pose (position, quaternion w x y z), every rod node, every
// object's pose (object<i>_px..._qz). --save-scene writes the scene JSON. --torque-noise adds
// Gaussian noise of that standard deviation to every entry of the expert's torques, redrawn every
// --noise-hold control steps (a learner's error; seeded by the scene's index and seed).
// --expert-config reads the expert's settings from JSON, one object per group of ExpertConfig
// (task/expert_config_json.hpp); the expert flags override it. Exit 0 whether or not the episode
// succeeds; 1 on an error (a malformed scene or expert configuration file, no valid scene), 2 on
// bad flags.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include "../cli_checks.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/expert_config_json.hpp"
#include "manisoft/task/task_env.hpp"

namespace scene = manisoft::scene;
namespace task = manisoft::task;

int main(int argc, char** argv) {
  CLI::App app{"Run the expert on one ManiSoft task episode"};
  std::string task_name = "COLL", setting = "clean", split = "train", scene_file, save_scene, trace_file;
  std::uint64_t index = 0, seed = 0;
  bool quiet = false;
  double noise_sigma = 0;
  int noise_hold = 1;
  app.add_option("--task", task_name, "COLL, ALN, STK, ARR or OVR")->check(CLI::IsMember(scene::task_names()));
  app.add_option("--setting", setting, "clean or randomized")->check(CLI::IsMember({"clean", "randomized"}));
  app.add_option("--index", index, "scene index (>= 0)");
  app.add_option("--seed", seed, "dataset seed (>= 0)");
  app.add_option("--split", split, "train (default) or eval")->check(CLI::IsMember({"train", "eval"}));
  app.add_option("--scene", scene_file, "scene JSON to run instead of sampling one")->check(CLI::ExistingFile);
  app.add_option("--save-scene", save_scene, "write the episode's scene JSON here");
  app.add_option("--torque-noise", noise_sigma, "Gaussian noise (N m, standard deviation per entry) added to the expert's torques, a learner's error")
      ->check(manisoft::cli::non_negative());
  app.add_option("--noise-hold", noise_hold, "control steps each noise draw is held (1: fresh every step)")->check(manisoft::cli::positive());
  app.add_option("--trace", trace_file, "CSV file: one row per control step (world_demo's layout)");
  app.add_flag("--quiet", quiet, "print only the JSON line");
  std::string expert_file;
  app.add_option("--expert-config", expert_file, "expert: JSON file of settings by group, e.g. {\"carry\": {\"peak_speed\": 1.2}} (docs/tasks.md); the flags below override it")
      ->check(CLI::ExistingFile);
  std::optional<double> path_speed, carry_speed;
  std::optional<int> max_retries;
  app.add_option("--path-speed", path_speed, "expert: peak end-effector speed of a path with the gripper empty, m/s (paths.peak_speed)")->check(manisoft::cli::positive());
  app.add_option("--carry-speed", carry_speed, "expert: peak end-effector speed while holding, m/s (carry.peak_speed)")->check(manisoft::cli::positive());
  app.add_option("--max-retries", max_retries, "expert: re-tries of a move whose grasp failed, each with another grasp (approach.max_retries)")->check(manisoft::cli::non_negative());
  bool no_arm_check = false;
  app.add_flag("--no-arm-check", no_arm_check, "expert: do not check planned lines against objects and obstacles (checks.objects false)");
  task::TaskEnvConfig env_config;
  app.add_option("--executor-damping", env_config.executor.damping_gain, "executor: node velocity feedback kd, 1/s")->check(manisoft::cli::non_negative());
  app.add_option("--executor-stiffness", env_config.executor.position_gain, "executor: node position feedback kp, 1/s^2")->check(manisoft::cli::non_negative());
  manisoft::cli::check_counts(app, {"--index", "--seed"});
  manisoft::cli::readable_errors(app, "run_task");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    task::ExpertConfig expert_config = expert_file.empty() ? task::ExpertConfig{} : task::load_expert_config(expert_file);
    if (path_speed) expert_config.paths.peak_speed = *path_speed;
    if (carry_speed) expert_config.carry.peak_speed = *carry_speed;
    if (max_retries) expert_config.approach.max_retries = *max_retries;
    if (no_arm_check) expert_config.checks.objects = false;
    const std::clock_t c0 = std::clock();
    scene::SceneSampler sampler;
    scene::SceneSpec spec;
    if (!scene_file.empty()) {
      spec = scene::load_scene(scene_file, sampler.library());
      scene::require_valid(spec, sampler.validator(), scene_file);
    } else {
      scene::SampleRequest q;
      q.task = scene::parse_task(task_name);
      q.setting = scene::parse_setting(setting);
      q.split = scene::parse_split(split);
      q.index = index;
      q.seed = seed;
      spec = sampler.sample(q);
    }
    if (!save_scene.empty()) scene::save_scene(save_scene, spec);
    task::TaskEnv env(sampler.library(), env_config);
    task::Expert expert(env, expert_config);
    const std::clock_t c1 = std::clock();
    env.reset(spec);
    if (!scene_file.empty()) task::require_a_task(env, scene_file);
    expert.reset();
    if (!quiet) {
      std::printf("%s %s scene %llu (seed %llu): %zu objects, %zu obstacles\n", std::string(scene::to_string(spec.task)).c_str(),
                  std::string(scene::to_string(spec.setting)).c_str(), static_cast<unsigned long long>(spec.index),
                  static_cast<unsigned long long>(spec.seed), spec.objects.size(), spec.obstacles.size());
      std::printf("instruction: %s\n", spec.instruction.empty() ? "(none)" : spec.instruction.c_str());
    }
    std::ofstream trace;
    auto write_row = [&](int phase, int s) {
      const auto& w = env.world();
      const auto& rigid = w.rigid();
      const auto& objects = env.bodies().objects;
      int held = -1;
      for (std::size_t i = 0; i < objects.size(); ++i)
        if (w.gripper().held() && *w.gripper().held() == objects[i]) held = static_cast<int>(i);
      auto pose = [&](manisoft::rigid::BodyId b) {
        const auto x = rigid.position(b);
        const auto q = rigid.orientation(b);
        trace << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z();
      };
      trace << env.info().step << ',' << double(env.info().step) * env.control_dt() << ',' << phase << ',' << s << ',' << w.gripper().finger_width()
            << ',' << held;
      pose(w.gripper_body());
      const auto& x = w.rod().state().positions;
      for (int i = 0; i < x.rows(); ++i) trace << ',' << x(i, 0) << ',' << x(i, 1) << ',' << x(i, 2);
      for (const auto b : objects) pose(b);
      trace << '\n';
    };
    if (!trace_file.empty()) {
      trace.open(trace_file);
      if (!trace) manisoft::detail::fail("run_task: cannot write ", trace_file);
      trace.precision(7);
      trace << "step,time,phase,S,finger_width,held";
      auto pose_columns = [&](const std::string& n) { trace << ',' << n << "_px," << n << "_py," << n << "_pz," << n << "_qw," << n << "_qx," << n << "_qy," << n << "_qz"; };
      pose_columns("gripper");
      for (int i = 0; i < env.world().rod().state().positions.rows(); ++i) trace << ",node" << i << "_x,node" << i << "_y,node" << i << "_z";
      for (std::size_t i = 0; i < spec.objects.size(); ++i) pose_columns("object" + std::to_string(i));
      trace << '\n';
      write_row(static_cast<int>(expert.phase()), env.world().gripper().state());
    }
    task::TaskEnv::Array3 torques;
    // The noise of --torque-noise: seeded by the scene (index, seed), so a run is repeatable.
    task::TaskEnv::Array3 noise = task::TaskEnv::Array3::Zero(env.arm_model().rod.n_elements, 3);
    std::mt19937_64 noise_rng(spec.index * 0x9E3779B97F4A7C15ull + spec.seed + 0x401);
    std::normal_distribution<double> gaussian(0.0, 1.0);
    int s = 0;
    std::size_t printed = 0;
    while (!env.done()) {
      expert.act(torques, s);
      if (noise_sigma > 0) {
        if (env.info().step % noise_hold == 0)
          for (auto& v : noise.reshaped()) v = noise_sigma * gaussian(noise_rng);
        torques += noise;
      }
      env.step(torques, s);
      for (; printed < expert.events().size(); ++printed) {
        const auto& e = expert.events()[printed];
        if (!quiet)
          std::printf("  step %4ld  move %d  %-8s  end-effector (%.3f, %.3f, %.3f)\n", e.step, e.move, std::string(task::to_string(e.phase)).c_str(),
                      e.position.x(), e.position.y(), e.position.z());
      }
      if (trace.is_open()) write_row(static_cast<int>(expert.phase()), s);
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
    if (!quiet && !info.success) {  // which conditions of the predicate failed, and where everything ended
      const auto snapshot = env.snapshot();
      std::printf("unmet at the end: %s\n", env.conditions().unmet().c_str());
      std::printf("at the end (gripper %s):\n", snapshot.gripper_open ? "open" : "closed");
      for (std::size_t i = 0; i < snapshot.objects.size(); ++i) {
        const auto& o = snapshot.objects[i];
        std::printf("  object %zu %-14s centre of mass (%.3f, %.3f, %.3f), speed %.3f m/s, spin %.2f rad/s%s%s\n", i,
                    spec.objects[i].asset_id.c_str(), o.center_of_mass.x(), o.center_of_mass.y(), o.center_of_mass.z(),
                    o.linear_velocity.norm(), o.angular_velocity.norm(), o.held ? ", held" : "", o.touches_table ? ", on the table" : "");
      }
    }
    const auto quoted = [](std::string_view text) { return nlohmann::json(text).dump(); };  // a JSON string, escaped
    std::string failure = info.success ? "null" : quoted(task::to_string(info.failure));
    std::string why = expert.failure() ? quoted(*expert.failure()) : "null";
    // What the episode was about, for per-category tables: its target object (task::target_object)
    // and ARR's first relation; which conditions of the predicate did not hold at the end.
    const int target = task::target_object(spec);
    const std::string relation = spec.goal.relations.empty() ? "null" : quoted(manisoft::geometry::to_string(spec.goal.relations.front().kind));
    const std::string object = target >= 0 ? quoted(spec.objects[static_cast<std::size_t>(target)].asset_id) : "null";
    nlohmann::json unmet = nlohmann::json::array();
    for (const auto& c : env.conditions())
      if (!c.holds) unmet.push_back(std::string(c.name));
    std::printf("{\"task\":\"%s\",\"setting\":\"%s\",\"index\":%llu,\"seed\":%llu,\"success\":%s,\"success_at_end\":%s,\"steps\":%ld,\"failure\":%s,"
                "\"expert\":%s,\"torque_noise\":%g,\"noise_hold\":%d,\"cpu_s\":%.3f,\"episode_cpu_s\":%.3f,\"object\":%s,\"relation\":%s,\"instruction\":%s,\"unmet\":%s}\n",
                std::string(scene::to_string(spec.task)).c_str(), std::string(scene::to_string(spec.setting)).c_str(),
                static_cast<unsigned long long>(spec.index), static_cast<unsigned long long>(spec.seed), info.success ? "true" : "false",
                env.success_at_end() ? "true" : "false", info.step, failure.c_str(), why.c_str(), noise_sigma, noise_hold, cpu, episode_cpu, object.c_str(),
                relation.c_str(), quoted(spec.instruction).c_str(), unmet.dump().c_str());
  } catch (const manisoft::Error& e) {
    std::fprintf(stderr, "run_task: %s\n", e.what());
    return 1;
  }
  return 0;
}
