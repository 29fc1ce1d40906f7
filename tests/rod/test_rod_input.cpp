// Bad input is refused with a message naming the value and the limit, and loses nothing:
// parameters, unstable time steps, non-finite loads, diverging states. Also: a step allocates
// no heap memory once the rod is built, and runs are bit-identical for identical inputs.
#include <catch2/catch.hpp>

#include "../support/allocation_counter.hpp"

#include <limits>

#include "manisoft/rod.hpp"

namespace test_rod_input {  // per-file namespace: the group's tests build as one unity translation unit

using manisoft_test::allocation_count;  // the no-allocation guarantee of step() is counted

namespace {

using Catch::Matchers::Contains;
using manisoft::rod::RodParameters;
using FullRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                      manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                      manisoft::rod::forcing::UniformLabTorque, manisoft::rod::forcing::ElementTorques,
                                      manisoft::rod::forcing::ElasticaRLMuscleTorques, manisoft::rod::forcing::TipLoad>;
using SimpleRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::None, manisoft::rod::bc::ClampedBase,
                                        manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::ElementTorques>;
const double not_a_number = std::numeric_limits<double>::quiet_NaN();
const double inf = std::numeric_limits<double>::infinity();

bool same_state(const manisoft::rod::RodState<double>& a, const manisoft::rod::RodState<double>& b) {
  return a.time == b.time && a.positions == b.positions && a.velocities == b.velocities && a.directors == b.directors &&
         a.angular_velocities == b.angular_velocities;
}

}  // namespace

TEST_CASE("invalid rod parameters are refused with their name", "[rod][input]") {
  auto build = [](auto edit) {
    RodParameters<double> p;
    edit(p);
    SimpleRod rod(p, 1e-4);
  };
  CHECK_THROWS_WITH(build([](auto& p) { p.n_elements = 1; }), Contains("n_elements = 1"));
  CHECK_THROWS_WITH(build([](auto& p) { p.length = -1; }), Contains("length = -1"));
  CHECK_THROWS_WITH(build([](auto& p) { p.radius = 0; }), Contains("radius = 0"));
  CHECK_THROWS_WITH(build([](auto& p) { p.density = not_a_number; }), Contains("density = nan"));
  CHECK_THROWS_WITH(build([](auto& p) { p.youngs_modulus = inf; }), Contains("youngs_modulus = inf"));
  CHECK_THROWS_WITH(build([](auto& p) { p.shear_modulus = not_a_number; }), Contains("shear_modulus"));
  CHECK_THROWS_WITH(build([](auto& p) { p.normal = {1, 0, 0}; }), Contains("perpendicular"));
  CHECK_THROWS_WITH(build([](auto& p) { p.direction = {0, 0, 0}; }), Contains("direction"));
  CHECK_THROWS_WITH(SimpleRod(RodParameters<double>{}, 0.0), Contains("dt = 0"));
  CHECK_THROWS_WITH(FullRod(RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(-1)),
                    Contains("damping_constant = -1"));
}

TEST_CASE("a time step above the stability limit is refused unless explicitly allowed", "[rod][input]") {
  RodParameters<double> p;
  p.n_elements = 50;
  const double limit = manisoft::rod::make_rod_model(p).stable_timestep_limit();
  // PyElastica: n = 50 is stable at 1.6e-4 s and blows up at 2e-4 s (axial CFL l0/c = 2e-4 s).
  CHECK(limit > 1.6e-4);
  CHECK(limit < 2e-4);
  CHECK_THROWS_WITH(SimpleRod(p, 2e-4), Contains("exceeds the explicit stability limit") && Contains("n_elements = 50"));
  CHECK_NOTHROW(SimpleRod(p, 1.6e-4));
  CHECK_NOTHROW(SimpleRod(manisoft::rod::allow_unstable_timestep, p, 2e-4));
}

TEST_CASE("non-finite torques and forces are refused and the state is kept", "[rod][input]") {
  FullRod rod(RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  rod.step(50);
  const auto before = rod.state();
  Eigen::MatrixX3d torques = Eigen::MatrixX3d::Zero(20, 3);
  torques(7, 2) = not_a_number;
  CHECK_THROWS_WITH(rod.forcing<manisoft::rod::forcing::ElementTorques>().set(torques), Contains("(7, 2)"));
  Eigen::MatrixX3d wrong_size = Eigen::MatrixX3d::Zero(19, 3);
  CHECK_THROWS_WITH(rod.forcing<manisoft::rod::forcing::ElementTorques>().set(wrong_size), Contains("19 x 3"));
  Eigen::Matrix<double, 6, 3> activation = Eigen::Matrix<double, 6, 3>::Zero();
  activation(3, 1) = inf;
  CHECK_THROWS_WITH(rod.forcing<manisoft::rod::forcing::ElasticaRLMuscleTorques>().set_control_points(activation), Contains("(3, 1)"));
  // A non-finite load that reaches the step (user force, tip load edited in place) is refused there.
  rod.state().external_forces(12, 1) = not_a_number;
  CHECK_THROWS_WITH(rod.step(), Contains("node 12") && Contains("step 50"));
  CHECK(same_state(rod.state(), before));
  CHECK(std::isnan(rod.state().external_forces(12, 1)));  // the rejected input is left for inspection
  rod.state().external_forces.setZero();
  rod.forcing<manisoft::rod::forcing::TipLoad>().couple_lab = {0, inf, 0};
  CHECK_THROWS_WITH(rod.step(), Contains("element 19"));
  CHECK(same_state(rod.state(), before));
  rod.forcing<manisoft::rod::forcing::TipLoad>().couple_lab.setZero();
  CHECK_NOTHROW(rod.step());
}

TEST_CASE("a diverging run reports the step and element and keeps the last good state", "[rod][input]") {
  RodParameters<double> p;
  p.n_elements = 50;
  using Rod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::None, manisoft::rod::bc::ClampedBase,
                                    manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity>;
  Rod rod(manisoft::rod::allow_unstable_timestep, p, 3e-4);
  bool threw = false;
  auto last_good = rod.state();
  for (int i = 0; i < 20000 && !threw; ++i) {
    last_good = rod.state();
    const long steps = rod.step_count();
    try {
      rod.step();
    } catch (const manisoft::Diverged& e) {
      threw = true;
      const std::string message = e.what();
      CAPTURE(message, e.where());
      CHECK(e.step() == steps);
      CHECK(rod.step_count() == steps);  // the failed step is not counted
      CHECK_THAT(message, Contains("step " + std::to_string(steps)));
      CHECK_THAT(message, Contains(e.where()));
      CHECK((e.where().rfind("element ", 0) == 0 || e.where().rfind("node ", 0) == 0));
    }
  }
  REQUIRE(threw);
  CHECK(same_state(rod.state(), last_good));  // bit for bit the state before the failed step
}

TEST_CASE("the allocation counter sees Eigen's heap temporaries", "[rod][alloc]") {
  if (!manisoft_test::counts_malloc) {
    SUCCEED("sanitizer build: ASan owns malloc, only operator new is counted here (the g++ build counts both)");
    return;
  }
  const Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(100, 0.0, 1.0);
  const long before = allocation_count.load();
  const Eigen::VectorXd b = a.cwiseProduct(a);  // a dynamic-size result: one heap allocation by Eigen
  const long counted = allocation_count.load() - before;
  CHECK(b.sum() > 0);
  CHECK(counted >= 1);
}

TEST_CASE("a step allocates no heap memory once the rod is built", "[rod][alloc]") {
  FullRod rod(RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  rod.forcing<manisoft::rod::forcing::UniformLabTorque>().torque = 2.0;
  rod.forcing<manisoft::rod::forcing::TipLoad>().force_lab = {0, 0.5, 0};
  Eigen::MatrixX3d torques = Eigen::MatrixX3d::Constant(20, 3, 0.1);
  Eigen::Matrix<double, 6, 3> activation = Eigen::Matrix<double, 6, 3>::Constant(0.2);
  rod.step();
  const long before = allocation_count.load();
  for (int i = 0; i < 1000; ++i) {
    if (i % 7 == 0) {  // control updates at 714 Hz, as in the benchmark
      rod.forcing<manisoft::rod::forcing::ElementTorques>().set(torques);
      rod.forcing<manisoft::rod::forcing::ElasticaRLMuscleTorques>().set_control_points(activation);
    }
    rod.state().external_forces(20, 2) += 0.01;
    rod.step();
  }
  (void)rod.energies();
  CHECK(allocation_count.load() - before == 0);
  CHECK(rod.tip_position().allFinite());
}

TEST_CASE("identical inputs give bit-identical runs", "[rod][determinism]") {
  auto run = [] {
    FullRod rod(RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
    Eigen::Matrix<double, 6, 3> activation;
    for (int i = 0; i < 18; ++i) activation(i % 6, i / 6) = 0.05 * std::sin(1.3 * i);
    rod.forcing<manisoft::rod::forcing::ElasticaRLMuscleTorques>().set_control_points(activation);
    rod.step(2000);
    return rod.state();
  };
  const auto a = run(), b = run();
  CHECK(same_state(a, b));
}

TEST_CASE("a step whose rotation rate exceeds 0.1 rad per dt is taken in equal pieces, bit for bit as steps of dt / m", "[rod][stability]") {
  // An undamped rod twisting at 1,200 rad/s about its axis: |omega| dt = 0.24 rad at dt = 2e-4 s,
  // so the step is 3 pieces of dt / 3. The reference is a rod built with dt / 3 stepped 3 times
  // (its own rotation per step is 0.08 rad: one piece each).
  const double dt = 2e-4;
  auto spun = [](SimpleRod& rod) {
    rod.state().angular_velocities.col(2).setConstant(1200.0);
    rod.state().angular_velocities(0, 2) = 0;
  };
  SimpleRod whole(RodParameters<double>{}, dt);
  SimpleRod pieces(RodParameters<double>{}, dt / 3);
  spun(whole);
  spun(pieces);
  whole.step();
  CHECK(whole.last_pieces() == 3);
  pieces.step(3);
  CHECK(pieces.last_pieces() == 1);
  CHECK(whole.state().positions == pieces.state().positions);
  CHECK(whole.state().directors == pieces.state().directors);
  CHECK(whole.state().angular_velocities == pieces.state().angular_velocities);
  CHECK(whole.state().velocities == pieces.state().velocities);
  CHECK(whole.step_count() == 1);
  // A slow state keeps one piece: the step is the plain explicit step.
  SimpleRod slow(RodParameters<double>{}, dt);
  slow.state().angular_velocities.col(2).setConstant(400.0);  // 0.08 rad per dt
  slow.step();
  CHECK(slow.last_pieces() == 1);
}

}  // namespace test_rod_input
