// The sweep driver: checkpoints, thread pool, MPI ranks, progress, assembly (see sweep.hpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/output_target.hpp"
#include "knit/meso/sweep/checkpoint.hpp"
#include "knit/meso/sweep/progress.hpp"
#include "knit/meso/sweep/sweep.hpp"

namespace knit::meso::sweep {

namespace fs = std::filesystem;

bool fails_sweep(const JobResult& r) {
  if (r.status == JobStatus::kConverged) return false;
  return r.status == JobStatus::kError || r.raw.path.set == "paper";
}

int SweepReport::failed_cases() const {
  int n = 0;
  for (const auto& r : results) n += fails_sweep(r) ? 1 : 0;
  return n;
}

int SweepReport::stopped_cases() const {
  int n = 0;
  for (const auto& r : results) n += r.status != JobStatus::kConverged && !fails_sweep(r) ? 1 : 0;
  return n;
}

bool SweepReport::fits_ok() const {
  return std::all_of(fits.begin(), fits.end(), [](const auto& f) { return f.ok(); }) &&
         (!energy_fit || energy_fit->ok());
}

namespace {
/// A build name from a manifest as a line of the terminal may show it (the second review of
/// session 45: a hand-edited entry went to stderr with its control characters, 6 kB long):
/// control characters as '?', at most 120 bytes, not cut inside a UTF-8 sequence.
std::string printable(std::string t) {
  for (char& c : t)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return shortened(std::move(t), 120);
}

/// Jobs waiting to run: filled up front (rank 0) or as rank 0 hands them out (other ranks).
class JobQueue {
 public:
  void push(const Job& j) {
    {
      std::lock_guard<std::mutex> lk(m_);
      q_.push_back(j);
    }
    cv_.notify_one();
  }
  /// No more jobs will come: waiting workers return.
  void close() {
    {
      std::lock_guard<std::mutex> lk(m_);
      closed_ = true;
    }
    cv_.notify_all();
  }
  /// The next job; waits while the queue is empty and open; nullopt when empty and closed.
  std::optional<Job> pop() {
    std::unique_lock<std::mutex> lk(m_);
    cv_.wait(lk, [this] { return !q_.empty() || closed_; });
    if (q_.empty()) return std::nullopt;
    Job j = q_.front();
    q_.pop_front();
    return j;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<Job> q_;
  bool closed_ = false;
};

/// A pool of `threads` workers taking jobs from a queue; finished results are handed to the
/// calling thread (drain()).
class Pool {
 public:
  Pool(JobQueue& queue, int threads, const RetryPolicy& retry, const PathRunner& runner) {
    for (int t = 0; t < std::max(1, threads); ++t)
      workers_.emplace_back([this, &queue, &retry, &runner] {
        while (const std::optional<Job> j = queue.pop()) {
          JobResult r = run_job(*j, retry, runner);
          {
            std::lock_guard<std::mutex> lk(m_);
            done_.push_back(std::move(r));
          }
          cv_.notify_one();
        }
      });
  }
  ~Pool() {
    for (auto& w : workers_) w.join();
  }
  /// Waits up to `wait` for results; returns those available.
  std::vector<JobResult> drain(std::chrono::milliseconds wait) {
    std::unique_lock<std::mutex> lk(m_);
    cv_.wait_for(lk, wait, [this] { return !done_.empty(); });
    std::vector<JobResult> out(std::make_move_iterator(done_.begin()),
                               std::make_move_iterator(done_.end()));
    done_.clear();
    return out;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<JobResult> done_;
  std::vector<std::thread> workers_;
};

std::string describe(const Job& j, const JobResult& r) {
  char b[256];
  const auto& p = j.load_path;
  switch (p.kind) {
    case material::PathKind::kShear:
      std::snprintf(b, sizeof b, "l=%.2f mm case %2d shear gamma=%.1f deg", j.loop_length, j.path,
                    p.target(0) * 180.0 / 3.14159265358979323846);
      break;
    case material::PathKind::kBiaxial:
      std::snprintf(b, sizeof b, "l=%.2f mm case %2d biaxial E=(%+.3f,%+.3f) %s", j.loop_length,
                    j.path, p.target(0), p.target(1), p.set.c_str());
      break;
    case material::PathKind::kUniaxial:
      std::snprintf(b, sizeof b, "l=%.2f mm case %2d uniaxial %s E=%+.3f %s", j.loop_length, j.path,
                    p.axis == 0 ? "course" : "wale", p.target(0), p.set.c_str());
      break;
    case material::PathKind::kGradient:
      std::snprintf(b, sizeof b, "l=%.2f mm case %2d gradient H=(%+.3f,%+.3f;%+.3f,%+.3f) %s",
                    j.loop_length, j.path, p.H(0, 0), p.H(0, 1), p.H(1, 0), p.H(1, 1),
                    p.set.c_str());
      break;
  }
  char c[160];
  std::snprintf(c, sizeof c, ": %s, %d/%d steps, %d attempt%s, %.2f s", to_string(r.status).c_str(),
                r.converged_steps(), p.steps, r.attempts, r.attempts == 1 ? "" : "s", r.seconds);
  return std::string(b) + c;
}

int default_threads(const MpiSession* mpi) {
  const int hw = std::max(1u, std::thread::hardware_concurrency());
  const int local = mpi ? mpi->local_size() : 1;
  return std::max(1, hw / std::max(1, local));
}

}  // namespace

std::filesystem::path failed_database_path(const std::filesystem::path& output, int n) {
  std::filesystem::path p = output;
  const std::string ext = output.extension().string();
  p.replace_filename(output.stem().string() + ".failed" + (n > 1 ? "-" + std::to_string(n) : "") +
                     ext);
  return p;
}

SweepReport run_sweep(const SweepInput& in, const SweepOptions& opt, const PathRunner& runner,
                      const MpiSession* mpi) {
  // Early check, before any case runs: a fit that cannot succeed with these paths and options
  // (the fit's own refusals, fit::check_feasible) is bad input, not hours of wasted cases.
  if (in.fit)
    if (const std::string why = fit::check_feasible(in.fit_options, in.paths); !why.empty())
      throw InputError(in.file, "/load_paths",
                       "the response-surface fit cannot succeed: " + why +
                           "; nothing was run (add load paths or steps, change \"fit\", or set "
                           "\"fit\": false to run the cases without a fit)");
  const auto t0 = std::chrono::steady_clock::now();
  const int rank = mpi ? mpi->rank() : 0, size = mpi ? mpi->size() : 1;
  const bool root = rank == 0;
  SweepReport rep;
  rep.ranks = size;
  rep.threads = opt.threads > 0 ? opt.threads : default_threads(mpi);
  const std::vector<Job> jobs = make_jobs(in);

  // ---- checkpoints (rank 0), the list of pending jobs (broadcast) ---------------------------
  std::optional<io::OutputLock> lock;  // DB.lock: one sweep per database and checkpoints
  std::unique_ptr<CheckpointStore> store;
  std::map<int, JobResult> finished;
  std::string msg;  // "OK i j k ..." or "ERR <file>\n<message>"
  if (root) {
    try {
      lock.emplace(opt.output);
      store = std::make_unique<CheckpointStore>(
          opt.output, in.job_definition(), static_cast<int>(jobs.size()), opt.resume, opt.force);
      finished = store->load_finished(jobs);
      // Resuming another build's checkpoints: said at the start (session 45), on stderr
      // whatever --no-progress says (a warning, not progress).
      if (const auto& b = store->builds();
          std::find(b.begin(), b.end(), CheckpointStore::this_build()) == b.end()) {
        std::string earlier;
        for (const auto& x : b) earlier += (earlier.empty() ? "" : "; ") + printable(x);
        std::fprintf(stderr,
                     "knit-meso sweep: warning: resuming checkpoints of another build (%s) "
                     "with %s: the database records every build whose cases it holds in "
                     "/sweep/report/case_builds\n",
                     earlier.c_str(), CheckpointStore::this_build().c_str());
      }
      std::ostringstream os;
      os << "OK";
      for (const auto& [i, r] : finished) os << ' ' << i;
      msg = os.str();
    } catch (const InputError& e) {
      msg = "ERR " + e.file() + "\n" + e.message();
    }
  }
  if (mpi) mpi->broadcast(msg);
  if (msg.rfind("ERR ", 0) == 0) {
    const auto nl = msg.find('\n');
    throw InputError(msg.substr(4, nl - 4), "", msg.substr(nl + 1));
  }
  std::vector<bool> done(jobs.size(), false);
  {
    std::istringstream is(msg.substr(2));
    int i = 0;
    while (is >> i) done[static_cast<std::size_t>(i)] = true;
  }
  std::vector<Job> pending;
  for (const Job& j : jobs)
    if (!done[static_cast<std::size_t>(j.index)]) pending.push_back(j);
  rep.resumed = static_cast<int>(jobs.size() - pending.size());
  // No more workers than cases (session 21: --threads 4096 started 4096 threads, 570 MB, for
  // the 7 cases of a small sweep). Every rank caps alike: each asks for one job per thread.
  rep.threads = std::min(rep.threads, std::max(1, static_cast<int>(jobs.size())));
  if (root && opt.log) {
    std::fprintf(opt.log, "knit-meso sweep: %zu loop lengths x %zu load cases = %zu cases -> %s\n",
                 in.loop_lengths.size(), in.paths.size(), jobs.size(), opt.output.c_str());
    if (opt.resume)
      std::fprintf(opt.log, "resume: %d of %zu cases already finished, %zu to run\n", rep.resumed,
                   jobs.size(), pending.size());
    std::fprintf(opt.log, "workers: %d rank%s x %d thread%s\n", size, size == 1 ? "" : "s",
                 rep.threads, rep.threads == 1 ? "" : "s");
    std::fflush(opt.log);
  }

  // ---- run -----------------------------------------------------------------------------------
  // Rank 0 (and a serial run): every pending job is queued here; its own threads take them in
  // order and the other ranks ask for them one by one. Other ranks: a local queue fed by rank 0.
  const bool distributed = mpi && size > 1;
  {
    Progress progress(static_cast<int>(pending.size()), rep.resumed, root ? opt.progress : nullptr,
                      opt.tty);
    JobQueue queue;  // rank 0: all pending jobs; others: the jobs rank 0 handed out
    if (root) {
      for (const Job& j : pending) queue.push(j);
      queue.close();
    }
    if (root) {
      int received = 0, retired = 0;
      const int expect = static_cast<int>(pending.size());
      // The root queue is shared with the other ranks: a request takes the next job from it.
      // (pop() on a closed queue never waits.)
      auto hand_out = [&](int dest) {
        const std::optional<Job> j = queue.pop();
        mpi->send(dest, MpiSession::kJob, std::to_string(j ? j->index : -1));
      };
      auto accept = [&](JobResult r) {
        store->store(r);
        progress.finished(describe(jobs[static_cast<std::size_t>(r.index)], r));
        finished[r.index] = std::move(r);
        ++received;
      };
      Pool pool(queue, rep.threads, in.retry, runner);
      while (received < expect || (distributed && retired < size - 1)) {
        for (JobResult& r : pool.drain(std::chrono::milliseconds(distributed ? 5 : 20))) {
          accept(std::move(r));
        }
        if (distributed) {
          std::string m;
          int src = 0;
          while (mpi->try_receive(MpiSession::kRequest, src, m)) hand_out(src);
          while (mpi->try_receive(MpiSession::kResult, src, m)) {
            accept(deserialize(m));
            hand_out(src);  // a result asks for the next job
          }
          while (mpi->try_receive(MpiSession::kDone, src, m)) ++retired;
        }
        progress.tick();
      }
      rep.computed = expect;
    } else {
      // Ask for one job per thread; each result asks for one more; -1 answers a request with
      // nothing left. Done when no request is outstanding and every job given here finished.
      for (int t = 0; t < rep.threads; ++t) mpi->send(0, MpiSession::kRequest, "");
      int outstanding = rep.threads, given = 0, finished_here = 0;
      Pool pool(queue, rep.threads, in.retry, runner);
      while (outstanding > 0 || finished_here < given) {
        std::string m;
        int src = 0;
        while (mpi->try_receive(MpiSession::kJob, src, m)) {
          --outstanding;
          const int idx = std::stoi(m);
          if (idx >= 0) {
            queue.push(jobs[static_cast<std::size_t>(idx)]);
            ++given;
          }
        }
        for (JobResult& r : pool.drain(std::chrono::milliseconds(5))) {
          ++finished_here;
          mpi->send(0, MpiSession::kResult, serialize(r));
          ++outstanding;
        }
      }
      queue.close();
      rep.computed = finished_here;
      mpi->send(0, MpiSession::kDone, "");
    }
    progress.done();
  }
  rep.seconds_cases = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!root) return rep;

  // ---- assemble, fit, write (rank 0) -----------------------------------------------------
  for (const Job& j : jobs) rep.results.push_back(finished.at(j.index));
  // Nothing converged (every loop length too short for the cell's geometry, say): a database
  // without a single state would replace whatever the output holds. Leave it as it was.
  if (std::none_of(rep.results.begin(), rep.results.end(),
                   [](const JobResult& r) { return r.converged_steps() > 0; })) {
    // (session 44's red team: "left as it was" of an output that did not exist; fit's wording)
    rep.not_written = "no case converged a single step; " + opt.output.string() +
                      io::unwritten_output_state(opt.output);
    rep.seconds_total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!opt.keep_parts) store->remove();
    return rep;
  }
  material::Database db = assemble_database(in, rep.results);
  const auto tf = std::chrono::steady_clock::now();
  if (in.fit) rep.fits = fit_sweep_database(db, in.fit_options, rep.threads);
  if (in.fit && in.energy_fit) {
    fit::EnergyFitOptions eo = in.energy_fit_options;
    eo.threads = rep.threads;  // the cases' threads are idle by now
    eo.progress = opt.progress;
    rep.energy_fit = fit::fit_energy_database(db, eo);
  }
  rep.seconds_fit = std::chrono::duration<double>(std::chrono::steady_clock::now() - tf).count();
  rep.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // A sweep that fails (a paper path that did not complete, a fit that could not be made) does
  // not replace a database already at the output: its own goes beside it, with its cases'
  // status and messages for the diagnosis (fit's policy is the same: a failed fit writes
  // nothing over its output).
  rep.written = opt.output;
  // DB.failed.h5 is locked as every output is (session 44's red team: a `knit-meso fit
  // DB.failed.h5` running, which holds DB.failed.h5.lock, renamed its refit over the one this
  // wrote, and the failed sweep's database was lost): a name held by another process, or
  // holding what is not a database, passes to the next, DB.failed-2.h5, ...; with none free
  // nothing is written, and the cases stay in the checkpoints, said so. Only DB.failed.h5, the
  // documented name, may be replaced; DB.failed-2.h5 ... are taken only where nothing is
  // (the review of session 44: a user's database there was overwritten).
  std::optional<io::OutputLock> failed_lock;
  std::error_code ec;
  if (!rep.ok() && std::filesystem::exists(opt.output, ec)) {
    std::string first_refusal;
    for (int n = 1; n <= kFailedDatabaseNames && !failed_lock; ++n) {
      const std::filesystem::path name = failed_database_path(opt.output, n);
      std::error_code there;
      if (n > 1 &&
          (std::filesystem::exists(name, there) || std::filesystem::is_symlink(name, there))) {
        if (first_refusal.empty()) first_refusal = name.string() + " exists";
        continue;
      }
      try {
        io::OutputLock l(name);
        io::check_output_target(name, io::OutputKind::kFile, "--output",
                                material::kDatabaseFormatName);
        failed_lock.emplace(std::move(l));
        rep.written = name;
      } catch (const InputError& e) {
        if (first_refusal.empty()) first_refusal = e.what();
      }
    }
    if (!failed_lock) {
      rep.not_written =
          "the sweep failed, so " + opt.output.string() +
          " (an earlier database) is left as it was, and this sweep's database could not be "
          "kept beside it: " +
          first_refusal + " (nor " + failed_database_path(opt.output, 2).filename().string() +
          " .. " + failed_database_path(opt.output, kFailedDatabaseNames).filename().string() +
          "); its cases are kept in " + store->dir().string() +
          ": run the sweep again with --resume once one of those is free";
      return rep;  // the checkpoints stay (not marked written)
    }
  }
  rep.case_builds = store->builds();  // with this build once it stored a case
  write_sweep_database(rep.written, db, in, rep.results, rep);
  rep.wrote_database = true;
  if (opt.on_written) opt.on_written(rep.written);
  // (--keep-parts: kept on purpose, so not marked: a later sweep without --resume refuses them)
  if (!opt.keep_parts) {
    store->mark_written();
    store->remove();
  }
  return rep;
}

}  // namespace knit::meso::sweep
