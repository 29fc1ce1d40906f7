// libFuzzer target: a scene file (scene/scene_json.hpp) parsed, then checked against the asset
// library as load_scene does (scene_validation.hpp's require_consistent).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "manisoft/scene/scene_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const manisoft::scene::AssetLibrary library;
  return manisoft_fuzz::accept_refusal([&] {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const manisoft::scene::SceneSpec spec = manisoft::scene::parse_scene(text, "fuzz.json");
    manisoft::scene::require_consistent(spec, library, "fuzz.json");
  });
}
