// Signed distance between two convex shapes from their support mappings (convex_support.hpp):
// GJK (Gilbert, Johnson, Keerthi 1988) for the distance and closest points of separated shapes,
// EPA (expanding polytope, van den Bergen 2001) for the penetration depth and direction of
// overlapping ones. Both work on the Minkowski difference M = A - B, whose support point in
// direction d is s_A(d) - s_B(-d); the shapes' distance is the distance from the origin to M, and
// when the origin is inside M the penetration depth is its distance to the boundary of M.
// Spheres and capsules enter as their core (point, segment) and their radius is subtracted at the
// end. GJK: the closest point of the current simplex to the origin (Ericson, "Real-Time Collision
// Detection", 5.1.2 / 5.1.5 / 5.1.6 for segment, triangle, tetrahedron) gives v; the next vertex
// is w = s_M(-v); |v| - (v . w)/|v| bounds the distance error and stops the loop. EPA: start from
// GJK's final simplex grown into a tetrahedron around the origin, repeatedly split the face
// closest to the origin with the support point along its normal (visible faces removed, the
// horizon re-triangulated), until the support point is no farther than the face. Fixed-size
// arrays: no heap allocation.
#pragma once

#include "manisoft/contact/convex_support.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace manisoft::contact {

/// Signed distance of two convex shapes with their witness points.
struct ConvexDistance {
  double separation{0};             ///< signed distance of the true surfaces; < 0 = penetration depth
  Vec3 normal{Vec3::UnitZ()};       ///< unit, from A to B (B moves along it to separate)
  Vec3 point_a{Vec3::Zero()};       ///< on A's surface
  Vec3 point_b{Vec3::Zero()};       ///< on B's surface
  bool penetrating{false};          ///< the cores overlap (EPA answered)
};

namespace detail {

struct MinkowskiVertex {
  Vec3 w{Vec3::Zero()}, a{Vec3::Zero()}, b{Vec3::Zero()};  ///< w = a - b
};

inline MinkowskiVertex minkowski_support(const ConvexSupport& sa, const ConvexSupport& sb, const Vec3& d) {
  MinkowskiVertex v;
  v.a = sa.support(d);
  v.b = sb.support(-d);
  v.w = v.a - v.b;
  return v;
}

struct Simplex {
  std::array<MinkowskiVertex, 4> v{};
  std::array<double, 4> lambda{};  ///< barycentric weights of the closest point
  int count{0};
};

/// Closest point of triangle (a, b, c) to the origin (Ericson 5.1.5), as weights.
inline void closest_triangle(const Vec3& a, const Vec3& b, const Vec3& c, std::array<double, 3>& l) {
  const Vec3 ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) { l = {1, 0, 0}; return; }
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) { l = {0, 1, 0}; return; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    l = {1 - t, t, 0};
    return;
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) { l = {0, 0, 1}; return; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    l = {1 - t, 0, t};
    return;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    l = {0, 1 - t, t};
    return;
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  l = {1 - v - w, v, w};
}

/// Replaces the simplex by the smallest sub-simplex holding its closest point to the origin and
/// returns that point. Returns false when the origin is inside the tetrahedron (overlap).
inline bool reduce_simplex(Simplex& s, Vec3& closest) {
  auto keep_nonzero = [&](const std::array<int, 3>& idx, const std::array<double, 3>& l, int n) {
    Simplex out;
    for (int k = 0; k < n; ++k) {
      if (l[static_cast<std::size_t>(k)] > 0) {
        out.v[static_cast<std::size_t>(out.count)] = s.v[static_cast<std::size_t>(idx[static_cast<std::size_t>(k)])];
        out.lambda[static_cast<std::size_t>(out.count++)] = l[static_cast<std::size_t>(k)];
      }
    }
    s = out;
  };
  if (s.count == 1) {
    s.lambda[0] = 1;
  } else if (s.count == 2) {
    const Vec3& a = s.v[0].w;
    const Vec3 ab = s.v[1].w - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp(-a.dot(ab) / len2, 0.0, 1.0) : 0.0;
    keep_nonzero({0, 1, 0}, {1 - t, t, 0}, 2);
  } else if (s.count == 3) {
    std::array<double, 3> l{};
    closest_triangle(s.v[0].w, s.v[1].w, s.v[2].w, l);
    keep_nonzero({0, 1, 2}, l, 3);
  } else {
    // Tetrahedron (Ericson 5.1.6): the origin is outside a face when it lies on the other side of
    // the face's plane from the opposite vertex; the closest point is on one of those faces.
    static constexpr int faces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
    double best = std::numeric_limits<double>::infinity();
    std::array<int, 3> best_idx{};
    std::array<double, 3> best_l{};
    bool outside_any = false;
    for (const auto& f : faces) {
      const Vec3& a = s.v[static_cast<std::size_t>(f[0])].w;
      const Vec3& b = s.v[static_cast<std::size_t>(f[1])].w;
      const Vec3& c = s.v[static_cast<std::size_t>(f[2])].w;
      const Vec3& d = s.v[static_cast<std::size_t>(f[3])].w;
      const Vec3 n = (b - a).cross(c - a);
      const double so = -n.dot(a), sd = n.dot(d - a);
      const bool degenerate = sd * sd <= 1e-24 * n.squaredNorm() * (d - a).squaredNorm();
      if (!(so * sd < 0) && !degenerate) continue;
      outside_any = true;
      std::array<double, 3> l{};
      closest_triangle(a, b, c, l);
      const Vec3 p = l[0] * a + l[1] * b + l[2] * c;
      if (p.squaredNorm() < best) {
        best = p.squaredNorm();
        best_idx = {f[0], f[1], f[2]};
        best_l = l;
      }
    }
    if (!outside_any) {
      closest.setZero();
      return false;
    }
    keep_nonzero(best_idx, best_l, 3);
  }
  closest.setZero();
  for (int k = 0; k < s.count; ++k) closest += s.lambda[static_cast<std::size_t>(k)] * s.v[static_cast<std::size_t>(k)].w;
  return true;
}

struct EpaFace {
  std::array<int, 3> i{};
  Vec3 n{Vec3::Zero()};
  double dist{0};
  bool live{false};
};

/// EPA on the cores; `s` is GJK's final simplex (origin in or on it). Fills depth (>= 0), the unit
/// direction B moves along to separate, and the core witness points. False if degenerate.
inline bool expanding_polytope(const ConvexSupport& sa, const ConvexSupport& sb, Simplex s, double& depth, Vec3& normal,
                               Vec3& pa, Vec3& pb) {
  constexpr int kMaxVertices = 96, kMaxFaces = 256, kMaxEdges = 128;
  constexpr double eps = 1e-12;
  // Grow the simplex into a tetrahedron holding the origin.
  if (s.count == 1) {
    for (int k = 0; k < 6 && s.count < 2; ++k) {
      Vec3 d = Vec3::Zero();
      d[k / 2] = k % 2 ? -1.0 : 1.0;
      const auto v = minkowski_support(sa, sb, d);
      if ((v.w - s.v[0].w).squaredNorm() > eps * eps) s.v[static_cast<std::size_t>(s.count++)] = v;
    }
  }
  if (s.count == 2) {
    const Vec3 line = (s.v[1].w - s.v[0].w).normalized();
    const Vec3 e1 = (std::abs(line.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY()).cross(line).normalized();
    const Vec3 e2 = line.cross(e1);
    for (int k = 0; k < 6 && s.count < 3; ++k) {
      const double angle = k * std::numbers::pi / 3.0;
      const auto v = minkowski_support(sa, sb, std::cos(angle) * e1 + std::sin(angle) * e2);
      if ((v.w - s.v[0].w).cross(line).squaredNorm() > eps * eps) s.v[static_cast<std::size_t>(s.count++)] = v;
    }
  }
  if (s.count == 3) {
    const Vec3 n = (s.v[1].w - s.v[0].w).cross(s.v[2].w - s.v[0].w);
    if (!(n.squaredNorm() > 0)) return false;
    for (const double sign : {1.0, -1.0}) {
      const auto v = minkowski_support(sa, sb, sign * n);
      if (std::abs(n.normalized().dot(v.w - s.v[0].w)) > eps) {
        s.v[3] = v;
        s.count = 4;
        break;
      }
    }
  }
  if (s.count != 4) return false;

  std::array<MinkowskiVertex, kMaxVertices> verts;
  std::array<EpaFace, kMaxFaces> faces;
  std::array<std::array<int, 2>, kMaxEdges> edges;
  int nv = 4, nf = 0;
  for (int k = 0; k < 4; ++k) verts[static_cast<std::size_t>(k)] = s.v[static_cast<std::size_t>(k)];
  const Vec3 centroid = 0.25 * (verts[0].w + verts[1].w + verts[2].w + verts[3].w);
  auto make_face = [&](int i0, int i1, int i2) {
    EpaFace f;
    f.i = {i0, i1, i2};
    const Vec3& a = verts[static_cast<std::size_t>(i0)].w;
    const Vec3 n = (verts[static_cast<std::size_t>(i1)].w - a).cross(verts[static_cast<std::size_t>(i2)].w - a);
    const double len = n.norm();
    f.live = true;
    if (len > 1e-300) {
      f.n = n / len;
      f.dist = f.n.dot(a);
    } else {
      f.n = Vec3::Zero();
      f.dist = std::numeric_limits<double>::infinity();  // sliver: never the closest
    }
    return f;
  };
  static constexpr int tetra[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  for (const auto& t : tetra) {
    EpaFace f = make_face(t[0], t[1], t[2]);
    if (f.n.dot(verts[static_cast<std::size_t>(t[0])].w - centroid) < 0) f = make_face(t[0], t[2], t[1]);
    faces[static_cast<std::size_t>(nf++)] = f;
  }
  int closest = 0;
  for (int iter = 0; iter < 128; ++iter) {
    closest = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < nf; ++k) {
      const auto& f = faces[static_cast<std::size_t>(k)];
      if (f.live && f.dist < best) { best = f.dist; closest = k; }
    }
    if (closest < 0) return false;
    const EpaFace f = faces[static_cast<std::size_t>(closest)];
    const auto v = minkowski_support(sa, sb, f.n);
    const double gain = f.n.dot(v.w) - f.dist;
    if (gain <= 1e-10 + 1e-9 * std::abs(f.dist) || nv == kMaxVertices) break;
    // Remove the faces the new vertex sees; their unshared edges form the horizon.
    int ne = 0;
    bool overflow = false;
    for (int k = 0; k < nf; ++k) {
      auto& g = faces[static_cast<std::size_t>(k)];
      if (!g.live || !(g.n.dot(v.w - verts[static_cast<std::size_t>(g.i[0])].w) > 1e-14)) continue;
      g.live = false;
      for (int e = 0; e < 3; ++e) {
        const int a = g.i[static_cast<std::size_t>(e)], b = g.i[static_cast<std::size_t>((e + 1) % 3)];
        int found = -1;
        for (int m = 0; m < ne; ++m) {
          if (edges[static_cast<std::size_t>(m)][0] == b && edges[static_cast<std::size_t>(m)][1] == a) { found = m; break; }
        }
        if (found >= 0) {
          edges[static_cast<std::size_t>(found)] = edges[static_cast<std::size_t>(--ne)];
        } else if (ne < kMaxEdges) {
          edges[static_cast<std::size_t>(ne++)] = {a, b};
        } else {
          overflow = true;
        }
      }
    }
    if (overflow) return false;
    // Compact the face list, then add the horizon fan.
    int live = 0;
    for (int k = 0; k < nf; ++k) {
      if (faces[static_cast<std::size_t>(k)].live) faces[static_cast<std::size_t>(live++)] = faces[static_cast<std::size_t>(k)];
    }
    nf = live;
    if (nf + ne > kMaxFaces) {
      // Out of room: answer with the face we have (its distance is a lower bound within `gain`).
      faces[static_cast<std::size_t>(nf)] = f;
      closest = nf++;
      break;
    }
    const int iv = nv++;
    verts[static_cast<std::size_t>(iv)] = v;
    for (int m = 0; m < ne; ++m) {
      faces[static_cast<std::size_t>(nf++)] = make_face(edges[static_cast<std::size_t>(m)][0], edges[static_cast<std::size_t>(m)][1], iv);
    }
    closest = -1;
  }
  if (closest < 0) {
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < nf; ++k) {
      const auto& g = faces[static_cast<std::size_t>(k)];
      if (g.live && g.dist < best) { best = g.dist; closest = k; }
    }
    if (closest < 0) return false;
  }
  const EpaFace& f = faces[static_cast<std::size_t>(closest)];
  if (!(f.n.squaredNorm() > 0.5)) return false;
  // Barycentric weights of the origin's projection on the closest face.
  const Vec3 p = f.dist * f.n;
  const auto& v0 = verts[static_cast<std::size_t>(f.i[0])];
  const auto& v1 = verts[static_cast<std::size_t>(f.i[1])];
  const auto& v2 = verts[static_cast<std::size_t>(f.i[2])];
  const Vec3 e0 = v1.w - v0.w, e1 = v2.w - v0.w, e2 = p - v0.w;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = e2.dot(e0), d21 = e2.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  double l1 = 0, l2 = 0;
  if (den > 1e-300) {
    l1 = (d11 * d20 - d01 * d21) / den;
    l2 = (d00 * d21 - d01 * d20) / den;
  }
  const double l0 = 1 - l1 - l2;
  depth = std::max(f.dist, 0.0);
  normal = f.n;
  pa = l0 * v0.a + l1 * v1.a + l2 * v2.a;
  pb = l0 * v0.b + l1 * v1.b + l2 * v2.b;
  return true;
}

}  // namespace detail

/// Signed distance of shapes a and b. Returns false (no answer) when they are farther apart than
/// `max_separation` (checked against GJK's lower bound, so far pairs stop early).
inline bool convex_distance(const ConvexSupport& a, const ConvexSupport& b, double max_separation, ConvexDistance& out) {
  const double radii = a.core_radius() + b.core_radius();
  detail::Simplex s;
  Vec3 v = a.pose.translation - b.pose.translation;
  if (!(v.squaredNorm() > 1e-24)) v = Vec3::UnitX();
  bool overlap = false;
  {
    // First vertex along -v.
    s.v[0] = detail::minkowski_support(a, b, -v);
    s.count = 1;
    s.lambda[0] = 1;
    v = s.v[0].w;
  }
  for (int iter = 0; iter < 64; ++iter) {
    const double vv = v.squaredNorm();
    if (vv < 1e-24) { overlap = true; break; }  // touching cores: let EPA decide the direction
    const double vn = std::sqrt(vv);
    const auto w = detail::minkowski_support(a, b, -v);
    const double lower = v.dot(w.w) / vn;  // every point x of M has x . v/|v| >= lower
    if (lower - radii > max_separation) return false;
    if (vn - lower <= 1e-10 + 1e-9 * vn) break;  // converged
    bool duplicate = false;
    for (int k = 0; k < s.count; ++k) duplicate = duplicate || (s.v[static_cast<std::size_t>(k)].w - w.w).squaredNorm() < 1e-26;
    if (duplicate) break;
    const detail::Simplex previous = s;
    s.v[static_cast<std::size_t>(s.count++)] = w;
    Vec3 next;
    if (!detail::reduce_simplex(s, next)) { overlap = true; break; }
    if (next.squaredNorm() >= vv * (1.0 - 1e-14)) {  // no progress (round-off): keep what we had
      s = previous;
      break;
    }
    v = next;
  }
  if (!overlap) {
    Vec3 pa = Vec3::Zero(), pb = Vec3::Zero();
    for (int k = 0; k < s.count; ++k) {
      pa += s.lambda[static_cast<std::size_t>(k)] * s.v[static_cast<std::size_t>(k)].a;
      pb += s.lambda[static_cast<std::size_t>(k)] * s.v[static_cast<std::size_t>(k)].b;
    }
    const Vec3 d = pb - pa;
    const double dist = d.norm();
    if (dist > 1e-12) {
      out.normal = d / dist;
      out.separation = dist - radii;
      if (out.separation > max_separation) return false;
      out.point_a = pa + a.core_radius() * out.normal;
      out.point_b = pb - b.core_radius() * out.normal;
      out.penetrating = false;
      return true;
    }
  }
  double depth = 0;
  Vec3 n, pa, pb;
  if (!detail::expanding_polytope(a, b, s, depth, n, pa, pb)) {
    // Degenerate (flat) shapes: push apart along the centre line, zero depth.
    n = b.pose.translation - a.pose.translation;
    n = n.squaredNorm() > 1e-24 ? Vec3(n.normalized()) : Vec3::UnitZ();
    depth = 0;
    pa = a.support(n);
    pb = b.support(-n);
  }
  out.normal = n;
  out.separation = -depth - radii;
  out.point_a = pa + a.core_radius() * n;
  out.point_b = pb - b.core_radius() * n;
  out.penetrating = true;
  return true;
}

}  // namespace manisoft::contact
