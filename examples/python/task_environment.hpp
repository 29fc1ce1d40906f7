// The benchmark's task environment for Python: task::TaskEnv (one ManiSoft
// task COLL/ALN/STK/ARR in the arm world, success predicate, failure reasons) with scenes from
// scene::SceneSampler, the camera image from a render::Renderer (PolicyRenderer: the in-process
// OpenGL renderer) over scene::make_render_scene, and the rule-based expert (task::Expert) for
// collecting data or as an upper bound. Gymnasium's signatures, no gymnasium dependency.
//
// Action, action_mode "torque" (the paper's, section 3.2): one float vector of 3n + 1 entries, the
// n x 3 material-frame element torques flattened row by row (element 0 is the clamped base: its
// bounds are 0), then the gripper state S (>= 0.5 closed, below open); one control step a call.
// Torques are clamped to the actuation limits. action_mode "ee_pose" (task/ee_track.hpp): 7 floats,
// the end effector's target position (m, world) and orientation as a rotation vector r (rad, world
// frame) from the home (tool-down) orientation, R = exp([r]x) R_home (task::ee_action), then S; the model executor tracks the target for
// action_repeat control steps a call (default 36: 20 Hz). NaN, wrong shape or a non-real dtype
// raise ValueError and change nothing.
// Observation: "instruction" (str) and, when rendering, "image" (uint8 H x W x 3, a fresh array a
// step, handed over without a copy); with privileged=True also "end_effector" (4 x 4, the rod tip's
// frame), "gripper_pose" (4 x 4, the gripper body: what Renderer.render takes), "rod_nodes" ((n+1) x 3), "gripper_width" (m), "gripper_state" (S), "object_poses"
// (objects x 4 x 4, asset frame -> world).
// Reward: 1 at the step the task succeeds, else 0. terminated / truncated as TaskEnv's StepInfo
// says (success or a terminal failure / the horizon). info["conditions"]: the success
// predicate's named conditions at this step.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "manisoft/control/action_layout.hpp"
#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_render.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/ee_track.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft_py {

namespace py = pybind11;
namespace ms = manisoft;

/// A 4 x 4 homogeneous matrix of a pose.
inline py::array_t<double> matrix_of(const ms::math::Pose<double>& p) {
  py::array_t<double> out({4, 4});
  auto v = out.mutable_unchecked<2>();
  const Eigen::Matrix4d m = p.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v(r, c) = m(r, c);
  return out;
}

/// A pose from a 4 x 4 matrix (its rotation block re-orthonormalised is not attempted: it is checked).
inline ms::math::Pose<double> pose_of(const py::handle& h, const std::string& what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) throw py::value_error(what + " must be a 4 x 4 matrix");
  const auto v = a.unchecked<2>();
  ms::math::Pose<double> p;
  for (int r = 0; r < 3; ++r) {
    p.translation(r) = v(r, 3);
    for (int c = 0; c < 3; ++c) p.rotation(r, c) = v(r, c);
  }
  if (!p.is_finite()) throw py::value_error(what + " is not finite");
  if ((p.rotation.transpose() * p.rotation - Eigen::Matrix3d::Identity()).norm() > 1e-6)
    throw py::value_error(what + ": its rotation block is not orthonormal");
  return p;
}

/// What a refused argument was: its repr and, unless an int or a float, its type ("'3' (str)").
inline std::string describe(const py::handle& v) {
  const std::string type = py::str(py::type::of(v).attr("__name__"));
  return std::string(py::repr(v)) + (type == "int" || type == "float" ? "" : " (" + type + ")");
}

/// A count or seed argument: a Python int (not a bool) in [0, 2^64), else ValueError naming it.
inline std::uint64_t count_arg(const py::handle& v, const std::string& what) {
  if (py::isinstance<py::int_>(v) && !py::isinstance<py::bool_>(v)) {
    const unsigned long long x = PyLong_AsUnsignedLongLong(v.ptr());
    if (!(x == static_cast<unsigned long long>(-1) && PyErr_Occurred())) return x;
    PyErr_Clear();  // negative or 2^64 and above
  }
  throw py::value_error(what + " must be an integer in [0, 2^64), got " + describe(v));
}

/// A string argument, else ValueError naming it.
inline std::string string_arg(const py::handle& v, const std::string& what) {
  if (!py::isinstance<py::str>(v)) throw py::value_error(what + " must be a string, got " + describe(v));
  return py::str(v);
}

/// An action as a numpy array: an array as it is, a list or tuple through numpy.asarray; else
/// ValueError naming `what`.
inline py::array action_array(const py::handle& action, const std::string& what) {
  if (py::isinstance<py::array>(action)) return py::reinterpret_borrow<py::array>(action);
  try {
    return py::module_::import("numpy").attr("asarray")(action);
  } catch (const py::error_already_set& e) {
    throw py::value_error(what + " must be an array of numbers, got " + describe(action) + ": " + e.what());
  }
}

/// Which threads may call an environment: any one at a time (a second thread's call while the
/// first runs without the GIL raises), and once it renders only the thread whose EGL context it
/// draws with. Every entry point calls enter() first, so a refused call changes nothing.
class ThreadUse {
 public:
  class Entered {
   public:
    explicit Entered(bool& busy) : busy_(busy) { busy_ = true; }
    Entered(const Entered&) = delete;
    Entered& operator=(const Entered&) = delete;
    ~Entered() { busy_ = false; }

   private:
    bool& busy_;
  };

  /// Checked under the GIL (no other Python thread runs meanwhile).
  [[nodiscard]] Entered enter(const char* call, bool any_thread = false) {
    if (busy_) throw std::runtime_error(std::string(call) + ": the environment is in use by another thread (one call at a time)");
    if (!any_thread && bound_ && *bound_ != std::this_thread::get_id())
      throw std::runtime_error(std::string(call) + ": this environment renders with an EGL context bound to the thread that first "
                               "reset it; call it from that thread (or make one environment per thread)");
    return Entered(busy_);
  }
  /// From now on only the calling thread may use it (its renderer's context is current here).
  void bind() {
    if (!bound_) bound_ = std::this_thread::get_id();
  }

 private:
  bool busy_ = false;
  std::optional<std::thread::id> bound_;
};

/// A camera from a dict (keys position, look_at, up, fov_y_deg, width, height; others refused),
/// starting from `base`.
inline ms::render::Camera camera_of(const py::dict& d, ms::render::Camera base) {
  auto vec = [](const py::handle& h, const std::string& key) {
    const auto v = h.cast<std::vector<double>>();
    if (v.size() != 3) throw py::value_error("camera['" + key + "'] must have 3 entries");
    return Eigen::Vector3d(v[0], v[1], v[2]);
  };
  for (const auto& [k, v] : d) {
    const std::string key = py::str(k);
    if (key == "position") base.position = vec(v, key);
    else if (key == "look_at") base.look_at = vec(v, key);
    else if (key == "up") base.up = vec(v, key);
    else if (key == "fov_y_deg") base.fov_y_deg = v.cast<double>();
    else if (key == "width") base.width = v.cast<int>();
    else if (key == "height") base.height = v.cast<int>();
    else throw py::value_error("camera: unknown key '" + key + "' (position, look_at, up, fov_y_deg, width, height)");
  }
  ms::render::validate(base);
  return base;
}

/// The pixels of a render handed to numpy without a copy: the array owns the moved buffer.
inline py::array_t<std::uint8_t> image_array(std::vector<std::uint8_t>&& rgb, int width, int height) {
  auto* owned = new std::vector<std::uint8_t>(std::move(rgb));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
  return py::array_t<std::uint8_t>({height, width, 3}, owned->data(), free_when_done);
}

/// The renderer of one scene: its description once, then a frame per state.
template <ms::render::Renderer R>
class SceneRenderer {
 public:
  SceneRenderer(const ms::scene::SceneSpec& spec, const ms::scene::AssetLibrary& library, const std::optional<ms::render::Camera>& camera, R& gl)
      : scene_(ms::scene::make_render_scene(spec, library)), gl_(&gl) {
    if (camera) scene_.scene.cameras = {*camera};
    gl_->set_scene(scene_.scene);
  }

  /// The frame of a state: rod centreline, gripper body pose and opening, object poses.
  void set_state(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3>>& rod_nodes, const ms::math::Pose<double>& gripper,
                 double finger_width, const std::vector<ms::math::Pose<double>>& objects) {
    frame_ = ms::scene::render_frame(scene_, rod_nodes, gripper, finger_width, objects);
  }

  /// Renders the current frame (the GIL released); the image as a numpy array.
  py::array_t<std::uint8_t> render() {
    {
      py::gil_scoped_release release;
      gl_->render_into(frame_, out_);
    }
    const int w = out_.width, h = out_.height;
    return image_array(std::move(out_.rgb), w, h);
  }

 private:
  ms::render::tabletop::TabletopScene scene_;
  R* gl_;
  ms::render::FrameState frame_;
  ms::render::RenderOutput out_;
};

/// The backend of the image a policy sees (any render::Renderer).
using PolicyRenderer = ms::render::GlRenderer;

/// A renderer for the image a policy sees: shadows on, only colour read back.
inline std::unique_ptr<PolicyRenderer> make_policy_renderer() { return ms::render::make_colour_renderer<PolicyRenderer>(); }

/// A task's flat action space as plain values (manisoft_vec.py makes a Box of it): the n x 3
/// element torques within the actuation limits, then S in [0, 1].
inline py::dict task_action_spec(int n) {
  using Action = ms::control::FlatAction;
  const ms::rod::ActuationLimits<double> lim = ms::world::ArmWorldSettings{}.limits;  // TaskEnv's world keeps the defaults
  py::array_t<double> low(Action::size(n)), high(Action::size(n));
  auto l = low.mutable_unchecked<1>();
  auto h = high.mutable_unchecked<1>();
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) {
      h(Action::torque(k, c)) = lim.bound(k, c);
      l(Action::torque(k, c)) = -lim.bound(k, c);
    }
  l(Action::gripper(n)) = 0.0;
  h(Action::gripper(n)) = 1.0;
  py::dict d;
  d["shape"] = py::make_tuple(Action::size(n));
  d["dtype"] = "float64";
  d["low"] = low;
  d["high"] = high;
  d["layout"] = "element torques (n x 3, material frame d1 d2 d3, row by row; element 0 fixed at 0) then S (>= 0.5 closed)";
  return d;
}

/// The end-effector track's action space: target position within a box around the arm's reach
/// (its base +- its length), rotation vector within [-pi, pi] each, then S in [0, 1].
inline py::dict ee_action_spec() {
  const ms::world::ArmMount mount{};
  const double reach = ms::world::tabletop_arm_parameters().length;
  py::array_t<double> low(7), high(7);
  auto l = low.mutable_unchecked<1>();
  auto h = high.mutable_unchecked<1>();
  for (int c = 0; c < 3; ++c) {
    l(c) = mount.base_position(c) - reach;
    h(c) = mount.base_position(c) + reach;
    l(3 + c) = -std::numbers::pi;
    h(3 + c) = std::numbers::pi;
  }
  l(6) = 0.0;
  h(6) = 1.0;
  py::dict d;
  d["shape"] = py::make_tuple(7);
  d["dtype"] = "float64";
  d["low"] = low;
  d["high"] = high;
  d["layout"] = "end-effector target position x y z (m, world), rotation vector rx ry rz from the home (tool-down) orientation "
                "(rad, world frame: R = exp([r]x) R_home), then S (>= 0.5 closed)";
  return d;
}

/// An end-effector action of a pose and S (task::ee_action).
inline py::array_t<double> ee_action_of(const ms::task::TaskEnv& env, const ms::math::Pose<double>& p, int s) {
  py::array_t<double> out(7);
  auto v = out.mutable_unchecked<1>();
  const auto a = ms::task::ee_action(p, s, env.home_pose().rotation);
  for (int c = 0; c < 7; ++c) v(c) = a(c);
  return out;
}

/// The end-effector track's settings with `action_repeat` control steps a command.
inline ms::task::EeTrackConfig ee_track_config(int action_repeat) {
  ms::task::EeTrackConfig c;
  if (action_repeat < 1) throw py::value_error("action_repeat = " + std::to_string(action_repeat) + " must be at least 1");
  c.action_repeat = action_repeat;
  return c;
}

class TaskEnvironment {
 public:
  using Array3 = ms::task::TaskEnv::Array3;
  using Action = ms::control::FlatAction;

  TaskEnvironment(const std::string& task, const std::string& setting, std::uint64_t seed, bool render, const std::optional<py::dict>& camera,
                  bool privileged, const std::string& split, const std::string& action_mode, int action_repeat)
      : env_(sampler_.library()), expert_(env_), track_(env_, ee_track_config(action_repeat)), seed_(seed), render_(render), privileged_(privileged) {
    if (action_mode != "torque" && action_mode != "ee_pose")
      throw py::value_error("make_env: action_mode = '" + action_mode + "' must be 'torque' or 'ee_pose'");
    ee_mode_ = action_mode == "ee_pose";
    request_.task = ms::scene::parse_task(task);
    request_.setting = ms::scene::parse_setting(setting);
    request_.split = ms::scene::parse_split(split);
    if (camera) camera_ = camera_of(*camera, ms::render::Camera{});
    n_ = env_.arm_model().rod.n_elements;
    torques_ = Array3::Zero(n_, 3);
  }

  /// options: "index" (scene index; default: the next one), "split" ("train" | "eval"),
  /// "instruction" ("canonical" | "seen" | "unseen"), "instruction_index" (which of them, modulo
  /// their number), "scene" (a scene JSON string instead of sampling).
  py::tuple reset(const py::object& seed, const std::optional<py::dict>& options) {
    const auto entered = threads_.enter("reset");
    check_open();
    ms::scene::SampleRequest q = request_;
    q.seed = seed.is_none() ? seed_ : count_arg(seed, "reset: seed");
    q.index = next_index_;
    std::string instruction_kind = "canonical";
    std::size_t instruction_index = 0;
    std::optional<std::string> scene_json;
    if (options) {
      for (const auto& [k, v] : *options) {
        const std::string key = py::str(k);
        const std::string what = "reset: options['" + key + "']";
        if (key == "index") q.index = count_arg(v, what);
        else if (key == "split") q.split = ms::scene::parse_split(string_arg(v, what));
        else if (key == "instruction") instruction_kind = string_arg(v, what);
        else if (key == "instruction_index") instruction_index = count_arg(v, what);
        else if (key == "scene") scene_json = string_arg(v, what);
        else throw py::value_error("reset: unknown option '" + key + "' (index, split, instruction, instruction_index, scene)");
      }
    }
    if (instruction_kind != "canonical" && instruction_kind != "seen" && instruction_kind != "unseen")
      throw py::value_error("reset: option 'instruction' = '" + instruction_kind + "' must be 'canonical', 'seen' or 'unseen'");
    {
      py::gil_scoped_release release;
      if (scene_json) {  // checked as a sampled scene is, before anything changes
        ms::scene::SceneSpec given = ms::scene::parse_scene(*scene_json, "reset(options['scene'])");
        ms::scene::require_valid(given, sampler_.validator(), "reset(options['scene'])");
        ms::task::TaskEnv probe(sampler_.library(), env_.config());  // a goal met at reset is refused on a copy
        probe.reset(given);
        ms::task::require_a_task(probe, "reset(options['scene'])");
        spec_ = std::move(given);
      } else {
        spec_ = sampler_.sample(q);
      }
      env_.reset(spec_);
      expert_.reset();
      track_.reset();
    }
    expert_s_ = 0;
    seed_ = q.seed;
    next_index_ = q.index + 1;
    const auto& list = instruction_kind == "seen" ? spec_.instructions_seen : instruction_kind == "unseen" ? spec_.instructions_unseen : std::vector<std::string>{};
    instruction_ = list.empty() ? spec_.instruction : list[instruction_index % list.size()];
    instruction_kind_ = list.empty() ? "canonical" : instruction_kind;
    if (render_) {
      threads_.bind();
      if (!gl_) gl_ = make_policy_renderer();
      renderer_.emplace(spec_, sampler_.library(), camera_ ? camera_ : std::optional<ms::render::Camera>(spec_.cameras.front()), *gl_);
    }
    started_ = true;
    return py::make_tuple(observation(), info());
  }

  py::tuple step(const py::handle& action) {
    const auto entered = threads_.enter("step");
    check_started();
    if (env_.done()) throw std::runtime_error("step: the episode is over (" + std::to_string(env_.info().step) + " steps); call reset()");
    if (ee_mode_) return step_end_effector(action);
    int s = read_action(action, torques_);
    {
      py::gil_scoped_release release;
      env_.step(torques_, s);
    }
    const auto& i = env_.info();
    return py::make_tuple(observation(), i.success ? 1.0 : 0.0, i.terminated, i.truncated, info());
  }

  /// The expert's end-effector target and gripper state after expert_action() (the end of the
  /// line or ramp it tracks), as an "ee_pose" action: recorded on the torque track, the targets
  /// drive the end-effector track (privileged).
  py::array_t<double> expert_target() {
    const auto entered = threads_.enter("expert_target");
    check_started();
    if (ee_mode_)
      throw std::runtime_error("expert_target: the expert acts at the control rate on the torque track; record its targets there "
                               "(make_env(..., action_mode='torque'): expert_action(), then expert_target())");
    return ee_action_of(env_, expert_.target(), expert_s_);
  }

  /// The expert's action for the current state (privileged: it reads the world).
  py::array_t<double> expert_action() {
    const auto entered = threads_.enter("expert_action");
    check_started();
    if (ee_mode_) throw std::runtime_error("expert_action: the expert's actions are torques (make_env(..., action_mode='torque'))");
    int s = 0;
    {
      py::gil_scoped_release release;
      expert_.act(torques_, s);
    }
    expert_s_ = s;
    py::array_t<double> out(Action::size(n_));
    Action::pack(torques_, s, out.mutable_unchecked<1>());
    return out;
  }

  /// The current frame from the environment's camera (any time after reset; needs render=True).
  py::array_t<std::uint8_t> render() {
    const auto entered = threads_.enter("render");
    check_started();
    if (!renderer_) throw std::runtime_error("render: make the environment with render=True");
    update_frame();
    return renderer_->render();
  }

  py::dict action_space() const { return ee_mode_ ? ee_action_spec() : task_action_spec(n_); }
  std::string action_mode() const { return ee_mode_ ? "ee_pose" : "torque"; }
  int action_repeat() const { return ee_mode_ ? track_.config().action_repeat : 1; }

  py::dict observation_space() const {
    py::dict d;
    d["instruction"] = py::make_tuple(py::make_tuple(), "str");
    if (render_) {
      const auto& cam = camera_ ? *camera_ : ms::render::Camera{};
      d["image"] = py::make_tuple(py::make_tuple(cam.height, cam.width, 3), "uint8");
    }
    if (privileged_) {
      d["end_effector"] = py::make_tuple(py::make_tuple(4, 4), "float64");
      d["gripper_pose"] = py::make_tuple(py::make_tuple(4, 4), "float64");
      d["rod_nodes"] = py::make_tuple(py::make_tuple(n_ + 1, 3), "float64");
      d["gripper_width"] = py::make_tuple(py::make_tuple(), "float64");
      d["gripper_state"] = py::make_tuple(py::make_tuple(), "int64");
      d["object_poses"] = py::make_tuple(py::make_tuple(-1, 4, 4), "float64");  // -1: the scene's object count
    }
    return d;
  }

  /// From any thread (the renderer's objects are left to its context when it is current elsewhere).
  void close() {
    const auto entered = threads_.enter("close", true);
    renderer_.reset();
    gl_.reset();
    closed_ = true;
  }
  int horizon() const { return env_.config().horizon; }
  int n_elements() const { return n_; }
  std::string scene_json() const {
    check_started();
    return ms::scene::to_json_string(spec_);
  }
  std::string expert_phase() const { return std::string(ms::task::to_string(expert_.phase())); }

 private:
  void check_open() const {
    if (closed_) throw std::runtime_error("the environment is closed");
  }
  void check_started() const {
    check_open();
    if (!started_) throw std::runtime_error("call reset() before step()");
  }

  /// Reads a flat action into `torques`; returns S. Refuses before anything changes.
  int read_action(const py::handle& given, Array3& torques) const {
    const auto values = finite_action(given, Action::size(n_), "step: action must have shape (" + std::to_string(Action::size(n_)) + ",) (n x 3 torques then S)",
                                      [&](int i) { return Action::describe(i, n_); });
    return Action::unpack(values.unchecked<1>(), torques);
  }

  /// A step's action as float64: a real 1-D array of `size` finite entries, else ValueError (the
  /// dtype; `shape_text` with the shape given; the entry i that is not finite, described by
  /// describe(i)). Refused before anything changes.
  template <typename Describe>
  static py::array_t<double> finite_action(const py::handle& given, py::ssize_t size, const std::string& shape_text, Describe describe) {
    const py::array action = action_array(given, "step: action");
    const char kind = action.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
      throw py::value_error("step: action dtype must be real (float64 preferred), got " + std::string(py::str(action.dtype())));
    if (action.ndim() != 1 || action.shape(0) != size)
      throw py::value_error(shape_text + ", got " + std::string(py::str(py::handle(action).attr("shape"))));
    auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(action);
    const auto v = values.unchecked<1>();
    for (py::ssize_t i = 0; i < v.shape(0); ++i)
      if (!std::isfinite(v(i)))
        throw py::value_error("step: action entry " + std::to_string(i) + " (" + describe(static_cast<int>(i)) + ") is not finite");
    return values;
  }

  /// One "ee_pose" action: the target commanded, then action_repeat control steps (fewer when the
  /// episode ends). The reward is 1 when the task succeeds within them.
  py::tuple step_end_effector(const py::handle& given) {
    static constexpr const char* names[7] = {"x", "y", "z", "rx", "ry", "rz", "S"};
    const auto values = finite_action(given, 7, "step: an ee_pose action must have shape (7,) (position, rotation vector, S)",
                                      [](int i) { return std::string(names[i]); });
    const auto v = values.unchecked<1>();
    ms::task::EeAction a;
    for (int c = 0; c < 7; ++c) a(c) = v(c);
    const ms::math::Pose<double> target = ms::task::ee_target_of(a, env_.home_pose().rotation);
    const int s = v(6) >= 0.5 ? 1 : 0;
    ms::task::EeCommand command{};
    int taken = 0;
    {
      py::gil_scoped_release release;
      command = track_.command(target);
      for (; taken < track_.config().action_repeat && !env_.done(); ++taken) {
        track_.act(torques_);
        env_.step(torques_, s);
      }
    }
    const auto& i = env_.info();
    py::dict d = info();
    d["ee_command"] = std::string(ms::task::to_string(command));
    d["control_steps"] = taken;
    return py::make_tuple(observation(), i.success ? 1.0 : 0.0, i.terminated, i.truncated, d);
  }

  std::vector<ms::math::Pose<double>> object_poses() const {
    std::vector<ms::math::Pose<double>> out;
    for (const auto& o : env_.snapshot().objects) out.push_back(o.pose);
    return out;
  }

  ms::math::Pose<double> gripper_pose() const {
    const auto& w = env_.world();
    return {w.rigid().orientation(w.gripper_body()).toRotationMatrix(), w.rigid().position(w.gripper_body())};
  }

  void update_frame() {
    const auto& w = env_.world();
    renderer_->set_state(w.rod().state().positions, gripper_pose(), w.gripper().finger_width(), object_poses());
  }

  py::dict observation() {
    py::dict o;
    o["instruction"] = instruction_;
    if (renderer_) {
      update_frame();
      o["image"] = renderer_->render();
    }
    if (privileged_) {
      const auto& w = env_.world();
      const auto frame = w.soft().end_effector_frame();
      o["end_effector"] = matrix_of(ms::math::Pose<double>{frame.rotation, frame.position});
      o["gripper_pose"] = matrix_of(gripper_pose());
      const auto& x = w.rod().state().positions;
      py::array_t<double> nodes({static_cast<py::ssize_t>(x.rows()), py::ssize_t{3}});
      auto nv = nodes.mutable_unchecked<2>();
      for (Eigen::Index i = 0; i < x.rows(); ++i)
        for (int c = 0; c < 3; ++c) nv(i, c) = x(i, c);
      o["rod_nodes"] = nodes;
      o["gripper_width"] = w.gripper().finger_width();
      o["gripper_state"] = w.gripper().state();
      const auto poses = object_poses();
      py::array_t<double> objects({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
      auto ov = objects.mutable_unchecked<3>();
      for (std::size_t i = 0; i < poses.size(); ++i) {
        const Eigen::Matrix4d m = poses[i].matrix();
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) ov(static_cast<py::ssize_t>(i), r, c) = m(r, c);
      }
      o["object_poses"] = objects;
    }
    return o;
  }

  py::dict info() const {
    const auto& i = env_.info();
    py::dict d;
    d["success"] = i.success;
    d["success_at_end"] = env_.success_at_end();
    d["steps"] = i.step;
    d["done"] = i.done;
    d["failure"] = i.done && !i.success ? py::object(py::str(std::string(ms::task::to_string(i.failure)))) : py::object(py::none());
    py::dict conditions;  // the predicate's named conditions at this step (success: all hold)
    for (const auto& c : env_.conditions()) conditions[py::str(std::string(c.name))] = c.holds;
    d["conditions"] = conditions;
    d["clamped"] = i.clamped;
    d["task"] = std::string(ms::scene::to_string(spec_.task));
    d["setting"] = std::string(ms::scene::to_string(spec_.setting));
    d["split"] = std::string(ms::scene::to_string(spec_.split));
    d["index"] = spec_.index;
    d["seed"] = spec_.seed;
    d["instruction_kind"] = instruction_kind_;
    return d;
  }

  ms::scene::SceneSampler sampler_;
  ms::task::TaskEnv env_;
  ms::task::Expert expert_;
  ms::task::EndEffectorTrack track_;
  bool ee_mode_ = false;
  int expert_s_ = 0;  ///< the expert's S after its last expert_action()
  ms::scene::SampleRequest request_;
  std::uint64_t seed_;
  std::uint64_t next_index_ = 0;
  bool render_;
  bool privileged_;
  std::optional<ms::render::Camera> camera_;
  std::unique_ptr<PolicyRenderer> gl_;
  std::optional<SceneRenderer<PolicyRenderer>> renderer_;
  ms::scene::SceneSpec spec_;
  std::string instruction_, instruction_kind_ = "canonical";
  int n_ = 0;
  Array3 torques_;
  bool started_ = false;
  bool closed_ = false;
  ThreadUse threads_;
};

}  // namespace manisoft_py
