// The energy-based response surface (see knit/material/energy_law.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "knit/material/energy_law.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::material {

int RidgeDirections::functions() const {
  return function_of.empty() ? 0 : *std::max_element(function_of.begin(), function_of.end()) + 1;
}

RidgeDirections mirror_closed(const std::vector<Eigen::Vector3d>& base) {
  std::vector<Eigen::Vector3d> dirs;
  std::vector<int> fn;
  auto add = [&](const Eigen::Vector3d& d, int g) {
    // Parallel directions of different functions duplicate each other. The mirror of pure
    // shear (0, 0, 1) is its opposite: f(2E12) + f(-2E12) with one f, the even shear term.
    for (std::size_t k = 0; k < dirs.size(); ++k)
      if (fn[k] != g && std::abs(std::abs(dirs[k].dot(d)) - 1.0) < 1e-12)
        throw std::invalid_argument("ridge directions: two directions are parallel");
    dirs.push_back(d);
    fn.push_back(g);
  };
  int g = 0;
  for (const auto& b : base) {
    const double n = b.norm();
    if (!(n > 0.0) || !std::isfinite(n))
      throw std::invalid_argument("ridge directions: zero or non-finite direction");
    const Eigen::Vector3d d = b / n;
    add(d, g);
    if (d(2) != 0.0) add(Eigen::Vector3d(d(0), d(1), -d(2)), g);
    ++g;
  }
  RidgeDirections r;
  r.d.resize(static_cast<Eigen::Index>(dirs.size()), 3);
  for (std::size_t k = 0; k < dirs.size(); ++k)
    r.d.row(static_cast<Eigen::Index>(k)) = dirs[k].transpose();
  r.function_of = std::move(fn);
  return r;
}

RidgeDirections default_ridge_directions() {
  std::vector<Eigen::Vector3d> b;
  const double pi = 3.14159265358979323846;
  // Fibre-like: the normal strain along theta, E_nn = c^2 E11 + s^2 E22 + c s (2 E12). The
  // mirror of theta is 180 - theta, so theta in [0, 90] spans the set with its mirrors.
  for (int deg = 0; deg <= 90; deg += 15) {
    const double c = std::cos(deg * pi / 180), s = std::sin(deg * pi / 180);
    b.emplace_back(c * c, s * s, std::abs(c * s) < 1e-15 ? 0.0 : c * s);
  }
  // Area-like (membrane dilatation, distortion, stretch with lateral contraction).
  b.emplace_back(1, 1, 0);
  b.emplace_back(1, -1, 0);
  b.emplace_back(1, -0.5, 0);
  b.emplace_back(-0.5, 1, 0);
  // Shear coupled with stretch, and pure shear.
  b.emplace_back(1, 0, 1);
  b.emplace_back(0, 1, 1);
  b.emplace_back(1, -1, 1);  // (1, 1, 1) is the fibre at 45 deg
  b.emplace_back(0, 0, 1);
  return mirror_closed(b);
}

void validate(const EnergyLawData& d) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("energy law: " + m); };
  if (!(std::isfinite(d.l_min) && std::isfinite(d.l_max) && d.l_min > 0 && d.l_max >= d.l_min))
    fail("loop-length range must be finite, positive and increasing");
  if (!(std::isfinite(d.floor) && d.floor >= 0.0)) fail("floor must be finite and >= 0");
  if (!d.box_min.allFinite() || !d.box_max.allFinite() ||
      (d.box_min.array() > d.box_max.array()).any())
    fail("data strain box must be finite with min <= max");
  if (d.family == EnergyFamily::kNetwork) {
    if (const std::string why = d.network.validate(); !why.empty()) fail("network: " + why);
    // The knots are the loop lengths whose networks were fitted, so they run from l_min to
    // l_max exactly: a last knot of 1e308 (or a first of 1e-300) "covered" the range and
    // stretched the interpolation between its neighbours over it, silently.
    const double tol = 1e-9 * d.l_max;
    if (d.network.l_knots.front() > d.l_min || d.network.l_knots.back() < d.l_max)
      fail("network: loop-length knots must cover [l_min, l_max]");
    if (d.network.l_knots.front() < d.l_min - tol || d.network.l_knots.back() > d.l_max + tol) {
      std::ostringstream o;
      o << "network: loop-length knots must run from l_min to l_max (the loop lengths of the "
           "fitted networks), got "
        << d.network.l_knots.front() << " ... " << d.network.l_knots.back() << " mm for ["
        << d.l_min << ", " << d.l_max << "] mm";
      fail(o.str());
    }
    return;
  }
  const Eigen::Index K = d.directions.d.rows();
  if (K < 1) fail("no directions");
  if (static_cast<Eigen::Index>(d.directions.function_of.size()) != K)
    fail("function_of must have one entry per direction");
  const int G = d.functions();
  for (int g : d.directions.function_of)
    if (g < 0) fail("function_of has a negative index");
  // No more functions than directions (session 49's red team: function_of[0] = 99 was refused
  // as "s_range needs one row per function").
  if (G > K)
    fail("function_of names function " + std::to_string(G - 1) + ", but there are only " +
         std::to_string(K) +
         " directions: the function indices run from 0 to the number of functions - 1");
  for (Eigen::Index k = 0; k < K; ++k) {
    const double n = d.directions.d.row(k).norm();
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-9)
      fail("direction " + std::to_string(k) + " is not a unit vector");
  }
  if (d.s_degree < 0 || d.s_degree > 5) fail("s_degree must be in 0..5");
  if (d.s_spans < 1 || d.s_spans > 1000) fail("s_spans must be in 1..1000");
  if (d.s_range.rows() != G)
    fail("s_range needs one row per function: function_of names " + std::to_string(G) +
         " functions (indices 0 to " + std::to_string(G - 1) + "), s_range has " +
         std::to_string(d.s_range.rows()) + " rows");
  for (int g = 0; g < G; ++g) {
    const std::string why = d.grid(g).validate();
    if (!why.empty()) fail("function " + std::to_string(g) + ": " + why);
  }
  try {
    spline::validate_knots(d.l_knots, d.l_degree);
  } catch (const std::exception& e) {
    fail(std::string("l_knots: ") + e.what());
  }
  if (d.l_knots.front() > d.l_min || d.l_knots.back() < d.l_max)
    fail("l_knots must cover [l_min, l_max]");
  if (d.coefficients.rows() != G || d.coefficients.cols() != d.n_s() * d.n_l())
    fail("coefficients must be functions x (n_s * n_l) = " + std::to_string(G) + " x " +
         std::to_string(d.n_s() * d.n_l()));
  if (!d.coefficients.allFinite()) fail("coefficients must be finite");
  if ((d.coefficients.array() < 0.0).any())
    fail("coefficients must be >= 0 (f'' >= 0 keeps W convex)");
}

EnergyLaw::EnergyLaw(EnergyLawData d) : d_(std::move(d)) {
  validate(d_);
  if (d_.family == EnergyFamily::kRidge) lb_ = spline::BSplineBasis(d_.l_degree, d_.l_knots);
}

Eigen::VectorXd EnergyLaw::l_basis(double l, int derivative) const {
  // Clamped beyond the knots: the law is constant in l there, so its l-derivatives are 0 (the
  // basis' derivative at the end knot is the one-sided one of the span inside).
  if (derivative > 0 && (l < lb_.lo() || l > lb_.hi()))
    return Eigen::VectorXd::Zero(lb_.eval_all(lb_.lo(), 0).size());
  return lb_.eval_all(std::clamp(l, lb_.lo(), lb_.hi()), derivative);
}

Eigen::VectorXd EnergyLaw::ridge_coefficients(int g, double l, int derivative) const {
  const Eigen::VectorXd M = l_basis(l, derivative);
  const int ns = d_.n_s();
  Eigen::VectorXd a = Eigen::VectorXd::Zero(ns);
  for (int j = 0; j < d_.n_l(); ++j)
    a += M(j) * d_.coefficients.row(g).segment(j * ns, ns).transpose();
  return a;
}

EnergyLawAt::EnergyLawAt(const EnergyLawData& d, double l, bool with_l_derivative,
                         LanesKernel kernel)
    : l_(l), floor_(d.floor), P_(d.s_degree + 2), box_min_(d.box_min), box_max_(d.box_max) {
  const EnergyLaw law(d);
  if (d.family == EnergyFamily::kNetwork) {
    network_ = true;
    with_l_derivative_ = with_l_derivative;
    if (d.network.l_interpolation == LInterpolation::kEnergy) {
      // W(e; l) = sum_k c_k W_j[k]: one knot's law, two in a span, three in a rounding window
      // (NetworkLawData::weights; docs/database.md "Interpolation in l").
      energy_blend_ = true;
      const KnotWeights w = d.network.weights(l);
      std::vector<std::vector<double>> th;
      for (int k = 0; k < w.count; ++k) th.push_back(d.network.theta_row(w.j[k]));
      if (w.count == 3 && kernel != LanesKernel::kPortable && NetworkLanesAt::six_lane_kernel()) {
        // One six-lane pass in a wide kernel: AVX-512 (session 48: 2.6e6 per second, against
        // 1.8e6 for the four-plus-two passes below) or AVX2 with FMA (lanes6s_avx2, session 53:
        // 2.70-2.76e6 with the AVX2 kernels forced on a processor with AVX-512; session 51's
        // six-lane AVX2 pass: 1.78-1.79e6 on one without it, against 1.45-1.48e6 for the four
        // plus two).
        lanes_ = NetworkLanesAt(d.network.shape, th[0], th[1], th[2],
                                Eigen::Vector3d(w.c[0], w.c[1], w.c[2]), kernel);
      } else if (w.count == 3) {
        // Without a wide kernel: (c0 + c2) [(1 - t) W_j-1 + t W_j+1] in the four-lane
        // evaluator plus c1 W_j in a two-lane one (session 44: faster than one portable
        // six-lane pass).
        const double outer = w.c[0] + w.c[2];
        lanes_ = NetworkLanesAt(d.network.shape, th[0], th[2], w.c[2] / outer, kernel);
        lanes_scale_ = outer;
        middle_ = NetworkLanesAt(d.network.shape, th[1]);
        middle_scale_ = w.c[1];
      } else if (w.count == 2 && w.c[1] > 0.0 && w.c[0] > 0.0) {
        lanes_ = NetworkLanesAt(d.network.shape, th[0], th[1], w.c[1], kernel);
      } else {  // one knot's law (at a knot: a span's t = 0 or 1)
        const int k = w.count == 2 && w.c[0] == 0.0 ? 1 : 0;
        lanes_ = NetworkLanesAt(d.network.shape, th[static_cast<std::size_t>(k)]);
      }
      if (with_l_derivative)
        for (int k = 0; k < w.count; ++k)
          if (w.dc[k] != 0.0) {
            dnet_.emplace_back(d.network.shape, th[static_cast<std::size_t>(k)]);
            dweight_.push_back(w.dc[k]);
          }
      return;
    }
    net_ = NetworkLawAt(d.network.shape, d.network.theta_at(l));
    lanes_ = NetworkLanesAt(d.network.shape, net_.theta());
    if (with_l_derivative) {
      // dS/dl = (dS/dtheta) dtheta/dl by central differences along dtheta/dl (theta(l) is
      // piecewise linear, so this is the derivative of the span that holds l).
      net_h_ = 1e-6;  // mm: truncation below the round-off eps |S| / h here
      std::vector<double> lo = net_.theta(), hi = lo;
      const std::vector<double> dt = d.network.theta_at(l, 1);
      for (std::size_t k = 0; k < lo.size(); ++k) {
        lo[k] -= net_h_ * dt[k];
        hi[k] += net_h_ * dt[k];
      }
      net_lo_ = NetworkLawAt(d.network.shape, lo);
      net_hi_ = NetworkLawAt(d.network.shape, hi);
    }
    return;
  }
  const int G = d.functions();
  std::vector<std::size_t> offset(static_cast<std::size_t>(G));
  for (int g = 0; g < G; ++g) {
    offset[static_cast<std::size_t>(g)] = poly_.size();
    const Eigen::VectorXd a = law.ridge_coefficients(g, l);
    ridge_polynomials(d.grid(g), a.data(), poly_);
    if (with_l_derivative) {
      const Eigen::VectorXd da = law.ridge_coefficients(g, l, 1);
      ridge_polynomials(d.grid(g), da.data(), dpoly_);
    }
  }
  for (Eigen::Index k = 0; k < d.directions.d.rows(); ++k) {
    const int g = d.directions.function_of[static_cast<std::size_t>(k)];
    const RidgeGrid grid = d.grid(g);
    dirs_.push_back({d.directions.d(k, 0), d.directions.d(k, 1), d.directions.d(k, 2), grid.a,
                     1.0 / grid.h(), grid.spans, offset[static_cast<std::size_t>(g)]});
  }
}

template <int P>
void EnergyLawAt::accumulate(const Eigen::Vector3d& e, EnergyResponse& r) const {
  double W = 0, S0 = 0, S1 = 0, S2 = 0, C00 = 0, C01 = 0, C02 = 0, C11 = 0, C12 = 0, C22 = 0;
  const double* q = poly_.data();
  for (const Dir& k : dirs_) {
    const double s = k.d0 * e(0) + k.d1 * e(1) + k.d2 * e(2);
    double f, df, ddf;
    ridge_eval<P>(q + k.offset, k.a, k.inv_h, k.spans, s, f, df, ddf);
    W += f;
    S0 += df * k.d0;
    S1 += df * k.d1;
    S2 += df * k.d2;
    const double c0 = ddf * k.d0, c1 = ddf * k.d1;
    C00 += c0 * k.d0;
    C01 += c0 * k.d1;
    C02 += c0 * k.d2;
    C11 += c1 * k.d1;
    C12 += c1 * k.d2;
    C22 += ddf * k.d2 * k.d2;
  }
  r.W += W;
  r.S += Eigen::Vector3d(S0, S1, S2);
  r.C(0, 0) += C00;
  r.C(1, 1) += C11;
  r.C(2, 2) += C22;
  r.C(0, 1) = r.C(1, 0) = C01;
  r.C(0, 2) = r.C(2, 0) = C02;
  r.C(1, 2) = r.C(2, 1) = C12;
}

EnergyResponse EnergyLawAt::evaluate_network(const Eigen::Vector3d& e) const {
  NetworkResponse n = lanes_.evaluate(e);
  if (middle_scale_ > 0.0) {  // a rounding window of l_blend: the middle knot's law besides
    const NetworkResponse m = middle_.evaluate(e);
    n.W = lanes_scale_ * n.W + middle_scale_ * m.W;
    n.S = lanes_scale_ * n.S + middle_scale_ * m.S;
    n.C = lanes_scale_ * n.C + middle_scale_ * m.C;
  }
  EnergyResponse r;
  r.W = n.W + 0.5 * floor_ * e.squaredNorm();
  r.S = n.S + floor_ * e;
  r.C = n.C + floor_ * Eigen::Matrix3d::Identity();
  return r;
}

EnergyResponse EnergyLawAt::evaluate(const Eigen::Vector3d& e) const {
  if (network_) return evaluate_network(e);
  EnergyResponse r;
  r.W = 0.5 * floor_ * e.squaredNorm();
  r.S = floor_ * e;
  r.C = floor_ * Eigen::Matrix3d::Identity();
  switch (P_) {
    case 2:
      accumulate<2>(e, r);
      break;
    case 3:
      accumulate<3>(e, r);
      break;
    case 4:
      accumulate<4>(e, r);
      break;
    case 5:
      accumulate<5>(e, r);
      break;
    case 6:
      accumulate<6>(e, r);
      break;
    default:
      accumulate<7>(e, r);
      break;
  }
  return r;
}

Eigen::Vector3d EnergyLawAt::dS_dl(const Eigen::Vector3d& e) const {
  if (network_) {
    if (!with_l_derivative_) throw std::logic_error("EnergyLawAt: built without the l-derivative");
    if (energy_blend_) {  // dS/dl = sum_k dc_k/dl S_j[k] (0 beyond the end knots)
      Eigen::Vector3d dS = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < dnet_.size(); ++k) dS += dweight_[k] * dnet_[k].evaluate(e).S;
      return dS;
    }
    return (net_hi_.evaluate(e).S - net_lo_.evaluate(e).S) / (2.0 * net_h_);
  }
  if (dpoly_.empty()) throw std::logic_error("EnergyLawAt: built without the l-derivative");
  Eigen::Vector3d dS = Eigen::Vector3d::Zero();
  for (const Dir& k : dirs_) {
    // Not a hot path: the generic evaluator (same polynomials, any degree).
    const RidgeGrid grid{k.a, k.a + k.spans / k.inv_h, k.spans, P_ - 2};
    const double s = k.d0 * e(0) + k.d1 * e(1) + k.d2 * e(2);
    dS += ridge_eval_any(grid, dpoly_.data() + k.offset, s)(1) * Eigen::Vector3d(k.d0, k.d1, k.d2);
  }
  return dS;
}

}  // namespace knit::material
