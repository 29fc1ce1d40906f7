// The scene-to-render adapter: a render::SceneDescription of a SceneSpec (what render_scene --scene,
// the Python environment's camera image and the dataset's episode images draw): floor, the spec's
// table (size, texture, colours), the arm mount, the soft arm sagging forward near its rest shape
// with its gripper, every object and obstacle drawn from its asset's visual parts (the spec's colour
// override replaces the main part's colour and texture), the ALN and OVR goal marker, the spec's lighting
// and cameras. Object ids: 1 floor, 2 table, 3 mount, 4 arm, 5 gripper, then 6 + i for object i,
// then the obstacles, then the goal marker.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "manisoft/render/tabletop_render_scene.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"

namespace manisoft::scene {

namespace detail_render {

/// Keeps the built-in scene's floor, table, mount, gripper and arm; drops its objects.
inline void keep_fixtures(render::tabletop::TabletopScene& t) {
  std::vector<render::Instance> kept;
  std::vector<math::Pose<double>> poses;
  for (std::size_t i = 0; i < t.scene.instances.size(); ++i) {
    if (t.scene.instances[i].object_id <= render::tabletop::gripper_id) {
      if (i == t.palm) t.palm = kept.size();
      if (i == t.left_finger) t.left_finger = kept.size();
      if (i == t.right_finger) t.right_finger = kept.size();
      kept.push_back(t.scene.instances[i]);
      poses.push_back(t.frame.instance_poses[i]);
    }
  }
  t.scene.instances = kept;
  t.frame.instance_poses = poses;
  t.object_instance.clear();
}

/// The spec's table: a top of its size and texture (legs kept at the corners).
inline void set_table(const SceneSpec& s, render::tabletop::TabletopScene& t) {
  render::SceneDescription& d = t.scene;
  for (std::size_t i = 0; i < d.instances.size(); ++i) {
    if (d.instances[i].object_id != render::tabletop::table_id) continue;
    render::Mesh table = render::make_box({s.table.half_x, s.table.half_y, 0.5 * s.table.thickness});
    const double leg = s.table.top_center.z() - s.table.thickness;
    for (double lx : {-s.table.half_x + 0.04, s.table.half_x - 0.04})
      for (double ly : {-s.table.half_y + 0.04, s.table.half_y - 0.04})
        render::append(table, render::make_box({0.025, 0.025, 0.5 * leg}), render::tabletop::at(lx, ly, -0.5 * s.table.thickness - 0.5 * leg));
    d.meshes.push_back(std::move(table));
    d.instances[i].mesh = static_cast<int>(d.meshes.size() - 1);
    render::Material m;
    m.base_color = s.table.color.cast<float>();
    m.secondary_color = s.table.secondary_color.cast<float>();
    m.texture = s.table.texture;
    m.texture_scale = static_cast<float>(s.table.texture_scale);
    m.specular = 0.15f;
    d.materials.push_back(m);
    d.instances[i].material = static_cast<int>(d.materials.size() - 1);
    t.frame.instance_poses[i] = render::tabletop::at(s.table.top_center.x(), s.table.top_center.y(), s.table.top_center.z() - 0.5 * s.table.thickness);
  }
}

/// Adds a placed asset's visual parts under one object id, named "<name> <asset id>".
inline void add_asset(const PlacedAsset& p, const std::string& name, const AssetLibrary& lib, std::uint16_t id, render::tabletop::TabletopScene& t) {
  render::SceneDescription& d = t.scene;
  const auto& a = lib.get(p.asset_id, name);
  for (std::size_t k = 0; k < a.visual.size(); ++k) {
    d.meshes.push_back(a.visual[k].mesh);
    render::Material m = a.visual[k].material;
    if (k == 0 && p.appearance.override_color) {
      m.base_color = p.appearance.color.cast<float>();
      m.texture = p.appearance.texture;
      m.secondary_color = 0.6f * m.base_color;
      m.texture_scale = 40.0f;
    }
    d.materials.push_back(m);
    d.instances.push_back(render::Instance{static_cast<int>(d.meshes.size() - 1), static_cast<int>(d.materials.size() - 1), id, name + " " + p.asset_id, true});
    t.frame.instance_poses.push_back(p.pose);
  }
  t.object_instance[name] = d.instances.size() - 1;
}

}  // namespace detail_render

/// The render scene of a SceneSpec, its assets from `lib`, and its static frame.
inline render::tabletop::TabletopScene make_render_scene(const SceneSpec& s, const AssetLibrary& lib) {
  namespace tabletop = render::tabletop;
  tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  detail_render::keep_fixtures(t);
  detail_render::set_table(s, t);
  std::uint16_t next_id = tabletop::gripper_id + 1;
  for (std::size_t i = 0; i < s.objects.size(); ++i) detail_render::add_asset(s.objects[i], "object" + std::to_string(i), lib, next_id++, t);
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) detail_render::add_asset(s.obstacles[i], "obstacle" + std::to_string(i), lib, next_id++, t);
  render::SceneDescription& d = t.scene;
  render::FrameState& f = t.frame;
  d.goal_marker.object_id = next_id;
  if (s.task == Task::aln || s.task == Task::ovr) f.goal_pose = s.goal.goal_pose;
  d.lighting.intensity = static_cast<float>(s.lighting.intensity);
  d.lighting.color = s.lighting.color.cast<float>();
  d.lighting.direction = s.lighting.direction;
  d.lighting.ambient_intensity = static_cast<float>(s.lighting.ambient_intensity);
  d.cameras = s.cameras;
  // the arm near its rest shape (sagging forward over the far part of the table), out of the objects' way
  f.rod = tabletop::arc_rod(s.arm_mount.base_position, 1.0, 20, 35.0 * 3.14159265358979323846 / 180.0, 0.05);
  tabletop::set_gripper(t, f, tabletop::gripper_at_tip(f.rod), 0.10);
  return t;
}

/// The frame of a task state in a make_render_scene scene: the rod's centreline, the gripper body's
/// pose and finger opening, and object i's pose (asset frame -> world) for every part named
/// "object<i> ...".
inline render::FrameState render_frame(const render::tabletop::TabletopScene& t, const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3>>& rod_nodes,
                                       const math::Pose<double>& gripper, double finger_width, const std::vector<math::Pose<double>>& objects) {
  render::FrameState f = t.frame;
  f.rod.nodes = rod_nodes;
  f.rod.directors.resize(0, 9);
  render::tabletop::set_gripper(t, f, gripper, finger_width);
  for (std::size_t i = 0; i < t.scene.instances.size(); ++i) {
    const std::string& name = t.scene.instances[i].name;
    if (name.rfind("object", 0) != 0) continue;
    const std::size_t k = std::stoul(name.substr(6, name.find(' ') - 6));
    if (k < objects.size()) f.instance_poses[i] = objects[k];
  }
  return f;
}

}  // namespace manisoft::scene
