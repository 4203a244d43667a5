// A numeric CSV table with one header line, as the files of data/ are written.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm {

class CsvTable {
 public:
  // Parses `text` (header line, then rows of numbers).  Throws
  // std::runtime_error naming `source`, the line and the column on any
  // malformed or non-numeric cell.
  static CsvTable parse(std::string_view text, std::string_view source);

  // Parses the embedded data/<name>.
  static CsvTable embedded(std::string_view name);

  const std::vector<std::string>& header() const { return header_; }
  std::size_t rows() const { return rows_; }
  bool has_column(std::string_view name) const;
  // The column called `name`; throws std::out_of_range naming it if absent.
  const std::vector<double>& column(std::string_view name) const;

 private:
  std::string source_;
  std::vector<std::string> header_;
  std::vector<std::vector<double>> columns_;
  std::size_t rows_ = 0;
};

}  // namespace skyfarm
