// render_blender: renders a recorded world_demo episode trace with Blender (Cycles or Workbench),
// headless, one Blender process for the whole trajectory: DIR/rgb_<k>.png (and mask_<k>.png
// with --masks) for every --every-th trace row, plus the exported scene in DIR/export.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "../cli_checks.hpp"
#include "blender_run.hpp"
#include "manisoft/render/render_io.hpp"
#include "manisoft/render/tabletop_render_scene.hpp"

using namespace manisoft::render;

int main(int argc, char** argv) {
  CLI::App app{"Render a world_demo episode trace with Blender (the paper's look)"};
  std::string trace_path, out_dir, engine = "cycles";
  int samples = 16, every = 50;
  std::size_t first = 0, last = static_cast<std::size_t>(-1);
  bool masks = false;
  app.add_option("--trace", trace_path, "world_demo CSV trace (README.md, \"world_demo\")")->required();
  app.add_option("--out", out_dir, "output folder")->required();
  app.add_option("--engine", engine, "cycles or workbench")->check(CLI::IsMember({"workbench", "cycles"}));
  app.add_option("--samples", samples, "Cycles samples (denoising is off)")->check(manisoft::cli::between(1, 4096));
  app.add_option("--every", every, "render every N-th trace row")->check(manisoft::cli::positive());
  app.add_option("--first", first, "first trace row");
  app.add_option("--last", last, "last trace row (inclusive)");
  app.add_flag("--masks", masks, "also write object-id masks (mask_<k>.png, flat colours)");
  manisoft::cli::readable_errors(app, "render_blender");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    const tabletop::TabletopScene scene = tabletop::make_tabletop_scene();
    const io::Trace trace = io::read_trace(trace_path);
    if (first >= trace.rows.size()) manisoft::detail::fail("--first ", first, " is out of range: the trace has ", trace.rows.size(), " rows");
    std::vector<FrameState> frames;
    for (std::size_t r = first; r < trace.rows.size() && r <= last; r += static_cast<std::size_t>(every)) frames.push_back(io::frame_from_trace(scene, trace, r));
    blender::RunOptions options;
    options.engine = engine;
    options.samples = samples;
    options.masks = masks;
    const auto t0 = std::chrono::steady_clock::now();
    blender::render_frames(scene.scene, frames, out_dir, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("blender %s: %zu frames in %.2f s (%.3f s a frame incl. start-up) -> %s\n", engine.c_str(), frames.size(), seconds,
                seconds / static_cast<double>(frames.size()), out_dir.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_blender: %s\n", e.what());
    return 1;
  }
}
