// Output targets: checks before a run, the output lock (see knit/io/output_target.hpp).
// POSIX (Linux) only.
#include "knit/io/output_target.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "knit/core/errors.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/io/names.hpp"

namespace fs = std::filesystem;

namespace knit::io {

namespace {

fs::path without_trailing_slash(fs::path p) {
  while (!p.has_filename() && p.has_parent_path() && p.parent_path() != p) p = p.parent_path();
  return p;
}

/// True if `inner` is `outer` or lies inside it (both made absolute and normal).
bool contains(const fs::path& outer, const fs::path& inner) {
  std::error_code ec;
  const fs::path o = fs::weakly_canonical(outer, ec);
  if (ec) return false;
  const fs::path i = fs::weakly_canonical(inner, ec);
  if (ec) return false;
  auto oi = o.begin(), ii = i.begin();
  for (; oi != o.end(); ++oi, ++ii) {
    if (oi->empty()) continue;  // trailing "" of "a/b/"
    if (ii == i.end() || *oi != *ii) return false;
  }
  return true;
}

std::string read_small(int fd) {
  char buf[128] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

constexpr const char* kLockTag = "knitscale lock pid ";

}  // namespace

bool is_knitscale_output(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(fs::symlink_status(dir, ec)) &&
         fs::is_regular_file(fs::symlink_status(dir / kOutputMarker, ec));
}

namespace {
std::string& owner_storage() {
  static std::string owner;
  return owner;
}
}  // namespace

void set_output_owner(std::string owner) {
  owner_storage() = std::move(owner);
}
const std::string& output_owner() {
  return owner_storage();
}

std::optional<std::string> output_marker_owner(const fs::path& dir) {
  if (!is_knitscale_output(dir)) return std::nullopt;
  std::ifstream in(dir / kOutputMarker, std::ios::binary);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  static const std::string tag = "knitscale output";
  if (line == tag) return std::string();
  if (line.rfind(tag + ": ", 0) == 0) return line.substr(tag.size() + 2);
  // Any other first line names somebody else; an empty marker is no marker of ours either
  // (session 29: an empty .knitscale-output was taken for an output naming no owner).
  return line.empty() ? std::string("an unknown program (its marker file is empty)") : line;
}

bool is_own_output(const fs::path& dir) {
  const auto owner = output_marker_owner(dir);
  return owner && (owner->empty() || *owner == output_owner());
}

std::optional<OutputMarker> read_output_marker(const fs::path& dir) {
  if (!is_knitscale_output(dir)) return std::nullopt;
  std::ifstream in(dir / kOutputMarker, std::ios::binary);
  OutputMarker m;
  std::string line;
  bool said_yes = false, said_no = false;
  for (int k = 0; std::getline(in, line); ++k) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (k == 1) {  // the provenance (JSON); its input file, if it names one
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_object() && j.contains("input") && j["input"].is_string())
        m.input = j["input"].get<std::string>();
    }
    if (k < 2) continue;  // the owner and the provenance
    if (line.rfind("for: ", 0) == 0) {
      m.for_name = line.substr(5);
    } else if (line.rfind("file: ", 0) == 0) {
      m.has_manifest = true;
      m.files.push_back(line.substr(6));
    } else if (line.rfind("replaced by pid ", 0) == 0) {
      char* end = nullptr;
      const long pid = std::strtol(line.c_str() + 16, &end, 10);
      if (end && *end == '\0' && pid > 0) m.replaced_by_pid = pid;
    } else if (line.rfind("input: ", 0) == 0) {
      m.input_absolute = line.substr(7);
    } else if (line == "completed: yes" || line == "completed: no") {
      (line == "completed: yes" ? said_yes : said_no) = true;
    } else if (line.rfind("pid ", 0) == 0) {
      char* end = nullptr;
      const long pid = std::strtol(line.c_str() + 4, &end, 10);
      if (end && *end == '\0' && pid > 0) m.writer_pid = pid;
    }
  }
  // Both "completed: yes" and "no" (never written so; a marker edited by hand or corrupted)
  // say nothing: the command judges the output from its files (session 51's red team: the
  // last line won, and a stopped rerun removed a completed output whose marker ended "no").
  m.completed_recorded = said_yes != said_no;
  m.completed = said_yes && !said_no;
  return m;
}

std::vector<std::string> foreign_entries(const fs::path& dir, std::size_t max) {
  std::vector<std::string> out;
  const auto m = read_output_marker(dir);
  if (!m || !m->has_manifest) return out;
  const std::set<std::string> ours(m->files.begin(), m->files.end());
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const std::string rel = it->path().lexically_relative(dir).generic_string();
    if (rel == kOutputMarker || ours.count(rel)) continue;
    out.push_back(rel);  // a foreign directory is named once, not its contents
    if (it->is_directory(ec) && !it->is_symlink(ec)) it.disable_recursion_pending();
  }
  std::sort(out.begin(), out.end());
  if (out.size() > max) out.resize(max);
  if (ec)  // what cannot be listed cannot be told ours: named as such
    out.insert(out.begin(), "(some of it could not be listed: " + ec.message() + ")");
  return out;
}

void check_default_output_input(const fs::path& target, const std::string& input) {
  const auto m = read_output_marker(without_trailing_slash(target));
  if (!m || input.empty()) return;
  std::error_code e1, e2, e3;
  const fs::path is = fs::weakly_canonical(input, e2);
  if (e2) return;
  std::string named;  // the other input, as the message names it
  if (!m->input_absolute.empty()) {
    const fs::path was = fs::weakly_canonical(m->input_absolute, e1);
    if (e1 || was == is) return;
    named = m->input_absolute;
  } else {
    // An older marker: the input as typed, perhaps relative to another directory. Refused
    // only when it names an existing file here that is not this input.
    if (m->input.empty() || !fs::is_regular_file(m->input, e1) || e1 ||
        fs::equivalent(m->input, input, e3) || e3)
      return;
    named = m->input;
  }
  throw InputError(target.string(), "output directory",
                   "holds the output of another input file, " + named +
                       " (the default output name is the input file's name; this input is " +
                       input + "): give --output to name this output, or to replace that one");
}

void check_output_target(const fs::path& target_in, OutputKind kind, std::string_view option,
                         std::string_view hdf5_format) {
  const std::string opt(option);
  const fs::path target = without_trailing_slash(target_in);
  auto refuse = [&](const std::string& why) { throw InputError(target_in.string(), opt, why); };
  if (target_in.empty()) throw InputError("", opt, "the output path is empty");
  const std::string name = target.filename().string();
  if (name.empty() || name == "." || name == ".." || target == target.root_path())
    refuse(
        "names no new file or directory (\".\", \"..\" and \"/\" cannot be replaced); give "
        "the name of the output to create, e.g. " +
        std::string(kind == OutputKind::kDirectory ? "out/run1" : "out/database.h5"));
  // A file output named with a trailing slash ("db/"): a directory's name, which the atomic
  // writer refuses only when it writes, after the whole sweep (session 36's red team: every
  // case run, then exit 1 with a --resume advice that the same name then refused).
  if (kind == OutputKind::kFile && target != target_in)
    refuse("ends in \"/\", the name of a directory; give the file's name, e.g. " +
           (target / "database.h5").string());
  // Control characters (a newline above all) in the output's path: the marker is written line
  // by line, and a name "o\nfile: notes.txt" put notes.txt into the run's manifest (review of
  // session 29); no one means them in a file name.
  if (has_control_character(target.string()))
    refuse("holds a control character (a newline, a tab, ...): give a plain path");
  // Names the file system cannot hold (session 29: a 5,000-character path failed later with
  // exit 1, naming no option). The partial and lock names add up to 30 characters.
  for (const auto& part : target)
    if (part.string().size() + 30 > 255)
      refuse("has a name of " + std::to_string(part.string().size()) +
             " characters; the file system allows 255 (with the run's partial and lock suffixes: "
             "at most 225)");
  {
    std::error_code aec;
    if (fs::absolute(target, aec).string().size() + 30 >= 4096)
      refuse("is too long for the file system (4096 characters with the run's suffixes)");
  }
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(target, ec);
  if (fs::is_symlink(st)) {
    const bool dangling = !fs::exists(fs::status(target, ec));
    refuse(dangling
               ? "is a dangling symbolic link; give a real path"
               : "is a symbolic link (the output would replace the link, not what it points to); "
                 "give the real path");
  }
  ec.clear();
  // Inside another run's output (session 46's red team: `knit-macro design D.json -o og2/run`,
  // og2 an earlier design output, replaced og2's run/ by another design's whole output, exit 0,
  // and og2's summary still described the old run). A directory whose marker a run wrote (a
  // "for:" line or a manifest) holds that run's files only; a container such as the
  // pipeline's OUT (its marker has neither) holds outputs. The partial directory of this very
  // process, not yet committed (no manifest), is where its nested outputs go (a design's run/).
  // Both the path as given and its lexical normal form are resolved (the review of session 46:
  // "nx/../lnk/db.h5", nx missing and lnk a link to an output, resolved lexically past the
  // missing nx and never followed lnk, while the writer, which makes nx, writes through it).
  // A marker that cannot be read, or a path that cannot be resolved for want of permission or
  // in a loop of links, cannot be told to lie outside a run's output, and is refused.
  {
    const fs::path abs = fs::absolute(target, ec);
    for (const fs::path& form : {abs, abs.lexically_normal()}) {
      std::error_code cec;
      const fs::path canon = fs::weakly_canonical(form, cec);
      if (cec == std::errc::permission_denied || cec == std::errc::too_many_symbolic_link_levels)
        refuse("cannot be resolved (" + cec.message() +
               "), so it cannot be told to lie outside another run's output");
      if (cec) continue;  // e.g. a parent that is a file: the checks below name it
      for (fs::path a = canon.parent_path(); !a.empty(); a = a.parent_path()) {
        if (is_knitscale_output(a) && !std::ifstream(a / kOutputMarker))
          refuse("lies inside " + a.string() + ", whose " + kOutputMarker +
                 " cannot be read: it cannot be told whether that is a run's output");
        const auto m = read_output_marker(a);
        const bool own_partial = m && !m->has_manifest && m->writer_pid == ::getpid();
        if (m && (!m->for_name.empty() || m->has_manifest) && !own_partial)
          refuse("lies inside " + a.string() + ", the output of a knitscale run (its " +
                 kOutputMarker +
                 " says so): a new output there would change that run's files; give a path "
                 "outside it");
        if (a == a.parent_path()) break;
      }
    }
    ec.clear();
  }
  const fs::path parent =
      target.has_parent_path() ? fs::absolute(target, ec).parent_path() : fs::current_path(ec);
  if (fs::exists(st)) {
    if (kind == OutputKind::kDirectory) {
      if (!fs::is_directory(st))
        refuse("exists and is not a directory (an output directory is asked for)");
      if (contains(target, fs::current_path(ec)))
        refuse("is the current directory or contains it; give a new directory for the outputs");
      const bool empty = fs::is_empty(target, ec);
      if (!ec && !empty && !is_knitscale_output(target))
        refuse(std::string("is a non-empty directory that is not a knitscale output (no ") +
               kOutputMarker +
               " file): its files are not ours to replace; give a new or empty directory");
      if (!ec && !empty && !is_own_output(target))
        refuse("is the output of " + *output_marker_owner(target) + " (its " + kOutputMarker +
               " says so), not of " +
               (output_owner().empty() ? std::string("this program") : output_owner()) +
               ": not ours to replace; give another directory");
      if (!ec && !empty) {
        const auto foreign = foreign_entries(target, 6);
        if (!foreign.empty()) {
          std::string list;
          for (std::size_t k = 0; k < std::min<std::size_t>(foreign.size(), 5); ++k)
            list += (k ? ", " : "") + foreign[k];
          refuse("is an earlier output that now holds entries its run did not write (" + list +
                 (foreign.size() > 5 ? ", ..." : "") +
                 "): a new run replaces the directory as a whole, and they are not ours to "
                 "delete; move them out, or give another directory");
        }
      }
    } else {
      if (fs::is_directory(st)) refuse("is a directory; give the name of the file to write");
      if (!fs::is_regular_file(st)) refuse("exists and is not a regular file");
      // The files written with kFile are HDF5 databases: an existing non-empty file that is
      // not HDF5 is somebody else's (found: `knit-meso sweep IN -o notes.txt` replaced a text
      // file by a database).
      if (!fs::is_empty(target, ec) && !ec && !is_hdf5_file(target))
        refuse(
            "exists and is not an HDF5 file (knitscale writes HDF5 databases): it is not ours "
            "to replace; give another name, or remove it first");
      // An HDF5 file of somebody else's (a results file, another program's data) is not an
      // earlier database either: ours carry their format in the root attribute "format".
      if (!hdf5_format.empty() && !fs::is_empty(target, ec) && !ec) {
        std::string format;
        try {
          const H5File f = H5File::open_read(target);
          if (f.has_attribute(".", "format")) format = f.attribute_string(".", "format");
        } catch (const std::exception&) {
          format.clear();
        }
        if (format != hdf5_format)
          refuse("exists and is an HDF5 file that is not a " + std::string(hdf5_format) +
                 " (root attribute format " +
                 (format.empty() ? std::string("missing") : "\"" + format + "\"") +
                 "): it is not ours to replace; give another name, or remove it first");
      }
    }
    if (::access(parent.c_str(), W_OK | X_OK) != 0)
      refuse("cannot be replaced: directory " + parent.string() + " is not writable");
    return;
  }
  // A new target: its nearest existing ancestor must be a writable directory (the writer creates
  // the missing parents).
  fs::path p = parent;
  while (!fs::exists(fs::symlink_status(p, ec)) && p.has_parent_path() && p.parent_path() != p)
    p = p.parent_path();
  if (!fs::is_directory(p, ec)) refuse("cannot be created: " + p.string() + " is not a directory");
  if (::access(p.c_str(), W_OK | X_OK) != 0)
    refuse("cannot be created: directory " + p.string() + " is not writable");
}

// ---- OutputLock -----------------------------------------------------------------------------

fs::path OutputLock::lock_path(const fs::path& target) {
  fs::path l = without_trailing_slash(target);
  l += ".lock";
  return l;
}

namespace {
/// Creates the missing directories of `dir`, one component at a time with mkdir(2), and appends
/// to `made` those that this call created (mkdir returned 0), deepest last. Only what mkdir
/// itself made counts: a path like "new/../keep" names the existing keep/ as well, and a
/// directory another process creates at the same moment is not ours (the review of session
/// 45). Stops at the first component it cannot make; the caller's next step reports it.
void make_directories(const fs::path& dir, std::vector<fs::path>& made) {
  fs::path p;
  for (const auto& part : dir) {
    p /= part;
    if (part == "/" || part == "." || part == "..") continue;
    if (::mkdir(p.c_str(), 0777) == 0)
      made.push_back(p);
    else if (errno != EEXIST)
      return;
  }
}

/// rmdir(2) of `made` (deepest first): removes only empty directories, nothing else.
void remove_if_empty(const std::vector<fs::path>& made) {
  for (auto it = made.rbegin(); it != made.rend(); ++it) ::rmdir(it->c_str());
}
}  // namespace

OutputLock::OutputLock(fs::path target) : file_(lock_path(target)) {
  // The parent directories this lock creates (as the writer would) are removed again, if they
  // are still empty, when it is released or cannot be taken (session 45; session 44's list:
  // `knit-meso fit DB -o a/b/x.h5` refused its options and left the empty a/b behind).
  try {
    take(without_trailing_slash(target).string());
  } catch (...) {
    remove_if_empty(new_dirs_);
    throw;
  }
}

void OutputLock::take(const std::string& out) {
  std::error_code ec;
  if (file_.has_parent_path()) make_directories(file_.parent_path(), new_dirs_);  // as the writer
  // A knitscale lock file never appears untagged at its final path: it is written and locked
  // under a private name, then link()ed to "<target>.lock" (atomic; EEXIST if one is there).
  // So a "<target>.lock" that is empty or holds anything but the tag is someone else's and is
  // refused at once. (Session 28: an empty one of the user's was taken over, and unlinked on
  // release. The first mend, waiting for an empty file to be tagged by its creator, could
  // refuse two runs started together and leave an empty lock that refused every later run;
  // found by review.) A lock file unlinked by its releasing holder between our open() and
  // flock() is not the lock any more: retry on the new file (checked by comparing inodes).
  const std::string me = kLockTag + std::to_string(::getpid()) + "\n";
  // A full or failing disk is no bad input: exit code 1, not 2 (session 34, found with the
  // test shim that makes the disk full).
  const auto cannot = [&](const std::string& what, int err) {
    const std::string msg = what + " " + file_.string() + " (" + std::strerror(err) + ")";
    if (err == ENOSPC || err == EDQUOT || err == EIO) throw std::runtime_error(out + ": " + msg);
    throw InputError(out, "", msg);
  };
  for (int attempt = 0; attempt < 20; ++attempt) {
    // 1. A new lock: tagged and locked under a private name, then linked into place.
    std::string tmpl = file_.string() + ".new-XXXXXX";
    int fd = ::mkostemp(tmpl.data(), O_CLOEXEC);
    if (fd < 0 && errno == ENOENT && attempt + 1 < 20) {
      // The parent was removed in between (another lock released it empty): made again.
      make_directories(file_.parent_path(), new_dirs_);
      continue;
    }
    if (fd < 0) cannot("cannot create the lock file", errno);
    ::fchmod(fd, 0644);
    const bool tagged = ::pwrite(fd, me.data(), me.size(), 0) == static_cast<ssize_t>(me.size());
    if (tagged && ::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::link(tmpl.c_str(), file_.c_str()) == 0) {
      ::unlink(tmpl.c_str());
      fd_ = fd;
      return;
    }
    const int err = errno;
    ::unlink(tmpl.c_str());
    ::close(fd);
    if (!tagged || err != EEXIST) cannot("cannot create the lock file", err);
    // 2. There is one: a held lock (refused), a stale one of a killed process (taken over), or
    // not a knitscale lock file (refused, untouched).
    fd = ::open(file_.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0 && errno == ENOENT) continue;  // released in between: again
    if (fd < 0) cannot("cannot open the lock file", errno);
    struct stat a {};
    const std::string have = read_small(fd);
    if (::fstat(fd, &a) != 0 || !S_ISREG(a.st_mode) || have.rfind(kLockTag, 0) != 0) {
      ::close(fd);
      throw InputError(out, "",
                       file_.string() + " exists and is not a knitscale lock file" +
                           (have.empty() ? " (it is empty)" : "") +
                           "; rename or remove it, or choose another output");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int e = errno;
      ::close(fd);
      if (e != EWOULDBLOCK) cannot("cannot lock", e);
      // Up to the line's end: a take-over writes the new tag over a longer old one before it
      // cuts the file to size.
      std::string pid = have.substr(std::strlen(kLockTag));
      pid = pid.substr(0, pid.find('\n'));
      while (!pid.empty() && pid.back() == ' ') pid.pop_back();
      throw InputError(out, "",
                       "is being written by another knitscale process (pid " +
                           (pid.empty() ? std::string("unknown") : pid) + ", lock file " +
                           file_.string() + "); wait for it to finish or choose another output");
    }
    struct stat b {};
    if (::fstat(fd, &a) != 0 || ::stat(file_.c_str(), &b) != 0 || a.st_ino != b.st_ino ||
        a.st_dev != b.st_dev) {
      ::close(fd);
      continue;
    }
    // The tag first, then the cut to its size: the file never reads empty (session 46's red
    // team, by reading: cut first, a process killed between the two left an empty lock file,
    // "not a knitscale lock file (it is empty)", which refused every later run until removed
    // by hand). Holding the lock is what counts; the pid is for the refused one's message.
    const bool retagged =
        ::pwrite(fd, me.data(), me.size(), 0) == static_cast<ssize_t>(me.size()) &&
        ::ftruncate(fd, static_cast<off_t>(me.size())) == 0;
    (void)retagged;
    fd_ = fd;
    return;
  }
  throw InputError(out, "", "cannot take the lock " + file_.string() + " (it keeps changing)");
}

OutputLock::OutputLock(OutputLock&& o) noexcept
    : file_(std::move(o.file_)), fd_(o.fd_), new_dirs_(std::move(o.new_dirs_)) {
  o.fd_ = -1;
  o.new_dirs_.clear();
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(file_.c_str());  // while still held: a waiting process retries on a new file
  ::close(fd_);
  remove_if_empty(new_dirs_);
}

// ---- sizes ----------------------------------------------------------------------------------

std::string format_bytes(std::uint64_t bytes) {
  static const char* units[] = {"bytes", "kB", "MB", "GB", "TB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1000.0 && u < 4) v /= 1000.0, ++u;
  char b[48];
  if (u == 0)
    std::snprintf(b, sizeof b, "%llu bytes", static_cast<unsigned long long>(bytes));
  else
    std::snprintf(b, sizeof b, "%.3g %s", v, units[u]);  // 18.5 MB, not "18 MB" (session 37)
  return b;
}

std::uint64_t parse_size(std::string_view text, std::string_view option) {
  const std::string s(text);
  auto bad = [&]() -> std::uint64_t {
    throw InputError("", std::string(option),
                     "\"" + s + "\" is not a size (a number with an optional k, M, G or T: 500M)");
  };
  // No sign: "-0" was read as 0, which means no cap (session 51).
  if (s.empty() || s[0] == '-' || s[0] == '+') return bad();
  // A decimal number only: strtod also reads hexadecimal ("0x10", 16 bytes; session 50's red
  // team), "inf", "nan" and leading blanks.
  // strtod must read exactly the leading run of decimal characters.
  const std::size_t number = std::min(s.find_first_not_of("0123456789.eE+-"), s.size());
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (number == 0 || end != s.c_str() + number) return bad();
  std::string unit(end);
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  double f = 1;
  if (unit == "k" || unit == "K")
    f = 1e3;
  else if (unit == "M" || unit == "m")
    f = 1e6;
  else if (unit == "G" || unit == "g")
    f = 1e9;
  else if (unit == "T" || unit == "t")
    f = 1e12;
  else if (!unit.empty())
    return bad();
  if (end == s.c_str() || !std::isfinite(v) || v < 0 || v * f > 1.8e19) return bad();
  // A positive size below one byte (0.5, 1e-300) would round to 0, which means "no cap": the
  // opposite of what was asked (session 24).
  if (v > 0 && v * f < 1)
    throw InputError("", std::string(option),
                     "\"" + s + "\" is below one byte (0 means no cap; give a size such as 500M)");
  return static_cast<std::uint64_t>(v * f);
}

}  // namespace knit::io
