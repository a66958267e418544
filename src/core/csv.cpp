#include "core/csv.h"

#include <charconv>
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

CsvTable ParseCsv(const std::string& text, const std::string& source, bool allow_empty) {
  CsvTable t;
  t.source = source;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool have_header = false;
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
      t.header = cells;
      have_header = true;
      continue;
    }
    if (cells.size() != t.header.size()) {
      throw InputError(where + ": expected " + std::to_string(t.header.size()) + " cells, found " +
                       std::to_string(cells.size()));
    }
    std::vector<double> row(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string& cell = cells[c];
      const std::string col_where =
          where + ": column " + std::to_string(c + 1) + " ('" + t.header[c] + "')";
      if (cell.empty()) throw InputError(col_where + ": empty cell");
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end != cell.c_str() + cell.size())
        throw InputError(col_where + ": '" + cell + "' is not a number");
      if (!std::isfinite(v))
        throw InputError(col_where + ": '" + cell + "' is not finite (NaN and inf are rejected)");
      row[c] = v;
    }
    t.rows.push_back(std::move(row));
    t.line_numbers.push_back(line_no);
  }
  if (!have_header) throw InputError(source + ": empty file (no header row)");
  if (t.rows.empty() && !allow_empty) throw InputError(source + ": table has no data rows");
  return t;
}

CsvTable ReadCsv(const std::filesystem::path& path, bool allow_empty) {
  return ParseCsv(ReadTextFile(path), path.string(), allow_empty);
}

std::string FormatNumber(double x) {
  char buf[64];
  for (int prec = 6; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
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
