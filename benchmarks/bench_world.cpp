// World step benchmark: the world_demo scene (tabletop_scene.hpp: table and floor, the
// arm mounted behind the table, the parallel gripper, eight resting objects), one world step =
// gripper pre-step, coupling, rod contact, rod step (n = 20), rigid step, at dt = 2e-4 s.
//   world_step/touching      the arm bent down, pressing the gripper onto the table top (the
//                            rod's tip elements 12 cm above it, inside the rod-contact broad
//                            phase), objects asleep after settling: the reference scene
//   world_step/free          the arm hanging in the air under gravity
//   world_step/holding       the gripper holding the cube in the air (weld active)
//   rod_lying_on_table       a free rod (n = 20) lying on the table: 40 rod-contact points every
//                            step (rod contact + rod step + rigid step), the narrow phase's cost
//   rod_step                 the rod alone (same rod type), for the breakdown
// Each benchmark settles the scene for 1 s first (untimed). Target: <= 10 us per world step.
// Run: bench_world --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace {

using namespace manisoft;
using namespace manisoft::geometry;
using namespace manisoft::rigid;
using Arm = rod::CosseratRod<double, rod::damping::AnalyticalLinear, rod::bc::ClampedBase, rod::integrator::PositionVerlet, rod::forcing::Gravity,
                        rod::forcing::ElementTorques>;
constexpr double kDt = 2e-4;

/// Bending in the vertical plane: a couple about d2 on every element and an extra one at the tip
/// (negative: down).
Eigen::Matrix<double, Eigen::Dynamic, 3> bend(int n, double per_element_about_d2, double tip_about_d2) {
  Eigen::Matrix<double, Eigen::Dynamic, 3> t = Eigen::Matrix<double, Eigen::Dynamic, 3>::Zero(n, 3);
  for (int k = 1; k < n; ++k) t(k, 1) = per_element_about_d2;
  t(n - 1, 1) += tip_about_d2;
  return t;
}

void world_step(benchmark::State& state, double couple, double tip, bool hold) {
  const world::ArmMount mount;
  world::ArmWorld<Arm> world(Arm(world::tabletop_arm_parameters(mount), kDt, rod::damping::AnalyticalLinear<double>(0.5)));
  const auto objects = world::populate_tabletop(world);
  const int n = world.rod().n_elements();
  world.rod().forcing<rod::forcing::ElementTorques>().set(bend(n, couple, tip));
  if (hold) {
    // Put the cube between the fingers and close: the weld carries it.
    const Eigen::Vector3d g = world.gripper().grasp_point(world.rigid());
    world.rigid().set_pose(objects[0], g - Eigen::Vector3d(0, 0, 0.025), world.rigid().orientation(objects[0]));
    world.set_gripper(1);
  }
  world.step(5000);  // 1 s: settle, objects fall asleep
  int contacts = 0;
  for (auto _ : state) {
    world.step();
    contacts += static_cast<int>(world.rod_contact().contacts().size());
  }
  state.counters["rod_contacts"] = benchmark::Counter(contacts, benchmark::Counter::kAvgIterations);
  state.counters["min_node_z"] = world.rod().state().positions.col(2).minCoeff();
  state.counters["held"] = world.gripper().held() ? 1 : 0;
  state.counters["awake_bodies"] = [&] {
    int a = 0;
    for (rigid::BodyId b = 0; b < world.rigid().body_count(); ++b) a += !world.rigid().model(b).is_static && world.rigid().is_awake(b);
    return a;
  }();
}

void rod_lying_on_table(benchmark::State& state) {
  using FreeRod = rod::CosseratRod<double, rod::damping::UniformExp, rod::bc::Free, rod::integrator::PositionVerlet, rod::forcing::Gravity>;
  rigid::RigidWorld world;
  rigid::RigidBodyDesc table;
  table.shape = geometry::Box<double>{Eigen::Vector3d(1.0, 0.5, 0.05)};
  table.position = Eigen::Vector3d(0.5, 0, -0.05);
  table.is_static = true;
  world.add_body(table);
  rod::RodParameters<double> rp;
  rp.base_position = Eigen::Vector3d(0, 0, rp.radius);
  FreeRod rod(rp, kDt, rod::damping::UniformExp<double>(5));
  interaction::RodCapsuleContact contact;
  auto step = [&] {
    contact.apply(rod, world);
    rod.step();
    world.step(kDt);
  };
  for (int i = 0; i < 5000; ++i) step();
  int contacts = 0;
  for (auto _ : state) {
    step();
    contacts += static_cast<int>(contact.contacts().size());
  }
  state.counters["rod_contacts"] = benchmark::Counter(contacts, benchmark::Counter::kAvgIterations);
}

void rod_step(benchmark::State& state) {
  Arm rod(world::tabletop_arm_parameters(), kDt, rod::damping::AnalyticalLinear<double>(0.5));
  rod.step(5000);
  for (auto _ : state) rod.step();
}

}  // namespace

BENCHMARK_CAPTURE(world_step, touching, -4.0, -40.0, false)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK_CAPTURE(world_step, free, 0.0, 0.0, false)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK_CAPTURE(world_step, holding, 0.0, 0.0, true)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(rod_lying_on_table)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(rod_step)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK_MAIN();
