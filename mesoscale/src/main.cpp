// knit-meso: the offline, mesoscale half of knitscale (paper Sect. 2.1.2).
//   knit-meso --help        lists the subcommands (each registers itself in cmd_*.cpp)
//   knit-meso --version     project version and git revision
#include "knit/core/cli.hpp"

int main(int argc, char** argv) {
  return knit::cli::run_main(
      argc, argv, "knit-meso",
      "knit-meso: yarn-level (mesoscale) simulation of single-jersey stitches and the\n"
      "material database of homogenized response surfaces (units: mm, N, MPa).");
}
