// States and sensitivities of a design (knit/macro/design_sensitivity.hpp; docs/design.md).
#include "knit/macro/design_sensitivity.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/macro/patch.hpp"
#include "knit/macro/reduced_tangent.hpp"
#include "knit/macro/shell_kinematics.hpp"

namespace knit::macro {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// dS/dp_j of the knit material for one control value j at a time (set()): f_int assembled
/// with it is D_j = df_int/dp_j at fixed u. The basis functions N_j are tabulated per bound
/// point (bind_points), so the assembly loop does not allocate; where N_j = 0 (outside its
/// support) the stress is zero without evaluating the law.
///   stitch value:   dS/dp_j = N_j dS/dl                    (KnitMaterial::dS_dl)
///   knitting angle: dS/dp_j = N_j (-G_S S + C G_E E)       (eqs. 20-22)
/// G_E = dT_E/dalpha at 0 = [[0, 0, 1], [0, 0, -1], [-2, 2, 0]] (strains E11, E22, 2E12),
/// G_S = dT_S/dalpha at 0 = [[0, 0, 2], [0, 0, -2], [-1, 1, 0]] (stresses); rotations
/// compose, T_E(alpha + d) = T_E(d) T_E(alpha), so S = T^-1 Shat(T_E E) has that derivative.
class ControlValueDerivative : public Material {
 public:
  ControlValueDerivative(std::shared_ptr<Material> base, std::vector<DesignVariable> vars,
                         double angle_scale)
      : base_(std::move(base)), vars_(std::move(vars)), angle_scale_(angle_scale) {
    knit_ = dynamic_cast<const KnitMaterial*>(base_.get());
    if (!knit_) throw std::logic_error("design sensitivities need the knit material");
    GE_ << 0, 0, 1, 0, 0, -1, -2, 2, 0;
    GS_ << 0, 0, 2, 0, 0, -2, -1, 1, 0;
  }
  std::string name() const override { return "dS/dp"; }
  void set(int j) { j_ = j; }
  void bind_points(const std::vector<Eigen::Vector2d>& theta) override {
    base_->bind_points(theta);
    N_.resize(static_cast<Eigen::Index>(theta.size()), static_cast<Eigen::Index>(vars_.size()));
    for (std::size_t q = 0; q < theta.size(); ++q)
      N_.row(static_cast<Eigen::Index>(q)) = basis(theta[q]);
  }
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const override {
    MaterialResponse r;
    const double N = where.point_id >= 0 && where.point_id < N_.rows() ? N_(where.point_id, j_)
                                                                       : basis(where.theta)(j_);
    if (N == 0.0) return r;
    if (vars_[static_cast<std::size_t>(j_)].field == DesignVariable::Field::kStitchValue) {
      r.S = N * knit_->dS_dl(E, where);
    } else {
      const MaterialResponse m = base_->evaluate(E, where);
      r.S = N * (-GS_ * m.S + m.C * (GE_ * E));
    }
    return r;
  }

 private:
  /// N_j(theta) of every control value (alpha: rad per unit of the written value).
  Eigen::RowVectorXd basis(const Eigen::Vector2d& t) const {
    Eigen::RowVectorXd out = Eigen::RowVectorXd::Zero(static_cast<Eigen::Index>(vars_.size()));
    spline::SurfaceBasis lb, ab;
    knit_->stitch_value_field().basis(t(0), t(1), 0, lb);
    knit_->knitting_angle_field().basis(t(0), t(1), 0, ab);
    for (std::size_t j = 0; j < vars_.size(); ++j) {
      const bool l = vars_[j].field == DesignVariable::Field::kStitchValue;
      const spline::SurfaceBasis& b = l ? lb : ab;
      for (Eigen::Index k = 0; k < b.index.size(); ++k)
        if (b.index(k) == vars_[j].index)
          out(static_cast<Eigen::Index>(j)) = b.R(0, k) * (l ? 1.0 : angle_scale_);
    }
    return out;
  }

  std::shared_ptr<Material> base_;
  const KnitMaterial* knit_ = nullptr;
  std::vector<DesignVariable> vars_;
  double angle_scale_;
  Eigen::MatrixXd N_;
  int j_ = 0;
  Eigen::Matrix3d GE_, GS_;
};

/// K v with the full (unreduced) tangent, element by element.
Eigen::VectorXd multiply_full(const ShellModel& m, const ShellModel::Evaluation& ev,
                              const Eigen::VectorXd& v) {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(v.size());
  for (int e = 0; e < m.num_elements(); ++e) {
    const Eigen::VectorXi& cp = m.element_control_points(e);
    Eigen::VectorXd ve(3 * cp.size());
    for (Eigen::Index a = 0; a < cp.size(); ++a) ve.segment<3>(3 * a) = v.segment<3>(3 * cp(a));
    const Eigen::VectorXd ye = ev.Ke[static_cast<std::size_t>(e)] * ve;
    for (Eigen::Index a = 0; a < cp.size(); ++a) y.segment<3>(3 * cp(a)) += ye.segment<3>(3 * a);
  }
  return y;
}

double angle_unit_scale(const std::string& text, const std::string& file) {
  const nlohmann::json root = io::parse_json(text, file);
  const nlohmann::json::json_pointer p("/material/knitting_angle/unit");
  return root.contains(p) && root.at(p) == "deg" ? std::numbers::pi / 180.0 : 1.0;
}

}  // namespace

Case scaled_case(Case c, double lambda) {
  for (auto& bc : c.bcs)
    for (auto& v : bc.prescribe)
      if (v) *v *= lambda;
  for (auto& l : c.loads) l.value *= lambda;
  if (c.output.applied) c.output.applied->value *= lambda;
  return c;
}

DesignSolve::~DesignSolve() = default;

DesignSolve::DesignSolve(const std::string& text, const std::string& file,
                         const std::vector<DesignVariable>& vars, const std::vector<double>& levels,
                         bool with_sensitivities) {
  (void)design_values(text, file, vars);  // checks the variables
  c_ = parse_case(text, file);
  if (levels.empty()) throw InputError(file, "", "a design solve needs at least one load level");
  for (double l : levels)
    if (!(l > 0.0) || !std::isfinite(l))
      throw InputError(file, "", "the load factors of a design solve must be positive");
  const double lmax = *std::max_element(levels.begin(), levels.end());
  levels_.resize(levels.size());
  std::vector<bool> found(levels.size(), false);
  const auto t0 = Clock::now();
  problem_ = std::make_unique<Problem>(setup_problem(scaled_case(c_, lmax)));
  auto capture = [&](double scale, int only) {
    return [&, scale, only](const StepResult& s) {
      for (std::size_t k = 0; k < levels.size(); ++k)
        if ((only < 0 || static_cast<int>(k) == only) &&
            std::abs(s.lambda * scale - levels[k]) <= 1e-9 * lmax) {
          levels_[k].lambda = levels[k];
          levels_[k].u = s.u;
          found[k] = true;
        }
    };
  };
  auto fail = [&](const RunReport& r) {
    if (r.status == RunStatus::kCompleted && c_.material->failed_evaluations() == 0) return false;
    status_ = RunStatus::kNotConverged;
    message_ = r.message.empty() ? material_failure_message(r, c_.material->failed_evaluations())
                                 : r.message;
    return true;
  };
  if (fail(solve_load_steps(*problem_->model, problem_->dofs, problem_->fext, c_.solver,
                            capture(lmax, -1))))
    return;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (found[k]) continue;
    const Problem pk = setup_problem(scaled_case(c_, levels[k]));
    if (fail(solve_load_steps(*pk.model, pk.dofs, pk.fext, c_.solver,
                              capture(levels[k], static_cast<int>(k)))))
      return;
  }
  forward_seconds_ = since(t0);
  const auto t1 = Clock::now();
  with_d_ = with_sensitivities;
  std::shared_ptr<ControlValueDerivative> deriv;
  std::unique_ptr<ShellModel> dm;
  if (with_d_ && !vars.empty()) {
    deriv =
        std::make_shared<ControlValueDerivative>(c_.material, vars, angle_unit_scale(text, file));
    ShellOptions so;
    so.integration = c_.integration;
    so.threads = c_.threads;
    so.extra_quadrature_points = c_.extra_quadrature_points;
    dm = std::make_unique<ShellModel>(c_.surface, c_.thickness, deriv, so);
  }
  const ShellModel& m = *problem_->model;
  const DofMap& dofs = problem_->dofs;
  const SolverOptions& so = c_.solver;
  const int n = dofs.num_free();
  const bool sparse = so.linear_solver == LinearSolver::kSparse ||
                      (so.linear_solver == LinearSolver::kAuto && n > so.dense_limit);
  std::unique_ptr<ReducedTangent> K;
  for (Level& L : levels_) {
    ShellModel::Evaluation ev;
    m.evaluate(L.u, with_d_, ev);
    L.fint = ev.fint;
    if (!with_d_) continue;
    // The tangent at the converged state: assembled and factored once per level.
    if (!K)
      K = std::make_unique<ReducedTangent>(m, dofs, m.material().hyperelastic() && so.symmetric,
                                           sparse);
    K->assemble(ev.Ke);
    const Factorization f = K->factorize();
    if (!f.ok) {
      status_ = RunStatus::kNotConverged;
      message_ = "the tangent at the converged state is singular (sensitivities): " + f.why;
      return;
    }
    const auto nv = static_cast<Eigen::Index>(vars.size());
    L.du.resize(m.num_dofs(), nv);
    L.df.resize(m.num_dofs(), nv);
    for (Eigen::Index j = 0; j < nv; ++j) {
      deriv->set(static_cast<int>(j));
      ShellModel::Evaluation dev;
      dm->evaluate(L.u, false, dev);
      L.du.col(j) = dofs.expand(K->solve(-dofs.reduce(dev.fint)), 0.0);
      L.df.col(j) = multiply_full(m, ev, L.du.col(j)) + dev.fint;
    }
  }
  sensitivity_seconds_ = since(t1);
}

int DesignSolve::level(double lambda) const {
  for (std::size_t k = 0; k < levels_.size(); ++k)
    if (levels_[k].lambda == lambda) return static_cast<int>(k);
  throw std::out_of_range("no such load level in the design solve");
}

Sensitive DesignSolve::reaction(int k, const ReactionOutput& r) const {
  const ShellModel& m = *problem_->model;
  const Level& L = levels_.at(static_cast<std::size_t>(k));
  // A corner reaction sums over the corner's pad, corner_region(radius), as run_case writes it
  // (session 31: only the corner control point was read, so a design on an output with a
  // radius optimized another number than the one its run reports).
  // The support reaction as run_case writes it (the dead load at the points taken off; it
  // does not depend on the design, so the derivatives are those of f_int alone).
  const std::vector<int> points = reaction_points(m, r);
  Sensitive s;
  s.value = support_reaction(L.fint, problem_->fext, L.lambda, points, r.component);
  s.d.resize(L.df.cols());
  for (Eigen::Index j = 0; j < L.df.cols(); ++j)
    s.d(j) = sum_over(L.df.col(j), points, r.component);
  return s;
}

Sensitive DesignSolve::displacement(int k, const Eigen::Vector2d& theta, int component) const {
  const ShellModel& m = *problem_->model;
  const Level& L = levels_.at(static_cast<std::size_t>(k));
  Sensitive s;
  s.value = m.displacement(L.u, theta)(component);
  s.d.resize(L.du.cols());
  for (Eigen::Index j = 0; j < L.du.cols(); ++j)  // linear in u
    s.d(j) = m.displacement(L.du.col(j), theta)(component);
  return s;
}

Sensitive DesignSolve::strain(int k, const Eigen::Vector2d& theta, int component) const {
  const ShellModel& m = *problem_->model;
  const Level& L = levels_.at(static_cast<std::size_t>(k));
  spline::SurfaceBasis sb;
  m.surface().basis(theta(0), theta(1), 2, sb);
  const Eigen::MatrixXd& P = m.surface().control_points();
  SurfaceDerivs dX = SurfaceDerivs::Zero(), dx = SurfaceDerivs::Zero();
  for (Eigen::Index l = 0; l < sb.index.size(); ++l) {
    const int a = sb.index(l);
    dX += sb.R.col(l) * P.row(a);
    dx += sb.R.col(l) * (P.row(a) + L.u.segment<3>(3 * a).transpose());
  }
  const ReferencePoint ref = reference_point(dX, theta, 1.0);
  const CurrentPoint cur = current_point(dx, ref);
  // E = T eps (local Cartesian Voigt); eps11 = (a1.a1 - A11)/2, eps22 = (a2.a2 - A22)/2,
  // 2 eps12 = a1.a2 - A12: d eps = (a1.dv1, a2.dv2, dv1.a2 + a1.dv2), dv_a = sum R_l,a du_l.
  const double factor = component == 2 ? 0.5 : 1.0;
  Sensitive s;
  s.value = factor * (ref.T * cur.eps)(component);
  s.d.resize(L.du.cols());
  for (Eigen::Index j = 0; j < L.du.cols(); ++j) {
    Eigen::Vector3d dv1 = Eigen::Vector3d::Zero(), dv2 = Eigen::Vector3d::Zero();
    for (Eigen::Index l = 0; l < sb.index.size(); ++l) {
      const Eigen::Vector3d v = L.du.col(j).segment<3>(3 * sb.index(l));
      dv1 += sb.R(1, l) * v;
      dv2 += sb.R(2, l) * v;
    }
    const Eigen::Vector3d deps(cur.a1.dot(dv1), cur.a2.dot(dv2), dv1.dot(cur.a2) + cur.a1.dot(dv2));
    s.d(j) = factor * (ref.T * deps)(component);
  }
  return s;
}

}  // namespace knit::macro
