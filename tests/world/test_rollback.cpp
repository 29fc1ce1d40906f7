// One rollback for the whole arm world: a step that fails part-way (after the gripper's weld
// wrench, the coupling, the rod-contact friction anchors and the rod's first half step have run)
// leaves the world exactly as before it, and continuing is bit-identical to a run that never tried
// that step; a saved snapshot replays the same future; worlds are built by value (movable).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <utility>

#include "manisoft/world/arm_world.hpp"

namespace test_rollback {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using Eigen::Vector3d;
using manisoft::rigid::BodyId;
using Catch::Matchers::Contains;
constexpr double kDt = 2e-4;
using Arm = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                       manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                       manisoft::rod::forcing::ElementTorques>;
using World = manisoft::world::ArmWorld<Arm>;
using Torques = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// The arm hanging from (0, 0, 1.3) along -z (d1 = +x) against a wall whose face is at x = 0.048
/// (the rod touches it over its length), a cube held between the fingers, a box resting on the
/// floor: every kind of state a step changes is in play (rod-contact anchors, the weld, rigid
/// contact manifolds with warm starts).
World make_world() {
  manisoft::rod::RodParameters<double> rp;
  rp.base_position = Vector3d(0, 0, 1.3);
  rp.direction = Vector3d(0, 0, -1);
  rp.normal = Vector3d(1, 0, 0);
  World world(Arm(rp, kDt, manisoft::rod::damping::AnalyticalLinear<double>(0.5)));
  manisoft::rigid::RigidBodyDesc floor;
  floor.shape = manisoft::geometry::Box<double>{Vector3d(2, 2, 0.05)};
  floor.position = Vector3d(0, 0, -0.05);
  floor.is_static = true;
  floor.name = "floor";
  world.add_obstacle(floor);
  manisoft::rigid::RigidBodyDesc wall;
  wall.shape = manisoft::geometry::Box<double>{Vector3d(0.05, 0.5, 0.3)};
  wall.position = Vector3d(0.098, 0, 0.85);
  wall.is_static = true;
  wall.name = "wall";
  world.add_obstacle(wall);
  manisoft::rigid::RigidBodyDesc cube;
  cube.shape = manisoft::geometry::Box<double>{Vector3d::Constant(0.025)};
  cube.position = Vector3d(0, 0, 0.215);  // in the grasp region (z 0.18 .. 0.25 below the palm)
  cube.mass = 0.1;
  cube.name = "cube";
  world.add_object(cube);
  manisoft::rigid::RigidBodyDesc box;
  box.shape = manisoft::geometry::Box<double>{Vector3d(0.04, 0.04, 0.03)};
  box.position = Vector3d(0.4, 0.3, 0.0305);
  box.mass = 0.3;
  box.name = "box";
  world.add_object(box);
  return world;  // by value: ArmWorld (and its RigidWorld) are movable
}

/// Torques that swing the hanging arm sideways along the wall (about d1) and back.
Torques swing(int n, int control_step) {
  Torques t = Torques::Zero(n, 3);
  const double couple = 6.0 * std::sin(0.02 * control_step);
  for (int k = 1; k < n; ++k) t(k, 0) = couple;
  return t;
}

/// Bitwise equality of everything observable.
void require_identical(const World& a, const World& b) {
  REQUIRE(a.step_count() == b.step_count());
  REQUIRE(a.rod().step_count() == b.rod().step_count());
  REQUIRE(a.rod().state().positions == b.rod().state().positions);
  REQUIRE(a.rod().state().velocities == b.rod().state().velocities);
  REQUIRE(a.rod().state().directors == b.rod().state().directors);
  REQUIRE(a.rod().state().angular_velocities == b.rod().state().angular_velocities);
  REQUIRE(a.rod().state().time == b.rod().state().time);
  REQUIRE(a.rigid().step_count() == b.rigid().step_count());
  for (BodyId i = 0; i < a.rigid().body_count(); ++i) {
    const auto& sa = a.rigid().state(i);
    const auto& sb = b.rigid().state(i);
    CAPTURE(i);
    REQUIRE(sa.position == sb.position);
    REQUIRE(sa.orientation.coeffs() == sb.orientation.coeffs());
    REQUIRE(sa.linear_velocity == sb.linear_velocity);
    REQUIRE(sa.angular_velocity == sb.angular_velocity);
  }
  REQUIRE(a.gripper().held() == b.gripper().held());
  REQUIRE(a.gripper().finger_width() == b.gripper().finger_width());
  for (std::size_t g = 0; g < a.rigid().geoms().size(); ++g) {
    REQUIRE(a.rigid().geoms()[g].local.translation == b.rigid().geoms()[g].local.translation);
    REQUIRE(a.rigid().geoms()[g].surface_velocity == b.rigid().geoms()[g].surface_velocity);
  }
  REQUIRE(a.gripper().weld_force() == b.gripper().weld_force());
  REQUIRE(a.rod_contact().contacts().size() == b.rod_contact().contacts().size());
  REQUIRE(a.events().size() == b.events().size());
}

}  // namespace

TEST_CASE("a step that fails part-way is undone, and continuing is bit-identical to never trying it", "[world][rollback]") {
  World a = make_world(), b = make_world();
  const int n = a.rod().n_elements();
  for (int c = 0; c < 150; ++c) {
    a.control_step(swing(n, c), 1);
    b.control_step(swing(n, c), 1);
  }
  // Everything the rollback must cover is active now.
  REQUIRE(a.gripper().held());
  REQUIRE(a.rod_contact().contacts().size() >= 2);
  REQUIRE(a.rigid().touching_point_count() >= 4);
  require_identical(a, b);

  // A non-finite load on node 9: the rod refuses it in its first force evaluation, after the
  // gripper, the coupling, the rod contact and the rod's first half step have already run.
  a.rod().state().external_forces(9, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(a.step(), Contains("node 9") && Contains("SoftArmWorld step"));
  CHECK_THROWS_AS((a.rod().state().external_forces(9, 1) = std::numeric_limits<double>::infinity(), a.step()), manisoft::InvalidInput);
  require_identical(a, b);  // as before the failed steps, the queued loads dropped

  // A diverged state: the step throws Diverged naming where, and restores the state.
  const double saved = a.rod().state().velocities(7, 1);
  a.rod().state().velocities(7, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    a.step();
    FAIL("the step should have been refused");
  } catch (const manisoft::Diverged& e) {
    CAPTURE(e.where());
    CHECK(e.where().rfind("node ", 0) == 0);  // the first node whose state went non-finite
    CHECK(e.step() == a.step_count());
  }
  CHECK(std::isnan(a.rod().state().velocities(7, 1)));  // the state before the step, as it was
  a.rod().state().velocities(7, 1) = saved;
  require_identical(a, b);

  // A rigid body that blows up inside the rigid step (after the rod's step succeeded): an absurd
  // spin overflows the gyroscopic update. The held cube moves, so resetting its velocity leaves
  // nothing else changed (its sleep timer is zero either way).
  const BodyId cube = a.objects()[0];
  const Vector3d v = a.rigid().linear_velocity(cube), w = a.rigid().angular_velocity(cube);
  REQUIRE(a.rigid().state(cube).sleep_time == 0.0);
  a.rigid().set_velocity(cube, v, Vector3d(1e200, 0, 0));
  CHECK_THROWS_WITH(a.step(), Contains("rigid body") && Contains("non-finite"));  // the gripper welded to it goes first
  a.rigid().set_velocity(cube, v, w);
  require_identical(a, b);

  for (int c = 150; c < 400; ++c) {
    if (c == 310) {  // the fingers are on their way open: a failed step puts them back too
      REQUIRE(a.gripper().opening());
      a.rod().state().external_forces(9, 1) = std::numeric_limits<double>::quiet_NaN();
      CHECK_THROWS_AS(a.step(), manisoft::InvalidInput);
      require_identical(a, b);
    }
    a.control_step(swing(n, c), c < 300 ? 1 : 0);
    b.control_step(swing(n, c), c < 300 ? 1 : 0);
  }
  require_identical(a, b);
  CHECK_FALSE(a.gripper().held());  // released at control step 300: the weld state went through it too
}

TEST_CASE("a saved snapshot of the arm world replays the same future", "[world][rollback]") {
  World w = make_world();
  const int n = w.rod().n_elements();
  for (int c = 0; c < 100; ++c) w.control_step(swing(n, c), 1);
  World::Soft::Snapshot snapshot;
  w.soft().save(snapshot);
  const auto events_before = w.events().size();
  auto run = [&](World& world) {
    for (int c = 100; c < 250; ++c) world.control_step(swing(n, c), c < 200 ? 1 : 0);
    return std::make_pair(world.rod().state().positions, world.rigid().state(3).position);
  };
  const auto first = run(w);
  REQUIRE(w.events().size() > events_before);  // the release happened in the replayed span
  w.soft().restore(snapshot);
  const auto second = run(w);
  CHECK(first.first == second.first);
  CHECK(first.second == second.second);
}

TEST_CASE("a rigid world snapshot restores contacts, caches and counters", "[world][rollback]") {
  manisoft::rigid::RigidWorld world;
  manisoft::rigid::RigidBodyDesc ground;
  ground.shape = manisoft::geometry::Box<double>{Vector3d(1, 1, 0.1)};
  ground.position = Vector3d(0, 0, -0.1);
  ground.is_static = true;
  world.add_body(ground);
  for (int i = 0; i < 3; ++i) {
    manisoft::rigid::RigidBodyDesc box;
    box.shape = manisoft::geometry::Box<double>{Vector3d::Constant(0.05)};
    box.position = Vector3d(0.01 * i, 0, 0.05 + 0.1 * i + 0.02);  // a falling stack
    box.mass = 0.5;
    world.add_body(box);
  }
  manisoft::rigid::RigidWorld twin;  // the same world, never failing
  for (BodyId i = 0; i < world.body_count(); ++i) {
    manisoft::rigid::RigidBodyDesc d;
    d.shape = i == 0 ? manisoft::geometry::Shape<double>(ground.shape) : manisoft::geometry::Shape<double>(manisoft::geometry::Box<double>{Vector3d::Constant(0.05)});
    d.position = world.position(i);
    d.is_static = i == 0;
    d.mass = i == 0 ? 0.0 : 0.5;
    twin.add_body(d);
  }
  for (int i = 0; i < 100; ++i) {
    world.step(kDt);
    twin.step(kDt);
  }
  // A step that fails inside (an absurd spin overflows the gyroscopic update of the falling top
  // box) leaves the world as before it: continuing matches the twin bit for bit.
  const Vector3d v = world.linear_velocity(3), w = world.angular_velocity(3);
  REQUIRE(world.state(3).sleep_time == 0.0);
  world.set_velocity(3, v, Vector3d(1e200, 0, 0));
  CHECK_THROWS_AS(world.step(kDt), manisoft::Diverged);
  world.set_velocity(3, v, w);
  for (int i = 0; i < 400; ++i) {
    world.step(kDt);
    twin.step(kDt);
  }
  for (BodyId i = 1; i < world.body_count(); ++i) {
    CHECK(world.state(i).position == twin.state(i).position);
    CHECK(world.state(i).angular_velocity == twin.state(i).angular_velocity);
  }
  REQUIRE(world.touching_point_count() >= 4);
  manisoft::rigid::RigidWorld::Snapshot snapshot;
  world.save(snapshot);
  auto run = [&] {
    for (int i = 0; i < 2000; ++i) world.step(kDt);
    return std::make_pair(world.state(3).position, world.state(3).orientation.coeffs());
  };
  const auto first = run();
  const auto steps = world.step_count();
  world.restore(snapshot);
  CHECK(world.step_count() == steps - 2000);
  const auto second = run();
  CHECK(first.first == second.first);
  CHECK(first.second == second.second);

  // Moved worlds keep working: the broad phase's object pointers survive the move.
  manisoft::rigid::RigidWorld moved = std::move(world);
  for (int i = 0; i < 100; ++i) moved.step(kDt);
  CHECK(moved.state(3).position.allFinite());
  CHECK(moved.touching_point_count() >= 4);
}

}  // namespace test_rollback
