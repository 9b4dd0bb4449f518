# detsim_warnings(target): the project's warning set, applied to its own targets only.
function(detsim_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                           -Wsign-conversion -Wold-style-cast)
  if(DETSIM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
