// The evaluator of the network law that the macroscale calls (session 17): all the network
// passes of one evaluation in one sweep of the units.
//
// The law at a loop length is a weighted sum of network energies G_k = outer(N_k) over lanes k
// (knit/material/convex_network.hpp):
//   at a knot, or with theta interpolated in l:  W = 1/2 G(e; theta) + 1/2 G(M e; theta)
//   between two knots, l_interpolation "energy":  W = (1 - t) [1/2 G(e; theta_j) + ...]
//                                                   + t [1/2 G(e; theta_j+1) + ...]
// minus the affine normalization W(0), S(0). The mirrored pass needs no mirrored input: the
// network at theta with the E12 column of A0 and A1 and the third row of L negated is
// N(M e; theta) as a function of e, with its gradient M S_N(M e) and Hessian M C_N(M e) M. So
// every lane takes the same e, and the K lanes (2, 4 or 6) are K networks side by side: one
// first layer of K h1 units, one second layer of K h2 units (V block diagonal), each loop over
// all of them at once. The arithmetic is that of NetworkLawAt::evaluate (the reference, tested
// equal to round-off); what is saved is the per-pass overhead and the serial dependence of one
// small pass on the next (the lanes are independent, so their work interleaves). Four lanes
// and six lanes take a wide kernel where the processor has one (LanesKernel below;
// docs/database.md).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "knit/material/convex_network.hpp"

namespace knit::material {

/// Which code evaluates four or six lanes: kAuto = the widest kernel the processor has: AVX-512
/// (four lanes in a 256-bit vector, six in a 512-bit one; session 48), else AVX2 with FMA (one
/// 256-bit vector holds a unit's four lanes, +45 % on the default law between knots, session
/// 17; six lanes as four in one 256-bit vector per unit and two per unit pair in another,
/// session 53), else the portable one (Eigen,
/// SSE2); kAvx2 = the AVX2 kernels where the processor has AVX2 and FMA, the portable one
/// otherwise (tests, benchmarks); kPortable = always the portable one (tests). Two lanes take the
/// portable one (faster there).
enum class LanesKernel { kAuto, kAvx2, kPortable };

class NetworkLanesAt {
 public:
  /// The wide kernels' signature (common/src/material_network_lanes.cpp).
  using WideKernel = void (*)(int, int, int, int, const double*, const double*, double*);
  NetworkLanesAt() = default;
  /// W at one theta: 1/2 (G(e) + G(M e)) - W0 - S0 . e (two lanes).
  NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta);
  /// W = (1 - t) W(theta_a) + t W(theta_b), each normalized as above (four lanes); t in [0, 1].
  NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta_a,
                 const std::vector<double>& theta_b, double t,
                 LanesKernel kernel = LanesKernel::kAuto);
  /// W = c0 W(theta_a) + c1 W(theta_b) + c2 W(theta_c), each normalized as above (six lanes:
  /// a rounding window's three knots); c >= 0 with sum 1.
  NetworkLanesAt(const NetworkShape& shape, const std::vector<double>& theta_a,
                 const std::vector<double>& theta_b, const std::vector<double>& theta_c,
                 const Eigen::Vector3d& c, LanesKernel kernel = LanesKernel::kAuto);
  /// W, S, C at e (material frame, e finite). Allocation-free.
  NetworkResponse evaluate(const Eigen::Vector3d& e) const;
  int lanes() const { return K_; }
  /// True if evaluate() runs a wide (AVX2 or AVX-512) kernel.
  bool wide() const { return wide_ != nullptr; }
  /// True if this processor has a six-lane kernel (AVX-512, or AVX2 with FMA); without one six
  /// portable lanes are slower than four plus two (EnergyLawAt).
  static bool six_lane_kernel();

 private:
  void build(const NetworkShape& shape, const std::vector<const std::vector<double>*>& thetas,
             const std::vector<double>& lane_weight, LanesKernel kernel);

  NetworkShape shape_;
  int K_ = 0;
  int width_ = 4;  ///< lanes in the wide kernel's vectors: 4, or 8 for six lanes
  /// Packed, each array K h1 (first layer) or K h2 (second layer) long, lane-major (lane k's
  /// units at k h + i): c0, c1, c2, b0, w1, p00, p01, p02, p11, p12, p22 (products of the
  /// columns of A0); then V (K blocks h2 x h1, row-major); then a10, a11, a12, b1, w.
  std::vector<double> packed_;
  /// Per lane: weight omega_k and Q = L L^T (upper triangle: 00, 01, 02, 11, 12, 22).
  std::vector<double> omega_, Q_;
  /// The same for the wide kernel (empty when the portable code evaluates): unit-major,
  /// [field][unit][lane], width_ lanes (the lanes beyond K_ copies of lane 0, not summed); for
  /// six lanes in the AVX2 kernel (lanes6s_avx2) instead a four-lane block of lanes 0-3, then
  /// lanes 4-5 two units to a vector ([field][unit pair][unit of the pair, lane]; a layer of
  /// odd size padded with a zero unit), width_ 8 with no lanes 6-7 stored.
  std::vector<double> packed4_;
  WideKernel wide_ = nullptr;
  double W0_ = 0.0;
  Eigen::Vector3d S0_ = Eigen::Vector3d::Zero();
};

}  // namespace knit::material
