// Scene checks (every sampled scene is valid, checked before it is returned; the stability test
// is RoboTwin 2.0's): a SceneSpec is
//  - consistent: known asset ids of the right kind, finite poses on the table (within its extent,
//    the asset's origin, its lowest point, between 1 cm below and 50 cm above the top), goal
//    indices in range and of the right kind (a COLL container has a receptacle), the world's arm
//    mount;
//  - free of interpenetration: after one rigid step no contact point (object, obstacle, table) is
//    deeper than `penetration_tolerance` (the contact layer's narrow phase through RigidWorld);
//  - at rest: settled in the rigid world for `settle_time`, no object moves more than `max_move`
//    or turns more than `max_rotation` over the following `watch_time` (nor more than
//    `max_drift` / `max_rotation` from where it was placed);
//  - solvable in principle: each object to grasp has an annotated grasp (assets/asset.hpp, the
//    variants of candidate_grasps) whose tool pose has an equilibrium within the actuation limits
//    (rod::InverseStatics) with the rod clear of the table top and of every obstacle's bounding
//    box; the goal (COLL: above the container's opening; ALN, OVR: the goal pose; STK: above the
//    bottom item; ARR: each relation's spot) is reachable the same way.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/rigid/rigid_world.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/reach_map.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/scene/scene_world.hpp"

namespace manisoft::scene {

struct ValidationSettings {
  double penetration_tolerance = 1e-3;  ///< m
  double dt = 1e-3;                     ///< s, rigid step of the settling run
  double settle_time = 0.3;             ///< s before the watch window
  double watch_time = 0.2;              ///< s, RoboTwin's last 200 of 500 steps at 1 ms
  double max_move = 0.002;              ///< m over the watch window
  double max_drift = 0.01;              ///< m from the placement over the whole run
  double max_rotation = 3.0 * 3.14159265358979323846 / 180.0;  ///< rad
  double table_clearance = 0.05;        ///< m, rod nodes above the top (the rod radius)
  double obstacle_clearance = 0.05;     ///< m, rod nodes from obstacle bounding boxes (the rod radius)
  double place_clearance = 0.02;        ///< m, held object's bottom above the container / stack when placing
};

struct ValidationResult {
  bool valid = true;
  std::string reason;  ///< why not, naming the object and the check
  int ik_solves = 0;
};

/// Refuses an inconsistent spec (see the header comment), naming `where` (file or caller) and
/// the field.
inline void require_consistent(const SceneSpec& s, const AssetLibrary& lib, const std::string& where) {
  require_world_mount(s);
  auto check_pose = [&](const math::Pose<double>& p, const std::string& field) {
    if (!p.translation.allFinite() || !p.rotation.allFinite())
      manisoft::detail::fail(where, ": ", field, " is not finite");
    const double err = (p.rotation * p.rotation.transpose() - Eigen::Matrix3d::Identity()).norm();
    if (err > 1e-9 || p.rotation.determinant() < 0)
      manisoft::detail::fail(where, ": ", field, ".rotation is not a rotation (|R R^T - I| = ", err, ", limit 1e-9)");
  };
  auto check_list = [&](const std::vector<PlacedAsset>& v, const char* name, assets::AssetKind kind) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string field = std::string(name) + "[" + std::to_string(i) + "]";
      const auto& a = lib.get(v[i].asset_id, where + ": " + field + ".asset_id");
      if (a.kind != kind)
        manisoft::detail::fail(where, ": ", field, ".asset_id '", v[i].asset_id, "' is an ", assets::to_string(a.kind), ", expected an ",
                               assets::to_string(kind));
      check_pose(v[i].pose, field + ".pose");
      const Eigen::Vector3d d = v[i].pose.translation - s.table.top_center;
      if (std::abs(d.x()) > s.table.half_x || std::abs(d.y()) > s.table.half_y)
        manisoft::detail::fail(where, ": ", field, ".pose position (", v[i].pose.translation.transpose(), ") is off the table (half sizes ",
                               s.table.half_x, " x ", s.table.half_y, " about (", s.table.top_center.transpose(), "))");
      if (d.z() < -0.01 || d.z() > 0.5)
        manisoft::detail::fail(where, ": ", field, ".pose position z = ", v[i].pose.translation.z(), " is not on the table: the asset's origin (its lowest point) ",
                               "must be from 0.01 m below to 0.5 m above the table top (z = ", s.table.top_center.z(), ")");
    }
  };
  if (!(s.table.half_x > 0) || !(s.table.half_y > 0) || !(s.table.thickness > 0) || !s.table.top_center.allFinite())
    manisoft::detail::fail(where, ": table: sizes must be > 0 and top_center finite");
  check_list(s.objects, "objects", assets::AssetKind::object);
  check_list(s.obstacles, "obstacles", assets::AssetKind::obstacle);
  const int n = static_cast<int>(s.objects.size());
  auto check_index = [&](int i, const std::string& field) {
    if (i < 0 || i >= n) manisoft::detail::fail(where, ": ", field, " = ", i, " is out of range: the scene has ", n, " objects");
  };
  switch (s.task) {
    case Task::coll:
      check_index(s.goal.object, "goal.object");
      check_index(s.goal.container, "goal.container");
      if (s.goal.object == s.goal.container) manisoft::detail::fail(where, ": goal.object and goal.container are both ", s.goal.object);
      if (lib.get(s.objects[static_cast<std::size_t>(s.goal.container)].asset_id, where).receptacles.empty())
        manisoft::detail::fail(where, ": goal.container = ", s.goal.container, " ('", s.objects[static_cast<std::size_t>(s.goal.container)].asset_id,
                               "') has no receptacle");
      break;
    case Task::aln:
      check_index(s.goal.object, "goal.object");
      check_pose(s.goal.goal_pose, "goal.goal_pose");
      break;
    case Task::ovr:
      check_index(s.goal.object, "goal.object");
      check_pose(s.goal.goal_pose, "goal.goal_pose");
      if (s.goal.obstacle < 0 || s.goal.obstacle >= static_cast<int>(s.obstacles.size()))
        manisoft::detail::fail(where, ": goal.obstacle = ", s.goal.obstacle, " is out of range: the scene has ", s.obstacles.size(), " obstacles");
      break;
    case Task::stk:
      if (s.goal.items.size() < 2) manisoft::detail::fail(where, ": goal.items has ", s.goal.items.size(), " items, at least 2 are needed");
      for (std::size_t i = 0; i < s.goal.items.size(); ++i) {
        check_index(s.goal.items[i], "goal.items[" + std::to_string(i) + "]");
        for (std::size_t j = 0; j < i; ++j)
          if (s.goal.items[i] == s.goal.items[j]) manisoft::detail::fail(where, ": goal.items repeats object ", s.goal.items[i]);
      }
      // From the bottom up, each item narrower than the one below (the sampler's order).
      for (std::size_t i = 1; i < s.goal.items.size(); ++i) {
        const auto& below = s.objects[static_cast<std::size_t>(s.goal.items[i - 1])].asset_id;
        const auto& above = s.objects[static_cast<std::size_t>(s.goal.items[i])].asset_id;
        const double wb = lib.get(below, where).bounding_half_extents.x(), wa = lib.get(above, where).bounding_half_extents.x();
        if (!(wa < wb))
          manisoft::detail::fail(where, ": goal.items[", i, "] ('", above, "', half width ", wa, " m) is not narrower than goal.items[", i - 1, "] ('",
                                 below, "', ", wb, " m): items go from the widest (bottom) to the narrowest (top)");
      }
      break;
    case Task::arr:
      if (s.goal.relations.empty()) manisoft::detail::fail(where, ": goal.relations is empty");
      for (std::size_t r = 0; r < s.goal.relations.size(); ++r) {
        const auto& rel = s.goal.relations[r];
        const std::string field = "goal.relations[" + std::to_string(r) + "]";
        const std::size_t want = (rel.kind == Relation::Kind::between || rel.kind == Relation::Kind::in_a_row) ? 2 : 1;
        if (rel.objects.size() != 1 || rel.references.size() != want)
          manisoft::detail::fail(where, ": ", field, " (", to_string(rel.kind), ") needs 1 object and ", want, " references, has ", rel.objects.size(),
                                 " and ", rel.references.size());
        for (std::size_t i = 0; i < rel.objects.size(); ++i) check_index(rel.objects[i], field + ".objects[" + std::to_string(i) + "]");
        for (std::size_t i = 0; i < rel.references.size(); ++i) check_index(rel.references[i], field + ".references[" + std::to_string(i) + "]");
        if (!rel.spots.empty() && rel.spots.size() != rel.objects.size())
          manisoft::detail::fail(where, ": ", field, ".spots has ", rel.spots.size(), " entries for ", rel.objects.size(), " objects");
        for (const auto& p : rel.spots)
          if (!p.allFinite()) manisoft::detail::fail(where, ": ", field, ".spots is not finite");
      }
      break;
  }
}

/// Checks scenes; owns the inverse statics it solves with (not thread-safe: one per thread). A
/// scene made by hand or loaded from a file is checked as a sampled one is with require_valid.
class SceneValidator {
 public:
  explicit SceneValidator(const AssetLibrary& lib, ValidationSettings settings = {})
      : lib_(&lib), settings_(settings), statics_(make_scene_statics()) {}

  const ValidationSettings& settings() const { return settings_; }

  /// All checks, cheapest first; the first failure is reported.
  ValidationResult check(const SceneSpec& s) {
    ValidationResult r;
    ik_solves_ = 0;
    try {
      require_consistent(s, *lib_, "scene");
    } catch (const Error& e) {
      return fail(e.what());
    }
    if (auto why = reachability(s); !why.empty()) return fail(why);
    if (auto why = physics(s); !why.empty()) return fail(why);
    r.ik_solves = ik_solves_;
    return r;
  }

  /// Physics only: interpenetration and rest (empty string = fine).
  std::string physics(const SceneSpec& s) const {
    rigid::RigidWorld w;
    const SceneBodies b = populate_rigid_world(w, s, *lib_);
    w.step(settings_.dt);
    for (const auto& m : w.manifolds())
      for (int k = 0; k < m.count; ++k)
        if (m.points[static_cast<std::size_t>(k)].separation < -settings_.penetration_tolerance)
          return "interpenetration: " + w.model(m.body_a).name + " and " + w.model(m.body_b).name + " overlap by " +
                 std::to_string(-m.points[static_cast<std::size_t>(k)].separation * 1e3) + " mm";
    const int settle = static_cast<int>(std::lround(settings_.settle_time / settings_.dt));
    const int watch = static_cast<int>(std::lround(settings_.watch_time / settings_.dt));
    for (int i = 1; i < settle; ++i) w.step(settings_.dt);
    std::vector<Eigen::Vector3d> x0;
    std::vector<Eigen::Quaterniond> q0;
    for (auto id : b.objects) {
      x0.push_back(w.position(id));
      q0.push_back(w.orientation(id));
    }
    for (int i = 0; i < watch; ++i) w.step(settings_.dt);
    for (std::size_t i = 0; i < b.objects.size(); ++i) {
      const auto id = b.objects[i];
      const double moved = (w.position(id) - x0[i]).norm();
      const double turned = w.orientation(id).angularDistance(q0[i]);
      const double drift = (w.position(id) - s.objects[i].pose.translation).norm();
      const double tilt = w.orientation(id).angularDistance(Eigen::Quaterniond(s.objects[i].pose.rotation));
      if (moved > settings_.max_move || turned > settings_.max_rotation)
        return "not at rest: " + w.model(id).name + " moved " + std::to_string(moved * 1e3) + " mm, turned " + std::to_string(turned * 180 / 3.14159265358979323846) +
               " deg over the last " + std::to_string(settings_.watch_time) + " s";
      if (drift > settings_.max_drift || tilt > settings_.max_rotation)
        return "unstable placement: " + w.model(id).name + " drifted " + std::to_string(drift * 1e3) + " mm, turned " +
               std::to_string(tilt * 180 / 3.14159265358979323846) + " deg while settling";
    }
    return {};
  }

  /// Whether the tool pose `target` is reachable with the rod clear of the table and obstacles.
  bool tool_pose_reachable(const SceneSpec& s, const math::Pose<double>& target) {
    ++ik_solves_;
    const double top = s.table.top_center.z();
    if (!pose_reachable(statics_, target, top, settings_.table_clearance)) return false;
    const auto& x = statics_.desired_state().positions;
    for (const auto& o : s.obstacles) {
      const auto& a = lib_->get(o.asset_id, "obstacle");
      for (int k = 0; k < x.rows(); ++k) {
        const Eigen::Vector3d p = x.row(k).transpose();
        if (distance_to_box(o.pose, a, p) < settings_.obstacle_clearance) return false;
        if (k + 1 < x.rows() && distance_to_box(o.pose, a, 0.5 * (p + Eigen::Vector3d(x.row(k + 1).transpose()))) < settings_.obstacle_clearance)
          return false;
      }
    }
    return true;
  }

  /// Some candidate grasp of `a` at `pose` is reachable.
  bool grasp_reachable(const SceneSpec& s, const assets::Asset& a, const math::Pose<double>& pose) {
    for (const auto& g : candidate_grasps(a, pose))
      if (tool_pose_reachable(s, g)) return true;
    return false;
  }

  /// A tool-down pose at `position` with some yaw in quarter turns is reachable.
  bool place_reachable(const SceneSpec& s, const Eigen::Vector3d& position) {
    for (int q = 0; q < 4; ++q)
      if (tool_pose_reachable(s, tool_down_pose(position, q * 1.5707963267948966))) return true;
    return false;
  }

  /// Grasp and goal reachability of the task (empty string = fine).
  std::string reachability(const SceneSpec& s) {
    auto obj = [&](int i) -> const assets::Asset& { return lib_->get(s.objects[static_cast<std::size_t>(i)].asset_id, "object"); };
    auto pose = [&](int i) -> const math::Pose<double>& { return s.objects[static_cast<std::size_t>(i)].pose; };
    auto grasp_height = [&](int i) { return obj(i).grasps.empty() ? asset_height(obj(i)) : obj(i).grasps.front().grasp.translation.z(); };
    auto need_grasp = [&](int i) -> std::string {
      if (obj(i).grasps.empty()) return "object " + std::to_string(i) + " (" + obj(i).id + ") has no grasp annotation";
      if (!grasp_reachable(s, obj(i), pose(i))) return "no reachable grasp for object " + std::to_string(i) + " (" + obj(i).id + ")";
      return {};
    };
    switch (s.task) {
      case Task::coll: {
        if (auto w = need_grasp(s.goal.object); !w.empty()) return w;
        const auto& c = obj(s.goal.container);
        const math::Pose<double> opening = pose(s.goal.container) * c.receptacles.front().opening;
        const Eigen::Vector3d at = opening.translation + Eigen::Vector3d(0, 0, grasp_height(s.goal.object) + settings_.place_clearance);
        if (!place_reachable(s, at)) return "container opening of object " + std::to_string(s.goal.container) + " (" + c.id + ") not reachable";
        return {};
      }
      case Task::aln:
      case Task::ovr: {
        if (auto w = need_grasp(s.goal.object); !w.empty()) return w;
        if (!grasp_reachable(s, obj(s.goal.object), s.goal.goal_pose)) return std::string(to_string(s.task)) + " goal pose not reachable";
        return {};
      }
      case Task::stk: {
        double stack = asset_height(obj(s.goal.items.front()));
        for (std::size_t k = 1; k < s.goal.items.size(); ++k) {
          if (auto w = need_grasp(s.goal.items[k]); !w.empty()) return w;
          const Eigen::Vector3d at = pose(s.goal.items.front()).translation + Eigen::Vector3d(0, 0, stack + grasp_height(s.goal.items[k]) + settings_.place_clearance);
          if (!place_reachable(s, at)) return "stacking spot for item " + std::to_string(k) + " not reachable";
          stack += asset_height(obj(s.goal.items[k]));
        }
        return {};
      }
      case Task::arr: {
        for (const auto& rel : s.goal.relations) {
          for (std::size_t i = 0; i < rel.objects.size(); ++i) {
            if (auto w = need_grasp(rel.objects[i]); !w.empty()) return w;
            if (rel.spots.size() == rel.objects.size()) {
              math::Pose<double> at = pose(rel.objects[i]);
              at.translation = rel.spots[i];
              if (!grasp_reachable(s, obj(rel.objects[i]), at)) return std::string("spot of relation ") + std::string(to_string(rel.kind)) + " not reachable";
            }
          }
        }
        return {};
      }
    }
    return {};
  }

  /// Distance from world point p to the bounding box of asset `a` at `pose` (0 inside).
  static double distance_to_box(const math::Pose<double>& pose, const assets::Asset& a, const Eigen::Vector3d& p) {
    const Eigen::Vector3d local = pose.rotation.transpose() * (p - pose.translation) - a.bounding_center;
    const Eigen::Vector3d d = (local.cwiseAbs() - a.bounding_half_extents).cwiseMax(0.0);
    return d.norm();
  }

 private:
  ValidationResult fail(const std::string& why) const {
    ValidationResult r;
    r.valid = false;
    r.reason = why;
    r.ik_solves = ik_solves_;
    return r;
  }

  const AssetLibrary* lib_;
  ValidationSettings settings_;
  rod::InverseStatics<double> statics_;
  int ik_solves_ = 0;
};

/// Refuses a scene a sampler would not return (SceneValidator::check: consistent, every grasp and
/// goal reachable, no interpenetration, at rest), naming `where` (file or caller) and the reason.
inline void require_valid(const SceneSpec& s, SceneValidator& validator, const std::string& where) {
  const ValidationResult r = validator.check(s);
  if (!r.valid) manisoft::detail::fail(where, ": not a valid scene: ", r.reason);
}

}  // namespace manisoft::scene
