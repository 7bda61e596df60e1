// Opening input files defensively (issue 14): only regular files are read (a FIFO would block
// forever, /dev/zero never ends), and only up to a stated size.
//
//   std::string text = knit::io::read_input_file(path);              // JSON inputs, <= 64 MiB
//   knit::io::check_input_file(db, knit::io::kMaxHdf5InputBytes);    // before HDF5 opens it
//
// Errors are knit::InputError(file, "", message): "file not found", "not a regular file (a
// FIFO)", "cannot read file", "is 80 MiB, more than the 64 MiB accepted for this input", and
// a name with a control character (a newline: an output's marker records its input's path
// line by line; session 48) is refused before the file is opened.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace knit::io {

/// Cap on JSON inputs (cases, rod/cell/sweep configurations): the largest case in cases/ is
/// well under 1 MiB; 64 MiB leaves room for dense control nets and fields.
inline constexpr std::uint64_t kMaxJsonInputBytes = 64ull << 20;
/// Cap on HDF5 inputs (material databases): HDF5 reads lazily, so the file size itself costs
/// nothing; the cap catches a wrong path (a disk image, a device). Datasets have their own
/// cap (kMaxH5DatasetBytes in hdf5.hpp).
inline constexpr std::uint64_t kMaxHdf5InputBytes = 16ull << 30;

/// Throws InputError unless `file` (after following symlinks) is an existing regular file of
/// at most max_bytes. Returns its size in bytes.
std::uint64_t check_input_file(const std::filesystem::path& file, std::uint64_t max_bytes);

/// Reads a whole regular file of at most max_bytes (checked on the open descriptor, so a file
/// swapped for a FIFO after a check is still refused, and never opened in blocking mode).
std::string read_input_file(const std::filesystem::path& file,
                            std::uint64_t max_bytes = kMaxJsonInputBytes);

}  // namespace knit::io
