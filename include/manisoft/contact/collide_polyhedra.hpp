// Separating-axis test with face clipping between two convex polyhedra (boxes, convex meshes): a
// multi-point contact manifold, which FCL's GJK/EPA (one point per pair) cannot give. Axes
// tested: the face normals of both shapes and the cross products of their unique edge directions;
// the best axis is the one of largest separation, with face axes preferred over edge axes unless
// an edge axis is clearly better (a face manifold is what keeps a resting box flat).
// Face case: the incident face (most anti-parallel to the reference normal) is clipped against the
// side planes of the reference face (Sutherland-Hodgman); points within the margin are kept and
// reduced to the 4 that span the largest area. Edge case: the closest points of the two edges.
#pragma once

#include "manisoft/geometry/convex_polyhedron.hpp"
#include "manisoft/contact/segment_geometry.hpp"

#include <limits>

namespace manisoft::contact {

/// Reusable buffers so that steady-state narrow phase does not allocate.
struct PolyhedronScratch {
  std::vector<Vec3> other_vertices;
  std::vector<Vec3> polygon, clipped;
  std::vector<double> depths;
};

namespace detail {

/// Keeps at most 4 of `count` points: the deepest, the farthest from it, then the two that make
/// the largest triangles on either side of that pair (normal `n`).
inline void reduce_to_four(const std::vector<Vec3>& pts, const std::vector<double>& sep, const Vec3& n,
                           std::array<std::size_t, 4>& keep, int& kept) {
  const std::size_t count = pts.size();
  if (count <= 4) {
    kept = static_cast<int>(count);
    for (std::size_t i = 0; i < count; ++i) keep[i] = i;
    return;
  }
  std::size_t i1 = 0;
  for (std::size_t i = 1; i < count; ++i) if (sep[i] < sep[i1] - 1e-12) i1 = i;
  std::size_t i2 = i1;
  double best = -1;
  for (std::size_t i = 0; i < count; ++i) {
    const double d = (pts[i] - pts[i1]).squaredNorm();
    if (d > best) { best = d; i2 = i; }
  }
  std::size_t i3 = i1, i4 = i1;
  double area_pos = 0, area_neg = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const double area = (pts[i1] - pts[i]).cross(pts[i2] - pts[i]).dot(n);
    if (area > area_pos) { area_pos = area; i3 = i; }
    if (area < area_neg) { area_neg = area; i4 = i; }
  }
  kept = 0;
  keep[static_cast<std::size_t>(kept++)] = i1;
  if (i2 != i1) keep[static_cast<std::size_t>(kept++)] = i2;
  if (i3 != i1) keep[static_cast<std::size_t>(kept++)] = i3;
  if (i4 != i1) keep[static_cast<std::size_t>(kept++)] = i4;
}

/// Clips the incident polygon (already in the reference shape's frame) against the reference
/// face's side planes; fills `scratch.polygon` with the surviving points.
inline void clip_against_face(const geometry::ConvexPolyhedron& ref, const geometry::PolyhedronFace& face, PolyhedronScratch& s) {
  for (std::uint32_t k = 0; k < face.count && !s.polygon.empty(); ++k) {
    const Vec3& v0 = ref.vertices[ref.face_vertices[face.first + k]];
    const Vec3& v1 = ref.vertices[ref.face_vertices[face.first + (k + 1) % face.count]];
    const Vec3 side = (v1 - v0).cross(face.normal);
    const double side_offset = side.dot(v0);
    s.clipped.clear();
    const std::size_t m = s.polygon.size();
    for (std::size_t i = 0; i < m; ++i) {
      const Vec3& a = s.polygon[i];
      const Vec3& b = s.polygon[(i + 1) % m];
      const double da = side.dot(a) - side_offset;
      const double db = side.dot(b) - side_offset;
      if (da <= 0) s.clipped.push_back(a);
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) s.clipped.push_back(a + (da / (da - db)) * (b - a));
    }
    std::swap(s.polygon, s.clipped);
  }
}

}  // namespace detail

/// Contacts between polyhedra `a` and `b` placed at `pose_a`, `pose_b`. Returns false (and leaves
/// `out` empty) when they are separated by more than `margin`.
inline bool collide_polyhedra(const geometry::ConvexPolyhedron& a, const Pose& pose_a, const geometry::ConvexPolyhedron& b,
                              const Pose& pose_b, double margin, ContactSet& out, PolyhedronScratch& s) {
  out.clear();
  // Work in A's frame: B's placement relative to A.
  const Mat3 rot = pose_a.rotation.transpose() * pose_b.rotation;
  const Vec3 trans = pose_a.rotation.transpose() * (pose_b.translation - pose_a.translation);
  s.other_vertices.resize(b.vertices.size());
  for (std::size_t i = 0; i < b.vertices.size(); ++i) s.other_vertices[i] = rot * b.vertices[i] + trans;
  const auto& bv = s.other_vertices;

  double sep_a = -std::numeric_limits<double>::infinity();
  std::size_t face_a = 0;
  for (std::size_t f = 0; f < a.faces.size(); ++f) {
    double lo = std::numeric_limits<double>::infinity();
    for (const auto& v : bv) lo = std::min(lo, a.faces[f].normal.dot(v));
    const double sep = lo - a.faces[f].offset;
    if (sep > margin) return false;
    if (sep > sep_a) { sep_a = sep; face_a = f; }
  }
  double sep_b = -std::numeric_limits<double>::infinity();
  std::size_t face_b = 0;
  for (std::size_t f = 0; f < b.faces.size(); ++f) {
    const Vec3 n = rot * b.faces[f].normal;
    const double offset = b.faces[f].offset + n.dot(trans);
    double lo = std::numeric_limits<double>::infinity();
    for (const auto& u : a.vertices) lo = std::min(lo, n.dot(u));
    const double sep = lo - offset;
    if (sep > margin) return false;
    if (sep > sep_b) { sep_b = sep; face_b = f; }
  }
  double sep_e = -std::numeric_limits<double>::infinity();
  Vec3 axis_e = Vec3::UnitZ();
  std::size_t dir_a = 0, dir_b = 0;
  for (std::size_t i = 0; i < a.directions.size(); ++i) {
    for (std::size_t j = 0; j < b.directions.size(); ++j) {
      Vec3 c = a.directions[i].cross(rot * b.directions[j]);
      const double len = c.norm();
      if (len < 1e-6) continue;
      c /= len;
      double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo, b_hi = -a_lo;
      for (const auto& u : a.vertices) { const double x = c.dot(u); a_lo = std::min(a_lo, x); a_hi = std::max(a_hi, x); }
      for (const auto& v : bv) { const double x = c.dot(v); b_lo = std::min(b_lo, x); b_hi = std::max(b_hi, x); }
      const double sep_pos = b_lo - a_hi, sep_neg = a_lo - b_hi;
      const double sep = std::max(sep_pos, sep_neg);
      if (sep > margin) return false;
      if (sep > sep_e) { sep_e = sep; axis_e = sep_pos >= sep_neg ? c : Vec3(-c); dir_a = i; dir_b = j; }
    }
  }

  auto edge_contact = [&]() {
    // Supporting edges of A (max along axis) and of B (min along axis) with the chosen directions.
    double best_a = -std::numeric_limits<double>::infinity(), best_b = std::numeric_limits<double>::infinity();
    std::size_t ea = 0, eb = 0;
    for (std::size_t e = 0; e < a.edges.size(); ++e) {
      if (a.edge_direction[e] != dir_a) continue;
      const double x = axis_e.dot(a.vertices[a.edges[e][0]] + a.vertices[a.edges[e][1]]);
      if (x > best_a) { best_a = x; ea = e; }
    }
    for (std::size_t e = 0; e < b.edges.size(); ++e) {
      if (b.edge_direction[e] != dir_b) continue;
      const double x = axis_e.dot(bv[b.edges[e][0]] + bv[b.edges[e][1]]);
      if (x < best_b) { best_b = x; eb = e; }
    }
    const auto cp = closest_segment_segment(a.vertices[a.edges[ea][0]], a.vertices[a.edges[ea][1]],
                                            bv[b.edges[eb][0]], bv[b.edges[eb][1]]);
    out.normal = pose_a.rotation * axis_e;
    out.normal_owner = NormalOwner::shape_a;
    out.add(pose_a.act(0.5 * (cp.point_a + cp.point_b)), sep_e);
  };

  const double face_best = std::max(sep_a, sep_b);
  if (sep_e > face_best + 1e-4 + 0.05 * std::abs(face_best)) {
    edge_contact();
    return true;
  }

  // Face contact. Reference face on A (preferred on ties, for determinism) or on B.
  const bool ref_is_a = sep_a >= sep_b - 1e-9;
  const geometry::ConvexPolyhedron& ref = ref_is_a ? a : b;
  const geometry::ConvexPolyhedron& inc = ref_is_a ? b : a;
  const geometry::PolyhedronFace& rface = ref.faces[ref_is_a ? face_a : face_b];
  // Incident geometry in the reference frame.
  Mat3 inc_rot;
  Vec3 inc_trans;
  if (ref_is_a) {
    inc_rot = rot;
    inc_trans = trans;
  } else {
    inc_rot = rot.transpose();
    inc_trans = -(rot.transpose() * trans);
  }
  std::size_t inc_face = 0;
  double most_anti = std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < inc.faces.size(); ++f) {
    const double d = (inc_rot * inc.faces[f].normal).dot(rface.normal);
    if (d < most_anti - 1e-12) { most_anti = d; inc_face = f; }
  }
  s.polygon.clear();
  const auto& iface = inc.faces[inc_face];
  for (std::uint32_t k = 0; k < iface.count; ++k) {
    s.polygon.push_back(inc_rot * inc.vertices[inc.face_vertices[iface.first + k]] + inc_trans);
  }
  detail::clip_against_face(ref, rface, s);
  // Keep points within the margin.
  s.clipped.clear();
  s.depths.clear();
  for (const auto& p : s.polygon) {
    const double sep = rface.normal.dot(p) - rface.offset;
    if (sep <= margin) {
      s.clipped.push_back(p - 0.5 * sep * rface.normal);
      s.depths.push_back(sep);
    }
  }
  if (s.clipped.empty()) {
    if (sep_e > -std::numeric_limits<double>::infinity() && sep_e <= margin) edge_contact();
    return out.count > 0;
  }
  std::array<std::size_t, 4> keep{};
  int kept = 0;
  detail::reduce_to_four(s.clipped, s.depths, rface.normal, keep, kept);
  const Pose& ref_pose = ref_is_a ? pose_a : pose_b;
  const Vec3 n_world = ref_pose.rotation * rface.normal;
  out.normal = ref_is_a ? n_world : Vec3(-n_world);
  out.normal_owner = ref_is_a ? NormalOwner::shape_a : NormalOwner::shape_b;
  for (int k = 0; k < kept; ++k) {
    const std::size_t i = keep[static_cast<std::size_t>(k)];
    out.add(ref_pose.act(s.clipped[i]), s.depths[i]);
  }
  return true;
}

}  // namespace manisoft::contact
