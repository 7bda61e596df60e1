// HDF5 adapter: round trips, shapes as h5py sees them, attribute kinds, and error messages
// that name the file and the object path.
#include <unistd.h>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>

#include "knit/io/hdf5.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using knit::io::H5File;

namespace {
fs::path scratch(const std::string& name) {
  static knit_test::ScratchDir dir("io_hdf5");
  return dir / name;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "<no exception>";
}
}  // namespace

TEST_CASE("HDF5 datasets round-trip with row-major shapes", "[unit][io][hdf5]") {
  const fs::path file = scratch("roundtrip.h5");
  knit::io::RowMatrixXd M(2, 3);
  M << 1, 2, 3, 4, 5, 6;
  Eigen::MatrixXd Mc = M;  // column-major source must be written with the same (i, j) layout
  Eigen::VectorXd v(4);
  v << 0.5, -1.5, 2.25, 1e-300;
  {
    H5File f = H5File::create(file);
    f.create_group("/loop_4.50/raw");
    f.write("/loop_4.50/raw/E", M);
    f.write("/loop_4.50/raw/Ec", Mc, {.gzip_level = 4});
    f.write("/loop_4.50/fit/v", v);  // intermediate group "fit" created on the fly
    f.write("ints", std::vector<int>{3, -1, 7});
    knit::io::RowMatrixXi I(3, 2);
    I << 1, 2, 3, 4, 5, 6;
    f.write("/imat", I);
    f.write("empty", std::vector<double>{});
    f.write_strings("/names", {"u0", "v1", "ünïcode"});
    const std::vector<double> cube{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
    f.write_dataset("/tensor3", std::span<const double>(cube), {2, 3, 2});
    const double scalar = 2.5;
    f.write_dataset("/scalar", std::span<const double>(&scalar, 1), {});
    f.close();
  }
  H5File f = H5File::open_read(file);
  CHECK(f.exists("/loop_4.50/raw/E"));
  CHECK_FALSE(f.exists("/loop_4.50/nope/E"));
  CHECK(f.is_group("/loop_4.50"));
  CHECK(f.is_dataset("/loop_4.50/raw/E"));
  CHECK_FALSE(f.is_dataset("/loop_4.50"));
  CHECK(f.shape("/loop_4.50/raw/E") == std::vector<std::size_t>{2, 3});
  CHECK(f.read_matrix("/loop_4.50/raw/E") == M);
  CHECK(f.read_matrix("/loop_4.50/raw/Ec") == M);
  auto g = f.open_group("/loop_4.50");
  CHECK(g.path() == "/loop_4.50");
  CHECK(g.children() == std::vector<std::string>{"fit", "raw"});
  const auto vr = g.read_doubles("fit/v");
  REQUIRE(vr.size() == 4);
  CHECK(vr[3] == 1e-300);
  CHECK(f.read_ints("ints") == std::vector<int>{3, -1, 7});
  CHECK(f.read_int_matrix("imat")(2, 1) == 6);
  CHECK(f.read_matrix("imat")(1, 0) == 3.0);  // integer data readable as double
  CHECK(f.read_doubles("empty").empty());
  CHECK(f.read_strings("names") == std::vector<std::string>{"u0", "v1", "ünïcode"});
  const auto t3 = f.read_array("/tensor3");
  CHECK(t3.shape == std::vector<std::size_t>{2, 3, 2});
  CHECK(t3.data[1 * 6 + 2 * 2 + 1] == 11.0);  // [1][2][1], row-major
  CHECK(f.shape("/scalar").empty());
  CHECK(f.read_doubles("/scalar") == std::vector<double>{2.5});
  CHECK(f.children("/") == std::vector<std::string>{"empty", "imat", "ints", "loop_4.50", "names",
                                                    "scalar", "tensor3"});
}

TEST_CASE("HDF5 attributes on files, groups and datasets", "[unit][io][hdf5]") {
  const fs::path file = scratch("attrs.h5");
  {
    H5File f = H5File::create(file);
    f.set_attribute(".", "version", "0.1.0");
    f.set_attribute("/", "n", 13);
    auto g = f.create_group("a/b");
    g.set_attribute(".", "loop_length", 4.5);
    g.write("d", std::vector<double>{1, 2});
    g.set_attribute("d", "bounds", std::vector<double>{0.0, 1.0, 2.5});
    g.set_attribute("d", "loop_length", 5.0);
    g.set_attribute("d", "loop_length", 6.0);  // overwrite
    f.close();
  }
  {
    H5File f = H5File::open_rw(file);
    f.set_attribute("/a", "unit", std::string("mm"));
  }
  H5File f = H5File::open_read(file);
  CHECK(f.attribute_string(".", "version") == "0.1.0");
  CHECK(f.attribute_int(".", "n") == 13);
  CHECK(f.attribute_double(".", "n") == 13.0);
  CHECK(f.attribute_double("/a/b", "loop_length") == 4.5);
  CHECK(f.attribute_doubles("/a/b/d", "bounds") == std::vector<double>{0.0, 1.0, 2.5});
  CHECK(f.attribute_double("/a/b/d", "loop_length") == 6.0);
  CHECK(f.attribute_string("a", "unit") == "mm");
  CHECK(f.has_attribute("/a/b/d", "bounds"));
  CHECK_FALSE(f.has_attribute("/a/b/d", "nope"));
  CHECK_FALSE(f.has_attribute("/nope", "x"));
  CHECK(f.attribute_names("/a/b/d") == std::vector<std::string>{"bounds", "loop_length"});
}

TEST_CASE("HDF5 errors name the file and the object path", "[unit][io][hdf5]") {
  const fs::path file = scratch("db.h5");
  {
    H5File f = H5File::create(file);
    f.write("/loop_4.50/raw/E", std::vector<double>{1.0, 2.0});
    f.write_strings("/loop_4.50/names", {"a"});
    f.set_attribute("/loop_4.50", "s", "text");
  }
  H5File f = H5File::open_read(file);
  const std::string fn = file.string();
  CHECK(message_of([&] { f.read_matrix("/loop_4.50/fit/S_surface"); }) ==
        fn + ": /loop_4.50/fit/S_surface: dataset missing");
  CHECK(message_of([&] { f.open_group("/loop_5.00"); }) == fn + ": /loop_5.00: group missing");
  auto g = f.open_group("loop_4.50");
  CHECK(message_of([&] { g.read_doubles("fit/x"); }) == fn + ": /loop_4.50/fit/x: dataset missing");
  CHECK_THAT(message_of([&] { g.read_matrix("raw/E"); }),
             Catch::Contains("/loop_4.50/raw/E: expected a 2-D dataset, found rank 1"));
  CHECK_THAT(message_of([&] { g.read_ints("raw/E"); }),
             Catch::Contains("expected an integer dataset, found floating-point"));
  CHECK_THAT(message_of([&] { g.read_doubles("names"); }),
             Catch::Contains("/loop_4.50/names: expected a numeric dataset, found string"));
  CHECK_THAT(message_of([&] { g.attribute_double(".", "s"); }),
             Catch::Contains("/loop_4.50: attribute s: expected a number, found string"));
  CHECK_THAT(message_of([&] { g.attribute_string(".", "t"); }),
             Catch::Contains("/loop_4.50: attribute t missing"));
  // Writing into a read-only file fails with a message, not a crash.
  CHECK_THAT(message_of([&] { f.write("/x", std::vector<double>{1}); }),
             Catch::Contains(fn + ": /x: cannot create dataset"));
}

TEST_CASE("HDF5 refuses missing, non-HDF5 and truncated files cleanly", "[unit][io][hdf5]") {
  const fs::path missing = scratch("missing.h5");
  fs::remove(missing);
  CHECK(message_of([&] { H5File::open_read(missing); }) == missing.string() + ": file not found");

  const fs::path text = scratch("text.h5");
  std::ofstream(text) << "{\"not\": \"hdf5\"}\n";
  CHECK_FALSE(knit::io::is_hdf5_file(text));
  CHECK(message_of([&] { H5File::open_read(text); }) ==
        text.string() + ": not an HDF5 file (or truncated)");

  const fs::path good = scratch("good.h5");
  {
    H5File f = H5File::create(good);
    knit::io::RowMatrixXd big = knit::io::RowMatrixXd::Random(200, 50);
    f.write("/big", big);
  }
  const fs::path cut = scratch("cut.h5");
  fs::copy_file(good, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(good) / 2);
  const std::string msg = message_of([&] {
    H5File f = H5File::open_read(cut);
    f.read_matrix("/big");
  });
  CHECK_THAT(msg, Catch::StartsWith(cut.string() + ": "));

  const fs::path nodir = scratch("no/such/dir/x.h5");
  CHECK_THAT(message_of([&] { H5File::create(nodir); }),
             Catch::Contains("cannot create HDF5 file"));
}

TEST_CASE("only the HDF5 adapter includes hdf5.h", "[unit][io][layering]") {
  const fs::path root = KNIT_SOURCE_DIR;
  const std::regex inc(R"(#\s*include\s*[<"]hdf5\.h[>"])");
  std::vector<std::string> hits;
  for (const char* dir : {"common", "mesoscale", "macroscale", "tests"}) {
    if (!fs::exists(root / dir)) continue;
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      if (!e.is_regular_file() || e.path().filename() == "io_hdf5.cpp") continue;
      const auto ext = e.path().extension();
      if (ext != ".cpp" && ext != ".hpp" && ext != ".h") continue;
      std::ifstream in(e.path());
      std::string line;
      while (std::getline(in, line))
        if (std::regex_search(line, inc)) hits.push_back(e.path().string());
    }
  }
  for (const auto& h : hits) UNSCOPED_INFO(h);
  CHECK(hits.empty());
}
