// The importer (assets/mesh_import.hpp) as the fuzz targets of sidecars and meshes call it,
// compiled once (fuzz_import.cpp) for both: its templates are the most expensive part of either.
#pragma once

#include <optional>
#include <string>

#include "manisoft/assets/sidecar.hpp"

namespace manisoft_fuzz {

/// assets::import_asset(mesh_path, sidecar) with the default options.
void import_mesh(const std::string& mesh_path, const std::optional<manisoft::assets::Sidecar>& sidecar);

}  // namespace manisoft_fuzz
