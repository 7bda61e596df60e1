// A macroscale case: one NURBS patch, its refinement, material, boundary conditions, dead
// loads, solver and output settings (docs/case-format.md, schemas/case.schema.json).
// Plain structs: the JSON lives only in case_loader.cpp and material_factory.cpp.
// Units: lengths mm, forces N, stresses and moduli MPa (any consistent set works for the
// verification cases, which use the literature's dimensionless units).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "knit/macro/material.hpp"
#include "knit/macro/newton.hpp"
#include "knit/macro/patch.hpp"
#include "knit/macro/section.hpp"
#include "knit/spline/surface.hpp"

namespace knit::macro {

/// One entry of "boundary_conditions". Targets: an edge's control-point row, a corner's
/// control point, or every control point ("all": planar problems fixing z).
struct BoundaryCondition {
  enum class Target { kEdge, kCorner, kAll };
  Target target = Target::kEdge;
  Edge edge = Edge::kU0;
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();
  std::array<bool, 3> fix = {false, false, false};
  std::array<std::optional<double>, 3> prescribe;  ///< displacement at load factor 1 (mm)
  bool clamp = false;  ///< tie the second row to the edge row (zero rotation about the edge)
  int symmetry = -1;   ///< plane normal component: fix it on the edge row, tie the others
  /// Corner targets: act on every control point of corner_region(radius) (mm; 0 = the corner
  /// control point alone). A prescribed displacement then moves the region as a rigid pad.
  double radius = 0.0;
  std::string pointer;  ///< JSON pointer of the entry (for messages)
};

/// Whether a condition of `bcs` clamps `edge` (its second row of control points tied to it).
inline bool edge_is_clamped(const std::vector<BoundaryCondition>& bcs, Edge edge) {
  for (const BoundaryCondition& bc : bcs)
    if (bc.clamp && bc.target == BoundaryCondition::Target::kEdge && bc.edge == edge) return true;
  return false;
}

struct Load {
  enum class Kind { kPoint, kEdge, kArea };
  Kind kind = Kind::kPoint;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();     ///< point loads: parametric point
  Edge edge = Edge::kU0;                            ///< edge loads
  Eigen::Vector3d value = Eigen::Vector3d::Zero();  ///< N, N/mm or N/mm^2
};

struct OutputPoint {
  std::string name;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
};

/// Sum of the internal forces in `component` over the control points of `rows` rows of an edge,
/// or at a corner control point.
struct ReactionOutput {
  std::string name;
  bool at_edge = true;
  Edge edge = Edge::kU0;
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();
  int component = 0;
  int rows = 1;
  double radius = 0.0;  ///< corners: sum over corner_region(radius) (the pad of a corner BC)
};

/// The applied displacement Delta (the prescribed value of a component on an edge or corner,
/// times the load factor) and the strain Delta / gauge_length (paper Sect. 2.3: eps = Delta/L).
struct AppliedDisplacement {
  bool at_edge = true;
  Edge edge = Edge::kV1;
  Eigen::Vector2d corner = Eigen::Vector2d::Ones();
  int component = 1;
  double gauge_length = 1.0;
  double value = 0.0;  ///< the prescribed value at load factor 1 (filled by the loader)
};

struct OutputOptions {
  int grid_u = 21, grid_v = 21;  ///< VTU sample grid
  int every = 1;                 ///< write a VTU file every n-th converged step (and the last)
  bool vtk = true, hdf5 = true;
  std::vector<OutputPoint> points;
  std::vector<ReactionOutput> reactions;
  std::optional<AppliedDisplacement> applied;
};

struct Case {
  std::string file;  ///< path of the case file
  std::string text;  ///< the case JSON as read (stored with the outputs)
  /// /units as declared ("" when absent): the outputs' unit labels follow it (ResultsWriter;
  /// a knit case is refused unless it is "mm, N, MPa").
  std::string units;
  std::string description;
  spline::SplineSurface input_surface;  ///< the patch as given
  spline::SplineSurface surface;        ///< after refinement
  double thickness = 0.0;
  std::shared_ptr<Material> material;
  ThicknessIntegration integration = ThicknessIntegration::kGauss3;
  int threads = 0;                  ///< assembly threads; 0: automatic (ShellOptions::threads)
  int extra_quadrature_points = 0;  ///< ShellOptions::extra_quadrature_points
  std::vector<BoundaryCondition> bcs;
  std::vector<Load> loads;
  SolverOptions solver;
  OutputOptions output;
};

/// Reads, validates and sets up a case. Every problem throws knit::InputError naming the file
/// and the JSON pointer of the field.
Case load_case(const std::string& path);
/// The same from text (file_label is used in messages).
Case parse_case(const std::string& text, const std::string& file_label);

}  // namespace knit::macro
