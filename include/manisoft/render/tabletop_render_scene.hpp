// The built-in tabletop scene of the render programs, from plain data (no physics headers): table,
// floor, arm mount, the soft arm (a 1 m rod of radius 5 cm, 20 elements), the parallel gripper
// and eight objects, in the ManiSoft world frame (z up, floor at z = 0, table top x in [0, 0.8],
// y in [-0.5, 0.5] at z = 0.75 m; the arm's base at (-0.05, 0, 1.5) pointing +x). Shared by
// render_scene, the render tests and bench_render. Also maps a world_demo trace row to a
// FrameState (tabletop_frame_from_trace).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "manisoft/render/mesh_builders.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render::tabletop {

/// Object ids of the built-in scene (0 is the background).
enum Id : std::uint16_t {
  floor_id = 1,
  table_id = 2,
  mount_id = 3,
  arm_id = 4,
  gripper_id = 5,
  cube_id = 6,
  block_id = 7,
  carton_id = 8,
  can_id = 9,
  bottle_id = 10,
  ball_id = 11,
  marker_id = 12,
  bowl_id = 13,
  goal_id = 14,
};

/// The eight objects in world_demo's trace column order.
inline const std::vector<std::string>& object_names() {
  static const std::vector<std::string> names = {"cube", "block", "carton", "can", "bottle", "ball", "marker", "bowl"};
  return names;
}

/// The scene plus where its parts are.
struct TabletopScene {
  SceneDescription scene;
  FrameState frame;                          ///< the static picture: arm bent in an arc, gripper open
  std::size_t palm = 0, left_finger = 0, right_finger = 0;  ///< instance indices of the gripper parts
  std::map<std::string, std::size_t> object_instance;        ///< object name -> instance index
  GripperGeometry gripper;
};

inline math::Pose<double> at(double x, double y, double z) { return math::Pose<double>{Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, y, z)}; }

/// A rod of `length` with n elements bent in a circular arc in the x-z plane, starting at `base`
/// along +x and turning by `bend` rad in total away from its d1 (d1 starts at +z turned by `roll`
/// rad about +x: roll 0 bends straight down); d2 = d3 x d1, d3 = tangent (PyElastica layout: row i
/// of Q_k is d_{i+1}).
inline RodShape arc_rod(const Eigen::Vector3d& base, double length, int elements, double bend, double radius, double roll = 0.0) {
  RodShape rod;
  rod.radius = radius;
  rod.nodes.resize(elements + 1, 3);
  rod.directors.resize(elements, 9);
  const double curvature_radius = bend > 1e-12 ? length / bend : 0.0;
  for (int i = 0; i <= elements; ++i) {
    const double s = length * i / elements;
    const double phi = bend * i / elements;
    const Eigen::Vector3d local = bend > 1e-12 ? Eigen::Vector3d(curvature_radius * std::sin(phi), 0, -curvature_radius * (1 - std::cos(phi)))
                                               : Eigen::Vector3d(s, 0, 0);
    const Eigen::Vector3d p = base + Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) * local;
    rod.nodes.row(i) = p.transpose();
  }
  for (int k = 0; k < elements; ++k) {
    const double phi = bend * (k + 0.5) / elements;
    const Eigen::AngleAxisd turn(roll, Eigen::Vector3d::UnitX());
    const Eigen::Vector3d d3 = turn * Eigen::Vector3d(std::cos(phi), 0, -std::sin(phi));
    const Eigen::Vector3d d1 = turn * Eigen::Vector3d(std::sin(phi), 0, std::cos(phi));
    const Eigen::Vector3d d2 = d3.cross(d1);
    rod.directors.row(k) << d1.transpose(), d2.transpose(), d3.transpose();
  }
  return rod;
}

/// Places the gripper's parts for a gripper frame and finger opening.
inline void set_gripper(const TabletopScene& t, FrameState& frame, const math::Pose<double>& gripper, double opening) {
  const auto parts = gripper_part_poses(gripper, opening, t.gripper);
  frame.instance_poses[t.palm] = parts[0];
  frame.instance_poses[t.left_finger] = parts[1];
  frame.instance_poses[t.right_finger] = parts[2];
}

/// The gripper frame at the rod's tip: origin at the last node, z along the last tangent, x along
/// the last element's d1 (PyElastica directors) or, without directors, any unit vector
/// perpendicular to z in the vertical plane.
inline math::Pose<double> gripper_at_tip(const RodShape& rod) {
  const Eigen::Index n = rod.nodes.rows() - 1;
  const Eigen::Vector3d z = (rod.nodes.row(n) - rod.nodes.row(n - 1)).transpose().normalized();
  Eigen::Vector3d x = rod.directors.rows() > 0 ? Eigen::Vector3d(rod.directors.row(n - 1).head<3>().transpose()) : Eigen::Vector3d::UnitZ();
  x = (x - x.dot(z) * z);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  math::Pose<double> pose;
  pose.rotation.col(0) = x;
  pose.rotation.col(1) = z.cross(x);
  pose.rotation.col(2) = z;
  pose.translation = rod.nodes.row(n).transpose();
  return pose;
}

namespace detail {

/// Adds materials, meshes and instances (with their poses in the static frame) to a scene.
struct SceneBuilder {
  TabletopScene& t;

  int material(Eigen::Vector3f base, TextureKind kind = TextureKind::none, Eigen::Vector3f secondary = {0, 0, 0}, float scale = 10.0f,
               float specular = 0.2f, float shininess = 32.0f) {
    Material m;
    m.base_color = base;
    m.texture = kind;
    m.secondary_color = secondary;
    m.texture_scale = scale;
    m.specular = specular;
    m.shininess = shininess;
    t.scene.materials.push_back(m);
    return static_cast<int>(t.scene.materials.size() - 1);
  }
  int mesh(Mesh m) {
    t.scene.meshes.push_back(std::move(m));
    return static_cast<int>(t.scene.meshes.size() - 1);
  }
  std::size_t instance(int mesh_index, int material_index, std::uint16_t id, std::string name, const math::Pose<double>& pose, bool casts_shadow = true) {
    t.scene.instances.push_back(Instance{mesh_index, material_index, id, std::move(name), casts_shadow});
    t.frame.instance_poses.push_back(pose);
    return t.scene.instances.size() - 1;
  }
};

/// Floor, table, arm mount and the gripper's parts.
inline void add_fixtures(SceneBuilder& b) {
  TabletopScene& t = b.t;
  // Floor: grey checker tiles, 6 x 6 m, top at z = 0; not a shadow caster (cheaper shadow pass).
  const int floor_material = b.material({0.55f, 0.55f, 0.53f}, TextureKind::checker, {0.42f, 0.42f, 0.41f}, 2.0f, 0.05f);
  b.instance(b.mesh(make_box({3.0, 3.0, 0.005})), floor_material, floor_id, "floor", at(0.4, 0, -0.005), false);

  // Table: wooden top 0.8 x 1.0 x 0.05 m (top face at 0.75) on four legs.
  Mesh table = make_box({0.4, 0.5, 0.025});
  for (double lx : {-0.36, 0.36}) {
    for (double ly : {-0.46, 0.46}) append(table, make_box({0.025, 0.025, 0.35}), at(lx, ly, -0.375));
  }
  const int wood = b.material({0.62f, 0.42f, 0.24f}, TextureKind::wood, {0.42f, 0.26f, 0.13f}, 30.0f, 0.15f, 24.0f);
  b.instance(b.mesh(std::move(table)), wood, table_id, "table", at(0.4, 0, 0.725));

  // Arm mount: a grey post from the floor to a block holding the rod's base.
  Mesh mount = make_box({0.06, 0.06, 0.06});
  append(mount, make_box({0.03, 0.03, 0.72}), at(-0.03, 0, -0.78));
  const int metal = b.material({0.35f, 0.36f, 0.38f}, TextureKind::none, {0, 0, 0}, 10.0f, 0.5f, 48.0f);
  b.instance(b.mesh(std::move(mount)), metal, mount_id, "mount", at(-0.11, 0, 1.5));

  // Gripper: palm and two fingers (dark grey), one id.
  const int gripper_material = b.material({0.18f, 0.19f, 0.21f}, TextureKind::none, {0, 0, 0}, 10.0f, 0.5f, 64.0f);
  t.palm = b.instance(b.mesh(make_box(t.gripper.palm_half_extents)), gripper_material, gripper_id, "gripper", {});
  const int finger_mesh = b.mesh(make_box(t.gripper.finger_half_extents));
  t.left_finger = b.instance(finger_mesh, gripper_material, gripper_id, "gripper", {});
  t.right_finger = b.instance(finger_mesh, gripper_material, gripper_id, "gripper", {});
}

/// The eight objects on the table top (z = 0.75), in world_demo's order.
inline void add_objects(SceneBuilder& b) {
  TabletopScene& t = b.t;
  const double top = 0.75;
  const double pi = std::numbers::pi;
  t.object_instance["cube"] =
      b.instance(b.mesh(make_box({0.025, 0.025, 0.025})), b.material({0.85f, 0.12f, 0.10f}), cube_id, "cube", at(0.55, 0.0, top + 0.025));
  t.object_instance["block"] = b.instance(b.mesh(make_box({0.04, 0.03, 0.02})),
                                          b.material({0.15f, 0.35f, 0.80f}, TextureKind::noise, {0.08f, 0.2f, 0.55f}, 40.0f), block_id, "block",
                                          at(0.25, -0.35, top + 0.02));
  t.object_instance["carton"] = b.instance(b.mesh(make_box({0.06, 0.04, 0.05})),
                                           b.material({0.72f, 0.58f, 0.38f}, TextureKind::fabric, {0.55f, 0.42f, 0.26f}, 60.0f, 0.05f), carton_id,
                                           "carton", at(0.62, -0.40, top + 0.05));
  t.object_instance["can"] = b.instance(b.mesh(make_cylinder(0.033, 0.06)),
                                        b.material({0.80f, 0.80f, 0.82f}, TextureKind::none, {0, 0, 0}, 10.0f, 0.8f, 80.0f), can_id, "can",
                                        at(0.25, 0.35, top + 0.06));
  t.object_instance["bottle"] = b.instance(b.mesh(make_cylinder(0.03, 0.10)),
                                           b.material({0.10f, 0.55f, 0.25f}, TextureKind::none, {0, 0, 0}, 10.0f, 0.6f, 64.0f), bottle_id, "bottle",
                                           at(0.68, 0.40, top + 0.10));
  t.object_instance["ball"] = b.instance(b.mesh(make_sphere(0.035)), b.material({0.95f, 0.78f, 0.10f}, TextureKind::noise, {0.85f, 0.45f, 0.05f}, 25.0f),
                                         ball_id, "ball", at(0.45, -0.28, top + 0.035));
  math::Pose<double> marker = at(0.45, 0.30, top + 0.02);
  marker.rotation = Eigen::AngleAxisd(pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  t.object_instance["marker"] = b.instance(b.mesh(make_capsule(0.02, 0.06)), b.material({0.50f, 0.20f, 0.65f}), marker_id, "marker", marker);
  t.object_instance["bowl"] = b.instance(b.mesh(make_vessel(0.05, 0.05, 0.004, 40.0 * pi / 180.0)),
                                         b.material({0.92f, 0.92f, 0.90f}, TextureKind::marble, {0.45f, 0.47f, 0.52f}, 25.0f, 0.5f, 64.0f), bowl_id,
                                         "bowl", at(0.10, -0.30, top));
}

}  // namespace detail

/// The built-in scene and its static frame.
inline TabletopScene make_tabletop_scene() {
  TabletopScene t;
  detail::SceneBuilder b{t};
  detail::add_fixtures(b);
  detail::add_objects(b);
  // The soft arm: silicone orange, its base at (-0.05, 0, 1.5) pointing +x, bent 85 degrees down
  // in a plane rolled 20 degrees sideways (seen from the front camera it reads as a curved tube).
  const double pi = std::numbers::pi;
  t.scene.rod.material = b.material({0.93f, 0.50f, 0.18f}, TextureKind::none, {0, 0, 0}, 10.0f, 0.35f, 32.0f);
  t.scene.rod.object_id = arm_id;
  t.scene.rod.name = "arm";
  t.frame.rod = arc_rod(Eigen::Vector3d(-0.05, 0, 1.5), 1.0, 20, 85.0 * pi / 180.0, 0.05, -20.0 * pi / 180.0);
  set_gripper(t, t.frame, gripper_at_tip(t.frame.rod), 0.10);

  t.scene.goal_marker.object_id = goal_id;
  t.scene.goal_marker.name = "goal";
  t.scene.cameras = {Camera{}};
  return t;
}

}  // namespace manisoft::render::tabletop
