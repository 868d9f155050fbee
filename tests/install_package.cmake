# cmake -DBUILD_DIR=<flexmbd build> -DTEST_DIR=<dir> -P install_package.cmake
# Setup of the install test (tests/CMakeLists.txt): empties TEST_DIR, installs the build into
# TEST_DIR/prefix as a user would (cmake --install), and checks the package files are there.
foreach(var BUILD_DIR TEST_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install_package.cmake: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE "${TEST_DIR}")
set(prefix "${TEST_DIR}/prefix")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}"
                RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD_DIR} --prefix ${prefix} failed: ${result}")
endif()
# The layout the README documents. GNUInstallDirs may use lib64 on some systems.
file(GLOB config "${prefix}/lib*/cmake/flexmbd/flexmbdConfig.cmake")
file(GLOB library "${prefix}/lib*/libflexmbd.*")
foreach(item config library)
  if(NOT ${item})
    message(FATAL_ERROR "install: no ${item} installed under ${prefix}")
  endif()
endforeach()
foreach(file include/flexmbd/core/types.hpp include/flexmbd/builders/planar_builders.hpp
             include/flexmbd/results/results_writer.hpp
             include/flexmbd/simulation/simulation.hpp include/flexmbd/linkage/kinematic_analysis.hpp
             include/flexmbd/tensegrity/tensegrity_structure.hpp bin/flexmbd)
  if(NOT EXISTS "${prefix}/${file}")
    message(FATAL_ERROR "install: ${prefix}/${file} missing")
  endif()
endforeach()
# Every "folder/file.hpp" an installed header includes is installed too (a
# folder missing from the install rules would break only the outside projects), and the
# subcommands of the command line (*_command.hpp, not in the library) are not.
file(GLOB_RECURSE headers RELATIVE "${prefix}/include/flexmbd" "${prefix}/include/flexmbd/*.hpp")
foreach(header IN LISTS headers)
  if(header MATCHES "_command\\.hpp$")
    message(FATAL_ERROR "install: ${header} is a header of the command line, not of the library")
  endif()
  file(STRINGS "${prefix}/include/flexmbd/${header}" includes REGEX "^#include \"[a-z_]+/[a-z0-9_]+\\.hpp\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    if(NOT EXISTS "${prefix}/include/flexmbd/${included}")
      message(FATAL_ERROR "install: ${header} includes ${included}, which is not installed")
    endif()
  endforeach()
endforeach()
message(STATUS "flexmbd installed in ${prefix}: ${config}")
