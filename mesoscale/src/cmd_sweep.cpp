// knit-meso sweep SWEEP.json [--output DB.h5] [--resume | --force] [--threads N] [--keep-parts]
//                [--no-progress] [--plain] [--max-output-size SIZE]
//   The mesoscale database sweep (issue #7; paper Sect. 2.1.2, 3.1.1): every loop length x
//   load case of SWEEP.json on the unit cell (one case per worker thread; across machines with
//   `mpirun -np N knit-meso sweep ...`), then the response-surface fit, written as the material
//   database. Killed at any moment, it continues with --resume (DB.h5.parts holds the finished
//   cases). Prints the time per case and the total; cases that did not converge are listed at
//   the end (exit code 1). Bad input: exit code 2.
// Examples:
//   knit-meso sweep cases/sweep/default.json --output db.h5
//   knit-meso sweep cases/sweep/reduced.json --output reduced.h5 --threads 2
//   mpirun -np 4 knit-meso sweep cases/sweep/default.json --output db.h5
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/output_target.hpp"
#include "knit/material/database.hpp"
#include "knit/meso/cell/geometry.hpp"
#include "knit/meso/fit/report.hpp"
#include "knit/meso/sweep/sweep.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::meso::cmd_sweep {
namespace {

struct Cli {
  std::string input, output = "database.h5";
  bool resume = false, force = false, keep_parts = false, no_progress = false, plain = false;
  int threads = 0;
  std::string max_output_size;  ///< --max-output-size ("" = the default cap)
};

void print_summary(const knit::meso::sweep::SweepInput& in,
                   const knit::meso::sweep::SweepReport& rep, const std::string& output) {
  using namespace knit::meso::sweep;
  const auto jobs = make_jobs(in);
  std::printf("\ntime per case (s), rows: loop length, columns: load case\n   l [mm]");
  for (std::size_t p = 0; p < in.paths.size(); ++p) std::printf(" %6zu", p);
  std::printf("\n");
  double sum = 0;
  for (std::size_t l = 0; l < in.loop_lengths.size(); ++l) {
    std::printf("   %6.2f", in.loop_lengths[l]);
    for (std::size_t p = 0; p < in.paths.size(); ++p) {
      const auto& r = rep.results[l * in.paths.size() + p];
      std::printf(" %6.2f", r.seconds);
      sum += r.seconds;
    }
    std::printf("\n");
  }
  const double n = static_cast<double>(rep.results.size());
  std::printf(
      "cases: %zu (%d computed now, %d from checkpoints); mean %.3f s/case (CPU-busy sum "
      "%.1f s)\n",
      rep.results.size(), rep.computed, rep.resumed, n > 0 ? sum / n : 0.0, sum);
  for (std::size_t k = 0; k < rep.fits.size(); ++k) {
    const auto& f = rep.fits[k];
    if (f.ok())
      std::printf(
          "fit l=%.2f mm: %s, max |dS| %.4g MPa (%.2f%% of the range), %d points used, "
          "%d skipped\n",
          in.loop_lengths[k],
          f.diagnostics.max_relative > knit::meso::fit::kPaperFitWarnRelative ? "POOR" : "ok",
          f.diagnostics.max.tail<3>().maxCoeff(), 100 * f.diagnostics.max_relative,
          f.diagnostics.points_used, f.diagnostics.points_skipped);
    else
      std::printf("fit l=%.2f mm: NOT FITTED: %s\n", in.loop_lengths[k], f.reason.c_str());
  }
  if (const std::string w = knit::meso::fit::paper_fit_warning(in.loop_lengths, rep.fits);
      !w.empty())
    std::fprintf(stderr, "knit-meso sweep: %s\n", w.c_str());
  if (rep.energy_fit) {
    std::printf("%s", knit::meso::fit::energy_fit_report(*rep.energy_fit).c_str());
    if (const std::string w = knit::meso::fit::energy_fit_warning(*rep.energy_fit); !w.empty())
      std::fprintf(stderr, "knit-meso sweep: %s\n", w.c_str());
    // Session 39's walkthrough: a sweep input without "energy_fit" got the code's defaults
    // (no tube, no outer function, 4,000 iterations: 12 % of the range at 5.0 mm) without a word.
    if (!in.energy_fit_given)
      std::printf(
          "note: the sweep input has no \"energy_fit\", so the energy law was fitted with the "
          "code's defaults (docs/database.md, \"Options and defaults\"); the default sweep's "
          "options (cases/sweep/default.json, /energy_fit: a tube of 4.5 %% of the range, the "
          "exponential outer function, 20,000 iterations) hold its fit within 5 %% of the "
          "range; `knit-meso fit DB --law energy --energy-options FILE` refits without a new "
          "sweep\n");
  }
  std::printf("time: cases %.2f s, fit %.2f s, total %.2f s (%d rank%s x %d thread%s)\n",
              rep.seconds_cases, rep.seconds_fit, rep.seconds_total, rep.ranks,
              rep.ranks == 1 ? "" : "s", rep.threads, rep.threads == 1 ? "" : "s");
  // Convergence per path kind and set (issue 11): completed paths / all, converged steps / all.
  {
    std::map<std::string, std::array<int, 4>> by;
    for (const auto& r : rep.results) {
      auto& c = by[knit::material::to_string(r.raw.path.kind) + " (" + r.raw.path.set + ")"];
      c[0] += r.status == JobStatus::kConverged ? 1 : 0;
      c[1] += 1;
      c[2] += r.converged_steps();
      c[3] += r.raw.path.steps;
    }
    for (const auto& [name, c] : by)
      std::printf("paths %-22s %3d/%3d completed, steps %5d/%5d converged\n", name.c_str(), c[0],
                  c[1], c[2], c[3]);
  }
  const int failed = rep.failed_cases(), stopped = rep.stopped_cases();
  if (failed + stopped > 0) {
    std::printf(
        "%d case%s did not converge (kept in the database with their status; %d of them "
        "coverage/holdout paths that stopped early, which does not fail the sweep):\n",
        failed + stopped, failed + stopped == 1 ? "" : "s", stopped);
    for (std::size_t i = 0; i < rep.results.size(); ++i) {
      const auto& r = rep.results[i];
      if (r.status == JobStatus::kConverged) continue;
      std::printf("  l=%.2f mm case %d (%s, %s): %s, %d/%d steps after %d attempts: %s\n",
                  jobs[i].loop_length, jobs[i].path,
                  knit::material::to_string(jobs[i].load_path.kind).c_str(),
                  jobs[i].load_path.set.c_str(), to_string(r.status).c_str(), r.converged_steps(),
                  jobs[i].load_path.steps, r.attempts, r.message.c_str());
    }
  }
  if (rep.wrote_database && rep.written != std::filesystem::path(output))
    std::printf(
        "database NOT replaced: the sweep failed, so %s (an earlier database) is kept as it was; "
        "this sweep's database, with every case's status and message, is %s\n",
        output.c_str(), rep.written.c_str());
  else if (rep.wrote_database)
    std::printf("wrote %s\n", output.c_str());
  else
    std::printf("database NOT written: %s\n", rep.not_written.c_str());
  std::fflush(stdout);
}

/// The one line a failing sweep writes on stderr: why it failed and what became of the output
/// (session 44's red team: with --no-progress stderr was empty, only stdout's summary said why;
/// knit-meso fit does the same since session 36).
std::string failure_line(const knit::meso::sweep::SweepInput& in,
                         const knit::meso::sweep::SweepReport& rep, const std::string& output) {
  using namespace knit::meso::sweep;
  std::string why;
  if (!rep.not_written.empty())
    return "knit-meso sweep: error: database not written: " + rep.not_written +
           " (the sweep's report is on stdout)";
  if (const int failed = rep.failed_cases(); failed > 0) {
    const auto jobs = make_jobs(in);
    for (std::size_t i = 0; i < rep.results.size() && why.empty(); ++i)
      if (fails_sweep(rep.results[i]))
        why = std::to_string(failed) + (failed == 1 ? " case" : " cases") +
              " did not converge; the first: l = " + knit::io::format_number(jobs[i].loop_length) +
              " mm case " + std::to_string(jobs[i].path) + " (" +
              knit::material::to_string(jobs[i].load_path.kind) + ", " + jobs[i].load_path.set +
              "): " + to_string(rep.results[i].status) + ": " + rep.results[i].message;
  }
  for (std::size_t k = 0; k < rep.fits.size() && why.empty(); ++k)
    if (!rep.fits[k].ok())
      why = "the paper law at l = " + knit::io::format_number(in.loop_lengths[k]) + " mm (/loop_" +
            std::to_string(k) + "): " + rep.fits[k].reason;
  if (why.empty() && rep.energy_fit && !rep.energy_fit->ok())
    why = "the energy law: " + rep.energy_fit->reason;
  if (why.empty()) why = "the sweep failed";
  std::string what;
  if (rep.wrote_database && rep.written != std::filesystem::path(output))
    what = output +
           " is left as it was; this sweep's database, with every case's status and "
           "message, is " +
           rep.written.string();
  else if (rep.wrote_database)
    what = "wrote " + output +
           " (no database was there) with every case's status and message, for the diagnosis";
  else
    what = "no database was written";
  return "knit-meso sweep: error: " + why + "; " + what + " (the sweep's report is on stdout)";
}

/// The command that resumes this sweep, for pasting into a shell: every option that shapes the
/// run again (the review of session 44: --max-output-size dropped made the command refuse the
/// very sweep that needed it, --keep-parts dropped removed the checkpoints asked to be kept),
/// each argument quoted (knit::cli::shell_quote), and a path that begins with '-' given as
/// ./-path (CLI11 would read it as an option).
std::string resume_command(const Cli& c) {
  auto arg = [](const std::string& a) {
    const bool dash = !a.empty() && a.front() == '-';
    return knit::cli::shell_quote(dash ? "./" + a : a);
  };
  std::string cmd = "knit-meso sweep " + arg(c.input) + " --output " + arg(c.output) + " --resume";
  if (c.threads > 0) cmd += " --threads " + std::to_string(c.threads);
  if (!c.max_output_size.empty())
    cmd += " --max-output-size " + knit::cli::shell_quote(c.max_output_size);
  if (c.keep_parts) cmd += " --keep-parts";
  if (c.no_progress) cmd += " --no-progress";
  if (c.plain) cmd += " --plain";
  return cmd;
}

// Ctrl-C (SIGINT), and SIGTERM and SIGHUP (a job scheduler's stop, a closed terminal; session
// 22), say what is kept and how to go on, then end the process as the signal would (session
// 21: it printed nothing). knit::cli::on_interrupt_say holds the async-signal-safe handler.
void explain_interrupt(const Cli& c) {
  knit::cli::on_interrupt_say(
      "knit-meso sweep: interrupted; the cases finished so far are kept "
      "in " +
      c.output + ".parts: continue with `" + resume_command(c) + "`");
}

int run(const Cli& c) {
  using namespace knit::meso::sweep;
  MpiSession mpi;
  // The output's missing parent directories are made by its lock (rank 0, io::OutputLock),
  // which removes them again if they are still empty when the sweep ends without a database in
  // them (session 44's red team: a failed `sweep -o a/b/db.h5` left a/b behind; since session
  // 45 the lock does it for every command, and only for the directories its mkdir made).
  try {
    const SweepInput in = load_sweep_input(c.input);
    // Session 48's walkthrough: cell and path warn of a loop length outside the published
    // cells (there the cell stiffens as the loops lengthen: S22 at E = 0.05 is 250 x larger
    // at 12 mm than at 6.5 mm), while a sweep of 12 mm wrote its database without a word.
    if (mpi.rank() == 0 && in.runner == RunnerKind::kCell)
      for (const double l : in.loop_lengths)
        if (const std::string w = knit::meso::cell::loop_length_range_warning(l); !w.empty())
          std::fprintf(stderr, "knit-meso sweep: %s (%s: /loop_lengths)\n", w.c_str(),
                       c.input.c_str());
    // The database and checkpoints' size, before any work (session 44's red team: 101,300
    // cases of up to 10,000 steps were accepted, about 240 GB; path and rod have the cap).
    check_output_size(in, c.max_output_size.empty()
                              ? kDefaultMaxOutputBytes
                              : knit::io::parse_size(c.max_output_size, "--max-output-size"));
    if (c.resume && c.force)
      throw knit::InputError("", "--force", "cannot be combined with --resume");
    if (c.threads < 0) throw knit::InputError("", "--threads", "must be >= 0");
    // Before any case runs (the lock is taken by run_sweep, on rank 0).
    knit::io::check_output_target(c.output, knit::io::OutputKind::kFile, "--output",
                                  knit::material::kDatabaseFormatName);
    if (in.runner == RunnerKind::kSynthetic)
      knit::material::refuse_replacing_swept_database(c.output, "--output, runner \"synthetic\"");
    SweepOptions o;
    o.output = c.output;
    o.resume = c.resume;
    o.force = c.force;
    o.keep_parts = c.keep_parts;
    o.threads = c.threads;
    o.progress = c.no_progress ? nullptr : stderr;
    o.tty = c.plain ? 0 : -1;
    o.log = mpi.rank() == 0 ? stdout : nullptr;
    const PathRunner runner = make_runner(in);
    if (mpi.rank() == 0) {
      explain_interrupt(c);
      // From here on the database is complete (session 36's red team: a stop while the
      // checkpoints were removed advised --resume, which then refused what was left).
      o.on_written = [&c](const std::filesystem::path& written) {
        // (a failing sweep's is DB.failed.h5, beside the earlier database it kept)
        knit::cli::on_interrupt_say(
            "knit-meso sweep: interrupted after the database was "
            "written: " +
            written.string() + " is complete; what is left of its checkpoints in " + c.output +
            ".parts is no longer needed");
      };
    }
    const SweepReport rep = run_sweep(in, o, runner, &mpi);
    if (mpi.rank() != 0) return knit::kExitOk;
    print_summary(in, rep, c.output);
    if (rep.ok()) return knit::kExitOk;
    std::fprintf(stderr, "%s\n", failure_line(in, rep, c.output).c_str());
    return knit::kExitFailure;
  } catch (const knit::InputError&) {
    throw;  // every rank reads the same input and fails the same way
  } catch (const std::exception& e) {
    if (mpi.active() && mpi.size() > 1) {
      std::fprintf(stderr, "knit-meso sweep (rank %d): %s\n", mpi.rank(), e.what());
      mpi.abort(knit::kExitFailure);
    }
    // Cases already finished (a full file system at the database write, say) are not lost:
    // say where they are and how to go on (session 22).
    std::error_code ec;
    if (std::filesystem::is_directory(c.output + ".parts", ec))
      throw std::runtime_error(std::string(e.what()) + "; the cases finished so far are kept in " +
                               c.output + ".parts: continue with `" + resume_command(c) +
                               "` once the cause is fixed");
    throw;
  }
}

knit::cli::SubcommandRegistrar reg(
    "sweep",
    "Mesoscale database sweep: loop lengths x load cases on the unit cell, fit, database "
    "(resumable; MPI under mpirun)",
    [](CLI::App& sub) {
      auto c = std::make_shared<Cli>();
      sub.add_option("input", c->input, "sweep input (JSON, schemas/sweep.schema.json)")
          ->required();
      sub.add_option("-o,--output,--out", c->output,
                     "material database to write (default database.h5)");
      sub.add_flag("--resume", c->resume, "continue an interrupted sweep from OUTPUT.parts");
      sub.add_flag("--force", c->force, "discard checkpoints of an unfinished earlier sweep");
      sub.add_option("--threads", c->threads, "worker threads per rank (default: all cores)")
          ->check(knit::cli::integer(0, 4096));
      sub.add_flag("--keep-parts", c->keep_parts, "keep OUTPUT.parts after writing the database");
      sub.add_flag("--no-progress", c->no_progress, "no progress output");
      sub.add_flag("--plain", c->plain, "plain progress lines even on a terminal");
      sub.add_option("--max-output-size", c->max_output_size,
                     "refuse the sweep before any case runs if its database and checkpoints are "
                     "estimated above this size (default 2GB; e.g. 500MB, 10GB; 0 = no cap)");
      return [c]() { return run(*c); };
    });

}  // namespace
}  // namespace knit::meso::cmd_sweep
