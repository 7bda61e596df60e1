// Defensive input files (see knit/io/input_file.hpp).
#include "knit/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "knit/core/errors.hpp"
#include "knit/io/names.hpp"

namespace knit::io {

namespace {

std::string kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

std::string mib(std::uint64_t bytes) {
  return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

/// Common checks on a stat result; returns the size.
std::uint64_t check_stat(const struct stat& st, const std::string& name, std::uint64_t max_bytes) {
  if (!S_ISREG(st.st_mode))
    throw InputError(name, "",
                     "not a regular file (" + kind_of(st.st_mode) +
                         "); inputs must be "
                         "regular files");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes)
    throw InputError(name, "",
                     "is " + mib(size) + ", more than the " + mib(max_bytes) +
                         " accepted for this input (knit/io/input_file.hpp)");
  return size;
}

/// Closes a descriptor on every path.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

/// Control characters (a newline above all) in an input's path (session 48's red team): its
/// absolute path is a line of the output's marker ("input: ...", io/atomic.hpp), and a case
/// named "x\nfile: notes.txt" put notes.txt into a run's own files, which a rerun then deleted.
/// Output paths are refused the same way (check_output_target). The name is shown with each
/// control character as '?'.
void check_input_name(const std::string& name) {
  if (!has_control_character(name)) return;
  std::string shown = name;
  for (char& ch : shown)
    if (is_control_character(ch)) ch = '?';
  throw InputError(shown, "",
                   "the file's name holds a control character (a newline, a tab, ...; shown "
                   "as '?'); rename it to a plain name");
}

}  // namespace

std::uint64_t check_input_file(const std::filesystem::path& file, std::uint64_t max_bytes) {
  const std::string name = file.string();
  check_input_name(name);
  struct stat st {};
  if (::stat(name.c_str(), &st) != 0)
    throw InputError(name, "",
                     errno == ENOENT ? "file not found"
                                     : std::string("cannot read file: ") + std::strerror(errno));
  return check_stat(st, name, max_bytes);
}

std::string read_input_file(const std::filesystem::path& file, std::uint64_t max_bytes) {
  const std::string name = file.string();
  check_input_name(name);
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  Fd f{::open(name.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (f.fd < 0)
    throw InputError(name, "",
                     errno == ENOENT ? "file not found"
                                     : std::string("cannot read file: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw InputError(name, "", "cannot read file");
  const std::uint64_t size = check_stat(st, name, max_bytes);
  std::string text;
  text.reserve(static_cast<std::size_t>(size));
  char buf[1 << 16];
  while (true) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(name, "", std::string("cannot read file: ") + std::strerror(errno));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > max_bytes)  // the file grew while being read
      throw InputError(name, "", "grew beyond " + mib(max_bytes) + " while being read");
  }
  return text;
}

}  // namespace knit::io
