# Warnings for the project's own targets (third-party headers are SYSTEM includes).
add_library(knit_warnings INTERFACE)
target_compile_options(knit_warnings INTERFACE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
