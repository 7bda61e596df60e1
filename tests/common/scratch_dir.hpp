// A per-process scratch directory of a test program under the build tree
// (test_scratch/<tag>_<pid>), removed when the program exits:
//   fs::path scratch(const std::string& name) {
//     static knit_test::ScratchDir dir("io_vtk");
//     return dir / name;
//   }
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace knit_test {

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag)
      : dir_(std::filesystem::path(KNIT_BINARY_DIR) / "test_scratch" /
             (tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    if (::getpid() == owner_) std::filesystem::remove_all(dir_, ec);  // not in a forked child
  }
  const std::filesystem::path& path() const { return dir_; }
  std::filesystem::path operator/(const std::string& name) const { return dir_ / name; }

 private:
  std::filesystem::path dir_;
  pid_t owner_ = ::getpid();
};

}  // namespace knit_test
