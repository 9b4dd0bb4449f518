# MPFR (with GMP) is the high-precision reference of the accuracy tests and of `detsim accuracy`.
# It never reaches the detsim libraries.
set(DETSIM_HAVE_MPFR OFF)
if(NOT DETSIM_WITH_MPFR)
  return()
endif()
find_path(MPFR_INCLUDE_DIR mpfr.h)
find_library(MPFR_LIBRARY mpfr)
find_library(GMP_LIBRARY gmp)
if(MPFR_INCLUDE_DIR AND MPFR_LIBRARY AND GMP_LIBRARY)
  set(DETSIM_HAVE_MPFR ON)
  add_library(detsim_mpfr INTERFACE)
  target_include_directories(detsim_mpfr SYSTEM INTERFACE ${MPFR_INCLUDE_DIR})
  target_link_libraries(detsim_mpfr INTERFACE ${MPFR_LIBRARY} ${GMP_LIBRARY})
else()
  set(DETSIM_HAVE_MPFR OFF)
  message(STATUS "MPFR not found: the accuracy test and `detsim accuracy` are not built "
                 "(Debian: apt-get install libmpfr-dev)")
endif()
