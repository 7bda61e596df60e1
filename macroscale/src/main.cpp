// knit-macro: the online, macroscale half of knitscale (paper Sect. 2.1.3 and 2.2).
//   knit-macro --help       lists the subcommands (each registers itself in cmd_*.cpp)
//   knit-macro --version    project version and git revision
#include "knit/core/cli.hpp"

int main(int argc, char** argv) {
  return knit::cli::run_main(
      argc, argv, "knit-macro",
      "knit-macro: fabric-level (macroscale) simulation of graded knitted textiles as\n"
      "nonlinear isogeometric Kirchhoff-Love shells (units: mm, N, MPa).");
}
