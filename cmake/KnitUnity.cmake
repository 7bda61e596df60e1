# Unity groups for the library and executable sources (issue 14; docs/build.md "What the build
# does about it"). Files in one group are compiled as one translation unit (CMake
# UNITY_BUILD_MODE GROUP), so the headers they share (Eigen, nlohmann-json, CLI11, Ceres) are
# parsed and their inline functions and templates generated once per group instead of once per
# file. Files of one group must not define colliding file-scope names (anonymous namespaces,
# `static`, namespace-scope constants): the groups are chosen so that they do not (each
# cmd_*.cpp wraps its Options/run/reg in its own named namespace). A file in no group (a new
# file, or one with its own COMPILE_OPTIONS such as the -O3 kernels) is compiled on its own.
# -DKNIT_UNITY=OFF compiles every file on its own (per-file rebuilds while editing).
option(KNIT_UNITY "Compile the library and executable sources in unity groups (faster clean builds)" ON)

# knit_unity_groups(<target> <source dir> "<group>:<stem>,<stem>,..." ...)
# <stem> names <source dir>/<stem>.cpp, which must be a source of <target>.
function(knit_unity_groups target dir)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ${KNIT_UNITY} UNITY_BUILD_MODE GROUP)
  get_target_property(sources ${target} SOURCES)
  foreach(g ${ARGN})
    string(REPLACE ":" ";" parts "${g}")
    list(GET parts 0 group)
    list(GET parts 1 members)
    string(REPLACE "," ";" members "${members}")
    foreach(m ${members})
      set(f ${dir}/${m}.cpp)
      if(NOT f IN_LIST sources)
        message(FATAL_ERROR "unity group ${group} of ${target}: ${f} is not one of its sources "
                            "(renamed or removed? update the group list)")
      endif()
      set_source_files_properties(${f} PROPERTIES UNITY_GROUP ${target}_${group})
    endforeach()
  endforeach()
endfunction()

# Optimization level per file (issue 14; docs/build.md). In a Release build the numerical
# kernels keep -O3 (KNIT_OPT_HOT) and the code that runs once per run (command line, JSON and
# schema input, HDF5/VTK/CSV output, reports, sweep orchestration) is compiled at -O1
# (KNIT_OPT_COLD): CLI11, nlohmann-json and the schema validator are about half as expensive to
# compile there, and none of it is in a hot loop. Empty values (the default in other build types)
# leave the build type's flags alone; scripts/test.sh sets its own for the sanitizer build.
if(CMAKE_BUILD_TYPE STREQUAL "Release")
  set(knit_hot_default -O3)
  set(knit_cold_default -O1)
  set(knit_tests_default -O1)
else()
  set(knit_hot_default "")
  set(knit_cold_default "")
  set(knit_tests_default "")
endif()
set(KNIT_OPT_HOT "${knit_hot_default}" CACHE STRING "Compile options of the numerical kernels (Release: -O3)")
set(KNIT_OPT_COLD "${knit_cold_default}" CACHE STRING "Compile options of the run-once code: CLI, input, output, reports (Release: -O1)")
# The test files (tests/CMakeLists.txt): their compile time is mostly the front end (Catch2's
# macros, Eigen and JSON templates), their run time mostly the library code they call.
set(KNIT_OPT_TESTS "${knit_tests_default}" CACHE STRING "Compile options of the test files (Release: -O1)")

# knit_split_cold(<hot var> <cold var> <source dir> <stems...>): splits the list in <hot var>
# into the sources <source dir>/<stem>.cpp (appended to <cold var>) and the rest (left in
# <hot var>). Every stem must name one of the sources.
function(knit_split_cold hot_var cold_var dir)
  set(hot ${${hot_var}})
  set(cold ${${cold_var}})
  foreach(stem ${ARGN})
    set(f ${dir}/${stem}.cpp)
    if(NOT f IN_LIST hot)
      message(FATAL_ERROR "cold source list: ${f} does not exist (renamed or removed? update the list)")
    endif()
    list(REMOVE_ITEM hot ${f})
    list(APPEND cold ${f})
  endforeach()
  set(${hot_var} ${hot} PARENT_SCOPE)
  set(${cold_var} ${cold} PARENT_SCOPE)
endfunction()

# knit_opt_level(<target> HOT|COLD|TESTS): the target's sources get KNIT_OPT_<level>
# (after the build type's flags, so they win).
function(knit_opt_level target level)
  if(KNIT_OPT_${level})
    separate_arguments(opts UNIX_COMMAND "${KNIT_OPT_${level}}")
    target_compile_options(${target} PRIVATE ${opts})
  endif()
endfunction()

# knit_cold_part(<lib>): the object library <lib>_cold (the run-once sources of <lib>, with the
# same usage requirements) is archived into <lib>; <lib> gets KNIT_OPT_HOT, <lib>_cold
# KNIT_OPT_COLD.
function(knit_cold_part lib)
  target_link_libraries(${lib} PRIVATE ${lib}_cold)
  knit_opt_level(${lib} HOT)
  knit_opt_level(${lib}_cold COLD)
endfunction()

# knit_cli_unity(<executable> <sources...>): a command-line front end (main.cpp, cmd_*.cpp with
# CLI11) runs once per call: KNIT_OPT_COLD, and one unity translation unit, so CLI11's inline
# code is generated once per executable (each cmd_*.cpp keeps its file-scope names in its own
# namespace knit::<layer>::cmd_<name>).
function(knit_cli_unity exe)
  knit_opt_level(${exe} COLD)
  set_target_properties(${exe} PROPERTIES UNITY_BUILD ${KNIT_UNITY} UNITY_BUILD_MODE GROUP)
  set_source_files_properties(${ARGN} PROPERTIES UNITY_GROUP ${exe}_cli)
endfunction()
