// render_scene: renders the built-in tabletop scene or a scene JSON (--scene), optionally one frame
// of a trace (world_demo's for the built-in scene, run_task's for its scene), and
// writes rgb.png, depth.png (16-bit, mm), mask.png (object ids) and camera.json into --out.
// With --episode it renders every --every-th trace row into DIR/frames/, an image strip
// (strip.png) and, when ffmpeg is installed, DIR/episode.mp4. A trace recorded in another scene
// (other objects) is refused; a run that fails leaves no output folder it created.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "../cli_checks.hpp"
#include "../output_file.hpp"
#include "blender_run.hpp"
#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/render_io.hpp"
#include "manisoft/render/renderer.hpp"
#include "manisoft/render/tabletop_render_scene.hpp"
#if MANISOFT_RENDER_SCENES
#include "manisoft/scene/scene_json.hpp"
#include "manisoft/scene/scene_render.hpp"
#endif

namespace fs = std::filesystem;
using namespace manisoft::render;

namespace {

// Horizontal strip of up to `count` frames, each downscaled by `factor` (box filter).
std::vector<std::uint8_t> strip_image(const std::vector<RenderOutput>& frames, int factor, int& width, int& height) {
  const int w = frames.front().width / factor, h = frames.front().height / factor;
  width = w * static_cast<int>(frames.size());
  height = h;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c) {
          int sum = 0;
          for (int dy = 0; dy < factor; ++dy) {
            for (int dx = 0; dx < factor; ++dx) {
              sum += frames[f].rgb[(static_cast<std::size_t>(y * factor + dy) * frames[f].width + (x * factor + dx)) * 3 + c];
            }
          }
          out[(static_cast<std::size_t>(y) * width + f * w + x) * 3 + c] = static_cast<std::uint8_t>(sum / (factor * factor));
        }
      }
    }
  }
  return out;
}

// Every `every`-th trace row rendered by `renderer` into out/frames/rgb_<k>.png, a strip of up to
// six of them (strip.png) and, when ffmpeg is installed, out/episode.mp4.
template <Renderer R>
void render_episode(R& renderer, const tabletop::TabletopScene& scene, const io::Trace& trace, int every, const fs::path& out) {
  const fs::path frames_dir = out / "frames";
  fs::create_directories(frames_dir);
  std::vector<RenderOutput> strip;
  std::size_t count = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t strip_every = std::max<std::size_t>(1, trace.rows.size() / static_cast<std::size_t>(every) / 6);
  for (std::size_t r = 0; r < trace.rows.size(); r += static_cast<std::size_t>(every), ++count) {
    const RenderOutput image = renderer.render(io::frame_from_trace(scene, trace, r));
    char name[32];
    std::snprintf(name, sizeof name, "rgb_%05zu.png", count);
    write_png_rgb(frames_dir / name, image.width, image.height, image.rgb);
    if (count % strip_every == 0 && strip.size() < 6) strip.push_back(image);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int sw = 0, sh = 0;
  const auto pixels = strip_image(strip, 2, sw, sh);
  write_png_rgb(out / "strip.png", sw, sh, pixels);
  std::printf("%zu frames (every %d-th of %zu rows) in %.2f s -> %s/frames, strip.png\n", count, every, trace.rows.size(), seconds,
              out.string().c_str());
  if (std::system("command -v ffmpeg > /dev/null 2>&1") == 0) {
    const std::string cmd = "ffmpeg -loglevel error -y -framerate 20 -i '" + (frames_dir / "rgb_%05d.png").string() +
                            "' -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -pix_fmt yuv420p '" + (out / "episode.mp4").string() + "'";
    if (std::system(cmd.c_str()) == 0) std::printf("video: %s\n", (out / "episode.mp4").string().c_str());
    else std::fprintf(stderr, "ffmpeg failed: frames are in %s\n", frames_dir.string().c_str());
  } else {
    std::printf("ffmpeg not found: no video (frames are in %s)\n", frames_dir.string().c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Render the ManiSoft tabletop scene: rgb.png, depth.png (16-bit mm), mask.png (ids), camera.json"};
  std::string scene_path, trace_path, renderer = "gl", out_dir, engine = "workbench";
  long frame_arg = 0;
  int msaa = 0, every = 50, egl_device = -1, samples = 16;
  bool no_shadows = false, episode = false;
  app.add_option("--scene", scene_path, "scene JSON written by scene_sample (docs/scenes.md)");
  app.add_option("--trace", trace_path, "CSV trace: world_demo's (built-in scene) or run_task's (with its --scene)");
  app.add_option("--frame", frame_arg, "trace row to render (0 = initial state; -1 the last row, -2 the one before, ...)");
  app.add_option("--renderer", renderer, "gl (in-process OpenGL, default) or blender")->check(CLI::IsMember({"gl", "blender"}));
  app.add_option("--out", out_dir, "output folder")->required();
  app.add_option("--msaa", msaa, "OpenGL multisampling: 0, 2, 4 or 8")->check(CLI::IsMember({0, 2, 4, 8}));
  app.add_flag("--no-shadows", no_shadows, "OpenGL: no shadow map");
  app.add_option("--egl-device", egl_device, "EGL device index (-1: Mesa surfaceless platform)");
  app.add_option("--engine", engine, "blender: workbench or cycles")->check(CLI::IsMember({"workbench", "cycles"}));
  app.add_option("--samples", samples, "blender: Cycles samples")->check(manisoft::cli::between(1, 4096));
  app.add_flag("--episode", episode, "render every --every-th trace row into DIR/frames, strip.png and episode.mp4 (ffmpeg)");
  app.add_option("--every", every, "with --episode: frame stride")->check(manisoft::cli::positive());
  manisoft::cli::readable_errors(app, "render_scene");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag

  try {
    if (episode && trace_path.empty()) manisoft::detail::fail("--episode needs --trace");
    tabletop::TabletopScene scene;
    if (!scene_path.empty()) {
#if MANISOFT_RENDER_SCENES
      const manisoft::scene::AssetLibrary library;
      scene = manisoft::scene::make_render_scene(manisoft::scene::load_scene(scene_path, library), library);
#else
      manisoft::detail::fail("--scene ", scene_path, ": this build has no scene component (nlohmann-json and the contact component are needed)");
#endif
    } else {
      scene = tabletop::make_tabletop_scene();
    }
    io::Trace trace;
    if (!trace_path.empty()) {
      trace = io::read_trace(trace_path);
      io::require_trace_matches(scene, trace, trace_path, scene_path.empty() ? "the built-in scene" : scene_path);
    }
    const long row_count = static_cast<long>(trace.rows.size());
    if (!trace_path.empty() && (frame_arg >= row_count || frame_arg < -row_count))
      manisoft::detail::fail("--frame ", frame_arg, " is out of range: the trace has ", row_count, " rows (0..", row_count - 1, ", or -1..-", row_count, ")");
    const std::size_t frame_index = static_cast<std::size_t>(frame_arg < 0 ? row_count + frame_arg : frame_arg);
    manisoft::cli::OutputFolder folder(out_dir);  // removed again if it is new and the run fails
    const fs::path& out = folder.path();

    if (renderer == "blender") {
      std::vector<std::size_t> rows;
      if (episode) {
        for (std::size_t r = 0; r < trace.rows.size(); r += static_cast<std::size_t>(every)) rows.push_back(r);
      }
      std::vector<FrameState> frames;
      if (trace_path.empty()) {
        frames.push_back(scene.frame);
      } else if (episode) {
        for (std::size_t r : rows) frames.push_back(io::frame_from_trace(scene, trace, r));
      } else {
        frames.push_back(io::frame_from_trace(scene, trace, frame_index));
      }
      blender::RunOptions options;
      options.engine = engine;
      options.samples = samples;
      options.masks = true;
      const auto t0 = std::chrono::steady_clock::now();
      blender::render_frames(scene.scene, frames, out / "blender", options);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!episode) {
        // Single frame: copy to the standard names, add camera.json from our own calibration.
        fs::copy_file(out / "blender" / "rgb_00000.png", out / "rgb.png", fs::copy_options::overwrite_existing);
        RenderOutput calib;
        calib.width = scene.scene.cameras[0].width;
        calib.height = scene.scene.cameras[0].height;
        calib.camera = camera_model(scene.scene.cameras[0]);
        const RgbImage mask_rgb = read_png_rgb(out / "blender" / "mask_00000.png");
        calib.mask = blender::decode_mask(mask_rgb);
        write_png_mask(out / "mask.png", calib.width, calib.height, calib.mask);
        io::write_text_atomically(out / "camera.json", io::camera_json(calib, object_bounds(scene.scene, frames[0])));
      }
      std::printf("blender (%s): %zu frame(s) in %.2f s -> %s\n", engine.c_str(), frames.size(), seconds, out.string().c_str());
      folder.keep();
      return 0;
    }

    GlRendererOptions options;
    options.shadows = !no_shadows;
    options.msaa_samples = msaa;
    options.egl.device_index = egl_device;
    GlRenderer gl(options);
    gl.set_scene(scene.scene);
    if (!episode) {
      const FrameState frame = trace_path.empty() ? scene.frame : io::frame_from_trace(scene, trace, frame_index);
      const RenderOutput image = gl.render(frame);
      io::write_frame(out, image, object_bounds(scene.scene, frame));
      std::printf("%s: %d x %d -> %s (rgb.png, depth.png, mask.png, camera.json)\n", gl.device_name().c_str(), image.width, image.height,
                  out.string().c_str());
      folder.keep();
      return 0;
    }
    render_episode(gl, scene, trace, every, out);
    folder.keep();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_scene: %s\n", e.what());
    return 1;
  }
}
