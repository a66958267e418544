#include "core/numbers.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace whirl {
namespace {

// printf of one double with a precision; 512 bytes hold "%.*f" of the largest double (309 digits)
// with up to 200 decimals.
std::string Printf(const char* format, int precision, double x) {
  char buf[512];
  std::snprintf(buf, sizeof buf, format, precision, x);
  return buf;
}

}  // namespace

std::string MessageNumber(double x) { return FormatSignificant(x, 6); }

std::string FormatNumber(double x) {
  std::string s;
  for (int digits = 6; digits <= 17; ++digits) {
    s = FormatSignificant(x, digits);
    if (std::strtod(s.c_str(), nullptr) == x) break;
  }
  return s;
}

std::string FormatSignificant(double x, int digits) { return Printf("%.*g", digits, x); }

std::string FormatDecimals(double x, int decimals) { return Printf("%.*f", decimals, x); }

std::string FormatExponent(double x, int decimals) { return Printf("%.*e", decimals, x); }

std::string FormatDecimalsOr(double x, int decimals, const std::string& if_nan) {
  return std::isnan(x) ? if_nan : FormatDecimals(x, decimals);
}

std::string FormatDecimalsTrimmed(double x, int decimals) {
  std::string s = FormatDecimals(x, decimals);
  if (s.find('.') == std::string::npos) return s;
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s;
}

std::string FormatFixed(double x, int decimals) {
  std::string s = FormatDecimals(x, decimals);
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

std::string PadLeft(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}

}  // namespace whirl
