// Property tests of manisoft/math/so3.hpp and se3.hpp over seeded random samples, for float and
// double: round trips of exp/log, the near-pi and near-zero regimes of log, Jacobians against
// central finite differences, SE(3) group identities, and (double) an independent check against
// Eigen's general matrix exponential and logarithm.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <type_traits>
#include <vector>

#include "manisoft/math/se3.hpp"
#include "manisoft/math/so3.hpp"

namespace {

namespace math = manisoft::math;
namespace so3 = manisoft::math::so3;
namespace se3 = manisoft::math::se3;

template <typename Scalar>
using V3 = math::Vector3<Scalar>;
template <typename Scalar>
using M3 = math::Matrix3<Scalar>;
template <typename Scalar>
using V6 = math::Vector6<Scalar>;
template <typename Scalar>
using M6 = math::Matrix6<Scalar>;

constexpr int kSamples = 400;

/// Per-type tolerances. Float loses about 1e-6 per operation; finite differences use a step
/// balancing truncation (h^2) against round-off (eps / h).
template <typename Scalar>
struct Tol;
template <>
struct Tol<double> {
  static constexpr double exact = 1e-13;  // round trips, group identities (measured: 2e-15)
  static constexpr double fd_step = 1e-6; // central difference step
  static constexpr double fd = 2e-8;      // Jacobian vs finite difference (measured: 1.4e-9)
};
template <>
struct Tol<float> {
  static constexpr float exact = 1e-5f;   // measured: 8e-7
  static constexpr float fd_step = 4e-3f;
  static constexpr float fd = 1e-3f;      // measured: 1.1e-4
};

template <typename Scalar>
constexpr Scalar pi = std::numbers::pi_v<Scalar>;

template <typename A, typename B>
double max_abs_diff(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  return static_cast<double>((a - b).cwiseAbs().maxCoeff());
}

/// N draws in a fixed order (function arguments have no evaluation order, so the samples would
/// differ between compilers if drawn inside one call).
template <int N, typename Distribution>
Eigen::Matrix<double, N, 1> draw(std::mt19937& rng, Distribution& distribution) {
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v(i) = distribution(rng);
  return v;
}

template <typename Scalar>
V3<Scalar> random_unit_vector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return draw<3>(rng, normal).normalized().cast<Scalar>();
}

/// A rotation vector with uniformly distributed axis and angle in [min_angle, max_angle].
template <typename Scalar>
V3<Scalar> random_rotation_vector(std::mt19937& rng, double min_angle, double max_angle) {
  std::uniform_real_distribution<double> angle(min_angle, max_angle);
  const Eigen::Vector3d axis = random_unit_vector<double>(rng);
  return (axis * angle(rng)).cast<Scalar>();
}

/// A uniformly random rotation matrix (from a normalised Gaussian quaternion), built in double.
template <typename Scalar>
M3<Scalar> random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(draw<4>(rng, normal));  // coefficients (x, y, z, w)
  q.normalize();
  return q.toRotationMatrix().cast<Scalar>();
}

template <typename Scalar>
math::Pose<Scalar> random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> coord(-2.0, 2.0);
  const M3<Scalar> rotation = random_rotation<Scalar>(rng);
  return math::Pose<Scalar>{rotation, draw<3>(rng, coord).cast<Scalar>()};
}

/// A twist with |rho| <= 2 m and |phi| in [min_angle, max_angle].
template <typename Scalar>
V6<Scalar> random_twist(std::mt19937& rng, double min_angle, double max_angle) {
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  V6<Scalar> xi;
  xi.template head<3>() = draw<3>(rng, coord).cast<Scalar>();
  xi.template tail<3>() = random_rotation_vector<Scalar>(rng, min_angle, max_angle);
  return xi;
}

/// Angles that exercise every branch: zero, the series regimes, their switch points, generic.
std::vector<double> probe_angles() {
  return {0.0, 1e-12, 1e-9, 1e-6, 1e-4, 1.3e-4, 0.018, 0.02, 0.1, 0.49, 0.51, 1.0, 2.0, 2.6, 2.8, 3.0};
}

// ---- finite differences: column i of the derivative of f(x + h e_i) (a tangent vector) ----

template <int N, typename Scalar, typename F>
Eigen::Matrix<Scalar, N, N> central_difference(F&& f) {
  Eigen::Matrix<Scalar, N, N> j;
  const Scalar h = Tol<Scalar>::fd_step;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<Scalar, N, 1> e = Eigen::Matrix<Scalar, N, 1>::Zero();
    e(i) = h;
    j.col(i) = (f(e) - f(Eigen::Matrix<Scalar, N, 1>(-e))) / (Scalar(2) * h);
  }
  return j;
}

}  // namespace

// =====================================  SO(3)  =====================================

TEMPLATE_TEST_CASE("so3 hat is the cross product and vee inverts it", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(11);
  for (int k = 0; k < kSamples; ++k) {
    const V3<Scalar> w = random_rotation_vector<Scalar>(rng, 0.0, 5.0);
    const V3<Scalar> v = random_rotation_vector<Scalar>(rng, 0.0, 5.0);
    CHECK(max_abs_diff(so3::hat(w) * v, w.cross(v)) <= Tol<Scalar>::exact * 10);
    CHECK(max_abs_diff(so3::vee(so3::hat(w)), w) == 0.0);
    CHECK(max_abs_diff(so3::hat(w).transpose(), -so3::hat(w)) == 0.0);
  }
}

TEMPLATE_TEST_CASE("so3 log(exp(v)) == v for |v| < pi", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(12);
  for (int k = 0; k < kSamples; ++k) {
    const V3<Scalar> v = random_rotation_vector<Scalar>(rng, 0.0, std::numbers::pi * (1.0 - 1e-3));
    INFO("v = " << v.transpose() << ", |v| = " << v.norm());
    CHECK(max_abs_diff(so3::log(so3::exp(v)), v) <= Tol<Scalar>::exact);
  }
  // small angles, log-uniform over 1e-12 .. 1e-1
  std::uniform_real_distribution<double> exponent(-12.0, -1.0);
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector3d axis = random_unit_vector<double>(rng);
    const V3<Scalar> v = (axis * std::pow(10.0, exponent(rng))).cast<Scalar>();
    INFO("v = " << v.transpose());
    CHECK(max_abs_diff(so3::log(so3::exp(v)), v) <= Tol<Scalar>::exact * static_cast<double>(v.norm()));
  }
}

TEMPLATE_TEST_CASE("so3 exp(log(R)) == R and |log R| <= pi", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(13);
  for (int k = 0; k < kSamples; ++k) {
    const M3<Scalar> r = random_rotation<Scalar>(rng);
    const V3<Scalar> phi = so3::log(r);
    CHECK(static_cast<double>(phi.norm()) <= std::numbers::pi + 1e-6);
    CHECK(max_abs_diff(so3::exp(phi), r) <= Tol<Scalar>::exact);
    // Expression arguments, and the geodesic angle between two rotations.
    const M3<Scalar> r2 = random_rotation<Scalar>(rng);
    const V3<Scalar> relative = so3::log(M3<Scalar>(r.transpose() * r2));
    CHECK(max_abs_diff(so3::log(r.transpose() * r2), relative) == 0.0);
    CHECK(std::abs(static_cast<double>(so3::angle_between(r, r2) - relative.norm())) <= Tol<Scalar>::exact);
  }
  CHECK(so3::log(M3<Scalar>::Identity()).norm() == Scalar(0));
  CHECK(so3::exp(V3<Scalar>::Zero()) == M3<Scalar>::Identity());
}

TEMPLATE_TEST_CASE("so3 log near pi keeps the right axis", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(14);
  const std::vector<double> gaps = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
  for (const double gap : gaps) {
    for (int k = 0; k < 50; ++k) {
      // Built in double, then rounded: the rotation a float user would actually hold.
      const Eigen::Vector3d axis = random_unit_vector<double>(rng);
      const double angle = std::numbers::pi - gap;
      const M3<Scalar> r = so3::exp(Eigen::Vector3d(angle * axis)).cast<Scalar>();
      const V3<Scalar> phi = so3::log(r);
      const V3<Scalar> expected = (angle * axis).cast<Scalar>();
      INFO("gap = " << gap << ", axis = " << axis.transpose() << ", log = " << phi.transpose());
      CHECK(max_abs_diff(so3::exp(phi), r) <= Tol<Scalar>::exact);
      // The sign of the axis is encoded in the skew part of R, of size sin(gap): float can only
      // resolve it while sin(gap) is well above its epsilon (about 1e-7).
      if (std::is_same_v<Scalar, double> || gap >= 1e-4) {
        CHECK(max_abs_diff(phi, expected) <= Tol<Scalar>::exact);
      } else {
        CHECK(std::min(max_abs_diff(phi, expected), max_abs_diff(phi, V3<Scalar>(-expected))) <=
              1e-5);
      }
    }
  }
  // Exactly pi: R = 2 u u^T - I, both +pi u and -pi u are valid logarithms.
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d axis = random_unit_vector<double>(rng);
    const M3<Scalar> r = (2.0 * axis * axis.transpose() - Eigen::Matrix3d::Identity()).cast<Scalar>();
    const V3<Scalar> phi = so3::log(r);
    const V3<Scalar> expected = (std::numbers::pi * axis).cast<Scalar>();
    INFO("axis = " << axis.transpose() << ", log = " << phi.transpose());
    CHECK(std::abs(static_cast<double>(phi.norm()) - std::numbers::pi) <= Tol<Scalar>::exact);
    CHECK(std::min(max_abs_diff(phi, expected), max_abs_diff(phi, V3<Scalar>(-expected))) <=
          Tol<Scalar>::exact);
    CHECK(max_abs_diff(so3::exp(phi), r) <= Tol<Scalar>::exact);
  }
  // Axis-aligned half turns (diagonal R), the classic failure of the naive formula.
  const M3<Scalar> half_turn_x = V3<Scalar>(1, -1, -1).asDiagonal();
  CHECK(max_abs_diff(so3::log(half_turn_x).cwiseAbs(), V3<Scalar>(pi<Scalar>, 0, 0)) <= Tol<Scalar>::exact);
}

TEMPLATE_TEST_CASE("so3 near-zero angles are accurate", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(15);
  for (int k = 0; k < 50; ++k) {
    const V3<Scalar> v = (1e-12 * random_unit_vector<double>(rng)).cast<Scalar>();
    const M3<Scalar> r = so3::exp(v);
    // Exp(v) = I + [v]_x + O(|v|^2) = I + [v]_x to machine precision at |v| = 1e-12.
    CHECK(max_abs_diff(r, M3<Scalar>(M3<Scalar>::Identity() + so3::hat(v))) <= 1e-22);
    // Relative accuracy of log at 1e-12.
    CHECK(max_abs_diff(so3::log(r), v) <= 4 * std::numeric_limits<Scalar>::epsilon() * 1e-12);
    // Jacobians tend to I -/+ [v]_x / 2.
    const M3<Scalar> half = Scalar(0.5) * so3::hat(v);
    CHECK(max_abs_diff(so3::right_jacobian(v), M3<Scalar>(M3<Scalar>::Identity() - half)) <= 1e-20);
    CHECK(max_abs_diff(so3::left_jacobian_inverse(v), M3<Scalar>(M3<Scalar>::Identity() - half)) <= 1e-20);
  }
}

TEMPLATE_TEST_CASE("so3 Jacobians match central finite differences", "[lie][so3]", float, double) {
  using Scalar = TestType;
  std::mt19937 rng(16);
  std::vector<V3<Scalar>> points;
  for (const double angle : probe_angles()) {
    points.push_back((angle * random_unit_vector<double>(rng)).cast<Scalar>());
  }
  for (int k = 0; k < 100; ++k) points.push_back(random_rotation_vector<Scalar>(rng, 0.0, 2.9));

  for (const V3<Scalar>& phi : points) {
    INFO("phi = " << phi.transpose() << ", |phi| = " << phi.norm());
    const M3<Scalar> r = so3::exp(phi);
    const M3<Scalar> rt = r.transpose();
    // Right: Exp(phi + d) = Exp(phi) Exp(J_r d).
    const M3<Scalar> jr_fd = central_difference<3, Scalar>(
        [&](const V3<Scalar>& d) { return so3::log(M3<Scalar>(rt * so3::exp(V3<Scalar>(phi + d)))); });
    // Left: Exp(phi + d) = Exp(J_l d) Exp(phi).
    const M3<Scalar> jl_fd = central_difference<3, Scalar>(
        [&](const V3<Scalar>& d) { return so3::log(M3<Scalar>(so3::exp(V3<Scalar>(phi + d)) * rt)); });
    // Log(R Exp(d)) = Log(R) + J_r^-1 d and Log(Exp(d) R) = Log(R) + J_l^-1 d.
    const M3<Scalar> jr_inv_fd = central_difference<3, Scalar>(
        [&](const V3<Scalar>& d) { return so3::log(M3<Scalar>(r * so3::exp(d))); });
    const M3<Scalar> jl_inv_fd = central_difference<3, Scalar>(
        [&](const V3<Scalar>& d) { return so3::log(M3<Scalar>(so3::exp(d) * r)); });

    M3<Scalar> jr_from_exp;
    so3::exp(phi, &jr_from_exp);
    M3<Scalar> jr_inv_from_log;
    so3::log(r, &jr_inv_from_log);

    CHECK(max_abs_diff(so3::right_jacobian(phi), jr_fd) <= Tol<Scalar>::fd);
    CHECK(max_abs_diff(so3::left_jacobian(phi), jl_fd) <= Tol<Scalar>::fd);
    CHECK(max_abs_diff(so3::right_jacobian_inverse(phi), jr_inv_fd) <= Tol<Scalar>::fd);
    CHECK(max_abs_diff(so3::left_jacobian_inverse(phi), jl_inv_fd) <= Tol<Scalar>::fd);
    CHECK(max_abs_diff(jr_from_exp, so3::right_jacobian(phi)) <= Tol<Scalar>::exact);
    CHECK(max_abs_diff(jr_inv_from_log, so3::right_jacobian_inverse(phi)) <= Tol<Scalar>::exact);
    CHECK(max_abs_diff(so3::right_jacobian(phi) * so3::right_jacobian_inverse(phi), M3<Scalar>::Identity()) <=
          Tol<Scalar>::exact);
    CHECK(max_abs_diff(so3::left_jacobian(phi) * so3::left_jacobian_inverse(phi), M3<Scalar>::Identity()) <=
          Tol<Scalar>::exact);
    // J_l(phi) = R J_r(phi).
    CHECK(max_abs_diff(so3::left_jacobian(phi), M3<Scalar>(r * so3::right_jacobian(phi))) <= Tol<Scalar>::exact);
  }
}

// =====================================  SE(3)  =====================================

TEMPLATE_TEST_CASE("se3 compose and inverse satisfy the group identities", "[lie][se3]", float, double) {
  using Scalar = TestType;
  using Pose = math::Pose<Scalar>;
  std::mt19937 rng(21);
  const Scalar tol = Tol<Scalar>::exact * 4;
  for (int k = 0; k < kSamples; ++k) {
    const Pose a = random_pose<Scalar>(rng);
    const Pose b = random_pose<Scalar>(rng);
    const Pose c = random_pose<Scalar>(rng);
    const V3<Scalar> p = random_pose<Scalar>(rng).translation;

    CHECK(max_abs_diff((a * a.inverse()).matrix(), math::Matrix4<Scalar>::Identity()) <= tol);
    CHECK(max_abs_diff((a.inverse() * a).matrix(), math::Matrix4<Scalar>::Identity()) <= tol);
    CHECK(max_abs_diff(((a * b) * c).matrix(), (a * (b * c)).matrix()) <= tol);
    CHECK(max_abs_diff((a * b).inverse().matrix(), (b.inverse() * a.inverse()).matrix()) <= tol);
    CHECK(max_abs_diff((a * b).matrix(), math::Matrix4<Scalar>(a.matrix() * b.matrix())) <= tol);
    CHECK(max_abs_diff((a * b).act(p), a.act(b.act(p))) <= tol);
    CHECK(max_abs_diff(a.inverse().act(a.act(p)), p) <= tol);
    CHECK(max_abs_diff((Pose::identity() * a).matrix(), a.matrix()) == 0.0);
  }
}

TEMPLATE_TEST_CASE("se3 exp and log round trip", "[lie][se3]", float, double) {
  using Scalar = TestType;
  using Pose = math::Pose<Scalar>;
  std::mt19937 rng(22);
  const Scalar tol = Tol<Scalar>::exact * 4;
  for (int k = 0; k < kSamples; ++k) {
    const V6<Scalar> xi = random_twist<Scalar>(rng, 0.0, std::numbers::pi * (1.0 - 1e-3));
    INFO("xi = " << xi.transpose());
    CHECK(max_abs_diff(se3::log(se3::exp(xi)), xi) <= tol);
    CHECK(max_abs_diff(se3::exp(V6<Scalar>(-xi)).matrix(), se3::exp(xi).inverse().matrix()) <= tol);

    const Pose t = random_pose<Scalar>(rng);
    CHECK(max_abs_diff(se3::exp(se3::log(t)).matrix(), t.matrix()) <= tol);
    // T Exp(xi) T^-1 = Exp(Ad_T xi) and J_l(xi) = Ad_{Exp xi} J_r(xi).
    CHECK(max_abs_diff((t * se3::exp(xi) * t.inverse()).matrix(),
                       se3::exp(V6<Scalar>(se3::adjoint(t) * xi)).matrix()) <= tol * 4);
    CHECK(max_abs_diff(se3::left_jacobian(xi), M6<Scalar>(se3::adjoint(se3::exp(xi)) * se3::right_jacobian(xi))) <=
          tol * 4);
  }
  // Small rotations, log-uniform 1e-12 .. 1e-1.
  std::uniform_real_distribution<double> exponent(-12.0, -1.0);
  for (int k = 0; k < kSamples; ++k) {
    V6<Scalar> xi = random_twist<Scalar>(rng, 0.0, 0.0);
    const Eigen::Vector3d axis = random_unit_vector<double>(rng);
    xi.template tail<3>() = (axis * std::pow(10.0, exponent(rng))).cast<Scalar>();
    CHECK(max_abs_diff(se3::log(se3::exp(xi)), xi) <= tol);
  }
  // Near pi: the translation part uses V^-1 at |phi| ~ pi, which is regular there.
  for (const double gap : {1e-3, 1e-5, 1e-7}) {
    for (int k = 0; k < 20; ++k) {
      V6<double> xi = random_twist<double>(rng, 0.0, 0.0);
      xi.tail<3>() = (std::numbers::pi - gap) * random_unit_vector<double>(rng);
      const Pose t = se3::exp(xi).template cast<Scalar>();
      CHECK(max_abs_diff(se3::exp(se3::log(t)).matrix(), t.matrix()) <= tol * 4);
      if (std::is_same_v<Scalar, double>) CHECK(max_abs_diff(se3::log(t), xi.cast<Scalar>()) <= 1e-9);
    }
  }
}

TEMPLATE_TEST_CASE("se3 log separates the screw translation from the straight-line one", "[lie][se3]", float,
                   double) {
  using Scalar = TestType;
  // Pure translation: rho = t, phi = 0.
  const math::Pose<Scalar> shift{M3<Scalar>::Identity(), V3<Scalar>(0.1, -0.2, 0.3)};
  CHECK(max_abs_diff(se3::log(shift), V6<Scalar>((V6<Scalar>() << 0.1, -0.2, 0.3, 0, 0, 0).finished())) == 0.0);
  // Quarter turn about z with t = (1, 0, 0). By hand, with theta = pi/2 and phi = (0, 0, theta):
  //   phi x t = (0, theta, 0), phi x (phi x t) = (-theta^2, 0, 0),
  //   e = 1/theta^2 - (1 + cos theta)/(2 theta sin theta) = 4/pi^2 - 1/pi,
  //   rho = t - 1/2 phi x t + e phi x (phi x t) = (1 - e theta^2, -theta/2, 0) = (pi/4, -pi/4, 0).
  // |rho| = pi sqrt(2)/4 is the length of the circular arc (radius 1/sqrt 2, angle pi/2) joining
  // the two origins, not the chord |t| = 1.
  const math::Pose<Scalar> screw{so3::exp(V3<Scalar>(0, 0, pi<Scalar> / 2)), V3<Scalar>(1, 0, 0)};
  const V6<Scalar> expected = (V6<Scalar>() << pi<Scalar> / 4, -pi<Scalar> / 4, 0, 0, 0, pi<Scalar> / 2).finished();
  CHECK(max_abs_diff(se3::log(screw), expected) <= Tol<Scalar>::exact);
}

TEMPLATE_TEST_CASE("se3 Jacobians match central finite differences", "[lie][se3]", float, double) {
  using Scalar = TestType;
  using Pose = math::Pose<Scalar>;
  std::mt19937 rng(23);
  std::vector<V6<Scalar>> points;
  for (const double angle : probe_angles()) {
    V6<Scalar> xi = random_twist<Scalar>(rng, 0.0, 0.0);
    xi.template tail<3>() = (angle * random_unit_vector<double>(rng)).cast<Scalar>();
    points.push_back(xi);
  }
  for (int k = 0; k < 100; ++k) points.push_back(random_twist<Scalar>(rng, 0.0, 2.9));

  for (const V6<Scalar>& xi : points) {
    INFO("xi = " << xi.transpose() << ", |phi| = " << xi.template tail<3>().norm());
    M6<Scalar> jr;
    const Pose t = se3::exp(xi, &jr);
    const Pose t_inv = t.inverse();
    const M6<Scalar> jr_fd = central_difference<6, Scalar>(
        [&](const V6<Scalar>& d) { return se3::log(t_inv * se3::exp(V6<Scalar>(xi + d))); });
    const M6<Scalar> jl_fd = central_difference<6, Scalar>(
        [&](const V6<Scalar>& d) { return se3::log(se3::exp(V6<Scalar>(xi + d)) * t_inv); });
    const M6<Scalar> jr_inv_fd =
        central_difference<6, Scalar>([&](const V6<Scalar>& d) { return se3::log(t * se3::exp(d)); });
    const M6<Scalar> jl_inv_fd =
        central_difference<6, Scalar>([&](const V6<Scalar>& d) { return se3::log(se3::exp(d) * t); });
    M6<Scalar> jr_inv;
    se3::log(t, &jr_inv);

    // Scale: the translational blocks grow with |rho| (up to about 2 m here).
    const double tol = Tol<Scalar>::fd * 3;
    CHECK(max_abs_diff(jr, jr_fd) <= tol);
    CHECK(max_abs_diff(jr, se3::right_jacobian(xi)) <= Tol<Scalar>::exact);
    CHECK(max_abs_diff(se3::left_jacobian(xi), jl_fd) <= tol);
    CHECK(max_abs_diff(jr_inv, jr_inv_fd) <= tol);
    CHECK(max_abs_diff(se3::right_jacobian_inverse(xi), jr_inv_fd) <= tol);
    CHECK(max_abs_diff(se3::left_jacobian_inverse(xi), jl_inv_fd) <= tol);
    CHECK(max_abs_diff(M6<Scalar>(jr * jr_inv), M6<Scalar>::Identity()) <= Tol<Scalar>::exact * 10);
    CHECK(max_abs_diff(M6<Scalar>(se3::left_jacobian(xi) * se3::left_jacobian_inverse(xi)), M6<Scalar>::Identity()) <=
          Tol<Scalar>::exact * 10);
  }
}

TEST_CASE("float results agree with double across angle scales", "[lie]") {
  std::mt19937 rng(24);
  for (const double angle : probe_angles()) {
    for (int k = 0; k < 20; ++k) {
      V6<double> xi = random_twist<double>(rng, 0.0, 0.0);
      xi.tail<3>() = angle * random_unit_vector<double>(rng);
      const V6<float> xf = xi.cast<float>();
      const V6<double> xfd = xf.cast<double>();  // compare on the same (rounded) input
      INFO("xi = " << xi.transpose());
      CHECK(max_abs_diff(se3::exp(xf).matrix().cast<double>(), se3::exp(xfd).matrix()) <= 1e-6);
      CHECK(max_abs_diff(se3::log(se3::exp(xfd).cast<float>()).cast<double>(), se3::log(se3::exp(xfd))) <= 1e-5);
      CHECK(max_abs_diff(se3::right_jacobian(xf).cast<double>(), se3::right_jacobian(xfd)) <= 1e-6);
      CHECK(max_abs_diff(se3::right_jacobian_inverse(xf).cast<double>(), se3::right_jacobian_inverse(xfd)) <= 1e-6);
    }
  }
}

TEST_CASE("se3 exp and log agree with Eigen's general matrix exponential and logarithm", "[lie][se3]") {
  // An independent reference: Eigen's MatrixFunctions (Pade / Schur-Parlett) know nothing of
  // Rodrigues or of V; exp of the 4x4 twist matrix must be the homogeneous pose matrix.
  std::mt19937 rng(25);
  for (int k = 0; k < 100; ++k) {
    const V6<double> xi = random_twist<double>(rng, 0.0, 3.0);
    const math::Matrix4<double> reference_exp = se3::hat(xi).exp();
    CHECK(max_abs_diff(se3::exp(xi).matrix(), reference_exp) <= 1e-12);

    const math::Pose<double> t = random_pose<double>(rng);
    if (so3::log(t.rotation).norm() > 3.1) continue;  // the general log is ill-conditioned near pi
    const math::Matrix4<double> reference_log = t.matrix().log();
    CHECK(max_abs_diff(se3::hat(se3::log(t)), reference_log) <= 1e-10);
  }
}
