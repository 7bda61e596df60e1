// The shell element tangent's hot loop (element_kernel.hpp); no Eigen in this file.
#include "knit/macro/element_kernel.hpp"

#include <cstring>

// The vector type never crosses a call (every helper is always inlined): no ABI concern.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace knit::macro::kernel {

namespace {

/// Vectors of doubles (GCC vector extensions): v4 for the AVX2 version (one register), v2 for
/// the default SSE2 version (one register; a v4 there is emulated by pairs, slower).
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
template <typename V>
inline __attribute__((always_inline)) V splat(double x) {
  V v;
  for (int i = 0; i < int(sizeof v / sizeof x); ++i) v[i] = x;
  return v;
}

/// KT(c, l) = sum_k W(c, k) PhiT(l, k) for rows c in [c_begin, c_end) (rounded up to the
/// tile) and all padded columns l, in tiles of CV vectors V of rows x 4 columns (4 CV
/// accumulators: 8 of the 16 registers with CV = 2; tiles of 8 rows for AVX2, 4 for SSE2).
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

/// The kernel's body, compiled into each version below.
template <typename V, int CV>
inline __attribute__((always_inline)) void blocks(const ElementTangentInput& in, double* W,
                                                  double* KT) {
  const int nl = in.nl, nlp = padded_functions(nl), ldw = workspace_rows(nl);
  const int nk = 5 * in.nq;
  // W(p nl + l, 5 q + f) = sum_g H_q(3 f + i, 3 g + j) Phi_g(l, q), (i, j) = pair p.
  for (int q = 0; q < in.nq; ++q) {
    const double* Hq = in.H + 225 * q;
    const double* c0 = in.PhiT + 5 * q * nlp;
    const double *c1 = c0 + nlp, *c2 = c1 + nlp, *c3 = c2 + nlp, *c4 = c3 + nlp;
    for (int p = 0; p < in.pairs; ++p)
      for (int f = 0; f < 5; ++f) {
        const int row = 3 * f + in.pi[p], cj = in.pj[p];
        const double h0 = Hq[row + 15 * cj], h1 = Hq[row + 15 * (3 + cj)],
                     h2 = Hq[row + 15 * (6 + cj)], h3 = Hq[row + 15 * (9 + cj)],
                     h4 = Hq[row + 15 * (12 + cj)];
        double* w = W + static_cast<long>(5 * q + f) * ldw + p * nl;
        for (int l = 0; l < nl; ++l)
          w[l] = h0 * c0[l] + h1 * c1[l] + h2 * c2[l] + h3 * c3[l] + h4 * c4[l];
      }
  }
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

__attribute__((target("arch=x86-64-v3"))) void blocks_v3(const ElementTangentInput& in, double* W,
                                                         double* KT) {
  blocks<v4, 2>(in, W, KT);
}

void blocks_default(const ElementTangentInput& in, double* W, double* KT) {
  blocks<v2, 2>(in, W, KT);
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

void element_tangent_blocks(const ElementTangentInput& in, double* W, double* KT, Isa isa) {
  if (isa == Isa::kAuto) isa = cpu_has_x86_64_v3() ? Isa::kX86_64_v3 : Isa::kDefault;
  if (isa == Isa::kX86_64_v3 && cpu_has_x86_64_v3())
    blocks_v3(in, W, KT);
  else
    blocks_default(in, W, KT);
}

}  // namespace knit::macro::kernel
