#include "csv_table.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spinesim::spine::detail {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

std::size_t CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  throw std::runtime_error(path + ": no column '" + name + "'");
}

double CsvTable::number(std::size_t r, const std::string& name) const {
  const std::string& cell = rows.at(r)[column(name)];
  try {
    std::size_t used = 0;
    const double v = std::stod(cell, &used);
    if (used == cell.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {}
  throw std::runtime_error(path + ": row " + std::to_string(r + 1) + " column '" + name + "': '" +
                           cell + "' is not a finite number");
}

std::size_t CsvTable::find(const std::string& key_column, const std::string& key) const {
  const std::size_t k = column(key_column);
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (rows[r][k] == key) return r;
  throw std::runtime_error(path + ": no row with " + key_column + " = " + key);
}

CsvTable read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  CsvTable t;
  t.path = path;
  std::string line;
  while (std::getline(in, line)) {
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    auto cells = split(s);
    if (t.header.empty()) {
      t.header = std::move(cells);
    } else {
      if (cells.size() != t.header.size())
        throw std::runtime_error(path + ": a row has " + std::to_string(cells.size()) +
                                 " cells, the header " + std::to_string(t.header.size()));
      t.rows.push_back(std::move(cells));
    }
  }
  if (t.header.empty()) throw std::runtime_error(path + ": no header row");
  return t;
}

}  // namespace spinesim::spine::detail
