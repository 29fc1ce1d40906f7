// A world step allocates no heap memory once the scene is set up and has run: the world_demo
// scene (table, floor, arm with gripper, eight objects) with the arm pressing the gripper onto the
// table and moving, and with the gripper holding an object. Global operator new is counted, not
// assumed.
#include <catch2/catch.hpp>

#include "../support/allocation_counter.hpp"

#include <cmath>

#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

using manisoft_test::allocation_count;

namespace {

using Arm = manisoft::CosseratRod<double, manisoft::damping::AnalyticalLinear, manisoft::bc::ClampedBase,
                                  manisoft::integrator::PositionVerlet, manisoft::forcing::Gravity,
                                  manisoft::forcing::ElementTorques>;
using Torques = Eigen::Matrix<double, Eigen::Dynamic, 3>;

Torques bend(int n, double per_element_about_d2) {
  Torques t = Torques::Zero(n, 3);
  for (int k = 1; k < n; ++k) t(k, 1) = per_element_about_d2;
  return t;
}

}  // namespace

TEST_CASE("a world step allocates no heap memory in steady state", "[world][alloc]") {
  const bool hold = GENERATE(false, true);
  CAPTURE(hold);
  const manisoft::tabletop::ArmMount mount;
  manisoft::ArmWorld<Arm> world(Arm(manisoft::tabletop::arm_parameters(mount), 2e-4, manisoft::damping::AnalyticalLinear<double>(0.5)));
  const auto objects = manisoft::tabletop::populate(world);
  const int n = world.rod().n_elements();
  Torques torques = bend(n, -3.0);  // bends the arm down towards the table top
  world.rod().forcing<manisoft::forcing::ElementTorques>().set(torques);
  if (hold) {
    const Eigen::Vector3d g = world.gripper().grasp_point(world.rigid());
    world.rigid().set_pose(objects[0], g - Eigen::Vector3d(0, 0, 0.025), world.rigid().orientation(objects[0]));
    world.set_gripper(1);
  }
  world.step(5000);  // 1 s of set-up: contacts found, buffers at their working size
  const long before = allocation_count.load();
  for (int control = 0; control < 300; ++control) {  // 0.42 s of moving arm at 714 Hz
    torques(n - 1, 1) = -3.0 + 2.0 * std::sin(0.05 * control);
    world.rod().forcing<manisoft::forcing::ElementTorques>().set(torques);
    world.step(7);
  }
  const long allocations = allocation_count.load() - before;
  CAPTURE(world.rod_contact().contacts().size(), world.gripper().held());
  CHECK(allocations == 0);
  if (hold) CHECK(world.gripper().held());
}

TEST_CASE("rod contact on every element allocates nothing in steady state", "[world][alloc]") {
  // A free rod lying on a table: 40 contact points every step through rod_contact::Capsules.
  using FreeRod = manisoft::CosseratRod<double, manisoft::damping::UniformExp, manisoft::bc::Free,
                                        manisoft::integrator::PositionVerlet, manisoft::forcing::Gravity>;
  manisoft::RigidWorld world;
  manisoft::RigidBodyDesc table;
  table.shape = manisoft::Box<double>{Eigen::Vector3d(1.0, 0.5, 0.05)};
  table.position = Eigen::Vector3d(0.5, 0, -0.05);
  table.is_static = true;
  world.add_body(table);
  manisoft::RodParameters<double> rp;
  rp.base_position = Eigen::Vector3d(0, 0, rp.radius);
  FreeRod rod(rp, 2e-4, manisoft::damping::UniformExp<double>(5));
  manisoft::rod_contact::Capsules contact;
  auto step = [&] {
    contact.apply(rod, world);
    rod.step();
    world.step(2e-4);
  };
  for (int i = 0; i < 2000; ++i) step();
  const long before = allocation_count.load();
  for (int i = 0; i < 1000; ++i) step();
  const long allocations = allocation_count.load() - before;  // read before Catch allocates
  CAPTURE(contact.contacts().size());
  CHECK(contact.contacts().size() >= 20);
  CHECK(allocations == 0);
}
