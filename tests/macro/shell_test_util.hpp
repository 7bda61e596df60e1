// Helpers shared by the macroscale tests: small patches and dense assembly.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "knit/macro/shell_model.hpp"
#include "knit/macro/svk_material.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::macro::test {

/// A curved, slightly irregular (rational) patch of degrees (pu, pv) over [0,Lx] x [0,Ly]
/// with `bump` out-of-plane shape.
inline spline::SplineSurface curved_patch(int pu, int pv, int eu, int ev, double Lx, double Ly,
                                          double bump, bool rational) {
  spline::BSplineBasis bu(pu, spline::uniform_knots(pu, eu)), bv(pv, spline::uniform_knots(pv, ev));
  const int nu = bu.size(), nv = bv.size();
  Eigen::MatrixXd P(nu * nv, 3);
  Eigen::VectorXd w(rational ? nu * nv : 0);
  const auto gu = bu.greville(), gv = bv.greville();
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double s = gu[i], t = gv[j];
      const int a = i + nu * j;
      P.row(a) << Lx * s + 0.03 * Lx * std::sin(3 * t), Ly * t + 0.02 * Ly * std::cos(2 * s),
          bump * (s - 0.5) * (s - 0.3) + 0.5 * bump * t * t;
      if (rational) w(a) = 1.0 + 0.2 * std::sin(1.0 + i + 2 * j);
    }
  return spline::SplineSurface(bu, bv, P, w);
}

inline Eigen::MatrixXd dense_tangent(const ShellModel& m, const ShellModel::Evaluation& ev) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m.num_dofs(), m.num_dofs());
  for (int e = 0; e < m.num_elements(); ++e) {
    const Eigen::VectorXi& cp = m.element_control_points(e);
    for (int l = 0; l < cp.size(); ++l)
      for (int k = 0; k < cp.size(); ++k)
        K.block<3, 3>(3 * cp(l), 3 * cp(k)) += ev.Ke[e].block<3, 3>(3 * l, 3 * k);
  }
  return K;
}

}  // namespace knit::macro::test
