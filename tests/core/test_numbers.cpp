// The number formats of core/numbers.h against their references: the printf conversion each one
// documents (and the ostream settings the replaced local formatters used), over many random
// doubles of every magnitude and sign, plus the hand-checked edge cases of each variant.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/numbers.h"

namespace whirl {
namespace {

std::string Printf(const char* format, int precision, double x) {
  char buf[512];
  std::snprintf(buf, sizeof buf, format, precision, x);
  return buf;
}

// Doubles of every sign and magnitude (random bit patterns that are finite), plus edge values.
std::vector<double> Samples() {
  std::vector<double> v{0.0,  -0.0, 1.0,   -1.0,  0.5,    -0.0004, 1e-300, -1e-300, 123456.789,
                        1e21, 1e300, 2.5,  -2.5,  0.125,  1e-5,    9.9999, 0.05,    -0.05};
  std::mt19937_64 rng(27);
  while (v.size() < 5000) {
    const std::uint64_t bits = rng();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    if (std::isfinite(x)) v.push_back(x);
    v.push_back(std::uniform_real_distribution<double>(-1e4, 1e4)(rng));
  }
  return v;
}

TEST(Numbers, SignificantIsPrintfGAndTheOstreamDefault) {
  for (double x : Samples())
    for (int digits : {3, 4, 6, 10, 17}) {
      std::ostringstream s;
      s.precision(digits);
      s << x;
      ASSERT_EQ(FormatSignificant(x, digits), Printf("%.*g", digits, x)) << x;
      ASSERT_EQ(FormatSignificant(x, digits), s.str()) << x;
    }
  for (double x : Samples()) ASSERT_EQ(MessageNumber(x), Printf("%.*g", 6, x)) << x;
}

TEST(Numbers, DecimalsIsPrintfFAndTheFixedOstream) {
  for (double x : Samples()) {
    if (std::abs(x) > 1e100) continue;  // the ostream buffer grows; printf's is enough
    for (int decimals : {0, 1, 3, 8}) {
      std::ostringstream s;
      s << std::fixed << std::setprecision(decimals) << x;
      ASSERT_EQ(FormatDecimals(x, decimals), Printf("%.*f", decimals, x)) << x;
      ASSERT_EQ(FormatDecimals(x, decimals), s.str()) << x;
    }
  }
  EXPECT_EQ(FormatDecimals(-0.04, 1), "-0.0") << "a table keeps the sign printf writes";
  EXPECT_EQ(FormatDecimals(1e300, 0).size(), 301u) << "every digit, no exponent";
  EXPECT_EQ(FormatDecimalsOr(std::nan(""), 3, "-"), "-");
  EXPECT_EQ(FormatDecimalsOr(1.5, 3, "-"), "1.500");
  EXPECT_EQ(FormatExponent(1.23456e-5, 4), "1.2346e-05");
  EXPECT_EQ(FormatExponent(-2.0, 6), Printf("%.*e", 6, -2.0));
}

TEST(Numbers, FixedNeverNegativeZeroNorExponent) {
  for (double x : Samples()) {
    for (int decimals : {3, 4, 6, 8}) {
      const std::string s = FormatFixed(x, decimals);
      ASSERT_EQ(s.find('e'), std::string::npos) << x;
      const bool zero = s.find_first_not_of("-0.") == std::string::npos;
      ASSERT_FALSE(zero && s[0] == '-') << x << " -> " << s;
      // Otherwise exactly printf's text: the value the control reads is what was rounded.
      ASSERT_EQ(s, Printf("%.*f", decimals, zero ? 0.0 : x)) << x;
    }
  }
}

TEST(Numbers, TrimmedDropsZerosButNotIntegerDigits) {
  EXPECT_EQ(FormatDecimalsTrimmed(0.5, 3), "0.5");
  EXPECT_EQ(FormatDecimalsTrimmed(12.0, 3), "12");
  EXPECT_EQ(FormatDecimalsTrimmed(-0.004, 3), "-0.004");
  EXPECT_EQ(FormatDecimalsTrimmed(100.0, 0), "100") << "no point: the zeros are digits";
  EXPECT_EQ(FormatDecimalsTrimmed(0.0001, 3), "0");
  for (double x : Samples()) {
    if (std::abs(x) > 1e100) continue;
    const std::string s = FormatDecimalsTrimmed(x, 3);
    // Reads back as the 3-decimal rounding.
    ASSERT_EQ(std::strtod(s.c_str(), nullptr), std::strtod(Printf("%.*f", 3, x).c_str(), nullptr))
        << x;
    ASSERT_TRUE(s.find('.') == std::string::npos || (s.back() != '0' && s.back() != '.')) << s;
  }
}

TEST(Numbers, RoundTripIsTheShortestThatParsesBack) {
  for (double x : Samples()) {
    const std::string s = FormatNumber(x);
    ASSERT_EQ(std::strtod(s.c_str(), nullptr), x) << s;
    // No shorter "%.*g" (from 6 digits) reads back the same.
    for (int digits = 6; Printf("%.*g", digits, x) != s; ++digits)
      ASSERT_NE(std::strtod(Printf("%.*g", digits, x).c_str(), nullptr), x) << s;
  }
}

TEST(Numbers, PadLeftIsPrintfWidth) {
  for (double x : Samples()) {
    if (std::abs(x) > 1e100) continue;
    char buf[512];
    std::snprintf(buf, sizeof buf, "%12.4f", x);
    ASSERT_EQ(PadLeft(FormatDecimals(x, 4), 12), buf);
    std::snprintf(buf, sizeof buf, "%11.4g", x);
    ASSERT_EQ(PadLeft(FormatSignificant(x, 4), 11), buf);
  }
}

}  // namespace
}  // namespace whirl
