// Spatial relations between objects on a table, judged on their centres in the horizontal plane
// (the ARR task of the ManiSoft paper, sections 3.2 and 3.4). One definition serves the scene
// sampler (which places the goal spot and rejects scenes whose relation already holds) and the
// success predicate (task/success.hpp), so the two can never disagree.
//
// Spatial words are the viewer's, looking from the default camera (in front of the table, on +x,
// towards -x): "left" is world -y, "right" +y, "in front of" +x (towards the camera), "behind" -x.
// The directional margins follow RoboTwin 2.0's place_a2b check (8-20 cm apart, 5 cm across),
// widened for 25 cm shoes.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <span>
#include <string_view>

namespace manisoft::geometry {

enum class RelationKind { left_of, right_of, in_front_of, behind, next_to, between, in_a_row };

inline std::string_view to_string(RelationKind kind) {
  switch (kind) {
    case RelationKind::left_of: return "left_of";
    case RelationKind::right_of: return "right_of";
    case RelationKind::in_front_of: return "in_front_of";
    case RelationKind::behind: return "behind";
    case RelationKind::next_to: return "next_to";
    case RelationKind::between: return "between";
    case RelationKind::in_a_row: return "in_a_row";
  }
  return "?";
}

/// How many centres a relation takes: the subject first, then its references (in_a_row: 3 or 4).
inline int relation_min_count(RelationKind kind) { return kind == RelationKind::between || kind == RelationKind::in_a_row ? 3 : 2; }
inline int relation_max_count(RelationKind kind) { return kind == RelationKind::in_a_row ? 4 : relation_min_count(kind); }

/// Margins of every relation (metres). The defaults are the benchmark's definition.
struct RelationTolerances {
  // left_of / right_of / in_front_of / behind: the centres `min_offset` to `max_offset` apart
  // along the relation's axis and at most `max_cross` apart across it;
  double min_offset = 0.05;
  double max_offset = 0.30;
  double max_cross = 0.08;
  // next_to: centres at most this far apart;
  double next_to = 0.20;
  // between(a; b, c): a projects onto the middle half of segment b-c, at most this far off it;
  double between_off_line = 0.05;
  // in_a_row: every centre at most this far from the line through the two farthest apart.
  double row_off_line = 0.03;

  /// The same relation with every margin tightened by `m` (m < 0 widens it): a spot that holds
  /// under the tightened margins still holds after the object settles up to `m` away.
  RelationTolerances tightened(double m) const {
    RelationTolerances t = *this;
    t.min_offset += m;
    t.max_offset -= m;
    t.max_cross -= m;
    t.next_to -= m;
    t.between_off_line -= m;
    t.row_off_line -= m;
    return t;
  }
};

/// Does `kind` hold between `centres` (subject first, then the references)? The caller checks
/// the count (relation_min_count .. relation_max_count).
inline bool relation_holds(RelationKind kind, std::span<const Eigen::Vector2d> c, const RelationTolerances& tol = {}) {
  using K = RelationKind;
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  const auto directional = [&](const Eigen::Vector2d& axis) {
    const Eigen::Vector2d d = c[0] - c[1];
    const double along = d.dot(axis);
    return along >= tol.min_offset && along <= tol.max_offset && std::abs(cross(d, axis)) <= tol.max_cross;
  };
  const Eigen::Vector2d left(0, -1), front(1, 0);
  switch (kind) {
    case K::left_of: return directional(left);
    case K::right_of: return directional(-left);
    case K::in_front_of: return directional(front);
    case K::behind: return directional(-front);
    case K::next_to: return (c[0] - c[1]).norm() <= tol.next_to;
    case K::between: {
      const Eigen::Vector2d bc = c[2] - c[1], ba = c[0] - c[1];
      const double length2 = bc.squaredNorm();
      if (length2 <= 0) return false;
      const double t = ba.dot(bc) / length2;
      return t >= 0.25 && t <= 0.75 && std::abs(cross(ba, bc)) / std::sqrt(length2) <= tol.between_off_line;
    }
    case K::in_a_row: {
      // The line through the two centres farthest apart; every centre close to it.
      const std::size_t n = c.size();
      std::size_t i0 = 0, i1 = 1;
      double far = -1;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
          if ((c[i] - c[j]).norm() > far) far = (c[i] - c[j]).norm(), i0 = i, i1 = j;
      if (far < tol.min_offset) return false;
      const Eigen::Vector2d u = (c[i1] - c[i0]) / far;
      for (std::size_t k = 0; k < n; ++k)
        if (std::abs(cross(c[k] - c[i0], u)) > tol.row_off_line) return false;
      return true;
    }
  }
  return false;
}

}  // namespace manisoft::geometry
