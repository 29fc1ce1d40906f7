// Imports a user's mesh file (OBJ, glTF 2.0 / GLB, STL, PLY; through assimp) and its JSON sidecar
// (sidecar.hpp, or a RoboTwin-OD model_data annotation) as an assets::Asset (paper section 3.3:
// the benchmark's objects and obstacles; users bring their own, e.g. the paper's RoboTwin-OD GLBs).
//
// Pipeline:
//   1. assimp reads the file: triangulate, join identical vertices, generate smooth normals where
//      missing, drop points and lines; texture coordinates (channel 0) kept where present.
//   2. Every node's mesh instances become visual parts (one per mesh instance, coloured by its
//      material: glTF base colour, else diffuse colour), with the node transforms applied, then the
//      unit scale (sidecar "scale"), the up-axis rotation (file up axis -> +z; y-up files turn
//      +90 degrees about x) and, unless "origin": "keep", the shift that puts the origin at the
//      centre of the footprint (bounding-box centre in x, y; lowest point z = 0), asset.hpp's frame.
//   3. The solid: all parts' triangles welded by position. If closed (every edge used once each way)
//      and physically sound (volume within the hull's, inertia of a real body), volume, centre of
//      mass and inertia are the exact polyhedral integrals of the mesh (geometry::mass_properties);
//      else (open, self-intersecting) those of the collision shape, and ImportReport::note says so.
//      Overlapping closed shells that stay within the hull are counted twice where they overlap.
//   4. Collision: the sidecar's convex decomposition when given (files, mesh parts or point sets,
//      each piece its convex hull); else the convex hull when (V_hull - V) / V <= convex_tolerance
//      or the surface is open; else geometry::approximate_convex_decomposition (recursive plane
//      splits, convex_decomposition.hpp) as a geometry::Compound.
//   5. Mass from the sidecar's mass, else its density, else ImportOptions::default_density.
//   6. Annotations: the sidecar's grasps, resting poses, receptacles; RoboTwin contact points as
//      grasps (frame conversion in sidecar.hpp). Missing grasp widths are the object's extent along
//      the closing axis through the contact point (ray cast), clamped to the gripper's open width.
//
// Refused, with manisoft::Error naming the file and the element: unreadable or malformed files
// (assimp's message), NaN or infinite coordinates (mesh and vertex index), out-of-range indices,
// no triangles, flat or zero-volume meshes, sizes above `max_size` (10 m) or below `min_size`
// (1 mm) after scaling, sidecar errors (line:column or JSON element). Nothing half-built is returned.
//
// Length: the pipeline's stages above are one import sharing assimp's scene and the ImportReport;
// each stage is its own function here (longer than the project's usual 600 lines for that reason).
#pragma once

#include "manisoft/assets/asset.hpp"
#include "manisoft/assets/sidecar.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/geometry/convex_decomposition.hpp"
#include "manisoft/geometry/convex_hull.hpp"
#include "manisoft/geometry/mass_properties.hpp"
#include "manisoft/geometry/shapes.hpp"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace manisoft::assets {

struct ImportOptions {
  double default_density = 500.0;    ///< kg/m^3 when the sidecar gives neither mass nor density
  double convex_tolerance = 0.05;    ///< hull accepted when (V_hull - V) / V <= this
  geometry::DecompositionOptions decomposition{};
  double max_size = 10.0;            ///< m, largest accepted bounding-box extent after scaling
  double min_size = 1e-3;            ///< m, smallest accepted largest extent
  double grasp_depth = GraspGripper{}.grasp_depth();  ///< m, gripper origin to contact point along +z
  double approach_distance = 0.10;   ///< m, approach pose backed off along the grasp frame's -z
  double lift_height = 0.10;         ///< m, lift pose above the grasp (asset +z)
  double gripper_open_width = GraspGripper{}.open_width;  ///< m, grasp widths are clamped below this
  std::uintmax_t max_file_bytes = std::uintmax_t{1} << 30;
};

/// RoboTwin-OD annotations other than grasps, in the asset frame (positions in metres).
struct ImportedFunctionalPoints {
  std::vector<math::Pose<double>> functional;
  std::vector<math::Pose<double>> target;
  std::optional<math::Pose<double>> orientation;
  std::optional<bool> stable;
};

/// What the importer did, for the summary.
struct ImportReport {
  bool closed = false;                  ///< the welded surface is closed (mass from the mesh itself)
  double mesh_volume = 0;               ///< m^3 of the closed surface (0 when open)
  double hull_volume = 0;               ///< m^3 of the convex hull of all vertices
  double collision_volume = 0;          ///< m^3, summed over convex pieces
  std::size_t convex_pieces = 0;
  std::string collision_method;         ///< "hull", "decomposition", "sidecar decomposition"
  std::size_t vertices = 0, triangles = 0;
  std::string sidecar;                  ///< path used ("" when none)
  std::string note;                     ///< why the convex hull stands in for the surface, if it does
  Eigen::Matrix4d file_to_asset{Eigen::Matrix4d::Identity()};  ///< maps file coordinates to the asset frame
  ImportedFunctionalPoints robotwin;
};

struct ImportResult {
  Asset asset;
  ImportReport report;
};

namespace detail {

/// Maps file coordinates to the asset frame: p -> R_up (s . p) - shift.
struct FileToAsset {
  Eigen::Vector3d scale{1, 1, 1};
  Eigen::Matrix3d up{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d shift{Eigen::Vector3d::Zero()};

  Eigen::Vector3d point(const Eigen::Vector3d& p) const { return up * scale.cwiseProduct(p) - shift; }
  /// A rigid frame given in the file frame (translation in file units): rotation turned by R_up.
  math::Pose<double> frame(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& position) const {
    return math::Pose<double>{up * rotation, point(position)};
  }
};

/// Rotation taking the file's up axis to +z (the least rotation; y-up: +90 degrees about x).
inline Eigen::Matrix3d up_rotation(const Eigen::Vector3d& up) {
  if (up.isApprox(Eigen::Vector3d::UnitZ())) return Eigen::Matrix3d::Identity();
  if (up.isApprox(-Eigen::Vector3d::UnitZ())) return Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

inline std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// A triangle mesh instance in file coordinates with node transforms applied.
struct RawPart {
  std::string name;
  int mesh_index = 0;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  render::Material material;
  std::string material_label;
};

inline Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

inline render::Material read_material(const aiScene& scene, unsigned index, std::string& label) {
  render::Material out;
  if (index >= scene.mNumMaterials || scene.mMaterials[index] == nullptr) return out;
  const aiMaterial& m = *scene.mMaterials[index];
  aiColor4D c;
  bool have = false;
#ifdef AI_MATKEY_BASE_COLOR
  if (m.Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS) have = true;
#endif
  if (!have && m.Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS) have = true;
  if (have) {
    Eigen::Vector3f rgb(c.r, c.g, c.b);
    if (rgb.allFinite()) out.base_color = rgb.cwiseMax(0.0f).cwiseMin(1.0f);
  }
  float shininess = 0;
  if (m.Get(AI_MATKEY_SHININESS, shininess) == aiReturn_SUCCESS && std::isfinite(shininess) && shininess > 0) {
    out.shininess = std::clamp(shininess, 1.0f, 256.0f);
  }
  aiString name;
  if (m.Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS) label = name.C_Str();
  return out;
}

inline void collect_parts(const aiScene& scene, const aiNode& node, const Eigen::Matrix4d& parent,
                          const std::string& file, std::vector<RawPart>& parts, int depth) {
  if (depth > 64) ::manisoft::detail::fail(file, ": node hierarchy deeper than 64 levels");
  const Eigen::Matrix4d transform = parent * to_eigen(node.mTransformation);
  if (!transform.allFinite()) ::manisoft::detail::fail(file, ": node '", node.mName.C_Str(), "' has a non-finite transform");
  const Eigen::Matrix3d linear = transform.topLeftCorner<3, 3>();
  const double det = linear.determinant();
  if (!(std::abs(det) > 1e-30)) ::manisoft::detail::fail(file, ": node '", node.mName.C_Str(), "' has a singular transform");
  const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const unsigned mi = node.mMeshes[k];
    if (mi >= scene.mNumMeshes) ::manisoft::detail::fail(file, ": node '", node.mName.C_Str(), "' refers to mesh ", mi, " of ", scene.mNumMeshes);
    const aiMesh& mesh = *scene.mMeshes[mi];
    if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    RawPart part;
    part.mesh_index = static_cast<int>(mi);
    part.name = mesh.mName.length > 0 ? mesh.mName.C_Str() : (node.mName.length > 0 ? node.mName.C_Str() : "");
    part.material = read_material(scene, mesh.mMaterialIndex, part.material_label);
    part.positions.reserve(mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      const Eigen::Vector3d local(p.x, p.y, p.z);
      if (!local.allFinite()) {
        ::manisoft::detail::fail(file, ": mesh ", mi, " vertex ", v, " has a non-finite coordinate (", p.x, ", ", p.y, ", ", p.z, ")");
      }
      part.positions.push_back((transform * local.homogeneous()).head<3>());
      if (mesh.mNormals != nullptr) {
        const aiVector3D& n = mesh.mNormals[v];
        Eigen::Vector3d nn = normal_matrix * Eigen::Vector3d(n.x, n.y, n.z);
        const double len = nn.norm();
        part.normals.push_back(std::isfinite(len) && len > 0 ? Eigen::Vector3d(nn / len) : Eigen::Vector3d::Zero());
      }
      if (mesh.mTextureCoords[0] != nullptr) {
        const aiVector3D& t = mesh.mTextureCoords[0][v];
        Eigen::Vector2f uv(t.x, t.y);
        part.uvs.push_back(uv.allFinite() ? uv : Eigen::Vector2f::Zero());
      }
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines (removed by assimp already)
      std::array<std::uint32_t, 3> t{};
      for (int c = 0; c < 3; ++c) {
        const unsigned idx = face.mIndices[c];
        if (idx >= mesh.mNumVertices) {
          ::manisoft::detail::fail(file, ": mesh ", mi, " face ", f, " refers to vertex ", idx, " of ", mesh.mNumVertices);
        }
        t[static_cast<std::size_t>(c)] = idx;
      }
      if (det < 0) std::swap(t[1], t[2]);  // mirrored instance: keep outward winding
      part.triangles.push_back(t);
    }
    if (!part.triangles.empty()) parts.push_back(std::move(part));
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    if (node.mChildren[c] == nullptr) ::manisoft::detail::fail(file, ": node '", node.mName.C_Str(), "' has a null child");
    collect_parts(scene, *node.mChildren[c], transform, file, parts, depth + 1);
  }
}

/// Checks a PLY header before assimp sees it (assimp's reader does not stop on a header without
/// "end_header"): magic, format line, element counts that the file's size can hold.
inline void check_ply_header(const std::string& path, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t line_number = 0;
  unsigned long long elements = 0;
  bool format = false;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) {
      if (line != "ply") ::manisoft::detail::fail(path, ":1: not a PLY file (first line '", line.substr(0, 40), "')");
      continue;
    }
    if (line == "end_header") {
      if (!format) ::manisoft::detail::fail(path, ": PLY header has no 'format' line");
      if (elements > size) ::manisoft::detail::fail(path, ": PLY header declares ", elements, " elements, more than the file's ", size, " bytes can hold");
      return;
    }
    std::istringstream fields(line);
    std::string keyword;
    fields >> keyword;
    if (keyword == "format") {
      std::string kind, version;
      fields >> kind >> version;
      if (kind != "ascii" && kind != "binary_little_endian" && kind != "binary_big_endian") {
        ::manisoft::detail::fail(path, ":", line_number, ": unknown PLY format '", kind, "'");
      }
      format = true;
    } else if (keyword == "element") {
      std::string name;
      long long count = -1;
      if (!(fields >> name >> count) || count < 0) ::manisoft::detail::fail(path, ":", line_number, ": malformed PLY element line '", line.substr(0, 60), "'");
      elements += static_cast<unsigned long long>(count);
    } else if (keyword != "property" && keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      ::manisoft::detail::fail(path, ":", line_number, ": unknown PLY header line '", line.substr(0, 60), "'");
    }
    if (line_number > 10000 || in.tellg() > std::streamoff{1 << 20}) break;
  }
  ::manisoft::detail::fail(path, ": PLY header has no 'end_header' line");
}

/// Reads a mesh file into parts in file coordinates (node transforms applied).
inline std::vector<RawPart> read_mesh_file(const std::string& path, std::uintmax_t max_bytes) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) ::manisoft::detail::fail("cannot open mesh file '", path, "': ", ec.message());
  if (size == 0) ::manisoft::detail::fail(path, ": empty file");
  if (size > max_bytes) ::manisoft::detail::fail(path, ": file of ", size, " bytes exceeds the limit of ", max_bytes);
  const std::string ext = lower_extension(path);
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb" && ext != ".stl" && ext != ".ply") {
    ::manisoft::detail::fail(path, ": unsupported extension '", ext, "' (obj, gltf, glb, stl, ply)");
  }
  if (ext == ".ply") check_ply_header(path, size);
  // Read without post-processing, check the raw data (assimp's own steps assume consistent
  // meshes), then triangulate, join identical vertices and generate missing normals.
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* read = importer.ReadFile(path, 0);
  if (read == nullptr) ::manisoft::detail::fail(path, ": cannot read mesh: ", importer.GetErrorString());
  if (read->mRootNode == nullptr || read->mNumMeshes == 0 || read->mMeshes == nullptr) {
    ::manisoft::detail::fail(path, ": no meshes in the file");
  }
  for (unsigned mi = 0; mi < read->mNumMeshes; ++mi) {
    aiMesh* mesh = read->mMeshes[mi];  // owned by the importer; fixed up in place
    if (mesh == nullptr) ::manisoft::detail::fail(path, ": mesh ", mi, " is missing");
    if (mesh->mNumVertices == 0 || mesh->mVertices == nullptr) ::manisoft::detail::fail(path, ": mesh ", mi, " has no vertices");
    if (mesh->mNumFaces == 0 || mesh->mFaces == nullptr) ::manisoft::detail::fail(path, ": mesh ", mi, " has no faces");
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ::manisoft::detail::fail(path, ": mesh ", mi, " vertex ", v, " has a non-finite coordinate (", p.x, ", ", p.y, ", ", p.z, ")");
      }
    }
    unsigned types = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 0 || face.mIndices == nullptr) ::manisoft::detail::fail(path, ": mesh ", mi, " face ", f, " has no vertices");
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= mesh->mNumVertices) {
          ::manisoft::detail::fail(path, ": mesh ", mi, " face ", f, " refers to vertex ", face.mIndices[k], " of ", mesh->mNumVertices);
        }
      }
      types |= face.mNumIndices == 1 ? aiPrimitiveType_POINT
             : face.mNumIndices == 2 ? aiPrimitiveType_LINE
             : face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE
                                     : aiPrimitiveType_POLYGON;
    }
    mesh->mPrimitiveTypes = types;
    if (mesh->mNormals != nullptr) {
      bool finite = true;
      for (unsigned v = 0; v < mesh->mNumVertices && finite; ++v) {
        const aiVector3D& n = mesh->mNormals[v];
        finite = std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z);
      }
      if (!finite) {  // regenerated below
        delete[] mesh->mNormals;
        mesh->mNormals = nullptr;
      }
    }
  }
  const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_SortByPType;
  const aiScene* scene = importer.ApplyPostProcessing(flags);
  if (scene == nullptr) ::manisoft::detail::fail(path, ": invalid mesh data: ", importer.GetErrorString());
  if (scene->mRootNode == nullptr) ::manisoft::detail::fail(path, ": incomplete scene (no nodes)");
  std::vector<RawPart> parts;
  collect_parts(*scene, *scene->mRootNode, Eigen::Matrix4d::Identity(), path, parts, 0);
  if (parts.empty()) ::manisoft::detail::fail(path, ": no triangles in the file");
  return parts;
}

inline std::string nearest_color_name(const Eigen::Vector3f& rgb) {
  struct Named {
    const char* name;
    float r, g, b;
  };
  static const std::array<Named, 12> table{{{"red", 0.8f, 0.1f, 0.1f},
                                            {"green", 0.1f, 0.6f, 0.15f},
                                            {"blue", 0.1f, 0.2f, 0.8f},
                                            {"yellow", 0.9f, 0.8f, 0.1f},
                                            {"orange", 0.95f, 0.45f, 0.05f},
                                            {"purple", 0.5f, 0.15f, 0.6f},
                                            {"pink", 0.95f, 0.5f, 0.65f},
                                            {"brown", 0.45f, 0.28f, 0.12f},
                                            {"black", 0.05f, 0.05f, 0.05f},
                                            {"white", 0.92f, 0.92f, 0.92f},
                                            {"gray", 0.5f, 0.5f, 0.5f},
                                            {"cyan", 0.1f, 0.7f, 0.8f}}};
  const Named* best = &table[0];
  float best_d = 1e9f;
  for (const auto& n : table) {
    const float d = (rgb - Eigen::Vector3f(n.r, n.g, n.b)).squaredNorm();
    if (d < best_d) best_d = d, best = &n;
  }
  return best->name;
}

/// Parameters t of the crossings of the line p + t d with the triangles (Moller-Trumbore).
inline std::vector<double> line_crossings(const std::vector<geometry::Triangle3>& tris, const Eigen::Vector3d& p,
                                          const Eigen::Vector3d& d) {
  std::vector<double> ts;
  for (const auto& t : tris) {
    const Eigen::Vector3d e1 = t[1] - t[0], e2 = t[2] - t[0];
    const Eigen::Vector3d h = d.cross(e2);
    const double a = e1.dot(h);
    if (std::abs(a) < 1e-15) continue;
    const Eigen::Vector3d s = p - t[0];
    const double u = s.dot(h) / a;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / a;
    if (v < 0 || u + v > 1) continue;
    ts.push_back(e2.dot(q) / a);
  }
  return ts;
}

inline geometry::ConvexMesh<double> hull_or_fail(const std::vector<Eigen::Vector3d>& pts, const std::string& what) {
  return geometry::convex_hull(pts, what);
}

inline geometry::Shape<double> make_collision(std::vector<geometry::ConvexMesh<double>> pieces) {
  if (pieces.size() == 1) return geometry::Shape<double>{std::move(pieces.front())};
  geometry::Compound<double> compound;
  for (auto& piece : pieces) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& v : piece.vertices) c += v;
    c /= static_cast<double>(piece.vertices.size());
    for (auto& v : piece.vertices) v -= c;
    geometry::CompoundPart<double> part;
    part.position = c;
    part.shape = std::move(piece);
    compound.parts.push_back(std::move(part));
  }
  return geometry::Shape<double>{std::move(compound)};
}

inline double mesh_volume(const geometry::ConvexMesh<double>& m) {
  std::vector<geometry::Triangle3> tris;
  for (const auto& t : m.triangles) tris.push_back({m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]});
  return std::abs(geometry::signed_volume(tris));
}

}  // namespace detail

namespace detail {

inline ImportResult import_asset_unchecked(const std::string& mesh_path, const std::optional<Sidecar>& sidecar,
                                           const ImportOptions& options) {
  using Vec3 = Eigen::Vector3d;
  std::vector<detail::RawPart> parts = detail::read_mesh_file(mesh_path, options.max_file_bytes);
  const Sidecar side = sidecar ? *sidecar : Sidecar{};
  const std::string ext = detail::lower_extension(mesh_path);
  const bool gltf = ext == ".gltf" || ext == ".glb";

  // ---- file -> asset transform
  detail::FileToAsset map;
  if (side.scale) map.scale = *side.scale;
  map.up = detail::up_rotation(side.up_axis ? *side.up_axis : (gltf ? Vec3::UnitY() : Vec3::UnitZ()));
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& p : parts) {
    for (const auto& v : p.positions) {
      const Vec3 a = map.point(v);
      lo = lo.cwiseMin(a);
      hi = hi.cwiseMax(a);
    }
  }
  const Vec3 extent = hi - lo;
  if (!extent.allFinite() || extent.maxCoeff() > options.max_size) {
    ::manisoft::detail::fail(mesh_path, ": size ", extent.transpose(), " m exceeds ", options.max_size,
                             " m (wrong units? set \"scale\" in the sidecar)");
  }
  if (!(extent.maxCoeff() >= options.min_size)) {
    ::manisoft::detail::fail(mesh_path, ": size ", extent.transpose(), " m is below ", options.min_size,
                             " m (wrong units? set \"scale\" in the sidecar)");
  }
  if (!side.keep_origin) map.shift = Vec3(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z());
  const Eigen::Matrix3d normal_map = (map.up * map.scale.cwiseInverse().asDiagonal()).eval();
  const bool mirrored = map.scale.prod() < 0;

  ImportResult result;
  Asset& asset = result.asset;
  ImportReport& report = result.report;
  report.sidecar = side.path;
  report.file_to_asset.topLeftCorner<3, 3>() = map.up * map.scale.asDiagonal();
  report.file_to_asset.topRightCorner<3, 1>() = -map.shift;

  // ---- visual parts and the welded solid
  std::vector<Vec3> welded;
  std::map<std::tuple<double, double, double>, std::uint32_t> weld_index;
  std::vector<std::array<std::uint32_t, 3>> solid_tris;
  std::vector<geometry::Triangle3> solid;
  for (std::size_t pi = 0; pi < parts.size(); ++pi) {
    auto& raw = parts[pi];
    VisualPart part;
    part.name = raw.name.empty() ? "part" + std::to_string(pi) : raw.name;
    part.material = raw.material;
    part.material_name = side.material_name.value_or("plastic");
    part.color_name = detail::nearest_color_name(raw.material.base_color);
    std::vector<std::uint32_t> local_weld(raw.positions.size());
    for (std::size_t v = 0; v < raw.positions.size(); ++v) {
      const Vec3 a = map.point(raw.positions[v]);
      part.mesh.positions.push_back(a.cast<float>());
      Vec3 n = raw.normals.empty() ? Vec3::UnitZ() : Vec3(normal_map * raw.normals[v]);
      n = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
      part.mesh.normals.push_back(n.cast<float>());
      if (!raw.uvs.empty()) part.mesh.uvs.push_back(raw.uvs[v]);
      const auto key = std::make_tuple(a.x(), a.y(), a.z());
      auto it = weld_index.find(key);
      if (it == weld_index.end()) {
        it = weld_index.emplace(key, static_cast<std::uint32_t>(welded.size())).first;
        welded.push_back(a);
      }
      local_weld[v] = it->second;
    }
    for (auto t : raw.triangles) {
      if (mirrored) std::swap(t[1], t[2]);
      for (auto idx : t) part.mesh.indices.push_back(idx);
      const std::array<std::uint32_t, 3> w{local_weld[t[0]], local_weld[t[1]], local_weld[t[2]]};
      if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;  // collapsed triangle: no area
      solid_tris.push_back(w);
      solid.push_back({welded[w[0]], welded[w[1]], welded[w[2]]});
    }
    asset.attributes.parts.push_back(part.name);
    asset.visual.push_back(std::move(part));
  }
  report.vertices = welded.size();
  report.triangles = solid_tris.size();
  if (solid_tris.empty()) ::manisoft::detail::fail(mesh_path, ": every triangle is degenerate (zero area)");

  // ---- solid volume, hull
  double volume = geometry::signed_volume(solid);
  report.closed = geometry::is_closed(solid_tris) && std::abs(volume) > 0;
  if (report.closed && volume < 0) {  // inside-out file: flip every triangle
    for (auto& t : solid) std::swap(t[1], t[2]);
    for (auto& t : solid_tris) std::swap(t[1], t[2]);
    volume = -volume;
  }
  geometry::ConvexMesh<double> hull;
  try {
    hull = geometry::convex_hull(welded, mesh_path);
  } catch (const ::manisoft::Error& e) {
    ::manisoft::detail::fail(mesh_path, ": the mesh is flat or degenerate, it encloses no volume (", e.what(), ")");
  }
  report.hull_volume = detail::mesh_volume(hull);
  // A closed surface is used as the solid only when its integrals describe a real body: volume
  // within its hull's, inertia positive with l1 + l2 >= l3. Otherwise (self-intersecting or
  // overlapping shells) the convex hull stands in, and the report says why.
  geometry::MassProperties<double> mesh_unit;  // density 1
  if (report.closed) {
    report.mesh_volume = volume;
    std::string problem;
    if (volume > report.hull_volume * (1 + 1e-6)) {
      problem = "the closed surface's volume exceeds its convex hull's (overlapping or self-intersecting shells)";
    } else if (volume < 1e-9 * report.hull_volume) {
      problem = "the closed surface encloses almost no volume";
    } else {
      geometry::ConvexMesh<double> as_mesh;  // mass_properties integrates any closed oriented surface
      as_mesh.vertices = welded;
      as_mesh.triangles = solid_tris;
      as_mesh.source = mesh_path;
      mesh_unit = geometry::mass_properties(as_mesh, 1.0);
      const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mesh_unit.inertia).eigenvalues();
      if (!l.allFinite() || !(l[0] > 0) || l[0] + l[1] < l[2] * (1 - 1e-9)) {
        problem = "the closed surface's inertia is not that of a real body (self-intersecting surface)";
      }
    }
    if (!problem.empty()) {
      report.closed = false;
      report.mesh_volume = 0;
      report.note = problem + ": the convex hull and its mass properties are used";
    }
  } else {
    report.note = "open surface: the convex hull and its mass properties are used";
  }

  // ---- collision
  std::vector<geometry::ConvexMesh<double>> pieces;
  auto to_asset_points = [&](const std::vector<Vec3>& pts, bool in_mesh_frame) {
    std::vector<Vec3> out;
    for (const auto& p : pts) out.push_back(in_mesh_frame ? map.point(p) : p);
    return out;
  };
  if (side.decomposition) {
    const auto& dec = *side.decomposition;
    for (const auto& f : dec.files) {
      std::vector<Vec3> pts;
      for (const auto& p : detail::read_mesh_file(f, options.max_file_bytes)) {
        for (const auto& v : p.positions) pts.push_back(map.point(v));
      }
      pieces.push_back(detail::hull_or_fail(pts, f));
    }
    for (std::size_t pi = 0; pi < parts.size(); ++pi) {
      const bool listed = dec.all_mesh_parts || std::find(dec.mesh_parts.begin(), dec.mesh_parts.end(), parts[pi].mesh_index) != dec.mesh_parts.end();
      if (!listed) continue;
      std::vector<Vec3> pts;
      for (const auto& v : parts[pi].positions) pts.push_back(map.point(v));
      pieces.push_back(detail::hull_or_fail(pts, mesh_path + " mesh " + std::to_string(parts[pi].mesh_index)));
    }
    for (int m : dec.mesh_parts) {
      const bool exists = std::any_of(parts.begin(), parts.end(), [&](const detail::RawPart& p) { return p.mesh_index == m; });
      if (!exists) ::manisoft::detail::fail(side.path, ": convex_decomposition mesh_parts: mesh ", m, " does not exist in ", mesh_path);
    }
    for (std::size_t i = 0; i < dec.point_sets.size(); ++i) {
      pieces.push_back(detail::hull_or_fail(to_asset_points(dec.point_sets[i], side.annotation_in_mesh_frame),
                                            side.path + " point set " + std::to_string(i)));
    }
    if (pieces.empty()) ::manisoft::detail::fail(side.path, ": convex_decomposition lists no piece");
    report.collision_method = "sidecar decomposition";
  } else if (!report.closed || report.hull_volume - volume <= options.convex_tolerance * volume) {
    pieces.push_back(hull);
    report.collision_method = "hull";
  } else {
    pieces = geometry::approximate_convex_decomposition(solid, mesh_path, options.decomposition);
    report.collision_method = "decomposition";
  }
  for (const auto& p : pieces) report.collision_volume += detail::mesh_volume(p);
  report.convex_pieces = pieces.size();
  asset.collision = detail::make_collision(pieces);

  // ---- mass properties
  const geometry::MassProperties<double> unit =
      report.closed ? mesh_unit : geometry::mass_properties(asset.collision, 1.0);
  const double density = side.mass ? *side.mass / unit.mass : side.density.value_or(options.default_density);
  const geometry::MassProperties<double> mp = unit.scaled(density);
  if (!(mp.mass > 0) || !std::isfinite(mp.mass) || !mp.inertia.allFinite() || !mp.center_of_mass.allFinite()) {
    ::manisoft::detail::fail(mesh_path, ": mass properties are not finite (mass ", mp.mass, " kg)");
  }
  asset.mass = mp.mass;
  asset.center_of_mass = mp.center_of_mass;
  asset.inertia = mp.inertia;
  asset.friction = side.friction.value_or(asset.friction);

  // ---- identity, attributes, bounding box
  const std::string stem = std::filesystem::path(mesh_path).stem().string();
  asset.category = side.category.value_or(stem);
  asset.id = side.id.value_or(asset.category + "/" + stem);
  asset.kind = side.kind.value_or(AssetKind::object);
  asset.source = mesh_path;
  asset.attributes.color_rgb = side.color_rgb.value_or(asset.visual.front().material.base_color);
  asset.attributes.color_name = side.color_name.value_or(detail::nearest_color_name(asset.attributes.color_rgb));
  asset.attributes.material_name = side.material_name.value_or("plastic");
  if (side.color_name && !asset.visual.empty()) asset.visual.front().color_name = *side.color_name;
  Vec3 blo = Vec3::Constant(std::numeric_limits<double>::infinity()), bhi = -blo;
  for (const auto& v : welded) blo = blo.cwiseMin(v), bhi = bhi.cwiseMax(v);
  asset.bounding_center = 0.5 * (blo + bhi);
  asset.bounding_half_extents = 0.5 * (bhi - blo);
  const double largest = (bhi - blo).maxCoeff();
  asset.attributes.size = side.size.value_or(largest < 0.08 ? SizeClass::small : largest < 0.2 ? SizeClass::medium : SizeClass::large);

  // ---- annotations
  auto frame_of = [&](const SidecarPose& p, bool in_mesh_frame) {
    return in_mesh_frame ? map.frame(p.rotation, p.position) : math::Pose<double>{p.rotation, p.position};
  };
  auto width_at = [&](const math::Pose<double>& grasp) {
    const Vec3 closing = grasp.rotation.col(0);
    const Vec3 contact = grasp.translation + options.grasp_depth * grasp.rotation.col(2);
    std::vector<double> ts = detail::line_crossings(solid, contact, closing);
    double width = 0;
    if (ts.size() >= 2) {
      width = *std::max_element(ts.begin(), ts.end()) - *std::min_element(ts.begin(), ts.end());
    } else {
      double a = std::numeric_limits<double>::infinity(), b = -a;
      for (const auto& v : hull.vertices) a = std::min(a, closing.dot(v)), b = std::max(b, closing.dot(v));
      width = b - a;
    }
    return std::min(width, options.gripper_open_width);
  };
  auto complete = [&](const math::Pose<double>& grasp, const std::optional<math::Pose<double>>& approach,
                      const std::optional<math::Pose<double>>& lift, std::optional<double> width) {
    GraspAnnotation g;
    g.grasp = grasp;
    g.approach = approach.value_or(math::Pose<double>{grasp.rotation, grasp.translation - options.approach_distance * grasp.rotation.col(2)});
    g.lift = lift.value_or(math::Pose<double>{grasp.rotation, grasp.translation + options.lift_height * Vec3::UnitZ()});
    g.width = width ? std::min(*width, options.gripper_open_width) : width_at(grasp);
    return g;
  };
  for (const auto& sg : side.grasps) {
    const bool mf = side.annotation_in_mesh_frame;
    std::optional<math::Pose<double>> approach, lift;
    if (sg.approach) approach = frame_of(*sg.approach, mf);
    if (sg.lift) lift = frame_of(*sg.lift, mf);
    asset.grasps.push_back(complete(frame_of(sg.grasp, mf), approach, lift, sg.width));
  }
  if (side.robotwin) {
    const auto& rt = *side.robotwin;
    Eigen::Matrix3d conversion;  // our gripper axes in the RoboTwin contact frame: x = z_C, y = -x_C, z = -y_C
    conversion << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    for (const auto& c : rt.contact_points) {
      const math::Pose<double> contact = map.frame(c.topLeftCorner<3, 3>(), c.topRightCorner<3, 1>());
      math::Pose<double> grasp{contact.rotation * conversion, contact.translation};
      grasp.translation -= options.grasp_depth * grasp.rotation.col(2);
      asset.grasps.push_back(complete(grasp, std::nullopt, std::nullopt, std::nullopt));
    }
    for (const auto& m : rt.functional_points) report.robotwin.functional.push_back(map.frame(m.topLeftCorner<3, 3>(), m.topRightCorner<3, 1>()));
    for (const auto& m : rt.target_points) report.robotwin.target.push_back(map.frame(m.topLeftCorner<3, 3>(), m.topRightCorner<3, 1>()));
    if (rt.orientation_point) report.robotwin.orientation = map.frame(rt.orientation_point->topLeftCorner<3, 3>(), rt.orientation_point->topRightCorner<3, 1>());
    report.robotwin.stable = rt.stable;
  }
  if (asset.kind == AssetKind::obstacle) asset.grasps.clear();
  for (const auto& r : side.resting_poses) {
    RestingPose rest;
    rest.name = r.name;
    rest.orientation = r.orientation;
    rest.height = r.height;
    asset.resting_poses.push_back(rest);
  }
  if (asset.resting_poses.empty() && !side.keep_origin) asset.resting_poses.push_back(RestingPose{Eigen::Quaterniond::Identity(), 0.0, "upright"});
  for (const auto& r : side.receptacles) {
    Receptacle rec;
    rec.opening = frame_of(r.opening, side.annotation_in_mesh_frame);
    rec.inner_radius = r.inner_radius;
    rec.inner_half_extents = r.inner_half_extents;
    rec.inner_depth = r.inner_depth;
    rec.placement = r.placement ? frame_of(*r.placement, side.annotation_in_mesh_frame)
                                : math::Pose<double>{Eigen::Matrix3d::Identity(), rec.opening.translation - r.inner_depth * rec.opening.rotation.col(2)};
    asset.receptacles.push_back(rec);
  }
  for (const auto& g : asset.grasps) {
    if (!g.grasp.is_finite() || !g.approach.is_finite() || !g.lift.is_finite() || !std::isfinite(g.width)) {
      ::manisoft::detail::fail(mesh_path, ": a grasp annotation is not finite");
    }
  }
  return result;
}

}  // namespace detail

/// Imports `mesh_path` with the sidecar `sidecar` (already parsed; pass std::nullopt for none).
/// Every failure, including those of the libraries underneath, is a manisoft::Error naming the file.
inline ImportResult import_asset(const std::string& mesh_path, const std::optional<Sidecar>& sidecar,
                                 const ImportOptions& options = {}) {
  try {
    return detail::import_asset_unchecked(mesh_path, sidecar, options);
  } catch (const ::manisoft::Error&) {
    throw;
  } catch (const std::exception& e) {
    ::manisoft::detail::fail(mesh_path, ": import failed: ", e.what());
  }
}

/// The sidecar that belongs to `mesh_path` when none is named: `<stem>.json` beside it, else (for
/// RoboTwin-OD's `base<N>.glb`) `model_data<N>.json`; "" when neither exists.
inline std::string find_sidecar(const std::string& mesh_path) {
  const std::filesystem::path p(mesh_path);
  const std::filesystem::path same = p.parent_path() / (p.stem().string() + ".json");
  if (std::filesystem::exists(same)) return same.string();
  const std::string stem = p.stem().string();
  if (stem.rfind("base", 0) == 0) {
    const std::filesystem::path rt = p.parent_path() / ("model_data" + stem.substr(4) + ".json");
    if (std::filesystem::exists(rt)) return rt.string();
  }
  return "";
}

/// Imports `mesh_path` with the sidecar at `sidecar_path` ("" = look for one with find_sidecar).
inline ImportResult import_asset(const std::string& mesh_path, const std::string& sidecar_path = "",
                                 const ImportOptions& options = {}) {
  std::optional<Sidecar> side;
  try {
    const std::string path = sidecar_path.empty() ? find_sidecar(mesh_path) : sidecar_path;
    if (!path.empty()) side = load_sidecar(path);
  } catch (const ::manisoft::Error&) {
    throw;
  } catch (const std::exception& e) {
    ::manisoft::detail::fail(sidecar_path, ": cannot read the sidecar: ", e.what());
  }
  return import_asset(mesh_path, side, options);
}

}  // namespace manisoft::assets
