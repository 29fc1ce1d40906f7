// libFuzzer target: a mesh file through the importer (assets/mesh_import.hpp, assimp), without a
// sidecar. The importer reads a path and picks the format by extension, so the input is written to
// a file named after its format: PLY, glTF binary (GLB), glTF text, STL (ASCII, or binary whose
// size matches its triangle count), else OBJ.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>

#include "fuzz_input.hpp"
#include "fuzz_import.hpp"

namespace {

bool starts_with(const std::uint8_t* data, std::size_t size, const char* prefix) {
  const std::size_t n = std::strlen(prefix);
  return size >= n && std::memcmp(data, prefix, n) == 0;
}

const char* extension_of(const std::uint8_t* data, std::size_t size) {
  if (starts_with(data, size, "ply")) return ".ply";
  if (starts_with(data, size, "glTF")) return ".glb";
  if (starts_with(data, size, "{")) return ".gltf";
  if (starts_with(data, size, "solid")) return ".stl";
  if (size >= 84) {
    std::uint32_t triangles = 0;
    std::memcpy(&triangles, data + 80, sizeof triangles);
    if (84 + 50 * std::uint64_t{triangles} == size) return ".stl";
  }
  return ".obj";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = manisoft_fuzz::write_input(data, size, std::string("mesh") + extension_of(data, size));
  return manisoft_fuzz::accept_refusal([&] { manisoft_fuzz::import_mesh(path, std::nullopt); });
}
