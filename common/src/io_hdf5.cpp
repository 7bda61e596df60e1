// HDF5 adapter (see knit/io/hdf5.hpp). The only translation unit that includes <hdf5.h>.
#include "knit/io/hdf5.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <system_error>

namespace knit::io {

static_assert(std::is_same_v<hid_t, std::int64_t>,
              "hid_t is expected to be int64_t (HDF5 >= 1.10)");

namespace {

/// HDF5 prints its error stack to stderr by default; we report through exceptions instead.
void silence_hdf5() {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

std::vector<std::string> split_path(const std::string& p) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : p) {
    if (c == '/') {
      if (!cur.empty() && cur != ".") out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty() && cur != ".") out.push_back(cur);
  return out;
}

std::string join_path(const std::string& base, const std::string& rel) {
  if (!rel.empty() && rel[0] == '/') {
    std::string out;
    for (const auto& c : split_path(rel)) out += "/" + c;
    return out.empty() ? "/" : out;
  }
  std::string out = base == "/" ? "" : base;
  for (const auto& c : split_path(rel)) out += "/" + c;
  return out.empty() ? "/" : out;
}

/// Link-creation property list that creates missing intermediate groups.
H5Handle intermediate_lcpl() {
  H5Handle lcpl(H5Pcreate(H5P_LINK_CREATE));
  if (lcpl.valid()) H5Pset_create_intermediate_group(lcpl.get(), 1);
  return lcpl;
}

H5Handle utf8_vlen_string_type() {
  H5Handle t(H5Tcopy(H5T_C_S1));
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

std::vector<std::size_t> dims_of(hid_t space) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) return {};
  std::vector<hsize_t> d(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, d.data(), nullptr);
  return {d.begin(), d.end()};
}

std::size_t product(const std::vector<std::size_t>& d) {
  std::size_t n = 1;
  for (auto x : d) n *= x;
  return n;
}

const char* class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "floating-point";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    default:
      return "non-numeric";
  }
}

/// Reads a string-typed object (dataset or attribute) into strings, variable or fixed length.
template <class ReadFn>
std::vector<std::string> read_string_data(hid_t ftype, hid_t space, std::size_t n, ReadFn read,
                                          const std::function<void(const std::string&)>& fail) {
  std::vector<std::string> out;
  if (n == 0) return out;
  if (H5Tis_variable_str(ftype) > 0) {
    H5Handle mtype = utf8_vlen_string_type();
    std::vector<char*> buf(n, nullptr);
    if (read(mtype.get(), buf.data()) < 0) fail("cannot read string data");
    out.reserve(n);
    for (char* s : buf) out.emplace_back(s ? s : "");
    H5Dvlen_reclaim(mtype.get(), space, H5P_DEFAULT, buf.data());
  } else {
    const std::size_t len = H5Tget_size(ftype);
    H5Handle mtype(H5Tcopy(H5T_C_S1));
    H5Tset_size(mtype.get(), len);
    std::vector<char> buf(n * len, '\0');
    if (read(mtype.get(), buf.data()) < 0) fail("cannot read string data");
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const char* s = buf.data() + i * len;
      out.emplace_back(s, strnlen(s, len));
    }
  }
  return out;
}

}  // namespace

// ---- H5Handle -------------------------------------------------------------------------------

H5Handle& H5Handle::operator=(H5Handle&& o) noexcept {
  if (this != &o) {
    reset();
    id_ = o.id_;
    o.id_ = -1;
  }
  return *this;
}

void H5Handle::reset() noexcept {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
    case H5I_FILE:
      H5Fclose(id_);
      break;
    case H5I_GROUP:
      H5Gclose(id_);
      break;
    case H5I_DATASET:
      H5Dclose(id_);
      break;
    case H5I_DATASPACE:
      H5Sclose(id_);
      break;
    case H5I_DATATYPE:
      H5Tclose(id_);
      break;
    case H5I_ATTR:
      H5Aclose(id_);
      break;
    case H5I_GENPROP_LST:
      H5Pclose(id_);
      break;
    default:
      break;  // already invalid (e.g. closed with its file)
  }
  id_ = -1;
}

// ---- H5Group: helpers -----------------------------------------------------------------------

std::string H5Group::full(const std::string& rel) const {
  return join_path(path_, rel);
}

std::string H5Group::h5name(const std::string& rel) {
  if (!rel.empty() && rel[0] == '/') return join_path("/", rel);
  std::string out;
  for (const auto& c : split_path(rel)) out += (out.empty() ? "" : "/") + c;
  return out.empty() ? "." : out;
}

void H5Group::fail(const std::string& rel, const std::string& what) const {
  throw std::runtime_error(file_ + ": " + full(rel) + ": " + what);
}

// ---- structure ------------------------------------------------------------------------------

bool H5Group::exists(const std::string& path) const {
  silence_hdf5();
  const bool absolute = !path.empty() && path[0] == '/';
  std::string cur = absolute ? "/" : "";
  for (const auto& c : split_path(path)) {
    cur += (cur.empty() || cur == "/" ? "" : "/") + c;
    if (H5Lexists(id_.get(), cur.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

namespace {
H5O_type_t object_type(hid_t loc, const std::string& name) {
  H5O_info_t info;
  if (H5Oget_info_by_name(loc, name.c_str(), &info, H5P_DEFAULT) < 0) return H5O_TYPE_UNKNOWN;
  return info.type;
}
}  // namespace

bool H5Group::is_group(const std::string& path) const {
  return exists(path) && object_type(id_.get(), h5name(path)) == H5O_TYPE_GROUP;
}

bool H5Group::is_dataset(const std::string& path) const {
  return exists(path) && object_type(id_.get(), h5name(path)) == H5O_TYPE_DATASET;
}

H5Group H5Group::create_group(const std::string& path) {
  silence_hdf5();
  if (exists(path)) {
    if (!is_group(path)) fail(path, "exists and is not a group");
    return open_group(path);
  }
  H5Handle lcpl = intermediate_lcpl();
  H5Handle g(H5Gcreate2(id_.get(), h5name(path).c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!g.valid()) fail(path, "cannot create group (file opened read-only?)");
  return H5Group(std::move(g), file_, full(path));
}

H5Group H5Group::open_group(const std::string& path) const {
  silence_hdf5();
  if (!exists(path)) fail(path, "group missing");
  if (!is_group(path)) fail(path, "not a group");
  H5Handle g(H5Gopen2(id_.get(), h5name(path).c_str(), H5P_DEFAULT));
  if (!g.valid()) fail(path, "cannot open group");
  return H5Group(std::move(g), file_, full(path));
}

std::vector<std::string> H5Group::children(const std::string& path) const {
  H5Group g = open_group(path);
  std::vector<std::string> names;
  auto cb = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Literate(g.id_.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, cb, &names) < 0)
    fail(path, "cannot list group");
  std::sort(names.begin(), names.end());
  return names;
}

void H5Group::remove(const std::string& path) {
  silence_hdf5();
  if (!exists(path)) fail(path, "object missing");
  if (H5Ldelete(id_.get(), h5name(path).c_str(), H5P_DEFAULT) < 0) fail(path, "cannot remove");
}

// ---- datasets -------------------------------------------------------------------------------

namespace {
template <class T>
hid_t native_type() {
  if constexpr (std::is_same_v<T, double>)
    return H5T_NATIVE_DOUBLE;
  else
    return H5T_NATIVE_INT;
}
}  // namespace

template <class T>
static void write_numeric(H5Group& self, hid_t loc, const std::string& name,
                          std::span<const T> data, const std::vector<std::size_t>& shape,
                          const H5WriteOptions& opts,
                          const std::function<void(const std::string&)>& fail) {
  (void)self;
  if (product(shape) != data.size()) fail("shape does not match the data size");
  const std::vector<hsize_t> dims(shape.begin(), shape.end());
  H5Handle space(shape.empty()
                     ? H5Screate(H5S_SCALAR)
                     : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
  if (!space.valid()) fail("cannot create dataspace");
  H5Handle dcpl(H5Pcreate(H5P_DATASET_CREATE));
  if (opts.gzip_level > 0 && !data.empty() && !shape.empty() &&
      H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
    // One chunk per dataset, capped to ~1M elements along the first axis.
    std::vector<hsize_t> chunk = dims;
    std::size_t rest = 1;
    for (std::size_t i = 1; i < chunk.size(); ++i) rest *= chunk[i];
    chunk[0] = std::max<hsize_t>(
        1, std::min<hsize_t>(chunk[0], (1u << 20) / std::max<std::size_t>(rest, 1)));
    H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data());
    H5Pset_deflate(dcpl.get(), static_cast<unsigned>(std::min(opts.gzip_level, 9)));
  }
  if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0) H5Ldelete(loc, name.c_str(), H5P_DEFAULT);
  H5Handle lcpl = intermediate_lcpl();
  H5Handle ds(H5Dcreate2(loc, name.c_str(), native_type<T>(), space.get(), lcpl.get(), dcpl.get(),
                         H5P_DEFAULT));
  if (!ds.valid()) fail("cannot create dataset (file opened read-only?)");
  if (data.empty()) return;
  if (H5Dwrite(ds.get(), native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    fail("cannot write dataset");
}

void H5Group::write_dataset(const std::string& path, std::span<const double> data,
                            const std::vector<std::size_t>& shape, const H5WriteOptions& opts) {
  silence_hdf5();
  write_numeric<double>(*this, id_.get(), h5name(path), data, shape, opts,
                        [&](const std::string& w) { fail(path, w); });
}

void H5Group::write_dataset(const std::string& path, std::span<const int> data,
                            const std::vector<std::size_t>& shape, const H5WriteOptions& opts) {
  silence_hdf5();
  write_numeric<int>(*this, id_.get(), h5name(path), data, shape, opts,
                     [&](const std::string& w) { fail(path, w); });
}

void H5Group::write_strings(const std::string& path, const std::vector<std::string>& v) {
  silence_hdf5();
  const std::string name = h5name(path);
  const hsize_t n = v.size();
  H5Handle space(H5Screate_simple(1, &n, nullptr));
  H5Handle type = utf8_vlen_string_type();
  if (H5Lexists(id_.get(), name.c_str(), H5P_DEFAULT) > 0)
    H5Ldelete(id_.get(), name.c_str(), H5P_DEFAULT);
  H5Handle lcpl = intermediate_lcpl();
  H5Handle ds(H5Dcreate2(id_.get(), name.c_str(), type.get(), space.get(), lcpl.get(), H5P_DEFAULT,
                         H5P_DEFAULT));
  if (!ds.valid()) fail(path, "cannot create dataset (file opened read-only?)");
  if (v.empty()) return;
  std::vector<const char*> ptrs;
  ptrs.reserve(v.size());
  for (const auto& s : v) ptrs.push_back(s.c_str());
  if (H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0)
    fail(path, "cannot write dataset");
}

namespace {
struct OpenDataset {
  H5Handle ds, space, type;
  std::vector<std::size_t> dims;
  H5T_class_t cls;
};
}  // namespace

static OpenDataset open_dataset(hid_t loc, const std::string& name,
                                const std::function<void(const std::string&)>& fail) {
  OpenDataset d;
  d.ds = H5Handle(H5Dopen2(loc, name.c_str(), H5P_DEFAULT));
  if (!d.ds.valid()) fail("cannot open dataset");
  d.space = H5Handle(H5Dget_space(d.ds.get()));
  d.type = H5Handle(H5Dget_type(d.ds.get()));
  d.dims = dims_of(d.space.get());
  d.cls = H5Tget_class(d.type.get());
  return d;
}

std::vector<std::size_t> H5Group::shape(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  auto d = open_dataset(id_.get(), h5name(path), [&](const std::string& w) { fail(path, w); });
  return d.dims;
}

template <class T>
static std::vector<T> read_numeric(hid_t loc, const std::string& name, std::size_t want_rank,
                                   std::vector<std::size_t>& dims_out,
                                   const std::function<void(const std::string&)>& fail) {
  auto d = open_dataset(loc, name, fail);
  if (d.cls != H5T_INTEGER && d.cls != H5T_FLOAT)
    fail(std::string("expected a numeric dataset, found ") + class_name(d.cls));
  if (std::is_same_v<T, int> && d.cls != H5T_INTEGER)
    fail(std::string("expected an integer dataset, found ") + class_name(d.cls));
  const std::size_t rank = d.dims.size();
  constexpr std::size_t kAnyRank = static_cast<std::size_t>(-1);
  if (want_rank != kAnyRank && !(rank == want_rank || (want_rank == 1 && rank == 0)))
    fail("expected a " + std::to_string(want_rank) + "-D dataset, found rank " +
         std::to_string(rank));
  dims_out = d.dims;
  std::vector<T> out(product(d.dims));
  if (!out.empty() &&
      H5Dread(d.ds.get(), native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail("cannot read dataset");
  return out;
}

std::vector<double> H5Group::read_doubles(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  std::vector<std::size_t> dims;
  return read_numeric<double>(id_.get(), h5name(path), 1, dims,
                              [&](const std::string& w) { fail(path, w); });
}

std::vector<int> H5Group::read_ints(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  std::vector<std::size_t> dims;
  return read_numeric<int>(id_.get(), h5name(path), 1, dims,
                           [&](const std::string& w) { fail(path, w); });
}

H5Array H5Group::read_array(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  H5Array a;
  a.data = read_numeric<double>(id_.get(), h5name(path), static_cast<std::size_t>(-1), a.shape,
                                [&](const std::string& w) { fail(path, w); });
  return a;
}

RowMatrixXd H5Group::read_matrix(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  std::vector<std::size_t> dims;
  auto v = read_numeric<double>(id_.get(), h5name(path), 2, dims,
                                [&](const std::string& w) { fail(path, w); });
  RowMatrixXd m(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
  std::copy(v.begin(), v.end(), m.data());
  return m;
}

RowMatrixXi H5Group::read_int_matrix(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  std::vector<std::size_t> dims;
  auto v = read_numeric<int>(id_.get(), h5name(path), 2, dims,
                             [&](const std::string& w) { fail(path, w); });
  RowMatrixXi m(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
  std::copy(v.begin(), v.end(), m.data());
  return m;
}

std::vector<std::string> H5Group::read_strings(const std::string& path) const {
  silence_hdf5();
  if (!is_dataset(path)) fail(path, "dataset missing");
  auto f = [&](const std::string& w) { fail(path, w); };
  auto d = open_dataset(id_.get(), h5name(path), f);
  if (d.cls != H5T_STRING)
    fail(path, std::string("expected a string dataset, found ") + class_name(d.cls));
  if (d.dims.size() > 1) fail(path, "expected a 1-D string dataset");
  hid_t ds = d.ds.get();
  return read_string_data(
      d.type.get(), d.space.get(), product(d.dims),
      [ds](hid_t mtype, void* buf) {
        return H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
      },
      f);
}

// ---- attributes -----------------------------------------------------------------------------

namespace {
/// Deletes an existing attribute so that it can be re-created with a new type/shape.
void drop_attribute(hid_t loc, const std::string& obj, const std::string& name) {
  if (H5Aexists_by_name(loc, obj.c_str(), name.c_str(), H5P_DEFAULT) > 0)
    H5Adelete_by_name(loc, obj.c_str(), name.c_str(), H5P_DEFAULT);
}
}  // namespace

void H5Group::set_attribute(const std::string& obj_path, const std::string& name,
                            const std::string& value) {
  silence_hdf5();
  if (!exists(obj_path)) fail(obj_path, "object missing (attribute " + name + ")");
  const std::string obj = h5name(obj_path);
  drop_attribute(id_.get(), obj, name);
  H5Handle type = utf8_vlen_string_type();
  H5Handle space(H5Screate(H5S_SCALAR));
  H5Handle a(H5Acreate_by_name(id_.get(), obj.c_str(), name.c_str(), type.get(), space.get(),
                               H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid()) fail(obj_path, "cannot create attribute " + name);
  const char* p = value.c_str();
  if (H5Awrite(a.get(), type.get(), &p) < 0) fail(obj_path, "cannot write attribute " + name);
}

template <class T>
static void set_numeric_attribute(hid_t loc, const std::string& obj, const std::string& name,
                                  const T* data, std::size_t n, bool scalar,
                                  const std::function<void(const std::string&)>& fail) {
  drop_attribute(loc, obj, name);
  const hsize_t dim = n;
  H5Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &dim, nullptr));
  H5Handle a(H5Acreate_by_name(loc, obj.c_str(), name.c_str(), native_type<T>(), space.get(),
                               H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid()) fail("cannot create attribute " + name);
  if (n > 0 && H5Awrite(a.get(), native_type<T>(), data) < 0)
    fail("cannot write attribute " + name);
}

void H5Group::set_attribute(const std::string& obj_path, const std::string& name, double value) {
  silence_hdf5();
  if (!exists(obj_path)) fail(obj_path, "object missing (attribute " + name + ")");
  set_numeric_attribute<double>(id_.get(), h5name(obj_path), name, &value, 1, true,
                                [&](const std::string& w) { fail(obj_path, w); });
}

void H5Group::set_attribute(const std::string& obj_path, const std::string& name, int value) {
  silence_hdf5();
  if (!exists(obj_path)) fail(obj_path, "object missing (attribute " + name + ")");
  set_numeric_attribute<int>(id_.get(), h5name(obj_path), name, &value, 1, true,
                             [&](const std::string& w) { fail(obj_path, w); });
}

void H5Group::set_attribute(const std::string& obj_path, const std::string& name,
                            const std::vector<double>& value) {
  silence_hdf5();
  if (!exists(obj_path)) fail(obj_path, "object missing (attribute " + name + ")");
  set_numeric_attribute<double>(id_.get(), h5name(obj_path), name, value.data(), value.size(),
                                false, [&](const std::string& w) { fail(obj_path, w); });
}

bool H5Group::has_attribute(const std::string& obj_path, const std::string& name) const {
  silence_hdf5();
  if (!exists(obj_path)) return false;
  return H5Aexists_by_name(id_.get(), h5name(obj_path).c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::vector<std::string> H5Group::attribute_names(const std::string& obj_path) const {
  silence_hdf5();
  if (!exists(obj_path)) fail(obj_path, "object missing");
  std::vector<std::string> names;
  auto cb = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Aiterate_by_name(id_.get(), h5name(obj_path).c_str(), H5_INDEX_NAME, H5_ITER_INC, &idx, cb,
                         &names, H5P_DEFAULT) < 0)
    fail(obj_path, "cannot list attributes");
  std::sort(names.begin(), names.end());
  return names;
}

namespace {
struct OpenAttribute {
  H5Handle a, space, type;
  std::vector<std::size_t> dims;
  H5T_class_t cls;
};
}  // namespace

static OpenAttribute open_attribute(const H5Group& g, hid_t loc, const std::string& obj_path,
                                    const std::string& obj, const std::string& name,
                                    const std::function<void(const std::string&)>& fail) {
  if (!g.has_attribute(obj_path, name)) fail("attribute " + name + " missing");
  OpenAttribute o;
  o.a = H5Handle(H5Aopen_by_name(loc, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT));
  if (!o.a.valid()) fail("cannot open attribute " + name);
  o.space = H5Handle(H5Aget_space(o.a.get()));
  o.type = H5Handle(H5Aget_type(o.a.get()));
  o.dims = dims_of(o.space.get());
  o.cls = H5Tget_class(o.type.get());
  return o;
}

std::string H5Group::attribute_string(const std::string& obj_path, const std::string& name) const {
  silence_hdf5();
  auto f = [&](const std::string& w) { fail(obj_path, w); };
  auto o = open_attribute(*this, id_.get(), obj_path, h5name(obj_path), name, f);
  if (o.cls != H5T_STRING)
    f("attribute " + name + ": expected a string, found " + class_name(o.cls));
  const std::size_t n = product(o.dims);
  if (n != 1) f("attribute " + name + ": expected one string, found " + std::to_string(n));
  hid_t a = o.a.get();
  auto v = read_string_data(
      o.type.get(), o.space.get(), 1,
      [a](hid_t mtype, void* buf) { return H5Aread(a, mtype, buf); }, f);
  return v.front();
}

std::vector<double> H5Group::attribute_doubles(const std::string& obj_path,
                                               const std::string& name) const {
  silence_hdf5();
  auto f = [&](const std::string& w) { fail(obj_path, w); };
  auto o = open_attribute(*this, id_.get(), obj_path, h5name(obj_path), name, f);
  if (o.cls != H5T_INTEGER && o.cls != H5T_FLOAT)
    f("attribute " + name + ": expected a number, found " + class_name(o.cls));
  std::vector<double> v(product(o.dims));
  if (!v.empty() && H5Aread(o.a.get(), H5T_NATIVE_DOUBLE, v.data()) < 0)
    f("cannot read attribute " + name);
  return v;
}

double H5Group::attribute_double(const std::string& obj_path, const std::string& name) const {
  auto v = attribute_doubles(obj_path, name);
  if (v.size() != 1)
    fail(obj_path,
         "attribute " + name + ": expected one number, found " + std::to_string(v.size()));
  return v.front();
}

int H5Group::attribute_int(const std::string& obj_path, const std::string& name) const {
  silence_hdf5();
  auto f = [&](const std::string& w) { fail(obj_path, w); };
  auto o = open_attribute(*this, id_.get(), obj_path, h5name(obj_path), name, f);
  if (o.cls != H5T_INTEGER)
    f("attribute " + name + ": expected an integer, found " + class_name(o.cls));
  if (product(o.dims) != 1) f("attribute " + name + ": expected one integer");
  int v = 0;
  if (H5Aread(o.a.get(), H5T_NATIVE_INT, &v) < 0) f("cannot read attribute " + name);
  return v;
}

// ---- H5File ---------------------------------------------------------------------------------

bool is_hdf5_file(const std::filesystem::path& file) {
  silence_hdf5();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return false;
  return H5Fis_hdf5(file.c_str()) > 0;
}

H5File::H5File(const std::filesystem::path& file, Mode mode)
    : H5Group(H5Handle(), file.string(), "/") {
  silence_hdf5();
  const std::string name = file.string();
  // File access: keep HDF5's file locking, but do not fail on file systems without locks (NFS).
  H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS));
  H5Pset_file_locking(fapl.get(), 1, 1);
  if (mode == Mode::Truncate) {
    file_id_ = H5Handle(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()));
    if (!file_id_.valid())
      throw std::runtime_error(name +
                               ": cannot create HDF5 file (directory missing or not writable?)");
  } else {
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) throw std::runtime_error(name + ": file not found");
    if (!is_hdf5_file(file)) throw std::runtime_error(name + ": not an HDF5 file (or truncated)");
    const unsigned flags = mode == Mode::ReadOnly ? H5F_ACC_RDONLY : H5F_ACC_RDWR;
    file_id_ = H5Handle(H5Fopen(name.c_str(), flags, fapl.get()));
    if (!file_id_.valid())
      throw std::runtime_error(name + ": cannot open HDF5 file (truncated, corrupt or locked?)");
  }
  id_ = H5Handle(H5Gopen2(file_id_.get(), "/", H5P_DEFAULT));
  if (!id_.valid()) throw std::runtime_error(name + ": cannot open the root group (corrupt file?)");
}

void H5File::flush() {
  if (file_id_.valid() && H5Fflush(file_id_.get(), H5F_SCOPE_GLOBAL) < 0)
    throw std::runtime_error(file_ + ": cannot flush HDF5 file");
}

void H5File::close() {
  if (!file_id_.valid()) return;
  flush();
  id_.reset();
  file_id_.reset();
}

// ---- AtomicH5File -------------------------------------------------------------------------

AtomicH5File::AtomicH5File(const std::filesystem::path& target)
    : atomic_(target), file_(H5File::create(atomic_.temp_path())) {}

void AtomicH5File::commit() {
  file_.close();
  atomic_.commit();
}

}  // namespace knit::io
