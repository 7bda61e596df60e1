// Load paths of issue 11 (knit/material/load_paths.hpp): the uniaxial and gradient kinds, the
// coverage and held-out sets, their names, and their HDF5 storage (every new field read back
// exactly; raw paths of older files, without the new attributes, read as set "paper").
#include <catch2/catch.hpp>
#include <filesystem>

#include "knit/io/hdf5.hpp"
#include "knit/material/database.hpp"
#include "knit/material/load_paths.hpp"
#include "test_material_util.hpp"

using namespace knit::material;
namespace fs = std::filesystem;

TEST_CASE("load paths: gradient F(t) = I + t H and uniaxial prescribed stretch", "[unit]") {
  LoadPath g;
  g.kind = PathKind::kGradient;
  g.H << 0.2, 0.5, 0.0, -0.1;
  for (double t : {0.0, 0.3, 1.0}) {
    const Eigen::Matrix2d F = deformation_gradient(g, t);
    CHECK((F - (Eigen::Matrix2d::Identity() + t * g.H)).norm() == 0.0);
    const Eigen::Matrix2d E = green_lagrange(F);
    CHECK(E(0, 1) == Approx(0.5 * F(0, 0) * F(0, 1)));  // E12 = F11 F12 / 2 for F21 = 0
  }
  LoadPath u;
  u.kind = PathKind::kUniaxial;
  u.target = {0.3, 0.0};
  for (int axis : {0, 1}) {
    u.axis = axis;
    const Eigen::Matrix2d F = deformation_gradient(u, 1.0);
    CHECK(green_lagrange(F)(axis, axis) == Approx(0.3).epsilon(1e-14));
    CHECK(F(1 - axis, 1 - axis) == 1.0);  // the lateral start value; the runner finds it
    CHECK(F(0, 1) == 0.0);
  }
  u.axis = 2;
  CHECK_THROWS(deformation_gradient(u, 1.0));
}

TEST_CASE("load paths: names of the kinds and sets", "[unit]") {
  for (PathKind k :
       {PathKind::kBiaxial, PathKind::kShear, PathKind::kUniaxial, PathKind::kGradient})
    CHECK(path_kind_from_string(to_string(k)) == k);
  CHECK(to_string(PathKind::kUniaxial) == "uniaxial");
  CHECK(to_string(PathKind::kGradient) == "gradient");
  CHECK_THROWS(path_kind_from_string("triaxial"));
  CHECK(is_valid_path_set("paper"));
  CHECK(is_valid_path_set("coverage"));
  CHECK(is_valid_path_set("holdout"));
  CHECK_FALSE(is_valid_path_set("Paper"));
}

TEST_CASE("load paths: coverage fills the circle to the box edge, held-out points inside",
          "[unit]") {
  CoverageOptions o;
  const auto cov = coverage_load_paths(o);
  REQUIRE(cov.size() == 2 + 16 + 7);
  int quadrant[4] = {0, 0, 0, 0};
  for (const auto& p : cov) {
    CHECK(p.set == "coverage");
    if (p.kind == PathKind::kBiaxial) {
      const double E11 = p.target(0), E22 = p.target(1);
      CHECK(o.box.contains(E11, E22, 0.0));
      // on the box edge
      const bool edge =
          std::abs(E11 - o.box.E11_min) < 1e-12 || std::abs(E11 - o.box.E11_max) < 1e-12 ||
          std::abs(E22 - o.box.E22_min) < 1e-12 || std::abs(E22 - o.box.E22_max) < 1e-12;
      CHECK(edge);
      if (E11 > 1e-9 && E22 > 1e-9) ++quadrant[0];
      if (E11 < -1e-9 && E22 > 1e-9) ++quadrant[1];
      if (E11 < -1e-9 && E22 < -1e-9) ++quadrant[2];  // biaxial compression
      if (E11 > 1e-9 && E22 < -1e-9) ++quadrant[3];
    }
  }
  for (int q = 0; q < 4; ++q) CHECK(quadrant[q] == 3);  // + 4 on the axes = 16
  CHECK(cov[0].kind == PathKind::kUniaxial);
  CHECK(cov[1].axis == 1);
  const auto hold = holdout_load_paths(o.box, 24, 6);
  REQUIRE(hold.size() == 24);
  for (const auto& p : hold) {
    CHECK(p.set == "holdout");
    CHECK(p.kind == PathKind::kGradient);
    const Eigen::Matrix2d E = green_lagrange(deformation_gradient(p, 1.0));
    CHECK(o.box.contains(E(0, 0), E(1, 1), E(0, 1)));
  }
  // Halton points of the first coordinate: 1/2, 1/4, 3/4, ...; the end strain is exact.
  CHECK(halton(3, 2) == 0.75);
  const Eigen::Matrix2d F = upper_gradient_for(0.1, -0.2, 0.3);
  const Eigen::Matrix2d E = green_lagrange(F);
  CHECK(E(0, 0) == Approx(0.1));
  CHECK(E(1, 1) == Approx(-0.2));
  CHECK(E(0, 1) == Approx(0.3));
}

TEST_CASE("load paths: quasi-random fill paths cover the box apart from the held-out points",
          "[unit]") {
  CoverageOptions o;
  o.fill_count = 48;
  o.fill_steps = 6;
  const auto cov = coverage_load_paths(o);
  REQUIRE(cov.size() == 2 + 16 + 7 + 48);
  const auto hold = holdout_load_paths(o.box, 24, 6);
  int octant[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (std::size_t k = 2 + 16 + 7; k < cov.size(); ++k) {
    const LoadPath& p = cov[k];
    CHECK(p.set == "coverage");
    CHECK(p.kind == PathKind::kGradient);
    CHECK(p.steps == 6);
    const Eigen::Matrix2d E = green_lagrange(deformation_gradient(p, 1.0));
    CHECK(o.box.contains(E(0, 0), E(1, 1), E(0, 1)));
    CHECK(deformation_gradient(p, 1.0).determinant() >= 0.5);
    ++octant[(E(0, 0) > 0) + 2 * (E(1, 1) > 0) + 4 * (E(0, 1) > 0)];
    // No fill path ends near a held-out state (distance in strain, relative to the box).
    for (const LoadPath& h : hold) {
      const Eigen::Matrix2d Eh = green_lagrange(deformation_gradient(h, 1.0));
      CHECK((E - Eh).norm() > 0.01);
    }
  }
  // Every sign combination of (E11, E22, E12) is visited, biaxial compression with shear too.
  for (int q = 0; q < 8; ++q) CHECK(octant[q] >= 2);
  // The R3 recurrence: frac(1/2 + i / g^k), g^4 = g + 1.
  const Eigen::Vector3d u1 = fill_point(1);
  CHECK(u1(0) == Approx(0.5 + 1.0 / 1.22074408460575947536 - 1.0));
  for (int i = 1; i < 200; ++i) CHECK((fill_point(i).array() >= 0.0).all());
  // Without the area floor the sequence reaches the locked corner (J < 0.5) within 48 points.
  o.fill_min_J = 0.0;
  int locked = 0;
  for (const LoadPath& p : coverage_load_paths(o))
    if (deformation_gradient(p, 1.0).determinant() < 0.5) ++locked;
  CHECK(locked >= 1);
  o.fill_steps = 0;
  CHECK_THROWS_AS(coverage_load_paths(o), std::invalid_argument);
}

TEST_CASE("load paths: rays of the strain box end on its surface or at the area floor", "[unit]") {
  // The Fibonacci half-sphere: unit vectors, heights (k + 1/2) / n, mean height 1/2 (the
  // centroid of a uniform lattice on the half-sphere), no two directions alike.
  const int n = 24;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d = half_sphere_direction(k, n);
    CHECK(d.norm() == Approx(1.0).epsilon(1e-14));
    CHECK(d(2) == Approx((k + 0.5) / n).epsilon(1e-14));
    mean += d / n;
    for (int j = 0; j < k; ++j) CHECK((d - half_sphere_direction(j, n)).norm() > 0.2);
  }
  CHECK(mean(2) == Approx(0.5).epsilon(1e-14));
  CHECK(std::abs(mean(0)) < 0.05);
  CHECK(std::abs(mean(1)) < 0.05);
  CHECK_THROWS_AS(half_sphere_direction(n, n), std::invalid_argument);

  CoverageOptions o;
  o.rays = n;
  const auto cov = coverage_load_paths(o);
  REQUIRE(cov.size() == 2 + 16 + 7 + static_cast<std::size_t>(n));
  const StrainBox& b = o.box;
  int on_surface = 0, at_floor = 0;
  for (int k = 0; k < n; ++k) {
    const LoadPath& p = cov[2 + 16 + 7 + k];
    CHECK(p.set == "coverage");
    CHECK(p.kind == PathKind::kGradient);
    CHECK(p.steps == 8);
    const Eigen::Matrix2d F = deformation_gradient(p, 1.0);
    const Eigen::Matrix2d E = green_lagrange(F);
    // Inside the box up to round-off (ends on its faces are computed, not copied).
    StrainBox wide = b;
    wide.E11_min -= 1e-12, wide.E11_max += 1e-12, wide.E22_min -= 1e-12, wide.E22_max += 1e-12;
    wide.E12_max += 1e-12;
    CHECK(wide.contains(E(0, 0), E(1, 1), E(0, 1)));
    CHECK(E(0, 1) > 0.0);
    const double J = F.determinant();
    CHECK(J >= o.fill_min_J * (1.0 - 1e-12));
    // The end lies on the ray: E is a positive multiple of the box-normalized direction.
    const Eigen::Vector3d d = half_sphere_direction(k, n);
    const Eigen::Vector3d u(E(0, 0) / (d(0) >= 0 ? b.E11_max : -b.E11_min),
                            E(1, 1) / (d(1) >= 0 ? b.E22_max : -b.E22_min), E(0, 1) / b.E12_max);
    CHECK((u / u.norm() - d).norm() < 1e-12);
    // Either on the box's surface (the cube [-1, 1]^3 in u) or shortened to J = fill_min_J.
    const bool surface = std::abs(u.cwiseAbs().maxCoeff() - 1.0) < 1e-12;
    const bool floor = std::abs(J - o.fill_min_J) < 1e-9;
    CHECK(surface != floor);
    on_surface += surface;
    at_floor += floor;
  }
  // The box holds both: most rays reach its faces, the compressed and sheared ones lock first.
  CHECK(on_surface >= n / 2);
  CHECK(at_floor >= 3);
  o.ray_steps = 0;
  CHECK_THROWS_AS(coverage_load_paths(o), std::invalid_argument);
}

TEST_CASE("load paths: the swapped shear-with-stretch paths are the course/wale mirror images",
          "[unit]") {
  CoverageOptions o;
  const auto plain = coverage_load_paths(o);
  o.gradient_swapped = true;
  const auto both = coverage_load_paths(o);
  const std::size_t first = 2 + 16, n = o.stretch.size();
  REQUIRE(both.size() == plain.size() + n);
  bool wale_compressed_sheared = false, before = false;
  for (std::size_t k = 0; k < n; ++k) {
    const LoadPath& p = both[first + k];
    const LoadPath& q = both[first + n + k];
    CHECK(q.kind == PathKind::kGradient);
    CHECK(q.set == "coverage");
    CHECK(q.steps == p.steps);
    for (double t : {0.5, 1.0}) {
      const Eigen::Matrix2d E = green_lagrange(deformation_gradient(p, t));
      const Eigen::Matrix2d Eq = green_lagrange(deformation_gradient(q, t));
      // E' = P E P with P the axis swap: E11 and E22 exchanged, E12 kept.
      CHECK(Eq(0, 0) == Approx(E(1, 1)).margin(1e-14));
      CHECK(Eq(1, 1) == Approx(E(0, 0)).margin(1e-14));
      CHECK(Eq(0, 1) == Approx(E(0, 1)).margin(1e-14));
      before = before || (E(1, 1) < -0.05 && E(0, 1) > 0.25);
      wale_compressed_sheared = wale_compressed_sheared || (Eq(1, 1) < -0.05 && Eq(0, 1) > 0.25);
    }
  }
  // The upper-triangular shear adds F12^2 / 2 to E22: only the mirror images reach shear with
  // the wale compressed.
  CHECK_FALSE(before);
  CHECK(wale_compressed_sheared);
}

namespace {
fs::path tmp(const std::string& name) {
  const fs::path d = fs::path(KNIT_BINARY_DIR) / "test_tmp";
  fs::create_directories(d);
  return d / name;
}
RawPath raw(const LoadPath& p) {
  RawPath r;
  r.path = p;
  r.path.steps = 2;  // one row per planned step (the reader refuses others since session 47)
  r.F = 0.2 * RowMatrixX::Random(2, 4);  // near I: det F > 0 (session 53)
  r.F.col(0).array() += 1.0;
  r.F.col(3).array() += 1.0;
  r.P = RowMatrixX::Random(2, 4);
  testing::set_strain_and_stress(r);  // E and S of F and P (eq. 9)
  r.status = {0, 1};
  return r;
}
}  // namespace

TEST_CASE("database: the new path fields round trip, old raw paths read as set paper", "[unit]") {
  Database db;
  db.provenance = current_provenance();
  db.generator = "test";
  db.sweep_input = "{}";
  LoopLengthEntry e;
  e.loop_length = 4.5;
  e.cell = {1.26, 0.88, 0.76};
  LoadPath b;  // paper biaxial
  b.target = {0.3, 0.1};
  LoadPath u;
  u.kind = PathKind::kUniaxial;
  u.axis = 1;
  u.target = {0.45, 0.0};
  u.set = "coverage";
  LoadPath g;
  g.kind = PathKind::kGradient;
  g.H << 0.1, 1.0 / 3.0, 0.0, -0.05;
  g.set = "holdout";
  for (const auto& p : {b, u, g}) e.raw.push_back(raw(p));
  db.entries.push_back(e);
  const auto file = tmp("load_paths_roundtrip.h5");
  write_database(file, db);
  const Database back = read_database(file);
  REQUIRE(back.entries.at(0).raw.size() == 3);
  for (std::size_t q = 0; q < 3; ++q) {
    const LoadPath &a = db.entries[0].raw[q].path, &c = back.entries[0].raw[q].path;
    CHECK(c.kind == a.kind);
    CHECK(c.axis == a.axis);
    CHECK((c.H.array() == a.H.array()).all());
    CHECK((c.target.array() == a.target.array()).all());
    CHECK(c.set == a.set);
    CHECK(c.steps == a.steps);
  }
  {  // /sweep: one row per path
    const auto f = knit::io::H5File::open_read(file);
    CHECK(f.read_ints("/sweep/load_path_kind") == std::vector<int>{0, 2, 3});
    CHECK(f.read_ints("/sweep/load_path_axis") == std::vector<int>{0, 1, 0});
    CHECK(f.read_strings("/sweep/load_path_set") ==
          std::vector<std::string>{"paper", "coverage", "holdout"});
    CHECK(f.read_matrix("/sweep/load_path_H")(2, 1) == 1.0 / 3.0);
  }
  // An older file: the path group as the format-1 writer made it (no axis, H, set), in a file
  // of format 1 (from format 2 on a missing attribute is a damaged file, commit 37e5153; this
  // test, its name holding a ';', had not run under CTest since, session 29).
  {
    auto f = knit::io::H5File::open_rw(file);
    f.set_attribute(".", "format_version", 1);
    const std::string p = "/loop_0/raw/path_01";
    f.remove(p);
    auto g0 = f.create_group(p);
    g0.set_attribute(".", "kind", "shear");
    g0.set_attribute(".", "target", std::vector<double>{0.5, 0.0});
    g0.set_attribute(".", "steps", 2);  // its rows
    const RawPath r = raw(b);
    g0.write("F", r.F);
    g0.write("P", r.P);
    g0.write("E", r.E);
    g0.write("S", r.S);
    g0.write("status", r.status);
    f.close();
  }
  const Database old = read_database(file);
  const LoadPath& o = old.entries[0].raw[1].path;
  CHECK(o.kind == PathKind::kShear);
  CHECK(o.set == "paper");
  CHECK(o.axis == 0);
  CHECK(o.H.isZero());
  CHECK(old.entries[0].raw[2].path.set == "holdout");
}
