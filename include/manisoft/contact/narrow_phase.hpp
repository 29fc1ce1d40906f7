// Narrow-phase dispatch for a pair of collision shapes, with FCL's pitfalls handled:
//  - sphere/capsule vs sphere/capsule/box: analytic (collide_primitives.hpp): exact normals and
//    depths, two points for parallel capsules and capsules lying on a face;
//  - box/cylinder/convex vs box/cylinder/convex: separating axis + face clipping
//    (collide_polyhedra.hpp): up to 4 points, so boxes, upright cylinders and meshes rest flat;
//  - sphere/capsule vs cylinder/convex: FCL with GST_INDEP (right normals and magnitudes on curved
//    shapes, unlike GST_LIBCCD), taking the absolute value of its negative depths; when FCL reports
//    no collision, an FCL distance query gives the speculative separation up to the margin. One
//    point per call: the contact cache (rigid_world.hpp) keeps the pair's points persistent.
#pragma once

#include "manisoft/contact/collide_polyhedra.hpp"
#include "manisoft/contact/collide_primitives.hpp"
#include "manisoft/contact/collision_shape.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

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

inline fcl::Transform3d to_fcl(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation;
  tf.translation() = pose.translation;
  return tf;
}

/// One contact point from FCL (GST_INDEP), normal from a to b.
inline bool collide_fcl(const CollisionShape& a, const Pose& pose_a, const CollisionShape& b, const Pose& pose_b,
                        double margin, ContactSet& out) {
  out.clear();
  const fcl::CollisionObjectd oa(a.fcl_geometry, to_fcl(pose_a));
  const fcl::CollisionObjectd ob(b.fcl_geometry, to_fcl(pose_b));
  fcl::CollisionRequestd request(1, true);
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::CollisionResultd result;
  fcl::collide(&oa, &ob, request, result);
  if (result.isCollision()) {
    const auto& c = result.getContact(0);
    const double depth = std::abs(c.penetration_depth);  // GST_INDEP reports it negative
    Vec3 n = c.normal;
    if (!(n.squaredNorm() > 0.5)) n = (pose_b.translation - pose_a.translation).normalized();
    out.normal = n.normalized();
    out.normal_owner = NormalOwner::shape_a;
    out.add(c.pos, -depth);
    return true;
  }
  fcl::DistanceRequestd drequest(true);
  drequest.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceResultd dresult;
  fcl::distance(&oa, &ob, drequest, dresult);
  if (!(dresult.min_distance <= margin) || dresult.min_distance < 0) return false;
  const Vec3 pa = dresult.nearest_points[0], pb = dresult.nearest_points[1];
  const Vec3 d = pb - pa;
  if (d.norm() < 1e-12) return false;
  out.normal = d.normalized();
  out.normal_owner = NormalOwner::shape_a;
  out.add(0.5 * (pa + pb), dresult.min_distance);
  return true;
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
  if (!a_round && !b_round) return collide_polyhedra(*a.polyhedron, pose_a, *b.polyhedron, pose_b, margin, out, scratch.polyhedra);
  return collide_fcl(a, pose_a, b, pose_b, margin, out);
}

}  // namespace manisoft::contact
