// The procedurally generated asset catalogue of the "ManiSoft" benchmark (paper section 3.3,
// assets): graspable objects (object_catalog) and obstacles (obstacle_catalog). Every instance is
// built deterministically from its category's parameters and instance index (no randomness): a
// lathe (surface of revolution, collision = equal-volume cylinder) or a box. Containers and
// tableware (cup, pen cup, plate, bowl, mug, basket) are hollow: the visual lathe runs up the
// outside, over the rim and down the inside to the floor (an open box for the basket), and the
// collision model is a compound of a floor and a ring of wall planks (24 per profile band, each
// as wide as the ring's circumference at its mid-height / 24, so the compound's volume matches the
// visual shell's), so things dropped in stay in. Masses come from geometry::mass_properties with
// an effective density chosen so the mass is realistic for the real object.
//
// Graspable objects are at most 0.085 m across (a shoe is long along y); the basket is a COLL
// container as large as a storage basket (20-28 cm square, 7-9 cm tall: every COLL category
// has instances that stand in one with their centre of mass below the rim) and has no grasp.
// Grasps (one per graspable object, tool-down, closing along the asset's x axis) are made for the
// ManiSoft parallel gripper (GraspGripper, asset.hpp: the dimensions interaction::ParallelGripperParameters
// takes its defaults from): the
// palm stops palm_clearance above the object's top, but never so low that the fingertips come
// closer than table_clearance to the support plane (flat objects: plate, bowl, Rubik's cube);
// the annotated width is the object's extent along the closing axis over the fingers' height
// range.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "manisoft/assets/asset.hpp"
#include "manisoft/assets/lathe.hpp"
#include "manisoft/geometry/mass_properties.hpp"
#include "manisoft/render/mesh_builders.hpp"

namespace manisoft::assets {

namespace catalog_detail {

struct NamedColor {
  const char* name;
  float r, g, b;
};

inline const std::vector<NamedColor>& palette() {
  static const std::vector<NamedColor> p{
      {"red", 0.8f, 0.1f, 0.1f},    {"blue", 0.1f, 0.2f, 0.8f},   {"green", 0.1f, 0.6f, 0.2f},
      {"yellow", 0.9f, 0.8f, 0.1f}, {"white", 0.9f, 0.9f, 0.9f},  {"black", 0.05f, 0.05f, 0.05f},
      {"orange", 0.9f, 0.45f, 0.1f}, {"purple", 0.5f, 0.1f, 0.6f}, {"grey", 0.5f, 0.5f, 0.5f},
      {"brown", 0.45f, 0.28f, 0.12f}};
  return p;
}

/// A box part of a multi-part asset, in units of the asset's size (centre and half extents are
/// fractions of size x, y, z; z from the bottom), optionally tilted about x, with its own colour
/// (an index into palette()) or the asset's main colour (-1). The first part is the body (main
/// colour): the language layer names the later ones ("the red shoe with the white sole").
struct BoxPart {
  const char* name;
  Eigen::Vector3d center;
  Eigen::Vector3d half;
  double tilt_x = 0;  ///< rad, about the part's centre
  int color = -1;
};

/// Category recipe: lathe profile (unit scale), box, or box parts; nominal size, mass, material.
struct Recipe {
  const char* category;
  bool lathe;                           ///< false: box
  std::vector<ProfilePoint> profile;    ///< lathe: radius and z for a unit-height object of nominal radius 1
  Eigen::Vector3d size;                 ///< nominal: lathe (diameter, diameter, height); box (x, y, z)
  double mass;                          ///< nominal kg
  const char* material;
  bool receptacle = false;
  bool on_side = false;
  std::vector<BoxPart> parts{};        ///< non-empty: the asset is these boxes (lathe = false)
  bool long_y = false;                 ///< graspable and longer than 0.085 m along y (a shoe)
  bool wide = false;                   ///< a container wider than the gripper opens (a basket): no grasp
};

/// Radius of a profile at height z (linear between points; clamped to the ends).
inline double profile_radius(const std::vector<ProfilePoint>& p, double z) {
  if (z <= p.front().z) return p.front().radius;
  for (std::size_t k = 0; k + 1 < p.size(); ++k) {
    if (z <= p[k + 1].z) {
      const double dz = p[k + 1].z - p[k].z;
      const double t = dz > 0 ? (z - p[k].z) / dz : 1.0;
      return p[k].radius + t * (p[k + 1].radius - p[k].radius);
    }
  }
  return p.back().radius;
}

/// Largest radius of a profile over heights [z0, z1] (at its points inside, or at the ends).
inline double max_profile_radius(const std::vector<ProfilePoint>& p, double z0, double z1) {
  double r = std::max(profile_radius(p, z0), profile_radius(p, z1));
  for (const auto& q : p)
    if (q.z >= z0 && q.z <= z1) r = std::max(r, q.radius);
  return r;
}

/// The closed cross-section of a hollow lathe of wall thickness t: up the outer profile, over the
/// rim, down the inner wall (the outer radius less t at each height) to the floor at z = t.
inline std::vector<ProfilePoint> hollow_profile(const std::vector<ProfilePoint>& outer, double t) {
  std::vector<ProfilePoint> out = outer;
  for (std::size_t k = outer.size(); k-- > 0;) {
    if (outer[k].z <= t) break;
    out.push_back({outer[k].radius - t, outer[k].z});
  }
  out.push_back({profile_radius(outer, t) - t, t});
  return out;
}

/// Collision compound of a hollow lathe: a floor disc (z in [0, t]) and per outer profile band
/// above the floor a ring of `planks` boxes, each spanning the band's slant between the outer
/// surface and the inner one (horizontal thickness t) and as wide as the ring's circumference at
/// the band's mid-height divided by the plank count.
inline geometry::Compound<double> hollow_lathe_collision(const std::vector<ProfilePoint>& outer, double t, int planks = 24) {
  const double pi = 3.14159265358979323846;
  geometry::Compound<double> c;
  geometry::CompoundPart<double> floor;
  floor.shape = geometry::Cylinder<double>{profile_radius(outer, 0.5 * t), 0.5 * t};
  floor.position = Eigen::Vector3d(0, 0, 0.5 * t);
  c.parts.push_back(floor);
  for (std::size_t k = 0; k + 1 < outer.size(); ++k) {
    const double za = std::max(outer[k].z, t), zb = outer[k + 1].z;
    if (!(zb > za + 1e-9)) continue;
    const double ra = profile_radius(outer, za) - 0.5 * t, rb = outer[k + 1].radius - 0.5 * t;  // wall centre line
    const double length = std::hypot(rb - ra, zb - za);
    const double alpha = std::atan2(rb - ra, zb - za);  // from the vertical, outward positive
    const double r_mid = 0.5 * (ra + rb);
    const double half_width = r_mid * std::tan(pi / planks);
    for (int i = 0; i < planks; ++i) {
      const double phi = 2.0 * pi * i / planks;
      const Eigen::Vector3d er(std::cos(phi), std::sin(phi), 0.0), et(-std::sin(phi), std::cos(phi), 0.0), ez = Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d slant = std::sin(alpha) * er + std::cos(alpha) * ez;
      const Eigen::Vector3d outward = std::cos(alpha) * er - std::sin(alpha) * ez;
      geometry::CompoundPart<double> plank;
      plank.shape = geometry::Box<double>{Eigen::Vector3d(half_width, 0.5 * t * std::cos(alpha), 0.5 * length)};
      plank.position = r_mid * er + 0.5 * (za + zb) * ez;
      Eigen::Matrix3d r;
      r.col(0) = et;
      r.col(1) = -outward;
      r.col(2) = slant;
      plank.orientation = Eigen::Quaterniond(r);
      c.parts.push_back(plank);
    }
  }
  return c;
}

/// Closed, outward-wound mesh of an open-topped box (outer half sizes hx, hy, height h, walls and
/// floor of thickness t), origin at the centre of its bottom face, flat normals, planar UVs.
inline render::Mesh open_box_mesh(double hx, double hy, double h, double t) {
  render::Mesh m;
  auto quad = [&m](const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& d,
                   const Eigen::Vector3f& n) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (const Eigen::Vector3f* p : {&a, &b, &c, &d}) {
      m.positions.push_back(*p);
      m.normals.push_back(n);
      // planar UVs on the face's two tangent axes
      const int ax = std::abs(n.x()) > 0.5f ? 1 : 0, ay = std::abs(n.z()) > 0.5f ? 1 : 2;
      m.uvs.emplace_back((*p)[ax] * 5.0f, (*p)[ay] * 5.0f);
    }
    const bool ccw = ((b - a).cross(c - a)).dot(n) > 0;
    if (ccw) m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    else m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  };
  const float X = static_cast<float>(hx), Y = static_cast<float>(hy), H = static_cast<float>(h), T = static_cast<float>(t);
  const float x = static_cast<float>(hx - t), y = static_cast<float>(hy - t);
  using V = Eigen::Vector3f;
  quad(V(-X, -Y, 0), V(X, -Y, 0), V(X, Y, 0), V(-X, Y, 0), V(0, 0, -1));                   // bottom
  quad(V(X, -Y, 0), V(X, Y, 0), V(X, Y, H), V(X, -Y, H), V(1, 0, 0));                       // outer sides
  quad(V(-X, -Y, 0), V(-X, Y, 0), V(-X, Y, H), V(-X, -Y, H), V(-1, 0, 0));
  quad(V(-X, Y, 0), V(X, Y, 0), V(X, Y, H), V(-X, Y, H), V(0, 1, 0));
  quad(V(-X, -Y, 0), V(X, -Y, 0), V(X, -Y, H), V(-X, -Y, H), V(0, -1, 0));
  quad(V(X, -Y, H), V(X, Y, H), V(x, y, H), V(x, -y, H), V(0, 0, 1));                       // rim
  quad(V(-X, -Y, H), V(-X, Y, H), V(-x, y, H), V(-x, -y, H), V(0, 0, 1));
  quad(V(-X, Y, H), V(X, Y, H), V(x, y, H), V(-x, y, H), V(0, 0, 1));
  quad(V(-X, -Y, H), V(X, -Y, H), V(x, -y, H), V(-x, -y, H), V(0, 0, 1));
  quad(V(x, -y, T), V(x, y, T), V(x, y, H), V(x, -y, H), V(-1, 0, 0));                      // inner walls
  quad(V(-x, -y, T), V(-x, y, T), V(-x, y, H), V(-x, -y, H), V(1, 0, 0));
  quad(V(-x, y, T), V(x, y, T), V(x, y, H), V(-x, y, H), V(0, -1, 0));
  quad(V(-x, -y, T), V(x, -y, T), V(x, -y, H), V(-x, -y, H), V(0, 1, 0));
  quad(V(-x, -y, T), V(x, -y, T), V(x, y, T), V(-x, y, T), V(0, 0, 1));                     // inner floor
  return m;
}

/// Collision compound of the open box: floor plus four walls, touching but not overlapping.
inline geometry::Compound<double> open_box_collision(double hx, double hy, double h, double t) {
  geometry::Compound<double> c;
  auto add = [&c](Eigen::Vector3d half, Eigen::Vector3d at) {
    geometry::CompoundPart<double> p;
    p.shape = geometry::Box<double>{half};
    p.position = at;
    c.parts.push_back(p);
  };
  const double wall_half_z = 0.5 * (h - t), wall_z = t + wall_half_z;
  add({hx, hy, 0.5 * t}, {0, 0, 0.5 * t});
  for (double s : {-1.0, 1.0}) {
    add({0.5 * t, hy, wall_half_z}, {s * (hx - 0.5 * t), 0, wall_z});
    add({hx - t, 0.5 * t, wall_half_z}, {0, s * (hy - 0.5 * t), wall_z});
  }
  return c;
}

inline std::string two_digits(int i) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%02d", i);
  return buf;
}

inline Asset build(const Recipe& r, int i, AssetKind kind) {
  Asset a;
  a.id = std::string(r.category) + "/" + two_digits(i);
  a.category = r.category;
  a.kind = kind;
  a.source = "generated";
  // Deterministic variation: sizes 0.85 .. 1.15, aspect varies independently.
  const double s = 0.85 + 0.05 * (i % 7);
  const double aspect = 0.9 + 0.1 * ((i * 3) % 3);
  Eigen::Vector3d size = r.size * s;
  size.z() *= aspect;
  if (std::string(r.category) == "rubiks_cube") size.z() = size.x();  // a cube
  if (kind == AssetKind::object && !r.wide) {  // graspable: at most 0.085 across
    size.x() = std::min(size.x(), 0.085);
    if (!r.long_y) size.y() = std::min(size.y(), 0.085);
  }
  const auto& col = palette()[static_cast<std::size_t>(i * 3 + static_cast<int>(a.category.size())) % palette().size()];
  VisualPart part;
  part.name = "body";
  part.material.base_color = Eigen::Vector3f(col.r, col.g, col.b);
  part.color_name = col.name;
  part.material_name = r.material;
  if (a.category == "rubiks_cube") {  // a 4 x 4 sticker grid on every face (solid checker, cells of edge / 4)
    const auto& other = palette()[static_cast<std::size_t>(i * 3 + 4) % palette().size()];
    part.material.texture = render::TextureKind::checker;
    part.material.secondary_color = Eigen::Vector3f(other.r, other.g, other.b);
    part.material.texture_scale = static_cast<float>(4.0 / size.x());
  }
  geometry::Compound<double> comp;
  geometry::CompoundPart<double> cp;
  const double wall = 0.004;                 // containers: wall and floor thickness, m
  std::vector<ProfilePoint> prof;            // lathe: the scaled outer profile
  if (r.lathe) {
    for (const auto& p : r.profile) prof.push_back({p.radius * 0.5 * size.x(), p.z * size.z()});
    if (r.receptacle) {
      const auto section = hollow_profile(prof, wall);
      part.mesh = make_lathe_mesh(section, 32);
      comp = hollow_lathe_collision(prof, wall);
    } else {
      part.mesh = make_lathe_mesh(prof, 32);
      cp.shape = lathe_equal_volume_cylinder(prof, 32);
      cp.position = Eigen::Vector3d(0, 0, 0.5 * size.z());
      comp.parts.push_back(cp);
    }
  } else if (!r.parts.empty()) {
    for (const auto& bp : r.parts) {
      VisualPart vp = part;
      vp.name = bp.name;
      if (bp.color >= 0) {
        const auto& pc = palette()[static_cast<std::size_t>(bp.color)];
        vp.material.base_color = Eigen::Vector3f(pc.r, pc.g, pc.b);
        vp.color_name = pc.name;
      }
      geometry::CompoundPart<double> box;
      const Eigen::Vector3d half = bp.half.cwiseProduct(size);
      box.shape = geometry::Box<double>{half};
      box.position = bp.center.cwiseProduct(size);
      box.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(bp.tilt_x, Eigen::Vector3d::UnitX()));
      render::append(vp.mesh, render::make_box(half), math::Pose<double>{box.orientation.toRotationMatrix(), box.position});
      comp.parts.push_back(box);
      a.visual.push_back(vp);
    }
  } else if (r.receptacle) {
    part.mesh = open_box_mesh(0.5 * size.x(), 0.5 * size.y(), size.z(), wall);
    comp = open_box_collision(0.5 * size.x(), 0.5 * size.y(), size.z(), wall);
  } else {
    part.mesh = render::make_box(0.5 * size);
    for (auto& p : part.mesh.positions) p.z() += static_cast<float>(0.5 * size.z());
    cp.shape = geometry::Box<double>{0.5 * size};
    cp.position = Eigen::Vector3d(0, 0, 0.5 * size.z());
    comp.parts.push_back(cp);
  }
  a.collision = comp;
  const double mass = std::min(r.mass * s * s * s, kind == AssetKind::object ? 0.29 : 1e9);
  const auto mp = geometry::mass_properties(comp, mass / geometry::shape_volume(geometry::Shape<double>(comp)));
  a.mass = mp.mass;
  a.center_of_mass = mp.center_of_mass;
  a.inertia = mp.inertia;
  if (r.parts.empty()) a.visual.push_back(part);
  a.attributes.color_name = col.name;
  a.attributes.color_rgb = Eigen::Vector3f(col.r, col.g, col.b);
  a.attributes.material_name = r.material;
  a.attributes.size = s < 0.95 ? SizeClass::small : (s < 1.05 ? SizeClass::medium : SizeClass::large);
  a.attributes.parts.clear();
  for (const auto& vp : a.visual) a.attributes.parts.push_back(vp.name);
  a.bounding_half_extents = 0.5 * size;
  a.bounding_center = Eigen::Vector3d(0, 0, 0.5 * size.z());
  if (!r.parts.empty()) {  // the union of the parts' vertices
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = Eigen::Vector3f::Constant(-1e30f);
    for (const auto& vp : a.visual)
      for (const auto& q : vp.mesh.positions) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    a.bounding_half_extents = 0.5 * (hi - lo).cast<double>();
    a.bounding_center = 0.5 * (hi + lo).cast<double>();
  }
  a.resting_poses.push_back(RestingPose{Eigen::Quaterniond::Identity(), 0.0, "upright"});
  if (r.on_side) {
    // Rotate +90 deg about x: the axis lies along -y; the origin (footprint centre) sits one radius up.
    a.resting_poses.push_back(RestingPose{Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitX())),
                                          0.5 * size.x(), "on its side"});
  }
  if (kind == AssetKind::object && !r.wide) {
    const GraspGripper gg;
    GraspAnnotation g;
    math::Matrix3<double> R;
    R << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // x closing along the asset's x, z (approach) straight down
    const double top = a.bounding_center.z() + a.bounding_half_extents.z();
    const double frame_z = std::max(top + gg.palm_clearance + gg.palm_thickness,
                                    gg.table_clearance + gg.palm_thickness + gg.finger_length);
    g.grasp.rotation = R;
    g.grasp.translation = Eigen::Vector3d(0, 0, frame_z);
    g.approach = g.grasp;
    g.approach.translation.z() += 0.10;
    g.lift = g.grasp;
    g.lift.translation.z() += 0.15;
    // Extent along the closing axis over the fingers' height range [tips, palm] within the object.
    const double lo = std::max(0.0, frame_z - gg.palm_thickness - gg.finger_length);
    const double hi = std::min(top, frame_z - gg.palm_thickness);
    g.width = r.lathe ? 2.0 * max_profile_radius(prof, lo, hi) : size.x();
    if (!r.parts.empty()) {  // the parts (tilted about x only: x extents unchanged) reaching into [lo, hi]
      double xlo = 1e30, xhi = -1e30;
      for (const auto& bp : r.parts) {
        const Eigen::Vector3d c = bp.center.cwiseProduct(size), h = bp.half.cwiseProduct(size);
        const double hz = std::abs(std::cos(bp.tilt_x)) * h.z() + std::abs(std::sin(bp.tilt_x)) * h.y();
        if (c.z() + hz <= lo || c.z() - hz >= hi) continue;
        xlo = std::min(xlo, c.x() - h.x());
        xhi = std::max(xhi, c.x() + h.x());
      }
      g.width = xhi - xlo;
    }
    a.grasps.push_back(g);
  }
  if (r.receptacle) {
    // The inner volume: the vertical cylinder (box) that fits the cavity from the floor (z = wall)
    // to the rim: for a lathe the smallest inner radius over that height.
    Receptacle rc;
    rc.opening.translation = Eigen::Vector3d(0, 0, size.z());
    if (r.lathe) {
      double rmin = profile_radius(prof, wall);
      for (const auto& p : prof)
        if (p.z >= wall) rmin = std::min(rmin, p.radius);
      rc.inner_radius = rmin - wall;
    } else {
      rc.inner_half_extents = Eigen::Vector2d(0.5 * size.x() - wall, 0.5 * size.y() - wall);
    }
    rc.inner_depth = size.z() - wall;
    rc.placement.translation = Eigen::Vector3d(0, 0, wall);
    a.receptacles.push_back(rc);
  }
  return a;
}

inline std::vector<ProfilePoint> cyl() { return {{1, 0}, {1, 1}}; }

}  // namespace catalog_detail

/// Graspable objects: 17 categories x 7 instances.
inline std::vector<Asset> object_catalog() {
  using catalog_detail::Recipe;
  using V = Eigen::Vector3d;
  const std::vector<Recipe> recipes{
      {"bottle", true, {{1, 0}, {1, 0.65}, {0.4, 0.85}, {0.4, 1}}, V(0.065, 0.065, 0.22), 0.25, "plastic", false, true},
      {"pill_bottle", true, {{1, 0}, {1, 0.85}, {0.9, 0.86}, {0.9, 1}}, V(0.04, 0.04, 0.08), 0.05, "plastic", false, true},
      {"can", true, {{0.9, 0}, {1, 0.05}, {1, 0.93}, {0.88, 1}}, V(0.066, 0.066, 0.12), 0.25, "metal", false, true},
      {"cup", true, {{0.75, 0}, {1, 1}}, V(0.075, 0.075, 0.1), 0.12, "ceramic", true},
      {"sand_clock", true, {{1, 0}, {1, 0.05}, {0.2, 0.5}, {1, 0.95}, {1, 1}}, V(0.07, 0.07, 0.14), 0.2, "glass"},
      {"shoe", false, {}, V(0.08, 0.2, 0.09), 0.28, "fabric", false, false,
       {{"upper", V(0, -0.2, 0.3), V(0.45, 0.3, 0.15)},
        {"heel", V(0, 0.3, 0.55), V(0.45, 0.2, 0.4)},
        {"sole", V(0, 0, 0.075), V(0.5, 0.5, 0.075), 0, 4}},
       true},
      {"candle_stick", true, {{1, 0}, {1, 0.1}, {0.35, 0.2}, {0.35, 1}}, V(0.07, 0.07, 0.2), 0.2, "metal"},
      {"box_drink", false, {}, V(0.06, 0.04, 0.11), 0.25, "cardboard"},
      {"kettle", true, {{0.8, 0}, {1, 0.4}, {0.8, 0.85}, {0.3, 1}}, V(0.085, 0.085, 0.13), 0.3, "metal"},
      {"pen_cup", true, {{1, 0}, {1, 1}}, V(0.07, 0.07, 0.1), 0.12, "plastic", true},
      {"sauce_can", true, {{1, 0}, {1, 1}}, V(0.06, 0.06, 0.08), 0.2, "metal", false, true},
      {"rubiks_cube", false, {}, V(0.057, 0.057, 0.057), 0.09, "plastic"},
      {"trophy", true, {{1, 0}, {1, 0.15}, {0.25, 0.25}, {0.25, 0.55}, {0.9, 1}}, V(0.08, 0.08, 0.16), 0.28, "metal"},
      {"plate", true, {{0.7, 0}, {1, 0.8}, {1, 1}}, V(0.085, 0.085, 0.02), 0.08, "ceramic", true},
      {"bowl", true, {{0.5, 0}, {0.85, 0.5}, {1, 1}}, V(0.085, 0.085, 0.05), 0.15, "ceramic", true},
      {"mug", true, {{1, 0}, {1, 1}}, V(0.08, 0.08, 0.095), 0.28, "ceramic", true},
      {"basket", false, {}, V(0.24, 0.24, 0.09), 0.4, "wood", true, false, {}, false, true},
  };
  std::vector<Asset> out;
  for (const auto& r : recipes)
    for (int i = 0; i < 7; ++i) out.push_back(catalog_detail::build(r, i, AssetKind::object));
  return out;
}

/// Obstacles: 36 categories x 5 instances.
inline std::vector<Asset> obstacle_catalog() {
  using catalog_detail::Recipe;
  using catalog_detail::cyl;
  using V = Eigen::Vector3d;
  const std::vector<Recipe> recipes{
      {"book", false, {}, V(0.16, 0.24, 0.03), 0.5, "paper"},
      {"laptop", false, {}, V(0.32, 0.22, 0.2), 1.5, "metal", false, false,
       {{"base", V(0, -0.06, 0.05), V(0.5, 0.44, 0.05)},
        {"screen", V(0, 0.45, 0.61), V(0.5, 0.47, 0.025), 1.35, 5}}},
      {"monitor", false, {}, V(0.5, 0.18, 0.35), 4.0, "plastic", false, false,
       {{"stand", V(0, 0, 0.025), V(0.25, 0.5, 0.025)},
        {"neck", V(0, 0.1, 0.175), V(0.04, 0.08, 0.125)},
        {"screen", V(0, 0.1, 0.65), V(0.5, 0.1, 0.35), 0, 5}}},
      {"lamp", true, {{1, 0}, {1, 0.05}, {0.1, 0.1}, {0.1, 0.7}, {0.8, 0.75}, {0.5, 1}}, V(0.18, 0.18, 0.4), 1.2, "metal"},
      {"vase", true, {{0.6, 0}, {1, 0.4}, {0.4, 0.85}, {0.55, 1}}, V(0.14, 0.14, 0.28), 1.0, "ceramic"},
      {"plant_pot", true, {{0.75, 0}, {1, 1}}, V(0.16, 0.16, 0.15), 1.5, "ceramic"},
      {"phone", false, {}, V(0.075, 0.15, 0.009), 0.18, "glass", false, false,
       {{"body", V(0, 0, 0.4), V(0.5, 0.5, 0.4)},
        {"screen", V(0, 0.02, 0.9), V(0.44, 0.44, 0.1), 0, 5}}},
      {"keyboard", false, {}, V(0.44, 0.14, 0.03), 0.7, "plastic"},
      {"mouse", false, {}, V(0.065, 0.11, 0.035), 0.09, "plastic"},
      {"speaker", false, {}, V(0.12, 0.12, 0.2), 1.5, "wood"},
      {"clock", true, cyl(), V(0.2, 0.2, 0.05), 0.6, "plastic"},
      {"jar", true, {{1, 0}, {1, 0.85}, {0.8, 0.9}, {0.8, 1}}, V(0.1, 0.1, 0.15), 0.5, "glass"},
      {"toy", false, {}, V(0.1, 0.08, 0.12), 0.2, "plastic"},
      {"tissue_box", false, {}, V(0.24, 0.12, 0.11), 0.3, "cardboard", false, false,
       {{"box", V(0, 0, 0.4), V(0.5, 0.5, 0.4)},
        {"tissue", V(0, 0, 0.9), V(0.2, 0.15, 0.1), 0, 4}}},
      {"stapler", false, {}, V(0.04, 0.15, 0.05), 0.3, "metal"},
      {"tape_dispenser", false, {}, V(0.06, 0.14, 0.07), 0.4, "plastic"},
      {"globe", true, {{0.4, 0}, {0.4, 0.1}, {1, 0.5}, {0.4, 1}}, V(0.25, 0.25, 0.35), 1.0, "plastic"},
      {"picture_frame", false, {}, V(0.2, 0.06, 0.25), 0.6, "wood"},
      {"radio", false, {}, V(0.25, 0.1, 0.14), 1.2, "plastic"},
      {"printer", false, {}, V(0.42, 0.35, 0.2), 6.0, "plastic"},
      {"router", false, {}, V(0.2, 0.13, 0.04), 0.4, "plastic"},
      {"thermos", true, {{1, 0}, {1, 0.9}, {0.85, 1}}, V(0.08, 0.08, 0.28), 0.6, "metal"},
      {"fruit_bowl", true, {{0.5, 0}, {1, 1}}, V(0.26, 0.26, 0.09), 1.0, "ceramic"},
      {"cutting_board", false, {}, V(0.35, 0.25, 0.02), 1.0, "wood"},
      {"toaster", false, {}, V(0.28, 0.17, 0.19), 2.0, "metal"},
      {"blender", true, {{1, 0}, {1, 0.3}, {0.8, 0.35}, {0.95, 1}}, V(0.17, 0.17, 0.4), 3.0, "plastic"},
      {"coffee_maker", false, {}, V(0.2, 0.25, 0.35), 3.0, "plastic"},
      {"bread_box", false, {}, V(0.4, 0.22, 0.18), 1.5, "wood"},
      {"pitcher", true, {{0.8, 0}, {1, 0.6}, {0.85, 1}}, V(0.14, 0.14, 0.24), 1.2, "glass"},
      {"candle_jar", true, cyl(), V(0.09, 0.09, 0.1), 0.5, "glass"},
      {"trash_can", true, {{0.85, 0}, {1, 1}}, V(0.25, 0.25, 0.32), 1.5, "plastic"},
      {"storage_box", false, {}, V(0.35, 0.25, 0.2), 1.5, "plastic"},
      {"binder", false, {}, V(0.06, 0.28, 0.31), 0.8, "cardboard"},
      {"helmet", true, {{1, 0}, {0.95, 0.5}, {0.6, 0.9}, {0.2, 1}}, V(0.22, 0.22, 0.2), 1.0, "plastic"},
      {"watering_can", true, {{1, 0}, {1, 0.8}, {0.5, 1}}, V(0.16, 0.16, 0.25), 0.8, "metal"},
      {"fire_extinguisher", true, {{1, 0}, {1, 0.85}, {0.4, 0.95}, {0.3, 1}}, V(0.12, 0.12, 0.4), 3.0, "metal"},
  };
  std::vector<Asset> out;
  for (const auto& r : recipes)
    for (int i = 0; i < 5; ++i) out.push_back(catalog_detail::build(r, i, AssetKind::obstacle));
  return out;
}

}  // namespace manisoft::assets
