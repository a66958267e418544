#include "core/csv.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/safe_text.h"

namespace whirl {
namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) cells.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

// A UTF-8 byte-order mark (EF BB BF) at the start of the text is not part of the first line.
std::string WithoutByteOrderMark(const std::string& text) {
  return text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? text.substr(3) : text;
}

// InputError at the first byte that is not UTF-8: line, CSV column and character position.
void CheckUtf8(const std::string& text, const std::string& source) {
  const std::size_t bad = InvalidUtf8Offset(text);
  if (bad == std::string::npos) return;
  const std::size_t newline = bad == 0 ? std::string::npos : text.rfind('\n', bad - 1);
  const std::size_t line_start = newline == std::string::npos ? 0 : newline + 1;
  const std::string before = text.substr(line_start, bad - line_start);
  const auto line =
      1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(bad), '\n');
  const auto column = 1 + std::count(before.begin(), before.end(), ',');
  std::size_t character = 1;  // code points before the bad byte (the line before it is UTF-8)
  for (const char ch : before) character += (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
  char byte[8];
  std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(text[bad]));
  throw InputError(source + ":" + std::to_string(line) + ": column " + std::to_string(column) +
                   ", character " + std::to_string(character) + ": byte " + byte +
                   " is not UTF-8 (save the file as UTF-8 text)");
}

// Column names of the header row: none empty, none twice.
std::vector<std::string> HeaderNames(std::vector<std::string> cells, const std::string& where) {
  std::set<std::string> seen;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (cells[c].empty())
      throw InputError(where + ": column " + std::to_string(c + 1) + " has an empty name");
    // The spreadsheet text marker whirl writes before a formula-like name
    // (SpreadsheetCell) is not part of the name, as in a spreadsheet.
    if (cells[c].size() > 1 && cells[c][0] == '\'' && LooksLikeFormula(cells[c].substr(1)))
      cells[c].erase(0, 1);
    if (!seen.insert(cells[c]).second)
      throw InputError(where + ": duplicated column '" + cells[c] + "'");
  }
  return cells;
}

bool IsDigit(char ch) { return ch >= '0' && ch <= '9'; }

// [+-]digits[.digits][(e|E)[+-]digits], at least one digit before the exponent.
bool IsDecimalNumber(const std::string& s) {
  std::size_t i = 0, digits = 0;
  const std::size_t n = s.size();
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  for (; i < n && IsDigit(s[i]); ++i) ++digits;
  if (i < n && s[i] == '.')
    for (++i; i < n && IsDigit(s[i]); ++i) ++digits;
  if (digits == 0) return false;
  if (i < n && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
    std::size_t exponent = 0;
    for (; i < n && IsDigit(s[i]); ++i) ++exponent;
    if (exponent == 0) return false;
  }
  return i == n;
}

bool IsMissing(const std::string& cell) {
  if (cell.empty()) return true;
  std::string lower = cell;
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return lower == "nan";
}

// One data cell as a finite decimal number; `where` names file, line and column.
double CellNumber(const std::string& cell, const std::string& where) {
  if (cell.empty()) throw InputError(where + ": empty cell");
  char* end = nullptr;
  const double v = std::strtod(cell.c_str(), &end);
  if (end != cell.c_str() + cell.size())
    throw InputError(where + ": '" + cell + "' is not a number");
  if (!std::isfinite(v))
    throw InputError(where + ": '" + cell + "' is not finite (NaN and inf are rejected)");
  if (!IsDecimalNumber(cell))
    throw InputError(where + ": '" + cell +
                     "' is not a decimal number (digits, '.', an exponent; hexadecimal and other "
                     "forms are refused)");
  return v;
}

}  // namespace

std::size_t CsvTable::ColumnIndex(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  std::string have;
  for (const auto& h : header) have += (have.empty() ? "" : ", ") + h;
  throw InputError(source + ": missing column '" + name + "' (have: " + have + ")");
}

bool CsvTable::HasColumn(const std::string& name) const {
  for (const auto& h : header)
    if (h == name) return true;
  return false;
}

std::vector<double> CsvTable::Column(const std::string& name) const {
  const std::size_t c = ColumnIndex(name);
  std::vector<double> out;
  out.reserve(rows.size());
  for (const auto& r : rows) out.push_back(r[c]);
  return out;
}

std::vector<double> CsvTable::IncreasingColumn(const std::string& name) const {
  std::vector<double> v = Column(name);
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (!(v[i] > v[i - 1]))
      throw InputError(source + ":" + std::to_string(line_numbers[i]) + ": " + name +
                       " must increase strictly (" + FormatNumber(v[i]) + " after " +
                       FormatNumber(v[i - 1]) + ")");
  }
  return v;
}

CsvTable ParseCsv(const std::string& text, const std::string& source, const CsvOptions& options) {
  const std::string body = WithoutByteOrderMark(text);
  CheckUtf8(body, source);
  CsvTable t;
  t.source = source;
  std::istringstream in(body);
  std::string line;
  int line_no = 0;
  bool have_header = false;
  std::vector<bool> may_miss;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string trimmed = Trim(line);
    if (trimmed.empty()) continue;
    if (trimmed[0] == '#') {
      t.comments.push_back(Trim(trimmed.substr(1)));
      continue;
    }
    std::vector<std::string> cells = SplitCells(line);
    const std::string where = source + ":" + std::to_string(line_no);
    if (!have_header) {
      t.header = HeaderNames(cells, where);
      t.header_line = line_no;
      for (const auto& h : t.header)
        may_miss.push_back(std::find(options.missing_allowed.begin(), options.missing_allowed.end(),
                                     h) != options.missing_allowed.end());
      have_header = true;
      continue;
    }
    if (cells.size() != t.header.size()) {
      throw InputError(where + ": expected " + std::to_string(t.header.size()) + " cells, found " +
                       std::to_string(cells.size()));
    }
    std::vector<double> row(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string col_where =
          where + ": column " + std::to_string(c + 1) + " ('" + t.header[c] + "')";
      row[c] = may_miss[c] && IsMissing(cells[c]) ? NAN : CellNumber(cells[c], col_where);
    }
    t.rows.push_back(std::move(row));
    t.line_numbers.push_back(line_no);
  }
  if (!have_header) throw InputError(source + ": empty file (no header row)");
  if (t.rows.empty() && !options.allow_empty) throw InputError(source + ": table has no data rows");
  return t;
}

CsvTable ParseCsv(const std::string& text, const std::string& source, bool allow_empty) {
  CsvOptions options;
  options.allow_empty = allow_empty;
  return ParseCsv(text, source, options);
}

CsvTable ReadCsv(const std::filesystem::path& path, bool allow_empty) {
  return ParseCsv(ReadTextFile(path), path.string(), allow_empty);
}

std::optional<double> ParseDecimal(const std::string& text) {
  if (!IsDecimalNumber(text)) return std::nullopt;
  const double v = std::strtod(text.c_str(), nullptr);
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

std::string FormatCsv(const std::vector<std::string>& header,
                      const std::vector<std::vector<double>>& rows,
                      const std::vector<std::string>& comments) {
  std::string out;
  // Comments and header carry user text (names, paths): one line each (a newline in a name must
  // not start a data row) and inert in a spreadsheet (SpreadsheetLine).
  for (const auto& c : comments) out += "# " + SpreadsheetLine(c) + "\n";
  std::string names;
  for (std::size_t i = 0; i < header.size(); ++i) names += (i ? "," : "") + header[i];
  out += SpreadsheetLine(names) + "\n";
  for (const auto& r : rows) {
    for (std::size_t i = 0; i < r.size(); ++i) out += (i ? "," : "") + FormatNumber(r[i]);
    out += "\n";
  }
  return out;
}

}  // namespace whirl
