// The unit-cell runner of the sweep: one load path (paper eq. 7, the shared definition of
// knit/material/load_paths.hpp) on the periodic cell of a loop length (knit/meso/homog),
// recording F*, P*, E, S of every step (eqs. 8-9). Each call builds its own cell, equilibrates
// it at F* = I and then follows the path step by step from the last converged state; it is
// deterministic and shares nothing with concurrent calls.
#include <nlohmann/json.hpp>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/meso/homog/cell_config.hpp"
#include "knit/meso/homog/periodic_cell.hpp"
#include "knit/meso/homog/uniaxial.hpp"
#include "knit/meso/sweep/sweep.hpp"

namespace knit::meso::sweep {

namespace {

/// The cell parameters: the sweep's inline "cell" object, or the file it names.
homog::CellOptions cell_options(const SweepInput& in) {
  if (!in.cell_file.empty()) return homog::read_cell_options(in.cell_file);
  return homog::cell_options_from_json(nlohmann::json::parse(in.cell_json), in.file, "/cell");
}

}  // namespace

PathRunner cell_runner(const SweepInput& in) {
  const homog::CellOptions co = cell_options(in);
  // Every loop length's cell is built once before any case runs: one the geometry cannot be
  // made for (a loop too short for its wale width and yarn diameter) is an input error. Found
  // with a loop length of 1 mm: every case of it failed with the same geometry error, and the
  // database was written with a loop length that holds no state.
  for (std::size_t k = 0; k < in.loop_lengths.size(); ++k) {
    const double l = in.loop_lengths[k];
    try {
      const homog::PeriodicCell cell(l, co);
    } catch (const std::exception& e) {
      std::ostringstream m;
      m << "the unit cell of loop length " << l << " mm (yarn diameter " << co.section.d
        << " mm) cannot be built: " << e.what();
      throw InputError(in.file, io::json_pointer_append("/loop_lengths", k), m.str());
    }
  }
  return [co](double l, const material::LoadPath& path) {
    const int n = path.steps;
    PathOutcome out;
    material::RawPath& r = out.raw;
    r.path = path;
    r.F = material::RowMatrixX::Zero(n, 4);
    r.P = material::RowMatrixX::Zero(n, 4);
    r.E = material::RowMatrixX::Zero(n, 3);
    r.S = material::RowMatrixX::Zero(n, 3);
    r.status.assign(static_cast<std::size_t>(n), kStepNotReached);
    homog::PeriodicCell cell(l, co);
    out.cell.wale_width = cell.dimensions().w;
    out.cell.course_height = cell.dimensions().c;
    out.cell.thickness = cell.thickness();
    const homog::StepResult eq = cell.equilibrate();
    if (!eq.converged) {
      r.status[0] = kStepFailed;
      out.message = "initial equilibrium did not converge: " + eq.message;
      return out;
    }
    out.residual << eq.S(0, 0), eq.S(1, 1), 0.5 * (eq.S(0, 1) + eq.S(1, 0));
    homog::UniaxialState uni;
    for (int k = 0; k < n; ++k) {
      const Eigen::Matrix2d F =
          material::deformation_gradient(path, static_cast<double>(k + 1) / n);
      homog::StepResult s;
      if (path.kind == material::PathKind::kUniaxial) {
        const homog::UniaxialStep u =
            homog::solve_uniaxial_step(cell, path.axis, F(path.axis, path.axis), uni);
        s = u.step;
      } else {
        s = cell.solve(F);
      }
      out.iterations += s.iterations;
      if (!s.converged) {
        r.status[static_cast<std::size_t>(k)] = kStepFailed;
        out.message = "step " + std::to_string(k + 1) + " did not converge: " + s.message;
        return out;
      }
      const Eigen::Matrix2d E = material::green_lagrange(s.F);
      const Eigen::Matrix2d S = material::second_piola_kirchhoff(s.F, s.P);
      r.F.row(k) << s.F(0, 0), s.F(0, 1), s.F(1, 0), s.F(1, 1);
      r.P.row(k) << s.P(0, 0), s.P(0, 1), s.P(1, 0), s.P(1, 1);
      r.E.row(k) << E(0, 0), E(1, 1), E(0, 1);
      r.S.row(k) << S(0, 0), S(1, 1), S(0, 1);
      r.status[static_cast<std::size_t>(k)] = kStepConverged;
    }
    out.message = "converged, " + std::to_string(out.iterations) + " Newton iterations";
    return out;
  };
}

}  // namespace knit::meso::sweep
