// Forcing policies of a Cosserat rod. Several can act at once; each adds its load to the step's
// applied forces (nodes, lab frame) and torques (elements, material frame), after the user's
// own external loads, in the order PyElastica applies forcing (after the internal forces).
//   Gravity              f_i += m_i g on every node (GravityForces).
//   UniformLabTorque     tau_k += Q_k (T u) / n: a total torque T u about a fixed lab axis
//                        spread over the elements (PyElastica UniformTorques; u is not normalized).
//   ElementTorques       tau_k += the user's N x 3 material-frame torques (the paper's action).
//   ElasticaRLMuscleTorques Elastica-RL muscle torques (MuscleTorquesWithVaryingBetaSplines):
//                        T_k = scale * spline_dir(s_k) at s_k = sum_{j<=k} l_j (end of element
//                        k, current lengths), applied as the difference
//                          tau_k(dir) += T_k - T_{k+1}   (T_0 and T_n taken as 0),
//                        i.e. +T_k on elements 1..n-1 and -T_{k+1} on elements 0..n-2. An
//                        internal muscle couple: the torques sum to zero over the rod, and
//                        sum_{j>=k} tau_j = T_k (k >= 1) is the couple carried across the start
//                        of element k. N control points per direction (normal d1, binormal d2,
//                        twist d3) at s = linspace(0, L, N + 2), end values pinned to 0, a
//                        cubic not-a-knot spline.
//   TipLoad              a force on the last node (lab), a couple on the last element given in
//                        the material frame (follower) and/or in the lab frame.
// Non-finite loads are refused when they are set, naming the element and component.
#pragma once

#include <Eigen/Core>

#include "manisoft/math/cubic_spline.hpp"
#include "manisoft/rod/internal_forces.hpp"

namespace manisoft::rod::forcing {

namespace detail {
template <typename Matrix>
void require_finite_entries(const char* what, const Matrix& m) {
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c)
      if (!std::isfinite(m(r, c)))
        manisoft::detail::fail(what, " refused: entry (", r, ", ", c, ") = ", m(r, c), " is not finite");
}
}  // namespace detail

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;

template <typename Scalar>
struct Gravity {
  Vector3<Scalar> acceleration{0, 0, Scalar(-9.81)};

  void setup(const RodModel<Scalar>&) { detail::require_finite_entries("Gravity acceleration", acceleration); }
  void apply(const RodModel<Scalar>& model, const RodState<Scalar>&, const RodWorkspace<Scalar>&,
             Array3<Scalar>& forces, Array3<Scalar>&) const {
    for (int c = 0; c < 3; ++c) forces.col(c) += model.node_masses * acceleration[c];
  }
};

template <typename Scalar>
struct UniformLabTorque {
  Scalar torque = 0;                                    ///< T, total over the rod [N m]
  Vector3<Scalar> direction = Vector3<Scalar>::UnitY();  ///< u, used as given (not normalized, as PyElastica)

  void setup(const RodModel<Scalar>&) {
    manisoft::detail::require_finite("UniformLabTorque torque", torque);
    detail::require_finite_entries("UniformLabTorque direction", direction);
  }
  void apply(const RodModel<Scalar>& model, const RodState<Scalar>& state, const RodWorkspace<Scalar>&,
             Array3<Scalar>&, Array3<Scalar>& torques) const {
    const Vector3<Scalar> per_element = (direction * torque) / Scalar(model.n_elements);
    for (int i = 0; i < 3; ++i)
      torques.col(i) += state.directors.col(3 * i) * per_element[0] + state.directors.col(3 * i + 1) * per_element[1] +
                        state.directors.col(3 * i + 2) * per_element[2];
  }
};

template <typename Scalar>
class ElementTorques {
 public:
  void setup(const RodModel<Scalar>& model) {
    if (torques_.rows() == 0) torques_ = Array3<Scalar>::Zero(model.n_elements, 3);
    if (torques_.rows() != model.n_elements)
      manisoft::detail::fail("ElementTorques has ", torques_.rows(), " rows, the rod has ", model.n_elements, " elements");
  }
  /// Sets the material-frame torque of every element (N x 3: normal, binormal, twist) [N m].
  template <typename Matrix>
  void set(const Matrix& torques) {
    if (torques_.rows() != 0 && (torques.rows() != torques_.rows() || torques.cols() != 3))
      manisoft::detail::fail("ElementTorques::set expects ", torques_.rows(), " x 3, got ", torques.rows(), " x ", torques.cols());
    detail::require_finite_entries("ElementTorques (element, component)", torques);
    torques_ = torques;
  }
  const Array3<Scalar>& torques() const { return torques_; }
  void apply(const RodModel<Scalar>&, const RodState<Scalar>&, const RodWorkspace<Scalar>&, Array3<Scalar>&,
             Array3<Scalar>& torques) const {
    torques += torques_;
  }

 private:
  Array3<Scalar> torques_;
};

/// Elastica-RL's B-spline muscle torques (Case1 MuscleTorquesWithVaryingBetaSplines.apply_torques):
/// per direction d, T_k = profile(d, s_k) at the end s_k = l_0 + ... + l_k of element k, and
///   element 0:           -T_1
///   element k (0<k<n-1): T_k - T_{k+1}
///   element n-1:         T_{n-1}
/// (numpy: external_torques[d, 1:] += T[1:]; external_torques[d, :-1] -= T[1:]). The muscle is
/// internal: the element torques sum to zero, and by telescoping the couple carried across the
/// cross-section between elements k-1 and k (the sum of the torques on elements k..n-1) is
/// T_k = scale * spline_d(s_k), although that cross-section sits at s_k - l_k: the couple lags
/// the spline by one element, as in Elastica-RL (T_0 is never used).
template <typename Scalar>
class ElasticaRLMuscleTorques {
 public:
  using Array = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  int control_points = 6;       ///< per direction, excluding the two pinned ends
  Scalar scale = Scalar(75);    ///< Elastica-RL's alpha = beta = 75

  void setup(const RodModel<Scalar>& model) {
    if (control_points < 2) manisoft::detail::fail("ElasticaRLMuscleTorques control_points = ", control_points, " must be >= 2");
    manisoft::detail::require_finite("ElasticaRLMuscleTorques scale", scale);
    const Scalar length = model.total_length();
    Array knots(control_points + 2);
    for (int i = 0; i < control_points + 2; ++i) knots[i] = length * Scalar(i) / Scalar(control_points + 1);
    for (auto& s : splines_) s = math::NotAKnotCubicSpline<Scalar>(knots);
    values_ = Array::Zero(control_points + 2);
    activation_ = Array3<Scalar>::Zero(control_points, 3);
    for (auto& s : splines_) s.fit(values_);
  }
  /// Control values (control_points x 3: normal, binormal, twist), typically in [-1, 1].
  template <typename Matrix>
  void set_control_points(const Matrix& activation) {
    if (activation.rows() != control_points || activation.cols() != 3)
      manisoft::detail::fail("ElasticaRLMuscleTorques expects ", control_points, " x 3 control points, got ", activation.rows(), " x ", activation.cols());
    detail::require_finite_entries("ElasticaRLMuscleTorques control point (index, direction)", activation);
    activation_ = activation;
    for (int d = 0; d < 3; ++d) {
      values_[0] = 0;
      values_[control_points + 1] = 0;
      for (int i = 0; i < control_points; ++i) values_[i + 1] = activation_(i, d);
      splines_[d].fit(values_);
    }
  }
  const Array3<Scalar>& control_point_values() const { return activation_; }
  /// The muscle couple profile scale * spline_d(s) of direction d at arc length s [N m].
  Scalar profile(int d, Scalar s) const { return scale * splines_[d](s); }

  /// Adds T_k - T_{k+1} to element k, T_k = profile(d, s_k) at the current lengths (class comment).
  void apply(const RodModel<Scalar>& model, const RodState<Scalar>&, const RodWorkspace<Scalar>& ws, Array3<Scalar>&,
             Array3<Scalar>& torques) const {
    Scalar s = ws.lengths[0];  // s_0: T_0 acts on no element
    for (int k = 1; k < model.n_elements; ++k) {
      s += ws.lengths[k];
      for (int d = 0; d < 3; ++d) {
        const Scalar couple = profile(d, s);
        torques(k, d) += couple;
        torques(k - 1, d) -= couple;
      }
    }
  }

 private:
  math::NotAKnotCubicSpline<Scalar> splines_[3];
  Array values_;
  Array3<Scalar> activation_;
};

template <typename Scalar>
struct TipLoad {
  Vector3<Scalar> force_lab = Vector3<Scalar>::Zero();        ///< on the last node [N]
  Vector3<Scalar> couple_material = Vector3<Scalar>::Zero();  ///< follower couple on the last element [N m]
  Vector3<Scalar> couple_lab = Vector3<Scalar>::Zero();       ///< fixed-axis couple on the last element [N m]

  void setup(const RodModel<Scalar>&) {
    detail::require_finite_entries("TipLoad force_lab", force_lab);
    detail::require_finite_entries("TipLoad couple_material", couple_material);
    detail::require_finite_entries("TipLoad couple_lab", couple_lab);
  }
  void apply(const RodModel<Scalar>& model, const RodState<Scalar>& state, const RodWorkspace<Scalar>&,
             Array3<Scalar>& forces, Array3<Scalar>& torques) const {
    const int last = model.n_elements - 1;
    forces.row(last + 1) += force_lab.transpose();
    torques.row(last) += (couple_material + state.director(last) * couple_lab).transpose();
  }
};

}  // namespace manisoft::rod::forcing
