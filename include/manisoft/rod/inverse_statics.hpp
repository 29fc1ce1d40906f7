// Inverse statics of a clamped Cosserat rod arm (discrete Cosserat rod of Gazzola et al. 2018 as
// in PyElastica; used by the ManiSoft executor, paper section 3.4): finds a
// static shape whose tip frame (last node, last element's directors) is a target SE(3) pose, and
// the material-frame element torques that make that shape an exact equilibrium of the discrete
// rod of rod/internal_forces.hpp.
//
// Shape family. The curvature/twist at Voronoi point k (arc length s_k, sigma = s_k / L) is a
// quadratic per material axis, kappa_i(s) = c_{3i} + c_{3i+1} sigma + c_{3i+2} sigma^2 (9
// coefficients, 1/m). Directors follow the rod's own discrete operator
//   Q_{k+1} = exp(-[kappa_k l0v_k]x) Q_k          (so that kappa_k = -log(Q_{k+1} Q_k^T) / l0v_k),
// from the clamped Q_0. Positions carry the shear/stretch that statics requires: the lab-frame
// internal force of element k is the sum of the external loads beyond it (gravity m_j g on every
// node j > k plus the payload m_p g on the tip node), n_k = S (e_k Q_k t_k - e3) with
// n_k = e_k Q_k (that force), solved for u_k = e_k Q_k t_k by fixed-point iteration, and
// x_{k+1} = x_k + l0_k Q_k^T u_k. Gravity and the payload then enter the torque balance through
// the shear couple (Q t x n) l0 exactly as in the simulated rod (a shape built without shear
// would drop gravity from the torques).
//
// Feed-forward. tau_ff = -(internal torque of the rod at the desired state, zero velocities):
// every element except the clamped one is in exact torque balance and every free node in exact
// force balance, so the desired state is an equilibrium to round-off. The clamped element 0
// carries no actuator (its rates are zeroed by the boundary condition): its entry is set to 0.
//
// Solver. Levenberg-Marquardt on the 6 tip-pose residuals
//   r = [p(c) - p*;  w_rot log(R*^T R(c))]
// plus a small regularizer mu c^T W c, where c^T W c is a curvature norm weighted like the
// elastic actuation effort: sum over actuated elements of |B (kappa_k - kappa_{k-1})|^2 / tau_ref^2
// (a Sobolev norm of kappa; it prefers shapes the torque limits can hold) plus eps int |kappa|^2.
// A few minimum-W-norm Gauss-Newton steps with mu = 0 then remove the regularizer's bias, so the
// returned shape meets the target to ~1e-12 m. The Jacobian is analytic (below). Warm start:
// solve() starts from the previous solution. Cold targets (solve_cold) start from the entries of
// a start library whose tip poses are nearest the target (1500 deterministic random curvature
// profiles within the actuation limits, built at construction), then the previous solution and
// the straight shape, on a budget of LM iterations over all starts.
// Model estimates (set_model_estimates): the feed-forward can assume a stiffness scale and a
// payload other than the model's without re-solving the shape (used by the model executor).
// No heap allocation after construction.
//
// Length: the shape family, its tip Jacobian, the feed-forward and the solver share the
// discretisation above and form one solver (longer than the project's usual 600 lines for that reason).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "manisoft/rod/actuation_limits.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/math/so3.hpp"
#include "manisoft/rod/internal_forces.hpp"

namespace manisoft::rod {

/// What the inverse statics (and the model executor) assume about the arm: a uniform clamped
/// rod (its RodModel), the clamp pose, uniform gravity and a point payload on the tip node.
template <typename Scalar>
struct ArmModel {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  RodModel<Scalar> rod;
  Vector3 base_position = Vector3::Zero();
  Matrix3 base_directors = Matrix3::Identity();  ///< Q_0, rows d1, d2, d3 (lab)
  Vector3 gravity{0, 0, Scalar(-9.81)};           ///< m/s^2
  Scalar payload_mass = Scalar(0.2);              ///< kg, point mass on the tip node (gripper)
};

/// The arm model of a straight rod built from `params` (its base pose is the clamp).
template <typename Scalar>
ArmModel<Scalar> make_arm_model(const RodParameters<Scalar>& params, Scalar payload_mass = Scalar(0.2),
                                const Eigen::Matrix<Scalar, 3, 1>& gravity = {0, 0, Scalar(-9.81)}) {
  manisoft::detail::require_non_negative("payload_mass", payload_mass);
  if (!gravity.allFinite()) manisoft::detail::fail("gravity = (", gravity.transpose(), ") is invalid: it must be finite");
  ArmModel<Scalar> m;
  m.rod = make_rod_model(params);
  const RodState<Scalar> s = make_straight_rod_state(params);
  m.base_position = s.position(0);
  m.base_directors = s.director(0);
  m.gravity = gravity;
  m.payload_mass = payload_mass;
  return m;
}

template <typename Scalar>
struct InverseStaticsSettings {
  Scalar rotation_weight = Scalar(0.5);       ///< w_rot, m/rad in the residual
  Scalar regularization = Scalar(1e-7);       ///< mu (dimensionless, on the effort norm)
  Scalar reference_torque = Scalar(10);       ///< tau_ref of the effort norm, N m
  Scalar curvature_weight = Scalar(1e-2);     ///< eps of int |kappa|^2 ds (relative)
  int max_iterations = 60;                    ///< LM iterations per start
  int polish_iterations = 12;                 ///< effort-minimizing SQP steps after LM
  Scalar tolerance = Scalar(1e-11);           ///< |r| at which a solve stops, m
  Scalar accept_error = Scalar(1e-6);         ///< |r| below which a solve counts as converged
  Scalar polish_threshold = Scalar(1e-2);     ///< |r| after LM below which the polish runs, m
  int library_size = 1500;                    ///< start shapes of solve_cold's library
  int cold_starts = 6;                        ///< starts tried by solve_cold (library + last + straight)
  int cold_iteration_budget = 120;            ///< LM iterations of solve_cold over all starts
  Scalar relief_threshold = Scalar(0.6);      ///< solve_near: torque ratio above which it relieves the actuators
  Scalar relief_step = Scalar(0.5);           ///< solve_near: largest relief step (coefficient change, 1/m)
  int relief_iterations = 2;                  ///< solve_near: relief steps per call (0: off)
};

template <typename Scalar>
struct InverseStaticsResult {
  bool converged = false;          ///< tip pose met to accept_error
  Scalar position_error = 0;       ///< |p(c) - p*|, m
  Scalar rotation_error = 0;       ///< |log(R*^T R(c))|, rad
  int iterations = 0;              ///< LM + polish iterations used
  int lm_iterations = 0;           ///< LM iterations used
  Scalar max_torque_ratio = 0;     ///< max over elements/components of |tau_ff| / limit
  bool within_limits = false;      ///< converged and max_torque_ratio <= 1
};

template <typename Scalar>
class InverseStatics {
 public:
  static constexpr int n_coefficients = 9;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Coefficients = Eigen::Matrix<Scalar, n_coefficients, 1>;
  using Residual = Eigen::Matrix<Scalar, 6, 1>;
  using Jacobian = Eigen::Matrix<Scalar, 6, n_coefficients>;
  using Matrix9 = Eigen::Matrix<Scalar, n_coefficients, n_coefficients>;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Pose = math::Pose<Scalar>;

  explicit InverseStatics(ArmModel<Scalar> model, InverseStaticsSettings<Scalar> settings = {},
                          ActuationLimits<Scalar> limits = {})
      : model_(std::move(model)), settings_(settings), limits_(limits), workspace_(model_.rod.n_elements) {
    const int n = model_.rod.n_elements;
    if (n < 3) manisoft::detail::fail("InverseStatics needs a rod of at least 3 elements, got ", n);
    manisoft::detail::require_positive("InverseStatics rotation_weight", settings_.rotation_weight);
    manisoft::detail::require_non_negative("InverseStatics regularization", settings_.regularization);
    manisoft::detail::require_positive("InverseStatics reference_torque", settings_.reference_torque);
    manisoft::detail::require_non_negative("InverseStatics curvature_weight", settings_.curvature_weight);
    if (!(settings_.relief_threshold > 0 && settings_.relief_threshold < 1))
      manisoft::detail::fail("InverseStatics relief_threshold = ", settings_.relief_threshold, " must be in (0, 1)");
    manisoft::detail::require_non_negative("InverseStatics relief_step", settings_.relief_step);
    if (settings_.relief_iterations < 0) manisoft::detail::fail("InverseStatics relief_iterations = ", settings_.relief_iterations, " must be >= 0");
    manisoft::detail::require_positive("ActuationLimits bend", limits_.bend);
    manisoft::detail::require_positive("ActuationLimits twist", limits_.twist);
    if (!model_.base_position.allFinite() || !model_.base_directors.allFinite())
      manisoft::detail::fail("InverseStatics: the base pose is not finite");
    const Matrix3 should_be_identity = model_.base_directors * model_.base_directors.transpose();
    if ((should_be_identity - Matrix3::Identity()).norm() > Scalar(1e-6))
      manisoft::detail::fail("InverseStatics: base_directors is not a rotation (|Q Q^T - I| = ",
                   (should_be_identity - Matrix3::Identity()).norm(), ")");
    sigma_.resize(n - 1);
    Scalar s = 0;
    for (int k = 0; k < n - 1; ++k) {
      s += model_.rod.rest_lengths[k];
      sigma_[k] = s / model_.rod.total_length();
    }
    // Lab-frame internal force of each element: the sum of external loads on the nodes beyond it.
    distal_force_.resize(n, 3);
    Vector3 acc = model_.gravity * model_.payload_mass;
    for (int k = n - 1; k >= 0; --k) {
      acc += model_.gravity * model_.rod.node_masses[k + 1];
      distal_force_.row(k) = acc.transpose();
      const Scalar softest = std::max({Scalar(1) / model_.rod.shear_stiffness(k, 0), Scalar(1) / model_.rod.shear_stiffness(k, 1),
                                       Scalar(1) / model_.rod.shear_stiffness(k, 2)});
      if (!(acc.norm() * softest < Scalar(0.5)))
        manisoft::detail::fail("InverseStatics: element ", k, " would shear or stretch by ", acc.norm() * softest,
                               " under the weight it carries (at most 0.5): the rod is too soft for its load");
    }
    build_regularizer();
    state_.positions.setZero(n + 1, 3);
    state_.velocities.setZero(n + 1, 3);
    state_.directors.setZero(n, 9);
    state_.angular_velocities.setZero(n, 3);
    state_.external_forces.setZero(n + 1, 3);
    state_.external_torques.setZero(n, 3);
    directors_.resize(n);
    rotation_a_.assign(n - 1, Scalar(1));
    rotation_b_.assign(n - 1, Scalar(0.5));
    positions_cache_.assign(n + 1, model_.base_position);
    feedforward_.setZero(n, 3);
    elastic_torques_.setZero(n, 3);
    payload_torques_.setZero(n, 3);
    payload_estimate_ = model_.payload_mass;
    coefficients_.setZero();
    shape(coefficients_);
    commit();
    build_library();
  }

  const ArmModel<Scalar>& model() const { return model_; }
  const ActuationLimits<Scalar>& limits() const { return limits_; }
  const InverseStaticsSettings<Scalar>& settings() const { return settings_; }
  int n_elements() const { return model_.rod.n_elements; }

  /// Forward statics: the tip pose of the shape with curvature coefficients c (fills the
  /// internal shape buffers; does not change the committed solution).
  Pose tip_pose(const Coefficients& c) {
    shape(c);
    return Pose{directors_[n_elements() - 1].transpose(), tip_};
  }

  /// Forward statics: node positions ((n + 1) x 3, lab) of the shape with coefficients c (does
  /// not change the committed solution; `positions` must have n + 1 rows). Does not allocate.
  void shape_positions(const Coefficients& c, Array3& positions) {
    if (positions.rows() != n_elements() + 1) manisoft::detail::fail("InverseStatics::shape_positions: positions has ", positions.rows(), " rows, expected ", n_elements() + 1);
    shape(c);
    for (int k = 0; k <= n_elements(); ++k) positions.row(k) = positions_cache_[k].transpose();
  }

  /// Solves for `target` starting from the last solution (warm start). Does not allocate.
  InverseStaticsResult<Scalar> solve(const Pose& target) { return solve_from(target, coefficients_); }

  /// Solves for a new, unrelated target: tries the start shapes of the start library whose tip
  /// poses are nearest the target (then the last solution and the straight shape), stops at the
  /// first converged solution within the actuation limits, else keeps the converged one with the
  /// smallest actuation (or the smallest residual if none converged). At most
  /// `cold_starts` starts and `cold_iteration_budget` LM iterations in all. Does not allocate.
  InverseStaticsResult<Scalar> solve_cold(const Pose& target) {
    require_finite_target(target);
    const Coefficients previous = coefficients_;
    // The nearest library entries by d = |dp| + w_rot |dR| (partial selection, no allocation).
    constexpr int max_near = 8;
    std::array<int, max_near> near;
    std::array<Scalar, max_near> near_d;
    const int n_near = std::min(max_near, std::max(0, settings_.cold_starts - 2));
    int found = 0;
    for (int i = 0; i < static_cast<int>(library_.size()); ++i) {
      const Scalar d = (library_[i].tip.translation - target.translation).norm() +
                       settings_.rotation_weight * math::so3::log(Matrix3(target.rotation.transpose() * library_[i].tip.rotation)).norm();
      if (found < n_near) {
        near[found] = i;
        near_d[found] = d;
        ++found;
      } else if (n_near > 0 && d < near_d[n_near - 1]) {
        near[n_near - 1] = i;
        near_d[n_near - 1] = d;
      } else {
        continue;
      }
      for (int j = found - 1; j > 0 && near_d[j] < near_d[j - 1]; --j) {
        std::swap(near_d[j], near_d[j - 1]);
        std::swap(near[j], near[j - 1]);
      }
    }
    InverseStaticsResult<Scalar> best;
    Coefficients best_c = previous;
    Scalar best_score = std::numeric_limits<Scalar>::infinity();
    int budget = settings_.cold_iteration_budget;
    const int n_starts = found + 2;
    for (int i = 0; i < n_starts && budget > 0; ++i) {
      const Coefficients start = i < found ? library_[near[i]].coefficients : (i == found ? previous : Coefficients::Zero());
      const InverseStaticsResult<Scalar> r = solve_impl(target, start, std::min(settings_.max_iterations, budget));
      budget -= std::max(1, r.lm_iterations);
      const Scalar residual = r.position_error + settings_.rotation_weight * r.rotation_error;
      // Converged solutions rank by actuation, the others after them by residual.
      const Scalar score = r.converged ? r.max_torque_ratio : Scalar(1e6) + residual;
      if (score < best_score) {
        best_score = score;
        best = r;
        best_c = coefficients_;
      }
      if (r.within_limits) break;
    }
    shape(best_c);
    coefficients_ = best_c;
    commit();
    return best;
  }

  /// The start library of solve_cold (built on first use, or here): `library_size` curvature
  /// profiles drawn deterministically (curvature at s = 0, L/2, L uniform in +-6 1/m bend,
  /// +-3 1/m twist), kept if their feed-forward is within the actuation limits, with their tip poses.
  void build_library() {
    if (library_built_) return;
    library_built_ = true;
    const Coefficients saved = coefficients_;
    library_.reserve(static_cast<std::size_t>(settings_.library_size));
    std::uint64_t state = 0x2545F4914F6CDD1Dull;
    auto uniform = [&state]() {  // splitmix64 -> [-1, 1)
      state += 0x9E3779B97F4A7C15ull;
      std::uint64_t z = state;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      z ^= z >> 31;
      return Scalar(2) * Scalar(z >> 11) * Scalar(1.0 / 9007199254740992.0) - Scalar(1);
    };
    for (int tries = 0; tries < 20 * settings_.library_size && static_cast<int>(library_.size()) < settings_.library_size; ++tries) {
      Coefficients c;
      for (int axis = 0; axis < 3; ++axis) {
        const Scalar amp = axis < 2 ? Scalar(6) : Scalar(3);
        const Scalar k0 = amp * uniform(), k1 = amp * uniform(), k2 = amp * uniform();
        // kappa(0) = k0, kappa(1/2) = k1, kappa(1) = k2
        c[3 * axis] = k0;
        c[3 * axis + 1] = -Scalar(3) * k0 + Scalar(4) * k1 - k2;
        c[3 * axis + 2] = Scalar(2) * k0 - Scalar(4) * k1 + Scalar(2) * k2;
      }
      shape(c);
      commit();
      if (max_torque_ratio() > Scalar(1)) continue;
      library_.push_back(LibraryEntry{c, Pose{directors_[n_elements() - 1].transpose(), tip_}});
    }
    shape(saved);
    coefficients_ = saved;
    commit();
  }

  /// Solves from an explicit start; the result becomes the committed solution.
  InverseStaticsResult<Scalar> solve_from(const Pose& target, const Coefficients& start) {
    return solve_impl(target, start, settings_.max_iterations);
  }

  /// Solves for a target near the shape `start` by minimum-effort-norm Gauss-Newton steps only
  /// (stage 3 below, at most `max_iterations`): the smallest change of the shape (in the effort
  /// norm W) that meets the target, so a path of nearby targets gives a continuous shape
  /// sequence. No LM, no polish: ~4 iterations for a 1 cm step. When the solution's largest
  /// torque ratio exceeds relief_threshold, up to relief_iterations small steps at the same tip
  /// pose lower it (relieve()): a path's shapes then bend around the actuation limits instead of
  /// running into them. The result becomes the committed solution; when it has not converged the
  /// caller can fall back to solve_from. Does not allocate.
  InverseStaticsResult<Scalar> solve_near(const Pose& target, const Coefficients& start, int max_iterations = 8) {
    require_finite_target(target);
    if (!start.allFinite()) manisoft::detail::fail("InverseStatics: the start coefficients are not finite");
    Coefficients c = start;
    Residual r = residual(c, target);
    int it = newton(target, c, r, max_iterations, true);
    if (r.norm() < settings_.accept_error) it += relieve(target, c, r);
    shape(c);
    coefficients_ = c;
    commit();
    return make_result(r, it, 0);
  }

  /// Solves for a tip position only, the tip rotation left free, near the shape `start`:
  /// minimum-effort-norm Gauss-Newton steps on the 3 position residuals (at most
  /// `max_iterations`), then, while the largest torque ratio exceeds `relief_ratio`, up to
  /// `relief_iterations` relief steps along the shapes with the same tip position (as
  /// solve_near's, in the 6-dimensional null space of the position Jacobian). For shapes
  /// between two poses whose tips should stay on a line (the model executor's line vias). The
  /// result (rotation_error 0) becomes the committed solution. Does not allocate.
  InverseStaticsResult<Scalar> solve_position_near(const Vector3& position, const Coefficients& start, Scalar relief_ratio,
                                                   int relief_iterations, int max_iterations = 12) {
    if (!position.allFinite()) manisoft::detail::fail("InverseStatics: the target position is not finite");
    if (!start.allFinite()) manisoft::detail::fail("InverseStatics: the start coefficients are not finite");
    if (!(relief_ratio > 0 && relief_ratio <= 1)) manisoft::detail::fail("InverseStatics: relief_ratio = ", relief_ratio, " must be in (0, 1]");
    if (relief_iterations < 0 || max_iterations < 0)
      manisoft::detail::fail("InverseStatics: relief_iterations = ", relief_iterations, " and max_iterations = ", max_iterations, " must be >= 0");
    Coefficients c = start;
    Vector3 r = position_residual(c, position);
    int it = position_newton(position, c, r, max_iterations);
    if (r.norm() < settings_.accept_error)
      it += relieve_along<3>(c, relief_ratio, relief_iterations, [&](const Coefficients& at) { return position_jacobian(at); },
                             [&](Coefficients& trial, int& newton_iterations) {
                               Vector3 r_trial = position_residual(trial, position);
                               newton_iterations += position_newton(position, trial, r_trial, 4);
                               return r_trial.norm() < settings_.accept_error;
                             });
    r = position_residual(c, position);  // (leaves c's shape in the buffers for commit())
    coefficients_ = c;
    commit();
    Residual full = Residual::Zero();
    full.template head<3>() = r;
    return make_result(full, it, 0);
  }

 private:
  Vector3 position_residual(const Coefficients& c, const Vector3& position) {
    shape(c);
    return tip_ - position;
  }

  /// The position rows of the analytic Jacobian (jacobian() with the rotation residual zero).
  Eigen::Matrix<Scalar, 3, n_coefficients> position_jacobian(const Coefficients& c) {
    shape(c);
    const Pose here{directors_[n_elements() - 1].transpose(), tip_};
    jacobian(c, Residual::Zero(), here);
    return jacobian_.template topRows<3>();
  }

  InverseStaticsResult<Scalar> solve_impl(const Pose& target, const Coefficients& start, int max_iterations) {
    require_finite_target(target);
    if (!start.allFinite()) manisoft::detail::fail("InverseStatics: the start coefficients are not finite");
    Coefficients c = start;
    Residual r = residual(c, target);
    const int lm_it = levenberg_marquardt(target, max_iterations, c, r);
    int it = lm_it;
    // A start whose LM did not get near a solution is not worth polishing (solve_cold moves on).
    if (r.norm() < settings_.polish_threshold) it += polish(target, c, r);
    it += newton(target, c, r, 3);
    shape(c);
    coefficients_ = c;
    commit();
    return make_result(r, it, lm_it);
  }

  InverseStaticsResult<Scalar> make_result(const Residual& r, int it, int lm_it) const {
    InverseStaticsResult<Scalar> result;
    result.position_error = r.template head<3>().norm();
    result.rotation_error = r.template tail<3>().norm() / settings_.rotation_weight;
    result.iterations = it;
    result.lm_iterations = lm_it;
    result.converged = std::isfinite(r.norm()) && r.norm() < settings_.accept_error;
    result.max_torque_ratio = max_torque_ratio();
    result.within_limits = result.converged && result.max_torque_ratio <= Scalar(1);
    return result;
  }

  /// Stage 1: Levenberg-Marquardt on the regularized objective from c; returns its iterations.
  int levenberg_marquardt(const Pose& target, int max_iterations, Coefficients& c, Residual& r) {
    Scalar cost = objective(r, c, settings_.regularization);
    Scalar lambda = Scalar(1e-3);
    int it = 0;
    for (; it < max_iterations && r.norm() > settings_.tolerance; ++it) {
      jacobian(c, r, target);
      const Scalar mu = settings_.regularization;
      const Matrix9 a = jacobian_.transpose() * jacobian_ + mu * regularizer_;
      const Coefficients g = jacobian_.transpose() * r + mu * regularizer_ * c;
      bool improved = false, stalled = false;
      for (int tries = 0; tries < 8; ++tries) {
        Matrix9 damped = a;
        damped.diagonal() += lambda * (a.diagonal().array() + Scalar(1e-9)).matrix();
        const Coefficients step = -damped.ldlt().solve(g);
        const Coefficients trial = c + step;
        const Residual r_trial = residual(trial, target);
        const Scalar cost_trial = objective(r_trial, trial, mu);
        if (std::isfinite(cost_trial) && cost_trial < cost) {
          const Scalar decrease = cost - cost_trial;
          c = trial;
          r = r_trial;
          cost = cost_trial;
          // Converged to the regularized optimum: the polish below removes its small bias.
          if (step.norm() < Scalar(1e-7) || decrease < Scalar(1e-6) * cost) stalled = true;
          lambda = std::max(lambda * Scalar(0.3), Scalar(1e-9));
          improved = true;
          break;
        }
        lambda *= Scalar(10);
      }
      if (!improved || stalled) break;
    }
    return it;
  }

  /// Stage 2 (polish): Gauss-Newton steps on the constraint r = 0 that also minimize the effort
  /// norm of the new point (SQP on  min c^T W c  s.t. r(c) = 0):
  ///   c+ = argmin |c + d|_W  s.t.  J d = -r   =>   c+ = W^-1 J^T (J W^-1 J^T)^-1 (J c - r).
  /// This removes mu's bias and slides along the 3-dimensional solution manifold to the least
  /// effortful shape near the LM solution. A step is kept while the residual stays small.
  /// Returns its iterations.
  int polish(const Pose& target, Coefficients& c, Residual& r) {
    const Scalar residual_cap = std::max(Scalar(10) * r.norm(), Scalar(1e-4));
    int p = 0;
    for (; p < settings_.polish_iterations; ++p) {
      jacobian(c, r, target);
      const Eigen::Matrix<Scalar, n_coefficients, 6> wj = regularizer_inverse_ * jacobian_.transpose();
      const Eigen::Matrix<Scalar, 6, 6> m = jacobian_ * wj;
      const Coefficients proposal = wj * m.ldlt().solve(jacobian_ * c - r);
      Coefficients trial = proposal;
      Residual r_trial = residual(trial, target);
      for (int half = 0; half < 6 && !(r_trial.norm() < residual_cap); ++half) {
        trial = Scalar(0.5) * (trial + c);
        r_trial = residual(trial, target);
      }
      if (!(r_trial.norm() < residual_cap)) break;
      const Scalar effort_change = trial.dot(regularizer_ * trial) - c.dot(regularizer_ * c);
      const bool done = r_trial.norm() < settings_.tolerance && std::abs(effort_change) < Scalar(1e-9) * (Scalar(1) + c.dot(regularizer_ * c));
      c = trial;
      r = r_trial;
      if (done) break;
    }
    return p;
  }

  /// Actuator relief (solve_near): while the shape's largest torque ratio exceeds
  /// relief_threshold, a step along the shapes with the same tip pose (the null space of the tip
  /// Jacobian, steepest descent in the W metric: gradient projection, Liegeois 1977) lowers the
  /// effort E(c) = sum over actuated entries of (tau_ff / limit)^8 (a smooth stand-in for the
  /// largest ratio, gradient by forward differences); Newton steps then return to the target. The
  /// step's length (Euclidean, in coefficients) grows from 0 at the threshold to relief_step at
  /// the limit, so a path's shapes change gradually (the executor's continuity check sees every
  /// step). A step is kept only if it meets the target and lowers E. Returns the Newton
  /// iterations used.
  int relieve(const Pose& target, Coefficients& c, Residual& r) {
    const int used = relieve_along<6>(c, settings_.relief_threshold, settings_.relief_iterations,
                                      [&](const Coefficients& at) -> Jacobian {
                                        jacobian(at, r, target);
                                        return jacobian_;
                                      },
                                      [&](Coefficients& trial, int& newton_iterations) {
                                        Residual r_trial = residual(trial, target);
                                        newton_iterations += newton(target, trial, r_trial, 4);
                                        return r_trial.norm() < settings_.accept_error;
                                      });
    r = residual(c, target);
    return used;
  }

  /// relieve() along the shapes that keep `Rows` constraints (the tip pose: 6, the tip position:
  /// 3): jacobian_of(c) gives their Jacobian, restore(trial, used) returns a trial step to them
  /// (adding its Newton iterations to `used`) and says whether it met them. Returns `used`.
  template <int Rows, typename JacobianOf, typename Restore>
  int relieve_along(Coefficients& c, Scalar threshold, int iterations, JacobianOf jacobian_of, Restore restore) {
    int used = 0;
    Scalar ratio = 0;
    Scalar e0 = effort(c, ratio);
    for (int step = 0; step < iterations; ++step) {
      if (!(ratio > threshold)) break;
      // The W-projected descent -(I - W^-1 J^T (J W^-1 J^T)^-1 J) W^-1 grad E equals -N N^T grad E
      // for a W-orthonormal basis N of the null space of J (N^T W N = I, J N = 0): with W = L L^T,
      // N = L^-T Y, Y an orthonormal basis of the null space of J L^-T (the last columns of a QR
      // of its transpose). So E is differentiated along the columns of N only (forward
      // differences), not along all 9 coefficients.
      const Eigen::Matrix<Scalar, Rows, n_coefficients> j = jacobian_of(c);
      const Eigen::Matrix<Scalar, n_coefficients, Rows> a_t = (j * regularizer_factor_inverse_t_).transpose();
      const Eigen::ColPivHouseholderQR<Eigen::Matrix<Scalar, n_coefficients, Rows>> qr(a_t);
      const Matrix9 q = qr.householderQ();
      constexpr int n_free = n_coefficients - Rows;
      const Eigen::Matrix<Scalar, n_coefficients, n_free> basis = regularizer_factor_inverse_t_ * q.template rightCols<n_free>();
      const Scalar c_scale = Scalar(1) + c.template lpNorm<Eigen::Infinity>();
      Eigen::Matrix<Scalar, n_free, 1> slope;
      for (int k = 0; k < n_free; ++k) {
        const Scalar h = Scalar(1e-6) * c_scale / basis.col(k).template lpNorm<Eigen::Infinity>();
        Scalar unused = 0;
        slope[k] = (effort(c + h * basis.col(k), unused) - e0) / h;
      }
      const Coefficients d = -(basis * slope);  // W-projected descent
      const Scalar d_norm = d.norm();
      if (!(d_norm > Scalar(0))) break;
      const Scalar strength = std::min(Scalar(1), (ratio - threshold) / (Scalar(1) - threshold));
      const Scalar length = settings_.relief_step * strength;
      bool kept = false;
      for (int half = 0; half < 4 && !kept; ++half) {
        Coefficients trial = c + std::ldexp(length / d_norm, -half) * d;
        Coefficients restored = trial;
        if (!restore(restored, used)) continue;
        Scalar trial_ratio = 0;
        const Scalar e_trial = effort(restored, trial_ratio);
        if (e_trial < e0) {
          c = restored;
          e0 = e_trial;
          ratio = trial_ratio;
          kept = true;
        }
      }
      if (!kept) break;
    }
    return used;
  }

  /// E(c) of relieve() and the largest torque ratio (commits c's shape to the feed-forward buffers).
  Scalar effort(const Coefficients& c, Scalar& max_ratio) {
    shape(c);
    commit();
    Scalar e = 0;
    for (int k = 1; k < n_elements(); ++k)
      for (int i = 0; i < 3; ++i) {
        const Scalar x = feedforward_(k, i) / limits_.limit(i), x2 = x * x, x4 = x2 * x2;
        e += x4 * x4;
      }
    max_ratio = max_torque_ratio();
    return e;
  }

  /// Stage 3: final Newton steps (minimum-W-norm step) so the shape meets the target to
  /// round-off; returns its iterations.
  int newton(const Pose& target, Coefficients& c, Residual& r, int max_iterations, bool halving = false) {
    return min_norm_newton<6>(c, r, max_iterations, halving,
                              [&](const Coefficients& at) -> const Jacobian& {
                                jacobian(at, r, target);
                                return jacobian_;
                              },
                              [&](const Coefficients& at) { return residual(at, target); });
  }

  /// newton() on the tip position alone, halving its steps (the line vias start away from the line).
  int position_newton(const Vector3& position, Coefficients& c, Vector3& r, int max_iterations) {
    return min_norm_newton<3>(c, r, max_iterations, true, [&](const Coefficients& at) { return position_jacobian(at); },
                              [&](const Coefficients& at) { return position_residual(at, position); });
  }

  /// Gauss-Newton on `Rows` residuals (residual_of(c), Jacobian jacobian_of(c)) by minimum-W-norm
  /// steps; with `halving`, a step that does not lower |r| is halved up to 4 times (far from the
  /// solution a full step can overshoot). Stops below `tolerance` or when a step does not help;
  /// returns its iterations.
  template <int Rows, typename JacobianOf, typename ResidualOf>
  int min_norm_newton(Coefficients& c, Eigen::Matrix<Scalar, Rows, 1>& r, int max_iterations, bool halving, JacobianOf jacobian_of,
                      ResidualOf residual_of) {
    int p = 0;
    for (; p < max_iterations && r.norm() > settings_.tolerance; ++p) {
      const Eigen::Matrix<Scalar, Rows, n_coefficients> j = jacobian_of(c);
      const Eigen::Matrix<Scalar, n_coefficients, Rows> wj = regularizer_inverse_ * j.transpose();
      const Eigen::Matrix<Scalar, Rows, Rows> m = j * wj;
      const Coefficients step = wj * m.ldlt().solve(r);
      Coefficients trial = c - step;
      Eigen::Matrix<Scalar, Rows, 1> r_trial = residual_of(trial);
      for (int half = 0; halving && half < 4 && !(r_trial.norm() < r.norm()); ++half) {
        trial = c - std::ldexp(Scalar(1), -(half + 1)) * step;
        r_trial = residual_of(trial);
      }
      if (!(r_trial.norm() < r.norm())) break;
      c = trial;
      r = r_trial;
    }
    return p;
  }

 public:
  /// Online model corrections (model executor): the feed-forward assumes the elastic torques
  /// scaled by `stiffness_scale` (a Young's/shear modulus error) and a tip payload of
  /// `payload_mass` kg instead of the model's. The desired shape is unchanged (its shear
  /// stretch, ~1e-3 relative, keeps the model's values); only the feed-forward moves:
  ///   tau_ff = -(tau_internal + (s - 1) tau_elastic + (m - m_model) tau_payload),
  /// tau_elastic the bend/twist part of the internal torque at the desired shape and
  /// tau_payload the shear couple (Q t x e Q g) l0 of a 1 kg tip mass.
  void set_model_estimates(Scalar stiffness_scale, Scalar payload_mass) {
    if (!(stiffness_scale > 0) || !std::isfinite(stiffness_scale) || !(payload_mass >= 0) || !std::isfinite(payload_mass))
      manisoft::detail::fail("InverseStatics: model estimates refused (stiffness scale ", stiffness_scale, ", payload ", payload_mass, " kg)");
    stiffness_scale_ = stiffness_scale;
    payload_estimate_ = payload_mass;
    apply_estimates();
  }
  Scalar stiffness_scale() const { return stiffness_scale_; }
  Scalar payload_estimate() const { return payload_estimate_; }
  /// Bend/twist part of the internal torque at the desired shape (nominal stiffness), n x 3.
  const Array3& elastic_torques() const { return elastic_torques_; }
  /// Internal torque change at the desired shape per kg of tip payload, n x 3.
  const Array3& payload_torques() const { return payload_torques_; }

  /// Shape change per unit relative scaling of the committed curvature (c -> (1 + e) c, by a
  /// forward difference): node positions (n + 1) x 3 and the tip rotation (lab rotation vector).
  /// A stiffness error s / s_hat of the arm bends it, to first order and without feedback, to the
  /// curvature (s_hat / s) c. Does not allocate (uses the solver's shape buffers).
  void curvature_scale_direction(Array3& positions, Vector3& tip_rotation) {
    constexpr Scalar e = Scalar(1e-4);
    shape(Scalar(1 + e) * coefficients_);
    const int n = n_elements();
    positions.row(0).setZero();
    for (int k = 1; k <= n; ++k) positions.row(k) = (positions_cache_[k].transpose() - state_.positions.row(k)) / e;
    tip_rotation = math::so3::log(Matrix3(directors_[n - 1].transpose() * state_.director(n - 1))) / e;
  }

  /// Makes c the committed solution (shape and feed-forward) without solving.
  void set_coefficients(const Coefficients& c) {
    if (!c.allFinite()) manisoft::detail::fail("InverseStatics: coefficients are not finite");
    shape(c);
    coefficients_ = c;
    commit();
  }

  // ---- the committed solution
  const Coefficients& coefficients() const { return coefficients_; }
  /// The desired static state (positions, directors; zero rates).
  const RodState<Scalar>& desired_state() const { return state_; }
  /// Feed-forward material-frame element torques, n x 3 (row 0, the clamped element, is 0).
  const Array3& feedforward() const { return feedforward_; }
  /// The desired shape's tip pose (body to lab).
  Pose desired_tip_pose() const { return state_.tip_pose(); }
  /// Curvature at Voronoi point k of coefficients c (material frame, 1/m).
  Vector3 curvature(const Coefficients& c, int k) const {
    const Scalar s = sigma_[k];
    return Vector3(c[0] + s * (c[1] + s * c[2]), c[3] + s * (c[4] + s * c[5]), c[6] + s * (c[7] + s * c[8]));
  }

 private:
  static void require_finite_target(const Pose& target) { math::require_valid_pose(target, "InverseStatics target"); }

  Scalar objective(const Residual& r, const Coefficients& c, Scalar mu) const {
    return r.squaredNorm() + mu * c.dot(regularizer_ * c);
  }

  Residual residual(const Coefficients& c, const Pose& target) {
    shape(c);
    Residual r;
    r.template head<3>() = tip_ - target.translation;
    const Matrix3 tip_rotation = directors_[n_elements() - 1].transpose();
    r.template tail<3>() = settings_.rotation_weight * math::so3::log(target.rotation.transpose() * tip_rotation);
    return r;
  }

  /// Analytic Jacobian of the residual at c. Perturbing kappa_k by d rotates everything beyond
  /// Voronoi point k by the lab-frame angle omega = G_k d, G_k = l0v_k Q_k^T J_r(-kappa_k l0v_k)
  /// (right-perturbation Jacobian of SO(3), [Sola (143)]), about node k + 1:
  ///   d p_tip = omega x (p_tip - x_{k+1}),   d log(R*^T R) = J_r^-1(log(R*^T R)) R^T omega.
  /// The change of the small shear offsets with orientation (S^-1 ~ 1e-3 relative) is neglected:
  /// Gauss-Newton then still converges, linearly at a rate ~1e-3.
  void jacobian(const Coefficients& c, const Residual& r, const Pose& target) {
    (void)r;
    shape(c);
    const int n = n_elements();
    const Matrix3 tip_rotation = directors_[n - 1].transpose();
    Matrix3 jr_inv;
    math::so3::log(target.rotation.transpose() * tip_rotation, &jr_inv);
    const Matrix3 rot_map = settings_.rotation_weight * jr_inv * tip_rotation.transpose();
    jacobian_.setZero();
    for (int k = 0; k < n - 1; ++k) {
      const Scalar l0v = model_.rod.rest_voronoi_lengths[k];
      const Vector3 phi = -curvature(c, k) * l0v;
      // J_r(phi) = I - B [phi]x + C [phi]x^2, C = (theta - sin theta) / theta^3 = (1 - A) / theta^2
      // (A, B of this phi from shape(); the series below theta^2 = 1e-6).
      const Scalar theta2 = phi.squaredNorm();
      const Scalar cc = theta2 < Scalar(1e-6) ? Scalar(1) / Scalar(6) - theta2 / Scalar(120) : (Scalar(1) - rotation_a_[k]) / theta2;
      const Matrix3 right_jacobian = (Scalar(1) - cc * theta2) * Matrix3::Identity() - rotation_b_[k] * math::so3::hat(phi) + cc * phi * phi.transpose();
      const Matrix3 g = l0v * directors_[k].transpose() * right_jacobian;
      const Vector3 arm = tip_ - positions_cache_[k + 1];
      Eigen::Matrix<Scalar, 6, 3> block;
      block.template topRows<3>() = -math::so3::hat(arm) * g;
      block.template bottomRows<3>() = rot_map * g;
      const Scalar s = sigma_[k];
      for (int axis = 0; axis < 3; ++axis) {
        jacobian_.col(3 * axis) += block.col(axis);
        jacobian_.col(3 * axis + 1) += s * block.col(axis);
        jacobian_.col(3 * axis + 2) += s * s * block.col(axis);
      }
    }
  }

  /// Forward statics of coefficients c into directors_ and the shape's node positions (state_
  /// positions are only written by commit()). The shape depends on c alone, so the buffers are
  /// reused when they already hold c's shape (the solvers evaluate the same c several times).
  void shape(const Coefficients& c) {
    if (shape_known_ && c == shape_of_) return;
    const int n = n_elements();
    const auto& rod = model_.rod;
    directors_[0] = model_.base_directors;
    for (int k = 0; k < n - 1; ++k) {
      // Exp(phi) = I + A [phi]x + B [phi]x^2 = (1 - B theta^2) I + A [phi]x + B phi phi^T with
      // A = sin(theta) / theta, B = (1 - cos theta) / theta^2, from one sine and cosine of theta / 2.
      const Vector3 phi = -curvature(c, k) * rod.rest_voronoi_lengths[k];
      const Scalar theta2 = phi.squaredNorm(), half = Scalar(0.5) * std::sqrt(theta2);
      const Scalar half_sinc = math::detail::sin_over_angle(half);
      const Scalar a = half_sinc * std::cos(half), b = Scalar(0.5) * half_sinc * half_sinc;
      rotation_a_[k] = a;
      rotation_b_[k] = b;
      const Matrix3 rotation = (Scalar(1) - b * theta2) * Matrix3::Identity() + a * math::so3::hat(phi) + b * phi * phi.transpose();
      directors_[k + 1] = rotation * directors_[k];
    }
    Vector3 x = model_.base_position;
    for (int k = 0; k < n; ++k) {
      const Matrix3& q = directors_[k];
      const Vector3 force_material = q * distal_force_.row(k).transpose();
      const Vector3 compliance(Scalar(1) / rod.shear_stiffness(k, 0), Scalar(1) / rod.shear_stiffness(k, 1),
                               Scalar(1) / rod.shear_stiffness(k, 2));
      // u = b + |u| l with b = sigma0 + e3, l = S^-1 Q f (|l| ~ 1e-3): s = |u| is the positive
      // root of (1 - |l|^2) s^2 - 2 (b . l) s - |b|^2 = 0 (|l| < 1/2 checked at construction).
      const Vector3 base = rod.rest_sigma.row(k).transpose() + Vector3::UnitZ();
      const Vector3 load = compliance.cwiseProduct(force_material);
      const Scalar bl = base.dot(load), a = Scalar(1) - load.squaredNorm();
      const Scalar stretch = (bl + std::sqrt(bl * bl + a * base.squaredNorm())) / a;
      const Vector3 u = base + stretch * load;
      x += rod.rest_lengths[k] * (q.transpose() * u);
      positions_cache_[k + 1] = x;
    }
    tip_ = x;
    shape_of_ = c;
    shape_known_ = true;
  }

  /// Copies the current shape buffers into the desired state and recomputes the feed-forward.
  void commit() {
    const int n = n_elements();
    state_.positions.row(0) = model_.base_position.transpose();
    for (int k = 1; k <= n; ++k) state_.positions.row(k) = positions_cache_[k].transpose();
    for (int k = 0; k < n; ++k) state_.set_director(k, directors_[k]);
    compute_internal_forces_and_torques(model_.rod, state_, workspace_);
    // Split the internal torque into its shear couple (Q t x n) l0 (the loads) and the rest
    // (bend/twist couples, stiffness-proportional); n = e Q F with F the distal load.
    for (int k = 0; k < n; ++k) {
      const Matrix3 q = state_.director(k);
      const Vector3 qt = q * workspace_.tangents.row(k).transpose();
      const Vector3 stress = workspace_.internal_stress.row(k).transpose();
      const Scalar l0 = model_.rod.rest_lengths[k];
      const Vector3 shear = l0 * qt.cross(stress);
      elastic_torques_.row(k) = workspace_.internal_torques.row(k) - shear.transpose();
      payload_torques_.row(k) = (l0 * workspace_.dilatation[k]) * qt.cross(q * model_.gravity).transpose();
    }
    apply_estimates();
  }

  void apply_estimates() {
    feedforward_ = -workspace_.internal_torques - (stiffness_scale_ - Scalar(1)) * elastic_torques_ -
                   (payload_estimate_ - model_.payload_mass) * payload_torques_;
    feedforward_.row(0).setZero();
  }

  Scalar max_torque_ratio() const {
    Scalar worst = 0;
    for (int k = 1; k < n_elements(); ++k)
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(feedforward_(k, i)) / limits_.limit(i));
    return worst;
  }

  /// W = T^T T / tau_ref^2 + eps int kappa^2: T maps c to the elastic part of the element torques
  /// B (kappa_k - kappa_{k-1}) of elements 1 .. n-1 (kappa_{n-1} = 0 past the tip).
  void build_regularizer() {
    const int n = n_elements();
    const auto& rod = model_.rod;
    regularizer_.setZero();
    const Scalar inv_ref2 = Scalar(1) / (settings_.reference_torque * settings_.reference_torque);
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Matrix<Scalar, 3, 3> block = Eigen::Matrix<Scalar, 3, 3>::Zero();
      for (int k = 1; k < n; ++k) {
        Eigen::Matrix<Scalar, 3, 1> row = Eigen::Matrix<Scalar, 3, 1>::Zero();
        auto basis = [&](int v) { return Eigen::Matrix<Scalar, 3, 1>(1, sigma_[v], sigma_[v] * sigma_[v]); };
        const Scalar b_here = k < n - 1 ? rod.bend_stiffness(k, axis) : Scalar(0);
        const Scalar b_prev = rod.bend_stiffness(k - 1, axis);
        if (k < n - 1) row += b_here * basis(k);
        row -= b_prev * basis(k - 1);
        block += row * row.transpose() * inv_ref2;
      }
      // int kappa^2 ds scaled to the same units: eps * (B / tau_ref)^2 * (Voronoi sum)
      Eigen::Matrix<Scalar, 3, 3> mass = Eigen::Matrix<Scalar, 3, 3>::Zero();
      for (int k = 0; k < n - 1; ++k) {
        const Eigen::Matrix<Scalar, 3, 1> b(1, sigma_[k], sigma_[k] * sigma_[k]);
        const Scalar scale = rod.bend_stiffness(k, axis) * rod.bend_stiffness(k, axis) * inv_ref2 * rod.rest_voronoi_lengths[k];
        mass += scale * b * b.transpose();
      }
      regularizer_.template block<3, 3>(3 * axis, 3 * axis) = block + settings_.curvature_weight * mass;
    }
    regularizer_inverse_ = regularizer_.ldlt().solve(Matrix9::Identity());
    // W = L L^T; relieve() uses L^-T.
    const Eigen::LLT<Matrix9> llt(regularizer_);
    if (llt.info() != Eigen::Success) manisoft::detail::fail("InverseStatics: the effort norm W is not positive definite");
    regularizer_factor_inverse_t_ = llt.matrixU().solve(Matrix9::Identity());
  }

  ArmModel<Scalar> model_;
  InverseStaticsSettings<Scalar> settings_;
  ActuationLimits<Scalar> limits_;
  RodWorkspace<Scalar> workspace_;
  RodState<Scalar> state_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> sigma_;
  Array3 distal_force_;
  std::vector<Matrix3> directors_;
  std::vector<Vector3> positions_cache_;
  Vector3 tip_ = Vector3::Zero();
  std::vector<Scalar> rotation_a_, rotation_b_;   ///< A, B of each Voronoi point's rotation (shape())
  Coefficients shape_of_ = Coefficients::Zero();  ///< the coefficients whose shape the buffers hold
  bool shape_known_ = false;
  Array3 feedforward_;
  Array3 elastic_torques_, payload_torques_;
  Scalar stiffness_scale_ = Scalar(1);
  Scalar payload_estimate_ = Scalar(0);
  Coefficients coefficients_;
  struct LibraryEntry {
    Coefficients coefficients;
    Pose tip;
  };
  std::vector<LibraryEntry> library_;
  bool library_built_ = false;
  Jacobian jacobian_;
  Matrix9 regularizer_;
  Matrix9 regularizer_inverse_;
  Matrix9 regularizer_factor_inverse_t_;  ///< L^-T, W = L L^T
};

}  // namespace manisoft::rod
