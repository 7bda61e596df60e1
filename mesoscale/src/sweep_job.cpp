#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "knit/meso/sweep/job.hpp"

namespace knit::meso::sweep {

using material::RawPath;

std::vector<Job> make_jobs(const SweepInput& in) {
  std::vector<Job> jobs;
  for (std::size_t l = 0; l < in.loop_lengths.size(); ++l)
    for (std::size_t p = 0; p < in.paths.size(); ++p) {
      Job j;
      j.index = static_cast<int>(jobs.size());
      j.loop = static_cast<int>(l);
      j.path = static_cast<int>(p);
      j.loop_length = in.loop_lengths[l];
      j.load_path = in.paths[p];
      jobs.push_back(j);
    }
  return jobs;
}

std::string to_string(JobStatus s) {
  switch (s) {
    case JobStatus::kConverged:
      return "converged";
    case JobStatus::kPartial:
      return "partial";
    case JobStatus::kFailed:
      return "failed";
    case JobStatus::kError:
      return "error";
  }
  return "?";
}

int JobResult::converged_steps() const {
  int n = 0;
  for (int s : raw.status) n += s == kStepConverged ? 1 : 0;
  return n;
}

namespace {

/// Rows k*m - 1 (k = 1..n) of a run refined by m: the same F* as the unrefined steps.
RawPath subsample(const RawPath& fine, const material::LoadPath& path, int m) {
  const int n = path.steps;
  RawPath r;
  r.path = path;
  r.F = material::RowMatrixX::Zero(n, 4);
  r.P = material::RowMatrixX::Zero(n, 4);
  r.E = material::RowMatrixX::Zero(n, 3);
  r.S = material::RowMatrixX::Zero(n, 3);
  r.status.assign(static_cast<std::size_t>(n), kStepNotReached);
  const int rows = static_cast<int>(fine.status.size());
  bool failed = false;
  for (int k = 0; k < n; ++k) {
    const int q = (k + 1) * m - 1;
    // A recorded step is converged only if every sub-step up to it converged.
    for (int s = k * m; s <= q && s < rows && !failed; ++s)
      if (fine.status[static_cast<std::size_t>(s)] != kStepConverged) failed = true;
    if (q >= rows) break;
    if (!failed) {
      r.F.row(k) = fine.F.row(q);
      r.P.row(k) = fine.P.row(q);
      r.E.row(k) = fine.E.row(q);
      r.S.row(k) = fine.S.row(q);
      r.status[static_cast<std::size_t>(k)] = kStepConverged;
    } else {
      r.status[static_cast<std::size_t>(k)] =
          (k == 0 || r.status[static_cast<std::size_t>(k - 1)] == kStepConverged) ? kStepFailed
                                                                                  : kStepNotReached;
    }
  }
  return r;
}

}  // namespace

JobResult run_job(const Job& job, const RetryPolicy& retry, const PathRunner& runner) {
  const auto t0 = std::chrono::steady_clock::now();
  JobResult best;
  best.index = job.index;
  best.raw = subsample(RawPath{}, job.load_path, 1);
  int best_steps = -1;
  int m = std::max(1, retry.substeps_for(job.load_path));
  const int max_retries = retry.retries_for(job.load_path);
  for (int a = 0; a <= max_retries; ++a, m *= retry.step_factor) {
    material::LoadPath lp = job.load_path;
    lp.steps = job.load_path.steps * m;
    ++best.attempts;
    try {
      PathOutcome out = runner(job.loop_length, lp);
      RawPath r = subsample(out.raw, job.load_path, m);
      int conv = 0;
      for (int s : r.status) conv += s == kStepConverged ? 1 : 0;
      if (conv > best_steps) {
        best_steps = conv;
        best.raw = std::move(r);
        best.cell = out.cell;
        best.residual = out.residual;
        best.step_factor = m;
        best.message = out.message;
      }
    } catch (const std::exception& e) {
      if (best_steps < 0) best.message = std::string("runner error: ") + e.what();
      if (best_steps < 0) best.status = JobStatus::kError;
    }
    if (best_steps == job.load_path.steps) break;
  }
  if (best_steps == job.load_path.steps)
    best.status = JobStatus::kConverged;
  else if (best_steps > 0)
    best.status = JobStatus::kPartial;
  else if (best_steps == 0)
    best.status = JobStatus::kFailed;
  best.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return best;
}

// ---- serialization --------------------------------------------------------------------------

namespace {
// Version 3 (issue 11): the path's axis, H and set follow its target.
constexpr const char* kMagic = "knit-sweep-job 3";

void put(std::ostringstream& os, double v) {
  char b[40];
  std::snprintf(b, sizeof b, " %a", v);
  os << b;
}

double get_double(std::istringstream& is) {
  std::string tok;
  if (!(is >> tok)) throw std::runtime_error("job result: truncated");
  char* end = nullptr;
  const double v = std::strtod(tok.c_str(), &end);
  if (end == tok.c_str() || *end != '\0') throw std::runtime_error("job result: bad number " + tok);
  return v;
}

int get_int(std::istringstream& is) {
  long v = 0;
  if (!(is >> v)) throw std::runtime_error("job result: truncated");
  return static_cast<int>(v);
}

void expect(std::istringstream& is, const char* key) {
  std::string tok;
  if (!(is >> tok) || tok != key)
    throw std::runtime_error(std::string("job result: expected '") + key + "', got '" + tok + "'");
}
}  // namespace

std::string serialize(const JobResult& r) {
  std::ostringstream os;
  os << kMagic << "\n";
  os << "index " << r.index << "\nstatus " << static_cast<int>(r.status) << "\nattempts "
     << r.attempts << "\nstep_factor " << r.step_factor << "\nseconds";
  put(os, r.seconds);
  os << "\ncell";
  put(os, r.cell.wale_width);
  put(os, r.cell.course_height);
  put(os, r.cell.thickness);
  os << "\nresidual";
  for (int c = 0; c < 3; ++c) put(os, r.residual(c));
  os << "\nkind " << static_cast<int>(r.raw.path.kind) << "\ntarget";
  put(os, r.raw.path.target(0));
  put(os, r.raw.path.target(1));
  os << "\naxis " << r.raw.path.axis << "\nH";
  for (int c = 0; c < 4; ++c) put(os, r.raw.path.H(c / 2, c % 2));
  os << "\nset " << r.raw.path.set;
  os << "\nsteps " << r.raw.path.steps << "\nrows " << r.raw.status.size() << "\n";
  for (std::size_t k = 0; k < r.raw.status.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    os << r.raw.status[k];
    for (int c = 0; c < 4; ++c) put(os, r.raw.F(i, c));
    for (int c = 0; c < 4; ++c) put(os, r.raw.P(i, c));
    for (int c = 0; c < 3; ++c) put(os, r.raw.E(i, c));
    for (int c = 0; c < 3; ++c) put(os, r.raw.S(i, c));
    os << "\n";
  }
  std::string msg = r.message;
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  os << "message " << msg << "\nend\n";
  return os.str();
}

JobResult deserialize(const std::string& text) {
  std::istringstream is(text);
  std::string line;
  if (!std::getline(is, line) || line != kMagic)
    throw std::runtime_error("job result: not a knit sweep job record");
  JobResult r;
  expect(is, "index");
  r.index = get_int(is);
  expect(is, "status");
  const int st = get_int(is);
  if (st < 0 || st > 3) throw std::runtime_error("job result: bad status");
  r.status = static_cast<JobStatus>(st);
  expect(is, "attempts");
  r.attempts = get_int(is);
  expect(is, "step_factor");
  r.step_factor = get_int(is);
  expect(is, "seconds");
  r.seconds = get_double(is);
  expect(is, "cell");
  r.cell.wale_width = get_double(is);
  r.cell.course_height = get_double(is);
  r.cell.thickness = get_double(is);
  expect(is, "residual");
  for (int c = 0; c < 3; ++c) r.residual(c) = get_double(is);
  expect(is, "kind");
  const int kind = get_int(is);
  if (kind < 0 || kind > 3) throw std::runtime_error("job result: bad path kind");
  r.raw.path.kind = static_cast<material::PathKind>(kind);
  expect(is, "target");
  r.raw.path.target(0) = get_double(is);
  r.raw.path.target(1) = get_double(is);
  expect(is, "axis");
  r.raw.path.axis = get_int(is);
  expect(is, "H");
  for (int c = 0; c < 4; ++c) r.raw.path.H(c / 2, c % 2) = get_double(is);
  expect(is, "set");
  if (!(is >> r.raw.path.set) || !material::is_valid_path_set(r.raw.path.set))
    throw std::runtime_error("job result: bad path set");
  expect(is, "steps");
  r.raw.path.steps = get_int(is);
  expect(is, "rows");
  const int n = get_int(is);
  if (n < 0 || n > 1000000) throw std::runtime_error("job result: bad row count");
  r.raw.F.resize(n, 4);
  r.raw.P.resize(n, 4);
  r.raw.E.resize(n, 3);
  r.raw.S.resize(n, 3);
  r.raw.status.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    r.raw.status[static_cast<std::size_t>(k)] = get_int(is);
    for (int c = 0; c < 4; ++c) r.raw.F(k, c) = get_double(is);
    for (int c = 0; c < 4; ++c) r.raw.P(k, c) = get_double(is);
    for (int c = 0; c < 3; ++c) r.raw.E(k, c) = get_double(is);
    for (int c = 0; c < 3; ++c) r.raw.S(k, c) = get_double(is);
  }
  expect(is, "message");
  std::getline(is, line);
  r.message = line.empty() ? line : line.substr(line[0] == ' ' ? 1 : 0);
  expect(is, "end");
  return r;
}

bool matches(const JobResult& r, const Job& job) {
  return r.index == job.index && r.raw.path.kind == job.load_path.kind &&
         r.raw.path.target == job.load_path.target && r.raw.path.axis == job.load_path.axis &&
         r.raw.path.H == job.load_path.H && r.raw.path.set == job.load_path.set &&
         r.raw.path.steps == job.load_path.steps &&
         static_cast<int>(r.raw.status.size()) == job.load_path.steps;
}

}  // namespace knit::meso::sweep
