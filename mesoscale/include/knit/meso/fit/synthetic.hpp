// A synthetic material database: the stand-in for the mesoscale sweep until real data exist
// (`knit-meso synth`). It evaluates a known orthotropic, stiffening law on the same load paths
// the sweep uses (knit/material/load_paths.hpp) and stores F*, P*, E, S like the sweep would.
//
// The law (MPa; E Green-Lagrange tensor components), softening with the loop length l:
//   k(l) = (l_ref / l)^2, l_ref = 4.5 mm
//   S1  = k (a1 E1 + a12 E2 + b1 E1^3)
//   S2  = k (a12 E1 + a2 E2 + b2 E2^3)
//   S12 = k (g E12 + h E12^3)
// Orthotropic (course 1 softer than wale 2), stiffening, with a linear part that is positive
// definite (a1 a2 > a12^2). It is not the knit's law; it only exercises the chain.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "knit/material/database.hpp"

namespace knit::meso::fit {

struct SyntheticLaw {
  double a1 = 0.5, a2 = 1.0, a12 = 0.1, b1 = 8.0, b2 = 12.0, g = 0.3, h = 4.0;
  double l_ref = 4.5;
  /// (S11, S22, S12) at tensor strains (E11, E22, E12) and loop length l.
  Eigen::Vector3d stress(const Eigen::Vector3d& E, double l) const;
};

/// Coverage paths for the energy-based law (set "coverage"): the full circle of biaxial
/// directions (every 15 degrees, radius e_max in (E11, E22), compression included) and
/// shear-with-stretch gradient paths F = I + t H; plus `holdout` single-state gradient paths
/// (set "holdout") at quasi-random (Halton 2, 3, 5) strain states inside the box. The law is
/// known, so these are exact data for the fit test.
std::vector<material::LoadPath> synthetic_coverage_paths(int steps = 10, double e_max = 0.4,
                                                         int holdout = 24);

struct SyntheticOptions {
  std::vector<double> loop_lengths = {4.5, 5.0, 5.5, 6.0, 6.5};
  std::vector<material::LoadPath> paths = material::default_load_paths();
  SyntheticLaw law;
};

/// F of a path at step fraction t, for every kind (uniaxial: the prescribed Green-Lagrange
/// strain along the axis grows linearly in t and the lateral strain makes the synthetic law's
/// lateral stress vanish).
Eigen::Matrix2d synthetic_deformation_gradient(const material::LoadPath& path, double t,
                                               const SyntheticLaw& law, double l);

/// Raw data of one loop length (all steps converged).
std::vector<material::RawPath> synthetic_paths(const SyntheticOptions& o, double l);

/// A database with raw data (not fitted yet), cell parameters from design/notes.md.
material::Database synthetic_database(const SyntheticOptions& o);

}  // namespace knit::meso::fit
