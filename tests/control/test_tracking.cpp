// The model executor as a trajectory tracker: shape continuity on the yaw-90 and
// yaw-180 tool-down cases, refusal of a path that cannot be held, a moving-target tracking error
// bound and payload compensation (the pick and place that uses it: tests/task/test_pick_place.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/env/reach_env.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace test_tracking {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

namespace control = manisoft::control;
using Pose = manisoft::math::Pose<double>;
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
using Env = manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear>;

/// The gripper pointing straight down with yaw `yaw` at attachment point p (world frame).
Pose tool_down(const Eigen::Vector3d& p, double yaw) {
  Eigen::Matrix3d down;
  down << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  return Pose{Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * down, p};
}

manisoft::rod::ArmModel<double> tabletop_model() {
  return manisoft::rod::make_arm_model(manisoft::world::tabletop_arm_parameters(), 0.2);
}

/// Runs `steps` control steps of env with the executor, the observation's target replaced by
/// `target`; calls check(step, observation) after each.
template <typename Check>
void drive(Env& env, control::ModelExecutor<double>& executor, const Pose& target, int steps, Check&& check) {
  control::Observation<double> o = control::make_arm_observation<double>(env.n_elements(), env.config().observe_stride);
  Array3 action = Array3::Zero(env.n_elements(), 3);
  for (int i = 0; i < steps; ++i) {
    control::observe_arm(env.world(), target, o);
    executor.act(o, action);
    env.step(action);
    control::observe_arm(env.world(), target, o);
    check(i, o);
  }
}

}  // namespace

TEST_CASE("a 4 cm move keeps the shape branch at gripper yaws of 90 and 180 degrees", "[executor][tracking]") {
  // DESIGN.md section 10: a cold re-solve for a nearby target jumped to a distant branch (a 3.3-3.5 m
  // tip path for a 4 cm move), mostly at these yaws. The tracked path's shapes, sampled here through
  // predicted_shape (independently of the planner's own check), move the tip along a path at most
  // 1.5 x the straight distance and no node by more than a few cm between samples.
  for (double yaw_deg : {90.0, 180.0}) {
    for (const Eigen::Vector3d& move : {Eigen::Vector3d(0.04, 0, 0), Eigen::Vector3d(0, 0.04, 0), Eigen::Vector3d(0, 0, -0.04)}) {
      control::ModelExecutor<double> executor(tabletop_model(), {150, 75});
      const Pose start = tool_down({0.5, 0.05, 0.93}, yaw_deg * std::numbers::pi / 180);
      REQUIRE(executor.set_target(start).within_limits);
      executor.complete_path();
      Pose goal = start;
      goal.translation += move;
      const auto report = executor.track_line(goal, 120);
      CAPTURE(yaw_deg, move.transpose(), report.reason);
      REQUIRE(report.accepted);
      CHECK(report.ratio <= 1.5);
      Array3 shape, previous;
      executor.predicted_shape(0, previous);
      CHECK((previous.row(previous.rows() - 1).transpose() - start.translation).norm() < 1e-6);
      double tip_path = 0, worst_node_step = 0;
      for (int step = 5; step <= 120; step += 5) {
        executor.predicted_shape(step, shape);
        tip_path += (shape.row(shape.rows() - 1) - previous.row(previous.rows() - 1)).norm();
        worst_node_step = std::max(worst_node_step, (shape - previous).rowwise().norm().maxCoeff());
        previous = shape;
      }
      CAPTURE(tip_path, worst_node_step);
      CHECK((previous.row(previous.rows() - 1).transpose() - goal.translation).norm() < 1e-6);
      CHECK(tip_path <= 1.5 * 0.04);
      CHECK(worst_node_step < 0.03);
    }
  }
}

TEST_CASE("solve_near bends a path's shapes around the actuation limits (actuator relief)", "[executor][tracking]") {
  // From the tasks' home pose across the table at a fixed tool-down orientation, in 1 cm knots
  // each warm-started from the previous one (the executor's path planning). Minimum-norm steps
  // alone run the shape into the torque limits; with relief the same path stays within them.
  // Independent checks: each knot's shape, by forward statics, meets its pose; the linear blend
  // between consecutive knots (what the executor interpolates) moves the tip along a path at
  // most 1.5 x the straight distance plus 1 mm.
  const Eigen::Vector3d waypoints[] = {{0.5, 0.0, 0.965}, {0.388, -0.322, 1.04}, {0.489, 0.071, 1.04}};
  const auto run = [&](int relief_iterations, double& worst_ratio, double& worst_blend) {
    manisoft::rod::InverseStaticsSettings<double> settings;
    settings.relief_iterations = relief_iterations;
    manisoft::rod::InverseStatics<double> statics(tabletop_model(), settings, {150, 75});
    REQUIRE(statics.solve_cold(tool_down(waypoints[0], 0.0)).within_limits);
    worst_ratio = 0;
    worst_blend = 0;
    for (int leg = 1; leg < 3; ++leg) {
      const int knots = static_cast<int>(std::ceil((waypoints[leg] - waypoints[leg - 1]).norm() / 0.01));
      for (int i = 1; i <= knots; ++i) {
        const Pose knot = tool_down(waypoints[leg - 1] + (double(i) / knots) * (waypoints[leg] - waypoints[leg - 1]), 0.0);
        const auto from = statics.coefficients();
        const Pose from_pose = statics.tip_pose(from);
        const auto r = statics.solve_near(knot, from, 8);
        REQUIRE(r.converged);
        worst_ratio = std::max(worst_ratio, r.max_torque_ratio);
        const auto to = statics.coefficients();
        CHECK((statics.tip_pose(to).translation - knot.translation).norm() < 1e-9);
        double path = 0;
        Eigen::Vector3d previous = from_pose.translation;
        for (int k = 1; k <= 16; ++k) {
          const Eigen::Vector3d x = statics.tip_pose(from + (k / 16.0) * (to - from)).translation;
          path += (x - previous).norm();
          previous = x;
        }
        worst_blend = std::max(worst_blend, path - 1.5 * (knot.translation - from_pose.translation).norm());
      }
    }
  };
  double ratio_off = 0, blend_off = 0, ratio_on = 0, blend_on = 0;
  run(0, ratio_off, blend_off);
  run(2, ratio_on, blend_on);
  CAPTURE(ratio_off, blend_off, ratio_on, blend_on);
  CHECK(ratio_off > 1.0);
  CHECK(ratio_on <= 1.0);
  CHECK(blend_on <= 1e-3);
}

TEST_CASE("solve_position_near meets a tip position with the rotation free and relieves the actuators", "[executor][tracking]") {
  // From the tasks' home pose 10 cm along x and 5 cm down: the tip position is met to round-off
  // (forward statics, an independent evaluation), and relief along the shapes with that tip
  // position lowers the largest torque ratio of the unrelieved minimum-norm shape (0.71) by more
  // than a tenth (to 0.58, short of the asked 0.8 x: the descent stops where E stops falling).
  manisoft::rod::InverseStatics<double> statics(tabletop_model(), {}, {150, 75});
  REQUIRE(statics.solve_cold(tool_down({0.5, 0.0, 0.965}, 0.0)).within_limits);
  const auto start = statics.coefficients();
  const Eigen::Vector3d goal(0.6, 0.0, 0.915);
  const auto plain = statics.solve_position_near(goal, start, 1.0, 0);
  REQUIRE(plain.converged);
  CHECK((statics.tip_pose(statics.coefficients()).translation - goal).norm() < 1e-9);
  const double threshold = 0.8 * plain.max_torque_ratio;
  const auto relieved = statics.solve_position_near(goal, start, threshold, 30);
  REQUIRE(relieved.converged);
  CAPTURE(plain.max_torque_ratio, relieved.max_torque_ratio);
  CHECK((statics.tip_pose(statics.coefficients()).translation - goal).norm() < 1e-9);
  CHECK(relieved.max_torque_ratio < 0.9 * plain.max_torque_ratio);
  CHECK_THROWS_WITH(statics.solve_position_near(Eigen::Vector3d(0.6, std::nan(""), 0.9), start, 1.0, 0), Catch::Contains("not finite"));
  CHECK_THROWS_WITH(statics.solve_position_near(goal, start, 1.5, 0), Catch::Contains("relief_ratio = 1.5"));
  CHECK_THROWS_WITH(statics.solve_position_near(goal, start, 0.9, -1), Catch::Contains("relief_iterations = -1"));
}

TEST_CASE("a path the arm cannot hold is refused and leaves the executor as it was", "[executor][tracking]") {
  control::ModelExecutor<double> executor(tabletop_model(), {150, 75});
  const Pose start = tool_down({0.5, 0.0, 0.93}, 0.0);
  REQUIRE(executor.set_target(start).within_limits);
  executor.complete_path();
  const auto before = executor.statics().coefficients();
  // 0.6 m below the table and far out: beyond the 1 m arm held within the limits.
  const auto report = executor.track_line(tool_down({1.3, 0.0, 0.3}, 0.0), 200);
  CHECK_FALSE(report.accepted);
  CHECK(std::string(report.reason).size() > 0);
  CHECK(executor.statics().coefficients() == before);
  // A path of length zero is a point target.
  const auto hold = executor.track_line(start, 0);
  CHECK(hold.accepted);
  CHECK(hold.knots == 2);
  CHECK_THROWS_WITH(executor.track_line(start, -1), Catch::Contains("-1"));
}

TEST_CASE("path timings: quintic by default, cruise profiles monotone from 0 to 1 at the stated peak speed", "[executor][tracking]") {
  using Executor = control::ModelExecutor<double>;
  for (double x = 0; x <= 1.0; x += 0.125) CHECK(Executor::path_timing(x, 0.0) == Approx(x * x * x * (10 - 15 * x + 6 * x * x)));
  for (const double cruise : {0.2, 0.5, 0.8}) {
    CAPTURE(cruise);
    CHECK(Executor::path_timing(0.0, cruise) == 0.0);
    CHECK(Executor::path_timing(1.0, cruise) == Approx(1.0));
    CHECK(Executor::path_timing(0.5, cruise) == Approx(0.5));
    constexpr int n = 2000;
    double previous = 0, peak = 0;
    for (int i = 1; i <= n; ++i) {
      const double s = Executor::path_timing(double(i) / n, cruise);
      CHECK(s >= previous);
      peak = std::max(peak, (s - previous) * n);
      previous = s;
      CHECK(Executor::path_timing(1.0 - double(i) / n, cruise) == Approx(1.0 - s).margin(1e-12));
    }
    CHECK(peak == Approx(2.0 / (1.0 + cruise)).epsilon(1e-3));
  }
  Executor executor(tabletop_model(), {150, 75});
  CHECK_THROWS_WITH(executor.track_line(executor.statics().desired_tip_pose(), 10, 1.0, 1.0), Catch::Contains("cruise"));
}

TEST_CASE("the tracker follows a moving target within a bound and converges at its end", "[executor][tracking]") {
  Env env({}, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  env.reset(1);
  control::ModelExecutor<double> executor(env.nominal_model(), env.config().limits);
  const Pose start = tool_down({0.5, 0.0, 0.93}, 0.3);
  REQUIRE(executor.set_target(start).within_limits);
  drive(env, executor, start, 700, [](int, const control::Observation<double>&) {});
  REQUIRE(executor.converged());
  // 15 cm sideways and 5 cm down in 250 control steps (0.35 s, peak 0.85 m/s at the tip).
  Pose goal = start;
  goal.translation += Eigen::Vector3d(0.0, 0.15, -0.05);
  const auto report = executor.track_line(goal, 250);
  REQUIRE(report.accepted);
  double worst = 0, node_speed = 0;
  bool converged_early = false;
  drive(env, executor, goal, 450, [&](int i, const control::Observation<double>& o) {
    // The error to the moving reference (the shape target's tip pose at this step).
    worst = std::max(worst, (o.end_effector.translation - executor.statics().desired_tip_pose().translation).norm());
    node_speed = std::max(node_speed, o.node_velocities.rowwise().norm().maxCoeff());
    if (i < 240 && executor.converged()) converged_early = true;
  });
  CAPTURE(worst, node_speed);
  CHECK(worst < 0.03);
  CHECK(node_speed < 1.5);
  CHECK_FALSE(converged_early);
  const Pose end = env.world().soft().end_effector_frame().position.allFinite() ? Pose{env.world().soft().end_effector_frame().rotation, env.world().soft().end_effector_frame().position} : Pose{};
  CHECK((end.translation - goal.translation).norm() < 0.01);
}

TEST_CASE("the payload hint removes a held object's sag", "[executor][tracking]") {
  // The reach arm holding 0.1 kg more than its model (in the gripper), estimators and outer loop
  // off so only the feed-forward and the node feedback act. The hint set_payload(0.1) puts the
  // pose within 1 mm of the unloaded arm's and cuts the sag left without it (measured here: 0.23
  // mm without, 0.06 mm with the hint at the default gains; the position feedback, kp = 800 1/s^2,
  // already holds most of the 8 mm DESIGN.md section 10 saw with its gains).
  const Pose target = tool_down({0.5, 0.05, 0.95}, 0.0);
  control::ModelExecutorSettings<double> settings;
  settings.outer_gain = 0;
  settings.stiffness_gain = 0;
  auto final_position = [&](double load, double hint) {
    manisoft::env::ReachEnvConfig config;
    config.load_mass = load;
    Env env(config, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
    env.reset(1);
    control::ModelExecutor<double> executor(env.nominal_model(), env.config().limits, settings);
    executor.set_target(target);
    executor.set_payload(hint);
    drive(env, executor, target, 900, [](int, const control::Observation<double>&) {});
    return Eigen::Vector3d(env.world().soft().end_effector_frame().position);
  };
  const Eigen::Vector3d unloaded = final_position(0, 0), sagging = final_position(0.1, 0), compensated = final_position(0.1, 0.1);
  CAPTURE(unloaded.transpose(), sagging.transpose(), compensated.transpose());
  CHECK((compensated - unloaded).norm() < 0.001);
  CHECK((sagging - unloaded).norm() > 2 * (compensated - unloaded).norm());
  CHECK((sagging - unloaded).z() < 0);  // it sags down
  control::ModelExecutor<double> executor(tabletop_model(), {150, 75});
  CHECK_THROWS_WITH(executor.set_payload(-0.1), Catch::Contains("-0.1"));
}

}  // namespace test_tracking
