// The case's refinement block delegates to the spline kernel's k-refinement
// (knit/spline/refine.hpp: degree elevation A5.9, then knot insertion A5.4).
#include "knit/macro/refinement.hpp"

#include <stdexcept>
#include <string>

#include "knit/spline/refine.hpp"

namespace knit::macro {

spline::SplineSurface refine_patch(const spline::SplineSurface& s, int p, int eu, int ev) {
  if (p < s.basis_u().degree() || p < s.basis_v().degree())
    throw std::invalid_argument("the refinement degree " + std::to_string(p) +
                                " is below the patch's degree");
  if (eu < 1 || ev < 1) throw std::invalid_argument("the number of elements must be at least 1");
  return spline::refine(s, p, eu, ev);
}

}  // namespace knit::macro
