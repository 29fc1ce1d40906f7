// OVR, "over": bring an object to a goal marker with a tall obstacle standing between its start
// and the goal ("Place the bottle at the marker behind the vase."), so the arm carries it over the
// obstacle: what a soft arm does that a rigid one struggles with (the ManiSoft paper, figure 1a:
// soft arms "reach around obstacles"). Success: the object's asset origin within
// Tolerances::aln_position of the marker's, its z axis within ovr_upright of world z (any yaw),
// released and at rest, held for TaskEnvConfig::hold_steps. The obstacle is one of the scene's
// obstacles (SceneSpec::goal.obstacle), placed there by the sampler (scene_sampler.hpp, draw_ovr).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <string_view>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

struct Ovr {
  static constexpr scene::Task id = scene::Task::ovr;
  static constexpr std::string_view summary = "carry an object over a tall obstacle to a goal marker";
  static constexpr bool tables_by_category = true;  ///< evaluation tables per category of target_object
  static constexpr std::array<std::string_view, 4> condition_names{"position", "upright", "released", "at_rest"};

  struct Goal {
    using Task = Ovr;
    int object = -1;
    Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< world, the marker's asset origin
  };

  static Goal goal(const scene::SceneSpec& spec, const scene::AssetLibrary&) {
    const auto& g = spec.goal;
    if (g.object < 0 || g.object >= static_cast<int>(spec.objects.size()))
      ::manisoft::detail::fail("OVR goal: object ", g.object, " is not one of the scene's ", spec.objects.size(), " objects");
    if (g.obstacle < 0 || g.obstacle >= static_cast<int>(spec.obstacles.size()))
      ::manisoft::detail::fail("OVR goal: obstacle ", g.obstacle, " is not one of the scene's ", spec.obstacles.size(), " obstacles");
    return Goal{g.object, g.goal_pose.translation};
  }

  /// Angle (rad) between the object's z axis and world z.
  static double tilt(const ObjectState& o) { return std::acos(std::clamp(o.pose.rotation(2, 2), -1.0, 1.0)); }

  static Conditions evaluate(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol = {}) {
    const ObjectState& o = detail::object_at(snapshot, goal.object);
    const std::array<int, 1> one{goal.object};
    Conditions c;
    c.add("position", (o.pose.translation - goal.position).norm() <= tol.aln_position);
    c.add("upright", tilt(o) <= tol.ovr_upright);
    c.add("released", released(snapshot, one));
    c.add("at_rest", all_at_rest(snapshot, one, tol));
    return c;
  }

  /// The object already at the marker (read off the conditions at reset).
  static bool holds_at_start(const Conditions& c) { return c.holds("position"); }

  static int target_object(const scene::SceneSpec& spec) { return spec.goal.object; }

  // ---- the expert's moves (moves.hpp)
  static constexpr bool states_yaw = false;
  static int moves(const scene::SceneSpec&) { return 1; }
  /// The object at the marker's position as it stands (the expert's carry lifts it over the
  /// obstacle between).
  static Move move(int, const MoveScene& s) {
    const auto& g = s.spec.goal;
    math::Pose<double> p = s.pose(g.object);
    p.translation = g.goal_pose.translation + Eigen::Vector3d(0, 0, s.place_clearance);
    return {g.object, p};
  }
  static Support support(int, const scene::SceneSpec&) { return {}; }
};

}  // namespace manisoft::task
