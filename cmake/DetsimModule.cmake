# detsim_module(NAME SOURCE...): the library target of one module (docs/ARCHITECTURE.md): detsim_NAME
# with the alias detsim::NAME, exported and installed as NAME, its public headers in the module's
# include/ directory (the same <detsim/...> paths in-tree and installed), and the project's warnings.
# The caller adds what the module links and defines.
function(detsim_module name)
  add_library(detsim_${name} ${ARGN})
  add_library(detsim::${name} ALIAS detsim_${name})
  set_target_properties(detsim_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME detsim_${name})
  target_include_directories(detsim_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  detsim_warnings(detsim_${name})
endfunction()
