# Optional contact component: rigid bodies with contact and friction on FCL 0.7 + libccd.
# Defines the INTERFACE target manisoft_contact (alias manisoft::contact) when FCL is found.
# Only the double-precision FCL is precompiled: keep contact code on double.
find_package(fcl QUIET)
if(fcl_FOUND)
  # fcl's config pulls ccd (reports version 2.0: never request 2.1) and octomap.
  add_library(manisoft_contact INTERFACE)
  add_library(manisoft::contact ALIAS manisoft_contact)
  target_link_libraries(manisoft_contact INTERFACE manisoft::manisoft fcl)
  # FCL (and its Eigen) as system headers: their warnings are not ours.
  get_target_property(_manisoft_fcl_inc fcl INTERFACE_INCLUDE_DIRECTORIES)
  if(_manisoft_fcl_inc)
    target_include_directories(manisoft_contact SYSTEM INTERFACE ${_manisoft_fcl_inc})
  endif()
  set(MANISOFT_HAVE_CONTACT ON)
  message(STATUS "ManiSoft: contact component enabled (FCL ${fcl_VERSION})")
else()
  set(MANISOFT_HAVE_CONTACT OFF)
  message(STATUS "ManiSoft: FCL not found, contact component (manisoft::contact) disabled")
endif()
