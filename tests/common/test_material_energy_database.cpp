// The energy-based law in the material database (format version 2): round trip, a version-1
// file still loads and refuses the energy law with file + HDF5 path + what to do, bad
// /energy_law content is refused with its HDF5 path.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include "knit/core/errors.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/material/database.hpp"
#include "test_energy_util.hpp"

using namespace knit::material;
namespace fs = std::filesystem;

namespace {
fs::path tmp(const std::string& name) {
  const fs::path d = fs::path(KNIT_BINARY_DIR) / "test_tmp";
  fs::create_directories(d);
  return d / name;
}
Database db_with_law() {
  Database db;
  db.provenance = current_provenance();
  db.generator = "test";
  db.sweep_input = "{}";
  for (double l : {4.5, 6.5}) {
    LoopLengthEntry e;
    e.loop_length = l;
    e.cell = {1.26, 0.88, 0.76};
    db.entries.push_back(e);
  }
  db.energy_law = testing::make_test_energy_law();
  auto& dg = db.energy_diagnostics;
  for (double l : {4.5, 6.5}) {
    EnergyFitDiagnostics::PerLoop p;
    p.loop_length = l;
    p.points = 17;
    p.rms << 0.1, 0.2, 0.3;
    p.max << 0.4, 0.5, 0.6;
    p.stress_range = 2.0;
    p.max_relative = 0.3;
    p.rms_relative = 0.15;
    p.monotonicity_bound = 0.01 * l;
    if (l == 6.5)  // a wale-wise uniaxial curve at 6.5 mm only, its last law state missing
      p.uniaxial[1] = {{0.1, 0.2, 0.3}, {0.5, 1.0, 2.0}, {0.6, 2.5, std::nan("")}};
    dg.per_loop.push_back(p);
  }
  dg.holdout_points = 21;
  dg.holdout_within_5_percent = 20;
  dg.holdout_rms << 0.01, 0.02, 0.03;
  dg.holdout_max << 0.04, 0.05, 0.06;
  dg.holdout_max_relative = 0.07;
  dg.points_used = 34;
  dg.points_skipped = 2;
  dg.min_eigenvalue = 0.02;
  dg.options_json = "{\"smoothing\": 1}";
  return db;
}
/// The test network law (knots 4.5, 5.5, 6.5 mm) in place of the ridge law, with the
/// database's loop lengths and the diagnostics' rows at its knots (the 4.5 mm entry and row
/// repeated at 5.5 mm), as the fit writes them.
void set_network_law(Database& db) {
  db.energy_law = testing::make_test_network_law();
  auto& pl = db.energy_diagnostics.per_loop;
  pl.insert(pl.begin() + 1, pl[0]);
  pl[1].loop_length = 5.5;
  db.entries.insert(db.entries.begin() + 1, db.entries[0]);
  db.entries[1].loop_length = 5.5;
}
}  // namespace

TEST_CASE("database v2: the energy law round trip", "[unit]") {
  const auto file = tmp("energy_roundtrip.h5");
  const Database db = db_with_law();
  write_database(file, db);
  const Database back = read_database(file, false);
  CHECK(back.format_version == kDatabaseFormatVersion);
  REQUIRE(back.energy_law);
  const EnergyLawData &a = *db.energy_law, &b = *back.energy_law;
  CHECK(b.directions.d == a.directions.d);
  CHECK(b.directions.function_of == a.directions.function_of);
  CHECK(b.s_range == a.s_range);
  CHECK(b.coefficients == a.coefficients);
  CHECK(b.l_knots == a.l_knots);
  CHECK(b.s_degree == a.s_degree);
  CHECK(b.s_spans == a.s_spans);
  CHECK(b.l_degree == a.l_degree);
  CHECK(b.floor == a.floor);
  CHECK(b.box_min == a.box_min);
  CHECK(b.box_max == a.box_max);
  CHECK(b.l_min == a.l_min);
  CHECK(b.l_max == a.l_max);
  const auto &da = db.energy_diagnostics, &dbk = back.energy_diagnostics;
  REQUIRE(dbk.per_loop.size() == 2);
  CHECK(dbk.per_loop[1].max == da.per_loop[1].max);
  CHECK(dbk.per_loop[0].rms == da.per_loop[0].rms);
  CHECK(dbk.per_loop[1].stress_range == 2.0);
  CHECK(dbk.per_loop[0].monotonicity_bound == 0.045);
  CHECK(dbk.per_loop[1].monotonicity_bound == 0.065);
  CHECK(dbk.holdout_points == 21);
  CHECK(dbk.holdout_within_5_percent == 20);
  CHECK(dbk.holdout_max == da.holdout_max);
  CHECK(dbk.min_eigenvalue == 0.02);
  CHECK(dbk.options_json == da.options_json);
  // The same law: same response.
  const auto ea = EnergyLaw(a).at(5.1).evaluate({0.1, -0.05, 0.2});
  const auto eb = EnergyLaw(b).at(5.1).evaluate({0.1, -0.05, 0.2});
  CHECK(ea.S == eb.S);
  CHECK(ea.W == eb.W);
  CHECK(&require_energy_law(back, file.string()) == &*back.energy_law);
}

TEST_CASE("database v2: the energy law states its units", "[unit]") {
  // Session 33 (a helper's audit): dropping the attribute passed the suite.
  const auto file = tmp("energy_units.h5");
  write_database(file, db_with_law());
  const auto f = knit::io::H5File::open_read(file);
  CHECK(f.attribute_string("/energy_law", "units") == "W MPa (N mm/mm^3), S and C MPa, l mm");
  CHECK(f.attribute_string("/energy_law/box_min", "units") ==
        "e = (E11, E22, 2 E12): the data strain box");
}

TEST_CASE("database v2: per-loop-length diagnostics of different lengths are refused", "[unit]") {
  // Without the check the reader indexed past the shorter dataset (session 33, a helper's
  // audit).
  const auto file = tmp("energy_short.h5");
  write_database(file, db_with_law());
  {
    auto f = knit::io::H5File::open_rw(file);
    f.write("/energy_law/diagnostics/points", std::vector<int>{17});
  }
  CHECK_THROWS_WITH(
      read_database(file),
      file.string() + ": /energy_law/diagnostics: per-loop-length datasets differ in length");
}

TEST_CASE("database: diagnostics written before the monotonicity bound still load", "[unit]") {
  const auto file = tmp("energy_no_mono.h5");
  write_database(file, db_with_law());
  {
    auto f = knit::io::H5File::open_rw(file);
    f.remove("/energy_law/diagnostics/monotonicity_bound");
  }
  const Database back = read_database(file, false);
  REQUIRE(back.energy_diagnostics.per_loop.size() == 2);
  CHECK(std::isnan(back.energy_diagnostics.per_loop[0].monotonicity_bound));
  CHECK(back.energy_diagnostics.per_loop[1].stress_range == 2.0);
}

TEST_CASE("database: the law's own uniaxial curves round trip, older files load without them",
          "[unit]") {
  // Session 41: knit-macro warns from them (KnitMaterial::warning()).
  const auto file = tmp("energy_uniaxial.h5");
  const Database db = db_with_law();
  write_database(file, db);
  const Database back = read_database(file, false);
  const auto& pl = back.energy_diagnostics.per_loop;
  REQUIRE(pl.size() == 2);
  CHECK(pl[0].uniaxial[0].empty());
  CHECK(pl[0].uniaxial[1].empty());
  CHECK(pl[1].uniaxial[0].empty());
  const UniaxialCurve& c = pl[1].uniaxial[1];
  CHECK(c.strain == std::vector<double>{0.1, 0.2, 0.3});
  CHECK(c.cell == std::vector<double>{0.5, 1.0, 2.0});
  REQUIRE(c.law.size() == 3);
  CHECK(c.law[0] == 0.6);
  CHECK(c.law[1] == 2.5);
  CHECK(std::isnan(c.law[2]));  // no state of the law there: kept as NaN
  {
    auto f = knit::io::H5File::open_rw(file);
    CHECK(f.exists("/energy_law/diagnostics/uniaxial/wale_1"));
    CHECK(f.attribute_string("/energy_law/diagnostics/uniaxial/wale_1", "units") ==
          "E_axial 1, S_cell MPa, S_law MPa");
    CHECK_FALSE(f.exists("/energy_law/diagnostics/uniaxial/course_1"));
    f.remove("/energy_law/diagnostics/uniaxial");  // as written before session 41
  }
  const Database old = read_database(file, false);
  CHECK(old.energy_diagnostics.per_loop[1].uniaxial[1].empty());
  // A malformed curve is refused with its HDF5 path: two columns, a non-finite cell stress, an
  // infinite law stress.
  const std::string w = "/energy_law/diagnostics/uniaxial/wale_1";
  auto refused_edit = [&](const std::function<void(knit::io::H5File&)>& edit) {
    write_database(file, db);
    {
      auto f = knit::io::H5File::open_rw(file);
      edit(f);
    }
    try {
      read_database(file);
    } catch (const knit::InputError& e) {
      return e.pointer() + ": " + e.message();
    }
    return std::string("no error");
  };
  auto refused = [&](const RowMatrixX& m) {
    return refused_edit([&](knit::io::H5File& f) { f.write(w, m); });
  };
  RowMatrixX m(3, 3);
  m << 0.1, 0.5, 0.6, 0.2, 1.0, 2.5, 0.3, 2.0, 3.0;
  CHECK(refused(m) == "no error");
  CHECK(refused(m.leftCols(2)) ==
        w + ": needs one row per step and 3 columns (E_axial, S_cell, S_law)");
  m(1, 1) = std::nan("");
  CHECK(refused(m) == w + ": row 1 is not finite");
  m(1, 1) = 1.0;
  m(2, 2) = std::numeric_limits<double>::infinity();
  CHECK(refused(m) == w + ": row 2 is not finite");
  m(2, 2) = 3.0;
  m(2, 0) = 0.2;  // the axial strain of the last step equals the one before
  CHECK(refused(m) == w + ": row 2: the axial strain must increase from step to step");
  // Session 41's review: a curve of a row the file does not have and a misspelt name were
  // passed over; loop lengths that do not increase misplace the knots' neighbours.
  const std::string u = "/energy_law/diagnostics/uniaxial";
  CHECK(refused_edit([&](knit::io::H5File& f) { f.write(u + "/wale_2", m); }) ==
        u + "/wale_2: not a curve of this file: the datasets are course_<k> and wale_<k> for k = "
            "0 ... 1 (the rows of loop_length)");
  CHECK_THAT(refused_edit([&](knit::io::H5File& f) { f.write(u + "/wales_1", m); }),
             Catch::StartsWith(u + "/wales_1: not a curve of this file"));
  CHECK(refused_edit([&](knit::io::H5File& f) {
          f.write("/energy_law/diagnostics/loop_length", std::vector<double>{6.5, 4.5});
        }) ==
        "/energy_law/diagnostics/loop_length: must increase (entry 1) where curves in "
        "/energy_law/diagnostics/uniaxial refer to its rows");
  // Session 42: the rows are the database's loop lengths (4.5 and 6.5 mm here) and, for the
  // network, its knots; a row off them is refused.
  CHECK(refused_edit([&](knit::io::H5File& f) {
          f.write("/energy_law/diagnostics/loop_length", std::vector<double>{4.5, 7.0});
        }) ==
        "/energy_law/diagnostics/loop_length: entry 1 (7 mm) is not the database's loop length "
        "/loop_lengths[1] = 6.5 mm, where curves in /energy_law/diagnostics/uniaxial refer to "
        "its rows");
  Database extra_row = db;  // a third row of diagnostics for two loop lengths
  extra_row.energy_diagnostics.per_loop.push_back(extra_row.energy_diagnostics.per_loop[1]);
  extra_row.energy_diagnostics.per_loop[2].loop_length = 7.0;
  write_database(file, extra_row);
  CHECK_THROWS_WITH(read_database(file),
                    file.string() +
                        ": /energy_law/diagnostics/loop_length: has 3 rows and /loop_lengths 2, "
                        "where curves in /energy_law/diagnostics/uniaxial refer to its rows");
  Database net = db;
  set_network_law(net);  // knots 4.5, 5.5, 6.5
  write_database(file, net);
  CHECK(read_database(file).energy_diagnostics.per_loop[2].uniaxial[1].strain.size() == 3);
  {
    auto f = knit::io::H5File::open_rw(file);
    f.write("/energy_law/diagnostics/loop_length", std::vector<double>{4.5, 5.25, 6.5});
  }
  CHECK_THROWS_WITH(read_database(file),
                    file.string() +
                        ": /energy_law/diagnostics/loop_length: entry 1 (5.25 mm) is not the "
                        "law's loop length /energy_law/l_knots[1] = 5.5 mm, where curves in "
                        "/energy_law/diagnostics/uniaxial refer to its rows");
}

TEST_CASE("database v1: loads, and asking it for the energy law names file and path", "[unit]") {
  const auto file = tmp("energy_v1.h5");
  Database db = db_with_law();
  write_database(file, db);
  {  // What a version-1 build wrote: no /energy_law (an extra group there would be ignored).
    auto f = knit::io::H5File::open_rw(file);
    f.set_attribute(".", "format_version", 1);
  }
  const Database back = read_database(file);
  CHECK(back.format_version == 1);
  CHECK_FALSE(back.energy_law);
  REQUIRE(back.entries.size() == 2);
  try {
    require_energy_law(back, file.string());
    FAIL("no error");
  } catch (const knit::InputError& e) {
    CHECK(e.file() == file.string());
    CHECK(e.pointer() == "/energy_law");
    CHECK_THAT(e.message(), Catch::Contains("format-version-1"));
    CHECK_THAT(e.message(), Catch::Contains("knit-meso fit " + file.string() + " --law energy"));
  }
  // A version-2 file fitted without the energy law says so too.
  db.energy_law.reset();
  write_database(file, db);
  const Database v2 = read_database(file);
  CHECK_THROWS_WITH(
      require_energy_law(v2, file.string()),
      Catch::Contains("/energy_law: group missing") && Catch::Contains("--law energy"));
}

TEST_CASE("database v2: bad /energy_law content is refused with its HDF5 path", "[unit]") {
  const auto good = tmp("energy_good.h5");
  write_database(good, db_with_law());
  const auto bad = tmp("energy_bad.h5");
  SECTION("negative coefficient (a non-convex law)") {
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    {
      auto f = knit::io::H5File::open_rw(bad);
      RowMatrixX c = f.read_matrix("/energy_law/coefficients");
      c(3, 4) = -0.5;
      f.write("/energy_law/coefficients", c);
    }
    CHECK_THROWS_WITH(read_database(bad), Catch::Contains("energy_bad.h5: /energy_law: ") &&
                                              Catch::Contains("coefficients must be >= 0"));
  }
  SECTION("missing dataset") {
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    {
      auto f = knit::io::H5File::open_rw(bad);
      f.remove("/energy_law/s_range");
    }
    CHECK_THROWS_WITH(read_database(bad),
                      Catch::Contains("energy_bad.h5: /energy_law/s_range: dataset missing"));
  }
  SECTION("missing attribute: its object's path once") {
    // Session 25: "energy_bad.h5: /energy_law: /energy_law: attribute floor missing".
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    knit::io::H5File::open_rw(bad).remove_attribute("/energy_law", "floor");
    CHECK_THROWS_WITH(read_database(bad), bad.string() + ": /energy_law: attribute floor missing");
  }
  SECTION("range that does not cover the loop lengths") {
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    {
      auto f = knit::io::H5File::open_rw(bad);
      f.set_attribute("/energy_law", "l_max", 6.0);
    }
    CHECK_THROWS_WITH(read_database(bad), Catch::Contains("/energy_law: ") &&
                                              Catch::Contains("does not cover /loop_lengths"));
  }
}

TEST_CASE("database: non-finite energy-law diagnostics are refused with their HDF5 path",
          "[unit]") {
  // Session 33 (a helper's audit): NaN and inf in /energy_law/diagnostics went through
  // `knit-meso fit --law paper` into the refitted file with exit 0. The monotonicity bound may
  // be NaN ("unknown", EnergyFitDiagnostics), not inf.
  const auto good = tmp("energy_diag_good.h5"), bad = tmp("energy_diag_bad.h5");
  write_database(good, db_with_law());
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  const std::string d = "/energy_law/diagnostics";
  auto with = [&](const std::function<void(knit::io::H5File&)>& edit) {
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    {
      auto f = knit::io::H5File::open_rw(bad);
      edit(f);
    }
    try {
      read_database(bad);
    } catch (const knit::InputError& e) {
      return e.pointer() + ": " + e.message();
    }
    return std::string("no error");
  };
  auto entry = [&](const std::string& name, int i, double v) {
    return [=](knit::io::H5File& f) {
      std::vector<double> x = f.read_doubles(d + "/" + name);
      x[static_cast<std::size_t>(i)] = v;
      f.write(d + "/" + name, x);
    };
  };
  for (const char* name : {"loop_length", "stress_range", "max_relative", "rms_relative",
                           "holdout_rms", "holdout_max"})
    CHECK(with(entry(name, 1, nan)) == d + "/" + name + ": entry 1 is not finite");
  CHECK(with([&](knit::io::H5File& f) {
          RowMatrixX m = f.read_matrix(d + "/max");
          m(1, 2) = inf;
          f.write(d + "/max", m);
        }) == d + "/max: entry 5 is not finite");
  CHECK(with(entry("monotonicity_bound", 0, inf)) ==
        d + "/monotonicity_bound: entry 0 is not finite (NaN, unknown, is accepted here)");
  CHECK(with(entry("monotonicity_bound", 0, nan)) == "no error");
  for (const char* name : {"holdout_max_relative", "min_eigenvalue"})
    CHECK(with([&](knit::io::H5File& f) { f.set_attribute(d, name, inf); }) ==
          d + ": attribute " + name + " is not finite");
}

TEST_CASE("database v3: the network law round trip", "[unit]") {
  const auto file = tmp("network_roundtrip.h5");
  Database db = db_with_law();
  set_network_law(db);
  db.energy_law->network.shape.stiff1 = 1;  // stiffening units (session 11) round-trip too
  db.energy_law->network.shape.stiff2 = 2;
  db.energy_law->network.shape.outer = 1;  // and the exponential outer function (session 15)
  db.energy_law->network.shape.outer_scale = 0.3;
  db.energy_law->network.shape.outer_cap = 1.7;
  // and the interpolation in l (session 16)
  db.energy_law->network.l_interpolation = LInterpolation::kEnergy;
  db.energy_law->network.l_blend = 0.2;  // and the rounding of its kinks (session 44)
  write_database(file, db);
  {
    const auto f = knit::io::H5File::open_read(file);
    CHECK(f.attribute_double("/energy_law", "l_blend") == 0.2);
    CHECK(f.attribute_string("/energy_law", "family") == "network");
    CHECK(f.attribute_string("/energy_law", "outer") == "exp");
    CHECK(f.attribute_string("/energy_law", "l_interpolation") == "energy");
    CHECK_FALSE(f.exists("/energy_law/coefficients"));  // no ridge datasets beside it
  }
  const Database back = read_database(file, false);
  REQUIRE(back.energy_law);
  const EnergyLawData &a = *db.energy_law, &b = *back.energy_law;
  CHECK(b.family == EnergyFamily::kNetwork);
  CHECK(b.network.shape.h1 == a.network.shape.h1);
  CHECK(b.network.shape.h2 == a.network.shape.h2);
  CHECK(b.network.shape.stiff1 == 1);
  CHECK(b.network.shape.stiff2 == 2);
  CHECK(b.network.shape.outer == 1);
  CHECK(b.network.shape.outer_scale == 0.3);
  CHECK(b.network.shape.outer_cap == 1.7);
  CHECK(b.network.l_interpolation == LInterpolation::kEnergy);
  CHECK(b.network.l_blend == 0.2);
  CHECK(b.network.l_knots == a.network.l_knots);
  CHECK(b.network.theta == a.network.theta);
  CHECK(b.floor == a.floor);
  CHECK(b.box_max == a.box_max);
  const auto ea = EnergyLaw(a).at(5.1).evaluate({0.1, -0.05, 0.2});
  const auto eb = EnergyLaw(b).at(5.1).evaluate({0.1, -0.05, 0.2});
  CHECK(ea.S == eb.S);
  CHECK(ea.C == eb.C);
}

namespace {
/// A database with the test network law written to tmp(name), then `edit` applied to the file
/// (an older or a damaged writer). Returns the database as written.
template <class Edit>
Database write_network_db_then(const std::string& file, Edit edit) {
  Database db = db_with_law();
  set_network_law(db);
  write_database(file, db);
  auto f = knit::io::H5File::open_rw(file);
  edit(f);
  return db;
}
}  // namespace

TEST_CASE("database v3: a network law written before the stiffening units still loads", "[unit]") {
  const auto file = tmp("network_no_stiff.h5");
  const Database db = write_network_db_then(file, [](knit::io::H5File& f) {
    f.remove_attribute("/energy_law", "stiff1");
    f.remove_attribute("/energy_law", "stiff2");
  });
  const Database back = read_database(file, false);
  REQUIRE(back.energy_law);
  CHECK(back.energy_law->network.shape.stiff1 == 0);
  CHECK(back.energy_law->network.shape.stiff2 == 0);
  CHECK(back.energy_law->network.shape.outer == 0);  // nor an outer function (session 15)
  CHECK(back.energy_law->network.theta == db.energy_law->network.theta);
}

TEST_CASE("database v3: a network law without l_interpolation interpolates theta", "[unit]") {
  // Written before session 16: theta piecewise linear in l, as it was fitted and checked.
  const auto file = tmp("network_no_l_interpolation.h5");
  write_network_db_then(file, [](knit::io::H5File& f) {
    REQUIRE(f.attribute_string("/energy_law", "l_interpolation") == "parameters");
    f.remove_attribute("/energy_law", "l_interpolation");
  });
  const Database back = read_database(file, false);
  REQUIRE(back.energy_law);
  CHECK(back.energy_law->network.l_interpolation == LInterpolation::kParameters);
  const auto bad = tmp("network_bad_l_interpolation.h5");
  write_network_db_then(bad, [](knit::io::H5File& f) {
    f.remove_attribute("/energy_law", "l_interpolation");
    f.set_attribute("/energy_law", "l_interpolation", "spline");
  });
  CHECK_THROWS_WITH(
      read_database(bad, false),
      Catch::Contains("/energy_law") && Catch::Contains("l_interpolation is \"spline\""));
}

TEST_CASE("database v3: l_blend is optional, written only when not 0, and checked", "[unit]") {
  // Session 44: a law without the attribute is the law of sessions 16-43 (no rounding); the
  // writer leaves it out at 0, so such a law's file is as before.
  const auto file = tmp("network_no_l_blend.h5");
  write_network_db_then(file, [](knit::io::H5File& f) {
    CHECK_FALSE(f.has_attribute("/energy_law", "l_blend"));
    f.remove_attribute("/energy_law", "l_interpolation");
    f.set_attribute("/energy_law", "l_interpolation", "energy");
  });
  const Database back = read_database(file, false);
  REQUIRE(back.energy_law);
  CHECK(back.energy_law->network.l_blend == 0.0);
  // Out of [0, 0.5], or beside the parameters' interpolation: refused with the HDF5 path.
  const auto wide = tmp("network_wide_l_blend.h5");
  write_network_db_then(wide, [](knit::io::H5File& f) {
    f.remove_attribute("/energy_law", "l_interpolation");
    f.set_attribute("/energy_law", "l_interpolation", "energy");
    f.set_attribute("/energy_law", "l_blend", 0.6);
  });
  CHECK_THROWS_WITH(read_database(wide, false), Catch::Contains("/energy_law") &&
                                                    Catch::Contains("l_blend must be in [0, 0.5]"));
  const auto theta = tmp("network_theta_l_blend.h5");
  write_network_db_then(
      theta, [](knit::io::H5File& f) { f.set_attribute("/energy_law", "l_blend", 0.1); });
  CHECK_THROWS_WITH(read_database(theta, false),
                    Catch::Contains("/energy_law") && Catch::Contains("l_blend is only read with"));
}

TEST_CASE("database v3: an unknown outer function is refused with its HDF5 path", "[unit]") {
  const auto file = tmp("network_bad_outer.h5");
  write_network_db_then(file, [](knit::io::H5File& f) {
    f.remove_attribute("/energy_law", "outer");
    f.set_attribute("/energy_law", "outer", "log");
  });
  CHECK_THROWS_WITH(read_database(file, false),
                    Catch::Contains("/energy_law") && Catch::Contains("outer is \"log\""));
}

TEST_CASE("database v3: the outer function's parameters without its kind are refused", "[unit]") {
  // Session 36 (a helper's red team): /energy_law@outer deleted, outer_scale and outer_cap
  // left, read as "none" with exit 0 (5.2 N instead of 84.6 N).
  for (const bool exp : {true, false}) {
    const auto file = tmp(exp ? "network_outer_gone_exp.h5" : "network_outer_gone_none.h5");
    Database db = db_with_law();
    set_network_law(db);
    if (exp) {
      db.energy_law->network.shape.outer = 1;
      db.energy_law->network.shape.outer_scale = 0.3;
      db.energy_law->network.shape.outer_cap = 1.7;
    }
    write_database(file, db);
    {
      auto f = knit::io::H5File::open_rw(file);
      REQUIRE(f.has_attribute("/energy_law", "outer_scale") == exp);
      f.remove_attribute("/energy_law", "outer");
    }
    if (exp)
      CHECK_THROWS_WITH(read_database(file, false),
                        file.string() +
                            ": /energy_law: attribute outer is missing but outer_scale is "
                            "there: the outer function's kind is unknown (\"exp\" or "
                            "\"none\"); the file was changed after it was written");
    else  // a law without an outer function: as written before session 15
      CHECK(read_database(file, false).energy_law->network.shape.outer == 0);
  }
}

TEST_CASE("database v3: a bad network law is refused with its HDF5 path", "[unit]") {
  Database db = db_with_law();
  set_network_law(db);
  const auto good = tmp("network_good.h5");
  write_database(good, db);
  const auto bad = tmp("network_bad.h5");
  fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
  SECTION("a negative weight (a non-convex law)") {
    {
      auto f = knit::io::H5File::open_rw(bad);
      RowMatrixX t = f.read_matrix("/energy_law/theta");
      t(1, db.energy_law->network.shape.V()) = -0.1;
      f.write("/energy_law/theta", t);
    }
    CHECK_THROWS_WITH(read_database(bad), Catch::Contains("network_bad.h5: /energy_law: ") &&
                                              Catch::Contains("V, w, w1 must be >= 0"));
  }
  SECTION("an unknown family") {
    {
      auto f = knit::io::H5File::open_rw(bad);
      f.set_attribute("/energy_law", "family", "spline3d");
    }
    CHECK_THROWS_WITH(read_database(bad), Catch::Contains("network_bad.h5: /energy_law: ") &&
                                              Catch::Contains("family is \"spline3d\""));
  }
  SECTION("a missing family (session 43's red team: read as a ridge law, 'directions missing')") {
    {
      auto f = knit::io::H5File::open_rw(bad);
      f.remove_attribute("/energy_law", "family");
    }
    CHECK_THROWS_WITH(read_database(bad),
                      Catch::Contains("network_bad.h5: /energy_law: attribute family missing"));
  }
  SECTION("a missing dataset") {
    {
      auto f = knit::io::H5File::open_rw(bad);
      f.remove("/energy_law/theta");
    }
    CHECK_THROWS_WITH(read_database(bad),
                      Catch::Contains("network_bad.h5: /energy_law/theta: dataset missing"));
  }
}
