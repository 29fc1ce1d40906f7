// A world step allocates no heap memory once the scene is set up and has run: the world_demo
// scene (table, floor, arm with gripper, eight objects) with the arm pressing the gripper onto the
// table and moving, and with the gripper holding an object; and a whole reach episode (executor
// act() after the target's set-up, environment step with reward) allocates nothing either.
// Global operator new is counted, not assumed.
#include <catch2/catch.hpp>

#include "../support/allocation_counter.hpp"

#include <cmath>

#include "manisoft/control/mlp_executor.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/control/projected_executor.hpp"
#include "manisoft/env/reach_env.hpp"
#include "manisoft/env/rollout.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace test_world_alloc {  // per-file namespace: the group's tests build as one unity translation unit

using manisoft_test::allocation_count;

namespace {

using Arm = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                  manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                  manisoft::rod::forcing::ElementTorques>;
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
  const manisoft::world::ArmMount mount;
  manisoft::world::ArmWorld<Arm> world(Arm(manisoft::world::tabletop_arm_parameters(mount), 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(0.5)));
  const auto objects = manisoft::world::populate_tabletop(world);
  const int n = world.rod().n_elements();
  // Bends the arm down onto the table top; holding the cube, less: slammed into the table by the
  // falling arm, the cube would stretch the weld past max_hold_force and slip out.
  const double base = hold ? -2.0 : -3.0;
  Torques torques = bend(n, base);
  world.rod().forcing<manisoft::rod::forcing::ElementTorques>().set(torques);
  if (hold) {
    const Eigen::Vector3d g = world.gripper().grasp_point(world.rigid());
    world.rigid().set_pose(objects[0], g - Eigen::Vector3d(0, 0, 0.025), world.rigid().orientation(objects[0]));
    world.set_gripper(1);
  }
  world.step(5000);  // 1 s of set-up: contacts found, buffers at their working size
  const long before = allocation_count.load();
  for (int control = 0; control < 300; ++control) {  // 0.42 s of moving arm at 714 Hz
    torques(n - 1, 1) = base + 2.0 * std::sin(0.05 * control);
    world.rod().forcing<manisoft::rod::forcing::ElementTorques>().set(torques);
    world.step(7);
  }
  const long allocations = allocation_count.load() - before;
  CAPTURE(world.rod_contact().contacts().size(), world.gripper().held());
  CHECK(allocations == 0);
  if (hold) CHECK(world.gripper().held());
}

TEST_CASE("rod contact on every element allocates nothing in steady state", "[world][alloc]") {
  // A free rod lying on a table: 40 contact points every step through interaction::RodCapsuleContact.
  using FreeRod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::UniformExp, manisoft::rod::bc::Free,
                                        manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity>;
  manisoft::rigid::RigidWorld world;
  manisoft::rigid::RigidBodyDesc table;
  table.shape = manisoft::geometry::Box<double>{Eigen::Vector3d(1.0, 0.5, 0.05)};
  table.position = Eigen::Vector3d(0.5, 0, -0.05);
  table.is_static = true;
  world.add_body(table);
  manisoft::rod::RodParameters<double> rp;
  rp.base_position = Eigen::Vector3d(0, 0, rp.radius);
  FreeRod rod(rp, 2e-4, manisoft::rod::damping::UniformExp<double>(5));
  manisoft::interaction::RodCapsuleContact contact;
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

namespace {

/// Allocations during one episode after its set-up: reset(), the executor's first act() (the
/// target's inverse statics) and the first control step (the world sizes its buffers).
template <typename Env, typename Executor>
long episode_allocations(Env& env, Executor& executor, std::uint64_t seed, bool& success) {
  long start = 0, end = 0;
  const auto record = manisoft::env::rollout(env, executor, seed, [&](const auto& step) {
    if (step.step == 0) start = allocation_count.load();
    if (step.result.done) end = allocation_count.load();
  });
  success = record.info.success;
  return end - start;
}

}  // namespace

TEST_CASE("a reach episode allocates nothing after the target's set-up", "[executor][alloc]") {
  bool success = false;
  SECTION("model executor, element torques, with an unknown load (the outer loop re-solves)") {
    manisoft::env::ReachEnvConfig config;
    config.load_mass = 0.3;
    config.model_error = 0.1;
    manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear> env(config, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
    manisoft::control::ModelExecutor<double> executor(env.nominal_model(), config.limits);
    CHECK(episode_allocations(env, executor, 5, success) == 0);
    CHECK(success);
  }
  SECTION("model executor through the B-spline projection") {
    manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear, manisoft::control::BsplineMuscleAction> env(
        {}, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
    manisoft::control::ProjectedExecutor executor(manisoft::control::ModelExecutor<double>(env.nominal_model(), env.config().limits),
                                                  env.action_space());
    CHECK(episode_allocations(env, executor, 6, success) == 0);
    CHECK(success);
  }
  SECTION("MLP executor") {
    manisoft::env::ReachEnv<manisoft::rod::damping::AnalyticalLinear> env({}, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
    const int inputs = manisoft::control::MlpExecutor<double>::feature_size(static_cast<int>(env.reset(1).node_indices.size()));
    using Mlp = manisoft::control::Mlp<double>;
    std::vector<Mlp::Layer> layers(2);
    layers[0].weights = Mlp::Matrix::Constant(16, inputs, 0.01);
    layers[0].bias = Mlp::Vector::Zero(16);
    layers[0].activation = manisoft::control::Activation::tanh;
    layers[1].weights = Mlp::Matrix::Constant(3 * env.n_elements(), 16, 0.1);
    layers[1].bias = Mlp::Vector::Zero(3 * env.n_elements());
    manisoft::control::MlpExecutor<double> executor(Mlp(layers), env.n_elements());
    CHECK(episode_allocations(env, executor, 7, success) == 0);
  }
}

}  // namespace test_world_alloc
