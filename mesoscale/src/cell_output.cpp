// Output of the unit cell: forwards to the shared writers of knit/io (vtk.hpp, atomic.hpp).
#include "knit/meso/cell/output.hpp"

#include "knit/io/atomic.hpp"
#include "knit/io/vtk.hpp"

namespace knit::meso::cell {

void write_text_atomic(const std::string& path, const std::string& text) {
  io::write_file_atomically(path, text);
}

void write_polylines_vtp(const std::string& path, const std::vector<Polyline>& lines, double r) {
  io::PolylineSet set;
  std::size_t npts = 0;
  for (const auto& l : lines) npts += l.points.size();
  set.points.resize(static_cast<Eigen::Index>(npts), 3);
  std::vector<double> piece, image;
  int k = 0;
  for (const auto& l : lines) {
    std::vector<int> idx;
    for (const auto& p : l.points) {
      set.points.row(k) = p.transpose();
      idx.push_back(k++);
    }
    set.lines.push_back(std::move(idx));
    piece.push_back(l.piece);
    image.push_back(l.image);
  }
  set.point_data.push_back(io::scalar_field("radius", std::vector<double>(npts, r)));
  set.cell_data.push_back(io::scalar_field("piece", piece));
  set.cell_data.push_back(io::scalar_field("image", image));
  io::write_vtp(path, set);
}

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& steps) {
  io::PvdCollection pvd(path);
  for (const auto& [t, f] : steps) pvd.add(t, f);
  pvd.write();
}

}  // namespace knit::meso::cell
