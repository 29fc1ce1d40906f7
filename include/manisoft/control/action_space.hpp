// Action spaces of the soft arm (ManiSoft paper, section 3, "Simulator"): how an action
// becomes the material-frame element torques tau_e (n x 3, rows = elements, columns = d1, d2, d3)
// that drive the rod, under the actuators' limits. Two policy classes, one interface (ActionSpace):
//
//   ElementTorqueAction  the action is tau_e itself (n x 3), the paper's action.
//   BsplineMuscleAction  the action is K x 3 control values of a muscle couple profile T_d(s) per
//                        direction (d1, d2 bending, d3 twist), as Elastica-RL drives its arm:
//                        a not-a-knot cubic spline through the control values at equally spaced
//                        knots, evaluated at the nodes between elements, s_k = k l0 (reference
//                        arc length: the muscle is attached to material points), and applied as
//                        an internal couple (equal and opposite on the two sides of node k):
//                          tau_k = scale (T(s_k) - T(s_{k+1})),  tau_{n-1} = scale T(s_{n-1}),
//                        so the couple carried across node k (elements k..n-1 on the far side)
//                        is sum_{j >= k} tau_j = scale T(s_k): at equilibrium the muscle profile
//                        is the bending/twisting couple the arm holds there. (Elastica-RL
//                        evaluates T one element further out, at s = (k + 1) l0, on current
//                        lengths; forcing::ElasticaRLMuscleTorques keeps that rule.) Knots:
//                        `pinned_ends` (Elastica-RL) puts K interior knots in
//                        linspace(0, L, K + 2) with zero end values;
//                        otherwise K knots span linspace(0, L, K) and every value is free (a tip
//                        couple can then bend the last element, which holding a bent tip needs).
//
// Interface, both classes:
//   rows()                         rows of an action (3 columns always);
//   apply(action, torques)         writes the element torques the action asks for. The actuation
//                                  limits are applied where every action enters the arm, the arm
//                                  world's control step (world::ArmWorld::control_step through
//                                  rod::clamp_to_limits); limits() reports them. A non-finite
//                                  action entry is refused naming its (row, column); nothing is
//                                  written then.
//   project(torques, action)       the action whose (unclamped) element torques reproduce
//                                  `torques` best: the identity for element torques, the least-
//                                  squares fit of the carried couples sum_{j >= k} tau_j
//                                  (k = 1..n-1) for the muscle profile. It lets an executor that
//                                  computes element torques drive either action space.
// Neither apply() nor project() allocates.
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/rod/actuation_limits.hpp"
#include "manisoft/math/cubic_spline.hpp"

namespace manisoft::control {

template <typename T>
concept ActionSpace = requires(const T& space, const Eigen::Matrix<typename T::Scalar, Eigen::Dynamic, 3>& in,
                               Eigen::Matrix<typename T::Scalar, Eigen::Dynamic, 3>& out) {
  { space.rows() } -> std::same_as<int>;
  { space.n_elements() } -> std::same_as<int>;
  { space.apply(in, out) } -> std::same_as<void>;
  { space.project(in, out) } -> std::same_as<void>;
};

namespace action_detail {
template <typename Scalar>
void check_action_space_arguments(const char* name, int n_elements, Scalar length, const rod::ActuationLimits<Scalar>& limits) {
  if (n_elements < 2) manisoft::detail::fail(name, ": n_elements = ", n_elements, " must be >= 2");
  manisoft::detail::require_positive("rod length", length);
  manisoft::detail::require_positive("rod::ActuationLimits bend", limits.bend);
  manisoft::detail::require_positive("rod::ActuationLimits twist", limits.twist);
}

template <typename Action>
void require_finite_action(const char* space, const Action& action) {
  for (int r = 0; r < action.rows(); ++r)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(action(r, c)))
        manisoft::detail::fail(space, ": action entry (", r, ", ", c, ") = ", action(r, c), " is not finite");
}

template <typename Matrix>
void require_shape(const char* space, const Matrix& m, int rows) {
  if (m.rows() != rows || m.cols() != 3)
    manisoft::detail::fail(space, " expects ", rows, " x 3, got ", m.rows(), " x ", m.cols());
}
}  // namespace action_detail

template <typename ScalarType>
class ElementTorqueAction {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  struct Settings {};

  ElementTorqueAction(int n_elements, Scalar length, rod::ActuationLimits<Scalar> limits, Settings = {})
      : n_elements_(n_elements), limits_(limits) {
    action_detail::check_action_space_arguments("ElementTorqueAction", n_elements, length, limits);
  }

  int rows() const { return n_elements_; }
  int n_elements() const { return n_elements_; }
  const rod::ActuationLimits<Scalar>& limits() const { return limits_; }

  void apply(const Array3& action, Array3& torques) const {
    action_detail::require_shape("ElementTorqueAction action", action, n_elements_);
    action_detail::require_finite_action("ElementTorqueAction", action);
    action_detail::require_shape("ElementTorqueAction torques", torques, n_elements_);
    torques = action;
  }

  void project(const Array3& torques, Array3& action) const {
    action_detail::require_shape("ElementTorqueAction::project torques", torques, n_elements_);
    action_detail::require_shape("ElementTorqueAction::project action", action, n_elements_);
    action = torques;
  }

 private:
  int n_elements_;
  rod::ActuationLimits<Scalar> limits_;
};

template <typename ScalarType>
class BsplineMuscleAction {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  struct Settings {
    int control_points = 8;   ///< K per direction (excluding pinned ends)
    bool pinned_ends = false;  ///< Elastica-RL: zero values at s = 0 and s = L
    Scalar scale = 1;          ///< N m per unit control value (Elastica-RL: 75)
  };

  BsplineMuscleAction(int n_elements, Scalar length, rod::ActuationLimits<Scalar> limits, Settings settings = {})
      : n_elements_(n_elements), limits_(limits), settings_(settings) {
    action_detail::check_action_space_arguments("BsplineMuscleAction", n_elements, length, limits);
    const int k_points = settings_.control_points;
    const int knots = k_points + (settings_.pinned_ends ? 2 : 0);
    if (knots < 4 || k_points > n_elements - 1)
      manisoft::detail::fail("BsplineMuscleAction: control_points = ", k_points, " must give at least 4 knots and be <= n_elements - 1 = ",
                             n_elements - 1, " (pinned_ends = ", settings_.pinned_ends, ")");
    manisoft::detail::require_positive("BsplineMuscleAction scale", settings_.scale);
    // basis_(k, j): the couple scale T(s_k) of unit control value j (the spline is linear in its values).
    math::NotAKnotCubicSpline<Scalar> spline(Eigen::Matrix<Scalar, Eigen::Dynamic, 1>::LinSpaced(knots, 0, length));
    basis_.setZero(n_elements_, k_points);
    Eigen::Matrix<Scalar, Eigen::Dynamic, 1> values(knots);
    for (int j = 0; j < k_points; ++j) {
      values.setZero();
      values[j + (settings_.pinned_ends ? 1 : 0)] = 1;
      spline.fit(values);
      for (int k = 0; k < n_elements_; ++k) basis_(k, j) = settings_.scale * spline(length * Scalar(k) / Scalar(n_elements_));
    }
    // Least squares on the carried couples of the actuated elements 1..n-1.
    projection_ = basis_.bottomRows(n_elements_ - 1).completeOrthogonalDecomposition().pseudoInverse();
    couples_.setZero(n_elements_, 3);
  }

  int rows() const { return settings_.control_points; }
  int n_elements() const { return n_elements_; }
  const Settings& settings() const { return settings_; }
  const rod::ActuationLimits<Scalar>& limits() const { return limits_; }
  /// scale T(s_k) per unit control value: rows = nodes k = 0..n-1 (the couple carried across
  /// node k), columns = control points.
  const Matrix& couple_basis() const { return basis_; }

  void apply(const Array3& action, Array3& torques) const {
    action_detail::require_shape("BsplineMuscleAction action", action, rows());
    action_detail::require_finite_action("BsplineMuscleAction", action);
    action_detail::require_shape("BsplineMuscleAction torques", torques, n_elements_);
    couples_.noalias() = basis_ * action;
    for (int k = 0; k + 1 < n_elements_; ++k) torques.row(k) = couples_.row(k) - couples_.row(k + 1);
    torques.row(n_elements_ - 1) = couples_.row(n_elements_ - 1);
  }

  void project(const Array3& torques, Array3& action) const {
    action_detail::require_shape("BsplineMuscleAction::project torques", torques, n_elements_);
    action_detail::require_shape("BsplineMuscleAction::project action", action, rows());
    couples_.row(n_elements_ - 1) = torques.row(n_elements_ - 1);
    for (int k = n_elements_ - 2; k >= 0; --k) couples_.row(k) = couples_.row(k + 1) + torques.row(k);
    action.noalias() = projection_ * couples_.bottomRows(n_elements_ - 1);
  }

 private:
  int n_elements_;
  rod::ActuationLimits<Scalar> limits_;
  Settings settings_;
  Matrix basis_, projection_;
  mutable Array3 couples_;  // scratch
};

}  // namespace manisoft::control
