// SceneSpec: the complete description of one ManiSoft scene (paper sections 3.3 and 3.5: every
// task, dataset episode and evaluation starts from a scene described by an instruction): the
// table, the arm mount (a read-only copy of the world's), the objects and obstacles (asset id,
// pose, appearance), lighting, cameras, the task's goal in terms of object indices, the task,
// setting, split, index and seed it was drawn with, and the instructions (filled in by the
// language layer). Plain data: JSON in scene_json.hpp, sampling in scene_sampler.hpp, the world
// in scene_world.hpp.
//
// Frames: the world frame of world/tabletop_scene.hpp (z up, floor z = 0, table top z = 0.75,
// arm base at (-0.05, 0, 1.5) pointing +x). Poses are asset frame -> world (assets/asset.hpp:
// origin at the centre of the footprint, z up). Spatial relations are in the viewer's words as in
// task/success.hpp (the default camera looks from +x towards -x): left = -y, right = +y,
// in front of = +x, behind = -x.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/spatial_relation.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/render/camera.hpp"
#include "manisoft/render/scene.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::scene {

/// The benchmark's tasks (paper section 3.2; each defined in include/manisoft/task/, listed in
/// task/registry.hpp).
enum class Task { coll, aln, stk, arr, ovr };
/// Every task, in the benchmark's order.
inline constexpr std::array<Task, 5> all_tasks{Task::coll, Task::aln, Task::stk, Task::arr, Task::ovr};
enum class Setting { clean, randomized };
enum class Split { train, eval };

inline std::string_view to_string(Task t) {
  switch (t) {
    case Task::coll: return "COLL";
    case Task::aln: return "ALN";
    case Task::stk: return "STK";
    case Task::arr: return "ARR";
    case Task::ovr: return "OVR";
  }
  return "?";
}
inline std::string_view to_string(Setting s) { return s == Setting::clean ? "clean" : "randomized"; }
inline std::string_view to_string(Split s) { return s == Split::train ? "train" : "eval"; }

namespace detail {
template <typename E, std::size_t N>
E parse_name(std::string_view what, std::string_view name, const std::array<E, N>& all) {
  std::string names;
  for (E e : all) {
    if (to_string(e) == name) return e;
    names += (names.empty() ? "" : ", ") + std::string(to_string(e));
  }
  ::manisoft::detail::fail(what, " '", name, "' is not one of ", names);
}
}  // namespace detail

/// Every task's name, in the benchmark's order ("COLL", "ALN", "STK", "ARR", "OVR").
inline std::vector<std::string> task_names() {
  std::vector<std::string> out;
  for (const Task t : all_tasks) out.emplace_back(to_string(t));
  return out;
}

/// The enumerator that to_string names ("COLL", "clean", "train"); an error lists the names.
inline Task parse_task(std::string_view name) { return detail::parse_name("task", name, all_tasks); }
inline Setting parse_setting(std::string_view name) { return detail::parse_name("setting", name, std::array{Setting::clean, Setting::randomized}); }
inline Split parse_split(std::string_view name) { return detail::parse_name("split", name, std::array{Split::train, Split::eval}); }

/// The table: a box whose top face is centred at top_center, and how its top looks.
struct TableSpec {
  Eigen::Vector3d top_center{0.4, 0.0, 0.75};
  double half_x = 0.4, half_y = 0.5, thickness = 0.05;
  double friction = 0.6;
  double rolling_resistance = world::TableDesc{}.rolling_resistance;  ///< m
  render::TextureKind texture = render::TextureKind::wood;
  Eigen::Vector3d color{0.55, 0.38, 0.22};            ///< linear RGB of the top
  Eigen::Vector3d secondary_color{0.35, 0.22, 0.12};  ///< texture's second colour
  double texture_scale = 8.0;                         ///< 1/m

  world::TableDesc desc() const {
    world::TableDesc t;
    t.top_center = top_center;
    t.half_x = half_x;
    t.half_y = half_y;
    t.thickness = thickness;
    t.friction = friction;
    t.rolling_resistance = rolling_resistance;
    t.add_floor = true;
    return t;
  }
};

/// The arm mount: a read-only copy of world::ArmMount{} (validated equal on load).
struct MountSpec {
  Eigen::Vector3d base_position = world::ArmMount{}.base_position;
  double pitch = world::ArmMount{}.pitch;
};

/// How an asset is drawn in this scene: its catalogue look, or an override of its main colour.
struct Appearance {
  bool override_color = false;
  Eigen::Vector3d color{0.7, 0.7, 0.7};  ///< linear RGB, used when override_color
  std::string color_name;                ///< what an instruction may call it ("red"); empty: the asset's
  render::TextureKind texture = render::TextureKind::none;
};

/// One asset placed in the scene.
struct PlacedAsset {
  std::string asset_id;  ///< "category/NN" of assets::object_catalog / obstacle_catalog
  math::Pose<double> pose;
  Appearance appearance;
};

struct LightingSpec {
  double intensity = 1.0;
  Eigen::Vector3d color{1.0, 1.0, 1.0};
  Eigen::Vector3d direction{0.3, 0.45, -1.0};  ///< direction the light travels
  double ambient_intensity = 0.35;
};

/// How a goal orientation is judged: fully, up to any rotation about the asset's z axis (a
/// bottle, a can), or up to a 1/order turn about it (a box: order 2 or 4).
struct Symmetry {
  enum class Kind { none, axial, discrete } kind = Kind::none;
  int order = 1;  ///< discrete: order-fold about z

  static Symmetry none() { return {}; }
  static Symmetry axial() { return {Kind::axial, 1}; }
  static Symmetry discrete(int n) { return {Kind::discrete, n}; }
};

/// ARR: a spatial relation. left_of..next_to: objects = {a}, references = {b} ("a left of b");
/// between: {a}, {b, c}; in_a_row: {a}, {b, c} (a joins b and c in one row). `spots` gives, per
/// object, a free reachable place on the table where the relation holds (a hint for planners).
struct Relation {
  using Kind = geometry::RelationKind;
  Kind kind = Kind::next_to;
  std::vector<int> objects;
  std::vector<int> references;
  std::vector<Eigen::Vector3d> spots;
};

/// The task's goal; only the part of the scene's task is used (and written to JSON).
struct Goal {
  // COLL: put objects[object] into objects[container].
  int object = -1;
  int container = -1;
  // ALN: bring objects[object] to goal_pose (asset frame -> world), judged modulo symmetry.
  // OVR: bring objects[object] to goal_pose's position, upright, over obstacles[obstacle] (which
  // stands between its start and the goal).
  math::Pose<double> goal_pose;
  Symmetry symmetry;
  int obstacle = -1;
  // STK: item indices from the largest (bottom) to the smallest (top).
  std::vector<int> items;
  // ARR: every relation must hold.
  std::vector<Relation> relations;
};

/// How the scene was drawn.
struct SamplingInfo {
  std::uint64_t engine_seed = 0;  ///< the std::mt19937_64 seed of the accepted draw
  int redraws = 0;                ///< rejected draws before it
  std::vector<std::string> rejections;  ///< why each rejected draw failed (first words of the reason)
};

struct SceneSpec {
  Task task = Task::coll;
  Setting setting = Setting::clean;
  Split split = Split::train;
  std::uint64_t index = 0;
  std::uint64_t seed = 0;
  TableSpec table;
  MountSpec arm_mount;
  std::vector<PlacedAsset> objects;    ///< manipulable (dynamic) objects, containers included
  std::vector<PlacedAsset> obstacles;  ///< static obstacles
  LightingSpec lighting;
  std::vector<render::Camera> cameras{render::Camera{}};
  Goal goal;
  std::string instruction;                      ///< canonical (language layer)
  std::vector<std::string> instructions_seen;   ///< language layer
  std::vector<std::string> instructions_unseen; ///< language layer
  SamplingInfo sampling;
};

/// One line of the hand-over list: what stands where.
struct PlacedItem {
  enum class Kind { object, obstacle } kind = Kind::object;
  int index = 0;  ///< in SceneSpec::objects or ::obstacles
  std::string asset_id;
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};
  double yaw = 0;  ///< rad about world z
};

/// Every object, then every obstacle, with its asset id and position (for the language layer and
/// the task planners; the goal refers to objects by their index here).
inline std::vector<PlacedItem> list_items(const SceneSpec& s) {
  std::vector<PlacedItem> out;
  auto add = [&](const std::vector<PlacedAsset>& v, PlacedItem::Kind kind) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      PlacedItem it;
      it.kind = kind;
      it.index = static_cast<int>(i);
      it.asset_id = v[i].asset_id;
      it.position = v[i].pose.translation;
      const Eigen::Vector3d x = v[i].pose.rotation.col(0);
      it.yaw = std::atan2(x.y(), x.x());
      out.push_back(std::move(it));
    }
  };
  add(s.objects, PlacedItem::Kind::object);
  add(s.obstacles, PlacedItem::Kind::obstacle);
  return out;
}

/// The object indices the goal names, in the goal's order (COLL: object, container; ALN, OVR:
/// object; STK: items; ARR: every relation's objects then references).
inline std::vector<int> goal_objects(const SceneSpec& s) {
  switch (s.task) {
    case Task::coll: return {s.goal.object, s.goal.container};
    case Task::aln:
    case Task::ovr: return {s.goal.object};
    case Task::stk: return s.goal.items;
    case Task::arr: {
      std::vector<int> out;
      for (const auto& r : s.goal.relations) {
        out.insert(out.end(), r.objects.begin(), r.objects.end());
        out.insert(out.end(), r.references.begin(), r.references.end());
      }
      return out;
    }
  }
  return {};
}

}  // namespace manisoft::scene
