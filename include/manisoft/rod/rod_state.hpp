// Rod state: the mutable kinematic variables of a discrete Cosserat rod, laid out like
// PyElastica so results compare directly:
//   positions, velocities (nodes, lab frame), directors Q_k (elements; row i of Q_k is director
//   d_{i+1} in lab coordinates, so Q maps lab to material), angular velocities (elements,
//   material frame), and the user's external loads for the coming step (forces on nodes in the
//   lab frame, torques on elements in the material frame; cleared after each step).
// Storage is structure-of-arrays: column c of an N x 3 array holds component c of every entry.
#pragma once

#include <Eigen/Core>

#include "manisoft/math/se3.hpp"
#include "manisoft/rod/rod_model.hpp"

namespace manisoft::rod {

template <typename Scalar>
struct RodState {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Array9 = Eigen::Matrix<Scalar, Eigen::Dynamic, 9>;

  Scalar time = 0;
  Array3 positions;          ///< (n + 1) x 3, lab frame [m]
  Array3 velocities;         ///< (n + 1) x 3, lab frame [m/s]
  Array9 directors;          ///< n x 9, column 3 i + j = Q(i, j)
  Array3 angular_velocities; ///< n x 3, material frame [rad/s]
  Array3 external_forces;    ///< (n + 1) x 3, lab frame [N]; added by the user before a step
  Array3 external_torques;   ///< n x 3, material frame [N m]; added by the user before a step

  int n_elements() const { return static_cast<int>(directors.rows()); }
  Vector3 position(int node) const { return positions.row(node).transpose(); }
  Vector3 velocity(int node) const { return velocities.row(node).transpose(); }
  Vector3 tip_position() const { return position(static_cast<int>(positions.rows()) - 1); }
  /// Q_k: rows are the directors d1, d2, d3 of element k in lab coordinates.
  Matrix3 director(int element) const {
    Matrix3 q;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) q(i, j) = directors(element, 3 * i + j);
    return q;
  }
  void set_director(int element, const Matrix3& q) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) directors(element, 3 * i + j) = q(i, j);
  }
  Vector3 angular_velocity(int element) const { return angular_velocities.row(element).transpose(); }
  /// The tip frame: origin at the last node, axes the last element's directors as columns
  /// (rotation = Q_{n-1}^T maps tip coordinates to the lab).
  math::Pose<Scalar> tip_pose() const {
    math::Pose<Scalar> p;
    p.rotation = director(n_elements() - 1).transpose();
    p.translation = tip_position();
    return p;
  }
};

/// The straight rod at rest described by the parameters: nodes evenly spaced from the base along
/// `direction`, every element with d3 = direction, d1 = normal, d2 = d3 x d1.
template <typename Scalar>
RodState<Scalar> make_straight_rod_state(const RodParameters<Scalar>& p) {
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  const Scalar dn = p.direction.norm(), nn = p.normal.norm();
  if (!std::isfinite(dn) || dn <= 0) manisoft::detail::fail("direction = (", p.direction.transpose(), ") is invalid: it must be a finite non-zero vector");
  if (!std::isfinite(nn) || nn <= 0) manisoft::detail::fail("normal = (", p.normal.transpose(), ") is invalid: it must be a finite non-zero vector");
  if (!p.base_position.allFinite()) manisoft::detail::fail("base_position = (", p.base_position.transpose(), ") is invalid: it must be finite");
  const Vector3 d3 = p.direction / dn, d1 = p.normal / nn;
  const Scalar tol = std::is_same_v<Scalar, float> ? Scalar(1e-5) : Scalar(1e-9);
  if (std::abs(d1.dot(d3)) > tol)
    manisoft::detail::fail("normal = (", p.normal.transpose(), ") is invalid: it must be perpendicular to direction = (",
                 p.direction.transpose(), "), |cos| = ", std::abs(d1.dot(d3)));
  const Vector3 d2 = d3.cross(d1);
  const int n = p.n_elements;
  RodState<Scalar> s;
  s.positions.resize(n + 1, 3);
  for (int k = 0; k <= n; ++k)
    s.positions.row(k) = (p.base_position + d3 * (p.length * Scalar(k) / Scalar(n))).transpose();
  s.velocities = RodState<Scalar>::Array3::Zero(n + 1, 3);
  s.directors.resize(n, 9);
  Eigen::Matrix<Scalar, 3, 3> q;
  q.row(0) = d1.transpose();
  q.row(1) = d2.transpose();
  q.row(2) = d3.transpose();
  for (int k = 0; k < n; ++k) s.set_director(k, q);
  s.angular_velocities = RodState<Scalar>::Array3::Zero(n, 3);
  s.external_forces = RodState<Scalar>::Array3::Zero(n + 1, 3);
  s.external_torques = RodState<Scalar>::Array3::Zero(n, 3);
  return s;
}

}  // namespace manisoft::rod
