# Optional scene component: scene descriptions (SceneSpec), their JSON files (nlohmann-json),
# samplers and validation (include/manisoft/scene/). Needs the contact component (the scenes are
# settled in the rigid world) and the language component (instructions; nlohmann-json, Debian:
# nlohmann-json3-dev). Defines the INTERFACE
# target manisoft_scene (alias manisoft::scene) only when both are there.
if(NOT nlohmann_json_FOUND)
  find_package(nlohmann_json 3 QUIET CONFIG)
endif()
if(TARGET manisoft::contact AND TARGET manisoft::language)
  add_library(manisoft_scene INTERFACE)
  add_library(manisoft::scene ALIAS manisoft_scene)
  target_link_libraries(manisoft_scene INTERFACE manisoft::contact manisoft::language)
  set(MANISOFT_HAVE_SCENE ON)
  message(STATUS "ManiSoft: scene component enabled (nlohmann_json ${nlohmann_json_VERSION})")
else()
  set(MANISOFT_HAVE_SCENE OFF)
  message(STATUS "ManiSoft: contact component or nlohmann_json missing, scene component (manisoft::scene) disabled")
endif()
