// The case's `refinement` block: elevate the patch to degree p, then insert uniform knots so
// that a single-element direction gets `elements` equal elements (breakpoints already present
// are kept; the same rule as knit::spline::refine). The geometry is unchanged (exactly).
#pragma once

#include <cstdint>
#include <string>

#include "knit/spline/surface.hpp"

namespace knit::macro {

/// Throws std::invalid_argument if p is below a degree of the patch or elements < 1.
spline::SplineSurface refine_patch(const spline::SplineSurface& s, int p, int elements_u,
                                   int elements_v);

/// Memory a shell run on this patch needs, estimated before anything is allocated (issue 14:
/// a schema-legal p = 15, 256 x 256 ended in std::bad_alloc). With nloc = (pu+1)(pv+1) local
/// functions, Q = (pu+1)(pv+1) Gauss points per element (the ShellModel default), E elements
/// and N = 3 n_cp unknowns, in bytes:
///   quadrature data   E Q (11 nloc 8 + 256)      basis derivatives R_ and Phi, point data
///   element tangents  2 (3 nloc)^2 8             a buffer per assembly thread (two)
///   global system     dense (N <= 2500): 2 N^2 8; sparse: 3 x 16 nnz, nnz = N 3 (2pu+1)(2pv+1)
/// It leaves out the solver's work vectors, the factor's fill, outputs and the material, and is
/// meant to refuse what cannot run, not to predict what can; measured against the peak RSS of
/// degree-5 patches of 32 to 256 elements a side (session 37) it lies 1.0-1.5 x above it.
struct MemoryEstimate {
  std::uint64_t quadrature = 0, element_tangents = 0, global_system = 0;
  std::uint64_t total() const { return quadrature + element_tangents + global_system; }
  /// e.g. "207 GB (quadrature data 186 GB, element tangents 19 GB, global system 2.1 GB)"
  std::string describe() const;
};
/// "207 GB", "12 MB" (decimal units).
std::string format_bytes(std::uint64_t bytes);
/// `extra`: Gauss points beyond p + 1 per direction (ShellOptions::extra_quadrature_points).
MemoryEstimate estimate_shell_memory(const spline::SplineSurface& s, int extra = 0);
/// The same from degrees, the number of elements (non-empty spans) and of control points.
MemoryEstimate estimate_shell_memory(double degree_u, double degree_v, double elements,
                                     double size_u, double size_v, int extra = 0);
/// A lower bound of estimate_shell_memory(refine_patch(s, p, elements_u, elements_v)) for any
/// patch s, known before the refinement is made: refine() keeps the patch's breakpoints and adds
/// uniform ones, so the refined patch has at least elements_u x elements_v elements and
/// elements + p control points a side (exactly so for a patch of one element); the estimate
/// grows with each count except the global system's, dense up to 2500 unknowns and sparse
/// beyond, so the bound takes the smaller of the two there. A refinement far beyond the memory
/// is refused at once, not
/// after seconds of knot insertion (session 49: 1.2 s for 256 x 256 elements of degree 15).
MemoryEstimate estimate_refinement_memory(int p, int elements_u, int elements_v);

/// The memory a run may use: KNIT_MAX_MEMORY_MB from the environment if set (a whole number of
/// MiB in [1, 2^40]; anything else throws knit::InputError naming the variable), else the
/// machine's physical memory.
std::uint64_t memory_limit_bytes();

}  // namespace knit::macro
