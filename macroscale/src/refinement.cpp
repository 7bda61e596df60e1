// The case's refinement block delegates to the spline kernel's k-refinement
// (knit/spline/refine.hpp: degree elevation A5.9, then knot insertion A5.4).
#include "knit/macro/refinement.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "knit/core/errors.hpp"
#include "knit/spline/refine.hpp"

namespace knit::macro {

spline::SplineSurface refine_patch(const spline::SplineSurface& s, int p, int eu, int ev) {
  if (p < s.basis_u().degree() || p < s.basis_v().degree())
    throw std::invalid_argument("the refinement degree " + std::to_string(p) +
                                " is below the patch's degree");
  if (eu < 1 || ev < 1) throw std::invalid_argument("the number of elements must be at least 1");
  return spline::refine(s, p, eu, ev);
}

namespace {
/// Number of non-empty knot spans.
std::uint64_t num_spans(const std::vector<double>& U) {
  std::uint64_t n = 0;
  for (std::size_t i = 1; i < U.size(); ++i) n += U[i] > U[i - 1];
  return n;
}

/// The global system of N unknowns: a dense matrix (two copies, the factor's too) up to
/// kDenseUnknowns, else 3 copies of 16 bytes per entry of the sparse pattern (bounded by N^2).
constexpr double kDenseUnknowns = 2500;
double dense_system_bytes(double N) {
  return 2.0 * N * N * 8.0;
}
double sparse_system_bytes(double N, double pu, double pv) {
  return 3.0 * 16.0 * std::min(N * 3.0 * (2 * pu + 1) * (2 * pv + 1), N * N);
}

}  // namespace

std::string format_bytes(std::uint64_t b) {
  char buf[32];
  const double gb = static_cast<double>(b) / 1e9;
  if (gb >= 1.0)
    std::snprintf(buf, sizeof buf, gb >= 10 ? "%.0f GB" : "%.1f GB", gb);
  else
    std::snprintf(buf, sizeof buf, "%.0f MB", static_cast<double>(b) / 1e6);
  return buf;
}

std::string MemoryEstimate::describe() const {
  return format_bytes(total()) + " (quadrature data " + format_bytes(quadrature) +
         ", element tangents " + format_bytes(element_tangents) + ", global system " +
         format_bytes(global_system) + ")";
}

MemoryEstimate estimate_shell_memory(double pu, double pv, double spans, double size_u,
                                     double size_v, int extra) {
  // Doubles throughout: the counts reach 1e11 for the largest schema-legal refinement.
  const double nloc = (pu + 1) * (pv + 1), q = (pu + 1 + extra) * (pv + 1 + extra);
  const double N = 3.0 * size_u * size_v;
  MemoryEstimate m;
  m.quadrature = static_cast<std::uint64_t>(spans * q * (11.0 * nloc * 8.0 + 256.0));
  // The element tangents go straight into the reduced matrix (ReducedTangent as the model's
  // ElementTangentSink): one buffer per assembly thread, counted for two (session 37: all E
  // were counted, 6.1 GB of a 256 x 256 patch of degree 5 that the run never holds, so the
  // estimate stood 1.5-2 x above the measured peak and refused runs that fit).
  m.element_tangents = static_cast<std::uint64_t>(2.0 * 9.0 * nloc * nloc * 8.0);
  m.global_system = static_cast<std::uint64_t>(
      N <= kDenseUnknowns ? dense_system_bytes(N) : sparse_system_bytes(N, pu, pv));
  return m;
}

MemoryEstimate estimate_shell_memory(const spline::SplineSurface& s, int extra) {
  return estimate_shell_memory(s.basis_u().degree(), s.basis_v().degree(),
                               static_cast<double>(num_spans(s.basis_u().knots())) *
                                   static_cast<double>(num_spans(s.basis_v().knots())),
                               static_cast<double>(s.size_u()), static_cast<double>(s.size_v()),
                               extra);
}

MemoryEstimate estimate_refinement_memory(int p, int elements_u, int elements_v) {
  MemoryEstimate m = estimate_shell_memory(p, p, static_cast<double>(elements_u) * elements_v,
                                           static_cast<double>(elements_u) + p,
                                           static_cast<double>(elements_v) + p);
  // The global system's term is not monotone in N: dense up to N = 2500 unknowns, sparse
  // beyond, and the sparse figure can be the smaller (the review of session 49: 25 x 25
  // elements of degree 3 on a patch with interior knots were refused by a dense bound of 105
  // MB where the refined patch's estimate is 41 MB). The smaller of the two formulas at the
  // bound's N is a lower bound in either regime.
  const double N = 3.0 * (elements_u + static_cast<double>(p)) * (elements_v + p);
  m.global_system =
      static_cast<std::uint64_t>(std::min(dense_system_bytes(N), sparse_system_bytes(N, p, p)));
  return m;
}

std::uint64_t memory_limit_bytes() {
  if (const char* env = std::getenv("KNIT_MAX_MEMORY_MB")) {
    // A value that is set but not understood is an error, not the machine's memory in silence
    // (session 24: "4G", "-1" and "1e308" were ignored; above 2^44 MiB the shift wrapped).
    constexpr unsigned long long kMaxMb = 1ull << 40;
    const std::string text(env);
    errno = 0;
    const unsigned long long mb = std::strtoull(env, nullptr, 10);
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
        errno == ERANGE || mb < 1 || mb > kMaxMb)
      throw InputError("KNIT_MAX_MEMORY_MB", "",
                       "the environment variable must be a whole number of MiB in [1, " +
                           std::to_string(kMaxMb) + "], got \"" + text + "\"");
    return static_cast<std::uint64_t>(mb) << 20;
  }
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return ~std::uint64_t{0};
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
}

}  // namespace knit::macro
