// The instructions of a scene (the ManiSoft benchmark paper, section 3.5: one canonical
// description in clean scenes, about 40 attribute-aware ones in randomized scenes): the scene's
// goal turned into the language layer's task slots, its objects and obstacles (with the scene's
// colour overrides) into language::SceneObject, and the result stored in the SceneSpec. A scene
// whose goal objects cannot all be named uniquely gets no instructions (describe() returns false)
// and the sampler redraws it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "manisoft/language/instructions.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"

namespace manisoft::scene {

/// Every object, then every obstacle, as the language layer sees it (goal indices refer to the
/// objects, which come first).
inline std::vector<language::SceneObject> language_objects(const SceneSpec& s, const AssetLibrary& assets) {
  std::vector<language::SceneObject> out;
  for (const auto* list : {&s.objects, &s.obstacles}) {
    for (std::size_t i = 0; i < list->size(); ++i) {
      const PlacedAsset& p = (*list)[i];
      language::SceneObject o;
      o.asset = &assets.get(p.asset_id, (list == &s.objects ? "objects[" : "obstacles[") + std::to_string(i) + "]");
      o.position = p.pose.translation;
      if (p.appearance.override_color) o.color_name = p.appearance.color_name;
      out.push_back(o);
    }
  }
  return out;
}

/// The language layer's slots of the scene's goal (ARR: its first relation; OVR: the object and
/// the obstacle between, which language_objects lists after the objects).
inline language::TaskSlots task_slots(const SceneSpec& s) {
  language::TaskSlots slots;
  slots.task = std::string(to_string(s.task));
  if (s.task == Task::arr) {
    if (s.goal.relations.empty() || s.goal.relations.front().objects.empty())
      manisoft::detail::fail("ARR scene ", s.index, " has no relation to describe");
    const Relation& r = s.goal.relations.front();
    slots.relation = std::string(to_string(r.kind));
    slots.objects.push_back(r.objects.front());
    slots.objects.insert(slots.objects.end(), r.references.begin(), r.references.end());
  } else if (s.task == Task::ovr) {
    slots.objects = {s.goal.object, static_cast<int>(s.objects.size()) + s.goal.obstacle};
  } else {
    slots.objects = goal_objects(s);
  }
  return slots;
}

/// Fills s.instruction (and, in randomized scenes, s.instructions_seen / _unseen) with
/// instructions drawn from `seed`; false (and nothing changed) if a goal object has no unique
/// referring expression.
inline bool describe(SceneSpec& s, const AssetLibrary& assets, const language::Library& library, std::uint64_t seed) {
  const auto objects = language_objects(s, assets);
  const auto made = language::make_instructions(library, objects, task_slots(s), s.setting == Setting::randomized, seed);
  if (!made) return false;
  s.instruction = made->canonical;
  s.instructions_seen = made->seen;
  s.instructions_unseen = made->unseen;
  return true;
}

}  // namespace manisoft::scene
