// pick_place_eval: the model executor as a trajectory tracker on a tabletop pick and place: the
// expert runs a cube (or a drinks can) to a place point as an ALN episode in TaskEnv
// (include/manisoft/task/pick_place.hpp).
//
//   pick_place_eval --episodes N --seed S [--mass KG] [--object cube|can] --out FILE.csv
//
// Episode i uses seed S * 100000 + i. Prints one table row per episode as it goes, then a last
// line of JSON:
//   {"episodes":N, "success_rate":..., "mean_steps":..., "max_steps":..., "mean_cpu_s":...,
//    "max_node_speed":..., "max_path_ratio":..., "failures":{"reason":count,...}}
// (steps over all episodes, successful or not; speeds in m/s; path ratio: measured end-effector
// path over its straight displacement, worst executor line of any episode). The CSV has one row
// per episode. Exit codes: 0 done, 1 refused configuration or failed run (no CSV is left: it is
// written under a temporary name and renamed when complete), 2 bad flags.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <string>

#include "../cli_checks.hpp"
#include "../output_file.hpp"
#include "manisoft/task/pick_place.hpp"

int main(int argc, char** argv) {
  CLI::App app{"pick_place_eval: tabletop pick and place by the expert, the model executor as a trajectory tracker"};
  int episodes = 20;
  long seed = 1;
  double mass = 0.1;
  std::string object = "cube", out;
  app.add_option("--episodes", episodes, "episodes to run")->required()->check(manisoft::cli::between(1, 1e6));
  app.add_option("--seed", seed, "seed of the task set (episode i: seed * 100000 + i)")->required()->check(manisoft::cli::between(0, 1e9));
  app.add_option("--mass", mass, "object mass, kg (default 0.1)")->check(manisoft::cli::between(0.001, 5));
  app.add_option("--object", object, "cube (a 5.7 cm Rubik's cube) or can (a drinks can, r 3.3 cm, 12 cm, upright)")->check(CLI::IsMember({"cube", "can"}));
  app.add_option("--out", out, "per-episode CSV")->required();
  manisoft::cli::readable_errors(app, "pick_place_eval");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  namespace task = manisoft::task;
  try {
    manisoft::cli::OutputFile file(out);
    std::ostream& csv = file.stream();
    csv << "episode,seed,success,failure,steps,cpu_s,max_node_speed,fastest_step,max_path_ratio,ramps,place_error,tilt,grasp_step,release_step,draws,"
           "object_x,object_y,object_yaw,place_x,place_y\n";
    csv.precision(9);
    const task::PickPlaceObject kind = object == "can" ? task::PickPlaceObject::can : task::PickPlaceObject::cube;
    const manisoft::scene::AssetLibrary library(task::pick_place_catalog(kind, mass));
    manisoft::scene::SceneValidator validator(library);
    task::TaskEnv env(library, task::pick_place_env_config());
    task::Expert expert(env, task::pick_place_expert_config());
    std::printf("pick and place: %d episodes, seed %ld, %s %.3f kg\n", episodes, seed, object.c_str(), mass);
    std::printf("%7s %8s %-13s %6s %7s %9s %10s %8s\n", "episode", "success", "failure", "steps", "cpu_s", "node_m/s", "path_ratio", "err_mm");
    int successes = 0;
    long total_steps = 0, max_steps = 0;
    double total_cpu = 0, max_speed = 0, max_ratio = 0;
    std::map<std::string, int> failures;
    for (int i = 0; i < episodes; ++i) {
      const std::uint64_t s = std::uint64_t(seed) * 100000u + std::uint64_t(i);
      const task::PickPlaceDraw draw = task::draw_pick_place(validator, expert, env, kind, s);
      const task::PickPlaceResult r = task::run_pick_place(env, expert, draw);
      successes += r.success;
      total_steps += r.steps;
      max_steps = std::max(max_steps, r.steps);
      total_cpu += r.cpu_seconds;
      max_speed = std::max(max_speed, r.max_node_speed);
      max_ratio = std::max(max_ratio, r.max_path_ratio);
      if (!r.success) ++failures[r.failure];
      std::printf("%7d %8s %-13s %6ld %7.3f %9.3f %10.3f %8.1f\n", i, r.success ? "yes" : "no", r.success ? "-" : r.failure.c_str(), r.steps,
                  r.cpu_seconds, r.max_node_speed, r.max_path_ratio, 1e3 * r.place_error);
      std::fflush(stdout);
      csv << i << ',' << s << ',' << int(r.success) << ',' << r.failure << ',' << r.steps << ',' << r.cpu_seconds << ',' << r.max_node_speed << ',' << r.fastest_step << ','
          << r.max_path_ratio << ',' << r.ramps << ',' << r.place_error << ',' << r.tilt << ',' << r.grasp_step << ',' << r.release_step << ',' << draw.draws << ','
          << draw.object.x() << ',' << draw.object.y() << ',' << draw.object_yaw << ',' << draw.place.x() << ',' << draw.place.y() << '\n';
    }
    file.commit();
    std::printf("{\"episodes\":%d, \"success_rate\":%.4f, \"mean_steps\":%.1f, \"max_steps\":%ld, \"mean_cpu_s\":%.4f, \"max_node_speed\":%.4f, "
                "\"max_path_ratio\":%.4f, \"failures\":{",
                episodes, double(successes) / episodes, double(total_steps) / episodes, max_steps, total_cpu / episodes, max_speed, max_ratio);
    bool first = true;
    for (const auto& [reason, count] : failures) {
      std::printf("%s\"%s\":%d", first ? "" : ", ", reason.c_str(), count);
      first = false;
    }
    std::printf("}}\n");
  } catch (const std::exception& e) {
    std::cerr << "pick_place_eval: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
