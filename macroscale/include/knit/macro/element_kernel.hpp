// The hot loop of the shell element tangent (shell_model.hpp "Element kernel"), on raw arrays:
//
//   K_ij(l, m) = sum_q sum_fg Phi_f(l, q) H_q(3f+i, 3g+j) Phi_g(m, q)
//
// for the component pairs (i, j) of one element, as W = [(H_q Phi)_ij] (per point, the point's
// Phi columns held in registers) and one product Phi^T W^T in register tiles (GCC vector
// extensions). Compiled three times (GCC's target attribute): for x86-64-v4 (AVX-512), for
// x86-64-v3 (AVX2 + FMA) and for the default x86-64, the widest the CPU has chosen at run time;
// the binary still runs on any x86-64. The file includes no Eigen
// (Eigen's inline functions compiled for two instruction sets in one program would clash:
// compiling shell_model.cpp alone with -mavx2 crashed), and it is compiled with
// -ffp-contract=fast (macroscale/CMakeLists.txt) so that a * b + c becomes one FMA in the
// AVX2 version. The two versions differ by round-off only (tested).
#pragma once

namespace knit::macro::kernel {

/// Padding of the element's local-function count nl: rows of PhiT and of the output are
/// allocated for padded_functions(nl) (the extra rows of PhiT must be zero): a multiple of 8,
/// one AVX-512 vector.
constexpr int padded_functions(int nl) {
  return (nl + 7) / 8 * 8;
}
/// Rows of the workspace W: 9 component pairs of nl plus the overrun of the last 16-wide tile
/// (AVX-512; 8 for AVX2).
constexpr int workspace_rows(int nl) {
  return (9 * nl + 16 + 7) / 8 * 8;
}

struct ElementTangentInput {
  int nl = 0;                    ///< local functions (control points) of the element
  int nq = 0;                    ///< quadrature points
  const double* PhiT = nullptr;  ///< padded_functions(nl) x 5 nq, column 5 q + f: Phi_f at q
  const double* H = nullptr;     ///< nq matrices 15 x 15 (column-major, 225 apart)
  int pairs = 0;                 ///< component pairs (i, j) to compute
  const int* pi = nullptr;       ///< their i
  const int* pj = nullptr;       ///< their j
  int full = 0;  ///< pairs [0, full) are computed whole; pairs [full, pairs) (diagonal pairs of
                 ///< a symmetric tangent) only where l >= m (their lower triangle)
  /// Optional tensor-product factors of Phi (a B-spline element with a tensor Gauss rule):
  ///   Phi_f(lu + nu lv, qu + nqu qv) = a_{du(f)}(lu, qu) b_{dv(f)}(lv, qv),
  ///   (du, dv)(f) = (1,0), (0,1), (2,0), (1,1), (0,2) for f = R_1, R_2, R_11, R_12, R_22,
  /// with Au[(d nqu + qu) nu + lu] = a_d(lu, qu) (d = 0, 1, 2: the derivative order) and
  /// Bk[(5 qv + f) nv + lv] = b_{dv(f)}(lv, qv). Given (and 2 <= nu, nv <= 6), the product
  /// Phi^T W^T is sum-factorized: first over qu, then over (qv, f) — p = 4: 2 x 94k instead
  /// of 356k multiply-adds per element — in the workspace Y (workspace_rows(nl) x 5 nqv nu).
  /// Every pair is then computed whole.
  const double* Au = nullptr;
  const double* Bk = nullptr;
  int nu = 0, nv = 0, nqu = 0, nqv = 0;
  double* Y = nullptr;
};

/// Whether element_tangent_blocks sum-factorizes an element of nu x nv functions (given the
/// factors).
constexpr bool sum_factorized(int nu, int nv) {
  return nu >= 2 && nu <= 6 && nv >= 2 && nv <= 6;
}

/// What a residual evaluation keeps per quadrature point (ShellModel::evaluate(..., keep_points))
/// so that the tangent at the same displacement (ShellModel::tangent_from) needs no second pass
/// through the kinematics and the material: the current base vectors and their derivatives, |a1 x
/// a2|, the covariant resultants and the section tangents (local Cartesian Voigt, column-major).
struct PointState {
  double a1[3], a2[3], a3[3], a11[3], a22[3], a12[3];
  double j;
  double N[3], M[3];
  double A[9], B[9], D[9];
};

inline void cross3(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
/// w = v - (v . a3) a3 with v = M11 a11 + M22 a22 + 2 M12 a12 (the bending resultants applied
/// to the second derivatives); returns v . a3.
inline double bending_vector(const PointState& s, double* v, double* w) {
  for (int i = 0; i < 3; ++i)
    v[i] = s.M[0] * s.a11[i] + s.M[1] * s.a22[i] + 2.0 * s.M[2] * s.a12[i];
  const double va3 = v[0] * s.a3[0] + v[1] * s.a3[1] + v[2] * s.a3[2];
  for (int i = 0; i < 3; ++i) w[i] = v[i] - va3 * s.a3[i];
  return va3;
}

enum class Isa {
  kAuto,       ///< the widest the CPU has: x86-64-v4, else x86-64-v3, else the default
  kDefault,    ///< SSE2 (any x86-64)
  kX86_64_v3,  ///< AVX2 + FMA (falls back to the default on a CPU without them)
  kX86_64_v4,  ///< AVX-512 F/DQ/CD/BW/VL (falls back to x86-64-v3, then the default)
};
/// Whether this CPU runs the x86-64-v3 version (AVX2, FMA, BMI2).
bool cpu_has_x86_64_v3();
/// Whether this CPU runs the x86-64-v4 version (x86-64-v3 and AVX-512 F, DQ, CD, BW, VL).
bool cpu_has_x86_64_v4();
/// The version `isa` runs on this CPU (kAuto and unsupported versions resolved).
Isa resolve(Isa isa);

/// Fills KT (workspace_rows(nl) x padded_functions(nl), column-major):
///   KT(p nl + m, l) = K_{pi[p] pj[p]}(l, m)
/// for every pair p; W is workspace of workspace_rows(nl) x 5 nq doubles whose padding rows
/// must be finite (zero them once). Entries outside the computed triangle are unspecified.
void element_tangent_blocks(const ElementTangentInput& in, double* W, double* KT,
                            Isa isa = Isa::kAuto);

/// The 15 x 15 matrix H of one quadrature point (shell_model.hpp; column-major) from its
/// state, T the covariant-to-Cartesian Voigt map (column-major 3 x 3) and dA the weighted
/// area element; clears `symmetric` if the section tangent is not symmetric. Raw arrays,
/// compiled for both instruction sets like the kernel. `use_symmetry` (default): where the
/// section tangent is symmetric, H's material part is computed below its diagonal and
/// mirrored (equal to the full product to round-off; false: the full product, the reference).
void point_matrix(const PointState& s, const double* T, double dA, double* H, bool& symmetric,
                  Isa isa = Isa::kAuto, bool use_symmetry = true);

/// The residual's two loops over the element's functions at one point, compiled for each
/// instruction set like the kernel (the rest of shell_model.cpp is built for the default
/// x86-64), in the layout of the kernel's PhiT: Phi holds the point's five columns
/// Phi_f(l) = Phi[f nlp + l] (f = R_1, R_2, R_11, R_12, R_22; nlp = padded_functions(nl), the
/// padding zero), xT the element's current control points x_i(l) = xT[i nlp + l] (padding
/// zero), feT the element forces fe_i(l) = feT[i nlp + l]:
///   current_derivatives: d[6 i + 1 + f] = sum_l Phi_f(l) x_i(l)  (dx = R x, column-major 6 x 3;
///                        row 0, the position, is set to 0: not needed)
///   add_point_forces:    fe_i(l) += sum_f Phi_f(l) g[3 f + i]
void current_derivatives(const double* Phi, const double* xT, int nl, double* d,
                         Isa isa = Isa::kAuto);
void add_point_forces(const double* Phi, const double* g, int nl, double* feT,
                      Isa isa = Isa::kAuto);

}  // namespace knit::macro::kernel
