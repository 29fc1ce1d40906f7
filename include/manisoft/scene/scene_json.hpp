// The scene JSON format (a SceneSpec round-trips exactly through JSON; a malformed or
// inconsistent file gets a clear error), through nlohmann-json (optional component
// manisoft::scene). Doubles are written in nlohmann's shortest round-trip form, so a written file
// parses back bit-identical; rotations are stored as 3 x 3 matrices (rows) for that reason.
// Reading refuses, naming the file and the field ("scene.json: objects[2].pose.position[1]"): a
// syntax error (with the byte offset), a number beyond the range of a double, a key given twice in
// one object, a field the format does not have (a misspelled name), a missing field, a value of
// the wrong type, a non-finite number, an unknown enum name, and (load_scene) an inconsistent
// scene (require_consistent: unknown asset id, index out of range, a rotation that is not one,
// another arm mount). Writing goes through a temporary file renamed into place: never a
// half-written file. The schema, with an example, is in docs/scenes.md.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/scene/scene_validation.hpp"

namespace manisoft::scene {

inline constexpr const char* scene_format = "manisoft.scene/1";

namespace json_detail {

using Json = nlohmann::json;

inline Json number(double v, const char* what) {
  if (!std::isfinite(v)) manisoft::detail::fail("scene JSON: ", what, " = ", v, " is not finite and cannot be written");
  return Json(v);
}
inline Json vec(const Eigen::Vector3d& v, const char* what) { return Json::array({number(v.x(), what), number(v.y(), what), number(v.z(), what)}); }
inline Json pose(const math::Pose<double>& p) {
  Json r = Json::array();
  for (int i = 0; i < 3; ++i) r.push_back(vec(p.rotation.row(i).transpose(), "rotation"));
  return Json{{"position", vec(p.translation, "position")}, {"rotation", r}};
}
inline const char* texture_name(render::TextureKind t) {
  switch (t) {
    case render::TextureKind::none: return "none";
    case render::TextureKind::wood: return "wood";
    case render::TextureKind::marble: return "marble";
    case render::TextureKind::fabric: return "fabric";
    case render::TextureKind::checker: return "checker";
    case render::TextureKind::noise: return "noise";
  }
  return "none";
}
inline Json placed(const PlacedAsset& a) {
  Json ap{{"override_color", a.appearance.override_color},
          {"color", vec(a.appearance.color, "appearance.color")},
          {"color_name", a.appearance.color_name},
          {"texture", texture_name(a.appearance.texture)}};
  return Json{{"asset_id", a.asset_id}, {"pose", pose(a.pose)}, {"appearance", ap}};
}

/// Reads fields, naming the file and the field path in every error.
struct Reader {
  std::string where;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const { manisoft::detail::fail(where, ": ", path, ": ", what); }
  const Json& at(const Json& j, const std::string& key, const std::string& path) const {
    if (!j.is_object()) fail(path, "expected an object");
    const auto it = j.find(key);
    if (it == j.end()) fail(path.empty() ? key : path + "." + key, "missing field");
    return *it;
  }
  static std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
  /// Refuses a field of `j` that is not in `known` (a misspelled name would otherwise be ignored).
  void only(const Json& j, const std::string& path, std::initializer_list<const char*> known) const {
    if (!j.is_object()) fail(path.empty() ? "(top level)" : path, "expected an object");
    for (const auto& item : j.items()) {
      if (std::find_if(known.begin(), known.end(), [&](const char* k) { return item.key() == k; }) != known.end()) continue;
      std::string names;
      for (const char* k : known) names += names.empty() ? k : std::string(", ") + k;
      fail(join(path, item.key()), "unknown field (the fields here: " + names + ")");
    }
  }
  double num(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_number()) fail(join(path, key), "expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(join(path, key), "is not finite");
    return d;
  }
  bool boolean(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_boolean()) fail(join(path, key), "expected true or false");
    return v.get<bool>();
  }
  std::uint64_t u64(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0)) fail(join(path, key), "expected a non-negative integer");
    return v.get<std::uint64_t>();
  }
  int integer(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_number_integer()) fail(join(path, key), "expected an integer");
    const auto x = v.get<std::int64_t>();
    if (x < -1000000 || x > 1000000) fail(join(path, key), "= " + std::to_string(x) + " is out of range");
    return static_cast<int>(x);
  }
  std::string str(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_string()) fail(join(path, key), "expected a string");
    return v.get<std::string>();
  }
  const Json& array(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    if (!v.is_array()) fail(join(path, key), "expected an array");
    return v;
  }
  Eigen::Vector3d vec3(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = array(j, key, path);
    const std::string p = join(path, key);
    if (v.size() != 3) fail(p, "expected 3 numbers, got " + std::to_string(v.size()));
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i) {
      const Json& e = v[static_cast<std::size_t>(i)];
      if (!e.is_number()) fail(p + "[" + std::to_string(i) + "]", "expected a number");
      out[i] = e.get<double>();
      if (!std::isfinite(out[i])) fail(p + "[" + std::to_string(i) + "]", "is not finite");
    }
    return out;
  }
  math::Pose<double> pose(const Json& j, const std::string& key, const std::string& path) const {
    const Json& v = at(j, key, path);
    const std::string p = join(path, key);
    only(v, p, {"position", "rotation"});
    math::Pose<double> out;
    out.translation = vec3(v, "position", p);
    const Json& r = array(v, "rotation", p);
    if (r.size() != 3) fail(p + ".rotation", "expected 3 rows");
    for (int i = 0; i < 3; ++i) {
      const Json row{{"row", r[static_cast<std::size_t>(i)]}};
      out.rotation.row(i) = vec3(row, "row", p + ".rotation[" + std::to_string(i) + "]").transpose();
    }
    return out;
  }
  template <typename Enum, std::size_t N>
  Enum name_of(const Json& j, const std::string& key, const std::string& path, const std::array<std::pair<const char*, Enum>, N>& names) const {
    const std::string s = str(j, key, path);
    std::string known;
    for (const auto& [n, e] : names) {
      if (s == n) return e;
      known += known.empty() ? n : std::string(", ") + n;
    }
    fail(join(path, key), "unknown value '" + s + "' (one of: " + known + ")");
  }
  std::vector<std::string> strings(const Json& j, const std::string& key, const std::string& path) const {
    std::vector<std::string> out;
    const Json& v = array(j, key, path);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string()) fail(join(path, key) + "[" + std::to_string(i) + "]", "expected a string");
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }
  std::vector<int> ints(const Json& j, const std::string& key, const std::string& path) const {
    std::vector<int> out;
    const Json& v = array(j, key, path);
    for (std::size_t i = 0; i < v.size(); ++i) {
      const Json w{{"v", v[i]}};
      out.push_back(integer(w, "v", join(path, key) + "[" + std::to_string(i) + "]"));
    }
    return out;
  }
};

/// Refuses a key given twice in one object (nlohmann keeps the last value silently): a parser
/// callback that keeps the path of the value being read ("table", "objects[2].pose") and the keys
/// seen in each open object.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(std::string where) : where_(std::move(where)) {}
  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, Json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        count_element();
        open_.push_back(Frame{event == Event::array_start, -1, {}, {}});
        break;
      case Event::object_end:
      case Event::array_end: open_.pop_back(); break;
      case Event::key: {
        Frame& f = open_.back();
        f.key = parsed.get<std::string>();
        if (std::find(f.keys.begin(), f.keys.end(), f.key) != f.keys.end())
          manisoft::detail::fail(where_, ": ", path(), ": duplicate key (an object names each field once)");
        f.keys.push_back(f.key);
        break;
      }
      case Event::value: count_element(); break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    long index;  // arrays: the element being read
    std::vector<std::string> keys;
    std::string key;  // objects: the key being read
  };
  void count_element() {
    if (!open_.empty() && open_.back().array) ++open_.back().index;
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : open_) p += f.array ? "[" + std::to_string(f.index) + "]" : (p.empty() ? "" : ".") + f.key;
    return p;
  }
  std::string where_;
  std::vector<Frame> open_;
};

inline const std::array<std::pair<const char*, render::TextureKind>, 6> texture_names{{{"none", render::TextureKind::none},
                                                                                       {"wood", render::TextureKind::wood},
                                                                                       {"marble", render::TextureKind::marble},
                                                                                       {"fabric", render::TextureKind::fabric},
                                                                                       {"checker", render::TextureKind::checker},
                                                                                       {"noise", render::TextureKind::noise}}};
inline const std::array<std::pair<const char*, Relation::Kind>, 7> relation_names{{{"left_of", Relation::Kind::left_of},
                                                                                   {"right_of", Relation::Kind::right_of},
                                                                                   {"in_front_of", Relation::Kind::in_front_of},
                                                                                   {"behind", Relation::Kind::behind},
                                                                                   {"next_to", Relation::Kind::next_to},
                                                                                   {"between", Relation::Kind::between},
                                                                                   {"in_a_row", Relation::Kind::in_a_row}}};

}  // namespace json_detail

/// The JSON value of a scene (every field; the goal holds only the scene's task's part).
inline nlohmann::json to_json(const SceneSpec& s) {
  using json_detail::Json;
  using json_detail::number;
  using json_detail::vec;
  Json j;
  j["format"] = scene_format;
  j["task"] = std::string(to_string(s.task));
  j["setting"] = std::string(to_string(s.setting));
  j["split"] = std::string(to_string(s.split));
  j["index"] = s.index;
  j["seed"] = s.seed;
  j["table"] = Json{{"top_center", vec(s.table.top_center, "table.top_center")},
                    {"half_x", number(s.table.half_x, "table.half_x")},
                    {"half_y", number(s.table.half_y, "table.half_y")},
                    {"thickness", number(s.table.thickness, "table.thickness")},
                    {"friction", number(s.table.friction, "table.friction")},
                    {"rolling_resistance", number(s.table.rolling_resistance, "table.rolling_resistance")},
                    {"texture", json_detail::texture_name(s.table.texture)},
                    {"color", vec(s.table.color, "table.color")},
                    {"secondary_color", vec(s.table.secondary_color, "table.secondary_color")},
                    {"texture_scale", number(s.table.texture_scale, "table.texture_scale")}};
  j["arm_mount"] = Json{{"base_position", vec(s.arm_mount.base_position, "arm_mount")}, {"pitch", number(s.arm_mount.pitch, "arm_mount.pitch")}};
  j["objects"] = Json::array();
  for (const auto& o : s.objects) j["objects"].push_back(json_detail::placed(o));
  j["obstacles"] = Json::array();
  for (const auto& o : s.obstacles) j["obstacles"].push_back(json_detail::placed(o));
  j["lighting"] = Json{{"intensity", number(s.lighting.intensity, "lighting.intensity")},
                       {"color", vec(s.lighting.color, "lighting.color")},
                       {"direction", vec(s.lighting.direction, "lighting.direction")},
                       {"ambient_intensity", number(s.lighting.ambient_intensity, "lighting.ambient_intensity")}};
  j["cameras"] = Json::array();
  for (const auto& c : s.cameras)
    j["cameras"].push_back(Json{{"position", vec(c.position, "camera.position")},
                                {"look_at", vec(c.look_at, "camera.look_at")},
                                {"up", vec(c.up, "camera.up")},
                                {"fov_y_deg", number(c.fov_y_deg, "camera.fov_y_deg")},
                                {"width", c.width},
                                {"height", c.height}});
  Json g = Json::object();
  switch (s.task) {
    case Task::coll:
      g["object"] = s.goal.object;
      g["container"] = s.goal.container;
      break;
    case Task::aln: {
      g["object"] = s.goal.object;
      g["goal_pose"] = json_detail::pose(s.goal.goal_pose);
      const char* kind = s.goal.symmetry.kind == Symmetry::Kind::none ? "none" : (s.goal.symmetry.kind == Symmetry::Kind::axial ? "axial" : "discrete");
      g["symmetry"] = Json{{"kind", kind}, {"order", s.goal.symmetry.order}};
      break;
    }
    case Task::ovr:
      g["object"] = s.goal.object;
      g["goal_pose"] = json_detail::pose(s.goal.goal_pose);
      g["obstacle"] = s.goal.obstacle;
      break;
    case Task::stk: g["items"] = s.goal.items; break;
    case Task::arr: {
      g["relations"] = Json::array();
      for (const auto& r : s.goal.relations) {
        Json spots = Json::array();
        for (const auto& p : r.spots) spots.push_back(vec(p, "relation spot"));
        g["relations"].push_back(Json{{"kind", std::string(to_string(r.kind))}, {"objects", r.objects}, {"references", r.references}, {"spots", spots}});
      }
      break;
    }
  }
  j["goal"] = g;
  j["instruction"] = s.instruction;
  j["instructions_seen"] = s.instructions_seen;
  j["instructions_unseen"] = s.instructions_unseen;
  j["sampling"] = Json{{"engine_seed", s.sampling.engine_seed}, {"redraws", s.sampling.redraws}, {"rejections", s.sampling.rejections}};
  return j;
}

/// The scene text (2-space indented JSON, newline-terminated).
inline std::string to_json_string(const SceneSpec& s) { return to_json(s).dump(2) + "\n"; }

/// Reads a scene from a JSON value; `where` (a file name) prefixes every error. Checks form and
/// types only: require_consistent (or load_scene) checks it against the assets.
inline SceneSpec from_json(const nlohmann::json& j, const std::string& where) {
  using json_detail::Json;
  const json_detail::Reader rd{where};
  if (!j.is_object()) rd.fail("(top level)", "expected a JSON object");
  rd.only(j, "", {"format", "task", "setting", "split", "index", "seed", "table", "arm_mount", "objects", "obstacles", "lighting", "cameras", "goal",
                  "instruction", "instructions_seen", "instructions_unseen", "sampling"});
  const std::string fmt = rd.str(j, "format", "");
  if (fmt != scene_format) rd.fail("format", "is '" + fmt + "', expected '" + scene_format + "'");
  SceneSpec s;
  s.task = rd.name_of(j, "task", "", std::array<std::pair<const char*, Task>, 5>{{{"COLL", Task::coll}, {"ALN", Task::aln}, {"STK", Task::stk}, {"ARR", Task::arr}, {"OVR", Task::ovr}}});
  s.setting = rd.name_of(j, "setting", "", std::array<std::pair<const char*, Setting>, 2>{{{"clean", Setting::clean}, {"randomized", Setting::randomized}}});
  s.split = rd.name_of(j, "split", "", std::array<std::pair<const char*, Split>, 2>{{{"train", Split::train}, {"eval", Split::eval}}});
  s.index = rd.u64(j, "index", "");
  s.seed = rd.u64(j, "seed", "");
  const Json& t = rd.at(j, "table", "");
  rd.only(t, "table", {"top_center", "half_x", "half_y", "thickness", "friction", "rolling_resistance", "texture", "color", "secondary_color", "texture_scale"});
  s.table.top_center = rd.vec3(t, "top_center", "table");
  s.table.half_x = rd.num(t, "half_x", "table");
  s.table.half_y = rd.num(t, "half_y", "table");
  s.table.thickness = rd.num(t, "thickness", "table");
  s.table.friction = rd.num(t, "friction", "table");
  // Optional (scenes written before rolling resistance existed keep the default).
  if (t.contains("rolling_resistance")) s.table.rolling_resistance = rd.num(t, "rolling_resistance", "table");
  s.table.texture = rd.name_of(t, "texture", "table", json_detail::texture_names);
  s.table.color = rd.vec3(t, "color", "table");
  s.table.secondary_color = rd.vec3(t, "secondary_color", "table");
  s.table.texture_scale = rd.num(t, "texture_scale", "table");
  const Json& m = rd.at(j, "arm_mount", "");
  rd.only(m, "arm_mount", {"base_position", "pitch"});
  s.arm_mount.base_position = rd.vec3(m, "base_position", "arm_mount");
  s.arm_mount.pitch = rd.num(m, "pitch", "arm_mount");
  auto read_list = [&](const char* key, std::vector<PlacedAsset>& out) {
    const Json& v = rd.array(j, key, "");
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string p = std::string(key) + "[" + std::to_string(i) + "]";
      PlacedAsset a;
      rd.only(v[i], p, {"asset_id", "pose", "appearance"});
      a.asset_id = rd.str(v[i], "asset_id", p);
      a.pose = rd.pose(v[i], "pose", p);
      const Json& ap = rd.at(v[i], "appearance", p);
      rd.only(ap, p + ".appearance", {"override_color", "color", "color_name", "texture"});
      a.appearance.override_color = rd.boolean(ap, "override_color", p + ".appearance");
      a.appearance.color = rd.vec3(ap, "color", p + ".appearance");
      a.appearance.color_name = rd.str(ap, "color_name", p + ".appearance");
      a.appearance.texture = rd.name_of(ap, "texture", p + ".appearance", json_detail::texture_names);
      out.push_back(std::move(a));
    }
  };
  read_list("objects", s.objects);
  read_list("obstacles", s.obstacles);
  const Json& l = rd.at(j, "lighting", "");
  rd.only(l, "lighting", {"intensity", "color", "direction", "ambient_intensity"});
  s.lighting.intensity = rd.num(l, "intensity", "lighting");
  s.lighting.color = rd.vec3(l, "color", "lighting");
  s.lighting.direction = rd.vec3(l, "direction", "lighting");
  s.lighting.ambient_intensity = rd.num(l, "ambient_intensity", "lighting");
  if (s.lighting.direction.norm() < 1e-9) rd.fail("lighting.direction", "must not be zero");
  const Json& cams = rd.array(j, "cameras", "");
  if (cams.empty()) rd.fail("cameras", "at least one camera is needed");
  s.cameras.clear();
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const std::string p = "cameras[" + std::to_string(i) + "]";
    render::Camera c;
    rd.only(cams[i], p, {"position", "look_at", "up", "fov_y_deg", "width", "height"});
    c.position = rd.vec3(cams[i], "position", p);
    c.look_at = rd.vec3(cams[i], "look_at", p);
    c.up = rd.vec3(cams[i], "up", p);
    c.fov_y_deg = rd.num(cams[i], "fov_y_deg", p);
    c.width = rd.integer(cams[i], "width", p);
    c.height = rd.integer(cams[i], "height", p);
    if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180)) rd.fail(p + ".fov_y_deg", "must be in (0, 180)");
    if (c.width < 1 || c.height < 1) rd.fail(p + ".width/height", "must be >= 1");
    s.cameras.push_back(c);
  }
  const Json& g = rd.at(j, "goal", "");
  switch (s.task) {
    case Task::coll:
      rd.only(g, "goal", {"object", "container"});
      s.goal.object = rd.integer(g, "object", "goal");
      s.goal.container = rd.integer(g, "container", "goal");
      break;
    case Task::aln: {
      rd.only(g, "goal", {"object", "goal_pose", "symmetry"});
      s.goal.object = rd.integer(g, "object", "goal");
      s.goal.goal_pose = rd.pose(g, "goal_pose", "goal");
      const Json& sy = rd.at(g, "symmetry", "goal");
      rd.only(sy, "goal.symmetry", {"kind", "order"});
      s.goal.symmetry.kind = rd.name_of(sy, "kind", "goal.symmetry",
                                        std::array<std::pair<const char*, Symmetry::Kind>, 3>{{{"none", Symmetry::Kind::none},
                                                                                               {"axial", Symmetry::Kind::axial},
                                                                                               {"discrete", Symmetry::Kind::discrete}}});
      s.goal.symmetry.order = rd.integer(sy, "order", "goal.symmetry");
      if (s.goal.symmetry.order < 1) rd.fail("goal.symmetry.order", "must be >= 1");
      break;
    }
    case Task::ovr:
      rd.only(g, "goal", {"object", "goal_pose", "obstacle"});
      s.goal.object = rd.integer(g, "object", "goal");
      s.goal.goal_pose = rd.pose(g, "goal_pose", "goal");
      s.goal.obstacle = rd.integer(g, "obstacle", "goal");
      break;
    case Task::stk:
      rd.only(g, "goal", {"items"});
      s.goal.items = rd.ints(g, "items", "goal");
      break;
    case Task::arr: {
      rd.only(g, "goal", {"relations"});
      const Json& rels = rd.array(g, "relations", "goal");
      for (std::size_t i = 0; i < rels.size(); ++i) {
        const std::string p = "goal.relations[" + std::to_string(i) + "]";
        Relation r;
        rd.only(rels[i], p, {"kind", "objects", "references", "spots"});
        r.kind = rd.name_of(rels[i], "kind", p, json_detail::relation_names);
        r.objects = rd.ints(rels[i], "objects", p);
        r.references = rd.ints(rels[i], "references", p);
        const Json& sp = rd.array(rels[i], "spots", p);
        for (std::size_t k = 0; k < sp.size(); ++k) {
          const Json w{{"v", sp[k]}};
          r.spots.push_back(rd.vec3(w, "v", p + ".spots[" + std::to_string(k) + "]"));
        }
        s.goal.relations.push_back(std::move(r));
      }
      break;
    }
  }
  s.instruction = rd.str(j, "instruction", "");
  s.instructions_seen = rd.strings(j, "instructions_seen", "");
  s.instructions_unseen = rd.strings(j, "instructions_unseen", "");
  const Json& sm = rd.at(j, "sampling", "");
  rd.only(sm, "sampling", {"engine_seed", "redraws", "rejections"});
  s.sampling.engine_seed = rd.u64(sm, "engine_seed", "sampling");
  s.sampling.redraws = rd.integer(sm, "redraws", "sampling");
  s.sampling.rejections = rd.strings(sm, "rejections", "sampling");
  return s;
}

/// Parses scene text; `where` names the source in errors (a syntax error gives its byte offset).
inline SceneSpec parse_scene(const std::string& text, const std::string& where) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text, json_detail::DuplicateKeyCheck(where));
  } catch (const nlohmann::json::parse_error& e) {
    manisoft::detail::fail(where, ": not valid JSON at byte ", e.byte, ": ", e.what());
  } catch (const nlohmann::json::exception& e) {  // a number beyond the range of a double (1e400)
    manisoft::detail::fail(where, ": cannot be read: ", e.what());
  }
  return from_json(j, where);
}

/// Reads and checks a scene file (form, then consistency with the asset library).
inline SceneSpec load_scene(const std::string& path, const AssetLibrary& lib) {
  std::ifstream in(path, std::ios::binary);
  if (!in) manisoft::detail::fail("cannot read the scene file '", path, "'");
  std::ostringstream text;
  text << in.rdbuf();
  SceneSpec s = parse_scene(text.str(), path);
  require_consistent(s, lib, path);
  return s;
}

/// Writes a scene file atomically (a temporary file renamed into place; a device or a pipe, such
/// as /dev/stdout, is written in place).
inline void save_scene(const std::string& path, const SceneSpec& s) {
  const std::string text = to_json_string(s);  // refuses non-finite values before touching the disk
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.flush();
    if (!out) manisoft::detail::fail("writing the scene file '", path, "' failed");
    return;
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) manisoft::detail::fail("cannot write the scene file '", tmp, "'");
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      manisoft::detail::fail("writing the scene file '", tmp, "' failed");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    manisoft::detail::fail("cannot move '", tmp, "' to '", path, "'");
  }
}

}  // namespace manisoft::scene
