// The adjoint gradient of a reaction (knit/macro/design_gradient.hpp; docs/design.md).
#include "knit/macro/design_gradient.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseLU>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/macro/run.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

namespace {

std::string field_pointer(const DesignVariable& v) {
  return v.field == DesignVariable::Field::kStitchValue ? "/material/stitch_value"
                                                        : "/material/knitting_angle";
}

/// The JSON value of a design variable (checked: a control value of a spline field).
nlohmann::json& value_of(nlohmann::json& root, const DesignVariable& v, const std::string& file) {
  const std::string p = field_pointer(v);
  const nlohmann::json::json_pointer jp(p);
  if (!root.contains(jp) || !root.at(jp).is_object() || !root.at(jp).contains("values"))
    throw InputError(file, p,
                     "a design variable needs a spline field with control values here "
                     "(not a constant or an aligned field)");
  nlohmann::json& vals = root.at(jp).at("values");
  if (!vals.is_array() || v.index < 0 || v.index >= static_cast<int>(vals.size()))
    throw InputError(file, p + "/values",
                     "control value " + std::to_string(v.index) + " is outside the field's " +
                         std::to_string(vals.is_array() ? vals.size() : 0) + " values");
  return vals[static_cast<std::size_t>(v.index)];
}

/// dS/dp_j for a stitch-value control value: a central difference of the material at fixed
/// strain, (S(p + h e_j) - S(p - h e_j)) / 2h (INTERIM, until the energy law's dS/dl).
class StitchValueDerivative : public Material {
 public:
  StitchValueDerivative(std::shared_ptr<Material> plus, std::shared_ptr<Material> minus, double h)
      : plus_(std::move(plus)), minus_(std::move(minus)), h_(h) {}
  std::string name() const override { return "dS/dl"; }
  void bind_points(const std::vector<Eigen::Vector2d>& theta) override {
    plus_->bind_points(theta);
    minus_->bind_points(theta);
  }
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const override {
    MaterialResponse r;
    r.S = (plus_->evaluate(E, where).S - minus_->evaluate(E, where).S) / (2 * h_);
    return r;
  }

 private:
  std::shared_ptr<Material> plus_, minus_;
  double h_;
};

/// dS/dp_j for a knitting-angle control value, analytic through T(alpha) (eqs. 20-22):
/// S = T^-1 Shat(T_E E); rotations compose, T_E(alpha + d) = T_E(d) T_E(alpha), so
///   dS/dalpha = -G_S S + C G_E E,
/// G_E = dT_E/dalpha at 0 = [[0, 0, 1], [0, 0, -1], [-2, 2, 0]] (strains E11, E22, 2E12),
/// G_S = dT_S/dalpha at 0 = [[0, 0, 2], [0, 0, -2], [-1, 1, 0]] (stresses S11, S22, S12);
/// times dalpha/dp_j = N_j(theta), the field's basis function (alpha is linear in its control
/// values: N_j = alpha(p + e_j) - alpha(p), exact, with the field's unit).
class KnittingAngleDerivative : public Material {
 public:
  KnittingAngleDerivative(std::shared_ptr<Material> at_p, std::shared_ptr<Material> unit_step)
      : p_(std::move(at_p)), step_(std::move(unit_step)) {
    GE_ << 0, 0, 1, 0, 0, -1, -2, 2, 0;
    GS_ << 0, 0, 2, 0, 0, -2, -1, 1, 0;
  }
  std::string name() const override { return "dS/dalpha"; }
  void bind_points(const std::vector<Eigen::Vector2d>& theta) override { p_->bind_points(theta); }
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const override {
    const auto& kp = dynamic_cast<const KnitMaterial&>(*p_);
    const auto& ks = dynamic_cast<const KnitMaterial&>(*step_);
    const double Nj = ks.knitting_angle(where.theta) - kp.knitting_angle(where.theta);
    const MaterialResponse m = p_->evaluate(E, where);
    MaterialResponse r;
    r.S = Nj * (-GS_ * m.S + m.C * (GE_ * E));
    return r;
  }

 private:
  std::shared_ptr<Material> p_, step_;
  Eigen::Matrix3d GE_, GS_;
};

using Sparse = Eigen::SparseMatrix<double>;

Sparse assemble(const ShellModel& m, const ShellModel::Evaluation& ev) {
  std::vector<Eigen::Triplet<double>> t;
  for (int e = 0; e < m.num_elements(); ++e) {
    const Eigen::VectorXi& cp = m.element_control_points(e);
    const Eigen::MatrixXd& Ke = ev.Ke[static_cast<std::size_t>(e)];
    for (int a = 0; a < cp.size(); ++a)
      for (int i = 0; i < 3; ++i)
        for (int b = 0; b < cp.size(); ++b)
          for (int j = 0; j < 3; ++j)
            t.emplace_back(3 * cp(a) + i, 3 * cp(b) + j, Ke(3 * a + i, 3 * b + j));
  }
  Sparse K(m.num_dofs(), m.num_dofs());
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

/// Z (num_dofs x num_free): u = Z u_f + lambda g.
Sparse expansion(const DofMap& d) {
  std::vector<Eigen::Triplet<double>> t;
  const Eigen::VectorXd g = d.expand(Eigen::VectorXd::Zero(d.num_free()), 0.0);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(d.num_free());
  for (int k = 0; k < d.num_free(); ++k) {
    e.setZero();
    e(k) = 1.0;
    const Eigen::VectorXd col = d.expand(e, 0.0) - g;
    for (Eigen::Index r = 0; r < col.size(); ++r)
      if (col(r) != 0.0) t.emplace_back(static_cast<int>(r), k, col(r));
  }
  Sparse Z(d.num_dofs(), d.num_free());
  Z.setFromTriplets(t.begin(), t.end());
  return Z;
}

/// The case with its prescribed displacements and dead loads scaled by lambda: its state at
/// load factor 1 is the original case's state at lambda (the law has no history).
Case scaled(Case c, double lambda) {
  for (auto& bc : c.bcs)
    for (auto& v : bc.prescribe)
      if (v) *v *= lambda;
  for (auto& l : c.loads) l.value *= lambda;
  if (c.output.applied) c.output.applied->value *= lambda;
  return c;
}

}  // namespace

Case case_with_design(const std::string& text, const std::string& file,
                      const std::vector<DesignVariable>& vars, const std::vector<double>& values) {
  nlohmann::json root = io::parse_json(text, file);
  for (std::size_t k = 0; k < vars.size(); ++k) value_of(root, vars[k], file) = values.at(k);
  return parse_case(root.dump(1), file);
}

std::vector<double> design_values(const std::string& text, const std::string& file,
                                  const std::vector<DesignVariable>& vars) {
  nlohmann::json root = io::parse_json(text, file);
  std::vector<double> v;
  for (const auto& d : vars) {
    const nlohmann::json& x = value_of(root, d, file);
    if (!x.is_number()) throw InputError(file, field_pointer(d) + "/values", "must be numbers");
    v.push_back(x.get<double>());
  }
  return v;
}

ReactionGradient reaction_gradient(const std::string& text, const std::string& file,
                                   const std::vector<DesignVariable>& vars, int reaction,
                                   double lambda, const GradientOptions& opt) {
  const std::vector<double> p = design_values(text, file, vars);
  if (!(lambda > 0.0)) throw InputError(file, "", "the load factor of a gradient must be positive");
  const Case c = scaled(case_with_design(text, file, vars, p), lambda);
  if (reaction < 0 || reaction >= static_cast<int>(c.output.reactions.size()))
    throw InputError(file, "/output/reactions",
                     "no reaction " + std::to_string(reaction) + " among the case's outputs");
  const ReactionOutput& ro = c.output.reactions[static_cast<std::size_t>(reaction)];
  if (!ro.at_edge)
    throw InputError(file, "/output/reactions/" + std::to_string(reaction),
                     "the adjoint gradient needs an edge reaction");
  ReactionGradient out;
  const RunResult run = run_case(c, {});
  out.status = run.report.status;
  out.message = run.report.message;
  if (out.status != RunStatus::kCompleted) return out;

  const Problem prob = setup_problem(c);
  const ShellModel& m = *prob.model;
  ShellModel::Evaluation ev;
  m.evaluate(run.u, true, ev);
  out.J = edge_reaction(m, ev.fint, ro.edge, ro.component, ro.rows);
  // c: J = c^T f_int (the reaction is linear in f_int).
  Eigen::VectorXd cvec = Eigen::VectorXd::Zero(m.num_dofs()), unit = cvec;
  for (int r = 0; r < m.num_dofs(); ++r) {
    unit(r) = 1.0;
    cvec(r) = edge_reaction(m, unit, ro.edge, ro.component, ro.rows);
    unit(r) = 0.0;
  }
  // The adjoint: (Z^T K Z)^T psi = Z^T K^T c.
  const Sparse K = assemble(m, ev);
  const Sparse Z = expansion(prob.dofs);
  const Sparse KffT = Sparse((Z.transpose() * K * Z).transpose());
  Eigen::SparseLU<Sparse> lu;
  lu.compute(KffT);
  if (lu.info() != Eigen::Success) {
    out.status = RunStatus::kNotConverged;
    out.message = "the tangent at the converged state is singular (adjoint)";
    return out;
  }
  const Eigen::VectorXd rhs = Z.transpose() * (K.transpose() * cvec);
  const Eigen::VectorXd psi = lu.solve(rhs);
  const Eigen::VectorXd w = cvec - Z * psi;  // dJ/dp_j = w^T df_int/dp_j

  ShellOptions so;
  so.integration = c.integration;
  so.threads = c.threads;
  out.dJ.resize(static_cast<Eigen::Index>(vars.size()));
  for (std::size_t j = 0; j < vars.size(); ++j) {
    std::shared_ptr<Material> dmat;
    if (vars[j].field == DesignVariable::Field::kStitchValue) {
      // Central difference; one-sided at the end of the database's loop lengths (a step
      // beyond it is refused by the material factory).
      const double h = opt.material_step * std::max(1.0, std::abs(p[j]));
      auto material_at = [&](double step, double& used) {
        std::vector<double> q = p;
        q[j] += step;
        try {
          used = std::abs(step);
          return case_with_design(text, file, vars, q).material;
        } catch (const InputError&) {
          used = 0.0;
          return c.material;
        }
      };
      double hp = 0.0, hm = 0.0;
      auto plus = material_at(h, hp);
      auto minus = material_at(-h, hm);
      dmat = std::make_shared<StitchValueDerivative>(plus, minus, 0.5 * (hp + hm));
    } else {
      std::vector<double> pp = p;
      pp[j] += 1.0;
      dmat = std::make_shared<KnittingAngleDerivative>(
          case_with_design(text, file, vars, p).material,
          case_with_design(text, file, vars, pp).material);
    }
    const ShellModel dm(c.surface, c.thickness, dmat, so);
    ShellModel::Evaluation dev;
    dm.evaluate(run.u, false, dev);
    out.dJ(static_cast<Eigen::Index>(j)) = w.dot(dev.fint);
  }
  return out;
}

}  // namespace knit::macro
