// The one way a number is read from text — a data table's cell, a flag's value, a list item:
// plain decimal notation ("12", "-0.5", "1e-3", ".5"), all of the text, finite. No hex ("0x10"
// is not 16), no "nan" or "inf", no blanks, no empty text (not 0): anything else is an error
// naming where it came from.
#pragma once

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace spinesim {

/// True when `text` is a number in plain decimal notation (integer: digits with an optional
/// sign only).
inline bool is_plain_number(const std::string& text, bool integer = false) {
  std::size_t i = 0, n = text.size();
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t digits = 0;
  while (i < n && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
  if (integer) return digits > 0 && i == n;
  if (i < n && text[i] == '.') {
    ++i;
    while (i < n && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exponent = 0;
    while (i < n && text[i] >= '0' && text[i] <= '9') ++i, ++exponent;
    if (exponent == 0) return false;
  }
  return i == n;
}

/// `text` as a finite number in plain decimal notation; otherwise std::invalid_argument
/// "<where>: '<text>' is not a finite number" (one line).
inline double to_double(const std::string& text, const std::string& where) {
  if (is_plain_number(text)) {
    const double v = std::strtod(text.c_str(), nullptr);
    if (std::isfinite(v)) return v;
  }
  throw std::invalid_argument(where + ": '" + text + "' is not a finite number");
}

}  // namespace spinesim
