// Pick and place in the tabletop world with the model executor as a trajectory tracker (the
// expert of the paper's tasks, section 3.4-3.5): the reusable routine behind
// examples/benchmark/pick_place_eval.cpp.
//
//   env::PickPlaceRunner runner(config);          // builds the world, brings the arm home (once)
//   const env::PickPlaceResult r = runner.run(seed);
//
// World: world::ArmWorld on the tabletop scene (table, floor, the arm mounted at (-0.05, 0, 1.5)
// pointing +x, the parallel gripper on the arm coupling), rod damping analytical 0.1 and the
// coupling both the executor's validated defaults (the reach environment's), 7 substeps of 2e-4 s
// per control step (714 Hz), rod contact on. One object of `object_mass` on the table: a 5 cm
// cube, or a can (r 3.3 cm, 11.6 cm long) lying on its side (`PickPlaceConfig::object`).
// Home: every episode starts from the same settled state, the gripper tool-down with its grasp
// centre at `home` (reached once from the straight arm by the executor's shape ramp; those reset steps are
// not the episode's and are reported apart: home_steps()).
// Task of a seed (draw_task; std::mt19937_64 raw output, own uniform): object centre uniform in
// the reachable band x in [0.30, 0.62], y in [-0.25, 0.25], yaw uniform; place point 15-25 cm away
// in a uniform direction, in the same band; redrawn until every path, planned from the home shape,
// needs at most plan_torque_ratio of the actuation limits (headroom for the shape the outer loop
// and the payload leave at run time) and every waypoint shape is 6 cm clear of the table top.
// Waypoints (gripper tool-down, constant yaw along the episode: the cube's yaw folded into
// [-45, 45] deg, or across the can's axis folded into [-90, 90] deg): pre-grasp (grasp +
// pregrasp_height), grasp (grasp centre grasp_height above the table top: fingertips 1 cm above
// it), carry (above the place point, carry_height higher; a diagonal line from the grasp), place
// (corrected for where the object sits in the hand, its bottom place_clearance above the top).
// Every move is executor.track_line (straight line, quintic timing, duration from
// path_peak_speed, lower_peak_speed for the last, at least min_segment_steps). The gripper closes
// only when the arm has settled (every node slower than settle_speed, end-effector within
// settle_error of the grasp pose; at most max_settle_steps of waiting), then tells the executor
// its payload (mass and offset in the hand); it opens once the table carries the object, or once
// settled at the place pose.
// Success: the object released (not held), its centre within success_distance (2 cm) of the place
// point horizontally, flat (a cube: a face axis within 5 deg of vertical; a can: its axis within
// 5 deg of horizontal) and at rest (< 1 cm/s, < 0.1 rad/s for rest_steps control steps), within
// max_steps control steps.
// Failure reasons: path_refused, missed_grasp, dropped, timeout, diverged, off_target, tilted.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <array>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/control/tool_down.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/rod/cosserat_rod.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::env {

/// What is picked and placed: a cube, or a can lying on its side (a cylinder whose axis is
/// horizontal; grasped across its axis, so the gripper's closing axis is perpendicular to it).
enum class PickPlaceObject { cube, can };

struct PickPlaceConfig {
  PickPlaceObject object = PickPlaceObject::cube;
  double object_mass = 0.1;            ///< kg
  double cube_half = 0.025;            ///< m
  double can_radius = 0.033;           ///< m (a 330 ml drinks can)
  double can_half_length = 0.058;      ///< m
  double can_rolling_resistance = 5e-4;  ///< m (the assets use 2 mm; a bare cube keeps 0)
  double dt = 2e-4;                    ///< s
  int substeps = 7;                    ///< per control step (714 Hz)
  int max_steps = 1500;                ///< control steps per episode (the paper's horizon)
  double rod_damping = 0.1;            ///< analytical linear damping of the simulated rod
  int observe_stride = 2;
  Eigen::Vector3d home{0.50, 0.0, 0.88};  ///< grasp centre of the home pose (tool down, yaw 0)
  int home_path_steps = 900;           ///< control steps of the straight arm's ramp home (reset)
  int home_settle_steps = 300;         ///< then held
  double grasp_height = 0.045;         ///< grasp centre above the table top at the grasp, m
  double pregrasp_height = 0.06;       ///< m above the grasp
  double carry_height = 0.05;          ///< m above the place pose
  double place_clearance = 0.005;      ///< object bottom above the table top when opening, m
  double path_peak_speed = 0.9;        ///< m/s, peak tip speed of a path's quintic timing
  double lower_peak_speed = 0.3;       ///< m/s, the same for the last path, lowering the object onto the table
                                       ///< (at 0.9 the arm swung and set objects down 13 mm off, median)
  double max_node_speed = 0.9;         ///< m/s, planned peak speed of any node (paths are slowed to it)
  int min_segment_steps = 60;          ///< shortest path, control steps
  double settle_speed = 0.05;          ///< m/s: close / open only when every node is slower
  double settle_error = 0.01;          ///< m: and the end-effector this near its pose
  int max_settle_steps = 200;          ///< longest wait for settling (then act anyway)
  double start_error = 0.015;          ///< m: a chained path starts once the previous one is this near its end
  double success_distance = 0.02;      ///< m
  double flat_angle = 5 * std::numbers::pi / 180;  ///< rad
  int rest_steps = 10;                 ///< control steps at rest after the release
  control::ModelExecutorSettings<double> executor{};
  double table_clearance = 0.06;       ///< m: every node of a waypoint shape this far above the top
  double plan_torque_ratio = 0.95;     ///< the task draw's paths use at most this fraction of the actuation limits
};

struct PickPlaceTask {
  Eigen::Vector3d object{0, 0, 0}; ///< object centre at the start
  double object_yaw = 0;           ///< rad (the can: of its axis)
  Eigen::Vector3d place{0, 0, 0};  ///< where the object centre should end (on the table)
  double gripper_yaw = 0;          ///< rad, in [-pi/4, pi/4] (cube) or [-pi/2, pi/2] (can)
  int draws = 0;                   ///< candidates drawn
};

struct PickPlaceResult {
  std::uint64_t seed = 0;
  PickPlaceTask task{};
  bool success = false;
  std::string failure;             ///< "" on success
  std::string detail;              ///< more on a failure (a refused path: the phase and the planner's reason)
  int steps = 0;                   ///< control steps taken (successful or not)
  double cpu_seconds = 0;          ///< process CPU time of the episode (simulation + executor)
  double executor_seconds = 0;     ///< CPU time inside act() and path set-ups
  double max_setup_seconds = 0;    ///< slowest track_line set-up (CPU time)
  double max_node_speed = 0;       ///< m/s, any rod node at any substep
  double max_path_ratio = 0;       ///< measured end-effector path / straight distance, worst segment
  double max_planned_ratio = 0;    ///< the planner's tip path / straight distance, worst segment
  double place_error = 0;          ///< m, horizontal, object centre to the place point at the end
  double tilt = 0;                 ///< rad at the end: the cube's most vertical face axis off the vertical, the can's axis off the horizontal
  int grasp_step = -1, release_step = -1;
};

inline const char* pick_place_phase_name(int phase) {
  static const char* names[] = {"approach", "descend", "close", "carry", "lower", "open", "rest"};
  return phase >= 0 && phase < 7 ? names[phase] : "?";
}

class PickPlaceRunner {
 public:
  using Rod = rod::CosseratRod<double, rod::damping::AnalyticalLinear, rod::bc::ClampedBase, rod::integrator::PositionVerlet,
                               rod::forcing::Gravity, rod::forcing::ElementTorques>;
  using World = world::ArmWorld<Rod>;
  using Pose = math::Pose<double>;
  using Vec3 = Eigen::Vector3d;
  using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
  using Executor = control::ModelExecutor<double>;

  explicit PickPlaceRunner(PickPlaceConfig config = {})
      : config_(validated(config)),
        params_(world::tabletop_arm_parameters()),
        model_(rod::make_arm_model(params_, gripper_.mass)),
        world_(Rod(params_, config_.dt, rod::damping::AnalyticalLinear<double>(config_.rod_damping)), world_settings()),
        executor_(model_, world_settings().limits, config_.executor) {
    table_ = world::tabletop_table();
    top_ = table_.top_center.z();
    world_.add_table(table_);
    rigid::RigidBodyDesc body;
    if (config_.object == PickPlaceObject::can) {
      body.shape = geometry::Cylinder<double>{config_.can_radius, config_.can_half_length};
      body.rolling_resistance = config_.can_rolling_resistance;
      body.name = "can";
    } else {
      body.shape = geometry::Box<double>{Vec3::Constant(config_.cube_half)};
      body.name = "cube";
    }
    body.position = parking_spot();
    body.mass = config_.object_mass;
    body.friction = 0.6;
    object_ = world_.add_object(body);
    observation_ = control::make_arm_observation<double>(params_.n_elements, config_.observe_stride);
    torques_.setZero(params_.n_elements, 3);
    go_home();
  }

  const PickPlaceConfig& config() const { return config_; }
  /// Control steps of the reset from the straight arm to the home pose (not part of episodes).
  int home_steps() const { return home_steps_; }
  const World& world() const { return world_; }
  /// The executor as it is at the settled home state (every episode starts from a copy).
  const Executor& home_executor() const { return home_executor_; }
  rigid::BodyId object() const { return object_; }

  /// The tool-down end-effector pose whose grasp centre is at `grasp_center` with yaw `yaw`.
  Pose tool_down(const Vec3& grasp_center, double yaw) const { return control::tool_down_pose(grasp_center, yaw, gripper_.grasp_center()); }

  /// The task of `seed` (deterministic).
  PickPlaceTask draw_task(std::uint64_t seed) {
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x91C4);
    auto uniform = [&rng](double lo, double hi) { return lo + (hi - lo) * (double(rng() >> 11) * 0x1.0p-53); };
    const double pi = std::numbers::pi;
    PickPlaceTask t;
    for (t.draws = 1; t.draws <= 1000; ++t.draws) {
      t.object = Vec3(uniform(0.30, 0.62), uniform(-0.25, 0.25), top_ + half_height());
      t.object_yaw = uniform(-pi, pi);
      const double distance = uniform(0.15, 0.25), direction = uniform(-pi, pi);
      t.place = t.object + distance * Vec3(std::cos(direction), std::sin(direction), 0);
      if (t.place.x() < 0.30 || t.place.x() > 0.62 || std::abs(t.place.y()) > 0.25) continue;
      // The cube: a quarter turn is a symmetry, so yaw in [-45, 45] deg. The can: the fingers
      // close across its axis (yaw + 90 deg), and a half turn is a symmetry: [-90, 90] deg.
      if (config_.object == PickPlaceObject::can) {
        const double across = t.object_yaw + pi / 2;
        t.gripper_yaw = across - pi * std::round(across / pi);
      } else {
        t.gripper_yaw = t.object_yaw - (pi / 2) * std::round(t.object_yaw / (pi / 2));
      }
      // The whole sequence is planned from home (on a copy of the home executor): every path
      // accepted (continuous, within the limits with the object's weight once it is held) and
      // every waypoint shape clear of the table top.
      planner_ = home_executor_;
      const auto w = waypoints(t, Vec3::Zero());
      bool ok = true;
      for (std::size_t i = 0; i < w.size() && ok; ++i) {
        if (i == 2) planner_.set_payload(config_.object_mass, nominal_in_hand(t));
        const auto report = planner_.track_line(w[i], 100);
        ok = report.accepted && report.max_torque_ratio <= config_.plan_torque_ratio;
        planner_.complete_path();
        ok = ok && planner_.statics().desired_state().positions.col(2).minCoeff() >= top_ + config_.table_clearance;
      }
      if (ok) return t;
    }
    manisoft::detail::fail("PickPlaceRunner: no feasible task found for seed ", seed, " in 1000 draws");
  }

  /// One episode from the home state (deterministic per seed; `observe(phase, step)` after each
  /// control step).
  template <typename Observer>
  PickPlaceResult run(std::uint64_t seed, Observer&& observe) {
    const std::clock_t c0 = std::clock();
    PickPlaceResult res;
    res.seed = seed;
    res.task = draw_task(seed);
    const PickPlaceTask& t = res.task;
    world_.soft().restore(home_snapshot_);
    executor_ = home_executor_;
    world_.rigid().set_pose(object_, t.object, start_orientation(t.object_yaw));
    world_.rigid().set_velocity(object_, Vec3::Zero(), Vec3::Zero());
    const auto wp = waypoints(t, Vec3::Zero());  // pre-grasp, grasp, carry, place (hand offset corrected at the grasp)
    Pose place = wp[3], carry = wp[2];
    int phase = 0, s = 0, waited = 0, rest = 0;
    Pose target = wp[0];
    // Segment measurement: end-effector path since the segment started.
    double seg_path = 0, seg_straight = 0;
    Vec3 last_ee = ee_pose().translation;
    bool in_segment = false;
    auto start_path = [&](const Pose& goal, double peak_speed) {
      const double distance = (goal.translation - executor_.statics().desired_tip_pose().translation).norm();
      const int steps = std::max(config_.min_segment_steps,
                                 static_cast<int>(std::ceil(1.875 * distance / peak_speed / control_dt())));
      const std::clock_t s0 = std::clock();
      const auto report = executor_.track_line(goal, steps, config_.max_node_speed * control_dt());
      const double setup = double(std::clock() - s0) / CLOCKS_PER_SEC;
      res.executor_seconds += setup;
      res.max_setup_seconds = std::max(res.max_setup_seconds, setup);
      if (!report.accepted) {
        res.detail = std::string(pick_place_phase_name(phase)) + ": " + report.reason;
        return false;
      }
      res.max_planned_ratio = std::max(res.max_planned_ratio, report.ratio);
      target = goal;
      seg_path = 0;
      seg_straight = distance;
      in_segment = true;
      return true;
    };
    auto end_segment = [&]() {
      if (in_segment && seg_straight > 1e-3) res.max_path_ratio = std::max(res.max_path_ratio, seg_path / seg_straight);
      in_segment = false;
    };
    if (!start_path(wp[0], config_.path_peak_speed)) res.failure = "path_refused";
    while (res.failure.empty() && !res.success) {
      if (res.steps >= config_.max_steps) {
        res.failure = "timeout";
        break;
      }
      control::observe_arm(world_, target, observation_);
      const std::clock_t a0 = std::clock();
      executor_.act(observation_, torques_);
      res.executor_seconds += double(std::clock() - a0) / CLOCKS_PER_SEC;
      try {
        world_.control_step(torques_, s, [&] {
          const auto& v = world_.rod().state().velocities;
          for (int j = 0; j < v.rows(); ++j) res.max_node_speed = std::max(res.max_node_speed, v.row(j).norm());
        });
      } catch (const Diverged&) {
        res.failure = "diverged";
        break;
      }
      ++res.steps;
      const Pose ee = ee_pose();
      if (in_segment) seg_path += (ee.translation - last_ee).norm();
      last_ee = ee.translation;
      observe(phase, res.steps);
      const double speed = max_node_speed_now();
      const double error = (ee.translation - target.translation).norm();
      const bool done = executor_.path_done();
      const bool settled = done && speed < config_.settle_speed && error < config_.settle_error;
      switch (phase) {
        case 0:  // approach -> descend
          if (done && error < config_.start_error) {
            end_segment();
            if (!start_path(wp[1], config_.path_peak_speed)) res.failure = "path_refused";
            phase = 1;
          }
          break;
        case 1:  // descend -> close when settled
          if (done) {
            end_segment();
            if (settled || ++waited > config_.max_settle_steps) {
              s = 1;
              phase = 2;
              waited = 0;
            }
          }
          break;
        case 2: {  // closing: did it grasp?
          if (world_.gripper().closing()) break;
          const auto held = world_.gripper().held();
          if (!held || *held != object_) {
            res.failure = "missed_grasp";
            break;
          }
          res.grasp_step = res.steps;
          // Where the object sits in the hand (end-effector frame): the payload hint and the place correction.
          const Vec3 in_hand = ee.rotation.transpose() * (world_.rigid().center_of_mass(object_) - ee.translation);
          executor_.set_payload(config_.object_mass, in_hand);
          place.translation = t.place - place.rotation * in_hand + Vec3(0, 0, config_.place_clearance);
          carry.translation = place.translation + Vec3(0, 0, config_.carry_height);
          if (!start_path(carry, config_.path_peak_speed)) res.failure = "path_refused";
          phase = 3;
          break;
        }
        case 3:  // carry -> lower
          if (!held_object()) {
            res.failure = "dropped";
            break;
          }
          if (done && error < config_.start_error) {
            end_segment();
            if (!start_path(place, config_.lower_peak_speed)) res.failure = "path_refused";
            phase = 4;
          }
          break;
        case 4:  // lower -> open when settled
          if (!held_object()) {
            res.failure = "dropped";
            break;
          }
          // The table already carries the object (it touches the top): open now rather than press it in.
          if (world_.rigid().center_of_mass(object_).z() < top_ + half_height() + 0.002) {
            end_segment();
            s = 0;
            executor_.set_payload(0.0);
            phase = 5;
            waited = 0;
          } else if (done) {
            end_segment();
            if (settled || ++waited > config_.max_settle_steps) {
              s = 0;
              executor_.set_payload(0.0);
              phase = 5;
              waited = 0;
            }
          }
          break;
        case 5:  // opened: wait for the object to rest
        default: {
          res.release_step = res.release_step < 0 ? res.steps : res.release_step;
          const Vec3 v = world_.rigid().linear_velocity(object_), w = world_.rigid().angular_velocity(object_);
          rest = (v.norm() < 0.01 && w.norm() < 0.1 && !held_object()) ? rest + 1 : 0;
          if (rest >= config_.rest_steps) {
            evaluate(res);
            if (!res.failure.empty()) break;
            res.success = true;
          }
          break;
        }
      }
    }
    if (res.place_error == 0) evaluate_geometry(res);
    res.cpu_seconds = double(std::clock() - c0) / CLOCKS_PER_SEC;
    return res;
  }
  PickPlaceResult run(std::uint64_t seed) {
    return run(seed, [](int, int) {});
  }

  /// The object centre in the end-effector frame at the nominal grasp of task t (the payload
  /// offset a planner assumes before the grasp is measured).
  Vec3 nominal_in_hand(const PickPlaceTask& t) const {
    const Pose grasp = waypoints(t, Vec3::Zero())[1];
    return grasp.rotation.transpose() * (t.object - grasp.translation);
  }

  /// The waypoints of task t: pre-grasp, grasp, carry, place (tool-down end-effector poses);
  /// `in_hand` the object centre in the end-effector frame (zero: the grasp centre's nominal one).
  std::array<Pose, 4> waypoints(const PickPlaceTask& t, const Vec3& in_hand) const {
    const Vec3 grasp_center(t.object.x(), t.object.y(), top_ + config_.grasp_height);
    const Pose grasp = tool_down(grasp_center, t.gripper_yaw);
    Pose pre = grasp;
    pre.translation.z() += config_.pregrasp_height;
    // Nominal hand offset: the object centre grasp_height - half_height() below the grasp centre.
    const Vec3 nominal = in_hand.isZero() ? Vec3(0, 0, gripper_.grasp_center().z() + config_.grasp_height - half_height()) : in_hand;
    Pose place = grasp;
    place.translation = t.place - place.rotation * nominal + Vec3(0, 0, config_.place_clearance);
    Pose carry = place;
    carry.translation.z() += config_.carry_height;
    return {pre, grasp, carry, place};
  }

 private:
  static PickPlaceConfig validated(const PickPlaceConfig& c) {
    manisoft::detail::require_positive("PickPlaceConfig object_mass", c.object_mass);
    manisoft::detail::require_positive("PickPlaceConfig cube_half", c.cube_half);
    manisoft::detail::require_positive("PickPlaceConfig can_radius", c.can_radius);
    manisoft::detail::require_positive("PickPlaceConfig can_half_length", c.can_half_length);
    manisoft::detail::require_non_negative("PickPlaceConfig can_rolling_resistance", c.can_rolling_resistance);
    manisoft::detail::require_positive("PickPlaceConfig dt", c.dt);
    if (c.substeps < 1) manisoft::detail::fail("PickPlaceConfig substeps = ", c.substeps, " must be >= 1");
    if (c.max_steps < 1) manisoft::detail::fail("PickPlaceConfig max_steps = ", c.max_steps, " must be >= 1");
    manisoft::detail::require_non_negative("PickPlaceConfig rod_damping", c.rod_damping);
    manisoft::detail::require_positive("PickPlaceConfig path_peak_speed", c.path_peak_speed);
    manisoft::detail::require_positive("PickPlaceConfig lower_peak_speed", c.lower_peak_speed);
    if (c.min_segment_steps < 1) manisoft::detail::fail("PickPlaceConfig min_segment_steps = ", c.min_segment_steps, " must be >= 1");
    if (c.home_path_steps < 1) manisoft::detail::fail("PickPlaceConfig home_path_steps = ", c.home_path_steps, " must be >= 1");
    if (!c.home.allFinite()) manisoft::detail::fail("PickPlaceConfig home is not finite");
    return c;
  }

  world::ArmWorldSettings world_settings() const {
    world::ArmWorldSettings s;
    s.gripper = gripper_;
    s.substeps_per_control_step = config_.substeps;
    return s;
  }

  double control_dt() const { return config_.dt * config_.substeps; }
  Vec3 parking_spot() const { return Vec3(0.72, 0.42, 0.75 + half_height()); }
  /// Height of the object's centre above its support when it lies as drawn.
  double half_height() const { return config_.object == PickPlaceObject::can ? config_.can_radius : config_.cube_half; }
  /// A cube stands on a face; a can lies on its side, its axis (the cylinder's z) along (cos yaw, sin yaw, 0).
  Eigen::Quaterniond start_orientation(double yaw) const {
    Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    if (config_.object == PickPlaceObject::can) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));
    return q;
  }

  Pose ee_pose() const {
    const auto f = world_.soft().end_effector_frame();
    return Pose{f.rotation, f.position};
  }
  double max_node_speed_now() const { return world_.rod().state().velocities.rowwise().norm().maxCoeff(); }
  bool held_object() const {
    const auto h = world_.gripper().held();
    return h && *h == object_;
  }

  /// From the straight arm to the home pose: a tracked path, then held; saved as the episodes' start.
  void go_home() {
    const Pose home = tool_down(config_.home, 0.0);
    executor_.reset();
    // A straight SE(3) line from the straight arm asks for shapes beyond the actuation limits
    // (its midway torques are ~4x the limits): the reset uses the executor's cold shape ramp.
    const auto solved = executor_.set_target(home);
    if (!solved.within_limits) manisoft::detail::fail("PickPlaceRunner: the home pose is not held within the actuation limits (torque ratio ", solved.max_torque_ratio, ")");
    for (int i = 0; i < config_.home_path_steps + config_.home_settle_steps; ++i) {
      control::observe_arm(world_, home, observation_);
      executor_.act(observation_, torques_);
      world_.control_step(torques_, 0);
      ++home_steps_;
    }
    world_.soft().save(home_snapshot_);
    home_executor_ = executor_;
  }

  /// Success geometry at the end: horizontal distance to the place point and tilt.
  void evaluate_geometry(PickPlaceResult& res) const {
    const Vec3 c = world_.rigid().center_of_mass(object_);
    res.place_error = (c - res.task.place).head<2>().norm();
    const Eigen::Matrix3d r = world_.rigid().orientation(object_).toRotationMatrix();
    if (config_.object == PickPlaceObject::can) {
      res.tilt = std::asin(std::min(1.0, std::abs(r(2, 2))));  // the axis out of the horizontal
    } else {
      res.tilt = std::acos(std::min(1.0, r.row(2).cwiseAbs().maxCoeff()));
    }
  }
  void evaluate(PickPlaceResult& res) const {
    evaluate_geometry(res);
    const Vec3 c = world_.rigid().center_of_mass(object_);
    if (res.place_error > config_.success_distance || c.z() < top_) res.failure = "off_target";
    else if (res.tilt > config_.flat_angle) res.failure = "tilted";
  }

  PickPlaceConfig config_;
  interaction::ParallelGripperParameters gripper_{};
  rod::RodParameters<double> params_;
  rod::ArmModel<double> model_;
  World world_;
  Executor executor_;
  Executor home_executor_{executor_};
  Executor planner_{executor_};
  world::TableDesc table_;
  double top_ = 0.75;
  rigid::BodyId object_ = 0;
  control::Observation<double> observation_;
  Array3 torques_;
  World::Soft::Snapshot home_snapshot_;
  int home_steps_ = 0;
};

}  // namespace manisoft::env
