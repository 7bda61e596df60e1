// Minimal VTP / PVD writers: see knit/meso/cell/output.hpp.
#include "knit/meso/cell/output.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace knit::meso::cell {

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw std::runtime_error("cannot write " + tmp);
    f << text;
    if (!f) throw std::runtime_error("error writing " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

void write_polylines_vtp(const std::string& path, const std::vector<Polyline>& lines, double r) {
  std::size_t npts = 0;
  for (const auto& l : lines) npts += l.points.size();
  std::ostringstream o;
  o.precision(10);
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
       "byte_order=\"LittleEndian\">\n<PolyData>\n<Piece NumberOfPoints=\""
    << npts << "\" NumberOfLines=\"" << lines.size() << "\">\n";
  o << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& l : lines)
    for (const auto& p : l.points) o << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  o << "</DataArray></Points>\n<PointData Scalars=\"radius\">\n"
       "<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < npts; ++i) o << r << '\n';
  o << "</DataArray></PointData>\n<CellData>\n"
       "<DataArray type=\"Int32\" Name=\"piece\" format=\"ascii\">\n";
  for (const auto& l : lines) o << l.piece << '\n';
  o << "</DataArray>\n<DataArray type=\"Int32\" Name=\"image\" format=\"ascii\">\n";
  for (const auto& l : lines) o << l.image << '\n';
  o << "</DataArray></CellData>\n<Lines>\n"
       "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  std::size_t k = 0;
  for (const auto& l : lines) {
    for (std::size_t i = 0; i < l.points.size(); ++i) o << k++ << ' ';
    o << '\n';
  }
  o << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  k = 0;
  for (const auto& l : lines) o << (k += l.points.size()) << '\n';
  o << "</DataArray></Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  write_text_atomic(path, o.str());
}

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& steps) {
  std::ostringstream o;
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, f] : steps)
    o << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << f << "\"/>\n";
  o << "</Collection>\n</VTKFile>\n";
  write_text_atomic(path, o.str());
}

}  // namespace knit::meso::cell
