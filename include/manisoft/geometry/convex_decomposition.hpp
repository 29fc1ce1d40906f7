// Closed triangle meshes as solids (signed volume, closedness, inside test) and an approximate
// convex decomposition for concave ones (a bowl, a mug, an L-shaped bracket), so they can collide
// as a geometry::Compound of convex pieces.
//
// Decomposition: recursive splitting by planes. A piece is the solid cut by half-spaces; its
// concavity is (V_hull - V) / V, its convex hull's volume over its own volume. While a piece's
// concavity exceeds `concavity_tolerance` (and its excess V_hull - V exceeds
// `absolute_tolerance` times the whole solid's volume), it is cut by the candidate plane that
// minimises the summed excess of the two halves (candidates: normals x, y, z and six more
// horizontal ones every 22.5 degrees, offsets at 1/8 ... 7/8 of the piece's extent along the
// normal), worst piece first, up to `max_pieces`. Each final piece becomes its convex hull. The
// pieces' hulls cover the solid; their summed volume exceeds the solid's by the pieces' excesses
// (reported by the caller).
//
// Clipping keeps every piece a closed oriented surface without triangulating the cut polygons:
// a cut face is closed by a fan of triangles from one point on the plane to each cut segment
// (oriented against the clipped triangle that made it). For a non-convex cut polygon some fan
// triangles overlap or stick out, but with opposite signs, so the divergence-theorem volume stays
// exact (the surface is a closed 2-cycle whose winding number is the solid's, restricted to the
// half-space). The hull of a piece uses only points truly on it: the clipped original triangles'
// vertices plus the fan vertices that lie inside the solid (generalized winding number >= 1/2,
// A. Jacobson et al., "Robust inside-outside segmentation using generalized winding numbers",
// SIGGRAPH 2013; solid angle of a triangle by A. Van Oosterom and J. Strackee, IEEE TBME 1983).
#pragma once

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/convex_hull.hpp"
#include "manisoft/geometry/shapes.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace manisoft::geometry {

using Triangle3 = std::array<Eigen::Vector3d, 3>;

/// Signed volume enclosed by an oriented triangle soup (positive for outward winding).
inline double signed_volume(const std::vector<Triangle3>& triangles) {
  Eigen::Vector3d ref = Eigen::Vector3d::Zero();
  for (const auto& t : triangles) ref += t[0];
  if (!triangles.empty()) ref /= static_cast<double>(triangles.size());
  double six = 0;
  for (const auto& t : triangles) six += (t[0] - ref).dot((t[1] - ref).cross(t[2] - ref));
  return six / 6.0;
}

/// True when every directed edge (a, b) of the indexed mesh is matched by as many (b, a): a closed,
/// consistently oriented surface (vertices must already be welded by position).
inline bool is_closed(const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> balance;
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      if (a == b) continue;
      const int sign = a < b ? 1 : -1;
      if (a > b) std::swap(a, b);
      balance[{a, b}] += sign;
    }
  }
  for (const auto& [edge, count] : balance) {
    if (count != 0) return false;
  }
  return true;
}

/// Generalized winding number of `point` with respect to an oriented closed surface: 1 inside,
/// 0 outside (sum of signed solid angles / 4 pi).
inline double winding_number(const std::vector<Triangle3>& triangles, const Eigen::Vector3d& point) {
  double total = 0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = t[0] - point, b = t[1] - point, c = t[2] - point;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    if (numerator == 0 && denominator == 0) continue;
    total += 2.0 * std::atan2(numerator, denominator);
  }
  return total / (4.0 * std::numbers::pi);
}

struct DecompositionOptions {
  double concavity_tolerance = 0.05;  ///< accept a piece when (V_hull - V) / V <= this
  double absolute_tolerance = 0.002;  ///< ... or when V_hull - V <= this x the solid's volume
  int max_pieces = 32;
  int max_depth = 10;
  double min_piece_fraction = 1e-5;   ///< pieces smaller than this x the solid's volume are dropped
};

namespace detail {

struct SolidPiece {
  std::vector<Triangle3> real;  ///< clipped triangles of the original surface
  std::vector<Triangle3> caps;  ///< fan triangles closing the cuts (signed; may overhang)
  double volume = 0;
  double hull_volume = 0;
};

/// Point where the plane (signed distances sa, sb) crosses the segment a-b, computed from the
/// lexicographically smaller end so both triangles sharing the edge get the same point.
inline Eigen::Vector3d plane_crossing(const Eigen::Vector3d& a, double sa, const Eigen::Vector3d& b, double sb) {
  const bool a_first = std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  if (!a_first) return plane_crossing(b, sb, a, sa);
  const double t = sa / (sa - sb);
  return a + t * (b - a);
}

/// Keeps the part of `triangles` where sign * (n . x - d) <= 0 (sign = +1: below the plane).
/// Appends the kept triangles to `out` and the cut segments (oriented as the kept polygon's
/// boundary runs along the plane) to `segments`.
inline void clip_triangles(const std::vector<Triangle3>& triangles, const Eigen::Vector3d& normal, double offset,
                           double sign, std::vector<Triangle3>& out,
                           std::vector<std::array<Eigen::Vector3d, 2>>& segments) {
  std::array<Eigen::Vector3d, 4> poly;
  for (const auto& t : triangles) {
    std::array<double, 3> s{};
    int inside_count = 0;
    for (int k = 0; k < 3; ++k) {
      s[static_cast<std::size_t>(k)] = sign * (normal.dot(t[static_cast<std::size_t>(k)]) - offset);
      if (s[static_cast<std::size_t>(k)] <= 0) ++inside_count;
    }
    if (inside_count == 3) {
      out.push_back(t);
      continue;
    }
    if (inside_count == 0) continue;
    int count = 0;
    int enter = -1, leave = -1;  // polygon indices of the crossing points
    for (int k = 0; k < 3; ++k) {
      const auto ka = static_cast<std::size_t>(k), kb = static_cast<std::size_t>((k + 1) % 3);
      const bool in_a = s[ka] <= 0, in_b = s[kb] <= 0;
      if (in_a) poly[static_cast<std::size_t>(count++)] = t[ka];
      if (in_a != in_b) {
        if (in_a) leave = count; else enter = count;
        poly[static_cast<std::size_t>(count++)] = plane_crossing(t[ka], s[ka], t[kb], s[kb]);
      }
    }
    for (int k = 1; k + 1 < count; ++k) {
      out.push_back({poly[0], poly[static_cast<std::size_t>(k)], poly[static_cast<std::size_t>(k + 1)]});
    }
    // The boundary runs leave -> enter along the plane (outside the half-space in between).
    if (leave >= 0 && enter >= 0) {
      segments.push_back({poly[static_cast<std::size_t>(leave)], poly[static_cast<std::size_t>(enter)]});
    }
  }
}

/// Splits `piece` by the plane n . x = d into the part below (first) and above (second).
inline std::array<SolidPiece, 2> split_piece(const SolidPiece& piece, const Eigen::Vector3d& normal, double offset) {
  std::array<SolidPiece, 2> halves;
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;
    auto& half = halves[static_cast<std::size_t>(side)];
    std::vector<std::array<Eigen::Vector3d, 2>> segments;
    clip_triangles(piece.real, normal, offset, sign, half.real, segments);
    clip_triangles(piece.caps, normal, offset, sign, half.caps, segments);
    if (segments.empty()) continue;
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    for (const auto& sgm : segments) center += sgm[0] + sgm[1];
    center /= static_cast<double>(2 * segments.size());
    center -= normal * (normal.dot(center) - offset);  // exactly on the plane
    // The cap's boundary runs opposite to the clipped triangles' cut edges.
    for (const auto& sgm : segments) half.caps.push_back({center, sgm[1], sgm[0]});
  }
  return halves;
}

inline std::vector<Eigen::Vector3d> piece_points(const SolidPiece& piece, const std::vector<Triangle3>* solid) {
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(3 * piece.real.size());
  for (const auto& t : piece.real) pts.insert(pts.end(), t.begin(), t.end());
  if (solid != nullptr) {
    for (const auto& t : piece.caps) {
      for (const auto& p : t) {
        if (winding_number(*solid, p) >= 0.5) pts.push_back(p);
      }
    }
  }
  return pts;
}

/// Hull volume of a point set; 0 when the set is flat or too small.
inline double hull_volume_or_zero(const std::vector<Eigen::Vector3d>& pts, ConvexMesh<double>* hull_out = nullptr) {
  if (pts.size() < 4) return 0;
  try {
    ConvexMesh<double> hull = convex_hull(pts, "piece");
    std::vector<Triangle3> tris;
    tris.reserve(hull.triangles.size());
    for (const auto& t : hull.triangles) tris.push_back({hull.vertices[t[0]], hull.vertices[t[1]], hull.vertices[t[2]]});
    const double v = signed_volume(tris);
    if (hull_out != nullptr) *hull_out = std::move(hull);
    return v;
  } catch (const ::manisoft::Error&) {
    return 0;
  }
}

}  // namespace detail

/// Approximate convex decomposition of a closed, outward-oriented triangle surface (see the header
/// comment). Returns the convex pieces (hulls, in the input's frame). Throws manisoft::Error when
/// the surface encloses no volume.
inline std::vector<ConvexMesh<double>> approximate_convex_decomposition(const std::vector<Triangle3>& solid,
                                                                         const std::string& source,
                                                                         const DecompositionOptions& options = {}) {
  const double total = signed_volume(solid);
  if (!(total > 0) || !std::isfinite(total)) {
    ::manisoft::detail::fail("convex decomposition of '", source, "': the surface encloses no positive volume (",
                             total, " m^3)");
  }
  // Best first: always split the piece whose hull exceeds it most, until every piece is within
  // the tolerances or the piece budget is spent.
  struct Candidate {
    detail::SolidPiece piece;
    ConvexMesh<double> hull;
    double excess = 0;
    int depth = 0;
    bool done = false;
  };
  auto evaluate = [&](detail::SolidPiece piece, int depth) {
    Candidate c;
    c.depth = depth;
    const double hull_volume = detail::hull_volume_or_zero(detail::piece_points(piece, &solid), &c.hull);
    c.excess = hull_volume - piece.volume;
    c.done = c.excess <= options.concavity_tolerance * piece.volume || c.excess <= options.absolute_tolerance * total ||
              depth >= options.max_depth;
    c.piece = std::move(piece);
    return c;
  };
  detail::SolidPiece root;
  root.real = solid;
  root.volume = total;
  std::vector<Candidate> pieces;
  pieces.push_back(evaluate(std::move(root), 0));
  std::vector<Eigen::Vector3d> normals{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  for (int k = 1; k < 8; ++k) {
    if (k == 4) continue;
    const double angle = std::numbers::pi * k / 8.0;
    normals.emplace_back(std::cos(angle), std::sin(angle), 0.0);
  }
  while (static_cast<int>(pieces.size()) < options.max_pieces) {
    std::size_t worst = pieces.size();
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      if (!pieces[i].done && (worst == pieces.size() || pieces[i].excess > pieces[worst].excess)) worst = i;
    }
    if (worst == pieces.size()) break;
    const detail::SolidPiece& piece = pieces[worst].piece;
    double best_cost = std::numeric_limits<double>::infinity();
    std::array<detail::SolidPiece, 2> best_halves;
    for (const auto& n : normals) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const auto& t : piece.real) {
        for (const auto& p : t) lo = std::min(lo, n.dot(p)), hi = std::max(hi, n.dot(p));
      }
      if (!(hi - lo > 0)) continue;
      for (int k = 1; k <= 7; ++k) {
        // An irrational-ish shift keeps cuts off the (often grid-aligned) vertices.
        const double offset = lo + (hi - lo) * (k / 8.0 + 1.234567e-4);
        auto halves = detail::split_piece(piece, n, offset);
        double cost = 0;
        bool usable = true;
        for (auto& h : halves) {
          std::vector<Triangle3> all = h.real;
          all.insert(all.end(), h.caps.begin(), h.caps.end());
          h.volume = signed_volume(all);
          if (!(h.volume > options.min_piece_fraction * total)) {
            usable = false;
            break;
          }
          cost += std::max(0.0, detail::hull_volume_or_zero(detail::piece_points(h, nullptr)) - h.volume);
        }
        if (usable && cost < best_cost) {
          best_cost = cost;
          best_halves = std::move(halves);
        }
      }
    }
    if (!std::isfinite(best_cost)) {
      pieces[worst].done = true;  // no usable cut
      continue;
    }
    const int depth = pieces[worst].depth + 1;
    pieces[worst] = evaluate(std::move(best_halves[0]), depth);
    pieces.push_back(evaluate(std::move(best_halves[1]), depth));
  }
  std::vector<ConvexMesh<double>> result;
  for (auto& c : pieces) {
    if (c.piece.volume <= options.min_piece_fraction * total || c.hull.vertices.size() < 4) continue;
    c.hull.source = source + " piece " + std::to_string(result.size());
    result.push_back(std::move(c.hull));
  }
  if (result.empty()) {
    ::manisoft::detail::fail("convex decomposition of '", source, "' produced no piece (degenerate solid)");
  }
  return result;
}

}  // namespace manisoft::geometry
