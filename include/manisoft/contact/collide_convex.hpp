// Multi-point contacts of convex shapes on their true surfaces, for every pair with a cylinder and
// for sphere/capsule against a convex mesh:
//  1. the contact normal n (from A to B) and signed distance: analytic for a cylinder on a box face
//     (below) and for a cylinder's side against a cylinder's side, a capsule or a sphere (the
//     closest points of the axis segments, detail::side_contact), else GJK/EPA (gjk_epa.hpp);
//  2. the supporting features of A along n and of B along -n (convex_support.hpp: point, segment
//     or polygon);
//  3. the features clipped against each other in the plane perpendicular to n (polygon against
//     polygon: Sutherland-Hodgman; segment against polygon: Cyrus-Beck; parallel segments: their
//     overlap), each surviving point paired with the point of the other feature on the same line
//     along n: separation s = (p_B - p_A) . n, position midway. Points with s above the margin are
//     dropped and at most 4 kept (the deepest, the farthest from it, the largest triangles on
//     either side). So a cylinder standing on its cap gets a polygon of rim points, a cylinder
//     lying on its side two points at the ends of its contact line (it rolls with no facet bumps),
//     and a cylinder tilted on its rim one point, each at its exact depth.
// When the clipped points miss the deepest contact by more than 1 um (polygons inscribed in a rim,
// chords where two rims cross) the exact witness point (analytic or GJK/EPA) is added; when they
// are deeper than it (a badly chosen feature) it replaces them.
//
// Cylinder (centre c, unit axis a, radius r, half height h) on a box face, in the box frame
// (half extents H): the face i with outward normal n = sgn(c_i) e_i has separation
//   s_i = |c_i| - H_i - (h |a_i| + r sqrt(1 - a_i^2)),
// the second term being the cylinder's extent along n: its support point in direction -n is
//   c - h sgn(n.a) a - r (n - (n.a) a) / |n - (n.a) a|,
// whose distance below c along n is h |n.a| + r |n - (n.a) a| = h |a_i| + r sqrt(1 - a_i^2).
// The cap axis (separation |a.c| - h - sum_j H_j |a_j|) and the axes a x e_j (box edge against the
// cylinder's side, cylinder extent exactly r) are tested too. Every such separation is a lower
// bound of the true signed distance (separating-axis theorem), so any above the margin means no
// contact. When a face separation is the largest and the deepest part of the cylinder lies over
// the face (its support point projects into the face, or the clipped feature reaches that depth),
// it is the exact signed distance and n the exact normal; otherwise (edge and corner contacts)
// GJK/EPA answers.
#pragma once

#include "manisoft/contact/contact_manifold.hpp"
#include "manisoft/contact/gjk_epa.hpp"
#include "manisoft/contact/segment_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace manisoft::contact {

namespace detail {

inline double cross2(const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); }

/// Candidate contact points before reduction.
struct ClipPoints {
  static constexpr int kCapacity = 40;
  int count{0};
  std::array<Vec3, kCapacity> position{};
  std::array<double, kCapacity> separation{};
  void add(const Vec3& p, double s) {
    if (count < kCapacity) {
      position[static_cast<std::size_t>(count)] = p;
      separation[static_cast<std::size_t>(count++)] = s;
    }
  }
};

/// Plane (unit normal, point) of a polygon feature, Newell's method.
inline Vec3 polygon_normal(const SupportFeature& f) {
  Vec3 n = Vec3::Zero();
  for (int k = 0; k < f.count; ++k) {
    const Vec3& p = f.points[static_cast<std::size_t>(k)];
    const Vec3& q = f.points[static_cast<std::size_t>((k + 1) % f.count)];
    n += (p - q).cross(p + q);
  }
  return n.squaredNorm() > 0 ? Vec3(n.normalized()) : Vec3::Zero();
}

/// Point of feature `f` on the line x + t n (f a polygon: its plane; a segment: by projection in
/// the plane perpendicular to n). False if the line misses it (plane nearly parallel to n).
inline bool point_on_feature(const SupportFeature& f, const Vec3& plane_n, const Vec3& x, const Vec3& n,
                             const Vec3& t1, const Vec3& t2, Vec3& y) {
  if (f.count >= 3) {
    const double nm = n.dot(plane_n);
    if (std::abs(nm) < 0.1) return false;
    y = x + ((f.points[0] - x).dot(plane_n) / nm) * n;
    return true;
  }
  if (f.count == 2) {
    const Vec3 d = f.points[1] - f.points[0];
    const Eigen::Vector2d d2(d.dot(t1), d.dot(t2));
    const double len2 = d2.squaredNorm();
    if (!(len2 > 1e-24)) return false;
    const Vec3 e = x - f.points[0];
    const double t = std::clamp((e.dot(t1) * d2.x() + e.dot(t2) * d2.y()) / len2, 0.0, 1.0);
    y = f.points[0] + t * d;
    return true;
  }
  return false;
}

/// Clips the incident feature against the reference one (perpendicular to n) and pairs each kept
/// point with the reference feature. `incident_is_a`: the incident feature belongs to shape A.
inline void clip_features(const SupportFeature& ref, const SupportFeature& inc, bool incident_is_a, const Vec3& n,
                          double margin, ClipPoints& out) {
  Vec3 t1, t2;
  tangent_basis(n, t1, t2);
  auto to2 = [&](const Vec3& p) { return Eigen::Vector2d(p.dot(t1), p.dot(t2)); };
  const Vec3 ref_n = ref.count >= 3 ? polygon_normal(ref) : Vec3::Zero();
  auto emit = [&](const Vec3& x) {
    Vec3 y;
    if (!point_on_feature(ref, ref_n, x, n, t1, t2, y)) return;
    const double s = incident_is_a ? (y - x).dot(n) : (x - y).dot(n);
    if (s <= margin) out.add(0.5 * (x + y), s);
  };
  if (ref.count >= 3) {
    // Reference polygon in 2D with its winding.
    std::array<Eigen::Vector2d, SupportFeature::kCapacity> r2;
    double area = 0;
    for (int k = 0; k < ref.count; ++k) r2[static_cast<std::size_t>(k)] = to2(ref.points[static_cast<std::size_t>(k)]);
    for (int k = 0; k < ref.count; ++k) area += cross2(r2[static_cast<std::size_t>(k)], r2[static_cast<std::size_t>((k + 1) % ref.count)]);
    const double wind = area >= 0 ? 1.0 : -1.0;
    auto inside = [&](int k, const Vec3& p) {
      const auto& a = r2[static_cast<std::size_t>(k)];
      const auto& b = r2[static_cast<std::size_t>((k + 1) % ref.count)];
      return wind * cross2(b - a, to2(p) - a);
    };
    if (inc.count >= 3) {
      // Sutherland-Hodgman: the incident polygon (3D, planar) clipped edge by edge.
      std::array<Vec3, ClipPoints::kCapacity> poly, next;
      int m = inc.count;
      for (int k = 0; k < m; ++k) poly[static_cast<std::size_t>(k)] = inc.points[static_cast<std::size_t>(k)];
      for (int e = 0; e < ref.count && m > 0; ++e) {
        int q = 0;
        for (int i = 0; i < m; ++i) {
          const Vec3& a = poly[static_cast<std::size_t>(i)];
          const Vec3& b = poly[static_cast<std::size_t>((i + 1) % m)];
          const double da = inside(e, a), db = inside(e, b);
          if (da >= 0 && q < ClipPoints::kCapacity) next[static_cast<std::size_t>(q++)] = a;
          if (((da < 0 && db > 0) || (da > 0 && db < 0)) && q < ClipPoints::kCapacity) {
            next[static_cast<std::size_t>(q++)] = a + (da / (da - db)) * (b - a);
          }
        }
        poly = next;
        m = q;
      }
      for (int i = 0; i < m; ++i) emit(poly[static_cast<std::size_t>(i)]);
    } else if (inc.count == 2) {
      // Cyrus-Beck: the segment's parameter range inside every edge.
      const Vec3& p0 = inc.points[0];
      const Vec3 d = inc.points[1] - p0;
      double lo = 0, hi = 1;
      for (int e = 0; e < ref.count && lo <= hi; ++e) {
        const double f0 = inside(e, p0), f1 = inside(e, inc.points[1]);
        if (f0 < 0 && f1 < 0) { lo = 1; hi = 0; break; }
        if (f0 < 0) lo = std::max(lo, f0 / (f0 - f1));
        if (f1 < 0) hi = std::min(hi, f0 / (f0 - f1));
      }
      if (lo <= hi) {
        emit(p0 + lo * d);
        if (hi - lo > 1e-9) emit(p0 + hi * d);
      }
    }
    return;
  }
  if (ref.count == 2 && inc.count == 2) {
    // Two segments: their overlap when parallel in the plane perpendicular to n.
    const Vec3 da = inc.points[1] - inc.points[0];
    const Eigen::Vector2d a2 = to2(da), b2 = to2(ref.points[1] - ref.points[0]);
    const double la = a2.norm(), lb = b2.norm();
    if (la < 1e-12 || lb < 1e-12 || std::abs(cross2(a2, b2)) > 0.05 * la * lb) return;
    const Eigen::Vector2d o = to2(inc.points[0]);
    double t0 = (to2(ref.points[0]) - o).dot(a2) / (la * la), t1p = (to2(ref.points[1]) - o).dot(a2) / (la * la);
    if (t0 > t1p) std::swap(t0, t1p);
    t0 = std::max(t0, 0.0);
    t1p = std::min(t1p, 1.0);
    if (t1p - t0 < 1e-9) return;
    emit(inc.points[0] + t0 * da);
    emit(inc.points[0] + t1p * da);
  }
}

/// Keeps at most 4 points: the deepest, the farthest from it, the largest triangles on either
/// side of that pair.
inline void reduce_points(const ClipPoints& c, const Vec3& n, ContactSet& out) {
  if (c.count <= kMaxContactPoints) {
    for (int k = 0; k < c.count; ++k) out.add(c.position[static_cast<std::size_t>(k)], c.separation[static_cast<std::size_t>(k)]);
    return;
  }
  auto P = [&](int i) -> const Vec3& { return c.position[static_cast<std::size_t>(i)]; };
  int i1 = 0;
  for (int i = 1; i < c.count; ++i) if (c.separation[static_cast<std::size_t>(i)] < c.separation[static_cast<std::size_t>(i1)] - 1e-12) i1 = i;
  int i2 = i1;
  double best = -1;
  for (int i = 0; i < c.count; ++i) {
    const double d = (P(i) - P(i1)).squaredNorm();
    if (d > best) { best = d; i2 = i; }
  }
  int i3 = i1, i4 = i1;
  double pos = 0, neg = 0;
  for (int i = 0; i < c.count; ++i) {
    const double area = (P(i1) - P(i)).cross(P(i2) - P(i)).dot(n);
    if (area > pos) { pos = area; i3 = i; }
    if (area < neg) { neg = area; i4 = i; }
  }
  for (const int i : {i1, i2, i3, i4}) {
    bool seen = false;
    for (int k = 0; k < out.count; ++k) seen = seen || (out.points[static_cast<std::size_t>(k)].position - P(i)).squaredNorm() == 0.0;
    if (!seen) out.add(P(i), c.separation[static_cast<std::size_t>(i)]);
  }
}

/// The manifold of a pair whose normal and signed distance are known (`d`). Returns the deepest
/// separation the clipped features reached by themselves (infinity if none).
inline double contacts_from_features(const ConvexSupport& a, const ConvexSupport& b, const ConvexDistance& d, double margin,
                                   ContactSet& out) {
  out.clear();
  out.normal = d.normal;
  out.normal_owner = NormalOwner::shape_a;
  SupportFeature fa, fb;
  a.feature(d.normal, fa);
  b.feature(-d.normal, fb);
  ClipPoints pts;
  if (fa.count >= 2 && fb.count >= 2) {
    // Reference: the polygon whose plane is closer to perpendicular to n (ties: A).
    bool ref_is_a;
    if (fa.count >= 3 && fb.count >= 3) {
      ref_is_a = std::abs(polygon_normal(fa).dot(d.normal)) >= std::abs(polygon_normal(fb).dot(d.normal)) - 1e-9;
    } else {
      ref_is_a = fa.count >= fb.count;
    }
    if (ref_is_a) {
      clip_features(fa, fb, false, d.normal, margin, pts);
    } else {
      clip_features(fb, fa, true, d.normal, margin, pts);
    }
    if (fa.count >= 3 || fb.count >= 3) out.normal_owner = ref_is_a ? NormalOwner::shape_a : NormalOwner::shape_b;
  }
  double deepest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < pts.count; ++k) deepest = std::min(deepest, pts.separation[static_cast<std::size_t>(k)]);
  const double tol = 1e-5 + 0.05 * std::abs(d.separation);
  const Vec3 witness = 0.5 * (d.point_a + d.point_b);
  if (pts.count == 0 || deepest < d.separation - tol) {
    out.normal_owner = NormalOwner::shape_a;
    out.add(witness, d.separation);
  } else {
    // Polygons inscribed in a rim (and chords where two of them cross) can stay a little above
    // the true deepest point: add it when they miss it by more than 1 um.
    if (deepest > d.separation + 1e-6) pts.add(witness, d.separation);
    reduce_points(pts, d.normal, out);
  }
  // Fewer than three points: a curved surface or an edge carries the contact, and the touching
  // material points change as the bodies roll (re-detect every step while moving).
  out.rolling = out.count < 3;
  return deepest;
}

/// Cylinder against a box face, analytic (see the file comment). Returns 1 with `out` filled,
/// 0 when separated beyond the margin, -1 when the contact is not a face contact (use GJK/EPA).
inline int cylinder_box_face(const ConvexSupport& cyl, const ConvexSupport& box, bool cylinder_is_a, double margin,
                             ContactSet& out) {
  const Mat3& rb = box.pose.rotation;
  const Vec3 c = rb.transpose() * (cyl.pose.translation - box.pose.translation);
  const Vec3 a = rb.transpose() * cyl.pose.rotation.col(2);
  const double r = cyl.shape->radius, h = cyl.shape->half_length;
  const Vec3& H = box.shape->half_extents;
  double best = -std::numeric_limits<double>::infinity();
  int face = 0;
  for (int i = 0; i < 3; ++i) {
    const double s = std::abs(c[i]) - H[i] - (h * std::abs(a[i]) + r * std::sqrt(std::max(0.0, 1.0 - a[i] * a[i])));
    if (s > margin) return 0;
    if (s > best) { best = s; face = i; }
  }
  const double cap = std::abs(a.dot(c)) - h - H.dot(a.cwiseAbs());
  if (cap > margin) return 0;
  double cross_best = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j) {
    Vec3 m = a.cross(Vec3::Unit(j));
    const double len = m.norm();
    if (len < 1e-6) continue;
    m /= len;
    const double s = std::abs(m.dot(c)) - r - H.dot(m.cwiseAbs());
    if (s > margin) return 0;
    cross_best = std::max(cross_best, s);
  }
  if (cap > best + 1e-9 || cross_best > best + 1e-9) return -1;
  // Face contact: normal from the box to the cylinder along the face normal.
  Vec3 n_local = Vec3::Zero();
  n_local[face] = c[face] >= 0 ? 1.0 : -1.0;
  const Vec3 n_box_to_cyl = rb * n_local;
  ConvexDistance d;
  d.normal = cylinder_is_a ? Vec3(-n_box_to_cyl) : n_box_to_cyl;
  d.separation = best;
  const Vec3 deep = cyl.support(-n_box_to_cyl);  // the cylinder's deepest point (one of them)
  d.point_a = cylinder_is_a ? deep : Vec3(deep - best * n_box_to_cyl);
  d.point_b = cylinder_is_a ? Vec3(deep - best * n_box_to_cyl) : deep;
  const ConvexSupport& sa = cylinder_is_a ? cyl : box;
  const ConvexSupport& sb = cylinder_is_a ? box : cyl;
  // Exact only if the cylinder's deepest part lies over the face: its support point projects into
  // the face rectangle, or the clipped features (the deepest point is not unique on a cap or a
  // side line) reach the face separation.
  const double clipped = contacts_from_features(sa, sb, d, margin, out);
  const Vec3 deep_local = rb.transpose() * (deep - box.pose.translation);
  const int j = (face + 1) % 3, k = (face + 2) % 3;
  const bool over_face = std::abs(deep_local[j]) <= H[j] && std::abs(deep_local[k]) <= H[k];
  if (!over_face && !(clipped <= best + 1e-9 + 1e-6 * std::abs(best))) return -1;
  // The face's normal belongs to the box.
  out.normal_owner = cylinder_is_a ? NormalOwner::shape_b : NormalOwner::shape_a;
  return 1;
}

/// A cylinder's side against another cylinder's side, a capsule or a sphere, analytic: each shape
/// lies inside the capsule of its axis segment and radius, so the distance is at least that of the
/// two capsules, |q_b - q_a| - r_a - r_b with q_a, q_b the closest points of the axis segments;
/// when q_a (and q_b for a cylinder) is interior to its segment, n = (q_b - q_a)/|q_b - q_a| is
/// perpendicular to that axis and q_a + r_a n, q_b - r_b n lie on the sides: the bound is reached,
/// the distance exact. For a shallow penetration (depth below half the smaller radius, closest
/// points at least the depth away from the segment ends) the same normal and depth are used.
/// Returns false when these conditions fail (GJK/EPA answers).
inline bool side_contact(const ConvexSupport& a, const ConvexSupport& b, ConvexDistance& d) {
  auto axis_segment = [](const ConvexSupport& x, Vec3& p0, Vec3& p1, double& radius) {
    const Vec3 half = x.shape->kind == ShapeKind::sphere ? Vec3::Zero() : Vec3(x.shape->half_length * x.axis());
    p0 = x.pose.translation - half;
    p1 = x.pose.translation + half;
    radius = x.shape->radius;
  };
  Vec3 a0, a1, b0, b1;
  double ra = 0, rb = 0;
  axis_segment(a, a0, a1, ra);
  axis_segment(b, b0, b1, rb);
  auto cp = closest_segment_segment(a0, a1, b0, b1);
  const Vec3 da = a1 - a0, db = b1 - b0;
  const double la2 = da.squaredNorm(), lb2 = db.squaredNorm();
  if (la2 > 0 && lb2 > 0 && da.cross(db).squaredNorm() < 1e-12 * la2 * lb2) {
    // Parallel axes: every point of the overlap is closest; take the middle of the overlap.
    double t0 = (b0 - a0).dot(da) / la2, t1 = (b1 - a0).dot(da) / la2;
    if (t0 > t1) std::swap(t0, t1);
    t0 = std::max(t0, 0.0);
    t1 = std::min(t1, 1.0);
    if (t1 > t0) {
      cp.s = 0.5 * (t0 + t1);
      cp.point_a = a0 + cp.s * da;
      cp.t = std::clamp((cp.point_a - b0).dot(db) / lb2, 0.0, 1.0);
      cp.point_b = b0 + cp.t * db;
    }
  }
  const Vec3 gap = cp.point_b - cp.point_a;
  const double dist = gap.norm();
  if (!(dist > 1e-9)) return false;
  const double sep = dist - ra - rb;
  const double depth = std::max(-sep, 0.0);
  if (depth > 0.5 * std::min(ra, rb)) return false;
  auto interior = [&](const ConvexSupport& x, double t, const Vec3& p0, const Vec3& p1) {
    if (x.shape->kind != ShapeKind::cylinder) return true;  // a capsule's surface surrounds its whole segment
    const double len = (p1 - p0).norm();
    return std::min(t, 1.0 - t) * len > depth && t > 0.0 && t < 1.0;
  };
  if (!interior(a, cp.s, a0, a1) || !interior(b, cp.t, b0, b1)) return false;
  d.normal = gap / dist;
  d.separation = sep;
  d.point_a = cp.point_a + ra * d.normal;
  d.point_b = cp.point_b - rb * d.normal;
  d.penetrating = sep < 0;
  return true;
}

}  // namespace detail

/// Contacts of two convex shapes (at least one of them a cylinder, or a sphere/capsule against a
/// convex mesh) on their true surfaces; normal from a to b. False when farther apart than `margin`.
inline bool collide_convex(const CollisionShape& a, const Pose& pose_a, const CollisionShape& b, const Pose& pose_b,
                           double margin, ContactSet& out) {
  out.clear();
  const ConvexSupport sa{&a, pose_a}, sb{&b, pose_b};
  if (a.kind == ShapeKind::cylinder && b.kind == ShapeKind::box) {
    const int face = detail::cylinder_box_face(sa, sb, true, margin, out);
    if (face >= 0) return face == 1 && out.count > 0;
  } else if (a.kind == ShapeKind::box && b.kind == ShapeKind::cylinder) {
    const int face = detail::cylinder_box_face(sb, sa, false, margin, out);
    if (face >= 0) return face == 1 && out.count > 0;
  }
  ConvexDistance d;
  const bool sided_a = a.kind == ShapeKind::cylinder || a.kind == ShapeKind::capsule || a.kind == ShapeKind::sphere;
  const bool sided_b = b.kind == ShapeKind::cylinder || b.kind == ShapeKind::capsule || b.kind == ShapeKind::sphere;
  if (sided_a && sided_b && detail::side_contact(sa, sb, d)) {
    if (d.separation > margin) return false;
    detail::contacts_from_features(sa, sb, d, margin, out);
    return out.count > 0;
  }
  if (!convex_distance(sa, sb, margin, d)) {
    out.clear();
    return false;
  }
  detail::contacts_from_features(sa, sb, d, margin, out);
  return out.count > 0;
}

}  // namespace manisoft::contact
