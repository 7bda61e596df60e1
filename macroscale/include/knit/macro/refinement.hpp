// The case's `refinement` block: elevate the patch to degree p, then insert uniform knots so
// that a single-element direction gets `elements` equal elements (breakpoints already present
// are kept; the same rule as knit::spline::refine). The geometry is unchanged (exactly).
#pragma once

#include "knit/spline/surface.hpp"

namespace knit::macro {

/// Throws std::invalid_argument if p is below a degree of the patch or elements < 1.
spline::SplineSurface refine_patch(const spline::SplineSurface& s, int p, int elements_u,
                                   int elements_v);

}  // namespace knit::macro
