// Support mapping and supporting features of a placed convex shape, on its true surface (no
// polygonal stand-in for a cylinder): what GJK/EPA (gjk_epa.hpp) and the feature-clipping
// manifold (collide_convex.hpp) work on.
//
// Support point s(d) = argmax_{x in shape} d . x (world direction d, any length):
//   box (half extents H, rotation R):   c + R (sgn(d'_i) H_i),            d' = R^T d;
//   cylinder (radius r, half height h, axis a = R e_z):
//                                       c + h sgn(d.a) a + r (d - (d.a) a) / |d - (d.a) a|;
//   convex mesh:                         the vertex of largest d . v;
//   sphere / capsule: a point / a segment (the "core") swept by the radius: GJK and EPA run on the
//   core and the radius is added afterwards (exact, and no slow convergence on a round surface).
// Supporting feature in a unit direction d: the set of surface points of (nearly) largest d . x,
// as a point, a segment or a convex polygon:
//   cylinder: the cap polygon when |d.a| >= 1/2 (eight body-fixed rim points, plus the exact
//   deepest rim point when the axis is tilted by more than ~1 degree from d), else the side line
//   c + r u +- h a with u the unit radial part of d (the straight generator of largest d . x);
//   box: the face whose normal is closest to d; convex mesh: likewise (its support vertex when
//   that face has too many vertices); capsule: the segment of its two end points pushed out by the
//   radius along d when |d.a| < 1/2, else the deeper end; sphere: the point c + r d.
// Points of a feature that lie farther than the contact margin from the other shape are dropped by
// the clipping, so choosing a cap or a face generously costs nothing (its far points go away).
#pragma once

#include "manisoft/contact/collision_shape.hpp"

#include <array>
#include <cmath>
#include <numbers>

namespace manisoft::contact {

/// A surface feature: 1 point, 2 points (segment) or a convex polygon (3+ points, either winding).
struct SupportFeature {
  static constexpr int kCapacity = 16;
  int count{0};
  std::array<Vec3, kCapacity> points{};
  void add(const Vec3& p) {
    if (count < kCapacity) points[static_cast<std::size_t>(count++)] = p;
  }
};

/// A collision shape placed in the world, seen through its support mapping.
struct ConvexSupport {
  const CollisionShape* shape{nullptr};
  Pose pose;

  /// Radius swept around the core (sphere, capsule); 0 for the others.
  double core_radius() const {
    return shape->kind == ShapeKind::sphere || shape->kind == ShapeKind::capsule ? shape->radius : 0.0;
  }
  Vec3 axis() const { return pose.rotation.col(2); }

  /// Support point of the core (the shape itself for box, cylinder, convex mesh).
  Vec3 support(const Vec3& d) const {
    switch (shape->kind) {
      case ShapeKind::sphere: return pose.translation;
      case ShapeKind::capsule: {
        const Vec3 a = axis();
        return pose.translation + (d.dot(a) >= 0 ? shape->half_length : -shape->half_length) * a;
      }
      case ShapeKind::box: {
        const Vec3 dl = pose.rotation.transpose() * d;
        const Vec3& h = shape->half_extents;
        const Vec3 p(dl.x() >= 0 ? h.x() : -h.x(), dl.y() >= 0 ? h.y() : -h.y(), dl.z() >= 0 ? h.z() : -h.z());
        return pose.act(p);
      }
      case ShapeKind::cylinder: {
        const Vec3 dl = pose.rotation.transpose() * d;
        const double rho = std::hypot(dl.x(), dl.y());
        Vec3 p(0.0, 0.0, dl.z() >= 0 ? shape->half_length : -shape->half_length);
        if (rho > 1e-300) {
          p.x() = shape->radius * dl.x() / rho;
          p.y() = shape->radius * dl.y() / rho;
        } else {
          p.x() = shape->radius;  // a whole rim supports: any of its points will do
        }
        return pose.act(p);
      }
      case ShapeKind::convex: {
        const Vec3 dl = pose.rotation.transpose() * d;
        const auto& verts = shape->polyhedron->vertices;
        std::size_t best = 0;
        double best_dot = dl.dot(verts[0]);
        for (std::size_t i = 1; i < verts.size(); ++i) {
          const double x = dl.dot(verts[i]);
          if (x > best_dot) { best_dot = x; best = i; }
        }
        return pose.act(verts[best]);
      }
    }
    return pose.translation;
  }

  /// Supporting feature of the true surface in the unit direction d (see the file comment).
  void feature(const Vec3& d, SupportFeature& f) const {
    f.count = 0;
    switch (shape->kind) {
      case ShapeKind::sphere: f.add(pose.translation + shape->radius * d); return;
      case ShapeKind::capsule: {
        const Vec3 a = axis();
        const double ad = a.dot(d);
        const Vec3 half = shape->half_length * a, out = shape->radius * d;
        if (std::abs(ad) < 0.5) {
          f.add(pose.translation - half + out);
          f.add(pose.translation + half + out);
        } else {
          f.add(pose.translation + (ad > 0 ? half : Vec3(-half)) + out);
        }
        return;
      }
      case ShapeKind::box: {
        const Vec3 dl = pose.rotation.transpose() * d;
        int i = 0;
        dl.cwiseAbs().maxCoeff(&i);
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        const Vec3& h = shape->half_extents;
        Vec3 p = Vec3::Zero();
        p[i] = dl[i] >= 0 ? h[i] : -h[i];
        const double sj[4] = {-1, 1, 1, -1}, sk[4] = {-1, -1, 1, 1};
        for (int c = 0; c < 4; ++c) {
          p[j] = sj[c] * h[j];
          p[k] = sk[c] * h[k];
          f.add(pose.act(p));
        }
        return;
      }
      case ShapeKind::cylinder: {
        const Vec3 dl = pose.rotation.transpose() * d;
        const double r = shape->radius, h = shape->half_length;
        const double rho = std::hypot(dl.x(), dl.y());
        const double ux = rho > 1e-12 ? dl.x() / rho : 1.0, uy = rho > 1e-12 ? dl.y() / rho : 0.0;
        if (std::abs(dl.z()) >= 0.5) {
          // Cap polygon: eight body-fixed rim points (a resting cylinder's points stay material
          // points from step to step), with the exact deepest rim point inserted in angular order
          // when the tilt is more than ~1 degree (a cylinder rocking on its rim rolls on a circle).
          const double z = dl.z() > 0 ? h : -h;
          constexpr int kRim = 8;
          constexpr double step = 2.0 * std::numbers::pi / kRim;
          const bool insert = rho > 0.02;
          double deep = std::atan2(uy, ux);
          if (deep < 0) deep += 2.0 * std::numbers::pi;
          const int after = std::min(static_cast<int>(deep / step), kRim - 1);
          for (int k = 0; k < kRim; ++k) {
            const double angle = k * step;
            const bool replace = insert && std::abs(angle - deep) < 1e-3;
            f.add(pose.act(replace ? Vec3(r * ux, r * uy, z) : Vec3(r * std::cos(angle), r * std::sin(angle), z)));
            if (insert && k == after && std::abs(deep - angle) >= 1e-3 && std::abs(deep - angle - step) >= 1e-3) {
              f.add(pose.act(Vec3(r * ux, r * uy, z)));
            }
          }
        } else {
          f.add(pose.act(Vec3(r * ux, r * uy, -h)));
          f.add(pose.act(Vec3(r * ux, r * uy, h)));
        }
        return;
      }
      case ShapeKind::convex: {
        const Vec3 dl = pose.rotation.transpose() * d;
        const auto& poly = *shape->polyhedron;
        std::size_t best = 0;
        double best_dot = -2;
        for (std::size_t i = 0; i < poly.faces.size(); ++i) {
          const double x = poly.faces[i].normal.dot(dl);
          if (x > best_dot) { best_dot = x; best = i; }
        }
        const auto& face = poly.faces[best];
        if (best_dot >= 0.5 && face.count <= static_cast<std::uint32_t>(SupportFeature::kCapacity)) {
          for (std::uint32_t k = 0; k < face.count; ++k) f.add(pose.act(poly.vertices[poly.face_vertices[face.first + k]]));
        } else {
          f.add(support(d));
        }
        return;
      }
    }
  }
};

}  // namespace manisoft::contact
