// File formats of the render programs (render_scene, render_blender): the world_demo CSV trace
// (README.md, "world_demo") read into FrameStates of the built-in tabletop scene, and
// camera.json (the OpenCV calibration and each mask id's name and world position).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/render/image.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/render/tabletop_render_scene.hpp"

namespace manisoft::render::io {

/// A world_demo trace: column names and numeric rows.
struct Trace {
  std::string name;  ///< the file read (messages name it)
  std::vector<std::string> columns;
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<double>> rows;

  double at(std::size_t row, const std::string& column) const {
    auto it = index.find(column);
    if (it == index.end()) manisoft::detail::fail(where(), ": no column '", column, "'");
    return rows[row][it->second];
  }
  bool has(const std::string& column) const { return index.count(column) > 0; }
  std::string where() const { return name.empty() ? "trace" : "trace " + name; }
};

inline std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    if (!cell.empty() && cell.back() == '\r') cell.pop_back();
    out.push_back(cell);
  }
  return out;
}

/// Reads a trace; throws manisoft::Error for a missing file, a row of the wrong width or a cell
/// that is not a finite number (naming the line and the column).
inline Trace read_trace(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) manisoft::detail::fail("trace ", path.string(), ": cannot open the file");
  Trace t;
  t.name = path.string();
  std::string line;
  if (!std::getline(in, line)) manisoft::detail::fail("trace ", path.string(), ": empty file (no header row)");
  t.columns = split_csv(line);
  for (std::size_t i = 0; i < t.columns.size(); ++i) t.index[t.columns[i]] = i;
  for (const char* required : {"finger_width", "gripper_px", "gripper_qw", "node0_x", "node1_x"}) {
    if (!t.has(required)) manisoft::detail::fail("trace ", path.string(), ": header lacks column '", required, "' (world_demo layout expected)");
  }
  std::size_t line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const auto cells = split_csv(line);
    if (cells.size() != t.columns.size()) {
      manisoft::detail::fail("trace ", path.string(), " line ", line_number, ": ", cells.size(), " cells, the header has ", t.columns.size());
    }
    std::vector<double> row(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      char* end = nullptr;
      row[i] = std::strtod(cells[i].c_str(), &end);
      if (end == cells[i].c_str() || *end != '\0' || !std::isfinite(row[i])) {
        manisoft::detail::fail("trace ", path.string(), " line ", line_number, ": column '", t.columns[i], "' = '", cells[i], "' is not a finite number");
      }
    }
    t.rows.push_back(std::move(row));
  }
  if (t.rows.empty()) manisoft::detail::fail("trace ", path.string(), ": no data rows");
  return t;
}

/// Refuses a trace recorded in another scene: every object the trace poses (its <name>_px columns
/// other than the gripper's) must be one of the scene's, and every object of a scene file
/// (object0, object1, ...) must be posed by the trace.
inline void require_trace_matches(const tabletop::TabletopScene& scene, const Trace& t, const std::string& trace_name, const std::string& scene_name) {
  std::string scene_objects;
  for (const auto& [name, instance] : scene.object_instance) scene_objects += (scene_objects.empty() ? "" : ", ") + name;
  for (const std::string& column : t.columns) {
    const auto suffix = column.rfind("_px");
    if (suffix == std::string::npos || suffix + 3 != column.size()) continue;
    const std::string name = column.substr(0, suffix);
    if (name != "gripper" && scene.object_instance.count(name) == 0)
      manisoft::detail::fail("trace ", trace_name, " poses '", name, "', which ", scene_name, " does not have (its objects: ", scene_objects,
                             "): the trace was recorded in another scene");
  }
  for (const auto& [name, instance] : scene.object_instance) {
    if (name.rfind("object", 0) == 0 && !t.has(name + "_px"))
      manisoft::detail::fail("trace ", trace_name, " has no pose of '", name, "' of ", scene_name, " (no column ", name,
                             "_px): the trace was recorded in another scene");
  }
}

inline math::Pose<double> pose_from(const Trace& t, std::size_t row, const std::string& prefix) {
  Eigen::Quaterniond q(t.at(row, prefix + "_qw"), t.at(row, prefix + "_qx"), t.at(row, prefix + "_qy"), t.at(row, prefix + "_qz"));
  if (!(q.norm() > 1e-9)) manisoft::detail::fail(t.where(), " row ", row, ": quaternion of '", prefix, "' has zero norm");
  math::Pose<double> pose;
  pose.rotation = q.normalized().toRotationMatrix();
  pose.translation = Eigen::Vector3d(t.at(row, prefix + "_px"), t.at(row, prefix + "_py"), t.at(row, prefix + "_pz"));
  return pose;
}

/// The frame of trace row `row` (world_demo's built-in scene, or a spec scene replayed from
/// run_task): rod nodes (frames derived from the centreline: the trace has no directors), gripper
/// pose and opening, object poses.
inline FrameState frame_from_trace(const tabletop::TabletopScene& scene, const Trace& t, std::size_t row) {
  if (row >= t.rows.size()) manisoft::detail::fail(t.where(), ": frame ", row, " is out of range: the trace has ", t.rows.size(), " rows (0..", t.rows.size() - 1, ")");
  FrameState f = scene.frame;
  int nodes = 0;
  while (t.has("node" + std::to_string(nodes) + "_x")) ++nodes;
  f.rod.nodes.resize(nodes, 3);
  f.rod.directors.resize(0, 9);
  for (int i = 0; i < nodes; ++i) {
    const std::string p = "node" + std::to_string(i);
    // read before the comma initializer: a missing column throws, and an initializer left
    // incomplete by an exception asserts in its destructor
    const double x = t.at(row, p + "_x"), y = t.at(row, p + "_y"), z = t.at(row, p + "_z");
    f.rod.nodes.row(i) << x, y, z;
  }
  tabletop::set_gripper(scene, f, pose_from(t, row, "gripper"), t.at(row, "finger_width"));
  // every instance whose name's first word has pose columns (all parts of a multi-part asset)
  for (std::size_t i = 0; i < scene.scene.instances.size(); ++i) {
    const std::string& n = scene.scene.instances[i].name;
    const std::string name = n.substr(0, n.find(' '));
    if (t.has(name + "_px")) f.instance_poses[i] = pose_from(t, row, name);
  }
  return f;
}

inline void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) manisoft::detail::fail("cannot write ", tmp.string());
    out << text;
    if (!out) manisoft::detail::fail("cannot write ", tmp.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) manisoft::detail::fail("cannot rename ", tmp.string(), " to ", path.string(), ": ", ec.message());
}

inline std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

/// camera.json: width, height, K (3x3 rows), R (3x3 rows) and t (3) mapping world to camera
/// (OpenCV: x right, y down, z forward), and for each id present in the mask its name and the
/// world centre of its bounding box.
inline std::string camera_json(const RenderOutput& image, const std::map<std::uint16_t, ObjectBounds>& bounds) {
  std::ostringstream o;
  o << std::setprecision(10);
  auto matrix = [&](const Eigen::Matrix3d& m) {
    o << "[";
    for (int r = 0; r < 3; ++r) o << (r ? ", " : "") << "[" << m(r, 0) << ", " << m(r, 1) << ", " << m(r, 2) << "]";
    o << "]";
  };
  const CameraModel& c = image.camera;
  o << "{\n  \"width\": " << c.width << ",\n  \"height\": " << c.height << ",\n  \"K\": ";
  matrix(c.K);
  o << ",\n  \"R\": ";
  matrix(c.R);
  o << ",\n  \"t\": [" << c.t.x() << ", " << c.t.y() << ", " << c.t.z() << "],\n";
  o << "  \"convention\": \"OpenCV: x_cam = R x_world + t; (u, v, 1) ~ K x_cam; u right, v down, pixel centres at integers\",\n";
  o << "  \"depth_png\": \"uint16 millimetres along the camera z axis, 0 = background\",\n";
  o << "  \"objects\": [";
  std::vector<bool> present(65536, false);
  for (std::uint16_t id : image.mask) present[id] = true;
  bool first = true;
  for (const auto& [id, b] : bounds) {
    if (!image.mask.empty() && !present[id]) continue;
    const Eigen::Vector3d p = b.center();
    o << (first ? "\n" : ",\n") << "    {\"id\": " << id << ", \"name\": " << json_string(b.name) << ", \"position\": [" << p.x() << ", " << p.y()
      << ", " << p.z() << "]}";
    first = false;
  }
  o << "\n  ]\n}\n";
  return o.str();
}

/// Writes rgb.png, depth.png (16-bit mm), mask.png and camera.json into `dir` (created).
inline void write_frame(const std::filesystem::path& dir, const RenderOutput& image, const std::map<std::uint16_t, ObjectBounds>& bounds) {
  std::filesystem::create_directories(dir);
  write_png_rgb(dir / "rgb.png", image.width, image.height, image.rgb);
  if (!image.depth.empty()) write_png_gray16(dir / "depth.png", image.width, image.height, depth_millimetres(image.depth));
  if (!image.mask.empty()) write_png_mask(dir / "mask.png", image.width, image.height, image.mask);
  write_text_atomically(dir / "camera.json", camera_json(image, bounds));
}

}  // namespace manisoft::render::io
