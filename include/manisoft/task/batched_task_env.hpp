// BatchedTaskEnv: B task environments (task_env.hpp) of one task and setting, stepped by one call
// over a persistent pool of threads (core/worker_pool.hpp), with the arms' state, rewards, flags
// and infos in batch arrays a binding hands to numpy without a copy: batched evaluation, data
// generation and learners of the state track; task/batched_task_images.hpp adds the camera images
// (a renderer per arm, drawn on its worker thread through the arm observer).
//
//   BatchedTaskEnv batch(B, threads, {scene::Task::aln, scene::Setting::clean});
//   batch.reset(indices);                     // arm i: the scene (task, setting, split, indices[i], seed)
//   batch.step(actions);                      // B flat actions of 3n + 1 (control/action_layout.hpp)
//   batch.rewards()[i], batch.terminated()[i], batch.object_poses() ...
//
// Tracks. The torque track (the default): an arm's action is its n x 3 element torques and S, one
// control step a step(). The end-effector track (Settings::ee_track set, task/ee_track.hpp): an
// arm's action is 7 values, the target position, the rotation vector from the home orientation and
// S (task::ee_action's layout; S >= 0.5 closes), commanded to the arm's own EndEffectorTrack, which
// then runs ee_track->action_repeat control steps (fewer when the episode ends) in one step();
// ee_command and control_steps say what the command did and how many control steps it ran.
//
// Layout. Every array is owned by the batch, contiguous, row-major with the arm as its leading
// dimension, allocated once and overwritten by every reset and step:
//   rod_nodes        B x (n + 1) x 3   m, lab frame
//   end_effector     B x 4 x 4         the end-effector frame (body to lab; last row 0 0 0 1)
//   gripper_pose     B x 4 x 4         the gripper body
//   gripper_width    B                 m between the fingers
//   gripper_state    B                 S the gripper is driven to (0 open, 1 closed)
//   object_poses     B x K x 4 x 4     K = Settings::max_objects: arm i's first object_count[i]
//                                      entries are its scene's objects, the others zero
//   object_count     B
//   rewards          B                 1 at the step of success, else 0
//   terminated       B                 success or a terminal failure in this step (StepInfo)
//   truncated        B                 the horizon was reached in this step
//   success          B                 the episode has succeeded
//   steps            B                 control steps of the current episode
//   failure          B                 FailureReason as an integer (0: none)
//   indices          B                 the scene index of each arm's current episode
//   ee_command       B                 the end-effector track's EeCommand of the step (unused on the torque track)
//   control_steps    B                 control steps the step ran (0 at a reset)
// Flags are std::uint8_t 0 / 1. The instruction of arm i's scene is instruction(i).
//
// Autoreset (Gymnasium 1.x NEXT_STEP): an arm whose episode ended in one step() is reset by the
// next step(): its action there is ignored (not even checked), its observation is the new
// episode's first, its reward 0, its flags and steps 0. The new episode's scene index is the
// ended one's plus B, so arms started at indices s, ..., s + B - 1 visit every index from s once.
// Scenes: each worker samples with its own scene::SceneSampler; a scene depends on its request
// only, so which worker samples it does not matter.
// Determinism: arms share nothing but the read-only asset library, so arm i's trajectory is
// bit-identical to a TaskEnv reset to the same scene and stepped alone with the same actions,
// whatever the thread count and the arm's position in the batch.
// Bad input (wrong sizes, a non-finite action of an arm that steps) is refused with InvalidInput
// naming the arm and the entry before any arm changes.
// Arm observer (set_observer): called on the worker thread that reset or stepped arm i, right after
// its arrays were written, so that per-worker work on the arm (a frame of its camera) runs in
// parallel as the physics does; its exceptions reach the caller of reset() or step().
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "manisoft/control/action_layout.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/core/worker_pool.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/ee_track.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task {

class BatchedTaskEnv {
 public:
  struct Settings {
    scene::Task task = scene::Task::coll;
    scene::Setting setting = scene::Setting::clean;
    scene::Split split = scene::Split::train;
    std::uint64_t seed = 0;  ///< the dataset seed of every scene draw
    int max_objects = 16;    ///< K of object_poses (a scene with more objects is refused, naming it)
    TaskEnvConfig env;
    std::optional<EeTrackConfig> ee_track;  ///< set: the end-effector track (actions of 7), else torques
  };
  using Action = control::FlatAction;

  BatchedTaskEnv(int batch_size, int threads, Settings settings) : settings_(std::move(settings)), pool_(threads) {
    if (batch_size < 1) manisoft::detail::fail("BatchedTaskEnv: batch_size = ", batch_size, " must be >= 1");
    if (settings_.max_objects < 1) manisoft::detail::fail("BatchedTaskEnv: max_objects = ", settings_.max_objects, " must be >= 1");
    samplers_.resize(std::size_t(pool_.threads()));
    arms_.resize(std::size_t(batch_size));
    tracks_.resize(std::size_t(batch_size));
    specs_.resize(std::size_t(batch_size));
    // every worker's sampler loads the asset library; the arms read the first one's
    for_each_part([&](int part) { samplers_[std::size_t(part)] = std::make_unique<scene::SceneSampler>(); });
    for_each_arm([&](int, std::size_t i) {
      arms_[i] = std::make_unique<TaskEnv>(samplers_[0]->library(), settings_.env);
      if (settings_.ee_track) tracks_[i] = std::make_unique<EndEffectorTrack>(*arms_[i], *settings_.ee_track);
    });
    n_ = arms_[0]->arm_model().rod.n_elements;
    torques_.assign(std::size_t(batch_size), TaskEnv::Array3::Zero(n_, 3));
    allocate(std::size_t(batch_size));
  }

  int batch_size() const { return int(arms_.size()); }
  int threads() const { return pool_.threads(); }
  int n_elements() const { return n_; }
  /// Entries of one arm's action: 3n + 1 on the torque track, 7 on the end-effector track.
  int action_size() const { return settings_.ee_track ? int(EeAction::RowsAtCompileTime) : Action::size(n_); }
  int max_objects() const { return settings_.max_objects; }
  const Settings& settings() const { return settings_; }
  /// Arm i's environment (its scene, world, conditions).
  const TaskEnv& arm(int i) const { return *arms_.at(std::size_t(i)); }
  /// The canonical instruction of arm i's current scene.
  const std::string& instruction(int i) const { return specs_.at(std::size_t(i)).instruction; }
  /// Arm i's current scene.
  const scene::SceneSpec& scene(int i) const { return specs_.at(std::size_t(i)); }

  /// observer(part, i, reset) after arm i's arrays were written by a reset (reset = true) or a step,
  /// on the worker thread `part` that ran it (see the header comment). Replaces any earlier one.
  using ArmObserver = std::function<void(int part, std::size_t arm, bool reset)>;
  void set_observer(ArmObserver observer) { observer_ = std::move(observer); }

  /// Calls f(part) once on each of the pool's threads (part 0: the caller's), e.g. to release what
  /// an observer keeps per worker thread on that thread.
  template <typename F>
  void for_each_part(F&& f) {
    auto job = [&f](int part, int) { f(part); };
    pool_.run(job, pool_.threads());
  }

  /// Starts a new episode on every arm, arm i on the scene of indices[i].
  void reset(std::span<const std::uint64_t> indices) {
    require_size("indices", indices.size());
    std::fill(do_reset_.begin(), do_reset_.end(), std::uint8_t(1));
    reset_marked(indices);
  }

  /// Starts a new episode on the arms with mask[i] != 0, arm i on the scene of indices[i] (the
  /// other indices are ignored); the other arms and their arrays are left as they are.
  void reset(std::span<const std::uint8_t> mask, std::span<const std::uint64_t> indices) {
    if (!started_) manisoft::detail::fail("BatchedTaskEnv::reset(mask, indices) called before reset(indices) started every arm");
    require_size("mask", mask.size());
    require_size("indices", indices.size());
    for (std::size_t i = 0; i < mask.size(); ++i) do_reset_[i] = mask[i] != 0;
    reset_marked(indices);
  }

  /// One control step of every arm (arms whose episode ended in the previous step reset instead).
  void step(std::span<const double> actions) {
    if (!started_) manisoft::detail::fail("BatchedTaskEnv::step called before reset");
    const std::size_t per_arm = std::size_t(action_size());
    if (actions.size() != arms_.size() * per_arm)
      manisoft::detail::fail("BatchedTaskEnv::step: actions hold ", actions.size(), " values, expected batch_size x ",
                             settings_.ee_track ? "7" : "(3n + 1)", " = ", arms_.size(), " x ", per_arm, " = ", arms_.size() * per_arm);
    for (std::size_t i = 0; i < arms_.size(); ++i) {
      if (pending_reset_[i]) continue;
      for (std::size_t k = 0; k < per_arm; ++k)
        if (!std::isfinite(actions[i * per_arm + k]))
          manisoft::detail::fail("BatchedTaskEnv::step: arm ", i, ": action entry ", k, " (",
                                 settings_.ee_track ? std::string(ee_entry_names[k]) : Action::describe(int(k), n_), ") = ",
                                 actions[i * per_arm + k], " is not finite");
    }
    for_each_arm([this, actions](int part, std::size_t i) { step_arm(part, i, actions); });
  }

  std::span<const double> rod_nodes() const { return rod_nodes_; }
  std::span<const double> end_effector() const { return end_effector_; }
  std::span<const double> gripper_pose() const { return gripper_pose_; }
  std::span<const double> gripper_width() const { return gripper_width_; }
  std::span<const std::int64_t> gripper_state() const { return gripper_state_; }
  std::span<const double> object_poses() const { return object_poses_; }
  std::span<const std::int64_t> object_count() const { return object_count_; }
  std::span<const double> rewards() const { return rewards_; }
  std::span<const std::uint8_t> terminated() const { return terminated_; }
  std::span<const std::uint8_t> truncated() const { return truncated_; }
  std::span<const std::uint8_t> success() const { return success_; }
  std::span<const std::int32_t> steps() const { return steps_; }
  std::span<const std::int32_t> failure() const { return failure_; }
  std::span<const std::uint64_t> indices() const { return indices_; }
  std::span<const std::int32_t> ee_command() const { return ee_command_; }
  std::span<const std::int32_t> control_steps() const { return control_steps_; }

 private:
  static constexpr const char* ee_entry_names[7] = {"x", "y", "z", "rx", "ry", "rz", "S"};

  void allocate(std::size_t b) {
    rod_nodes_.assign(b * std::size_t(n_ + 1) * 3, 0.0);
    end_effector_.assign(b * 16, 0.0);
    gripper_pose_.assign(b * 16, 0.0);
    gripper_width_.assign(b, 0.0);
    object_poses_.assign(b * std::size_t(settings_.max_objects) * 16, 0.0);
    rewards_.assign(b, 0.0);
    terminated_.assign(b, 0);
    truncated_.assign(b, 0);
    success_.assign(b, 0);
    pending_reset_.assign(b, 0);
    do_reset_.assign(b, 0);
    gripper_state_.assign(b, 0);
    object_count_.assign(b, 0);
    steps_.assign(b, 0);
    failure_.assign(b, 0);
    indices_.assign(b, 0);
    ee_command_.assign(b, 0);
    control_steps_.assign(b, 0);
  }

  void require_size(const char* what, std::size_t size) const {
    if (size != arms_.size())
      manisoft::detail::fail("BatchedTaskEnv::reset: ", what, " hold ", size, " values, expected batch_size = ", arms_.size());
  }

  std::size_t chunk_begin(int part, int parts) const { return arms_.size() * std::size_t(part) / std::size_t(parts); }

  /// Calls f(part, i) for every arm i over the pool: each thread (part) takes a contiguous chunk.
  template <typename F>
  void for_each_arm(F&& f) {
    auto job = [this, &f](int part, int parts) {
      for (std::size_t i = chunk_begin(part, parts); i < chunk_begin(part + 1, parts); ++i) f(part, i);
    };
    pool_.run(job, std::min(pool_.threads(), int(arms_.size())));
  }

  void reset_marked(std::span<const std::uint64_t> indices) {
    for_each_arm([this, indices](int part, std::size_t i) {
      if (do_reset_[i]) reset_arm(part, i, indices[i]);
    });
    started_ = true;
  }

  void reset_arm(int part, std::size_t i, std::uint64_t index) {
    scene::SampleRequest q;
    q.task = settings_.task;
    q.setting = settings_.setting;
    q.split = settings_.split;
    q.index = index;
    q.seed = settings_.seed;
    specs_[i] = samplers_[std::size_t(part)]->sample(q);
    if (int(specs_[i].objects.size()) > settings_.max_objects)
      manisoft::detail::fail("BatchedTaskEnv: scene ", index, " has ", specs_[i].objects.size(), " objects, more than max_objects = ",
                             settings_.max_objects);
    arms_[i]->reset(specs_[i]);
    if (tracks_[i]) tracks_[i]->reset();
    indices_[i] = index;
    ee_command_[i] = control_steps_[i] = 0;
    write(i);
    pending_reset_[i] = terminated_[i];  // a scene that is no task (scene_invalid) is replaced at the next step
    if (observer_) observer_(part, i, true);
  }

  void step_arm(int part, std::size_t i, std::span<const double> actions) {
    if (pending_reset_[i]) {
      reset_arm(part, i, indices_[i] + arms_.size());
      return;
    }
    const double* a = actions.data() + i * std::size_t(action_size());
    if (tracks_[i]) {
      const EeAction ee = Eigen::Map<const EeAction>(a);
      const int s = ee(6) >= 0.5 ? 1 : 0;
      ee_command_[i] = std::int32_t(tracks_[i]->command(ee_target_of(ee, arms_[i]->home_pose().rotation)));
      int taken = 0;
      for (; taken < tracks_[i]->config().action_repeat && !arms_[i]->done(); ++taken) {
        tracks_[i]->act(torques_[i]);
        arms_[i]->step(torques_[i], s);
      }
      control_steps_[i] = taken;
    } else {
      const int s = Action::unpack([a](int k) { return a[k]; }, torques_[i]);
      arms_[i]->step(torques_[i], s);
      control_steps_[i] = 1;
    }
    write(i);
    pending_reset_[i] = terminated_[i] || truncated_[i];
    if (observer_) observer_(part, i, false);
  }

  static void write_pose(double* out, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& position) {
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> m(out);
    m.setIdentity();
    m.topLeftCorner<3, 3>() = rotation;
    m.topRightCorner<3, 1>() = position;
  }

  /// Arm i's arrays from its environment.
  void write(std::size_t i) {
    const TaskEnv& env = *arms_[i];
    const auto& w = env.world();
    const auto& x = w.rod().state().positions;
    double* nodes = rod_nodes_.data() + i * std::size_t(n_ + 1) * 3;
    for (int k = 0; k <= n_; ++k)
      for (int c = 0; c < 3; ++c) nodes[k * 3 + c] = x(k, c);
    const auto frame = w.soft().end_effector_frame();
    write_pose(end_effector_.data() + i * 16, frame.rotation, frame.position);
    write_pose(gripper_pose_.data() + i * 16, w.rigid().orientation(w.gripper_body()).toRotationMatrix(), w.rigid().position(w.gripper_body()));
    gripper_width_[i] = w.gripper().finger_width();
    gripper_state_[i] = w.gripper().state();
    const std::size_t k_max = std::size_t(settings_.max_objects);
    double* poses = object_poses_.data() + i * k_max * 16;
    std::fill(poses, poses + k_max * 16, 0.0);
    const Snapshot snapshot = env.snapshot();  // the objects' poses in their asset frames, as the single environment's
    for (std::size_t k = 0; k < snapshot.objects.size(); ++k)
      write_pose(poses + k * 16, snapshot.objects[k].pose.rotation, snapshot.objects[k].pose.translation);
    object_count_[i] = std::int64_t(snapshot.objects.size());
    const StepInfo& info = env.info();
    rewards_[i] = info.success ? 1.0 : 0.0;  // the episode ends at its success: 1 at that step
    terminated_[i] = info.terminated;
    truncated_[i] = info.truncated;
    success_[i] = info.success;
    steps_[i] = std::int32_t(info.step);
    failure_[i] = std::int32_t(info.failure);
  }

  Settings settings_;
  WorkerPool pool_;
  std::vector<std::unique_ptr<scene::SceneSampler>> samplers_;
  std::vector<std::unique_ptr<TaskEnv>> arms_;
  std::vector<std::unique_ptr<EndEffectorTrack>> tracks_;  ///< the end-effector track's, else null
  std::vector<scene::SceneSpec> specs_;
  std::vector<TaskEnv::Array3> torques_;
  ArmObserver observer_;
  int n_ = 0;
  bool started_ = false;
  std::vector<double> rod_nodes_, end_effector_, gripper_pose_, gripper_width_, object_poses_, rewards_;
  std::vector<std::uint8_t> terminated_, truncated_, success_, pending_reset_, do_reset_;
  std::vector<std::int64_t> gripper_state_, object_count_;
  std::vector<std::int32_t> steps_, failure_, ee_command_, control_steps_;
  std::vector<std::uint64_t> indices_;
};

}  // namespace manisoft::task
