// Resolution check by bisection (knit/meso/rod/resolution.hpp).
#include <Eigen/Geometry>
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
  os << "the output displacements change by " << 100.0 * displacement_difference
     << " % of their largest (max |u| = " << u_max << " mm";
  if (u_max < floor) os << ", below the floor 1e-6 L = " << floor << " mm, which is the scale";
  os << ") and the rotations by " << 100.0 * rotation_difference
     << " % of their largest (max angle " << angle_max << " rad";
  if (angle_max < kRotationFloor) os << ", below the floor " << kRotationFloor << " rad";
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
  double diff = 0.0, turn = 0.0;
  const Eigen::VectorXd x0 = sys.initial_state(), xf0 = fine.initial_state();
  auto angle = [](const Eigen::Matrix3d& Q) { return Eigen::AngleAxisd(Q).angle(); };
  for (const RodPoint& p : points) {
    const Eigen::Vector3d r0 = sys.reference_position(p.rod, p.xi);
    const Eigen::Vector3d u = sys.position(p.rod, p.xi, x) - r0;
    const Eigen::Vector3d uf = fine.position(p.rod, p.xi, xf) - r0;
    diff = std::max(diff, (u - uf).norm());
    rc.u_max = std::max(rc.u_max, uf.norm());
    // The rotation from the reference directors to the current ones, Lambda = R R0^T: the
    // bisected mesh rebuilds its reference frame, so R itself is not compared (session 29:
    // a straight rod twisted by 190 degrees, one element of degree 2, ended 24 degrees short
    // with its displacements zero on both meshes and no warning).
    const Eigen::Matrix3d L =
        sys.state(p.rod, p.xi, x).R * sys.state(p.rod, p.xi, x0).R.transpose();
    const Eigen::Matrix3d Lf =
        fine.state(p.rod, p.xi, xf).R * fine.state(p.rod, p.xi, xf0).R.transpose();
    turn = std::max(turn, angle(L.transpose() * Lf));
    rc.angle_max = std::max(rc.angle_max, angle(Lf));
  }
  rc.checked = true;
  // Relative to the largest displacement, but not below 1e-6 of the longest rod: where nothing
  // moves (pure torsion, no output point displaced) both are round-off, and their ratio was
  // 191 % (review of session 28).
  double length = 0.0;
  for (int k = 0; k < sys.num_rods(); ++k) length = std::max(length, sys.reference_length(k));
  rc.floor = kDisplacementFloor * length;
  rc.displacement_difference = diff / std::max(rc.u_max, rc.floor);
  rc.rotation_difference = turn / std::max(rc.angle_max, kRotationFloor);
  rc.difference = std::max(rc.displacement_difference, rc.rotation_difference);
  return rc;
}

}  // namespace knit::meso::rod
