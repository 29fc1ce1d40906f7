// Asset gallery for the "ManiSoft" benchmark (paper section 3.3, assets): lists every category
// of the generated catalogues with instance count and mass range; --markdown prints a table;
// --export DIR writes each visual mesh as a Wavefront OBJ; --contact-sheet FILE.png renders every
// asset (objects, then obstacles) with the in-process OpenGL renderer into a grid of tiles, each
// framed by its bounding box from a 3/4 view and numbered in its top-left corner, and writes the
// legend FILE.csv beside it (tile, id, kind, category, colour, RGB, material, mass).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_checks.hpp"
#include "manisoft/assets/asset_view.hpp"
#include "manisoft/assets/catalog.hpp"
#ifdef MANISOFT_HAVE_RENDER
#include "manisoft/render/gl_renderer.hpp"
#include "manisoft/render/image.hpp"
#endif

namespace {

namespace fs = std::filesystem;
using manisoft::assets::Asset;

#ifdef MANISOFT_HAVE_RENDER
/// Writes `text` to `path` through a temporary file and a rename (never a half-written file).
void write_text_atomically(const fs::path& path, const std::string& text) {
  fs::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) manisoft::detail::fail("cannot write '", tmp.string(), "'");
    f << text;
    if (!f.flush()) manisoft::detail::fail("cannot write '", tmp.string(), "'");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    manisoft::detail::fail("cannot rename '", tmp.string(), "' to '", path.string(), "'");
  }
}

/// The legend of a contact sheet: one row per tile.
std::string legend_csv(const std::vector<Asset>& all, int columns) {
  std::ostringstream o;
  o << "tile,row,column,id,kind,category,color,r,g,b,material,size,mass_kg\n";
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Asset& a = all[i];
    char buf[512];
    std::snprintf(buf, sizeof buf, "%zu,%zu,%zu,%s,%s,%s,%s,%.3f,%.3f,%.3f,%s,%s,%.4f\n", i, i / std::size_t(columns), i % std::size_t(columns),
                  a.id.c_str(), manisoft::assets::to_string(a.kind), a.category.c_str(), a.attributes.color_name.c_str(),
                  static_cast<double>(a.attributes.color_rgb.x()), static_cast<double>(a.attributes.color_rgb.y()),
                  static_cast<double>(a.attributes.color_rgb.z()), a.attributes.material_name.c_str(),
                  manisoft::assets::to_string(a.attributes.size), a.mass);
    o << buf;
  }
  return o.str();
}

/// 3 x 5 pixel digits (rows top to bottom, 3 bits a row, most significant = left).
constexpr std::array<std::array<std::uint8_t, 5>, 10> kDigits{{{7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7},
                                                              {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1},
                                                              {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}}};

/// Draws `number` in dark grey at (x, y) (top-left), each font pixel `scale` x `scale`.
void draw_number(std::vector<std::uint8_t>& rgb, int width, int height, int x, int y, int number, int scale) {
  const std::string text = std::to_string(number);
  for (std::size_t c = 0; c < text.size(); ++c) {
    const auto& glyph = kDigits[static_cast<std::size_t>(text[c] - '0')];
    for (int row = 0; row < 5; ++row) {
      for (int col = 0; col < 3; ++col) {
        if (!((glyph[static_cast<std::size_t>(row)] >> (2 - col)) & 1)) continue;
        for (int dy = 0; dy < scale; ++dy) {
          for (int dx = 0; dx < scale; ++dx) {
            const int px = x + (static_cast<int>(c) * 4 + col) * scale + dx, py = y + row * scale + dy;
            if (px < 0 || py < 0 || px >= width || py >= height) continue;
            for (int k = 0; k < 3; ++k) rgb[(static_cast<std::size_t>(py) * width + px) * 3 + k] = 40;
          }
        }
      }
    }
  }
}

/// Renders every asset into a tile of a `columns`-wide grid; returns the sheet (RGB).
std::vector<std::uint8_t> contact_sheet(const std::vector<Asset>& all, int columns, int tile, int msaa, int downscale, int& width, int& height) {
  const int rows = (static_cast<int>(all.size()) + columns - 1) / columns;
  const int t = tile / downscale;
  width = columns * t;
  height = rows * t;
  std::vector<std::uint8_t> sheet(static_cast<std::size_t>(width) * height * 3, 255);
  manisoft::render::GlRendererOptions options;
  options.msaa_samples = msaa;
  options.read_depth = false;
  options.read_mask = false;
  manisoft::render::GlRenderer gl(options);
  manisoft::assets::AssetViewOptions view;
  view.width = view.height = tile;
  manisoft::render::SceneDescription scene;
  manisoft::render::FrameState frame;
  manisoft::render::RenderOutput image;
  for (std::size_t i = 0; i < all.size(); ++i) {
    manisoft::assets::asset_scene(all[i], view, scene, frame);
    gl.set_scene(scene);
    gl.render_into(frame, image);
    const int x0 = static_cast<int>(i % std::size_t(columns)) * t, y0 = static_cast<int>(i / std::size_t(columns)) * t;
    for (int y = 0; y < t; ++y) {
      for (int x = 0; x < t; ++x) {
        for (int k = 0; k < 3; ++k) {
          int sum = 0;
          for (int dy = 0; dy < downscale; ++dy)
            for (int dx = 0; dx < downscale; ++dx)
              sum += image.rgb[(static_cast<std::size_t>(y * downscale + dy) * tile + (x * downscale + dx)) * 3 + k];
          sheet[(static_cast<std::size_t>(y0 + y) * width + (x0 + x)) * 3 + k] = static_cast<std::uint8_t>(sum / (downscale * downscale));
        }
      }
    }
    // A thin grey frame around the tile and its number.
    for (int k = 0; k < t; ++k) {
      for (const auto& [px, py] : {std::pair{x0 + k, y0}, std::pair{x0, y0 + k}}) {
        for (int c = 0; c < 3; ++c) sheet[(static_cast<std::size_t>(py) * width + px) * 3 + c] = 200;
      }
    }
    draw_number(sheet, width, height, x0 + 3, y0 + 3, static_cast<int>(i), std::max(1, t / 64));
  }
  return sheet;
}
#endif

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"List the ManiSoft asset catalogues; export meshes; render a contact sheet"};
  bool markdown = false;
  std::string export_dir, sheet_path;
  int columns = 20, tile = 160, msaa = 4, downscale = 1, levels = 256;
  app.add_flag("--markdown", markdown, "print the category table as Markdown");
  app.add_option("--export", export_dir, "write every visual mesh as an OBJ file into this folder");
  app.add_option("--contact-sheet", sheet_path, "render every asset into this PNG (legend: the same name with .csv)");
  app.add_option("--columns", columns, "contact sheet: tiles a row")->check(manisoft::cli::between(1, 100));
  app.add_option("--tile", tile, "contact sheet: rendered tile size, pixels")->check(manisoft::cli::between(16, 1024));
  app.add_option("--msaa", msaa, "contact sheet: OpenGL multisampling (0, 2, 4, 8)")->check(CLI::IsMember({0, 2, 4, 8}));
  app.add_option("--downscale", downscale, "contact sheet: box-filter each tile down by this factor")->check(manisoft::cli::between(1, 8));
  app.add_option("--levels", levels, "contact sheet: quantize each colour channel to this many levels (smaller PNG)")
      ->check(manisoft::cli::between(2, 256));
  manisoft::cli::readable_errors(app, "asset_gallery");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  try {
    using namespace manisoft::assets;
    auto all = object_catalog();
    const auto obstacles = obstacle_catalog();
    all.insert(all.end(), obstacles.begin(), obstacles.end());
    struct Row { std::string kind; int n = 0; double lo = 1e300, hi = 0; };
    std::vector<std::string> order;
    std::map<std::string, Row> rows;
    for (const auto& a : all) {
      if (!rows.count(a.category)) order.push_back(a.category);
      auto& r = rows[a.category];
      r.kind = to_string(a.kind);
      ++r.n;
      r.lo = std::min(r.lo, a.mass);
      r.hi = std::max(r.hi, a.mass);
    }
    if (markdown) std::printf("| category | kind | instances | mass (kg) |\n|---|---|---|---|\n");
    for (const auto& c : order) {
      const auto& r = rows[c];
      if (markdown) std::printf("| %s | %s | %d | %.3f - %.3f |\n", c.c_str(), r.kind.c_str(), r.n, r.lo, r.hi);
      else std::printf("%-18s %-9s %2d instances  mass %.3f .. %.3f kg\n", c.c_str(), r.kind.c_str(), r.n, r.lo, r.hi);
    }
    if (!markdown) std::printf("total: %zu assets, %zu categories\n", all.size(), order.size());
    if (!export_dir.empty()) {
      for (const auto& a : all) {
        for (const auto& part : a.visual) {
          std::string name = a.id + "_" + part.name + ".obj";
          std::replace(name.begin(), name.end(), '/', '_');
          const auto path = std::filesystem::path(export_dir) / name;
          std::filesystem::create_directories(path.parent_path());
          std::ofstream f(path);
          f << "# " << a.id << " " << part.name << " (" << part.color_name << " " << part.material_name << ")\n";
          for (const auto& p : part.mesh.positions) f << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
          for (const auto& t : part.mesh.uvs) f << "vt " << t.x() << ' ' << t.y() << '\n';
          for (const auto& n : part.mesh.normals) f << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
          for (std::size_t i = 0; i + 2 < part.mesh.indices.size(); i += 3) {
            f << 'f';
            for (int k = 0; k < 3; ++k) {
              const auto v = part.mesh.indices[i + static_cast<std::size_t>(k)] + 1;
              f << ' ' << v << '/' << v << '/' << v;
            }
            f << '\n';
          }
        }
      }
    }
    if (!sheet_path.empty()) {
      if (tile % downscale != 0) manisoft::detail::fail("--tile ", tile, " must be a multiple of --downscale ", downscale);
#ifdef MANISOFT_HAVE_RENDER
      int w = 0, h = 0;
      auto sheet = contact_sheet(all, columns, tile, msaa, downscale, w, h);
      if (levels < 256) {
        const double step = 255.0 / (levels - 1);
        for (auto& c : sheet) c = static_cast<std::uint8_t>(std::lround(std::round(c / step) * step));
      }
      const fs::path png(sheet_path);
      if (png.has_parent_path()) fs::create_directories(png.parent_path());
      manisoft::render::write_png_rgb(png, w, h, sheet);
      fs::path csv = png;
      csv.replace_extension(".csv");
      write_text_atomically(csv, legend_csv(all, columns));
      std::printf("contact sheet: %zu assets, %d x %d tiles of %d px -> %s (legend %s)\n", all.size(), columns,
                  (static_cast<int>(all.size()) + columns - 1) / columns, tile / downscale, png.string().c_str(), csv.string().c_str());
#else
      manisoft::detail::fail("--contact-sheet needs the render component (EGL, OpenGL and libpng; Debian: libegl-dev libgl-dev ",
                             "libegl1-mesa-dev libgl1-mesa-dri libpng-dev): this asset_gallery was built without it");
#endif
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "asset_gallery: %s\n", e.what());
    return 1;
  }
  return 0;
}
