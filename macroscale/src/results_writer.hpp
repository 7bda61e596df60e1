// Output directory of a run (private to run.cpp): CSV of the converged steps, VTU/PVD of the
// sampled mid-surface, case copy, summary. Built in DIR.partial-<pid>, renamed on finish().
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "knit/io/atomic.hpp"
#include "knit/io/vtk.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/output_units.hpp"
#include "knit/macro/run.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

/// Refuses (knit::InputError naming /output/grid, with the estimate) a case whose estimated
/// output exceeds opt.max_output_bytes; warns on opt.warnings above a tenth of it.
void check_output_size(const Case& c, const RunOptions& opt);

class ResultsWriter {
 public:
  ResultsWriter(const Case& c, const ShellModel& m, std::filesystem::path dir);
  ~ResultsWriter();
  void add_row(const StepRow& row);
  /// Samples the mid-surface on the output grid and writes vtk/step_NNNN.vtu.
  void add_step(int step, double lambda, const Eigen::VectorXd& u);
  /// Writes the CSV, PVD, HDF5 and summary, then moves the directory into place.
  void finish(const RunReport& report);
  /// The material's end-of-run summary (Material::report()), written to summary.txt and HDF5.
  void set_material_report(std::string r) { material_report_ = std::move(r); }
  /// The run's verdict on the material (run.hpp, material_failure_message()); empty if the
  /// material never failed. Written to summary.txt and load_strain.csv.
  void set_material_failure(std::string m) { material_failure_ = std::move(m); }
  /// Material::warning(): a comment in the CSV, a line in summary.txt, an HDF5 attribute.
  void set_material_warning(std::string m) { material_warning_ = std::move(m); }
  /// Load drops (load_drop.hpp), a line each: CSV comments, summary.txt lines and the HDF5
  /// attribute "load_drops" (the lines joined by newlines).
  void set_load_drops(std::vector<std::string> d) { load_drops_ = std::move(d); }
  /// RunResult::solver_warning: a summary.txt line and the HDF5 attribute "solver_warning".
  void set_solver_warning(std::string w) { solver_warning_ = std::move(w); }
  /// RunResult::input_warnings: "warning: " lines of summary.txt.
  void set_input_warnings(std::vector<std::string> w) { input_warnings_ = std::move(w); }
  /// io::AtomicDirectory::keep_replaced_as: the earlier output this one replaces is kept there.
  void keep_replaced_as(std::string suffix) { dir_.keep_replaced_as(std::move(suffix)); }
  const std::filesystem::path& replaced_kept_in() const { return dir_.replaced_kept_in(); }
  /// Empty, or where the sampled output fields first held a non-finite number (the first
  /// field, step and point, and how many values in all): the quadrature points, which Newton
  /// checks, may never reach a strain where the material's stress overflows, the output grid
  /// can. Written to summary.txt, load_strain.csv and results.h5; the run then fails.
  std::string output_failure() const;

 private:
  struct Fields {
    int step = 0;
    double lambda = 0.0;
    Eigen::MatrixXd X, x, u;         ///< n x 3
    std::vector<std::string> names;  ///< scalar field names
    Eigen::MatrixXd values;          ///< n x names.size()
  };
  Fields sample(int step, double lambda, const Eigen::VectorXd& u) const;
  void check_finite(const Fields& f);
  void write_vtu(const std::filesystem::path& file, const Fields& f) const;
  void write_hdf5(const std::filesystem::path& file, const RunReport& report) const;

  const Case& case_;
  UnitLabels units_;  ///< from the case's /units (knit/macro/output_units.hpp)
  const ShellModel& model_;
  io::AtomicDirectory dir_;  ///< DIR.partial-<pid> until finish(); removed if abandoned
  io::PvdCollection pvd_;
  std::vector<StepRow> rows_;
  std::vector<Fields> steps_;  ///< kept for the HDF5 file
  std::string material_report_;
  std::string material_failure_;
  std::string material_warning_;
  std::vector<std::string> load_drops_;
  std::string solver_warning_;
  std::vector<std::string> input_warnings_;
  std::string nonfinite_output_;
  long nonfinite_values_ = 0;
};

}  // namespace knit::macro
