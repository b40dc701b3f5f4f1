// The one table formatter of the program: aligned text (units in the headers) or a markdown
// table. Every table the program prints goes through it.
#pragma once

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::output {

/// A plain table. The first `text_columns` columns are left-aligned, the rest (numbers)
/// right-aligned; in markdown a '|' inside a cell is escaped and number columns are marked
/// right-aligned (`---:`).
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> header, std::size_t text_columns = 1)
      : header_(std::move(header)), text_columns_(text_columns) {}
  void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  std::size_t num_rows() const { return rows_.size(); }

  /// Markdown, or aligned text with `indent` before each line and `gap` spaces between columns.
  void print(std::ostream& os, bool markdown, const std::string& indent = "  ",
             std::size_t gap = 2) const;
  /// Column alignment only (markdown: `---|` for every column, as plain GitHub tables).
  void set_plain_markdown(bool plain) { plain_markdown_ = plain; }
  /// Minimum display width of column `i` in text mode (headers narrower than their data).
  void set_min_width(std::size_t i, std::size_t width);

 private:
  std::vector<std::string> header_;
  std::size_t text_columns_ = 1;
  bool plain_markdown_ = false;
  std::vector<std::size_t> min_width_;
  std::vector<std::vector<std::string>> rows_;
};

}  // namespace spinesim::output
