// The geometry of incremental drawing and the renderer's projections, without GL: rectangles
// (dirty_rects.hpp), the camera's and the light's projections (gl_projection.hpp) and depth
// linearisation (gl_readback.hpp), against values computed by hand.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "manisoft/render/camera.hpp"
#include "manisoft/render/dirty_rects.hpp"
#include "manisoft/render/gl_projection.hpp"
#include "manisoft/render/scene.hpp"

using namespace manisoft::render;
using rects::PixelRect;

namespace {

bool same(const PixelRect& a, const PixelRect& b) { return a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1; }

// A camera 2 m above the origin looking straight down, image 320 x 200, vertical field of view
// 60 degrees: right = forward x up = (0, 0, -1) x (0, 1, 0) = (1, 0, 0), down = forward x right =
// (0, -1, 0). A point (X, Y, 0) is at depth 2 and lands at u = 159.5 + f X / 2,
// v = 99.5 - f Y / 2 with f = (200 / 2) / tan(30 deg) = 100 sqrt(3) = 173.205 px.
Camera top_down_camera() {
  Camera c;
  c.position = {0.0, 0.0, 2.0};
  c.look_at = {0.0, 0.0, 0.0};
  c.up = {0.0, 1.0, 0.0};
  c.fov_y_deg = 60.0;
  c.width = 320;
  c.height = 200;
  return c;
}

const double f_top = 100.0 * std::sqrt(3.0);

// A light straight down over a shadow sphere of radius 1 at the origin: its view's x and y are the
// world's x and y (look_at from (0, 0, 2) towards the origin, up hint +z replaced by +y).
Lighting down_light() {
  Lighting l;
  l.kind = LightKind::directional;
  l.direction = {0.0, 0.0, -1.0};
  l.shadow_center = {0.0, 0.0, 0.0};
  l.shadow_radius = 1.0;
  return l;
}

Eigen::AlignedBox3f box(float x0, float y0, float z0, float x1, float y1, float z1) {
  return Eigen::AlignedBox3f(Eigen::Vector3f(x0, y0, z0), Eigen::Vector3f(x1, y1, z1));
}

}  // namespace

TEST_CASE("rectangles: area, intersection, join, complement", "[render][rects]") {
  const PixelRect a{0, 0, 10, 20}, b{5, 15, 30, 40};
  CHECK(rects::area(a) == 200);
  CHECK(rects::area(PixelRect{3, 3, 3, 9}) == 0);  // empty
  CHECK(rects::area(PixelRect{5, 5, 2, 9}) == 0);  // inverted: empty
  CHECK(same(rects::intersect(a, b), PixelRect{5, 15, 10, 20}));
  CHECK(rects::intersect(a, PixelRect{10, 0, 20, 20}).empty());  // touching edges share no pixel
  CHECK(same(rects::join(a, b), PixelRect{0, 0, 30, 40}));
  // The image 100 x 50 minus {20, 10, 60, 30}: below, above, left, right; together 5000 - 800 pixels.
  const auto parts = rects::complement(PixelRect{20, 10, 60, 30}, 100, 50);
  CHECK(same(parts[0], PixelRect{0, 0, 100, 10}));
  CHECK(same(parts[1], PixelRect{0, 30, 100, 50}));
  CHECK(same(parts[2], PixelRect{0, 10, 20, 30}));
  CHECK(same(parts[3], PixelRect{60, 10, 100, 30}));
  long long total = 0;
  for (const PixelRect& p : parts) total += rects::area(p);
  CHECK(total == 100 * 50 - 40 * 20);
  const auto all = rects::complement(PixelRect{}, 100, 50);
  CHECK(same(all[0], PixelRect{0, 0, 100, 50}));
  CHECK(all[1].empty());
}

TEST_CASE("rectangles: clip space to pixels, and points to the pixels covering them", "[render][rects]") {
  // window x = (x / w + 1) width / 2: the centre, the corner, and ndc (0.25, 0.25) in 320 x 200.
  CHECK(rects::clip_to_pixels(Eigen::Vector4f(0, 0, 0.3f, 1), 320, 200).isApprox(Eigen::Vector2f(160, 100)));
  CHECK(rects::clip_to_pixels(Eigen::Vector4f(-2, -2, 0, 2), 320, 200).isApprox(Eigen::Vector2f(0, 0)));
  CHECK(rects::clip_to_pixels(Eigen::Vector4f(0.5f, 0.5f, 0, 2), 320, 200).isApprox(Eigen::Vector2f(200, 125)));
  // floor / ceil, the margin added, clamped to the image.
  const Eigen::AlignedBox2f points(Eigen::Vector2f(10.2f, 20.7f), Eigen::Vector2f(30.1f, 40.0f));
  CHECK(same(rects::to_pixels(points, 2.0f, 320, 200), PixelRect{8, 18, 33, 42}));
  const Eigen::AlignedBox2f wide(Eigen::Vector2f(-5.0f, 1.0f), Eigen::Vector2f(400.0f, 199.5f));
  CHECK(same(rects::to_pixels(wide, 1.0f, 320, 200), PixelRect{0, 0, 320, 200}));
  CHECK(rects::to_pixels(Eigen::AlignedBox2f(), 1.0f, 320, 200).empty());
}

TEST_CASE("rectangles: a body box moved to the world", "[render][rects]") {
  // A quarter turn about z maps (x, y) to (-y, x): [0, 2] x [0, 1] x [0, 1] becomes
  // [-1, 0] x [0, 2] x [0, 1], then moved by (1, 2, 3).
  manisoft::math::Pose<double> pose;
  pose.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation = {1.0, 2.0, 3.0};
  const Eigen::AlignedBox3f w = rects::world_box(pose, box(0, 0, 0, 2, 1, 1));
  CHECK((w.min() - Eigen::Vector3f(0, 2, 3)).norm() < 1e-6f);
  CHECK((w.max() - Eigen::Vector3f(1, 4, 4)).norm() < 1e-6f);
  CHECK(rects::world_box(pose, Eigen::AlignedBox3f()).isEmpty());
}

TEST_CASE("the camera's view-projection puts pixel (u, v) at window (u + 0.5, v + 0.5) on a non-square image", "[render][rects]") {
  const Camera c = top_down_camera();
  const CameraModel model = camera_model(c);
  const Eigen::Matrix4f vp = detail_gl::camera_view_projection(c, model);
  CHECK(model.K(0, 0) == Approx(f_top));
  CHECK(model.K(1, 1) == Approx(f_top));
  CHECK(model.K(0, 2) == Approx(159.5));
  CHECK(model.K(1, 2) == Approx(99.5));
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1.5, 0.8, 0), Eigen::Vector3d(-1.7, -0.9, 0), Eigen::Vector3d(0.3, -0.4, 0.5)}) {
    const double depth = 2.0 - p.z();
    const Eigen::Vector2d hand(159.5 + f_top * p.x() / depth, 99.5 - f_top * p.y() / depth);
    const Eigen::Vector2d opencv = model.project(p);
    const Eigen::Vector2f window = rects::clip_to_pixels(vp * p.cast<float>().homogeneous(), c.width, c.height);
    INFO("point " << p.transpose() << ": by hand (" << hand.transpose() << "), window (" << window.transpose() << ")");
    CHECK((opencv - hand).norm() < 1e-9);
    CHECK(std::abs(window.x() - 0.5 - hand.x()) < 1e-3);
    CHECK(std::abs(window.y() - 0.5 - hand.y()) < 1e-3);
  }
}

TEST_CASE("rectangles: a box's screen rectangle under a known camera", "[render][rects]") {
  const Camera c = top_down_camera();
  const Eigen::Matrix4f vp = detail_gl::camera_view_projection(c, camera_model(c));
  // A flat box x, y in [-0.1, 0.1] at z = 0 (depth 2): window x = 160 +- f 0.1 / 2 = 160 +- 8.660,
  // window y = 100 -+ 8.660; floor / ceil and two pixels a side: [149, 171) x [89, 111).
  CHECK(same(rects::screen_rect(box(-0.1f, -0.1f, 0, 0.1f, 0.1f, 0), vp, 320, 200), PixelRect{149, 89, 171, 111}));
  // Shifted to x in [0.5, 0.7], y in [0.2, 0.3]: window x in [160 + 43.301, 160 + 60.622] = [203.301, 220.622],
  // window y in [100 - 25.981, 100 - 17.321] = [74.019, 82.679]: [201, 223) x [72, 85).
  CHECK(same(rects::screen_rect(box(0.5f, 0.2f, 0, 0.7f, 0.3f, 0), vp, 320, 200), PixelRect{201, 72, 223, 85}));
  // A corner behind the camera (z = 3 > 2): the whole image. An empty box: nothing.
  CHECK(same(rects::screen_rect(box(-0.1f, -0.1f, 0, 0.1f, 0.1f, 3), vp, 320, 200), PixelRect{0, 0, 320, 200}));
  CHECK(rects::screen_rect(Eigen::AlignedBox3f(), vp, 320, 200).empty());
}

TEST_CASE("a directional light's shadow window and the texels a box covers", "[render][rects]") {
  const Lighting l = down_light();
  const Eigen::Matrix4f view = detail_gl::directional_light_view(l);
  // The light's view maps world (x, y) to (x, y).
  const Eigen::Vector4f q = view * Eigen::Vector4f(0.3f, -0.2f, 0.1f, 1.0f);
  CHECK(q.x() == Approx(0.3).margin(1e-6));
  CHECK(q.y() == Approx(-0.2).margin(1e-6));
  // Casters over x, y in [-0.125, 0.125]; a map of 128 texels over [-1, 1]: texel tau = 1 / 64 m.
  // k0 = floor((-0.125 + 1) / tau) - 1 = 56 - 1 = 55, k1 = ceil((0.125 + 1) / tau) + 1 = 73:
  // 18 texels from -1 + 55 tau = -0.140625 to -1 + 73 tau = 0.140625.
  const Eigen::AlignedBox2f extent(Eigen::Vector2f(-0.125f, -0.125f), Eigen::Vector2f(0.125f, 0.125f));
  const detail_gl::ShadowProjection s = detail_gl::directional_shadow_projection(l, view, extent, 128);
  CHECK(s.windowed);
  CHECK(s.window_x == 18);
  CHECK(s.window_y == 18);
  CHECK(s.window_min.x() == Approx(-0.140625));
  CHECK(s.window_max.y() == Approx(0.140625));
  CHECK(s.bias == Approx(1.0 / 128));
  CHECK(s.limit_x(128) == 19);  // the window and one texel beyond it
  // A box x, y in [0.04, 0.07]: texels (0.04 + 0.140625) / tau = 11.56 to (0.07 + 0.140625) / tau
  // = 13.48; floor / ceil and two a side: [9, 16).
  CHECK(same(rects::shadow_texel_rect(box(0.04f, 0.04f, 0, 0.07f, 0.07f, 0.2f), s, 128), PixelRect{9, 9, 16, 16}));
  // Beyond the window the rectangle is clamped to the texels the pass may clear.
  CHECK(same(rects::shadow_texel_rect(box(-0.5f, -0.5f, 0, 0.5f, 0.5f, 0.2f), s, 128), PixelRect{0, 0, 19, 19}));
  // A spot light uses the whole map.
  Lighting spot = l;
  spot.kind = LightKind::spot;
  const detail_gl::ShadowProjection whole = detail_gl::spot_shadow_projection(spot, 128);
  CHECK_FALSE(whole.windowed);
  CHECK(whole.window_x == 128);
  CHECK(whole.limit_x(128) == 128);
}

TEST_CASE("rectangles: the part of a box inside a light's prism, projected", "[render][rects]") {
  const Camera c = top_down_camera();
  const Eigen::Matrix4f vp = detail_gl::camera_view_projection(c, camera_model(c));
  const Eigen::Matrix4f light_view = detail_gl::directional_light_view(down_light());
  // A 1 m slab at z = 0 cut by the prism x in [0.1, 0.2], y in [-0.05, 0.05] (a light straight
  // down): that patch at depth 2 spans window x 160 + f x / 2 in [168.660, 177.321] and window y
  // 100 - f y / 2 in [95.670, 104.330]; floor / ceil and one pixel a side: [167, 179) x [94, 106).
  const Eigen::AlignedBox3f slab = box(-0.5f, -0.5f, 0, 0.5f, 0.5f, 0);
  const Eigen::Vector2f lo(0.1f, -0.05f), hi(0.2f, 0.05f);
  CHECK(same(rects::prism_screen_rect(slab, light_view, lo, hi, vp, 320, 200), PixelRect{167, 94, 179, 106}));
  // The whole box inside the prism: its own rectangle with one pixel a side (x, y in [-0.1, 0.1]:
  // [151.340, 168.660] x [91.340, 108.660] -> [150, 170) x [90, 110)).
  CHECK(same(rects::prism_screen_rect(box(-0.1f, -0.1f, 0, 0.1f, 0.1f, 0), light_view, Eigen::Vector2f(-1, -1), Eigen::Vector2f(1, 1), vp, 320, 200),
             PixelRect{150, 90, 170, 110}));
  // A box beside the prism: nothing.
  CHECK(rects::prism_screen_rect(box(0.5f, -0.1f, 0, 0.6f, 0.1f, 0), light_view, lo, hi, vp, 320, 200).empty());
}

TEST_CASE("rectangles: merging joins overlapping and adjacent ones, and keeps at most max_count", "[render][rects]") {
  auto contains = [](const std::vector<PixelRect>& v, const PixelRect& r) { return std::any_of(v.begin(), v.end(), [&](const PixelRect& x) { return same(x, r); }); };
  // Two overlapping squares join for free (joined 150 pixels < 100 + 100), the far one stays, the empty one goes.
  std::vector<PixelRect> r = {{0, 0, 10, 10}, {5, 0, 15, 10}, {100, 100, 110, 110}, {0, 0, 0, 5}};
  rects::merge_rects(r, 12);
  REQUIRE(r.size() == 2);
  CHECK(contains(r, PixelRect{0, 0, 15, 10}));
  CHECK(contains(r, PixelRect{100, 100, 110, 110}));
  // Side by side: joining adds no pixel (200 = 100 + 100): one rectangle.
  r = {{0, 0, 10, 10}, {10, 0, 20, 10}};
  rects::merge_rects(r, 12);
  REQUIRE(r.size() == 1);
  CHECK(same(r[0], PixelRect{0, 0, 20, 10}));
  // One slot: everything in one bounding rectangle.
  r = {{0, 0, 10, 10}, {100, 100, 110, 110}};
  rects::merge_rects(r, 1);
  REQUIRE(r.size() == 1);
  CHECK(same(r[0], PixelRect{0, 0, 110, 110}));
  // Largest first: A (100 px) kept, B (80 px, a gap of 2 from A: joining adds 20) kept, C (the
  // 20 px gap) joins A for free; then A + C and B join for free: one rectangle.
  r = {{12, 0, 20, 10}, {10, 0, 12, 10}, {0, 0, 10, 10}};
  rects::merge_rects(r, 12);
  REQUIRE(r.size() == 1);
  CHECK(same(r[0], PixelRect{0, 0, 20, 10}));
}

TEST_CASE("rectangles: where a drawable reaches the cleared rectangles", "[render][rects]") {
  const std::vector<PixelRect> cleared = {{10, 10, 20, 20}, {50, 60, 70, 80}, {200, 200, 210, 210}};
  // The bounding rectangle of its overlaps with the cleared ones.
  CHECK(same(rects::reach(PixelRect{0, 0, 100, 100}, cleared), PixelRect{10, 10, 70, 80}));
  CHECK(same(rects::reach(PixelRect{15, 0, 55, 65}, cleared), PixelRect{15, 10, 55, 65}));
  CHECK(rects::reach(PixelRect{100, 100, 150, 150}, cleared).empty());
  CHECK(rects::reach(PixelRect{0, 0, 100, 100}, {}).empty());
}
