// Helpers of the output tests (issue 14; docs/io.md "Output targets"): run a command and keep
// its exit code and output, hold an output lock from another process like a concurrent run.
#pragma once

#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace knit_test {

struct CommandResult {
  int rc = -1;         ///< exit code (-1: killed by a signal)
  std::string output;  ///< stdout and stderr
};

/// The prefix of a command run with the failing-disk shim preloaded (tests/support/
/// fail_io_shim.c) and its variables `env` ("KNIT_FAIL_WRITE=NAME", "KNIT_FAIL_FSYNC=NAME",
/// "KNIT_LOG_REMOVE=FILE"; empty: the shim changes nothing). ASan's link-order check is off in
/// the sanitizer build, since the shim comes before ASan's runtime.
inline std::string with_fail_io_shim(const std::string& env) {
  return "env LD_PRELOAD=" + std::string(KNIT_FAIL_IO_SHIM) +
         " ASAN_OPTIONS=verify_asan_link_order=0 " + env + " ";
}

/// Runs `command` with /bin/sh (stdout and stderr captured; killed after `timeout_s`).
inline CommandResult run_command(const std::string& command, int timeout_s = 120) {
  const std::string log =
      std::filesystem::temp_directory_path() / ("knit_cmd_" + std::to_string(::getpid()) + ".log");
  const std::string cmd =
      "timeout " + std::to_string(timeout_s) + " sh -c '" + command + "' > " + log + " 2>&1";
  const int st = std::system(cmd.c_str());
  CommandResult r;
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  std::filesystem::remove(log);
  return r;
}

/// A child process holding the lock of an output like a running knitscale command does:
/// flock(2) on `lock_file`, which holds "knitscale lock pid <pid>". release() kills the child:
/// the lock file stays, with a dead pid in it (the stale lock of a killed run).
class LockHolder {
 public:
  explicit LockHolder(const std::filesystem::path& lock_file) {
    int ready[2];
    if (::pipe(ready) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(ready[0]);
      const int fd = ::open(lock_file.c_str(), O_RDWR | O_CREAT, 0644);
      if (fd < 0 || ::flock(fd, LOCK_EX) != 0) ::_exit(1);
      const std::string me = "knitscale lock pid " + std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) != 0 || ::write(fd, me.data(), me.size()) < 0) ::_exit(1);
      if (::write(ready[1], "x", 1) != 1) ::_exit(1);
      for (;;) ::pause();
    }
    ::close(ready[1]);
    char c = 0;
    if (::read(ready[0], &c, 1) != 1) pid_ = -1;
    ::close(ready[0]);
  }
  LockHolder(const LockHolder&) = delete;
  LockHolder& operator=(const LockHolder&) = delete;
  ~LockHolder() { release(); }
  int pid() const { return pid_; }
  void release() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = 0;
  }

 private:
  int pid_ = -1;
};

inline bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// The rows of a CSV file as text cells, its '#' comment lines and empty lines left out (the
/// header is the first row): load_strain.csv, history.csv, path.csv.
inline std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& f) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(f);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The pid of a process that has exited (for stale files of killed runs).
inline int dead_pid() {
  const int pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

/// Rewrites the marker of output directory `dir` as session 48 wrote it: without its
/// "completed:" line (the stopped-rerun tests of knit-meso path and rod judge such an older
/// output from its files).
inline void strip_completed_line(const std::filesystem::path& dir) {
  std::ifstream in(dir / ".knitscale-output");
  std::string marker, line;
  while (std::getline(in, line))
    if (line.rfind("completed:", 0) != 0) marker += line + "\n";
  in.close();
  std::ofstream(dir / ".knitscale-output") << marker;
}

}  // namespace knit_test
