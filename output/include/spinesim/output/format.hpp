// Numbers and strings for readable output: one number formatter with one NaN rule, percentages,
// one-line messages and display widths (UTF-8 aware, so "N·mm" and "Δx" align).
//
// The NaN rule: a value that is not a number prints as "n/a" (a missing reference, a ratio of
// nothing); a value that rounds to zero prints without a sign ("0.000", never "-0.000").
#pragma once

#include <string>

namespace spinesim::output {

/// `v` with `decimals` digits after the point ("n/a" for NaN, "inf"/"-inf" for infinities).
std::string fixed(double v, int decimals);

/// `fraction` as a percentage with `decimals` digits and " %": percent(0.123) == "12.3 %".
std::string percent(double fraction, int decimals = 1);

/// `v` with `digits` significant digits (std::defaultfloat), NaN as "n/a".
std::string significant(double v, int digits);

/// `s` with every newline replaced by a space (an error message on one line).
std::string one_line(std::string s);

/// Display columns of a UTF-8 string: continuation bytes take no column.
std::size_t display_width(const std::string& s);

/// `s` padded with spaces to `width` display columns, right-aligned (or left when `left`).
std::string pad(const std::string& s, std::size_t width, bool left = false);

}  // namespace spinesim::output
