// Resolution check by bisection (knit/meso/rod/resolution.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "knit/meso/rod/resolution.hpp"
#include "knit/spline/curve.hpp"
#include "knit/spline/refine.hpp"

namespace knit::meso::rod {

RodSystem bisected(const RodSystem& sys) {
  RodSystem out;
  for (int k = 0; k < sys.num_rods(); ++k) {
    RodSpec s = sys.spec(k);
    std::vector<double> mid;
    const std::vector<double>& U = s.basis.knots();
    for (std::size_t i = 0; i + 1 < U.size(); ++i)
      if (U[i + 1] > U[i]) mid.push_back(0.5 * (U[i] + U[i + 1]));
    const spline::SplineCurve fine =
        spline::insert_knots(spline::SplineCurve(s.basis, s.r0, s.weights), mid);
    s.basis = fine.basis();
    s.r0 = fine.control_points();
    s.weights = fine.rational() ? Eigen::VectorXd(fine.weights()) : Eigen::VectorXd();
    s.q0.resize(0, 0);  // rebuilt on the finer basis from d1_hint
    out.add_rod(std::move(s));
  }
  return out;
}

std::string ResolutionCheck::describe() const {
  if (!checked) return "not checked: " + note;
  std::ostringstream os;
  os.precision(3);
  os << "the output displacements change by " << 100.0 * difference
     << " % of their largest (max |u| = " << u_max << " mm";
  if (u_max < floor) os << ", below the floor 1e-6 L = " << floor << " mm, which is the scale";
  os << ") when every knot span is halved";
  return os.str();
}

ResolutionCheck check_resolution(const RodSystem& sys, const Eigen::VectorXd& x,
                                 const PathOptions& path, const std::vector<RodPoint>& points) {
  ResolutionCheck rc;
  const RodSystem fine = bisected(sys);
  Eigen::VectorXd xf = fine.initial_state();
  const PathReport rep = solve_path(fine, xf, path);
  if (!rep.completed) {
    rc.note =
        "the run on the bisected mesh stopped at lambda = " + std::to_string(rep.lambda_reached) +
        " (" + rep.message + ")";
    return rc;
  }
  double diff = 0.0;
  for (const RodPoint& p : points) {
    const Eigen::Vector3d r0 = sys.reference_position(p.rod, p.xi);
    const Eigen::Vector3d u = sys.position(p.rod, p.xi, x) - r0;
    const Eigen::Vector3d uf = fine.position(p.rod, p.xi, xf) - r0;
    diff = std::max(diff, (u - uf).norm());
    rc.u_max = std::max(rc.u_max, uf.norm());
  }
  rc.checked = true;
  // Relative to the largest displacement, but not below 1e-6 of the longest rod: where nothing
  // moves (pure torsion, no output point displaced) both are round-off, and their ratio was
  // 191 % (review of session 28). Rotations are not compared.
  double length = 0.0;
  for (int k = 0; k < sys.num_rods(); ++k) length = std::max(length, sys.reference_length(k));
  rc.floor = kDisplacementFloor * length;
  rc.difference = diff / std::max(rc.u_max, rc.floor);
  return rc;
}

}  // namespace knit::meso::rod
