#pragma once
// Strict numeric CSV, the one reader of every CSV file whirl takes: a header row of column names,
// then rows of finite decimal numbers. Lines starting with '#' are comments (data files carry
// their provenance there); blank lines are skipped. Every error names the file, the 1-based line
// and the column.
// Text: UTF-8 (RFC 3629). A byte-order mark at the start (what spreadsheet programs write) is
// skipped, so it can neither hide the first column's name nor turn a first '#' line into the
// header; a byte that is not UTF-8 anywhere (header, comment, cell) is an InputError naming the
// line, the column and the character position.
// Numbers: decimal only, [+-]digits[.digits][(e|E)[+-]digits] (also ".5" and "5."); hexadecimal
// floats (0x1p3), "inf", "nan" and every other form strtod would take are refused.
// Quotes: RFC 4180 ("Common Format and MIME Type for CSV Files", section 2), as a spreadsheet's
// "quote all text cells" export writes: a name or cell in double quotes (blanks around them
// dropped) keeps its text as it is, ',' and line breaks included, "" read as one '"'; a quoted
// number follows its column's number rules. A '"' inside an unquoted cell, text after a closing
// quote and a quote never closed are refused (file, line, column, character, the rule). A record
// whose quoted cell holds line breaks spans those file lines; line numbers are the file's (a
// row's is the line it starts on). A column name keeps the blanks inside its quotes, and loses
// the spreadsheet text marker whirl writes before a formula-like name (SpreadsheetText).
// FormatCsv writes every name through CsvTextCell, so every table it writes reads back.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/numbers.h"  // FormatNumber, the round-trip format of the cells

namespace whirl {

struct CsvTable {
  std::string source;                     ///< file name used in error messages
  std::vector<std::string> header;        ///< column names in file order
  std::vector<std::vector<double>> rows;  ///< one vector per data row, header.size() values each
  std::vector<int> line_numbers;          ///< 1-based file line of each row
  std::vector<std::string> comments;      ///< '#' lines without the leading '#', in order
  int header_line = 0;                    ///< 1-based file line of the header row

  /// Index of a column; InputError "file: missing column 'x' (have: ...)" if absent.
  std::size_t ColumnIndex(const std::string& name) const;
  bool HasColumn(const std::string& name) const;
  /// All values of one column.
  std::vector<double> Column(const std::string& name) const;
  /// All values of one column, which must increase strictly from row to row (a time or position
  /// axis); InputError "file:line: name must increase strictly (b after a)" otherwise.
  std::vector<double> IncreasingColumn(const std::string& name) const;
};

struct CsvOptions {
  bool allow_empty = false;  ///< a table without data rows is not an error
  /// Columns whose cells may be missing: an empty cell or "nan" (any case) reads as NaN (a logger
  /// that did not record time in some rows, drift/run_file.h); their other cells follow the
  /// number rules above.
  std::vector<std::string> missing_allowed;
};

/// Comment lines a CsvReader on a file keeps (the first ones: a logger may write many).
inline constexpr std::size_t kMaxCsvComments = 1000;
/// Longest record a CsvReader takes [bytes] (a run file of 512 columns needs about 15 kB): a line,
/// or the lines of a quoted cell holding line breaks (an unclosed quote stops here).
inline constexpr std::size_t kMaxCsvLineBytes = 16u << 20;

/// A CSV text read row by row by the rules of this header, for files too long to hold (a
/// machine's log of millions of rows): a file is read in chunks of 1 MiB and each row parsed once
/// into the caller's buffer, so memory does not grow with the file. The constructor reads up to
/// the header row; Next returns the data rows in order. A record without '"' (the common one) is
/// cut at its commas in place; one with quotes goes through the RFC 4180 rules above. The errors
/// are ParseCsv's, naming the
/// file, line and column; an invalid UTF-8 byte is reported on the line it is found on (ParseCsv
/// on text reports the first one in the text before any other error).
class CsvReader {
 public:
  /// A file: InputError if it cannot be opened or is not a regular file (CheckInputFile).
  CsvReader(const std::filesystem::path& path, const CsvOptions& options = {});
  /// In-memory text, named `source` in messages; keeps every comment.
  CsvReader(std::string text, std::string source, const CsvOptions& options = {});
  ~CsvReader();
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;

  const std::string& source() const;
  const std::vector<std::string>& header() const;
  int header_line() const;
  /// The '#' lines read so far (before and among the rows), at most kMaxCsvComments from a file.
  const std::vector<std::string>& comments() const;
  /// Index of a column; InputError "file: missing column 'x' (have: ...)" if absent.
  std::size_t ColumnIndex(const std::string& name) const;
  bool HasColumn(const std::string& name) const;

  /// The next data row: header().size() values into `row` (NaN for a missing cell of a
  /// missing_allowed column), its 1-based line into *line. False at the end of the text; then an
  /// InputError for a table without data rows (unless allow_empty).
  bool Next(double* row, int* line);
  /// The next data row without parsing it: only the trimmed text of cell `column` (the row's cell
  /// count is checked, the numbers are not); for a quick scan before the real pass.
  bool NextCell(std::size_t column, std::string* cell, int* line);
  long long rows() const;                 ///< data rows returned so far
  unsigned long long bytes_read() const;  ///< of the text, for progress
  unsigned long long total_bytes() const;  ///< the file's size (the text's)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Parses CSV text. Rejects: text that is not UTF-8, no header, an empty or duplicated column
/// name, a quote against RFC 4180, a row with the wrong number of cells, a cell that is not a
/// complete decimal number, NaN
/// or infinity (outside options.missing_allowed), and (unless options.allow_empty) a table with
/// no data row. `source` names the text in error messages.
CsvTable ParseCsv(const std::string& text, const std::string& source, const CsvOptions& options);
CsvTable ParseCsv(const std::string& text, const std::string& source, bool allow_empty = false);

/// Reads and parses a CSV file (InputError if it cannot be opened).
CsvTable ReadCsv(const std::filesystem::path& path, bool allow_empty = false);

/// The value of `text` when it is a finite decimal number by the rule above (a CSV cell, a
/// command-line number); nullopt otherwise ("0x1p3", "nan", "1e999", "1,5", "").
std::optional<double> ParseDecimal(const std::string& text);

/// Builds CSV text: optional '#' comment lines (SpreadsheetLine), a header of CsvTextCell names
/// (quoted where needed, formula-guarded) and rows (formatted by FormatNumber).
std::string FormatCsv(const std::vector<std::string>& header,
                      const std::vector<std::vector<double>>& rows,
                      const std::vector<std::string>& comments = {});

}  // namespace whirl
