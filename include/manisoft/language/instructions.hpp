// Instructions for a scene (the ManiSoft benchmark paper, section 3.5: one canonical description in
// clean scenes; about 40 attribute-aware instructions per randomized scene): task templates from
// the Library filled with unique referring expressions (referring.hpp). Seen instructions use
// seen templates, relation phrases and nouns only; unseen instructions use unseen templates (and
// unseen nouns where a category has them), so evaluation can test generalisation to wording never
// trained on. Deterministic: draws come from std::mt19937_64's raw output through our own bounded
// draw (the standard distributions differ between standard libraries).
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "manisoft/language/library.hpp"
#include "manisoft/language/referring.hpp"

namespace manisoft::language {

/// The task and which objects (indices into the scene's objects) fill its placeholders.
struct TaskSlots {
  std::string task;          ///< "COLL", "ALN", "STK", "ARR", "OVR"
  std::vector<int> objects;  ///< COLL {A, B}; ALN {A}; STK items, largest first; ARR {A, B} or {A, B, C}; OVR {A, B}: B the obstacle
  std::string relation;      ///< ARR: a relation kind of Library::relations ("left_of", "between", ...)
};

struct Instructions {
  std::string canonical;            ///< the clean scene's one instruction (also given for randomized scenes)
  std::vector<std::string> seen;    ///< randomized: for training
  std::vector<std::string> unseen;  ///< randomized: evaluation only
};

namespace detail {

/// Uniform integer in [0, n) from the raw engine, by rejection (portable, unbiased).
inline std::size_t draw_index(std::mt19937_64& engine, std::size_t n) {
  const std::uint64_t limit = std::mt19937_64::max() - std::mt19937_64::max() % n;
  std::uint64_t x = engine();
  while (x >= limit) x = engine();
  return static_cast<std::size_t>(x % n);
}

inline std::string replace_all(std::string text, const std::string& placeholder, const std::string& value) {
  const std::string key = "{" + placeholder + "}";
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
    text.replace(at, key.size(), value);
  return text;
}

inline std::string join_items(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) s += i + 1 == items.size() ? " and " : ", ";
    s += items[i];
  }
  return s;
}

/// Capitalises the first letter (a template may start with a placeholder: "{A} goes into {B}.").
inline std::string sentence(std::string text) {
  if (!text.empty() && text[0] >= 'a' && text[0] <= 'z') text[0] = static_cast<char>(text[0] - 'a' + 'A');
  return text;
}

}  // namespace detail

/// Fills `template_text` with one expression per slot: `pick(slot)` returns the expression of
/// the slot-th object of `slots`.
template <typename Pick>
std::string fill(const Library& library, const TaskSlots& slots, const std::string& template_text, const std::string& relation_phrase,
                 Pick pick) {
  std::string text = template_text;
  if (slots.task == "STK") {
    std::vector<std::string> items;
    for (std::size_t k = 0; k < slots.objects.size(); ++k) items.push_back(pick(k));
    text = detail::replace_all(text, "ITEMS", detail::join_items(items));
  } else {
    std::string relation = relation_phrase;
    if (slots.objects.size() > 1) {
      relation = detail::replace_all(relation, "B", pick(1));
      if (slots.objects.size() > 2) relation = detail::replace_all(relation, "C", pick(2));
    }
    text = detail::replace_all(text, "RELATION", relation);
    text = detail::replace_all(text, "A", pick(0));
    if (slots.task == "COLL" || slots.task == "OVR") text = detail::replace_all(text, "B", pick(1));
  }
  (void)library;
  return detail::sentence(text);
}

/// Checks that `slots` fits its task and the scene (throws InvalidInput naming what is wrong).
inline void validate(const Library& library, const TaskSlots& slots, std::size_t object_count) {
  const auto it = library.templates.find(slots.task);
  if (it == library.templates.end()) ::manisoft::detail::fail("unknown task '", slots.task, "': expected COLL, ALN, STK, ARR or OVR");
  std::size_t lo = 1, hi = 1;
  if (slots.task == "COLL" || slots.task == "OVR") lo = hi = 2;
  if (slots.task == "STK") lo = 2, hi = 8;
  if (slots.task == "ARR") {
    if (!library.relations.count(slots.relation)) ::manisoft::detail::fail("ARR: unknown relation '", slots.relation, "'");
    lo = hi = relation_placeholders().at(slots.relation).count("C") ? 3 : 2;
  }
  if (slots.objects.size() < lo || slots.objects.size() > hi)
    ::manisoft::detail::fail(slots.task, slots.relation.empty() ? "" : " " + slots.relation, " needs ", lo, lo == hi ? "" : " to " + std::to_string(hi),
                             " objects, got ", slots.objects.size());
  std::set<int> distinct;
  for (int k : slots.objects) {
    if (k < 0 || static_cast<std::size_t>(k) >= object_count)
      ::manisoft::detail::fail(slots.task, ": object index ", k, " is outside the scene's ", object_count, " objects");
    if (!distinct.insert(k).second) ::manisoft::detail::fail(slots.task, ": object ", k, " fills two slots");
  }
}

/// The instructions of a scene, or nothing if some slot's object has no unique expression (then
/// the scene cannot be described unambiguously: redraw it). Clean: `canonical` only; randomized:
/// also `count` instructions, about 4 seen to 1 unseen, all distinct.
inline std::optional<Instructions> make_instructions(const Library& library, std::span<const SceneObject> objects,
                                                     const TaskSlots& slots, bool randomized, std::uint64_t seed, int count = 40) {
  validate(library, slots, objects.size());
  if (count < 0) ::manisoft::detail::fail("count = ", count, " must be >= 0");
  std::vector<std::vector<Description>> seen_expr, unseen_expr;
  for (int k : slots.objects) {
    seen_expr.push_back(referring_expressions(library, objects, k, true));
    if (seen_expr.back().empty()) return std::nullopt;
    unseen_expr.push_back(referring_expressions(library, objects, k, false));
    if (unseen_expr.back().empty()) unseen_expr.back() = seen_expr.back();
  }
  const Split& templates = library.templates.at(slots.task);
  const Split* relations = slots.task == "ARR" ? &library.relations.at(slots.relation) : nullptr;

  Instructions out;
  out.canonical = fill(library, slots, templates.seen.front(), relations ? relations->seen.front() : "",
                       [&](std::size_t slot) { return seen_expr[slot].front().text(); });
  if (!randomized) return out;

  std::mt19937_64 engine(seed);
  const int unseen_count = count / 5;
  const int seen_count = count - unseen_count;
  std::set<std::string> made;
  for (const bool seen : {true, false}) {
    const int wanted = seen ? seen_count : unseen_count;
    auto& list = seen ? out.seen : out.unseen;
    const auto& expressions = seen ? seen_expr : unseen_expr;
    for (int attempt = 0; static_cast<int>(list.size()) < wanted && attempt < 50 * count + 100; ++attempt) {
      const auto& pool = templates.of(seen);
      const std::string& t = pool[detail::draw_index(engine, pool.size())];
      std::string phrase;
      if (relations) phrase = relations->of(seen)[detail::draw_index(engine, relations->of(seen).size())];
      const std::string text = fill(library, slots, t, phrase, [&](std::size_t slot) {
        const auto& options = expressions[slot];
        return options[detail::draw_index(engine, options.size())].text();
      });
      if (made.insert(text).second) list.push_back(text);
    }
  }
  return out;
}

}  // namespace manisoft::language
