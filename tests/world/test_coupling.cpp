// The elastic spring coupling between the rod tip and a rigid end-effector, in SoftArmWorld:
// momentum conservation of the free pair, the steady separation m g / kF of a hanging load, what
// the paper's printed stiffness does to a gripper, and that the default preset holds the
// heaviest load within 1 mm and 1 degree.
#include <catch2/catch.hpp>

#include <cmath>

#include "manisoft/world/soft_arm_world.hpp"

namespace test_coupling {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using manisoft::rod::RodParameters;
using FreeRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::None, manisoft::rod::bc::Free, manisoft::rod::integrator::PositionVerlet>;
using ClampedRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::UniformExp, manisoft::rod::bc::ClampedBase,
                                         manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity>;

/// A box end-effector attached at the centre of its top face (the attach frame's d3 points down
/// into the box, so a rod pointing down continues into it).
manisoft::interaction::EndEffectorDesc box_end_effector(double mass, double lever = 0) {
  manisoft::interaction::EndEffectorDesc ee;
  ee.body.shape = manisoft::geometry::Box<double>{Eigen::Vector3d(0.04, 0.04, 0.03)};
  ee.body.mass = mass;
  ee.attach_position = Eigen::Vector3d(lever, 0, 0.03);  // half extents: top face at z = +0.03
  return ee;
}

struct Momentum {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
};

template <typename World>
Momentum momentum(const World& world) {
  Momentum p;
  const auto& rod = world.rod();
  const auto& s = rod.state();
  const auto& m = rod.model();
  for (int i = 0; i <= rod.n_elements(); ++i) {
    p.linear += m.node_masses[i] * s.velocity(i);
    p.angular += m.node_masses[i] * s.position(i).cross(s.velocity(i));
  }
  for (int k = 0; k < rod.n_elements(); ++k) {
    const Eigen::Vector3d spin = m.inertia.row(k).transpose().cwiseProduct(s.angular_velocity(k));
    p.angular += s.director(k).transpose() * spin;
  }
  const auto& rigid = world.rigid();
  const auto id = world.end_effector();
  const double mb = rigid.model(id).mass;
  const Eigen::Matrix3d r = rigid.orientation(id).toRotationMatrix();
  p.linear += mb * rigid.linear_velocity(id);
  p.angular += mb * rigid.center_of_mass(id).cross(rigid.linear_velocity(id)) +
               r * rigid.model(id).inertia * r.transpose() * rigid.angular_velocity(id);
  return p;
}

}  // namespace

TEST_CASE("the coupled rod and end-effector conserve momentum without external loads", "[world][coupling]") {
  manisoft::rigid::RigidWorldSettings settings;
  settings.gravity.setZero();
  auto params = manisoft::interaction::ElasticSpringParameters::stiff();
  params.translational_damping = 0;
  params.rotational_damping = 0;
  auto ee = box_end_effector(0.3);
  ee.body.linear_velocity = Eigen::Vector3d(0.2, -0.3, 0.4);  // the body flies off: the spring pulls back
  ee.body.angular_velocity = Eigen::Vector3d(1.0, 0.5, -2.0);
  RodParameters<double> rp;
  manisoft::world::SoftArmWorld<FreeRod> world(FreeRod(rp, 2e-4), settings, ee, manisoft::interaction::ElasticSpring(params));
  const Momentum p0 = momentum(world);
  double max_linear = 0, max_angular = 0, max_separation = 0;
  for (int i = 0; i < 50; ++i) {
    world.step(100);
    const Momentum p = momentum(world);
    max_linear = std::max(max_linear, (p.linear - p0.linear).norm());
    max_angular = std::max(max_angular, (p.angular - p0.angular).norm());
    max_separation = std::max(max_separation, world.last_wrench().separation.norm());
  }
  CAPTURE(p0.linear.transpose(), p0.angular.transpose(), max_linear, max_angular, max_separation);
  REQUIRE(max_separation > 1e-4);  // the spring really worked
  CHECK(max_linear < 1e-12);  // equal and opposite impulses: exact to round-off
  // Central force, opposite torques; the residual comes from the rod applying the load over its
  // half-step kinematics while the body integrates with symplectic Euler (measured 6.5e-5).
  CHECK(max_angular < 2e-4 * p0.angular.norm());
}

namespace {

/// A rod hanging straight down from a clamp at the origin, carrying a box end-effector of `mass`.
template <typename Coupling>
manisoft::world::SoftArmWorld<ClampedRod> hanging(double mass, const Coupling& coupling) {
  RodParameters<double> rp;
  rp.direction = Eigen::Vector3d(0, 0, -1);
  rp.normal = Eigen::Vector3d(1, 0, 0);
  auto ee = box_end_effector(mass);
  // The attach frame takes the tip's directors: d1 = +x, d2 = d3 x d1 = -y, d3 = -z.
  ee.attach_rotation << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  return manisoft::world::SoftArmWorld<ClampedRod>(ClampedRod(rp, 2e-4, manisoft::rod::damping::UniformExp<double>(15)),
                                            manisoft::rigid::RigidWorldSettings{}, ee, coupling);
}

}  // namespace

TEST_CASE("a hanging load stretches the spring by m g / kF", "[world][coupling]") {
  for (double stiffness : {1e3, manisoft::interaction::ElasticSpringParameters::stiff().translational_stiffness}) {
    auto params = manisoft::interaction::ElasticSpringParameters::stiff();
    params.translational_stiffness = stiffness;
    const double mass = 0.5;
    auto world = hanging(mass, manisoft::interaction::ElasticSpring(params));
    world.step(10000);  // 2 s: the rod's uniform damping and the spring damping settle the pair
    const Eigen::Vector3d separation = world.end_effector_frame().position - world.tip_frame().position;
    CAPTURE(stiffness, separation.transpose(), mass * 9.81 / stiffness);
    CHECK(separation.z() == Approx(-mass * 9.81 / stiffness).epsilon(0.01));
    CHECK(std::abs(separation.x()) < 1e-3 * mass * 9.81 / stiffness);
    CHECK(std::abs(separation.y()) < 1e-3 * mass * 9.81 / stiffness);
    CHECK(world.rigid().linear_velocity(world.end_effector()).norm() < 1e-4);
  }
}

TEST_CASE("the paper's kF = 0.1 N/m lets a 0.2 kg gripper fall away from the arm", "[world][coupling]") {
  // Equilibrium would be m g / kF = 19.6 m below the tip; the gripper falls almost freely.
  auto world = hanging(0.2, manisoft::interaction::ElasticSpring(manisoft::interaction::ElasticSpringParameters::paper()));
  world.step(1500);  // 0.3 s
  const double drop = -world.last_wrench().separation.z();
  const double free_fall = 0.5 * 9.81 * 0.3 * 0.3;
  CAPTURE(drop, free_fall);
  CHECK(drop == Approx(free_fall).epsilon(0.03));
}

TEST_CASE("the default coupling holds gripper plus heaviest object within 1 mm and 1 degree", "[world][coupling]") {
  // 0.2 kg gripper + 0.5 kg object with its centre 5 cm off the attachment axis, on a horizontal
  // arm (the worst orientation: the lever arm is horizontal).
  RodParameters<double> rp;
  auto ee = box_end_effector(0.7, -0.05);
  manisoft::world::SoftArmWorld<ClampedRod> world(ClampedRod(rp, 2e-4, manisoft::rod::damping::UniformExp<double>(15)),
                                           manisoft::rigid::RigidWorldSettings{}, ee);
  double worst_separation = 0, worst_angle = 0;
  for (int i = 0; i < 100; ++i) {
    world.step(100);
    worst_separation = std::max(worst_separation, world.last_wrench().separation.norm());
    worst_angle = std::max(worst_angle, world.last_wrench().rotation_error.norm());
  }
  const auto& w = world.last_wrench();
  CAPTURE(worst_separation, worst_angle, w.separation.norm(), w.rotation_error.norm(), world.tip_frame().position.transpose());
  CHECK(w.separation.norm() < 1e-3);
  CHECK(w.rotation_error.norm() < 1.0 * 3.14159265358979 / 180);
  CHECK(worst_separation < 1e-3);  // also during the 2 s swing of the arm settling under the load
  CHECK(worst_angle < 1.0 * 3.14159265358979 / 180);
}

}  // namespace test_coupling
