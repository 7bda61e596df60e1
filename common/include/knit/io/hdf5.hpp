// Small RAII adapter over the HDF5 C API (1.10). This header and io_hdf5.cpp are the only
// places that know about HDF5 (design/style.md habit 6); <hdf5.h> is included nowhere else.
//
// What it offers:
//  * H5File: create (truncating), open read-only or read-write; it is the root group "/".
//  * H5Group: groups with nested paths ("/loop_4.50/raw"; missing intermediate groups are
//    created on write), existence tests, listing of children.
//  * Datasets of double and int: 1-D std::vector / Eigen vectors, 2-D Eigen matrices written
//    row-major so that h5py sees shape (rows, cols) and M[i, j] == m(i, j); optional gzip.
//  * Datasets of variable-length UTF-8 strings.
//  * Attributes (string, double, int, vector<double>) on files, groups and datasets.
//
// Failures throw std::runtime_error naming the file and the object path, e.g.
//   "db.h5: /loop_4.50/fit/S_surface: dataset missing".
// A file whose content is wrong throws knit::InputError(file, object path, message):
//   "db.h5: /loop_0/fit/S_ctrl: checksum mismatch (Fletcher32): the stored data is corrupt"
//   "db.h5: /loop_lengths: declares 134217728 x 2 elements (2.1 GB) but the file has only ..."
//
// Integrity, two layers. (1) The file's structure: when a file written here is closed, a
// trailer after HDF5's end of file stores an FNV-1a 64 digest of every byte that is not
// dataset raw data (superblock, object headers, B-trees, heaps, attributes, strings), with
// the raw-data extents it skipped; opening the file verifies it BEFORE HDF5 parses anything
// (HDF5 1.10 itself hung on a damaged global heap, found by the fuzz test). A mismatch is
// InputError(file, "", "the file's structure checksum does not match ..."). (2) The data:
// every non-empty numeric array is written chunked with HDF5's Fletcher32 filter
// (verified by every read); scalar and string datasets carry a digest attribute
// "knit_fnv1a64" (FNV-1a 64 of the values), verified on read. Files written before this
// (no filter, no digest) are read without verification and without a warning. A file of
// ours that another program opened for writing has lost its trailer (HDF5 cuts the file to
// its own end when it closes it) but keeps its data checksums: structure_sealed() and
// has_checksum() tell it from an old file, and the database reader refuses it (session 36).
// Attributes are covered by the structure checksum only.
// Reading: only regular files are opened (knit/io/input_file.hpp, at most kMaxHdf5InputBytes);
// every declared extent is checked against kMaxH5DatasetBytes and the file size before
// allocating.
// HDF5's automatic error-stack printing is switched off. Opening a file that is not HDF5 (or
// was truncated) throws "<file>: not an HDF5 file (or truncated)".
//
// Paths: absolute ("/a/b") from the file root, or relative to the group they are called on.
// "" and "." name the group itself. Writing a dataset or attribute that exists replaces it.
//
// Not thread-safe (the Debian HDF5 build is serial): use one thread for HDF5 I/O.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "knit/io/atomic.hpp"
#include "knit/io/matrix_types.hpp"

namespace knit::io {

/// Largest dataset or attribute read into memory (1 GiB; our databases hold kilobytes to a few
/// megabytes per dataset). A larger declared extent, or one larger than the file can hold,
/// is an InputError before anything is allocated.
inline constexpr std::uint64_t kMaxH5DatasetBytes = 1ull << 30;

/// A numeric dataset of any rank: values in row-major (C) order.
struct H5Array {
  std::vector<std::size_t> shape;  ///< empty for a scalar dataset
  std::vector<double> data;
};

/// Options for writing a dataset.
struct H5WriteOptions {
  /// gzip (deflate) level 1..9; 0 = no compression. Ignored for empty datasets and when the
  /// HDF5 library lacks the deflate filter.
  int gzip_level = 0;
  /// Fletcher32 (arrays) or a digest attribute (scalars, strings). Off only to produce files as
  /// written before checksums existed (tests of reading old files).
  bool checksum = true;
};

/// Owns one HDF5 identifier (hid_t) and closes it with the matching H5*close. Move-only.
class H5Handle {
 public:
  H5Handle() = default;
  explicit H5Handle(std::int64_t id) : id_(id) {}
  H5Handle(H5Handle&& o) noexcept : id_(o.id_) { o.id_ = -1; }
  H5Handle& operator=(H5Handle&& o) noexcept;
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() { reset(); }
  std::int64_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() noexcept;
  /// Gives up ownership without closing (after the id was closed by hand).
  std::int64_t release() noexcept {
    const std::int64_t id = id_;
    id_ = -1;
    return id;
  }

 private:
  std::int64_t id_ = -1;
};

struct H5GroupAccess;  // io_hdf5.cpp's helpers report errors through the group

/// A group (also the base of H5File, which is the root group). Move-only.
class H5Group {
 public:
  H5Group(H5Group&&) noexcept = default;
  H5Group& operator=(H5Group&&) noexcept = default;
  virtual ~H5Group() = default;

  /// The file name as given when opening (used in error messages).
  const std::string& file_name() const { return file_; }
  /// Absolute path of this group inside the file ("/" for the root).
  const std::string& path() const { return path_; }

  // ---- structure -------------------------------------------------------------------------
  /// Creates the group (and missing intermediate groups); opens it if it already exists.
  H5Group create_group(const std::string& path);
  /// Opens an existing group; throws "<file>: <path>: group missing" otherwise.
  H5Group open_group(const std::string& path) const;
  /// True if every component of the path exists (any object kind).
  bool exists(const std::string& path) const;
  /// Copies the object at `path` of `from` (a group with everything under it, or a dataset,
  /// with their attributes; H5Ocopy) to the same path here, creating missing parent groups.
  /// The path must not exist here. Throws naming this file and the path.
  void copy_from(const H5Group& from, const std::string& path);
  bool is_group(const std::string& path) const;
  bool is_dataset(const std::string& path) const;
  /// True if the dataset at path carries a checksum of ours: the Fletcher32 filter or the
  /// digest attribute "knit_fnv1a64" (every dataset written since the checksums exist).
  bool has_checksum(const std::string& path) const;
  /// True if any dataset at or below this group carries a checksum of ours (has_checksum).
  /// Every object is visited once (H5Ovisit), so a file whose hard links form a cycle ends too
  /// (session 43's review: a recursive walk of children() never did).
  bool any_checksum() const;
  /// Names of the direct children (groups and datasets) of the group at path, sorted by name.
  std::vector<std::string> children(const std::string& path = ".") const;
  /// Removes the link at path (the space is not reclaimed by HDF5; fine for our sizes).
  void remove(const std::string& path);
  /// A second name (a hard link) `name` for the existing object at `existing`.
  void hard_link(const std::string& existing, const std::string& name);

  // ---- datasets ----------------------------------------------------------------------------
  /// Raw writers: data in row-major (C) order with the given shape (rank 0..N).
  void write_dataset(const std::string& path, std::span<const double> data,
                     const std::vector<std::size_t>& shape, const H5WriteOptions& opts = {});
  void write_dataset(const std::string& path, std::span<const int> data,
                     const std::vector<std::size_t>& shape, const H5WriteOptions& opts = {});

  void write(const std::string& path, const std::vector<double>& v,
             const H5WriteOptions& opts = {}) {
    write_dataset(path, std::span<const double>(v), {v.size()}, opts);
  }
  void write(const std::string& path, const std::vector<int>& v, const H5WriteOptions& opts = {}) {
    write_dataset(path, std::span<const int>(v), {v.size()}, opts);
  }
  /// Eigen vectors (compile-time one column or one row) become 1-D datasets; any other
  /// matrix becomes a 2-D dataset of shape (rows, cols) in row-major order. Scalar double or
  /// int.
  template <class Derived>
  void write(const std::string& path, const Eigen::DenseBase<Derived>& m,
             const H5WriteOptions& opts = {});
  /// A 1-D dataset of variable-length UTF-8 strings.
  void write_strings(const std::string& path, const std::vector<std::string>& v);

  /// Shape of a dataset (empty for a scalar dataset).
  std::vector<std::size_t> shape(const std::string& path) const;
  /// Reads any numeric 1-D (or scalar) dataset as doubles.
  std::vector<double> read_doubles(const std::string& path) const;
  /// Reads an integer 1-D (or scalar) dataset; a floating-point dataset is an error.
  std::vector<int> read_ints(const std::string& path) const;
  /// Reads a numeric 2-D dataset of shape (rows, cols).
  RowMatrixXd read_matrix(const std::string& path) const;
  /// Reads an integer 2-D dataset of shape (rows, cols).
  RowMatrixXi read_int_matrix(const std::string& path) const;
  /// Reads a numeric dataset of any rank as doubles, with its shape.
  H5Array read_array(const std::string& path) const;
  /// Reads a 1-D (or scalar) string dataset, variable or fixed length.
  std::vector<std::string> read_strings(const std::string& path) const;

  // ---- attributes (on the object at obj_path: "." = this group) ---------------------------
  void set_attribute(const std::string& obj_path, const std::string& name,
                     const std::string& value);
  void set_attribute(const std::string& obj_path, const std::string& name, const char* value) {
    set_attribute(obj_path, name, std::string(value));
  }
  void set_attribute(const std::string& obj_path, const std::string& name, double value);
  void set_attribute(const std::string& obj_path, const std::string& name, int value);
  void set_attribute(const std::string& obj_path, const std::string& name,
                     const std::vector<double>& value);

  bool has_attribute(const std::string& obj_path, const std::string& name) const;
  /// Removes attribute `name` of the object at obj_path (as an older writer would have left it
  /// out); throws if there is none.
  void remove_attribute(const std::string& obj_path, const std::string& name);
  std::vector<std::string> attribute_names(const std::string& obj_path = ".") const;
  std::string attribute_string(const std::string& obj_path, const std::string& name) const;
  /// Scalar or one-element numeric attribute.
  double attribute_double(const std::string& obj_path, const std::string& name) const;
  /// Scalar or one-element integer attribute.
  int attribute_int(const std::string& obj_path, const std::string& name) const;
  std::vector<double> attribute_doubles(const std::string& obj_path, const std::string& name) const;

  /// From now on, and in the groups opened from this one, real datasets (read_doubles,
  /// read_array, read_matrix) must be stored as they are written, as 8-byte floats: integer
  /// storage is refused (its values would have been truncated). For files written by knitscale
  /// only (the material database); results.h5 stores its step numbers as integers.
  void require_real_data() { real_only_ = true; }

 protected:
  H5Group(H5Handle id, std::string file, std::string path)
      : id_(std::move(id)), file_(std::move(file)), path_(std::move(path)) {}
  /// Absolute path of `rel` resolved against this group (for messages).
  std::string full(const std::string& rel) const;
  /// HDF5 name of `rel` relative to this group ("." for the group itself).
  static std::string h5name(const std::string& rel);
  [[noreturn]] void fail(const std::string& rel, const std::string& what) const;
  /// The file's content is wrong (checksum, impossible size): knit::InputError(file, path).
  [[noreturn]] void fail_input(const std::string& rel, const std::string& what) const;
  friend struct H5GroupAccess;

  H5Handle id_;
  std::string file_, path_;
  bool real_only_ = false;  ///< require_real_data()
};

/// An HDF5 file; as a group it is the root "/".
class H5File : public H5Group {
 public:
  enum class Mode { Truncate, ReadOnly, ReadWrite };
  /// Truncate creates (or empties) the file; ReadOnly/ReadWrite need an existing HDF5 file.
  H5File(const std::filesystem::path& file, Mode mode);
  static H5File create(const std::filesystem::path& f) { return H5File(f, Mode::Truncate); }
  static H5File open_read(const std::filesystem::path& f) { return H5File(f, Mode::ReadOnly); }
  static H5File open_rw(const std::filesystem::path& f) { return H5File(f, Mode::ReadWrite); }
  H5File(H5File&&) noexcept = default;
  H5File& operator=(H5File&&) noexcept = default;
  /// Closes the root group, then the file.
  ~H5File() override;

  /// Flushes everything to disk (H5Fflush, global scope).
  void flush();
  /// Flushes and closes the file, and with it every group opened from it (using such a group
  /// afterwards is an error), then appends the structure checksum (files written or opened
  /// read-write). The data is on disk after close() (safe to rename, see atomic.hpp). The
  /// destructor does the same but cannot report failures: call close() to see them.
  void close();
  bool is_open() const { return file_id_.valid(); }
  /// Whether the opened file had a structure checksum (verified at open; a mismatch throws).
  /// False for files written before the checksum existed, and for files of ours opened for
  /// writing by another program afterwards: HDF5 cuts a file it closes to its own end, so
  /// h5py's "r+" or "a" drops the checksum even without a change. Readers tell the two apart
  /// with has_checksum() on a dataset every such file holds (material::read_database).
  bool structure_sealed() const { return sealed_; }

 private:
  H5Handle file_id_;
  Mode mode_ = Mode::ReadOnly;
  bool sealed_ = false;
};

/// An HDF5 file written atomically: created at a temporary path next to `target`, closed and
/// renamed onto it by commit(); without commit() the temporary is removed and `target` is
/// untouched.
///   knit::io::AtomicH5File db("material.h5");
///   db->write("/loop_4.50/fit/S", S);
///   db.commit();
class AtomicH5File {
 public:
  explicit AtomicH5File(const std::filesystem::path& target);
  H5File& file() { return file_; }
  H5File* operator->() { return &file_; }
  const std::filesystem::path& target() const { return atomic_.target(); }
  /// Closes the file, then fsync + rename (see AtomicFile::commit).
  void commit();

 private:
  AtomicFile atomic_;  // declared first: destroyed after file_ (removes the closed temporary)
  H5File file_;
};

/// True if `file` exists and carries an HDF5 signature.
bool is_hdf5_file(const std::filesystem::path& file);

// ---- template implementation ---------------------------------------------------------------
template <class Derived>
void H5Group::write(const std::string& path, const Eigen::DenseBase<Derived>& m,
                    const H5WriteOptions& opts) {
  using Scalar = typename Derived::Scalar;
  static_assert(std::is_same_v<Scalar, double> || std::is_same_v<Scalar, int>,
                "knit::io::H5Group::write: only double and int matrices");
  constexpr bool is_vector = Derived::ColsAtCompileTime == 1 || Derived::RowsAtCompileTime == 1;
  using Row = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Row r = m.derived();
  const std::span<const Scalar> data(r.data(), static_cast<std::size_t>(r.size()));
  if constexpr (is_vector)
    write_dataset(path, data, {static_cast<std::size_t>(r.size())}, opts);
  else
    write_dataset(path, data,
                  {static_cast<std::size_t>(r.rows()), static_cast<std::size_t>(r.cols())}, opts);
}

}  // namespace knit::io
