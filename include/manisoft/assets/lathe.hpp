// Surfaces of revolution for the procedurally generated assets of the "ManiSoft" benchmark
// (paper section 3.3, assets): a 2-D profile r(z) (a polyline of (radius, height) points from
// bottom to top) is swept around the z axis and closed by flat bottom and top caps. The mesh is
// watertight by position (caps and bands share ring positions), wound counter-clockwise seen from
// outside, with unit normals (per band, flat along the profile, smooth around z) and UVs
// (u = angle / 2 pi, v = normalised profile height). Also: the enclosed volume of a closed
// triangle mesh (divergence theorem) and a cylinder collision stand-in of equal volume.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "manisoft/geometry/shapes.hpp"
#include "manisoft/render/scene.hpp"

namespace manisoft::assets {

/// One profile point: radius (> 0) at height z.
struct ProfilePoint {
  double radius = 0;
  double z = 0;
};

/// Sweeps `profile` (bottom to top, increasing or equal z, radii > 0) around z with `segments`
/// divisions; closes the bottom (z = profile.front().z) and top caps.
inline render::Mesh make_lathe_mesh(const std::vector<ProfilePoint>& profile, int segments = 32) {
  if (profile.size() < 2) throw std::invalid_argument("make_lathe_mesh: profile needs >= 2 points");
  if (segments < 3) throw std::invalid_argument("make_lathe_mesh: segments must be >= 3");
  for (const auto& p : profile)
    if (!(p.radius > 0)) throw std::invalid_argument("make_lathe_mesh: radii must be > 0");
  render::Mesh m;
  const double two_pi = 2.0 * 3.14159265358979323846;
  const double z0 = profile.front().z;
  const double z1 = profile.back().z;
  const double zspan = (z1 - z0) > 0 ? (z1 - z0) : 1.0;
  auto push = [&](double r, double z, double a, const Eigen::Vector3d& n, float u, float v) {
    m.positions.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                             static_cast<float>(z));
    m.normals.push_back(n.normalized().cast<float>());
    m.uvs.emplace_back(u, v);
    return static_cast<std::uint32_t>(m.positions.size() - 1);
  };
  // Side bands: each profile segment gets its own vertex rings (flat normal along the profile).
  for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
    const auto& p = profile[k];
    const auto& q = profile[k + 1];
    const double dr = q.radius - p.radius;
    const double dz = q.z - p.z;
    if (std::abs(dr) < 1e-15 && std::abs(dz) < 1e-15) continue;
    // Outward normal in the (r, z) plane of direction (dr, dz): (dz, -dr).
    const double nr = dz, nz = -dr;
    const std::uint32_t base = static_cast<std::uint32_t>(m.positions.size());
    for (int i = 0; i <= segments; ++i) {
      const double a = two_pi * (i % segments) / segments;
      const Eigen::Vector3d n(nr * std::cos(a), nr * std::sin(a), nz);
      const float u = static_cast<float>(i) / static_cast<float>(segments);
      push(p.radius, p.z, a, n, u, static_cast<float>((p.z - z0) / zspan));
      push(q.radius, q.z, a, n, u, static_cast<float>((q.z - z0) / zspan));
    }
    for (int i = 0; i < segments; ++i) {
      const std::uint32_t a0 = base + 2u * static_cast<std::uint32_t>(i), a1 = a0 + 1, b0 = a0 + 2, b1 = a0 + 3;
      m.indices.insert(m.indices.end(), {a0, b0, b1, a0, b1, a1});
    }
  }
  // Caps: a centre vertex and a ring.
  auto cap = [&](const ProfilePoint& p, bool top) {
    const Eigen::Vector3d n(0, 0, top ? 1.0 : -1.0);
    const std::uint32_t c = push(0.0, p.z, 0.0, n, 0.5f, 0.5f);
    const std::uint32_t base = static_cast<std::uint32_t>(m.positions.size());
    for (int i = 0; i < segments; ++i) {
      const double a = two_pi * i / segments;
      push(p.radius, p.z, a, n, static_cast<float>(0.5 + 0.5 * std::cos(a)),
           static_cast<float>(0.5 + 0.5 * std::sin(a)));
    }
    for (int i = 0; i < segments; ++i) {
      const std::uint32_t r0 = base + static_cast<std::uint32_t>(i);
      const std::uint32_t r1 = base + static_cast<std::uint32_t>((i + 1) % segments);
      if (top) m.indices.insert(m.indices.end(), {c, r0, r1});
      else m.indices.insert(m.indices.end(), {c, r1, r0});
    }
  };
  cap(profile.front(), false);
  cap(profile.back(), true);
  return m;
}

/// Enclosed volume of a closed, outward-wound triangle mesh (divergence theorem).
inline double mesh_volume(const render::Mesh& m) {
  double v = 0;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const Eigen::Vector3d a = m.positions[m.indices[t]].cast<double>();
    const Eigen::Vector3d b = m.positions[m.indices[t + 1]].cast<double>();
    const Eigen::Vector3d c = m.positions[m.indices[t + 2]].cast<double>();
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

/// Exact volume of the polygonal lathe (sum of frustum volumes of the polygon-section solid).
inline double lathe_volume(const std::vector<ProfilePoint>& profile, int segments = 32) {
  const double pi = 3.14159265358979323846;
  const double k = 0.5 * segments * std::sin(2.0 * pi / segments);  // polygon area / r^2
  double v = 0;
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    const double r0 = profile[i].radius, r1 = profile[i + 1].radius;
    v += k * (profile[i + 1].z - profile[i].z) * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
  }
  return v;
}

/// Cylinder collision stand-in (axis z, centred at half the profile height: place it with a
/// compound offset) whose volume equals the lathe's: radius = sqrt(V / (pi h)).
inline geometry::Cylinder<double> lathe_equal_volume_cylinder(const std::vector<ProfilePoint>& profile,
                                                              int segments = 32) {
  const double pi = 3.14159265358979323846;
  const double h = profile.back().z - profile.front().z;
  geometry::Cylinder<double> c;
  c.half_height = 0.5 * h;
  c.radius = std::sqrt(lathe_volume(profile, segments) / (pi * h));
  return c;
}

}  // namespace manisoft::assets
