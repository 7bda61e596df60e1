// Atomic files and directories (see knit/io/atomic.hpp). POSIX (Linux) only.
#include "knit/io/atomic.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>   // renameat2 (glibc >= 2.28, _GNU_SOURCE is defined by g++)
#include <stdlib.h>  // mkstemps
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "knit/io/names.hpp"
#include "knit/io/provenance.hpp"

namespace fs = std::filesystem;

namespace knit::io {

namespace {

std::atomic<unsigned> g_counter{0};

[[noreturn]] void fail(const fs::path& p, const std::string& what, int err = 0) {
  std::string msg = p.string() + ": " + what;
  if (err != 0) msg += std::string(" (") + std::strerror(err) + ")";
  throw std::runtime_error(msg);
}

/// fsync a file or a directory by name; returns errno or 0.
int fsync_path(const fs::path& p, bool directory) {
  const int fd = ::open(p.c_str(), (directory ? O_DIRECTORY : 0) | O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  const int rc = ::fsync(fd);
  const int err = rc == 0 ? 0 : errno;
  ::close(fd);
  return err;
}

fs::path strip_trailing_slash(fs::path p) {
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p;
}

fs::path parent_or_dot(const fs::path& p) {
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

bool pid_is_dead(long pid) {
  return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

/// The pid in a name "<prefix><pid>" (with_counter: "<prefix><pid>-<n>"), or -1 if the name
/// has another form (digits only, at most 9 of them).
long pid_in_name(const std::string& f, const std::string& prefix, bool with_counter) {
  if (f.size() <= prefix.size() || f.compare(0, prefix.size(), prefix) != 0) return -1;
  std::string digits = f.substr(prefix.size());
  if (with_counter) {
    const size_t dash = digits.find('-');
    if (dash == std::string::npos) return -1;
    const std::string n = digits.substr(dash + 1);
    if (n.empty() || n.size() > 9 || n.find_first_not_of("0123456789") != std::string::npos)
      return -1;
    digits.resize(dash);
  }
  if (digits.empty() || digits.size() > 9 ||
      digits.find_first_not_of("0123456789") != std::string::npos)
    return -1;
  return std::stol(digits);
}

/// Whether a file's content could be a temporary of ours that a kill cut short: empty, or an
/// HDF5 file (the databases; text outputs are written inside output directories, which are
/// replaced whole). Session 36's red team: a user's text file named ".X.h5.tmp-999999-0" was
/// deleted by `knit-meso synth -o X.h5`.
bool looks_like_our_temporary(const fs::path& p) {
  static constexpr char kHdf5Signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  std::ifstream in(p, std::ios::binary);
  char head[8] = {};
  in.read(head, sizeof head);
  const std::streamsize n = in.gcount();
  return n == 0 || (n == 8 && std::memcmp(head, kHdf5Signature, 8) == 0);
}

/// Removes the temporaries ".<name>.tmp-<pid>-<n>" of `target` left by killed runs: regular
/// files only, only when their pid is dead (ours may be writing another one right now), and
/// only when their content could be ours (looks_like_our_temporary).
void remove_stale_temporaries(const fs::path& target) {
  std::string prefix(".");
  prefix += target.filename().string();
  prefix += ".tmp-";
  std::error_code ec;
  for (auto it = fs::directory_iterator(parent_or_dot(target), ec);
       !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const long pid = pid_in_name(it->path().filename().string(), prefix, true);
    std::error_code st;
    if (pid > 0 && pid_is_dead(pid) && fs::is_regular_file(fs::symlink_status(it->path(), st)) &&
        looks_like_our_temporary(it->path())) {
      std::error_code rm;
      fs::remove(it->path(), rm);
    }
  }
}

}  // namespace

// ---- AtomicFile -----------------------------------------------------------------------------

namespace {
// The temporaries of AtomicFiles not yet committed, for unlink_live_temporaries() in a signal
// handler. A slot is claimed, its generation made odd, its path copied, the generation made
// even again; a release makes it odd (and never even again until the next path is in). The
// handler copies a slot's path while its generation is even and unlinks the copy only if the
// generation is still the same: a path that another thread released or rewrote meanwhile is
// skipped, never a torn mix of two (session 43's review).
constexpr int kLiveSlots = 16;
constexpr std::size_t kLivePathMax = 4096;
char g_live_path[kLiveSlots][kLivePathMax];
std::atomic<bool> g_live_claimed[kLiveSlots];
std::atomic<unsigned> g_live_generation[kLiveSlots];  // even: the path is ours and complete
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<unsigned>::is_always_lock_free,
              "the signal handler reads these: they must be lock-free");

int register_live(const fs::path& p) {
  const std::string& s = p.native();
  if (s.size() + 1 > kLivePathMax) return -1;
  for (int i = 0; i < kLiveSlots; ++i) {
    if (g_live_claimed[i].exchange(true)) continue;
    // Released slots are odd already; a slot never used is 0 (even, but with an empty path).
    if (g_live_generation[i].load() % 2 == 0) g_live_generation[i].fetch_add(1);
    std::memcpy(g_live_path[i], s.c_str(), s.size() + 1);
    g_live_generation[i].fetch_add(1);  // even: complete
    return i;
  }
  return -1;  // more than kLiveSlots at once: left for the next run's clean-up
}

void release_live(int slot) {
  if (slot < 0) return;
  g_live_generation[slot].fetch_add(1);  // odd: not a live temporary
  g_live_claimed[slot].store(false);
}
}  // namespace

void unlink_live_temporaries() noexcept {
  char path[kLivePathMax];
  for (int i = 0; i < kLiveSlots; ++i) {
    const unsigned g = g_live_generation[i].load();
    if (g == 0 || g % 2 != 0) continue;  // never used, or released / being written
    std::memcpy(path, g_live_path[i], kLivePathMax);
    path[kLivePathMax - 1] = '\0';
    std::atomic_thread_fence(std::memory_order_acquire);  // the copy before the re-check
    if (g_live_generation[i].load() == g) ::unlink(path);
  }
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (!target_.has_filename()) fail(target_, "not a file name");
  const fs::path dir = parent_or_dot(target_);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    fail(target_, "cannot write: directory " + dir.string() + " missing");
  std::string name(".");  // built step by step: GCC 12 warns falsely on "." + std::string
  name += target_.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(g_counter++);
  temp_ = dir / name;
  remove_stale_temporaries(target_);
  live_slot_ = register_live(temp_);
}

AtomicFile::AtomicFile(AtomicFile&& o) noexcept
    : target_(std::move(o.target_)),
      temp_(std::move(o.temp_)),
      stream_(std::move(o.stream_)),
      committed_(o.committed_),
      live_slot_(o.live_slot_) {
  o.temp_.clear();
  o.committed_ = true;
  o.live_slot_ = -1;
}

AtomicFile::~AtomicFile() {
  release_live(live_slot_);
  if (committed_ || temp_.empty()) return;
  if (stream_.is_open()) stream_.close();
  std::error_code ec;
  fs::remove(temp_, ec);
}

std::ofstream& AtomicFile::stream() {
  if (committed_) fail(target_, "stream() after commit()");
  if (!stream_.is_open()) {
    stream_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!stream_) fail(temp_, "cannot open for writing", errno);
  }
  return stream_;
}

void AtomicFile::commit() {
  if (committed_) return;
  if (stream_.is_open()) {
    stream_.flush();
    const bool ok = static_cast<bool>(stream_);
    stream_.close();
    if (!ok || stream_.fail()) fail(target_, "write failed (disk full?)");
  }
  std::error_code ec;
  if (!fs::exists(temp_, ec)) fail(target_, "nothing was written to " + temp_.string());
  if (int err = fsync_path(temp_, false)) fail(target_, "fsync failed", err);
  if (::rename(temp_.c_str(), target_.c_str()) != 0)
    fail(target_, "cannot rename temporary", errno);
  committed_ = true;
  release_live(live_slot_);  // renamed: a signal from here on must not unlink a new temporary
  live_slot_ = -1;
  fsync_path(parent_or_dot(target_), true);  // best effort: makes the rename durable
}

// ---- ScratchFile ----------------------------------------------------------------------------

namespace {
/// Every signal blocked in this thread for the object's lifetime.
struct SignalsBlocked {
  sigset_t old;
  SignalsBlocked() {
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
  }
  ~SignalsBlocked() { pthread_sigmask(SIG_SETMASK, &old, nullptr); }
  SignalsBlocked(const SignalsBlocked&) = delete;
  SignalsBlocked& operator=(const SignalsBlocked&) = delete;
};
}  // namespace

ScratchFile::ScratchFile(const fs::path& dir, std::string_view stem, std::string_view suffix) {
  std::string name = (dir / stem).string();
  name += "XXXXXX";
  name += suffix;
  const SignalsBlocked blocked;  // created and registered as one step for a signal
  const int fd = ::mkstemps(name.data(), static_cast<int>(suffix.size()));
  if (fd >= 0) {
    ::close(fd);
    path_ = name;
    live_slot_ = register_live(path_);
  }
}

ScratchFile::~ScratchFile() {
  if (path_.empty()) return;
  const SignalsBlocked blocked;  // removed and released as one step for a signal
  std::error_code ec;
  fs::remove(path_, ec);
  release_live(live_slot_);
}

void write_file_atomically(const fs::path& target, std::string_view content) {
  AtomicFile f(target);
  f.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  f.commit();
}

// ---- AtomicDirectory ------------------------------------------------------------------------

namespace {

/// Checks the target and creates its parents; returns it without a trailing '/'.
fs::path prepare_target(fs::path target, std::string_view option) {
  target = strip_trailing_slash(std::move(target));
  check_output_target(target, OutputKind::kDirectory, option);
  // The missing parent directories are made by the lock (OutputLock), which removes them again
  // if they are still empty when it is released (session 45's review: made here, a refused
  // `knit-meso path --out fresh/sub/p` left the empty fresh/sub behind).
  return target;
}

/// Removes an output directory of ours with its marker last, so that a kill part-way leaves a
/// marked directory, which the next run's clean-up recognizes and removes (session 26: the
/// marker went in directory order, 1st or 2nd, and a kill then left "DIR.partial-<pid>"
/// without it, which nothing ever removed).
void remove_marked_tree(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> entries;
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator();
       it.increment(ec))
    if (it->path().filename() != kOutputMarker) entries.push_back(it->path());
  if (ec) return;  // not listed: keep it marked for a later clean-up
  for (const auto& e : entries) {
    fs::remove_all(e, ec);
    if (ec) return;  // something stays: so does the marker
  }
  fs::remove(dir / kOutputMarker, ec);
  fs::remove(dir, ec);
}

/// True if `dir` is an output that process `pid` was moving aside ("replaced by pid" in its
/// marker, written just before the rename to "<target>.old-<pid>").
bool moved_aside_by(const fs::path& dir, long pid) {
  const auto m = read_output_marker(dir);
  return m && m->replaced_by_pid == pid;
}

/// Removes "<target>.partial-<pid>" and "<target>.old-<pid>" left by killed runs: only those
/// whose pid is dead (or ours: an earlier run with a recycled pid) and whose marker says that
/// a run of ours left them (a partial directory "for: <target>", an output "replaced by pid
/// <pid>").
void remove_stale_siblings(const fs::path& target) {
  const std::string name = target.filename().string();
  std::error_code ec;
  // A run killed between the two renames of a replacement without RENAME_EXCHANGE left no
  // DIR and the earlier output in DIR.old-<pid>: put it back first (session 26: the clean-up
  // deleted it, before a run that could still fail).
  if (!fs::exists(fs::symlink_status(target, ec))) {
    for (auto it = fs::directory_iterator(parent_or_dot(target), ec);
         !ec && it != fs::directory_iterator(); it.increment(ec)) {
      const long pid = pid_in_name(it->path().filename().string(), name + ".old-", false);
      if (pid >= 0 && (pid == ::getpid() || pid_is_dead(pid)) && moved_aside_by(it->path(), pid) &&
          ::rename(it->path().c_str(), target.c_str()) == 0)
        break;
    }
    ec.clear();
  }
  for (auto it = fs::directory_iterator(parent_or_dot(target), ec);
       !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string f = it->path().filename().string();
    for (const char* tag : {".partial-", ".old-"}) {
      const long pid = pid_in_name(f, name + tag, false);
      if (pid < 0 || !(pid == ::getpid() || pid_is_dead(pid))) continue;
      // Only what a run of ours left there: a partial directory written for this target, or
      // an output that run moved aside (session 29: any marked directory of that name went,
      // a user's copy "cp -a out out.old-2024" or an output asked for as "out.partial-31337").
      const auto m = read_output_marker(it->path());
      if (!m) continue;
      const bool partial = std::string(tag) == ".partial-";
      // A partial directory has no manifest yet (written at commit): a copy of a finished
      // output under that name keeps its "for:" line and is not ours to remove (review).
      // Killed within its commit (manifest written, not yet renamed) it has the manifest and
      // the writer's "pid" line, which is the pid of its name; after the exchange of a
      // replacement it holds the earlier output, marked "replaced by pid" (session 38's red
      // team: a SIGINT in the commit's fsyncs left a 298 MB DIR.partial-<pid> for good).
      const bool left_by_run =
          m->replaced_by_pid == pid ||
          (partial && m->for_name == name && (!m->has_manifest || m->writer_pid == pid));
      if (left_by_run) remove_marked_tree(it->path());
    }
  }
}

/// "replaced by pid <pid>" appended to the marker of `dir` (best effort): the clean-up after a
/// kill then knows the output there for one this process was replacing.
void mark_replaced(const fs::path& dir) {
  std::ofstream(dir / kOutputMarker, std::ios::binary | std::ios::app)
      << "replaced by pid " << ::getpid() << "\n";
}

/// A warning about `target` on stderr, named by the program (output_owner).
void warn_about(const fs::path& target, const std::string& what) {
  std::cerr << (output_owner().empty() ? std::string("knitscale") : output_owner())
            << ": warning: " << target.string() << ": " << what << "\n";
}

/// rename(2) that never replaces what is at `to` (renameat2 RENAME_NOREPLACE; on a file system
/// without it, a look and a rename). 0, or the errno (EEXIST when something is there).
int rename_noreplace(const fs::path& from, const fs::path& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return errno;
  std::error_code ec;
  if (fs::exists(fs::symlink_status(to, ec))) return EEXIST;
  return ::rename(from.c_str(), to.c_str()) == 0 ? 0 : errno;
}

/// The old output after a replacement: removed if it is ours (marker) or empty, else kept.
void remove_old_output(const fs::path& old, const fs::path& target) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(old, ec);
  // What the exchange took out of the target's place is ours only as a directory (the review of
  // session 46: a file or a link that raced into the target's place just before the exchange
  // was removed if it was, or pointed to, something empty). Anything else stays, and is named.
  if (!fs::is_directory(st)) {
    if (fs::exists(st))
      warn_about(target, std::string("something that took its place just before the new output "
                                     "was moved in (a ") +
                             (fs::is_symlink(st) ? "symbolic link" : "file") + ") is now at " +
                             old.string() + ", left alone");
    return;
  }
  if (is_knitscale_output(old))
    remove_marked_tree(old);
  else if (fs::is_empty(old, ec))
    fs::remove(old, ec);
  // What could not be removed (a subdirectory the user cannot write) stays, marked; the next
  // run into the target tries again. Said once on stderr (session 46's red team: every rerun
  // left another copy of the earlier output beside the target without a word).
  if (fs::exists(fs::symlink_status(old, ec)))
    warn_about(target, "the new output is in place, but the earlier one, moved to " + old.string() +
                           ", could not be removed entirely (permissions?); the next run into " +
                           target.string() + " tries again, or remove it by hand");
}

}  // namespace

AtomicDirectory::AtomicDirectory(fs::path target, OnAbandon on_abandon, std::string_view option,
                                 std::string input)
    : target_(prepare_target(std::move(target), option)), lock_(target_), on_abandon_(on_abandon) {
  // Under the lock: nobody else writes this target now. Clean up after killed runs (which may
  // put an earlier output back in place), then check again what the target holds.
  remove_stale_siblings(target_);
  check_output_target(target_, OutputKind::kDirectory, option);
  if (const auto m = read_output_marker(target_)) {
    earlier_completed_ = m->completed;
    earlier_marked_ = true;
    earlier_recorded_ = m->completed_recorded;
  }
  partial_ = target_;
  partial_ += ".partial-";
  partial_ += std::to_string(::getpid());
  std::error_code ec;
  if (fs::exists(fs::symlink_status(partial_, ec)))
    fail(partial_, "exists and is not a knitscale output; rename or remove it");
  fs::create_directory(partial_, ec);
  if (ec) fail(partial_, "cannot create directory: " + ec.message());
  std::ofstream marker(partial_ / kOutputMarker, std::ios::binary);
  // The first line names the writer (output_owner): only it replaces this output later.
  marker << "knitscale output" << (output_owner().empty() ? "" : ": " + output_owner()) << "\n"
         << Provenance::current(input).to_json_string() << "\n"
         << "for: " << target_.filename().string() << "\n"
         << "pid " << ::getpid() << "\n";
  // The input file's absolute path: the provenance keeps it as typed, relative to a directory
  // the marker does not record (check_default_output_input; session 47's review).
  if (!input.empty()) {
    std::error_code aec;
    const fs::path abs = fs::absolute(input, aec);
    const std::string line = abs.lexically_normal().string();
    // (no control character: read_input_file refuses them in an input's name; a caller that
    // did not read its input through it gets no "input:" line rather than a forged one)
    const bool plain = !has_control_character(line);
    if (!aec && plain) marker << "input: " << line << "\n";
  }
  if (!marker.flush()) {
    // The directory is ours, just created, and holds only this file: without its marker no
    // later run would remove it (session 34: a full disk left DIR.partial-<pid> for good).
    marker.close();
    fs::remove(partial_ / kOutputMarker, ec);
    fs::remove(partial_, ec);
    fail(partial_ / kOutputMarker, "cannot write");
  }
}

AtomicDirectory::AtomicDirectory(AtomicDirectory&& o) noexcept
    : target_(std::move(o.target_)),
      lock_(std::move(o.lock_)),
      partial_(std::move(o.partial_)),
      keep_suffix_(std::move(o.keep_suffix_)),
      replaced_kept_in_(std::move(o.replaced_kept_in_)),
      completed_flag_(o.completed_flag_),
      earlier_completed_(o.earlier_completed_),
      earlier_marked_(o.earlier_marked_),
      earlier_recorded_(o.earlier_recorded_),
      on_abandon_(o.on_abandon_),
      committed_(o.committed_),
      active_(o.active_) {
  o.active_ = false;
}

AtomicDirectory::~AtomicDirectory() {
  if (!active_ || committed_) return;
  std::error_code ec;
  if (on_abandon_ == OnAbandon::Remove) {
    remove_marked_tree(partial_);
  } else {
    std::ofstream(partial_ / "INCOMPLETE")
        << "This directory is the incomplete output for " << target_.string()
        << ": the run stopped before committing it. " << target_.string()
        << " (if it exists) was left untouched.\n";
  }
}

void AtomicDirectory::dispose_replaced(const fs::path& old) {
  std::error_code ec;
  if (!keep_suffix_.empty() && is_knitscale_output(old)) {
    // The order keeps every state a kill can leave recognisable (the review of session 46):
    // the output kept before for this DIR is exchanged with the replaced one and marked
    // "replaced by pid" first, so that the clean-up of DIR.partial-<pid> removes it if the
    // removal below is cut short; the newly kept output loses that line once it is in place.
    const auto strip_replaced_line = [](const fs::path& dir) {
      std::ifstream in(dir / kOutputMarker, std::ios::binary);
      std::string text, line;
      while (std::getline(in, line))
        if (line.rfind("replaced by pid ", 0) != 0) text += line + "\n";
      in.close();
      std::ofstream(dir / kOutputMarker, std::ios::binary | std::ios::trunc) << text;
    };
    fs::path where = target_;
    where += keep_suffix_;
    const auto kept_before = read_output_marker(where);
    const bool ours_for_here = kept_before && is_own_output(where) &&
                               kept_before->for_name == target_.filename().string() &&
                               foreign_entries(where).empty();
    if (ours_for_here) {
      mark_replaced(where);
      if (::renameat2(AT_FDCWD, old.c_str(), AT_FDCWD, where.c_str(), RENAME_EXCHANGE) == 0) {
        strip_replaced_line(where);
        replaced_kept_in_ = where;
        remove_old_output(old, target_);  // the output kept before, now at `old`
        return;
      }
      strip_replaced_line(where);  // no exchange: it stays as it was
    }
    if (fs::exists(fs::symlink_status(where, ec))) where += "-" + std::to_string(::getpid());
    if (rename_noreplace(old, where) == 0) {
      strip_replaced_line(where);
      replaced_kept_in_ = where;
      return;
    }
  }
  remove_old_output(old, target_);
}

void AtomicDirectory::commit() {
  if (committed_) return;
  if (!active_) fail(target_, "commit() on a moved-from AtomicDirectory");
  std::error_code ec;
  // The manifest: every file and directory of the run, so that a later run replaces only
  // these (check_output_target refuses an output holding others; session 29).
  {
    std::string manifest;
    for (auto it = fs::recursive_directory_iterator(partial_, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      const std::string rel = it->path().lexically_relative(partial_).generic_string();
      if (rel != kOutputMarker) manifest += "file: " + rel + "\n";
    }
    if (ec) fail(partial_, "cannot list the outputs: " + ec.message());
    if (completed_flag_ >= 0) manifest += completed_flag_ ? "completed: yes\n" : "completed: no\n";
    if (completed_flag_ == 0 && earlier_completed_ && keep_suffix_.empty())
      keep_suffix_ = ".last-completed";
    std::ofstream marker(partial_ / kOutputMarker, std::ios::binary | std::ios::app);
    marker << manifest;
    if (!marker.flush()) fail(partial_ / kOutputMarker, "cannot write");
  }
  // Make the contents durable before they become visible under the final name.
  // A file that cannot be made durable fails the commit, as AtomicFile's does (session 34:
  // ignored, exit 0); directories are best effort (some file systems refuse their fsync).
  for (auto it = fs::recursive_directory_iterator(partial_, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file(ec)) {
      if (const int err = fsync_path(it->path(), false)) fail(it->path(), "fsync failed", err);
    } else if (it->is_directory(ec)) {
      fsync_path(it->path(), true);
    }
  }
  fsync_path(partial_, true);

  // What took the target's place while the run went on is left alone, and the new output is
  // kept beside it under a name of its own (the clean-up of partial directories would remove
  // it; session 26: the message named it, and it was gone; session 46's red team: a file or a
  // symbolic link there made the commit fail and the finished output was deleted).
  const auto keep_beside = [&](const std::string& what) {
    std::string where;
    for (int k = 0; k < 100 && where.empty(); ++k) {
      fs::path kept = target_;
      kept += ".new-" + std::to_string(::getpid()) + (k ? "-" + std::to_string(k) : "");
      if (rename_noreplace(partial_, kept) == 0) where = kept.string();
    }
    if (where.empty()) {  // kept as the partial directory, complete, without INCOMPLETE
      where =
          partial_.string() + " (rename it: the next run into " + target_.string() + " removes it)";
    }
    active_ = false;  // nothing to remove or mark
    fail(target_, what + " while the run went on: left alone; the new output is kept in " + where);
  };
  const fs::file_status now = fs::symlink_status(target_, ec);
  // Into a target that is not there (any more): never over something that appeared meanwhile.
  const auto move_in = [&](const char* what) {
    if (const int err = rename_noreplace(partial_, target_); err != 0) {
      if (err == EEXIST) keep_beside(what);
      fail(target_, "cannot rename " + partial_.string(), err);
    }
  };
  if (!fs::exists(now)) {
    move_in("appeared");
  } else {
    if (!fs::is_directory(now))
      keep_beside(std::string("became ") +
                  (fs::is_symlink(now) ? "a symbolic link" : "a file or another non-directory"));
    const std::vector<std::string> foreign = foreign_entries(target_);
    if ((!is_own_output(target_) || !foreign.empty()) && !fs::is_empty(target_, ec)) {
      if (!foreign.empty())
        keep_beside("received entries that the earlier run did not write (" + foreign[0] +
                    (foreign.size() > 1 ? ", ..." : "") + ")");
      keep_beside("became a non-empty directory that is not this program's output (its " +
                  std::string(kOutputMarker) + " is missing or names another)");
    }
    // So that the clean-up after a kill knows the earlier output for ours wherever the kill
    // leaves it (DIR.partial-<pid> after the exchange, DIR.old-<pid> below): appended to a
    // marker of ours only (an empty target has none), best effort (without it a killed run
    // leaves the earlier output for the user).
    if (read_output_marker(target_)) mark_replaced(target_);
    if (::renameat2(AT_FDCWD, partial_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
      dispose_replaced(partial_);  // now holds the old contents
    } else if (errno == ENOENT) {
      // The earlier output went away after the look (the review of session 46: a user's rm -rf
      // during the commit made the exchange and the move aside fail, and the finished output
      // was deleted).
      move_in("was removed, and something else appeared in its place,");
    } else {
      // File system without RENAME_EXCHANGE: move the old directory aside first.
      fs::path old = target_;
      old += ".old-";
      old += std::to_string(::getpid());
      if (fs::exists(fs::symlink_status(old, ec)))
        fail(old, "exists and is not ours to remove; rename or remove it");
      if (::rename(target_.c_str(), old.c_str()) != 0) {
        if (errno != ENOENT) fail(target_, "cannot move the previous output aside", errno);
        move_in("was removed, and something else appeared in its place,");
        committed_ = true;
        fsync_path(parent_or_dot(target_), true);
        return;
      }
      if (const int err = rename_noreplace(partial_, target_); err != 0) {
        if (err != EEXIST) ::rename(old.c_str(), target_.c_str());  // put the old output back
        // Something appeared at the target between the two renames: the earlier output stays
        // at its .old- name (the next run puts it back), the new one is kept beside.
        if (err == EEXIST) keep_beside("appeared (the earlier output is in " + old.string() + ")");
        fail(target_, "cannot rename " + partial_.string(), err);
      }
      dispose_replaced(old);
    }
  }
  committed_ = true;
  fsync_path(parent_or_dot(target_), true);
}

std::string explain_unwritten_outputs(const std::string& message) {
  const std::string token = ".partial-" + std::to_string(::getpid());
  const std::size_t at = message.find(token);
  if (at == std::string::npos) return message;
  // The directory's path runs back to the start of the message or to the blank before it.
  const std::size_t blank = message.rfind(' ', at);
  const std::size_t start = blank == std::string::npos ? 0 : blank + 1;
  const std::string target = message.substr(start, at - start);
  if (target.empty()) return message;
  // REASON: the message with every partial directory of this process named as its target,
  // files of the outer one relative to it ("DIR.partial-1/run.partial-1/x" -> "run/x").
  std::string why = message.substr(0, start) + message.substr(at + token.size());
  if (why.size() > start && why[start] == '/') why.erase(start, 1);
  for (std::size_t k = why.find(token); k != std::string::npos; k = why.find(token, k))
    why.erase(k, token.size());
  std::error_code ec;
  const bool earlier = fs::exists(target, ec);
  return target + ": outputs not written (" +
         (earlier ? "the earlier outputs are left as they were" : "nothing was written") +
         "): " + why;
}

const char* unwritten_output_state(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec) ? " is left as it was" : " was not created";
}

}  // namespace knit::io
