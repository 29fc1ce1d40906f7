// Mesh import (assets/mesh_import.hpp, assets/sidecar.hpp) and the geometry underneath it
// (geometry/convex_hull.hpp, geometry/convex_decomposition.hpp). Fixture files are written by the
// test itself into a temporary folder; expectations are hand-computed volumes, masses and
// inertias, and the documented RoboTwin-OD frame mapping.
#include <catch2/catch.hpp>

#include "manisoft/assets/mesh_import.hpp"
#include "../support/scratch_dir.hpp"

#include <Eigen/Eigenvalues>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using manisoft::assets::import_asset;
using manisoft::assets::ImportResult;
using Vec3 = Eigen::Vector3d;

namespace {

fs::path temp_dir() { return manisoft::test::scratch_dir("manisoft_import_test"); }

std::string write(const std::string& name, const std::string& bytes) {
  const fs::path p = temp_dir() / name;
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return p.string();
}

struct TriMesh {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> f;
};

// Axis-aligned box [lo, hi], outward winding.
TriMesh box(const Vec3& lo, const Vec3& hi) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.v.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.f.push_back({q[0], q[1], q[2]});
    m.f.push_back({q[0], q[2], q[3]});
  }
  return m;
}

void append(TriMesh& a, const TriMesh& b) {
  const int base = static_cast<int>(a.v.size());
  a.v.insert(a.v.end(), b.v.begin(), b.v.end());
  for (auto t : b.f) a.f.push_back({t[0] + base, t[1] + base, t[2] + base});
}

std::string to_obj(const TriMesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "# test mesh\no body\n";
  for (const auto& v : m.v) s << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : m.f) s << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return s.str();
}

std::string to_ply_ascii(const TriMesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "ply\nformat ascii 1.0\nelement vertex " << m.v.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
    << "element face " << m.f.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : m.v) s << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const auto& t : m.f) s << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return s.str();
}

Vec3 face_normal(const TriMesh& m, const std::array<int, 3>& t) {
  return (m.v[static_cast<std::size_t>(t[1])] - m.v[static_cast<std::size_t>(t[0])])
      .cross(m.v[static_cast<std::size_t>(t[2])] - m.v[static_cast<std::size_t>(t[0])])
      .normalized();
}

std::string to_stl_ascii(const TriMesh& m) {
  std::ostringstream s;
  s.precision(9);
  s << "solid test\n";
  for (const auto& t : m.f) {
    const Vec3 n = face_normal(m, t);
    s << " facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n  outer loop\n";
    for (int k : t) {
      const Vec3& v = m.v[static_cast<std::size_t>(k)];
      s << "   vertex " << v.x() << " " << v.y() << " " << v.z() << "\n";
    }
    s << "  endloop\n endfacet\n";
  }
  s << "endsolid test\n";
  return s.str();
}

template <typename T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

std::string to_stl_binary(const TriMesh& m) {
  std::string s(80, ' ');
  put<std::uint32_t>(s, static_cast<std::uint32_t>(m.f.size()));
  for (const auto& t : m.f) {
    const Vec3 n = face_normal(m, t);
    for (int i = 0; i < 3; ++i) put<float>(s, static_cast<float>(n[i]));
    for (int k : t) {
      for (int i = 0; i < 3; ++i) put<float>(s, static_cast<float>(m.v[static_cast<std::size_t>(k)][i]));
    }
    put<std::uint16_t>(s, 0);
  }
  return s;
}

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const auto a = static_cast<unsigned char>(in[i]), b = static_cast<unsigned char>(in[i + 1]),
               c = static_cast<unsigned char>(in[i + 2]);
    out += table[a >> 2];
    out += table[((a & 3) << 4) | (b >> 4)];
    out += table[((b & 15) << 2) | (c >> 6)];
    out += table[c & 63];
  }
  if (i + 1 == in.size()) {
    const auto a = static_cast<unsigned char>(in[i]);
    out += table[a >> 2];
    out += table[(a & 3) << 4];
    out += "==";
  } else if (i + 2 == in.size()) {
    const auto a = static_cast<unsigned char>(in[i]), b = static_cast<unsigned char>(in[i + 1]);
    out += table[a >> 2];
    out += table[((a & 3) << 4) | (b >> 4)];
    out += table[(b & 15) << 2];
    out += '=';
  }
  return out;
}

// glTF 2.0 buffer: float32 positions then uint16 indices.
std::string gltf_buffer(const TriMesh& m) {
  std::string b;
  for (const auto& v : m.v) {
    for (int i = 0; i < 3; ++i) put<float>(b, static_cast<float>(v[i]));
  }
  for (const auto& t : m.f) {
    for (int k : t) put<std::uint16_t>(b, static_cast<std::uint16_t>(k));
  }
  while (b.size() % 4) b.push_back('\0');
  return b;
}

// glTF JSON: one mesh under a node with the given scale and translation, red material.
std::string gltf_json(const TriMesh& m, const std::string& buffer_uri, std::size_t buffer_bytes, double node_scale,
                      const Vec3& translation) {
  Vec3 lo = m.v[0], hi = m.v[0];
  for (const auto& v : m.v) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const std::size_t pos_bytes = 12 * m.v.size();
  std::ostringstream s;
  s.precision(9);
  s << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
    << R"("nodes":[{"mesh":0,"scale":[)" << node_scale << "," << node_scale << "," << node_scale << R"(],"translation":[)"
    << translation.x() << "," << translation.y() << "," << translation.z() << "]}],"
    << R"("meshes":[{"name":"body","primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],)"
    << R"("materials":[{"name":"red","pbrMetallicRoughness":{"baseColorFactor":[0.8,0.1,0.1,1.0]}}],)"
    << R"("buffers":[{"byteLength":)" << buffer_bytes;
  if (!buffer_uri.empty()) s << R"(,"uri":")" << buffer_uri << '"';
  s << "}],"
    << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << pos_bytes << R"(,"target":34962},)"
    << R"({"buffer":0,"byteOffset":)" << pos_bytes << R"(,"byteLength":)" << 6 * m.f.size() << R"(,"target":34963}],)"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << m.v.size() << R"(,"type":"VEC3","min":[)"
    << lo.x() << "," << lo.y() << "," << lo.z() << R"(],"max":[)" << hi.x() << "," << hi.y() << "," << hi.z() << "]},"
    << R"({"bufferView":1,"componentType":5123,"count":)" << 3 * m.f.size() << R"(,"type":"SCALAR"}]})";
  return s.str();
}

std::string to_gltf_embedded(const TriMesh& m, double node_scale, const Vec3& translation) {
  const std::string buffer = gltf_buffer(m);
  return gltf_json(m, "data:application/octet-stream;base64," + base64(buffer), buffer.size(), node_scale, translation);
}

std::string to_glb(const TriMesh& m, double node_scale, const Vec3& translation) {
  const std::string buffer = gltf_buffer(m);
  std::string json = gltf_json(m, "", buffer.size(), node_scale, translation);
  while (json.size() % 4) json.push_back(' ');
  std::string out;
  put<std::uint32_t>(out, 0x46546C67u);
  put<std::uint32_t>(out, 2);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + buffer.size()));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(json.size()));
  put<std::uint32_t>(out, 0x4E4F534Au);
  out += json;
  put<std::uint32_t>(out, static_cast<std::uint32_t>(buffer.size()));
  put<std::uint32_t>(out, 0x004E4942u);
  out += buffer;
  return out;
}

// L-shaped prism: the L polygon (0,0) (0.2,0) (0.2,0.1) (0.1,0.1) (0.1,0.2) (0,0.2) extruded 0.05 m
// along z. Area 0.03 m^2, volume 1.5e-3 m^3. Caps are fans from the reflex corner (0.1, 0.1).
TriMesh l_prism() {
  const std::vector<Eigen::Vector2d> poly{{0, 0}, {0.2, 0}, {0.2, 0.1}, {0.1, 0.1}, {0.1, 0.2}, {0, 0.2}};
  const double h = 0.05;
  TriMesh m;
  const int n = static_cast<int>(poly.size());
  for (const auto& p : poly) m.v.emplace_back(p.x(), p.y(), 0);
  for (const auto& p : poly) m.v.emplace_back(p.x(), p.y(), h);
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    m.f.push_back({k, k1, n + k1});
    m.f.push_back({k, n + k1, n + k});
  }
  const int reflex = 3;
  for (int k = 0; k < n; ++k) {
    const int a = (reflex + 1 + k) % n, b = (reflex + 2 + k) % n;
    if (a == reflex || b == reflex) continue;
    m.f.push_back({reflex, b, a});              // bottom, facing -z
    m.f.push_back({n + reflex, n + a, n + b});  // top, facing +z
  }
  return m;
}

constexpr double kMugOuter = 0.04, kMugInner = 0.035, kMugHeight = 0.10, kMugFloor = 0.01;
constexpr int kMugSegments = 24;

double polygon_area(double radius, int n) { return 0.5 * n * radius * radius * std::sin(2.0 * std::numbers::pi / n); }

// A mug: a cup (regular 24-gon walls of outer radius 0.04 m, inner 0.035 m, height 0.1 m, floor
// 0.01 m thick) and a handle of three boxes touching each other and the cup's outermost vertex.
TriMesh mug(double* volume) {
  TriMesh m;
  const int n = kMugSegments;
  auto ring = [&](double r, double z) {
    const int first = static_cast<int>(m.v.size());
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * k / n;
      m.v.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
    return first;
  };
  const int o0 = ring(kMugOuter, 0), o1 = ring(kMugOuter, kMugHeight), i1 = ring(kMugInner, kMugHeight),
            i0 = ring(kMugInner, kMugFloor);
  const int cb = static_cast<int>(m.v.size());
  m.v.emplace_back(0, 0, 0);
  const int cf = static_cast<int>(m.v.size());
  m.v.emplace_back(0, 0, kMugFloor);
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    m.f.push_back({cb, o0 + k1, o0 + k});
    m.f.push_back({o0 + k, o0 + k1, o1 + k1});
    m.f.push_back({o0 + k, o1 + k1, o1 + k});
    m.f.push_back({o1 + k, o1 + k1, i1 + k1});
    m.f.push_back({o1 + k, i1 + k1, i1 + k});
    m.f.push_back({i1 + k, i1 + k1, i0 + k1});
    m.f.push_back({i1 + k, i0 + k1, i0 + k});
    m.f.push_back({cf, i0 + k, i0 + k1});
  }
  const double x0 = kMugOuter, x1 = kMugOuter + 0.025, t = 0.008, w = 0.006;
  append(m, box(Vec3(x0, -w, 0.070), Vec3(x1, w, 0.080)));
  append(m, box(Vec3(x0, -w, 0.020), Vec3(x1, w, 0.030)));
  append(m, box(Vec3(x1, -w, 0.020), Vec3(x1 + t, w, 0.080)));
  const double a_out = polygon_area(kMugOuter, n), a_in = polygon_area(kMugInner, n);
  *volume = a_out * kMugFloor + (a_out - a_in) * (kMugHeight - kMugFloor) + 2 * (x1 - x0) * 2 * w * 0.01 +
            t * 2 * w * 0.06;
  return m;
}

double mesh_volume(const manisoft::geometry::ConvexMesh<double>& m) {
  double six = 0;
  for (const auto& t : m.triangles) six += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]]));
  return six / 6.0;
}

double collision_volume(const manisoft::geometry::Shape<double>& s) { return manisoft::geometry::shape_volume(s); }

/// Every piece of the collision shape as (points in the asset frame) for inside tests.
std::vector<manisoft::geometry::ConvexMesh<double>> pieces_in_asset_frame(const manisoft::geometry::Shape<double>& s) {
  std::vector<manisoft::geometry::ConvexMesh<double>> out;
  if (const auto* m = std::get_if<manisoft::geometry::ConvexMesh<double>>(&s)) out.push_back(*m);
  if (const auto* c = std::get_if<manisoft::geometry::Compound<double>>(&s)) {
    for (const auto& p : c->parts) {
      auto m = std::get<manisoft::geometry::ConvexMesh<double>>(p.shape);
      for (auto& v : m.vertices) v = p.orientation * v + p.position;
      out.push_back(m);
    }
  }
  return out;
}

bool inside_convex(const manisoft::geometry::ConvexMesh<double>& m, const Vec3& p) {
  for (const auto& t : m.triangles) {
    const Vec3 n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    if (n.dot(p - m.vertices[t[0]]) > 1e-12) return false;
  }
  return true;
}

void check_finite(const manisoft::assets::Asset& a) {
  REQUIRE(std::isfinite(a.mass));
  REQUIRE(a.mass > 0);
  REQUIRE(a.inertia.allFinite());
  REQUIRE(a.center_of_mass.allFinite());
  REQUIRE(a.bounding_half_extents.allFinite());
  REQUIRE(a.bounding_center.allFinite());
  REQUIRE(!a.visual.empty());
  for (const auto& part : a.visual) {
    for (const auto& p : part.mesh.positions) REQUIRE(p.allFinite());
    for (const auto& n : part.mesh.normals) REQUIRE(n.allFinite());
    for (auto idx : part.mesh.indices) REQUIRE(idx < part.mesh.positions.size());
  }
  for (const auto& piece : pieces_in_asset_frame(a.collision)) {
    REQUIRE(piece.vertices.size() >= 4);
    for (const auto& v : piece.vertices) REQUIRE(v.allFinite());
    REQUIRE(mesh_volume(piece) > 0);
  }
  for (const auto& g : a.grasps) {
    REQUIRE(g.grasp.is_finite());
    REQUIRE(std::isfinite(g.width));
  }
  // Inertia about the COM of a real body: symmetric, positive eigenvalues, triangle inequality.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a.inertia);
  const Eigen::Vector3d l = eig.eigenvalues();
  REQUIRE(l.minCoeff() > 0);
  REQUIRE(l[0] + l[1] >= l[2] * (1 - 1e-9));
}

}  // namespace

TEST_CASE("convex hull of a point cloud: the cube's corners, interior points dropped", "[import]") {
  std::vector<Vec3> pts;
  std::mt19937_64 rng(7);
  auto uniform = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  for (int i = 0; i < 8; ++i) pts.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  for (int i = 0; i < 500; ++i) pts.emplace_back(uniform(), uniform(), uniform());
  // points on the faces (coplanar with hull faces) must not become hull vertices
  for (int i = 0; i < 50; ++i) pts.emplace_back(uniform(), uniform(), 1.0);
  const auto hull = manisoft::geometry::convex_hull(pts, "cube cloud");
  CHECK(hull.vertices.size() == 8);
  CHECK(hull.triangles.size() == 12);
  CHECK(mesh_volume(hull) == Approx(1.0).epsilon(1e-12));
  for (const auto& p : pts) CHECK(inside_convex(hull, p + Vec3::Constant(1e-9) * 0.0));

  // Points on a sphere: all are hull vertices; the hull volume approaches 4/3 pi.
  std::vector<Vec3> sphere;
  for (int i = 0; i < 2000; ++i) {
    Vec3 v(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
    if (v.norm() < 1e-3) continue;
    sphere.push_back(v.normalized());
  }
  const auto sh = manisoft::geometry::convex_hull(sphere, "sphere");
  CHECK(sh.vertices.size() == sphere.size());
  CHECK(sh.triangles.size() == 2 * sphere.size() - 4);  // Euler, all triangles
  CHECK(mesh_volume(sh) == Approx(4.0 / 3.0 * std::numbers::pi).epsilon(0.01));

  CHECK_THROWS_AS(manisoft::geometry::convex_hull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}, "flat"),
                  manisoft::Error);
  CHECK_THROWS_AS(manisoft::geometry::convex_hull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, NAN)}, "nan"),
                  manisoft::Error);
}

TEST_CASE("a cube in every format: volume, mass, inertia, footprint origin", "[import]") {
  const double a = 0.1, density = 800.0;
  const TriMesh cube = box(Vec3(1.0, 2.0, 3.0), Vec3(1.1, 2.1, 3.1));
  const TriMesh cube_mm = box(Vec3(1000, 2000, 3000), Vec3(1100, 2100, 3100));
  const std::string side = write("cube.sidecar.json", R"({"density": 800, "friction": 0.4})");
  const std::string side_mm = write("cube_mm.json", R"({"density": 800, "scale": 0.001})");
  // glTF: a 0.05 m cube centred at 0, node scale 2 -> 0.1 m; y-up file.
  const TriMesh half = box(Vec3::Constant(-0.025), Vec3::Constant(0.025));
  struct Case {
    std::string file;
    std::string sidecar;
  };
  const std::vector<Case> cases{
      {write("cube.obj", to_obj(cube)), side},
      {write("cube.ply", to_ply_ascii(cube_mm)), side_mm},
      {write("cube_ascii.stl", to_stl_ascii(cube)), side},
      {write("cube_binary.stl", to_stl_binary(cube)), side},
      {write("cube.gltf", to_gltf_embedded(half, 2.0, Vec3(5, 6, 7))), side},
      {write("cube.glb", to_glb(half, 2.0, Vec3(5, 6, 7))), side},
  };
  for (const auto& c : cases) {
    INFO(c.file);
    const ImportResult r = import_asset(c.file, c.sidecar);
    const auto& asset = r.asset;
    check_finite(asset);
    CHECK(r.report.closed);
    CHECK(r.report.mesh_volume == Approx(a * a * a).epsilon(1e-5));
    CHECK(asset.mass == Approx(density * a * a * a).epsilon(1e-5));
    const double i_cube = asset.mass * (a * a + a * a) / 12.0;
    CHECK(asset.inertia(0, 0) == Approx(i_cube).epsilon(1e-4));
    CHECK(asset.inertia(1, 1) == Approx(i_cube).epsilon(1e-4));
    CHECK(asset.inertia(2, 2) == Approx(i_cube).epsilon(1e-4));
    CHECK(std::abs(asset.inertia(0, 1)) < 1e-9);
    // footprint origin: centred in x, y; resting on z = 0
    CHECK((asset.center_of_mass - Vec3(0, 0, a / 2)).norm() < 1e-6);
    CHECK((asset.bounding_half_extents - Vec3::Constant(a / 2)).norm() < 1e-6);
    CHECK((asset.bounding_center - Vec3(0, 0, a / 2)).norm() < 1e-6);
    // a convex mesh's collision shape is its own hull, one piece, same volume
    CHECK(r.report.collision_method == "hull");
    CHECK(r.report.convex_pieces == 1);
    REQUIRE(std::holds_alternative<manisoft::geometry::ConvexMesh<double>>(asset.collision));
    CHECK(std::get<manisoft::geometry::ConvexMesh<double>>(asset.collision).vertices.size() == 8);
    CHECK(collision_volume(asset.collision) == Approx(a * a * a).epsilon(1e-5));
    CHECK(asset.resting_poses.size() == 1);
    // every visual normal is a unit vector
    for (const auto& n : asset.visual.front().mesh.normals) CHECK(n.norm() == Approx(1.0).epsilon(1e-5));
  }
  // Friction from the sidecar; glTF material colour read (red base colour factor).
  CHECK(import_asset(cases[0].file, side).asset.friction == Approx(0.4));
  const auto gltf = import_asset(cases[4].file, side).asset;
  CHECK(gltf.attributes.color_rgb.x() == Approx(0.8f));
  CHECK(gltf.attributes.color_name == "red");
}

TEST_CASE("an L-shaped prism becomes >= 2 convex pieces whose volumes add up to the L's", "[import]") {
  const std::string file = write("l_shape.obj", to_obj(l_prism()));
  const std::string side = write("l_shape.json", R"({"mass": 3.0, "category": "bracket", "kind": "obstacle"})");
  const ImportResult r = import_asset(file, side);
  check_finite(r.asset);
  const double volume = 0.03 * 0.05;
  CHECK(r.report.closed);
  CHECK(r.report.mesh_volume == Approx(volume).epsilon(1e-6));
  CHECK(r.report.hull_volume == Approx((0.04 - 0.005) * 0.05).epsilon(1e-6));  // hull cuts the notch's diagonal
  CHECK(r.report.collision_method == "decomposition");
  CHECK(r.report.convex_pieces >= 2);
  CHECK(r.report.collision_volume == Approx(volume).epsilon(0.03));
  CHECK(collision_volume(r.asset.collision) == Approx(volume).epsilon(0.03));
  CHECK(r.asset.mass == Approx(3.0));
  CHECK(r.asset.category == "bracket");
  CHECK(r.asset.kind == manisoft::assets::AssetKind::obstacle);
  // The notch (the missing square's middle, moved with the footprint shift) is in no piece.
  const Vec3 notch = Vec3(0.15, 0.15, 0.025) - Vec3(0.1, 0.1, 0.0);
  for (const auto& piece : pieces_in_asset_frame(r.asset.collision)) CHECK(!inside_convex(piece, notch));
  // COM of the L (three unit squares of 0.1 m: centroid (0.0833, 0.0833) before the shift)
  CHECK((r.asset.center_of_mass - Vec3(0.25 / 3 - 0.1, 0.25 / 3 - 0.1, 0.025)).norm() < 1e-9);
}

TEST_CASE("a mug: concave, decomposed, the cavity stays free and the volume is kept", "[import]") {
  double volume = 0;
  const TriMesh m = mug(&volume);
  const std::string file = write("mug.obj", to_obj(m));
  const std::string side = write("mug.json", R"({"density": 1000, "attributes": {"color": "white", "material": "ceramic", "size": "small"}})");
  const ImportResult r = import_asset(file, side);
  check_finite(r.asset);
  CHECK(r.report.closed);
  CHECK(r.report.mesh_volume == Approx(volume).epsilon(1e-6));
  CHECK(r.asset.mass == Approx(1000 * volume).epsilon(1e-6));
  CHECK(r.report.collision_method == "decomposition");
  CHECK(r.report.convex_pieces >= 4);
  // footprint shift: the bounding box's x centre moves by (max x + min x) / 2
  const double shift_x = 0.5 * (kMugOuter + 0.025 + 0.008 - kMugOuter);
  const Vec3 cavity = Vec3(0 - shift_x, 0, 0.06);
  for (const auto& piece : pieces_in_asset_frame(r.asset.collision)) CHECK(!inside_convex(piece, cavity));
  // the hull's excess is bounded by the tolerances: within 25% of the true volume overall
  CHECK(r.report.collision_volume >= volume * (1 - 1e-6));
  CHECK(r.report.collision_volume <= volume * 1.25);
  CHECK(r.asset.attributes.color_name == "white");
  CHECK(r.asset.attributes.material_name == "ceramic");
  CHECK(r.asset.attributes.size == manisoft::assets::SizeClass::small);
  WARN("mug: " << r.report.convex_pieces << " pieces, collision volume / true volume = "
               << r.report.collision_volume / volume);
}

TEST_CASE("sidecar grasps, resting poses, receptacles and a given decomposition land in the Asset", "[import]") {
  const TriMesh cube = box(Vec3(0, 0, 0), Vec3(0.06, 0.06, 0.06));
  const std::string file = write("block.obj", to_obj(cube));
  // Quaternion [w x y z] = [0, 1, 0, 0]: 180 degrees about x (tool pointing down).
  const std::string side = write("block.json", R"({
    "id": "block/01", "name": "green block", "category": "block",
    "attributes": {"color": "green", "color_rgb": [0.1, 0.6, 0.1]},
    "density": 700,
    "grasps": [
      {"grasp": {"position": [0, 0, 0.115], "quaternion": [0, 1, 0, 0]},
       "approach": {"position": [0, 0, 0.2], "quaternion": [0, 1, 0, 0]},
       "lift": [[1,0,0,0],[0,-1,0,0],[0,0,-1,0.3],[0,0,0,1]],
       "width": 0.06},
      {"grasp": [1,0,0,0, 0,-1,0,0, 0,0,-1,0.115, 0,0,0,1]}
    ],
    "resting_poses": [{"name": "upright", "quaternion": [1, 0, 0, 0], "height": 0}],
    "receptacles": [{"opening": {"position": [0, 0, 0.06]}, "inner_radius": 0.02, "inner_depth": 0.03}],
    "convex_decomposition": {"point_sets": [
      [[-0.03,-0.03,0],[0.03,-0.03,0],[0.03,0.03,0],[-0.03,0.03,0],[-0.03,-0.03,0.03],[0.03,-0.03,0.03],[0.03,0.03,0.03],[-0.03,0.03,0.03]],
      [[-0.03,-0.03,0.03],[0.03,-0.03,0.03],[0.03,0.03,0.03],[-0.03,0.03,0.03],[-0.03,-0.03,0.06],[0.03,-0.03,0.06],[0.03,0.03,0.06],[-0.03,0.03,0.06]]]}
  })");
  const ImportResult r = import_asset(file, side);
  const auto& a = r.asset;
  check_finite(a);
  CHECK(a.id == "block/01");
  CHECK(a.attributes.color_name == "green");
  CHECK(a.attributes.color_rgb.y() == Approx(0.6f));
  REQUIRE(a.grasps.size() == 2);
  const Eigen::Matrix3d down = Eigen::Vector3d(1, -1, -1).asDiagonal();
  CHECK((a.grasps[0].grasp.translation - Vec3(0, 0, 0.115)).norm() < 1e-12);
  CHECK((a.grasps[0].grasp.rotation - down).norm() < 1e-12);
  CHECK((a.grasps[0].approach.translation - Vec3(0, 0, 0.2)).norm() < 1e-12);
  CHECK((a.grasps[0].lift.translation - Vec3(0, 0, 0.3)).norm() < 1e-12);
  CHECK(a.grasps[0].width == Approx(0.06));
  // second grasp: defaults. Approach 0.1 m back along -z of the grasp frame (= up), lift 0.1 m up,
  // width = the cube's extent along the closing axis through the contact point (0.06 m).
  CHECK((a.grasps[1].grasp.rotation - down).norm() < 1e-12);
  CHECK((a.grasps[1].approach.translation - Vec3(0, 0, 0.215)).norm() < 1e-12);
  CHECK((a.grasps[1].lift.translation - Vec3(0, 0, 0.215)).norm() < 1e-12);
  CHECK(a.grasps[1].width == Approx(0.06).epsilon(1e-6));
  REQUIRE(a.resting_poses.size() == 1);
  CHECK(a.resting_poses[0].name == "upright");
  REQUIRE(a.receptacles.size() == 1);
  CHECK(a.receptacles[0].inner_radius == Approx(0.02));
  CHECK((a.receptacles[0].placement.translation - Vec3(0, 0, 0.03)).norm() < 1e-12);
  CHECK(r.report.collision_method == "sidecar decomposition");
  CHECK(r.report.convex_pieces == 2);
  CHECK(collision_volume(a.collision) == Approx(0.06 * 0.06 * 0.06).epsilon(1e-6));
  CHECK(a.mass == Approx(700 * 0.06 * 0.06 * 0.06).epsilon(1e-6));
}

TEST_CASE("a RoboTwin-OD model_data annotation maps to the documented grasps", "[import]") {
  // A y-up GLB box of 2 x 1 x 1 file units (x from -1 to 1, y from 0 to 1, z from -0.5 to 0.5),
  // scale 0.05 -> 0.1 x 0.05 x 0.05 m. RoboTwin contact frame C: rows [[1,0,0],[0,0,-1],[0,1,0]]
  // at (0.5, 1, 0) (top face, file units): C's -y axis is file -z... rotated by the y-up turn.
  const TriMesh block = box(Vec3(-1, 0, -0.5), Vec3(1, 1, 0.5));
  fs::create_directories(temp_dir() / "robotwin" / "001_block");
  const std::string file = write("robotwin/001_block/base0.glb", to_glb(block, 1.0, Vec3::Zero()));
  write("robotwin/001_block/model_data0.json", R"({
    "center": [0, 0.5, 0], "extents": [2, 1, 1], "scale": [0.05, 0.05, 0.05], "stable": true,
    "contact_points_pose": [
      [[1, 0, 0, 0.5], [0, 0, -1, 1.0], [0, 1, 0, 0], [0, 0, 0, 1]],
      [1, 0, 0, -0.5, 0, 0, -1, 1.0, 0, 1, 0, 0, 0, 0, 0, 1]
    ],
    "functional_matrix": [[[1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]]],
    "target_pose": [[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]],
    "orientation_point": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
    "transform_matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
  })");
  const ImportResult r = import_asset(file);  // finds model_data0.json beside base0.glb
  const auto& a = r.asset;
  check_finite(a);
  CHECK(r.report.sidecar.find("model_data0.json") != std::string::npos);
  // y-up -> z-up (+90 deg about x): file (x, y, z) -> (x, -z, y); scaled 0.05; footprint origin.
  CHECK((a.bounding_half_extents - Vec3(0.05, 0.025, 0.025)).norm() < 1e-7);
  CHECK((a.bounding_center - Vec3(0, 0, 0.025)).norm() < 1e-7);
  REQUIRE(a.grasps.size() == 2);
  // Contact C: R_C columns x_C = (1,0,0), y_C = (0,0,1), z_C = (0,-1,0) in the file frame. After the
  // up turn R_up = [[1,0,0],[0,0,-1],[0,1,0]]: x_C -> (1,0,0), y_C -> (0,-1,0), z_C -> (0,0,-1).
  // Our gripper axes: x = z_C = (0,0,-1), y = -x_C = (-1,0,0), z = -y_C = (0,1,0): approach along +y.
  Eigen::Matrix3d expected;
  expected.col(0) = Vec3(0, 0, -1);
  expected.col(1) = Vec3(-1, 0, 0);
  expected.col(2) = Vec3(0, 1, 0);
  CHECK((a.grasps[0].grasp.rotation - expected).norm() < 1e-9);
  CHECK(a.grasps[0].grasp.rotation.determinant() == Approx(1.0));
  // Contact point: file (0.5, 1, 0) * 0.05 = (0.025, 0.05, 0) -> up turn (0.025, 0, 0.05) -> minus the
  // footprint shift (0, 0, -0.025)... file y in [0, 1] maps to z in [0, 0.05]: shift z = 0, x, y centred.
  const Vec3 contact(0.025, 0.0, 0.05);
  const manisoft::assets::ImportOptions defaults;
  CHECK((a.grasps[0].grasp.translation - (contact - defaults.grasp_depth * Vec3(0, 1, 0))).norm() < 1e-9);
  CHECK((a.grasps[0].approach.translation - (a.grasps[0].grasp.translation - 0.1 * Vec3(0, 1, 0))).norm() < 1e-9);
  CHECK((a.grasps[0].lift.translation - (a.grasps[0].grasp.translation + 0.1 * Vec3::UnitZ())).norm() < 1e-9);
  // The closing axis (asset z) through the contact point on the top face: a ray through the box's
  // top face hits the top and bottom: width 0.05 m.
  CHECK(a.grasps[0].width == Approx(0.05).epsilon(1e-6));
  CHECK((a.grasps[1].grasp.translation - a.grasps[0].grasp.translation - Vec3(-0.05, 0, 0)).norm() < 1e-9);
  // Functional point: file (0, 1, 0) * 0.05 -> (0, 0, 0.05) in the asset frame.
  REQUIRE(r.report.robotwin.functional.size() == 1);
  CHECK((r.report.robotwin.functional[0].translation - Vec3(0, 0, 0.05)).norm() < 1e-9);
  CHECK(r.report.robotwin.target.size() == 1);
  REQUIRE(r.report.robotwin.orientation.has_value());
  REQUIRE(r.report.robotwin.stable.has_value());
  CHECK(*r.report.robotwin.stable);
}

TEST_CASE("malformed input: errors name the file and the line or element", "[import]") {
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const manisoft::Error& e) {
      return e.what();
    }
    return "no error";
  };
  const TriMesh cube = box(Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1));
  const std::string good = write("good.obj", to_obj(cube));
  // JSON syntax error on line 3: line:column
  const std::string bad_json = write("bad.json", "{\n  \"mass\": 1.0,\n  \"friction\": ,\n}\n");
  std::string msg = message([&] { import_asset(good, bad_json); });
  CHECK(msg.find("bad.json:3:") != std::string::npos);
  // a number beyond the range of a double: refused as the file's error, not nlohmann's exception
  // (tests/fuzz/corpus/sidecar/number_overflow.json)
  msg = message([&] { manisoft::assets::parse_sidecar(R"({"density": 1e400})", "huge.json"); });
  CHECK(msg.find("huge.json: cannot be read") != std::string::npos);
  CHECK(msg.find("1e400") != std::string::npos);
  // wrong type: the element's JSON pointer
  const std::string wrong = write("wrong.json", R"({"grasps": [{"grasp": {"position": [0, 0, "x"]}}]})");
  msg = message([&] { import_asset(good, wrong); });
  CHECK(msg.find("/grasps/0/grasp/position/2") != std::string::npos);
  const std::string missing = write("missing.json", R"({"grasps": [{"approach": {"position": [0, 0, 1]}}]})");
  CHECK(message([&] { import_asset(good, missing); }).find("missing field 'grasp'") != std::string::npos);
  const std::string unknown = write("unknown.json", R"({"colour": "red"})");
  CHECK(message([&] { import_asset(good, unknown); }).find("unknown field 'colour'") != std::string::npos);
  // NaN vertex: mesh and vertex index
  std::string obj = to_obj(cube);
  obj.replace(obj.find("v 0 0 0"), 7, "v nan 0 0");
  msg = message([&] { import_asset(write("nan.obj", obj)); });
  CHECK(msg.find("nan.obj") != std::string::npos);
  // absurd size: a 100 m cube
  const std::string huge = write("huge.obj", to_obj(box(Vec3(0, 0, 0), Vec3(100, 100, 100))));
  CHECK(message([&] { import_asset(huge); }).find("exceeds 10") != std::string::npos);
  // flat mesh (zero volume)
  TriMesh flat;
  flat.v = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, 0.1, 0), Vec3(0, 0.1, 0)};
  flat.f = {{0, 1, 2}, {0, 2, 3}, {0, 2, 1}, {0, 3, 2}};
  CHECK(message([&] { import_asset(write("flat.obj", to_obj(flat))); }).find("flat.obj") != std::string::npos);
  // out-of-range index
  CHECK(message([&] { import_asset(write("index.obj", to_obj(cube) + "f 1 2 99\n")); }).find("index.obj") != std::string::npos);
  // missing file, unsupported extension
  CHECK(message([&] { import_asset((temp_dir() / "nope.obj").string()); }).find("nope.obj") != std::string::npos);
  CHECK(message([&] { import_asset(write("cube.xyz", "1 2 3")); }).find("unsupported extension") != std::string::npos);
}

TEST_CASE("fuzz: mutated files import into a finite asset or throw manisoft::Error", "[import]") {
  const TriMesh cube = box(Vec3(0, 0, 0), Vec3(0.1, 0.08, 0.06));
  struct Seed {
    std::string ext;
    std::string bytes;
  };
  const std::vector<Seed> seeds{{".obj", to_obj(l_prism())},
                                {".ply", to_ply_ascii(cube)},
                                {".stl", to_stl_binary(cube)},
                                {".stl", to_stl_ascii(cube)},
                                {".gltf", to_gltf_embedded(cube, 1.0, Vec3(0.1, 0, 0))},
                                {".glb", to_glb(cube, 1.0, Vec3::Zero())},
                                {".json", R"({"density": 700, "grasps": [{"grasp": {"position": [0, 0, 0.1], "quaternion": [0, 1, 0, 0]}, "width": 0.05}], "convex_decomposition": {"mesh_parts": "all"}})"}};
  const std::string sidecar_mesh = write("fuzz_base.obj", to_obj(cube));
  // Deterministic by default; MANISOFT_FUZZ_SEED / MANISOFT_FUZZ_ITERATIONS run longer campaigns locally.
  const char* seed_env = std::getenv("MANISOFT_FUZZ_SEED");
  const char* count_env = std::getenv("MANISOFT_FUZZ_ITERATIONS");
  const int iterations = count_env != nullptr ? std::max(1, std::atoi(count_env)) : 420;
  std::mt19937_64 rng(seed_env != nullptr ? std::strtoull(seed_env, nullptr, 10) : 20240611ull);
  auto below = [&](std::size_t n) { return n == 0 ? std::size_t{0} : static_cast<std::size_t>(rng() % n); };
  const std::vector<std::string> injections{"nan", "inf", "-inf", "1e300", "-1e308", "0", "1e-300", "999999999999", "-", "e", ""};
  int imported = 0, refused = 0;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    const Seed& seed = seeds[static_cast<std::size_t>(iteration) % seeds.size()];
    std::string bytes = seed.bytes;
    const int mutations = 1 + static_cast<int>(below(3));
    for (int m = 0; m < mutations && !bytes.empty(); ++m) {
      switch (below(6)) {
        case 0:  // byte flip
          bytes[below(bytes.size())] ^= static_cast<char>(1u << below(8));
          break;
        case 1:  // truncation
          bytes.resize(below(bytes.size()));
          break;
        case 2: {  // replace a number-like token with an injection
          std::size_t at = below(bytes.size());
          while (at < bytes.size() && !std::isdigit(static_cast<unsigned char>(bytes[at]))) ++at;
          std::size_t end = at;
          while (end < bytes.size() && (std::isdigit(static_cast<unsigned char>(bytes[end])) || bytes[end] == '.' || bytes[end] == 'e' || bytes[end] == '-')) ++end;
          if (at < bytes.size()) bytes.replace(at, end - at, injections[below(injections.size())]);
          break;
        }
        case 3: {  // delete a line
          const std::size_t at = below(bytes.size());
          const std::size_t start = bytes.rfind('\n', at);
          const std::size_t stop = bytes.find('\n', at);
          const std::size_t s0 = start == std::string::npos ? 0 : start;
          bytes.erase(s0, (stop == std::string::npos ? bytes.size() : stop) - s0);
          break;
        }
        case 4: {  // write a huge float into binary data
          const std::size_t at = below(bytes.size());
          const float values[4] = {NAN, INFINITY, 3e38f, -1e30f};
          const float v = values[below(4)];
          char raw[4];
          std::memcpy(raw, &v, 4);
          for (std::size_t k = 0; k < 4 && at + k < bytes.size(); ++k) bytes[at + k] = raw[k];
          break;
        }
        default: {  // degenerate: collapse a region by duplicating a chunk over another
          const std::size_t len = 1 + below(24);
          const std::size_t from = below(bytes.size()), to = below(bytes.size());
          for (std::size_t k = 0; k < len && from + k < bytes.size() && to + k < bytes.size(); ++k) bytes[to + k] = bytes[from + k];
          break;
        }
      }
    }
    const std::string name = "fuzz_" + std::to_string(iteration) + seed.ext;
    const std::string path = write(name, bytes);
    INFO("iteration " << iteration << " file " << path);
    try {
      const ImportResult r = seed.ext == ".json" ? import_asset(sidecar_mesh, path) : import_asset(path);
      check_finite(r.asset);
      ++imported;
    } catch (const manisoft::Error& e) {
      CHECK(std::string(e.what()).find(name) != std::string::npos);
      ++refused;
    }
    fs::remove(path);
  }
  WARN("fuzz: " << imported << " imported, " << refused << " refused");
  CHECK(imported + refused == iterations);
  CHECK(imported > 0);
  CHECK(refused > 0);
}
