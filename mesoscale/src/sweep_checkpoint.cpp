#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/meso/sweep/checkpoint.hpp"

namespace knit::meso::sweep {

namespace fs = std::filesystem;

namespace {
constexpr const char* kManifest = "manifest.json";
/// Written once the database is in place (CheckpointStore::mark_written).
constexpr const char* kWritten = "database_written";
/// Marks a directory that existed empty before the sweep used it (keep_dir_): not ours to remove,
/// also for a sweep that resumes it (the review of session 52).
constexpr const char* kKeepDirectory = "directory_not_ours";

/// The build that writes a manifest, as it is recorded there: "knit-meso VERSION (git REV)".
std::string build_name() {
  return std::string("knit-meso ") + project_version() + " (git " + git_revision() + ")";
}
/// In the list of builds for a manifest written before session 45, which names none.
constexpr const char* kUnnamedBuild = "an earlier knit-meso (its manifest names no build)";

std::string job_file(int index) {
  char b[32];
  std::snprintf(b, sizeof b, "job_%05d.txt", index);
  return b;
}

// Every record ends with a digest line over the record text before it (fingerprint() of
// input.hpp: a 64-bit FNV-1a variant whose offset basis lacks the standard's last digit, kept
// for the checkpoints of earlier versions; docs/sweep.md): a record edited by hand or damaged
// on disk is refused on --resume, naming the file and the record.
constexpr const char* kDigestTag = "digest fnv1a64 ";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A file the store writes: manifest.json, job_NNNNN.txt, or an atomic temporary of either
/// (".NAME.tmp-<pid>-<n>").
bool is_store_file(std::string name) {
  if (name.size() > 1 && name[0] == '.') {
    const std::size_t tmp = name.find(".tmp-");
    if (tmp == std::string::npos) return false;
    name = name.substr(1, tmp - 1);
  }
  if (name == kManifest || name == kWritten || name == kKeepDirectory) return true;
  // job_%05d.txt: at least 5 digits (index 100000 has 6)
  if (name.size() < 13 || name.rfind("job_", 0) != 0 ||
      name.compare(name.size() - 4, 4, ".txt") != 0)
    return false;
  for (std::size_t i = 4; i + 4 < name.size(); ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  return true;
}

/// Why `dir` is not a checkpoint directory of ours, or "" if it is: a directory holding only
/// the store's files, whose manifest (when readable) is a knit-sweep-parts manifest. A damaged
/// manifest beside our job files is still ours (--force may discard it).
std::string not_ours(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec)))
    return "exists and is not a directory of sweep checkpoints";
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!is_store_file(name) || !fs::is_regular_file(it->symlink_status(ec)))
      return "holds \"" + name + "\", which the sweep does not write";
  }
  if (ec) return "cannot be read: " + ec.message();
  if (fs::exists(dir / kManifest, ec)) {
    try {
      const auto m = nlohmann::json::parse(slurp(dir / kManifest));
      if (!m.is_object() || m.value("format", std::string()) != "knit-sweep-parts")
        return "has a manifest.json that is not a sweep's (format is not \"knit-sweep-parts\")";
    } catch (const std::exception&) {
      // damaged: judged by its neighbours (all ours)
    }
  }
  return "";
}

/// What differs between the job definition stored in a manifest and this sweep's, as pointers
/// into the job definition with both values (at most `max_items`, then "; N more"); "" if
/// the manifest holds none (written before session 26) or they are equal. Session 44's list of
/// what was left open: the refusal said only "a different sweep input", and a user with a long
/// input had to diff the manifest by hand to find the one step count they had changed.
std::string describe_difference(const nlohmann::json& stored, const nlohmann::json& now,
                                std::size_t max_items = 4) {
  const auto short_text = [](const nlohmann::json& v) { return shortened(v.dump(), 60); };
  const nlohmann::json patch = nlohmann::json::diff(stored, now);
  std::ostringstream o;
  std::size_t shown = 0;
  std::map<std::string, std::size_t> appended;
  for (const auto& op : patch) {
    if (shown == max_items) {
      o << "; " << patch.size() - shown << " more";
      break;
    }
    std::string path = op.at("path").get<std::string>();
    const std::string kind = op.at("op").get<std::string>();
    // JSON Patch appends to an array at ".../-": named here by the index it takes.
    if (path.size() >= 2 && path.compare(path.size() - 2, 2, "/-") == 0) {
      const std::string parent = path.substr(0, path.size() - 2);
      path = parent + "/" +
             std::to_string(stored.at(nlohmann::json::json_pointer(parent)).size() +
                            appended[parent]++);
    }
    o << (shown == 0 ? "" : "; ") << (path.empty() ? "/" : path) << ": ";
    if (kind == "replace")
      o << short_text(stored.at(nlohmann::json::json_pointer(path))) << " in the checkpoints, "
        << short_text(op.at("value")) << " now";
    else if (kind == "add")
      o << "only now (" << short_text(op.at("value")) << ")";
    else
      o << "only in the checkpoints (" << short_text(stored.at(nlohmann::json::json_pointer(path)))
        << ")";
    ++shown;
  }
  return o.str();
}

/// Whether the store `dir` (ours) holds a finished case's record (a job_NNNNN.txt).
bool holds_job_records(const fs::path& dir) {
  std::error_code ec;
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name[0] != '.' && name != kManifest && name != kWritten && name != kKeepDirectory &&
        is_store_file(name))
      return true;
  }
  return false;
}
}  // namespace

fs::path CheckpointStore::parts_dir(const fs::path& database) {
  fs::path d = database;
  d += ".parts";
  return d;
}

CheckpointStore::CheckpointStore(const fs::path& database, const std::string& job_definition,
                                 int job_count, bool resume, bool force)
    : dir_(parts_dir(database)), fingerprint_(fingerprint(job_definition)), builds_{build_name()} {
  const std::string& fp = fingerprint_;
  std::error_code ec;
  bool fresh_in_kept = false;  // a kept directory (keep_dir_) that holds nothing of a sweep
  if (fs::exists(fs::symlink_status(dir_, ec))) {
    // Session 26 (found by a helper's audit): --force deleted a directory of that name with
    // the user's files in it (or a plain file), with exit 0.
    if (const std::string why = not_ours(dir_); !why.empty())
      throw InputError(dir_.string(), "",
                       why +
                           ": not ours to continue or discard; rename or remove it, or give "
                           "the database another --output");
    // No finished case in it (a run stopped while it wrote its first manifest left only the
    // manifest's temporary; session 36's red team): nothing to continue or to lose, so it is
    // discarded and the sweep starts afresh, with or without --resume.
    // A directory that existed empty before an earlier sweep used it stays the user's.
    keep_dir_ = fs::exists(dir_ / kKeepDirectory, ec);
    if (!holds_job_records(dir_)) {
      if ((fs::is_empty(dir_, ec) && !ec) || keep_dir_) {
        // An empty directory records nothing of a sweep, so nothing says it is ours (session
        // 52's red team: a user's empty DB.h5.parts was deleted by a successful sweep). The
        // sweep keeps its checkpoints in it, marks it so (kKeepDirectory: a resumed sweep
        // keeps it too), and leaves it, emptied again, in place.
        keep_dir_ = true;
        remove();  // our files only (a marker, a manifest's temporary); the directory stays
        fresh_in_kept = true;
      } else {
        remove();
        if (fs::exists(fs::symlink_status(dir_, ec)))
          throw InputError(dir_.string(), "", "cannot discard the empty checkpoint directory");
      }
      resume = false;
    }
  }
  // Left by a sweep that wrote its database and was stopped while it removed them: nothing of
  // an unfinished sweep to keep (--resume still takes them: every case is in them).
  if (!resume && fs::exists(dir_ / kWritten, ec)) {
    remove();
    if (keep_dir_)
      fresh_in_kept = true;
    else if (fs::exists(fs::symlink_status(dir_, ec)))
      throw InputError(dir_.string(), "", "cannot discard the finished sweep's checkpoints");
  }
  if (!fresh_in_kept && fs::exists(fs::symlink_status(dir_, ec))) {
    if (!resume && !force)
      throw InputError(dir_.string(), "",
                       "checkpoints of an unfinished sweep (or kept by --keep-parts) exist: "
                       "continue it with --resume, or discard them with --force");
    if (resume) {
      std::string have;
      nlohmann::json manifest;
      try {
        manifest = nlohmann::json::parse(slurp(dir_ / kManifest));
        have = manifest.at("fingerprint").get<std::string>();
      } catch (const std::exception&) {
        throw InputError((dir_ / kManifest).string(), "",
                         "--resume: the checkpoints' manifest is missing or damaged, so they "
                         "cannot be matched to this sweep input; use --force to discard them");
      }
      if (have != fp) {
        std::string what;
        try {
          what = describe_difference(manifest.at("job_definition"),
                                     nlohmann::json::parse(job_definition));
        } catch (const std::exception&) {
          // a manifest without a readable job definition: the general words alone
        }
        throw InputError(dir_.string(), "",
                         "--resume: these checkpoints were made from a different sweep input "
                         "(loop lengths, paths, steps, cell, retry or runner differ" +
                             (what.empty() ? std::string()
                                           : "; in the job definition of " +
                                                 (dir_ / kManifest).string() + ", " + what) +
                             "); use --force to discard them");
      }
      // The builds whose cases the checkpoints hold (session 45; left open by session 44: a
      // resume by a rebuilt knit-meso made a database of two builds' cases that named only the
      // last). Another build may resume (a rebuild is routine, and the cases of hours would be
      // lost otherwise); it is added to the manifest's list when it stores its first case
      // (store()), and the database records the list (/sweep/report/case_builds). Nothing is
      // changed on disk here: a resume refused later (a damaged record) leaves the checkpoints
      // as they were (the second review of session 45).
      builds_.clear();
      const auto add = [&](const nlohmann::json& b) {
        if (b.is_string() &&
            std::find(builds_.begin(), builds_.end(), b.get<std::string>()) == builds_.end())
          builds_.push_back(b.get<std::string>());
      };
      if (const auto it = manifest.find("builds"); it != manifest.end() && it->is_array())
        for (const auto& b : *it) add(b);
      else if (const auto sw = manifest.find("software"); sw != manifest.end())
        add(*sw);  // the one-build form of 192295e
      if (builds_.empty()) builds_.push_back(kUnnamedBuild);
      resumed_ = true;
      return;
    }
    remove();
    if (!keep_dir_ && fs::exists(fs::symlink_status(dir_, ec)))
      throw InputError(dir_.string(), "", "--force: cannot discard the checkpoints");
  }
  fs::create_directories(dir_);
  if (keep_dir_)
    std::ofstream(dir_ / kKeepDirectory) << "this directory existed before the sweep\n";
  const nlohmann::json m = {{"format", "knit-sweep-parts"},
                            {"version", 1},
                            {"fingerprint", fp},
                            {"builds", nlohmann::json::array({build_name()})},
                            {"jobs", job_count},
                            {"job_definition", nlohmann::json::parse(job_definition)}};
  io::write_file_atomically(dir_ / kManifest, m.dump(1) + "\n");
}

namespace {

// Since session 36 a record names the sweep it belongs to (the manifest's fingerprint) in a
// line before its digest: a job file copied from another sweep's checkpoints (another cell,
// friction, ...) was taken on --resume with exit 0, since a record holds only its path.
constexpr const char* kSweepTag = "sweep ";

std::string seal_record(const std::string& record, const std::string& sweep) {
  const std::string text = record + kSweepTag + sweep + "\n";
  return text + kDigestTag + fingerprint(text) + "\n";
}

/// If `text` ends with a line "TAG value\n", cuts that line off and returns value; otherwise
/// returns nothing and leaves `text` as it is.
std::optional<std::string> take_last_line(std::string& text, const std::string& tag) {
  if (text.empty() || text.back() != '\n') return std::nullopt;
  const std::size_t start = text.rfind('\n', text.size() - 2);
  const std::size_t line = start == std::string::npos ? 0 : start + 1;
  if (text.compare(line, tag.size(), tag) != 0) return std::nullopt;
  std::string value = text.substr(line + tag.size(), text.size() - 1 - line - tag.size());
  text.resize(line);
  return value;
}

/// Splits the sweep line off a record (its fingerprint, or "" for a record written before
/// session 36, which has none).
std::string take_sweep_line(std::string& record) {
  return take_last_line(record, kSweepTag).value_or("");
}

std::string open_record(const std::string& text, const std::string& file, const std::string& what) {
  auto refuse = [&](const std::string& why) -> std::string {
    throw InputError(file, "",
                     what + ": " + why +
                         "; the checkpoint was edited or damaged -- delete this file to "
                         "recompute the case, or discard all checkpoints with --force");
  };
  std::string record = text;
  const std::optional<std::string> stored = take_last_line(record, kDigestTag);
  if (!stored) refuse("no digest line at the end");
  const std::string& have = *stored;
  const std::string want = fingerprint(record);
  if (have != want) refuse("digest mismatch (stored " + have + ", record hashes to " + want + ")");
  return record;
}

}  // namespace

std::string CheckpointStore::this_build() {
  return build_name();
}

std::string shortened(std::string text, std::size_t max_bytes) {
  if (text.size() <= max_bytes || max_bytes < 3) return text;
  std::size_t cut = max_bytes - 3;  // not inside a UTF-8 sequence (the review of session 45)
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return text.substr(0, cut) + "...";
}

std::map<int, JobResult> CheckpointStore::load_finished(const std::vector<Job>& jobs) const {
  std::map<int, JobResult> out;
  for (const Job& j : jobs) {
    const fs::path p = dir_ / job_file(j.index);
    if (!fs::exists(p)) continue;
    const std::string what = "checkpoint record of job " + std::to_string(j.index) +
                             " (l = " + std::to_string(j.loop_length) + " mm, load case " +
                             std::to_string(j.path) + ")";
    std::string record = open_record(slurp(p), p.string(), what);
    const std::string sweep = take_sweep_line(record);
    if (!sweep.empty() && sweep != fingerprint_) continue;  // another sweep's: recomputed
    JobResult r;
    try {
      r = deserialize(record);
    } catch (const std::exception& e) {
      throw InputError(p.string(), "", what + ": " + e.what());
    }
    if (matches(r, j)) out.emplace(j.index, std::move(r));  // else: foreign, recomputed
  }
  // Resumed, and every record read: they are this run's again, and the mark goes (a
  // --keep-parts resume keeps them on purpose, and a later plain sweep must then refuse them,
  // not discard them). Only now: a refused resume leaves it (the reviews of session 45).
  if (resumed_) {
    std::error_code ec;
    fs::remove(dir_ / kWritten, ec);
  }
  return out;
}

void CheckpointStore::store(const JobResult& r) {
  // The first case this build adds to checkpoints of other builds: its name goes into the
  // manifest first, so that the list never misses a build whose case is stored.
  if (std::find(builds_.begin(), builds_.end(), build_name()) == builds_.end()) {
    nlohmann::json m = nlohmann::json::parse(slurp(dir_ / kManifest));
    builds_.push_back(build_name());
    m["builds"] = builds_;
    m.erase("software");
    io::write_file_atomically(dir_ / kManifest, m.dump(1) + "\n");
  }
  io::write_file_atomically(dir_ / job_file(r.index), seal_record(serialize(r), fingerprint_));
}

void CheckpointStore::mark_written() const {
  std::ofstream(dir_ / kWritten) << "the database of these checkpoints was written\n";
}

void CheckpointStore::remove() const {
  // Only the store's own files, then the directory if that emptied it: a file somebody put
  // there meanwhile stays, with the directory. The manifest goes last, so a run stopped in
  // between leaves a store that --resume continues (session 36's red team: the manifest went
  // first in directory order, and --resume then refused the job files left).
  std::error_code ec;
  std::vector<fs::path> ours;
  for (auto it = fs::directory_iterator(dir_, ec); !ec && it != fs::directory_iterator();
       it.increment(ec))
    if (is_store_file(it->path().filename().string()) && it->is_regular_file(ec))
      ours.push_back(it->path());
  // The job files first, then the "database_written" mark (a stop before it leaves a store
  // the next sweep still discards as finished), the manifest last.
  const auto rank = [](const fs::path& p) {
    return p.filename() == kKeepDirectory ? 3
           : p.filename() == kManifest    ? 2
           : p.filename() == kWritten     ? 1
                                          : 0;
  };
  std::stable_sort(ours.begin(), ours.end(),
                   [&](const fs::path& a, const fs::path& b) { return rank(a) < rank(b); });
  for (const auto& p : ours) fs::remove(p, ec);
  if (!keep_dir_) fs::remove(dir_, ec);  // fails (and keeps it) unless empty
}

}  // namespace knit::meso::sweep
