// VTK XML writers for ParaView (format: "VTK User's Guide", 11th ed., "VTK File Formats", XML
// section): unstructured grids of quads (.vtu) for shell surfaces sampled on a structured
// grid, polylines (.vtp) for yarn centerlines, and collections (.pvd) for time series.
//
// * Data are inline, either ASCII or base64 "binary" (uncompressed: base64 of a UInt64 byte
//   count followed by the little-endian values, encoded together). Points are Float64,
//   connectivity/offsets Int64, cell types UInt8.
// * Every file is written atomically (temporary + rename, see atomic.hpp).
// * Point/cell data: scalars (1 component), vectors (3), tensors (9, row-major 3x3) or any
//   number of named components (e.g. Voigt (E11, E22, 2E12)). The first 1-, 3- and
//   9-component point arrays become ParaView's active Scalars, Vectors and Tensors; put a
//   "radius" array first in a PolylineSet so that the Tube filter ("Vary Radius: By Absolute
//   Scalar") draws yarns with their radius.
// * `comment` (e.g. Provenance::to_json_string()) is written as an XML comment after the
//   header line, each "--" (not allowed there) as "-\u002d", which JSON reads back as "--".
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "knit/io/matrix_types.hpp"

namespace knit::io {

enum class VtkEncoding { Ascii, Base64 };

/// A named data array attached to points or cells.
struct VtkField {
  std::string name;
  int components = 1;                        ///< values per point/cell
  std::vector<double> values;                ///< entity-major: values[k*components + c]
  std::vector<std::string> component_names;  ///< optional (ParaView shows them)
};

/// One value per entity.
VtkField scalar_field(std::string name, std::vector<double> values);
/// n x 3 (or n x 2, padded with z = 0) vectors.
VtkField vector_field(std::string name, const Eigen::Ref<const RowMatrixXd>& v);
/// n x 9 (3x3 row-major) or n x 4 (2x2 row-major, padded into 3x3 with zeros) tensors.
VtkField tensor_field(std::string name, const Eigen::Ref<const RowMatrixXd>& t);
/// n x k values with component names, e.g. Voigt strains {"E11", "E22", "2E12"}.
VtkField components_field(std::string name, const Eigen::Ref<const RowMatrixXd>& v,
                          std::vector<std::string> component_names);

/// A surface mesh of quadrilaterals.
struct QuadMesh {
  RowMatrixXd points;  ///< n x 3 (n x 2 is padded with z = 0)
  RowMatrixXi quads;   ///< m x 4 point indices, counter-clockwise
  std::vector<VtkField> point_data;
  std::vector<VtkField> cell_data;
};

/// Quads of a structured grid of nu x nv points with point index i + nu*j (u fastest, the
/// ordering of SplineSurface control points): (nu-1)(nv-1) quads, counter-clockwise in (u, v).
RowMatrixXi structured_quads(int nu, int nv);
/// A QuadMesh from points sampled on an nu x nv grid (index i + nu*j).
QuadMesh structured_quad_mesh(int nu, int nv, const RowMatrixXd& points);

/// Polylines (yarn centerlines): each line is a list of point indices.
struct PolylineSet {
  RowMatrixXd points;  ///< n x 3 (n x 2 is padded with z = 0)
  std::vector<std::vector<int>> lines;
  std::vector<VtkField> point_data;  ///< e.g. scalar_field("radius", ...) first
  std::vector<VtkField> cell_data;   ///< one value per polyline
};

/// Writes a .vtu (UnstructuredGrid). Throws std::invalid_argument (bad sizes/indices) or
/// std::runtime_error (I/O), naming the file.
void write_vtu(const std::filesystem::path& file, const QuadMesh& mesh,
               VtkEncoding encoding = VtkEncoding::Base64, const std::string& comment = "");
/// Writes a .vtp (PolyData with Lines).
void write_vtp(const std::filesystem::path& file, const PolylineSet& lines,
               VtkEncoding encoding = VtkEncoding::Base64, const std::string& comment = "");

/// A .pvd collection (time step -> dataset file). Rewritten atomically by write(), so it can be
/// refreshed after every step and is valid if the run stops.
class PvdCollection {
 public:
  explicit PvdCollection(std::filesystem::path file);
  /// `dataset` is stored relative to the .pvd's directory (a bare file name as given).
  void add(double time, const std::filesystem::path& dataset, int part = 0);
  void write() const;
  std::size_t size() const { return entries_.size(); }
  const std::filesystem::path& file() const { return file_; }

 private:
  struct Entry {
    double time;
    int part;
    std::string file;
  };
  std::filesystem::path file_;
  std::vector<Entry> entries_;
};

/// Base64 (RFC 4648, with padding); exposed for tests.
std::string base64_encode(const void* data, std::size_t bytes);

}  // namespace knit::io
