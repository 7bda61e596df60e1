#include <cmath>

#include "knit/meso/fit/synthetic.hpp"

namespace knit::meso::fit {

using material::RawPath;

Eigen::Vector3d SyntheticLaw::stress(const Eigen::Vector3d& E, double l) const {
  const double k = (l_ref / l) * (l_ref / l);
  return k * Eigen::Vector3d(a1 * E(0) + a12 * E(1) + b1 * E(0) * E(0) * E(0),
                             a12 * E(0) + a2 * E(1) + b2 * E(1) * E(1) * E(1),
                             g * E(2) + h * E(2) * E(2) * E(2));
}

std::vector<RawPath> synthetic_paths(const SyntheticOptions& o, double l) {
  std::vector<RawPath> out;
  for (const auto& path : o.paths) {
    RawPath r;
    r.path = path;
    const int n = path.steps;
    r.F.resize(n, 4);
    r.P.resize(n, 4);
    r.E.resize(n, 3);
    r.S.resize(n, 3);
    r.status.assign(n, 0);
    for (int k = 0; k < n; ++k) {
      const Eigen::Matrix2d F =
          material::deformation_gradient(path, static_cast<double>(k + 1) / n);
      const Eigen::Matrix2d E = material::green_lagrange(F);
      const Eigen::Vector3d s = o.law.stress({E(0, 0), E(1, 1), E(0, 1)}, l);
      Eigen::Matrix2d S;
      S << s(0), s(2), s(2), s(1);
      const Eigen::Matrix2d P = material::first_piola_kirchhoff(F, S);
      r.F.row(k) << F(0, 0), F(0, 1), F(1, 0), F(1, 1);
      r.P.row(k) << P(0, 0), P(0, 1), P(1, 0), P(1, 1);
      r.E.row(k) << E(0, 0), E(1, 1), E(0, 1);
      r.S.row(k) = s.transpose();
    }
    out.push_back(std::move(r));
  }
  return out;
}

material::Database synthetic_database(const SyntheticOptions& o) {
  material::Database db;
  db.provenance = material::current_provenance();
  db.generator = "synth";
  db.sweep_input =
      "{\"generator\": \"synth\", \"note\": \"synthetic stand-in for the mesoscale sweep: a known "
      "orthotropic stiffening law, not a knit\"}";
  db.yarn = {{"diameter", 0.38}, {"youngs_modulus", 800.0}, {"poisson_ratio", 0.3}};
  for (double l : o.loop_lengths) {
    material::LoopLengthEntry e;
    e.loop_length = l;
    // design/notes.md: w linear in l between (4.5, 1.26) and (6.5, 1.41); c = l^2/(18.27 w).
    e.cell.wale_width = 1.26 + (l - 4.5) * (1.41 - 1.26) / 2.0;
    e.cell.course_height = l * l / (18.27 * e.cell.wale_width);
    e.cell.thickness = 2 * 0.38;
    e.raw = synthetic_paths(o, l);
    db.entries.push_back(std::move(e));
  }
  return db;
}

}  // namespace knit::meso::fit
