// Recording a task episode into a dataset::Episode and replaying it (the paper's
// scene-trajectory pairs, section 3.5). Per control step, before its action:
//   actions           the element torques (n x 3, row by row) then S: what TaskEnv::step received
//   states            rod node positions ((n+1) x 3), every object's pose (position, quaternion
//                     w x y z), the finger width and S: enough to check a replay bit for bit (the
//                     episode itself replays exactly from the scene JSON and the actions: TaskEnv is
//                     deterministic) and to render any frame later (render_dataset)
//   obs/eef_pose      the end-effector frame (position, quaternion w x y z)
//   obs/gripper       finger width (m), S
//   obs/rod_centerline (n+1) x 3 node positions
//   obs/rod_directors n x 9: element k's directors, column 3 i + j = Q_k(i, j) (rows of Q_k are
//                     d1, d2, d3 in world coordinates; d3 is the element's tangent)
//   obs/object_poses  7 per object
//   obs/ee_target     the end-effector target the actions track (the expert's: the end of its
//                     current line or ramp) as the end-effector track's action (task::ee_action:
//                     position, rotation vector from the home orientation, S): one dataset trains
//                     the torque track (actions) and the end-effector track (obs/ee_target)
//   obs/ee_waypoint   which target it is: 0 at the first step, one more each time it changes
//   rewards           1 at the step the task succeeded, else 0; dones 1 at the last step
// Attributes: task, setting, split, scene (JSON), instruction, instructions_seen and
// instructions_unseen (JSON arrays), failure; numbers success, steps, seed, scene_index, redraws.
// Deterministic and allocation-free per step once reserved (the recorder's matrices grow by rows
// reserved for the horizon).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "manisoft/control/action_layout.hpp"
#include "manisoft/dataset/episode.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/task/ee_track.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::dataset {

/// Columns of the state vector of an episode with `n_elements` rod elements and `objects` objects.
inline int state_columns(int n_elements, int objects) { return 3 * (n_elements + 1) + 7 * objects + 2; }

/// The state vector of `env` now (see the header comment), into `row` (state_columns entries).
template <typename Row>
void read_state(const task::TaskEnv& env, Row&& row) {
  const auto& w = env.world();
  const auto& x = w.rod().state().positions;
  int c = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (int k = 0; k < 3; ++k) row(c++) = x(i, k);
  for (const auto b : env.bodies().objects) {
    const Eigen::Vector3d p = w.rigid().position(b);
    const Eigen::Quaterniond q = w.rigid().orientation(b);
    row(c++) = p.x(), row(c++) = p.y(), row(c++) = p.z();
    row(c++) = q.w(), row(c++) = q.x(), row(c++) = q.y(), row(c++) = q.z();
  }
  row(c++) = w.gripper().finger_width();
  row(c++) = w.gripper().state();
}

/// Records the steps of one episode of `env` (after its reset): call step() with each action just
/// before TaskEnv::step, then finish().
class EpisodeRecorder {
 public:
  explicit EpisodeRecorder(const task::TaskEnv& env) : env_(&env) {
    const int n = env.arm_model().rod.n_elements;
    const int objects = static_cast<int>(env.spec().objects.size());
    const long t = env.config().horizon;
    e_.actions.resize(t, control::FlatAction::size(n));
    e_.states.resize(t, state_columns(n, objects));
    eef_.resize(t, 7);
    gripper_.resize(t, 2);
    rod_.resize(t, 3 * (n + 1));
    directors_.resize(t, 9 * n);
    objects_.resize(t, 7 * objects);
    target_.resize(t, 7);
    waypoint_.resize(t, 1);
  }

  /// Records the state before the action (torques n x 3, S) about to be stepped, and the
  /// end-effector target those torques track.
  template <typename Matrix>
  void step(const Matrix& torques, int s, const math::Pose<double>& ee_target) {
    if (rows_ >= e_.actions.rows()) manisoft::detail::fail("EpisodeRecorder: more steps than the horizon (", e_.actions.rows(), ")");
    const long r = rows_++;
    const task::EeAction a = task::ee_action(ee_target, s, env_->home_pose().rotation);
    target_.row(r) = a.transpose();
    const bool moved = r > 0 && (ee_target.translation != last_target_.translation || ee_target.rotation != last_target_.rotation);
    waypoint_(r, 0) = r == 0 ? 0.0 : waypoint_(r - 1, 0) + (moved ? 1.0 : 0.0);
    last_target_ = ee_target;
    control::FlatAction::pack(torques, s, e_.actions.row(r));
    read_state(*env_, e_.states.row(r));
    const auto f = env_->world().soft().end_effector_frame();
    const Eigen::Quaterniond q(f.rotation);
    eef_.row(r) << f.position.x(), f.position.y(), f.position.z(), q.w(), q.x(), q.y(), q.z();
    const int nr = static_cast<int>(rod_.cols()), no = static_cast<int>(objects_.cols());
    rod_.row(r) = e_.states.row(r).head(nr);
    objects_.row(r) = e_.states.row(r).segment(nr, no);
    gripper_.row(r) = e_.states.row(r).tail(2);
    const auto& directors = env_->world().rod().state().directors;
    for (Eigen::Index k = 0; k < directors.rows(); ++k) directors_.row(r).segment<9>(9 * k) = directors.row(k);
  }

  /// The episode (`index`: demo_<index>) once TaskEnv is done; `seed`, `redraws` and the scene's
  /// own fields go to the attributes.
  Episode finish(long index, std::uint64_t seed, int redraws) {
    if (!env_->done()) manisoft::detail::fail("EpisodeRecorder::finish: the episode is not over (step ", env_->info().step, ")");
    const long t = rows_;
    Episode e;
    e.index = index;
    e.actions = e_.actions.topRows(t);
    e.states = e_.states.topRows(t);
    e.rewards = Eigen::VectorXd::Zero(t);
    if (env_->info().success && t > 0) e.rewards(t - 1) = 1.0;
    e.dones.assign(static_cast<std::size_t>(t), 0);
    if (t > 0) e.dones.back() = 1;
    e.observations["eef_pose"] = eef_.topRows(t);
    e.observations["gripper"] = gripper_.topRows(t);
    e.observations["rod_centerline"] = rod_.topRows(t);
    e.observations["rod_directors"] = directors_.topRows(t);
    e.observations["object_poses"] = objects_.topRows(t);
    e.observations["ee_target"] = target_.topRows(t);
    e.observations["ee_waypoint"] = waypoint_.topRows(t);
    const scene::SceneSpec& s = env_->spec();
    e.text["task"] = std::string(scene::to_string(s.task));
    e.text["setting"] = std::string(scene::to_string(s.setting));
    e.text["split"] = std::string(scene::to_string(s.split));
    e.text["scene"] = scene::to_json_string(s);
    e.text["instruction"] = s.instruction;
    e.text["instructions_seen"] = nlohmann::json(s.instructions_seen).dump();
    e.text["instructions_unseen"] = nlohmann::json(s.instructions_unseen).dump();
    e.text["failure"] = env_->info().success ? "" : std::string(task::to_string(env_->info().failure));
    e.numbers["success"] = env_->info().success ? 1.0 : 0.0;
    e.numbers["steps"] = static_cast<double>(t);
    e.numbers["seed"] = static_cast<double>(seed);
    e.numbers["scene_index"] = static_cast<double>(s.index);
    e.numbers["redraws"] = redraws;
    return e;
  }

 private:
  const task::TaskEnv* env_;
  Episode e_;
  StepMatrix eef_, gripper_, rod_, directors_, objects_, target_, waypoint_;
  math::Pose<double> last_target_;
  long rows_ = 0;
};

/// Replays `episode` in `env` from its scene and actions. Returns -1 when every recorded state
/// matches the replayed one bit for bit, else the first step whose state differs.
inline long replay_mismatch(task::TaskEnv& env, const Episode& episode) {
  const auto scene_text = episode.text.find("scene");
  if (scene_text == episode.text.end()) manisoft::detail::fail("replay: episode ", episode.index, " has no scene attribute");
  env.reset(scene::parse_scene(scene_text->second, "episode " + std::to_string(episode.index) + " scene"));
  const int n = env.arm_model().rod.n_elements;
  if (episode.actions.cols() != control::FlatAction::size(n))
    manisoft::detail::fail("replay: episode ", episode.index, " actions have ", episode.actions.cols(), " columns, the arm needs ", control::FlatAction::size(n));
  if (episode.states.cols() != state_columns(n, static_cast<int>(env.spec().objects.size())))
    manisoft::detail::fail("replay: episode ", episode.index, " states have ", episode.states.cols(), " columns, the scene needs ",
                           state_columns(n, static_cast<int>(env.spec().objects.size())));
  task::TaskEnv::Array3 torques(n, 3);
  Eigen::RowVectorXd state(episode.states.cols());
  for (long r = 0; r < episode.steps(); ++r) {
    read_state(env, state);
    if (!(state.array() == episode.states.row(r).array()).all()) return r;
    if (env.done()) return r;  // the recording goes on past the replay's end
    const int s = control::FlatAction::unpack(episode.actions.row(r), torques);
    env.step(torques, s);
  }
  return env.done() ? -1 : episode.steps();
}

}  // namespace manisoft::dataset
