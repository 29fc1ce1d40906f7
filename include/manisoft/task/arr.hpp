// ARR, "arrange" (paper section 3.2): place objects in spatial relations to others ("Put the
// cup to the left of the bowl."). Success: every relation of the goal holds between the objects'
// centres of mass in the horizontal plane (geometry/spatial_relation.hpp, with the margins of
// Tolerances::arr), every object named in them released and at rest, held for
// TaskEnvConfig::hold_steps. Spatial words are the viewer's: "left" is world -y, "in front of" +x.
#pragma once

#include <Eigen/Core>

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/spatial_relation.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

/// A relation of the goal: `objects` (the one placed, "a") then `references` ("b", "c").
using Relation = scene::Relation;

struct Arr {
  static constexpr scene::Task id = scene::Task::arr;
  static constexpr std::string_view summary = "place objects in spatial relations to others";
  static constexpr bool tables_by_category = true;  ///< evaluation tables per category of target_object
  static constexpr std::array<std::string_view, 3> condition_names{"relations", "released", "at_rest"};

  struct Goal {
    using Task = Arr;
    std::vector<Relation> relations;
  };

  static Goal goal(const scene::SceneSpec& spec, const scene::AssetLibrary&) {
    if (spec.goal.relations.empty()) ::manisoft::detail::fail("an arrangement needs at least one relation");
    return Goal{spec.goal.relations};
  }

  /// The relation's objects then references (at most 4), as the geometry orders them.
  static int named(const Relation& r, std::array<int, 4>& out) {
    int n = 0;
    for (const auto* list : {&r.objects, &r.references})
      for (const int i : *list) {
        if (n == 4) ::manisoft::detail::fail("relation ", to_string(r.kind), " names more than 4 objects");
        out[static_cast<std::size_t>(n++)] = i;
      }
    return n;
  }

  /// Does the relation hold between the objects' centres of mass (horizontal plane)?
  static bool relation_holds(const Snapshot& snapshot, const Relation& r, const Tolerances& tol = {}) {
    std::array<int, 4> who{};
    return holds(snapshot, r.kind, who, named(r, who), tol);
  }
  /// The same for the relation's objects `who[0 .. n - 1]` (named()).
  static bool holds(const Snapshot& snapshot, geometry::RelationKind kind, const std::array<int, 4>& who, int n, const Tolerances& tol) {
    const int lo = geometry::relation_min_count(kind), hi = geometry::relation_max_count(kind);
    if (n < lo || n > hi) ::manisoft::detail::fail("relation ", to_string(kind), " needs ", lo, lo == hi ? "" : " or 4", " objects, got ", n);
    std::array<Eigen::Vector2d, 4> centres;
    for (int k = 0; k < n; ++k)
      centres[static_cast<std::size_t>(k)] = detail::object_at(snapshot, who[static_cast<std::size_t>(k)]).center_of_mass.head<2>();
    return geometry::relation_holds(kind, std::span<const Eigen::Vector2d>(centres.data(), static_cast<std::size_t>(n)), tol.arr);
  }

  static Conditions evaluate(const Snapshot& snapshot, std::span<const Relation> relations, const Tolerances& tol = {}) {
    if (relations.empty()) ::manisoft::detail::fail("an arrangement needs at least one relation");
    bool hold = true, free = true, rest = true;
    for (const Relation& r : relations) {
      std::array<int, 4> who{};
      const int n = named(r, who);
      hold = holds(snapshot, r.kind, who, n, tol) && hold;
      const std::span<const int> objects(who.data(), static_cast<std::size_t>(n));
      free = free && released(snapshot, objects);
      rest = rest && all_at_rest(snapshot, objects, tol);
    }
    Conditions c;
    c.add("relations", hold);
    c.add("released", free);
    c.add("at_rest", rest);
    return c;
  }
  static Conditions evaluate(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol = {}) {
    return evaluate(snapshot, std::span<const Relation>(goal.relations), tol);
  }

  /// Every relation holds already (read off the conditions at reset).
  static bool holds_at_start(const Conditions& c) { return c.holds("relations"); }

  /// The object the episode is about: the first relation's placed object.
  static int target_object(const scene::SceneSpec& spec) {
    return spec.goal.relations.empty() || spec.goal.relations.front().objects.empty() ? -1 : spec.goal.relations.front().objects.front();
  }

  // ---- the expert's moves (moves.hpp)
  static constexpr bool states_yaw = false;
  /// One move per placed object of each relation (Relation::spots).
  static int moves(const scene::SceneSpec& spec) {
    int n = 0;
    for (const auto& r : spec.goal.relations) n += static_cast<int>(r.spots.size());
    return n;
  }
  /// Move k: the relation's object at the free spot the scene gives for it, at its height.
  static Move move(int k, const MoveScene& s) {
    const double top = s.spec.table.top_center.z();
    int n = 0;
    for (const auto& r : s.spec.goal.relations)
      for (std::size_t j = 0; j < r.spots.size(); ++j, ++n)
        if (n == k) {
          const int o = r.objects.at(j);
          math::Pose<double> p = s.pose(o);
          p.translation = Eigen::Vector3d(r.spots[j].x(), r.spots[j].y(), top + (p.translation.z() - top) + s.place_clearance);
          return {o, p};
        }
    ::manisoft::detail::fail("ARR: no move ", k, " among the scene's ", n);
  }
  static Support support(int, const scene::SceneSpec&) { return {}; }
};

/// ARR's predicate on its own.
inline bool arranged(const Snapshot& snapshot, std::span<const Relation> relations, const Tolerances& tol = {}) {
  return Arr::evaluate(snapshot, relations, tol).all();
}

}  // namespace manisoft::task
