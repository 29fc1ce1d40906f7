// Closest points between segments and between a segment and a box: the exact geometric
// primitives behind the analytic sphere/capsule contacts (Ericson, "Real-Time Collision
// Detection", 5.1.9 for segment-segment; the segment-box distance is minimised exactly as a
// piecewise quadratic in the segment parameter, one quadratic per interval between the
// parameters where the segment crosses a slab plane of the box).
#pragma once

#include "manisoft/contact/contact_point.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace manisoft::contact {

struct SegmentClosest {
  double s{0}, t{0};  ///< parameters on the first and second segment, in [0, 1]
  Vec3 point_a{Vec3::Zero()}, point_b{Vec3::Zero()};
};

/// Closest points of segments p0-p1 and q0-q1.
inline SegmentClosest closest_segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double eps = 1e-300;
  SegmentClosest out;
  if (a <= eps && e <= eps) {
  } else if (a <= eps) {
    out.t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      out.s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      out.s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      out.t = (b * out.s + f) / e;
      if (out.t < 0) {
        out.t = 0;
        out.s = std::clamp(-c / a, 0.0, 1.0);
      } else if (out.t > 1) {
        out.t = 1;
        out.s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  out.point_a = p0 + out.s * d1;
  out.point_b = q0 + out.t * d2;
  return out;
}

/// Closest point of segment p0-p1 (box frame) to the box |x_i| <= h_i. Returns the segment
/// parameter; `box_point` receives the closest box point. Squared distance is 0 if they touch.
inline double closest_segment_box(const Vec3& p0, const Vec3& p1, const Vec3& h, Vec3& segment_point,
                                  Vec3& box_point) {
  const Vec3 d = p1 - p0;
  // Breakpoints where a coordinate crosses +-h_i: between them the clamping pattern is fixed and
  // the squared distance is a quadratic in t.
  std::array<double, 8> cuts{};
  int count = 0;
  cuts[static_cast<std::size_t>(count++)] = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) > 1e-300) {
      for (double side : {-h[i], h[i]}) {
        const double t = (side - p0[i]) / d[i];
        if (t > 0.0 && t < 1.0) cuts[static_cast<std::size_t>(count++)] = t;
      }
    }
  }
  cuts[static_cast<std::size_t>(count++)] = 1.0;
  for (int i = 1; i < count; ++i) {  // insertion sort (at most 8 values)
    const double x = cuts[static_cast<std::size_t>(i)];
    int j = i - 1;
    while (j >= 0 && cuts[static_cast<std::size_t>(j)] > x) {
      cuts[static_cast<std::size_t>(j + 1)] = cuts[static_cast<std::size_t>(j)];
      --j;
    }
    cuts[static_cast<std::size_t>(j + 1)] = x;
  }
  double best_t = 0, best_d2 = INFINITY;
  for (int k = 0; k + 1 < count; ++k) {
    const double lo = cuts[static_cast<std::size_t>(k)], hi = cuts[static_cast<std::size_t>(k + 1)];
    const Vec3 mid = p0 + 0.5 * (lo + hi) * d;
    // f(t) = sum over clamped axes of (p0_i + t d_i - c_i)^2, c_i = +-h_i on the side of mid.
    double qa = 0, qb = 0;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(mid[i]) > h[i]) {
        const double c = mid[i] > 0 ? h[i] : -h[i];
        qa += d[i] * d[i];
        qb += d[i] * (p0[i] - c);
      }
    }
    double t = qa > 0 ? std::clamp(-qb / qa, lo, hi) : lo;
    const Vec3 p = p0 + t * d;
    const Vec3 q = p.cwiseMax(-h).cwiseMin(h);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best_t = t;
    }
  }
  segment_point = p0 + best_t * d;
  box_point = segment_point.cwiseMax(-h).cwiseMin(h);
  return best_t;
}

}  // namespace manisoft::contact
