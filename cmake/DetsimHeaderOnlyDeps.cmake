# Header-only use of the host's Debian dependency headers, for cross builds (the determinism matrix,
# scripts/matrix.sh). A cross compiler must not see the host's /usr/include as a whole (its C
# library headers are the host's), so each header a cross build needs (xxhash.h, CLI11) is copied
# from the host into a directory of the build tree, and only that directory is put on the path.
set(DETSIM_HOST_INCLUDE_DIR "/usr/include" CACHE PATH
    "Where the host's Debian dependency headers are (header-only dependency builds)")
set(detsim_staged_include_dir "${CMAKE_BINARY_DIR}/detsim-host-headers")

# detsim_stage_host_header(<file or directory relative to the host include dir> <result var>):
# copies it into the staging directory; sets <result var> to that directory, or to NOTFOUND.
function(detsim_stage_host_header path out_var)
  set(source "${DETSIM_HOST_INCLUDE_DIR}/${path}")
  if(NOT EXISTS "${source}")
    message(STATUS "Header-only dependencies: ${source} not found")
    set(${out_var} "${out_var}-NOTFOUND" PARENT_SCOPE)
    return()
  endif()
  get_filename_component(parent "${detsim_staged_include_dir}/${path}" DIRECTORY)
  file(COPY "${source}" DESTINATION "${parent}")
  set(${out_var} "${detsim_staged_include_dir}" PARENT_SCOPE)
endfunction()
