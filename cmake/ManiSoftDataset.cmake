# Optional dataset component: the expert dataset's HDF5 files (robomimic layout) through the HDF5
# C library. Defines the INTERFACE target manisoft_dataset (alias manisoft::dataset) when HDF5 is
# found (Debian: libhdf5-dev); without it the rest of the library builds.
# FindHDF5 test-compiles a C file: the C language must be enabled (only for that check).
get_property(_manisoft_languages GLOBAL PROPERTY ENABLED_LANGUAGES)
if(NOT "C" IN_LIST _manisoft_languages)
  enable_language(C)
endif()
find_package(HDF5 QUIET COMPONENTS C)
if(HDF5_FOUND)
  add_library(manisoft_dataset INTERFACE)
  add_library(manisoft::dataset ALIAS manisoft_dataset)
  target_link_libraries(manisoft_dataset INTERFACE manisoft::manisoft ${HDF5_C_LIBRARIES})
  target_include_directories(manisoft_dataset SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
  target_compile_definitions(manisoft_dataset INTERFACE ${HDF5_C_DEFINITIONS} ${HDF5_DEFINITIONS})
  set(MANISOFT_HAVE_DATASET ON)
  message(STATUS "ManiSoft: dataset component enabled (HDF5 ${HDF5_VERSION})")
else()
  set(MANISOFT_HAVE_DATASET OFF)
  message(STATUS "ManiSoft: HDF5 not found, dataset component (manisoft::dataset) disabled")
endif()
