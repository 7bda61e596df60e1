// A small CSV writer: one header row, numbers as %.10g, written atomically on commit().
//
//   knit::io::CsvWriter csv("load_displacement.csv", {"step", "u_mm", "F_N", "status"});
//   csv.add_comment("knitscale 0.1.0 (git abc123)");  // "# ..." lines before the header
//   csv.add_row({3, 0.25, 12.5, "converged"});
//   csv.add_row(std::vector<double>{...});
//   csv.commit();
//
// Cells containing a comma, quote or newline are quoted (RFC 4180). Comment lines start with
// "# " (pandas: read_csv(..., comment="#")).
#pragma once

#include <filesystem>
#include <initializer_list>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace knit::io {

/// "%.10g" (non-finite values as "nan", "inf", "-inf").
std::string format_number(double x);

/// One CSV cell: a number (integers printed exactly, floating point with %.10g) or text.
class CsvCell {
 public:
  template <class T>
  requires std::is_arithmetic_v<T> CsvCell(
      T v) {  // NOLINT(google-explicit-constructor): cells are built from braced lists
    if constexpr (std::is_floating_point_v<T>)
      text_ = format_number(static_cast<double>(v));
    else if constexpr (std::is_same_v<T, bool>)
      text_ = v ? "1" : "0";
    else
      text_ = std::to_string(v);
  }
  CsvCell(std::string s);                              // NOLINT(google-explicit-constructor)
  CsvCell(const char* s) : CsvCell(std::string(s)) {}  // NOLINT(google-explicit-constructor)
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

class CsvWriter {
 public:
  CsvWriter(std::filesystem::path file, std::vector<std::string> header);
  /// A "# text" line written before the header (e.g. provenance). Multi-line text gives
  /// several comment lines.
  void add_comment(const std::string& text);
  /// Throws std::invalid_argument if the row width differs from the header's.
  void add_row(const std::vector<CsvCell>& cells);
  void add_row(std::initializer_list<CsvCell> cells) { add_row(std::vector<CsvCell>(cells)); }
  void add_row(std::span<const double> values);
  std::size_t rows() const { return rows_.size(); }
  const std::filesystem::path& file() const { return file_; }
  /// Writes the whole file atomically (temporary + rename).
  void commit();

 private:
  std::filesystem::path file_;
  std::vector<std::string> comments_;
  std::string header_;
  std::size_t columns_;
  std::vector<std::string> rows_;
};

}  // namespace knit::io
