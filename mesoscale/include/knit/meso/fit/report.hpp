// Small helpers of the fit subcommands: fit summaries as text, reading an options file.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "knit/meso/fit/response_fit.hpp"

namespace knit::meso::fit {

/// One line per loop length: max / rms stress errors or the refusal reason.
void print_fit_summaries(std::ostream& os, const material::Database& db,
                         const std::vector<FitSummary>& fits);

/// The whole file as text; throws knit::InputError if it cannot be opened.
std::string read_text_file(const std::string& file);

}  // namespace knit::meso::fit
