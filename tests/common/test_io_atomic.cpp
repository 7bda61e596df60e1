// Atomic files/directories, CSV writer and provenance records.
#include <unistd.h>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "knit/core/build_info.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/io/provenance.hpp"

namespace fs = std::filesystem;

namespace {
struct Scratch {
  fs::path dir =
      fs::path(KNIT_BINARY_DIR) / "test_scratch" / ("io_atomic_" + std::to_string(getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};
fs::path scratch(const std::string& name) {
  static Scratch s;
  return s.dir / name;
}
std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}
}  // namespace

TEST_CASE("AtomicFile replaces the target only on commit", "[unit][io][atomic]") {
  const fs::path dir = scratch("af");
  fs::create_directories(dir);
  const fs::path target = dir / "out.txt";
  std::ofstream(target) << "old";

  {  // abandoned: the old content stays, no temporary remains
    knit::io::AtomicFile f(target);
    f.stream() << "new but never committed";
    CHECK(fs::exists(f.temp_path()));
    CHECK(f.temp_path().parent_path() == dir);
  }
  CHECK(slurp(target) == "old");
  CHECK(entries(dir) == 1);

  {
    knit::io::AtomicFile f(target);
    f.stream() << "new";
    CHECK(slurp(target) == "old");  // not visible before commit
    f.commit();
    CHECK(f.committed());
  }
  CHECK(slurp(target) == "new");
  CHECK(entries(dir) == 1);

  knit::io::write_file_atomically(dir / "b.txt", "hello");
  CHECK(slurp(dir / "b.txt") == "hello");

  // A library that writes by file name (HDF5) goes through temp_path().
  {
    knit::io::AtomicFile f(dir / "x.h5");
    auto h5 = knit::io::H5File::create(f.temp_path());
    h5.write("/v", std::vector<double>{1, 2, 3});
    h5.close();
    f.commit();
  }
  CHECK(knit::io::H5File::open_read(dir / "x.h5").read_doubles("/v").size() == 3);
  {  // AtomicH5File: abandoned leaves the old file, committed replaces it
    knit::io::AtomicH5File db(dir / "x.h5");
    db->write("/v", std::vector<double>{1});
  }
  CHECK(knit::io::H5File::open_read(dir / "x.h5").read_doubles("/v").size() == 3);
  CHECK(entries(dir) == 3);  // out.txt, b.txt, x.h5: no temporary left behind
  {
    knit::io::AtomicH5File db(dir / "x.h5");
    db->write("/v", std::vector<double>{1});
    db.commit();
  }
  CHECK(knit::io::H5File::open_read(dir / "x.h5").read_doubles("/v").size() == 1);

  CHECK_THROWS_WITH(knit::io::AtomicFile(dir / "missing_dir" / "y.txt"),
                    Catch::Contains("missing_dir/y.txt: cannot write: directory"));
  knit::io::AtomicFile nothing(dir / "z.txt");
  CHECK_THROWS_WITH(nothing.commit(), Catch::Contains("nothing was written"));
}

TEST_CASE("AtomicDirectory leaves an existing output intact until commit", "[unit][io][atomic]") {
  const fs::path target = scratch("ad") / "run_out";
  fs::create_directories(target);
  std::ofstream(target / "old.txt") << "old";

  {  // abandoned (as when an exception unwinds): old output untouched, partial removed
    knit::io::AtomicDirectory d(target);
    CHECK(d.path() != target);
    CHECK_THAT(d.path().filename().string(), Catch::StartsWith("run_out.partial-"));
    std::ofstream(d / "new.txt") << "new";
  }
  CHECK(fs::exists(target / "old.txt"));
  CHECK_FALSE(fs::exists(target / "new.txt"));
  CHECK(entries(target.parent_path()) == 1);

  {  // kept for inspection, clearly marked
    knit::io::AtomicDirectory d(target, knit::io::AtomicDirectory::OnAbandon::Keep);
    std::ofstream(d / "new.txt") << "new";
    const fs::path partial = d.path();
    (void)partial;
  }
  fs::path kept;
  for (const auto& e : fs::directory_iterator(target.parent_path()))
    if (e.path().filename().string().find(".partial-") != std::string::npos) kept = e.path();
  REQUIRE_FALSE(kept.empty());
  CHECK(fs::exists(kept / "INCOMPLETE"));
  fs::remove_all(kept);

  {  // committed: the directory holds exactly the new files
    knit::io::AtomicDirectory d(target);
    knit::io::write_file_atomically(d / "new.txt", "new");
    fs::create_directories(d / "sub");
    std::ofstream(d / "sub" / "a.txt") << "a";
    d.commit();
    CHECK(d.path() == target);
  }
  CHECK(fs::exists(target / "new.txt"));
  CHECK(fs::exists(target / "sub" / "a.txt"));
  CHECK_FALSE(fs::exists(target / "old.txt"));
  CHECK(entries(target.parent_path()) == 1);

  {  // fresh target, trailing slash
    const fs::path fresh = scratch("ad2") / "fresh_out";
    knit::io::AtomicDirectory d(fresh.string() + "/");
    std::ofstream(d / "f.txt") << "f";
    d.commit();
    CHECK(fs::exists(fresh / "f.txt"));
  }
}

TEST_CASE("CsvWriter writes a header, %.10g numbers and quoted text", "[unit][io][csv]") {
  const fs::path file = scratch("curve.csv");
  knit::io::CsvWriter csv(file, {"step", "u_mm", "F_N", "status"});
  csv.add_comment("knitscale test\nsecond line");
  csv.add_row({3, 0.1, 1.0 / 3.0, "converged"});
  csv.add_row({4, 1e-20, -2.5e7, "a, \"b\""});
  CHECK_THROWS_AS(csv.add_row({1.0, 2.0}), std::invalid_argument);
  knit::io::CsvWriter nums(scratch("nums.csv"), {"a", "b"});
  nums.add_row(std::vector<double>{1.5, 2.0});
  nums.commit();
  CHECK_FALSE(fs::exists(file));  // nothing before commit
  csv.commit();
  CHECK(slurp(file) ==
        "# knitscale test\n# second line\nstep,u_mm,F_N,status\n3,0.1,0.3333333333,converged\n"
        "4,1e-20,-25000000,\"a, \"\"b\"\"\"\n");
  CHECK(slurp(scratch("nums.csv")) == "a,b\n1.5,2\n");
  CHECK(knit::io::format_number(std::nan("")) == "nan");
  CHECK(knit::io::format_number(123456789012.0) == "1.23456789e+11");
}

TEST_CASE("Provenance records version, revision, UTC date and command line",
          "[unit][io][provenance]") {
  const auto p = knit::io::Provenance::current("cases/x.json");
  CHECK(p.version == knit::project_version());
  CHECK(p.git_revision == knit::git_revision());
  CHECK(std::regex_match(p.date_utc, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
  CHECK_THAT(p.command_line, Catch::Contains("test_common"));
  CHECK_FALSE(p.host.empty());
  const std::string j = p.to_json_string();
  CHECK(j.find('\n') == std::string::npos);
  CHECK_THAT(j, Catch::StartsWith("{\"program\":\"knitscale\",\"version\":\""));
  CHECK_THAT(j, Catch::Contains("\"input\":\"cases/x.json\""));

  const fs::path file = scratch("prov.h5");
  {
    auto f = knit::io::H5File::create(file);
    knit::io::write_provenance(f, p);
    f.create_group("g");
    knit::io::write_provenance(f, p, "g");
  }
  auto f = knit::io::H5File::open_read(file);
  const auto q = knit::io::read_provenance(f);
  CHECK(q.to_json_string() == j);
  CHECK(f.attribute_string("/g", "git_revision") == p.git_revision);
}
