// SO(3), the rotation group: hat/vee, the exponential and logarithm maps, and the right and left
// Jacobians with their inverses, for float and double.
//
// Conventions follow J. Sola, J. Deray, D. Atchuthan, "A micro Lie theory for state estimation
// in robotics" (arXiv:1812.01537, 2018), referred to below as [Sola]:
//   - a rotation vector phi = theta * u (angle theta = |phi|, unit axis u) is the tangent element;
//   - right perturbations: Exp(phi + dphi) ~= Exp(phi) Exp(J_r(phi) dphi)            [Sola (143)]
//     and Log(R Exp(dphi)) ~= Log(R) + J_r^-1(Log R) dphi                            [Sola (144)];
//   - left perturbations:  Exp(phi + dphi) ~= Exp(J_l(phi) dphi) Exp(phi), J_l(phi) = J_r(-phi).
// Composition and inverse are plain matrix operations (R1 * R2, R.transpose()).
//
// Every closed form that loses precision for small angles switches to its Taylor series below
// a threshold where the truncation error is far below the type's epsilon. Log is robust near
// theta = 0 and near theta = pi (see log()). Everything uses fixed-size Eigen types: no heap.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <limits>

namespace manisoft::math {

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;

namespace detail {

/// theta^2 below which the SO(3) coefficients use their Taylor series (theta < eps^(1/4):
/// 1.2e-4 for double, 1.9e-2 for float). The first dropped term is O(theta^6) = O(eps^1.5).
template <typename Scalar>
constexpr Scalar small_angle_squared() {
  // sqrt(eps) written out so the function stays constexpr.
  if constexpr (std::numeric_limits<Scalar>::digits <= 24) {
    return Scalar(3.4526698e-4);  // sqrt(2^-23)
  } else {
    return Scalar(1.4901161193847656e-8);  // sqrt(2^-52)
  }
}

/// a(theta) = sin(theta) / theta.
template <typename Scalar>
Scalar sin_over_angle(Scalar theta) {
  const Scalar theta2 = theta * theta;
  if (theta2 < small_angle_squared<Scalar>()) {
    return Scalar(1) - theta2 / Scalar(6) * (Scalar(1) - theta2 / Scalar(20));
  }
  return std::sin(theta) / theta;
}

/// b(theta) = (1 - cos(theta)) / theta^2 = (1/2) (sin(theta/2) / (theta/2))^2, written in the
/// half-angle form, which has no cancellation at any angle.
template <typename Scalar>
Scalar one_minus_cos_over_angle2(Scalar theta) {
  const Scalar half_sinc = sin_over_angle(theta / Scalar(2));
  return Scalar(0.5) * half_sinc * half_sinc;
}

/// c(theta) = (theta - sin(theta)) / theta^3 = 1/6 - theta^2/120 + theta^4/5040 - ...
template <typename Scalar>
Scalar angle_minus_sin_over_angle3(Scalar theta) {
  const Scalar theta2 = theta * theta;
  if (theta2 < small_angle_squared<Scalar>()) {
    return Scalar(1) / Scalar(6) - theta2 / Scalar(120) + theta2 * theta2 / Scalar(5040);
  }
  return (theta - std::sin(theta)) / (theta2 * theta);
}

/// e(theta) = 1/theta^2 - (1 + cos(theta)) / (2 theta sin(theta))
///          = 1/theta^2 - cot(theta/2) / (2 theta)  = 1/12 + theta^2/720 + theta^4/30240 + ...
/// The cot(theta/2) form stays finite at theta = pi, where sin(theta) = 0. Singular at 2 pi.
template <typename Scalar>
Scalar inverse_jacobian_coefficient(Scalar theta) {
  const Scalar theta2 = theta * theta;
  if (theta2 < small_angle_squared<Scalar>()) {
    return Scalar(1) / Scalar(12) + theta2 / Scalar(720) + theta2 * theta2 / Scalar(30240);
  }
  const Scalar half = theta / Scalar(2);
  return Scalar(1) / theta2 - std::cos(half) / (Scalar(2) * theta * std::sin(half));
}

}  // namespace detail

namespace so3 {

/// hat(w) = [w]_x, the skew-symmetric matrix with hat(w) v = w x v   [Sola (10)].
template <typename Derived>
Matrix3<typename Derived::Scalar> hat(const Eigen::MatrixBase<Derived>& w) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 1,
                "so3::hat expects a 3-vector");
  using Scalar = typename Derived::Scalar;
  Matrix3<Scalar> m;
  m << Scalar(0), -w(2), w(1),  //
      w(2), Scalar(0), -w(0),   //
      -w(1), w(0), Scalar(0);
  return m;
}

/// vee(W): the 3-vector of a skew-symmetric matrix, inverse of hat. For a matrix that is not
/// exactly skew-symmetric it returns the vector of its skew part (W - W^T)/2.
template <typename Derived>
Vector3<typename Derived::Scalar> vee(const Eigen::MatrixBase<Derived>& m) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "so3::vee expects a 3x3 matrix");
  using Scalar = typename Derived::Scalar;
  return Scalar(0.5) * Vector3<Scalar>(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

/// Right Jacobian   J_r(phi) = I - b(theta) [phi]_x + c(theta) [phi]_x^2       [Sola (143)]
/// with b = (1 - cos theta)/theta^2, c = (theta - sin theta)/theta^3.
template <typename Derived>
Matrix3<typename Derived::Scalar> right_jacobian(const Eigen::MatrixBase<Derived>& phi) {
  using Scalar = typename Derived::Scalar;
  const Scalar theta = phi.norm();
  const Matrix3<Scalar> w = hat(phi);
  return Matrix3<Scalar>::Identity() - detail::one_minus_cos_over_angle2(theta) * w +
         detail::angle_minus_sin_over_angle3(theta) * (w * w);
}

/// Inverse right Jacobian   J_r^-1(phi) = I + 1/2 [phi]_x + e(theta) [phi]_x^2    [Sola (144)]
/// with e = 1/theta^2 - (1 + cos theta)/(2 theta sin theta). Valid for theta < 2 pi.
template <typename Derived>
Matrix3<typename Derived::Scalar> right_jacobian_inverse(const Eigen::MatrixBase<Derived>& phi) {
  using Scalar = typename Derived::Scalar;
  const Scalar theta = phi.norm();
  const Matrix3<Scalar> w = hat(phi);
  return Matrix3<Scalar>::Identity() + Scalar(0.5) * w +
         detail::inverse_jacobian_coefficient(theta) * (w * w);
}

/// Left Jacobian   J_l(phi) = J_r(-phi) = I + b [phi]_x + c [phi]_x^2          [Sola (145)].
/// It is also the matrix V of the SE(3) exponential.
template <typename Derived>
Matrix3<typename Derived::Scalar> left_jacobian(const Eigen::MatrixBase<Derived>& phi) {
  using Scalar = typename Derived::Scalar;
  const Scalar theta = phi.norm();
  const Matrix3<Scalar> w = hat(phi);
  return Matrix3<Scalar>::Identity() + detail::one_minus_cos_over_angle2(theta) * w +
         detail::angle_minus_sin_over_angle3(theta) * (w * w);
}

/// Inverse left Jacobian   J_l^-1(phi) = I - 1/2 [phi]_x + e(theta) [phi]_x^2     [Sola (146)].
template <typename Derived>
Matrix3<typename Derived::Scalar> left_jacobian_inverse(const Eigen::MatrixBase<Derived>& phi) {
  using Scalar = typename Derived::Scalar;
  const Scalar theta = phi.norm();
  const Matrix3<Scalar> w = hat(phi);
  return Matrix3<Scalar>::Identity() - Scalar(0.5) * w +
         detail::inverse_jacobian_coefficient(theta) * (w * w);
}

/// Exp(phi) = I + sin(theta)/theta [phi]_x + (1 - cos theta)/theta^2 [phi]_x^2  (Rodrigues,
/// [Sola (132)]). If right_jacobian_out is given it receives J_r(phi) = d Exp(phi) / d phi in
/// the right-perturbation sense [Sola (143)].
template <typename Derived>
Matrix3<typename Derived::Scalar> exp(const Eigen::MatrixBase<Derived>& phi,
                                      Matrix3<typename Derived::Scalar>* right_jacobian_out = nullptr) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 1,
                "so3::exp expects a 3-vector (rotation vector, rad)");
  using Scalar = typename Derived::Scalar;
  const Vector3<Scalar> v = phi;  // evaluate an expression argument once
  const Scalar theta = v.norm();
  const Matrix3<Scalar> w = hat(v);
  const Matrix3<Scalar> w2 = w * w;
  const Scalar b = detail::one_minus_cos_over_angle2(theta);
  if (right_jacobian_out != nullptr) {
    *right_jacobian_out = Matrix3<Scalar>::Identity() - b * w +
                          detail::angle_minus_sin_over_angle3(theta) * w2;
  }
  return Matrix3<Scalar>::Identity() + detail::sin_over_angle(theta) * w + b * w2;
}

/// Log(R): the rotation vector phi = theta u with theta in [0, pi] and Exp(phi) = R [Sola (133)].
/// R must be a rotation matrix (orthonormal, det +1); nothing is re-orthonormalized here.
///
/// The angle is theta = atan2(|s|, (tr R - 1)/2) with s = vee(R - R^T)/2 = sin(theta) u, which
/// is well conditioned at every angle (acos is not, near 0 and pi).
///   - Generic angles: phi = theta / sin(theta) * s (Taylor series of theta/sin(theta) near 0).
///   - Near pi, s ~ sin(theta) u carries almost no information about the axis, so the axis is
///     read from the symmetric part instead: (R + R^T)/2 = cos(theta) I + (1 - cos theta) u u^T.
///     The column of u u^T with the largest diagonal gives u up to sign, and the sign is taken
///     from s (u . s = sin(theta) >= 0). This keeps the axis right for theta = pi - 1e-7 in double;
///     in float the sign is only resolvable while sin(theta) is well above float epsilon (about
///     pi - 1e-5). At exactly pi both signs are valid logarithms; the one returned is arbitrary.
/// If right_jacobian_inverse_out is given it receives J_r^-1(phi) = d Log(R Exp(dphi)) / d dphi
/// at dphi = 0 [Sola (144)].
template <typename Derived>
Vector3<typename Derived::Scalar> log(
    const Eigen::MatrixBase<Derived>& rotation,
    Matrix3<typename Derived::Scalar>* right_jacobian_inverse_out = nullptr) {
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "so3::log expects a 3x3 rotation matrix");
  using Scalar = typename Derived::Scalar;
  const Matrix3<Scalar> r = rotation;  // evaluate an expression argument (e.g. a product) once
  const Vector3<Scalar> s = vee(r);    // sin(theta) u
  const Scalar sin_theta = s.norm();
  const Scalar cos_theta = Scalar(0.5) * (r.trace() - Scalar(1));
  const Scalar theta = std::atan2(sin_theta, cos_theta);

  Vector3<Scalar> phi;
  // Below cos(theta) = -0.9 (theta > 2.69 rad) the symmetric-part branch is used; both branches
  // are exact there, the threshold only keeps the generic one away from sin(theta) -> 0.
  if (cos_theta > Scalar(-0.9)) {
    const Scalar theta2 = theta * theta;
    // theta / sin(theta) = 1 + theta^2/6 + 7 theta^4/360 + ...
    const Scalar angle_over_sin =
        theta2 < detail::small_angle_squared<Scalar>()
            ? Scalar(1) + theta2 / Scalar(6) + Scalar(7) * theta2 * theta2 / Scalar(360)
            : theta / sin_theta;
    phi = angle_over_sin * s;
  } else {
    // (1 - cos theta) u u^T = (R + R^T)/2 - cos(theta) I, with 1 - cos(theta) in [1.9, 2].
    const Matrix3<Scalar> symmetric =
        Scalar(0.5) * (r + r.transpose()) - cos_theta * Matrix3<Scalar>::Identity();
    Eigen::Index k = 0;
    symmetric.diagonal().maxCoeff(&k);
    Vector3<Scalar> axis = symmetric.col(k);  // = (1 - cos theta) u_k u
    axis.normalize();
    if (axis.dot(s) < Scalar(0)) axis = -axis;
    phi = theta * axis;
  }
  if (right_jacobian_inverse_out != nullptr) *right_jacobian_inverse_out = right_jacobian_inverse(phi);
  return phi;
}

/// Geodesic angle between two rotations, |Log(a^T b)| in [0, pi] (rad).
template <typename DerivedA, typename DerivedB>
typename DerivedA::Scalar angle_between(const Eigen::MatrixBase<DerivedA>& a,
                                        const Eigen::MatrixBase<DerivedB>& b) {
  using Scalar = typename DerivedA::Scalar;
  const Matrix3<Scalar> relative = a.transpose() * b;
  return std::atan2(vee(relative).norm(), Scalar(0.5) * (relative.trace() - Scalar(1)));
}

}  // namespace so3
}  // namespace manisoft::math
