// The registry of the benchmark's tasks: the one list of task types (coll.hpp, aln.hpp, stk.hpp,
// arr.hpp, ovr.hpp) and the one switch from a scene's task to its type. Everything that needs a task's
// name, predicate, condition names or target object asks here: the task environment, the
// programs, the Python module (and through it the Python scripts).
//
// A task type provides: `id` (scene::Task), `summary`, `condition_names`, a `Goal` prepared from
// the scene by `goal(spec, library)` (which refuses an ill-formed goal), `evaluate(snapshot,
// goal, tolerances)` returning the named conditions (success: all hold), `holds_at_start(conditions)`
// (the goal already met before any step, read off the conditions at reset: the scene is no task), `target_object(spec)` and
// `tables_by_category` (whether evaluation groups its episodes by the target's category), and the
// expert's moves (moves.hpp): `states_yaw`, `moves(spec)`, `move(k, scene)`, `support(k, spec)`.
#pragma once

#include <array>
#include <concepts>
#include <string_view>
#include <utility>
#include <vector>

#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/aln.hpp"
#include "manisoft/task/arr.hpp"
#include "manisoft/task/coll.hpp"
#include "manisoft/task/conditions.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/ovr.hpp"
#include "manisoft/task/stk.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

template <typename T>
concept TaskType = requires(const scene::SceneSpec& spec, const scene::AssetLibrary& library, const Snapshot& snapshot,
                            const typename T::Goal& goal, const Tolerances& tol, const MoveScene& move_scene) {
  { T::id } -> std::convertible_to<scene::Task>;
  { T::summary } -> std::convertible_to<std::string_view>;
  { T::goal(spec, library) } -> std::same_as<typename T::Goal>;
  { T::evaluate(snapshot, goal, tol) } -> std::same_as<Conditions>;
  { T::holds_at_start(T::evaluate(snapshot, goal, tol)) } -> std::same_as<bool>;
  { T::target_object(spec) } -> std::same_as<int>;
  { T::tables_by_category } -> std::convertible_to<bool>;
  { T::states_yaw } -> std::convertible_to<bool>;
  { T::moves(spec) } -> std::same_as<int>;
  { T::move(0, move_scene) } -> std::same_as<Move>;
  { T::support(0, spec) } -> std::same_as<Support>;
};

/// Calls f(T{}) with the type of the task `task`; the one place a task enum becomes a type.
template <typename F>
decltype(auto) visit_task(scene::Task task, F&& f) {
  switch (task) {
    case scene::Task::coll: return std::forward<F>(f)(Coll{});
    case scene::Task::aln: return std::forward<F>(f)(Aln{});
    case scene::Task::stk: return std::forward<F>(f)(Stk{});
    case scene::Task::arr: return std::forward<F>(f)(Arr{});
    case scene::Task::ovr: return std::forward<F>(f)(Ovr{});
  }
  ::manisoft::detail::fail("unknown task ", static_cast<int>(task));
}

using scene::all_tasks;

/// What a user reads of a task (the Python module's manisoft.tasks(), the docs).
struct TaskInfo {
  scene::Task id;
  std::string_view name;
  std::string_view summary;
  std::vector<std::string_view> conditions;
  bool tables_by_category = true;  ///< evaluation tables (and episode plans) per target-object category
};

inline TaskInfo task_info(scene::Task task) {
  return visit_task(task, []<TaskType T>(T) {
    return TaskInfo{T::id, scene::to_string(T::id), T::summary, std::vector<std::string_view>(T::condition_names.begin(), T::condition_names.end()),
                    T::tables_by_category};
  });
}

/// The object an episode is about, for per-category tables (COLL, ALN: the goal's object; STK:
/// the top item, moved first; ARR: the first relation's placed object; OVR: the carried object);
/// -1 when none.
inline int target_object(const scene::SceneSpec& spec) {
  return visit_task(spec.task, [&spec]<TaskType T>(T) { return T::target_object(spec); });
}

}  // namespace manisoft::task
