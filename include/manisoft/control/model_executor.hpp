// Model-based executor (the low-level executor of the ManiSoft paper, section 3.4): inverse statics feed-forward, node
// velocity and position feedback mapped to element torques, an online estimate of the arm's
// stiffness scale, and an outer loop on the measured end-effector pose.
//
// Model it assumes (rod::ArmModel): a uniform clamped Cosserat rod with known rest geometry,
// density and Young's/shear moduli, uniform gravity, and a known point payload on the tip node
// (the gripper); the end-effector frame is the tip frame (last node, last element's directors).
// A stiffness error is estimated online (below); anything else (an unknown held load, the
// damping of the simulated rod) is left to the feedback and the outer loop.
//
// Per control step, action = clamp(tau_ff + tau_fb), element 0 (clamped) = 0; from the tip
// inwards, what the clamp cuts off an element is added to the next proximal element
// (carry_saturation): the couple carried across every other node is then still the one asked for
// (sum_{j >= k} tau_j), only the node between the two elements sees the difference (without it,
// targets near the limits slip into a slow saturated oscillation; BENCHMARKS.md, "Executor").
//   tau_ff    the inverse statics feed-forward of the current shape target (inverse_statics.hpp),
//             with the elastic part scaled by the stiffness estimate s_hat;
//   tau_fb    node forces F_j = -m_j (kd v_j + kp (x_j - x*_j)) (positions and velocities of
//             unobserved nodes interpolated linearly between observed ones; the tip node carries
//             the payload mass too) turned into the statically equivalent element couples. A set
//             of couples m_i is equivalent to node forces F_j when it gives the same moment at
//             every cross-section:
//               m_k = (x_{k+1} - x_k) x sum_{j > k} F_j        (lab; to material with Q_k),
//             the same lever-arm form as the rod's own shear couple (Q t x n) l0. Q_k is the
//             desired director turned by the smallest rotation taking the desired element
//             tangent onto the observed one. The position term matters beyond steady-state
//             accuracy: the feed-forward torques are follower (material-frame) loads, and on
//             strongly curled shapes the equilibrium they hold flutters unless the feedback is
//             stiff enough (the gains' choice: BENCHMARKS.md, "Executor").
//   twist     the position feedback cannot see twist: a twist couple -k_tw phi (s_k / L) on every
//             element, phi the twist of the observed end-effector frame about the tip tangent
//             relative to the estimated tip frame, holds the twist of curled shapes (without it
//             strongly curled shapes can twist off to another equilibrium branch).
//   ramp      a new target's shape is reached through the coefficient blend of the old and new
//             inverse statics solutions (smoothstep) over max(ramp_steps, tip path / ramp_max_speed)
//             control steps (at most max_ramp_steps): a blend whose tip sweeps a long path (it
//             can be several times the arm's length) is slowed so the arm can follow it.
//   stiffness estimate (after the ramp, while every observed node is slower than
//             estimate_speed_gate and no actuator saturates): a stiffness error s/s_hat bends the arm, to first order, to
//             the curvature (s_hat/s) c* of the desired one. Every `outer_period` steps the
//             observed node deviations (and the tip rotation deviation) averaged over the period
//             are regressed on the shape change of a relative curvature scaling, beta, and
//             s_hat <- s_hat (1 - g beta). With the right s_hat the desired shape is again an exact
//             equilibrium of the arm.
//   outer loop every `outer_period` control steps while quasi-static: with the pose error
//             averaged over the period, e_p = p* - p, e_R = log(R* R^T) (lab), the shape target
//             moves by  p_s <- p_s + K e_p,  R_s <- Exp(K e_R) R_s,  and the inverse statics is
//             re-solved (warm started) for the shifted target: integral action on the SE(3) tip
//             error for what the stiffness estimate does not explain (an unknown load).
// Only the observation is used: target, node positions/velocities, the end-effector pose.
// No heap allocation in act() after the first call for a target; the inverse statics set-up of a
// new target runs inside that call.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <Eigen/Geometry>

#include "manisoft/control/executor.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/math/so3.hpp"

namespace manisoft::control {

template <typename Scalar>
struct ModelExecutorSettings {
  Scalar damping_gain = Scalar(35);        ///< kd, 1/s: node force -kd m v
  Scalar position_gain = Scalar(800);      ///< kp, 1/s^2: node force -kp m (x - x_desired), same mapping
  Scalar outer_gain = Scalar(0.1);         ///< K per outer update (0 disables the outer loop)
  int outer_period = 20;                   ///< control steps between outer (and estimate) updates
  int outer_delay = 60;                    ///< control steps after the ramp before the first outer update
  int ramp_steps = 250;                    ///< control steps of the shape ramp to a new target (minimum)
  int max_ramp_steps = 800;                ///< longest ramp
  Scalar ramp_max_speed = Scalar(0.006);   ///< m per control step: mean tip speed along the ramp's path
  Scalar outer_speed_gate = Scalar(0.15);  ///< m/s: integrate only while every observed node is slower
  Scalar outer_max_shift = Scalar(0.3);    ///< bound on |p_s - p*| (m) and |log(R_s R*^T)| (rad)
  Scalar stiffness_gain = Scalar(1);       ///< g of the stiffness-scale estimate (0: off)
  int estimate_delay = 20;                 ///< control steps after the ramp before estimating
  Scalar estimate_speed_gate = Scalar(1);  ///< m/s: estimate only while every observed node is slower
  Scalar min_stiffness_scale = Scalar(0.5);  ///< bounds of s_hat
  bool carry_saturation = true;            ///< a clamped element's excess goes to the next proximal one
  Scalar max_stiffness_scale = Scalar(2);
  Scalar twist_gain = Scalar(20);          ///< N m/rad: twist couple -k phi_tip (s_k / L) on the tip twist error
  Scalar twist_damping = Scalar(0);        ///< N m s/rad: twist couple -c w_tip (s_k / L) from end-effector
                                           ///< pose differences (0: off; BENCHMARKS.md has the runs)
};

template <typename ScalarType>
class ModelExecutor {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Pose = math::Pose<Scalar>;

  ModelExecutor(rod::ArmModel<Scalar> model, rod::ActuationLimits<Scalar> limits, ModelExecutorSettings<Scalar> settings = {},
                rod::InverseStaticsSettings<Scalar> statics = {})
      : statics_(std::move(model), statics, limits), settings_(settings) {
    manisoft::detail::require_non_negative("ModelExecutor damping_gain", settings_.damping_gain);
    manisoft::detail::require_non_negative("ModelExecutor outer_gain", settings_.outer_gain);
    manisoft::detail::require_non_negative("ModelExecutor position_gain", settings_.position_gain);
    if (settings_.ramp_steps < 0) manisoft::detail::fail("ModelExecutor ramp_steps = ", settings_.ramp_steps, " must be >= 0");
    if (settings_.max_ramp_steps < settings_.ramp_steps)
      manisoft::detail::fail("ModelExecutor max_ramp_steps = ", settings_.max_ramp_steps, " must be >= ramp_steps = ", settings_.ramp_steps);
    manisoft::detail::require_positive("ModelExecutor ramp_max_speed", settings_.ramp_max_speed);
    if (settings_.outer_period < 1) manisoft::detail::fail("ModelExecutor outer_period = ", settings_.outer_period, " must be >= 1");
    if (settings_.outer_delay < 0) manisoft::detail::fail("ModelExecutor outer_delay = ", settings_.outer_delay, " must be >= 0");
    manisoft::detail::require_positive("ModelExecutor outer_max_shift", settings_.outer_max_shift);
    manisoft::detail::require_non_negative("ModelExecutor stiffness_gain", settings_.stiffness_gain);
    manisoft::detail::require_non_negative("ModelExecutor twist_damping", settings_.twist_damping);
    manisoft::detail::require_non_negative("ModelExecutor twist_gain", settings_.twist_gain);
    if (settings_.estimate_delay < 0) manisoft::detail::fail("ModelExecutor estimate_delay = ", settings_.estimate_delay, " must be >= 0");
    if (!(settings_.min_stiffness_scale > 0) || !(settings_.max_stiffness_scale >= settings_.min_stiffness_scale) ||
        !std::isfinite(settings_.max_stiffness_scale))
      manisoft::detail::fail("ModelExecutor stiffness scale bounds [", settings_.min_stiffness_scale, ", ", settings_.max_stiffness_scale, "] are invalid");
    const int n = statics_.n_elements();
    positions_.setZero(n + 1, 3);
    velocities_.setZero(n + 1, 3);
    direction_.setZero(n + 1, 3);
    node_mass_ = statics_.model().rod.node_masses;
    node_mass_[n] += statics_.model().payload_mass;
  }

  /// Forgets the target; the arm is assumed straight at rest (the shape ramp starts there).
  void reset() {
    has_target_ = false;
    has_previous_ = false;
    steps_ = 0;
    statics_.set_model_estimates(Scalar(1), statics_.model().payload_mass);
    statics_.set_coefficients(rod::InverseStatics<Scalar>::Coefficients::Zero());
    adapt_count_ = 0;
  }

  void act(const Observation<Scalar>& o, Array3& action) {
    const int n = statics_.n_elements();
    validate_observation(o, n + 1);
    if (action.rows() != n) action.resize(n, 3);  // allocates only if the caller passed a wrong size
    if (!has_target_ || !same_pose(o.target, target_)) set_target(o.target);
    interpolate(o);
    advance_shape_target(o);
    const Scalar twist_rate = tip_twist_rate(o);
    const bool adapting = settings_.stiffness_gain > Scalar(0) && steps_ >= ramp_steps_ + settings_.estimate_delay &&
                          o.node_velocities.rowwise().norm().maxCoeff() <= settings_.estimate_speed_gate;
    const bool saturated = feedforward_plus_feedback(o, twist_rate, action);
    // A saturated actuator does not apply the torque the estimate assumes: no update then.
    if (adapting && !saturated) accumulate_estimate(o);
    ++steps_;
  }

  /// Sets up a new target (inverse statics from cold starts); act() calls it when the target changes.
  rod::InverseStaticsResult<Scalar> set_target(const Pose& target) {
    if (!target.is_finite()) manisoft::detail::fail("executor: target pose refused, it is not finite (translation = ", target.translation.transpose(), ")");
    target_ = target;
    shifted_ = target;
    has_target_ = true;
    steps_ = 0;
    error_sum_.setZero();
    error_count_ = 0;
    adapt_count_ = 0;
    ramp_start_ = statics_.coefficients();
    last_result_ = statics_.solve_cold(target);
    ramp_end_ = statics_.coefficients();
    // Ramp length: at least ramp_steps, longer when the blend's tip path (sampled) is long, so
    // that the mean tip speed along it stays below ramp_max_speed.
    ramp_path_ = 0;
    if (settings_.ramp_steps > 0) {
      Vector3 previous = statics_.tip_pose(ramp_start_).translation;
      for (int i = 1; i <= ramp_samples; ++i) {
        const Scalar x = Scalar(i) / Scalar(ramp_samples);
        const Vector3 p = statics_.tip_pose(ramp_start_ + x * x * (Scalar(3) - Scalar(2) * x) * (ramp_end_ - ramp_start_)).translation;
        ramp_path_ += (p - previous).norm();
        previous = p;
      }
    }
    const Scalar needed = ramp_path_ / settings_.ramp_max_speed;
    ramp_steps_ = settings_.ramp_steps == 0 ? 0 : std::clamp(static_cast<int>(std::ceil(needed)), settings_.ramp_steps, settings_.max_ramp_steps);
    statics_.set_coefficients(ramp_steps_ > 0 ? ramp_start_ : ramp_end_);
    return last_result_;
  }

  const rod::InverseStatics<Scalar>& statics() const { return statics_; }
  const rod::InverseStaticsResult<Scalar>& last_statics_result() const { return last_result_; }
  const ModelExecutorSettings<Scalar>& settings() const { return settings_; }
  const Pose& shape_target() const { return shifted_; }
  /// Control steps of the current target's shape ramp and the tip path length along it (m).
  int ramp_length() const { return ramp_steps_; }
  Scalar ramp_path() const { return ramp_path_; }
  /// The stiffness scale the feed-forward currently assumes (1 = the model's).
  Scalar stiffness_estimate() const { return statics_.stiffness_scale(); }

 private:
  /// Stage 1: the shape target of this step: along the ramp (every intermediate shape an exact
  /// equilibrium of the model), then the outer loop's corrections.
  void advance_shape_target(const Observation<Scalar>& o) {
    if (steps_ < ramp_steps_) {
      const Scalar x = Scalar(steps_ + 1) / Scalar(ramp_steps_);
      const Scalar blend = x * x * (Scalar(3) - Scalar(2) * x);
      statics_.set_coefficients(ramp_start_ + blend * (ramp_end_ - ramp_start_));
    } else {
      outer_loop(o);
    }
  }

  /// Stage 2: twist rate at the tip from successive end-effector poses (lab angular velocity . d3).
  Scalar tip_twist_rate(const Observation<Scalar>& o) {
    Scalar rate = 0;
    if (has_previous_ && o.time > previous_time_) {
      const Vector3 w = math::so3::log(Matrix3(o.end_effector.rotation * previous_rotation_.transpose())) / (o.time - previous_time_);
      if (w.allFinite()) rate = w.dot(o.end_effector.rotation.col(2));
    }
    previous_rotation_ = o.end_effector.rotation;
    previous_time_ = o.time;
    has_previous_ = true;
    return rate;
  }

  /// Stage 3: feed-forward plus the node feedback turned into element couples through the lever
  /// arms of the nodes beyond each element, the twist couple, clamped with the saturation carry.
  /// Returns whether an actuated element saturated.
  bool feedforward_plus_feedback(const Observation<Scalar>& o, Scalar twist_rate, Array3& action) const {
    const int n = statics_.n_elements();
    const Array3& ff = statics_.feedforward();
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    const auto& limits = statics_.limits();
    Vector3 distal = Vector3::Zero();
    Vector3 excess = Vector3::Zero();  // clamped-off torque carried to the next proximal element
    Scalar tip_twist = 0;
    bool saturated = false;
    for (int k = n - 1; k >= 0; --k) {
      distal -= node_mass_[k + 1] * (settings_.damping_gain * velocities_.row(k + 1).transpose() +
                                     settings_.position_gain * (positions_.row(k + 1) - desired.positions.row(k + 1)).transpose());
      const Vector3 lever = (positions_.row(k + 1) - positions_.row(k)).transpose();
      // Material frame of element k estimated from the desired one, turned by the smallest
      // rotation that takes the desired element tangent onto the observed one.
      const Vector3 desired_lever = (desired.positions.row(k + 1) - desired.positions.row(k)).transpose();
      const Matrix3 turn = Eigen::Quaternion<Scalar>::FromTwoVectors(desired_lever, lever).toRotationMatrix();
      const Matrix3 frame = desired.director(k) * turn.transpose();  // lab -> estimated material
      if (k == n - 1) {
        // Twist of the observed tip frame about the tip tangent relative to the estimated one.
        const Vector3 d = math::so3::log(Matrix3(o.end_effector.rotation * frame));
        tip_twist = d.allFinite() ? d.dot(lever.normalized()) : Scalar(0);
      }
      Vector3 couple = frame * lever.cross(distal);
      const Scalar share = (Scalar(k) + Scalar(0.5)) / Scalar(n);
      couple[2] -= share * (settings_.twist_gain * tip_twist + settings_.twist_damping * twist_rate);
      for (int i = 0; i < 3; ++i) {
        const Scalar lim = limits.limit(i);
        const Scalar a = ff(k, i) + couple[i] + (settings_.carry_saturation ? excess[i] : Scalar(0));
        if (k > 0 && std::abs(a) > lim) saturated = true;
        action(k, i) = std::clamp(a, -lim, lim);
        excess[i] = a - action(k, i);
      }
    }
    action.row(0).setZero();
    return saturated;
  }

  static bool same_pose(const Pose& a, const Pose& b) {
    return a.translation == b.translation && a.rotation == b.rotation;
  }

  /// Node positions and velocities of every node: the observed position errors (observed minus
  /// desired) and velocities interpolated linearly between observed nodes (held constant past
  /// the first/last observed node); positions = desired + interpolated error.
  void interpolate(const Observation<Scalar>& o) {
    const int n_nodes = statics_.n_elements() + 1;
    const rod::RodState<Scalar>& desired = statics_.desired_state();
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

  /// Stiffness-scale estimate from the observed shape: with the arm quasi-static, the deviation
  /// of the observed nodes (and the tip rotation) from the desired shape is regressed on the
  /// shape change of a relative curvature scaling (rod::InverseStatics::curvature_scale_direction);
  /// a stiffer arm (s > s_hat) bends less (beta < 0), so s_hat <- s_hat (1 - gain beta).
  void accumulate_estimate(const Observation<Scalar>& o) {
    if (adapt_count_ == 0) {
      statics_.curvature_scale_direction(direction_, direction_tip_);
      adapt_num_ = adapt_den_ = 0;
    }
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    Scalar num = 0, den = 0;
    for (Eigen::Index i = 0; i < o.node_indices.size(); ++i) {
      const int j = o.node_indices[i];
      if (j == 0) continue;
      const Vector3 u = direction_.row(j).transpose();
      const Vector3 d = (o.node_positions.row(i) - desired.positions.row(j)).transpose();
      num += u.dot(d);
      den += u.dot(u);
    }
    const Scalar w = statics_.settings().rotation_weight;
    const Matrix3 desired_tip = desired.tip_pose().rotation;
    const Vector3 dr = math::so3::log(Matrix3(o.end_effector.rotation * desired_tip.transpose()));
    num += w * w * direction_tip_.dot(dr);
    den += w * w * direction_tip_.squaredNorm();
    if (!std::isfinite(num) || !std::isfinite(den)) return;
    adapt_num_ += num;
    adapt_den_ += den;
    if (++adapt_count_ < settings_.outer_period) return;
    adapt_count_ = 0;
    if (!(adapt_den_ > Scalar(1e-12))) return;
    const Scalar beta = std::clamp(adapt_num_ / adapt_den_, Scalar(-0.2), Scalar(0.2));
    const Scalar s = std::clamp(statics_.stiffness_scale() * (Scalar(1) - settings_.stiffness_gain * beta), settings_.min_stiffness_scale,
                                settings_.max_stiffness_scale);
    statics_.set_model_estimates(s, statics_.payload_estimate());
  }

  void outer_loop(const Observation<Scalar>& o) {
    if (settings_.outer_gain == Scalar(0) || steps_ < ramp_steps_ + settings_.outer_delay) return;
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
    const rod::InverseStaticsResult<Scalar> r = statics_.solve(next);
    if (r.converged) {
      shifted_ = next;
    } else {
      statics_.set_coefficients(previous);
    }
  }

  rod::InverseStatics<Scalar> statics_;
  ModelExecutorSettings<Scalar> settings_;
  rod::InverseStaticsResult<Scalar> last_result_;
  Pose target_, shifted_;
  typename rod::InverseStatics<Scalar>::Coefficients ramp_start_ = rod::InverseStatics<Scalar>::Coefficients::Zero();
  typename rod::InverseStatics<Scalar>::Coefficients ramp_end_ = rod::InverseStatics<Scalar>::Coefficients::Zero();
  bool has_target_ = false;
  static constexpr int ramp_samples = 24;
  int ramp_steps_ = 0;
  Scalar ramp_path_ = 0;
  long steps_ = 0;
  Array3 positions_, velocities_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> node_mass_;
  Eigen::Matrix<Scalar, 6, 1> error_sum_ = Eigen::Matrix<Scalar, 6, 1>::Zero();
  int error_count_ = 0;
  Matrix3 previous_rotation_ = Matrix3::Identity();
  Scalar previous_time_ = 0;
  bool has_previous_ = false;
  Array3 direction_;
  Vector3 direction_tip_ = Vector3::Zero();
  int adapt_count_ = 0;
  Scalar adapt_num_ = 0, adapt_den_ = 0;
};

}  // namespace manisoft::control
