// libFuzzer target: the convex-mesh OBJ loader (geometry/obj_loader.hpp), read from memory.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "fuzz_input.hpp"
#include "manisoft/geometry/obj_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return manisoft_fuzz::accept_refusal([&] {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    manisoft::geometry::parse_obj_convex_mesh<double>(in, "fuzz.obj");
  });
}
