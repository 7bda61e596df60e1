#include <algorithm>
#include <cmath>

#include "knit/material/load_paths.hpp"
#include "knit/meso/fit/synthetic.hpp"

namespace knit::meso::fit {

using material::RawPath;

Eigen::Vector3d SyntheticLaw::stress(const Eigen::Vector3d& E, double l) const {
  const double k = (l_ref / l) * (l_ref / l);
  return k * Eigen::Vector3d(a1 * E(0) + a12 * E(1) + b1 * E(0) * E(0) * E(0),
                             a12 * E(0) + a2 * E(1) + b2 * E(1) * E(1) * E(1),
                             g * E(2) + h * E(2) * E(2) * E(2));
}

namespace {

double stretch_of(double green) {
  return std::sqrt(1.0 + 2.0 * green);
}

}  // namespace

Eigen::Matrix2d synthetic_deformation_gradient(const material::LoadPath& path, double t,
                                               const SyntheticLaw& law, double l) {
  using material::PathKind;
  if (path.kind == PathKind::kGradient) return Eigen::Matrix2d::Identity() + t * path.H;
  if (path.kind != PathKind::kUniaxial) return material::deformation_gradient(path, t);
  // Uniaxial stress: E along the axis prescribed, the other normal strain by Newton on the
  // lateral stress of the law (monotone in that strain: a12 E + a E^3 with a > 0).
  const int a = path.axis == 1 ? 1 : 0, b = 1 - a;
  Eigen::Vector3d E = Eigen::Vector3d::Zero();
  E(a) = t * path.target(0);
  for (int it = 0; it < 60; ++it) {
    const double r = law.stress(E, l)(b);
    Eigen::Vector3d Ep = E;
    Ep(b) += 1e-7;
    const double d = (law.stress(Ep, l)(b) - r) / 1e-7;
    const double step = r / d;
    E(b) = std::max(E(b) - step, -0.45);
    if (std::abs(step) < 1e-15) break;
  }
  return Eigen::Vector2d(stretch_of(E(0)), stretch_of(E(1))).asDiagonal();
}

std::vector<material::LoadPath> synthetic_coverage_paths(int steps, double e_max, int holdout) {
  using material::LoadPath;
  using material::PathKind;
  std::vector<LoadPath> out;
  const double pi = 3.14159265358979323846;
  for (int deg = 0; deg < 360; deg += 15) {
    LoadPath p;
    p.kind = PathKind::kBiaxial;
    p.target = e_max * Eigen::Vector2d(std::cos(deg * pi / 180), std::sin(deg * pi / 180));
    p.steps = steps;
    p.set = "coverage";
    out.push_back(p);
  }
  // Shear with stretch: H = [[h11, g], [0, h22]] (g = tan of the shear angle at t = 1).
  for (double h11 : {-0.15, 0.0, 0.3})
    for (double h22 : {-0.15, 0.0, 0.3})
      for (double g : {0.4, -0.4}) {
        if (h11 == 0.0 && h22 == 0.0 && g < 0) continue;
        LoadPath p;
        p.kind = PathKind::kGradient;
        p.H << h11, g, 0.0, h22;
        p.steps = steps;
        p.set = "coverage";
        out.push_back(p);
      }
  // Held out: single states at quasi-random gradients inside the box.
  for (int k = 1; k <= holdout; ++k) {
    LoadPath p;
    p.kind = PathKind::kGradient;
    p.H << -0.12 + 0.38 * material::halton(k, 2), 0.35 * (2 * material::halton(k, 5) - 1), 0.0,
        -0.12 + 0.38 * material::halton(k, 3);
    p.steps = 1;
    p.set = "holdout";
    out.push_back(p);
  }
  return out;
}

std::vector<RawPath> synthetic_paths(const SyntheticOptions& o, double l) {
  std::vector<RawPath> out;
  for (const auto& path : o.paths) {
    RawPath r;
    r.path = path;
    r.index = static_cast<int>(out.size());
    const int n = path.steps;
    r.F.resize(n, 4);
    r.P.resize(n, 4);
    r.E.resize(n, 3);
    r.S.resize(n, 3);
    r.status.assign(n, 0);
    for (int k = 0; k < n; ++k) {
      const Eigen::Matrix2d F =
          synthetic_deformation_gradient(path, static_cast<double>(k + 1) / n, o.law, l);
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
