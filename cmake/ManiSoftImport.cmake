# Optional import component: loads users' meshes (OBJ, glTF/GLB, STL, PLY) through assimp and
# their JSON sidecars (and RoboTwin-OD model_data annotations) through nlohmann-json into
# assets::Asset. Defines the INTERFACE target manisoft_import (alias manisoft::import) only when
# both are found (Debian: libassimp-dev nlohmann-json3-dev).
find_package(assimp QUIET CONFIG)
find_package(nlohmann_json 3 QUIET CONFIG)
if(assimp_FOUND AND TARGET assimp::assimp AND nlohmann_json_FOUND)
  add_library(manisoft_import INTERFACE)
  add_library(manisoft::import ALIAS manisoft_import)
  target_link_libraries(manisoft_import INTERFACE manisoft::manisoft assimp::assimp nlohmann_json::nlohmann_json)
  # assimp's headers as system headers: their warnings are not ours.
  get_target_property(_manisoft_assimp_inc assimp::assimp INTERFACE_INCLUDE_DIRECTORIES)
  if(_manisoft_assimp_inc)
    target_include_directories(manisoft_import SYSTEM INTERFACE ${_manisoft_assimp_inc})
  endif()
  set(MANISOFT_HAVE_IMPORT ON)
  message(STATUS "ManiSoft: import component enabled (assimp ${assimp_VERSION}, nlohmann_json ${nlohmann_json_VERSION})")
else()
  set(MANISOFT_HAVE_IMPORT OFF)
  message(STATUS "ManiSoft: assimp or nlohmann_json not found, import component (manisoft::import) disabled")
endif()
