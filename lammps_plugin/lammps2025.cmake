# SPDX-License-Identifier: GPL-2.0-or-later
# pair_style gran/hooke/stickslip as a plugin of LAMMPS 2023 and later (PLUGIN package), from
# the source Debian's LAMMPS builds (lammps_api.h: where the APIs differ). CMakeLists.txt
# includes this file instead of its Debian build when LAMMPS_2025_DIR is set:
#   cmake -S lammps_plugin -B build/lammps_2025_plugin -DLAMMPS_2025_DIR=$PWD/build/lammps_2025
#   cmake --build build/lammps_2025_plugin
# Produces libstickslip_lammps2025.so: `plugin load <path>/libstickslip_lammps2025.so` in an
# input script of that LAMMPS, then `pair_style gran/hooke/stickslip ...`.
# LAMMPS_2025_DIR: ./run.sh's layout (source/src: LAMMPS' src/ tree, GRANULAR included;
# build/: its CMake build, liblammps.so and CMakeCache.txt). Another layout: give
# LAMMPS_2025_SRC and LAMMPS_2025_LIBRARY (and LAMMPS_2025_BUILD, the CMake build directory
# whose integer sizes to use; none: smallbig, LAMMPS' default).
set(LAMMPS_2025_SRC ${LAMMPS_2025_DIR}/source/src CACHE PATH "LAMMPS' src/ directory (2023 or later)")
set(LAMMPS_2025_BUILD ${LAMMPS_2025_DIR}/build CACHE PATH "LAMMPS' CMake build directory")
set(LAMMPS_2025_LIBRARY ${LAMMPS_2025_BUILD}/liblammps.so CACHE FILEPATH "LAMMPS' shared library")
foreach(h version.h lammpsplugin.h pair.h fix_neigh_history.h GRANULAR/pair_gran_hooke_history.h)
  if(NOT EXISTS ${LAMMPS_2025_SRC}/${h})
    message(FATAL_ERROR "LAMMPS header ${LAMMPS_2025_SRC}/${h} not found (LAMMPS_2025_SRC: LAMMPS' src/ "
                        "with GRANULAR; STICKSLIP_SOURCE_BUILDS=lammps-2025 ./run.sh setup makes build/lammps_2025)")
  endif()
endforeach()
if(NOT EXISTS ${LAMMPS_2025_LIBRARY})
  message(FATAL_ERROR "${LAMMPS_2025_LIBRARY} not found: the plugin links LAMMPS' shared library "
                      "(LAMMPS built with -D BUILD_SHARED_LIBS=on)")
endif()

# the version, yyyymmdd, from version.h's "4 Feb 2025"
file(STRINGS ${LAMMPS_2025_SRC}/version.h version_line REGEX "^#define LAMMPS_VERSION ")
if(NOT version_line MATCHES "\"([0-9]+) ([A-Z][a-z][a-z])[a-z]* ([0-9][0-9][0-9][0-9])\"")
  message(FATAL_ERROR "cannot read the LAMMPS version in ${LAMMPS_2025_SRC}/version.h: '${version_line}'")
endif()
set(day ${CMAKE_MATCH_1})
set(year ${CMAKE_MATCH_3})
set(months Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec)
list(FIND months ${CMAKE_MATCH_2} month)
math(EXPR lammps_version "${year} * 10000 + (${month} + 1) * 100 + ${day}")
if(month LESS 0 OR lammps_version LESS 20230802)
  message(FATAL_ERROR "LAMMPS ${lammps_version} (${version_line}): LAMMPS_2025_DIR needs LAMMPS 2 Aug 2023 or "
                      "later (Debian 12's LAMMPS: the default build, without LAMMPS_2025_DIR)")
endif()
message(STATUS "stickslip plugin for LAMMPS ${lammps_version}")

# integer sizes and MPI as LAMMPS was built (its lmp -h lists them): they set class layouts
set(sizes smallbig)
set(mpi on)
if(EXISTS ${LAMMPS_2025_BUILD}/CMakeCache.txt)
  load_cache(${LAMMPS_2025_BUILD} READ_WITH_PREFIX lammps_ LAMMPS_SIZES BUILD_MPI)
  if(lammps_LAMMPS_SIZES)
    string(TOLOWER ${lammps_LAMMPS_SIZES} sizes)
  endif()
  set(mpi ${lammps_BUILD_MPI})
endif()
if(NOT mpi)
  message(FATAL_ERROR "LAMMPS in ${LAMMPS_2025_BUILD} was built without MPI: the plugin is built for an MPI build")
endif()
string(TOUPPER "LAMMPS_${sizes}" sizes_define)
find_package(MPI REQUIRED COMPONENTS CXX)
if(NOT CMAKE_BUILD_TYPE)
  set(CMAKE_BUILD_TYPE Release)
endif()

add_library(stickslip_lammps2025 MODULE pair_gran_hooke_stickslip.cpp stickslip_lammpsplugin.cpp)
set_target_properties(stickslip_lammps2025 PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON CXX_EXTENSIONS OFF)
target_include_directories(stickslip_lammps2025 PRIVATE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/granular ${CMAKE_CURRENT_SOURCE_DIR}/../law_core
                           ${LAMMPS_2025_SRC} ${LAMMPS_2025_SRC}/GRANULAR)
target_compile_definitions(stickslip_lammps2025 PRIVATE STICKSLIP_LAMMPS_VERSION=${lammps_version} ${sizes_define}
                           OMPI_SKIP_MPICXX MPICH_SKIP_MPICXX)
# the flags of the Debian build, for the same reasons (CMakeLists.txt); LAMMPS' own Release
# build is -O3 as CMAKE_BUILD_TYPE Release here, which the drop-in's bit-for-bit needs
target_compile_options(stickslip_lammps2025 PRIVATE -ffp-contract=off -fno-math-errno -fno-tree-vectorize
                       -fvisibility=hidden -fvisibility-inlines-hidden
                       -fmacro-prefix-map=${CMAKE_CURRENT_SOURCE_DIR}/=lammps_plugin/)
# linked to liblammps so that a symbol missing from this LAMMPS fails here, not at `plugin load`
target_link_libraries(stickslip_lammps2025 PRIVATE ${LAMMPS_2025_LIBRARY} MPI::MPI_CXX -Wl,--no-undefined)
