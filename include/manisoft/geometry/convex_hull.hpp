// 3-D convex hull of a point set (Quickhull: C. B. Barber, D. P. Dobkin, H. Huhdanpaa, "The
// Quickhull algorithm for convex hulls", ACM TOMS 22(4), 1996), used to build the collision
// shapes of imported meshes (geometry::ConvexMesh). Each point is assigned to the outside set of
// one face; the farthest outside point of a face is added by deleting the faces it sees and
// joining it to their horizon. A point counts as outside a face when it lies more than
// `tolerance` above its plane (tolerance relative to the point cloud's size), so near-coplanar
// points are absorbed, not added as slivers. The result is checked to be a closed 2-manifold
// (every edge shared by exactly two faces, Euler characteristic 2) whose faces all keep every
// input point within the tolerance; otherwise, and for fewer than 4 points, non-finite points
// or a flat (coplanar or collinear) set, manisoft::Error is thrown.
#pragma once

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/shapes.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

namespace manisoft::geometry {

/// Convex hull of `points` as a closed triangle mesh, outward (counter-clockwise seen from outside)
/// winding, only the hull's vertices kept. `source` names the input in error messages.
/// `relative_tolerance` times the bounding-box diagonal is the distance below which a point counts
/// as on a face plane.
inline ConvexMesh<double> convex_hull(const std::vector<Eigen::Vector3d>& points, const std::string& source = "points",
                                      double relative_tolerance = 1e-9) {
  using Vec3 = Eigen::Vector3d;
  const std::size_t n = points.size();
  if (n < 4) ::manisoft::detail::fail("convex hull of '", source, "': needs at least 4 points, got ", n);
  if (n > std::numeric_limits<std::uint32_t>::max() / 2) {
    ::manisoft::detail::fail("convex hull of '", source, "': too many points (", n, ")");
  }
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (std::size_t i = 0; i < n; ++i) {
    if (!points[i].allFinite()) {
      ::manisoft::detail::fail("convex hull of '", source, "': point ", i, " is not finite (", points[i].transpose(), ")");
    }
    lo = lo.cwiseMin(points[i]);
    hi = hi.cwiseMax(points[i]);
  }
  const double diagonal = (hi - lo).norm();
  const double magnitude = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  const double eps = std::max(relative_tolerance * diagonal, 16.0 * std::numeric_limits<double>::epsilon() * magnitude);
  if (!(diagonal > 0)) ::manisoft::detail::fail("convex hull of '", source, "': all ", n, " points coincide");

  // ---- initial tetrahedron: extreme pair along the widest axis, then farthest from the line, then from the plane.
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  std::uint32_t i0 = 0, i1 = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (points[i][axis] < points[i0][axis]) i0 = i;
    if (points[i][axis] > points[i1][axis]) i1 = i;
  }
  const Vec3 dir01 = (points[i1] - points[i0]).normalized();
  std::uint32_t i2 = i0;
  double best = -1;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d = (points[i] - points[i0]).cross(dir01).norm();
    if (d > best) best = d, i2 = i;
  }
  if (best <= eps) ::manisoft::detail::fail("convex hull of '", source, "': the ", n, " points are collinear (zero volume)");
  const Vec3 normal012 = (points[i1] - points[i0]).cross(points[i2] - points[i0]).normalized();
  std::uint32_t i3 = i0;
  best = -1;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d = std::abs((points[i] - points[i0]).dot(normal012));
    if (d > best) best = d, i3 = i;
  }
  if (best <= eps) ::manisoft::detail::fail("convex hull of '", source, "': the ", n, " points are coplanar (zero volume)");

  struct Face {
    std::array<std::uint32_t, 3> v;
    Vec3 normal;
    double offset;
    std::vector<std::uint32_t> outside;
    bool alive = true;
  };
  std::vector<Face> faces;
  std::unordered_map<std::uint64_t, std::uint32_t> edge_owner;  // directed edge (a, b) -> face
  auto key = [](std::uint32_t a, std::uint32_t b) { return (static_cast<std::uint64_t>(a) << 32) | b; };
  auto add_face = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    Face f;
    f.v = {a, b, c};
    const Vec3 cross = (points[b] - points[a]).cross(points[c] - points[a]);
    const double norm = cross.norm();
    f.normal = norm > 0 ? Vec3(cross / norm) : Vec3::Zero();
    f.offset = f.normal.dot(points[a]);
    const auto index = static_cast<std::uint32_t>(faces.size());
    faces.push_back(std::move(f));
    edge_owner[key(a, b)] = index;
    edge_owner[key(b, c)] = index;
    edge_owner[key(c, a)] = index;
    return index;
  };
  {
    // Orient so that i3 lies below (0, 1, 2).
    const bool below = (points[i3] - points[i0]).dot(normal012) < 0;
    const std::uint32_t a = i0, b = below ? i1 : i2, c = below ? i2 : i1;
    add_face(a, b, c);
    add_face(a, i3, b);
    add_face(b, i3, c);
    add_face(c, i3, a);
  }
  // Outside sets: each point goes to the first face it is above.
  for (std::uint32_t i = 0; i < n; ++i) {
    if (i == i0 || i == i1 || i == i2 || i == i3) continue;
    for (auto& f : faces) {
      if (f.normal.dot(points[i]) - f.offset > eps) {
        f.outside.push_back(i);
        break;
      }
    }
  }

  std::vector<std::uint32_t> stack;
  std::vector<std::uint32_t> visible;
  std::vector<std::uint32_t> visit_stamp;  // per face: the iteration that found it visible
  std::vector<std::uint32_t> pending;      // faces that may have outside points
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    if (!faces[f].outside.empty()) pending.push_back(f);
  }
  std::vector<std::array<std::uint32_t, 2>> horizon;
  std::vector<std::uint32_t> orphans;
  std::size_t iterations = 0;
  const std::size_t max_iterations = 4 * n + 16;
  while (!pending.empty()) {
    const std::uint32_t fi = pending.back();
    pending.pop_back();
    if (!faces[fi].alive || faces[fi].outside.empty()) continue;
    if (++iterations > max_iterations) {
      ::manisoft::detail::fail("convex hull of '", source, "': did not converge after ", max_iterations, " steps");
    }
    // Farthest outside point of this face.
    std::uint32_t eye = faces[fi].outside.front();
    double far = -1;
    for (auto p : faces[fi].outside) {
      const double d = faces[fi].normal.dot(points[p]) - faces[fi].offset;
      if (d > far) far = d, eye = p;
    }
    // Faces the eye sees: flood fill over edge neighbours.
    const auto stamp = static_cast<std::uint32_t>(iterations);
    visit_stamp.resize(faces.size(), 0);
    visible.clear();
    stack.assign(1, fi);
    visit_stamp[fi] = stamp;
    horizon.clear();
    while (!stack.empty()) {
      const std::uint32_t f = stack.back();
      stack.pop_back();
      visible.push_back(f);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = faces[f].v[static_cast<std::size_t>(k)];
        const std::uint32_t b = faces[f].v[static_cast<std::size_t>((k + 1) % 3)];
        const auto it = edge_owner.find(key(b, a));
        if (it == edge_owner.end()) {
          ::manisoft::detail::fail("convex hull of '", source, "': lost an edge (numerically degenerate input)");
        }
        const std::uint32_t g = it->second;
        if (visit_stamp[g] == stamp) continue;
        if (faces[g].normal.dot(points[eye]) - faces[g].offset > eps) {
          visit_stamp[g] = stamp;
          stack.push_back(g);
        } else {
          horizon.push_back({a, b});
        }
      }
    }
    orphans.clear();
    for (auto f : visible) {
      faces[f].alive = false;
      for (int k = 0; k < 3; ++k) {
        edge_owner.erase(key(faces[f].v[static_cast<std::size_t>(k)], faces[f].v[static_cast<std::size_t>((k + 1) % 3)]));
      }
      for (auto p : faces[f].outside) {
        if (p != eye) orphans.push_back(p);
      }
      faces[f].outside.clear();
      faces[f].outside.shrink_to_fit();
    }
    const auto first_new = static_cast<std::uint32_t>(faces.size());
    for (const auto& e : horizon) add_face(e[0], e[1], eye);
    for (auto p : orphans) {
      for (std::uint32_t g = first_new; g < faces.size(); ++g) {
        if (faces[g].normal.dot(points[p]) - faces[g].offset > eps) {
          faces[g].outside.push_back(p);
          break;
        }
      }
    }
    for (std::uint32_t g = first_new; g < faces.size(); ++g) {
      if (!faces[g].outside.empty()) pending.push_back(g);
    }
  }

  // ---- compact, then check the result.
  ConvexMesh<double> hull;
  hull.source = source;
  std::vector<std::uint32_t> remap(n, std::numeric_limits<std::uint32_t>::max());
  std::size_t face_count = 0;
  for (const auto& f : faces) {
    if (!f.alive) continue;
    ++face_count;
    std::array<std::uint32_t, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = f.v[static_cast<std::size_t>(k)];
      if (remap[v] == std::numeric_limits<std::uint32_t>::max()) {
        remap[v] = static_cast<std::uint32_t>(hull.vertices.size());
        hull.vertices.push_back(points[v]);
      }
      t[static_cast<std::size_t>(k)] = remap[v];
    }
    hull.triangles.push_back(t);
  }
  const std::size_t directed_edges = 3 * face_count;
  const long long euler = static_cast<long long>(hull.vertices.size()) - static_cast<long long>(directed_edges / 2) +
                          static_cast<long long>(face_count);
  if (edge_owner.size() != directed_edges || euler != 2) {
    ::manisoft::detail::fail("convex hull of '", source, "': result is not a closed convex surface (",
                             hull.vertices.size(), " vertices, ", face_count, " faces): numerically degenerate input");
  }
  for (const auto& [k, f] : edge_owner) {
    const auto a = static_cast<std::uint32_t>(k >> 32), b = static_cast<std::uint32_t>(k & 0xffffffffu);
    if (edge_owner.find(key(b, a)) == edge_owner.end() || !faces[f].alive) {
      ::manisoft::detail::fail("convex hull of '", source, "': open edge in the result: numerically degenerate input");
    }
  }
  return hull;
}

}  // namespace manisoft::geometry
