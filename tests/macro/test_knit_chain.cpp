// The chain database -> knit material -> shell: a homogeneous patch under a uniform biaxial
// stretch reproduces the database's stresses at every step; a rotated problem with the
// material rotated along gives the same load-strain curve; bad knit inputs name the field.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>

#include "../common/test_material_util.hpp"
#include "knit/core/errors.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/macro/run.hpp"
#include "knit/material/database.hpp"

using namespace knit::macro;
using namespace knit::material;
namespace fs = std::filesystem;

namespace {

/// A fitted database of the test law at 4.5 ... 6.5 mm (no raw data needed by the shell).
std::string test_database() {
  const fs::path dir = fs::path(KNIT_BINARY_DIR) / "test_tmp";
  fs::create_directories(dir);
  const fs::path f = dir / "knit_chain_db.h5";
  Database db;
  db.provenance = current_provenance();
  db.generator = "test";
  for (double l : {4.5, 5.0, 5.5, 6.0, 6.5}) {
    LoopLengthEntry e;
    e.loop_length = l;
    e.surface = testing::make_test_surface(std::pow(4.5 / l, 2));
    db.entries.push_back(e);
  }
  write_database(f, db);
  return f.string();
}

std::string square(double beta, double L = 50.0) {
  const double c = std::cos(beta), s = std::sin(beta);
  std::ostringstream os;
  os.precision(17);
  auto pt = [&](double x, double y) {
    os << "[" << c * x - s * y << ", " << s * x + c * y << ", 0]";
  };
  os << "{\"degrees\": [1, 1], \"knots_u\": [0, 0, 1, 1], \"knots_v\": [0, 0, 1, 1], "
        "\"control_points\": [";
  pt(0, 0);
  os << ", ";
  pt(L, 0);
  os << ", ";
  pt(0, L);
  os << ", ";
  pt(L, L);
  os << "], \"thickness\": 0.76}";
  return os.str();
}

}  // namespace

TEST_CASE("knit chain: uniform biaxial stretch gives the database's stresses at every step",
          "[case]") {
  const std::string db = test_database();
  const double dx = 10.0, dy = -3.0, L = 50.0, t = 0.76, l = 5.25;
  std::ostringstream cs;
  cs << R"({"geometry": )" << square(0.0) << R"(,
    "refinement": {"degree": 2, "elements": [1, 1]},
    "material": {"type": "knit", "database": ")"
     << db << R"(", "stitch_value": )" << l << R"(,
                 "knitting_angle": 0.0},
    "boundary_conditions": [
      {"all": true, "fix": ["z"]},
      {"edge": "u0", "fix": ["x"]}, {"edge": "v0", "fix": ["y"]},
      {"edge": "u1", "prescribe": {"x": )"
     << dx << R"(}},
      {"edge": "v1", "prescribe": {"y": )"
     << dy << R"(}}],
    "solver": {"steps": 10, "tolerance": 1e-10, "max_iterations": 30},
    "output": {"vtk": false, "hdf5": false,
               "reactions": [{"name": "fx", "edge": "u1", "component": "x"},
                             {"name": "fy", "edge": "v1", "component": "y"}]}})";
  const Case c = parse_case(cs.str(), "chain.json");
  const RunResult r = run_case(c, {});
  REQUIRE(r.report.status == RunStatus::kCompleted);
  REQUIRE(r.rows.size() == 10);
  const ResponseSurface rs(read_database(db, false).family().at(l));
  for (const auto& row : r.rows) {
    const double F11 = 1 + row.lambda * dx / L, F22 = 1 + row.lambda * dy / L;
    const Eigen::Vector3d E(0.5 * (F11 * F11 - 1), 0.5 * (F22 * F22 - 1), 0.0);
    const Eigen::Vector3d S = rs.evaluate(E).S;
    // Edge force = P11 * (t L) with P = F S (first Piola-Kirchhoff, reference area).
    INFO("step " << row.step << " E = " << E.transpose());
    CHECK(row.reactions[0] == Approx(F11 * S(0) * t * L).epsilon(1e-6));
    CHECK(row.reactions[1] == Approx(F22 * S(1) * t * L).epsilon(1e-6));
  }
}

TEST_CASE("knit chain: rotating the patch with its parameterization keeps the curve", "[case]") {
  // The same tensile problem (u0 held, u1 pulled along a1 with the lateral motion held),
  // with the whole patch rotated in its plane by beta: alpha (relative to e1) is unchanged,
  // so the reaction along the pull must be the same at every step.
  const std::string db = test_database();
  auto run = [&](double beta) {
    const double c = std::cos(beta), s = std::sin(beta), d = 12.0;
    std::ostringstream cs;
    cs.precision(17);
    cs << R"({"geometry": )" << square(beta) << R"(,
      "refinement": {"degree": 3, "elements": [2, 2]},
      "material": {"type": "knit", "database": ")"
       << db << R"(",
                   "stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1],
                                    "values": [4.5, 6.0]},
                   "knitting_angle": 0.5},
      "boundary_conditions": [
        {"all": true, "fix": ["z"]},
        {"edge": "u0", "fix": ["x", "y"]},
        {"edge": "u1", "prescribe": {"x": )"
       << d * c << R"(, "y": )" << d * s << R"(}}],
      "solver": {"steps": 5, "tolerance": 1e-10, "max_iterations": 30},
      "output": {"vtk": false, "hdf5": false,
                 "reactions": [{"name": "fx", "edge": "u1", "component": "x"},
                               {"name": "fy", "edge": "u1", "component": "y"}]}})";
    const RunResult r = run_case(parse_case(cs.str(), "rot.json"), {});
    REQUIRE(r.report.status == RunStatus::kCompleted);
    std::vector<double> f;
    for (const auto& row : r.rows) f.push_back(c * row.reactions[0] + s * row.reactions[1]);
    return f;
  };
  const auto a = run(0.0), b = run(0.7);
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) CHECK(b[k] == Approx(a[k]).epsilon(1e-6));
  CHECK(a.back() > 0.0);
}

TEST_CASE("knit chain: bad knit inputs name the field", "[unit]") {
  const std::string db = test_database();
  auto load = [&](const std::string& material) {
    std::ostringstream cs;
    cs << R"({"geometry": )" << square(0.0) << R"(, "refinement": {"degree": 2, "elements": [1, 1]},
      "material": )"
       << material << R"(, "boundary_conditions": [{"edge": "u0", "fix": ["x", "y", "z"]}]})";
    return parse_case(cs.str(), "bad.json");
  };
  const std::string head = R"({"type": "knit", "database": ")" + db + "\", ";
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 7.0})"),
                    Catch::Contains("bad.json: /material/stitch_value: 7 mm is outside the "
                                    "database's 4.5-6.5 mm"));
  // A control value outside the range; one ulp above it prints as such (session 27: "6.5 mm is
  // outside ... 4.5-6.5 mm").
  for (const std::string v : {"9.2", "6.500000000000001"})
    CHECK_THROWS_WITH(
        load(
            head +
            R"("stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1], "values": [5, )" +
            v + "]}}"),
        Catch::Contains("/material/stitch_value/values/1: " + v +
                        " mm is outside the database's 4.5-6.5 mm"));
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 6.500000000000001})"),
                    Catch::Contains("6.500000000000001 mm is outside the database's 4.5-6.5 mm"));
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1], "values": [5]}})"),
      Catch::Contains("/material/stitch_value/values: the knots and degrees define 2 x 1"));
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 2, 2], "knots_v": [0, 1], "values": [5, 5]}})"),
      Catch::Contains("/material/stitch_value/knots_u: the field's domain [0, 2] differs from "
                      "the patch's [0, 1]"));
  // Printed in full, not as std::to_string's 300 digits (session 38's red team).
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1e308, 1e308], "knots_v": [0, 1], "values": [5, 5]}})"),
      Catch::Contains("the field's domain [0, 1e+308] differs"));
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": 5, "knitting_angle": {"align_with": [0, 0, 1], "degrees": [0, 0], "knots_u": [0, 1], "knots_v": [0, 1]}})"),
      Catch::Contains("/material/knitting_angle/align_with: "));
  // Knitting angles within one turn either way (session 21: 1e308 rad ran with exit 0).
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 5, "knitting_angle": 1e308})"),
                    Catch::Contains("/material/knitting_angle: a knitting angle must lie in "
                                    "[-2 pi, 2 pi] rad, got 1e+308"));
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": 5, "knitting_angle": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1], "values": [350, 400], "unit": "deg"}})"),
      Catch::Contains("/material/knitting_angle/values/1: a knitting angle must lie in "
                      "[-360, 360] deg, got 400"));
  CHECK_NOTHROW(load(
      head +
      R"("stitch_value": 5, "knitting_angle": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1], "values": [-360, 360], "unit": "deg"}})"));
  CHECK_NOTHROW(load(head + R"("stitch_value": 5, "knitting_angle": -6.28})"));
  // Just outside, printed with the digits that show it (session 40's red team: "got 6.28319").
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 5, "knitting_angle": 6.283185307181})"),
                    Catch::Contains("[-2 pi, 2 pi] rad, got 6.283185307181 "));
  CHECK_THROWS_WITH(
      load(
          head +
          R"("stitch_value": 5, "knitting_angle": {"degrees": [0, 0], "knots_u": [0, 1], "knots_v": [0, 1], "values": [360.0000001], "unit": "deg"}})"),
      Catch::Contains("[-360, 360] deg, got 360.0000001 "));
  // An angle that reads as degrees says how to write it in degrees (session 39).
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 5, "knitting_angle": 30})"),
                    Catch::EndsWith("; if it is in degrees, give the spline field \"unit\": "
                                    "\"deg\" (a constant angle as {\"degrees\": [0, 0], "
                                    "\"knots_u\": [0, 1], \"knots_v\": [0, 1], \"values\": "
                                    "[30], \"unit\": \"deg\"}) (line 2)"));
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 5, "knitting_angle": 1e308})"),
                    !Catch::Contains("if it is in degrees"));
  CHECK_THROWS_WITH(load(head + R"("stitch_value": 5, "colour": 1})"),
                    Catch::Contains("/material/colour: unknown key"));
  // The material readers suggest a close key, as every reader does (io::unknown_key_note).
  CHECK_THROWS_WITH(load(head + R"("stitch_valu": 5})"),
                    Catch::Contains("/material/stitch_valu: unknown key (did you mean "
                                    "\"stitch_value\"? allowed: "));
  CHECK_THROWS_WITH(
      load(R"({"type": "knit", "database": "/nonexistent/db.h5", "stitch_value": 5})"),
      Catch::Contains("bad.json: /material/database: /nonexistent/db.h5: file not found"));
  // "" was resolved to the case's directory ("...: not an HDF5 file"; session 36).
  CHECK_THROWS_WITH(load(R"({"type": "knit", "database": "", "stitch_value": 5})"),
                    Catch::Contains("bad.json: /material/database: must not be empty"));
}

TEST_CASE("knit chain: a relative database path that is not there says where it was looked for",
          "[unit]") {
  // Session 47's walkthrough: "out/database.h5: file not found" did not say that the path is
  // the case file's, nor where that led.
  const std::string text =
      R"({"geometry": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
          "control_points": [[0, 0, 0], [50, 0, 0], [0, 50, 0], [50, 50, 0]], "thickness": 0.76},
        "refinement": {"degree": 2, "elements": [1, 1]},
        "material": {"type": "knit", "database": "no_such_dir/db.h5", "stitch_value": 5},
        "boundary_conditions": [{"edge": "u0", "fix": ["x", "y", "z"]}]})";
  const std::string where =
      (std::filesystem::current_path() / "cases" / "no_such_dir" / "db.h5").string();
  CHECK_THROWS_WITH(parse_case(text, "cases/bad.json"),
                    Catch::Contains("cases/no_such_dir/db.h5: file not found (a relative database "
                                    "path is taken from the case file's directory: here " +
                                    where + ")"));
  // An absolute path needs no such note.
  std::string abs = text;
  abs.replace(abs.find("no_such_dir/db.h5"), 17, "/no_such_dir/db.h5");
  CHECK_THROWS_WITH(
      parse_case(abs, "cases/bad.json"),
      Catch::Contains("/no_such_dir/db.h5: file not found") && !Catch::Contains("relative"));
}
