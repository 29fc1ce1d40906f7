// The asset catalogue as scenes use it (paper section 3.3: objects and obstacles): lookup by
// asset id, each asset's footprint on the table, its symmetry about z (for ALN goals and for the
// grasp yaws a planner may choose), and the world-frame candidate grasps of a placed asset (its
// annotated grasps, each also turned half a turn about the approach axis: the parallel gripper is
// symmetric; axially symmetric assets also at a quarter turn).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <variant>
#include <utility>
#include <vector>

#include "manisoft/assets/asset.hpp"
#include "manisoft/assets/catalog.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/scene/scene_spec.hpp"

namespace manisoft::scene {

class AssetLibrary {
 public:
  AssetLibrary() : AssetLibrary(assets::object_catalog()) {}
  /// A library of other objects (e.g. the catalogue with one asset's mass changed) and obstacles.
  explicit AssetLibrary(std::vector<assets::Asset> objects, std::vector<assets::Asset> obstacles = assets::obstacle_catalog())
      : objects_(std::move(objects)), obstacles_(std::move(obstacles)) {
    for (std::size_t i = 0; i < objects_.size(); ++i) index_.push_back({objects_[i].id, &objects_[i]});
    for (std::size_t i = 0; i < obstacles_.size(); ++i) index_.push_back({obstacles_[i].id, &obstacles_[i]});
    std::sort(index_.begin(), index_.end(), [](const Entry& a, const Entry& b) { return a.id < b.id; });
  }
  // The index points into the owned vectors: not copyable or movable.
  AssetLibrary(const AssetLibrary&) = delete;
  AssetLibrary& operator=(const AssetLibrary&) = delete;

  /// The asset with this id, or nullptr.
  const assets::Asset* find(const std::string& id) const {
    const auto it = std::lower_bound(index_.begin(), index_.end(), id, [](const Entry& e, const std::string& k) { return e.id < k; });
    return it != index_.end() && it->id == id ? it->asset : nullptr;
  }
  /// The asset with this id; refuses an unknown id naming `where` (e.g. "scene.json: objects[2].asset_id").
  const assets::Asset& get(const std::string& id, const std::string& where) const {
    const assets::Asset* a = find(id);
    if (!a) manisoft::detail::fail(where, ": unknown asset id '", id, "' (ids look like 'bottle/03'; see asset_gallery)");
    return *a;
  }
  /// The instances of a category, in catalogue order.
  std::vector<const assets::Asset*> category(const std::string& name) const {
    std::vector<const assets::Asset*> out;
    for (const auto& a : objects_)
      if (a.category == name) out.push_back(&a);
    for (const auto& a : obstacles_)
      if (a.category == name) out.push_back(&a);
    return out;
  }
  const std::vector<assets::Asset>& objects() const { return objects_; }
  const std::vector<assets::Asset>& obstacles() const { return obstacles_; }

 private:
  struct Entry {
    std::string id;
    const assets::Asset* asset;
  };
  std::vector<assets::Asset> objects_, obstacles_;
  std::vector<Entry> index_;
};

/// Radius of the vertical cylinder about the asset's z axis that holds its bounding box.
inline double footprint_radius(const assets::Asset& a) {
  return std::hypot(std::abs(a.bounding_center.x()) + a.bounding_half_extents.x(), std::abs(a.bounding_center.y()) + a.bounding_half_extents.y());
}
/// Height of the asset's top above its origin (upright).
inline double asset_height(const assets::Asset& a) { return a.bounding_center.z() + a.bounding_half_extents.z(); }

/// Whether a compound is a hollow lathe's (assets/catalog.hpp): a floor cylinder on the z axis,
/// then rings of at least 8 equal parts, each ring's parts at one height and one distance from
/// the axis, evenly spaced in angle.
inline bool hollow_lathe_rings(const geometry::Compound<double>& c) {
  const auto& floor = c.parts.front();
  if (!std::holds_alternative<geometry::Cylinder<double>>(floor.shape) || floor.position.head<2>().norm() > 1e-9) return false;
  std::size_t ring = 0;  // parts per ring: those at the first ring's height
  while (1 + ring < c.parts.size() && std::abs(c.parts[1 + ring].position.z() - c.parts[1].position.z()) < 1e-12) ++ring;
  if (ring < 8 || (c.parts.size() - 1) % ring != 0) return false;
  for (std::size_t first = 1; first < c.parts.size(); first += ring) {
    const Eigen::Vector3d p0 = c.parts[first].position;
    for (std::size_t i = 0; i < ring; ++i) {
      const Eigen::Vector3d p = c.parts[first + i].position;
      const double angle = 2 * 3.14159265358979323846 * static_cast<double>(i) / static_cast<double>(ring);
      const Eigen::Vector2d expected = Eigen::Rotation2Dd(angle) * p0.head<2>();
      if (std::abs(p.z() - p0.z()) > 1e-9 || (p.head<2>() - expected).norm() > 1e-9) return false;
    }
  }
  return true;
}

/// The asset's symmetry about its z axis, read from its collision shape: one cylinder part or a
/// hollow lathe's rings -> axial; one box part -> 4-fold when its footprint is square, else
/// 2-fold; anything else none.
inline Symmetry asset_symmetry(const assets::Asset& a) {
  Symmetry s;
  auto from_box_or_cylinder = [&s](const auto& shape) {
    using S = std::decay_t<decltype(shape)>;
    if constexpr (std::is_same_v<S, geometry::Cylinder<double>>) {
      s.kind = Symmetry::Kind::axial;
    } else if constexpr (std::is_same_v<S, geometry::Box<double>>) {
      s.kind = Symmetry::Kind::discrete;
      s.order = std::abs(shape.half_extents.x() - shape.half_extents.y()) < 1e-9 ? 4 : 2;
    }
  };
  if (const auto* c = std::get_if<geometry::Compound<double>>(&a.collision)) {
    if (c->parts.size() > 1) {
      if (hollow_lathe_rings(*c)) s.kind = Symmetry::Kind::axial;
      return s;
    }
    if (c->parts.empty()) return s;
    const auto& part = c->parts.front();
    const double yaw_free = std::abs(part.orientation.x()) + std::abs(part.orientation.y()) + std::abs(part.orientation.z());
    if (std::abs(part.position.x()) > 1e-9 || std::abs(part.position.y()) > 1e-9 || yaw_free > 1e-9) return s;
    std::visit(from_box_or_cylinder, part.shape);
  } else {
    std::visit([&](const auto& shape) {
      if constexpr (!std::is_same_v<std::decay_t<decltype(shape)>, geometry::Compound<double>>) from_box_or_cylinder(shape);
    }, a.collision);
  }
  return s;
}

/// World-frame gripper poses that grasp asset `a` placed at `pose`: each annotated grasp, the
/// same turned half a turn about its approach axis, and for an axially symmetric asset both also
/// turned a quarter turn about the asset's z axis.
inline std::vector<math::Pose<double>> candidate_grasps(const assets::Asset& a, const math::Pose<double>& pose) {
  std::vector<math::Pose<double>> out;
  const bool axial = asset_symmetry(a).kind == Symmetry::Kind::axial;
  for (const auto& g : a.grasps) {
    for (int quarter = 0; quarter < (axial ? 2 : 1); ++quarter) {
      math::Pose<double> turn;
      turn.rotation = Eigen::AngleAxisd(quarter * 1.5707963267948966, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const math::Pose<double> w = pose * turn * g.grasp;
      out.push_back(w);
      math::Pose<double> flip = w;  // half a turn about the approach axis (gripper z)
      flip.rotation = w.rotation * Eigen::AngleAxisd(3.14159265358979323846, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      out.push_back(flip);
    }
  }
  return out;
}

}  // namespace manisoft::scene
