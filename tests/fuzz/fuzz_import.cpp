// See fuzz_import.hpp.
#include "fuzz_import.hpp"

#include "manisoft/assets/mesh_import.hpp"

namespace manisoft_fuzz {

void import_mesh(const std::string& mesh_path, const std::optional<manisoft::assets::Sidecar>& sidecar) {
  manisoft::assets::import_asset(mesh_path, sidecar);
}

}  // namespace manisoft_fuzz
