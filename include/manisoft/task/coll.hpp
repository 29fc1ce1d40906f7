// COLL, "collect" (paper section 3.2): put an object into a container ("Put the apple into the
// basket."). Success: the object's centre of mass inside the container's inner volume (the
// receptacle annotation, in the container's asset frame), the object touching the container and
// not the table, both released and at rest (success.hpp), held for TaskEnvConfig::hold_steps.
// The goal's categories, sampling and language live with the scene sampler and the language
// library; the expert's moves are below (moves.hpp).
#pragma once

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <string_view>

#include "manisoft/assets/asset.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

struct Coll {
  static constexpr scene::Task id = scene::Task::coll;
  static constexpr std::string_view summary = "put an object into a container";
  static constexpr bool tables_by_category = true;  ///< evaluation tables per category of target_object
  static constexpr std::array<std::string_view, 5> condition_names{"inside", "touching_container", "off_table", "released", "at_rest"};

  /// What the predicate reads, prepared once per episode from the scene.
  struct Goal {
    using Task = Coll;
    int object = -1;
    int container = -1;
    assets::Receptacle receptacle;
  };

  static Goal goal(const scene::SceneSpec& spec, const scene::AssetLibrary& library) {
    const auto& g = spec.goal;
    const auto n = static_cast<int>(spec.objects.size());
    if (g.object < 0 || g.object >= n || g.container < 0 || g.container >= n || g.object == g.container)
      ::manisoft::detail::fail("COLL goal: object ", g.object, " and container ", g.container, " must be two different objects of the scene's ", n);
    const auto& a = library.get(spec.objects[static_cast<std::size_t>(g.container)].asset_id, "COLL container");
    if (a.receptacles.empty()) ::manisoft::detail::fail("COLL goal: the container ", a.id, " has no receptacle annotation");
    return Goal{g.object, g.container, a.receptacles.front()};
  }

  /// Whether the object's centre of mass lies inside the container's inner volume.
  static bool inside(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol) {
    const ObjectState& o = detail::object_at(snapshot, goal.object);
    const ObjectState& c = detail::object_at(snapshot, goal.container);
    const assets::Receptacle& r = goal.receptacle;
    // Centre of mass in the opening frame: z up out of the opening, floor at -inner_depth.
    const Eigen::Vector3d p = r.opening.inverse_act(c.pose.inverse_act(o.center_of_mass));
    if (p.z() < -r.inner_depth || p.z() > tol.coll_above_rim) return false;
    if (r.inner_radius > 0) return p.head<2>().norm() <= r.inner_radius;
    return std::abs(p.x()) <= r.inner_half_extents.x() && std::abs(p.y()) <= r.inner_half_extents.y();
  }

  static Conditions evaluate(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol = {}) {
    const ObjectState& o = detail::object_at(snapshot, goal.object);
    detail::object_at(snapshot, goal.container);
    const std::array<int, 2> both{goal.object, goal.container};
    Conditions c;
    c.add("inside", inside(snapshot, goal, tol));
    c.add("touching_container", o.touches(goal.container));
    c.add("off_table", !o.touches_table);
    c.add("released", released(snapshot, both));
    c.add("at_rest", all_at_rest(snapshot, both, tol));
    return c;
  }

  /// The part of the goal that a scene can satisfy before any step (contacts are known only
  /// after one), read off the conditions at reset: the object already inside the container.
  static bool holds_at_start(const Conditions& c) { return c.holds("inside"); }

  /// The object the episode is about (per-category tables): the one to collect.
  static int target_object(const scene::SceneSpec& spec) { return spec.goal.object; }

  // ---- the expert's moves (moves.hpp)
  static constexpr bool states_yaw = false;
  static int moves(const scene::SceneSpec&) { return 1; }
  /// The object over the container's placement point, its bottom place_clearance above the
  /// rim (the expert lowers it on into the container: SupportKind::into).
  static Move move(int, const MoveScene& s) {
    const auto& g = s.spec.goal;
    const math::Pose<double> container = s.pose(g.container);
    const auto& rc = s.asset(g.container).receptacles.at(0);
    const math::Pose<double> opening = container * rc.opening, placement = container * rc.placement;
    math::Pose<double> p = s.pose(g.object);
    p.translation = Eigen::Vector3d(placement.translation.x(), placement.translation.y(), opening.translation.z() + s.place_clearance);
    return {g.object, p};
  }
  static Support support(int, const scene::SceneSpec& spec) { return {spec.goal.container, SupportKind::into}; }
};

/// COLL's predicate on its own (hand-built states, recorded episodes).
inline bool collected(const Snapshot& snapshot, int object, int container, const assets::Receptacle& receptacle, const Tolerances& tol = {}) {
  return Coll::evaluate(snapshot, Coll::Goal{object, container, receptacle}, tol).all();
}

}  // namespace manisoft::task
