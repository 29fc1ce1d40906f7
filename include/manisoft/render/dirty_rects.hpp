// The geometry of incremental drawing (gl_renderer.hpp, GlRendererOptions::incremental), as pure
// functions (no GL): rectangles of framebuffer pixels or shadow-map texels; where a world box can
// appear in an image (its corners projected by a view-projection, clip_to_pixels) or in the
// shadow map's window (shadow_texel_rect); the part of a box inside the prism that a rectangle of
// shadow-map texels sweeps along a directional light, projected into the image
// (prism_screen_rect: the pixels whose shadow lookup can read those texels); and the joining of
// many rectangles into a few (merge_rects) that a frame clears and redraws under a scissor.
//
// Conventions: a PixelRect is [x0, x1) x [y0, y1) in window coordinates (pixel (i, j) covers
// [i, i + 1) x [j, j + 1), its centre at (i + 0.5, j + 0.5)); clip space is OpenGL's (x, y, w
// from a view-projection; window x = (x / w + 1) width / 2).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "manisoft/math/se3.hpp"
#include "manisoft/render/gl_projection.hpp"

namespace manisoft::render::rects {

/// A rectangle of framebuffer pixels (or shadow-map texels) [x0, x1) x [y0, y1).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

/// Its pixel count (0 when empty).
inline long long area(const PixelRect& r) { return r.empty() ? 0 : static_cast<long long>(r.x1 - r.x0) * (r.y1 - r.y0); }

/// The common part (empty when they do not overlap).
inline PixelRect intersect(const PixelRect& a, const PixelRect& b) {
  return PixelRect{std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

/// The smallest rectangle holding both.
inline PixelRect join(const PixelRect& a, const PixelRect& b) {
  return PixelRect{std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

/// The image minus `inside`: up to four rectangles (bands below and above, then left and right).
inline std::array<PixelRect, 4> complement(const PixelRect& inside, int width, int height) {
  if (inside.empty()) return {PixelRect{0, 0, width, height}, PixelRect{}, PixelRect{}, PixelRect{}};
  return {PixelRect{0, 0, width, inside.y0}, PixelRect{0, inside.y1, width, height}, PixelRect{0, inside.y0, inside.x0, inside.y1},
          PixelRect{inside.x1, inside.y0, width, inside.y1}};
}

/// The world axis-aligned box of a body-frame box moved by `pose` (its corners moved, in float).
inline Eigen::AlignedBox3f world_box(const math::Pose<double>& pose, const Eigen::AlignedBox3f& body_box) {
  Eigen::AlignedBox3f box;
  if (body_box.isEmpty()) return box;
  const Eigen::Matrix4f model = pose.matrix().cast<float>();
  for (int c = 0; c < 8; ++c) {
    box.extend((model.topLeftCorner<3, 3>() * body_box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)) + model.topRightCorner<3, 1>()).eval());
  }
  return box;
}


// A clip-space point's position in a width x height viewport, in pixels.
inline Eigen::Vector2f clip_to_pixels(const Eigen::Vector4f& clip, int width, int height) {
  return Eigen::Vector2f((clip.x() / clip.w() + 1.0f) * 0.5f * static_cast<float>(width), (clip.y() / clip.w() + 1.0f) * 0.5f * static_cast<float>(height));
}

// Framebuffer pixels covering a set of points given in pixel units, `margin` added a side,
// clamped to [0, width) x [0, height).
inline PixelRect to_pixels(const Eigen::AlignedBox2f& points, float margin, int width, int height) {
  if (points.isEmpty()) return PixelRect{};
  auto clamp_to = [](float v, int hi) { return static_cast<int>(std::clamp(v, 0.0f, static_cast<float>(hi))); };
  return PixelRect{clamp_to(std::floor(points.min().x()) - margin, width), clamp_to(std::floor(points.min().y()) - margin, height),
                   clamp_to(std::ceil(points.max().x()) + margin, width), clamp_to(std::ceil(points.max().y()) + margin, height)};
}

// The pixels a world box can cover: its corners projected, two pixels added a side; the whole
// image when a corner is not in front of the camera.
inline PixelRect screen_rect(const Eigen::AlignedBox3f& box, const Eigen::Matrix4f& view_projection, int width, int height) {
  if (box.isEmpty()) return PixelRect{};
  Eigen::AlignedBox2f pixels;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector4f clip = view_projection * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).homogeneous();
    if (!(clip.w() > 1e-6f)) return PixelRect{0, 0, width, height};
    pixels.extend(clip_to_pixels(clip, width, height));
  }
  return to_pixels(pixels, 2.0f, width, height);
}

// The shadow-map texels (window coordinates) a world box can cover, two added a side, within the
// texels the shadow pass may clear (ShadowProjection::limit_x, limit_y of a map of `map_size`).
inline PixelRect shadow_texel_rect(const Eigen::AlignedBox3f& box, const detail_gl::ShadowProjection& shadow, int map_size) {
  Eigen::AlignedBox2f texels;
  for (int c = 0; c < 8 && !box.isEmpty(); ++c) {
    const Eigen::Vector4f p = shadow.view_projection * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).homogeneous();
    texels.extend(clip_to_pixels(p, shadow.window_x, shadow.window_y));
  }
  return to_pixels(texels, 2.0f, shadow.limit_x(map_size), shadow.limit_y(map_size));
}

// The pixels of a world box's part inside the prism {light-view x, y in [lo, hi]} (`light_view`:
// world to the light's view), projected into the image, plus one pixel: the box clipped face by
// face. The whole image when part of the clipped box is behind the camera; empty when the box
// misses the prism.
inline PixelRect prism_screen_rect(const Eigen::AlignedBox3f& box, const Eigen::Matrix4f& light_view, const Eigen::Vector2f& lo,
                                   const Eigen::Vector2f& hi, const Eigen::Matrix4f& view_projection, int width, int height) {
  const PixelRect whole{0, 0, width, height};
  if (box.isEmpty()) return PixelRect{};
  // The box's faces as corner indices (bit 0: x max, bit 1: y max, bit 2: z max).
  static constexpr std::array<std::array<int, 4>, 6> faces = {{{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}};
  Eigen::AlignedBox2f pixels;
  for (const auto& face : faces) {
    // Sutherland-Hodgman against the prism's four planes: each adds at most one vertex.
    std::array<Eigen::Vector3f, 8> polygon, clipped;
    int n = 4;
    for (int k = 0; k < 4; ++k) polygon[static_cast<std::size_t>(k)] = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(face[static_cast<std::size_t>(k)]));
    for (int plane = 0; plane < 4 && n > 0; ++plane) {
      const int axis = plane / 2;
      const float sign = plane % 2 == 0 ? 1.0f : -1.0f;  // inside: sign (light-view coordinate - bound) >= 0
      const float bound = plane % 2 == 0 ? lo[axis] : hi[axis];
      auto distance = [&](const Eigen::Vector3f& p) { return sign * (light_view.row(axis).head<3>().dot(p) + light_view(axis, 3) - bound); };
      int m = 0;
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3f& a = polygon[static_cast<std::size_t>(k)];
        const Eigen::Vector3f& b = polygon[static_cast<std::size_t>((k + 1) % n)];
        const float da = distance(a), db = distance(b);
        if (da >= 0) clipped[static_cast<std::size_t>(m++)] = a;
        if ((da >= 0) != (db >= 0)) clipped[static_cast<std::size_t>(m++)] = a + (b - a) * (da / (da - db));
      }
      polygon = clipped;
      n = m;
    }
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector4f clip = view_projection * polygon[static_cast<std::size_t>(k)].homogeneous();
      if (!(clip.w() > 1e-6f)) return whole;
      pixels.extend(clip_to_pixels(clip, width, height));
    }
  }
  return to_pixels(pixels, 1.0f, width, height);
}

// The pixels where a receiver can be in shadow: its world bounding box clipped to the prism
// that the shadow map's window sweeps along the light (light-view x, y inside the window, one
// texel added). The whole image when that cannot be bounded (spot light).
inline PixelRect shadowed_screen_rect(const math::Pose<double>& pose, const Eigen::AlignedBox3f& body_box, const detail_gl::ShadowProjection& shadow,
                                      const Eigen::Matrix4f& view_projection, int width, int height) {
  if (!shadow.windowed || body_box.isEmpty()) return PixelRect{0, 0, width, height};
  const Eigen::Vector2f margin = Eigen::Vector2f::Constant((shadow.window_max.x() - shadow.window_min.x()) / static_cast<float>(shadow.window_x));
  return prism_screen_rect(world_box(pose, body_box), shadow.view, shadow.window_min - margin, shadow.window_max + margin, view_projection, width,
                           height);
}


// Joins the rectangles into at most max_count: largest first, each joins the kept rectangle it
// adds the fewest pixels to when that adds none or no slot is left; then kept rectangles join
// while joining two adds no pixels. Empty rectangles are dropped. O(n max_count).
inline void merge_rects(std::vector<PixelRect>& rects, std::size_t max_count) {
  std::erase_if(rects, [](const PixelRect& r) { return r.empty(); });
  std::sort(rects.begin(), rects.end(), [](const PixelRect& a, const PixelRect& b) { return area(a) > area(b); });
  auto cost = [&](const PixelRect& a, const PixelRect& b) { return area(join(a, b)) - area(a) - area(b); };
  std::size_t kept = 0;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    std::size_t best = 0;
    long long best_cost = std::numeric_limits<long long>::max();
    for (std::size_t j = 0; j < kept; ++j) {
      if (const long long c = cost(rects[j], rects[i]); c < best_cost) {
        best_cost = c;
        best = j;
      }
    }
    if (kept < std::max<std::size_t>(max_count, 1) && best_cost > 0) {
      rects[kept++] = rects[i];
    } else {
      rects[best] = join(rects[best], rects[i]);
    }
  }
  rects.resize(kept);
  for (bool joined = true; joined;) {
    joined = false;
    for (std::size_t a = 0; a < rects.size() && !joined; ++a) {
      for (std::size_t b = a + 1; b < rects.size() && !joined; ++b) {
        if (cost(rects[a], rects[b]) > 0) continue;
        rects[a] = join(rects[a], rects[b]);
        rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(b));
        joined = true;
      }
    }
  }
}


// Where a drawable with screen (or shadow-map) rectangle `r` is drawn: the bounding rectangle of
// its overlaps with the cleared rectangles. Between those, its fragments meet the depth the
// targets already hold, which is this frame's (nothing there changed), and fail the depth test
// (GL_LESS: the same fragment, or one behind): drawing once over the bounding rectangle costs
// one pass over the geometry instead of one per rectangle.
inline PixelRect reach(const PixelRect& r, const std::vector<PixelRect>& cleared) {
  PixelRect box;
  for (const PixelRect& c : cleared) {
    const PixelRect part = intersect(r, c);
    if (part.empty()) continue;
    box = box.empty() ? part : join(box, part);
  }
  return box;
}

}  // namespace manisoft::render::rects
