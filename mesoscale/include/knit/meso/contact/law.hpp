// Constitutive laws of yarn-to-yarn contact (paper Sect. 2.1.2: "a suitable nonlinear law for
// the scaling of the contact penalty force, that only mildly penalizes initial penetrations",
// Coulomb friction with mu = 0.15).
//
// Normal law (choice, documented in docs/unit-cell.md): quadratic-linear penalty on the gap
// g = |x_s - x_m| - d (d = yarn diameter; g < 0 is a penetration), shifted by an allowance g0
// for the flattening of the soft yarn cross-sections (a heuristic of the kind the paper describes:
// the initial overlaps of the compact loops, up to ~0.16 mm for 4.5 mm, cost little), as a line
// load [N/mm], with gh = g + g0:
//   p = 0                          gh >= 0
//   p = k_N gh^2 / (2 delta)       -delta < gh < 0     (soft onset)
//   p = k_N (-gh - delta/2)        gh <= -delta        (linear, stiffness k_N)
// C1 at gh = 0 and gh = -delta. Energy Pi(g) = int_g^{-g0} p.
//
// Friction (choice): regularized Coulomb law along the master tangent with an elastic stick
// penalty k_T [N/mm^2] and the return mapping of elastoplasticity (Wriggers, Computational
// Contact Mechanics, Sect. 5.2). The tangential gap is e = |x_m,u| (u - u_anchor), u the closest
// point on the master, u_anchor the history variable (the master parameter at which the slave
// point sticks). Trial f_T = -k_T e; if |f_T| > mu p: slip, f_T = -mu p sign(e) and the anchor is
// moved so that k_T |e| = mu p.
#pragma once

namespace knit::meso::contact {

struct PenaltyLaw {
  double k_N = 1000.0;  ///< linear penalty stiffness [N/mm per mm of yarn = MPa]
  double delta = 0.05;  ///< penetration beyond g0 at which the law becomes linear [mm]
  double g0 = 0.14;     ///< penetration allowance (cross-section flattening) [mm]

  struct Value {
    double p = 0;       ///< line load magnitude [N/mm], >= 0
    double dp_dg = 0;   ///< derivative w.r.t. the gap (<= 0)
    double energy = 0;  ///< Pi(g) = int_g^0 p(s) ds [N]
  };
  Value eval(double g_in) const {
    Value v;
    const double g = g_in + g0;
    if (g >= 0) return v;
    if (g > -delta) {
      v.p = k_N * g * g / (2 * delta);
      v.dp_dg = k_N * g / delta;
      v.energy = -k_N * g * g * g / (6 * delta);
    } else {
      v.p = k_N * (-g - 0.5 * delta);
      v.dp_dg = -k_N;
      v.energy = k_N * delta * delta / 6 + k_N * (0.5 * g * g + 0.5 * delta * g);
    }
    return v;
  }
};

struct FrictionLaw {
  double mu = 0.15;   ///< Coulomb coefficient (paper)
  double k_T = 20.0;  ///< stick (tangential) penalty [N/mm per mm of slip per mm of yarn]
};

}  // namespace knit::meso::contact
