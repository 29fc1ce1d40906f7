// ArmWorld (rod + gripper + table + objects): a grasp made by the arm holds through the arm's
// fastest swing; the world is deterministic (bit-identical reruns); a non-finite state is
// reported naming the rod node/element or the body; objects leaving the table or the workspace
// are reported as events and the world keeps running.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace test_arm_world {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using Eigen::Vector3d;
using manisoft::rigid::BodyId;
using Catch::Matchers::Contains;
constexpr double kDt = 2e-4;
using Arm = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                  manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                  manisoft::rod::forcing::ElementTorques>;
using Torques = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// The arm hanging straight down from (0, 0, 1.3) (d1 = +x: the fingers close along x), a 5 cm
/// cube of `mass` on a narrow pedestal between the open fingers.
struct Hanging {
  manisoft::world::ArmWorld<Arm> world;
  BodyId cube = 0, pedestal = 0;
  explicit Hanging(double mass) : world(make_arm()) {
    manisoft::rigid::RigidBodyDesc floor;
    floor.shape = manisoft::geometry::Box<double>{Vector3d(2, 2, 0.05)};
    floor.position = Vector3d(0, 0, -0.05);
    floor.is_static = true;
    floor.name = "floor";
    world.add_obstacle(floor);
    manisoft::rigid::RigidBodyDesc ped;
    ped.shape = manisoft::geometry::Box<double>{Vector3d(0.015, 0.015, 0.085)};
    ped.position = Vector3d(0, 0, 0.085);  // top at z = 0.17
    ped.name = "pedestal";
    ped.mass = 5.0;  // dynamic, so a test can take it away (set_pose) after the grasp
    pedestal = world.rigid().add_body(ped);
    manisoft::rigid::RigidBodyDesc c;
    c.shape = manisoft::geometry::Box<double>{Vector3d::Constant(0.025)};
    c.position = Vector3d(0, 0, 0.195);  // the grasp region spans z 0.18 .. 0.25
    c.mass = mass;
    c.name = "cube";
    cube = world.add_object(c);
  }
  static Arm make_arm() {
    manisoft::rod::RodParameters<double> rp;
    rp.base_position = Vector3d(0, 0, 1.3);
    rp.direction = Vector3d(0, 0, -1);
    rp.normal = Vector3d(1, 0, 0);
    return Arm(rp, kDt, manisoft::rod::damping::AnalyticalLinear<double>(0.5));
  }
};

}  // namespace

TEST_CASE("a grasp holds through the arm's fastest swing", "[world][gripper][arm]") {
  Hanging h(0.1);
  auto& w = h.world;
  const int n = w.rod().n_elements();
  Torques zero = Torques::Zero(n, 3);
  for (int i = 0; i < 70; ++i) w.control_step(zero, 0);  // 0.1 s
  // The fingers close in stroke_time (0.1 s, 70 control steps): they reach the cube half way.
  int steps = 0;
  while (!w.gripper().held() && steps < 80) {
    w.control_step(zero, 1);
    ++steps;
  }
  CHECK(steps > 20);
  CHECK(steps < 50);
  REQUIRE(w.gripper().held());
  REQUIRE(*w.gripper().held() == h.cube);
  // Take the pedestal away: the swing passes through the lowest point again.
  w.rigid().set_pose(h.pedestal, Vector3d(2.5, 0, 0.085), Eigen::Quaterniond::Identity());
  const auto relative = [&] {
    const Eigen::Matrix3d r = w.rigid().orientation(w.gripper_body()).toRotationMatrix();
    return Vector3d(r.transpose() * (w.rigid().center_of_mass(h.cube) - w.rigid().position(w.gripper_body())));
  };
  const Vector3d rel0 = relative();
  // Swing: 3 N m per element about d2, then reversed: the hanging arm whips its gripper through
  // 4-5 m/s, the speeds of the fastest swings in test_rod_contact.
  Torques swing = Torques::Zero(n, 3);
  for (int k = 1; k < n; ++k) swing(k, 1) = 3.0;
  double max_speed = 0, max_force = 0, max_shift = 0;
  for (int i = 0; i < 700; ++i) {  // 1 s
    w.control_step(i < 150 ? swing : (i < 300 ? Torques(-swing) : zero), 1);
    max_speed = std::max(max_speed, w.rigid().linear_velocity(w.gripper_body()).norm());
    max_force = std::max(max_force, w.gripper().grip_force());
    max_shift = std::max(max_shift, (relative() - rel0).norm());
  }
  CAPTURE(max_speed, max_force, max_shift, w.rigid().center_of_mass(h.cube).transpose());
  CHECK(max_speed > 3.0);
  CHECK(w.gripper().held());
  CHECK(max_force < w.gripper().parameters().max_hold_force);
  CHECK(max_shift < 2e-3);
  CHECK(w.events().size() == 1u);  // the grasp only
  // Opening releases the cube.
  w.control_step(zero, 0);
  CHECK_FALSE(w.gripper().held());
  REQUIRE(w.events().size() == 2u);
  CHECK(w.events().back().kind == manisoft::world::WorldEvent::Kind::released);
}

namespace {

/// The tabletop scene with the arm curled down onto the table, for `steps` substeps.
/// Returns the number of rod contact points summed over the control steps.
template <typename World>
long run_tabletop(World& w, int control_steps) {
  const int n = w.rod().n_elements();
  Torques t = Torques::Zero(n, 3);
  for (int k = 1; k < n; ++k) t(k, 1) = -10.0;
  long contacts = 0;
  for (int i = 0; i < control_steps; ++i) {
    w.control_step(t, i > control_steps / 2 ? 1 : 0);
    contacts += static_cast<long>(w.rod_contact().contacts().size());
  }
  return contacts;
}

}  // namespace

TEST_CASE("the world is deterministic", "[world][arm]") {
  auto make = [] {
    return manisoft::world::ArmWorld<Arm>(Arm(manisoft::world::tabletop_arm_parameters(), kDt, manisoft::rod::damping::AnalyticalLinear<double>(0.5)));
  };
  manisoft::world::ArmWorld<Arm> a = make(), b = make();
  manisoft::world::populate_tabletop(a);
  manisoft::world::populate_tabletop(b);
  const long contacts = run_tabletop(a, 600);
  run_tabletop(b, 600);
  CAPTURE(contacts);
  REQUIRE(contacts > 0);  // the arm touched the table
  CHECK(a.rod().state().positions == b.rod().state().positions);
  CHECK(a.rod().state().velocities == b.rod().state().velocities);
  CHECK(a.rod().state().directors == b.rod().state().directors);
  for (BodyId i = 0; i < a.rigid().body_count(); ++i) {
    CHECK(a.rigid().state(i).position == b.rigid().state(i).position);
    CHECK(a.rigid().state(i).orientation.coeffs() == b.rigid().state(i).orientation.coeffs());
    CHECK(a.rigid().state(i).linear_velocity == b.rigid().state(i).linear_velocity);
  }
}

TEST_CASE("a non-finite state is reported with the element or body", "[world][arm]") {
  {
    Hanging h(0.1);
    h.world.step(10);
    h.world.rod().state().velocities(7, 1) = std::numeric_limits<double>::quiet_NaN();
    // NaN spreads to the neighbours within the step; the first bad node is named.
    CHECK_THROWS_WITH(h.world.step(), Contains("non-finite state at node") && Contains("rod"));
  }
  {
    Hanging h(0.1);
    h.world.rigid().set_pose(h.cube, Vector3d(1, 1, 1), Eigen::Quaterniond::Identity());  // touching nothing
    h.world.step(10);
    const double big = std::numeric_limits<double>::max();
    h.world.rigid().add_force(h.cube, Vector3d(big, 0, 0));
    h.world.rigid().add_force(h.cube, Vector3d(big, 0, 0));  // the sum overflows to inf
    CHECK_THROWS_WITH(h.world.step(), Contains("rigid body") && Contains("'cube'") && Contains("non-finite"));
  }
  {
    Hanging h(0.1);
    Torques t = Torques::Zero(h.world.rod().n_elements(), 3);
    t(4, 2) = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(h.world.control_step(t, 0), Contains("(4, 2)"));
    CHECK_THROWS_WITH(h.world.control_step(Torques::Zero(h.world.rod().n_elements(), 3), 3), Contains("S = 3"));
  }
}

TEST_CASE("objects leaving the table or the workspace are reported, not fatal", "[world][arm]") {
  manisoft::world::ArmWorldSettings s;
  s.workspace_lo = Vector3d(-1, -1, 0.3);  // below the table top (0.75) but above the floor
  s.workspace_hi = Vector3d(2, 1, 3);
  manisoft::world::ArmWorld<Arm> w(Arm(manisoft::world::tabletop_arm_parameters(), kDt, manisoft::rod::damping::AnalyticalLinear<double>(0.5)), s);
  const auto ids = manisoft::world::populate_tabletop(w);
  const BodyId ball = ids[5];
  w.step(10);
  w.rigid().set_velocity(ball, Vector3d(0, -3, 0), Vector3d::Zero());  // rolls off the side
  for (int i = 0; i < 5000 && w.events().size() < 2; ++i) w.step();
  REQUIRE(w.events().size() >= 2u);
  CHECK(w.events()[0].kind == manisoft::world::WorldEvent::Kind::left_table);
  CHECK(w.events()[0].name == "ball");
  CHECK(w.events()[1].kind == manisoft::world::WorldEvent::Kind::left_workspace);
  CHECK(w.is_off_table(ball));
  w.step(2500);  // keeps running; the floor catches the ball
  CHECK(w.rigid().center_of_mass(ball).z() > 0);
  CHECK(w.events().size() == 2u);  // reported once
}

}  // namespace test_arm_world
