// The language library of the benchmark's instructions (the ManiSoft benchmark paper, section 3.5:
// about 40 instructions per scene; RoboTwin 2.0's layout of task templates with placeholders and
// per-object descriptions): task templates, ARR relation phrases and nouns per asset category,
// each split into `seen` (training) and `unseen` (evaluation only) lists, read from JSON files a
// user can extend (examples/data/language/tasks.json and objects.json, installed to
// share/manisoft/language/). Malformed files are refused naming the file, the entry and, for
// JSON syntax errors, the byte offset nlohmann reports.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"

namespace manisoft::language {

/// Phrases usable in training data (`seen`) and kept for evaluation (`unseen`).
struct Split {
  std::vector<std::string> seen;
  std::vector<std::string> unseen;
  const std::vector<std::string>& of(bool seen_phrases) const { return seen_phrases ? seen : unseen; }
};

/// The tasks and the placeholders their templates may use.
inline const std::map<std::string, std::set<std::string>>& task_placeholders() {
  static const std::map<std::string, std::set<std::string>> p{
      {"COLL", {"A", "B"}}, {"ALN", {"A"}}, {"STK", {"ITEMS"}}, {"ARR", {"A", "RELATION"}}, {"OVR", {"A", "B"}}};
  return p;
}

/// ARR relation kinds (geometry/spatial_relation.hpp's RelationKind names) and their placeholders.
inline const std::map<std::string, std::set<std::string>>& relation_placeholders() {
  static const std::map<std::string, std::set<std::string>> p{
      {"left_of", {"B"}}, {"right_of", {"B"}}, {"in_front_of", {"B"}}, {"behind", {"B"}},
      {"next_to", {"B"}}, {"between", {"B", "C"}}, {"in_a_row", {"B", "C"}}};
  return p;
}

/// The placeholders ("{A}" -> "A") of a template, in order of appearance; throws on a brace
/// that does not close.
inline std::vector<std::string> placeholders_of(const std::string& text) {
  std::vector<std::string> names;
  for (std::size_t at = text.find('{'); at != std::string::npos; at = text.find('{', at + 1)) {
    const std::size_t end = text.find('}', at);
    if (end == std::string::npos) ::manisoft::detail::fail("'{' without '}' at character ", at);
    names.push_back(text.substr(at + 1, end - at - 1));
  }
  return names;
}

struct Library {
  std::map<std::string, Split> templates;  ///< task -> templates
  std::map<std::string, Split> relations;  ///< ARR relation kind -> phrases
  std::map<std::string, Split> nouns;      ///< asset category -> nouns

  /// The nouns of a category; a category the files do not list is named by its id with spaces
  /// ("tape_dispenser" -> "tape dispenser"), in both splits.
  Split nouns_of(const std::string& category) const {
    const auto it = nouns.find(category);
    if (it != nouns.end()) return it->second;
    std::string noun = category;
    for (char& c : noun)
      if (c == '_') c = ' ';
    return Split{{noun}, {noun}};
  }

  /// The library shipped with ManiSoft (the CMake target manisoft::language defines
  /// MANISOFT_LANGUAGE_DIR: the source tree's examples/data/language, or the installed copy).
  static Library load_default() {
#ifdef MANISOFT_LANGUAGE_DIR
    return load(MANISOFT_LANGUAGE_DIR);
#else
    ::manisoft::detail::fail("no default language folder: link manisoft::language or call Library::load(dir)");
#endif
  }

  /// Reads DIR/tasks.json and DIR/objects.json.
  static Library load(const std::filesystem::path& dir) {
    Library library;
    const nlohmann::json tasks = read_json(dir / "tasks.json");
    const nlohmann::json objects = read_json(dir / "objects.json");
    const std::string tasks_file = (dir / "tasks.json").string(), objects_file = (dir / "objects.json").string();
    for (const auto& [task, allowed] : task_placeholders())
      library.templates[task] = read_split(tasks_file, tasks, task, allowed, true);
    if (!tasks.contains("relations") || !tasks["relations"].is_object())
      ::manisoft::detail::fail(tasks_file, ": entry 'relations' must be an object of relation kinds");
    for (const auto& [kind, allowed] : relation_placeholders())
      library.relations[kind] = read_split(tasks_file, tasks["relations"], kind, allowed, true, "relations.");
    if (!objects.contains("categories") || !objects["categories"].is_object())
      ::manisoft::detail::fail(objects_file, ": entry 'categories' must be an object of asset categories");
    for (const auto& [category, entry] : objects["categories"].items())
      library.nouns[category] = read_split(objects_file, objects["categories"], category, {}, false, "categories.");
    return library;
  }

 private:
  static nlohmann::json read_json(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) ::manisoft::detail::fail(path.string(), ": cannot open the language file");
    try {
      return nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
      ::manisoft::detail::fail(path.string(), ": malformed JSON at byte ", e.byte, ": ", e.what());
    }
  }

  static Split read_split(const std::string& file, const nlohmann::json& parent, const std::string& key,
                          const std::set<std::string>& allowed, bool need_unseen, const std::string& prefix = "") {
    const std::string where = file + ": entry '" + prefix + key + "'";
    if (!parent.contains(key)) ::manisoft::detail::fail(where, " is missing");
    const nlohmann::json& entry = parent[key];
    if (!entry.is_object() || !entry.contains("seen") || !entry.contains("unseen"))
      ::manisoft::detail::fail(where, " must be an object with 'seen' and 'unseen' lists");
    Split split;
    for (const char* part : {"seen", "unseen"}) {
      const nlohmann::json& list = entry[part];
      if (!list.is_array()) ::manisoft::detail::fail(where, ".", part, " must be a list of strings");
      auto& out = std::string(part) == "seen" ? split.seen : split.unseen;
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (!list[i].is_string() || list[i].get<std::string>().empty())
          ::manisoft::detail::fail(where, ".", part, "[", i, "] must be a non-empty string");
        const std::string text = list[i].get<std::string>();
        std::vector<std::string> names;
        try {
          names = placeholders_of(text);
        } catch (const InvalidInput& e) {
          ::manisoft::detail::fail(where, ".", part, "[", i, "] '", text, "': ", e.what());
        }
        for (const auto& name : names)
          if (!allowed.count(name))
            ::manisoft::detail::fail(where, ".", part, "[", i, "] '", text, "' uses {", name, "}, which ", prefix + key,
                                     allowed.empty() ? " does not allow (nouns take no placeholders)" : " does not fill");
        out.push_back(text);
      }
    }
    if (split.seen.empty() || (need_unseen && split.unseen.empty()))
      ::manisoft::detail::fail(where, " needs at least one 'seen'", need_unseen ? " and one 'unseen'" : "", " phrase");
    for (const auto& s : split.seen)
      for (const auto& u : split.unseen)
        if (s == u) ::manisoft::detail::fail(where, ": '", s, "' is both seen and unseen");
    return split;
  }
};

}  // namespace manisoft::language
