// The arm's reachable table area (the scenes use only what the arm reaches; paper figure 4c: targets "broadly and evenly distributed across the entire table"): for a grid
// of cells over the table top, whether a tool-down gripper pose above the cell centre, at a given
// height above the top, has a static equilibrium within the actuation limits (rod::InverseStatics
// + rod::ActuationLimits) whose rod stays clear of the table. Samplers place objects only in
// reachable cells, and tool_down_reachable() is the per-pose check the scene validation uses.
//
// A cell counts as reachable when, at every height of `ReachMapSettings::heights` (the grasp
// frames of short and tall objects), the tool-down pose with some yaw of `yaws` is reachable.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <vector>

#include "manisoft/control/tool_down.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/interaction/gripper.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::scene {

/// The tool-down gripper frame (z = -world z, closing axis x rotated by `yaw` about world z) at
/// `position` (palm top centre, where the rod tip attaches).
inline math::Pose<double> tool_down_pose(const Eigen::Vector3d& position, double yaw) {
  return math::Pose<double>{control::tool_down_rotation(yaw), position};
}

/// The inverse statics of the scene arm (world::tabletop_arm_parameters at the world's mount,
/// the gripper's mass on the tip), within the arm world's actuation limits.
inline rod::InverseStatics<double> make_scene_statics() {
  const interaction::ParallelGripperParameters gp;
  const world::ArmWorldSettings ws;
  return rod::InverseStatics<double>(rod::make_arm_model(world::tabletop_arm_parameters(), gp.mass), {}, ws.limits);
}

/// Whether `target` (a gripper frame) has an equilibrium within the actuation limits whose rod
/// nodes all stay at least `clearance` above the plane z = `table_top` (nodes inside the gripper,
/// the last one, excepted). Solves cold (unrelated targets).
inline bool pose_reachable(rod::InverseStatics<double>& statics, const math::Pose<double>& target, double table_top, double clearance) {
  const auto r = statics.solve_cold(target);
  if (!r.within_limits) return false;
  const auto& x = statics.desired_state().positions;
  for (int k = 0; k + 1 < x.rows(); ++k)
    if (x(k, 2) < table_top + clearance) return false;
  return true;
}

/// Where samplers place things: the measured reachable area (measure_reach_map; docs/scenes.md
/// has the picture) as two simple shapes, both shrunk by `margin`:
///  - the band in front of the base in which tool-down poses at height h (gripper frame above the
///    table top) are reachable, an annulus of radii r_in(h) = inner + inner_slope h and
///    r_out(h) = outer + outer_slope h about the base's horizontal position;
///  - the two back corners of the table beside the base (x <= corner_x_max, |y| >= corner_y_min),
///    reached with the gripper turned a quarter turn: only with `corners` (off by default). The
///    arm reaches them curled back beside its base, and moves between them and the annulus are
///    where the expert fails most (refused or slow lines, lost objects).
/// The coefficients are design parameters read off the measured maps; every sampled pose is still
/// checked with the inverse statics before a scene is returned.
struct ReachBand {
  Eigen::Vector2d center = world::ArmMount{}.base_position.head<2>();
  double inner = 0.40, inner_slope = 0.43;
  double outer = 0.60, outer_slope = 0.53;
  double corner_x_max = 0.325, corner_y_min = 0.275;
  double margin = 0.02;
  bool corners = false;  ///< the back corners are part of the area
  double r_in(double h) const { return inner + inner_slope * h + margin; }
  double r_out(double h) const { return outer + outer_slope * h - margin; }
  bool in_annulus(const Eigen::Vector2d& p, double h) const {
    const double r = (p - center).norm();
    return p.x() > center.x() && r >= r_in(h) && r <= r_out(h);
  }
  bool in_corners(const Eigen::Vector2d& p) const { return p.x() <= corner_x_max - margin && std::abs(p.y()) >= corner_y_min + margin; }
  bool contains(const Eigen::Vector2d& p, double h) const { return in_annulus(p, h) || (corners && in_corners(p)); }
};

struct ReachMapSettings {
  double cell = 0.05;                       ///< m, grid cell size over the table top
  std::vector<double> heights{0.10, 0.30};  ///< m, gripper frame above the top (short and tall objects' grasps)
  std::vector<double> yaws{0.0, 1.5707963267948966};  ///< rad, tried in order
  double clearance = 0.05;                  ///< m, rod nodes above the top (the rod radius)
};

/// Reachability per cell of the table top; row ix = x index (from the back edge), column iy.
struct ReachMap {
  double x0 = 0, y0 = 0, cell = 0.05;  ///< lower corner of cell (0, 0)
  int nx = 0, ny = 0;
  std::vector<std::uint8_t> reachable;  ///< nx * ny, 1 = reachable

  bool cell_reachable(int ix, int iy) const {
    return ix >= 0 && iy >= 0 && ix < nx && iy < ny && reachable[static_cast<std::size_t>(ix * ny + iy)] != 0;
  }
  /// Whether the point (x, y) lies in a reachable cell.
  bool contains(double x, double y) const {
    const int ix = static_cast<int>(std::floor((x - x0) / cell)), iy = static_cast<int>(std::floor((y - y0) / cell));
    return cell_reachable(ix, iy);
  }
  Eigen::Vector2d cell_center(int ix, int iy) const { return {x0 + (ix + 0.5) * cell, y0 + (iy + 0.5) * cell}; }
  int reachable_count() const {
    int c = 0;
    for (auto v : reachable) c += v != 0;
    return c;
  }
  double covered_fraction() const { return reachable.empty() ? 0.0 : double(reachable_count()) / double(reachable.size()); }
};

/// Measures the map over the table top `table` with `statics` (one cold solve per cell, height
/// and yaw until one succeeds).
inline ReachMap measure_reach_map(rod::InverseStatics<double>& statics, const world::TableDesc& table, const ReachMapSettings& s = {}) {
  manisoft::detail::require_positive("ReachMapSettings cell", s.cell);
  if (s.heights.empty() || s.yaws.empty()) manisoft::detail::fail("ReachMapSettings: heights and yaws must not be empty");
  ReachMap m;
  m.cell = s.cell;
  m.x0 = table.top_center.x() - table.half_x;
  m.y0 = table.top_center.y() - table.half_y;
  m.nx = static_cast<int>(std::floor(2 * table.half_x / s.cell + 1e-9));
  m.ny = static_cast<int>(std::floor(2 * table.half_y / s.cell + 1e-9));
  m.reachable.assign(static_cast<std::size_t>(m.nx * m.ny), 0);
  const double top = table.top_center.z();
  for (int ix = 0; ix < m.nx; ++ix)
    for (int iy = 0; iy < m.ny; ++iy) {
      const Eigen::Vector2d c = m.cell_center(ix, iy);
      bool all_heights = true;
      for (double h : s.heights) {
        bool any_yaw = false;
        for (double yaw : s.yaws) {
          if (pose_reachable(statics, tool_down_pose({c.x(), c.y(), top + h}, yaw), top, s.clearance)) {
            any_yaw = true;
            break;
          }
        }
        if (!any_yaw) {
          all_heights = false;
          break;
        }
      }
      m.reachable[static_cast<std::size_t>(ix * m.ny + iy)] = all_heights ? 1 : 0;
    }
  return m;
}

}  // namespace manisoft::scene
