// The element kernel (element_kernel.hpp) against a plain triple sum, in both of its
// instruction-set versions (the x86-64-v3 one only where the CPU has it), for a symmetric
// (6 pairs, 3 of them triangular) and an unsymmetric (9 full pairs) request.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "knit/macro/element_kernel.hpp"

using namespace knit::macro;

namespace {

struct Problem {
  int nl = 0, nq = 0;
  std::vector<double> PhiT, H;
  // Tensor-product factors (element_kernel.hpp, ElementTangentInput::Au), if any.
  int nu = 0, nv = 0, nqu = 0, nqv = 0;
  std::vector<double> Au, Bk;
};

Problem random_problem(int nl, int nq, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int nlp = kernel::padded_functions(nl);
  Problem p;
  p.nl = nl, p.nq = nq;
  p.PhiT.assign(size_t(nlp) * 5 * nq, 0.0);
  p.H.resize(size_t(225) * nq);
  for (int k = 0; k < 5 * nq; ++k)
    for (int l = 0; l < nl; ++l) p.PhiT[size_t(k) * nlp + l] = u(gen);
  for (double& h : p.H) h = u(gen);
  return p;
}

/// A random tensor-product element: Phi_f(lu + nu lv, qu + nqu qv) = a_du(lu, qu) b_dv(lv, qv).
Problem random_tensor_problem(int nu, int nv, int nqu, int nqv, unsigned seed) {
  Problem p = random_problem(nu * nv, nqu * nqv, seed);
  std::mt19937 gen(seed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  p.nu = nu, p.nv = nv, p.nqu = nqu, p.nqv = nqv;
  p.Au.resize(size_t(3) * nqu * nu);
  std::vector<double> b(size_t(3) * nqv * nv);  // b[(d nqv + qv) nv + lv]
  for (double& x : p.Au) x = u(gen);
  for (double& x : b) x = u(gen);
  const int du[5] = {1, 0, 2, 1, 0}, dv[5] = {0, 1, 0, 1, 2};
  const int nlp = kernel::padded_functions(p.nl);
  p.Bk.resize(size_t(5) * nqv * nv);
  for (int qv = 0; qv < nqv; ++qv)
    for (int f = 0; f < 5; ++f)
      for (int lv = 0; lv < nv; ++lv) {
        const double bv = b[size_t(dv[f] * nqv + qv) * nv + lv];
        p.Bk[size_t(5 * qv + f) * nv + lv] = bv;
        for (int qu = 0; qu < nqu; ++qu)
          for (int lu = 0; lu < nu; ++lu)
            p.PhiT[size_t(5 * (qu + nqu * qv) + f) * nlp + lu + nu * lv] =
                p.Au[size_t(du[f] * nqu + qu) * nu + lu] * bv;
      }
  return p;
}

/// The instruction-set versions this CPU runs.
std::vector<kernel::Isa> available_isas() {
  std::vector<kernel::Isa> isas = {kernel::Isa::kDefault};
  if (kernel::cpu_has_x86_64_v3()) isas.push_back(kernel::Isa::kX86_64_v3);
  if (kernel::cpu_has_x86_64_v4()) isas.push_back(kernel::Isa::kX86_64_v4);
  return isas;
}

/// K_ij(l, m) = sum_q sum_fg Phi_f(l, q) H_q(3f+i, 3g+j) Phi_g(m, q), summed directly.
double reference(const Problem& p, int i, int j, int l, int m) {
  const int nlp = kernel::padded_functions(p.nl);
  double s = 0.0;
  for (int q = 0; q < p.nq; ++q)
    for (int f = 0; f < 5; ++f)
      for (int g = 0; g < 5; ++g)
        s += p.PhiT[size_t(5 * q + f) * nlp + l] * p.H[225 * q + (3 * f + i) + 15 * (3 * g + j)] *
             p.PhiT[size_t(5 * q + g) * nlp + m];
  return s;
}

/// Largest |kernel - reference| / largest |reference| over the computed entries.
double kernel_error(const Problem& p, bool symmetric, kernel::Isa isa) {
  int pi[9], pj[9], pairs = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = symmetric ? i + 1 : 0; j < 3; ++j) pi[pairs] = i, pj[pairs++] = j;
  const int full = pairs;
  if (symmetric)
    for (int i = 0; i < 3; ++i) pi[pairs] = i, pj[pairs++] = i;
  const int ldw = kernel::workspace_rows(p.nl), nlp = kernel::padded_functions(p.nl);
  std::vector<double> W(size_t(ldw) * 5 * p.nq, 0.0), KT(size_t(ldw) * nlp, 0.0);
  kernel::ElementTangentInput in;
  in.nl = p.nl;
  in.nq = p.nq;
  in.PhiT = p.PhiT.data();
  in.H = p.H.data();
  in.pairs = pairs;
  in.pi = pi;
  in.pj = pj;
  in.full = full;
  std::vector<double> Y;
  if (!p.Au.empty()) {
    Y.assign(size_t(ldw) * 5 * p.nqv * p.nu, 0.0);
    in.Au = p.Au.data();
    in.Bk = p.Bk.data();
    in.nu = p.nu, in.nv = p.nv, in.nqu = p.nqu, in.nqv = p.nqv;
    in.Y = Y.data();
  }
  kernel::element_tangent_blocks(in, W.data(), KT.data(), isa);
  double err = 0.0, scale = 0.0;
  for (int k = 0; k < pairs; ++k)
    for (int l = 0; l < p.nl; ++l)
      for (int m = 0; m < (k >= full ? l + 1 : p.nl); ++m) {
        const double r = reference(p, pi[k], pj[k], l, m);
        err = std::max(err, std::abs(KT[size_t(l) * ldw + k * p.nl + m] - r));
        scale = std::max(scale, std::abs(r));
      }
  return err / scale;
}

}  // namespace

TEST_CASE("element kernel: both instruction-set versions match the direct sum", "[unit]") {
  // p = 4 (25 functions, 25 points: padding in l and in the row tiles), p = 2 (9, 9), and an
  // odd 6 x 4 = 24-function element with 12 points.
  const int shapes[3][2] = {{25, 25}, {9, 9}, {24, 12}};
  const std::vector<kernel::Isa> isas = available_isas();
  for (const auto& s : shapes)
    for (const bool symmetric : {true, false})
      for (const kernel::Isa isa : isas) {
        CAPTURE(s[0], s[1], symmetric, int(isa));
        const Problem p = random_problem(s[0], s[1], 7u + unsigned(s[0]));
        CHECK(kernel_error(p, symmetric, isa) < 1e-13);
      }
}

TEST_CASE(
    "element kernel: the sum-factorized product of a tensor-product element matches the "
    "direct sum",
    "[unit]") {
  // p = 4 (5 x 5 functions and points), p = 2, an anisotropic 6 x 3 element with 4 x 2
  // points, and 7 x 2 functions (outside sum_factorized: the direct product).
  const int shapes[4][4] = {{5, 5, 5, 5}, {3, 3, 3, 3}, {6, 3, 4, 2}, {7, 2, 3, 3}};
  const std::vector<kernel::Isa> isas = available_isas();
  for (const auto& s : shapes)
    for (const bool symmetric : {true, false})
      for (const kernel::Isa isa : isas) {
        CAPTURE(s[0], s[1], s[2], s[3], symmetric, int(isa));
        const Problem p = random_tensor_problem(s[0], s[1], s[2], s[3], 11u + unsigned(s[0]));
        CHECK(kernel_error(p, symmetric, isa) < 1e-13);
      }
  CHECK(kernel::sum_factorized(5, 5));
  CHECK_FALSE(kernel::sum_factorized(7, 2));
}

TEST_CASE("element kernel: the point matrix H agrees between the instruction-set versions",
          "[unit]") {
  // Correctness of H itself: the shell tangent against finite differences
  // (test_shell_element.cpp); here the x86-64-v3 (FMA) and x86-64-v4 (AVX-512) builds of the
  // same code against the default one, to round-off.
  if (!kernel::cpu_has_x86_64_v3()) return;
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  kernel::PointState s;
  for (double* v : {s.a1, s.a2, s.a11, s.a22, s.a12, s.N, s.M})
    for (int i = 0; i < 3; ++i) v[i] = u(gen);
  double a3[3];
  kernel::cross3(s.a1, s.a2, a3);
  s.j = std::sqrt(a3[0] * a3[0] + a3[1] * a3[1] + a3[2] * a3[2]);
  for (int i = 0; i < 3; ++i) s.a3[i] = a3[i] / s.j;
  double T[9];
  for (double& t : T) t = u(gen);
  for (const bool sym : {true, false}) {
    for (double* X : {s.A, s.B, s.D})
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c <= r; ++c) X[r + 3 * c] = X[c + 3 * r] = u(gen);
    if (!sym) s.D[1] += 0.5;
    double H0[225], H1[225];
    bool sym0 = true;
    kernel::point_matrix(s, T, 0.7, H0, sym0, kernel::Isa::kDefault);
    CHECK(sym0 == sym);
    for (const auto isa : available_isas()) {
      bool sym1 = true;
      kernel::point_matrix(s, T, 0.7, H1, sym1, isa);
      CHECK(sym1 == sym);
      double err = 0.0, big = 0.0;
      for (int k = 0; k < 225; ++k) {
        err = std::max(err, std::abs(H0[k] - H1[k]));
        big = std::max(big, std::abs(H0[k]));
      }
      CAPTURE(int(isa), err, big);
      CHECK(err <= 1e-13 * big);
    }
    // The material part from its lower triangle (symmetric section tangent) against the full
    // product G^T E (the reference), every instruction set.
    for (const auto isa : available_isas()) {
      double Hf[225], Hl[225];
      bool symf = true, syml = true;
      kernel::point_matrix(s, T, 0.7, Hf, symf, isa, false);
      kernel::point_matrix(s, T, 0.7, Hl, syml, isa, true);
      CHECK(symf == syml);
      double e = 0.0, b = 0.0, asym = 0.0;
      for (int c = 0; c < 15; ++c)
        for (int r = 0; r < 15; ++r) {
          e = std::max(e, std::abs(Hf[r + 15 * c] - Hl[r + 15 * c]));
          b = std::max(b, std::abs(Hf[r + 15 * c]));
          asym = std::max(asym, std::abs(Hl[r + 15 * c] - Hl[c + 15 * r]));
        }
      CAPTURE(sym, e, b, asym);
      CHECK(e <= 1e-13 * b);
      CHECK((sym || asym > 1e-3 * b));  // unsymmetric law: the full product
    }
  }
}

TEST_CASE("element kernel: the residual's loops agree with the plain sums in every version",
          "[unit]") {
  // kernel::current_derivatives (dx = R x) and kernel::add_point_forces (fe += Phi^T g), in the
  // PhiT layout (component-major, padded_functions(nl) rows, zero padding), against the plain
  // sums, for every instruction set this CPU runs, 1e-13 relative.
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const int nl : {4, 9, 25, 36}) {
    const int nlp = kernel::padded_functions(nl);
    std::vector<double> Phi(5 * nlp, 0.0), xT(3 * nlp, 0.0), g(15), fe0(3 * nlp, 0.0);
    for (int l = 0; l < nl; ++l) {
      for (int f = 0; f < 5; ++f) Phi[f * nlp + l] = u(gen);
      for (int i = 0; i < 3; ++i) xT[i * nlp + l] = u(gen), fe0[i * nlp + l] = u(gen);
    }
    for (double& v : g) v = u(gen);
    double dref[18] = {};
    std::vector<double> feref = fe0;
    for (int i = 0; i < 3; ++i)
      for (int f = 0; f < 5; ++f)
        for (int l = 0; l < nl; ++l) dref[6 * i + 1 + f] += Phi[f * nlp + l] * xT[i * nlp + l];
    for (int l = 0; l < nl; ++l)
      for (int i = 0; i < 3; ++i)
        for (int f = 0; f < 5; ++f) feref[i * nlp + l] += Phi[f * nlp + l] * g[3 * f + i];
    for (const auto isa : available_isas()) {
      double d[18];
      kernel::current_derivatives(Phi.data(), xT.data(), nl, d, isa);
      std::vector<double> fe = fe0;
      kernel::add_point_forces(Phi.data(), g.data(), nl, fe.data(), isa);
      double ed = 0.0, bd = 0.0, ef = 0.0, bf = 0.0;
      for (int k = 0; k < 18; ++k)
        ed = std::max(ed, std::abs(d[k] - dref[k])), bd = std::max(bd, std::abs(dref[k]));
      for (int k = 0; k < 3 * nlp; ++k)
        ef = std::max(ef, std::abs(fe[k] - feref[k])), bf = std::max(bf, std::abs(feref[k]));
      CAPTURE(nl, int(isa), ed, bd, ef, bf);
      CHECK(ed <= 1e-13 * bd);
      CHECK(ef <= 1e-13 * bf);
    }
  }
}
