#include <algorithm>

#include "knit/core/errors.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/input_file.hpp"
#include "knit/meso/fit/report.hpp"

namespace knit::meso::fit {

std::string paper_fit_warning(const std::vector<double>& loop_lengths,
                              const std::vector<FitSummary>& fits) {
  std::size_t worst = fits.size();
  for (std::size_t k = 0; k < fits.size() && k < loop_lengths.size(); ++k)
    if (fits[k].ok() && fits[k].diagnostics.max_relative > kPaperFitWarnRelative &&
        (worst == fits.size() ||
         fits[k].diagnostics.max_relative > fits[worst].diagnostics.max_relative))
      worst = k;
  if (worst == fits.size()) return {};
  return "warning: the paper law's surfaces miss their fit data by up to " +
         io::format_number(100 * fits[worst].diagnostics.max_relative) +
         " % of the stress range (at l = " + io::format_number(loop_lengths[worst]) +
         " mm; more than " + io::format_number(100 * kPaperFitWarnRelative) +
         " %): their fit options do not suit these data (the code's defaults give 0.3-0.4 %; "
         "look at smoothing, the control points and the loss)";
}

void refuse_unfittable_options(const material::Database& db, const FitOptions& fo,
                               const std::string& fo_file, const EnergyFitOptions& eo,
                               const std::string& eo_file) {
  if (db.entries.empty()) return;  // the fits say so themselves
  if (!fo_file.empty()) {
    std::vector<material::LoadPath> paths;
    for (const auto& r : db.entries.front().raw) paths.push_back(r.path);
    // Only when the code's defaults could fit these paths: otherwise the database's paths
    // are the cause, which the fit names (exit 1), not the file (the review of session 54).
    if (const std::string why = check_feasible(fo, paths);
        !why.empty() && check_feasible(FitOptions{}, paths).empty())
      throw InputError(
          fo_file, "",
          "these options cannot fit the paper law to the database's load paths: " + why);
  }
  if (!eo_file.empty())
    if (const std::string why = eo.ridge_size_refusal(static_cast<int>(db.entries.size()));
        !why.empty())
      throw InputError(eo_file, eo.ridge_size_key(static_cast<int>(db.entries.size())), why);
}

std::string first_fit_failure(const material::Database& db, const std::vector<FitSummary>& fits) {
  for (std::size_t k = 0; k < fits.size() && k < db.entries.size(); ++k)
    if (!fits[k].ok())
      return "the paper law at l = " + io::format_number(db.entries[k].loop_length) +
             " mm (/loop_" + std::to_string(k) + "): " + fits[k].reason;
  return {};
}

void print_fit_summaries(std::ostream& os, const material::Database& db,
                         const std::vector<FitSummary>& fits) {
  for (std::size_t k = 0; k < fits.size(); ++k) {
    const auto& f = fits[k];
    os << "  l = " << db.entries[k].loop_length << " mm: ";
    if (!f.ok()) {
      os << "REFUSED: " << f.reason << "\n";
      continue;
    }
    const auto& d = f.diagnostics;
    os << "max |S error| S1 " << d.max(2) << ", S2 " << d.max(3) << ", S12 " << d.max(4) << " MPa ("
       << 100 * d.max_relative << " % of the stress range); rms S1 " << d.rms(2) << ", S2 "
       << d.rms(3) << ", S12 " << d.rms(4) << " MPa\n";
  }
}

std::vector<FitSummary> fit_paper_law(material::Database& db, const FitOptions& options) {
  material::Database paper = db;
  for (auto& e : paper.entries)
    e.raw.erase(std::remove_if(e.raw.begin(), e.raw.end(),
                               [](const material::RawPath& r) { return r.path.set != "paper"; }),
                e.raw.end());
  const auto fits = fit_database(paper, options);
  for (std::size_t k = 0; k < db.entries.size(); ++k) {
    db.entries[k].surface = paper.entries[k].surface;
    db.entries[k].diagnostics = paper.entries[k].diagnostics;
  }
  return fits;
}

std::string read_text_file(const std::string& file, const std::string& option) {
  // The defensive reader of every other input (session 24: an ifstream here read /dev/zero
  // until memory ran out and blocked for ever on a FIFO).
  try {
    return knit::io::read_input_file(file);
  } catch (const InputError& e) {
    // (session 44's red team: "/nonexist.json: file not found" did not say which option)
    if (option.empty()) throw;
    throw InputError("", option, file + ": " + e.message());
  }
}

}  // namespace knit::meso::fit
