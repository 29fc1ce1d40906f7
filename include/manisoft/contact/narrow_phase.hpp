// Narrow-phase dispatch for a pair of collision shapes:
//  - sphere/capsule vs sphere/capsule/box: analytic (collide_primitives.hpp): exact normals and
//    depths, two points for parallel capsules and capsules lying on a face;
//  - box/convex vs box/convex: separating axis + face clipping (collide_polyhedra.hpp): up to 4
//    points, so boxes and meshes rest flat;
//  - every pair with a cylinder, and sphere/capsule vs convex mesh: the true curved shape
//    (collide_convex.hpp): analytic for a cylinder on a box face, else GJK/EPA on support
//    mappings, with a multi-point manifold clipped from the supporting features (a cylinder
//    standing on its cap, lying on its side or tilted on its rim, at its exact depths).
// No FCL in the narrow phase (FCL remains the broad phase) and no heap allocation.
#pragma once

#include "manisoft/contact/collide_convex.hpp"
#include "manisoft/contact/collide_polyhedra.hpp"
#include "manisoft/contact/collide_primitives.hpp"
#include "manisoft/contact/collision_shape.hpp"

namespace manisoft::contact {

struct NarrowPhaseScratch {
  PolyhedronScratch polyhedra;
};

inline RoundedSegment rounded_segment(const CollisionShape& shape, const Pose& pose) {
  RoundedSegment seg;
  seg.radius = shape.radius;
  const Vec3 half = shape.kind == ShapeKind::capsule ? Vec3(pose.rotation.col(2) * shape.half_length) : Vec3::Zero();
  seg.p0 = pose.translation - half;
  seg.p1 = pose.translation + half;
  return seg;
}

/// Contacts between shapes a and b (normal from a to b). False when farther apart than `margin`.
inline bool collide(const CollisionShape& a, const Pose& pose_a, const CollisionShape& b, const Pose& pose_b,
                    double margin, ContactSet& out, NarrowPhaseScratch& scratch) {
  const bool a_round = a.kind == ShapeKind::sphere || a.kind == ShapeKind::capsule;
  const bool b_round = b.kind == ShapeKind::sphere || b.kind == ShapeKind::capsule;
  if (a_round && b_round) return collide_rounded_segments(rounded_segment(a, pose_a), rounded_segment(b, pose_b), margin, out);
  if (a_round && b.kind == ShapeKind::box) {
    return collide_rounded_segment_box(rounded_segment(a, pose_a), b.half_extents, pose_b, true, margin, out);
  }
  if (b_round && a.kind == ShapeKind::box) {
    return collide_rounded_segment_box(rounded_segment(b, pose_b), a.half_extents, pose_a, false, margin, out);
  }
  if (a.kind == ShapeKind::cylinder || b.kind == ShapeKind::cylinder || a_round || b_round) {
    return collide_convex(a, pose_a, b, pose_b, margin, out);
  }
  return collide_polyhedra(*a.polyhedron, pose_a, *b.polyhedron, pose_b, margin, out, scratch.polyhedra);
}

}  // namespace manisoft::contact
