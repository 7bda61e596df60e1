// Input and output of the knitting map (knit/macro/knitmap.hpp): the case is read by
// load_case (its knit material by knit_material_factory.cpp); here only the database's cell
// parameters are read again, for w(l) and c(l). Outputs go to an atomic directory.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/provenance.hpp"
#include "knit/macro/knitmap.hpp"
#include "knit/material/database.hpp"

namespace knit::macro {

KnitMapInput load_knitmap_input(const std::string& case_file) {
  KnitMapInput in;
  in.c = load_case(case_file);  // validates everything, the knit fields and the database too
  const nlohmann::json root = io::parse_json(in.c.text, case_file);
  const nlohmann::json& m = root.at("material");
  const std::string type = m.value("type", std::string());
  if (type != "knit")
    throw InputError(
        case_file, "/material/type",
        "the knitting map needs the knit material (type \"knit\"), not \"" + type + "\"");
  in.database = io::resolve_input_path(case_file, m.at("database").get<std::string>()).string();
  material::Database db;
  try {
    db = material::read_database(in.database, false);
  } catch (const InputError& e) {
    throw InputError(case_file, "/material/database", e.what());
  }
  in.cells = CellTable(db, in.database);
  in.database_date_utc = db.provenance.date_utc;
  return in;
}

namespace {

/// The significant digits that resolve kCoordinateResolution mm at the map's largest coordinate:
/// io::format_number's 10 (every other CSV's) for a patch within 1e5 mm of the origin, up to a
/// double's 17. Session 54's red team: a patch moved to (2e9, 2e9) mm (the loader allows 1e8
/// times the patch's size) printed x = 2000000000, 2000000002, 2000000003 for stitches 1.26 mm
/// apart, and 240 stitch centres twice.
constexpr double kCoordinateResolution = 1e-4;
int coordinate_digits(const KnitMap& map) {
  double far = 0.0;
  for (const auto& s : map.stitches) far = std::max(far, s.position.cwiseAbs().maxCoeff());
  // log10(far / resolution) digits reach the resolution; one more keeps the rounding below it.
  const double d = std::ceil(std::log10(std::max(far, 1.0) / kCoordinateResolution)) + 1;
  return static_cast<int>(std::clamp(d, 10.0, 17.0));
}

std::string coordinate(double x, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

}  // namespace

void write_knitmap(const KnitMap& map, const KnitMapInput& in, const std::filesystem::path& dir,
                   std::string_view option) {
  io::AtomicDirectory out(dir, io::AtomicDirectory::OnAbandon::Remove, option, in.c.file);
  const std::string prov = "provenance: " + io::Provenance::current(in.c.file).to_json_string();
  {
    io::CsvWriter csv(out / "knitmap.csv", {"course", "needle", "l_mm", "x_mm", "y_mm"});
    csv.add_comment(prov);
    csv.add_comment("database: " + in.database);
    const int digits = coordinate_digits(map);
    for (const auto& s : map.stitches)
      csv.add_row({s.course, s.needle, s.l, coordinate(s.position.x(), digits),
                   coordinate(s.position.y(), digits)});
    csv.commit();
  }
  {
    io::CsvWriter csv(out / "courses.csv", {"course", "first_needle", "last_needle", "stitches",
                                            "height_mm", "t_mm", "height_mismatch"});
    csv.add_comment(prov);
    for (const auto& k : map.courses)
      csv.add_row({k.index, k.first_needle, k.first_needle + k.stitches - 1, k.stitches, k.height,
                   k.t, k.height_mismatch});
    csv.commit();
  }
  io::write_file_atomically(
      out / "summary.txt",
      "# " + prov + "\ncase: " + in.c.file + "\ndatabase: " + in.database + "\n" +
          (in.database_date_utc.empty() ? std::string()
                                        : "database_date_utc: " + in.database_date_utc + "\n") +
          knitmap_summary(map));
  out.commit();
}

}  // namespace knit::macro
