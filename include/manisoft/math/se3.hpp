// SE(3), rigid-body poses: the Pose type (rotation matrix + translation), composition, inverse,
// action on points, the exponential and logarithm of a twist and the SE(3) Jacobians.
//
// Conventions follow J. Sola et al., "A micro Lie theory for state estimation in robotics"
// (arXiv:1812.01537, 2018), [Sola] below, Appendix D:
//   - a twist is the 6-vector xi = [rho; phi]: rho (first three, m) is the translational part,
//     phi (last three, rad) the rotation vector;
//   - Exp(xi) = (Exp_SO3(phi), V(phi) rho) with V(phi) = J_l(phi), the left Jacobian of SO(3)
//     [Sola (172)]; Log(R, t) = [V^-1(phi) t; phi] with phi = Log_SO3(R). Note that rho is
//     V^-1 t, not t: it is the translation measured along the screw motion, and |rho| differs
//     from |t| whenever the rotation is not zero;
//   - right perturbations, Exp(xi + dxi) ~= Exp(xi) Exp(J_r(xi) dxi) and
//     Log(T Exp(dxi)) ~= Log(T) + J_r^-1(Log T) dxi, with the 6x6 Jacobians of [Sola (179, 180)].
// Poses map body coordinates to world (lab) coordinates: p_world = R p_body + t.
// Everything uses fixed-size Eigen types: no heap allocation.
#pragma once

#include "manisoft/core/error.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

#include <array>
#include <cstddef>

#include "manisoft/math/so3.hpp"

namespace manisoft::math {

template <typename Scalar>
using Vector6 = Eigen::Matrix<Scalar, 6, 1>;
template <typename Scalar>
using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
template <typename Scalar>
using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;

/// A rigid-body pose (element of SE(3)): p_world = rotation * p_body + translation.
/// An aggregate, default-initialised to the identity: Pose<double>{R, t} or
/// Pose<double>{.translation = t}.
template <typename Scalar>
struct Pose {
  Matrix3<Scalar> rotation = Matrix3<Scalar>::Identity();  ///< orthonormal, det +1
  Vector3<Scalar> translation = Vector3<Scalar>::Zero();    ///< m

  static Pose identity() { return Pose{}; }

  /// T1 * T2 = (R1 R2, R1 t2 + t1)   [Sola (171)].
  Pose operator*(const Pose& other) const {
    return Pose{rotation * other.rotation, rotation * other.translation + translation};
  }

  /// T^-1 = (R^T, -R^T t).
  Pose inverse() const {
    Pose out;  // assigned rather than constructed from the transpose: GCC 12 flags Eigen's
               // debug aliasing check on a matrix constructed from a transpose as uninitialized
    out.rotation = rotation.transpose();
    out.translation = -(out.rotation * translation);
    return out;
  }

  /// Maps a point from body to world coordinates: R p + t.
  Vector3<Scalar> act(const Vector3<Scalar>& point) const { return rotation * point + translation; }

  /// Maps a point from world to body coordinates: R^T (p - t).
  Vector3<Scalar> inverse_act(const Vector3<Scalar>& point) const { return rotation.transpose() * (point - translation); }

  /// The homogeneous 4x4 matrix [[R, t], [0, 1]].
  Matrix4<Scalar> matrix() const {
    Matrix4<Scalar> m = Matrix4<Scalar>::Identity();
    m.template topLeftCorner<3, 3>() = rotation;
    m.template topRightCorner<3, 1>() = translation;
    return m;
  }

  template <typename OtherScalar>
  Pose<OtherScalar> cast() const {
    return Pose<OtherScalar>{rotation.template cast<OtherScalar>(),
                             translation.template cast<OtherScalar>()};
  }

  /// True when no coefficient is NaN or infinite.
  bool is_finite() const { return rotation.allFinite() && translation.allFinite(); }
};

/// Refuses (manisoft::InvalidInput, naming `who`) a pose that is not finite or whose rotation is
/// not a rotation matrix (|R R^T - I| > 1e-6 or det R < 0): the one check every target goes through.
template <typename Scalar>
void require_valid_pose(const Pose<Scalar>& pose, const char* who) {
  if (!pose.is_finite())
    manisoft::detail::fail(who, ": pose refused, it is not finite (translation = ", pose.translation.transpose(), ")");
  const Scalar e = (pose.rotation * pose.rotation.transpose() - Matrix3<Scalar>::Identity()).norm();
  if (e > Scalar(1e-6) || pose.rotation.determinant() < 0)
    manisoft::detail::fail(who, ": pose refused, its rotation is not a rotation matrix (|R R^T - I| = ", e, ")");
}

namespace detail {

/// Coefficients of the SE(3) Jacobian block Q(rho, phi) [Sola (180)], theta = |phi|:
///   c1 = (theta - sin theta) / theta^3                          = sum_k (-theta^2)^k / (2k+3)!
///   c2 = (theta^2 + 2 cos theta - 2) / (2 theta^4)              = sum_k (-theta^2)^k / (2k+4)!
///   c3 = (2 theta - 3 sin theta + theta cos theta) / (2 theta^5) = sum_k (-theta^2)^k (k+1)/(2k+5)!
/// The closed forms of c2 and c3 cancel badly (an error of eps / theta^2 once multiplied by the
/// matrices), so they switch to 7-term series below theta = 0.5, where the first dropped term
/// is below 1e-18.
template <typename Scalar>
struct SE3JacobianCoefficients {
  Scalar c1;
  Scalar c2;
  Scalar c3;
};

template <typename Scalar>
SE3JacobianCoefficients<Scalar> se3_jacobian_coefficients(Scalar theta) {
  const Scalar theta2 = theta * theta;
  if (theta < Scalar(0.5)) {
    constexpr std::size_t terms = 7;
    constexpr std::array<double, 18> inverse_factorial = [] {
      std::array<double, 18> f{};
      double factorial = 1.0;
      for (std::size_t n = 0; n < f.size(); ++n) {
        if (n > 0) factorial *= static_cast<double>(n);
        f[n] = 1.0 / factorial;
      }
      return f;
    }();
    Scalar c1(0), c2(0), c3(0);
    for (std::size_t i = terms; i-- > 0;) {  // Horner in x = -theta^2
      c1 = c1 * -theta2 + Scalar(inverse_factorial[2 * i + 3]);
      c2 = c2 * -theta2 + Scalar(inverse_factorial[2 * i + 4]);
      c3 = c3 * -theta2 + Scalar(static_cast<double>(i + 1) * inverse_factorial[2 * i + 5]);
    }
    return {c1, c2, c3};
  }
  const Scalar sin_theta = std::sin(theta);
  const Scalar cos_theta = std::cos(theta);
  const Scalar theta4 = theta2 * theta2;
  return {(theta - sin_theta) / (theta2 * theta),
          (theta2 + Scalar(2) * cos_theta - Scalar(2)) / (Scalar(2) * theta4),
          (Scalar(2) * theta - Scalar(3) * sin_theta + theta * cos_theta) / (Scalar(2) * theta4 * theta)};
}

/// Q(rho, phi), the top-right block of the left Jacobian of SE(3) [Sola (180)], with
/// P = [rho]_x and W = [phi]_x:
///   Q = 1/2 P + c1 (W P + P W + W P W) + c2 (W W P + P W W - 3 W P W) + c3 (W P W W + W W P W).
template <typename Scalar>
Matrix3<Scalar> se3_q_block(const Vector3<Scalar>& rho, const Vector3<Scalar>& phi) {
  const auto [c1, c2, c3] = se3_jacobian_coefficients(phi.norm());
  const Matrix3<Scalar> p = so3::hat(rho);
  const Matrix3<Scalar> w = so3::hat(phi);
  const Matrix3<Scalar> wp = w * p;
  const Matrix3<Scalar> pw = p * w;
  const Matrix3<Scalar> wpw = wp * w;
  const Matrix3<Scalar> ww = w * w;
  return Scalar(0.5) * p + c1 * (wp + pw + wpw) + c2 * (ww * p + pw * w - Scalar(3) * wpw) +
         c3 * (wpw * w + ww * pw);
}

}  // namespace detail

namespace se3 {

/// The 4x4 element of the Lie algebra se(3): [[ [phi]_x, rho ], [0, 0]]   [Sola (169)].
template <typename Derived>
Matrix4<typename Derived::Scalar> hat(const Eigen::MatrixBase<Derived>& xi) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "se3::hat expects a 6-vector twist [rho; phi]");
  using Scalar = typename Derived::Scalar;
  Matrix4<Scalar> m = Matrix4<Scalar>::Zero();
  m.template topLeftCorner<3, 3>() = so3::hat(xi.template tail<3>());
  m.template topRightCorner<3, 1>() = xi.template head<3>();
  return m;
}

/// Adjoint matrix of a pose for twists ordered [rho; phi]: Ad_T = [[R, [t]_x R], [0, R]],
/// so that T Exp(xi) T^-1 = Exp(Ad_T xi) and J_l(xi) = Ad_{Exp(xi)} J_r(xi).
template <typename Scalar>
Matrix6<Scalar> adjoint(const Pose<Scalar>& pose) {
  Matrix6<Scalar> ad = Matrix6<Scalar>::Zero();
  ad.template topLeftCorner<3, 3>() = pose.rotation;
  ad.template topRightCorner<3, 3>() = so3::hat(pose.translation) * pose.rotation;
  ad.template bottomRightCorner<3, 3>() = pose.rotation;
  return ad;
}

/// Left Jacobian J_l(xi) = [[J_l(phi), Q(rho, phi)], [0, J_l(phi)]]   [Sola (179, 180)].
template <typename Derived>
Matrix6<typename Derived::Scalar> left_jacobian(const Eigen::MatrixBase<Derived>& xi) {
  using Scalar = typename Derived::Scalar;
  const Vector3<Scalar> rho = xi.template head<3>();
  const Vector3<Scalar> phi = xi.template tail<3>();
  Matrix6<Scalar> j = Matrix6<Scalar>::Zero();
  j.template topLeftCorner<3, 3>() = so3::left_jacobian(phi);
  j.template bottomRightCorner<3, 3>() = j.template topLeftCorner<3, 3>();
  j.template topRightCorner<3, 3>() = detail::se3_q_block(rho, phi);
  return j;
}

/// Right Jacobian J_r(xi) = J_l(-xi) = [[J_r(phi), Q(-rho, -phi)], [0, J_r(phi)]]
/// [Sola, note after (180)].
template <typename Derived>
Matrix6<typename Derived::Scalar> right_jacobian(const Eigen::MatrixBase<Derived>& xi) {
  using Scalar = typename Derived::Scalar;
  const Vector6<Scalar> minus_xi = -xi;
  return left_jacobian(minus_xi);
}

/// J_l^-1(xi) = [[J_l^-1(phi), -J_l^-1(phi) Q(rho, phi) J_l^-1(phi)], [0, J_l^-1(phi)]]
/// (block-triangular inverse of (179)). Valid for |phi| < 2 pi.
template <typename Derived>
Matrix6<typename Derived::Scalar> left_jacobian_inverse(const Eigen::MatrixBase<Derived>& xi) {
  using Scalar = typename Derived::Scalar;
  const Vector3<Scalar> rho = xi.template head<3>();
  const Vector3<Scalar> phi = xi.template tail<3>();
  const Matrix3<Scalar> inv = so3::left_jacobian_inverse(phi);
  Matrix6<Scalar> j = Matrix6<Scalar>::Zero();
  j.template topLeftCorner<3, 3>() = inv;
  j.template bottomRightCorner<3, 3>() = inv;
  j.template topRightCorner<3, 3>() = -inv * detail::se3_q_block(rho, phi) * inv;
  return j;
}

/// J_r^-1(xi) = J_l^-1(-xi).
template <typename Derived>
Matrix6<typename Derived::Scalar> right_jacobian_inverse(const Eigen::MatrixBase<Derived>& xi) {
  using Scalar = typename Derived::Scalar;
  const Vector6<Scalar> minus_xi = -xi;
  return left_jacobian_inverse(minus_xi);
}

/// Exp(xi) for xi = [rho; phi]: rotation Exp_SO3(phi), translation V(phi) rho with
/// V = J_l(phi) = I + (1 - cos theta)/theta^2 [phi]_x + (theta - sin theta)/theta^3 [phi]_x^2
/// [Sola (172)]. If right_jacobian_out is given it receives J_r(xi), the derivative of Exp in
/// the right-perturbation sense: Exp(xi + dxi) ~= Exp(xi) Exp(J_r(xi) dxi).
template <typename Derived>
Pose<typename Derived::Scalar> exp(const Eigen::MatrixBase<Derived>& xi,
                                   Matrix6<typename Derived::Scalar>* right_jacobian_out = nullptr) {
  static_assert(Derived::RowsAtCompileTime == 6 && Derived::ColsAtCompileTime == 1,
                "se3::exp expects a 6-vector twist [rho (m); phi (rad)]");
  using Scalar = typename Derived::Scalar;
  const Vector3<Scalar> rho = xi.template head<3>();
  const Vector3<Scalar> phi = xi.template tail<3>();
  const Scalar theta = phi.norm();
  // V rho = rho + b phi x rho + c phi x (phi x rho), without forming V.
  const Vector3<Scalar> phi_x_rho = phi.cross(rho);
  Pose<Scalar> pose{so3::exp(phi),
                    rho + detail::one_minus_cos_over_angle2(theta) * phi_x_rho +
                        detail::angle_minus_sin_over_angle3(theta) * phi.cross(phi_x_rho)};
  if (right_jacobian_out != nullptr) *right_jacobian_out = right_jacobian(xi);
  return pose;
}

/// Log(T) = [rho; phi] with phi = Log_SO3(R) (|phi| in [0, pi], robust near 0 and pi, see
/// so3::log) and rho = V^-1(phi) t = t - 1/2 phi x t + e(theta) phi x (phi x t), the inverse of
/// (172). If right_jacobian_inverse_out is given it receives J_r^-1(Log T), the derivative of
/// Log under a right perturbation: Log(T Exp(dxi)) ~= Log(T) + J_r^-1 dxi.
template <typename Scalar>
Vector6<Scalar> log(const Pose<Scalar>& pose, Matrix6<Scalar>* right_jacobian_inverse_out = nullptr) {
  const Vector3<Scalar> phi = so3::log(pose.rotation);
  const Vector3<Scalar>& t = pose.translation;
  const Vector3<Scalar> phi_x_t = phi.cross(t);
  Vector6<Scalar> xi;
  xi.template head<3>() = t - Scalar(0.5) * phi_x_t +
                          detail::inverse_jacobian_coefficient(phi.norm()) * phi.cross(phi_x_t);
  xi.template tail<3>() = phi;
  if (right_jacobian_inverse_out != nullptr) *right_jacobian_inverse_out = right_jacobian_inverse(xi);
  return xi;
}

}  // namespace se3
}  // namespace manisoft::math
