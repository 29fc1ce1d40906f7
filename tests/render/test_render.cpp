// Tests of the OpenGL renderer (label render): object ids at pixels projected by hand, the rod tube
// where its centreline projects, determinism, camera validation, EGL failure, PNG round trip.
#include <catch2/catch.hpp>

#include "../support/scratch_dir.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/image.hpp"
#include "manisoft/render/mesh_builders.hpp"
#include "manisoft/render/render_io.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/render/tabletop_render_scene.hpp"

using namespace manisoft::render;
using Catch::Matchers::Contains;

namespace {

manisoft::math::Pose<double> at(double x, double y, double z) { return manisoft::math::Pose<double>{Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, y, z)}; }

// One shared renderer: a context costs ~25 ms, the first shader compile much more.
GlRenderer& renderer() {
  static GlRenderer gl;
  return gl;
}

// A known scene: a grey slab (id 1), three boxes (ids 2-4) on it, a straight rod (id 9) across.
SceneDescription known_scene() {
  SceneDescription s;
  s.materials.push_back(Material{});
  Material red;
  red.base_color = {0.8f, 0.1f, 0.1f};
  s.materials.push_back(red);
  s.meshes.push_back(make_box({0.5, 0.5, 0.02}));
  s.meshes.push_back(make_box({0.04, 0.04, 0.04}));
  s.instances.push_back(Instance{0, 0, 1, "slab", false});
  s.instances.push_back(Instance{1, 1, 2, "box_a", true});
  s.instances.push_back(Instance{1, 1, 3, "box_b", true});
  s.instances.push_back(Instance{1, 1, 4, "box_c", true});
  s.rod.object_id = 9;
  s.rod.material = 1;
  Camera c;
  c.position = {1.5, 0.3, 1.2};
  c.look_at = {0.0, 0.0, 0.0};
  c.width = 320;
  c.height = 240;
  c.fov_y_deg = 50;
  s.cameras = {c};
  return s;
}

FrameState known_frame() {
  FrameState f;
  f.instance_poses = {at(0, 0, -0.02), at(0.3, 0.25, 0.04), at(-0.25, -0.3, 0.04), at(0.2, -0.3, 0.04)};
  f.rod.radius = 0.03;
  f.rod.nodes.resize(11, 3);
  for (int i = 0; i <= 10; ++i) f.rod.nodes.row(i) << -0.2, -0.4 + 0.08 * i, 0.25;  // straight, along +y, 25 cm up
  return f;
}

}  // namespace

TEST_CASE("camera model matches a hand computation", "[render]") {
  Camera c;
  c.position = {2.0, 0.0, 2.35};
  c.look_at = {0.4, 0.0, 0.95};
  c.width = 514;
  c.height = 514;
  c.fov_y_deg = 60;
  const CameraModel m = camera_model(c);
  // f = (514 / 2) / tan(30 deg) = 257 * sqrt(3); principal point at the centre between pixels 256 and 257.
  CHECK(m.K(0, 0) == Approx(257.0 * std::sqrt(3.0)));
  CHECK(m.K(1, 1) == Approx(257.0 * std::sqrt(3.0)));
  CHECK(m.K(0, 2) == Approx(256.5));
  CHECK(m.K(1, 2) == Approx(256.5));
  // Forward = (-1.6, 0, -1.4) / |.|; right = forward x up = (0, 1, 0) (world +y appears on the right);
  // down = forward x right.
  const double norm = std::sqrt(1.6 * 1.6 + 1.4 * 1.4);
  CHECK(m.R(2, 0) == Approx(-1.6 / norm));
  CHECK(m.R(2, 2) == Approx(-1.4 / norm));
  CHECK(m.R(0, 1) == Approx(1.0));
  CHECK(m.R(1, 0) == Approx(1.4 / norm));
  CHECK(m.R(1, 2) == Approx(-1.6 / norm));
  // The look-at point lands on the principal point; a point above it lands higher in the image.
  const Eigen::Vector2d centre = m.project(c.look_at);
  CHECK(centre.x() == Approx(256.5));
  CHECK(centre.y() == Approx(256.5));
  CHECK(m.project(c.look_at + Eigen::Vector3d(0, 0, 0.1)).y() < 256.5);
  CHECK(m.project(c.look_at + Eigen::Vector3d(0, 0.1, 0)).x() > 256.5);
  CHECK((m.position() - c.position).norm() < 1e-12);
}

TEST_CASE("invalid cameras give clear errors", "[render]") {
  Camera c;
  c.width = 0;
  CHECK_THROWS_WITH(camera_model(c), Contains("width and height must be >= 1"));
  c = Camera{};
  c.fov_y_deg = 180;
  CHECK_THROWS_WITH(camera_model(c), Contains("fov_y_deg = 180") && Contains("(0, 180)"));
  c.fov_y_deg = 0;
  CHECK_THROWS_WITH(camera_model(c), Contains("fov_y_deg = 0"));
  c = Camera{};
  c.look_at = c.position;
  CHECK_THROWS_WITH(camera_model(c), Contains("equals position"));
  c = Camera{};
  c.up = c.look_at - c.position;
  CHECK_THROWS_WITH(camera_model(c), Contains("parallel to the view direction"));
  // The renderer refuses such a camera in the scene too.
  SceneDescription s = known_scene();
  s.cameras[0].height = -3;
  CHECK_THROWS_AS(renderer().set_scene(s), manisoft::Error);
}

TEST_CASE("failure to open an EGL display or device is a clear error", "[render]") {
  GlRendererOptions options;
  options.egl.device_index = 4096;
  CHECK_THROWS_WITH(GlRenderer(options), Contains("EGL"));
  options.egl.device_index = -7;
  CHECK_THROWS_WITH(GlRenderer(options), Contains("device_index = -7"));
}

TEST_CASE("object centres project onto their objects, and depth matches", "[render]") {
  GlRenderer& gl = renderer();
  gl.set_scene(known_scene());
  const FrameState frame = known_frame();
  const RenderOutput out = gl.render(frame);
  REQUIRE(out.width == 320);
  REQUIRE(out.height == 240);
  REQUIRE(out.mask.size() == 320u * 240u);
  // Top-face centres of the boxes (visible from above) and a slab point; projected by hand
  // with the stored K, R, t: u = fx x_c / z_c + cx, v = fy y_c / z_c + cy.
  const std::vector<std::pair<Eigen::Vector3d, std::uint16_t>> points = {
      {{0.3, 0.25, 0.08}, 2}, {{-0.25, -0.3, 0.08}, 3}, {{0.2, -0.3, 0.08}, 4}, {{0.35, -0.05, 0.0}, 1}};
  for (const auto& [p, id] : points) {
    const Eigen::Vector3d c = out.camera.R * p + out.camera.t;
    const double u = out.camera.K(0, 0) * c.x() / c.z() + out.camera.K(0, 2);
    const double v = out.camera.K(1, 1) * c.y() / c.z() + out.camera.K(1, 2);
    const int ui = static_cast<int>(std::lround(u)), vi = static_cast<int>(std::lround(v));
    INFO("point " << p.transpose() << " -> pixel (" << u << ", " << v << ")");
    REQUIRE(ui >= 0);
    REQUIRE(ui < out.width);
    REQUIRE(vi >= 0);
    REQUIRE(vi < out.height);
    CHECK(out.id_at(ui, vi) == id);
    CHECK(out.depth_at(ui, vi) == Approx(c.z()).margin(0.005));
  }
  // Corners of the image see the background (id 0, depth 0).
  CHECK(out.id_at(0, 0) == 0);
  CHECK(out.depth_at(0, 0) == 0.0f);
}

TEST_CASE("the rod tube appears where its centreline projects", "[render]") {
  GlRenderer& gl = renderer();
  gl.set_scene(known_scene());
  const FrameState frame = known_frame();
  const RenderOutput out = gl.render(frame);
  int on = 0, checked = 0;
  for (int i = 0; i <= 10; ++i) {
    const Eigen::Vector3d node = frame.rod.nodes.row(i).transpose();
    const Eigen::Vector2d px = out.camera.project(node);
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= out.width || v >= out.height) continue;
    ++checked;
    if (out.id_at(u, v) == 9) ++on;
    // 12 cm above the rod axis (4 radii) is not rod.
    const Eigen::Vector2d above = out.camera.project(node + Eigen::Vector3d(0, 0, 0.12));
    CHECK(out.id_at(static_cast<int>(std::lround(above.x())), static_cast<int>(std::lround(above.y()))) != 9);
  }
  CHECK(checked >= 9);
  CHECK(on == checked);
  // The tube's image is about 2 r wide: count rod pixels on the column through the middle node.
  const Eigen::Vector3d mid = frame.rod.nodes.row(5).transpose();
  const Eigen::Vector2d top = out.camera.project(mid + Eigen::Vector3d(0, 0, 0.03));
  const Eigen::Vector2d bottom = out.camera.project(mid - Eigen::Vector3d(0, 0, 0.03));
  const int u = static_cast<int>(std::lround(top.x()));
  int rod_rows = 0;
  for (int v = 0; v < out.height; ++v) rod_rows += out.id_at(u, v) == 9;
  // The silhouette of a cylinder seen from above-front spans at least its projected vertical diameter.
  CHECK(rod_rows >= static_cast<int>(std::floor(bottom.y() - top.y())) - 1);
  CHECK(rod_rows <= static_cast<int>(std::ceil(bottom.y() - top.y())) * 2 + 2);
}

TEST_CASE("same inputs give identical pixels", "[render]") {
  GlRenderer& gl = renderer();
  const tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  gl.set_scene(t.scene);
  const RenderOutput a = gl.render(t.frame);
  const RenderOutput b = gl.render(t.frame);
  CHECK(a.rgb == b.rgb);
  CHECK(a.mask == b.mask);
  CHECK(a.depth == b.depth);
  GlRendererOptions options;  // a second renderer, its own context
  GlRenderer other(options);
  other.set_scene(t.scene);
  const RenderOutput c = other.render(t.frame);
  CHECK(a.rgb == c.rgb);
  CHECK(a.mask == c.mask);
}

TEST_CASE("the built-in tabletop scene shows the table, arm, gripper and every object", "[render]") {
  GlRenderer& gl = renderer();
  const tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  gl.set_scene(t.scene);
  FrameState frame = t.frame;
  frame.goal_pose = at(0.3, 0.15, 0.9);
  const RenderOutput out = gl.render(frame);
  std::map<std::uint16_t, int> count;
  for (std::uint16_t id : out.mask) ++count[id];
  for (std::uint16_t id = tabletop::floor_id; id <= tabletop::goal_id; ++id) {
    INFO("object id " << id);
    CHECK(count[id] >= 40);
  }
  CHECK(count[tabletop::table_id] > 10000);
  CHECK(count[tabletop::arm_id] > 3000);
  // The centre of each object's bounding box projects inside the image.
  for (const auto& [id, b] : object_bounds(t.scene, frame)) {
    const Eigen::Vector2d px = out.camera.project(b.center());
    INFO(b.name);
    CHECK(px.x() >= 0);
    CHECK(px.x() < out.width);
    CHECK(px.y() >= 0);
    CHECK(px.y() < out.height);
  }
}

namespace {

// A slab (top at z = 0, no specular) and one 8 cm box on it at the origin; light from -y above.
SceneDescription shadow_scene(LightKind kind) {
  SceneDescription s = known_scene();
  s.materials[0].specular = 0.0f;
  s.instances.resize(2);
  s.rod.present = false;
  s.lighting.kind = kind;
  s.lighting.direction = {0.0, 1.0, -1.0};  // travels +y and down: the shadow falls on +y
  s.lighting.position = {0.0, -1.0, 1.0};    // spot: 1.41 m up the light's ray through the origin
  return s;
}

int brightness(const RenderOutput& out, const Eigen::Vector3d& p) {
  const Eigen::Vector2d px = out.camera.project(p);
  const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
  REQUIRE(u >= 0);
  REQUIRE(u < out.width);
  REQUIRE(v >= 0);
  REQUIRE(v < out.height);
  const std::size_t i = (static_cast<std::size_t>(v) * out.width + u) * 3;
  return out.rgb[i] + out.rgb[i + 1] + out.rgb[i + 2];
}

}  // namespace

TEST_CASE("a caster's shadow falls where the light projects it, for directional and spot lights", "[render]") {
  FrameState frame;
  frame.instance_poses = {at(0, 0, -0.02), at(0, 0, 0.04)};
  // (0, 0.09, 0): its ray to the light passes through the box; (0, -0.09, 0) is lit. Both are on
  // the slab, seen by the camera, same normal and material.
  const Eigen::Vector3d shadowed(0, 0.09, 0), lit(0, -0.09, 0);
  GlRendererOptions plain;
  plain.shadows = false;
  GlRenderer no_shadows(plain);
  for (LightKind kind : {LightKind::directional, LightKind::spot}) {
    INFO("light kind " << static_cast<int>(kind));
    const SceneDescription scene = shadow_scene(kind);
    GlRenderer& gl = renderer();
    gl.set_scene(scene);
    const RenderOutput out = gl.render(frame);
    CHECK(out.id_at(static_cast<int>(std::lround(out.camera.project(shadowed).x())), static_cast<int>(std::lround(out.camera.project(shadowed).y()))) == 1);
    no_shadows.set_scene(scene);
    const RenderOutput flat = no_shadows.render(frame);
    CHECK(brightness(flat, shadowed) - brightness(out, shadowed) > 150);  // sum of R, G, B: the direct light is gone
    CHECK(std::abs(brightness(flat, lit) - brightness(out, lit)) <= 6);
  }
}

TEST_CASE("read-back options and MSAA keep the picture and the ids", "[render]") {
  const SceneDescription scene = known_scene();
  const FrameState frame = known_frame();
  GlRenderer& gl = renderer();
  gl.set_scene(scene);
  const RenderOutput full = gl.render(frame);
  GlRendererOptions colour_only;
  colour_only.read_depth = false;
  colour_only.read_mask = false;
  GlRenderer plain(colour_only);
  plain.set_scene(scene);
  const RenderOutput rgb = plain.render(frame);
  CHECK(rgb.mask.empty());
  CHECK(rgb.depth.empty());
  CHECK(rgb.rgb == full.rgb);  // the id target is not drawn, the colours are the same
  GlRendererOptions msaa;
  msaa.msaa_samples = 4;
  GlRenderer smooth(msaa);
  smooth.set_scene(scene);
  const RenderOutput out = smooth.render(frame);
  REQUIRE(out.mask.size() == full.mask.size());
  std::size_t same = 0;
  for (std::size_t i = 0; i < out.mask.size(); ++i) same += out.mask[i] == full.mask[i];
  CHECK(same > out.mask.size() * 97 / 100);  // ids differ only along edges
  CHECK(out.id_at(0, 0) == 0);
  CHECK(out.depth_at(0, 0) == 0.0f);
}

TEST_CASE("mesh builders: tube radius, box extents, directors or transported frames", "[render]") {
  const tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  const RodShape& rod = t.frame.rod;
  for (bool with_directors : {true, false}) {
    const Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> none(0, 9);
    const Mesh tube = make_tube(rod.nodes, with_directors ? rod.directors : none, rod.radius, TubeOptions{16, 3, false});
    // Each ring vertex lies one radius from the arc's axis: the arc's centre of curvature is known.
    double worst = 0;
    for (std::size_t i = 0; i < tube.positions.size(); ++i) {
      // Distance from the nearest centreline node segment.
      double best = 1e9;
      for (Eigen::Index k = 0; k + 1 < rod.nodes.rows(); ++k) {
        const Eigen::Vector3d a = rod.nodes.row(k).transpose(), b = rod.nodes.row(k + 1).transpose();
        const Eigen::Vector3d p = tube.positions[i].cast<double>();
        const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (p - (a + s * (b - a))).norm());
      }
      worst = std::max(worst, std::abs(best - rod.radius));
    }
    CHECK(worst < 2e-3);  // chord sagitta of a 5 cm element on a 0.67 m bend radius is < 1 mm
  }
  const Mesh box = make_box({0.1, 0.2, 0.3});
  CHECK(box.triangle_count() == 12);
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-1);
  for (const auto& p : box.positions) hi = hi.cwiseMax(p);
  CHECK(hi.isApprox(Eigen::Vector3f(0.1f, 0.2f, 0.3f)));
  // make_tube_into replaces a mesh's contents (the renderer reuses one mesh every frame).
  Mesh reused = make_tube(rod.nodes, rod.directors, rod.radius);
  const Mesh fresh = make_tube(rod.nodes.topRows(6), rod.directors.topRows(5), 0.5 * rod.radius, TubeOptions{8, 2, true});
  make_tube_into(reused, rod.nodes.topRows(6), rod.directors.topRows(5), 0.5 * rod.radius, TubeOptions{8, 2, true});
  CHECK(reused.positions == fresh.positions);
  CHECK(reused.normals == fresh.normals);
  CHECK(reused.uvs == fresh.uvs);
  CHECK(reused.indices == fresh.indices);
  CHECK_THROWS_WITH(make_tube(rod.nodes.topRows(1), rod.directors, 0.05), Contains("need >= 2"));
  CHECK_THROWS_WITH(make_tube(rod.nodes, rod.directors.topRows(3), 0.05), Contains("director rows"));
}

TEST_CASE("PNG files round-trip and are written atomically", "[render]") {
  const std::filesystem::path dir = manisoft::test::scratch_dir("manisoft_test_render_png");
  std::filesystem::create_directories(dir);
  std::vector<std::uint8_t> rgb(7 * 5 * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 37);
  write_png_rgb(dir / "a.png", 7, 5, rgb);
  CHECK_FALSE(std::filesystem::exists(dir / "a.png.tmp"));
  const RgbImage back = read_png_rgb(dir / "a.png");
  CHECK(back.width == 7);
  CHECK(back.height == 5);
  CHECK(back.rgb == rgb);
  CHECK_THROWS_WITH(write_png_rgb(dir / "b.png", 7, 5, std::vector<std::uint8_t>(10)), Contains("need 105"));
  CHECK(depth_millimetres({0.0f, 1.2344f, 70.0f}) == std::vector<std::uint16_t>{0, 1234, 65535});
  std::filesystem::remove_all(dir);
}

namespace {

// Frame k of a short episode in the built-in scene: the arm sways and bends, the gripper follows
// its tip carrying the cube, the goal marker comes and goes, the ball is knocked once; frames 9
// and 10 are the same.
FrameState episode_frame(const tabletop::TabletopScene& t, int k) {
  const double pi = std::numbers::pi;
  const int s = k == 10 ? 9 : k;
  FrameState f = t.frame;
  f.rod = tabletop::arc_rod(Eigen::Vector3d(-0.05, 0, 1.5), 1.0, 20, (85.0 + 2.0 * s) * pi / 180.0, 0.05, (-20.0 + 3.0 * s) * pi / 180.0);
  const manisoft::math::Pose<double> gripper = tabletop::gripper_at_tip(f.rod);
  tabletop::set_gripper(t, f, gripper, 0.06);
  f.instance_poses[t.object_instance.at("cube")] = gripper * tabletop::at(0, 0, 0.1);
  if (s >= 12) f.instance_poses[t.object_instance.at("ball")] = tabletop::at(0.50, -0.20, 0.785);
  if (s % 8 < 5) f.goal_pose = tabletop::at(0.3, 0.15, 0.9 + 0.01 * s);
  return f;
}

}  // namespace

TEST_CASE("incremental frames are the full redraws, pixel for pixel, and redraw less", "[render]") {
  tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  Camera side = t.scene.cameras.front();
  side.position = {1.6, -1.2, 1.4};
  t.scene.cameras.push_back(side);
  struct Case {
    const char* name;
    bool shadows;
    int msaa;
    LightKind light;
  };
  for (const Case& c : {Case{"shadows", true, 0, LightKind::directional}, Case{"no shadows", false, 0, LightKind::directional},
                        Case{"4x MSAA", true, 4, LightKind::directional}, Case{"spot light", true, 0, LightKind::spot}}) {
    INFO(c.name);
    SceneDescription scene = t.scene;
    scene.lighting.kind = c.light;
    GlRendererOptions full_options;
    full_options.shadows = c.shadows;
    full_options.msaa_samples = c.msaa;
    full_options.incremental = false;
    GlRendererOptions incremental_options = full_options;
    incremental_options.incremental = true;
    GlRenderer full(full_options), incremental(incremental_options);
    full.set_scene(scene);
    incremental.set_scene(scene);
    const std::size_t pixels = static_cast<std::size_t>(scene.cameras[0].width) * static_cast<std::size_t>(scene.cameras[0].height);
    RenderOutput a, b;
    int partial = 0;
    for (int k = 0; k < 18; ++k) {
      INFO("frame " << k);
      const std::size_t camera = k == 15 ? 1 : 0;  // one frame from the other camera
      const FrameState frame = episode_frame(t, k);
      full.render_into(frame, a, camera);
      incremental.render_into(frame, b, camera);
      CHECK(a.rgb == b.rgb);
      CHECK(a.depth == b.depth);
      CHECK(a.mask == b.mask);
      const GlRenderer::DrawStats& drawn = incremental.last_draw();
      CHECK(full.last_draw().everything);
      if (k == 0 || k == 15 || k == 16 || c.light == LightKind::spot) {
        CHECK(drawn.everything);  // first frame, camera changes, spot light
        CHECK(drawn.pixels == pixels);
      } else if (k == 10) {
        CHECK_FALSE(drawn.everything);  // nothing moved
        CHECK(drawn.rectangles == 0);
        CHECK(drawn.shadow_texels == 0);
      } else if (!drawn.everything) {  // the shadow map's window may grow or shrink with the arm
        CHECK(drawn.rectangles > 0);
        CHECK(drawn.pixels < pixels / 2);
      }
      partial += drawn.everything ? 0 : 1;
    }
    if (c.light == LightKind::directional) CHECK(partial >= 12);  // of the 15 frames that may be drawn in part
    incremental.set_scene(scene);
    incremental.render_into(episode_frame(t, 17), b);
    CHECK(incremental.last_draw().everything);  // a new scene draws everything
  }
}

TEST_CASE("the projection is within half a pixel on a non-square image", "[render]") {
  // A camera 2 m above the origin looking straight down, 320 x 200 pixels, 60 degree vertical field
  // of view: right = forward x up = (0, 0, -1) x (0, 1, 0) = (1, 0, 0), down = forward x right =
  // (0, -1, 0), f = (200 / 2) / tan(30 deg) = 100 sqrt(3), principal point ((320 - 1) / 2,
  // (200 - 1) / 2) = (159.5, 99.5). A point (X, Y, 0) (depth 2) lands at u = 159.5 + f X / 2,
  // v = 99.5 - f Y / 2.
  const double f = 100.0 * std::sqrt(3.0), half = 0.05, depth = 2.0;
  SceneDescription s;
  s.materials.push_back(Material{});
  // A square marker facing up (+z), 10 cm a side, as two counter-clockwise triangles.
  Mesh square;
  for (const auto& [x, y] : {std::pair{-half, -half}, std::pair{half, -half}, std::pair{half, half}, std::pair{-half, half}}) {
    square.positions.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
    square.normals.emplace_back(0.0f, 0.0f, 1.0f);
    square.uvs.emplace_back(0.0f, 0.0f);
  }
  square.indices = {0, 1, 2, 0, 2, 3};
  s.meshes.push_back(square);
  Camera c;
  c.position = {0.0, 0.0, depth};
  c.look_at = {0.0, 0.0, 0.0};
  c.up = {0.0, 1.0, 0.0};
  c.fov_y_deg = 60.0;
  c.width = 320;
  c.height = 200;
  s.cameras = {c};
  s.rod.present = false;
  // Markers over the whole image (near its left and right ends too), edges at many sub-pixel offsets.
  FrameState frame;
  std::vector<Eigen::Vector2d> centres;
  for (const double x : {-1.5, -0.73, 0.0, 0.41, 1.62}) {
    for (const double y : {-0.9, 0.27, 0.88}) centres.emplace_back(x, y);
  }
  for (std::size_t i = 0; i < centres.size(); ++i) {
    s.instances.push_back(Instance{0, 0, static_cast<std::uint16_t>(i + 1), "marker", true});
    frame.instance_poses.push_back(at(centres[i].x(), centres[i].y(), 0.0));
  }
  GlRenderer& gl = renderer();
  gl.set_scene(s);
  const RenderOutput out = gl.render(frame);
  REQUIRE(out.width == 320);
  REQUIRE(out.height == 200);
  // The camera's calibration is the hand computation.
  CHECK(out.camera.K(0, 0) == Approx(f));
  CHECK(out.camera.K(1, 1) == Approx(f));
  CHECK(out.camera.K(0, 2) == Approx(159.5));
  CHECK(out.camera.K(1, 2) == Approx(99.5));
  double worst = 0;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const auto id = static_cast<std::uint16_t>(i + 1);
    const double X = centres[i].x(), Y = centres[i].y();
    // Edges by hand: left, right (u) and top, bottom (v).
    const double left = 159.5 + f * (X - half) / depth, right = 159.5 + f * (X + half) / depth;
    const double top = 99.5 - f * (Y + half) / depth, bottom = 99.5 - f * (Y - half) / depth;
    CHECK((out.camera.project(Eigen::Vector3d(X - half, Y + half, 0)) - Eigen::Vector2d(left, top)).norm() < 1e-9);
    CHECK((out.camera.project(Eigen::Vector3d(X + half, Y - half, 0)) - Eigen::Vector2d(right, bottom)).norm() < 1e-9);
    // The rendered marker: the pixels with its id form the rectangle [u0, u1] x [v0, v1]; its edges
    // lie half a pixel outside the outermost pixel centres.
    int u0 = out.width, u1 = -1, v0 = out.height, v1 = -1, count = 0;
    for (int v = 0; v < out.height; ++v) {
      for (int u = 0; u < out.width; ++u) {
        if (out.id_at(u, v) != id) continue;
        u0 = std::min(u0, u);
        u1 = std::max(u1, u);
        v0 = std::min(v0, v);
        v1 = std::max(v1, v);
        ++count;
      }
    }
    INFO("marker " << id << " at (" << X << ", " << Y << "): by hand u in [" << left << ", " << right << "], v in [" << top << ", " << bottom
                   << "]; rendered columns " << u0 << ".." << u1 << ", rows " << v0 << ".." << v1);
    REQUIRE(u1 >= u0);
    CHECK(count == (u1 - u0 + 1) * (v1 - v0 + 1));
    for (const double error : {(u0 - 0.5) - left, (u1 + 0.5) - right, (v0 - 0.5) - top, (v1 + 0.5) - bottom}) {
      CHECK(std::abs(error) <= 0.5);
      worst = std::max(worst, std::abs(error));
    }
    // Depth at the marker's centre pixel: 2 m.
    const Eigen::Vector2d centre = out.camera.project(Eigen::Vector3d(X, Y, 0));
    CHECK(out.depth_at(static_cast<int>(std::lround(centre.x())), static_cast<int>(std::lround(centre.y()))) == Approx(depth).margin(1e-3));
  }
  INFO("worst edge error " << worst << " px");
  CHECK(worst <= 0.5);
}

TEST_CASE("a trace cell that is not a finite number is refused naming the line and column", "[render]") {
  const std::filesystem::path dir = manisoft::test::scratch_dir("manisoft_test_render_trace");
  std::filesystem::create_directories(dir);
  const std::string header = "finger_width,gripper_px,gripper_qw,node0_x,node1_x\n";
  for (const char* cell : {"nan", "inf", "-inf", "1e400"}) {
    CAPTURE(cell);
    const std::filesystem::path path = dir / "trace.csv";
    std::ofstream(path) << header << "0.05,0.4,1,0,0.1\n0.05,0.4,1," << cell << ",0.1\n";
    CHECK_THROWS_WITH(io::read_trace(path), Catch::Contains("line 3: column 'node0_x' = '" + std::string(cell) + "' is not a finite number"));
  }
  std::ofstream(dir / "trace.csv") << header << "0.05,0.4,1,0,0.1\n";
  const io::Trace ok = io::read_trace(dir / "trace.csv");
  REQUIRE(ok.rows.size() == 1);
  CHECK(ok.at(0, "node1_x") == 0.1);
  // a node without its _y column: refused naming the column (an exception thrown inside Eigen's
  // comma initializer aborted on its assertion; tests/fuzz/corpus/trace/node_without_y.csv)
  CHECK_THROWS_WITH(io::frame_from_trace(tabletop::make_tabletop_scene(), ok, 0), Catch::Contains("no column 'node0_y'"));
}
