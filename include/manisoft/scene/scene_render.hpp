// A render::SceneDescription of a scene::SceneSpec (render_scene --scene): floor, the spec's
// table (size, texture, colours), the arm mount, the soft arm sagging forward near its rest shape
// with its gripper, every object and obstacle drawn from its asset's visual parts (the spec's colour
// override replaces the main part's colour and texture), the ALN goal marker, the spec's lighting
// and cameras. Object ids: 1 floor, 2 table, 3 mount, 4 arm, 5 gripper, then 6 + i for object i,
// then the obstacles, then the goal marker.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "tabletop_render_scene.hpp"

namespace manisoft::render::spec {

inline tabletop::TabletopScene make_spec_scene(const scene::SceneSpec& s, const scene::AssetLibrary& lib) {
  tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  // keep floor, table, mount, gripper and arm; drop the built-in objects
  SceneDescription& d = t.scene;
  FrameState& f = t.frame;
  std::vector<Instance> kept;
  std::vector<math::Pose<double>> poses;
  for (std::size_t i = 0; i < d.instances.size(); ++i) {
    if (d.instances[i].object_id <= tabletop::gripper_id) {
      if (i == t.palm) t.palm = kept.size();
      if (i == t.left_finger) t.left_finger = kept.size();
      if (i == t.right_finger) t.right_finger = kept.size();
      kept.push_back(d.instances[i]);
      poses.push_back(f.instance_poses[i]);
    }
  }
  d.instances = kept;
  f.instance_poses = poses;
  t.object_instance.clear();
  // the table from the spec: a top of its size and texture (legs kept at the corners)
  for (std::size_t i = 0; i < d.instances.size(); ++i) {
    if (d.instances[i].object_id != tabletop::table_id) continue;
    Mesh table = make_box({s.table.half_x, s.table.half_y, 0.5 * s.table.thickness});
    const double leg = s.table.top_center.z() - s.table.thickness;
    for (double lx : {-s.table.half_x + 0.04, s.table.half_x - 0.04})
      for (double ly : {-s.table.half_y + 0.04, s.table.half_y - 0.04})
        append(table, make_box({0.025, 0.025, 0.5 * leg}), tabletop::at(lx, ly, -0.5 * s.table.thickness - 0.5 * leg));
    d.meshes.push_back(std::move(table));
    d.instances[i].mesh = static_cast<int>(d.meshes.size() - 1);
    Material m;
    m.base_color = s.table.color.cast<float>();
    m.secondary_color = s.table.secondary_color.cast<float>();
    m.texture = s.table.texture;
    m.texture_scale = static_cast<float>(s.table.texture_scale);
    m.specular = 0.15f;
    d.materials.push_back(m);
    d.instances[i].material = static_cast<int>(d.materials.size() - 1);
    f.instance_poses[i] = tabletop::at(s.table.top_center.x(), s.table.top_center.y(), s.table.top_center.z() - 0.5 * s.table.thickness);
  }
  std::uint16_t next_id = tabletop::gripper_id + 1;
  auto add = [&](const scene::PlacedAsset& p, const std::string& name) {
    const auto& a = lib.get(p.asset_id, name);
    for (std::size_t k = 0; k < a.visual.size(); ++k) {
      d.meshes.push_back(a.visual[k].mesh);
      Material m = a.visual[k].material;
      if (k == 0 && p.appearance.override_color) {
        m.base_color = p.appearance.color.cast<float>();
        m.texture = p.appearance.texture;
        m.secondary_color = 0.6f * m.base_color;
        m.texture_scale = 40.0f;
      }
      d.materials.push_back(m);
      d.instances.push_back(Instance{static_cast<int>(d.meshes.size() - 1), static_cast<int>(d.materials.size() - 1), next_id, name + " " + p.asset_id, true});
      f.instance_poses.push_back(p.pose);
    }
    t.object_instance[name] = d.instances.size() - 1;
    ++next_id;
  };
  for (std::size_t i = 0; i < s.objects.size(); ++i) add(s.objects[i], "object" + std::to_string(i));
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) add(s.obstacles[i], "obstacle" + std::to_string(i));
  d.goal_marker.object_id = next_id;
  if (s.task == scene::Task::aln) f.goal_pose = s.goal.goal_pose;
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

/// The frame of a task state in a make_spec_scene scene: the rod's centreline, the gripper body's
/// pose and finger opening, and object i's pose (asset frame -> world) for every part named
/// "object<i> ...".
inline FrameState task_frame(const tabletop::TabletopScene& t, const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3>>& rod_nodes,
                             const math::Pose<double>& gripper, double finger_width, const std::vector<math::Pose<double>>& objects) {
  FrameState f = t.frame;
  f.rod.nodes = rod_nodes;
  f.rod.directors.resize(0, 9);
  tabletop::set_gripper(t, f, gripper, finger_width);
  for (std::size_t i = 0; i < t.scene.instances.size(); ++i) {
    const std::string& name = t.scene.instances[i].name;
    if (name.rfind("object", 0) != 0) continue;
    const std::size_t k = std::stoul(name.substr(6, name.find(' ') - 6));
    if (k < objects.size()) f.instance_poses[i] = objects[k];
  }
  return f;
}

}  // namespace manisoft::render::spec
