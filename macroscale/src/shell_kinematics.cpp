#include "knit/macro/shell_kinematics.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

namespace knit::macro {

ReferencePoint reference_point(const SurfaceDerivs& dX, const Eigen::Vector2d& theta,
                               double scale) {
  ReferencePoint r;
  r.theta = theta;
  const Eigen::Vector3d A1 = dX.row(1).transpose(), A2 = dX.row(2).transpose();
  const Eigen::Vector3d A3t = A1.cross(A2);
  r.jacobian = A3t.norm();
  if (!(r.jacobian > 1e-10 * scale * scale) || !(A1.norm() > 1e-12 * scale)) {
    std::ostringstream s;
    s << "degenerate geometry: the surface Jacobian |A1 x A2| = " << r.jacobian
      << " vanishes at (theta1, theta2) = (" << theta(0) << ", " << theta(1) << ")";
    throw DegenerateGeometryError(theta, s.str());
  }
  const Eigen::Vector3d A3 = A3t / r.jacobian;
  r.A << A1.dot(A1), A2.dot(A2), A1.dot(A2);
  r.B << dX.row(3).dot(A3), dX.row(5).dot(A3), dX.row(4).dot(A3);
  // Contravariant base vectors A^a = A^{ab} A_b.
  Eigen::Matrix2d Am;
  Am << r.A(0), r.A(2), r.A(2), r.A(1);
  const Eigen::Matrix2d Ai = Am.inverse();
  const Eigen::Vector3d G1 = Ai(0, 0) * A1 + Ai(0, 1) * A2, G2 = Ai(1, 0) * A1 + Ai(1, 1) * A2;
  r.e1 = A1.normalized();
  r.e3 = A3;
  r.e2 = A3.cross(r.e1);
  // L(i, a) = e_i . A^a
  const double L11 = r.e1.dot(G1), L12 = r.e1.dot(G2), L21 = r.e2.dot(G1), L22 = r.e2.dot(G2);
  r.T << L11 * L11, L12 * L12, L11 * L12,  //
      L21 * L21, L22 * L22, L21 * L22,     //
      2 * L11 * L21, 2 * L12 * L22, L11 * L22 + L12 * L21;
  return r;
}

CurrentPoint current_point(const SurfaceDerivs& dx, const ReferencePoint& ref) {
  CurrentPoint c;
  c.a1 = dx.row(1).transpose();
  c.a2 = dx.row(2).transpose();
  c.a11 = dx.row(3).transpose();
  c.a12 = dx.row(4).transpose();
  c.a22 = dx.row(5).transpose();
  const Eigen::Vector3d a3t = c.a1.cross(c.a2);
  c.j = a3t.norm();
  c.a3 = a3t / c.j;
  c.eps << 0.5 * (c.a1.dot(c.a1) - ref.A(0)), 0.5 * (c.a2.dot(c.a2) - ref.A(1)),
      c.a1.dot(c.a2) - ref.A(2);
  c.kap << ref.B(0) - c.a11.dot(c.a3), ref.B(1) - c.a22.dot(c.a3),
      2.0 * (ref.B(2) - c.a12.dot(c.a3));
  return c;
}

}  // namespace knit::macro
