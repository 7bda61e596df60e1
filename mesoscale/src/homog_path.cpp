// Deformation paths of the unit cell: see knit/meso/homog/path.hpp.
#include "knit/meso/homog/path.hpp"

#include "knit/meso/homog/uniaxial.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace knit::meso::homog {

Eigen::Matrix2d path_F(const PathSpec& p, double lam) {
  Eigen::Matrix2d F;
  if (p.kind == PathSpec::Kind::kBiaxial) {
    F << 1 + lam * p.eps11, 0, 0, 1 + lam * p.eps22;
  } else if (p.kind == PathSpec::Kind::kUniaxial) {
    F.setIdentity();
    F(p.axis, p.axis) = 1 + lam * (p.stretch - 1);
  } else {
    const double g = lam * p.gamma;
    F << 1, std::sin(g), 0, std::cos(g);
  }
  return F;
}

PathResult run_path(PeriodicCell& cell, const PathSpec& path,
                    const std::function<void(int, const StepResult&)>& on_step) {
  PathResult out;
  StepResult r0 = cell.equilibrate();
  out.equilibration_seconds = r0.seconds;
  out.steps.push_back(r0);
  if (!r0.converged) {
    out.message = "initial equilibrium did not converge: " + r0.message;
    return out;
  }
  if (on_step) on_step(0, r0);
  const auto t0 = std::chrono::steady_clock::now();
  UniaxialState uni;
  for (int k = 1; k <= path.steps; ++k) {
    const Eigen::Matrix2d F = path_F(path, double(k) / path.steps);
    const StepResult r =
        path.kind == PathSpec::Kind::kUniaxial
            ? solve_uniaxial_step(cell, path.axis, F(path.axis, path.axis), uni).step
            : cell.solve(F);
    out.iterations += r.iterations;
    if (!r.converged) {
      out.message = "step " + std::to_string(k) + " did not converge: " + r.message;
      out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return out;
    }
    out.steps.push_back(r);
    if (on_step) on_step(k, r);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.completed = true;
  out.message = "completed";
  return out;
}

std::string csv_header() {
  // Units in the column names, as knit-macro's load_strain.csv has them (F and E are
  // dimensionless; session 38's red team: P and S had no unit).
  return "step,lambda,F11,F12,F21,F22,P11_MPa,P12_MPa,P21_MPa,P22_MPa,E11,E22,E12,S11_MPa,"
         "S22_MPa,S12_MPa,S21_MPa,"
         "newton_iterations,cutbacks,substeps,seconds,active_contacts,min_gap_mm,dissipation_Nmm,"
         "imbalance_N\n";
}

std::string csv_row(int step, double lambda, const StepResult& r) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%d,%.6g,%.12g,%.12g,%.12g,%.12g,%.10g,%.10g,%.10g,%.10g,%.12g,%.12g,%.12g,"
                "%.10g,%.10g,%.10g,%.10g,%d,%d,%d,%.4f,%d,%.6g,%.6g,%.3g\n",
                step, lambda, r.F(0, 0), r.F(0, 1), r.F(1, 0), r.F(1, 1), r.P(0, 0), r.P(0, 1),
                r.P(1, 0), r.P(1, 1), r.E(0, 0), r.E(1, 1), r.E(0, 1), r.S(0, 0), r.S(1, 1),
                r.S(0, 1), r.S(1, 0), r.iterations, r.cutbacks, r.substeps, r.seconds,
                r.active_contacts, r.min_gap, r.dissipation, r.imbalance);
  return buf;
}

double stress_work(const std::vector<StepResult>& s) {
  double W = 0;
  for (std::size_t k = 0; k + 1 < s.size(); ++k)
    W += (0.5 * (s[k].P + s[k + 1].P)).cwiseProduct(s[k + 1].F - s[k].F).sum();
  return W;
}

double boundary_work(const std::vector<StepResult>& s, double w, double c, double t) {
  double W = 0;
  for (std::size_t k = 0; k + 1 < s.size(); ++k) {
    const Eigen::Vector2d da1 = (s[k + 1].F - s[k].F) * Eigen::Vector2d(w, 0);
    const Eigen::Vector2d da2 = (s[k + 1].F - s[k].F) * Eigen::Vector2d(0, c);
    W += 0.5 * (s[k].n1 + s[k + 1].n1).head<2>().dot(da1) +
         0.5 * (s[k].n2 + s[k + 1].n2).head<2>().dot(da2);
  }
  return W / (w * c * t);
}

}  // namespace knit::meso::homog
