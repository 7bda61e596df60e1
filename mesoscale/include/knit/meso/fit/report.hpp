// Small helpers of the fit subcommands: fit summaries as text, reading an options file.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "knit/meso/fit/energy_fit.hpp"
#include "knit/meso/fit/response_fit.hpp"

namespace knit::meso::fit {

/// One line per loop length: max / rms stress errors or the refusal reason.
void print_fit_summaries(std::ostream& os, const material::Database& db,
                         const std::vector<FitSummary>& fits);

/// "the paper law at l = L mm: REASON" of the first loop length whose fit failed; "" if none
/// (the stderr line of knit-meso fit and synth, which then write nothing).
std::string first_fit_failure(const material::Database& db, const std::vector<FitSummary>& fits);

/// A fit of the paper's law that succeeded but misses its own data by more than this fraction
/// of the stress range is told as a warning (the default fits: 0.3-0.4 %; session 54's red
/// team: smoothing 1000 missed by 62 % and was printed "ok", exit 0, nothing on stderr). The
/// energy law's is kEnergyFitWarnRelative, the same 10 %.
inline constexpr double kPaperFitWarnRelative = 0.10;

/// "warning: the paper law's surfaces miss their data by up to X % ..." for the loop length
/// (of `loop_lengths`, the fits' order) with the largest error above kPaperFitWarnRelative
/// among the fits that succeeded; "" if none.
std::string paper_fit_warning(const std::vector<double>& loop_lengths,
                              const std::vector<FitSummary>& fits);

/// Before any fit of knit-meso fit and synth: throws knit::InputError naming an options file
/// the user gave (`fo_file`, `eo_file`; "" for options not from a file, which are not judged)
/// when its options cannot fit db's load paths (check_feasible) or make a ridge law too large
/// to solve (ridge_size_refusal): what the sweep refuses before its cases. Session 54's red
/// team: fit named the database ("energy law refused", exit 2; "(/loop_0)", exit 1) and synth
/// neither file nor key.
void refuse_unfittable_options(const material::Database& db, const FitOptions& fo,
                               const std::string& fo_file, const EnergyFitOptions& eo,
                               const std::string& eo_file);

/// Fits the paper's law (eq. 17) of every loop length from the raw paths of the "paper" set
/// only (the coverage and held-out paths are the energy law's), and stores it in db.
std::vector<FitSummary> fit_paper_law(material::Database& db, const FitOptions& options);

/// The whole file as text (knit::io::read_input_file: a regular file of at most 64 MiB); throws
/// knit::InputError if it cannot be read, naming the command-line option that gave the file
/// first when there is one ("--energy-options: /x.json: file not found").
std::string read_text_file(const std::string& file, const std::string& option = {});

}  // namespace knit::meso::fit
