// The ManiSoft tabletop scene (paper section 3.3, "the soft arm is fixed behind the table and
// centred relative to the workspace"): table, arm mount, gripper and eight household objects,
// shared by examples/world_demo.cpp and benchmarks/bench_world.cpp.
//
// Frame: z up, floor at z = 0; the table top is the rectangle x in [0, 0.8], y in [-0.5, 0.5] at
// z = 0.75 m; the arm's base is behind the back edge (x = 0), centred (y = 0).
// Mount: base at (-0.05, 0, 0.75 + 0.75) = 75 cm above the top, 5 cm behind its back edge,
// pointing forward horizontally (d3 = +x, d1 = +z, d2 = -y), as the reach task assumes (base
// 0.75 m above the table plane). Of the mounts 0.45 / 0.6 / 0.75 m above the top, pitched 0 / 30 /
// 60 degrees down, it is the one whose grasp-capable equilibria (arm clear of the top, grasp centre
// 2-20 cm above it, tool axis within 45 degrees of straight down) cover the most of the table top:
// lower mounts sag onto the top before the gripper turns down. `world_demo --map` measures it
// (docs/physics.md, "world_demo").
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "manisoft/geometry/compound_builders.hpp"
#include "manisoft/world/arm_world.hpp"

namespace manisoft::world {

/// Where and how the arm's base is mounted.
struct ArmMount {
  Eigen::Vector3d base_position{-0.05, 0.0, 1.50};
  double pitch = 0.0;  ///< rad below the horizontal, pointing toward +x
};

inline TableDesc tabletop_table() {
  TableDesc t;
  t.top_center = Eigen::Vector3d(0.4, 0, 0.75);
  t.half_x = 0.4;
  t.half_y = 0.5;
  t.thickness = 0.05;
  t.friction = 0.6;
  t.add_floor = true;
  return t;
}

/// The ManiSoft arm (paper "Key Parameters") mounted at `mount`.
inline rod::RodParameters<double> tabletop_arm_parameters(const ArmMount& mount = {}) {
  rod::RodParameters<double> p;
  p.base_position = mount.base_position;
  p.direction = Eigen::Vector3d(std::cos(mount.pitch), 0, -std::sin(mount.pitch));
  p.normal = Eigen::Vector3d(std::sin(mount.pitch), 0, std::cos(mount.pitch));
  return p;
}

/// One object of the scene: its description and a short kind label for traces.
struct ObjectSpec {
  rigid::RigidBodyDesc desc;
  const char* kind = "";
};

/// Eight objects resting on the table (top at `top_z`); the first, a 5 cm cube of 0.1 kg, is the
/// demo's target, at `target_xy`. The others stand off the arm's centre line (|y| >= 0.25 m).
inline std::vector<ObjectSpec> tabletop_objects(double top_z = 0.75, Eigen::Vector2d target_xy = {0.55, 0.0}) {
  std::vector<ObjectSpec> out;
  auto add = [&](geometry::Shape<double> shape, Eigen::Vector3d position, double mass, const char* name, const char* kind,
                 Eigen::Quaterniond q = Eigen::Quaterniond::Identity()) {
    rigid::RigidBodyDesc desc;
    desc.shape.swap(shape);  // (a move assignment here trips GCC 12's -Wmaybe-uninitialized)
    desc.position = position;
    desc.orientation = q;
    desc.mass = mass;
    desc.friction = 0.6;
    desc.name = name;
    out.push_back(ObjectSpec{std::move(desc), kind});
  };
  const double z = top_z;
  add(geometry::Box<double>{Eigen::Vector3d::Constant(0.025)}, {target_xy.x(), target_xy.y(), z + 0.025}, 0.10, "cube", "box");
  add(geometry::Box<double>{Eigen::Vector3d(0.04, 0.03, 0.02)}, {0.25, -0.35, z + 0.02}, 0.15, "block", "box");
  add(geometry::Box<double>{Eigen::Vector3d(0.06, 0.04, 0.05)}, {0.62, -0.40, z + 0.05}, 0.30, "carton", "box");
  add(geometry::Cylinder<double>{0.033, 0.06}, {0.25, 0.35, z + 0.06}, 0.35, "can", "cylinder");
  add(geometry::Cylinder<double>{0.03, 0.10}, {0.68, 0.40, z + 0.10}, 0.50, "bottle", "cylinder");
  add(geometry::Sphere<double>{0.035}, {0.45, -0.28, z + 0.035}, 0.06, "ball", "sphere");
  add(geometry::Capsule<double>{0.02, 0.06}, {0.45, 0.30, z + 0.02}, 0.08, "marker", "capsule",
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY())));
  add(geometry::make_bowl(), {0.10, -0.30, z}, 0.25, "bowl", "bowl");
  return out;
}

/// Adds the table (with floor) and the eight objects; returns the objects' ids (target first).
template <typename Rod>
std::vector<rigid::BodyId> populate_tabletop(ArmWorld<Rod>& world, Eigen::Vector2d target_xy = {0.55, 0.0}) {
  const TableDesc t = tabletop_table();
  world.add_table(t);
  std::vector<rigid::BodyId> ids;
  for (const auto& o : tabletop_objects(t.top_center.z(), target_xy)) ids.push_back(world.add_object(o.desc));
  return ids;
}

}  // namespace manisoft::world
