// The energy law's own uniaxial response beside the unit cell's (session 41).
//
// The law's acceptance measures its errors against each loop length's stress range (issue 11:
// within 5 % of it), a range set by the jammed corners of the strain box (21-33 MPa). Uniaxial
// tension, where the tensile cases work, carries a few MPa at most, so the law can be within
// 5 % of the range there and still carry 2.6 times the cell's stress (6.5 mm wale-wise on the
// default database; docs/database.md, "The law's own uniaxial response"). The fit stores,
// per loop length and axis, the cell's uniaxial-stress path (one stretch prescribed, the other
// found so that its stress vanishes) beside the law driven the same way: at the cell's axial
// strain, the law's axial stress where the law's lateral stress vanishes. knit-macro warns
// from it (KnitMaterial::warning()).
#pragma once

#include <vector>

namespace knit::material {

/// One uniaxial-stress path: at each converged step the cell's axial Green-Lagrange strain,
/// its axial stress S (MPa) and the law's own axial stress at that axial strain (MPa; NaN
/// where the law has no uniaxial state there). Stored in /energy_law/diagnostics/uniaxial.
struct UniaxialCurve {
  std::vector<double> strain, cell, law;
  bool empty() const { return strain.empty(); }
};

/// The smallest cell stress a comparison keeps, as a share of the path's largest: below it the
/// ratio of two small numbers says little (the loose cell's slack start, a few kPa).
inline constexpr double kUniaxialMinShare = 0.1;

/// The state of a curve where the law departs most from the cell.
struct UniaxialDeviation {
  double deviation = 0.0;  ///< |law / cell - 1| there (infinity where the law has no state)
  double ratio = 1.0;      ///< law / cell there (NaN where the law has no state)
  double strain = 0.0;     ///< the cell's axial strain there
  int states = 0;          ///< states compared
};

/// The largest |law / cell - 1| over the curve's states with an axial strain of at most
/// `max_strain` (the strains increase along the curve; where max_strain lies between two
/// states, the curve interpolated linearly there is one more state) and a cell stress of at
/// least `min_share` times the largest |S_cell| of those states. states == 0 when none
/// qualifies.
UniaxialDeviation uniaxial_deviation(const UniaxialCurve& c, double max_strain,
                                     double min_share = kUniaxialMinShare);

}  // namespace knit::material
