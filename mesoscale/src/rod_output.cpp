#include "knit/meso/rod/output.hpp"

#include "knit/io/atomic.hpp"
#include "knit/io/vtk.hpp"

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
  io::write_file_atomically(file, content);
}

void write_vtp(const std::filesystem::path& file, const std::vector<Polyline>& lines,
               const std::string& comment) {
  int npts = 0;
  for (const auto& l : lines) npts += static_cast<int>(l.points.rows());
  io::PolylineSet set;
  set.points.resize(npts, 3);
  io::RowMatrixXd F(npts, 3), M(npts, 3), D(npts, 3);
  std::vector<double> radius, rod;
  int r = 0;
  for (size_t k = 0; k < lines.size(); ++k) {
    const Polyline& l = lines[k];
    const int m = static_cast<int>(l.points.rows());
    set.points.middleRows(r, m) = l.points;
    F.middleRows(r, m) = l.force;
    M.middleRows(r, m) = l.moment;
    D.middleRows(r, m) = l.d1;
    std::vector<int> ids(m);
    for (int i = 0; i < m; ++i) ids[i] = r + i;
    set.lines.push_back(std::move(ids));
    radius.insert(radius.end(), l.radius.data(), l.radius.data() + l.radius.size());
    rod.push_back(static_cast<double>(k));
    r += m;
  }
  set.point_data.push_back(io::scalar_field("radius", radius));  // first scalar: active (Tube)
  set.point_data.push_back(io::vector_field("force", F));
  set.point_data.push_back(io::vector_field("moment", M));
  set.point_data.push_back(io::vector_field("d1", D));
  set.cell_data.push_back(io::scalar_field("rod", rod));
  io::write_vtp(file, set, io::VtkEncoding::Base64, comment);
}

void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& entries) {
  io::PvdCollection pvd(file);
  for (const auto& [t, f] : entries) pvd.add(t, file.parent_path() / f);
  pvd.write();
}

}  // namespace knit::meso::rod
