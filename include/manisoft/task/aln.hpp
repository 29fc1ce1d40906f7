// ALN, "align" (paper section 3.2): bring an object to a goal pose shown by a marker ("Place the
// shoe at the marker."). Success: the object's asset origin within Tolerances::aln_position of
// the goal's, its orientation within aln_orientation of the goal's modulo the asset's symmetry
// (success.hpp, orientation_error), released and at rest, held for TaskEnvConfig::hold_steps.
#pragma once

#include <array>
#include <string_view>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

struct Aln {
  static constexpr scene::Task id = scene::Task::aln;
  static constexpr std::string_view summary = "bring an object to a goal pose";
  static constexpr bool tables_by_category = true;  ///< evaluation tables per category of target_object
  static constexpr std::array<std::string_view, 4> condition_names{"position", "orientation", "released", "at_rest"};

  struct Goal {
    using Task = Aln;
    int object = -1;
    math::Pose<double> pose;  ///< asset frame -> world
    Symmetry symmetry;
  };

  static Goal goal(const scene::SceneSpec& spec, const scene::AssetLibrary&) {
    const auto& g = spec.goal;
    if (g.object < 0 || g.object >= static_cast<int>(spec.objects.size()))
      ::manisoft::detail::fail("ALN goal: object ", g.object, " is not one of the scene's ", spec.objects.size(), " objects");
    return Goal{g.object, g.goal_pose, g.symmetry};
  }

  static Conditions evaluate(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol = {}) {
    const ObjectState& o = detail::object_at(snapshot, goal.object);
    const std::array<int, 1> one{goal.object};
    Conditions c;
    c.add("position", (o.pose.translation - goal.pose.translation).norm() <= tol.aln_position);
    c.add("orientation", orientation_error(o.pose.rotation, goal.pose.rotation, goal.symmetry) <= tol.aln_orientation);
    c.add("released", released(snapshot, one));
    c.add("at_rest", all_at_rest(snapshot, one, tol));
    return c;
  }

  /// The object already at its goal pose (read off the conditions at reset).
  static bool holds_at_start(const Conditions& c) { return c.holds("position") && c.holds("orientation"); }

  static int target_object(const scene::SceneSpec& spec) { return spec.goal.object; }

  // ---- the expert's moves (moves.hpp)
  static constexpr bool states_yaw = true;
  static int moves(const scene::SceneSpec&) { return 1; }
  /// The object at the goal pose, in the symmetric equivalent nearest its current orientation.
  static Move move(int, const MoveScene& s) {
    const auto& g = s.spec.goal;
    const math::Pose<double> now = s.pose(g.object);
    math::Pose<double> p = g.goal_pose;
    p.translation.z() += s.place_clearance;
    p.rotation = nearest_equivalent(now.rotation, p.rotation, g.symmetry);
    return {g.object, p};
  }
  static Support support(int, const scene::SceneSpec&) { return {}; }
};

/// ALN's predicate on its own.
inline bool aligned(const Snapshot& snapshot, int object, const math::Pose<double>& goal, const Symmetry& symmetry, const Tolerances& tol = {}) {
  return Aln::evaluate(snapshot, Aln::Goal{object, goal, symmetry}, tol).all();
}

}  // namespace manisoft::task
