#pragma once
// Strict numeric CSV: a header row of column names, then rows of finite numbers.
// Lines starting with '#' are comments (data files carry their provenance there); blank lines are
// skipped. Every error names the file, the 1-based line and the column.
#include <filesystem>
#include <string>
#include <vector>

namespace whirl {

struct CsvTable {
  std::string source;                     ///< file name used in error messages
  std::vector<std::string> header;        ///< column names in file order
  std::vector<std::vector<double>> rows;  ///< one vector per data row, header.size() values each
  std::vector<int> line_numbers;          ///< 1-based file line of each row
  std::vector<std::string> comments;      ///< '#' lines without the leading '#', in order

  /// Index of a column; InputError "file: missing column 'x' (have: ...)" if absent.
  std::size_t ColumnIndex(const std::string& name) const;
  bool HasColumn(const std::string& name) const;
  /// All values of one column.
  std::vector<double> Column(const std::string& name) const;
  /// All values of one column, which must increase strictly from row to row (a time or position
  /// axis); InputError "file:line: name must increase strictly (b after a)" otherwise.
  std::vector<double> IncreasingColumn(const std::string& name) const;
};

/// Parses CSV text. Rejects: no header, an empty or duplicated column name, a row with the wrong
/// number of cells, a cell that is not a complete number, NaN or infinity, and (unless
/// allow_empty) a table with no data row. `source` names the text in error messages.
CsvTable ParseCsv(const std::string& text, const std::string& source, bool allow_empty = false);

/// Reads and parses a CSV file (InputError if it cannot be opened).
CsvTable ReadCsv(const std::filesystem::path& path, bool allow_empty = false);

/// Formats a number for CSV/JSON-like text output with round-trip precision (17 significant
/// digits, shortest form that parses back to the same double).
std::string FormatNumber(double x);

/// Builds CSV text: optional '#' comment lines, a header, and rows (formatted by FormatNumber).
std::string FormatCsv(const std::vector<std::string>& header,
                      const std::vector<std::vector<double>>& rows,
                      const std::vector<std::string>& comments = {});

}  // namespace whirl
