// Model-based executor (issue 4 part 4; DESIGN.md section 8): inverse statics feed-forward, node
// velocity damping mapped to element torques, and an outer loop on the measured end-effector pose.
//
// Model it assumes (ArmModel): a uniform clamped Cosserat rod with known rest geometry,
// density and Young's/shear moduli, uniform gravity, and a known point payload on the tip node
// (the gripper); the end-effector frame is the tip frame (last node, last element's directors).
// Anything else (a stiffness error, an unknown held load, the damping of the simulated rod) is
// left to the feedback.
//
// Per control step, action = clamp(tau_ff + tau_damp), element 0 (clamped) = 0:
//   tau_ff    the inverse statics feed-forward of the current shape target (inverse_statics.hpp);
//   tau_damp  node forces F_j = -kd m_j v_j (velocities of unobserved nodes interpolated linearly
//             between observed ones; the tip node carries the payload mass too) turned into the
//             statically equivalent element couples. A set of couples m_i is equivalent to node
//             forces F_j when it gives the same moment at every cross-section:
//               m_k = (x_{k+1} - x_k) x sum_{j > k} F_j        (lab; to material with Q_k),
//             the same lever-arm form as the rod's own shear couple (Q t x n) l0.
//   outer loop every `outer_period` control steps: with the pose error averaged over the period,
//             e_p = p* - p, e_R = log(R* R^T) (lab), the shape target moves by
//               p_s <- p_s + K e_p,   R_s <- Exp(K e_R) R_s,
//             and the inverse statics is re-solved (warm started) for the shifted target. This is
//             integral action on the SE(3) tip error: it removes static errors from model errors
//             (Young's modulus, unknown loads). K and the period set its speed.
// No heap allocation in act() after the first call for a target; the inverse statics set-up of a
// new target runs inside that call.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <Eigen/Geometry>

#include "manisoft/control/executor.hpp"
#include "manisoft/control/inverse_statics.hpp"
#include "manisoft/math/so3.hpp"

namespace manisoft::control {

template <typename Scalar>
struct ModelExecutorSettings {
  Scalar damping_gain = Scalar(25);        ///< kd, 1/s
  Scalar position_gain = Scalar(200);     ///< kp, 1/s^2: node force -kp m (x - x_desired), same mapping
  Scalar outer_gain = Scalar(0.1);         ///< K per outer update (0 disables the outer loop)
  int outer_period = 20;                   ///< control steps between outer updates
  int outer_delay = 60;                    ///< control steps after the ramp before the first outer update
  int ramp_steps = 250;                    ///< control steps of the shape ramp to a new target
  Scalar outer_speed_gate = Scalar(0.15);  ///< m/s: integrate only while every observed node is slower
  Scalar outer_max_shift = Scalar(0.3);    ///< bound on |p_s - p*| (m) and |log(R_s R*^T)| (rad)
};

template <typename ScalarType>
class ModelExecutor {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Pose = math::Pose<Scalar>;

  ModelExecutor(ArmModel<Scalar> model, ActuationLimits<Scalar> limits, ModelExecutorSettings<Scalar> settings = {},
                InverseStaticsSettings<Scalar> statics = {})
      : statics_(std::move(model), statics, limits), settings_(settings) {
    detail::require_non_negative("ModelExecutor damping_gain", settings_.damping_gain);
    detail::require_non_negative("ModelExecutor outer_gain", settings_.outer_gain);
    detail::require_non_negative("ModelExecutor position_gain", settings_.position_gain);
    if (settings_.ramp_steps < 0) detail::fail("ModelExecutor ramp_steps = ", settings_.ramp_steps, " must be >= 0");
    if (settings_.outer_period < 1) detail::fail("ModelExecutor outer_period = ", settings_.outer_period, " must be >= 1");
    if (settings_.outer_delay < 0) detail::fail("ModelExecutor outer_delay = ", settings_.outer_delay, " must be >= 0");
    detail::require_positive("ModelExecutor outer_max_shift", settings_.outer_max_shift);
    const int n = statics_.n_elements();
    positions_.setZero(n + 1, 3);
    velocities_.setZero(n + 1, 3);
    node_mass_ = statics_.model().rod.node_masses;
    node_mass_[n] += statics_.model().payload_mass;
  }

  /// Forgets the target; the arm is assumed straight at rest (the shape ramp starts there).
  void reset() {
    has_target_ = false;
    steps_ = 0;
    statics_.set_coefficients(InverseStatics<Scalar>::Coefficients::Zero());
  }

  void act(const Observation<Scalar>& o, Array3& action) {
    const int n = statics_.n_elements();
    validate_observation(o, n + 1);
    if (action.rows() != n) action.resize(n, 3);  // allocates only if the caller passed a wrong size
    if (!has_target_ || !same_pose(o.target, target_)) set_target(o.target);
    interpolate(o);
    if (steps_ < settings_.ramp_steps) {
      // Quasi-static ramp: every intermediate shape is an exact equilibrium of the model.
      const Scalar x = Scalar(steps_ + 1) / Scalar(settings_.ramp_steps);
      const Scalar blend = x * x * (Scalar(3) - Scalar(2) * x);
      statics_.set_coefficients(ramp_start_ + blend * (ramp_end_ - ramp_start_));
    } else {
      outer_loop(o);
    }
    // Velocity damping as element couples through the lever arms of the nodes beyond each element.
    const Array3& ff = statics_.feedforward();
    const RodState<Scalar>& desired = statics_.desired_state();
    const auto& limits = statics_.limits();
    Vector3 distal = Vector3::Zero();
    for (int k = n - 1; k >= 0; --k) {
      distal -= node_mass_[k + 1] * (settings_.damping_gain * velocities_.row(k + 1).transpose() +
                                     settings_.position_gain * (positions_.row(k + 1) - desired.positions.row(k + 1)).transpose());
      const Vector3 lever = (positions_.row(k + 1) - positions_.row(k)).transpose();
      // Material frame of element k estimated from the desired one, turned by the smallest
      // rotation that takes the desired element tangent onto the observed one.
      const Vector3 desired_lever = (desired.positions.row(k + 1) - desired.positions.row(k)).transpose();
      const Matrix3 turn = Eigen::Quaternion<Scalar>::FromTwoVectors(desired_lever, lever).toRotationMatrix();
      const Vector3 couple = desired.director(k) * (turn.transpose() * lever.cross(distal));
      for (int i = 0; i < 3; ++i) {
        const Scalar lim = limits.limit(i);
        action(k, i) = std::clamp(ff(k, i) + couple[i], -lim, lim);
      }
    }
    action.row(0).setZero();
    ++steps_;
  }

  /// Sets up a new target (inverse statics from cold starts); act() calls it when the target changes.
  InverseStaticsResult<Scalar> set_target(const Pose& target) {
    if (!target.is_finite()) detail::fail("executor: target pose refused, it is not finite (translation = ", target.translation.transpose(), ")");
    target_ = target;
    shifted_ = target;
    has_target_ = true;
    steps_ = 0;
    error_sum_.setZero();
    error_count_ = 0;
    ramp_start_ = statics_.coefficients();
    last_result_ = statics_.solve_cold(target);
    ramp_end_ = statics_.coefficients();
    statics_.set_coefficients(settings_.ramp_steps > 0 ? ramp_start_ : ramp_end_);
    return last_result_;
  }

  const InverseStatics<Scalar>& statics() const { return statics_; }
  const InverseStaticsResult<Scalar>& last_statics_result() const { return last_result_; }
  const ModelExecutorSettings<Scalar>& settings() const { return settings_; }
  const Pose& shape_target() const { return shifted_; }

 private:
  static bool same_pose(const Pose& a, const Pose& b) {
    return a.translation == b.translation && a.rotation == b.rotation;
  }

  /// Node positions and velocities of every node: the observed position errors (observed minus
  /// desired) and velocities interpolated linearly between observed nodes (held constant past
  /// the first/last observed node); positions = desired + interpolated error.
  void interpolate(const Observation<Scalar>& o) {
    const int n_nodes = statics_.n_elements() + 1;
    const RodState<Scalar>& desired = statics_.desired_state();
    const auto m = o.node_indices.size();
    Eigen::Index seg = 0;
    for (int j = 0; j < n_nodes; ++j) {
      while (seg + 2 < m && o.node_indices[seg + 1] < j) ++seg;
      const int a = o.node_indices[seg], b = o.node_indices[seg + 1];
      const Scalar w = std::clamp(Scalar(j - a) / Scalar(b - a), Scalar(0), Scalar(1));
      const Eigen::Matrix<Scalar, 1, 3> ea = o.node_positions.row(seg) - desired.positions.row(a);
      const Eigen::Matrix<Scalar, 1, 3> eb = o.node_positions.row(seg + 1) - desired.positions.row(b);
      positions_.row(j) = desired.positions.row(j) + (Scalar(1) - w) * ea + w * eb;
      velocities_.row(j) = (Scalar(1) - w) * o.node_velocities.row(seg) + w * o.node_velocities.row(seg + 1);
    }
  }

  void outer_loop(const Observation<Scalar>& o) {
    if (settings_.outer_gain == Scalar(0) || steps_ < settings_.ramp_steps + settings_.outer_delay) return;
    Eigen::Matrix<Scalar, 6, 1> e;
    e.template head<3>() = target_.translation - o.end_effector.translation;
    e.template tail<3>() = math::so3::log(target_.rotation * o.end_effector.rotation.transpose());
    if (!e.allFinite()) return;
    // Integrate only while the arm is quasi-static: during transients the pose error is not the
    // static error the shape shift should remove, and integrating it winds up the loop.
    if (o.node_velocities.rowwise().norm().maxCoeff() > settings_.outer_speed_gate) return;
    error_sum_ += e;
    ++error_count_;
    if (error_count_ < settings_.outer_period) return;
    const Eigen::Matrix<Scalar, 6, 1> mean = error_sum_ / Scalar(error_count_);
    error_sum_.setZero();
    error_count_ = 0;
    const Scalar k = settings_.outer_gain;
    Pose next = shifted_;
    next.translation += k * mean.template head<3>();
    next.rotation = math::so3::exp(Vector3(k * mean.template tail<3>())) * shifted_.rotation;
    // Bound the shift away from the true target.
    Vector3 dp = next.translation - target_.translation;
    if (dp.norm() > settings_.outer_max_shift) next.translation = target_.translation + dp * (settings_.outer_max_shift / dp.norm());
    Vector3 dr = math::so3::log(next.rotation * target_.rotation.transpose());
    if (dr.norm() > settings_.outer_max_shift) next.rotation = math::so3::exp(Vector3(dr * (settings_.outer_max_shift / dr.norm()))) * target_.rotation;
    const auto previous = statics_.coefficients();
    const InverseStaticsResult<Scalar> r = statics_.solve(next);
    if (r.converged) {
      shifted_ = next;
    } else {
      statics_.set_coefficients(previous);
    }
  }

  InverseStatics<Scalar> statics_;
  ModelExecutorSettings<Scalar> settings_;
  InverseStaticsResult<Scalar> last_result_;
  Pose target_, shifted_;
  typename InverseStatics<Scalar>::Coefficients ramp_start_ = InverseStatics<Scalar>::Coefficients::Zero();
  typename InverseStatics<Scalar>::Coefficients ramp_end_ = InverseStatics<Scalar>::Coefficients::Zero();
  bool has_target_ = false;
  long steps_ = 0;
  Array3 positions_, velocities_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> node_mass_;
  Eigen::Matrix<Scalar, 6, 1> error_sum_ = Eigen::Matrix<Scalar, 6, 1>::Zero();
  int error_count_ = 0;
};

}  // namespace manisoft::control
