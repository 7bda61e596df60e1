// Knot vectors: validation with specific errors and the knot-span search.
//
// References: L. Piegl & W. Tiller, The NURBS Book, 2nd ed. (1997), Sect. 2.2 and
// Algorithm A2.1 (FindSpan), p. 68.
//
// Conventions used throughout knit::spline
//   p        polynomial degree (p >= 0)
//   U        knot vector, size m + 1 = n + p + 1 where n is the number of basis functions
//   n        number of basis functions (= number of control points)
//   span     index i with U[i] <= u < U[i+1] and p <= i <= n - 1 (clamped at the last knot)
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace knit::spline {

/// Why a knot vector was rejected. Each reason has its own code so that callers (and tests)
/// can tell them apart, and its own message that says what to fix.
enum class KnotError {
  kNegativeDegree,       ///< p < 0
  kNotFinite,            ///< a knot is NaN or infinite
  kTooFewKnots,          ///< fewer than 2(p+1) knots: not even one non-empty span of degree p
  kDecreasing,           ///< U[i] > U[i+1]
  kMultiplicityTooHigh,  ///< a knot value repeated more than p+1 times (an interior multiplicity of
                         ///< exactly p+1 is allowed: a C^{-1} break, used by graded design fields)
  kNotClamped,   ///< the first or last p+1 knots are not equal (required for open/clamped splines)
  kEmptyDomain,  ///< U[p] == U[n]: the parametric domain has zero length
  kCountMismatch,  ///< U.size() != n + p + 1 for the given number of control points
  kDegreeTooHigh,  ///< p > kMaxDegree, the largest degree of the allocation-free kernels
};

class KnotVectorError : public std::invalid_argument {
 public:
  KnotVectorError(KnotError code, const std::string& what)
      : std::invalid_argument(what), code_(code) {}
  KnotError code() const { return code_; }

 private:
  KnotError code_;
};

/// Validates U for degree p. If n_ctrl >= 0 also checks U.size() == n_ctrl + p + 1.
/// Throws KnotVectorError with the first problem found (the message names the knot index), in
/// this order: kNegativeDegree, kNotFinite, kTooFewKnots, kDecreasing, kEmptyDomain,
/// kMultiplicityTooHigh, kNotClamped (if require_clamped), kCountMismatch (if n_ctrl >= 0).
/// (kDegreeTooHigh is raised by BSplineBasis, whose kernels have a fixed maximum degree.)
void validate_knots(const std::vector<double>& U, int p, int n_ctrl = -1,
                    bool require_clamped = true);

/// Number of basis functions defined by U and p: U.size() - p - 1.
inline int num_basis(const std::vector<double>& U, int p) {
  return static_cast<int>(U.size()) - p - 1;
}

/// Algorithm A2.1 (FindSpan), The NURBS Book p. 68, with n = number of basis functions.
/// Returns the span index i such that U[i] <= u < U[i+1]; at u = U[n] (the last knot of the
/// domain) it returns the last non-empty span n - 1, the classic end-of-domain special case.
/// u outside [U[p], U[n]] is clamped to the domain.
int find_span(int n, int p, double u, const std::vector<double>& U);

/// Multiplicity of the knot value u in U (exact comparison).
int knot_multiplicity(const std::vector<double>& U, double u);

/// The first interior knot of U (degree p) where the spline is not C^1 (multiplicity m >= p,
/// continuity C^(p-m)), or nothing: the shell geometry and the rod centerline must be C^1.
struct KnotBreak {
  double value = 0.0;
  int multiplicity = 0;
};
std::optional<KnotBreak> first_non_c1_knot(const std::vector<double>& U, int p);
/// "interior knot 0.5 has multiplicity 2 >= the degree 2: the <what> is only C^0 there".
std::string describe_knot_break(const KnotBreak& k, int p, const std::string& what);

/// The distinct knot values of U (breakpoints), in increasing order.
std::vector<double> unique_knots(const std::vector<double>& U);

/// Open (clamped) uniform knot vector on [a, b] with `elements` equal spans, degree p and
/// interior knot multiplicity `mult` (1 gives C^{p-1} continuity).
std::vector<double> uniform_knots(int p, int elements, double a = 0.0, double b = 1.0,
                                  int mult = 1);

}  // namespace knit::spline
