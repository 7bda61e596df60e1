// VTK XML writers (see knit/io/vtk.hpp).
#include "knit/io/vtk.hpp"

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "knit/io/atomic.hpp"

namespace fs = std::filesystem;

namespace knit::io {

static_assert(std::endian::native == std::endian::little,
              "the VTK writer declares byte_order=\"LittleEndian\"");

// ---- fields ---------------------------------------------------------------------------------

VtkField scalar_field(std::string name, std::vector<double> values) {
  return {std::move(name), 1, std::move(values), {}};
}

VtkField vector_field(std::string name, const Eigen::Ref<const RowMatrixXd>& v) {
  if (v.cols() != 2 && v.cols() != 3)
    throw std::invalid_argument("vector field " + name + ": needs 2 or 3 columns, got " +
                                std::to_string(v.cols()));
  VtkField f{
      std::move(name), 3, std::vector<double>(static_cast<std::size_t>(v.rows()) * 3, 0.0), {}};
  for (Eigen::Index k = 0; k < v.rows(); ++k)
    for (Eigen::Index c = 0; c < v.cols(); ++c)
      f.values[static_cast<std::size_t>(3 * k + c)] = v(k, c);
  return f;
}

VtkField tensor_field(std::string name, const Eigen::Ref<const RowMatrixXd>& t) {
  if (t.cols() != 4 && t.cols() != 9)
    throw std::invalid_argument("tensor field " + name +
                                ": needs 4 (2x2) or 9 (3x3) columns, got " +
                                std::to_string(t.cols()));
  VtkField f{
      std::move(name), 9, std::vector<double>(static_cast<std::size_t>(t.rows()) * 9, 0.0), {}};
  for (Eigen::Index k = 0; k < t.rows(); ++k) {
    double* out = f.values.data() + 9 * k;
    if (t.cols() == 9) {
      for (int c = 0; c < 9; ++c) out[c] = t(k, c);
    } else {  // 2x2 row-major -> upper-left block of 3x3
      out[0] = t(k, 0);
      out[1] = t(k, 1);
      out[3] = t(k, 2);
      out[4] = t(k, 3);
    }
  }
  return f;
}

VtkField components_field(std::string name, const Eigen::Ref<const RowMatrixXd>& v,
                          std::vector<std::string> component_names) {
  if (!component_names.empty() && component_names.size() != static_cast<std::size_t>(v.cols()))
    throw std::invalid_argument("field " + name + ": " + std::to_string(component_names.size()) +
                                " component names for " + std::to_string(v.cols()) + " columns");
  VtkField f{std::move(name), static_cast<int>(v.cols()), {}, std::move(component_names)};
  f.values.resize(static_cast<std::size_t>(v.size()));
  for (Eigen::Index k = 0; k < v.rows(); ++k)
    for (Eigen::Index c = 0; c < v.cols(); ++c)
      f.values[static_cast<std::size_t>(k * v.cols() + c)] = v(k, c);
  return f;
}

RowMatrixXi structured_quads(int nu, int nv) {
  if (nu < 2 || nv < 2) throw std::invalid_argument("structured_quads: needs nu, nv >= 2");
  RowMatrixXi q((nu - 1) * (nv - 1), 4);
  int e = 0;
  for (int j = 0; j + 1 < nv; ++j)
    for (int i = 0; i + 1 < nu; ++i, ++e) {
      const int a = i + nu * j;
      q.row(e) << a, a + 1, a + 1 + nu, a + nu;
    }
  return q;
}

QuadMesh structured_quad_mesh(int nu, int nv, const RowMatrixXd& points) {
  if (points.rows() != static_cast<Eigen::Index>(nu) * nv)
    throw std::invalid_argument("structured_quad_mesh: " + std::to_string(points.rows()) +
                                " points for a " + std::to_string(nu) + " x " + std::to_string(nv) +
                                " grid");
  return QuadMesh{points, structured_quads(nu, nv), {}, {}};
}

// ---- encoding -------------------------------------------------------------------------------

std::string base64_encode(const void* data, std::size_t bytes) {
  static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes; i += 3) {
    const unsigned v = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += tbl[v & 63];
  }
  if (i < bytes) {
    const unsigned v = (p[i] << 16) | (i + 1 < bytes ? p[i + 1] << 8 : 0);
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += i + 1 < bytes ? tbl[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

namespace {

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

template <class T>
const char* vtk_type_name() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

/// Writes one <DataArray> element.
class XmlOut {
 public:
  explicit XmlOut(VtkEncoding enc) : enc_(enc) {}
  std::string s;

  template <class T>
  void array(const std::string& indent, const std::string& name, int components,
             const std::vector<T>& v, const std::vector<std::string>& component_names = {}) {
    s += indent + "<DataArray type=\"" + vtk_type_name<T>() + "\"";
    if (!name.empty()) s += " Name=\"" + xml_escape(name) + "\"";
    if (components != 1) s += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    for (std::size_t c = 0; c < component_names.size(); ++c)
      s += " ComponentName" + std::to_string(c) + "=\"" + xml_escape(component_names[c]) + "\"";
    s += enc_ == VtkEncoding::Ascii ? " format=\"ascii\">\n" : " format=\"binary\">\n";
    s += indent + "  ";
    if (enc_ == VtkEncoding::Ascii) {
      char buf[40];
      for (std::size_t i = 0; i < v.size(); ++i) {
        if constexpr (std::is_same_v<T, double>)
          std::snprintf(buf, sizeof buf, "%.16g", v[i]);
        else
          std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v[i]));
        s += buf;
        s += (i + 1) % 12 == 0 && i + 1 < v.size() ? "\n" + indent + "  " : " ";
      }
    } else {
      // Uncompressed inline binary: base64 of (UInt64 byte count, data), encoded together.
      const std::uint64_t nbytes = v.size() * sizeof(T);
      std::string raw(sizeof nbytes + nbytes, '\0');
      std::memcpy(raw.data(), &nbytes, sizeof nbytes);
      if (nbytes) std::memcpy(raw.data() + sizeof nbytes, v.data(), nbytes);
      s += base64_encode(raw.data(), raw.size());
    }
    s += "\n" + indent + "</DataArray>\n";
  }

 private:
  VtkEncoding enc_;
};

std::vector<double> points3(const RowMatrixXd& p, const fs::path& file) {
  if (p.cols() != 2 && p.cols() != 3)
    throw std::invalid_argument(file.string() + ": points need 2 or 3 columns, got " +
                                std::to_string(p.cols()));
  std::vector<double> out(static_cast<std::size_t>(p.rows()) * 3, 0.0);
  for (Eigen::Index k = 0; k < p.rows(); ++k)
    for (Eigen::Index c = 0; c < p.cols(); ++c) out[static_cast<std::size_t>(3 * k + c)] = p(k, c);
  return out;
}

void check_fields(const std::vector<VtkField>& fields, std::size_t n, const char* where,
                  const fs::path& file) {
  for (const auto& f : fields) {
    if (f.components < 1)
      throw std::invalid_argument(file.string() + ": " + where + " " + f.name + ": no components");
    if (f.values.size() != n * static_cast<std::size_t>(f.components))
      throw std::invalid_argument(file.string() + ": " + where + " " + f.name + ": " +
                                  std::to_string(f.values.size()) + " values, expected " +
                                  std::to_string(n) + " x " + std::to_string(f.components));
  }
}

/// <PointData>/<CellData> with the first 1/3/9-component arrays as active Scalars/Vectors/Tensors.
void data_section(XmlOut& x, const char* tag, const std::vector<VtkField>& fields) {
  if (fields.empty()) return;
  std::string head = std::string("      <") + tag;
  for (auto [comps, attr] :
       {std::pair{1, "Scalars"}, std::pair{3, "Vectors"}, std::pair{9, "Tensors"}})
    for (const auto& f : fields)
      if (f.components == comps) {
        head += std::string(" ") + attr + "=\"" + xml_escape(f.name) + "\"";
        break;
      }
  x.s += head + ">\n";
  for (const auto& f : fields)
    x.array("        ", f.name, f.components, f.values, f.component_names);
  x.s += std::string("      </") + tag + ">\n";
}

std::string header(const char* type, const std::string& comment) {
  std::string s = "<?xml version=\"1.0\"?>\n";
  if (!comment.empty()) {
    // "--" is not allowed inside an XML comment. It is written "-\u002d", which a JSON
    // comment (the provenance, where "--" only occurs inside strings: "--output") reads back
    // as "--"; session 39's walkthrough found "- -output", which no JSON reader restores.
    std::string c = comment;
    for (std::size_t p = c.find("--"); p != std::string::npos; p = c.find("--", p))
      c.replace(p, 2, "-\\u002d");
    s += "<!-- " + c + " -->\n";
  }
  s += std::string("<VTKFile type=\"") + type +
       "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
  return s;
}

}  // namespace

// ---- writers --------------------------------------------------------------------------------

void write_vtu(const fs::path& file, const QuadMesh& mesh, VtkEncoding encoding,
               const std::string& comment) {
  const auto n = static_cast<std::size_t>(mesh.points.rows());
  const auto m = static_cast<std::size_t>(mesh.quads.rows());
  if (mesh.quads.cols() != 4 && m > 0)
    throw std::invalid_argument(file.string() + ": quads need 4 columns");
  std::vector<std::int64_t> conn(m * 4), offsets(m);
  for (std::size_t e = 0; e < m; ++e) {
    for (int a = 0; a < 4; ++a) {
      const int idx = mesh.quads(static_cast<Eigen::Index>(e), a);
      if (idx < 0 || static_cast<std::size_t>(idx) >= n)
        throw std::invalid_argument(file.string() + ": quad " + std::to_string(e) +
                                    " refers to point " + std::to_string(idx) + " of " +
                                    std::to_string(n));
      conn[4 * e + a] = idx;
    }
    offsets[e] = static_cast<std::int64_t>(4 * (e + 1));
  }
  check_fields(mesh.point_data, n, "point field", file);
  check_fields(mesh.cell_data, m, "cell field", file);
  const std::vector<std::uint8_t> types(m, 9);  // VTK_QUAD

  XmlOut x(encoding);
  x.s = header("UnstructuredGrid", comment);
  x.s += "  <UnstructuredGrid>\n";
  x.s += "    <Piece NumberOfPoints=\"" + std::to_string(n) + "\" NumberOfCells=\"" +
         std::to_string(m) + "\">\n";
  data_section(x, "PointData", mesh.point_data);
  data_section(x, "CellData", mesh.cell_data);
  x.s += "      <Points>\n";
  x.array("        ", "Points", 3, points3(mesh.points, file));
  x.s += "      </Points>\n      <Cells>\n";
  x.array("        ", "connectivity", 1, conn);
  x.array("        ", "offsets", 1, offsets);
  x.array("        ", "types", 1, types);
  x.s += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(file, x.s);
}

void write_vtp(const fs::path& file, const PolylineSet& lines, VtkEncoding encoding,
               const std::string& comment) {
  const auto n = static_cast<std::size_t>(lines.points.rows());
  const std::size_t m = lines.lines.size();
  std::vector<std::int64_t> conn, offsets;
  offsets.reserve(m);
  for (std::size_t l = 0; l < m; ++l) {
    for (int idx : lines.lines[l]) {
      if (idx < 0 || static_cast<std::size_t>(idx) >= n)
        throw std::invalid_argument(file.string() + ": line " + std::to_string(l) +
                                    " refers to point " + std::to_string(idx) + " of " +
                                    std::to_string(n));
      conn.push_back(idx);
    }
    offsets.push_back(static_cast<std::int64_t>(conn.size()));
  }
  check_fields(lines.point_data, n, "point field", file);
  check_fields(lines.cell_data, m, "cell field", file);

  XmlOut x(encoding);
  x.s = header("PolyData", comment);
  x.s += "  <PolyData>\n";
  x.s += "    <Piece NumberOfPoints=\"" + std::to_string(n) +
         "\" NumberOfVerts=\"0\" NumberOfLines=\"" + std::to_string(m) +
         "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
  data_section(x, "PointData", lines.point_data);
  data_section(x, "CellData", lines.cell_data);
  x.s += "      <Points>\n";
  x.array("        ", "Points", 3, points3(lines.points, file));
  x.s += "      </Points>\n      <Lines>\n";
  x.array("        ", "connectivity", 1, conn);
  x.array("        ", "offsets", 1, offsets);
  x.s += "      </Lines>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  write_file_atomically(file, x.s);
}

// ---- PVD ------------------------------------------------------------------------------------

PvdCollection::PvdCollection(fs::path file) : file_(std::move(file)) {}

void PvdCollection::add(double time, const fs::path& dataset, int part) {
  std::string name = dataset.generic_string();
  if (dataset.is_absolute() || dataset.has_parent_path()) {
    const fs::path base = fs::absolute(file_).parent_path();
    const fs::path rel =
        fs::absolute(dataset).lexically_normal().lexically_relative(base.lexically_normal());
    if (!rel.empty()) name = rel.generic_string();
  }
  entries_.push_back({time, part, std::move(name)});
}

void PvdCollection::write() const {
  std::string s = "<?xml version=\"1.0\"?>\n";
  s +=
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
  char buf[40];
  // 15 significant digits, so that an accumulated load factor reads 0.5, not
  // 0.4999999999999999 (session 39's walkthrough); 17 (exact) for both times of a neighbouring
  // pair whose order the 15 digits would not keep (equal, or crossed). An exact time then lies
  // within half a 15-digit step of its rounded value, so it keeps its order with a rounded
  // neighbour too (the session's review: one pass fixed only the later time of such a pair).
  const auto sign = [](double x) { return (x > 0) - (x < 0); };
  const std::size_t n = entries_.size();
  std::vector<double> rounded(n);
  for (std::size_t k = 0; k < n; ++k) {
    std::snprintf(buf, sizeof buf, "%.15g", entries_[k].time);
    rounded[k] = std::strtod(buf, nullptr);
  }
  std::vector<bool> exact(n, false);
  for (std::size_t k = 1; k < n; ++k)
    if (sign(rounded[k] - rounded[k - 1]) != sign(entries_[k].time - entries_[k - 1].time))
      exact[k] = exact[k - 1] = true;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& e = entries_[k];
    std::snprintf(buf, sizeof buf, exact[k] ? "%.17g" : "%.15g", e.time);
    s += std::string("    <DataSet timestep=\"") + buf + "\" group=\"\" part=\"" +
         std::to_string(e.part) + "\" file=\"" + xml_escape(e.file) + "\"/>\n";
  }
  s += "  </Collection>\n</VTKFile>\n";
  write_file_atomically(file_, s);
}

}  // namespace knit::io
