// Asset gallery for the "ManiSoft" benchmark (paper section 3.3, assets): lists every category
// of the generated catalogues with instance count and mass range; --markdown prints a table;
// --export DIR writes each visual mesh as a Wavefront OBJ.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "manisoft/assets/catalog.hpp"

int main(int argc, char** argv) {
  bool markdown = false;
  std::string export_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--markdown") markdown = true;
    else if (a == "--export" && i + 1 < argc) export_dir = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--markdown] [--export DIR]\n", argv[0]);
      return a == "--help" ? 0 : 2;
    }
  }
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
  return 0;
}
