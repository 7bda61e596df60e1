// knit-macro: the online, macroscale half of knitscale (paper Sect. 2.1.3 and 2.2).
//   knit-macro --help       lists the subcommands (each registers itself in cmd_*.cpp)
//   knit-macro --version    project version and git revision
#include "knit/core/cli.hpp"

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#include <malloc.h>
#endif

int main(int argc, char** argv) {
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
  // The shell allocates its per-evaluation workspaces once per call (kernel products and kept
  // point states, ~0.2-4 MB). With glibc's dynamic mmap threshold those blocks come from fresh
  // mmap'd pages, or from a heap trimmed back to the system, at every call: the inverse design
  // (many small forward solves) spent 35 % of its time in page faults (cases/design
  // diagonal_linear: 11.4 s instead of 2.5 s, scripts/bench/design.sh). Keep blocks up to
  // 64 MB in the heap and do not return it to the system below 256 MB free.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
  return knit::cli::run_main(
      argc, argv, "knit-macro",
      "knit-macro: fabric-level (macroscale) simulation of graded knitted textiles as\n"
      "nonlinear isogeometric Kirchhoff-Love shells (units: mm, N, MPa).");
}
