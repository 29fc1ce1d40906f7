// A tabletop pick and place on the task layer: one object (a cube, or a drinks can) at
// a random spot of the reachable band and a place point 15-25 cm away, run as an ALN episode
// (aln.hpp) in TaskEnv by the Expert. It measures the model executor as a trajectory tracker
// (paper section 3.4): steps, node speeds and how straight the end-effector's paths are.
//
//   const scene::AssetLibrary library(pick_place_catalog(PickPlaceObject::cube, 0.1));
//   TaskEnv env(library, pick_place_env_config());
//   Expert expert(env, pick_place_expert_config());
//   scene::SceneValidator validator(library);
//   const PickPlaceResult r = run_pick_place(env, expert, draw_pick_place(validator, expert, env, object, seed));
//
// The draw of a seed (std::mt19937_64 raw output, own uniform): the object's origin uniform in
// x in [0.30, 0.62], y in [-0.25, 0.25] on the table, yaw uniform; the place point 15-25 cm away in
// a uniform direction, in the same band; the goal pose is the object's at the place point with
// the same orientation. A draw is taken when the scene validator accepts it (every grasp and the
// goal reachable, the object at rest) and the expert finds a plan for it from home; otherwise
// the next draw of the same engine is tried.
// Success is ALN's predicate (position within 2 cm, orientation within 0.2 rad modulo the
// object's symmetry, released, at rest, held 10 control steps), within TaskEnv's horizon.
// Measured per episode: the fastest rod node at the end of any control step, and for every
// executor line (track_line) whose end-effector moved at least min_path_length, the end-effector's
// path over its straight displacement while the line ran (PickPlaceResult::max_path_ratio); the
// shape ramps the expert falls back on where a line is refused are counted apart.
#pragma once

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "manisoft/assets/catalog.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_validation.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task {

/// What is picked and placed: a Rubik's cube (5.7 cm) or a drinks can (r 3.3 cm, 12 cm), upright.
enum class PickPlaceObject { cube, can };

inline const char* pick_place_asset(PickPlaceObject o) { return o == PickPlaceObject::cube ? "rubiks_cube/00" : "can/00"; }

/// The object catalogue with the pick-and-place object's mass set to `mass` kg (its inertia
/// scaled with it: the same shape, uniformly denser), for an AssetLibrary.
inline std::vector<assets::Asset> pick_place_catalog(PickPlaceObject o, double mass) {
  manisoft::detail::require_positive("pick and place object mass", mass);
  std::vector<assets::Asset> objects = assets::object_catalog();
  for (auto& a : objects)
    if (a.id == pick_place_asset(o)) {
      a.inertia *= mass / a.mass;
      a.mass = mass;
    }
  return objects;
}

/// The expert's configuration for the pick and place: its lines planned at 0.9 m/s for the
/// end-effector and every node, with or without the object. The task expert plans at 1.5 m/s; the
/// tracker's bound here is 1.5 m/s for every node, and at the end of a line that turns the tool
/// the tip overshoots the planned speed by up to about 60%.
inline ExpertConfig pick_place_expert_config() {
  ExpertConfig c;
  c.paths.peak_speed = c.paths.node_speed = c.carry.peak_speed = c.carry.node_speed = 0.9;
  return c;
}
/// The task environment's configuration for the pick and place: the expert's shape ramps (its
/// fallback where a line is refused) keep every node's planned speed within the same 0.9 m/s.
inline TaskEnvConfig pick_place_env_config() {
  TaskEnvConfig c;
  c.executor.ramp_max_node_step = 0.9 * c.dt * c.substeps;
  return c;
}

struct PickPlaceDraw {
  scene::SceneSpec spec;
  Eigen::Vector3d object{0, 0, 0};  ///< object origin at the start
  double object_yaw = 0;            ///< rad
  Eigen::Vector3d place{0, 0, 0};   ///< where the object origin should end
  int draws = 0;                    ///< candidates drawn
};

struct PickPlaceResult {
  bool success = false;
  std::string failure;           ///< "" on success: TaskEnv's reason, or "expert: why it gave up"
  long steps = 0;                ///< control steps taken
  double cpu_seconds = 0;        ///< process CPU time of the episode (simulation, expert and executor)
  double max_node_speed = 0;     ///< m/s, any rod node at the end of any control step
  long fastest_step = 0;         ///< the control step of max_node_speed
  double max_path_ratio = 0;     ///< measured end-effector path / straight displacement, worst executor line
  int ramps = 0;                 ///< shape ramps the expert ran where a line was refused (not in max_path_ratio)
  double place_error = 0;        ///< m, horizontal, object origin to the place point at the end
  double tilt = 0;               ///< rad at the end: the object's orientation error to the goal's, modulo its symmetry
  long grasp_step = -1, release_step = -1;  ///< control steps of the first closing and of the first opening
};

/// The object's pose on the table: upright (the asset's z up), yawed, its origin at (x, y) and the
/// lowest point of its bounding box on the table top.
inline math::Pose<double> pick_place_pose(const assets::Asset& a, const Eigen::Vector2d& xy, double yaw, double table_top) {
  math::Pose<double> p;
  p.rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation = Eigen::Vector3d(xy.x(), xy.y(), table_top + a.bounding_half_extents.z() - a.bounding_center.z());
  return p;
}

/// The scene of `seed` (deterministic): see the header's comment. Refuses a seed with no
/// accepted draw in 1000.
inline PickPlaceDraw draw_pick_place(scene::SceneValidator& validator, Expert& expert, TaskEnv& env, PickPlaceObject o, std::uint64_t seed) {
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x91C4);
  auto uniform = [&rng](double lo, double hi) { return lo + (hi - lo) * (double(rng() >> 11) * 0x1.0p-53); };
  const double pi = std::numbers::pi;
  const assets::Asset& asset = env.library().get(pick_place_asset(o), "pick and place");
  const double top = scene::TableSpec{}.top_center.z();
  PickPlaceDraw d;
  d.spec.task = scene::Task::aln;
  d.spec.index = seed;
  d.spec.objects.resize(1);
  d.spec.objects[0].asset_id = asset.id;
  d.spec.goal.object = 0;
  d.spec.goal.symmetry = scene::asset_symmetry(asset);
  for (d.draws = 1; d.draws <= 1000; ++d.draws) {
    const Eigen::Vector2d xy(uniform(0.30, 0.62), uniform(-0.25, 0.25));
    d.object_yaw = uniform(-pi, pi);
    const double distance = uniform(0.15, 0.25), direction = uniform(-pi, pi);
    const Eigen::Vector2d goal = xy + distance * Eigen::Vector2d(std::cos(direction), std::sin(direction));
    if (goal.x() < 0.30 || goal.x() > 0.62 || std::abs(goal.y()) > 0.25) continue;
    d.spec.objects[0].pose = pick_place_pose(asset, xy, d.object_yaw, top);
    d.spec.goal.goal_pose = pick_place_pose(asset, goal, d.object_yaw, top);
    d.object = d.spec.objects[0].pose.translation;
    d.place = d.spec.goal.goal_pose.translation;
    if (!validator.check(d.spec).valid) continue;
    env.reset(d.spec);
    expert.reset();
    if (!env.done() && !expert.failure()) return d;
  }
  manisoft::detail::fail("pick and place: no scene accepted for seed ", seed, " in 1000 draws");
}

/// Runs the expert on `draw`'s scene to the end of the episode and measures it.
inline PickPlaceResult run_pick_place(TaskEnv& env, Expert& expert, const PickPlaceDraw& draw, double min_path_length = 0.02) {
  const std::clock_t c0 = std::clock();
  env.reset(draw.spec);
  expert.reset();
  PickPlaceResult r;
  TaskEnv::Array3 torques;
  int s = 0, last_s = 0;
  long last_path_step = std::numeric_limits<long>::max();
  bool path_open = false;
  double path_length = 0;
  Eigen::Vector3d path_start = Eigen::Vector3d::Zero(), last_ee = env.world().soft().end_effector_frame().position;
  auto close_path = [&] {
    const double straight = (last_ee - path_start).norm();
    if (path_open && straight >= min_path_length) r.max_path_ratio = std::max(r.max_path_ratio, path_length / straight);
    path_open = false;
  };
  while (!env.done()) {
    expert.act(torques, s);
    const auto& executor = expert.executor();
    if (executor.path_step() <= last_path_step) {  // the expert started a new line (or ramp) in this act()
      close_path();
      r.ramps += !executor.tracking();
      path_open = executor.tracking();
      path_length = 0;
      path_start = last_ee;
    }
    last_path_step = executor.path_step();
    if (s == 1 && last_s == 0 && r.grasp_step < 0) r.grasp_step = env.info().step;
    if (s == 0 && last_s == 1 && r.release_step < 0) r.release_step = env.info().step;
    last_s = s;
    env.step(torques, s);
    const Eigen::Vector3d ee = env.world().soft().end_effector_frame().position;
    if (path_open) path_length += (ee - last_ee).norm();
    last_ee = ee;
    if (path_open && executor.path_done()) close_path();
    const double fastest = env.world().rod().state().velocities.rowwise().norm().maxCoeff();
    if (fastest > r.max_node_speed) {
      r.max_node_speed = fastest;
      r.fastest_step = env.info().step;
    }
  }
  close_path();
  const auto& info = env.info();
  r.success = info.success;
  r.steps = info.step;
  if (!r.success) r.failure = expert.failure() ? "expert: " + std::string(*expert.failure()) : std::string(to_string(info.failure));
  const ObjectState& o = env.snapshot().objects[0];
  r.place_error = (o.pose.translation - draw.place).head<2>().norm();
  r.tilt = orientation_error(o.pose.rotation, draw.spec.goal.goal_pose.rotation, draw.spec.goal.symmetry);
  r.cpu_seconds = double(std::clock() - c0) / CLOCKS_PER_SEC;
  return r;
}

}  // namespace manisoft::task
