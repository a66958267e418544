#include "core/safe_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace whirl {
namespace {

std::string HexEscape(const char* prefix, unsigned value) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%s%02X", prefix, value);
  return buffer;
}

// Length of the valid UTF-8 sequence starting at text[i] (2-4), or 0 if none starts there
// (overlong forms, surrogates and code points above U+10FFFF are invalid).
std::size_t Utf8Length(std::string_view text, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(text[i + k]); };
  const unsigned lead = b(0);
  const std::size_t n = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 ? 2 : 0;
  if (n == 0 || lead > 0xF4 || i + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((b(k) & 0xC0) != 0x80) return 0;
  if (lead == 0xE0 && b(1) < 0xA0) return 0;   // overlong
  if (lead == 0xED && b(1) >= 0xA0) return 0;  // surrogate
  if (lead == 0xF0 && b(1) < 0x90) return 0;   // overlong
  if (lead == 0xF4 && b(1) >= 0x90) return 0;  // above U+10FFFF
  return n;
}

// A finite number and nothing after it but blanks ("-0.5", "+3e2 ").
bool IsPlainNumber(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  return end != text.c_str() &&
         text.find_first_not_of(' ', static_cast<std::size_t>(end - text.c_str())) ==
             std::string::npos &&
         std::isfinite(value);
}

}  // namespace

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        if ((u < 0x20 && ch != '\t' && ch != '\n') || u == 0x7f)
          out += "\xEF\xBF\xBD";  // U+FFFD
        else
          out += ch;
    }
  }
  return out;
}

std::string GnuplotString(std::string_view text) {
  std::string out = "'";
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '\'')
      out += "''";
    else if (u < 0x20 || u == 0x7f)
      out += ' ';
    else
      out += ch;
  }
  return out + "'";
}

std::string Slug(std::string_view text, std::size_t max_length) {
  std::string out;
  for (const char ch : text) {
    if (out.size() >= max_length) break;
    const bool keep = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                      (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
    out += keep ? ch : '_';
  }
  if (out.empty()) return "x";
  if (out.front() == '.' || out.front() == '-') out.front() = '_';
  return out;
}

std::string TerminalText(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto u = static_cast<unsigned char>(text[i]);
    if (u < 0x80) {
      const bool control = (u < 0x20 && u != '\t' && u != '\n') || u == 0x7f;
      out += control ? HexEscape("\\x", u) : std::string(1, text[i]);
      ++i;
      continue;
    }
    const std::size_t n = Utf8Length(text, i);
    if (n == 0) {
      out += HexEscape("\\x", u);
      ++i;
    } else if (u == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0) {
      out += HexEscape("\\u00", static_cast<unsigned char>(text[i + 1]));  // C1 control
      i += 2;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::size_t InvalidUtf8Offset(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    if (static_cast<unsigned char>(text[i]) < 0x80) {
      ++i;
      continue;
    }
    const std::size_t n = Utf8Length(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

bool LooksLikeFormula(std::string_view text) {
  if (text.empty()) return false;
  const char c = text.front();
  return c == '=' || c == '+' || c == '-' || c == '@' || c == '\t' || c == '\r';
}

namespace {

// SpreadsheetCell's rule: the text after its leading apostrophes and spaces looks like a formula.
// Prepending an apostrophe keeps the answer, so SpreadsheetText can undo the marker.
bool NeedsTextMarker(std::string_view text) {
  const std::size_t first = text.find_first_not_of("' ");
  return first != std::string_view::npos && LooksLikeFormula(text.substr(first));
}

// A cell that CsvTextCell encloses in quotes: RFC 4180's ',', '"', CR and LF; a blank at either
// end (a reader trims unquoted cells); ';' and tab (a spreadsheet in a decimal-comma locale
// splits there); a leading '#' (a comment line when it is a row's first cell) or byte-order mark.
bool NeedsQuotes(std::string_view cell) {
  if (cell.empty()) return false;
  return cell.find_first_of(",\"\r\n;\t") != std::string_view::npos || cell.front() == ' ' ||
         cell.back() == ' ' || cell.front() == '#' || cell.substr(0, 3) == "\xEF\xBB\xBF";
}

}  // namespace

std::string SpreadsheetCell(std::string_view text) {
  return NeedsTextMarker(text) ? "'" + std::string(text) : std::string(text);
}

std::string SpreadsheetText(std::string_view cell) {
  if (!cell.empty() && cell.front() == '\'' && NeedsTextMarker(cell.substr(1)))
    cell.remove_prefix(1);
  return std::string(cell);
}

std::string CsvTextCell(std::string_view text) {
  const std::string cell = SpreadsheetCell(text);
  if (!NeedsQuotes(cell)) return cell;
  std::string out = "\"";
  for (const char ch : cell) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string SpreadsheetLine(std::string_view line) {
  std::string out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(line.find(',', start), line.size());
    std::string cell(line.substr(start, end - start));
    for (char& ch : cell)
      if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
    const std::size_t first = cell.find_first_not_of(' ');
    if (first != std::string::npos && LooksLikeFormula(cell.substr(first)) &&
        !IsPlainNumber(cell.substr(first)))
      cell.insert(first, "'");
    out += cell;
    if (end == line.size()) return out;
    out += ',';
    start = end + 1;
  }
}

}  // namespace whirl
