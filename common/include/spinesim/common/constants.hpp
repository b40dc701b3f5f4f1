// The project's one π and its degree conversions. Every module uses these; none defines its own
// (two spellings of one constant once meant π/180 in one file and 180/π in another).
#pragma once

namespace spinesim {

inline constexpr double kPi = 3.14159265358979323846;
/// Multiply an angle in degrees by this to get radians.
inline constexpr double kRadPerDeg = kPi / 180.0;
/// Multiply an angle in radians by this to get degrees.
inline constexpr double kDegPerRad = 180.0 / kPi;

}  // namespace spinesim
