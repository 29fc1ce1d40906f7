// The collision-side description of one primitive shape: its kind, sizes, its polyhedron (box,
// convex mesh; a cylinder's prism is kept for callers that want a polyhedron, the narrow phase
// uses the true cylinder) for the separating-axis narrow phase, and its FCL geometry for the FCL
// broad phase.
#pragma once

#include "manisoft/contact/contact_point.hpp"
#include "manisoft/geometry/convex_polyhedron.hpp"
#include "manisoft/geometry/shapes.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>

#include <memory>
#include <variant>

namespace manisoft::contact {

enum class ShapeKind : std::uint8_t { sphere, capsule, box, cylinder, convex };

struct CollisionShape {
  ShapeKind kind{ShapeKind::sphere};
  double radius{0};                         ///< sphere, capsule, cylinder
  double half_length{0};                    ///< capsule segment half length, cylinder half height
  Vec3 half_extents{Vec3::Zero()};          ///< box
  std::shared_ptr<const geometry::ConvexPolyhedron> polyhedron;  ///< box, cylinder, convex
  std::shared_ptr<fcl::CollisionGeometryd> fcl_geometry;
  double bounding_radius{0};                ///< about the shape origin

  /// Axis-aligned bounds of the shape placed at `pose`.
  void bounds(const Pose& pose, Vec3& lo, Vec3& hi) const {
    Vec3 extent = Vec3::Zero();
    switch (kind) {
      case ShapeKind::sphere: extent.setConstant(radius); break;
      case ShapeKind::capsule: extent = (pose.rotation.col(2) * half_length).cwiseAbs() + Vec3::Constant(radius); break;
      case ShapeKind::box: extent = pose.rotation.cwiseAbs() * half_extents; break;
      case ShapeKind::cylinder: {
        const Vec3 axis = pose.rotation.col(2);
        extent = (axis * half_length).cwiseAbs() +
                 radius * (Vec3::Ones() - axis.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
        break;
      }
      case ShapeKind::convex: {
        lo = hi = pose.act(polyhedron->vertices.front());
        for (const auto& v : polyhedron->vertices) {
          const Vec3 w = pose.act(v);
          lo = lo.cwiseMin(w);
          hi = hi.cwiseMax(w);
        }
        return;
      }
    }
    lo = pose.translation - extent;
    hi = pose.translation + extent;
  }
};

/// Builds the collision shape of a primitive. A convex mesh is re-centred by `mesh_origin` (its
/// vertices are shifted by -mesh_origin).
inline CollisionShape make_collision_shape(const geometry::PrimitiveShape<double>& shape, const Vec3& mesh_origin = Vec3::Zero()) {
  CollisionShape out;
  if (const auto* s = std::get_if<geometry::Sphere<double>>(&shape)) {
    out.kind = ShapeKind::sphere;
    out.radius = s->radius;
    out.fcl_geometry = std::make_shared<fcl::Sphered>(s->radius);
    out.bounding_radius = s->radius;
  } else if (const auto* c = std::get_if<geometry::Capsule<double>>(&shape)) {
    out.kind = ShapeKind::capsule;
    out.radius = c->radius;
    out.half_length = c->half_length;
    out.fcl_geometry = std::make_shared<fcl::Capsuled>(c->radius, 2.0 * c->half_length);
    out.bounding_radius = c->radius + c->half_length;
  } else if (const auto* b = std::get_if<geometry::Box<double>>(&shape)) {
    out.kind = ShapeKind::box;
    out.half_extents = b->half_extents;
    out.polyhedron = std::make_shared<geometry::ConvexPolyhedron>(geometry::make_polyhedron(*b));
    out.fcl_geometry = std::make_shared<fcl::Boxd>(2.0 * b->half_extents);
    out.bounding_radius = b->half_extents.norm();
  } else if (const auto* y = std::get_if<geometry::Cylinder<double>>(&shape)) {
    out.kind = ShapeKind::cylinder;
    out.radius = y->radius;
    out.half_length = y->half_height;
    out.polyhedron = std::make_shared<geometry::ConvexPolyhedron>(geometry::make_polyhedron(*y));
    out.fcl_geometry = std::make_shared<fcl::Cylinderd>(y->radius, 2.0 * y->half_height);
    out.bounding_radius = std::hypot(y->radius, y->half_height);
  } else {
    const auto& m = std::get<geometry::ConvexMesh<double>>(shape);
    out.kind = ShapeKind::convex;
    auto poly = std::make_shared<geometry::ConvexPolyhedron>(geometry::make_polyhedron(m, mesh_origin));
    auto verts = std::make_shared<std::vector<Vec3>>(poly->vertices);
    auto faces = std::make_shared<std::vector<int>>();
    for (const auto& f : poly->faces) {
      faces->push_back(static_cast<int>(f.count));
      for (std::uint32_t k = 0; k < f.count; ++k) faces->push_back(static_cast<int>(poly->face_vertices[f.first + k]));
    }
    out.fcl_geometry = std::make_shared<fcl::Convexd>(verts, static_cast<int>(poly->faces.size()), faces);
    out.bounding_radius = poly->bounding_radius;
    out.polyhedron = std::move(poly);
  }
  out.fcl_geometry->computeLocalAABB();
  return out;
}

}  // namespace manisoft::contact
