#include "core/numbers.h"

#include <algorithm>
#include <charconv>
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
  // The fewest digits d >= 6 whose "%.*g" reads back as x. No d below the shortest round-trip
  // representation's digit count can (it would be shorter), so the search starts there: one or
  // two std::to_chars (printf's %g, exactly) instead of up to twelve printf and strtod.
  if (!std::isfinite(x)) return FormatSignificant(x, 6);
  // The significant digits of a number's text, without leading and trailing zeros.
  const auto significant = [](const char* b, const char* e, char* out) {
    char* o = out;
    for (; b != e && *b != 'e'; ++b)
      if (*b >= '0' && *b <= '9' && (o != out || *b != '0')) *o++ = *b;
    while (o != out && o[-1] == '0') --o;
    return static_cast<int>(o - out);
  };
  char shortest[64], digits[32], buf[64], printed[32];
  const auto s = std::to_chars(shortest, shortest + sizeof shortest, x, std::chars_format::scientific);
  const int n = significant(shortest, s.ptr, digits);
  for (int d = std::max(6, n); d <= 17; ++d) {
    const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, d);
    // The same digits as the shortest representation: the same number, which reads back as x.
    const int m = significant(buf, r.ptr, printed);
    if (m == n && std::equal(digits, digits + n, printed)) return std::string(buf, r.ptr);
    double back = 0;
    std::from_chars(buf, r.ptr, back);
    if (back == x || d == 17) return std::string(buf, r.ptr);
  }
  return FormatSignificant(x, 17);
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
