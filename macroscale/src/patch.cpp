#include "knit/macro/patch.hpp"

namespace knit::macro {

std::optional<Edge> parse_edge(const std::string& s) {
  if (s == "u0") return Edge::kU0;
  if (s == "u1") return Edge::kU1;
  if (s == "v0") return Edge::kV0;
  if (s == "v1") return Edge::kV1;
  return std::nullopt;
}

std::string edge_name(Edge e) {
  switch (e) {
    case Edge::kU0:
      return "u0";
    case Edge::kU1:
      return "u1";
    case Edge::kV0:
      return "v0";
    case Edge::kV1:
      return "v1";
  }
  return "?";
}

std::optional<Eigen::Vector2d> parse_corner(const std::string& s) {
  if (s == "u0v0") return Eigen::Vector2d(0, 0);
  if (s == "u1v0") return Eigen::Vector2d(1, 0);
  if (s == "u0v1") return Eigen::Vector2d(0, 1);
  if (s == "u1v1") return Eigen::Vector2d(1, 1);
  return std::nullopt;
}

std::vector<int> edge_row(int nu, int nv, Edge e, int row) {
  std::vector<int> out;
  switch (e) {
    case Edge::kU0:
    case Edge::kU1: {
      const int i = e == Edge::kU0 ? row : nu - 1 - row;
      for (int j = 0; j < nv; ++j) out.push_back(i + nu * j);
      break;
    }
    case Edge::kV0:
    case Edge::kV1: {
      const int j = e == Edge::kV0 ? row : nv - 1 - row;
      for (int i = 0; i < nu; ++i) out.push_back(i + nu * j);
      break;
    }
  }
  return out;
}

int corner_control_point(int nu, int nv, const Eigen::Vector2d& c) {
  const int i = c(0) > 0.5 ? nu - 1 : 0, j = c(1) > 0.5 ? nv - 1 : 0;
  return i + nu * j;
}

std::vector<int> corner_region(const spline::SplineSurface& s, const Eigen::Vector2d& corner,
                               double radius) {
  const int nu = s.size_u(), nv = s.size_v();
  const int a0 = corner_control_point(nu, nv, corner);
  const Eigen::VectorXd x0 = s.eval(corner(0) > 0.5 ? 1.0 : 0.0, corner(1) > 0.5 ? 1.0 : 0.0);
  const std::vector<double> gu = s.basis_u().greville(), gv = s.basis_v().greville();
  std::vector<int> out;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = i + nu * j;
      if (a == a0 || (s.eval(gu[i], gv[j]) - x0).norm() <= radius) out.push_back(a);
    }
  return out;
}

int parse_component(const std::string& s) {
  if (s == "x" || s == "1") return 0;
  if (s == "y" || s == "2") return 1;
  if (s == "z" || s == "3") return 2;
  return -1;
}

}  // namespace knit::macro
