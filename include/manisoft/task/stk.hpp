// STK, "stack" (paper section 3.2): stack 2-4 bowls or plates of graded size, the largest at the
// bottom ("Stack the plates."). Success: each item touches the one below, its centre of mass
// lies higher and within Tolerances::stk_horizontal of the one below horizontally, only the
// bottom item touches the table, all released and at rest, held for TaskEnvConfig::hold_steps.
// A goal must list its items from the widest to the narrowest (scene_validation.hpp).
#pragma once

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

struct Stk {
  static constexpr scene::Task id = scene::Task::stk;
  static constexpr std::string_view summary = "stack items of graded size, the largest at the bottom";
  static constexpr bool tables_by_category = false;  ///< the evaluation takes K stacks in all: a stack is a set of one category
  static constexpr std::array<std::string_view, 6> condition_names{"touching_below", "above_below", "centred_on_below", "only_bottom_on_table",
                                                                   "released", "at_rest"};

  struct Goal {
    using Task = Stk;
    std::vector<int> items;  ///< bottom (largest) to top (smallest)
  };

  static Goal goal(const scene::SceneSpec& spec, const scene::AssetLibrary&) {
    for (const int i : spec.goal.items)
      if (i < 0 || i >= static_cast<int>(spec.objects.size()))
        ::manisoft::detail::fail("STK goal: item ", i, " is not one of the scene's ", spec.objects.size(), " objects");
    if (spec.goal.items.size() < 2) ::manisoft::detail::fail("a stack needs at least 2 items, got ", spec.goal.items.size());
    return Goal{spec.goal.items};
  }

  static Conditions evaluate(const Snapshot& snapshot, std::span<const int> items, const Tolerances& tol = {}) {
    if (items.size() < 2) ::manisoft::detail::fail("a stack needs at least 2 items, got ", items.size());
    bool touching = true, above = true, centred = true, off_table = true;
    for (std::size_t k = 1; k < items.size(); ++k) {
      const ObjectState& below = detail::object_at(snapshot, items[k - 1]);
      const ObjectState& top = detail::object_at(snapshot, items[k]);
      touching = touching && top.touches(items[k - 1]);
      off_table = off_table && !top.touches_table;
      above = above && top.center_of_mass.z() > below.center_of_mass.z();
      centred = centred && (top.center_of_mass - below.center_of_mass).head<2>().norm() <= tol.stk_horizontal;
    }
    Conditions c;
    c.add("touching_below", touching);
    c.add("above_below", above);
    c.add("centred_on_below", centred);
    c.add("only_bottom_on_table", off_table);
    c.add("released", released(snapshot, items));
    c.add("at_rest", all_at_rest(snapshot, items, tol));
    return c;
  }
  static Conditions evaluate(const Snapshot& snapshot, const Goal& goal, const Tolerances& tol = {}) { return evaluate(snapshot, std::span<const int>(goal.items), tol); }

  /// The items already stacked, as far as positions tell (read off the conditions at reset).
  static bool holds_at_start(const Conditions& c) { return c.holds("above_below") && c.holds("centred_on_below"); }

  /// The first item the stack moves: the top one (the bottom item stays where it is).
  static int target_object(const scene::SceneSpec& spec) { return spec.goal.items.empty() ? -1 : spec.goal.items.back(); }

  // ---- the expert's moves (moves.hpp)
  static constexpr bool states_yaw = false;
  /// items[k + 1] onto items[k] for k = 0, 1, ...
  static int moves(const scene::SceneSpec& spec) { return static_cast<int>(spec.goal.items.size()) - 1; }
  /// Move k: the item onto the receptacle of the item below, or onto its top, as that stands now.
  static Move move(int k, const MoveScene& s) {
    const auto& items = s.spec.goal.items;
    const int below = items.at(static_cast<std::size_t>(k)), item = items.at(static_cast<std::size_t>(k) + 1);
    const math::Pose<double> b = s.pose(below);
    const auto& ab = s.asset(below);
    math::Pose<double> p = s.pose(item);
    const Eigen::Vector3d on = ab.receptacles.empty() ? Eigen::Vector3d(b.translation + Eigen::Vector3d(0, 0, scene::asset_height(ab)))
                                                      : Eigen::Vector3d((b * ab.receptacles.front().placement).translation);
    p.translation = on + Eigen::Vector3d(0, 0, s.place_clearance);
    return {item, p};
  }
  static Support support(int k, const scene::SceneSpec& spec) { return {spec.goal.items.at(static_cast<std::size_t>(k)), SupportKind::onto}; }
};

/// STK's predicate on its own.
inline bool stacked(const Snapshot& snapshot, std::span<const int> items, const Tolerances& tol = {}) { return Stk::evaluate(snapshot, items, tol).all(); }

}  // namespace manisoft::task
