// The expert's configuration as JSON (through nlohmann-json): one object per group of
// ExpertConfig, keyed by the names of for_each_field() (expert_config.hpp), e.g.
//   {"carry": {"peak_speed": 1.2}, "checks": {"objects": false}}
// Reading starts from the defaults and sets only the settings the file names. It refuses, naming
// the file and the key: a syntax error (with its byte offset), a key given twice, a group or a
// setting that ExpertConfig does not have, a value of the wrong type (a number for a distance or
// a speed, an integer for a count, true / false for a flag) and a value out of its range
// (ExpertConfig::validate()). Writing gives every setting, so a written file reads back to the
// same configuration.
#pragma once

#include <nlohmann/json.hpp>

#include <climits>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "manisoft/core/error.hpp"
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/task/expert_config.hpp"

namespace manisoft::task {

/// Every setting of `c`, grouped.
inline nlohmann::json to_json(const ExpertConfig& c) {
  nlohmann::json j = nlohmann::json::object();
  for_each_field(c, [&](std::string_view group, std::string_view name, const auto& value, const ExpertLimit&) {
    j[std::string(group)][std::string(name)] = value;
  });
  return j;
}

namespace detail {

/// Sets the setting group.name of `c` from `value`; false when ExpertConfig has no such setting.
/// `where` names the file in errors.
inline bool set_expert_field(ExpertConfig& c, const std::string& group, const std::string& name, const nlohmann::json& value,
                             const std::string& where) {
  bool found = false;
  for_each_field(c, [&](std::string_view g, std::string_view n, auto& field, const ExpertLimit&) {
    if (found || g != group || n != name) return;
    found = true;
    using T = std::decay_t<decltype(field)>;
    const bool fits = std::is_same_v<T, bool> ? value.is_boolean() : std::is_same_v<T, int> ? value.is_number_integer() : value.is_number();
    if (!fits) {
      const char* wanted = std::is_same_v<T, bool> ? "true or false" : std::is_same_v<T, int> ? "an integer" : "a number";
      manisoft::detail::fail(where, ": ", group, '.', name, " = ", value.dump(), " is invalid: it must be ", wanted);
    }
    if constexpr (std::is_same_v<T, int>) {
      const bool fits_int = value.is_number_unsigned() ? value.get<unsigned long long>() <= INT_MAX : value.get<long long>() >= INT_MIN;
      if (!fits_int) manisoft::detail::fail(where, ": ", group, '.', name, " = ", value.dump(), " is out of range: it must fit an int");
    }
    field = value.get<T>();
  });
  return found;
}

}  // namespace detail

/// The configuration a JSON object gives: the defaults, with the settings it names set; `where`
/// names the source in errors. Refuses an unknown group or setting, a wrong type and a value out
/// of range.
inline ExpertConfig expert_config_from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) manisoft::detail::fail(where, ": the expert configuration must be a JSON object of groups, not ", j.type_name());
  ExpertConfig c;
  for (const auto& [group, settings] : j.items()) {
    if (!settings.is_object()) manisoft::detail::fail(where, ": ", group, " must be an object of settings, not ", settings.type_name());
    for (const auto& [name, value] : settings.items()) {
      if (!detail::set_expert_field(c, group, name, value, where))
        manisoft::detail::fail(where, ": ", group, '.', name, " is not a setting of the expert (the groups and their settings: docs/tasks.md)");
    }
  }
  try {
    c.validate();
  } catch (const InvalidInput& e) {
    manisoft::detail::fail(where, ": ", e.what());
  }
  return c;
}

/// Reads an expert configuration file (expert_config_from_json).
inline ExpertConfig load_expert_config(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) manisoft::detail::fail("cannot read the expert configuration file '", path, "'");
  std::ostringstream text;
  text << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str(), scene::json_detail::DuplicateKeyCheck(path));
  } catch (const nlohmann::json::parse_error& e) {
    manisoft::detail::fail(path, ": not valid JSON at byte ", e.byte, ": ", e.what());
  } catch (const nlohmann::json::exception& e) {  // a number beyond the range of a double (1e400)
    manisoft::detail::fail(path, ": cannot be read: ", e.what());
  }
  return expert_config_from_json(j, path);
}

}  // namespace manisoft::task
