#include <cstdio>
#include <manisoft/rod.hpp>
#include <manisoft/world/tabletop_scene.hpp>

namespace ms = manisoft;
using Rod = ms::rod::CosseratRod<double, ms::rod::damping::AnalyticalLinear, ms::rod::bc::ClampedBase,
                                 ms::rod::integrator::PositionVerlet, ms::rod::forcing::Gravity,
                                 ms::rod::forcing::ElementTorques>;

int main() {
  // A Cosserat rod: 1 m, r = 5 cm, E = 1e7 Pa, 20 elements, clamped at the origin along +x.
  Rod rod(ms::rod::RodParameters<double>{}, 2e-4, ms::rod::damping::AnalyticalLinear<double>(0.1));
  for (int i = 0; i < 500; ++i) rod.step();  // 0.1 s: the free end sags under gravity
  const Eigen::Vector3d tip = rod.state().tip_position();
  std::printf("rod tip after 0.1 s: (%.3f, %.3f, %.3f) m\n", tip.x(), tip.y(), tip.z());

  // The same rod as the ManiSoft arm: mounted behind a table, with the parallel gripper, a cube.
  ms::world::ArmWorld<Rod> world(Rod(ms::world::tabletop_arm_parameters(), 2e-4,
                                     ms::rod::damping::AnalyticalLinear<double>(0.1)));
  world.add_table(ms::world::tabletop_table());
  ms::rigid::RigidBodyDesc cube;
  cube.shape = ms::geometry::Box<double>{Eigen::Vector3d::Constant(0.025)};
  cube.mass = 0.1;
  cube.position = {0.5, 0.0, 0.775};
  world.add_object(cube);
  Eigen::Matrix<double, Eigen::Dynamic, 3> torques(world.rod().n_elements(), 3);
  torques.setZero();
  torques.col(1).setConstant(-3.0);  // bend every element about its d2 axis [N m]
  for (int k = 0; k < 100; ++k) world.control_step(torques, /*S open*/ 0);  // 7 substeps each
  const Eigen::Vector3d grip = world.rod().state().tip_position();
  std::printf("arm tip after %.2f s: (%.3f, %.3f, %.3f) m\n", world.time(), grip.x(), grip.y(), grip.z());
  return tip.z() < 0 && grip.allFinite() ? 0 : 1;
}
