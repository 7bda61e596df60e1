// VTK writers: the files are parsed back (a minimal XML reader below, base64 decoding) and
// their structure checked — element nesting, counts, array sizes and values — not their text.
#include <unistd.h>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "knit/io/vtk.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using namespace knit::io;

namespace {
fs::path scratch(const std::string& name) {
  static knit_test::ScratchDir dir("io_vtk");
  return dir / name;
}

// ---- a minimal XML reader, enough for well-formed VTK files -------------------------------
struct Node {
  std::string tag, text;
  std::map<std::string, std::string> attr;
  std::vector<std::unique_ptr<Node>> kids;
  const Node& child(const std::string& t) const {
    for (const auto& k : kids)
      if (k->tag == t) return *k;
    throw std::runtime_error("no <" + t + "> in <" + tag + ">");
  }
  std::vector<const Node*> all(const std::string& t) const {
    std::vector<const Node*> out;
    for (const auto& k : kids)
      if (k->tag == t) out.push_back(k.get());
    return out;
  }
};

struct XmlReader {
  std::string s;
  std::size_t i = 0;
  void skip_ws() {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  }
  void skip_misc() {  // declarations and comments
    for (;;) {
      skip_ws();
      if (s.compare(i, 2, "<?") == 0)
        i = s.find("?>", i) + 2;
      else if (s.compare(i, 4, "<!--") == 0) {
        const auto e = s.find("-->", i + 4);
        if (s.substr(i + 4, e - i - 4).find("--") != std::string::npos)
          throw std::runtime_error("'--' inside a comment");
        i = e + 3;
      } else
        return;
    }
  }
  std::unique_ptr<Node> element() {
    skip_misc();
    if (s[i] != '<') throw std::runtime_error("expected '<' at " + std::to_string(i));
    ++i;
    auto n = std::make_unique<Node>();
    while (!std::isspace(static_cast<unsigned char>(s[i])) && s[i] != '>' && s[i] != '/')
      n->tag += s[i++];
    for (;;) {
      skip_ws();
      if (s[i] == '/') {
        if (s[i + 1] != '>') throw std::runtime_error("bad '/'");
        i += 2;
        return n;
      }
      if (s[i] == '>') {
        ++i;
        break;
      }
      std::string key;
      while (s[i] != '=') key += s[i++];
      if (s[i + 1] != '"') throw std::runtime_error("unquoted attribute " + key);
      const auto e = s.find('"', i + 2);
      n->attr[key] = s.substr(i + 2, e - i - 2);
      i = e + 1;
    }
    for (;;) {
      const auto lt = s.find('<', i);
      n->text += s.substr(i, lt - i);
      i = lt;
      if (s.compare(i, 2, "</") == 0) {
        const auto gt = s.find('>', i);
        if (s.substr(i + 2, gt - i - 2) != n->tag)
          throw std::runtime_error("mismatched </" + s.substr(i + 2, gt - i - 2) + "> for <" +
                                   n->tag + ">");
        i = gt + 1;
        return n;
      }
      if (s.compare(i, 4, "<!--") == 0) {
        skip_misc();
        continue;
      }
      n->kids.push_back(element());
    }
  }
};

std::unique_ptr<Node> parse_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  XmlReader r{ss.str()};
  auto root = r.element();
  r.skip_misc();
  if (r.i != r.s.size()) throw std::runtime_error("trailing content");
  return root;
}

std::string base64_decode(const std::string& in) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  unsigned buf = 0;
  int bits = 0;
  for (char c : in) {
    const int v = val(c);
    if (v < 0) continue;  // whitespace, padding
    buf = (buf << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((buf >> bits) & 0xFF);
    }
  }
  return out;
}

/// Values of a <DataArray>, ASCII or base64 (UInt64 header + data), as doubles.
std::vector<double> values(const Node& da) {
  const std::string type = da.attr.at("type");
  std::vector<double> out;
  if (da.attr.at("format") == "ascii") {
    std::istringstream in(da.text);
    double x;
    while (in >> x) out.push_back(x);
    return out;
  }
  REQUIRE(da.attr.at("format") == "binary");
  const std::string raw = base64_decode(da.text);
  std::uint64_t nbytes = 0;
  REQUIRE(raw.size() >= 8);
  std::memcpy(&nbytes, raw.data(), 8);
  REQUIRE(raw.size() == 8 + nbytes);
  const char* p = raw.data() + 8;
  auto take = [&](auto zero) {
    using T = decltype(zero);
    REQUIRE(nbytes % sizeof(T) == 0);
    for (std::size_t k = 0; k < nbytes / sizeof(T); ++k) {
      T v;
      std::memcpy(&v, p + k * sizeof(T), sizeof(T));
      out.push_back(static_cast<double>(v));
    }
  };
  if (type == "Float64")
    take(double{});
  else if (type == "Int64")
    take(std::int64_t{});
  else if (type == "UInt8")
    take(std::uint8_t{});
  else
    FAIL("unexpected type " << type);
  return out;
}

const Node& array_named(const Node& section, const std::string& name) {
  for (const Node* da : section.all("DataArray"))
    if (da->attr.count("Name") && da->attr.at("Name") == name) return *da;
  throw std::runtime_error("no DataArray " + name);
}
}  // namespace

TEST_CASE("base64 encoding (RFC 4648 test vectors)", "[unit][io][vtk]") {
  CHECK(base64_encode("", 0).empty());
  CHECK(base64_encode("f", 1) == "Zg==");
  CHECK(base64_encode("fo", 2) == "Zm8=");
  CHECK(base64_encode("foo", 3) == "Zm9v");
  CHECK(base64_encode("foobar", 6) == "Zm9vYmFy");
}

TEST_CASE("VTU surface grid: structure, counts and values parse back", "[unit][io][vtk]") {
  const int nu = 4, nv = 3;
  RowMatrixXd P(nu * nv, 3);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) P.row(i + nu * j) << 1.5 * i, 2.0 * j, 0.1 * i * j;
  QuadMesh mesh = structured_quad_mesh(nu, nv, P);
  std::vector<double> s(nu * nv);
  for (int a = 0; a < nu * nv; ++a) s[a] = a * 0.25;
  mesh.point_data.push_back(scalar_field("alpha", s));
  RowMatrixXd u = RowMatrixXd::Random(nu * nv, 3);
  mesh.point_data.push_back(vector_field("displacement", u));
  RowMatrixXd S2 = RowMatrixXd::Random(nu * nv, 4);
  mesh.point_data.push_back(tensor_field("n", S2));
  mesh.point_data.push_back(
      components_field("E_voigt", RowMatrixXd::Ones(nu * nv, 3), {"E11", "E22", "2E12"}));
  mesh.cell_data.push_back(scalar_field("element", std::vector<double>((nu - 1) * (nv - 1), 7.0)));

  for (auto enc : {VtkEncoding::Ascii, VtkEncoding::Base64}) {
    const fs::path file = scratch(enc == VtkEncoding::Ascii ? "grid_ascii.vtu" : "grid_b64.vtu");
    write_vtu(file, mesh, enc, "provenance: {\"x\": \"a--b---c\"}");
    auto root = parse_file(file);  // refuses "--" inside a comment
    {
      // The provenance JSON reads back exactly (session 39: "--output" was written "- -output").
      std::ifstream in(file);
      const std::string text((std::istreambuf_iterator<char>(in)), {});
      const auto a = text.find("<!-- provenance: "), b = text.find(" -->");
      REQUIRE(a != std::string::npos);
      REQUIRE(b != std::string::npos);
      const std::string json_text = text.substr(a + 17, b - a - 17);
      CHECK(nlohmann::json::parse(json_text).at("x") == "a--b---c");
    }
    CHECK(root->tag == "VTKFile");
    CHECK(root->attr.at("type") == "UnstructuredGrid");
    CHECK(root->attr.at("byte_order") == "LittleEndian");
    const Node& piece = root->child("UnstructuredGrid").child("Piece");
    CHECK(piece.attr.at("NumberOfPoints") == "12");
    CHECK(piece.attr.at("NumberOfCells") == "6");

    const auto pts = values(piece.child("Points").child("DataArray"));
    REQUIRE(pts.size() == 36);
    CHECK(pts[3 * 5 + 0] == 1.5);  // point (i=1, j=1)
    CHECK(pts[3 * 5 + 1] == 2.0);
    CHECK(pts[3 * 5 + 2] == Approx(0.1));

    const Node& cells = piece.child("Cells");
    const auto conn = values(array_named(cells, "connectivity"));
    const auto off = values(array_named(cells, "offsets"));
    const auto types = values(array_named(cells, "types"));
    REQUIRE(conn.size() == 24);
    CHECK(off == std::vector<double>{4, 8, 12, 16, 20, 24});
    CHECK(types == std::vector<double>(6, 9.0));
    // First quad counter-clockwise in (u, v): (0,0) (1,0) (1,1) (0,1).
    CHECK(std::vector<double>(conn.begin(), conn.begin() + 4) == std::vector<double>{0, 1, 5, 4});
    // Last quad.
    CHECK(std::vector<double>(conn.end() - 4, conn.end()) == std::vector<double>{6, 7, 11, 10});

    const Node& pd = piece.child("PointData");
    CHECK(pd.attr.at("Scalars") == "alpha");
    CHECK(pd.attr.at("Vectors") == "displacement");
    CHECK(pd.attr.at("Tensors") == "n");
    CHECK(values(array_named(pd, "alpha")) == s);
    const auto disp = values(array_named(pd, "displacement"));
    REQUIRE(disp.size() == 36);
    CHECK(disp[3 * 7 + 2] == Approx(u(7, 2)).epsilon(1e-15));
    const auto n = values(array_named(pd, "n"));
    REQUIRE(n.size() == 9 * 12);
    CHECK(n[9 * 2 + 3] == Approx(S2(2, 2)).epsilon(1e-15));  // (1,0) entry of the 2x2
    CHECK(n[9 * 2 + 8] == 0.0);
    const Node& ev = array_named(pd, "E_voigt");
    CHECK(ev.attr.at("NumberOfComponents") == "3");
    CHECK(ev.attr.at("ComponentName2") == "2E12");
    CHECK(values(ev).size() == 36);
    CHECK(values(array_named(piece.child("CellData"), "element")).size() == 6);
  }
}

TEST_CASE("VTP polylines with a radius array for the Tube filter", "[unit][io][vtk]") {
  PolylineSet yarns;
  yarns.points = RowMatrixXd::Random(7, 3);
  yarns.lines = {{0, 1, 2, 3}, {4, 5, 6}};
  yarns.point_data.push_back(scalar_field("radius", {0.19, 0.19, 0.18, 0.17, 0.19, 0.2, 0.21}));
  yarns.point_data.push_back(scalar_field("contact_gap", std::vector<double>(7, 0.0)));
  yarns.cell_data.push_back(scalar_field("yarn", {0, 1}));
  const fs::path file = scratch("yarns.vtp");
  write_vtp(file, yarns);
  auto root = parse_file(file);
  CHECK(root->attr.at("type") == "PolyData");
  const Node& piece = root->child("PolyData").child("Piece");
  CHECK(piece.attr.at("NumberOfPoints") == "7");
  CHECK(piece.attr.at("NumberOfLines") == "2");
  const Node& pd = piece.child("PointData");
  CHECK(pd.attr.at("Scalars") == "radius");
  CHECK(values(array_named(pd, "radius"))[6] == 0.21);
  const Node& lines = piece.child("Lines");
  CHECK(values(array_named(lines, "connectivity")) == std::vector<double>{0, 1, 2, 3, 4, 5, 6});
  CHECK(values(array_named(lines, "offsets")) == std::vector<double>{4, 7});
  const auto pts = values(piece.child("Points").child("DataArray"));
  REQUIRE(pts.size() == 21);
  CHECK(pts[3 * 6 + 1] == yarns.points(6, 1));
}

TEST_CASE("VTK writers reject inconsistent sizes, naming the file and array", "[unit][io][vtk]") {
  QuadMesh mesh = structured_quad_mesh(2, 2, RowMatrixXd::Zero(4, 2));
  mesh.point_data.push_back(scalar_field("alpha", {1, 2, 3}));
  const fs::path file = scratch("bad.vtu");
  CHECK_THROWS_WITH(write_vtu(file, mesh),
                    Catch::Contains("bad.vtu: point field alpha: 3 values, expected 4 x 1"));
  CHECK_FALSE(fs::exists(file));
  PolylineSet l;
  l.points = RowMatrixXd::Zero(2, 3);
  l.lines = {{0, 2}};
  CHECK_THROWS_WITH(write_vtp(scratch("bad.vtp"), l),
                    Catch::Contains("line 0 refers to point 2 of 2"));
  CHECK_THROWS_AS(structured_quad_mesh(3, 3, RowMatrixXd::Zero(8, 3)), std::invalid_argument);
  CHECK_THROWS_AS(vector_field("v", RowMatrixXd::Zero(3, 4)), std::invalid_argument);
}

// Session 33 (mutation audit): an index check off by one (point n accepted of n points) passed,
// because the only bad-index test was of a polyline (write_vtp). A quad referring to point 4 of
// 4 points is refused before anything is written; point 3 is the last one accepted.
TEST_CASE("VTU quads referring to a point past the last are refused, no file written",
          "[unit][io][vtk]") {
  QuadMesh mesh{RowMatrixXd::Zero(4, 3), RowMatrixXi(1, 4), {}, {}};
  mesh.quads.row(0) << 0, 1, 2, 4;
  const fs::path file = scratch("past_last.vtu");
  CHECK_THROWS_AS(write_vtu(file, mesh), std::invalid_argument);
  CHECK_THROWS_WITH(write_vtu(file, mesh),
                    Catch::Contains("past_last.vtu: quad 0 refers to point 4 of 4"));
  CHECK_FALSE(fs::exists(file));
  mesh.quads.row(0) << 0, 1, 2, 3;
  const fs::path good = scratch("last.vtu");
  write_vtu(good, mesh);
  CHECK(
      values(array_named(parse_file(good)->child("UnstructuredGrid").child("Piece").child("Cells"),
                         "connectivity")) == std::vector<double>{0, 1, 2, 3});
}

// Session 33 (mutation audit): names reach the XML as attribute values -- field names in
// Name="..." and in PointData's Scalars="...", dataset file names in the .pvd's file="..." --
// and nothing tested one holding a markup character, so writing them unescaped (a file
// ParaView cannot read) passed. Pinned on the text itself: the reader above does not unescape.
TEST_CASE("VTK and PVD attribute values escape markup characters", "[unit][io][vtk]") {
  const std::string name = "a<b&\"c", escaped = "a&lt;b&amp;&quot;c";
  QuadMesh mesh = structured_quad_mesh(2, 2, RowMatrixXd::Zero(4, 3));
  mesh.point_data.push_back(scalar_field(name, {1, 2, 3, 4}));
  const fs::path file = scratch("markup.vtu");
  write_vtu(file, mesh, VtkEncoding::Ascii);
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  CHECK_THAT(text.str(), Catch::Contains("<PointData Scalars=\"" + escaped + "\">"));
  CHECK_THAT(text.str(), Catch::Contains("<DataArray type=\"Float64\" Name=\"" + escaped +
                                         "\" format=\"ascii\">"));
  CHECK(text.str().find("a<b") == std::string::npos);
  // Well-formed for an XML reader (one expression: a parse error is one failed check).
  CHECK(values(array_named(
            parse_file(file)->child("UnstructuredGrid").child("Piece").child("PointData"),
            escaped)) == std::vector<double>{1, 2, 3, 4});

  PvdCollection pvd(scratch("markup.pvd"));
  pvd.add(0.0, "R&D <1>.vtu");
  pvd.write();
  std::ifstream pin(scratch("markup.pvd"));
  std::stringstream ptext;
  ptext << pin.rdbuf();
  CHECK_THAT(ptext.str(), Catch::Contains("file=\"R&amp;D &lt;1&gt;.vtu\"/>"));
  CHECK(parse_file(scratch("markup.pvd"))->child("Collection").child("DataSet").attr.at("file") ==
        "R&amp;D &lt;1&gt;.vtu");
}

TEST_CASE("PVD collection lists time steps with relative file names", "[unit][io][vtk]") {
  const fs::path dir = scratch("series");
  fs::create_directories(dir / "steps");
  PvdCollection pvd(dir / "run.pvd");
  for (int k = 0; k < 3; ++k) {
    const fs::path f = dir / "steps" / ("step_" + std::to_string(k) + ".vtu");
    write_vtu(f, structured_quad_mesh(2, 2, RowMatrixXd::Zero(4, 3)));
    pvd.add(0.5 * k, f);
  }
  pvd.add(2.0, "bare.vtu", 1);
  pvd.write();
  auto root = parse_file(dir / "run.pvd");
  CHECK(root->attr.at("type") == "Collection");
  const auto sets = root->child("Collection").all("DataSet");
  REQUIRE(sets.size() == 4);
  CHECK(sets[1]->attr.at("timestep") == "0.5");
  CHECK(sets[1]->attr.at("file") == "steps/step_1.vtu");
  CHECK(fs::exists(dir / sets[2]->attr.at("file")));
  CHECK(sets[3]->attr.at("file") == "bare.vtu");
  CHECK(sets[3]->attr.at("part") == "1");
  // Accumulated load factors read as the user wrote them (session 39: a load factor 0.5 was
  // written 0.4999999999999999; here 0.7 - 0.2, which %.16g wrote so), and times closer than
  // 15 digits keep their order: exact there.
  PvdCollection noise(dir / "noise.pvd");
  const double t1 = 0.7 - 0.2, t2 = 0.7, t3 = std::nextafter(0.7, 1.0),
               t4 = std::nextafter(t3, 1.0);
  for (double t : {t1, t2, t3, t4}) noise.add(t, "bare.vtu");
  noise.write();
  const auto noise_root = parse_file(dir / "noise.pvd");  // owns the nodes
  const auto ns = noise_root->child("Collection").all("DataSet");
  REQUIRE(ns.size() == 4);
  CHECK(ns[0]->attr.at("timestep") == "0.5");
  CHECK(std::stod(ns[1]->attr.at("timestep")) == t2);  // exact: 15 digits join it with t3
  CHECK(std::stod(ns[2]->attr.at("timestep")) == t3);
  CHECK(std::stod(ns[3]->attr.at("timestep")) == t4);
  // Approached from below, the earlier time rounds up onto the later one: both exact (the
  // session's review: "0.7" then "0.69999999999999996", equal once read).
  PvdCollection below(dir / "below.pvd");
  const double b1 = std::nextafter(0.7, 0.0), b2 = 0.7;
  below.add(b1, "bare.vtu");
  below.add(b2, "bare.vtu");
  below.write();
  const auto below_root = parse_file(dir / "below.pvd");
  const auto bs = below_root->child("Collection").all("DataSet");
  REQUIRE(bs.size() == 2);
  CHECK(std::stod(bs[0]->attr.at("timestep")) == b1);
  CHECK(std::stod(bs[1]->attr.at("timestep")) == b2);
}
