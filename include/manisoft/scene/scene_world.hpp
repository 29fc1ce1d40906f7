// Builds the physical scene of a SceneSpec (paper section 3.3): rigid body descriptions of its assets (collision shape, mass,
// inertia about the centre of mass, friction from the asset), added to an ArmWorld (table and
// floor, static obstacles, dynamic objects, in the spec's order) or to a bare RigidWorld (what the
// scene validation settles). The arm's mount is the world's (world/tabletop_scene.hpp): a spec
// with another mount is refused.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/rigid/rigid_world.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::scene {

/// The body of asset `a` placed at `pose` (static for obstacles).
inline rigid::RigidBodyDesc asset_body(const assets::Asset& a, const math::Pose<double>& pose, bool is_static, const std::string& name) {
  rigid::RigidBodyDesc d;
  d.shape = a.collision;
  d.mass = a.mass;
  d.inertia = a.inertia;
  d.position = pose.translation;
  d.orientation = Eigen::Quaterniond(pose.rotation).normalized();
  d.friction = a.friction;
  d.rolling_resistance = a.rolling_resistance;
  d.is_static = is_static;
  d.name = name;
  return d;
}

/// Body name of object i / obstacle i ("object 0 (bottle/03)").
inline std::string body_name(bool obstacle, std::size_t i, const std::string& asset_id) {
  return std::string(obstacle ? "obstacle " : "object ") + std::to_string(i) + " (" + asset_id + ")";
}

/// Refuses a spec whose arm mount is not the world's.
inline void require_world_mount(const SceneSpec& s) {
  const world::ArmMount m;
  if ((s.arm_mount.base_position - m.base_position).norm() > 1e-12 || std::abs(s.arm_mount.pitch - m.pitch) > 1e-12)
    manisoft::detail::fail("SceneSpec arm_mount: base (", s.arm_mount.base_position.transpose(), "), pitch ", s.arm_mount.pitch,
                           " differs from the world's mount (", m.base_position.transpose(), "), pitch ", m.pitch,
                           ": the mount is fixed (world/tabletop_scene.hpp)");
}

/// Body ids of a built scene, in the spec's order.
struct SceneBodies {
  rigid::BodyId table = 0;
  std::vector<rigid::BodyId> objects, obstacles;
};

/// Adds the spec's obstacles (static) and objects (dynamic) to `world` (which has its table
/// already: SceneBodies::table is left 0).
template <typename Rod>
SceneBodies populate_objects(world::ArmWorld<Rod>& world, const SceneSpec& s, const AssetLibrary& lib) {
  require_world_mount(s);
  SceneBodies b;
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
    const auto& o = s.obstacles[i];
    const auto& a = lib.get(o.asset_id, "obstacles[" + std::to_string(i) + "]");
    b.obstacles.push_back(world.add_obstacle(asset_body(a, o.pose, true, body_name(true, i, o.asset_id))));
  }
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const auto& o = s.objects[i];
    const auto& a = lib.get(o.asset_id, "objects[" + std::to_string(i) + "]");
    b.objects.push_back(world.add_object(asset_body(a, o.pose, false, body_name(false, i, o.asset_id))));
  }
  return b;
}

/// Adds the spec's table (and floor), obstacles (static) and objects (dynamic) to `world`.
template <typename Rod>
SceneBodies populate_arm_world(world::ArmWorld<Rod>& world, const SceneSpec& s, const AssetLibrary& lib) {
  require_world_mount(s);
  const rigid::BodyId table = world.add_table(s.table.desc());
  SceneBodies b = populate_objects(world, s, lib);
  b.table = table;
  return b;
}

/// The same bodies in a bare rigid world (the table as a static box, no floor).
inline SceneBodies populate_rigid_world(rigid::RigidWorld& world, const SceneSpec& s, const AssetLibrary& lib) {
  SceneBodies b;
  rigid::RigidBodyDesc t;
  t.shape = geometry::Box<double>{Eigen::Vector3d(s.table.half_x, s.table.half_y, 0.5 * s.table.thickness)};
  t.position = s.table.top_center - Eigen::Vector3d(0, 0, 0.5 * s.table.thickness);
  t.is_static = true;
  t.friction = s.table.friction;
  t.rolling_resistance = s.table.rolling_resistance;
  t.name = "table";
  b.table = world.add_body(t);
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
    const auto& o = s.obstacles[i];
    b.obstacles.push_back(world.add_body(asset_body(lib.get(o.asset_id, "obstacles[" + std::to_string(i) + "]"), o.pose, true, body_name(true, i, o.asset_id))));
  }
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const auto& o = s.objects[i];
    b.objects.push_back(world.add_body(asset_body(lib.get(o.asset_id, "objects[" + std::to_string(i) + "]"), o.pose, false, body_name(false, i, o.asset_id))));
  }
  return b;
}

}  // namespace manisoft::scene
