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

std::map<int, JobResult> CheckpointStore::load_finished(const std::vector<Job>& jobs) const {
  std::map<int, JobResult> out;
  for (const Job& j : jobs) {
    const fs::path p = dir_ / job_file(j.index);
    if (!fs::exists(p)) continue;
    try {
      JobResult r = deserialize(slurp(p));
      if (matches(r, j)) out.emplace(j.index, std::move(r));
    } catch (const std::exception&) {
      // unreadable: recomputed
    }
  }
  return out;
}

void CheckpointStore::store(const JobResult& r) const {
  io::write_file_atomically(dir_ / job_file(r.index), serialize(r));
}

void CheckpointStore::remove() const {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

}  // namespace knit::meso::sweep
