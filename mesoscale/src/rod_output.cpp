#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "knit/meso/rod/output.hpp"

namespace knit::meso::rod {

std::vector<Polyline> sample_centerlines(const RodSystem& sys, const Eigen::VectorXd& x,
                                         int samples_per_element) {
  std::vector<Polyline> out;
  const int spe = std::max(1, samples_per_element);
  for (int k = 0; k < sys.num_rods(); ++k) {
    const auto br = sys.spec(k).basis.breakpoints();
    std::vector<double> xi;
    for (size_t e = 0; e + 1 < br.size(); ++e)
      for (int i = 0; i < spe; ++i) xi.push_back(br[e] + (br[e + 1] - br[e]) * i / spe);
    xi.push_back(br.back());
    Polyline pl;
    pl.name = sys.spec(k).name;
    const int m = static_cast<int>(xi.size());
    pl.points.resize(m, 3);
    pl.force.resize(m, 3);
    pl.moment.resize(m, 3);
    pl.d1.resize(m, 3);
    pl.radius = Eigen::VectorXd::Constant(m, 0.5 * sys.spec(k).section.d);
    for (int i = 0; i < m; ++i) {
      const PointState s = sys.state(k, xi[i], x);
      pl.points.row(i) = s.r.transpose();
      pl.force.row(i) = s.n.transpose();
      pl.moment.row(i) = s.m.transpose();
      pl.d1.row(i) = s.R.col(0).transpose();
    }
    out.push_back(std::move(pl));
  }
  return out;
}

void write_text_atomically(const std::filesystem::path& file, const std::string& content) {
  const std::filesystem::path tmp =
      file.parent_path() / ("." + file.filename().string() + ".tmp-" + std::to_string(::getpid()));
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
    f << content;
    f.close();
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot rename onto " + file.string());
  }
}

namespace {

void data_array(std::ostringstream& o, const char* name, const Eigen::MatrixXd& M, int ncomp) {
  o << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"" << ncomp
    << "\" format=\"ascii\">\n          ";
  for (int i = 0; i < M.rows(); ++i)
    for (int c = 0; c < ncomp; ++c) o << M(i, c) << ' ';
  o << "\n        </DataArray>\n";
}

}  // namespace

void write_vtp(const std::filesystem::path& file, const std::vector<Polyline>& lines,
               const std::string& comment) {
  std::ostringstream o;
  o.precision(10);
  o << "<?xml version=\"1.0\"?>\n";
  if (!comment.empty()) o << "<!-- " << comment << " -->\n";
  int npts = 0;
  for (const auto& l : lines) npts += static_cast<int>(l.points.rows());
  auto stack = [&](auto get, int ncomp) {
    Eigen::MatrixXd M(npts, ncomp);
    int r = 0;
    for (const auto& l : lines) {
      const Eigen::MatrixXd& A = get(l);
      M.middleRows(r, A.rows()) = A;
      r += static_cast<int>(A.rows());
    }
    return M;
  };
  o << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n"
    << "    <Piece NumberOfPoints=\"" << npts << "\" NumberOfLines=\"" << lines.size() << "\">\n"
    << "      <Points>\n";
  data_array(o, "Points",
             stack([](const Polyline& l) -> const Eigen::MatrixXd& { return l.points; }, 3), 3);
  o << "      </Points>\n      <Lines>\n"
    << "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n          ";
  for (int i = 0; i < npts; ++i) o << i << ' ';
  o << "\n        </DataArray>\n        <DataArray type=\"Int32\" Name=\"offsets\" "
       "format=\"ascii\">\n          ";
  int off = 0;
  for (const auto& l : lines) o << (off += static_cast<int>(l.points.rows())) << ' ';
  o << "\n        </DataArray>\n      </Lines>\n      <PointData Scalars=\"radius\">\n";
  Eigen::MatrixXd rad(npts, 1);
  {
    int r = 0;
    for (const auto& l : lines) {
      rad.middleRows(r, l.radius.size()) = l.radius;
      r += static_cast<int>(l.radius.size());
    }
  }
  data_array(o, "radius", rad, 1);
  data_array(o, "force",
             stack([](const Polyline& l) -> const Eigen::MatrixXd& { return l.force; }, 3), 3);
  data_array(o, "moment",
             stack([](const Polyline& l) -> const Eigen::MatrixXd& { return l.moment; }, 3), 3);
  data_array(o, "d1", stack([](const Polyline& l) -> const Eigen::MatrixXd& { return l.d1; }, 3),
             3);
  o << "      </PointData>\n      <CellData>\n"
    << "        <DataArray type=\"Int32\" Name=\"rod\" format=\"ascii\">\n          ";
  for (size_t i = 0; i < lines.size(); ++i) o << i << ' ';
  o << "\n        </DataArray>\n      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  write_text_atomically(file, o.str());
}

void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& entries) {
  std::ostringstream o;
  o.precision(12);
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [t, f] : entries)
    o << "    <DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << f << "\"/>\n";
  o << "  </Collection>\n</VTKFile>\n";
  write_text_atomically(file, o.str());
}

}  // namespace knit::meso::rod
