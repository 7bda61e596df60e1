// All network passes of one law evaluation in one sweep (see knit/material/network_lanes.hpp).
#include <algorithm>
#include <cstring>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <stdexcept>

#include "knit/material/network_lanes.hpp"

namespace knit::material {

namespace {

constexpr int kMaxUnitsPerLane = 64;  // NetworkShape::validate's bound
constexpr int kMaxLanes = 6;

/// The activation on the n units of a lane; rho on its last `stiff`. The sigma units two at a
/// time, branch-free (SSE2, part of every x86-64): x clamped to [-1, 1] gives the cubic piece's
/// s, s', s'' (their values at -1 and 1 are those of the linear pieces), and max(x - 1, 0)
/// adds the linear part beyond 1. The same function as network_activation_impl to round-off
/// (tested); in the lane layout this is 5 % faster than per-unit branches (measured, session 17).
inline void activate_lane(const double* x, double* s, double* ds, double* dds, int n, int stiff) {
  int i = 0;
#ifdef __SSE2__
  const __m128d one = _mm_set1_pd(1.0), mone = _mm_set1_pd(-1.0), zero = _mm_setzero_pd();
  const __m128d c34 = _mm_set1_pd(0.75), half = _mm_set1_pd(0.5), c12 = _mm_set1_pd(1.0 / 12.0),
                c3 = _mm_set1_pd(1.0 / 3.0), c316 = _mm_set1_pd(3.0 / 16.0);
  for (; i + 2 <= n - stiff; i += 2) {
    const __m128d xv = _mm_loadu_pd(x + i);
    const __m128d xc = _mm_min_pd(_mm_max_pd(xv, mone), one), x2 = _mm_mul_pd(xc, xc);
    // s = 3/4 (x^2 / 2 - x^4 / 12) + x / 2 + 3/16 on [-1, 1], + max(x - 1, 0) beyond
    const __m128d poly =
        _mm_mul_pd(c34, _mm_sub_pd(_mm_mul_pd(half, x2), _mm_mul_pd(_mm_mul_pd(x2, x2), c12)));
    _mm_storeu_pd(s + i, _mm_add_pd(_mm_add_pd(poly, _mm_add_pd(_mm_mul_pd(half, xc), c316)),
                                    _mm_max_pd(_mm_sub_pd(xv, one), zero)));
    _mm_storeu_pd(
        ds + i,
        _mm_add_pd(_mm_mul_pd(c34, _mm_sub_pd(xc, _mm_mul_pd(_mm_mul_pd(x2, xc), c3))), half));
    _mm_storeu_pd(dds + i, _mm_mul_pd(c34, _mm_sub_pd(one, x2)));
  }
#endif
  for (; i < n - stiff; ++i) network_activation_impl<true>(x[i], s[i], ds[i], dds[i]);
  for (; i < n; ++i) network_stiffening_activation(x[i], s[i], ds[i], dds[i]);
}

/// The upper triangle (00, 01, 02, 11, 12, 22) of C += c g g^T, for doubles or lane vectors.
template <class T>
[[gnu::always_inline]] inline void add_outer_upper(T* C, T c, T g0, T g1, T g2) {
  const T x0 = c * g0, x1 = c * g1;
  C[0] += x0 * g0;
  C[1] += x0 * g1;
  C[2] += x0 * g2;
  C[3] += x1 * g1;
  C[4] += x1 * g2;
  C[5] += c * g2 * g2;
}

/// r += omega G_k, G_k = outer(N_k) of one lane from its N, S_N and C_N (upper triangle 00, 01,
/// 02, 11, 12, 22): G = c g(N), S_G = c g' S_N, C_G = c (g' C_N + g'' S_N S_N^T) (the identity
/// without an outer function). Upper triangle of r.C only.
inline void add_lane(const NetworkShape& sh, double omega, double Wn, const Eigen::Vector3d& S,
                     const double* C, NetworkResponse& r) {
  double gW = Wn, gS = 1.0, gC = 0.0;
  if (sh.outer == 1) {
    double g, dg, ddg;
    network_outer(Wn, sh.outer_cap, g, dg, ddg);
    gW = sh.outer_scale * g;
    gS = sh.outer_scale * dg;
    gC = sh.outer_scale * ddg;
  }
  const double s1 = omega * gS, s2 = omega * gC;
  r.W += omega * gW;
  r.S += s1 * S;
  r.C(0, 0) += s1 * C[0] + s2 * S(0) * S(0);
  r.C(0, 1) += s1 * C[1] + s2 * S(0) * S(1);
  r.C(0, 2) += s1 * C[2] + s2 * S(0) * S(2);
  r.C(1, 1) += s1 * C[3] + s2 * S(1) * S(1);
  r.C(1, 2) += s1 * C[4] + s2 * S(1) * S(2);
  r.C(2, 2) += s1 * C[5] + s2 * S(2) * S(2);
}

/// The lanes' weighted sum of outer(N_k) and its derivatives, before normalization. H1c, H2c,
/// Kc > 0: sizes fixed at compile time (Eigen unrolls the lane products); 0: the shape's.
template <int H1c, int H2c, int Kc>
NetworkResponse lanes_sum(const NetworkShape& sh, int k_lanes, const double* q, const double* omega,
                          const double* Q, const Eigen::Vector3d& e) {
  constexpr int D1 = H1c > 0 ? H1c : Eigen::Dynamic, D2 = H2c > 0 ? H2c : Eigen::Dynamic;
  constexpr int M1 = (H1c > 0 ? H1c : kMaxUnitsPerLane) * (Kc > 0 ? Kc : kMaxLanes);
  constexpr int M2 = (H2c > 0 ? H2c : kMaxUnitsPerLane) * (Kc > 0 ? Kc : kMaxLanes);
  using Seg1 = Eigen::Map<const Eigen::Array<double, D1, 1>>;
  using Seg2 = Eigen::Map<const Eigen::Array<double, D2, 1>>;
  using Vec1 = Eigen::Map<const Eigen::Matrix<double, D1, 1>>;
  using Vec2 = Eigen::Map<const Eigen::Matrix<double, D2, 1>>;
  using Blk = Eigen::Map<const Eigen::Matrix<double, D2, D1, Eigen::RowMajor>>;
  const int H1 = H1c > 0 ? H1c : sh.h1, H2 = H2c > 0 ? H2c : sh.h2;
  const int K = Kc > 0 ? Kc : k_lanes;
  const int N1 = K * H1, N2 = K * H2;
  const double *c0 = q, *c1 = q + N1, *c2 = q + 2 * N1, *b0 = q + 3 * N1, *w1 = q + 4 * N1;
  const double* p = q + 5 * N1;  // p00, p01, p02, p11, p12, p22
  const double* V = q + 11 * N1;
  const double* a1 = V + N2 * H1;  // a10, a11, a12, b1, w
  const double *b1 = a1 + 3 * N2, *w = a1 + 4 * N2;
  const double e0 = e(0), e1 = e(1), e2 = e(2);

  // First layer, all lanes.
  double y[M1], h[M1], dh[M1], ddh[M1];
  for (int i = 0; i < N1; ++i) y[i] = c0[i] * e0 + c1[i] * e1 + c2[i] * e2 + b0[i];
  for (int k = 0; k < K; ++k)
    activate_lane(y + k * H1, h + k * H1, dh + k * H1, ddh + k * H1, H1, sh.stiff1);
  // Second layer: z = V_k h_k + A1 e + b1.
  double z[M2], u[M2], du[M2], ddu[M2], wd[M2];
  for (int j = 0; j < N2; ++j) z[j] = a1[j] * e0 + a1[N2 + j] * e1 + a1[2 * N2 + j] * e2 + b1[j];
  for (int k = 0; k < K; ++k) {
    Eigen::Map<Eigen::Matrix<double, D2, 1>> zk(z + k * H2, H2);
    zk.noalias() += Blk(V + k * H2 * H1, H2, H1).lazyProduct(Vec1(h + k * H1, H1));
  }
  for (int k = 0; k < K; ++k)
    activate_lane(z + k * H2, u + k * H2, du + k * H2, ddu + k * H2, H2, sh.stiff2);
  for (int j = 0; j < N2; ++j) wd[j] = w[j] * du[j];
  // kappa = w1 + V_k^T (w du)_k, and its products with h', h''.
  double kd[M1], kdd[M1];
  for (int k = 0; k < K; ++k) {
    Eigen::Map<Eigen::Matrix<double, D1, 1>> kk(kd + k * H1, H1);
    kk.noalias() = Blk(V + k * H2 * H1, H2, H1).transpose().lazyProduct(Vec2(wd + k * H2, H2));
  }
  for (int i = 0; i < N1; ++i) {
    const double kappa = kd[i] + w1[i];
    kd[i] = kappa * dh[i];
    kdd[i] = kappa * ddh[i];
  }

  NetworkResponse r;
  for (int k = 0; k < K; ++k) {
    const int o1 = k * H1, o2 = k * H2;
    const Seg1 kdk(kd + o1, H1), kddk(kdd + o1, H1);
    const double* Qk = Q + 6 * k;
    // N_k, S_N, C_N (upper triangle) of lane k.
    double Wn =
        (Seg1(w1 + o1, H1) * Seg1(h + o1, H1)).sum() + (Seg2(w + o2, H2) * Seg2(u + o2, H2)).sum();
    const Seg2 wdk(wd + o2, H2);
    Eigen::Vector3d S((kdk * Seg1(c0 + o1, H1)).sum() + (wdk * Seg2(a1 + o2, H2)).sum(),
                      (kdk * Seg1(c1 + o1, H1)).sum() + (wdk * Seg2(a1 + N2 + o2, H2)).sum(),
                      (kdk * Seg1(c2 + o1, H1)).sum() + (wdk * Seg2(a1 + 2 * N2 + o2, H2)).sum());
    double C[6];
    for (int m = 0; m < 6; ++m) C[m] = (kddk * Seg1(p + m * N1 + o1, H1)).sum() + Qk[m];
    // Second-layer curvature: w_j u''_j grad z_j grad z_j^T for the curved units only.
    for (int j = 0; j < H2; ++j) {
      const double cj = w[o2 + j] * ddu[o2 + j];
      if (cj == 0.0) continue;
      const double* v = V + (o2 + j) * H1;
      double g0 = a1[o2 + j], g1 = a1[N2 + o2 + j], g2 = a1[2 * N2 + o2 + j];
      for (int i = 0; i < H1; ++i) {
        const double vd = v[i] * dh[o1 + i];
        g0 += vd * c0[o1 + i];
        g1 += vd * c1[o1 + i];
        g2 += vd * c2[o1 + i];
      }
      add_outer_upper(C, cj, g0, g1, g2);
    }
    // 1/2 e^T Q e.
    const double Qe0 = Qk[0] * e0 + Qk[1] * e1 + Qk[2] * e2;
    const double Qe1 = Qk[1] * e0 + Qk[3] * e1 + Qk[4] * e2;
    const double Qe2 = Qk[2] * e0 + Qk[4] * e1 + Qk[5] * e2;
    Wn += 0.5 * (e0 * Qe0 + e1 * Qe1 + e2 * Qe2);
    S += Eigen::Vector3d(Qe0, Qe1, Qe2);
    add_lane(sh, omega[k], Wn, S, C, r);
  }
  r.C(1, 0) = r.C(0, 1);
  r.C(2, 0) = r.C(0, 2);
  r.C(2, 1) = r.C(1, 2);
  return r;
}

// ---- The four-wide kernel (session 17): unit-major, the 4 lanes of a unit in one 256-bit
// vector, so every step is vertical (no horizontal sums). GCC's vector extension, compiled for
// AVX2 with FMA only (target attribute on the entry point; without AVX GCC splits the vectors
// into SSE2 halves and it ran at half the portable code's rate, so a processor without AVX2 and
// FMA takes lanes_sum). Contraction: GCC's default in C++ (-ffp-contract=fast; -std=c++20 does
// not turn it off) cannot fuse in baseline x86-64 code (no FMA), so the portable code rounds
// every product; the wide kernels' targets have FMA and fuse multiply-adds (AVX-512 since
// session 48's review, AVX2 since session 51). Both equal the portable code to round-off
// (tested, 1e-13); without the fusion the AVX-512 six-lane kernel ran 2.21-2.25e6 instead of
// 2.32-2.42e6 per second (the same hour), and the AVX2 four-lane one at l = 5.25 mm 2.98e6
// instead of 3.31e6 (session 51, an AMD EPYC without AVX-512).
// -Wpsabi (GCC's note that a 256-bit vector passed by value without AVX changes the ABI) is
// silenced for the rest of this translation unit (and its unity group; the note is issued at
// its end): every function that takes or returns v4 or v8 is always_inline into an entry
// point.
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double v2 __attribute__((vector_size(16)));
typedef double v4 __attribute__((vector_size(32)));
typedef double v8 __attribute__((vector_size(64)));

/// Doubles between one unit's consecutive lane vectors in the packed layout.
template <class VT>
constexpr int kStride = static_cast<int>(sizeof(VT) / sizeof(double));

template <class VT>
[[gnu::always_inline]] inline VT ldv(const double* p) {
  VT r;
  std::memcpy(&r, p, sizeof r);
  return r;
}
template <class VT>
[[gnu::always_inline]] inline void stv(double* p, const VT& x) {
  std::memcpy(p, &x, sizeof x);
}
template <class VT>
[[gnu::always_inline]] inline VT splatv(double x) {
  VT r;
  for (int l = 0; l < kStride<VT>; ++l) r[l] = x;
  return r;
}
/// Lane by lane: x < y ? a : b, and x > y ? a : b.
template <class VT>
[[gnu::always_inline]] inline VT where_less(VT x, VT y, VT a, VT b) {
  return x < y ? a : b;
}
template <class VT>
[[gnu::always_inline]] inline VT where_greater(VT x, VT y, VT a, VT b) {
  return where_less(y, x, a, b);
}
/// True if every lane of x is zero: v8's padding lanes (copies of lane 0) too, which never
/// changes the answer.
template <class VT>
[[gnu::always_inline]] inline bool all_zero(const VT& x) {
  bool zero = true;
  for (int l = 0; l < kStride<VT>; ++l) zero = zero && x[l] == 0.0;
  return zero;
}

/// The activation of a vector of units (lane by lane): sigma, or rho where `stiff`.
template <class VT>
[[gnu::always_inline]] inline void activate_units(VT x, bool stiff, VT& s, VT& ds, VT& dds) {
  const VT one = splatv<VT>(1.0), mone = splatv<VT>(-1.0), zero = splatv<VT>(0.0);
  if (!stiff) {
    VT xc = where_less(x, mone, mone, x);
    xc = where_greater(xc, one, one, xc);
    const VT x2 = xc * xc;
    s = 0.75 * (0.5 * x2 - x2 * x2 * (1.0 / 12.0)) + 0.5 * xc + 3.0 / 16.0 +
        where_greater(x, one, x - one, zero);
    ds = 0.75 * (xc - x2 * xc * (1.0 / 3.0)) + 0.5;
    dds = 0.75 * (one - x2);
  } else {
    const VT xp = where_greater(x, zero, x, zero);
    dds = xp;
    ds = 0.5 * xp * xp;
    s = ds * xp / 3.0;
  }
}

/// The first layer's sums, over n unit vectors (units, or unit pairs): kappa_i = w1_i + sum_j
/// V_ji (w u')_j, then W += w1 . h, S += kappa h' A0, C += kappa h'' (A0 A0^T) (upper
/// triangle). f1(f, i), vv(j, i): the kernel's loads; wd(j): (w u')_j as a vector of the
/// first layer's layout.
template <class VT, class F1, class VV, class WD>
[[gnu::always_inline]] inline void first_layer_sums(int n, int H2, F1 f1, VV vv, WD wd, const VT* h,
                                                    const VT* dh, const VT* ddh, VT& W, VT& S0,
                                                    VT& S1, VT& S2, VT* C) {
  for (int i = 0; i < n; ++i) {
    VT kappa = f1(4, i);
    for (int j = 0; j < H2; ++j) kappa += vv(j, i) * wd(j);
    const VT kd = kappa * dh[i], kdd = kappa * ddh[i];
    W += f1(4, i) * h[i];
    S0 += kd * f1(0, i);
    S1 += kd * f1(1, i);
    S2 += kd * f1(2, i);
    for (int m = 0; m < 6; ++m) C[m] += kdd * f1(5 + m, i);
  }
}
/// The kernel's output: W, S and C (upper triangle) plus the lanes' quadratic term 1/2 e^T Q e
/// (Q's upper triangle at Qp, one vector per entry, `stride` doubles apart), stored as ten
/// vectors `out_stride` doubles apart.
template <class VT>
[[gnu::always_inline]] inline void store_with_quadratic(const double* Qp, int stride,
                                                        const double* e, VT W, VT S0, VT S1, VT S2,
                                                        const VT* C, double* out, int out_stride) {
  VT Qm[6];
  for (int m = 0; m < 6; ++m) Qm[m] = ldv<VT>(Qp + stride * m);
  const VT E0 = splatv<VT>(e[0]), E1 = splatv<VT>(e[1]), E2 = splatv<VT>(e[2]);
  const VT Qe0 = Qm[0] * E0 + Qm[1] * E1 + Qm[2] * E2;
  const VT Qe1 = Qm[1] * E0 + Qm[3] * E1 + Qm[4] * E2;
  const VT Qe2 = Qm[2] * E0 + Qm[4] * E1 + Qm[5] * E2;
  W += 0.5 * (E0 * Qe0 + E1 * Qe1 + E2 * Qe2);
  const VT res[10] = {W,
                      S0 + Qe0,
                      S1 + Qe1,
                      S2 + Qe2,
                      C[0] + Qm[0],
                      C[1] + Qm[1],
                      C[2] + Qm[2],
                      C[3] + Qm[3],
                      C[4] + Qm[4],
                      C[5] + Qm[5]};
  for (int m = 0; m < 10; ++m) stv(out + out_stride * m, res[m]);
}

/// A second-layer unit vector's (w u')_r, with W += w u and S += (w u') A1_r.
template <class VT, class F2>
[[gnu::always_inline]] inline VT second_layer_sums(int r, F2 f2, VT u, VT du, VT& W, VT& S0, VT& S1,
                                                   VT& S2) {
  const VT w = f2(4, r), wd = w * du;
  W += w * u;
  S0 += wd * f2(0, r);
  S1 += wd * f2(1, r);
  S2 += wd * f2(2, r);
  return wd;
}
/// sum_i V_ji h'_i A0_i over n unit vectors: the first layer's part of grad z_j.
template <class VT, class F1, class VV>
[[gnu::always_inline]] inline void grad_z_sums(int j, int n, F1 f1, VV vv, const VT* dh, VT& g0,
                                               VT& g1, VT& g2) {
  for (int i = 0; i < n; ++i) {
    const VT vd = vv(j, i) * dh[i];
    g0 += vd * f1(0, i);
    g1 += vd * f1(1, i);
    g2 += vd * f1(2, i);
  }
}

template <class VT, int H1c, int H2c, int OS = kStride<VT>>
[[gnu::always_inline]] inline void lanes4_body(int h1, int h2, int stiff1, int stiff2,
                                               const double* q, const double* e, double* out) {
  const int H1 = H1c > 0 ? H1c : h1, H2 = H2c > 0 ? H2c : h2;
  constexpr int L = kStride<VT>;
  const auto ld4 = [](const double* p) __attribute__((always_inline)) {
    return ldv<VT>(p);
  };
  const auto splat4 = [](double x) __attribute__((always_inline)) {
    return splatv<VT>(x);
  };
  const double* F1 = q;                 // [f][i][lane], f: c0 c1 c2 b0 w1 p00 p01 p02 p11 p12 p22
  const double* Vp = q + 11 * H1 * L;   // [j][i][lane]
  const double* F2 = Vp + H2 * H1 * L;  // [f][j][lane], f: a10 a11 a12 b1 w
  const double* Qp = F2 + 5 * H2 * L;   // [m][lane]
  const auto f1 = [&](int f, int i) __attribute__((always_inline)) {
    return ld4(F1 + (f * H1 + i) * L);
  };
  const auto f2 = [&](int f, int j) __attribute__((always_inline)) {
    return ld4(F2 + (f * H2 + j) * L);
  };
  const auto vv = [&](int j, int i) __attribute__((always_inline)) {
    return ld4(Vp + (j * H1 + i) * L);
  };
  const VT E0 = splat4(e[0]), E1 = splat4(e[1]), E2 = splat4(e[2]);
  const VT zero = splat4(0.0);
  const auto act = [](VT x, bool stiff, VT& s, VT& ds, VT& dds) __attribute__((always_inline)) {
    activate_units(x, stiff, s, ds, dds);
  };
  VT h[kMaxUnitsPerLane], dh[kMaxUnitsPerLane], ddh[kMaxUnitsPerLane];
  for (int i = 0; i < H1; ++i)
    act(f1(0, i) * E0 + f1(1, i) * E1 + f1(2, i) * E2 + f1(3, i), i >= H1 - stiff1, h[i], dh[i],
        ddh[i]);
  VT u[kMaxUnitsPerLane], du[kMaxUnitsPerLane], ddu[kMaxUnitsPerLane], wd[kMaxUnitsPerLane];
  VT W = zero, S0 = zero, S1 = zero, S2 = zero;
  for (int j = 0; j < H2; ++j) {
    VT z = zero;
    for (int i = 0; i < H1; ++i) z += vv(j, i) * h[i];
    z += f2(0, j) * E0 + f2(1, j) * E1 + f2(2, j) * E2 + f2(3, j);
    act(z, j >= H2 - stiff2, u[j], du[j], ddu[j]);
    wd[j] = second_layer_sums(j, f2, u[j], du[j], W, S0, S1, S2);
  }
  VT C[6] = {zero, zero, zero, zero, zero, zero};
  first_layer_sums(
      H1, H2, f1, vv, [&](int j) __attribute__((always_inline)) { return wd[j]; }, h, dh, ddh, W,
      S0, S1, S2, C);
  // Second-layer curvature, for the units curved in some lane (c_j = 0 in the others).
  for (int j = 0; j < H2; ++j) {
    const VT cj = f2(4, j) * ddu[j];
    if (all_zero(cj)) continue;
    VT g0 = f2(0, j), g1 = f2(1, j), g2 = f2(2, j);
    grad_z_sums(j, H1, f1, vv, dh, g0, g1, g2);
    add_outer_upper(C, cj, g0, g1, g2);
  }
  store_with_quadratic(Qp, L, e, W, S0, S1, S2, C, out, OS);
}

/// The kernel's entry points: 12 / 6 units (the default) with compiled sizes, any other shape
/// with the shape's; AVX2 with FMA where the processor has them (chosen at the build of a law).
template <int H1c, int H2c>
__attribute__((target("avx2,fma"))) void lanes4_avx2(int h1, int h2, int stiff1, int stiff2,
                                                     const double* q, const double* e,
                                                     double* out) {
  lanes4_body<v4, H1c, H2c>(h1, h2, stiff1, stiff2, q, e, out);
}

/// Lanes 4 and 5 of a six-lane pass with AVX2, two units to a 256-bit vector (session 53): in
/// session 51's six-lane kernel (v6) they took a 128-bit vector per unit, which costs a 256-bit
/// vector's issue slot for half its work. Here the units are paired, [unit 2p lanes 4, 5 | unit 2p
/// + 1 lanes 4, 5], in both layers (a layer of odd size ends with a zero unit, which adds nothing:
/// its weights, inputs and products are zero); a sum over the paired index ends with a fold of the
/// two halves, and a second-layer value that multiplies every first-layer pair is broadcast to both
/// halves. The arithmetic is lanes4_body's, in another order of the sums (equal to round-off). `q`:
/// [f][p][4] for the first layer's 11 fields, V as [j][p][4], the second layer's 5 fields as
/// [f][r][4], Q as [m][2]; `out`: lanes 4 and 5 of the six-lane output (stride 8).
[[gnu::always_inline]] inline v2 fold(v4 x) {
  return __builtin_shufflevector(x, x, 0, 1) + __builtin_shufflevector(x, x, 2, 3);
}
/// Half s (0: the pair's first unit, 1: its second) of a pair vector.
[[gnu::always_inline]] inline v2 half(v4 x, int s) {
  return s == 0 ? __builtin_shufflevector(x, x, 0, 1) : __builtin_shufflevector(x, x, 2, 3);
}
/// A pair's activation: both units sigma, both rho, or (stiff units are a layer's last, so
/// only the second can be rho alone) sigma then rho.
[[gnu::always_inline]] inline void activate_pair(v4 x, int stiff_units, v4& s, v4& ds, v4& dds) {
  if (stiff_units != 1) {
    activate_units(x, stiff_units == 2, s, ds, dds);
    return;
  }
  v4 s0, ds0, dds0, s1, ds1, dds1;
  activate_units(x, false, s0, ds0, dds0);
  activate_units(x, true, s1, ds1, dds1);
  s = __builtin_shufflevector(s0, s1, 0, 1, 6, 7);
  ds = __builtin_shufflevector(ds0, ds1, 0, 1, 6, 7);
  dds = __builtin_shufflevector(dds0, dds1, 0, 1, 6, 7);
}
/// The first layer's pairs and the second layer's pairs of a shape.
constexpr int pairs(int units) {
  return (units + 1) / 2;
}
/// Stiff units in pair p of a layer of n units whose last `stiff` are rho (the zero unit that
/// pads an odd layer counts as its partner's kind).
inline int stiff_in_pair(int p, int n, int stiff) {
  const int first = 2 * p, second = std::min(2 * p + 1, n - 1);
  return (first >= n - stiff ? 1 : 0) + (second >= n - stiff ? 1 : 0);
}

template <int H1c, int H2c>
[[gnu::always_inline]] inline void lanes2p_body(int h1, int h2, int stiff1, int stiff2,
                                                const double* q, const double* e, double* out) {
  const int H1 = H1c > 0 ? H1c : h1, H2 = H2c > 0 ? H2c : h2;
  const int P1 = pairs(H1), P2 = pairs(H2);
  const double* F1 = q;                 // [f][p][4], f: c0 c1 c2 b0 w1 p00 p01 p02 p11 p12 p22
  const double* Vp = q + 11 * P1 * 4;   // [j][p][4]
  const double* F2 = Vp + H2 * P1 * 4;  // [f][r][4], f: a10 a11 a12 b1 w
  const double* Qp = F2 + 5 * P2 * 4;   // [m][2]
  const auto f1 = [&](int f, int p) __attribute__((always_inline)) {
    return ldv<v4>(F1 + (f * P1 + p) * 4);
  };
  const auto vv = [&](int j, int p) __attribute__((always_inline)) {
    return ldv<v4>(Vp + (j * P1 + p) * 4);
  };
  const auto f2 = [&](int f, int r) __attribute__((always_inline)) {
    return ldv<v4>(F2 + (f * P2 + r) * 4);
  };
  const v4 E0 = splatv<v4>(e[0]), E1 = splatv<v4>(e[1]), E2 = splatv<v4>(e[2]);
  const v4 zero = splatv<v4>(0.0);
  constexpr int kMaxPairs = kMaxUnitsPerLane / 2;
  v4 h[kMaxPairs], dh[kMaxPairs], ddh[kMaxPairs];
  for (int p = 0; p < P1; ++p)
    activate_pair(f1(0, p) * E0 + f1(1, p) * E1 + f1(2, p) * E2 + f1(3, p),
                  stiff_in_pair(p, H1, stiff1), h[p], dh[p], ddh[p]);
  // Second layer: z_j = sum over the first layer's pairs, folded; then two units to a vector.
  v4 zs[2 * kMaxPairs];
  for (int j = 0; j < H2; ++j) {
    v4 acc = zero;
    for (int p = 0; p < P1; ++p) acc += vv(j, p) * h[p];
    zs[j] = acc;
  }
  if (H2 % 2 == 1) zs[H2] = zero;
  v4 u[kMaxPairs], du[kMaxPairs], ddu[kMaxPairs], wd[kMaxPairs];
  v4 W = zero, S0 = zero, S1 = zero, S2 = zero;
  for (int r = 0; r < P2; ++r) {
    const v4 a = zs[2 * r], b = zs[2 * r + 1];
    const v4 z = __builtin_shufflevector(a, b, 0, 1, 4, 5) +
                 __builtin_shufflevector(a, b, 2, 3, 6, 7) + f2(0, r) * E0 + f2(1, r) * E1 +
                 f2(2, r) * E2 + f2(3, r);
    activate_pair(z, stiff_in_pair(r, H2, stiff2), u[r], du[r], ddu[r]);
    wd[r] = second_layer_sums(r, f2, u[r], du[r], W, S0, S1, S2);
  }
  // w_j u'_j of each second-layer unit in both halves, for every first-layer pair.
  v4 wdb[2 * kMaxPairs];
  for (int j = 0; j < H2; ++j)
    wdb[j] = j % 2 == 0 ? __builtin_shufflevector(wd[j / 2], wd[j / 2], 0, 1, 0, 1)
                        : __builtin_shufflevector(wd[j / 2], wd[j / 2], 2, 3, 2, 3);
  v4 C[6] = {zero, zero, zero, zero, zero, zero};
  first_layer_sums(
      P1, H2, f1, vv, [&](int j) __attribute__((always_inline)) { return wdb[j]; }, h, dh, ddh, W,
      S0, S1, S2, C);
  v2 Cf[6];
  for (int m = 0; m < 6; ++m) Cf[m] = fold(C[m]);
  // Second-layer curvature, for the units curved in lane 4 or 5.
  for (int j = 0; j < H2; ++j) {
    const int r = j / 2, s = j % 2;
    const v2 cj = half(f2(4, r), s) * half(ddu[r], s);
    if (all_zero(cj)) continue;
    v4 g0 = zero, g1 = zero, g2 = zero;
    grad_z_sums(j, P1, f1, vv, dh, g0, g1, g2);
    add_outer_upper(Cf, cj, fold(g0) + half(f2(0, r), s), fold(g1) + half(f2(1, r), s),
                    fold(g2) + half(f2(2, r), s));
  }
  store_with_quadratic(Qp, 2, e, fold(W), fold(S0), fold(S1), fold(S2), Cf, out + 4, 8);
}

/// Doubles of the four-lane block of the split six-lane layout (lanes4_body's, L = 4).
inline int split_block_a(int h1, int h2) {
  return 4 * (11 * h1 + h2 * h1 + 5 * h2 + 6);
}

/// Six lanes with AVX2, split (session 53): lanes 0-3 in lanes4_body's four-lane layout, then
/// lanes 4 and 5 two units to a vector (lanes2p_body). In a rounding window 2.70-2.76e6
/// evaluations of the law per second against 2.28-2.31e6 for v6 (a unit's six lanes in a
/// 256-bit and a 128-bit vector; the same hour, AVX2 kernels forced on an AMD EPYC with
/// AVX-512; docs/database.md "Without AVX-512").
template <int H1c, int H2c>
__attribute__((target("avx2,fma"))) void lanes6s_avx2(int h1, int h2, int stiff1, int stiff2,
                                                      const double* q, const double* e,
                                                      double* out) {
  lanes4_body<v4, H1c, H2c, 8>(h1, h2, stiff1, stiff2, q, e, out);
  lanes2p_body<H1c, H2c>(h1, h2, stiff1, stiff2, q + split_block_a(h1, h2), e, out);
}

/// The same kernel with AVX-512 (session 48, this machine's AMD EPYC): four lanes in a 256-bit
/// vector, with AVX-512VL's 32 vector registers (4.3e6 instead of 3.5e6 evaluations per second
/// between knots), and six lanes (a rounding window's three knots) padded to eight in a 512-bit
/// vector (2.6e6 instead of 1.8e6 for the four-lane AVX2 pass plus a two-lane portable one).
/// Eight lanes with AVX2 alone (GCC splits each vector into two halves) ran at 0.6e6: there six
/// lanes take lanes6s_avx2. That split kernel with AVX-512's registers ran no faster than the
/// eight-lane one (session 53: 2.97-3.11e6 against 3.03-3.37e6 per second in a window).
template <int H1c, int H2c>
__attribute__((target("avx512f,avx512vl"))) void lanes4_avx512(int h1, int h2, int stiff1,
                                                               int stiff2, const double* q,
                                                               const double* e, double* out) {
  lanes4_body<v4, H1c, H2c>(h1, h2, stiff1, stiff2, q, e, out);
}
template <int H1c, int H2c>
__attribute__((target("avx512f,avx512vl"))) void lanes8_avx512(int h1, int h2, int stiff1,
                                                               int stiff2, const double* q,
                                                               const double* e, double* out) {
  lanes4_body<v8, H1c, H2c>(h1, h2, stiff1, stiff2, q, e, out);
}

bool cpu_avx512() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return yes;
}
bool cpu_avx2_fma() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}

/// The wide kernel for this shape, kernel choice and vector width (4 or 8 lanes), or nullptr
/// where the processor has none (then the portable code evaluates).
NetworkLanesAt::WideKernel wide_kernel(int h1, int h2, int width, LanesKernel kernel, bool& split) {
  const bool d = h1 == 12 && h2 == 6;
  split = false;
  if (kernel == LanesKernel::kAuto && cpu_avx512()) {
    if (width == 8) return d ? lanes8_avx512<12, 6> : lanes8_avx512<0, 0>;
    return d ? lanes4_avx512<12, 6> : lanes4_avx512<0, 0>;
  }
  if (kernel == LanesKernel::kPortable || !cpu_avx2_fma()) return nullptr;
  if (width == 8) {
    split = true;
    return d ? lanes6s_avx2<12, 6> : lanes6s_avx2<0, 0>;
  }
  return d ? lanes4_avx2<12, 6> : lanes4_avx2<0, 0>;
}

}  // namespace

NetworkLanesAt::NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta) {
  build(shape, {&theta, &theta}, {0.5, 0.5}, LanesKernel::kPortable);
}

NetworkLanesAt::NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta_a,
                               const std::vector<double>& theta_b, double t, LanesKernel kernel) {
  const double a = 0.5 * (1.0 - t), b = 0.5 * t;
  build(shape, {&theta_a, &theta_a, &theta_b, &theta_b}, {a, a, b, b}, kernel);
}

NetworkLanesAt::NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta_a,
                               const std::vector<double>& theta_b,
                               const std::vector<double>& theta_c, const Eigen::Vector3d& c,
                               LanesKernel kernel) {
  const double a = 0.5 * c(0), b = 0.5 * c(1), d = 0.5 * c(2);
  build(shape, {&theta_a, &theta_a, &theta_b, &theta_b, &theta_c, &theta_c}, {a, a, b, b, d, d},
        kernel);
}

void NetworkLanesAt::build(const NetworkShape& shape,
                           const std::vector<const std::vector<double>*>& thetas,
                           const std::vector<double>& lane_weight, LanesKernel kernel) {
  if (const std::string why = shape.validate(); !why.empty())
    throw std::invalid_argument("NetworkLanesAt: " + why);
  shape_ = shape;
  K_ = static_cast<int>(thetas.size());
  const int H1 = shape.h1, H2 = shape.h2, N1 = K_ * H1, N2 = K_ * H2;
  packed_.assign(static_cast<std::size_t>(11 * N1 + N2 * H1 + 5 * N2), 0.0);
  omega_ = lane_weight;
  Q_.assign(static_cast<std::size_t>(6 * K_), 0.0);
  double* q = packed_.data();
  double* V = q + 11 * N1;
  double* a1 = V + N2 * H1;
  for (int k = 0; k < K_; ++k) {
    if (static_cast<int>(thetas[static_cast<std::size_t>(k)]->size()) != shape.size())
      throw std::invalid_argument("NetworkLanesAt: theta must have shape.size() entries");
    const double* th = thetas[static_cast<std::size_t>(k)]->data();
    // Odd lanes are the mirror images: the E12 column of A0 and A1 and the third row of L
    // negated, so that the lane's network at e is N(M e).
    const double m = k % 2 == 1 ? -1.0 : 1.0;
    for (int i = 0; i < H1; ++i) {
      const double* a = th + shape.a0() + 3 * i;
      const int o = k * H1 + i;
      const double a2 = m * a[2];
      q[o] = a[0];
      q[N1 + o] = a[1];
      q[2 * N1 + o] = a2;
      q[3 * N1 + o] = th[shape.b0() + i];
      q[4 * N1 + o] = th[shape.w1() + i];
      q[5 * N1 + o] = a[0] * a[0];
      q[6 * N1 + o] = a[0] * a[1];
      q[7 * N1 + o] = a[0] * a2;
      q[8 * N1 + o] = a[1] * a[1];
      q[9 * N1 + o] = a[1] * a2;
      q[10 * N1 + o] = a2 * a2;
    }
    std::copy(th + shape.V(), th + shape.V() + H2 * H1, V + k * H2 * H1);
    for (int j = 0; j < H2; ++j) {
      const double* a = th + shape.a1() + 3 * j;
      const int o = k * H2 + j;
      a1[o] = a[0];
      a1[N2 + o] = a[1];
      a1[2 * N2 + o] = m * a[2];
      a1[3 * N2 + o] = th[shape.b1() + j];
      a1[4 * N2 + o] = th[shape.w() + j];
    }
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> L =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(th + shape.L());
    L.row(2) *= m;
    const Eigen::Matrix3d Qk = L * L.transpose();
    double* Qp = Q_.data() + 6 * k;
    Qp[0] = Qk(0, 0);
    Qp[1] = Qk(0, 1);
    Qp[2] = Qk(0, 2);
    Qp[3] = Qk(1, 1);
    Qp[4] = Qk(1, 2);
    Qp[5] = Qk(2, 2);
  }
  // The wide kernel's layout (four lanes in four, six in eight, where the processor has one).
  width_ = K_ == 4 ? 4 : 8;
  bool split = false;
  wide_ = K_ >= 4 ? wide_kernel(H1, H2, width_, kernel, split) : nullptr;
  packed4_.clear();
  if (wide_ && split) {
    // Lanes 0-3 unit-major four wide, then lanes 4 and 5 two units to a vector (lanes6s_avx2).
    const int P1 = pairs(H1), P2 = pairs(H2);
    packed4_.assign(
        static_cast<std::size_t>(split_block_a(H1, H2) + 4 * (11 * P1 + H2 * P1 + 5 * P2) + 12),
        0.0);
    double* F1 = packed4_.data();
    double* V4 = F1 + 11 * H1 * 4;
    double* F2 = V4 + H2 * H1 * 4;
    double* Q4 = F2 + 5 * H2 * 4;
    for (int k = 0; k < 4; ++k) {
      for (int f = 0; f < 11; ++f)
        for (int i = 0; i < H1; ++i) F1[(f * H1 + i) * 4 + k] = q[f * N1 + k * H1 + i];
      for (int j = 0; j < H2; ++j)
        for (int i = 0; i < H1; ++i) V4[(j * H1 + i) * 4 + k] = V[(k * H2 + j) * H1 + i];
      for (int f = 0; f < 5; ++f)
        for (int j = 0; j < H2; ++j) F2[(f * H2 + j) * 4 + k] = a1[f * N2 + k * H2 + j];
      for (int m = 0; m < 6; ++m) Q4[m * 4 + k] = Q_[static_cast<std::size_t>(6 * k + m)];
    }
    // Pair vectors [unit 2p lanes 4, 5 | unit 2p + 1 lanes 4, 5]; a padding unit stays zero.
    double* B1 = packed4_.data() + split_block_a(H1, H2);
    double* VB = B1 + 11 * P1 * 4;
    double* B2 = VB + H2 * P1 * 4;
    double* QB = B2 + 5 * P2 * 4;
    for (int k = 4; k < 6; ++k) {
      const int l = k - 4;
      for (int f = 0; f < 11; ++f)
        for (int i = 0; i < H1; ++i)
          B1[(f * P1 + i / 2) * 4 + 2 * (i % 2) + l] = q[f * N1 + k * H1 + i];
      for (int j = 0; j < H2; ++j)
        for (int i = 0; i < H1; ++i)
          VB[(j * P1 + i / 2) * 4 + 2 * (i % 2) + l] = V[(k * H2 + j) * H1 + i];
      for (int f = 0; f < 5; ++f)
        for (int j = 0; j < H2; ++j)
          B2[(f * P2 + j / 2) * 4 + 2 * (j % 2) + l] = a1[f * N2 + k * H2 + j];
      for (int m = 0; m < 6; ++m) QB[m * 2 + l] = Q_[static_cast<std::size_t>(6 * k + m)];
    }
  } else if (wide_) {
    const int L = width_;
    packed4_.assign(static_cast<std::size_t>(L * (11 * H1 + H2 * H1 + 5 * H2 + 6)), 0.0);
    double* F1 = packed4_.data();
    double* V4 = F1 + 11 * H1 * L;
    double* F2 = V4 + H2 * H1 * L;
    double* Q4 = F2 + 5 * H2 * L;
    for (int kk = 0; kk < L; ++kk) {
      const int k = kk < K_ ? kk : 0;  // padding lanes: copies of lane 0, not summed
      for (int f = 0; f < 11; ++f)
        for (int i = 0; i < H1; ++i) F1[(f * H1 + i) * L + kk] = q[f * N1 + k * H1 + i];
      for (int j = 0; j < H2; ++j)
        for (int i = 0; i < H1; ++i) V4[(j * H1 + i) * L + kk] = V[(k * H2 + j) * H1 + i];
      for (int f = 0; f < 5; ++f)
        for (int j = 0; j < H2; ++j) F2[(f * H2 + j) * L + kk] = a1[f * N2 + k * H2 + j];
      for (int m = 0; m < 6; ++m) Q4[m * L + kk] = Q_[static_cast<std::size_t>(6 * k + m)];
    }
  }
  W0_ = 0.0;
  S0_.setZero();
  const NetworkResponse n0 = evaluate(Eigen::Vector3d::Zero());
  W0_ = n0.W;
  S0_ = n0.S;  // mirror-symmetric lanes: S0(2) = 0 up to round-off
  S0_(2) = 0.0;
}

bool NetworkLanesAt::six_lane_kernel() {
  return cpu_avx512() || cpu_avx2_fma();
}

NetworkResponse NetworkLanesAt::evaluate(const Eigen::Vector3d& e) const {
  const double *q = packed_.data(), *om = omega_.data(), *Q = Q_.data();
  NetworkResponse r;
  if (wide_) {
    double ls[80];  // per quantity m (N, S_N, C_N upper triangle) lane k at width m + k
    wide_(shape_.h1, shape_.h2, shape_.stiff1, shape_.stiff2, packed4_.data(), e.data(), ls);
    const int L = width_;
    for (int k = 0; k < K_; ++k) {
      const double C[6] = {ls[4 * L + k], ls[5 * L + k], ls[6 * L + k],
                           ls[7 * L + k], ls[8 * L + k], ls[9 * L + k]};
      add_lane(shape_, omega_[static_cast<std::size_t>(k)], ls[k],
               Eigen::Vector3d(ls[L + k], ls[2 * L + k], ls[3 * L + k]), C, r);
    }
    r.C(1, 0) = r.C(0, 1);
    r.C(2, 0) = r.C(0, 2);
    r.C(2, 1) = r.C(1, 2);
  } else if (shape_.h1 == 12 && shape_.h2 == 6 && K_ == 2)
    r = lanes_sum<12, 6, 2>(shape_, K_, q, om, Q, e);
  else if (shape_.h1 == 12 && shape_.h2 == 6 && K_ == 4)
    r = lanes_sum<12, 6, 4>(shape_, K_, q, om, Q, e);
  else
    r = lanes_sum<0, 0, 0>(shape_, K_, q, om, Q, e);
  r.W -= W0_ + S0_.dot(e);
  r.S -= S0_;
  return r;
}

}  // namespace knit::material
