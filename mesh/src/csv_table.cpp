// The data/ CSV reader shared by mesh/'s tables (csv_table.hpp).
#include "csv_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace spinesim::mesh::detail {
std::size_t CsvTable::column(const std::string& name) const {
  auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) throw std::invalid_argument(path + ": missing column '" + name + "'");
  return std::size_t(it - header.begin());
}

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

namespace {

std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    cells.push_back(
        trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cells;
}

}  // namespace

CsvTable read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + path.string());
  CsvTable t;
  t.path = path.string();
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    auto cells = split_cells(s);
    if (t.header.empty()) {
      t.header = std::move(cells);
      continue;
    }
    if (cells.size() != t.header.size())
      throw std::invalid_argument(t.path + ":" + std::to_string(line_no) + ": expected " +
                                  std::to_string(t.header.size()) + " cells, got " +
                                  std::to_string(cells.size()));
    t.rows.push_back(std::move(cells));
  }
  if (t.header.empty()) throw std::invalid_argument(t.path + ": no header row");
  return t;
}

double to_double(const std::string& cell, const std::string& where) {
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (cell.empty() || end != cell.c_str() + cell.size() || !std::isfinite(v))
    throw std::invalid_argument(where + ": '" + cell + "' is not a finite number");
  return v;
}

/// Row of `table` whose `key_column` equals `key` (exact match).
const std::vector<std::string>& find_row(const CsvTable& table, const std::string& key_column,
                                         const std::string& key) {
  const std::size_t k = table.column(key_column);
  for (const auto& row : table.rows)
    if (row[k] == key) return row;
  throw std::invalid_argument(table.path + ": no row with " + key_column + " = " + key);
}

Eigen::Vector3d point(const CsvTable& table, const std::vector<std::string>& row,
                      const std::string& what) {
  return {to_double(row[table.column("x_mm")], what + " x_mm"),
          to_double(row[table.column("y_mm")], what + " y_mm"),
          to_double(row[table.column("z_mm")], what + " z_mm")};
}

}  // namespace spinesim::mesh::detail
