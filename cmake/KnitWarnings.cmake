# Warnings for the project's own targets (third-party headers are SYSTEM includes).
add_library(knit_warnings INTERFACE)
target_compile_options(knit_warnings INTERFACE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
# Warnings that are always a bug stop the build. A helper that called itself (session 19's review
# mend of tests/meso/test_fit_cli.cpp) was warned about, missed in the log, and crashed two tests
# in CI; a function that falls off its end without returning is the same kind.
target_compile_options(knit_warnings INTERFACE -Werror=infinite-recursion -Werror=return-type)
# GCC's -Wpsabi note ("the ABI for passing parameters with 32-byte alignment has changed in GCC
# 4.6") is printed for the 4-lane vector arguments of the network lanes' always-inline lambda
# (common/src/material_network_lanes.cpp): an internal lambda, no ABI boundary is crossed, and
# the note was the one non-clean line of every build log.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(knit_warnings INTERFACE -Wno-psabi)
endif()
