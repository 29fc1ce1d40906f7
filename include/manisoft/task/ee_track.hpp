// The end-effector track: an action mode in which a policy commands a target pose of the end
// effector (the rod tip's frame, in the world) and the gripper state S, and the model executor
// tracks it at the control rate (paper section 3.4: the executor between the planner and the
// torques, offered to policies; ManiSkill's and robosuite's end-effector pose controllers are the
// rigid-arm equivalent).
//
//   task::EndEffectorTrack track(env);          // env: a task::TaskEnv
//   env.reset(spec);  track.reset();
//   while (!env.done()) {
//     track.command(target);                    // every EeTrackConfig::action_repeat control steps
//     for (int k = 0; k < K && !env.done(); ++k) { track.act(torques); env.step(torques, S); }
//   }
//
// A target further than min_change from the current one starts a straight line from the
// executor's present target (ModelExecutor::track_line), timed as the expert times its lines
// (timed_line_steps: paths.peak_speed with the gripper empty; carry.peak_speed holding, its peak
// acceleration within carry.grip_share of what the grip holds; every rod node within the node
// speed). A line the executor refuses is replaced by its shape ramp to the target's cold inverse
// statics solution (paths.ramp_fallback); a target with neither is refused and the arm keeps its
// previous one. While the gripper holds an object the executor carries the object's mass where it
// sits in the hand (set_payload); while the gripper touches anything else its stiffness estimate
// is frozen (freeze_estimate), as the expert's is in its contact phases.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <optional>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/math/so3.hpp"
#include "manisoft/task/expert_checks.hpp"
#include "manisoft/task/expert_config.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task {

struct EeTrackConfig {
  int action_repeat = 36;       ///< control steps per command (20 Hz at the tasks' 714 Hz control rate)
  ExpertConfig::Paths paths{};  ///< line timing with the gripper empty, node speed, ramp fallback
  ExpertConfig::Carry carry{};  ///< line timing while an object is held
  double min_change = 1e-3;     ///< m, and rad: a target nearer the current one starts no new line

  /// Refuses a value out of its range, naming it.
  void validate() const {
    if (action_repeat < 1) manisoft::detail::fail("EeTrackConfig action_repeat = ", action_repeat, " must be at least 1");
    if (!(min_change >= 0 && std::isfinite(min_change))) manisoft::detail::fail("EeTrackConfig min_change = ", min_change, " must be finite and >= 0");
    ExpertConfig c;
    c.paths = paths;
    c.carry = carry;
    c.validate();
  }
};

/// An end-effector action as 7 numbers: the target position (m, world), the orientation as a
/// rotation vector r (rad, world frame) from the home (tool-down) orientation, R = exp([r]x)
/// R_home, and S. Relative to the home orientation the tasks' rotations (yaw, small tilts) are
/// short vectors, far from the rotation vector's branch cut at pi, where a tool-down pose sits in
/// absolute terms.
using EeAction = Eigen::Matrix<double, 7, 1>;

inline EeAction ee_action(const math::Pose<double>& target, int s, const Eigen::Matrix3d& home_rotation) {
  EeAction a;
  a.head<3>() = target.translation;
  a.segment<3>(3) = math::so3::log(Eigen::Matrix3d(target.rotation * home_rotation.transpose()));
  a(6) = s;
  return a;
}

/// The target pose of an action (its S is a(6)).
inline math::Pose<double> ee_target_of(const EeAction& a, const Eigen::Matrix3d& home_rotation) {
  return {math::so3::exp(Eigen::Vector3d(a.segment<3>(3))) * home_rotation, a.head<3>()};
}

/// What a command did.
enum class EeCommand {
  kept,     ///< within min_change of the current target: nothing changed
  line,     ///< a straight line to the target started
  ramp,     ///< the line was refused: a shape ramp to the target started
  refused,  ///< neither: the previous target is kept
};

inline const char* to_string(EeCommand c) {
  switch (c) {
    case EeCommand::kept: return "kept";
    case EeCommand::line: return "line";
    case EeCommand::ramp: return "ramp";
    case EeCommand::refused: return "refused";
  }
  return "?";
}

class EndEffectorTrack {
 public:
  using Pose = math::Pose<double>;
  using Array3 = TaskEnv::Array3;
  using Executor = TaskEnv::Executor;

  explicit EndEffectorTrack(const TaskEnv& env, EeTrackConfig config = {})
      : env_(&env), config_((config.validate(), config)), executor_(env.home_executor()), planner_(env.home_executor()) {
    observation_ = control::make_arm_observation<double>(env.arm_model().rod.n_elements, env.config().observe_stride);
  }

  /// Starts the episode of the env's current scene (call after env.reset()): the home target.
  void reset() {
    executor_ = env_->home_executor();
    target_ = env_->home_pose();
    held_.reset();
  }

  /// Tracks `target` from now on (see the header comment). A non-finite target or a rotation
  /// that is not orthonormal is refused with an error, nothing changed.
  EeCommand command(const Pose& target) {
    if (!target.is_finite()) manisoft::detail::fail("EndEffectorTrack: the target pose is not finite");
    if ((target.rotation.transpose() * target.rotation - Eigen::Matrix3d::Identity()).norm() > 1e-6 || target.rotation.determinant() < 0)
      manisoft::detail::fail("EndEffectorTrack: the target's rotation is not a rotation matrix");
    const double moved = (target.translation - target_.translation).norm();
    const double turned = math::so3::log(Eigen::Matrix3d(target_.rotation.transpose() * target.rotation)).norm();
    if (moved <= config_.min_change && turned <= config_.min_change) return EeCommand::kept;
    update_payload();
    const bool loaded = held_.has_value();
    const double distance = (target.translation - executor_.statics().desired_tip_pose().translation).norm();
    const double peak = loaded ? config_.carry.peak_speed : config_.paths.peak_speed;
    double max_accel = 0;
    if (loaded && config_.carry.grip_share > 0) max_accel = config_.carry.grip_share * env_->gripper_parameters().max_hold_force / held_mass_;
    const int steps = detail::timed_line_steps(config_.paths, env_->control_dt(), distance, peak, max_accel);
    const double node_step = (loaded ? config_.carry.node_speed : config_.paths.node_speed) * env_->control_dt();
    if (executor_.track_line(target, steps, node_step, config_.paths.cruise).accepted) {
      target_ = target;
      return EeCommand::line;
    }
    if (!config_.paths.ramp_fallback) return EeCommand::refused;
    planner_ = executor_;
    if (!planner_.set_target(target).within_limits) return EeCommand::refused;
    executor_.set_target(target);
    target_ = target;
    return EeCommand::ramp;
  }

  /// The torques of the next control step (call once per env.step()).
  void act(Array3& torques) {
    const auto& w = env_->world();
    update_payload();
    executor_.freeze_estimate(gripper_touches_other());
    control::observe_arm(w, target_, observation_);
    executor_.act(observation_, torques);
  }

  /// The pose tracked now (the home pose after reset()).
  const Pose& target() const { return target_; }
  const Executor& executor() const { return executor_; }
  const EeTrackConfig& config() const { return config_; }

 private:
  /// Tells the executor what the gripper holds when that changed: the held object's mass at
  /// its centre of mass in the end-effector frame, or nothing.
  void update_payload() {
    const auto& w = env_->world();
    const std::optional<rigid::BodyId> held = w.gripper().held();
    if (held == held_) return;
    held_ = held;
    if (!held) {
      executor_.set_payload(0.0);
      return;
    }
    const auto& bodies = env_->bodies().objects;
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      if (bodies[k] != *held) continue;
      const auto& a = env_->library().get(env_->spec().objects[k].asset_id, "held object");
      const auto ee = w.soft().end_effector_frame();
      const Pose object = env_->snapshot().objects[k].pose;
      held_mass_ = a.mass;
      executor_.set_payload(a.mass, ee.rotation.transpose() * (object.act(a.center_of_mass) - ee.position));
      return;
    }
  }

  /// Whether the gripper touches anything but the object it holds.
  bool gripper_touches_other() const {
    const auto& w = env_->world();
    const rigid::BodyId g = w.gripper_body();
    for (const auto& m : w.rigid().manifolds()) {
      if (m.body_a != g && m.body_b != g) continue;
      const rigid::BodyId other = m.body_a == g ? m.body_b : m.body_a;
      if ((!held_ || other != *held_) && TaskEnv::touching(m)) return true;
    }
    return false;
  }

  const TaskEnv* env_;
  EeTrackConfig config_;
  Executor executor_, planner_;
  control::Observation<double> observation_;
  Pose target_;
  std::optional<rigid::BodyId> held_;
  double held_mass_ = 1;
};

}  // namespace manisoft::task
