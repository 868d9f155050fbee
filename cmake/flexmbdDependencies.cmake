# The libraries flexmbd links privately that ship no usable CMake package on Debian 12:
# Siconos numerics (libsiconos-numerics-dev; Debian's siconos-config.cmake imports every
# Siconos library, kernel, io, ..., while that package ships only numerics), SuiteSparse
# CAMD and KLU (libsuitesparse-dev) and the HDF5 C library (libhdf5-dev, serial flavour:
# CMake's FindHDF5 needs the C language enabled, which a C++-only project has not). Used by the build (CMakeLists.txt) and by the installed
# package (flexmbdConfig.cmake): a static libflexmbd names these imported targets in its
# link interface, so a project linking flexmbd::flexmbd gets them found here too.
#
# Creates the imported targets flexmbd_deps::siconos_numerics, flexmbd_deps::camd,
# flexmbd_deps::klu and flexmbd_deps::hdf5 (those not yet defined); sets
# FLEXMBD_DEPS_MISSING to the list of the libraries not found (empty when all are). Hints:
# the cache variables SICONOS_NUMERICS_LIBRARY, CAMD_LIBRARY, KLU_LIBRARY,
# FLEXMBD_HDF5_LIBRARY (full paths), FLEXMBD_HDF5_INCLUDE_DIR, or CMAKE_PREFIX_PATH.
set(FLEXMBD_DEPS_MISSING "")
foreach(_flexmbd_dep IN ITEMS siconos_numerics camd klu)
  string(TOUPPER "${_flexmbd_dep}_LIBRARY" _flexmbd_var)
  if(NOT TARGET flexmbd_deps::${_flexmbd_dep})
    find_library(${_flexmbd_var} ${_flexmbd_dep})
    if(${_flexmbd_var})
      add_library(flexmbd_deps::${_flexmbd_dep} UNKNOWN IMPORTED)
      set_target_properties(flexmbd_deps::${_flexmbd_dep} PROPERTIES IMPORTED_LOCATION "${${_flexmbd_var}}")
    else()
      list(APPEND FLEXMBD_DEPS_MISSING lib${_flexmbd_dep})
    endif()
  endif()
endforeach()
if(NOT TARGET flexmbd_deps::hdf5)
  # Debian: /usr/include/hdf5/serial, /usr/lib/<arch>/libhdf5_serial.so (also
  # hdf5/serial/libhdf5.so); elsewhere include/hdf5.h and libhdf5.
  find_path(FLEXMBD_HDF5_INCLUDE_DIR hdf5.h PATH_SUFFIXES hdf5/serial)
  find_library(FLEXMBD_HDF5_LIBRARY NAMES hdf5_serial hdf5 PATH_SUFFIXES hdf5/serial)
  if(FLEXMBD_HDF5_INCLUDE_DIR AND FLEXMBD_HDF5_LIBRARY)
    add_library(flexmbd_deps::hdf5 UNKNOWN IMPORTED)
    set_target_properties(flexmbd_deps::hdf5 PROPERTIES IMPORTED_LOCATION "${FLEXMBD_HDF5_LIBRARY}"
                          INTERFACE_INCLUDE_DIRECTORIES "${FLEXMBD_HDF5_INCLUDE_DIR}")
  else()
    list(APPEND FLEXMBD_DEPS_MISSING libhdf5)
  endif()
endif()
unset(_flexmbd_dep)
unset(_flexmbd_var)
