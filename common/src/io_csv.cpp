// CSV writer (see knit/io/csv.hpp).
#include "knit/io/csv.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "knit/io/atomic.hpp"

namespace knit::io {

std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

namespace {
std::string quote_if_needed(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

std::string join(const std::vector<std::string>& cells) {
  std::string line;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += cells[i];
  }
  return line;
}
}  // namespace

CsvCell::CsvCell(std::string s) : text_(quote_if_needed(s)) {}

CsvWriter::CsvWriter(std::filesystem::path file, std::vector<std::string> header)
    : file_(std::move(file)), columns_(header.size()) {
  if (header.empty()) throw std::invalid_argument(file_.string() + ": CSV header is empty");
  for (auto& h : header) h = quote_if_needed(h);
  header_ = join(header);
}

void CsvWriter::add_comment(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) comments_.push_back("# " + line);
}

void CsvWriter::add_row(const std::vector<CsvCell>& cells) {
  if (cells.size() != columns_)
    throw std::invalid_argument(file_.string() + ": CSV row has " + std::to_string(cells.size()) +
                                " cells, header has " + std::to_string(columns_));
  std::string line;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i) line += ',';
    line += cells[i].text();
  }
  rows_.push_back(std::move(line));
}

void CsvWriter::add_row(std::span<const double> values) {
  std::vector<CsvCell> cells(values.begin(), values.end());
  add_row(cells);
}

void CsvWriter::commit() {
  std::string out;
  for (const auto& c : comments_) out += c + "\n";
  out += header_ + "\n";
  for (const auto& r : rows_) out += r + "\n";
  write_file_atomically(file_, out);
}

}  // namespace knit::io
