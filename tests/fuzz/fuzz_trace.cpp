// libFuzzer target: a world_demo / run_task CSV trace (render/render_io.hpp) read, matched against
// the built-in tabletop scene and turned into frames (render_scene's path, without rendering).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "manisoft/render/render_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = manisoft::render::io;
  static const manisoft::render::tabletop::TabletopScene scene = manisoft::render::tabletop::make_tabletop_scene();
  const std::string path = manisoft_fuzz::write_input(data, size, "trace.csv");
  return manisoft_fuzz::accept_refusal([&] {
    const io::Trace trace = io::read_trace(path);
    io::require_trace_matches(scene, trace, path, "the built-in scene");
    for (std::size_t row = 0; row < trace.rows.size(); ++row) io::frame_from_trace(scene, trace, row);
  });
}
