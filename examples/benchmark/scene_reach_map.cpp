// scene_reach_map: measures where the arm reaches the table top tool-down (scene/reach_map.hpp:
// one inverse-statics solve within the actuation limits per cell, height and yaw, the rod clear
// of the top), prints the maps and the covered fractions, and writes a PGM picture: per cell the
// number of grasp heights reached (black none, white all), with the samplers' area (ReachBand)
// at the lowest height outlined (black on reachable cells, white elsewhere).
//   scene_reach_map [--cell 0.025] [--heights 0.08,0.15,0.22,0.30] [--out reach.pgm] [--scale 8]
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "../cli_checks.hpp"
#include "manisoft/scene/reach_map.hpp"

namespace scene = manisoft::scene;

int main(int argc, char** argv) {
  CLI::App app{"Measure the arm's tool-down reach over the table top with the inverse statics"};
  double cell = 0.025;
  std::vector<double> heights{0.08, 0.15, 0.22, 0.30};
  std::string out = "reach.pgm";
  int scale = 8;
  app.add_option("--cell", cell, "grid cell size [m]")->check(manisoft::cli::between(0.005, 0.2));
  app.add_option("--heights", heights, "gripper frame heights above the top [m]")->delimiter(',');
  app.add_option("--out", out, "PGM picture to write");
  app.add_option("--scale", scale, "pixels per cell")->check(manisoft::cli::between(1, 64));
  manisoft::cli::readable_errors(app, "scene_reach_map");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    auto statics = scene::make_scene_statics();
    const auto table = manisoft::world::tabletop_table();
    std::vector<scene::ReachMap> maps;
    const scene::ReachBand band;
    for (double h : heights) {
      scene::ReachMapSettings s;
      s.cell = cell;
      s.heights = {h};
      maps.push_back(scene::measure_reach_map(statics, table, s));
      const auto& m = maps.back();
      int in_band = 0, band_ok = 0;
      for (int ix = 0; ix < m.nx; ++ix)
        for (int iy = 0; iy < m.ny; ++iy)
          if (band.contains(m.cell_center(ix, iy), h)) {
            ++in_band;
            band_ok += m.cell_reachable(ix, iy);
          }
      std::printf("height %.2f m: reachable %d of %zu cells (%.1f%% of the table); band: %d cells (%.1f%% of the table), %.1f%% of them reachable\n", h,
                  m.reachable_count(), m.reachable.size(), 100 * m.covered_fraction(), in_band, 100.0 * in_band / double(m.reachable.size()),
                  in_band ? 100.0 * band_ok / in_band : 0.0);
    }
    const auto& m0 = maps.front();
    int all = 0;
    for (int ix = 0; ix < m0.nx; ++ix)
      for (int iy = 0; iy < m0.ny; ++iy) {
        bool every = true;
        for (const auto& m : maps) every = every && m.cell_reachable(ix, iy);
        all += every;
      }
    std::printf("reachable at every height: %d of %zu cells (%.1f%% of the table)\n", all, m0.reachable.size(), 100.0 * all / double(m0.reachable.size()));
    std::printf("map (rows: x from the far edge down to the back edge; columns: y from -0.5 to +0.5; digit = heights reached)\n");
    for (int ix = m0.nx - 1; ix >= 0; --ix) {
      for (int iy = 0; iy < m0.ny; ++iy) {
        int c = 0;
        for (const auto& m : maps) c += m.cell_reachable(ix, iy);
        std::printf("%c", c == 0 ? '.' : static_cast<char>('0' + c));
      }
      std::printf("\n");
    }
    std::ofstream img(out, std::ios::binary);
    if (!img) manisoft::detail::fail("cannot write '", out, "'");
    img << "P5\n" << m0.ny * scale << " " << m0.nx * scale << "\n255\n";
    for (int row = 0; row < m0.nx * scale; ++row) {
      const int ix = m0.nx - 1 - row / scale;  // far edge at the top
      for (int col = 0; col < m0.ny * scale; ++col) {
        const int iy = col / scale;
        int c = 0;
        for (const auto& m : maps) c += m.cell_reachable(ix, iy);
        int v = c * 255 / static_cast<int>(maps.size());
        // the samplers' area (ReachBand) at the lowest height: outlined where it begins or ends
        const double px = cell / scale;
        const double x = m0.x0 + (m0.nx * scale - row - 0.5) * px, y = m0.y0 + (col + 0.5) * px;
        const bool in = band.contains({x, y}, heights.front());
        if (in != band.contains({x - px, y}, heights.front()) || in != band.contains({x, y + px}, heights.front())) v = v >= 128 ? 0 : 255;
        img.put(static_cast<char>(v));
      }
    }
    std::printf("picture: %s\n", out.c_str());
  } catch (const manisoft::Error& e) {
    std::fprintf(stderr, "scene_reach_map: %s\n", e.what());
    return 1;
  }
  return 0;
}
