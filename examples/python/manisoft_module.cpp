// The `manisoft` Python module (pybind11): the soft-arm environments with Gymnasium's API,
// without depending on gymnasium. Today: the reach environment (env/reach_env.hpp, the paper's
// executor benchmark, section 3.4) and its model-based expert; the benchmark's task environments
// join it as they land.
//
//   import manisoft
//   env = manisoft.make_env("reach", target_set="table", seed=0)
//   obs, info = env.reset(seed=3)
//   obs, reward, terminated, truncated, info = env.step(env.expert_action())
//
// Actions: float64 (n x 3) material-frame element torques (other real dtypes are converted);
// clamped to the actuation limits (action_space["low"/"high"]). Bad input (shape, dtype, NaN, a
// call after close) raises ValueError / RuntimeError with the library's message; the GIL is
// released while the simulation steps.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "manisoft/control/model_executor.hpp"
#include "manisoft/env/reach_env.hpp"

namespace py = pybind11;

namespace {

using Env = manisoft::env::ReachEnv<>;  // PyElastica's analytical damping, element torques
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;

py::array_t<double> to_numpy(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& m) {
  py::array_t<double> out({m.rows(), m.cols()});
  auto view = out.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) view(r, c) = m(r, c);
  return out;
}

py::array_t<double> pose_matrix(const manisoft::math::Pose<double>& pose) { return to_numpy(pose.matrix()); }

class ReachEnvironment {
 public:
  ReachEnvironment(const std::string& target_set, std::uint64_t seed, int horizon)
      : env_(make_config(target_set, horizon), manisoft::rod::damping::AnalyticalLinear<double>(0.1)),
        expert_(env_.nominal_model(), env_.config().limits),
        next_seed_(seed),
        action_(Array3::Zero(env_.n_elements(), 3)) {}

  py::tuple reset(std::optional<std::uint64_t> seed, const std::optional<py::dict>& options) {
    check_open();
    if (options) {
      for (const auto& item : *options)
        throw py::value_error("reset: unknown option '" + py::str(item.first).cast<std::string>() + "' (the reach environment takes none)");
    }
    const std::uint64_t s = seed ? *seed : next_seed_;
    next_seed_ = s + 1;
    {
      py::gil_scoped_release release;
      observation_ = &env_.reset(s);
      expert_.reset();
    }
    started_ = true;
    return py::make_tuple(observation(), info());
  }

  py::tuple step(const py::array& action) {
    check_started();
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
    check_started();
    Array3 action(env_.n_elements(), 3);
    {
      py::gil_scoped_release release;
      expert_.act(*observation_, action);
    }
    return to_numpy(action);
  }

  py::dict action_space() const {
    const auto& limits = env_.config().limits;
    Array3 high(env_.n_elements(), 3);
    for (int k = 0; k < env_.n_elements(); ++k)
      for (int c = 0; c < 3; ++c) high(k, c) = k == 0 ? 0.0 : limits.limit(c);
    py::dict d;
    d["shape"] = py::make_tuple(env_.n_elements(), 3);
    d["dtype"] = "float64";
    d["low"] = to_numpy(-high);
    d["high"] = to_numpy(high);
    return d;
  }

  py::dict observation_space() const {
    const auto nodes = static_cast<int>(env_.config().rod.n_elements / env_.config().observe_stride + 1 +
                                        (env_.config().rod.n_elements % env_.config().observe_stride ? 1 : 0));
    py::dict d;
    d["end_effector"] = py::make_tuple(py::make_tuple(4, 4), "float64");
    d["target"] = py::make_tuple(py::make_tuple(4, 4), "float64");
    d["node_positions"] = py::make_tuple(py::make_tuple(nodes, 3), "float64");
    d["node_velocities"] = py::make_tuple(py::make_tuple(nodes, 3), "float64");
    d["time"] = py::make_tuple(py::make_tuple(), "float64");
    return d;
  }

  void close() { closed_ = true; }
  int horizon() const { return env_.config().horizon; }

 private:
  static manisoft::env::ReachEnvConfig make_config(const std::string& target_set, int horizon) {
    manisoft::env::ReachEnvConfig config;
    config.target_set = manisoft::env::parse_target_set(target_set);
    if (horizon < 1) manisoft::detail::fail("horizon = ", horizon, " must be >= 1");
    config.horizon = horizon;
    return config;
  }

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
};

}  // namespace

PYBIND11_MODULE(manisoft, m) {
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
      .def_property_readonly("action_space", &ReachEnvironment::action_space)
      .def_property_readonly("observation_space", &ReachEnvironment::observation_space)
      .def_property_readonly("horizon", &ReachEnvironment::horizon);
  m.def(
      "make_env",
      [](const std::string& name, const std::string& target_set, std::uint64_t seed, int horizon) {
        if (name != "reach") throw py::value_error("make_env: unknown environment '" + name + "' (available: reach)");
        return std::make_unique<ReachEnvironment>(target_set, seed, horizon);
      },
      py::arg("name"), py::arg("target_set") = "table", py::arg("seed") = 0, py::arg("horizon") = 1500,
      "Makes an environment: make_env('reach', target_set='table'|'equilibria', seed=0, horizon=1500)");
}
