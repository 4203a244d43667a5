#include "common/data/csv_table.h"

#include <charconv>
#include <stdexcept>

#include "common/data/embedded_files.h"

namespace skyfarm {
namespace {

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return cells;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

double parse_number(std::string_view cell, std::string_view source, std::size_t line, std::size_t col) {
  cell = trim(cell);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (ec != std::errc() || end != cell.data() + cell.size()) {
    throw std::runtime_error(std::string(source) + ":" + std::to_string(line) + ": column " +
                             std::to_string(col + 1) + " is not a number: '" + std::string(cell) + "'");
  }
  return value;
}

}  // namespace

CsvTable CsvTable::parse(std::string_view text, std::string_view source) {
  CsvTable table;
  table.source_ = source;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view line = trim(text.substr(pos, nl - pos));
    pos = nl + 1;
    ++line_no;
    if (line.empty()) continue;
    const auto cells = split_commas(line);
    if (table.header_.empty()) {
      for (auto c : cells) table.header_.emplace_back(trim(c));
      table.columns_.resize(cells.size());
      continue;
    }
    if (cells.size() != table.header_.size()) {
      throw std::runtime_error(std::string(source) + ":" + std::to_string(line_no) + ": expected " +
                               std::to_string(table.header_.size()) + " columns, got " +
                               std::to_string(cells.size()));
    }
    for (std::size_t c = 0; c < cells.size(); ++c)
      table.columns_[c].push_back(parse_number(cells[c], source, line_no, c));
    ++table.rows_;
  }
  if (table.header_.empty()) throw std::runtime_error(std::string(source) + ": empty table");
  return table;
}

CsvTable CsvTable::embedded(std::string_view name) { return parse(embedded_file(name), name); }

bool CsvTable::has_column(std::string_view name) const {
  for (const auto& h : header_)
    if (h == name) return true;
  return false;
}

const std::vector<double>& CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (header_[i] == name) return columns_[i];
  throw std::out_of_range(source_ + ": no column '" + std::string(name) + "'");
}

}  // namespace skyfarm
