#pragma once
// Numeric constants and every number format whirl writes, one copy for the whole library. Pick
// by where the number goes:
//   a message (error, warning, progress, a one-line summary)  MessageNumber       "%.6g"
//   a data file read back by whirl or a spreadsheet (CSV, JSON) FormatNumber        round trip
//   a figure for a person with a chosen number of digits       FormatSignificant   "%.*g"
//   a table or report column with fixed decimals               FormatDecimals      "%.*f"
//   coefficients spanning many decades                         FormatExponent      "%.*e"
//   a value a control or a person re-types (NC programs, PLC)  FormatFixed         no -0, no e
// Each is exactly the C printf conversion named (the C locale's '.'), so text written before
// these helpers existed (golden files, shipped tables) reads the same. An ostream with
// precision(n) and the default float field prints "%.*g" with n digits, with std::fixed "%.*f".
#include <cstddef>
#include <string>

namespace whirl {

inline constexpr double kPi = 3.14159265358979323846;  ///< C++17 has no std::numbers::pi

/// A number in an error or progress message: 6 significant digits ("%.6g", FormatSignificant
/// with 6 digits). Files use FormatNumber (round trip) or FormatFixed (controls).
std::string MessageNumber(double x);

/// A number for CSV/JSON-like text output with round-trip precision: the shortest "%.*g" (6 to 17
/// significant digits) that parses back to the same double.
std::string FormatNumber(double x);

/// `digits` significant digits, printf's "%.*g" (an exponent when the number is very large or
/// small, trailing zeros dropped): "0.0001235", "1.235e+06", "nan", "inf".
std::string FormatSignificant(double x, int digits);

/// `decimals` digits after the point, printf's "%.*f" exactly: "-0.0" for a small negative
/// number, every digit of a huge one ("1e300" has 301). Tables and reports whose columns must
/// keep their width and sign as written so far.
std::string FormatDecimals(double x, int decimals);

/// As FormatDecimals, but `if_nan` for NaN (a table cell with no value, e.g. "-").
std::string FormatDecimalsOr(double x, int decimals, const std::string& if_nan);

/// As FormatDecimals without the trailing zeros and a then trailing point: "0.5", "12", "-0.004"
/// (3 decimals). Values quoted from a standard's table.
std::string FormatDecimalsTrimmed(double x, int decimals);

/// `decimals` digits after the point in exponent form, printf's "%.*e": "1.234560e-05" (6).
/// Polynomial coefficients spanning many decades.
std::string FormatExponent(double x, int decimals);

/// Fixed decimals for a value a control reads (NC programs, PLC tables): as FormatDecimals but
/// never "-0.000" (a value that rounds to zero is written "0.000"), never an exponent.
std::string FormatFixed(double x, int decimals);

/// `text` right-aligned in `width` columns (printf's "%*s"; longer text is kept whole): table
/// columns, e.g. PadLeft(FormatDecimals(x, 4), 12) is "%12.4f".
std::string PadLeft(const std::string& text, std::size_t width);

}  // namespace whirl
