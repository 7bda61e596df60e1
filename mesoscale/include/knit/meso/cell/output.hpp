// Minimal output of the unit cell for viewing in ParaView: VTK XML PolyData (.vtp) polylines
// with a "radius" point array (use the Tube filter with "Vary radius by scalar" / radius
// factor 1), an integer "piece" and "image" cell array, and PVD collections for paths.
// Kept behind these functions until knit/io/vtk.hpp lands on main (then they forward to it).
// Files are written atomically (temporary file, then rename).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace knit::meso::cell {

struct Polyline {
  std::vector<Eigen::Vector3d> points;
  int piece = 0;  ///< which curve of the cell
  int image = 0;  ///< 0: the cell itself, k > 0: a periodic neighbour
};

/// Writes the polylines to `path` (ASCII .vtp), every point carrying radius r.
void write_polylines_vtp(const std::string& path, const std::vector<Polyline>& lines, double r);

/// Writes a ParaView collection (.pvd) listing (time, file) pairs; files relative to the pvd.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& steps);

/// Writes `text` to `path` atomically.
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace knit::meso::cell
