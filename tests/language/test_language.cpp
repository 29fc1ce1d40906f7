// The language layer (include/manisoft/language/): referring expressions are unique, checked by a
// matcher written here independently (the set of every truthful phrasing of each object, compared
// as strings) on hand-built look-alike scenes and on random tables of catalogue assets; instructions
// fill every placeholder, keep seen and unseen wording apart, are deterministic; the shipped data
// files are large enough; malformed data files are refused naming the file and the entry.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "../support/language_matcher.hpp"
#include "../support/scratch_dir.hpp"
#include "manisoft/assets/catalog.hpp"
#include "manisoft/language/instructions.hpp"

namespace {

namespace lang = manisoft::language;
namespace assets = manisoft::assets;
using Catch::Contains;

const lang::Library& library() {
  static const lang::Library l = lang::Library::load_default();
  return l;
}

/// A hand-made asset: category, main colour and material, size, extra parts (name, colour).
assets::Asset make(const std::string& category, const std::string& color, const std::string& material,
                   assets::SizeClass size, std::vector<std::pair<std::string, std::string>> parts = {}) {
  assets::Asset a;
  a.id = category + "/hand";
  a.category = category;
  a.attributes.color_name = color;
  a.attributes.material_name = material;
  a.attributes.size = size;
  assets::VisualPart body;
  body.name = "body";
  body.color_name = color;
  a.visual.push_back(body);
  for (const auto& [name, part_color] : parts) {
    assets::VisualPart p;
    p.name = name;
    p.color_name = part_color;
    a.visual.push_back(p);
  }
  return a;
}

/// The independent matcher (tests/support/language_matcher.hpp) with the shipped library.
std::set<std::string> truthful_phrasings(const assets::Asset& a, const std::string& scene_color = "") {
  return manisoft::test::truthful_phrasings(library(), a, scene_color);
}

lang::SceneObject on(const assets::Asset& asset, const std::string& color = "") {
  lang::SceneObject o;
  o.asset = &asset;
  o.color_name = color;
  return o;
}

int count_matches(const std::string& expression, const std::vector<lang::SceneObject>& scene) {
  return manisoft::test::count_matches(library(), expression, scene);
}

std::vector<std::string> texts(const std::vector<lang::Description>& ds) {
  std::vector<std::string> out;
  for (const auto& d : ds) out.push_back(d.text());
  return out;
}

/// A regular expression that matches what a template can produce ({X} -> one or more characters).
std::regex template_regex(std::string t) {
  std::string pattern;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] == '{') {
      i = t.find('}', i);
      pattern += ".+";
    } else if (std::string("\\^$.|?*+()[]").find(t[i]) != std::string::npos) {
      pattern += std::string("\\") + t[i];
    } else {
      pattern += t[i];
    }
  }
  return std::regex(pattern);
}

bool made_from(const std::string& instruction, const std::vector<std::string>& templates) {
  for (const auto& t : templates) {
    std::string capitalised = t;
    if (!capitalised.empty() && capitalised[0] >= 'a' && capitalised[0] <= 'z') capitalised[0] = char(capitalised[0] - 32);
    if (std::regex_match(instruction, template_regex(capitalised)) ||
        (t[0] == '{' && std::regex_match(instruction, template_regex(t))))
      return true;
  }
  return false;
}

}  // namespace

TEST_CASE("look-alike bottles: only expressions that single one out are produced", "[language]") {
  using S = assets::SizeClass;
  const assets::Asset green_cap = make("bottle", "yellow", "plastic", S::medium, {{"cap", "green"}});
  const assets::Asset red_cap = make("bottle", "yellow", "plastic", S::medium, {{"cap", "red"}});
  const assets::Asset pills = make("pill_bottle", "white", "plastic", S::small, {{"lid", "white"}});
  const std::vector<lang::SceneObject> scene{on(green_cap), on(red_cap), on(pills)};
  const auto expressions = texts(lang::referring_expressions(library(), scene, 0));
  CAPTURE(expressions);
  for (const char* ambiguous : {"the yellow bottle", "the bottle", "the plastic bottle", "the water bottle",
                                "the medium yellow bottle", "the yellow plastic bottle"})
    CHECK(std::find(expressions.begin(), expressions.end(), ambiguous) == expressions.end());
  CHECK(std::find(expressions.begin(), expressions.end(), "the bottle with the green cap") != expressions.end());
  for (const auto& e : expressions) CHECK(count_matches(e, scene) == 1);
  // "bottle" also names the pill bottle ("pill bottle" ends with it): the pill bottle is "the
  // pill bottle", never "the bottle" (the yellow ones are bottles too).
  const auto pill_expressions = texts(lang::referring_expressions(library(), scene, 2));
  CHECK(std::find(pill_expressions.begin(), pill_expressions.end(), "the pill bottle") != pill_expressions.end());
  CHECK(std::find(pill_expressions.begin(), pill_expressions.end(), "the bottle") == pill_expressions.end());
  CHECK(std::find(pill_expressions.begin(), pill_expressions.end(), "the white pill bottle") != pill_expressions.end());
  // A scene that recolours the second bottle red makes "the yellow bottle" unique, and "the red
  // bottle" names the recoloured one.
  std::vector<lang::SceneObject> recoloured{on(green_cap), on(red_cap, "red"), on(pills)};
  const auto yellow = texts(lang::referring_expressions(library(), recoloured, 0));
  CHECK(std::find(yellow.begin(), yellow.end(), "the yellow bottle") != yellow.end());
  const auto red = texts(lang::referring_expressions(library(), recoloured, 1));
  CHECK(std::find(red.begin(), red.end(), "the red bottle") != red.end());
  // Two identical bottles cannot be told apart: no expression, and no instruction.
  const std::vector<lang::SceneObject> twins{on(green_cap), on(green_cap)};
  CHECK(lang::referring_expressions(library(), twins, 0).empty());
  CHECK_FALSE(lang::make_instructions(library(), twins, {"ALN", {0}, ""}, true, 1).has_value());
}

TEST_CASE("random tables of catalogue assets: every expression names exactly its object", "[language]") {
  static const std::vector<assets::Asset> objects = assets::object_catalog();
  static const std::vector<assets::Asset> obstacles = assets::obstacle_catalog();
  std::mt19937_64 engine(2026);
  long checked = 0, described = 0, total = 0;
  for (int table = 0; table < 100; ++table) {
    std::vector<lang::SceneObject> scene;
    const int n_objects = 2 + static_cast<int>(engine() % 6), n_obstacles = static_cast<int>(engine() % 8);
    for (int i = 0; i < n_objects; ++i) {
      // A quarter of the objects recoloured by the scene, as randomized scenes do.
      static const std::vector<std::string> colors{"red", "blue", "green", "yellow", "white"};
      const auto& asset = objects[engine() % objects.size()];
      scene.push_back(on(asset, engine() % 4 == 0 ? colors[engine() % colors.size()] : ""));
    };
    for (int i = 0; i < n_obstacles; ++i) scene.push_back(on(obstacles[engine() % obstacles.size()]));
    for (int k = 0; k < static_cast<int>(scene.size()); ++k) {
      ++total;
      bool any = false;
      for (const bool seen : {true, false}) {
        for (const auto& d : lang::referring_expressions(library(), scene, k, seen)) {
          const std::string e = d.text();
          INFO("table " << table << " object " << k << " (" << scene[static_cast<std::size_t>(k)].asset->id << "): " << e);
          REQUIRE(count_matches(e, scene) == 1);
          REQUIRE(truthful_phrasings(*scene[static_cast<std::size_t>(k)].asset, scene[static_cast<std::size_t>(k)].color_name).count(e) == 1);
          ++checked;
          any = true;
        }
      }
      described += any ? 1 : 0;
    }
  }
  CHECK(checked > 3000);
  // Only exact duplicates of an asset on one table (same id drawn twice) can lack an expression.
  CHECK(described >= total * 9 / 10);
}

TEST_CASE("instructions: hand-computed canonical sentences for the four tasks", "[language]") {
  using S = assets::SizeClass;
  const assets::Asset bottle = make("bottle", "blue", "glass", S::medium);
  const assets::Asset basket = make("basket", "brown", "wood", S::large);
  const assets::Asset cup = make("cup", "red", "plastic", S::small);
  const assets::Asset mug = make("mug", "white", "ceramic", S::medium);
  const assets::Asset bowl_l = make("bowl", "white", "ceramic", S::large);
  const assets::Asset bowl_m = make("bowl", "white", "ceramic", S::medium);
  const assets::Asset bowl_s = make("bowl", "white", "ceramic", S::small);
  const std::vector<lang::SceneObject> scene{on(bottle), on(basket), on(cup), on(mug), on(bowl_l), on(bowl_m), on(bowl_s)};
  const auto canonical = [&](const lang::TaskSlots& slots) {
    const auto made = lang::make_instructions(library(), scene, slots, false, 7);
    REQUIRE(made.has_value());
    CHECK(made->seen.empty());
    CHECK(made->unseen.empty());
    return made->canonical;
  };
  CHECK(canonical({"COLL", {0, 1}, ""}) == "Put the bottle into the basket.");
  CHECK(canonical({"ALN", {0}, ""}) == "Place the bottle at the marker.");
  CHECK(canonical({"STK", {4, 5, 6}, ""}) == "Stack the large bowl, the medium bowl and the small bowl, largest at the bottom.");
  CHECK(canonical({"ARR", {2, 0, 3}, "between"}) == "Place the cup between the bottle and the mug.");
  CHECK(canonical({"ARR", {2, 0}, "left_of"}) == "Place the cup to the left of the bottle.");
  CHECK_THROWS_WITH(canonical({"ARR", {2, 0}, "between"}), Contains("ARR between needs 3 objects, got 2"));
  CHECK_THROWS_WITH(canonical({"COLL", {0, 9}, ""}), Contains("object index 9 is outside the scene's 7 objects"));
  CHECK_THROWS_WITH(canonical({"SORT", {0}, ""}), Contains("unknown task 'SORT'"));
}

TEST_CASE("randomized instructions: about 40, distinct, filled, seen and unseen wording apart, deterministic", "[language]") {
  using S = assets::SizeClass;
  const assets::Asset bottle = make("bottle", "blue", "glass", S::medium, {{"cap", "black"}});
  const assets::Asset other_bottle = make("bottle", "green", "plastic", S::large);
  const assets::Asset basket = make("basket", "brown", "wood", S::large);
  const assets::Asset cup = make("cup", "red", "plastic", S::small);
  const assets::Asset mug = make("mug", "white", "ceramic", S::medium);
  const std::vector<lang::SceneObject> scene{on(bottle), on(other_bottle), on(basket), on(cup), on(mug)};
  for (const lang::TaskSlots& slots : {lang::TaskSlots{"COLL", {0, 2}, ""}, lang::TaskSlots{"ALN", {0}, ""},
                                       lang::TaskSlots{"STK", {2, 4, 3}, ""}, lang::TaskSlots{"ARR", {0, 3, 4}, "in_a_row"},
                                       lang::TaskSlots{"ARR", {3, 0}, "behind"}}) {
    CAPTURE(slots.task, slots.relation);
    const auto made = lang::make_instructions(library(), scene, slots, true, 42);
    REQUIRE(made.has_value());
    CHECK(made->seen.size() == 32);
    CHECK(made->unseen.size() == 8);
    std::set<std::string> all(made->seen.begin(), made->seen.end());
    for (const auto& u : made->unseen) CHECK(all.insert(u).second);  // distinct, and disjoint
    const auto& templates = library().templates.at(slots.task);
    for (const auto& s : made->seen) {
      CHECK(s.find('{') == std::string::npos);
      CHECK(made_from(s, templates.seen));
      // Never "the bottle" (or "the water bottle") alone: two bottles are on the table.
      CHECK_FALSE(std::regex_search(s, std::regex("the (water |drink )?bottle(?! with)[ .,?]")));
    }
    for (const auto& u : made->unseen) {
      CHECK(u.find('{') == std::string::npos);
      CHECK(made_from(u, templates.unseen));
    }
    const auto again = lang::make_instructions(library(), scene, slots, true, 42);
    CHECK(again->seen == made->seen);
    CHECK(again->unseen == made->unseen);
    CHECK(lang::make_instructions(library(), scene, slots, true, 43)->seen != made->seen);
  }
}

TEST_CASE("the shipped data: >= 30 templates per task, nouns for every catalogue category", "[language]") {
  for (const char* task : {"COLL", "ALN", "STK", "ARR", "OVR"}) {
    const auto& t = library().templates.at(task);
    CAPTURE(task);
    CHECK(t.seen.size() + t.unseen.size() >= 30);
    CHECK(t.seen.size() >= 3 * t.unseen.size());  // about 4:1
  }
  std::set<std::string> categories;
  for (const auto& a : assets::object_catalog()) categories.insert(a.category);
  for (const auto& a : assets::obstacle_catalog()) categories.insert(a.category);
  for (const auto& c : categories) {
    CAPTURE(c);
    CHECK(library().nouns.count(c) == 1);
  }
}

TEST_CASE("malformed language files are refused naming the file and the entry", "[language][input]") {
  const auto dir = manisoft::test::scratch_dir("manisoft_language_files");
  const std::string good_objects = R"({"categories": {"bottle": {"seen": ["bottle"], "unseen": []}}})";
  const auto tasks_with = [](const std::string& coll, const std::string& aln) {
    const std::string rel = R"("relations": {"left_of": {"seen": ["left of {B}"], "unseen": ["just left of {B}"]},
      "right_of": {"seen": ["right of {B}"], "unseen": ["x {B}"]}, "in_front_of": {"seen": ["a {B}"], "unseen": ["b {B}"]},
      "behind": {"seen": ["c {B}"], "unseen": ["d {B}"]}, "next_to": {"seen": ["e {B}"], "unseen": ["f {B}"]},
      "between": {"seen": ["g {B} {C}"], "unseen": ["h {B} {C}"]}, "in_a_row": {"seen": ["i {B} {C}"], "unseen": ["j {B} {C}"]}})";
    return "{\"COLL\": " + coll + ", \"ALN\": " + aln +
           R"(, "STK": {"seen": ["Stack {ITEMS}."], "unseen": ["Pile {ITEMS}."]},
               "ARR": {"seen": ["Put {A} {RELATION}."], "unseen": ["Move {A} {RELATION}."]},
               "OVR": {"seen": ["Carry {A} over {B}."], "unseen": ["Lift {A} over {B}."]}, )" + rel + "}";
  };
  const std::string coll = R"({"seen": ["Put {A} in {B}."], "unseen": ["Drop {A} in {B}."]})";
  const std::string aln = R"({"seen": ["Align {A}."], "unseen": ["Match {A}."]})";
  const auto load_with = [&](const std::string& tasks, const std::string& objects) {
    std::ofstream(dir / "tasks.json") << tasks;
    std::ofstream(dir / "objects.json") << objects;
    return lang::Library::load(dir);
  };
  CHECK_NOTHROW(load_with(tasks_with(coll, aln), good_objects));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, aln) + "}", good_objects), Contains("tasks.json: malformed JSON at byte"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, R"({"seen": ["Align {A} with {B}."], "unseen": ["x {A}"]})"), good_objects),
                    Contains("tasks.json: entry 'ALN'.seen[0] 'Align {A} with {B}.' uses {B}, which ALN does not fill"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, R"({"seen": ["Align {A."], "unseen": ["x {A}"]})"), good_objects),
                    Contains("entry 'ALN'.seen[0] 'Align {A.': '{' without '}'"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, R"({"seen": ["Align {A}."], "unseen": ["Align {A}."]})"), good_objects),
                    Contains("entry 'ALN': 'Align {A}.' is both seen and unseen"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, R"({"seen": ["Align {A}."]})"), good_objects),
                    Contains("entry 'ALN' must be an object with 'seen' and 'unseen' lists"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, R"({"seen": [3], "unseen": ["x {A}"]})"), good_objects),
                    Contains("entry 'ALN'.seen[0] must be a non-empty string"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, aln), R"({"categories": {"bottle": {"seen": ["{A} bottle"], "unseen": []}}})"),
                    Contains("objects.json: entry 'categories.bottle'.seen[0] '{A} bottle' uses {A}"));
  CHECK_THROWS_WITH(load_with(tasks_with(coll, aln), R"({"nouns": {}})"), Contains("objects.json: entry 'categories' must be"));
  std::filesystem::remove(dir / "tasks.json");
  CHECK_THROWS_WITH(lang::Library::load(dir), Contains("tasks.json: cannot open the language file"));
}

TEST_CASE("the word helpers: whole words, case-insensitive, placeholders stand for words", "[language]") {
  using manisoft::test::says;
  CHECK(says("drink carton", "carton"));
  CHECK(says("Picture Frame", "frame"));
  CHECK(says("Put the award cup into the basket.", "award"));
  CHECK_FALSE(says("candle holder", "can"));  // a word, not a prefix of one
  CHECK_FALSE(says("soda can", "drink can"));
  CHECK(says("midway between {B} and {C}", "between {B} and {C}"));
  CHECK_FALSE(says("midway between {B} and {C}", "halfway between {B} and {C}"));
  CHECK(says("Put the cup halfway between the red bottle and the mug.", "halfway between {B} and {C}"));
  CHECK_FALSE(says("Put the cup midway between the red bottle and the mug.", "halfway between {B} and {C}"));
  CHECK(says("Let the cup rest close to the shoe.", "close to {B}"));
  CHECK_FALSE(says("Put the cup in front of the shoe, closer to the camera.", "close to {B}"));
}

TEST_CASE("unseen wording is never a word of seen wording: every category's nouns, every relation's phrases", "[language]") {
  // An unseen noun or relation phrase inside a seen noun, phrase or template would reach training
  // instructions: the unseen-instruction results would not measure wording never trained on.
  const lang::Library& l = library();
  CHECK(manisoft::test::wording_leaks(l) == std::vector<std::string>{});
  const std::set<std::string> own_words = manisoft::test::unseen_only_words(l);
  for (const auto& [kind, split] : l.relations) {
    // each unseen relation phrase has a word that no seen wording has ("beyond", "halfway"), so a
    // seen instruction can be checked for it word by word
    for (const auto& u : split.unseen) {
      bool own_word = false;
      for (const auto& w : manisoft::test::words_of(u)) own_word = own_word || own_words.count(w) > 0;
      CAPTURE(kind, u);
      CHECK(own_word);
    }
  }
  // The check finds a leak: a box drink whose unseen noun "carton" is a word of its seen "drink
  // carton", and a jar whose unseen "pot" is a word of another category's seen "flower pot".
  lang::Library leaky = l;
  leaky.nouns["box_drink"] = lang::Split{{"box drink", "drink carton"}, {"carton"}};
  leaky.nouns["jar"] = lang::Split{{"jar"}, {"pot"}};
  const std::vector<std::string> leaks = manisoft::test::wording_leaks(leaky);
  CAPTURE(leaks);
  CHECK(std::find(leaks.begin(), leaks.end(), "box_drink: unseen 'carton' is in seen 'drink carton'") != leaks.end());
  CHECK(std::find(leaks.begin(), leaks.end(), "jar: unseen 'pot' is in seen 'flower pot'") != leaks.end());
  CHECK(leaks.size() == 4);  // and "pot" in "plant pot" and "watering pot"
}
