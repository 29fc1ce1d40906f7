// libFuzzer target: an asset sidecar (assets/sidecar.hpp) parsed, then applied by the importer
// (assets/mesh_import.hpp) to a 10 cm cube, so that its values (scale, up axis, grasps, receptacles,
// decomposition point sets) reach the code that uses them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "fuzz_import.hpp"

namespace {

const std::string& cube_path() {
  static const std::string path = [] {
    const std::string text =
        "v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nv 0 0 0.1\nv 0.1 0 0.1\nv 0.1 0.1 0.1\nv 0 0.1 0.1\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    return manisoft_fuzz::write_input(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), "cube.obj");
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& cube = cube_path();
  return manisoft_fuzz::accept_refusal([&] {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const manisoft::assets::Sidecar sidecar = manisoft::assets::parse_sidecar(text, "fuzz.json", manisoft_fuzz::scratch().string());
    manisoft_fuzz::import_mesh(cube, sidecar);
  });
}
