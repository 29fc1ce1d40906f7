// The schema of an expert episode file (what expert_recording.hpp records and episode_file.hpp
// stores; the ManiSoft benchmark paper, section 3.5), checked element by element:
//   datasets   actions, states, rewards, dones and obs/eef_pose, obs/gripper, obs/rod_centerline,
//              obs/rod_directors, obs/object_poses, obs/ee_target, obs/ee_waypoint, each with its
//              dtype and shape (n elements of the benchmark arm, the scene's object count); images
//              (uint8 F x H x W x 3, with int64 <name>_steps under images/) are optional; anything
//              else is refused
//   values     actions within the arm's actuation limits (rod::ActuationLimits as the arm world
//              applies them: |tau_1|, |tau_2| <= bend and |tau_3| <= twist, element 0 on the
//              clamped base none), S in {0, 1}; obs/ee_target's S the action's S; obs/ee_waypoint
//              0 at the first step, then the step before's or one more; dones 0 or 1 with the last
//              1 and only the last; rewards 0 or 1, only the last may be 1, and it is 1 exactly
//              when success is
//   attributes task, setting, split, scene, instruction, instructions_seen, instructions_unseen,
//              failure (strings); success, steps, seed, scene_index, redraws (numbers); optional
//              generate_args (string); the scene a valid scene (scene_json.hpp's reader) whose
//              task, setting, split, index, seed and instructions the attributes repeat; success 0
//              or 1 and failure empty exactly when it is 1; steps = the number of rows
// Every error names the file, the dataset or attribute, the element and the rule.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/control/action_layout.hpp"
#include "manisoft/dataset/dataset_index.hpp"
#include "manisoft/dataset/expert_recording.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::dataset {

namespace schema_detail {

/// One episode's file and group, for error messages.
struct Where {
  std::string file, demo;
  template <typename... Parts>
  [[noreturn]] void fail(const std::string& field, Parts&&... parts) const {
    h5::fail_at(file, field.empty() ? demo : demo + "/" + field, std::forward<Parts>(parts)...);
  }
};

inline std::string shape_text(const std::vector<hsize_t>& s) {
  std::string out;
  for (hsize_t d : s) out += (out.empty() ? "" : " x ") + std::to_string(d);
  return "(" + out + ")";
}

/// The dataset at `field` must have `dtype` and `shape`.
inline void require_dataset(const h5::File& f, const Where& at, const std::string& field, const std::string& dtype,
                            const std::vector<hsize_t>& shape) {
  const std::string path = at.demo + "/" + field;
  if (!f.exists(path)) at.fail(field, "missing dataset (the expert episode layout has it)");
  const std::string stored = f.dtype(path);
  if (stored != dtype) at.fail(field, "dtype ", stored, ", the layout says ", dtype);
  const std::vector<hsize_t> s = f.shape(path);
  if (s != shape) at.fail(field, "shape ", shape_text(s), ", the layout says ", shape_text(shape));
}

/// An image array: uint8 F x H x W x 3 (F = `frames` when known, else any).
inline hsize_t require_images(const h5::File& f, const Where& at, const std::string& field, hsize_t frames) {
  const std::vector<hsize_t> s = f.shape(at.demo + "/" + field);
  if (s.size() != 4 || s[3] != 3 || f.dtype(at.demo + "/" + field) != "uint8" || (frames > 0 && s[0] != frames))
    at.fail(field, "not an image array (uint8 F x H x W x 3", frames > 0 ? ", F = " + std::to_string(frames) : std::string(), "): ",
            f.dtype(at.demo + "/" + field), " ", shape_text(s));
  return s[0];
}

}  // namespace schema_detail

/// Rod elements of the benchmark arm (the task environment's arm).
inline int expert_arm_elements() { return world::tabletop_arm_parameters().n_elements; }

/// The actuation limits every recorded action must respect (those the arm world applies).
inline rod::ActuationLimits<double> expert_actuation_limits() { return world::ArmWorldSettings{}.limits; }

/// Checks the datasets of episode `e.index` in `file` against the layout (dtypes, shapes, nothing
/// unknown) for an arm of `elements` elements and a scene of `objects` objects.
inline void check_expert_layout(const std::filesystem::path& file, const Episode& e, int elements, int objects) {
  const h5::File f = h5::File::open(file.string());
  const schema_detail::Where at{file.string(), demo_path(e.index)};
  const auto t = static_cast<hsize_t>(e.steps());
  const std::map<std::string, std::pair<std::string, std::vector<hsize_t>>> layout{
      {"actions", {"float64", {t, static_cast<hsize_t>(control::FlatAction::size(elements))}}},
      {"states", {"float64", {t, static_cast<hsize_t>(state_columns(elements, objects))}}},
      {"rewards", {"float64", {t}}},
      {"dones", {"uint8", {t}}},
      {"obs/eef_pose", {"float32", {t, 7}}},
      {"obs/gripper", {"float32", {t, 2}}},
      {"obs/rod_centerline", {"float32", {t, static_cast<hsize_t>(3 * (elements + 1))}}},
      {"obs/rod_directors", {"float32", {t, static_cast<hsize_t>(9 * elements)}}},
      {"obs/object_poses", {"float32", {t, static_cast<hsize_t>(7 * objects)}}},
      {"obs/ee_target", {"float32", {t, 7}}},
      {"obs/ee_waypoint", {"float32", {t, 1}}}};
  for (const auto& [field, expected] : layout) schema_detail::require_dataset(f, at, field, expected.first, expected.second);
  for (const std::string& name : f.children(at.demo))
    if (!layout.count(name) && name != "obs" && name != "images") at.fail(name, "unexpected member (not in the expert episode layout)");
  for (const std::string& name : f.children(at.demo + "/obs"))
    if (!layout.count("obs/" + name)) schema_detail::require_images(f, at, "obs/" + name, t);
  if (!f.exists(at.demo + "/images")) return;
  const std::vector<std::string> names = f.children(at.demo + "/images");
  const std::set<std::string> members(names.begin(), names.end());
  for (const std::string& name : names) {
    if (name.ends_with("_steps") && members.count(name.substr(0, name.size() - 6))) continue;
    const hsize_t frames = schema_detail::require_images(f, at, "images/" + name, 0);
    if (!members.count(name + "_steps")) at.fail("images/" + name, "has no ", name, "_steps dataset");
    schema_detail::require_dataset(f, at, "images/" + name + "_steps", "int64", {frames});
  }
}

/// Checks the recorded actions, dones and rewards of `e` (read from `file`) against their rules.
inline void check_expert_values(const std::filesystem::path& file, const Episode& e, int elements, const rod::ActuationLimits<double>& limits) {
  const schema_detail::Where at{file.string(), demo_path(e.index)};
  const long t = e.steps();
  const int s_column = control::FlatAction::gripper(elements);
  const StepMatrix& target = e.observations.at("ee_target");
  const StepMatrix& waypoint = e.observations.at("ee_waypoint");
  for (long r = 0; r < t; ++r) {
    for (int c = 0; c < s_column; ++c) {
      const double a = e.actions(r, c), limit = c < 3 ? 0.0 : limits.limit(c % 3);  // element 0: the clamped base, no torque
      if (!(std::abs(a) <= limit))
        at.fail("actions", "element [", r, ", ", c, "] (step ", r, ", ", control::FlatAction::describe(c, elements), ") = ", a,
                " is outside the actuation limit +-", limit, " N m");
    }
    const double s = e.actions(r, s_column);
    if (s != 0.0 && s != 1.0) at.fail("actions", "element [", r, ", ", s_column, "] (step ", r, ", S) = ", s, ": S must be 0 or 1");
    if (const double ts = target(r, 6); ts != s) at.fail("obs/ee_target", "element [", r, ", 6] (step ", r, ", S) = ", ts, " but the action's S is ", s);
    const double w = waypoint(r, 0), before = r == 0 ? 0.0 : waypoint(r - 1, 0);
    if (r == 0 ? w != 0.0 : w != before && w != before + 1)
      at.fail("obs/ee_waypoint", "element [", r, ", 0] = ", w, ": 0 at the first step, then the step before's (", before, ") or one more");
    const int last = r + 1 == t ? 1 : 0;
    if (e.dones[static_cast<std::size_t>(r)] != last)
      at.fail("dones", "element [", r, "] = ", static_cast<int>(e.dones[static_cast<std::size_t>(r)]), ": dones must be 0 before the last step and 1 at it (step ", t - 1, ")");
    const double reward = e.rewards(r);
    if (reward != 0.0 && (reward != 1.0 || r + 1 != t))
      at.fail("rewards", "element [", r, "] = ", reward, ": rewards are 0, and 1 only at the last step of a successful episode");
  }
}

/// Checks the attributes of `e` (read from `file`): present with their types, the scene valid and
/// repeated consistently, success and failure agreeing with the rewards. Returns the scene.
inline scene::SceneSpec check_expert_attributes(const std::filesystem::path& file, const Episode& e) {
  const schema_detail::Where at{file.string(), demo_path(e.index)};
  const std::set<std::string> texts{"task", "setting", "split", "scene", "instruction", "instructions_seen", "instructions_unseen", "failure"};
  const std::set<std::string> numbers{"success", "steps", "seed", "scene_index", "redraws"};
  const auto text = [&](const std::string& name) -> const std::string& {
    if (e.numbers.count(name)) at.fail("", "attribute '", name, "' is a number, the layout says a string");
    const auto it = e.text.find(name);
    if (it == e.text.end()) at.fail("", "missing attribute '", name, "' (a string in the expert episode layout)");
    return it->second;
  };
  const auto number = [&](const std::string& name) {
    if (e.text.count(name)) at.fail("", "attribute '", name, "' is a string, the layout says a number");
    const auto it = e.numbers.find(name);
    if (it == e.numbers.end()) at.fail("", "missing attribute '", name, "' (a number in the expert episode layout)");
    return it->second;
  };
  for (const auto& name : texts) text(name);
  for (const auto& name : numbers) number(name);
  for (const auto& [name, value] : e.text)
    if (!texts.count(name) && name != generate_args_attribute) at.fail("", "unexpected attribute '", name, "' (not in the expert episode layout)");
  for (const auto& [name, value] : e.numbers)
    if (!numbers.count(name)) at.fail("", "unexpected attribute '", name, "' (not in the expert episode layout)");

  const scene::SceneSpec spec = scene::parse_scene(text("scene"), at.file + ": " + at.demo + ": attribute 'scene'");
  const auto same = [&](const std::string& name, const std::string& recorded, const std::string& of_scene) {
    if (recorded != of_scene) at.fail("", "attribute '", name, "' = '", recorded, "' but the scene attribute says '", of_scene, "'");
  };
  same("task", text("task"), std::string(scene::to_string(spec.task)));
  same("setting", text("setting"), std::string(scene::to_string(spec.setting)));
  same("split", text("split"), std::string(scene::to_string(spec.split)));
  same("instruction", text("instruction"), spec.instruction);
  same("instructions_seen", text("instructions_seen"), nlohmann::json(spec.instructions_seen).dump());
  same("instructions_unseen", text("instructions_unseen"), nlohmann::json(spec.instructions_unseen).dump());
  for (const auto& [name, of_scene] : {std::pair<const char*, double>{"scene_index", static_cast<double>(spec.index)}, {"seed", static_cast<double>(spec.seed)}})
    if (number(name) != of_scene) at.fail("", "attribute '", name, "' = ", number(name), " but the scene attribute says ", of_scene);

  const double success = number("success");
  if (success != 0.0 && success != 1.0) at.fail("", "attribute 'success' = ", success, ": must be 0 or 1");
  if (success != e.rewards(e.steps() - 1))
    at.fail("", "attribute 'success' = ", success, " but the last reward is ", e.rewards(e.steps() - 1), " (1 exactly for a success)");
  if ((success == 1.0) != text("failure").empty())
    at.fail("", "attribute 'failure' = '", text("failure"), "' with success = ", success, ": a failure reason exactly when not successful");
  if (number("steps") != static_cast<double>(e.steps()))
    at.fail("", "attribute 'steps' = ", number("steps"), " but the episode has ", e.steps(), " steps");
  for (const char* name : {"seed", "redraws"})
    if (number(name) < 0 || number(name) != std::floor(number(name))) at.fail("", "attribute '", name, "' = ", number(name), ": must be a whole number >= 0");
  return spec;
}

/// The whole expert schema of episode `e` read from `file` (attributes, layout, values).
inline void check_expert_episode(const std::filesystem::path& file, const Episode& e) {
  const scene::SceneSpec spec = check_expert_attributes(file, e);
  const int elements = expert_arm_elements();
  check_expert_layout(file, e, elements, static_cast<int>(spec.objects.size()));
  check_expert_values(file, e, elements, expert_actuation_limits());
}

}  // namespace manisoft::dataset
