// The shell element tangent's hot loop (element_kernel.hpp); no Eigen in this file.
#include "knit/macro/element_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

// The vector type never crosses a call (every helper is always inlined): no ABI concern.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace knit::macro::kernel {

namespace {

/// Vectors of doubles (GCC vector extensions): v8 for the AVX-512 version, v4 for the AVX2
/// version, v2 for the default SSE2 version (one register each; a wider vector than the
/// instruction set's is emulated by pairs, slower).
typedef double v8 __attribute__((vector_size(64)));
typedef double v4 __attribute__((vector_size(32)));
typedef double v2 __attribute__((vector_size(16)));

template <typename V>
inline __attribute__((always_inline)) V load(const double* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <typename V>
inline __attribute__((always_inline)) void store(double* p, V v) {
  std::memcpy(p, &v, sizeof v);
}
/// x in every lane. 512-bit vectors: lane 0 shuffled into all (one vbroadcastsd; the lane-by-lane
/// assignment, and x - V{}, made GCC emit eight masked inserts: the AVX-512 kernel then ran
/// slower than the AVX2 one; V{} + x costs a scalar add first); the narrower ones as before.
template <typename V>
inline __attribute__((always_inline)) V splat(double x) {
  if constexpr (sizeof(V) == 64) {
    const V v{x};  // x in lane 0, then broadcast (one vbroadcastsd)
    return __builtin_shufflevector(v, v, 0, 0, 0, 0, 0, 0, 0, 0);
  } else {
    V v;
    for (int i = 0; i < int(sizeof v / sizeof x); ++i) v[i] = x;
    return v;
  }
}

/// KT(c, l) = sum_k W(c, k) PhiT(l, k) for rows c in [c_begin, c_end) (rounded up to the
/// tile) and all padded columns l, in tiles of CV vectors V of rows x 4 columns (4 CV
/// accumulators: 8 of the 16 registers with CV = 2; tiles of 16 rows for AVX-512, 8 for AVX2, 4
/// for SSE2).
/// tri_origin >= 0: only the tiles holding some c - tri_origin <= l (a lower triangle).
/// Always inlined, so it is compiled for the instruction set of its caller.
template <typename V, int CV>
inline __attribute__((always_inline)) void product_rows(const double* W, const double* PhiT,
                                                        double* KT, int ldw, int nlp, int nk,
                                                        int c_begin, int c_end, int tri_origin) {
  for (int l0 = 0; l0 < nlp; l0 += 4)
    for (int c0 = c_begin; c0 < c_end; c0 += CV * int(sizeof(V) / sizeof(double))) {
      if (tri_origin >= 0 && c0 - tri_origin > l0 + 3) break;  // all m > l: upper triangle
      constexpr int lanes = sizeof(V) / sizeof(double);
      V acc[4][CV];
      for (int j = 0; j < 4; ++j)
        for (int h = 0; h < CV; ++h) acc[j][h] = splat<V>(0.0);
      const double* w = W + c0;
      const double* b = PhiT + l0;
      for (int k = 0; k < nk; ++k, w += ldw, b += nlp) {
        V x[CV];
        for (int h = 0; h < CV; ++h) x[h] = load<V>(w + lanes * h);
        for (int j = 0; j < 4; ++j) {
          const V bj = splat<V>(b[j]);
          for (int h = 0; h < CV; ++h) acc[j][h] += x[h] * bj;
        }
      }
      double* out = KT + static_cast<long>(l0) * ldw + c0;
      for (int j = 0; j < 4; ++j)
        for (int h = 0; h < CV; ++h) store<V>(out + j * ldw + lanes * h, acc[j][h]);
    }
}

/// out(c, j) = sum_k X(c, k) B(j, k) for rows c in [0, rows) (rounded up to the tile) and the
/// NJ columns j, X(c, k) = X[k xs + c], B(j, k) = B[k NJ + j], out(c, j) = out[j os + c]; tiles
/// of CV vectors of rows x NJ columns (NJ <= 6 with CV = 2: at most 12 accumulators). The two
/// steps of the sum-factorized product.
template <typename V, int CV, int NJ>
inline __attribute__((always_inline)) void narrow_product(const double* X, long xs, const double* B,
                                                          int nk, double* out, long os, int rows) {
  constexpr int lanes = sizeof(V) / sizeof(double);
  for (int c0 = 0; c0 < rows; c0 += CV * lanes) {
    V acc[NJ][CV];
    for (int j = 0; j < NJ; ++j)
      for (int h = 0; h < CV; ++h) acc[j][h] = splat<V>(0.0);
    const double* x = X + c0;
    const double* b = B;
    for (int k = 0; k < nk; ++k, x += xs, b += NJ) {
      V xv[CV];
      for (int h = 0; h < CV; ++h) xv[h] = load<V>(x + lanes * h);
      for (int j = 0; j < NJ; ++j) {
        const V bj = splat<V>(b[j]);
        for (int h = 0; h < CV; ++h) acc[j][h] += xv[h] * bj;
      }
    }
    for (int j = 0; j < NJ; ++j)
      for (int h = 0; h < CV; ++h) store<V>(out + j * os + c0 + lanes * h, acc[j][h]);
  }
}

/// narrow_product with NJ = nj (2 <= nj <= 6), chosen at run time.
template <typename V, int CV, int NJ = 2>
inline __attribute__((always_inline)) void narrow_product_n(int nj, const double* X, long xs,
                                                            const double* B, int nk, double* out,
                                                            long os, int rows) {
  if constexpr (NJ < 6) {
    if (nj != NJ) {
      narrow_product_n<V, CV, NJ + 1>(nj, X, xs, B, nk, out, os, rows);
      return;
    }
  }
  narrow_product<V, CV, NJ>(X, xs, B, nk, out, os, rows);
}

/// Sum-factorized Phi^T W^T (element_kernel.hpp, ElementTangentInput::Au):
///   Y(c, (5 qv + f) nu + lu) = sum_qu a_{du(f)}(lu, qu) W(c, 5 (qu + nqu qv) + f)
///   KT(c, lu + nu lv)        = sum_{qv, f} b_{dv(f)}(lv, qv) Y(c, (5 qv + f) nu + lu)
template <typename V, int CV>
inline __attribute__((always_inline)) void factorized_product(const ElementTangentInput& in,
                                                              const double* W, double* KT) {
  constexpr int kDu[5] = {1, 0, 2, 1, 0};
  const long ldw = workspace_rows(in.nl);
  const int rows = in.pairs * in.nl, nu = in.nu, nqu = in.nqu;
  for (int qv = 0; qv < in.nqv; ++qv)
    for (int f = 0; f < 5; ++f)
      narrow_product_n<V, CV>(nu, W + (5L * nqu * qv + f) * ldw, 5 * ldw, in.Au + kDu[f] * nqu * nu,
                              nqu, in.Y + (5L * qv + f) * nu * ldw, ldw, rows);
  for (int lu = 0; lu < nu; ++lu)
    narrow_product_n<V, CV>(in.nv, in.Y + lu * ldw, nu * ldw, in.Bk, 5 * in.nqv, KT + lu * ldw,
                            nu * ldw, rows);
}

/// W(p nl + l, 5 q + f) = sum_g H_q(3 f + i, 3 g + j) Phi_g(l, q), (i, j) = pair p: per point
/// q and chunk of LC vectors of l, the five columns Phi_g(chunk, q) are held in registers
/// while every (pair, f) of the point is computed from them (one store per output vector
/// instead of five loads). Vectors in [nl, padded_functions(nl)) run into the next pair's
/// first rows (with zeros: PhiT's padding): the chunks are taken last to first, so the next
/// pair's own first chunk overwrites them later; the last pair's overrun stays in W's padding
/// rows (workspace_rows).
template <typename V, int LC>
inline __attribute__((always_inline)) void w_columns(const ElementTangentInput& in, double* W) {
  constexpr int lanes = sizeof(V) / sizeof(double), chunk = LC * lanes;
  const int nl = in.nl, nlp = padded_functions(nl), ldw = workspace_rows(nl);
  const int chunks = (nl + chunk - 1) / chunk;
  for (int q = 0; q < in.nq; ++q) {
    const double* Hq = in.H + 225 * q;
    const double* Phi = in.PhiT + 5L * q * nlp;
    for (int ch = chunks - 1; ch >= 0; --ch) {
      const int l0 = ch * chunk;
      V c[5][LC];
      for (int g = 0; g < 5; ++g)
        for (int h = 0; h < LC; ++h)
          c[g][h] = l0 + lanes * h < nlp ? load<V>(Phi + g * nlp + l0 + lanes * h) : splat<V>(0.0);
      for (int p = 0; p < in.pairs; ++p)
        for (int f = 0; f < 5; ++f) {
          const int row = 3 * f + in.pi[p], cj = in.pj[p];
          const V h0 = splat<V>(Hq[row + 15 * cj]), h1 = splat<V>(Hq[row + 15 * (3 + cj)]),
                  h2 = splat<V>(Hq[row + 15 * (6 + cj)]), h3 = splat<V>(Hq[row + 15 * (9 + cj)]),
                  h4 = splat<V>(Hq[row + 15 * (12 + cj)]);
          double* w = W + static_cast<long>(5 * q + f) * ldw + p * nl + l0;
          for (int h = 0; h < LC; ++h)
            if (l0 + lanes * h < nlp)
              store<V>(w + lanes * h,
                       h0 * c[0][h] + h1 * c[1][h] + h2 * c[2][h] + h3 * c[3][h] + h4 * c[4][h]);
        }
    }
  }
}

/// The kernel's body, compiled into each version below.
template <typename V, int CV>
inline __attribute__((always_inline)) void blocks(const ElementTangentInput& in, double* W,
                                                  double* KT) {
  const int nl = in.nl, nlp = padded_functions(nl), ldw = workspace_rows(nl);
  const int nk = 5 * in.nq;
  w_columns<V, (sizeof(V) == 64 ? 4 : 2)>(in, W);
  if (in.Au && in.Bk && in.Y && sum_factorized(in.nu, in.nv)) {
    factorized_product<V, CV>(in, W, KT);
    return;
  }
  // Rows c: the whole pairs [0, full) as one range, then each triangular pair on its own (in
  // increasing order: a tile's overrun into the next pair is overwritten by that pair).
  if (in.full > 0) product_rows<V, CV>(W, in.PhiT, KT, ldw, nlp, nk, 0, in.full * nl, -1);
  for (int p = in.full; p < in.pairs; ++p)
    product_rows<V, CV>(W, in.PhiT, KT, ldw, nlp, nk, p * nl, (p + 1) * nl, p * nl);
}

/// point_matrix (element_kernel.hpp), compiled into each version below.
inline __attribute__((always_inline)) void point_matrix_body(const PointState& s, const double* T,
                                                             double dA, double* H, bool& symmetric,
                                                             bool use_symmetry) {
  const double ij = 1.0 / s.j;
  // Q_alpha e_i: Q1 e_i = e_i x a2, Q2 e_i = a1 x e_i; Pr = I - a3 a3^T; P_alpha = Pr Q_alpha / j,
  // so that a3_,(l,i) = R1_l P1(:, i) + R2_l P2(:, i). Row-major 3 x 3.
  double Q[2][3][3], P[2][3][3];
  for (int i = 0; i < 3; ++i) {
    double e[3] = {0.0, 0.0, 0.0}, c1[3], c2[3];
    e[i] = 1.0;
    cross3(e, s.a2, c1);
    cross3(s.a1, e, c2);
    for (int k = 0; k < 3; ++k) Q[0][k][i] = c1[k], Q[1][k][i] = c2[k];
  }
  for (int al = 0; al < 2; ++al)
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) {
        const double a3Q = s.a3[0] * Q[al][0][i] + s.a3[1] * Q[al][1][i] + s.a3[2] * Q[al][2][i];
        P[al][k][i] = ij * (Q[al][k][i] - s.a3[k] * a3Q);
      }
  // G (6 x 15): strain variations B(:, 3l+i) = sum_f Phi_f(l) G(:, 3f+i), rows eps11, eps22,
  // 2eps12, kap11, kap22, 2kap12. Nonzero: columns 0-5 (f = R_1, R_2) and -a3 (or -2 a3) in
  // the bending row of each second derivative: f = 2 (R_11) row 3, f = 3 (R_12) row 5 (x2),
  // f = 4 (R_22) row 4.
  double G[6][6] = {};
  const double* ak[3] = {s.a11, s.a22, s.a12};
  const double ck[3] = {1.0, 1.0, 2.0};
  for (int i = 0; i < 3; ++i) {
    G[0][i] = s.a1[i];
    G[2][i] = s.a2[i];
    G[1][3 + i] = s.a2[i];
    G[2][3 + i] = s.a1[i];
    for (int k = 0; k < 3; ++k)
      for (int al = 0; al < 2; ++al)
        G[3 + k][3 * al + i] =
            -ck[k] * (ak[k][0] * P[al][0][i] + ak[k][1] * P[al][1][i] + ak[k][2] * P[al][2][i]);
  }
  constexpr int kRow[3] = {3, 5, 4};  // bending row of f = 2, 3, 4
  constexpr double kScale[3] = {1.0, 2.0, 1.0};
  // Covariant section tangent Dc = [[T^T A T, T^T B T], [T^T B T, T^T D T]] (column-major
  // 6 x 6), scaled by dA.
  double Dc[36];
  const double* blocks[3] = {s.A, s.B, s.D};
  const int at[4][2] = {{0, 0}, {0, 3}, {3, 0}, {3, 3}};
  const int which[4] = {0, 1, 1, 2};
  double dmax = 0.0;
  for (int b = 0; b < 4; ++b) {
    const double* X = blocks[which[b]];  // column-major 3 x 3
    double Z[9];                         // X T
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        Z[r + 3 * c] = X[r] * T[3 * c] + X[r + 3] * T[1 + 3 * c] + X[r + 6] * T[2 + 3 * c];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) {
        const double y =
            T[3 * r] * Z[3 * c] + T[1 + 3 * r] * Z[1 + 3 * c] + T[2 + 3 * r] * Z[2 + 3 * c];
        Dc[(at[b][0] + r) + 6 * (at[b][1] + c)] = y;
        dmax = std::max(dmax, std::abs(y));
      }
  }
  bool sym_here = true;
  for (int c = 0; c < 6; ++c)
    for (int r = 0; r < c; ++r)
      if (std::abs(Dc[r + 6 * c] - Dc[c + 6 * r]) > 1e-12 * dmax) sym_here = false;
  if (!sym_here) symmetric = false;
  // A symmetric section tangent gives a symmetric material part G^T E: its lower triangle
  // (rows a >= col) computed, the upper mirrored (~40 % of the multiplications of H).
  const bool lower = use_symmetry && sym_here;
  // E = dA Dc G (6 x 15): columns 0-5 full, column 3f+i of f >= 2 is Dc(:, row f) x G entry.
  double E[15][6];
  for (int col = 0; col < 6; ++col)
    for (int r = 0; r < 6; ++r) {
      double acc = 0.0;
      for (int k = 0; k < 6; ++k) acc += Dc[r + 6 * k] * G[k][col];
      E[col][r] = dA * acc;
    }
  for (int f = 2; f < 5; ++f)
    for (int i = 0; i < 3; ++i) {
      const double gi = -kScale[f - 2] * s.a3[i];
      for (int r = 0; r < 6; ++r) E[3 * f + i][r] = dA * Dc[r + 6 * kRow[f - 2]] * gi;
    }
  // Material part H = G^T E (column-major 15 x 15), the lower triangle only if `lower`.
  for (int col = 0; col < 15; ++col) {
    double* Hc = H + 15 * col;
    const double* Ec = E[col];
    for (int a = lower ? std::min(col, 6) : 0; a < 6; ++a) {
      double acc = 0.0;
      for (int r = 0; r < 6; ++r) acc += G[r][a] * Ec[r];
      Hc[a] = acc;
    }
    for (int f = 2; f < 5; ++f)
      for (int i = 0; i < 3; ++i)
        if (!lower || 3 * f + i >= col) Hc[3 * f + i] = -kScale[f - 2] * s.a3[i] * Ec[kRow[f - 2]];
  }
  if (lower)
    for (int col = 1; col < 15; ++col)
      for (int a = 0; a < col; ++a) H[a + 15 * col] = H[col + 15 * a];
  // Geometric part: n : eps_,rs + m : kappa_,rs (the variations listed in shell_model.hpp).
  double v[3], w[3];
  const double va3 = bending_vector(s, v, w);
  double t[2][3], h[2][3];
  cross3(s.a2, s.a3, t[0]);  // t_alpha = a3^T Q_alpha
  cross3(s.a3, s.a1, t[1]);
  cross3(s.a2, w, h[0]);  // h_alpha = v^T P_alpha = w^T Q_alpha / j
  cross3(w, s.a1, h[1]);
  for (int k = 0; k < 3; ++k) h[0][k] *= ij, h[1][k] *= ij;
  const double Wm[3][3] = {{0.0, w[2], -w[1]}, {-w[2], 0.0, w[0]}, {w[1], -w[0], 0.0}};
  for (int al = 0; al < 2; ++al)
    for (int be = 0; be < 2; ++be) {
      const double Nab = al == be ? s.N[al] : s.N[2];
      const double sw = al == be ? 0.0 : (al == 0 ? -ij : ij);
      for (int jj = 0; jj < 3; ++jj)
        for (int i = 0; i < 3; ++i) {
          const double QP =
              Q[al][0][i] * P[be][0][jj] + Q[al][1][i] * P[be][1][jj] + Q[al][2][i] * P[be][2][jj];
          double gab = ij * (t[al][i] * h[be][jj] + h[al][i] * t[be][jj] + va3 * QP);
          if (i == jj) gab += Nab;
          gab += sw * Wm[i][jj];
          H[(3 * al + i) + 15 * (3 * be + jj)] += dA * gab;
        }
    }
  // m : (a_ab,r . a3_,s + a_ab,s . a3_,r): second-derivative functions f = 2, 3, 4.
  const double cf[3] = {s.M[0], 2.0 * s.M[2], s.M[1]};
  for (int f = 0; f < 3; ++f)
    for (int be = 0; be < 2; ++be)
      for (int jj = 0; jj < 3; ++jj)
        for (int i = 0; i < 3; ++i) {
          const double X = -dA * cf[f] * P[be][i][jj];
          H[(3 * (f + 2) + i) + 15 * (3 * be + jj)] += X;
          H[(3 * be + jj) + 15 * (3 * (f + 2) + i)] += X;
        }
}

__attribute__((target("arch=x86-64-v4"))) void point_matrix_v4(const PointState& s, const double* T,
                                                               double dA, double* H,
                                                               bool& symmetric, bool use_symmetry) {
  point_matrix_body(s, T, dA, H, symmetric, use_symmetry);
}

__attribute__((target("arch=x86-64-v3"))) void point_matrix_v3(const PointState& s, const double* T,
                                                               double dA, double* H,
                                                               bool& symmetric, bool use_symmetry) {
  point_matrix_body(s, T, dA, H, symmetric, use_symmetry);
}

void point_matrix_default(const PointState& s, const double* T, double dA, double* H,
                          bool& symmetric, bool use_symmetry) {
  point_matrix_body(s, T, dA, H, symmetric, use_symmetry);
}

__attribute__((target("arch=x86-64-v4"))) void blocks_v4(const ElementTangentInput& in, double* W,
                                                         double* KT) {
  blocks<v8, 2>(in, W, KT);
}

__attribute__((target("arch=x86-64-v3"))) void blocks_v3(const ElementTangentInput& in, double* W,
                                                         double* KT) {
  blocks<v4, 2>(in, W, KT);
}

void blocks_default(const ElementTangentInput& in, double* W, double* KT) {
  blocks<v2, 2>(in, W, KT);
}

/// current_derivatives and add_point_forces (element_kernel.hpp), compiled into each version:
/// contiguous vectors of l (V: one register), a lane sum at the end.
template <typename V>
inline __attribute__((always_inline)) double lane_sum(V v) {
  double s = 0.0;
  for (int k = 0; k < int(sizeof(V) / sizeof(double)); ++k) s += v[k];
  return s;
}

template <typename V>
inline __attribute__((always_inline)) void derivatives_body(const double* Phi, const double* xT,
                                                            int nl, double* d) {
  constexpr int lanes = sizeof(V) / sizeof(double);
  const int nlp = padded_functions(nl);
  V acc[3][5];
  for (int i = 0; i < 3; ++i)
    for (int f = 0; f < 5; ++f) acc[i][f] = splat<V>(0.0);
  for (int l0 = 0; l0 < nlp; l0 += lanes) {
    const V x0 = load<V>(xT + l0), x1 = load<V>(xT + nlp + l0), x2 = load<V>(xT + 2 * nlp + l0);
    for (int f = 0; f < 5; ++f) {
      const V p = load<V>(Phi + f * nlp + l0);
      acc[0][f] += p * x0;
      acc[1][f] += p * x1;
      acc[2][f] += p * x2;
    }
  }
  for (int i = 0; i < 3; ++i) {
    d[6 * i] = 0.0;  // the position: not needed
    for (int f = 0; f < 5; ++f) d[6 * i + 1 + f] = lane_sum(acc[i][f]);
  }
}

template <typename V>
inline __attribute__((always_inline)) void forces_body(const double* Phi, const double* g, int nl,
                                                       double* feT) {
  constexpr int lanes = sizeof(V) / sizeof(double);
  const int nlp = padded_functions(nl);
  for (int l0 = 0; l0 < nlp; l0 += lanes) {
    V p[5];
    for (int f = 0; f < 5; ++f) p[f] = load<V>(Phi + f * nlp + l0);
    for (int i = 0; i < 3; ++i) {
      V a = load<V>(feT + i * nlp + l0);
      for (int f = 0; f < 5; ++f) a += p[f] * splat<V>(g[3 * f + i]);
      store<V>(feT + i * nlp + l0, a);
    }
  }
}

__attribute__((target("arch=x86-64-v4"))) void derivatives_v4(const double* Phi, const double* xT,
                                                              int nl, double* d) {
  derivatives_body<v8>(Phi, xT, nl, d);
}
__attribute__((target("arch=x86-64-v3"))) void derivatives_v3(const double* Phi, const double* xT,
                                                              int nl, double* d) {
  derivatives_body<v4>(Phi, xT, nl, d);
}
void derivatives_default(const double* Phi, const double* xT, int nl, double* d) {
  derivatives_body<v2>(Phi, xT, nl, d);
}
__attribute__((target("arch=x86-64-v4"))) void forces_v4(const double* Phi, const double* g, int nl,
                                                         double* feT) {
  forces_body<v8>(Phi, g, nl, feT);
}
__attribute__((target("arch=x86-64-v3"))) void forces_v3(const double* Phi, const double* g, int nl,
                                                         double* feT) {
  forces_body<v4>(Phi, g, nl, feT);
}
void forces_default(const double* Phi, const double* g, int nl, double* feT) {
  forces_body<v2>(Phi, g, nl, feT);
}

}  // namespace

bool cpu_has_x86_64_v3() {
  static const bool v3 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
           __builtin_cpu_supports("bmi2");
  }();
  return v3;
}

bool cpu_has_x86_64_v4() {
  static const bool v4 = [] {
    __builtin_cpu_init();
    return cpu_has_x86_64_v3() && __builtin_cpu_supports("avx512f") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512cd") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
  }();
  return v4;
}

Isa resolve(Isa isa) {
  if (isa == Isa::kAuto) isa = Isa::kX86_64_v4;
  if (isa == Isa::kX86_64_v4 && !cpu_has_x86_64_v4()) isa = Isa::kX86_64_v3;
  if (isa == Isa::kX86_64_v3 && !cpu_has_x86_64_v3()) isa = Isa::kDefault;
  return isa;
}

namespace {
/// Calls the version of a kernel function that `isa` runs on this CPU.
template <typename Fn, typename... Args>
void dispatch(Isa isa, Fn v4, Fn v3, Fn plain, Args&&... args) {
  const Isa run = resolve(isa);
  const Fn fn = run == Isa::kX86_64_v4 ? v4 : (run == Isa::kX86_64_v3 ? v3 : plain);
  fn(std::forward<Args>(args)...);
}
}  // namespace

void element_tangent_blocks(const ElementTangentInput& in, double* W, double* KT, Isa isa) {
  dispatch(isa, blocks_v4, blocks_v3, blocks_default, in, W, KT);
}

void point_matrix(const PointState& s, const double* T, double dA, double* H, bool& symmetric,
                  Isa isa, bool use_symmetry) {
  dispatch(isa, point_matrix_v4, point_matrix_v3, point_matrix_default, s, T, dA, H, symmetric,
           use_symmetry);
}

void current_derivatives(const double* Phi, const double* xT, int nl, double* d, Isa isa) {
  dispatch(isa, derivatives_v4, derivatives_v3, derivatives_default, Phi, xT, nl, d);
}

void add_point_forces(const double* Phi, const double* g, int nl, double* feT, Isa isa) {
  dispatch(isa, forces_v4, forces_v3, forces_default, Phi, g, nl, feT);
}

}  // namespace knit::macro::kernel
