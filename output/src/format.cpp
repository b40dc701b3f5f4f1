#include "spinesim/output/format.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace spinesim::output {

std::string fixed(double v, int decimals) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0;  // no "-0.000"
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

std::string percent(double fraction, int decimals) {
  if (std::isnan(fraction)) return "n/a";
  return fixed(100.0 * fraction, decimals) + " %";
}

std::string significant(double v, int digits) {
  if (std::isnan(v)) return "n/a";
  std::ostringstream os;
  os << std::defaultfloat << std::setprecision(digits) << v;
  return os.str();
}

std::string one_line(std::string s) {
  for (char& c : s)  // newlines, carriage returns and other control characters
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t') c = ' ';
  return s;
}

std::size_t display_width(const std::string& s) {
  return std::size_t(std::count_if(
      s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

std::string pad(const std::string& s, std::size_t width, bool left) {
  const std::size_t w = display_width(s);
  const std::string fill(width > w ? width - w : 0, ' ');
  return left ? s + fill : fill + s;
}

}  // namespace spinesim::output
