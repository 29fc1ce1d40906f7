// The `manisoft` Python module (pybind11): the soft-arm environments with Gymnasium's API,
// without depending on gymnasium: the four benchmark tasks (task_environment.hpp: COLL, ALN, STK,
// ARR with the camera image, the instruction and the expert) and the reach environment
// (env/reach_env.hpp, the paper's executor benchmark, section 3.4) with its model-based expert;
// scene sampling and rendering a given state.
//
//   import manisoft
//   env = manisoft.make_env("COLL", "clean", seed=0, render=True)
//   obs, info = env.reset(options={"index": 3})          # obs["image"], obs["instruction"]
//   obs, reward, terminated, truncated, info = env.step(env.expert_action())
//   reach = manisoft.make_env("reach", target_set="table", seed=0)
//   vec = manisoft.make_vec_env("reach", 64)             # B arms stepped together (manisoft_vec.py)
//
// Task actions: float vectors of 3n + 1 (torques row by row, then S); reach actions: (n x 3)
// torques. Other real dtypes are converted; torques are clamped to the actuation limits
// (action_space.low / .high; the spaces are made by manisoft_vec.py from the specs here). Bad input (shape, dtype, NaN, a call after close) raises
// ValueError / RuntimeError with the library's message; the GIL is released while the simulation
// steps and while a frame renders. Lists and tuples are accepted as actions (numpy.asarray). An
// environment serves one call at a time from any thread, and once it renders only the thread that
// first reset it (its EGL context is current there); other calls raise RuntimeError and change
// nothing (task_environment.hpp, ThreadUse). close() and deletion work from any thread.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "manisoft/control/mlp_executor.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/env/batched_reach_env.hpp"
#include "manisoft/env/reach_env.hpp"
#include "manisoft/task/batched_task_env.hpp"
#include "manisoft/task/batched_task_images.hpp"
#include "task_environment.hpp"

namespace py = pybind11;

namespace manisoft_py {
/// Runs the module's Python half (manisoft_vec.py: spaces, make_vec_env) in the module (python_side.cpp).
void add_python_side(py::module_& m);
}  // namespace manisoft_py

namespace {

using Env = manisoft::env::ReachEnv<>;  // PyElastica's analytical damping, element torques
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
using Seeds = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>;
using Flags = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;
using Actions = py::array_t<double, py::array::c_style | py::array::forcecast>;
const int task_horizon = manisoft::task::TaskEnvConfig{}.horizon;  ///< the tasks' T

py::array_t<double> to_numpy(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& m) {
  py::array_t<double> out({m.rows(), m.cols()});
  auto view = out.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) view(r, c) = m(r, c);
  return out;
}

manisoft::env::ReachEnvConfig reach_config(const std::string& target_set, int horizon, double stability_beta = 1) {
  manisoft::env::ReachEnvConfig config;
  config.stability.beta = stability_beta;
  config.target_set = manisoft::env::parse_target_set(target_set);
  if (horizon < 1) manisoft::detail::fail("horizon = ", horizon, " must be >= 1");
  config.horizon = horizon;
  return config;
}

py::array_t<double> pose_matrix(const manisoft::math::Pose<double>& pose) { return to_numpy(pose.matrix()); }

/// The reach environment's action and observation spaces as plain values (manisoft_vec.py makes spaces of them).
py::dict reach_action_spec(const Env& env) {
  const auto& limits = env.config().limits;
  Array3 high(env.n_elements(), 3);
  for (int k = 0; k < env.n_elements(); ++k)
    for (int c = 0; c < 3; ++c) high(k, c) = limits.bound(k, c);
  py::dict d;
  d["shape"] = py::make_tuple(env.n_elements(), 3);
  d["dtype"] = "float64";
  d["low"] = to_numpy(-high);
  d["high"] = to_numpy(high);
  return d;
}

py::dict reach_observation_spec(const Env& env) {
  const auto nodes = static_cast<int>(env.observation().node_positions.rows());
  py::dict d;
  d["end_effector"] = py::make_tuple(py::make_tuple(4, 4), "float64");
  d["target"] = py::make_tuple(py::make_tuple(4, 4), "float64");
  d["node_positions"] = py::make_tuple(py::make_tuple(nodes, 3), "float64");
  d["node_velocities"] = py::make_tuple(py::make_tuple(nodes, 3), "float64");
  d["time"] = py::make_tuple(py::make_tuple(), "float64");
  return d;
}

/// control::MlpExecutor from Python: the action a weight file's network gives for a reach observation.
class MlpExecutorHandle {
 public:
  MlpExecutorHandle(const std::string& path, int action_rows) : executor_(manisoft::control::MlpExecutor<double>::load(path, action_rows)) {}

  /// observation: the reach environment's dict (target, end_effector 4 x 4; node_positions, node_velocities m x 3).
  py::array_t<double> act(const py::dict& observation) {
    manisoft::control::Observation<double> o;
    o.target = manisoft_py::pose_of(observation["target"], "observation['target']");
    o.end_effector = manisoft_py::pose_of(observation["end_effector"], "observation['end_effector']");
    o.node_positions = nodes(observation, "node_positions");
    o.node_velocities = nodes(observation, "node_velocities");
    o.node_indices = Eigen::VectorXi::LinSpaced(o.node_positions.rows(), 0, int(o.node_positions.rows()) - 1);
    Array3 action;
    executor_.act(o, action);
    return to_numpy(action);
  }

 private:
  static Array3 nodes(const py::dict& observation, const char* key) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(observation[key]);
    if (!a || a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string("observation['") + key + "'] must be an m x 3 array");
    Array3 out(a.shape(0), 3);
    const auto v = a.unchecked<2>();
    for (py::ssize_t r = 0; r < a.shape(0); ++r)
      for (int c = 0; c < 3; ++c) out(r, c) = v(r, c);
    return out;
  }
  manisoft::control::MlpExecutor<double> executor_;
};

class ReachEnvironment {
 public:
  ReachEnvironment(const std::string& target_set, std::uint64_t seed, int horizon)
      : env_(reach_config(target_set, horizon), manisoft::rod::damping::AnalyticalLinear<double>(0.1)),
        expert_(env_.nominal_model(), env_.config().limits),
        next_seed_(seed),
        action_(Array3::Zero(env_.n_elements(), 3)) {}

  py::tuple reset(const py::object& seed, const std::optional<py::dict>& options) {
    const auto entered = threads_.enter("reset");
    check_open();
    if (options) {
      for (const auto& item : *options)
        throw py::value_error("reset: unknown option '" + py::str(item.first).cast<std::string>() + "' (the reach environment takes none)");
    }
    const std::uint64_t s = seed.is_none() ? next_seed_ : manisoft_py::count_arg(seed, "reset: seed");
    next_seed_ = s + 1;
    {
      py::gil_scoped_release release;
      observation_ = &env_.reset(s);
      expert_.reset();
    }
    started_ = true;
    return py::make_tuple(observation(), info());
  }

  py::tuple step(const py::handle& given) {
    const auto entered = threads_.enter("step");
    check_started();
    const py::array action = manisoft_py::action_array(given, "step: action");
    const char kind = action.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
      throw py::value_error("step: action dtype must be real (float64 preferred), got " + py::str(action.dtype()).cast<std::string>());
    if (action.ndim() != 2 || action.shape(0) != env_.n_elements() || action.shape(1) != 3)
      throw py::value_error("step: action must have shape (" + std::to_string(env_.n_elements()) + ", 3), got " +
                            py::str(py::handle(action).attr("shape")).cast<std::string>());
    const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(action);
    const auto view = values.unchecked<2>();
    for (Eigen::Index r = 0; r < action_.rows(); ++r)
      for (int c = 0; c < 3; ++c) action_(r, c) = view(r, c);
    double reward = 0;
    bool done = false;
    {
      py::gil_scoped_release release;
      const auto result = env_.step(action_);  // InvalidInput (NaN) leaves the state unchanged
      observation_ = &result.observation;
      reward = result.reward;
      done = result.done;
    }
    const bool terminated = env_.info().diverged;
    const bool truncated = done && !terminated;
    return py::make_tuple(observation(), reward, terminated, truncated, info());
  }

  /// The model-based expert's action for the current observation (float64 n x 3).
  py::array_t<double> expert_action() {
    const auto entered = threads_.enter("expert_action");
    check_started();
    Array3 action(env_.n_elements(), 3);
    {
      py::gil_scoped_release release;
      expert_.act(*observation_, action);
    }
    return to_numpy(action);
  }

  py::dict action_space() const { return reach_action_spec(env_); }
  py::dict observation_space() const { return reach_observation_spec(env_); }

  void close() {
    const auto entered = threads_.enter("close", true);
    closed_ = true;
  }
  int horizon() const { return env_.config().horizon; }

 private:
  void check_open() const {
    if (closed_) throw std::runtime_error("the environment is closed");
  }
  void check_started() const {
    check_open();
    if (!started_) throw std::runtime_error("call reset() before step()");
  }

  py::dict observation() const {
    py::dict o;
    o["end_effector"] = pose_matrix(observation_->end_effector);
    o["target"] = pose_matrix(observation_->target);
    o["node_positions"] = to_numpy(observation_->node_positions);
    o["node_velocities"] = to_numpy(observation_->node_velocities);
    o["time"] = observation_->time;
    return o;
  }

  py::dict info() const {
    const auto& i = env_.info();
    py::dict d;
    d["success"] = i.success;
    d["in_tolerance"] = i.in_tolerance;
    d["steps"] = i.step;
    d["position_error"] = i.error.position_error;
    d["rotation_error"] = i.error.rotation_error;
    d["diverged"] = i.diverged;
    d["clipped"] = i.clipped;
    d["failure"] = i.diverged ? py::object(py::str("diverged")) : py::object(py::none());
    return d;
  }

  Env env_;
  manisoft::control::ModelExecutor<double> expert_;
  std::uint64_t next_seed_;
  Array3 action_;
  const manisoft::control::Observation<double>* observation_ = nullptr;
  bool started_ = false;
  bool closed_ = false;
  manisoft_py::ThreadUse threads_;
};

/// A read-only numpy view of a batch buffer, kept alive by `owner` (flags: numpy bool over the
/// same 0 / 1 bytes).
template <typename T>
py::array batch_view(std::span<const T> data, std::vector<py::ssize_t> shape, const py::object& owner) {
  const py::dtype type = std::is_same_v<T, std::uint8_t> ? py::dtype::of<bool>() : py::dtype::of<T>();
  py::array out(type, std::move(shape), {}, data.data(), owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// What the batches share from Python (env::BatchedReachEnv, task::BatchedTaskEnv): reset with a
/// mask and a value per arm (its seed, or its scene index), step with a C-ordered float64 array,
/// both without the GIL and from one thread at a time.
template <typename Batch>
class BatchHandle {
 public:
  template <typename... Args>
  explicit BatchHandle(Args&&... args) : batch_(std::forward<Args>(args)...) {}

  /// Resets the arms with mask[i] (every arm when mask is None), arm i with values[i].
  void reset(const Seeds& values, const std::optional<Flags>& mask) {
    const auto entered = threads_.enter("reset");
    py::gil_scoped_release release;
    const std::span<const std::uint64_t> v(values.data(), std::size_t(values.size()));
    if (mask)
      batch_.reset(std::span<const std::uint8_t>(mask->data(), std::size_t(mask->size())), v);
    else
      batch_.reset(v);
  }

  /// One step of every arm: actions hold num_envs x (one arm's action) float64 values (C order).
  void step(const Actions& actions) {
    const auto entered = threads_.enter("step");
    py::gil_scoped_release release;
    batch_.step(std::span<const double>(actions.data(), std::size_t(actions.size())));
  }

  int num_envs() const { return batch_.batch_size(); }
  int threads() const { return batch_.threads(); }

 protected:
  Batch batch_;
  manisoft_py::ThreadUse threads_;
};

/// The batched reach environment's compiled half (env/batched_reach_env.hpp); manisoft.make_vec_env
/// wraps it with Gymnasium's vector API (manisoft_vec.py). Its arrays are numpy views of the batch's
/// own buffers, kept alive by the object and overwritten by every reset and step.
class ReachBatch : public BatchHandle<manisoft::env::BatchedReachEnv<>> {
 public:
  ReachBatch(int num_envs, int threads, const std::string& target_set, int horizon, double stability_beta)
      : BatchHandle(num_envs, threads, reach_config(target_set, horizon, stability_beta), manisoft::rod::damping::AnalyticalLinear<double>(0.1)) {}

  /// The batch's arrays by name (views; the owner keeps the batch alive).
  static py::dict arrays(const py::object& owner) {
    const auto& b = owner.cast<const ReachBatch&>().batch_;
    const py::ssize_t n = b.batch_size(), m = b.observed_nodes();
    py::dict d;
    d["end_effector"] = batch_view(b.end_effector(), {n, 4, 4}, owner);
    d["target"] = batch_view(b.target(), {n, 4, 4}, owner);
    d["node_positions"] = batch_view(b.node_positions(), {n, m, 3}, owner);
    d["node_velocities"] = batch_view(b.node_velocities(), {n, m, 3}, owner);
    d["rewards"] = batch_view(b.rewards(), {n}, owner);
    d["terminated"] = batch_view(b.terminated(), {n}, owner);
    d["truncated"] = batch_view(b.truncated(), {n}, owner);
    d["success"] = batch_view(b.success(), {n}, owner);
    d["steps"] = batch_view(b.steps(), {n}, owner);
    d["position_error"] = batch_view(b.position_error(), {n}, owner);
    d["rotation_error"] = batch_view(b.rotation_error(), {n}, owner);
    d["clipped"] = batch_view(b.clipped(), {n}, owner);
    d["max_node_speed"] = batch_view(b.max_node_speed(), {n}, owner);
    d["seeds"] = batch_view(b.seeds(), {n}, owner);
    return d;
  }

  int action_rows() const { return batch_.action_rows(); }
  py::dict action_space() const { return reach_action_spec(batch_.arm(0)); }
  py::dict observation_space() const { return reach_observation_spec(batch_.arm(0)); }
};

/// The batched task environment's compiled half (task/batched_task_env.hpp); manisoft.make_vec_env
/// wraps it with Gymnasium's vector API (manisoft_vec.py). Its arrays are numpy views as ReachBatch's.
class TaskBatch : public BatchHandle<manisoft::task::BatchedTaskEnv> {
 public:
  TaskBatch(const std::string& task, const std::string& setting, const std::string& split, std::uint64_t seed, int num_envs, int threads,
            const std::string& action_mode, int action_repeat, bool render, const std::optional<py::dict>& camera)
      : BatchHandle(num_envs, threads, settings(task, setting, split, seed, action_mode, action_repeat)) {
    if (!render) {
      if (camera) throw py::value_error("make_vec_env: camera is given but render=False");
      return;
    }
    // as make_env's camera: a dict replaces the scene's camera (unset keys: the defaults); none: each scene's own
    const std::optional<manisoft::render::Camera> c = camera ? std::optional(manisoft_py::camera_of(*camera, {})) : std::nullopt;
    const manisoft::render::Camera size = c ? *c : manisoft::render::Camera{};
    images_ = std::make_unique<manisoft::task::BatchedTaskImages>(batch_, size.width, size.height, c);
  }

  /// As BatchHandle::reset; a rendering batch is bound to the thread of its first reset (its
  /// renderer on part 0 has its EGL context there).
  void reset(const Seeds& values, const std::optional<Flags>& mask) {
    BatchHandle::reset(values, mask);
    if (images_) threads_.bind();
  }

  static py::dict arrays(const py::object& owner) {
    const auto& b = owner.cast<const TaskBatch&>().batch_;
    const py::ssize_t n = b.batch_size(), k = b.max_objects();
    py::dict d;
    d["rod_nodes"] = batch_view(b.rod_nodes(), {n, b.n_elements() + 1, 3}, owner);
    d["end_effector"] = batch_view(b.end_effector(), {n, 4, 4}, owner);
    d["gripper_pose"] = batch_view(b.gripper_pose(), {n, 4, 4}, owner);
    d["gripper_width"] = batch_view(b.gripper_width(), {n}, owner);
    d["gripper_state"] = batch_view(b.gripper_state(), {n}, owner);
    d["object_poses"] = batch_view(b.object_poses(), {n, k, 4, 4}, owner);
    d["object_count"] = batch_view(b.object_count(), {n}, owner);
    d["rewards"] = batch_view(b.rewards(), {n}, owner);
    d["terminated"] = batch_view(b.terminated(), {n}, owner);
    d["truncated"] = batch_view(b.truncated(), {n}, owner);
    d["success"] = batch_view(b.success(), {n}, owner);
    d["steps"] = batch_view(b.steps(), {n}, owner);
    d["failure"] = batch_view(b.failure(), {n}, owner);
    d["indices"] = batch_view(b.indices(), {n}, owner);
    d["control_steps"] = batch_view(b.control_steps(), {n}, owner);
    if (const auto& images = owner.cast<const TaskBatch&>().images_) {
      py::array image(py::dtype::of<std::uint8_t>(), std::vector<py::ssize_t>{n, images->height(), images->width(), 3}, {}, images->images().data(), owner);
      py::detail::array_proxy(image.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
      d["image"] = image;
    }
    return d;
  }

  /// The instruction of each arm's scene.
  py::tuple instructions() const {
    py::tuple out(batch_.batch_size());
    for (int i = 0; i < batch_.batch_size(); ++i) out[i] = batch_.instruction(i);
    return out;
  }
  /// Each arm's failure reason: None, or its name (as the single environment's info["failure"]).
  py::tuple failures() const {
    py::tuple out(batch_.batch_size());
    const auto f = batch_.failure();
    for (int i = 0; i < batch_.batch_size(); ++i) {
      const auto reason = static_cast<manisoft::task::FailureReason>(f[std::size_t(i)]);
      out[i] = reason == manisoft::task::FailureReason::none ? py::object(py::none()) : py::object(py::str(std::string(manisoft::task::to_string(reason))));
    }
    return out;
  }

  /// Each arm's end-effector command of the last step (as the single environment's info["ee_command"]).
  py::tuple ee_commands() const {
    py::tuple out(batch_.batch_size());
    const auto c = batch_.ee_command();
    for (int i = 0; i < batch_.batch_size(); ++i) out[i] = std::string(manisoft::task::to_string(static_cast<manisoft::task::EeCommand>(c[std::size_t(i)])));
    return out;
  }

  int n_elements() const { return batch_.n_elements(); }
  int max_objects() const { return batch_.max_objects(); }
  bool ee_pose() const { return batch_.settings().ee_track.has_value(); }
  py::dict action_space() const { return ee_pose() ? manisoft_py::ee_action_spec() : manisoft_py::task_action_spec(batch_.n_elements()); }
  /// The images' height and width, or None without rendering.
  py::object image_size() const { return images_ ? py::object(py::make_tuple(images_->height(), images_->width())) : py::object(py::none()); }

 private:
  std::unique_ptr<manisoft::task::BatchedTaskImages> images_;  // declared after the batch: released first

  static manisoft::task::BatchedTaskEnv::Settings settings(const std::string& task, const std::string& setting, const std::string& split, std::uint64_t seed,
                                                          const std::string& action_mode, int action_repeat) {
    manisoft::task::BatchedTaskEnv::Settings s;
    if (action_mode != "torque" && action_mode != "ee_pose")
      throw py::value_error("make_vec_env: action_mode = '" + action_mode + "' must be 'torque' or 'ee_pose'");
    if (action_mode == "ee_pose") s.ee_track = manisoft_py::ee_track_config(action_repeat);
    s.task = manisoft::scene::parse_task(task);
    s.setting = manisoft::scene::parse_setting(setting);
    s.split = manisoft::scene::parse_split(split);
    s.seed = seed;
    return s;
  }
};

/// Renders any state of a scene: for replaying recorded states or a user's own.
class StateRenderer {
 public:
  py::array_t<std::uint8_t> render(const std::string& scene_json, const py::array& rod_nodes, const py::handle& gripper_pose, double finger_width,
                                   const py::array& object_poses, const std::optional<py::dict>& camera) {
    const auto spec = manisoft::scene::parse_scene(scene_json, "Renderer.render(scene)");
    manisoft::scene::require_consistent(spec, sampler_.library(), "Renderer.render(scene)");
    const auto nodes = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(rod_nodes);
    if (!nodes || nodes.ndim() != 2 || nodes.shape(1) != 3 || nodes.shape(0) < 2) throw py::value_error("rod_nodes must be an (n+1) x 3 array, n >= 1");
    Eigen::Matrix<double, Eigen::Dynamic, 3> x(nodes.shape(0), 3);
    const auto nv = nodes.unchecked<2>();
    for (py::ssize_t i = 0; i < nodes.shape(0); ++i)
      for (int c = 0; c < 3; ++c) x(i, c) = nv(i, c);
    if (!x.allFinite()) throw py::value_error("rod_nodes is not finite");
    if (!std::isfinite(finger_width) || finger_width < 0) throw py::value_error("finger_width must be finite and >= 0");
    const auto poses = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object_poses);
    if (!poses || poses.ndim() != 3 || poses.shape(1) != 4 || poses.shape(2) != 4 || poses.shape(0) != static_cast<py::ssize_t>(spec.objects.size()))
      throw py::value_error("object_poses must be an array of " + std::to_string(spec.objects.size()) + " 4 x 4 matrices (one per scene object)");
    std::vector<manisoft::math::Pose<double>> objects;
    for (py::ssize_t i = 0; i < poses.shape(0); ++i) objects.push_back(manisoft_py::pose_of(poses[py::make_tuple(i)], "object_poses[" + std::to_string(i) + "]"));
    const auto gripper = manisoft_py::pose_of(gripper_pose, "gripper_pose");
    if (!gl_) gl_ = manisoft_py::make_policy_renderer();
    manisoft_py::SceneRenderer r(spec, sampler_.library(),
                                 camera ? manisoft_py::camera_of(*camera, spec.cameras.front()) : spec.cameras.front(), *gl_);
    r.set_state(x, gripper, finger_width, objects);
    return r.render();
  }

 private:
  manisoft::scene::SceneSampler sampler_;
  std::unique_ptr<manisoft_py::PolicyRenderer> gl_;
};

}  // namespace

PYBIND11_MODULE(_manisoft, m) {
  m.doc() = "ManiSoft: soft continuum arm simulation and benchmark environments (Gymnasium-style API)";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const manisoft::InvalidInput& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const manisoft::Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  py::class_<ReachEnvironment>(m, "ReachEnv", "Reach a target end-effector pose and hold it (paper section 3.4)")
      .def("reset", &ReachEnvironment::reset, py::arg("seed") = py::none(), py::arg("options") = py::none(),
           "Starts an episode: (observation, info)")
      .def("step", &ReachEnvironment::step, py::arg("action"),
           "One control step (7 x 0.2 ms): (observation, reward, terminated, truncated, info)")
      .def("expert_action", &ReachEnvironment::expert_action, "The model-based executor's action now")
      .def("close", &ReachEnvironment::close)
      .def("_action_space_spec", &ReachEnvironment::action_space)            // manisoft_vec.py makes the spaces of these
      .def("_observation_space_spec", &ReachEnvironment::observation_space)
      .def_property_readonly("horizon", &ReachEnvironment::horizon);
  py::class_<MlpExecutorHandle>(m, "MlpExecutor", "An MLP executor's weight file (control/mlp_executor.hpp) acting on reach observations")
      .def(py::init<const std::string&, int>(), py::arg("path"), py::arg("action_rows") = manisoft::env::ReachEnvConfig{}.rod.n_elements)
      .def("act", &MlpExecutorHandle::act, py::arg("observation"), "The action (rows x 3 element torques, unclamped) for a reach observation");
  py::class_<ReachBatch>(m, "_ReachBatch", "B reach environments stepped together (use manisoft.make_vec_env)")
      .def(py::init<int, int, const std::string&, int, double>(), py::arg("num_envs"), py::arg("threads"), py::arg("target_set"), py::arg("horizon"),
           py::arg("stability_beta"))
      .def("reset", &ReachBatch::reset, py::arg("seeds"), py::arg("mask") = py::none())
      .def("step", &ReachBatch::step, py::arg("actions"))
      .def("arrays", [](const py::object& self) { return ReachBatch::arrays(self); })
      .def_property_readonly("num_envs", &ReachBatch::num_envs)
      .def_property_readonly("threads", &ReachBatch::threads)
      .def_property_readonly("action_rows", &ReachBatch::action_rows)
      .def("_action_space_spec", &ReachBatch::action_space)
      .def("_observation_space_spec", &ReachBatch::observation_space);
  py::class_<TaskBatch>(m, "_TaskBatch", "B task environments stepped together (use manisoft.make_vec_env)")
      .def(py::init<const std::string&, const std::string&, const std::string&, std::uint64_t, int, int, const std::string&, int, bool,
                    const std::optional<py::dict>&>(),
           py::arg("task"), py::arg("setting"), py::arg("split"), py::arg("seed"), py::arg("num_envs"), py::arg("threads"), py::arg("action_mode"),
           py::arg("action_repeat"), py::arg("render") = false, py::arg("camera") = py::none())
      .def("reset", &TaskBatch::reset, py::arg("indices"), py::arg("mask") = py::none())
      .def("step", &TaskBatch::step, py::arg("actions"))
      .def("arrays", [](const py::object& self) { return TaskBatch::arrays(self); })
      .def("instructions", &TaskBatch::instructions)
      .def("failures", &TaskBatch::failures)
      .def("ee_commands", &TaskBatch::ee_commands)
      .def_property_readonly("num_envs", &TaskBatch::num_envs)
      .def_property_readonly("threads", &TaskBatch::threads)
      .def_property_readonly("n_elements", &TaskBatch::n_elements)
      .def_property_readonly("max_objects", &TaskBatch::max_objects)
      .def_property_readonly("image_size", &TaskBatch::image_size)
      .def("_action_space_spec", &TaskBatch::action_space)
      .def("_observation_space_spec", [](const TaskBatch&) { return py::dict(); });
  using manisoft_py::TaskEnvironment;
  py::class_<TaskEnvironment>(m, "TaskEnv",
                              "A ManiSoft task (COLL, ALN, STK, ARR): instruction and camera image in, torques and gripper state out (paper section 3.2)")
      .def("reset", &TaskEnvironment::reset, py::arg("seed") = py::none(), py::arg("options") = py::none(),
           "Starts an episode on scene (task, setting, split, options['index'], seed): (observation, info). Options: index, split, "
           "instruction ('canonical'|'seen'|'unseen'), instruction_index, scene (JSON text)")
      .def("step", &TaskEnvironment::step, py::arg("action"),
           "One control step (7 x 0.2 ms): (observation, reward, terminated, truncated, info)")
      .def("expert_action", &TaskEnvironment::expert_action, "The rule-based expert's action now (privileged: it reads the world)")
      .def("expert_target", &TaskEnvironment::expert_target,
           "The expert's end-effector target and gripper state after expert_action(), as an 'ee_pose' action (7 floats)")
      .def_property_readonly("action_mode", &TaskEnvironment::action_mode)
      .def_property_readonly("action_repeat", &TaskEnvironment::action_repeat, "control steps a step() takes (1 on the torque track)")
      .def("render", &TaskEnvironment::render, "The current camera image (uint8 H x W x 3)")
      .def("close", &TaskEnvironment::close)
      .def("scene_json", &TaskEnvironment::scene_json, "The episode's scene (manisoft.scene/1 JSON)")
      .def_property_readonly("expert_phase", &TaskEnvironment::expert_phase)
      .def("_action_space_spec", &TaskEnvironment::action_space)
      .def("_observation_space_spec", &TaskEnvironment::observation_space)
      .def_property_readonly("horizon", &TaskEnvironment::horizon)
      .def_property_readonly("n_elements", &TaskEnvironment::n_elements);
  m.def(
      "make_env",
      [](const std::string& name, const std::string& setting, std::uint64_t seed, bool render, const std::optional<py::dict>& camera,
         bool privileged, const std::string& split, const std::string& target_set, int horizon, const std::string& action_mode,
         int action_repeat) -> py::object {
        if (name == "reach") {
          if (action_mode != "torque") throw py::value_error("make_env: the reach environment's actions are torques (action_mode 'torque')");
          return py::cast(std::make_unique<ReachEnvironment>(target_set, seed, horizon));
        }
        std::string names;
        bool known = false;
        for (const auto t : manisoft::scene::all_tasks) {
          known = known || name == manisoft::scene::to_string(t);
          names += std::string(manisoft::scene::to_string(t)) + ", ";
        }
        if (!known) throw py::value_error("make_env: unknown environment '" + name + "' (available: " + names + "reach)");
        if (horizon != task_horizon)
          throw py::value_error("make_env: the tasks' horizon is the paper's T = " + std::to_string(task_horizon) + " (got " + std::to_string(horizon) + ")");
        return py::cast(std::make_unique<TaskEnvironment>(name, setting, seed, render, camera, privileged, split, action_mode, action_repeat));
      },
      py::arg("name"), py::arg("setting") = "clean", py::arg("seed") = 0, py::arg("render") = true, py::arg("camera") = py::none(),
      py::arg("privileged") = false, py::arg("split") = "train", py::arg("target_set") = "table", py::arg("horizon") = task_horizon,
      py::arg("action_mode") = "torque", py::arg("action_repeat") = manisoft::task::EeTrackConfig{}.action_repeat,
      "Makes an environment: make_env(task, 'clean'|'randomized', seed=0, render=True, camera=None, privileged=False, split='train', "
      "action_mode='torque'|'ee_pose', action_repeat=36) "
      "(the paper's observation: image and instruction; privileged=True adds the state, render=False leaves the image out) "
      "for a task of manisoft.tasks(), or make_env('reach', target_set='table'|'equilibria', seed=0, horizon=HORIZON)");
  // The tasks and the episode's timing, from the one definition of each (task/registry.hpp, TaskEnvConfig).
  m.def(
      "tasks",
      [] {
        py::list out;
        for (const auto t : manisoft::scene::all_tasks) {
          const auto info = manisoft::task::task_info(t);
          py::dict d;
          d["name"] = std::string(info.name);
          d["summary"] = std::string(info.summary);
          py::list conditions;
          for (const auto c : info.conditions) conditions.append(std::string(c));
          d["conditions"] = conditions;
          d["by_category"] = info.tables_by_category;
          out.append(d);
        }
        return out;
      },
      "The benchmark's tasks in order: [{'name', 'summary', 'conditions', 'by_category'}] (success: every condition holds; "
      "by_category: evaluation plans and tables per target-object category)");
  m.attr("HORIZON") = task_horizon;
  m.attr("ACTION_REPEAT") = manisoft::task::EeTrackConfig{}.action_repeat;  ///< the end-effector track's default control steps a step
  manisoft_py::add_python_side(m);
  m.attr("CONTROL_DT") = manisoft::task::TaskEnvConfig{}.dt * manisoft::task::TaskEnvConfig{}.substeps;
  m.def(
      "target_object",
      [](const std::string& scene_json) {
        const auto spec = manisoft::scene::parse_scene(scene_json, "target_object scene");
        return manisoft::task::target_object(spec);
      },
      py::arg("scene"),
      "The index of the object a scene's episode is about (COLL, ALN, OVR: the goal's object; STK: the top item; ARR: the first relation's "
      "placed object), -1 when none");
  py::class_<manisoft::scene::SceneSampler>(m, "SceneSampler", "The benchmark's scenes (assets, layouts, instructions), drawn deterministically")
      .def(py::init<>())
      .def(
          "sample",
          [](manisoft::scene::SceneSampler& sampler, const std::string& task, const std::string& setting, std::uint64_t index, std::uint64_t seed,
             const std::string& split) {
            manisoft::scene::SampleRequest q;
            q.task = manisoft::scene::parse_task(task);
            q.setting = manisoft::scene::parse_setting(setting);
            q.split = manisoft::scene::parse_split(split);
            q.index = index;
            q.seed = seed;
            py::gil_scoped_release release;
            return manisoft::scene::to_json_string(sampler.sample(q));
          },
          py::arg("task"), py::arg("setting") = "clean", py::arg("index") = 0, py::arg("seed") = 0, py::arg("split") = "train",
          "The scene (task, setting, split, index, seed) as manisoft.scene/1 JSON text: the scene make_env's reset builds for them");
  py::class_<StateRenderer>(m, "Renderer", "Renders a scene in a given state (OpenGL through EGL)")
      .def(py::init<>())
      .def("render", &StateRenderer::render, py::arg("scene"), py::arg("rod_nodes"), py::arg("gripper_pose"), py::arg("finger_width"),
           py::arg("object_poses"), py::arg("camera") = py::none(),
           "Image (uint8 H x W x 3) of scene JSON text with the rod's nodes ((n+1) x 3), the gripper's pose (4 x 4), its finger width (m) and "
           "the objects' poses (objects x 4 x 4), e.g. the privileged keys of an observation");
}
