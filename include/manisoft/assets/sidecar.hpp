// The JSON sidecar of an imported mesh (paper section 3.3: the assets' attributes and grasp
// annotations), read with nlohmann-json, and the RoboTwin-OD `model_data*.json` annotation layout
// (the paper's object dataset) read into the same structure.
//
// Sidecar (every field optional; quaternions are [w, x, y, z]; a pose is
// {"position": [x, y, z], "quaternion": [w, x, y, z]} or a 4x4 matrix, nested rows or 16 numbers
// row-major):
//   { "id": "mug/01", "name": "red mug", "category": "mug", "kind": "object" | "obstacle",
//     "scale": 0.001 | [sx, sy, sz],          file units -> metres (default 1)
//     "up_axis": "z" | "y" | "x" | "-z" ...,  the file's up axis (default "y" for glTF/GLB, else "z")
//     "origin": "footprint" | "keep",         re-centre on the footprint (default) or keep the file's origin
//     "annotation_frame": "asset" | "mesh",   poses below in the asset frame (default) or in the file's
//                                             frame and units (mapped like the vertices)
//     "attributes": { "color": "red", "color_rgb": [r, g, b], "material": "ceramic", "size": "small" },
//     "mass": 0.3 (kg) | "density": 900 (kg/m^3),  "friction": 0.6,
//     "grasps": [ { "approach": POSE, "grasp": POSE, "lift": POSE, "width": 0.05 } ],
//     "resting_poses": [ { "name": "upright", "quaternion": [1, 0, 0, 0], "height": 0 } ],
//     "receptacles": [ { "opening": POSE, "inner_radius": 0.04 | "inner_half_extents": [hx, hy],
//                        "inner_depth": 0.08, "placement": POSE } ],
//     "convex_decomposition": { "files": ["part0.obj", ...],       each file's hull is one piece
//                               "mesh_parts": [0, 2] | "all",      each listed mesh of the file: one piece
//                               "point_sets": [[[x, y, z], ...]] } each set's hull: one piece (annotation frame)
//   }
// Grasp frames follow asset.hpp (gripper attachment frame: +z along the approach, +x the closing
// axis). A grasp needs "grasp"; "approach" defaults to the grasp backed off 0.1 m along -z of the
// grasp frame, "lift" to the grasp raised 0.1 m along the asset's +z, "width" to the object's
// extent along the closing axis.
//
// RoboTwin-OD model_data (recognised by its "contact_points_pose" field): "scale" [sx, sy, sz]
// (file units -> metres), "contact_points_pose" (4x4 contact frames, translation in file units,
// multiplied by scale), "functional_matrix", "target_pose", "orientation_point" (4x4 frames),
// "stable" (bool), "extents", "center" ([x, y, z], file units), "transform_matrix" (4x4; RoboTwin's
// own loaders use only "scale", so it is kept, not applied). The GLB is y-up (glTF); RoboTwin stands
// it up with a +90 degree rotation about x, as our "up_axis": "y" does. RoboTwin's grasp builder
// turns a contact frame C into its end-effector frame C * [[0,0,1],[-1,0,0],[0,-1,0]] whose +x (the
// approach) is C's -y and backs it off along that axis; the closing axis is C's z (the direction
// across the thin side of annotated objects). Our gripper frame in C's axes is therefore
// x = z_C, y = -x_C, z = -y_C (a proper rotation), placed `grasp_depth` back from the contact point
// along its +z so the contact point sits between the fingers.
#pragma once

#include "manisoft/assets/asset.hpp"
#include "manisoft/core/error.hpp"

#include <nlohmann/json.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace manisoft::assets {

/// A pose as written in a sidecar (frame given by Sidecar::annotation_in_mesh_frame).
struct SidecarPose {
  Eigen::Matrix3d rotation{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};
};

struct SidecarGrasp {
  std::optional<SidecarPose> approach;
  SidecarPose grasp;
  std::optional<SidecarPose> lift;
  std::optional<double> width;
};

struct SidecarResting {
  std::string name;
  Eigen::Quaterniond orientation{Eigen::Quaterniond::Identity()};
  double height = 0;
};

struct SidecarReceptacle {
  SidecarPose opening;
  double inner_radius = 0;
  Eigen::Vector2d inner_half_extents{0, 0};
  double inner_depth = 0;
  std::optional<SidecarPose> placement;
};

struct SidecarDecomposition {
  std::vector<std::string> files;  ///< resolved against the sidecar's folder
  bool all_mesh_parts = false;
  std::vector<int> mesh_parts;
  std::vector<std::vector<Eigen::Vector3d>> point_sets;
};

/// RoboTwin-OD annotations in the file's frame and units (see the header comment).
struct RoboTwinModelData {
  std::vector<Eigen::Matrix4d> contact_points;
  std::vector<Eigen::Matrix4d> functional_points;
  std::vector<Eigen::Matrix4d> target_points;
  std::optional<Eigen::Matrix4d> orientation_point;
  Eigen::Matrix4d transform_matrix{Eigen::Matrix4d::Identity()};
  std::optional<bool> stable;
  std::optional<Eigen::Vector3d> extents;
  std::optional<Eigen::Vector3d> center;
};

/// Everything a sidecar can say; unset fields take the importer's defaults.
struct Sidecar {
  std::string path;  ///< where it was read from ("" when built in code)
  std::optional<std::string> id, name, category;
  std::optional<AssetKind> kind;
  std::optional<Eigen::Vector3d> scale;
  std::optional<Eigen::Vector3d> up_axis;  ///< unit axis of the file that points up
  bool keep_origin = false;
  bool annotation_in_mesh_frame = false;
  std::optional<std::string> color_name, material_name;
  std::optional<Eigen::Vector3f> color_rgb;
  std::optional<SizeClass> size;
  std::optional<double> mass, density, friction;
  std::vector<SidecarGrasp> grasps;
  std::vector<SidecarResting> resting_poses;
  std::vector<SidecarReceptacle> receptacles;
  std::optional<SidecarDecomposition> decomposition;
  std::optional<RoboTwinModelData> robotwin;
};

namespace detail {

/// "line L, column C" of byte offset `byte` (1-based, as nlohmann reports it) in `text`.
inline std::string line_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, column = 1;
  const std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  std::ostringstream out;
  out << line << ":" << column;
  return out.str();
}

class JsonReader {
 public:
  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail_at(const std::string& where, const std::string& what) const {
    ::manisoft::detail::fail(file_, ": element ", where.empty() ? std::string("/") : where, ": ", what);
  }

  double number(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_number()) fail_at(where, "expected a number, found " + std::string(j.type_name()));
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail_at(where, "number is not finite");
    if (std::abs(v) > 1e6) fail_at(where, "number " + std::to_string(v) + " is out of range (|x| <= 1e6)");
    return v;
  }
  double positive(const nlohmann::json& j, const std::string& where) const {
    const double v = number(j, where);
    if (!(v > 0)) fail_at(where, "must be > 0, found " + std::to_string(v));
    return v;
  }
  std::string string(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_string()) fail_at(where, "expected a string, found " + std::string(j.type_name()));
    return j.get<std::string>();
  }
  bool boolean(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_boolean()) fail_at(where, "expected true or false, found " + std::string(j.type_name()));
    return j.get<bool>();
  }
  const nlohmann::json& array(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_array()) fail_at(where, "expected an array, found " + std::string(j.type_name()));
    return j;
  }
  const nlohmann::json& object(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_object()) fail_at(where, "expected an object, found " + std::string(j.type_name()));
    return j;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vector(const nlohmann::json& j, const std::string& where) const {
    array(j, where);
    if (j.size() != static_cast<std::size_t>(N)) {
      fail_at(where, "expected " + std::to_string(N) + " numbers, found " + std::to_string(j.size()));
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = number(j[static_cast<std::size_t>(i)], where + "/" + std::to_string(i));
    return v;
  }
  /// A 4x4 rigid transform: nested rows or 16 numbers row-major; last row (0 0 0 1); rotation
  /// orthonormal with det +1 (within 1e-3, then re-orthonormalised).
  Eigen::Matrix4d matrix4(const nlohmann::json& j, const std::string& where) const {
    array(j, where);
    Eigen::Matrix4d m;
    if (j.size() == 16) {
      for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = number(j[static_cast<std::size_t>(i)], where + "/" + std::to_string(i));
    } else if (j.size() == 4) {
      for (int r = 0; r < 4; ++r) m.row(r) = vector<4>(j[static_cast<std::size_t>(r)], where + "/" + std::to_string(r)).transpose();
    } else {
      fail_at(where, "expected a 4x4 matrix (4 rows of 4 or 16 numbers), found " + std::to_string(j.size()) + " entries");
    }
    if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-6) {
      fail_at(where, "the last row of a rigid transform must be (0 0 0 1)");
    }
    m.topLeftCorner<3, 3>() = orthonormal(m.topLeftCorner<3, 3>(), where);
    return m;
  }
  Eigen::Matrix3d orthonormal(const Eigen::Matrix3d& r, const std::string& where) const {
    if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 || r.determinant() < 0) {
      fail_at(where, "the rotation part is not a rotation (orthonormal, det +1)");
    }
    const Eigen::Quaterniond q(r);
    return q.normalized().toRotationMatrix();
  }
  SidecarPose pose(const nlohmann::json& j, const std::string& where) const {
    SidecarPose p;
    if (j.is_array()) {
      const Eigen::Matrix4d m = matrix4(j, where);
      p.rotation = m.topLeftCorner<3, 3>();
      p.position = m.topRightCorner<3, 1>();
      return p;
    }
    object(j, where);
    if (!j.contains("position")) fail_at(where, "missing field 'position'");
    p.position = vector<3>(j["position"], where + "/position");
    if (j.contains("quaternion")) p.rotation = quaternion(j["quaternion"], where + "/quaternion").toRotationMatrix();
    return p;
  }
  Eigen::Quaterniond quaternion(const nlohmann::json& j, const std::string& where) const {
    const Eigen::Vector4d q = vector<4>(j, where);
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-2) fail_at(where, "quaternion [w, x, y, z] must have unit length, |q| = " + std::to_string(norm));
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  }
  std::vector<Eigen::Matrix4d> matrices(const nlohmann::json& j, const std::string& where) const {
    array(j, where);
    std::vector<Eigen::Matrix4d> out;
    for (std::size_t i = 0; i < j.size(); ++i) out.push_back(matrix4(j[i], where + "/" + std::to_string(i)));
    return out;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

inline Eigen::Vector3d parse_axis(const std::string& text, const JsonReader& r, const std::string& where) {
  if (text == "x" || text == "+x") return Eigen::Vector3d::UnitX();
  if (text == "y" || text == "+y") return Eigen::Vector3d::UnitY();
  if (text == "z" || text == "+z") return Eigen::Vector3d::UnitZ();
  if (text == "-x") return -Eigen::Vector3d::UnitX();
  if (text == "-y") return -Eigen::Vector3d::UnitY();
  if (text == "-z") return -Eigen::Vector3d::UnitZ();
  r.fail_at(where, "up axis '" + text + "' is not one of x, y, z, -x, -y, -z");
}

inline RoboTwinModelData parse_robotwin(const nlohmann::json& j, const JsonReader& r, Sidecar& sidecar) {
  RoboTwinModelData d;
  d.contact_points = r.matrices(j["contact_points_pose"], "/contact_points_pose");
  if (j.contains("functional_matrix")) d.functional_points = r.matrices(j["functional_matrix"], "/functional_matrix");
  if (j.contains("target_pose")) d.target_points = r.matrices(j["target_pose"], "/target_pose");
  if (j.contains("orientation_point")) {
    const auto& o = j["orientation_point"];
    // Stored either as one 4x4 or as a list holding one.
    if (o.is_array() && !o.empty() && o[0].is_array() && o[0].size() == 4 && o[0][0].is_array()) {
      d.orientation_point = r.matrix4(o[0], "/orientation_point/0");
    } else {
      d.orientation_point = r.matrix4(o, "/orientation_point");
    }
  }
  if (j.contains("transform_matrix")) d.transform_matrix = r.matrix4(j["transform_matrix"], "/transform_matrix");
  if (j.contains("stable")) d.stable = r.boolean(j["stable"], "/stable");
  if (j.contains("extents")) d.extents = r.vector<3>(j["extents"], "/extents");
  if (j.contains("center")) d.center = r.vector<3>(j["center"], "/center");
  if (j.contains("scale")) {
    const auto& s = j["scale"];
    if (s.is_number()) {
      sidecar.scale = Eigen::Vector3d::Constant(r.positive(s, "/scale"));
    } else {
      const Eigen::Vector3d v = r.vector<3>(s, "/scale");
      for (int i = 0; i < 3; ++i) {
        if (!(v[i] > 0)) r.fail_at("/scale/" + std::to_string(i), "scale must be > 0");
      }
      sidecar.scale = v;
    }
  }
  sidecar.up_axis = Eigen::Vector3d::UnitY();  // glTF
  sidecar.annotation_in_mesh_frame = true;
  return d;
}

}  // namespace detail

/// Parses sidecar text (`file` names it in errors: syntax errors give line:column, content errors the
/// element's JSON pointer). `folder` resolves the decomposition's file names.
inline Sidecar parse_sidecar(const std::string& text, const std::string& file, const std::string& folder = ".") {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    ::manisoft::detail::fail(file, ":", detail::line_column(text, e.byte), ": JSON syntax error: ", e.what());
  } catch (const nlohmann::json::exception& e) {  // a number beyond the range of a double (1e400)
    ::manisoft::detail::fail(file, ": cannot be read: ", e.what());
  }
  const detail::JsonReader r(file);
  r.object(j, "");
  Sidecar s;
  s.path = file;
  if (j.contains("contact_points_pose")) {
    s.robotwin = detail::parse_robotwin(j, r, s);
    return s;
  }
  static const std::array<const char*, 20> known{"id", "name", "category", "kind", "scale", "up_axis", "origin",
                                                 "annotation_frame", "attributes", "mass", "density", "friction",
                                                 "grasps", "resting_poses", "receptacles", "convex_decomposition",
                                                 "comment", "description", "version", "robotwin"};
  for (const auto& [key, value] : j.items()) {
    if (std::find(known.begin(), known.end(), key) == known.end()) r.fail_at("/" + key, "unknown field '" + key + "'");
  }
  if (j.contains("id")) s.id = r.string(j["id"], "/id");
  if (j.contains("name")) s.name = r.string(j["name"], "/name");
  if (j.contains("category")) s.category = r.string(j["category"], "/category");
  if (j.contains("kind")) {
    const std::string k = r.string(j["kind"], "/kind");
    if (k == "object") {
      s.kind = AssetKind::object;
    } else if (k == "obstacle") {
      s.kind = AssetKind::obstacle;
    } else {
      r.fail_at("/kind", "'" + k + "' is not 'object' or 'obstacle'");
    }
  }
  if (j.contains("scale")) {
    const auto& sc = j["scale"];
    if (sc.is_number()) {
      s.scale = Eigen::Vector3d::Constant(r.positive(sc, "/scale"));
    } else {
      const Eigen::Vector3d v = r.vector<3>(sc, "/scale");
      for (int i = 0; i < 3; ++i) {
        if (!(v[i] > 0)) r.fail_at("/scale/" + std::to_string(i), "scale must be > 0");
      }
      s.scale = v;
    }
  }
  if (j.contains("up_axis")) s.up_axis = detail::parse_axis(r.string(j["up_axis"], "/up_axis"), r, "/up_axis");
  if (j.contains("origin")) {
    const std::string o = r.string(j["origin"], "/origin");
    if (o != "footprint" && o != "keep") r.fail_at("/origin", "'" + o + "' is not 'footprint' or 'keep'");
    s.keep_origin = o == "keep";
  }
  if (j.contains("annotation_frame")) {
    const std::string f = r.string(j["annotation_frame"], "/annotation_frame");
    if (f != "asset" && f != "mesh") r.fail_at("/annotation_frame", "'" + f + "' is not 'asset' or 'mesh'");
    s.annotation_in_mesh_frame = f == "mesh";
  }
  if (j.contains("attributes")) {
    const auto& a = r.object(j["attributes"], "/attributes");
    for (const auto& [key, value] : a.items()) {
      if (key == "color") {
        s.color_name = r.string(value, "/attributes/color");
      } else if (key == "color_rgb") {
        const Eigen::Vector3d c = r.vector<3>(value, "/attributes/color_rgb");
        if (c.minCoeff() < 0 || c.maxCoeff() > 1) r.fail_at("/attributes/color_rgb", "components must lie in [0, 1]");
        s.color_rgb = c.cast<float>();
      } else if (key == "material") {
        s.material_name = r.string(value, "/attributes/material");
      } else if (key == "size") {
        const std::string z = r.string(value, "/attributes/size");
        if (z == "small") {
          s.size = SizeClass::small;
        } else if (z == "medium") {
          s.size = SizeClass::medium;
        } else if (z == "large") {
          s.size = SizeClass::large;
        } else {
          r.fail_at("/attributes/size", "'" + z + "' is not small, medium or large");
        }
      } else {
        r.fail_at("/attributes/" + key, "unknown attribute '" + key + "'");
      }
    }
  }
  if (j.contains("mass") && j.contains("density")) r.fail_at("/mass", "give either mass or density, not both");
  if (j.contains("mass")) s.mass = r.positive(j["mass"], "/mass");
  if (j.contains("density")) s.density = r.positive(j["density"], "/density");
  if (j.contains("friction")) {
    s.friction = r.number(j["friction"], "/friction");
    if (*s.friction < 0 || *s.friction > 10) r.fail_at("/friction", "friction must lie in [0, 10]");
  }
  if (j.contains("grasps")) {
    const auto& g = r.array(j["grasps"], "/grasps");
    for (std::size_t i = 0; i < g.size(); ++i) {
      const std::string w = "/grasps/" + std::to_string(i);
      r.object(g[i], w);
      if (!g[i].contains("grasp")) r.fail_at(w, "missing field 'grasp'");
      SidecarGrasp sg;
      sg.grasp = r.pose(g[i]["grasp"], w + "/grasp");
      if (g[i].contains("approach")) sg.approach = r.pose(g[i]["approach"], w + "/approach");
      if (g[i].contains("lift")) sg.lift = r.pose(g[i]["lift"], w + "/lift");
      if (g[i].contains("width")) sg.width = r.positive(g[i]["width"], w + "/width");
      s.grasps.push_back(sg);
    }
  }
  if (j.contains("resting_poses")) {
    const auto& rp = r.array(j["resting_poses"], "/resting_poses");
    for (std::size_t i = 0; i < rp.size(); ++i) {
      const std::string w = "/resting_poses/" + std::to_string(i);
      r.object(rp[i], w);
      SidecarResting rest;
      if (rp[i].contains("name")) rest.name = r.string(rp[i]["name"], w + "/name");
      if (rp[i].contains("quaternion")) rest.orientation = r.quaternion(rp[i]["quaternion"], w + "/quaternion");
      if (rp[i].contains("height")) rest.height = r.number(rp[i]["height"], w + "/height");
      s.resting_poses.push_back(rest);
    }
  }
  if (j.contains("receptacles")) {
    const auto& rc = r.array(j["receptacles"], "/receptacles");
    for (std::size_t i = 0; i < rc.size(); ++i) {
      const std::string w = "/receptacles/" + std::to_string(i);
      r.object(rc[i], w);
      if (!rc[i].contains("opening")) r.fail_at(w, "missing field 'opening'");
      if (!rc[i].contains("inner_depth")) r.fail_at(w, "missing field 'inner_depth'");
      SidecarReceptacle rec;
      rec.opening = r.pose(rc[i]["opening"], w + "/opening");
      rec.inner_depth = r.positive(rc[i]["inner_depth"], w + "/inner_depth");
      if (rc[i].contains("inner_radius")) {
        rec.inner_radius = r.positive(rc[i]["inner_radius"], w + "/inner_radius");
      } else if (rc[i].contains("inner_half_extents")) {
        const Eigen::Vector2d h = r.vector<2>(rc[i]["inner_half_extents"], w + "/inner_half_extents");
        if (!(h.minCoeff() > 0)) r.fail_at(w + "/inner_half_extents", "half extents must be > 0");
        rec.inner_half_extents = h;
      } else {
        r.fail_at(w, "missing field 'inner_radius' or 'inner_half_extents'");
      }
      if (rc[i].contains("placement")) rec.placement = r.pose(rc[i]["placement"], w + "/placement");
      s.receptacles.push_back(rec);
    }
  }
  if (j.contains("convex_decomposition")) {
    const auto& d = r.object(j["convex_decomposition"], "/convex_decomposition");
    SidecarDecomposition dec;
    for (const auto& [key, value] : d.items()) {
      const std::string w = "/convex_decomposition/" + key;
      if (key == "files") {
        r.array(value, w);
        for (std::size_t i = 0; i < value.size(); ++i) {
          const std::string name = r.string(value[i], w + "/" + std::to_string(i));
          dec.files.push_back(!name.empty() && name.front() == '/' ? name : folder + "/" + name);
        }
      } else if (key == "mesh_parts") {
        if (value.is_string() && value.get<std::string>() == "all") {
          dec.all_mesh_parts = true;
        } else {
          r.array(value, w);
          for (std::size_t i = 0; i < value.size(); ++i) {
            const double v = r.number(value[i], w + "/" + std::to_string(i));
            if (v < 0 || v != std::floor(v)) r.fail_at(w + "/" + std::to_string(i), "mesh index must be an integer >= 0");
            dec.mesh_parts.push_back(static_cast<int>(v));
          }
        }
      } else if (key == "point_sets") {
        r.array(value, w);
        for (std::size_t i = 0; i < value.size(); ++i) {
          const std::string wi = w + "/" + std::to_string(i);
          r.array(value[i], wi);
          if (value[i].size() < 4) r.fail_at(wi, "a convex piece needs at least 4 points");
          std::vector<Eigen::Vector3d> pts;
          for (std::size_t k = 0; k < value[i].size(); ++k) pts.push_back(r.vector<3>(value[i][k], wi + "/" + std::to_string(k)));
          dec.point_sets.push_back(std::move(pts));
        }
      } else {
        r.fail_at(w, "unknown field '" + key + "' (files, mesh_parts, point_sets)");
      }
    }
    s.decomposition = std::move(dec);
  }
  if (j.contains("robotwin")) {
    const auto& rt = r.object(j["robotwin"], "/robotwin");
    if (!rt.contains("contact_points_pose")) r.fail_at("/robotwin", "missing field 'contact_points_pose'");
    Sidecar inner;
    s.robotwin = detail::parse_robotwin(rt, detail::JsonReader(file + " (/robotwin)"), inner);
    if (!s.scale && inner.scale) s.scale = inner.scale;
    if (!s.up_axis) s.up_axis = inner.up_axis;
  }
  return s;
}

/// Reads a sidecar file (see parse_sidecar).
inline Sidecar load_sidecar(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ::manisoft::detail::fail("cannot open sidecar file '", path, "'");
  std::ostringstream text;
  text << in.rdbuf();
  const auto slash = path.find_last_of('/');
  return parse_sidecar(text.str(), path, slash == std::string::npos ? std::string(".") : path.substr(0, slash));
}

}  // namespace manisoft::assets
