# The layer order of the folders: each line names a folder and the folders its files may
# include (besides its own and the libraries outside the project). A folder may include
# only folders listed above it, so the order has no cycle; a folder of the project that
# is not in the table fails the check until it is given its line.
#   cmake -DSOURCE_DIR=<root> -P check_layers.cmake
cmake_minimum_required(VERSION 3.22)
set(FLEXMBD_LAYERS
  "core:"                                   # types, the System, the DAE's assembly
  "elements: core"                          # beam finite elements and sections
  "bodies: core elements"                   # rigid, FFR and FE bodies
  "joints: core elements bodies"            # constraints and drivers
  "forces: core elements bodies joints"     # springs, dampers, loads
  "builders: core elements bodies joints forces"   # building a System from descriptions
  "integrators: core"                       # IDA, Radau IIA, CVODE, the augmented Lagrangian
  "analysis: core elements bodies joints forces integrators"   # linearisation, modes, statics
  "simulation: core elements bodies joints forces integrators analysis"   # the run loop and its stages
  "sensitivity: core elements bodies joints forces integrators analysis simulation"   # forward and adjoint
  "fe_import: core elements bodies"         # Abaqus, Ansys, CalculiX and SID readers
  "scene: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import"
  "linkage: core scene"                     # kinematic analysis of linkages (document 000)
  "tensegrity: core integrators simulation scene"   # tensegrity dynamics (document 001)
  "viewer: core elements bodies joints forces integrators analysis simulation"   # drawing, the HTML viewer
  "results: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene linkage tensegrity viewer"
  "problems: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene"
  "python: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene linkage tensegrity viewer results"
  "app: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene linkage tensegrity viewer results"
  "benchmarks: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene linkage tensegrity viewer results problems"
  "tests: core elements bodies joints forces builders integrators analysis simulation sensitivity fe_import scene linkage tensegrity viewer results problems benchmarks"
)

set(known "")
set(problems "")
foreach(line IN LISTS FLEXMBD_LAYERS)
  string(REGEX MATCH "^([a-z_]+):(.*)$" matched "${line}")
  set(dir "${CMAKE_MATCH_1}")
  string(STRIP "${CMAKE_MATCH_2}" allowed_text)
  separate_arguments(allowed UNIX_COMMAND "${allowed_text}")
  foreach(a IN LISTS allowed)
    if(NOT a IN_LIST known)
      list(APPEND problems "the table: ${dir} may include ${a}, which is not listed above it")
    endif()
  endforeach()
  list(APPEND known "${dir}")
  set(allowed_${dir} ${allowed})
endforeach()

# every top-level folder with C++ sources must have its line
file(GLOB entries LIST_DIRECTORIES true "${SOURCE_DIR}/*")
foreach(entry IN LISTS entries)
  get_filename_component(name "${entry}" NAME)
  if(IS_DIRECTORY "${entry}" AND NOT name MATCHES "^(build.*|\\..*|docs|examples|scripts|cmake)$")
    file(GLOB_RECURSE sources "${entry}/*.cpp" "${entry}/*.hpp")
    list(FILTER sources EXCLUDE REGEX "/node_modules/")
    if(sources AND NOT name IN_LIST known)
      list(APPEND problems "${name}/ holds C++ sources but has no line in the layer table")
    endif()
  endif()
endforeach()

foreach(dir IN LISTS known)
  file(GLOB_RECURSE sources "${SOURCE_DIR}/${dir}/*.cpp" "${SOURCE_DIR}/${dir}/*.hpp")
  list(FILTER sources EXCLUDE REGEX "/node_modules/")
  foreach(source IN LISTS sources)
    file(STRINGS "${source}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"[a-z_]+/")
    foreach(l IN LISTS lines)
      string(REGEX MATCH "include[ \t]*\"([a-z_]+)/" m "${l}")
      set(target "${CMAKE_MATCH_1}")
      if(target IN_LIST known AND NOT target STREQUAL dir AND NOT target IN_LIST allowed_${dir})
        file(RELATIVE_PATH rel "${SOURCE_DIR}" "${source}")
        list(APPEND problems "${rel} includes ${target}/, which ${dir}/ may not (its line: ${allowed_${dir}})")
      endif()
    endforeach()
  endforeach()
endforeach()

if(problems)
  list(JOIN problems "\n  " text)
  message(FATAL_ERROR "the layer order (tests/check_layers.cmake) is broken:\n  ${text}")
endif()
list(LENGTH known count)
message(STATUS "layers: the ${count} folders include only the folders their lines allow")
