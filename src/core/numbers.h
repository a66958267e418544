#pragma once
// Numeric constants and the short number format of messages, one copy for the whole library.
#include <cstdio>
#include <string>

namespace whirl {

inline constexpr double kPi = 3.14159265358979323846;  ///< C++17 has no std::numbers::pi

/// A number in an error or progress message: 6 significant digits ("%.6g"). Files use
/// FormatNumber (core/csv.h, round-trip precision) or fixed decimals (interp).
inline std::string MessageNumber(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace whirl
