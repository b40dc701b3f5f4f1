// The data/ CSV convention (data/README.md): '#' comment lines, one header row, cells without
// commas or quotes. Private to spine/ (the module stands alone, docs/architecture.md).
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::spine::detail {

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  /// Index of a column; throws std::runtime_error naming the file.
  std::size_t column(const std::string& name) const;
  /// Number in row r, column `name`; throws naming file, row and column when not finite.
  double number(std::size_t r, const std::string& name) const;
  const std::string& text(std::size_t r, const std::string& name) const {
    return rows[r][column(name)];
  }
  /// Row whose `key_column` equals `key`; throws when absent.
  std::size_t find(const std::string& key_column, const std::string& key) const;
};

/// Reads a data/ CSV; throws std::runtime_error for a missing file or a ragged row.
CsvTable read_csv(const std::string& path);

}  // namespace spinesim::spine::detail
