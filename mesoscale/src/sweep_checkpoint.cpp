#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/meso/sweep/checkpoint.hpp"

namespace knit::meso::sweep {

namespace fs = std::filesystem;

namespace {
constexpr const char* kManifest = "manifest.json";

std::string job_file(int index) {
  char b[32];
  std::snprintf(b, sizeof b, "job_%05d.txt", index);
  return b;
}

// Every record ends with a digest line over the record text before it (64-bit FNV-1a,
// fingerprint() of input.hpp): a record edited by hand or damaged on disk is refused on
// --resume, naming the file and the record.
constexpr const char* kDigestTag = "digest fnv1a64 ";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

fs::path CheckpointStore::parts_dir(const fs::path& database) {
  fs::path d = database;
  d += ".parts";
  return d;
}

CheckpointStore::CheckpointStore(const fs::path& database, const std::string& job_definition,
                                 int job_count, bool resume, bool force)
    : dir_(parts_dir(database)) {
  const std::string fp = fingerprint(job_definition);
  if (fs::exists(dir_)) {
    if (!resume && !force)
      throw InputError(dir_.string(), "",
                       "checkpoints of an unfinished sweep exist: continue it with --resume, or "
                       "discard them with --force");
    if (resume) {
      std::string have;
      try {
        have = nlohmann::json::parse(slurp(dir_ / kManifest)).at("fingerprint").get<std::string>();
      } catch (const std::exception&) {
        have = "";
      }
      if (have != fp)
        throw InputError(dir_.string(), "",
                         "--resume: these checkpoints were made from a different sweep input "
                         "(loop lengths, paths, steps, cell, retry or runner differ); use --force "
                         "to discard them");
      return;
    }
    fs::remove_all(dir_);
  }
  fs::create_directories(dir_);
  const nlohmann::json m = {{"format", "knit-sweep-parts"},
                            {"version", 1},
                            {"fingerprint", fp},
                            {"jobs", job_count},
                            {"job_definition", nlohmann::json::parse(job_definition)}};
  io::write_file_atomically(dir_ / kManifest, m.dump(1) + "\n");
}

namespace {

std::string seal_record(const std::string& record) {
  return record + kDigestTag + fingerprint(record) + "\n";
}

std::string open_record(const std::string& text, const std::string& file, const std::string& what) {
  auto refuse = [&](const std::string& why) -> std::string {
    throw InputError(file, "",
                     what + ": " + why +
                         "; the checkpoint was edited or damaged -- delete this file to "
                         "recompute the case, or discard all checkpoints with --force");
  };
  if (text.empty() || text.back() != '\n') refuse("no digest line at the end");
  const std::size_t start = text.rfind('\n', text.size() - 2);
  const std::size_t line = start == std::string::npos ? 0 : start + 1;
  const std::string last = text.substr(line, text.size() - 1 - line);
  if (last.rfind(kDigestTag, 0) != 0) refuse("no digest line at the end");
  const std::string record = text.substr(0, line);
  const std::string have = last.substr(std::string(kDigestTag).size());
  const std::string want = fingerprint(record);
  if (have != want) refuse("digest mismatch (stored " + have + ", record hashes to " + want + ")");
  return record;
}

}  // namespace

std::map<int, JobResult> CheckpointStore::load_finished(const std::vector<Job>& jobs) const {
  std::map<int, JobResult> out;
  for (const Job& j : jobs) {
    const fs::path p = dir_ / job_file(j.index);
    if (!fs::exists(p)) continue;
    const std::string what = "checkpoint record of job " + std::to_string(j.index) +
                             " (l = " + std::to_string(j.loop_length) + " mm, load case " +
                             std::to_string(j.path) + ")";
    const std::string record = open_record(slurp(p), p.string(), what);
    JobResult r;
    try {
      r = deserialize(record);
    } catch (const std::exception& e) {
      throw InputError(p.string(), "", what + ": " + e.what());
    }
    if (matches(r, j)) out.emplace(j.index, std::move(r));  // else: foreign, recomputed
  }
  return out;
}

void CheckpointStore::store(const JobResult& r) const {
  io::write_file_atomically(dir_ / job_file(r.index), seal_record(serialize(r)));
}

void CheckpointStore::remove() const {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

}  // namespace knit::meso::sweep
