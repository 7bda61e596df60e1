// Dirichlet conditions by elimination: each DOF is free, fixed (u = 0), prescribed
// (u = lambda * value, ramped with the load factor) or tied to other DOFs (u_a = u_b, used
// by clamped edges and symmetry planes to keep the cross-edge slope). Ties form groups; a
// group is constrained if any member is, with that member's value.
//
// The reduced unknowns are one per free group: u = Z u_free + lambda g, with Z a 0/1 matrix;
// reduced residual Z^T r, reduced tangent Z^T K Z (scatter-add through free_index).
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace knit::macro {

/// Whether two prescribed values of one DOF conflict: they differ by more than round-off,
/// 1e-14 (1 + |b|) mm. One rule for Constraints, DofMap and the case loader's message.
inline bool values_conflict(double a, double b) {
  return std::abs(a - b) > 1e-14 * (1.0 + std::abs(b));
}

class Constraints {
 public:
  explicit Constraints(int num_dofs);
  int num_dofs() const { return n_; }
  void fix(int dof) { prescribe(dof, 0.0); }
  /// u(dof) = lambda * value. A DOF given two different values is a conflict (see build).
  void prescribe(int dof, double value);
  void tie(int a, int b);

  friend class DofMap;

 private:
  int n_;
  std::vector<std::optional<double>> value_;
  std::vector<std::pair<int, int>> ties_;
};

/// Thrown by DofMap for contradictory constraints; names the DOF.
class ConstraintConflict : public std::runtime_error {
 public:
  ConstraintConflict(int dof, const std::string& what, int other = -1)
      : std::runtime_error(what), dof_(dof), other_(other) {}
  int dof() const { return dof_; }
  /// The DOF whose prescribed value the group already held (a tied group's conflict), else -1.
  int other() const { return other_; }

 private:
  int dof_;
  int other_;
};

class DofMap {
 public:
  DofMap() = default;
  explicit DofMap(const Constraints& c);
  int num_dofs() const { return static_cast<int>(free_.size()); }
  int num_free() const { return nfree_; }
  /// Reduced index of a DOF, or -1 if it is constrained.
  int free_index(int dof) const { return free_[dof]; }
  bool constrained(int dof) const { return free_[dof] < 0; }
  /// Prescribed value at lambda = 1 of a constrained DOF (0 for fixed ones).
  double value(int dof) const { return value_(dof); }
  /// Full displacement from the reduced unknowns at load factor lambda.
  Eigen::VectorXd expand(const Eigen::VectorXd& ufree, double lambda) const;
  /// Z^T r.
  Eigen::VectorXd reduce(const Eigen::VectorXd& full) const;
  /// Reduced unknowns of a full vector (the first DOF of each free group).
  Eigen::VectorXd restrict(const Eigen::VectorXd& full) const;

  /// Looks for an infinitesimal rigid-body motion of the control net X (ncp x 3) that the
  /// constraints do not prevent. Returns a description ("translation along (0, 0, 1)",
  /// "rotation about the axis (...) through (...)") or nullopt if every motion is blocked.
  std::optional<std::string> unconstrained_rigid_mode(const Eigen::MatrixXd& X) const;

 private:
  std::vector<int> free_, root_;
  Eigen::VectorXd value_;
  int nfree_ = 0;
};

}  // namespace knit::macro
