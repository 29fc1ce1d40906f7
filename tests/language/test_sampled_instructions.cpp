// The instructions stored with sampled scenes (the sampler through scene/scene_instructions.hpp),
// checked from outside the language layer: every referring expression of every stored instruction
// (canonical, seen and unseen) names exactly the object of its slot among all the objects and
// obstacles on the table, by the independent matcher of tests/support/language_matcher.hpp; and no
// canonical or seen instruction says an unseen noun, an unseen relation phrase or a word that only
// unseen wording has. Scenes: train indices 0-14 of every task and setting, seed 3 (the randomized
// ones: 75 scenes, 32 seen and 8 unseen instructions each).
#include <catch2/catch.hpp>

#include <cctype>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "../support/language_matcher.hpp"
#include "manisoft/scene/scene_sampler.hpp"

namespace test_sampled_instructions {  // per-file namespace: the group's tests build as one unity translation unit

namespace lang = manisoft::language;
using namespace manisoft::scene;

namespace {

SceneSampler& sampler() {
  static SceneSampler s;
  return s;
}

const lang::Library& library() {
  static const lang::Library l = lang::Library::load_default();
  return l;
}

/// The scenes of the check: train indices 0-14 of every task and setting, seed 3.
const std::vector<SceneSpec>& scenes() {
  static const std::vector<SceneSpec> all = [] {
    std::vector<SceneSpec> out;
    for (const Task t : {Task::coll, Task::aln, Task::stk, Task::arr, Task::ovr})
      for (const Setting setting : {Setting::clean, Setting::randomized})
        for (std::uint64_t index = 0; index < 15; ++index) {
          SampleRequest q;
          q.task = t;
          q.setting = setting;
          q.index = index;
          q.seed = 3;
          out.push_back(sampler().sample(q));
        }
    return out;
  }();
  return all;
}

/// The table as the matcher sees it: every object, then every obstacle, with the scene's colour.
std::vector<lang::SceneObject> table_of(const SceneSpec& s) {
  std::vector<lang::SceneObject> out;
  for (const auto* list : {&s.objects, &s.obstacles})
    for (const PlacedAsset& p : *list) {
      lang::SceneObject o;
      o.asset = &sampler().library().get(p.asset_id, "test");
      o.color_name = p.appearance.override_color ? p.appearance.color_name : "";
      out.push_back(o);
    }
  return out;
}

/// A template with a relation phrase in its {RELATION}, as a regular expression whose groups are
/// its placeholders ({A}, {B}, {C}: an expression "the ..."; {ITEMS}: a list), and their names.
struct Pattern {
  std::regex regex;
  std::vector<std::string> names;
};

Pattern pattern_of(const std::string& template_text, const std::string& relation) {
  std::string text = template_text;
  const std::size_t at = text.find("{RELATION}");
  if (at != std::string::npos) text.replace(at, 10, relation);
  Pattern p;
  std::string re;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '{') {
      const std::size_t end = text.find('}', i);
      p.names.push_back(text.substr(i + 1, end - i - 1));
      re += p.names.back() == "ITEMS" ? "(.+)" : "([Tt]he .+?)";
      i = end;
    } else {
      if (std::string("\\^$.|?*+()[]{}").find(text[i]) != std::string::npos) re += '\\';
      re += i == 0 ? static_cast<char>(std::toupper(static_cast<unsigned char>(text[i]))) : text[i];  // sentence case
    }
  }
  p.regex = std::regex(re);
  return p;
}

/// Every pattern of `task`'s seen (or unseen) templates and, for ARR, relation phrases of `kind`.
const std::vector<Pattern>& patterns(const std::string& task, const std::string& kind, bool seen) {
  static std::map<std::string, std::vector<Pattern>> cache;
  std::vector<Pattern>& out = cache[task + "/" + kind + (seen ? "/seen" : "/unseen")];
  if (out.empty()) {
    const std::vector<std::string> none{""};
    const auto& phrases = task == "ARR" ? library().relations.at(kind).of(seen) : none;
    for (const auto& t : library().templates.at(task).of(seen))
      for (const auto& r : phrases) out.push_back(pattern_of(t, r));
  }
  return out;
}

/// The expressions of an {ITEMS} list: "x, y and z" -> x, y, z.
std::vector<std::string> items_of(const std::string& list) {
  std::vector<std::string> out;
  std::size_t from = 0;
  for (std::size_t comma = list.find(", "); comma != std::string::npos; comma = list.find(", ", from)) {
    out.push_back(list.substr(from, comma - from));
    from = comma + 2;
  }
  const std::string last = list.substr(from);
  const std::size_t and_at = last.rfind(" and ");
  if (and_at == std::string::npos) return {list};
  out.push_back(last.substr(0, and_at));
  out.push_back(last.substr(and_at + 5));
  return out;
}

/// Does `instruction` read as one of the patterns with each placeholder holding an expression
/// that truthfully names its slot's object and no other object on the table?
bool refers_uniquely(const std::string& instruction, const std::vector<Pattern>& candidates, const std::vector<int>& slots,
                     const std::vector<lang::SceneObject>& table) {
  const auto names_only = [&](std::string expression, int object) {
    if (expression.starts_with("The ")) expression[0] = 't';
    const auto& o = table[static_cast<std::size_t>(object)];
    return manisoft::test::count_matches(library(), expression, table) == 1 &&
           manisoft::test::truthful_phrasings(library(), *o.asset, o.color_name).count(expression) == 1;
  };
  for (const Pattern& p : candidates) {
    std::smatch m;
    if (!std::regex_match(instruction, m, p.regex)) continue;
    bool all = true;
    for (std::size_t g = 0; g < p.names.size() && all; ++g) {
      const std::string& name = p.names[g];
      if (name == "ITEMS") {
        const std::vector<std::string> items = items_of(m[g + 1].str());
        all = items.size() == slots.size();
        for (std::size_t k = 0; k < items.size() && all; ++k) all = names_only(items[k], slots[k]);
      } else {
        all = names_only(m[g + 1].str(), slots[static_cast<std::size_t>(name[0] - 'A')]);
      }
    }
    if (all) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("sampled scenes' stored instructions name each goal object uniquely (independent matcher)", "[language][scene]") {
  long checked = 0;
  std::vector<std::string> failed;
  for (const SceneSpec& s : scenes()) {
    const auto slots = task_slots(s);
    const auto table = table_of(s);
    for (const bool seen : {true, false}) {
      std::vector<std::string> stored = seen ? s.instructions_seen : s.instructions_unseen;
      if (seen) stored.push_back(s.instruction);
      for (const std::string& instruction : stored) {
        if (!refers_uniquely(instruction, patterns(slots.task, slots.relation, seen), slots.objects, table))
          failed.push_back(slots.task + " " + std::string(to_string(s.setting)) + " " + std::to_string(s.index) + ": " + instruction);
        ++checked;
      }
    }
  }
  CHECK(failed == std::vector<std::string>{});
  CHECK(checked == 150 + 75 * 40);  // every scene's canonical one; 32 seen + 8 unseen per randomized scene
}

TEST_CASE("sampled scenes' canonical and seen instructions say no unseen noun, relation phrase or word", "[language][scene]") {
  const auto unseen = manisoft::test::unseen_wording(library());
  const std::set<std::string> unseen_words = manisoft::test::unseen_only_words(library());
  REQUIRE(unseen_words.count("beyond") == 1);  // the behind relation's unseen word
  long checked = 0;
  std::vector<std::string> leaks;
  for (const SceneSpec& s : scenes()) {
    std::vector<std::string> stored = s.instructions_seen;
    stored.push_back(s.instruction);
    for (const std::string& instruction : stored) {
      const std::string where = std::string(to_string(s.task)) + " " + std::string(to_string(s.setting)) + " " + std::to_string(s.index) + ": '";
      for (const auto& [name, wording] : unseen)
        if (manisoft::test::says(instruction, wording)) leaks.push_back(where + instruction + "' says " + name + "'s unseen '" + wording + "'");
      for (const std::string& w : manisoft::test::words_of(instruction))
        if (unseen_words.count(w)) leaks.push_back(where + instruction + "' has the unseen word '" + w + "'");
      ++checked;
    }
  }
  CHECK(leaks == std::vector<std::string>{});
  CHECK(checked == 150 + 75 * 32);
}

}  // namespace test_sampled_instructions
