// The data/ CSV convention (data/README.md): '#' comment lines, one header row, cells without
// commas or quotes. Private to mesh/ (the disc levels and the parametric vertebrae read it).
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

namespace spinesim::mesh::detail {

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  /// Index of a column; throws std::invalid_argument naming the file.
  std::size_t column(const std::string& name) const;
};

std::string trim(const std::string& s);
/// Reads a data/ CSV; throws std::invalid_argument for a missing file or a ragged row.
CsvTable read_csv(const std::filesystem::path& path);
/// A finite number or std::invalid_argument naming `where`.
double to_double(const std::string& cell, const std::string& where);
/// Row of `table` whose `key_column` equals `key` (exact match); throws when absent.
const std::vector<std::string>& find_row(const CsvTable& table, const std::string& key_column,
                                         const std::string& key);
/// The x_mm, y_mm, z_mm cells of `row`.
Eigen::Vector3d point(const CsvTable& table, const std::vector<std::string>& row,
                      const std::string& what);

}  // namespace spinesim::mesh::detail
