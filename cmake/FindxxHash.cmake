# FindxxHash: the xxHash library (Debian libxxhash-dev), as the imported target xxHash::xxhash.
# detsim hashes its canonical state bytes with XXH3-64 from it.
#
# With DETSIM_HEADER_ONLY_DEPS (cross builds: no target-architecture libxxhash exists), the target
# is instead xxhash.h alone, compiled into each user with XXH_INLINE_ALL: the same XXH3 code, built
# for the target by its own compiler (see cmake/DetsimHeaderOnlyDeps.cmake).
if(DETSIM_HEADER_ONLY_DEPS)
  include(${CMAKE_CURRENT_LIST_DIR}/DetsimHeaderOnlyDeps.cmake)
  detsim_stage_host_header(xxhash.h xxHash_INCLUDE_DIR)
  include(FindPackageHandleStandardArgs)
  find_package_handle_standard_args(xxHash REQUIRED_VARS xxHash_INCLUDE_DIR)
  if(xxHash_FOUND AND NOT TARGET xxHash::xxhash)
    add_library(xxHash::xxhash INTERFACE IMPORTED)
    set_target_properties(xxHash::xxhash PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${xxHash_INCLUDE_DIR}"
      INTERFACE_COMPILE_DEFINITIONS XXH_INLINE_ALL)
  endif()
  return()
endif()

find_path(xxHash_INCLUDE_DIR xxhash.h)
find_library(xxHash_LIBRARY NAMES xxhash)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(xxHash REQUIRED_VARS xxHash_LIBRARY xxHash_INCLUDE_DIR)
if(xxHash_FOUND AND NOT TARGET xxHash::xxhash)
  add_library(xxHash::xxhash UNKNOWN IMPORTED)
  set_target_properties(xxHash::xxhash PROPERTIES
    IMPORTED_LOCATION "${xxHash_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${xxHash_INCLUDE_DIR}")
endif()
mark_as_advanced(xxHash_INCLUDE_DIR xxHash_LIBRARY)
