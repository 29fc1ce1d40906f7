// Rod elements against the world (interaction::RodCapsuleContact): a rod lying on the table carries its
// weight (total normal force = m g within 1 %, penetration far below 1 mm), equal and opposite
// impulses between a free rod and a free box (linear momentum conserved to round-off), a rod on
// a slope slides with a = g (sin - mu cos) when it must and holds still (static friction, no
// creep) when mu > tan, a rod on a table pushed along its axis holds below mu m g and slides with
// a = (F - mu m g) / m above, pushed across its axis it rolls (a = 2 F / (3 m)), and an arm swung
// at its top speed into a box obstacle stops against it and never passes through.
#include <catch2/catch.hpp>

#include <cmath>

#include "manisoft/world/arm_world.hpp"

namespace test_rod_contact {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using manisoft::rod::RodParameters;
using Eigen::Vector3d;
constexpr double kDt = 2e-4;

using FreeRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::UniformExp, manisoft::rod::bc::Free,
                                      manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity>;
using WeightlessRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::None, manisoft::rod::bc::Free, manisoft::rod::integrator::PositionVerlet>;
using Arm = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                  manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                  manisoft::rod::forcing::ElementTorques>;

manisoft::rigid::BodyId add_box(manisoft::rigid::RigidWorld& w, const Vector3d& center, const Vector3d& half, bool is_static,
                         double mass = 1.0, const char* name = "box") {
  manisoft::rigid::RigidBodyDesc d;
  d.shape = manisoft::geometry::Box<double>{half};
  d.position = center;
  d.is_static = is_static;
  d.mass = is_static ? 0.0 : mass;
  d.name = name;
  return w.add_body(d);
}

/// The rod-contact loads, the rod step and the rigid step, as SoftArmWorld orders them.
template <typename Rod>
void step(Rod& rod, manisoft::rigid::RigidWorld& world, manisoft::interaction::RodCapsuleContact& contact) {
  contact.apply(rod, world);
  rod.step();
  world.step(kDt);
}

}  // namespace

TEST_CASE("a rod lying on the table carries its weight", "[world][rod_contact]") {
  manisoft::rigid::RigidWorld world;
  add_box(world, Vector3d(0.5, 0, -0.05), Vector3d(1.0, 0.5, 0.05), true, 0, "table");  // top face at z = 0
  RodParameters<double> rp;
  rp.base_position = Vector3d(0, 0, rp.radius);  // resting on the top face, along +x
  FreeRod rod(rp, kDt, manisoft::rod::damping::UniformExp<double>(5));
  manisoft::interaction::RodCapsuleContact contact;
  const double weight = rod.model().total_mass() * 9.81;
  step(rod, world, contact);
  for (int i = 0; i < 5000; ++i) step(rod, world, contact);  // 1 s: settle
  double sum_fz = 0, max_pen = 0;
  const int samples = 500;
  for (int i = 0; i < samples; ++i) {
    step(rod, world, contact);
    // The table pushes the rod up: the force on the rod's z sums the normal forces.
    sum_fz += contact.total_force_on_rod().z();
    max_pen = std::max(max_pen, contact.max_penetration());
  }
  const double mean_fz = sum_fz / samples;
  const Vector3d drift = rod.state().position(0) - rp.base_position;
  CAPTURE(weight, mean_fz, mean_fz / weight, max_pen, contact.contacts().size(), drift.transpose());
  CHECK(mean_fz == Approx(weight).epsilon(0.01));
  CHECK(max_pen < 1e-4);     // 0.02 mm expected: m_node g / (2 k)
  CHECK(max_pen > 1e-6);     // it does rest on the penalty springs
  CHECK(drift.norm() < 1e-4);
  CHECK(contact.contacts().size() == 40u);  // two points per element
}

TEST_CASE("a free rod hitting a free box: equal and opposite impulses", "[world][rod_contact]") {
  manisoft::rigid::RigidWorldSettings settings;
  settings.gravity.setZero();
  manisoft::rigid::RigidWorld world(settings);
  const auto box = add_box(world, Vector3d(0.5, 0, -0.2), Vector3d(0.1, 0.1, 0.1), false, 2.0);
  RodParameters<double> rp;
  WeightlessRod rod(rp, kDt);
  rod.state().velocities.col(2).setConstant(-1.0);  // falling onto the box at 1 m/s
  manisoft::interaction::RodCapsuleContact contact;
  auto momentum = [&] {
    Vector3d p = world.model(box).mass * world.linear_velocity(box);
    for (int i = 0; i <= rod.n_elements(); ++i) p += rod.model().node_masses[i] * rod.state().velocity(i);
    return p;
  };
  const Vector3d p0 = momentum();
  int touching = 0;
  for (int i = 0; i < 2500; ++i) {
    step(rod, world, contact);
    touching += !contact.contacts().empty();
  }
  const Vector3d p1 = momentum();
  CAPTURE(p0.transpose(), p1.transpose(), touching, world.linear_velocity(box).transpose());
  REQUIRE(touching > 10);
  CHECK(world.linear_velocity(box).z() < -0.1);  // the box was pushed
  CHECK((p1 - p0).norm() < 1e-10 * p0.norm());
}

TEST_CASE("a rod on a slope: Coulomb sliding and sticking", "[world][rod_contact]") {
  for (double mu_pair : {0.3, 0.8}) {
    const double slope = 20.0 * 3.14159265358979 / 180;  // tan = 0.36
    manisoft::rigid::RigidWorld world;
    manisoft::rigid::RigidBodyDesc d;
    d.shape = manisoft::geometry::Box<double>{Vector3d(2.0, 0.5, 0.05)};
    d.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(slope, Vector3d::UnitY()));  // descends along +x
    d.position = -d.orientation.toRotationMatrix() * Vector3d(0, 0, 0.05);  // top face through the origin
    d.is_static = true;
    d.friction = mu_pair;
    world.add_body(d);
    manisoft::interaction::RodContactParameters cp;
    cp.friction = mu_pair;  // pair mu = sqrt(mu mu) = mu_pair
    manisoft::interaction::RodCapsuleContact contact(cp);
    RodParameters<double> rp;
    const Eigen::Matrix3d r = d.orientation.toRotationMatrix();
    rp.direction = r * Vector3d::UnitX();  // lying down the slope: it slides, it cannot roll
    rp.normal = r * Vector3d::UnitZ();
    rp.base_position = r * Vector3d(-0.5, 0, rp.radius);
    FreeRod rod(rp, kDt, manisoft::rod::damping::UniformExp<double>(0));
    const Vector3d down = r * Vector3d::UnitX();
    auto mean_position = [&] { return Vector3d(rod.state().positions.colwise().mean().transpose()); };
    for (int i = 0; i < 1000; ++i) step(rod, world, contact);  // 0.2 s
    const Vector3d v1 = rod.state().velocities.colwise().mean().transpose();
    const Vector3d x1 = mean_position();
    // 0.5 s more; the mean over it of the velocity along the slope.
    double mean_v_down = 0;
    for (int i = 0; i < 2500; ++i) {
      step(rod, world, contact);
      mean_v_down += rod.state().velocities.colwise().mean().dot(down.transpose()) / 2500;
    }
    const Vector3d v2 = rod.state().velocities.colwise().mean().transpose();
    const double displacement = (mean_position() - x1).norm();
    const double accel = (v2 - v1).dot(down) / (2500 * kDt);
    const double expected = 9.81 * (std::sin(slope) - mu_pair * std::cos(slope));
    CAPTURE(mu_pair, accel, expected, v2.dot(down), mean_v_down, displacement);
    INFO("mean velocity along the slope " << mean_v_down << " m/s, displacement over 0.5 s " << displacement << " m");
    if (expected > 0) {
      // Coulomb sliding along the rod's axis.
      CHECK(accel == Approx(expected).epsilon(0.05));
    } else {
      // Static friction: the stick-slip springs hold it (elastic pre-slip of micrometres, no creep).
      CHECK(std::abs(mean_v_down) < 1e-4);
      CHECK(displacement < 1e-4);
      for (const auto& c : contact.contacts()) CHECK(c.sticking);
    }
  }
}

TEST_CASE("a rod on a table pushed along its axis: static friction, then Coulomb sliding", "[world][rod_contact]") {
  // Pushed along its axis: a push across it would roll the rod (not a test of static friction).
  constexpr double kMu = 0.5;
  for (double load_ratio : {0.6, 1.5}) {  // F / (mu m g)
    manisoft::rigid::RigidWorld world;
    manisoft::rigid::RigidBodyDesc d;
    d.shape = manisoft::geometry::Box<double>{Vector3d(2.0, 0.5, 0.05)};
    d.position = Vector3d(0.5, 0, -0.05);  // top face at z = 0
    d.is_static = true;
    d.friction = kMu;
    world.add_body(d);
    manisoft::interaction::RodContactParameters cp;
    cp.friction = kMu;  // pair mu = kMu
    manisoft::interaction::RodCapsuleContact contact(cp);
    RodParameters<double> rp;
    rp.base_position = Vector3d(0, 0, rp.radius);
    FreeRod rod(rp, kDt, manisoft::rod::damping::UniformExp<double>(0));
    const double mass = rod.model().total_mass();
    const double push = load_ratio * kMu * mass * 9.81;
    auto mean_x = [&] { return rod.state().positions.col(0).mean(); };
    auto mean_vx = [&] { return rod.state().velocities.col(0).mean(); };
    auto pushed_step = [&] {
      // The push on every node in proportion to its mass: a uniform acceleration, no bending.
      for (int i = 0; i <= rod.n_elements(); ++i)
        rod.state().external_forces(i, 0) += push * rod.model().node_masses[i] / mass;
      step(rod, world, contact);
    };
    for (int i = 0; i < 1000; ++i) step(rod, world, contact);  // 0.2 s: settle on the table
    const double x0 = mean_x();
    if (load_ratio < 1) {
      double max_drift = 0;
      for (int i = 0; i < 5000; ++i) {  // 1 s under the push
        pushed_step();
        max_drift = std::max(max_drift, std::abs(mean_x() - x0));
      }
      const double drift = mean_x() - x0;
      std::size_t sticking = 0;
      for (const auto& c : contact.contacts()) sticking += c.sticking;
      CAPTURE(mass, push, drift, max_drift, mean_vx(), sticking, contact.contacts().size());
      INFO("drift " << drift << " m, largest " << max_drift << " m, mean velocity " << mean_vx() << " m/s");
      CHECK(max_drift < 1e-4);  // the elastic pre-slip F / (40 k_t): 6 um
      CHECK(std::abs(mean_vx()) < 1e-4);
      CHECK(sticking == contact.contacts().size());
    } else {
      for (int i = 0; i < 1000; ++i) pushed_step();  // 0.2 s: break away
      const double v1 = mean_vx();
      for (int i = 0; i < 2500; ++i) pushed_step();  // 0.5 s of sliding
      const double v2 = mean_vx();
      const double accel = (v2 - v1) / (2500 * kDt);
      const double expected = (push - kMu * mass * 9.81) / mass;
      CAPTURE(mass, push, accel, expected, v2, mean_x() - x0);
      CHECK(accel == Approx(expected).epsilon(0.05));
    }
  }
}

TEST_CASE("a rod on a table pushed across its axis rolls without slipping", "[world][rod_contact]") {
  // A solid cylinder pushed at its axis rolls: a = F / (m + J / r^2) = 2 F / (3 m), the friction
  // F / 3 below mu m g. The anchors are re-based every step, so the rolling (contact point
  // wandering over the rod's surface) does not load the stick-slip springs.
  manisoft::rigid::RigidWorld world;
  add_box(world, Vector3d(0.5, 0, -0.05), Vector3d(1.0, 1.0, 0.05), true, 0, "table");
  manisoft::interaction::RodCapsuleContact contact;
  RodParameters<double> rp;
  rp.base_position = Vector3d(0, 0, rp.radius);
  FreeRod rod(rp, kDt, manisoft::rod::damping::UniformExp<double>(0));
  const double mass = rod.model().total_mass();
  const double push = 0.2 * mass * 9.81;
  auto pushed_step = [&] {
    for (int i = 0; i <= rod.n_elements(); ++i) rod.state().external_forces(i, 1) += push * rod.model().node_masses[i] / mass;
    step(rod, world, contact);
  };
  for (int i = 0; i < 1000; ++i) step(rod, world, contact);  // settle
  for (int i = 0; i < 500; ++i) pushed_step();
  const double v1 = rod.state().velocities.col(1).mean();
  for (int i = 0; i < 2500; ++i) pushed_step();
  const double v2 = rod.state().velocities.col(1).mean();
  const double accel = (v2 - v1) / (2500 * kDt);
  const double spin = rod.state().angular_velocities.col(2).mean();  // about d3 (the axis)
  std::size_t sticking = 0;
  for (const auto& c : contact.contacts()) sticking += c.sticking;
  CAPTURE(mass, push, accel, 2 * push / (3 * mass), v2, spin, spin * rp.radius, sticking, contact.contacts().size());
  CHECK(accel == Approx(2 * push / (3 * mass)).epsilon(0.05));
  CHECK(std::abs(std::abs(spin) * rp.radius - v2) < 0.05 * v2);  // rolling: omega r = v
}

namespace {

/// Swing test scene: arm clamped at (0, 0, 1) along +x (d1 = +z), a tall static box beside it.
struct SwingResult {
  double tip_speed_before = 0, max_tip_speed = 0, max_penetration = 0, min_node_clearance = 1e9, max_normal_force = 0;
  int contact_steps = 0;  ///< control steps that ended with rod-obstacle contact
  bool passed_through = false;
};

SwingResult swing_into_box(double couple) {
  manisoft::world::ArmWorldSettings s;
  s.coupling = manisoft::interaction::ElasticSpringParameters::stiff();  // the values this test was measured with
  RodParameters<double> rp;
  rp.base_position = Vector3d(0, 0, 1.0);
  manisoft::world::ArmWorld<Arm> world(Arm(rp, kDt, manisoft::rod::damping::AnalyticalLinear<double>(0.1)), s);
  // Obstacle: faces at y = 0.35 .. 0.65, x 0.3 .. 1.2, z 0.5 .. 1.5.
  manisoft::rigid::RigidBodyDesc ob;
  ob.shape = manisoft::geometry::Box<double>{Vector3d(0.45, 0.15, 0.5)};
  ob.position = Vector3d(0.75, 0.5, 1.0);
  ob.name = "obstacle";
  world.add_obstacle(ob);
  // A couple about d2 of the material frame... d1 = +z: bending about d1 swings the arm about z
  // toward +y. Torques on every element: the arm's strongest action within the limits.
  Eigen::MatrixXd tau = Eigen::MatrixXd::Zero(rp.n_elements, 3);
  for (int k = 1; k < rp.n_elements; ++k) tau(k, 0) = couple;
  SwingResult r;
  for (int c = 0; c < 300; ++c) {  // 0.42 s
    world.control_step(tau, 0);
    const auto& st = world.rod().state();
    const double v = st.velocity(rp.n_elements).norm();
    r.max_tip_speed = std::max(r.max_tip_speed, v);
    if (world.rod_contact().contacts().empty() && r.max_penetration == 0) r.tip_speed_before = v;
    r.max_penetration = std::max(r.max_penetration, world.rod_contact().max_penetration());
    bool touching = false;
    for (const auto& c : world.rod_contact().contacts()) {
      touching = touching || world.rigid().model(c.body).name == "obstacle";
      r.max_normal_force = std::max(r.max_normal_force, c.normal_force);
    }
    r.contact_steps += touching;
    for (int i = 0; i <= rp.n_elements; ++i) {
      const Vector3d x = st.position(i);
      // Inside the box's x/z extent, the clearance is the distance of the node centre to the
      // face y = 0.35; a node centre beyond it (or beyond y = 0.65) means the rod went through.
      if (x.x() > 0.3 && x.x() < 1.2 && x.z() > 0.5 && x.z() < 1.5) {
        r.min_node_clearance = std::min(r.min_node_clearance, 0.35 - x.y());
        if (x.y() > 0.35) r.passed_through = true;
      }
    }
  }
  return r;
}

}  // namespace

TEST_CASE("an arm swung at top speed into a box stops against it", "[world][rod_contact]") {
  // 10 N m on each of 19 elements (the reach task's equilibria are actuated with at most 10 N m
  // per element plus 60 N m at the tip): ~190 N m at the base, tip at ~4-6 m/s; and 2.5 times that.
  for (double couple : {10.0, 25.0}) {
    const SwingResult r = swing_into_box(couple);
    CAPTURE(couple, r.tip_speed_before, r.max_tip_speed, r.max_penetration, r.min_node_clearance, r.contact_steps, r.max_normal_force);
    CHECK(r.tip_speed_before > 2.0);  // it hit the box fast
    CHECK(r.contact_steps > 50);      // and stayed pressed against it
    CHECK(r.max_normal_force > 10.0);
    CHECK_FALSE(r.passed_through);
    CHECK(r.min_node_clearance > 0.0);
    // Deepest penetration measured: 4.8 mm at 10 N m, 10.6 mm at 25 N m; bound 1.5 times that.
    CHECK(r.max_penetration < (couple < 20 ? 0.0072 : 0.016));
  }
}

}  // namespace test_rod_contact
