// The one Catch2 main, compiled once and shared by all test executables.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
