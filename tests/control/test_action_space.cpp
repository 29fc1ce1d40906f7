// Action spaces: element torques are clamped to the actuation limits and the
// clamped count is exact; the B-spline muscle action reproduces a cubic couple profile exactly
// (not-a-knot splines are exact on cubics), carries its couple across every node, is undone by
// its projection, and bends a weightless rod until B kappa equals the muscle couple at every node.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include "manisoft/control/action_space.hpp"
#include "manisoft/rod.hpp"

namespace test_action_space {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

namespace control = manisoft::control;
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;

static_assert(control::ActionSpace<control::ElementTorqueAction<double>>);
static_assert(control::ActionSpace<control::BsplineMuscleAction<double>>);
static_assert(control::ActionSpace<control::BsplineMuscleAction<float>>);

constexpr int n = 20;
constexpr double length = 1.0;

double cubic(double s, int direction) { return (direction + 1) * (3 - 20 * s + 35 * s * s - 17 * s * s * s); }

}  // namespace

TEST_CASE("element torque actions pass through, the limits clamp them once", "[executor][action]") {
  control::ElementTorqueAction<double> space(4, length, {150, 75});
  CHECK(space.rows() == 4);
  Array3 action(4, 3), torques = Array3::Zero(4, 3);
  action << 9, 9, 9,            // element 0 is clamped by the base: 0, not counted
      200, -10, -80,            // 2 entries beyond the limits
      -151, 150, 75,            // 1 entry beyond (the limits themselves are allowed)
      1, 2, 3;
  space.apply(action, torques);
  CHECK(torques == action);
  CHECK(manisoft::rod::clamp_to_limits(space.limits(), torques) == 3);
  Array3 expected(4, 3);
  expected << 0, 0, 0, 150, -10, -75, -150, 150, 75, 1, 2, 3;
  CHECK(torques == expected);
  Array3 projected = Array3::Zero(4, 3);
  space.project(expected, projected);
  CHECK(projected == expected);

  action(2, 1) = std::numeric_limits<double>::quiet_NaN();
  const Array3 before = torques;
  CHECK_THROWS_WITH(space.apply(action, torques), Catch::Contains("(2, 1)") && Catch::Contains("not finite"));
  CHECK(torques == before);  // nothing written
  CHECK_THROWS_WITH(space.apply(Array3::Zero(3, 3), torques), Catch::Contains("expects 4 x 3, got 3 x 3"));
  CHECK_THROWS_WITH(control::ElementTorqueAction<double>(1, length, {150, 75}), Catch::Contains("n_elements = 1"));
  CHECK_THROWS_WITH(control::ElementTorqueAction<double>(4, length, {-1, 75}), Catch::Contains("bend"));
}

TEST_CASE("B-spline muscle actions carry the spline's couple across every node", "[executor][action]") {
  const double scale = 2.5;
  control::BsplineMuscleAction<double> space(n, length, {1e6, 1e6}, {8, false, scale});
  REQUIRE(space.rows() == 8);
  // Control values sampled from a cubic at the 8 knots linspace(0, 1, 8): the spline is that cubic.
  Array3 action(8, 3);
  for (int j = 0; j < 8; ++j)
    for (int d = 0; d < 3; ++d) action(j, d) = cubic(j / 7.0, d);
  Array3 torques = Array3::Zero(n, 3);
  space.apply(action, torques);
  CHECK(manisoft::rod::clamp_to_limits(space.limits(), torques) == 0);
  for (int d = 0; d < 3; ++d) {
    CHECK(torques(0, d) == 0.0);  // the clamped element
    double carried = 0;           // sum of the torques on elements k..n-1 = the couple across node k
    for (int k = n - 1; k >= 1; --k) {
      carried += torques(k, d);
      CAPTURE(k, d);
      CHECK(carried == Approx(scale * cubic(k * length / n, d)).margin(1e-11));
    }
  }
  // The projection recovers the control values from the torques (the fit is exact here).
  Array3 recovered = Array3::Zero(8, 3);
  space.project(torques, recovered);
  CHECK((recovered - action).cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("pinned B-spline muscle actions vanish at both ends and fit by least squares", "[executor][action]") {
  control::BsplineMuscleAction<double> pinned(n, length, {150, 75}, {6, true, 75});
  Array3 action = Array3::Zero(6, 3);
  action(2, 0) = 1;  // the knot at s = 3/7 (interior knots of linspace(0, L, 8))
  // The basis is the spline through (0, ..., 1 at knot 3, ..., 0): 75 at s = 3/7 is between
  // nodes; at the nodes it is the spline value, and the couple at the base node is 0.
  CHECK(pinned.couple_basis()(0, 2) == Approx(0).margin(1e-12));
  double peak = 0;
  for (int k = 0; k < n; ++k) peak = std::max(peak, pinned.couple_basis()(k, 2));
  CHECK(peak > 60);
  CHECK(peak < 80);
  // Torques that no spline can make: a point couple on one element. The least-squares action
  // leaves a residual orthogonal to the basis: the basis columns times the residual are zero.
  Array3 target = Array3::Zero(n, 3);
  target(12, 1) = 40;
  Array3 fit = Array3::Zero(6, 3);
  pinned.project(target, fit);
  Eigen::VectorXd carried = Eigen::VectorXd::Zero(n - 1);  // nodes 1..n-1
  for (int k = 12; k >= 1; --k) carried[k - 1] = 40;
  const Eigen::VectorXd residual = pinned.couple_basis().bottomRows(n - 1) * fit.col(1) - carried;
  CHECK((pinned.couple_basis().bottomRows(n - 1).transpose() * residual).norm() < 1e-8);
  CHECK(fit.col(0).norm() == 0.0);

  CHECK_THROWS_WITH(control::BsplineMuscleAction<double>(n, length, {150, 75}, {3, false, 1}), Catch::Contains("control_points = 3"));
  CHECK_THROWS_WITH(control::BsplineMuscleAction<double>(n, length, {150, 75}, {20, false, 1}), Catch::Contains("n_elements - 1 = 19"));
  CHECK_THROWS_WITH(control::BsplineMuscleAction<double>(n, length, {150, 75}, {8, false, 0}), Catch::Contains("scale"));
  Array3 torques = Array3::Zero(n, 3);
  action(5, 2) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(pinned.apply(action, torques), Catch::Contains("(5, 2)"));
  CHECK(torques.norm() == 0.0);
}

TEST_CASE("a B-spline muscle action bends a weightless rod until B kappa equals the muscle couple", "[executor][action][physics]") {
  // Static balance of the couples across node k (paper eq. of the Cosserat rod, discrete form of
  // PyElastica): at rest with no forces, the bending couple B kappa at node k carries the sum of
  // the external torques beyond it, i.e. the muscle couple scale T(k l0).
  using Rod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::UniformExp, manisoft::rod::bc::ClampedBase,
                                    manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::ElementTorques>;
  manisoft::rod::RodParameters<double> params;
  Rod rod(params, 2e-4, manisoft::rod::damping::UniformExp<double>(20));
  control::BsplineMuscleAction<double> space(n, length, {150, 75}, {6, false, 1});
  Array3 action = Array3::Zero(6, 3);
  action.col(1) << 4, 10, 6, -3, -8, -2;  // binormal couple, N m
  Array3 torques = Array3::Zero(n, 3);
  space.apply(action, torques);
  REQUIRE(manisoft::rod::clamp_to_limits(space.limits(), torques) == 0);
  rod.forcing<manisoft::rod::forcing::ElementTorques>().set(torques);
  rod.step(20000);  // 4 s; the slowest bending mode decays like exp(-5 t)
  const auto& ws = rod.refresh();
  const double bend = rod.model().bend_stiffness(0, 1);
  REQUIRE(bend == Approx(params.youngs_modulus * std::numbers::pi * std::pow(params.radius, 4) / 4).epsilon(1e-12));
  for (int k = 1; k < n; ++k) {
    const double muscle = (space.couple_basis().row(k) * action.col(1))(0);
    CAPTURE(k, muscle);
    CHECK(bend * ws.kappa(k - 1, 1) == Approx(muscle).margin(1e-6));
    CHECK(std::abs(ws.kappa(k - 1, 0)) < 1e-9);
  }
}

}  // namespace test_action_space
