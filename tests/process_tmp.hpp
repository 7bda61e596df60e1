// A directory of one test process under the build tree's test_tmp/: CTest runs the test cases
// of a file side by side (one process each), and two of them rewriting one case file let the
// other read it half-written. The directory is removed when the process ends.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace knit::testing {

/// test_tmp/<name>_<pid> of the build tree (not created).
inline std::filesystem::path process_tmp_dir(const std::string& name) {
  return std::filesystem::path(KNIT_BINARY_DIR) / "test_tmp" /
         (name + "_" + std::to_string(::getpid()));
}

/// Removes `dir` (this process's own) when destroyed: declare it after the path.
struct RemoveAtExit {
  std::filesystem::path dir;
  ~RemoveAtExit() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

}  // namespace knit::testing
