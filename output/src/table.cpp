#include "spinesim/output/table.hpp"

#include "spinesim/output/format.hpp"

#include <algorithm>

namespace spinesim::output {

void TextTable::set_min_width(std::size_t i, std::size_t width) {
  if (min_width_.size() <= i) min_width_.resize(i + 1, 0);
  min_width_[i] = width;
}

void TextTable::print(std::ostream& os, bool markdown, const std::string& indent,
                      std::size_t gap) const {
  if (markdown) {
    auto line = [&](const std::vector<std::string>& r) {
      os << "|";
      for (const auto& c : r) {
        std::string cell;  // a '|' inside a cell (|Δx|) would end it
        for (char ch : c) cell += ch == '|' ? std::string("\\|") : std::string(1, ch);
        os << " " << cell << " |";
      }
      os << "\n";
    };
    line(header_);
    os << "|";
    for (std::size_t i = 0; i < header_.size(); ++i)
      os << (plain_markdown_ || i < text_columns_ ? "---|" : "---:|");
    os << "\n";
    for (const auto& r : rows_) line(r);
    return;
  }
  std::vector<std::size_t> w(header_.size(), 0);
  for (std::size_t i = 0; i < header_.size(); ++i)
    w[i] = std::max(display_width(header_[i]), i < min_width_.size() ? min_width_[i] : 0);
  for (const auto& r : rows_)
    for (std::size_t i = 0; i < r.size() && i < w.size(); ++i)
      w[i] = std::max(w[i], display_width(r[i]));
  const std::string space(gap, ' ');
  auto line = [&](const std::vector<std::string>& r) {
    os << indent;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::size_t width = i < w.size() ? w[i] : 0;
      if (i > 0) os << space;
      if (i < text_columns_)
        os << (i + 1 < r.size() ? pad(r[i], width, true) : r[i]);
      else
        os << pad(r[i], width);
    }
    os << "\n";
  };
  line(header_);
  for (const auto& r : rows_) line(r);
}

}  // namespace spinesim::output
