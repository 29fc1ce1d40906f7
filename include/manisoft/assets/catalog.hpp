// The procedurally generated asset catalogue of the "ManiSoft" benchmark (paper section 3.3,
// assets): graspable objects (object_catalog) and obstacles (obstacle_catalog). Every instance is
// built deterministically from its category's parameters and instance index (no randomness): a
// lathe (surface of revolution, collision = equal-volume cylinder) or a box. Masses come from
// geometry::mass_properties with an effective density chosen so the mass is realistic for the
// (possibly hollow) real object.
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

/// Category recipe: lathe profile (unit scale) or box, nominal size, mass and material.
struct Recipe {
  const char* category;
  bool lathe;                           ///< false: box
  std::vector<ProfilePoint> profile;    ///< lathe: radius and z for a unit-height object of nominal radius 1
  Eigen::Vector3d size;                 ///< nominal: lathe (diameter, diameter, height); box (x, y, z)
  double mass;                          ///< nominal kg
  const char* material;
  bool receptacle = false;
  bool on_side = false;
};

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
  if (kind == AssetKind::object) {  // graspable: at most 0.085 across
    size.x() = std::min(size.x(), 0.085);
    size.y() = std::min(size.y(), 0.085);
  }
  const auto& col = palette()[static_cast<std::size_t>(i * 3 + static_cast<int>(a.category.size())) % palette().size()];
  VisualPart part;
  part.name = "body";
  part.material.base_color = Eigen::Vector3f(col.r, col.g, col.b);
  part.color_name = col.name;
  part.material_name = r.material;
  double volume = 0;
  geometry::Compound<double> comp;
  geometry::CompoundPart<double> cp;
  if (r.lathe) {
    std::vector<ProfilePoint> prof;
    for (const auto& p : r.profile) prof.push_back({p.radius * 0.5 * size.x(), p.z * size.z()});
    part.mesh = make_lathe_mesh(prof, 32);
    volume = lathe_volume(prof, 32);
    cp.shape = lathe_equal_volume_cylinder(prof, 32);
    cp.position = Eigen::Vector3d(0, 0, 0.5 * size.z());
  } else {
    part.mesh = render::make_box(0.5 * size);
    for (auto& p : part.mesh.positions) p.z() += static_cast<float>(0.5 * size.z());
    volume = size.prod();
    cp.shape = geometry::Box<double>{0.5 * size};
    cp.position = Eigen::Vector3d(0, 0, 0.5 * size.z());
  }
  comp.parts.push_back(cp);
  a.collision = comp;
  const double mass = std::min(r.mass * s * s * s, kind == AssetKind::object ? 0.29 : 1e9);
  const auto mp = geometry::mass_properties(comp, mass / volume);
  a.mass = mp.mass;
  a.center_of_mass = mp.center_of_mass;
  a.inertia = mp.inertia;
  a.visual.push_back(part);
  a.attributes.color_name = col.name;
  a.attributes.color_rgb = Eigen::Vector3f(col.r, col.g, col.b);
  a.attributes.material_name = r.material;
  a.attributes.size = s < 0.95 ? SizeClass::small : (s < 1.05 ? SizeClass::medium : SizeClass::large);
  a.attributes.parts = {"body"};
  a.bounding_half_extents = 0.5 * size;
  a.bounding_center = Eigen::Vector3d(0, 0, 0.5 * size.z());
  a.resting_poses.push_back(RestingPose{Eigen::Quaterniond::Identity(), 0.0, "upright"});
  if (r.on_side) {
    // Rotate +90 deg about x: the axis lies along -y; the origin (footprint centre) sits one radius up.
    a.resting_poses.push_back(RestingPose{Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitX())),
                                          0.5 * size.x(), "on its side"});
  }
  if (kind == AssetKind::object) {
    GraspAnnotation g;
    math::Matrix3<double> R;
    R << 1, 0, 0, 0, -1, 0, 0, 0, -1;
    const double top = size.z();
    g.grasp.rotation = R;
    g.grasp.translation = Eigen::Vector3d(0, 0, top + 0.05);
    g.approach = g.grasp;
    g.approach.translation.z() += 0.10;
    g.lift = g.grasp;
    g.lift.translation.z() += 0.15;
    g.width = size.x();
    a.grasps.push_back(g);
  }
  if (r.receptacle) {
    Receptacle rc;
    rc.opening.translation = Eigen::Vector3d(0, 0, size.z());
    const double wall = 0.004;
    if (r.lathe) rc.inner_radius = 0.5 * size.x() * r.profile.back().radius - wall;
    else rc.inner_half_extents = Eigen::Vector2d(0.5 * size.x() - wall, 0.5 * size.y() - wall);
    rc.inner_depth = std::max(0.0, size.z() - wall);
    rc.placement.translation = Eigen::Vector3d(0, 0, size.z() - rc.inner_depth);
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
      {"shoe", false, {}, V(0.08, 0.08, 0.09), 0.28, "fabric"},
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
      {"basket", false, {}, V(0.08, 0.08, 0.06), 0.15, "wood", true},
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
      {"laptop", false, {}, V(0.32, 0.22, 0.02), 1.5, "metal"},
      {"monitor", false, {}, V(0.5, 0.18, 0.35), 4.0, "plastic"},
      {"lamp", true, {{1, 0}, {1, 0.05}, {0.1, 0.1}, {0.1, 0.7}, {0.8, 0.75}, {0.5, 1}}, V(0.18, 0.18, 0.4), 1.2, "metal"},
      {"vase", true, {{0.6, 0}, {1, 0.4}, {0.4, 0.85}, {0.55, 1}}, V(0.14, 0.14, 0.28), 1.0, "ceramic"},
      {"plant_pot", true, {{0.75, 0}, {1, 1}}, V(0.16, 0.16, 0.15), 1.5, "ceramic"},
      {"phone", false, {}, V(0.075, 0.15, 0.009), 0.18, "glass"},
      {"keyboard", false, {}, V(0.44, 0.14, 0.03), 0.7, "plastic"},
      {"mouse", false, {}, V(0.065, 0.11, 0.035), 0.09, "plastic"},
      {"speaker", false, {}, V(0.12, 0.12, 0.2), 1.5, "wood"},
      {"clock", true, cyl(), V(0.2, 0.2, 0.05), 0.6, "plastic"},
      {"jar", true, {{1, 0}, {1, 0.85}, {0.8, 0.9}, {0.8, 1}}, V(0.1, 0.1, 0.15), 0.5, "glass"},
      {"toy", false, {}, V(0.1, 0.08, 0.12), 0.2, "plastic"},
      {"tissue_box", false, {}, V(0.24, 0.12, 0.09), 0.3, "cardboard"},
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
