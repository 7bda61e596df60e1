#include "results_writer.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "knit/core/build_info.hpp"
#include "knit/core/errors.hpp"
#if __has_include("knit/io/hdf5.hpp")
#include "knit/io/hdf5.hpp"
#include "knit/io/provenance.hpp"
#define KNIT_MACRO_HAVE_IO 1
#endif

namespace knit::macro {

namespace fs = std::filesystem;

namespace {

std::string fmt(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", x);
  return b;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace

ResultsWriter::ResultsWriter(const Case& c, const ShellModel& m, fs::path dir)
    : case_(c), model_(m), target_(std::move(dir)) {
  partial_ = target_;
  partial_ += ".partial-" + std::to_string(::getpid());
  if (fs::exists(target_) && !fs::is_directory(target_))
    throw InputError("", "--output", target_.string() + " exists and is not a directory");
  fs::remove_all(partial_);
  fs::create_directories(partial_ / "vtk");
  write_text(partial_ / "case.json", c.text);
}

ResultsWriter::~ResultsWriter() {
  if (!finished_) {
    std::error_code ec;
    fs::remove_all(partial_, ec);
  }
}

void ResultsWriter::add_row(const StepRow& row) {
  rows_.push_back(row);
}

ResultsWriter::Fields ResultsWriter::sample(int step, double lambda,
                                            const Eigen::VectorXd& u) const {
  const int gu = case_.output.grid_u, gv = case_.output.grid_v, n = gu * gv;
  Fields f;
  f.step = step;
  f.lambda = lambda;
  f.X.resize(n, 3);
  f.x.resize(n, 3);
  f.u.resize(n, 3);
  f.names = {"E11", "E22", "E12", "kappa11", "kappa22", "kappa12",
             "n11", "n22", "n12", "m11",     "m22",     "m12"};
  std::vector<std::pair<std::string, double>> extra;
  for (int j = 0; j < gv; ++j) {
    for (int i = 0; i < gu; ++i) {
      const int k = i + gu * j;
      const Eigen::Vector2d t(double(i) / (gu - 1), double(j) / (gv - 1));
      const ShellSample s = model_.sample(u, t);
      extra = model_.material().output_fields(t, s.E);
      if (k == 0) {
        for (const auto& [name, v] : extra) f.names.push_back(name);
        f.values.resize(n, f.names.size());
      }
      f.X.row(k) = s.X.transpose();
      f.x.row(k) = s.x.transpose();
      f.u.row(k) = s.u.transpose();
      // Voigt shear components (2E12, 2k12) are stored as tensor components E12, k12.
      const double v[12] = {s.E(0), s.E(1), 0.5 * s.E(2), s.kappa(0), s.kappa(1), 0.5 * s.kappa(2),
                            s.n(0), s.n(1), s.n(2),       s.m(0),     s.m(1),     s.m(2)};
      for (int c = 0; c < 12; ++c) f.values(k, c) = v[c];
      for (size_t c = 0; c < extra.size() && 12 + c < f.names.size(); ++c)
        f.values(k, 12 + c) = extra[c].second;
    }
  }
  return f;
}

void ResultsWriter::add_step(int step, double lambda, const Eigen::VectorXd& u) {
  Fields f = sample(step, lambda, u);
  char name[64];
  std::snprintf(name, sizeof name, "step_%04d.vtu", step);
  write_vtu(partial_ / "vtk" / name, f);
  steps_.push_back(std::move(f));
}

void ResultsWriter::write_vtu(const fs::path& file, const Fields& f) const {
  const int gu = case_.output.grid_u, gv = case_.output.grid_v, n = gu * gv;
  const int nc = (gu - 1) * (gv - 1);
  std::ostringstream o;
  o << "<?xml version=\"1.0\"?>\n<!-- knit-macro: deformed mid-surface, load factor "
    << fmt(f.lambda) << "; strains in the local Cartesian frame of the reference surface -->\n"
    << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
       "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n"
    << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << nc << "\">\n<Points>\n"
    << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int k = 0; k < n; ++k)
    o << fmt(f.x(k, 0)) << ' ' << fmt(f.x(k, 1)) << ' ' << fmt(f.x(k, 2)) << '\n';
  o << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" "
       "format=\"ascii\">\n";
  for (int j = 0; j + 1 < gv; ++j)
    for (int i = 0; i + 1 < gu; ++i) {
      const int a = i + gu * j;
      o << a << ' ' << a + 1 << ' ' << a + 1 + gu << ' ' << a + gu << '\n';
    }
  o << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int c = 1; c <= nc; ++c) o << 4 * c << '\n';
  o << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int c = 0; c < nc; ++c) o << "9\n";
  o << "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">\n"
    << "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
       "format=\"ascii\">\n";
  for (int k = 0; k < n; ++k)
    o << fmt(f.u(k, 0)) << ' ' << fmt(f.u(k, 1)) << ' ' << fmt(f.u(k, 2)) << '\n';
  o << "</DataArray>\n";
  for (size_t c = 0; c < f.names.size(); ++c) {
    o << "<DataArray type=\"Float64\" Name=\"" << f.names[c] << "\" format=\"ascii\">\n";
    for (int k = 0; k < n; ++k) o << fmt(f.values(k, c)) << '\n';
    o << "</DataArray>\n";
  }
  o << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  write_text(file, o.str());
}

#ifdef KNIT_MACRO_HAVE_IO
void ResultsWriter::write_hdf5(const fs::path& file, const RunReport& report) const {
  auto h5 = io::H5File::create(file);
  io::write_provenance(h5, io::Provenance::current(case_.file));
  h5.set_attribute(".", "status", report.status == RunStatus::kCompleted ? "completed" : "stopped");
  h5.set_attribute(".", "message", report.message);
  h5.set_attribute(".", "units", "mm, N, MPa");
  h5.set_attribute(".", "material", case_.material->name());
  h5.set_attribute(".", "material_report", material_report_);
  h5.write_strings("case_json", {case_.text});
  // The CSV columns.
  const int n = static_cast<int>(rows_.size());
  Eigen::VectorXd lam(n), app(n), eps(n), res(n), sec(n);
  Eigen::VectorXi step(n), its(n);
  for (int k = 0; k < n; ++k) {
    const StepRow& r = rows_[k];
    step(k) = r.step, lam(k) = r.lambda, app(k) = r.applied, eps(k) = r.strain;
    its(k) = r.iterations, res(k) = r.residual, sec(k) = r.seconds;
  }
  h5.write("steps/step", step);
  h5.write("steps/load_factor", lam);
  if (case_.output.applied) {
    h5.write("steps/applied_displacement", app);
    h5.write("steps/strain", eps);
  }
  h5.write("steps/iterations", its);
  h5.write("steps/residual", res);
  h5.write("steps/seconds", sec);
  for (size_t c = 0; c < case_.output.reactions.size(); ++c) {
    Eigen::VectorXd f(n);
    for (int k = 0; k < n; ++k) f(k) = rows_[k].reactions[c];
    h5.write("steps/reactions/" + case_.output.reactions[c].name, f);
  }
  for (size_t c = 0; c < case_.output.points.size(); ++c) {
    Eigen::MatrixXd d(n, 3);
    for (int k = 0; k < n; ++k) d.row(k) = rows_[k].points[c].transpose();
    h5.write("steps/points/" + case_.output.points[c].name, d);
  }
  // Sampled fields of each output step.
  for (const Fields& f : steps_) {
    char g[64];
    std::snprintf(g, sizeof g, "fields/step_%04d", f.step);
    const std::string grp(g);
    h5.create_group(grp);
    h5.set_attribute(grp, "load_factor", f.lambda);
    h5.set_attribute(grp, "grid_u", case_.output.grid_u);
    h5.set_attribute(grp, "grid_v", case_.output.grid_v);
    h5.write(grp + "/X", f.X);
    h5.write(grp + "/x", f.x);
    h5.write(grp + "/displacement", f.u);
    for (size_t c = 0; c < f.names.size(); ++c) h5.write(grp + "/" + f.names[c], Eigen::VectorXd(f.values.col(c)));
  }
  h5.close();
}
#else
void ResultsWriter::write_hdf5(const fs::path&, const RunReport&) const {}
#endif

void ResultsWriter::finish(const RunReport& report) {
  // load_strain.csv
  std::ostringstream csv;
  csv << "# knit-macro results of " << case_.file << " (knitscale " << project_version() << ", git " << git_revision()
      << ")\n";
  if (report.status != RunStatus::kCompleted)
    csv << "# run stopped early: " << report.message << "\n";
  csv << "step,load_factor";
  if (case_.output.applied) csv << ",applied_displacement_mm,strain";
  for (const ReactionOutput& r : case_.output.reactions) csv << "," << r.name << "_N";
  for (const OutputPoint& p : case_.output.points)
    csv << "," << p.name << "_ux_mm," << p.name << "_uy_mm," << p.name << "_uz_mm";
  csv << ",iterations,residual,seconds\n";
  for (const StepRow& r : rows_) {
    csv << r.step << "," << fmt(r.lambda);
    if (case_.output.applied) csv << "," << fmt(r.applied) << "," << fmt(r.strain);
    for (double f : r.reactions) csv << "," << fmt(f);
    for (const auto& d : r.points) csv << "," << fmt(d(0)) << "," << fmt(d(1)) << "," << fmt(d(2));
    csv << "," << r.iterations << "," << fmt(r.residual) << "," << fmt(r.seconds) << "\n";
  }
  write_text(partial_ / "load_strain.csv", csv.str());
  // results.pvd
  std::ostringstream pvd;
  pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n<Collection>\n";
  for (const Fields& f : steps_) {
    char name[64];
    std::snprintf(name, sizeof name, "vtk/step_%04d.vtu", f.step);
    pvd << "<DataSet timestep=\"" << fmt(f.lambda) << "\" group=\"\" part=\"0\" file=\"" << name
        << "\"/>\n";
  }
  pvd << "</Collection>\n</VTKFile>\n";
  write_text(partial_ / "results.pvd", pvd.str());
  if (case_.output.hdf5) write_hdf5(partial_ / "results.h5", report);
  std::ostringstream sum;
  sum << "status: " << (report.status == RunStatus::kCompleted ? "completed" : "stopped") << "\n"
      << "converged steps: " << report.converged_steps
      << "\nlast load factor: " << fmt(report.last_lambda) << "\n";
  if (!report.message.empty()) sum << "message: " << report.message << "\n";
  sum << "material: " << case_.material->name() << "\n";
  if (!material_report_.empty()) sum << "material report: " << material_report_ << "\n";
  write_text(partial_ / "summary.txt", sum.str());
  // Put the directory in place: an existing one is moved aside first, then removed.
  fs::path old;
  if (fs::exists(target_)) {
    old = target_;
    old += ".old-" + std::to_string(::getpid());
    fs::rename(target_, old);
  }
  fs::rename(partial_, target_);
  if (!old.empty()) fs::remove_all(old);
  finished_ = true;
}

}  // namespace knit::macro
