// Renderer speed: one 514 x 514 frame of the built-in tabletop scene (table,
// floor, mount, arm tube re-built and re-uploaded every frame, gripper, 8 objects, goal marker),
// per variant: no shadows, shadows (1024^2 map, or 512^2), shadows + depth + id read back, 4x MSAA,
// a spot light (perspective shadow map over its cone); and the set-up cost (EGL display + context +
// shaders + scene upload). Wall time is the reported time (UseRealTime); CPU time is the calling
// thread's only (llvmpipe's raster threads are not counted). BM_Frame_*: every frame is drawn from
// scratch (GlRendererOptions::incremental off). BM_Episode_*: the frames of an episode, drawn
// incrementally (the default): the arm sways and bends (tip about 7 mm a frame), the gripper follows
// it carrying the cube, the other objects rest; counters: the mean share of the image and of the
// shadow map's window redrawn, and how many frames were drawn whole.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/tabletop_render_scene.hpp"

using namespace manisoft::render;

namespace {

void set_shader_cache() {
  if (std::getenv("MESA_SHADER_CACHE_DIR") == nullptr) setenv("MESA_SHADER_CACHE_DIR", "/tmp/manisoft_mesa_shader_cache", 0);
}

void run_frames(benchmark::State& state, bool shadows, bool readback, int msaa, bool textures = true, int shadow_map_size = 1024,
                bool spot = false) {
  set_shader_cache();
  GlRendererOptions options;
  options.shadows = shadows;
  options.shadow_map_size = shadow_map_size;
  options.read_depth = readback;
  options.read_mask = readback;
  options.msaa_samples = msaa;
  options.incremental = false;
  GlRenderer gl(options);
  tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  if (!textures) {
    for (Material& m : t.scene.materials) m.texture = TextureKind::none;
  }
  if (spot) t.scene.lighting.kind = LightKind::spot;
  gl.set_scene(t.scene);
  FrameState frame = t.frame;
  frame.goal_pose = tabletop::at(0.3, 0.15, 0.9);
  RenderOutput out;
  gl.render_into(frame, out);  // warm-up: first-frame shader variants
  std::size_t k = 0;
  for (auto _ : state) {
    // Move the arm a little each frame so the tube is rebuilt from new nodes.
    frame.rod.nodes(frame.rod.nodes.rows() - 1, 2) = 0.9 + 1e-4 * static_cast<double>(k++ % 7);
    gl.render_into(frame, out);
    benchmark::DoNotOptimize(out.rgb.data());
  }
  std::size_t triangles = 0;
  for (const Instance& i : t.scene.instances) triangles += t.scene.meshes[static_cast<std::size_t>(i.mesh)].triangle_count();
  state.counters["triangles"] = static_cast<double>(triangles + make_tube(frame.rod.nodes, frame.rod.directors, 0.05).triangle_count());
  state.SetLabel(gl.device_name());
}

// One 300-frame cycle of a swaying arm: roll -20 +- 25 degrees (period 300 frames), bend 85 +- 10
// degrees (period 150).
std::vector<FrameState> episode(const tabletop::TabletopScene& t) {
  const double pi = std::numbers::pi;
  std::vector<FrameState> frames;
  for (int k = 0; k < 300; ++k) {
    FrameState f = t.frame;
    const double bend = (85.0 + 10.0 * std::sin(2 * pi * k / 150.0)) * pi / 180.0;
    const double roll = (-20.0 + 25.0 * std::sin(2 * pi * k / 300.0)) * pi / 180.0;
    f.rod = tabletop::arc_rod(Eigen::Vector3d(-0.05, 0, 1.5), 1.0, 20, bend, 0.05, roll);
    const manisoft::math::Pose<double> gripper = tabletop::gripper_at_tip(f.rod);
    tabletop::set_gripper(t, f, gripper, 0.06);
    f.instance_poses[t.object_instance.at("cube")] = gripper * tabletop::at(0, 0, 0.1);
    f.goal_pose = tabletop::at(0.3, 0.15, 0.9);
    frames.push_back(std::move(f));
  }
  return frames;
}

void run_episode(benchmark::State& state, bool shadows, bool readback) {
  set_shader_cache();
  GlRendererOptions options;
  options.shadows = shadows;
  options.read_depth = readback;
  options.read_mask = readback;
  GlRenderer gl(options);
  const tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  gl.set_scene(t.scene);
  const std::vector<FrameState> frames = episode(t);
  RenderOutput out;
  gl.render_into(frames.back(), out);  // warm-up: first-frame shader variants, drawn whole
  double window = static_cast<double>(gl.last_draw().shadow_texels);
  std::size_t k = 0, whole = 0;
  double pixels = 0, texels = 0;
  for (auto _ : state) {
    gl.render_into(frames[k++ % frames.size()], out);
    benchmark::DoNotOptimize(out.rgb.data());
    const GlRenderer::DrawStats& drawn = gl.last_draw();
    if (drawn.everything) {
      ++whole;
      window = static_cast<double>(drawn.shadow_texels);
    }
    pixels += static_cast<double>(drawn.pixels);
    texels += static_cast<double>(drawn.shadow_texels);
  }
  const double frames_drawn = static_cast<double>(k);
  state.counters["image_redrawn"] = pixels / frames_drawn / static_cast<double>(out.width * out.height);
  if (shadows && window > 0) state.counters["shadow_redrawn"] = texels / frames_drawn / window;
  state.counters["whole_frames"] = static_cast<double>(whole);
  state.SetLabel(gl.device_name());
}

void BM_Episode_NoShadows(benchmark::State& s) { run_episode(s, false, false); }
void BM_Episode_NoShadows_DepthIds(benchmark::State& s) { run_episode(s, false, true); }
void BM_Episode_Shadows_DepthIds(benchmark::State& s) { run_episode(s, true, true); }

void BM_Frame_NoShadows(benchmark::State& s) { run_frames(s, false, false, 0); }
void BM_Frame_NoShadows_NoTextures(benchmark::State& s) { run_frames(s, false, false, 0, false); }
void BM_Frame_Shadows(benchmark::State& s) { run_frames(s, true, false, 0); }
void BM_Frame_Shadows_DepthIds(benchmark::State& s) { run_frames(s, true, true, 0); }
void BM_Frame_Shadows512_DepthIds(benchmark::State& s) { run_frames(s, true, true, 0, true, 512); }
void BM_Frame_SpotLight_Shadows_DepthIds(benchmark::State& s) { run_frames(s, true, true, 0, true, 1024, true); }
void BM_Frame_NoShadows_DepthIds(benchmark::State& s) { run_frames(s, false, true, 0); }
void BM_Frame_MSAA4_Shadows_DepthIds(benchmark::State& s) { run_frames(s, true, true, 4); }

void BM_SetUp(benchmark::State& state) {
  set_shader_cache();
  const tabletop::TabletopScene t = tabletop::make_tabletop_scene();
  for (auto _ : state) {
    GlRenderer gl;
    gl.set_scene(t.scene);
    benchmark::DoNotOptimize(&gl);
  }
}

}  // namespace

BENCHMARK(BM_Frame_NoShadows_NoTextures)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_NoShadows)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_NoShadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_Shadows)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_Shadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_Shadows512_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_SpotLight_Shadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Frame_MSAA4_Shadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Episode_NoShadows)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Episode_NoShadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_Episode_Shadows_DepthIds)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_SetUp)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

BENCHMARK_MAIN();
