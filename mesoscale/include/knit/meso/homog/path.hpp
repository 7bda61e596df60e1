// Macroscopic deformation paths of the unit cell (paper eq. 7) and their CSV record.
//   biaxial:    F*(lambda) = diag(1 + lambda eps11, 1 + lambda eps22)
//   pure shear: F*(lambda) = [[1, sin(lambda gamma)], [0, cos(lambda gamma)]]
//               (E11 = E22 = 0, E12 = sin(lambda gamma)/2 exactly at every step)
//   uniaxial:   F*_aa(lambda) = 1 + lambda (stretch - 1) along `axis` (0 = course, 1 = wale),
//               the lateral stretch found so that S_bb = 0 (homog/uniaxial.hpp; the sweep's
//               uniaxial kind, knit/material/load_paths.hpp)
// lambda = k / steps, k = 0..steps; step 0 is the equilibrated initial state (zero stress with
// the stress-free reference, the residual stress with contact.reference = none).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "knit/meso/homog/periodic_cell.hpp"

namespace knit::meso::homog {

struct PathSpec {
  enum class Kind { kBiaxial, kShear, kUniaxial };
  Kind kind = Kind::kBiaxial;
  double eps11 = 0, eps22 = 0;  ///< biaxial strains in F*
  double gamma = 0;             ///< shear angle [rad]
  int axis = 0;                 ///< uniaxial: 0 = course (F11 prescribed), 1 = wale (F22)
  double stretch = 1;           ///< uniaxial: end stretch F*_aa along `axis`
  int steps = 20;
};

/// The prescribed F* at `lambda`; for a uniaxial path only the prescribed stretch is meaningful
/// (the lateral entry is 1: the solve finds it).
Eigen::Matrix2d path_F(const PathSpec& path, double lambda);

struct PathResult {
  bool completed = false;
  std::vector<StepResult> steps;  ///< steps[0]: equilibrated state at F* = I
  double seconds = 0;             ///< wall time of the loading steps (without equilibration)
  double equilibration_seconds = 0;
  int iterations = 0;  ///< Newton iterations of the loading steps
  std::string message;
};

/// Equilibrates the cell, then runs the path; on_step(k, result) after every converged step
/// (k = 0 for the equilibrium). Stops at the first step that fails.
PathResult run_path(PeriodicCell& cell, const PathSpec& path,
                    const std::function<void(int, const StepResult&)>& on_step = {});

/// CSV header and one row (F*, P*, E, S per step plus solver figures).
std::string csv_header();
std::string csv_row(int step, double lambda, const StepResult& r);

/// Work of the homogenized stresses per unit reference volume along recorded steps,
/// W = sum 1/2 (P_k + P_{k+1}) : (F_{k+1} - F_k) (trapezoidal) [MPa = N mm / mm^3].
double stress_work(const std::vector<StepResult>& steps);
/// Work of the boundary forces per unit reference volume: sum 1/2 (n1_k + n1_{k+1}) . (a1_{k+1}
/// - a1_k) + (n2 ...) . (a2 ...), a1 = F*(w,0), a2 = F*(0,c), divided by V = w c t.
double boundary_work(const std::vector<StepResult>& steps, double w, double c, double t);

}  // namespace knit::meso::homog
