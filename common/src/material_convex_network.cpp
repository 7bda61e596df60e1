// The input-convex network of the energy-based law (see knit/material/convex_network.hpp).
#include <algorithm>
#include <array>
#include <cmath>

#include "knit/material/convex_network.hpp"

namespace knit::material {

namespace {

constexpr int kMaxUnits = NetworkForward::kMaxUnits;  // per layer: work arrays on the stack

/// Upper triangle of C += c a a^T.
inline void add_outer(Eigen::Matrix3d& C, double c, const Eigen::Vector3d& a) {
  const double c0 = c * a(0), c1 = c * a(1);
  C(0, 0) += c0 * a(0);
  C(0, 1) += c0 * a(1);
  C(0, 2) += c0 * a(2);
  C(1, 1) += c1 * a(1);
  C(1, 2) += c1 * a(2);
  C(2, 2) += c * a(2) * a(2);
}

/// The first layer's activations h, h', h'' at e (the reverse-mode gradients start here).
inline void first_layer(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                        double* h, double* dh, double* ddh) {
  const double *a0 = th + sh.a0(), *b0 = th + sh.b0();
  for (int i = 0; i < sh.h1; ++i) {
    const double* a = a0 + 3 * i;
    network_unit_activation(sh.stiffening1(i), a[0] * e(0) + a[1] * e(1) + a[2] * e(2) + b0[i],
                            h[i], dh[i], ddh[i]);
  }
}

/// The second layer's pre-activation z_j = sum_i V_ji h_i + a1_j . e + b1_j.
inline double second_layer_input(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                                 const double* h, int j) {
  const double* a = th + sh.a1() + 3 * j;
  const double* v = th + sh.V() + j * sh.h1;
  double z = a[0] * e(0) + a[1] * e(1) + a[2] * e(2) + th[sh.b1() + j];
  for (int i = 0; i < sh.h1; ++i) z += v[i] * h[i];
  return z;
}

}  // namespace

std::string NetworkShape::validate() const {
  if (h1 < 1 || h1 > kMaxUnits || h2 < 1 || h2 > kMaxUnits)
    return "hidden layer sizes must be in 1.." + std::to_string(kMaxUnits);
  if (stiff1 < 0 || stiff1 > h1 || stiff2 < 0 || stiff2 > h2)
    return "the stiffening units (stiff1, stiff2) must be in 0..h1 and 0..h2";
  if (outer != 0 && outer != 1) return "outer must be 0 (none) or 1 (exponential)";
  if (outer == 1 && !(std::isfinite(outer_scale) && outer_scale > 0.0))
    return "outer_scale must be finite and positive";
  if (outer == 1 && !(std::isfinite(outer_cap) && std::abs(outer_cap) <= 600.0))
    return "outer_cap must be finite, |outer_cap| <= 600";
  return {};
}

void network_forward(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                     NetworkForward& f) {
  first_layer(sh, th, e, f.h.data(), f.dh.data(), f.ddh.data());
  for (int j = 0; j < sh.h2; ++j)
    network_unit_activation(sh.stiffening2(j), second_layer_input(sh, th, e, f.h.data(), j), f.u[j],
                            f.du[j], f.ddu[j]);
}

NetworkResponse network_evaluate(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                                 bool with_C) {
  NetworkForward f;
  network_forward(sh, th, e, f);
  return network_evaluate(sh, th, e, f, with_C);
}

NetworkResponse network_evaluate(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                                 const NetworkForward& f, bool with_C) {
  std::array<double, kMaxUnits> kappa;
  const double *a0 = th + sh.a0(), *w1 = th + sh.w1(), *V = th + sh.V(), *a1 = th + sh.a1(),
               *w = th + sh.w(), *L = th + sh.L();
  const double *h = f.h.data(), *dh = f.dh.data(), *ddh = f.ddh.data();
  const int H1 = sh.h1, H2 = sh.h2;
  NetworkResponse r;
  for (int i = 0; i < H1; ++i) {
    r.W += w1[i] * h[i];
    kappa[i] = w1[i];
  }
  for (int j = 0; j < H2; ++j) {
    const double* a = a1 + 3 * j;
    const double* v = V + j * H1;
    const double u = f.u[j], du = f.du[j], ddu = f.ddu[j];
    r.W += w[j] * u;
    const double wdu = w[j] * du;
    for (int i = 0; i < H1; ++i) kappa[i] += wdu * v[i];
    r.S += wdu * Eigen::Vector3d(a[0], a[1], a[2]);
    if (with_C && ddu != 0.0) {
      Eigen::Vector3d g(a[0], a[1], a[2]);
      for (int i = 0; i < H1; ++i) {
        const double c = v[i] * dh[i];
        g += c * Eigen::Vector3d(a0[3 * i], a0[3 * i + 1], a0[3 * i + 2]);
      }
      add_outer(r.C, w[j] * ddu, g);
    }
  }
  for (int i = 0; i < H1; ++i) {
    const Eigen::Vector3d a(a0[3 * i], a0[3 * i + 1], a0[3 * i + 2]);
    r.S += (kappa[i] * dh[i]) * a;
    if (with_C && ddh[i] != 0.0) add_outer(r.C, kappa[i] * ddh[i], a);
  }
  // C was accumulated in its upper triangle: mirror it (symmetric to the last bit).
  r.C(1, 0) = r.C(0, 1);
  r.C(2, 0) = r.C(0, 2);
  r.C(2, 1) = r.C(1, 2);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Lm(L);
  Eigen::Matrix3d Q = Lm * Lm.transpose();
  Q(1, 0) = Q(0, 1);
  Q(2, 0) = Q(0, 2);
  Q(2, 1) = Q(1, 2);
  r.W += 0.5 * e.dot(Q * e);
  r.S += Q * e;
  if (with_C) r.C += Q;
  return r;
}

NetworkResponse network_compose_outer(const NetworkShape& sh, const NetworkResponse& n,
                                      bool with_C) {
  if (sh.outer == 0) return n;
  double g, dg, ddg;
  network_outer(n.W, sh.outer_cap, g, dg, ddg);
  NetworkResponse r;
  r.W = sh.outer_scale * g;
  r.S = (sh.outer_scale * dg) * n.S;
  if (with_C) {
    r.C = (sh.outer_scale * dg) * n.C + (sh.outer_scale * ddg) * (n.S * n.S.transpose());
    r.C(1, 0) = r.C(0, 1);
    r.C(2, 0) = r.C(0, 2);
    r.C(2, 1) = r.C(1, 2);
  }
  return r;
}

void network_value_gradient(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                            double scale, double* grad) {
  NetworkForward f;
  network_forward(sh, th, e, f);
  network_value_gradient(sh, th, e, f, scale, grad);
}

void network_value_gradient(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                            const NetworkForward& f, double scale, double* grad) {
  // N = sum_j w_j u_j + sum_i w1_i h_i + 1/2 e^T L L^T e:
  //   dN/dw_j = u_j, dN/dw1_i = h_i, dN/dz_j = w_j u'_j (-> b1_j, a1_j e, V_ji h_i),
  //   dN/dy_i = kappa_i h'_i (-> b0_i, a0_i e), dN/dL = e (L^T e)^T.
  std::array<double, kMaxUnits> kappa;
  const double *w1 = th + sh.w1(), *V = th + sh.V(), *w = th + sh.w(), *L = th + sh.L();
  const double *h = f.h.data(), *dh = f.dh.data();
  const int H1 = sh.h1, H2 = sh.h2;
  for (int i = 0; i < H1; ++i) {
    kappa[i] = w1[i];
    grad[sh.w1() + i] += scale * h[i];
  }
  for (int j = 0; j < H2; ++j) {
    const double* v = V + j * H1;
    const double u = f.u[j], du = f.du[j];
    grad[sh.w() + j] += scale * u;
    const double dz = scale * w[j] * du;
    grad[sh.b1() + j] += dz;
    for (int c = 0; c < 3; ++c) grad[sh.a1() + 3 * j + c] += dz * e(c);
    double* gv = grad + sh.V() + j * H1;
    for (int i = 0; i < H1; ++i) {
      gv[i] += dz * h[i];
      kappa[i] += w[j] * du * v[i];
    }
  }
  for (int i = 0; i < H1; ++i) {
    const double dy = scale * kappa[i] * dh[i];
    grad[sh.b0() + i] += dy;
    for (int c = 0; c < 3; ++c) grad[sh.a0() + 3 * i + c] += dy * e(c);
  }
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Lm(L);
  const Eigen::Vector3d Le = Lm.transpose() * e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) grad[sh.L() + 3 * r + c] += scale * e(r) * Le(c);
}

void network_stress_gradient(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                             const Eigen::Vector3d& g, double* grad) {
  NetworkForward f;
  network_forward(sh, th, e, f);
  network_stress_gradient(sh, th, e, f, g, grad);
}

void network_stress_gradient(const NetworkShape& sh, const double* th, const Eigen::Vector3d& e,
                             const NetworkForward& f, const Eigen::Vector3d& g, double* grad) {
  // F = g . S. With alpha_i = a0_i . g, beta_j = a1_j . g, gamma_j = grad z_j . g:
  //   F = sum_i w1_i h'_i alpha_i + sum_j w_j u'_j gamma_j + g^T L L^T e,
  // zeta_j = dF/dz_j = w_j u''_j gamma_j, omega_j = dF/dgamma_j = w_j u'_j,
  // eta_i = dF/dy_i = h'_i sum_j zeta_j V_ji + h''_i kappa_i alpha_i.
  std::array<double, kMaxUnits> alpha, kappa, back;
  const double *a0 = th + sh.a0(), *w1 = th + sh.w1(), *V = th + sh.V(), *a1 = th + sh.a1(),
               *w = th + sh.w(), *L = th + sh.L();
  const double *h = f.h.data(), *dh = f.dh.data(), *ddh = f.ddh.data();
  const int H1 = sh.h1, H2 = sh.h2;
  for (int i = 0; i < H1; ++i) {
    const double* a = a0 + 3 * i;
    alpha[i] = a[0] * g(0) + a[1] * g(1) + a[2] * g(2);
    kappa[i] = w1[i];
    back[i] = 0.0;
    grad[sh.w1() + i] += dh[i] * alpha[i];
  }
  for (int j = 0; j < H2; ++j) {
    const double* a = a1 + 3 * j;
    const double* v = V + j * H1;
    double gamma = a[0] * g(0) + a[1] * g(1) + a[2] * g(2);
    for (int i = 0; i < H1; ++i) gamma += v[i] * dh[i] * alpha[i];
    const double du = f.du[j], ddu = f.ddu[j];
    const double zeta = w[j] * ddu * gamma, omega = w[j] * du;
    grad[sh.w() + j] += du * gamma;
    grad[sh.b1() + j] += zeta;
    for (int c = 0; c < 3; ++c) grad[sh.a1() + 3 * j + c] += zeta * e(c) + omega * g(c);
    double* gv = grad + sh.V() + j * H1;
    for (int i = 0; i < H1; ++i) {
      gv[i] += zeta * h[i] + omega * dh[i] * alpha[i];
      back[i] += zeta * v[i];
      kappa[i] += omega * v[i];
    }
  }
  for (int i = 0; i < H1; ++i) {
    const double eta = dh[i] * back[i] + ddh[i] * kappa[i] * alpha[i];
    grad[sh.b0() + i] += eta;
    const double kd = kappa[i] * dh[i];
    for (int c = 0; c < 3; ++c) grad[sh.a0() + 3 * i + c] += eta * e(c) + kd * g(c);
  }
  // g^T L L^T e: d/dL = g (L^T e)^T + e (L^T g)^T.
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Lm(L);
  const Eigen::Vector3d Le = Lm.transpose() * e, Lg = Lm.transpose() * g;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) grad[sh.L() + 3 * r + c] += g(r) * Le(c) + e(r) * Lg(c);
}

NetworkLawAt::NetworkLawAt(const NetworkShape& shape, std::vector<double> theta)
    : shape_(shape), theta_(std::move(theta)) {
  const int H1 = shape_.h1, H2 = shape_.h2;
  const double* th = theta_.data();
  packed_.assign(static_cast<std::size_t>(11 * H1 + H2 * H1 + 5 * H2), 0.0);
  double* q = packed_.data();
  for (int i = 0; i < H1; ++i) {
    const double* a = th + shape_.a0() + 3 * i;
    q[i] = a[0];
    q[H1 + i] = a[1];
    q[2 * H1 + i] = a[2];
    q[3 * H1 + i] = th[shape_.b0() + i];
    q[4 * H1 + i] = th[shape_.w1() + i];
    q[5 * H1 + i] = a[0] * a[0];
    q[6 * H1 + i] = a[0] * a[1];
    q[7 * H1 + i] = a[0] * a[2];
    q[8 * H1 + i] = a[1] * a[1];
    q[9 * H1 + i] = a[1] * a[2];
    q[10 * H1 + i] = a[2] * a[2];
  }
  std::copy(th + shape_.V(), th + shape_.V() + H2 * H1, q + 11 * H1);
  std::copy(th + shape_.a1(), th + shape_.a1() + 3 * H2, q + 11 * H1 + H2 * H1);
  std::copy(th + shape_.b1(), th + shape_.b1() + H2, q + 11 * H1 + H2 * H1 + 3 * H2);
  std::copy(th + shape_.w(), th + shape_.w() + H2, q + 11 * H1 + H2 * H1 + 4 * H2);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> Lm(th + shape_.L());
  Q_ = Lm * Lm.transpose();
  Q_(1, 0) = Q_(0, 1);
  Q_(2, 0) = Q_(0, 2);
  Q_(2, 1) = Q_(1, 2);
  const NetworkResponse n0 = pass(Eigen::Vector3d::Zero());
  W0_ = n0.W;
  S0_ = Eigen::Vector3d(n0.S(0), n0.S(1), 0.0);  // 1/2 (S + M S) at e = 0
}

namespace {

/// The activation on a whole layer, per unit (its fast form; a branch-free, vectorized copy
/// measured 15-20 % slower on the benchmark's strains); rho on the last `stiff` units.
template <class X, class S>
inline void activation_layer(const X& x, S& s, S& ds, S& dds, int stiff) {
  for (Eigen::Index i = 0; i < x.size() - stiff; ++i)
    network_activation_impl<true>(x(i), s(i), ds(i), dds(i));
  for (Eigen::Index i = x.size() - stiff; i < x.size(); ++i)
    network_stiffening_activation(x(i), s(i), ds(i), dds(i));
}

/// One network pass from the packed layout, the layer sizes fixed at compile time (N1, N2 > 0:
/// Eigen unrolls and vectorizes the products) or Eigen::Dynamic (any size up to kMaxUnits).
template <int N1, int N2>
NetworkResponse pass_impl(const NetworkShape& shape, const double* q, const Eigen::Matrix3d& Q,
                          const Eigen::Vector3d& e) {
  constexpr int M1 = N1 == Eigen::Dynamic ? kMaxUnits : N1;
  constexpr int M2 = N2 == Eigen::Dynamic ? kMaxUnits : N2;
  using A1 = Eigen::Array<double, N1, 1, 0, M1, 1>;
  using A2 = Eigen::Array<double, N2, 1, 0, M2, 1>;
  using CA1 = Eigen::Map<const Eigen::Array<double, N1, 1>>;
  using CA2 = Eigen::Map<const Eigen::Array<double, N2, 1>>;
  const int H1 = shape.h1, H2 = shape.h2;
  const CA1 c0(q, H1), c1(q + H1, H1), c2(q + 2 * H1, H1), b0(q + 3 * H1, H1), w1(q + 4 * H1, H1);
  const Eigen::Map<const Eigen::Matrix<double, N2, N1, Eigen::RowMajor>> V(q + 11 * H1, H2, H1);
  const double* a1p = q + 11 * H1 + H2 * H1;
  const Eigen::Map<const Eigen::Matrix<double, N2, 3, Eigen::RowMajor>> a1(a1p, H2, 3);
  const CA2 b1(a1p + 3 * H2, H2), w(a1p + 4 * H2, H2);
  A1 y = c0 * e(0) + c1 * e(1) + c2 * e(2) + b0;
  A1 h(H1), dh(H1), ddh(H1);
  activation_layer(y, h, dh, ddh, shape.stiff1);
  A2 z = (V.lazyProduct(h.matrix()) + a1.lazyProduct(e)).array() + b1;
  A2 u(H2), du(H2), ddu(H2);
  activation_layer(z, u, du, ddu, shape.stiff2);
  NetworkResponse r;
  r.W = (w * u).sum() + (w1 * h).sum() + 0.5 * e.dot(Q * e);
  const A2 wd = w * du;
  // kappa = w1 + V^T (w du).
  const A1 kappa = (V.transpose().lazyProduct(wd.matrix())).array() + w1;
  // C, second-layer part: grad z_j = sum_i V_ji h'_i a0_i + a1_j = (V B + a1)_j, B = diag(h') A0,
  // for the units in their curved part only (u''_j > 0; B only when there is one).
  if ((ddu != 0.0).any()) {
    Eigen::Matrix<double, N1, 3, 0, M1, 3> B(H1, 3);
    B.col(0) = (dh * c0).matrix();
    B.col(1) = (dh * c1).matrix();
    B.col(2) = (dh * c2).matrix();
    for (int j = 0; j < H2; ++j)
      if (ddu(j) != 0.0)
        add_outer(r.C, w(j) * ddu(j), (V.row(j).lazyProduct(B) + a1.row(j)).transpose());
  }
  // First-layer part: sum_i kappa_i h''_i a0_i a0_i^T from the column products.
  const CA1 p00(q + 5 * H1, H1), p01(q + 6 * H1, H1), p02(q + 7 * H1, H1), p11(q + 8 * H1, H1),
      p12(q + 9 * H1, H1), p22(q + 10 * H1, H1);
  const A1 kh2 = kappa * ddh;
  r.C(0, 0) += (kh2 * p00).sum() + Q(0, 0);
  r.C(0, 1) += (kh2 * p01).sum() + Q(0, 1);
  r.C(0, 2) += (kh2 * p02).sum() + Q(0, 2);
  r.C(1, 1) += (kh2 * p11).sum() + Q(1, 1);
  r.C(1, 2) += (kh2 * p12).sum() + Q(1, 2);
  r.C(2, 2) += (kh2 * p22).sum() + Q(2, 2);
  r.C(1, 0) = r.C(0, 1);
  r.C(2, 0) = r.C(0, 2);
  r.C(2, 1) = r.C(1, 2);
  const A1 kh1 = kappa * dh;
  r.S = Eigen::Vector3d((kh1 * c0).sum(), (kh1 * c1).sum(), (kh1 * c2).sum()) + Q * e +
        a1.transpose().lazyProduct(wd.matrix());
  return r;
}

}  // namespace

NetworkResponse NetworkLawAt::pass(const Eigen::Vector3d& e) const {
  // The default shape and the sizes the docs measure get compiled sizes; any other the general
  // path (the same code, Eigen::Dynamic).
  // The outer function (if any) is applied to each pass: the mirror average and the affine
  // normalization act on G = c g(N).
  const double* q = packed_.data();
  if (shape_.h1 == 12 && shape_.h2 == 6)
    return network_compose_outer(shape_, pass_impl<12, 6>(shape_, q, Q_, e));
  if (shape_.h1 == 16 && shape_.h2 == 8)
    return network_compose_outer(shape_, pass_impl<16, 8>(shape_, q, Q_, e));
  return network_compose_outer(shape_, pass_impl<Eigen::Dynamic, Eigen::Dynamic>(shape_, q, Q_, e));
}

NetworkResponse NetworkLawAt::evaluate(const Eigen::Vector3d& e) const {
  const Eigen::Vector3d me(e(0), e(1), -e(2));
  const NetworkResponse a = pass(e);
  const NetworkResponse b = pass(me);
  NetworkResponse r;
  r.W = 0.5 * (a.W + b.W) - W0_ - S0_.dot(e);
  r.S = 0.5 * (a.S + Eigen::Vector3d(b.S(0), b.S(1), -b.S(2))) - S0_;
  // M C(Me) M flips the signs of the (1,3), (2,3) entries.
  Eigen::Matrix3d cb = b.C;
  cb(0, 2) = cb(2, 0) = -b.C(0, 2);
  cb(1, 2) = cb(2, 1) = -b.C(1, 2);
  r.C = 0.5 * (a.C + cb);
  return r;
}

std::string NetworkLawData::validate() const {
  if (const std::string why = shape.validate(); !why.empty()) return why;
  const auto n = static_cast<Eigen::Index>(l_knots.size());
  if (n < 1) return "no loop-length knot";
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(l_knots[static_cast<std::size_t>(j)]) ||
        !(l_knots[static_cast<std::size_t>(j)] > 0.0))
      return "loop-length knots must be finite and positive";
    if (j > 0 && !(l_knots[static_cast<std::size_t>(j)] > l_knots[static_cast<std::size_t>(j - 1)]))
      return "loop-length knots must be strictly increasing";
  }
  if (theta.rows() != n || theta.cols() != shape.size())
    return "theta must be knots x " + std::to_string(shape.size()) +
           " (h1 = " + std::to_string(shape.h1) + ", h2 = " + std::to_string(shape.h2) + ")";
  if (!theta.allFinite()) return "theta must be finite";
  for (Eigen::Index j = 0; j < n; ++j)
    for (int k = 0; k < shape.size(); ++k)
      if (shape.nonnegative(k) && theta(j, k) < 0.0)
        return "theta row " + std::to_string(j) + " column " + std::to_string(k) +
               ": the weights V, w, w1 must be >= 0 (they keep W convex)";
  if (!(l_blend >= 0.0 && l_blend <= 0.5))
    return "l_blend must be in [0, 0.5] (a fraction of the shorter span at each knot)";
  return {};
}

KnotWeights NetworkLawData::weights(double l) const {
  const auto n = static_cast<Eigen::Index>(l_knots.size());
  KnotWeights w;
  w.count = 1;
  w.c[0] = 1.0;
  auto knot = [&](Eigen::Index j) { return l_knots[static_cast<std::size_t>(j)]; };
  if (n <= 1 || l < knot(0) || l > knot(n - 1)) {  // clamped: one knot law, d/dl = 0
    w.j[0] = n > 1 && l > knot(n - 1) ? n - 1 : 0;
    return w;
  }
  // A rounding window around an interior knot j: [l_j - d, l_j + d], d = l_blend x the shorter
  // neighbouring span. P0 = (1 - a) W_j + a W_j-1, P2 = (1 - b) W_j + b W_j+1 (a = d / h_j-1,
  // b = d / h_j), W = (1 - s)^2 P0 + 2 s (1 - s) W_j + s^2 P2: c_j-1 = a (1 - s)^2, c_j+1 =
  // b s^2; at s = 0 and 1 value and slope are the spans' (C1).
  if (l_blend > 0.0 && n > 2) {
    const auto up = static_cast<Eigen::Index>(std::upper_bound(l_knots.begin(), l_knots.end(), l) -
                                              l_knots.begin());
    for (Eigen::Index j : {up - 1, up}) {  // the knots either side of l
      if (j < 1 || j > n - 2) continue;
      const double hl = knot(j) - knot(j - 1), hr = knot(j + 1) - knot(j);
      const double d = l_blend * std::min(hl, hr);
      if (!(std::abs(l - knot(j)) < d)) continue;
      const double s = (l - knot(j) + d) / (2.0 * d), a = d / hl, b = d / hr;
      w.count = 3;
      w.j[0] = j - 1;
      w.j[1] = j;
      w.j[2] = j + 1;
      w.c[0] = a * (1.0 - s) * (1.0 - s);
      w.c[2] = b * s * s;
      w.c[1] = 1.0 - w.c[0] - w.c[2];
      w.dc[0] = -a * (1.0 - s) / d;  // ds/dl = 1 / (2 d)
      w.dc[2] = b * s / d;
      w.dc[1] = -(w.dc[0] + w.dc[2]);
      return w;
    }
  }
  // A span [l_j, l_j+1) (the last knot itself: the span before it, one-sided).
  Eigen::Index j = static_cast<Eigen::Index>(std::upper_bound(l_knots.begin(), l_knots.end(), l) -
                                             l_knots.begin()) -
                   1;
  if (j >= n - 1) j = n - 2;
  const double h = knot(j + 1) - knot(j), t = (l - knot(j)) / h;
  w.count = 2;
  w.j[0] = j;
  w.j[1] = j + 1;
  w.c[0] = 1.0 - t;
  w.c[1] = t;
  w.dc[0] = -1.0 / h;
  w.dc[1] = 1.0 / h;
  return w;
}

std::vector<double> NetworkLawData::theta_row(Eigen::Index j) const {
  std::vector<double> out(static_cast<std::size_t>(shape.size()));
  for (int k = 0; k < shape.size(); ++k) out[static_cast<std::size_t>(k)] = theta(j, k);
  return out;
}

std::vector<double> NetworkLawData::theta_at(double l, int derivative) const {
  const auto n = static_cast<Eigen::Index>(l_knots.size());
  std::vector<double> out(static_cast<std::size_t>(shape.size()), 0.0);
  // Beyond the knots theta is constant (derivative 0). At the end knots themselves the
  // derivative is the one-sided one of the span inside: it was 0 there until session 39, so a
  // design that reached the database's first or last loop length saw dJ/dl = 0 and stopped at
  // the bound ("infeasible target") where the target lay inside.
  const bool at_end = n > 1 && (l == l_knots.front() || l == l_knots.back());
  if (n == 1 || l < l_knots.front() || l > l_knots.back() || (at_end && derivative == 0)) {
    if (derivative != 0) return out;
    const Eigen::Index j = (n == 1 || l <= l_knots.front()) ? 0 : n - 1;
    for (int k = 0; k < shape.size(); ++k) out[static_cast<std::size_t>(k)] = theta(j, k);
    return out;
  }
  // l in [l_j, l_j+1); the last knot belongs to the last span.
  const auto it = std::upper_bound(l_knots.begin(), l_knots.end(), l);
  const auto j = std::min(static_cast<Eigen::Index>(it - l_knots.begin()) - 1, n - 2);
  const double dl = l_knots[static_cast<std::size_t>(j + 1)] - l_knots[static_cast<std::size_t>(j)];
  const double t = (l - l_knots[static_cast<std::size_t>(j)]) / dl;
  for (int k = 0; k < shape.size(); ++k)
    out[static_cast<std::size_t>(k)] = derivative == 0
                                           ? (1.0 - t) * theta(j, k) + t * theta(j + 1, k)
                                           : (theta(j + 1, k) - theta(j, k)) / dl;
  return out;
}

}  // namespace knit::material
