# Optional language component: instruction templates and referring expressions read from JSON
# files (nlohmann-json; Debian: nlohmann-json3-dev). Defines the INTERFACE target
# manisoft_language (alias manisoft::language), whose MANISOFT_LANGUAGE_DIR points at the shipped
# data files (examples/data/language here, share/manisoft/language once installed).
find_package(nlohmann_json 3 QUIET CONFIG)
if(nlohmann_json_FOUND)
  add_library(manisoft_language INTERFACE)
  add_library(manisoft::language ALIAS manisoft_language)
  target_link_libraries(manisoft_language INTERFACE manisoft::manisoft nlohmann_json::nlohmann_json)
  target_compile_definitions(manisoft_language INTERFACE
    $<BUILD_INTERFACE:MANISOFT_LANGUAGE_DIR="${PROJECT_SOURCE_DIR}/examples/data/language">)
  install(DIRECTORY examples/data/language/ DESTINATION ${CMAKE_INSTALL_DATADIR}/manisoft/language)
  set(MANISOFT_HAVE_LANGUAGE ON)
  message(STATUS "ManiSoft: language component enabled (nlohmann_json ${nlohmann_json_VERSION})")
else()
  set(MANISOFT_HAVE_LANGUAGE OFF)
  message(STATUS "ManiSoft: nlohmann_json not found, language component (manisoft::language) disabled")
endif()
