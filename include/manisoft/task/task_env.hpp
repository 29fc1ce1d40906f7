// The task environment of the ManiSoft tasks (paper sections 3.2 and 3.4): one scene
// (scene::SceneSpec) in the one arm world (world::ArmWorld on the tabletop), stepped one control
// step at a time through the actuation limits, with the task's success predicate (its named
// conditions, task/registry.hpp) judged after every step.
//
//   task::TaskEnv env(library);          // builds the arm and brings it home once
//   env.reset(spec);                     // the scene's bodies, the arm at home, step 0
//   while (!env.done()) env.step(torques, S);   // torques n x 3 (material frame), S 0 open / 1 closed
//
// Control step: 7 substeps of 2e-4 s (714 Hz), horizon 1500 control steps (the paper's T).
// Home: every episode starts from the same settled arm, tool-down with the gripper's grasp centre
// at `home` (high above the reachable band, so it is clear of every scene's objects), reached once
// from the straight arm by the model executor's shape ramp and then held; the arm's state is
// saved and restored at each reset (those steps are not the episode's).
// Success: the predicate holds (released and at rest included) for `hold_steps` consecutive
// control steps; the episode ends at the first such step (success once) and `success_at_end()`
// says whether it still held at the last step (ManiSkill reports both).
// Failure reasons (FailureReason): scene_invalid (the goal holds already at reset, as far as
// positions tell: no task; the episode ends before its first step), diverged (the step was refused: the world is as before it, the
// episode ends), object_off_table (a scene object left the table top: ends the episode),
// arm_hit_obstacle (the rod or the gripper touched an obstacle at some step; the episode goes on,
// the reason is reported if it does not succeed), object_dropped (a held object slipped or was
// released away from the goal and the episode timed out), timeout. The first three end the
// episode (StepInfo::terminated), the others are reported when the horizon ends it
// (StepInfo::truncated), as Gymnasium's terminated / truncated.
// conditions() names which parts of the predicate held at the last step: a failed episode's
// explanation.
// No heap allocation in step() once reset() has sized everything.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/control/tool_down.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/rod/cosserat_rod.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/scene/scene_world.hpp"
#include "manisoft/task/registry.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::task {

struct TaskEnvConfig {
  double dt = 2e-4;          ///< s, substep
  int substeps = 7;          ///< per control step (714 Hz)
  int horizon = 1500;        ///< control steps (the paper's T)
  double rod_damping = 0.1;  ///< analytical linear damping of the simulated rod
  Eigen::Vector3d home{0.50, 0.0, 0.88};  ///< grasp centre of the home pose (tool down, yaw 0), m
  int home_path_steps = 900;              ///< control steps of the straight arm's ramp home
  int home_settle_steps = 300;            ///< then held
  int hold_steps = 10;                    ///< control steps the predicate must hold for success
  int observe_stride = 2;                 ///< every this many nodes in the executor's observation
  /// s: an island of bodies slower than the rigid world's sleep speeds (5 mm/s, 0.05 rad/s) for
  /// this long sleeps (rigid::RigidWorldSettings::time_to_sleep, whose default 0.5 s is a quarter
  /// of an episode: a nested stack stays in the contact solve that long). A sleeping body is at
  /// rest in the predicates' sense too: it was slower than half their limits all that time.
  double time_to_sleep = 0.1;
  Tolerances tolerances{};
  /// The executor the expert (and any model-based policy) uses in the task world: the reach
  /// environment's defaults with twice its node velocity feedback (kd 70 /s): with a held object
  /// and fast lines, the reach environment's gain leaves the arm swaying after every path, which
  /// costs the expert's settling waits their time and sets objects down swinging.
  control::ModelExecutorSettings<double> executor = task_executor_settings();

  static control::ModelExecutorSettings<double> task_executor_settings() {
    control::ModelExecutorSettings<double> s;
    s.damping_gain = 70;
    return s;
  }
};

/// What one control step reports.
struct StepInfo {
  long step = 0;         ///< control steps taken in this episode
  bool success = false;  ///< reached at this step or before
  bool done = false;     ///< success, horizon or a terminal failure
  FailureReason failure = FailureReason::none;  ///< set once done without success
  int clamped = 0;       ///< torque entries clamped to the actuation limits this step
  bool terminated = false;  ///< done by success or a terminal failure (diverged, object_off_table, scene_invalid)
  bool truncated = false;   ///< done by the horizon without success
};

/// Whether a failure ends the episode where it happens (the others are reported at the horizon).
inline bool is_terminal(FailureReason reason) {
  return reason == FailureReason::diverged || reason == FailureReason::object_off_table || reason == FailureReason::scene_invalid;
}

class TaskEnv {
 public:
  /// Whether a contact manifold has a point closer than contact_margin (what the predicates and
  /// the expert count as touching).
  static bool touching(const contact::ContactManifold& m) {
    for (int k = 0; k < m.count; ++k)
      if (m.points[static_cast<std::size_t>(k)].separation <= contact_margin) return true;
    return false;
  }
  using Rod = rod::CosseratRod<double, rod::damping::AnalyticalLinear, rod::bc::ClampedBase, rod::integrator::PositionVerlet,
                               rod::forcing::Gravity, rod::forcing::ElementTorques>;
  using World = world::ArmWorld<Rod>;
  using Pose = math::Pose<double>;
  using Vec3 = Eigen::Vector3d;
  using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
  using Executor = control::ModelExecutor<double>;

  explicit TaskEnv(const scene::AssetLibrary& library, TaskEnvConfig config = {})
      : library_(&library), config_(validated(config)), params_(world::tabletop_arm_parameters()),
        model_(rod::make_arm_model(params_, gripper_.mass)), executor_(model_, world_settings().limits, config_.executor) {
    go_home();
  }

  // ---- episode
  /// Builds the scene's bodies around the arm at home; step 0. A spec whose table geometry or
  /// mount differs from the world's is refused (only its looks may vary).
  void reset(const scene::SceneSpec& spec) {
    const world::TableDesc t = spec.table.desc(), home_table = scene::TableSpec{}.desc();
    if ((t.top_center - home_table.top_center).norm() > 1e-12 || t.half_x != home_table.half_x || t.half_y != home_table.half_y ||
        t.thickness != home_table.thickness)
      manisoft::detail::fail("TaskEnv::reset: the scene's table (top centre ", t.top_center.transpose(), ", half extents ", t.half_x, " x ", t.half_y,
                             ") differs from the world's (", home_table.top_center.transpose(), ", ", home_table.half_x, " x ", home_table.half_y, ")");
    if (static_cast<int>(spec.objects.size()) > max_objects)
      manisoft::detail::fail("TaskEnv::reset: ", spec.objects.size(), " objects, at most ", max_objects);
    spec_ = spec;
    world_.reset();
    world_.emplace(make_rod(), world_settings());
    World& w = *world_;
    w.add_table(t);
    w.soft().restore(home_snapshot_);  // the arm, the gripper, the table and the floor
    bodies_ = scene::populate_objects(w, spec_, *library_);
    bodies_.table = w.table();
    object_of_body_.assign(w.rigid().body_count(), -1);
    obstacle_body_.assign(w.rigid().body_count(), 0);
    for (std::size_t i = 0; i < bodies_.objects.size(); ++i) object_of_body_[bodies_.objects[i]] = static_cast<int>(i);
    for (const auto b : bodies_.obstacles) obstacle_body_[b] = 1;
    states_.assign(spec_.objects.size(), ObjectState{});
    goal_ = visit_task(spec_.task, [this]<TaskType T>(T) { return GoalVariant(T::goal(spec_, *library_)); });
    tracker_ = SuccessTracker(config_.hold_steps);
    info_ = StepInfo{};
    touched_obstacle_ = false;
    dropped_ = false;
    last_event_step_ = 0;
    update_states();
    predicate();
    // A goal that holds before any action is no task: the scene is invalid (the episode ends).
    const bool met = std::visit([this](const auto& g) { return task_of<decltype(g)>::holds_at_start(conditions_); }, goal_);
    if (met) finish(FailureReason::scene_invalid);
  }

  /// One control step: element torques (n x 3, material frame; clamped to the actuation limits)
  /// and gripper state S (0 open, 1 closed). Non-finite or ill-shaped input is refused naming the
  /// entry before anything changes; stepping a finished episode is refused.
  template <typename Matrix>
  const StepInfo& step(const Matrix& torques, int s) {
    if (!world_) manisoft::detail::fail("TaskEnv::step: call reset() first");
    if (info_.done) manisoft::detail::fail("TaskEnv::step: the episode is over (step ", info_.step, "); call reset()");
    World& w = *world_;
    try {
      info_.clamped = w.control_step(torques, s, [this] { note_obstacle_contacts(); });
    } catch (const Diverged&) {
      return finish(FailureReason::diverged);
    }
    ++info_.step;
    for (const auto& e : w.events())
      if (e.step > last_event_step_ && e.kind == world::WorldEvent::Kind::slipped) dropped_ = true;
    last_event_step_ = w.step_count();
    update_states();
    if (tracker_.update(info_.step, predicate())) {
      info_.success = true;
      info_.done = true;
      info_.terminated = true;
      return info_;
    }
    for (const auto b : bodies_.objects)
      if (w.is_off_table(b)) return finish(FailureReason::object_off_table);
    if (info_.step >= config_.horizon) {
      return finish(touched_obstacle_ ? FailureReason::arm_hit_obstacle : dropped_ ? FailureReason::object_dropped : FailureReason::timeout);
    }
    return info_;
  }

  // ---- state
  const StepInfo& info() const { return info_; }
  /// The predicate's named conditions at the last step (or at reset): which held, which did not.
  const Conditions& conditions() const { return conditions_; }
  bool done() const { return info_.done; }
  /// Whether the predicate held at the last step (ManiSkill's "success at end").
  bool success_at_end() const { return tracker_.holds_now(); }
  bool touched_obstacle() const { return touched_obstacle_; }
  /// The predicates' view of the current step (objects as in the spec).
  Snapshot snapshot() const {
    return Snapshot{std::span<const ObjectState>(states_.data(), states_.size()), world_ ? world_->gripper().state() == 0 : true};
  }
  const scene::SceneSpec& spec() const { return spec_; }
  const scene::SceneBodies& bodies() const { return bodies_; }
  const World& world() const {
    if (!world_) manisoft::detail::fail("TaskEnv::world: call reset() first");
    return *world_;
  }
  const scene::AssetLibrary& library() const { return *library_; }
  const TaskEnvConfig& config() const { return config_; }
  /// The model executor that brought the arm home (its internal state matches the home arm): an
  /// expert starts each episode from a copy.
  const Executor& home_executor() const { return home_executor_; }
  /// The home pose (end-effector frame) and the tool-down pose with grasp centre `c`, yaw `yaw`.
  Pose home_pose() const { return tool_down(config_.home, 0.0); }
  Pose tool_down(const Vec3& grasp_center, double yaw) const { return control::tool_down_pose(grasp_center, yaw, gripper_.grasp_center()); }
  const interaction::ParallelGripperParameters& gripper_parameters() const { return gripper_; }
  const rod::ArmModel<double>& arm_model() const { return model_; }
  double control_dt() const { return config_.dt * config_.substeps; }
  /// Control steps of the reset from the straight arm to home (once, not part of episodes).
  int home_steps() const { return config_.home_path_steps + config_.home_settle_steps; }

 private:
  static TaskEnvConfig validated(const TaskEnvConfig& c) {
    manisoft::detail::require_positive("TaskEnvConfig dt", c.dt);
    if (c.substeps < 1) manisoft::detail::fail("TaskEnvConfig substeps = ", c.substeps, " must be >= 1");
    if (c.horizon < 1) manisoft::detail::fail("TaskEnvConfig horizon = ", c.horizon, " must be >= 1");
    if (c.hold_steps < 1) manisoft::detail::fail("TaskEnvConfig hold_steps = ", c.hold_steps, " must be >= 1");
    if (c.home_path_steps < 1) manisoft::detail::fail("TaskEnvConfig home_path_steps = ", c.home_path_steps, " must be >= 1");
    manisoft::detail::require_non_negative("TaskEnvConfig rod_damping", c.rod_damping);
    manisoft::detail::require_positive("TaskEnvConfig time_to_sleep", c.time_to_sleep);
    if (!c.home.allFinite()) manisoft::detail::fail("TaskEnvConfig home is not finite");
    return c;
  }
  world::ArmWorldSettings world_settings() const {
    world::ArmWorldSettings s;
    s.gripper = gripper_;
    s.substeps_per_control_step = config_.substeps;
    s.rigid.time_to_sleep = config_.time_to_sleep;
    return s;
  }
  Rod make_rod() const { return Rod(params_, config_.dt, rod::damping::AnalyticalLinear<double>(config_.rod_damping)); }

  /// From the straight arm to home in a world with only the table: saved as every episode's start.
  void go_home() {
    world_.emplace(make_rod(), world_settings());
    world_->add_table(scene::TableSpec{}.desc());
    const Pose home = home_pose();
    const auto solved = executor_.set_target(home);
    if (!solved.within_limits)
      manisoft::detail::fail("TaskEnv: the home pose (grasp centre ", config_.home.transpose(), ") is not held within the actuation limits (torque ratio ",
                             solved.max_torque_ratio, ")");
    auto observation = control::make_arm_observation<double>(params_.n_elements, config_.observe_stride);
    Array3 torques = Array3::Zero(params_.n_elements, 3);
    for (int i = 0; i < home_steps(); ++i) {
      control::observe_arm(*world_, home, observation);
      executor_.act(observation, torques);
      world_->control_step(torques, 0);
    }
    world_->soft().save(home_snapshot_);
    home_executor_ = executor_;
    world_.reset();
  }

  using GoalVariant = std::variant<Coll::Goal, Aln::Goal, Stk::Goal, Arr::Goal, Ovr::Goal>;
  /// The task type whose Goal `G` is.
  template <typename G>
  using task_of = typename std::decay_t<G>::Task;

  /// Evaluates the task's conditions at the current step; true when all hold.
  bool predicate() {
    conditions_ = std::visit([this](const auto& g) { return task_of<decltype(g)>::evaluate(snapshot(), g, config_.tolerances); }, goal_);
    return conditions_.all();
  }

  void update_states() {
    const World& w = *world_;
    const auto& rigid = w.rigid();
    const auto held = w.gripper().held();
    for (std::size_t i = 0; i < states_.size(); ++i) {
      const rigid::BodyId b = bodies_.objects[i];
      ObjectState& o = states_[i];
      o.pose.rotation = rigid.orientation(b).toRotationMatrix();
      o.pose.translation = rigid.position(b);
      o.center_of_mass = rigid.center_of_mass(b);
      o.linear_velocity = rigid.linear_velocity(b);
      o.angular_velocity = rigid.angular_velocity(b);
      o.touches_table = false;
      o.touching = 0;
      o.held = held && *held == b;
    }
    for (const auto& m : rigid.manifolds()) {
      if (!touching(m)) continue;
      const int a = object_of_body_[m.body_a], b = object_of_body_[m.body_b];
      if (a >= 0 && b >= 0) {
        states_[static_cast<std::size_t>(a)].touching |= std::uint64_t(1) << b;
        states_[static_cast<std::size_t>(b)].touching |= std::uint64_t(1) << a;
      }
      if (a >= 0 && m.body_b == bodies_.table) states_[static_cast<std::size_t>(a)].touches_table = true;
      if (b >= 0 && m.body_a == bodies_.table) states_[static_cast<std::size_t>(b)].touches_table = true;
    }
  }
  /// After each substep: did the rod or the gripper touch an obstacle?
  void note_obstacle_contacts() {
    if (touched_obstacle_) return;
    const World& w = *world_;
    for (const auto& c : w.rod_contact().contacts())
      if (c.separation <= 0 && obstacle_body_[c.body]) touched_obstacle_ = true;
    const rigid::BodyId g = w.gripper_body();
    for (const auto& m : w.rigid().manifolds()) {
      if (m.count == 0 || (m.body_a != g && m.body_b != g)) continue;
      const rigid::BodyId other = m.body_a == g ? m.body_b : m.body_a;
      if (obstacle_body_[other]) touched_obstacle_ = true;
    }
  }
  const StepInfo& finish(FailureReason reason) {
    info_.done = true;
    info_.failure = reason;
    info_.terminated = is_terminal(reason);
    info_.truncated = !info_.terminated;
    return info_;
  }

  static constexpr double contact_margin = 1e-3;  ///< m: closer than this counts as touching

  const scene::AssetLibrary* library_;
  TaskEnvConfig config_;
  interaction::ParallelGripperParameters gripper_{};
  rod::RodParameters<double> params_;
  rod::ArmModel<double> model_;
  Executor executor_;
  Executor home_executor_{executor_};
  std::optional<World> world_;
  World::Soft::Snapshot home_snapshot_;
  scene::SceneSpec spec_;
  scene::SceneBodies bodies_;
  std::vector<int> object_of_body_;
  std::vector<char> obstacle_body_;
  std::vector<ObjectState> states_;
  GoalVariant goal_;
  Conditions conditions_;
  SuccessTracker tracker_{1};
  StepInfo info_;
  bool touched_obstacle_ = false, dropped_ = false;
  long last_event_step_ = 0;
};

/// Refuses a scene that is no task, after `env.reset(spec)`: its goal held before any step (the
/// episode ended as scene_invalid). `where` names the scene's file or source in the message.
inline void require_a_task(const TaskEnv& env, std::string_view where) {
  if (env.info().failure == FailureReason::scene_invalid)
    ::manisoft::detail::fail(where, ": the goal already holds before any step (", env.conditions().met(),
                             "): the scene is no task");
}

}  // namespace manisoft::task
