// The data/ CSV convention (data/README.md): '#' comment lines, one header row, cells without
// commas or quotes, surrounding blanks trimmed. The one reader of the shipped tables (mesh/'s
// disc and vertebra tables, spine/'s model tables); every error is a one-line
// std::invalid_argument naming the file, and the row and column where there is one. Numbers are
// read as every number is (numbers.hpp).
#pragma once

#include "spinesim/common/numbers.hpp"
#include "spinesim/common/provenance.hpp"

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim {

/// `s` without leading and trailing blanks (space, tab, CR, LF).
inline std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  /// Index of a column; throws naming the file.
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    throw std::invalid_argument(path + ": no column '" + name + "'");
  }
  const std::string& text(std::size_t r, const std::string& name) const {
    return rows.at(r)[column(name)];
  }
  /// Number in row r (0 = the first data row), column `name`; throws naming file, row, column.
  double number(std::size_t r, const std::string& name) const {
    return to_double(text(r, name),
                     path + ": row " + std::to_string(r + 1) + " column '" + name + "'");
  }
  /// Index of the row whose `key_column` equals `key` (exact match); throws when absent.
  std::size_t find(const std::string& key_column, const std::string& key) const {
    const std::size_t k = column(key_column);
    for (std::size_t r = 0; r < rows.size(); ++r)
      if (rows[r][k] == key) return r;
    throw std::invalid_argument(path + ": no row with " + key_column + " = " + key);
  }
};

/// Reads a data/ CSV; throws for a missing file, a ragged row or no header row.
inline CsvTable read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + path);
  record_input_file(path);
  CsvTable t;
  t.path = path;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    std::vector<std::string> cells;
    for (std::size_t start = 0;;) {
      const auto comma = s.find(',', start);
      cells.push_back(trim(s.substr(start, comma == std::string::npos ? comma : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (t.header.empty()) {
      t.header = std::move(cells);
      continue;
    }
    if (cells.size() != t.header.size())
      throw std::invalid_argument(path + ":" + std::to_string(line_no) + ": expected " +
                                  std::to_string(t.header.size()) + " cells, got " +
                                  std::to_string(cells.size()));
    t.rows.push_back(std::move(cells));
  }
  if (t.header.empty()) throw std::invalid_argument(path + ": no header row");
  return t;
}

}  // namespace spinesim
