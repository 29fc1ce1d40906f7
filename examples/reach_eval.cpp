// reach_eval: success rate of an executor on a seeded set of reach targets.
//
//   reach_eval --targets 100 --seed S --set table|equilibria --executor model|mlp
//              [--weights FILE] [--load-kg M] [--model-error F] [--tol-pos M --tol-rot RAD] [--hold-steps N]
//              [--damping analytical|analytical:NU|uniform:GAMMA] [--action elements|bspline[:K]|bspline-pinned[:K]]
//              [--max-node-speed V] --out FILE.csv
//
// Every target runs the full horizon (1500 control steps). Success: the pose error is within
// tolerance (|d_p| < tol-pos, |d_r| < tol-rot; defaults 0.03 m, 0.3 rad) and then stays within it
// for 100 control steps (--hold-steps; 1 is the paper's criterion for its learned executor: within
// tolerance once). Prints "success: X% (K of N)", the mean control steps to success (first
// step of the held window, over successes) and the stability metric (variance of the pose
// distance d over the last 1000 simulation steps, mean over targets). The CSV has one row per
// target. Set-up (the first act() of a target: the inverse statics solve) is reported in wall
// time and in process CPU time (std::clock; on a shared machine the wall time includes waits for
// the CPU). --damping picks the simulated rod's damping (default analytical:0.1, PyElastica's).
// --action picks the action space (control/action_space.hpp): element torques (n x 3, default)
// or K B-spline muscle control values per direction (default K = 8; bspline-pinned: K interior
// control values with zero ends, Elastica-RL's layout). The model
// executor drives the B-spline space through ProjectedExecutor (least-squares fit of its element
// torques); an MLP's network must output rows x 3 values of the chosen space.
// --max-node-speed V (m/s) gives the model executor a smooth shape ramp
// (ModelExecutorSettings::smooth_ramp: planned peak node speed at most V, via shapes where a
// blend loops, cruise timing), allowed to last until hold_steps + 100 control steps before the
// horizon. Without it the ramp runs with the executor's defaults (a single smoothstep blend at a
// mean tip speed of 4.2 m/s).
// Also reported per target (the transients a success rate hides): the fastest rod node at any
// substep (m/s) and the tip path ratio, the end-effector's path from the end of the first control
// step to the first step of the held window (to the horizon if none) over the straight distance
// from there to the target.
// --help lists the flags. Bad flags exit 2 with a message naming the flag and the value (the
// load at most the bend limit over g times the arm's length); a refused configuration or a failed
// write exits 1, leaving no CSV (written under a temporary name, renamed when complete).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "cli_checks.hpp"
#include "manisoft/control/mlp_executor.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/control/projected_executor.hpp"
#include "manisoft/env/reach_env.hpp"
#include "manisoft/env/rollout.hpp"
#include "output_file.hpp"

namespace {

struct Options {
  int targets = 100;
  long seed = 0;
  std::string set = "table", executor = "model", weights, out, damping = "analytical:0.1", action = "elements";
  double load = 0, model_error = 0, tol_pos = 0.03, tol_rot = 0.3;
  double max_node_speed = 0;  // m/s, 0: the executor's default ramp
  int hold_steps = manisoft::env::ReachEnvConfig{}.hold_steps;
};

[[noreturn]] void usage_error(const std::string& message) {
  std::cerr << "reach_eval: " << message << "\nRun with --help for more information.\n";
  std::exit(2);
}

double parse_number(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) usage_error(flag + " expects a finite number, got '" + text + "'");
  return v;
}

/// The heaviest load the arm can hold: its weight at the arm's length takes the whole bend limit.
double max_load_kg() {
  const manisoft::env::ReachEnvConfig defaults;
  return defaults.limits.bend / (9.81 * defaults.rod.length);
}

/// --damping analytical[:NU] or uniform[:GAMMA], the value finite and >= 0.
void check_damping(const std::string& d) {
  const auto colon = d.find(':');
  const std::string kind = d.substr(0, colon);
  if (kind != "analytical" && kind != "uniform") usage_error("--damping must be analytical[:NU] or uniform[:GAMMA], got '" + d + "'");
  if (colon == std::string::npos) return;
  const std::string value = d.substr(colon + 1);
  if (parse_number("--damping", value) < 0) usage_error("--damping value must be >= 0 (got " + value + ")");
}

/// The options; `exit_code` is -1 to go on, else the code to exit with (0 after --help, 2 after
/// a bad flag).
Options parse(int argc, char** argv, int& exit_code) {
  namespace cli = manisoft::cli;
  Options o;
  CLI::App app{"reach_eval: success rate of an executor on a seeded set of reach targets (CSV: one row per target). "
               "Exit 0 done, 1 refused configuration or failed write, 2 bad flags."};
  app.add_option("--targets", o.targets, "targets to run (default 100)")->check(cli::between(1, 1e7));
  app.add_option("--seed", o.seed, "seed of the target set (target i: seed * 1000003 + i)")->required()->check(cli::between(0, 1e15));
  app.add_option("--set", o.set, "table (default) or equilibria")->check(CLI::IsMember({"table", "equilibria"}));
  app.add_option("--executor", o.executor, "model (default) or mlp")->check(CLI::IsMember({"model", "mlp"}));
  app.add_option("--weights", o.weights, "MLP weight file (--executor mlp)");
  const double max_load = max_load_kg();
  char load_help[160];
  std::snprintf(load_help, sizeof load_help, "held load unknown to the model, kg (at most %.3g: the bend limit over g times the arm's length)", max_load);
  app.add_option("--load-kg", o.load, load_help)->check(cli::between(0, max_load));
  app.add_option("--model-error", o.model_error, "F: the simulated Young's modulus is (1 + F) times the model's")->check(cli::above(-0.9));
  app.add_option("--tol-pos", o.tol_pos, "position tolerance, m (default 0.03)")->check(cli::positive());
  app.add_option("--tol-rot", o.tol_rot, "rotation tolerance, rad (default 0.3)")->check(cli::positive());
  app.add_option("--hold-steps", o.hold_steps, "control steps the tolerance must hold for a success (default 100; 1: reached once)")
      ->check(cli::between(1, manisoft::env::ReachEnvConfig{}.horizon));
  app.add_option("--damping", o.damping, "the simulated rod's damping: analytical[:NU] (default analytical:0.1) or uniform[:GAMMA]");
  app.add_option("--action", o.action, "elements (default), bspline[:K] or bspline-pinned[:K]");
  app.add_option("--max-node-speed", o.max_node_speed, "model executor: planned peak node speed of a smooth ramp, m/s")->check(cli::positive());
  app.add_option("--out", o.out, "CSV file to write")->required();
  cli::readable_errors(app, "reach_eval");
  exit_code = cli::parse(app, argc, argv);
  if (exit_code >= 0) return o;
  if (o.executor == "mlp" && o.weights.empty()) usage_error("--executor mlp needs --weights FILE");
  check_damping(o.damping);
  return o;
}

template <typename Env, typename Executor>
int run(const Options& o, Executor& executor, Env& env) {
  manisoft::cli::OutputFile file(o.out);
  std::ostream& csv = file.stream();
  csv << "index,target_x,target_y,target_z,target_rx,target_ry,target_rz,success,first_success_step,final_position_error,"
         "final_rotation_error,min_distance,stability_variance,diverged,target_draws,setup_us,setup_cpu_us,mean_step_us,clipped_fraction,"
         "max_node_speed,path_ratio\n";
  csv.precision(9);
  int successes = 0;
  double steps_sum = 0, variance_sum = 0, step_us_sum = 0, setup_us_sum = 0, setup_us_max = 0, setup_cpu_max = 0, setup_cpu_sum = 0;
  long step_count = 0;
  double max_speed_all = 0, max_ratio_all = 0;
  std::vector<double> path(static_cast<std::size_t>(env.config().horizon) + 1);  // end-effector path after k steps
  for (int i = 0; i < o.targets; ++i) {
    const std::uint64_t seed = static_cast<std::uint64_t>(o.seed) * 1000003ull + static_cast<std::uint64_t>(i);
    double min_d = 1e300, max_speed = 0;
    long clipped = 0;
    Eigen::Vector3d start = Eigen::Vector3d::Zero(), last = start;
    const auto record = manisoft::env::rollout(env, executor, seed, [&](const auto& step) {
      clipped += step.result.info.clipped;
      min_d = std::min(min_d, step.result.info.error.distance);
      max_speed = std::max(max_speed, step.result.info.max_node_speed);
      const Eigen::Vector3d p = step.result.observation.end_effector.translation;
      if (step.step == 0) start = last = p, path[0] = 0;  // from the end of the first control step
      const auto k = static_cast<std::size_t>(step.step);
      path[k + 1] = path[k] + (p - last).norm();
      last = p;
    });
    const auto& info = record.info;
    const double straight = (env.target().translation - start).norm();
    const double travelled = path[static_cast<std::size_t>(info.success ? info.first_success_step : record.steps)];
    const double ratio = straight > 1e-3 ? travelled / straight : 1.0;
    max_speed_all = std::max(max_speed_all, max_speed);
    max_ratio_all = std::max(max_ratio_all, ratio);
    const double setup_us = 1e6 * record.first_act_seconds, setup_cpu_us = 1e6 * record.first_act_cpu_seconds;
    const double target_step_us = 1e6 * record.act_seconds;
    const double variance = env.stability_variance();
    const int steps = std::max(1, info.step - 1);
    step_us_sum += target_step_us;
    step_count += steps;
    setup_us_sum += setup_us;
    setup_us_max = std::max(setup_us_max, setup_us);
    setup_cpu_sum += setup_cpu_us;
    setup_cpu_max = std::max(setup_cpu_max, setup_cpu_us);
    variance_sum += variance;
    if (info.success) {
      ++successes;
      steps_sum += info.first_success_step;
    }
    const auto& target = env.target();
    const Eigen::Vector3d rv = manisoft::math::so3::log(target.rotation);
    csv << i << ',' << target.translation.x() << ',' << target.translation.y() << ',' << target.translation.z() << ',' << rv.x() << ','
        << rv.y() << ',' << rv.z() << ',' << int(info.success) << ',' << info.first_success_step << ',' << info.error.position_error << ','
        << info.error.rotation_error << ',' << min_d << ',' << variance << ',' << int(info.diverged) << ',' << env.target_draws() << ','
        << setup_us << ',' << setup_cpu_us << ',' << target_step_us / steps << ',' << double(clipped) / (double(info.step) * 3 * (env.n_elements() - 1))
        << ',' << max_speed << ',' << ratio << '\n';
  }
  file.commit();  // before the summary: a run whose CSV failed reports no success rate
  std::printf("success: %.1f%% (%d of %d)\n", 100.0 * successes / o.targets, successes, o.targets);
  if (successes > 0) std::printf("mean control steps to success: %.1f\n", steps_sum / successes);
  else std::printf("mean control steps to success: n/a (no success)\n");
  std::printf("stability (variance of d over the last 1000 simulation steps, mean over targets): %.3e\n", variance_sum / o.targets);
  std::printf("fastest node: %.3f m/s; largest tip path ratio: %.3f\n", max_speed_all, max_ratio_all);
  std::printf("executor compute: %.2f us per control step (mean), set-up %.0f us per target (mean, max %.0f; CPU time mean %.0f, max %.0f)\n",
              step_us_sum / double(std::max(1L, step_count)), setup_us_sum / o.targets, setup_us_max, setup_cpu_sum / o.targets, setup_cpu_max);
  return 0;
}

template <template <class> class Damping, template <class> class ActionPolicy>
int run_with(const Options& o, Damping<double> damping, typename ActionPolicy<double>::Settings action_settings = {}) {
  manisoft::env::ReachEnvConfig config;
  config.target_set = manisoft::env::parse_target_set(o.set);
  config.load_mass = o.load;
  config.model_error = o.model_error;
  config.tolerance_position = o.tol_pos;
  config.tolerance_rotation = o.tol_rot;
  config.hold_steps = o.hold_steps;
  manisoft::env::ReachEnv<Damping, ActionPolicy> env(config, damping, action_settings);
  if (o.executor == "model") {
    const auto settings = o.max_node_speed > 0 ? manisoft::control::ModelExecutorSettings<double>::smooth_ramp(
                                                      o.max_node_speed * config.dt * config.substeps, config.horizon - config.hold_steps - 100)
                                                : manisoft::control::ModelExecutorSettings<double>{};
    manisoft::control::ModelExecutor<double> model(env.nominal_model(), config.limits, settings);
    manisoft::control::ProjectedExecutor executor(std::move(model), env.action_space());
    return run(o, executor, env);
  }
  auto executor = manisoft::control::MlpExecutor<double>::load(o.weights, env.action_space().rows());
  return run(o, executor, env);
}

template <template <class> class Damping>
int run_with_action(const Options& o, Damping<double> damping) {
  if (o.action == "elements") return run_with<Damping, manisoft::control::ElementTorqueAction>(o, damping);
  for (const bool pinned : {true, false}) {
    const std::string name = pinned ? "bspline-pinned" : "bspline";
    if (o.action != name && o.action.rfind(name + ":", 0) != 0) continue;
    manisoft::control::BsplineMuscleAction<double>::Settings settings;
    settings.pinned_ends = pinned;
    if (o.action.size() > name.size()) {
      const double k = parse_number("--action", o.action.substr(name.size() + 1));
      if (k != std::floor(k) || k < 1 || k > 1000) usage_error("--action " + name + ":K needs a positive integer K");
      settings.control_points = static_cast<int>(k);
    }
    return run_with<Damping, manisoft::control::BsplineMuscleAction>(o, damping, settings);
  }
  usage_error("--action must be elements, bspline[:K] or bspline-pinned[:K]");
}

}  // namespace

int main(int argc, char** argv) {
  int exit_code = -1;
  const Options o = parse(argc, argv, exit_code);
  if (exit_code >= 0) return exit_code;
  try {
    const std::string d = o.damping;
    const auto colon = d.find(':');
    const std::string kind = d.substr(0, colon);
    const double value = colon == std::string::npos ? -1 : parse_number("--damping", d.substr(colon + 1));
    if (kind == "analytical") return run_with_action(o, manisoft::rod::damping::AnalyticalLinear<double>(value < 0 ? 0.1 : value));
    if (kind == "uniform") return run_with_action(o, manisoft::rod::damping::UniformExp<double>(value < 0 ? 1.0 : value));
    usage_error("--damping must be analytical[:NU] or uniform[:GAMMA]");
  } catch (const manisoft::Error& e) {
    std::cerr << "reach_eval: " << e.what() << "\n";
    return 1;
  }
}
