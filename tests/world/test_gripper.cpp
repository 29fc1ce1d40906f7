// The parallel gripper's grasp mechanism on a gripper body driven kinematically (velocity set
// every step, gravity cancelled) above a table: the fingers move at open_width / stroke_time,
// closing on an object between them grasps it where both touch it and lifts it (sag m g / k), an
// off-centre object is pushed to the middle, closing on nothing grasps nothing, a closed gripper
// lands on an object instead of passing around it, opening stops while something presses on a
// finger's outer face, opening releases (the object falls back onto
// the table), a held object still collides with the world (a wall stops it, and pushing on makes
// the grasp slide and slip at the hold-force limit), the grip's friction (a jerk slides the
// object v^2 / 2a), the implicit weld at any stiffness, bad commands are refused.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "manisoft/interaction/gripper.hpp"

namespace test_gripper {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using Eigen::Vector3d;
using manisoft::rigid::BodyId;
constexpr double kDt = 2e-4;

struct Scene {
  manisoft::rigid::RigidWorld world;
  manisoft::interaction::ParallelGripper gripper;
  BodyId gripper_body = 0, cube = 0;
  double cube_half = 0.025, cube_mass = 0.1;

  /// Table top at z = 0; a 5 cm cube at (cube_x, 0); the gripper pointing down (+z of its frame
  /// = -z) with its fingertips 5 mm above the table, centred at (gripper_x, 0).
  explicit Scene(double cube_x, double gripper_x = 0.0) {
    manisoft::rigid::RigidBodyDesc table;
    table.shape = manisoft::geometry::Box<double>{Vector3d(1, 1, 0.05)};
    table.position = Vector3d(0, 0, -0.05);
    table.is_static = true;
    table.name = "table";
    world.add_body(table);
    auto ee = manisoft::interaction::make_parallel_gripper();
    const auto& p = gripper.parameters();
    ee.body.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Vector3d::UnitX()));
    ee.body.position = Vector3d(gripper_x, 0, p.palm_thickness + p.finger_length + 0.005);
    gripper_body = world.add_body(ee.body);
    gripper.attach(gripper_body);
    manisoft::rigid::RigidBodyDesc c;
    c.shape = manisoft::geometry::Box<double>{Vector3d::Constant(cube_half)};
    c.position = Vector3d(cube_x, 0, cube_half);
    c.mass = cube_mass;
    c.name = "cube";
    cube = world.add_body(c);
  }

  /// One step with the gripper moving at velocity v (kinematically).
  void step(const Vector3d& v) {
    world.set_velocity(gripper_body, v, Vector3d::Zero());
    world.add_force(gripper_body, -world.model(gripper_body).mass * world.settings().gravity);
    gripper.pre_step(world, kDt);
    world.step(kDt);
  }
  void run(const Vector3d& v, double seconds) {
    const int n = static_cast<int>(std::lround(seconds / kDt));
    for (int i = 0; i < n; ++i) step(v);
  }
};

}  // namespace

TEST_CASE("closing on an object between the fingers grasps and lifts it", "[world][gripper]") {
  Scene s(0.0);
  s.run(Vector3d::Zero(), 0.05);
  CHECK(s.gripper.finger_width() == Approx(0.10));
  s.gripper.command(1);
  // The gap closes at 0.10 m / 0.1 s: the fingers reach the 5 cm cube after 0.05 s (250 steps),
  // within touch_tolerance (0.5 mm) a side, one step of 0.2 mm earlier at most.
  int steps = 0;
  while (!s.gripper.held() && steps < 400) {
    s.step(Vector3d::Zero());
    ++steps;
  }
  REQUIRE(s.gripper.held());
  CHECK(*s.gripper.held() == s.cube);
  CHECK(s.gripper.grasped_now());
  CHECK(steps >= 244);
  CHECK(steps <= 250);
  CHECK(s.gripper.finger_width() >= 2 * s.cube_half);
  CHECK(s.gripper.finger_width() <= 2 * s.cube_half + 2 * 5e-4 + 1e-12);
  s.run(Vector3d::Zero(), 0.05);
  CHECK(s.gripper.finger_width() == Approx(2 * s.cube_half).margin(1e-3));  // stopped on the cube
  const Vector3d offset0 = s.world.center_of_mass(s.cube) - s.world.position(s.gripper_body);
  s.run(Vector3d(0, 0, 0.3), 1.0);      // lift 0.3 m
  s.run(Vector3d(0.5, 0.0, 0.0), 0.4);  // carry sideways at 0.5 m/s
  s.run(Vector3d::Zero(), 0.5);         // and hold
  const Vector3d offset = s.world.center_of_mass(s.cube) - s.world.position(s.gripper_body);
  // The implicit weld's static stretch under a load f is f (1 + h (c + h k) / m_eff) / k (the
  // backward-Euler spring sees the load one step late).
  manisoft::interaction::ParallelGripper::Snapshot weld;
  s.gripper.save(weld);
  const double sag = s.cube_mass * 9.81 * (1 + kDt * (weld.c + kDt * weld.k) / weld.m_eff) / weld.k;
  CAPTURE(offset0.transpose(), offset.transpose(), sag, s.world.center_of_mass(s.cube).transpose());
  REQUIRE(s.gripper.held());
  // The weld holds the cube: the gripper's contacts with it are left out (empty manifolds).
  const auto excluded = s.world.excluded_contact();
  REQUIRE(excluded);
  CHECK(excluded->body == s.cube);
  CHECK(excluded->first_geom == s.world.model(s.gripper_body).first_geom);
  CHECK(excluded->geom_count == s.world.model(s.gripper_body).geom_count);
  int pairs = 0;
  for (const auto& m : s.world.manifolds()) {
    if ((m.body_a == s.gripper_body && m.body_b == s.cube) || (m.body_b == s.gripper_body && m.body_a == s.cube)) {
      ++pairs;
      CHECK(m.count == 0);
    }
  }
  CHECK(pairs >= 2);  // the fingers' fat boxes overlap the cube's
  CHECK(s.world.center_of_mass(s.cube).z() > 0.3);
  CHECK((offset - offset0).z() == Approx(-sag).margin(0.1 * sag));  // hangs m g / k below
  CHECK((offset - offset0).head<2>().norm() < 1e-4);
  CHECK_FALSE(s.gripper.slipped());
}

TEST_CASE("the grip is friction: a jerk beyond max_hold_force slides the object v^2 / (2 a) and past max_slide it slips out", "[world][gripper]") {
  // Held and at rest 0.3 m up, the gripper jumps to v along its closing axis. The grip decelerates
  // the cube's lag at most a = max_hold_force / m = 400 m/s^2 (the 1 N of gravity changes it by
  // 0.03%), so it slides at most v^2 / (2 a) before it sticks: 1.125 cm at 3 m/s, held;
  // 3.1 cm at 5 m/s, beyond max_slide (2 cm): it slips out. The weld's damping alone stays within
  // the limit below v_t = max_hold_force (1 + h c' / m_eff) / c' (c' = c + h k), so the slide is at
  // least (v^2 - v_t^2) / (2 a).
  for (const double v : {3.0, 5.0}) {
    Scene s(0.0);
    s.gripper.command(1);
    s.run(Vector3d::Zero(), 0.1);
    REQUIRE(s.gripper.held());
    s.run(Vector3d(0, 0, 0.3), 1.0);
    s.run(Vector3d::Zero(), 0.2);
    REQUIRE(s.gripper.slide() < 1e-9);
    const double a = s.gripper.parameters().max_hold_force / s.cube_mass;
    double max_slide = 0;
    bool slipped = false;
    for (int i = 0; i < 250; ++i) {  // 50 ms
      s.step(Vector3d(v, 0, 0));
      if (s.gripper.held()) max_slide = std::max(max_slide, s.gripper.slide());
      slipped = slipped || s.gripper.slipped();
    }
    manisoft::interaction::ParallelGripper::Snapshot weld;
    s.gripper.save(weld);
    const double c_implicit = weld.c + kDt * weld.k;
    const double v_t = s.gripper.parameters().max_hold_force * (1 + kDt * c_implicit / weld.m_eff) / c_implicit;
    CAPTURE(v, max_slide, v_t);
    if (v == 3.0) {
      REQUIRE(s.gripper.held());
      CHECK_FALSE(slipped);
      CHECK(max_slide <= v * v / (2 * a) + 5e-4);
      CHECK(max_slide >= (v * v - v_t * v_t) / (2 * a) - 5e-4);
      CHECK(s.world.linear_velocity(s.cube).x() == Approx(v).margin(0.05));  // carried along
    } else {
      CHECK(slipped);
      CHECK_FALSE(s.gripper.held());
    }
  }
}

TEST_CASE("the implicit weld holds at a stiffness far beyond the explicit step's limit", "[world][gripper]") {
  // k = 1e8 N/m, k_r = 1e5 N m/rad on the cube: sqrt(k / m_eff) dt = 13 and the rotational one
  // larger, where an explicit spring diverges (its limit is 2). Lifted and carried at 5 cm/s (the
  // weld's force stays far within the grip: no slide), the cube hangs 2e-6 m below its grasp
  // (m g (1 + h c' / m_eff) / k) and turns by nothing measurable.
  manisoft::interaction::ParallelGripperParameters stiff;
  stiff.weld_stiffness = 1e8;
  stiff.weld_rotational_stiffness = 1e5;
  Scene s(0.0);
  s.gripper = manisoft::interaction::ParallelGripper(stiff);
  s.gripper.attach(s.gripper_body);
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.1);
  REQUIRE(s.gripper.held());
  const Vector3d offset0 = s.world.center_of_mass(s.cube) - s.world.position(s.gripper_body);
  const Eigen::Matrix3d r0 = s.world.orientation(s.cube).toRotationMatrix();
  s.run(Vector3d(0, 0, 0.05), 1.0);
  s.run(Vector3d(0.05, 0, 0), 0.4);
  s.run(Vector3d::Zero(), 0.5);
  REQUIRE(s.gripper.held());
  CHECK(s.gripper.slide() == 0.0);
  const Vector3d offset = s.world.center_of_mass(s.cube) - s.world.position(s.gripper_body);
  CAPTURE(offset.transpose(), offset0.transpose());
  CHECK((offset - offset0).norm() < 1e-5);
  CHECK(Eigen::AngleAxisd(s.world.orientation(s.cube).toRotationMatrix() * r0.transpose()).angle() < 1e-4);
  CHECK(s.world.linear_velocity(s.cube).norm() < 1e-3);
}

TEST_CASE("closing on nothing grasps nothing", "[world][gripper]") {
  Scene s(0.3);  // the cube is 30 cm away
  s.run(Vector3d::Zero(), 0.05);
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.05);  // half the stroke
  CHECK(s.gripper.finger_width() == Approx(0.05).margin(1e-9));
  CHECK(s.gripper.closing());
  s.run(Vector3d::Zero(), 0.06);
  CHECK_FALSE(s.gripper.held());
  CHECK_FALSE(s.gripper.closing());
  CHECK(s.gripper.state() == 1);
  CHECK(s.gripper.finger_width() == 0.0);
  const Vector3d cube0 = s.world.center_of_mass(s.cube);
  s.run(Vector3d(0, 0, 0.3), 0.5);
  // A closed gripper does not pick up what it meets later: sweep over the cube, closed.
  s.run(Vector3d(0.6, 0, -0.3), 0.5);
  CHECK_FALSE(s.gripper.held());
  CHECK(s.world.center_of_mass(s.cube).z() < cube0.z() + 1e-3);
}

TEST_CASE("opening releases the object onto the table", "[world][gripper]") {
  Scene s(0.01);  // slightly off-centre between the fingers: still grasped
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.1);
  REQUIRE(s.gripper.held());
  s.run(Vector3d(0, 0, 0.2), 0.5);  // lift 10 cm
  const double lifted = s.world.center_of_mass(s.cube).z();
  s.gripper.command(0);
  CHECK_FALSE(s.gripper.released_now());
  s.step(Vector3d::Zero());
  CHECK(s.gripper.released_now());  // the event is reported in the step it happens ...
  CHECK_FALSE(s.gripper.slipped());
  CHECK_FALSE(s.world.excluded_contact());  // the fingers collide with the cube again
  s.step(Vector3d::Zero());
  CHECK_FALSE(s.gripper.released_now());  // ... and only in that step
  s.run(Vector3d::Zero(), 0.02);
  CHECK_FALSE(s.gripper.held());
  CHECK(s.gripper.last_released() == s.cube);
  CHECK(s.gripper.opening());
  s.run(Vector3d::Zero(), 0.6);  // free fall of 7.5 cm (0.12 s), then rest
  CHECK_FALSE(s.gripper.opening());
  CHECK(s.gripper.finger_width() == Approx(0.10).margin(1e-12));
  CAPTURE(lifted, s.world.center_of_mass(s.cube).transpose());
  CHECK(lifted > 0.12);
  CHECK(s.world.center_of_mass(s.cube).z() == Approx(s.cube_half).margin(1e-3));
  CHECK(s.world.linear_velocity(s.cube).norm() < 1e-2);
}

TEST_CASE("a grasped object still collides with the world", "[world][gripper]") {
  Scene s(0.0);
  // A static curb 4.5 cm high whose face is at y = 0.2. The fingers close along x: moving along
  // +y, the cube (half size 2.5 cm) leads the fingers (half width 2 cm) by 5 mm; the palm
  // (half width 4 cm) passes above the curb.
  manisoft::rigid::RigidBodyDesc wall;
  wall.shape = manisoft::geometry::Box<double>{Vector3d(0.3, 0.05, 0.0225)};
  wall.position = Vector3d(0, 0.25, 0.0225);
  wall.is_static = true;
  wall.name = "wall";
  s.world.add_body(wall);
  manisoft::interaction::ParallelGripperParameters short_slide;
  short_slide.max_slide = 1e-3;
  s.gripper = manisoft::interaction::ParallelGripper(short_slide);
  s.gripper.attach(s.gripper_body);
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.1);
  REQUIRE(s.gripper.held());
  s.run(Vector3d(0, 0, 0.1), 0.2);  // lift 2 cm
  // Carry the cube into the wall at 0.5 m/s: its face reaches it after 0.175 m (0.35 s); pushing
  // on loads the weld to the grip's force limit (40 N: about 1 mm of stretch and damping), then
  // the cube slides in the grip and slips out once it has slid max_slide (here 1 mm), before the
  // fingers reach the wall 5 mm (10 ms) later.
  double max_face = -1;
  bool slipped = false;
  double slip_time = -1;
  for (int i = 0; i < static_cast<int>(0.36 / kDt); ++i) {
    s.step(Vector3d(0, 0.5, 0));
    max_face = std::max(max_face, s.world.center_of_mass(s.cube).y() + s.cube_half);
    if (s.gripper.slipped() && !slipped) slip_time = (i + 1) * kDt;
    slipped = slipped || s.gripper.slipped();
  }
  CAPTURE(max_face, slip_time);
  CHECK(max_face < 0.2 + 2e-3);  // stopped at the wall's face, never through it
  CHECK(max_face > 0.2 - 2e-3);
  CHECK(slipped);
  CHECK(slip_time > 0.35);
  CHECK(slip_time < 0.36);
  CHECK_FALSE(s.gripper.held());
}

TEST_CASE("the closing fingers push an off-centre object to the middle before they grasp it", "[world][gripper]") {
  Scene s(0.02);  // 2 cm towards the +x finger: its inner face (at 5 cm) is 5 mm from the cube
  s.gripper.command(1);
  double first_touch = -1;
  for (int i = 0; i < 400 && !s.gripper.held(); ++i) {
    s.step(Vector3d::Zero());
    if (first_touch < 0 && s.world.center_of_mass(s.cube).x() < 0.02 - 1e-4) first_touch = (i + 1) * kDt;
  }
  REQUIRE(s.gripper.held());
  // The +x finger moves at 0.5 m/s: it reaches the cube after 5 mm (0.01 s) and pushes it; the
  // grasp comes when the other finger touches, with the cube between them, at the middle.
  CAPTURE(first_touch, s.world.center_of_mass(s.cube).transpose());
  CHECK(first_touch == Approx(0.01).margin(0.002));
  CHECK(std::abs(s.world.center_of_mass(s.cube).x() - s.world.position(s.gripper_body).x()) < 2e-3);
  CHECK(s.world.center_of_mass(s.cube).z() == Approx(s.cube_half).margin(1e-3));  // slid, not lifted or tipped
  CHECK(s.gripper.finger_width() == Approx(2 * s.cube_half).margin(2e-3));
}

TEST_CASE("a closed gripper lands on an object instead of passing around it", "[world][gripper]") {
  Scene s(0.0);
  s.run(Vector3d(0, 0, 0.2), 0.5);  // up 10 cm, open: the cube is out of reach
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.12);
  REQUIRE(s.gripper.finger_width() == 0.0);
  REQUIRE_FALSE(s.gripper.held());
  // Down at 0.2 m/s for 0.7 s (14 cm): open fingers would straddle the cube; closed ones stop on
  // its top face (z = 5 cm), and the cube stays on the table.
  const auto& p = s.gripper.parameters();
  s.run(Vector3d(0, 0, -0.2), 0.7);
  const double tips = s.world.position(s.gripper_body).z() - (p.palm_thickness + p.finger_length);
  CAPTURE(tips, s.world.center_of_mass(s.cube).transpose());
  CHECK(tips > 2 * s.cube_half - 3e-3);
  CHECK(tips < 2 * s.cube_half + 1e-3);
  CHECK(s.world.center_of_mass(s.cube).z() == Approx(s.cube_half).margin(2e-3));
  CHECK_FALSE(s.gripper.held());
}

TEST_CASE("opening stops while something presses on a finger's outer face", "[world][gripper]") {
  Scene s(0.0);
  s.gripper.command(1);
  s.run(Vector3d::Zero(), 0.1);
  REQUIRE(s.gripper.held());
  const double held_width = s.gripper.finger_width();
  // A static block 4 cm high just outside the +x finger (its outer face at held_width / 2 +
  // finger_thickness; the block 0.2 mm beyond): opening would push into it.
  const auto& p = s.gripper.parameters();
  const double face = 0.5 * held_width + p.finger_thickness + 2e-4;
  manisoft::rigid::RigidBodyDesc block;
  block.shape = manisoft::geometry::Box<double>{Vector3d(0.03, 0.05, 0.02)};
  block.position = Vector3d(face + 0.03, 0, 0.02);
  block.is_static = true;
  block.name = "block";
  s.world.add_body(block);
  s.gripper.command(0);
  s.run(Vector3d::Zero(), 0.05);  // half a stroke
  CHECK_FALSE(s.gripper.held());
  CHECK(s.gripper.finger_width() == Approx(held_width).margin(1e-3));  // stopped by the block
  CHECK(s.gripper.opening());
  // Up at 0.2 m/s: the fingertips (5 mm above the table) clear the block's top (4 cm) after
  // 0.175 s; then the fingers open fully within the rest of a stroke.
  s.run(Vector3d(0, 0, 0.2), 0.15);
  CHECK(s.gripper.finger_width() == Approx(held_width).margin(1e-3));
  s.run(Vector3d(0, 0, 0.2), 0.2);
  CHECK(s.gripper.finger_width() == Approx(p.open_width));
  CHECK_FALSE(s.gripper.opening());
  CHECK(s.world.center_of_mass(s.cube).z() == Approx(s.cube_half).margin(1e-3));  // left on the table
}

TEST_CASE("the gripper refuses bad commands and parameters", "[world][gripper]") {
  manisoft::interaction::ParallelGripper g;
  CHECK_THROWS_WITH(g.command(2), Catch::Matchers::Contains("S = 2"));
  manisoft::interaction::ParallelGripperParameters p;
  p.open_width = 0.2;  // wider than the palm
  CHECK_THROWS_WITH(manisoft::interaction::ParallelGripper(p), Catch::Matchers::Contains("palm_half_x"));
  p = {};
  p.stroke_time = 0;
  CHECK_THROWS_WITH(manisoft::interaction::ParallelGripper(p), Catch::Matchers::Contains("stroke_time = 0"));
  p = {};
  p.mass = -1;
  CHECK_THROWS_WITH(manisoft::interaction::make_parallel_gripper(p), Catch::Matchers::Contains("mass = -1"));
}

}  // namespace test_gripper
