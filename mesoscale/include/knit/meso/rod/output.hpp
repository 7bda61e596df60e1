// Output of rod states: sampled centerlines as VTK PolyData (.vtp) polylines with a "radius"
// point array (ParaView: Tube filter, "Vary Radius: By Absolute Scalar" on radius, draws the
// yarn), the spatial internal force n, moment m and director d1; and a PVD collection.
// Written through knit/io/vtk.hpp (base64 XML), atomically (temporary + rename).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "knit/meso/rod/rod_system.hpp"

namespace knit::meso::rod {

/// One sampled centerline.
struct Polyline {
  std::string name;
  Eigen::MatrixXd points;  ///< k x 3
  Eigen::VectorXd radius;  ///< k
  Eigen::MatrixXd force;   ///< k x 3 spatial n [N]
  Eigen::MatrixXd moment;  ///< k x 3 spatial m [N mm]
  Eigen::MatrixXd d1;      ///< k x 3 first director (cross-section orientation)
};

/// Samples every rod at `samples_per_element` points per knot span (plus the end point).
std::vector<Polyline> sample_centerlines(const RodSystem& sys, const Eigen::VectorXd& x,
                                         int samples_per_element = 8);

/// Writes the polylines as one .vtp file (one VTK line cell per rod). `comment` (e.g.
/// provenance) goes into an XML comment at the top.
void write_vtp(const std::filesystem::path& file, const std::vector<Polyline>& lines,
               const std::string& comment = "");

/// Writes a ParaView .pvd collection of (time, relative file name) pairs.
void write_pvd(const std::filesystem::path& file,
               const std::vector<std::pair<double, std::string>>& entries);

/// Writes `content` to `file` atomically (temporary in the same directory, then rename).
void write_text_atomically(const std::filesystem::path& file, const std::string& content);

}  // namespace knit::meso::rod
