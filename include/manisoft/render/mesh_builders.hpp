// Triangle meshes for the renderer: primitives in their body frame (box,
// sphere, cylinder, capsule, surfaces of revolution such as a bowl, an axis triad for the goal
// marker) and the soft arm's tube, swept along the rod's centreline (a Catmull-Rom curve through
// the nodes) with frames from the directors (PyElastica layout: row i of Q_k is d_{i+1}) or, when
// none are given, rotation-minimising frames transported along the curve.
//
// Body-frame conventions match the rigid shapes of include/manisoft/rigid/: boxes, spheres,
// cylinders and capsules are centred on their origin, with cylinder and capsule axes along z.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::render {

namespace detail_mesh {

inline std::uint32_t add_vertex(Mesh& m, const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector2f& uv) {
  m.positions.push_back(p);
  m.normals.push_back(n);
  m.uvs.push_back(uv);
  return static_cast<std::uint32_t>(m.positions.size() - 1);
}

inline void add_triangle(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.indices.push_back(a);
  m.indices.push_back(b);
  m.indices.push_back(c);
}

inline void require_segments(const char* what, int segments, int minimum) {
  if (segments < minimum || segments > 4096) {
    manisoft::detail::fail(what, " = ", segments, " is invalid: it must lie in [", minimum, ", 4096]");
  }
}

}  // namespace detail_mesh

/// Appends `part` to `mesh`, moved by `pose` (body of part -> body of mesh).
inline void append(Mesh& mesh, const Mesh& part, const math::Pose<double>& pose = {}) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  const Eigen::Matrix3f r = pose.rotation.cast<float>();
  const Eigen::Vector3f t = pose.translation.cast<float>();
  for (std::size_t i = 0; i < part.positions.size(); ++i) {
    mesh.positions.push_back(r * part.positions[i] + t);
    mesh.normals.push_back(r * part.normals[i]);
    mesh.uvs.push_back(part.uvs[i]);
  }
  for (std::uint32_t idx : part.indices) mesh.indices.push_back(base + idx);
}

/// Axis-aligned box of the given half extents, centred on the origin (24 vertices, 12 triangles).
inline Mesh make_box(const Eigen::Vector3d& half_extents) {
  if (!half_extents.allFinite() || !(half_extents.minCoeff() > 0)) {
    manisoft::detail::fail("make_box: half_extents = (", half_extents.transpose(), ") must be finite and > 0");
  }
  Mesh m;
  const Eigen::Vector3f h = half_extents.cast<float>();
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = static_cast<float>(sign);
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;  // (a, b, axis) is right-handed
      std::uint32_t v[4];
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (int c = 0; c < 4; ++c) {
        Eigen::Vector3f p = Eigen::Vector3f::Zero();
        p[axis] = static_cast<float>(sign) * h[axis];
        p[a] = corners[c][0] * h[a];
        p[b] = corners[c][1] * h[b];
        v[c] = detail_mesh::add_vertex(m, p, n, {0.5f * (corners[c][0] + 1), 0.5f * (corners[c][1] + 1)});
      }
      if (sign > 0) {
        detail_mesh::add_triangle(m, v[0], v[1], v[2]);
        detail_mesh::add_triangle(m, v[0], v[2], v[3]);
      } else {
        detail_mesh::add_triangle(m, v[0], v[2], v[1]);
        detail_mesh::add_triangle(m, v[0], v[3], v[2]);
      }
    }
  }
  return m;
}

/// Sphere of `radius` centred on the origin (latitude-longitude grid).
inline Mesh make_sphere(double radius, int slices = 32, int stacks = 16) {
  manisoft::detail::require_positive("make_sphere: radius", radius);
  detail_mesh::require_segments("make_sphere: slices", slices, 3);
  detail_mesh::require_segments("make_sphere: stacks", stacks, 2);
  Mesh m;
  const double pi = std::numbers::pi;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = pi * i / stacks;  // from +z down to -z
    for (int j = 0; j <= slices; ++j) {
      const double phi = 2 * pi * j / slices;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      detail_mesh::add_vertex(m, (radius * n).cast<float>(), n.cast<float>(),
                              {static_cast<float>(j) / slices, static_cast<float>(i) / stacks});
    }
  }
  const auto row = static_cast<std::uint32_t>(slices + 1);
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = i * row + j, b = a + 1, c = a + row, d = c + 1;
      if (i > 0) detail_mesh::add_triangle(m, a, c, b);
      if (i < stacks - 1) detail_mesh::add_triangle(m, b, c, d);
    }
  }
  return m;
}

/// Surface of revolution about z: `profile` holds (r, z) points in order; the surface faces
/// outward where the profile runs upward with r on its left... concretely, normals point to the
/// right of the direction of travel in the (r, z) plane (outward for a profile going up).
inline Mesh make_lathe(const std::vector<Eigen::Vector2d>& profile, int sides = 32) {
  detail_mesh::require_segments("make_lathe: sides", sides, 3);
  if (profile.size() < 2) manisoft::detail::fail("make_lathe: profile has ", profile.size(), " points: need >= 2");
  Mesh m;
  const double pi = std::numbers::pi;
  // Each profile segment gets its own rings: flat shading across the profile's corners.
  for (std::size_t s = 0; s + 1 < profile.size(); ++s) {
    const Eigen::Vector2d p0 = profile[s], p1 = profile[s + 1];
    const Eigen::Vector2d d = p1 - p0;
    if (!(d.norm() > 0)) continue;
    const Eigen::Vector2d n2 = Eigen::Vector2d(d.y(), -d.x()).normalized();  // right of travel
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int j = 0; j <= sides; ++j) {
      const double phi = 2 * pi * j / sides;
      const double c = std::cos(phi), sn = std::sin(phi);
      const Eigen::Vector3f n(static_cast<float>(n2.x() * c), static_cast<float>(n2.x() * sn), static_cast<float>(n2.y()));
      for (const Eigen::Vector2d& p : {p0, p1}) {
        detail_mesh::add_vertex(m, Eigen::Vector3f(static_cast<float>(p.x() * c), static_cast<float>(p.x() * sn), static_cast<float>(p.y())),
                                n, {static_cast<float>(j) / sides, static_cast<float>(p.y())});
      }
    }
    for (int j = 0; j < sides; ++j) {
      const std::uint32_t a = base + 2 * j, b = a + 1, c = a + 2, d2 = a + 3;  // a,c on p0; b,d2 on p1
      detail_mesh::add_triangle(m, a, c, d2);
      detail_mesh::add_triangle(m, a, d2, b);
    }
  }
  return m;
}

/// Closed cylinder of `radius`, axis z from -half_height to +half_height.
inline Mesh make_cylinder(double radius, double half_height, int sides = 32) {
  manisoft::detail::require_positive("make_cylinder: radius", radius);
  manisoft::detail::require_positive("make_cylinder: half_height", half_height);
  const double r = radius, h = half_height;
  return make_lathe({{0, -h}, {r, -h}, {r, h}, {0, h}}, sides);
}

/// Capsule: a cylinder of `radius` from z = -half_length to +half_length with hemispherical ends.
inline Mesh make_capsule(double radius, double half_length, int sides = 24, int cap_stacks = 8) {
  manisoft::detail::require_positive("make_capsule: radius", radius);
  manisoft::detail::require_non_negative("make_capsule: half_length", half_length);
  detail_mesh::require_segments("make_capsule: cap_stacks", cap_stacks, 1);
  Mesh m;
  // Smooth normals: build the profile with one ring per point and radial normals.
  std::vector<Eigen::Vector2d> points, normals;
  for (int i = 0; i <= cap_stacks; ++i) {
    const double a = -0.5 * std::numbers::pi + 0.5 * std::numbers::pi * i / cap_stacks;
    points.emplace_back(radius * std::cos(a), -half_length + radius * std::sin(a));
    normals.emplace_back(std::cos(a), std::sin(a));
  }
  for (int i = 0; i <= cap_stacks; ++i) {
    const double a = 0.5 * std::numbers::pi * i / cap_stacks;
    points.emplace_back(radius * std::cos(a), half_length + radius * std::sin(a));
    normals.emplace_back(std::cos(a), std::sin(a));
  }
  const double pi = std::numbers::pi;
  const auto row = static_cast<std::uint32_t>(sides + 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int j = 0; j <= sides; ++j) {
      const double phi = 2 * pi * j / sides;
      const double c = std::cos(phi), s = std::sin(phi);
      detail_mesh::add_vertex(
          m, Eigen::Vector3f(static_cast<float>(points[i].x() * c), static_cast<float>(points[i].x() * s), static_cast<float>(points[i].y())),
          Eigen::Vector3f(static_cast<float>(normals[i].x() * c), static_cast<float>(normals[i].x() * s), static_cast<float>(normals[i].y())),
          {static_cast<float>(j) / sides, static_cast<float>(i) / (points.size() - 1)});
    }
  }
  for (std::uint32_t i = 0; i + 1 < points.size(); ++i) {
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sides); ++j) {
      const std::uint32_t a = i * row + j, b = a + 1, c = a + row, d = c + 1;
      detail_mesh::add_triangle(m, a, b, d);
      detail_mesh::add_triangle(m, a, d, c);
    }
  }
  return m;
}

/// Open bowl (or cup, plate): flat base disc of `base_radius`, a wall of slant length
/// `wall_length` flared `flare_angle` (rad) from vertical, `thickness` thick; origin at the centre
/// of the base's underside. The same profile as rigid::make_vessel's bowl.
inline Mesh make_vessel(double base_radius, double wall_length, double thickness, double flare_angle, int sides = 32) {
  manisoft::detail::require_positive("make_vessel: base_radius", base_radius);
  manisoft::detail::require_positive("make_vessel: wall_length", wall_length);
  manisoft::detail::require_positive("make_vessel: thickness", thickness);
  if (!(flare_angle >= 0) || !(flare_angle < 0.5 * std::numbers::pi)) {
    manisoft::detail::fail("make_vessel: flare_angle = ", flare_angle, " rad must lie in [0, pi/2)");
  }
  const double rim_r = base_radius + wall_length * std::sin(flare_angle);
  const double rim_z = wall_length * std::cos(flare_angle);
  const double t = thickness;
  // Outer surface going up, the rim, then the inner surface going down to the centre.
  return make_lathe({{0, 0}, {base_radius, 0}, {rim_r, rim_z}, {rim_r - t, rim_z}, {base_radius - t, t}, {0, t}}, sides);
}

/// An axis triad (x red, y green, z blue by the caller's materials): three boxes, returned
/// separately so each can get its own material. Each starts at the origin and runs `length`
/// along its axis.
inline std::vector<Mesh> make_axis_triad(double length, double width) {
  manisoft::detail::require_positive("make_axis_triad: length", length);
  manisoft::detail::require_positive("make_axis_triad: width", width);
  std::vector<Mesh> out;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * width);
    half[axis] = 0.5 * length;
    math::Pose<double> pose;
    pose.translation[axis] = 0.5 * length;
    Mesh m;
    append(m, make_box(half), pose);
    out.push_back(std::move(m));
  }
  return out;
}

/// Unit normal of a frame along the curve: rotation-minimising frames (parallel transport of the
/// first normal by the rotation taking each tangent to the next).
inline std::vector<Eigen::Vector3d> transport_normals(const std::vector<Eigen::Vector3d>& tangents, Eigen::Vector3d first_normal) {
  std::vector<Eigen::Vector3d> normals(tangents.size());
  if (tangents.empty()) return normals;
  Eigen::Vector3d n = first_normal - first_normal.dot(tangents[0]) * tangents[0];
  if (!(n.norm() > 1e-9)) {  // any perpendicular
    n = tangents[0].unitOrthogonal();
  }
  n.normalize();
  normals[0] = n;
  for (std::size_t i = 1; i < tangents.size(); ++i) {
    const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(tangents[i - 1], tangents[i]);
    n = q * n;
    n = (n - n.dot(tangents[i]) * tangents[i]).normalized();
    normals[i] = n;
  }
  return normals;
}

/// Options of the rod tube.
struct TubeOptions {
  int sides = 24;        ///< vertices around
  int subdivisions = 4;  ///< rings per element
  bool caps = true;      ///< flat discs closing both ends
};

/// The rod as a smooth tube of `radius` (world frame): rings swept along a uniform Catmull-Rom
/// curve through the (n + 1) nodes; ring frames from the directors when given (d1 averaged at the
/// nodes, interpolated and made orthogonal to the curve's tangent), else transported along the
/// curve. Throws for fewer than 2 nodes, non-finite input, or mismatched director rows.
/// make_tube_into writes into `m` (replacing its contents, reusing its storage: the renderer
/// rebuilds the tube every frame).
inline void make_tube_into(Mesh& m, const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& nodes,
                           const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor>>& directors, double radius,
                           const TubeOptions& options = {}) {
  manisoft::detail::require_positive("make_tube: radius", radius);
  detail_mesh::require_segments("make_tube: sides", options.sides, 3);
  detail_mesh::require_segments("make_tube: subdivisions", options.subdivisions, 1);
  const Eigen::Index count = nodes.rows();
  if (count < 2) manisoft::detail::fail("make_tube: ", count, " nodes: need >= 2");
  if (!nodes.allFinite()) manisoft::detail::fail("make_tube: the rod's nodes must be finite");
  const bool have_directors = directors.rows() > 0;
  if (have_directors && directors.rows() != count - 1) {
    manisoft::detail::fail("make_tube: ", directors.rows(), " director rows for ", count, " nodes: need nodes - 1 = ", count - 1);
  }
  if (have_directors && !directors.allFinite()) manisoft::detail::fail("make_tube: the rod's directors must be finite");
  auto node = [&](Eigen::Index i) -> Eigen::Vector3d { return nodes.row(i).transpose(); };
  // Mirrored end points make the curve's end tangents follow the end segments.
  auto point = [&](Eigen::Index i) -> Eigen::Vector3d {
    if (i < 0) return 2 * node(0) - node(1);
    if (i >= count) return 2 * node(count - 1) - node(count - 2);
    return node(i);
  };
  // d1 at each node from the directors (row 0 of Q_k).
  std::vector<Eigen::Vector3d> node_normals;
  if (have_directors) {
    node_normals.resize(static_cast<std::size_t>(count));
    for (Eigen::Index i = 0; i < count; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      if (i > 0) d += directors.row(i - 1).head<3>().transpose();
      if (i < count - 1) d += directors.row(i).head<3>().transpose();
      node_normals[static_cast<std::size_t>(i)] = d;
    }
  }
  const int sub = options.subdivisions;
  std::vector<Eigen::Vector3d> centres, tangents, normals;
  for (Eigen::Index seg = 0; seg + 1 < count; ++seg) {
    const Eigen::Vector3d p0 = point(seg - 1), p1 = point(seg), p2 = point(seg + 1), p3 = point(seg + 2);
    for (int k = (seg == 0 ? 0 : 1); k <= sub; ++k) {
      const double s = static_cast<double>(k) / sub;
      const double s2 = s * s, s3 = s2 * s;
      // Uniform Catmull-Rom: C(s) = 0.5 [2 p1 + (-p0 + p2) s + (2p0 - 5p1 + 4p2 - p3) s^2 + (-p0 + 3p1 - 3p2 + p3) s^3]
      const Eigen::Vector3d c = 0.5 * (2 * p1 + (p2 - p0) * s + (2 * p0 - 5 * p1 + 4 * p2 - p3) * s2 + (3 * p1 - p0 - 3 * p2 + p3) * s3);
      Eigen::Vector3d d = 0.5 * ((p2 - p0) + 2 * (2 * p0 - 5 * p1 + 4 * p2 - p3) * s + 3 * (3 * p1 - p0 - 3 * p2 + p3) * s2);
      if (!(d.norm() > 1e-12)) d = p2 - p1;
      if (!(d.norm() > 1e-12)) manisoft::detail::fail("make_tube: nodes ", seg, " and ", seg + 1, " coincide");
      centres.push_back(c);
      tangents.push_back(d.normalized());
      if (have_directors) {
        normals.push_back((1 - s) * node_normals[static_cast<std::size_t>(seg)] + s * node_normals[static_cast<std::size_t>(seg + 1)]);
      }
    }
  }
  const std::vector<Eigen::Vector3d> transported = transport_normals(tangents, have_directors ? normals[0] : Eigen::Vector3d::UnitZ());
  m.positions.clear();
  m.normals.clear();
  m.uvs.clear();
  m.indices.clear();
  const int sides = options.sides;
  const double pi = std::numbers::pi;
  const auto row = static_cast<std::uint32_t>(sides + 1);
  std::vector<double> cosines(static_cast<std::size_t>(sides) + 1), sines(static_cast<std::size_t>(sides) + 1);
  for (int j = 0; j <= sides; ++j) {
    const double phi = 2 * pi * j / sides;
    cosines[static_cast<std::size_t>(j)] = std::cos(phi);
    sines[static_cast<std::size_t>(j)] = std::sin(phi);
  }
  std::vector<Eigen::Vector3d> n1s(centres.size()), n2s(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d& t = tangents[i];
    Eigen::Vector3d n1 = transported[i];
    if (have_directors) {
      const Eigen::Vector3d cand = normals[i] - normals[i].dot(t) * t;
      if (cand.norm() > 0.1 * normals[i].norm() && cand.norm() > 1e-9) n1 = cand.normalized();
    }
    n1s[i] = n1;
    n2s[i] = t.cross(n1);
    for (int j = 0; j <= sides; ++j) {
      const Eigen::Vector3d radial = cosines[static_cast<std::size_t>(j)] * n1 + sines[static_cast<std::size_t>(j)] * n2s[i];
      detail_mesh::add_vertex(m, (centres[i] + radius * radial).cast<float>(), radial.cast<float>(),
                              {static_cast<float>(i) / (centres.size() - 1), static_cast<float>(j) / sides});
    }
  }
  for (std::uint32_t i = 0; i + 1 < centres.size(); ++i) {
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sides); ++j) {
      const std::uint32_t a = i * row + j, b = a + 1, c = a + row, d = c + 1;
      detail_mesh::add_triangle(m, a, d, c);  // (d - a) x (c - a) points outward
      detail_mesh::add_triangle(m, a, b, d);
    }
  }
  if (options.caps) {
    for (int end = 0; end < 2; ++end) {
      const std::size_t i = end == 0 ? 0 : centres.size() - 1;
      const Eigen::Vector3f n = (end == 0 ? -tangents[i] : tangents[i]).cast<float>();
      const std::uint32_t centre = detail_mesh::add_vertex(m, centres[i].cast<float>(), n, {0.5f, 0.5f});
      const auto first = static_cast<std::uint32_t>(m.positions.size());
      for (int j = 0; j <= sides; ++j) {
        const double c = cosines[static_cast<std::size_t>(j)], sn = sines[static_cast<std::size_t>(j)];
        const Eigen::Vector3d radial = c * n1s[i] + sn * n2s[i];
        detail_mesh::add_vertex(m, (centres[i] + radius * radial).cast<float>(), n, {static_cast<float>(0.5 + 0.5 * c), static_cast<float>(0.5 + 0.5 * sn)});
      }
      for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sides); ++j) {
        if (end == 0) detail_mesh::add_triangle(m, centre, first + j + 1, first + j);
        else detail_mesh::add_triangle(m, centre, first + j, first + j + 1);
      }
    }
  }
}

inline Mesh make_tube(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& nodes,
                      const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor>>& directors, double radius,
                      const TubeOptions& options = {}) {
  Mesh m;
  make_tube_into(m, nodes, directors, radius, options);
  return m;
}

}  // namespace manisoft::render
