#include "core/csv.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <set>
#include <string_view>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/safe_text.h"

namespace whirl {
namespace {

bool IsBlank(char ch) { return ch == ' ' || ch == '\t' || ch == '\r'; }

std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
  return s;
}

// The cells of a line: every ',' ends one (a trailing ',' leaves an empty last cell), each trimmed.
std::vector<std::string> SplitCells(std::string_view line) {
  std::vector<std::string> cells;
  for (;;) {
    const std::size_t comma = line.find(',');
    cells.emplace_back(Trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return cells;
    line.remove_prefix(comma + 1);
  }
}

// InputError at the first byte of `line` that is not UTF-8: line, CSV column and character
// position; nothing when the line is UTF-8.
void CheckUtf8Line(std::string_view line, int line_no, const std::string& source) {
  const std::size_t bad = InvalidUtf8Offset(line);
  if (bad == std::string_view::npos) return;
  const std::string_view before = line.substr(0, bad);
  const auto column = 1 + std::count(before.begin(), before.end(), ',');
  std::size_t character = 1;  // code points before the bad byte (the line before it is UTF-8)
  for (const char ch : before) character += (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
  char byte[8];
  std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(line[bad]));
  throw InputError(source + ":" + std::to_string(line_no) + ": column " + std::to_string(column) +
                   ", character " + std::to_string(character) + ": byte " + byte +
                   " is not UTF-8 (save the file as UTF-8 text)");
}

// True when every byte is below 0x80 (the common case of a data row: no UTF-8 check needed).
bool IsAscii(std::string_view s) {
  unsigned char any = 0;
  for (const char ch : s) any |= static_cast<unsigned char>(ch);
  return any < 0x80;
}

// Column names of the header row: none empty, none twice, and not one name holding a ';' or a
// tab (a spreadsheet's export in a decimal-comma locale).
std::vector<std::string> HeaderNames(std::vector<std::string> cells, const std::string& where) {
  if (cells.size() == 1)
    for (const char sep : {';', '\t'})
      if (cells[0].find(sep) != std::string::npos)
        throw InputError(where + ": the header is one column holding " +
                         (sep == ';' ? std::string("';'") : std::string("tabs")) +
                         ": whirl reads comma-separated files (',' between columns, '.' as the "
                         "decimal point); save the table as CSV with commas");
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
bool IsDecimalNumber(std::string_view s) {
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

bool IsMissing(std::string_view cell) {
  if (cell.empty()) return true;
  return cell.size() == 3 && (cell[0] | 0x20) == 'n' && (cell[1] | 0x20) == 'a' &&
         (cell[2] | 0x20) == 'n';
}

// One data cell as a finite decimal number; `where` names file, line and column. The slow path
// of CellValue, which also words every refusal.
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

// A decimal cell by std::from_chars (correctly rounded, as strtod), else CellNumber's answer.
bool FastDecimal(std::string_view cell, double* v) {
  if (!IsDecimalNumber(cell)) return false;
  if (cell.front() == '+') cell.remove_prefix(1);  // from_chars takes no '+'
  const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), *v);
  return r.ec == std::errc() && r.ptr == cell.data() + cell.size() && std::isfinite(*v);
}

constexpr std::size_t kChunkBytes = 1u << 20;

}  // namespace

// The reader's state: the text (read in chunks from a file, or held), the line scanner and the
// header.
struct CsvReader::Impl {
  std::string source;
  CsvOptions options;
  int fd = -1;
  std::string buf;       // [pos, end) not yet scanned
  std::size_t pos = 0, end = 0;
  bool eof = false, first_line = true;
  unsigned long long consumed = 0, total = 0;
  int line_no = 0;
  std::size_t comment_cap = std::numeric_limits<std::size_t>::max();
  std::vector<std::string> header, comments;
  std::vector<bool> may_miss;
  int header_line = 0;
  long long rows = 0;
  bool finished = false;

  ~Impl() {
    if (fd >= 0) ::close(fd);
  }

  // Reads more text into the buffer; false at the end of the file.
  bool Fill() {
    if (eof) return false;
    if (pos > 0) {  // the unscanned rest (a partial line) to the front
      std::memmove(buf.data(), buf.data() + pos, end - pos);
      end -= pos;
      pos = 0;
    }
    if (end > kMaxCsvLineBytes)  // the buffer holds the current line alone
      throw InputError(source + ":" + std::to_string(line_no + 1) + ": a line longer than " +
                       std::to_string(kMaxCsvLineBytes >> 20) + " MiB (not a CSV table?)");
    if (buf.size() - end < kChunkBytes) buf.resize(end + kChunkBytes);  // grows, never shrinks
    for (;;) {
      const ssize_t n = ::read(fd, buf.data() + end, buf.size() - end);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw InputError("cannot read '" + source + "': " + std::strerror(errno));
      if (n == 0) eof = true;
      end += static_cast<std::size_t>(n);
      return n > 0;
    }
  }

  // The next line without its '\n' (and a final '\r'); false at the end of the text.
  bool NextLine(std::string_view* line) {
    for (;;) {
      const char* b = buf.data() + pos;
      const void* nl = std::memchr(b, '\n', end - pos);
      if (nl != nullptr || (eof || fd < 0)) {
        const std::size_t len = nl ? static_cast<const char*>(nl) - b : end - pos;
        if (!nl && len == 0) return false;
        *line = std::string_view(b, len);
        pos += len + (nl ? 1 : 0);
        consumed += len + (nl ? 1 : 0);
        ++line_no;
        if (first_line) {  // a UTF-8 byte-order mark is not part of the first line
          first_line = false;
          if (line->substr(0, 3) == "\xEF\xBB\xBF") line->remove_prefix(3);
        }
        if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
        return true;
      }
      Fill();
    }
  }

  // The next line that is not blank, a comment or (once) the header; false at the end.
  bool NextDataLine(std::string_view* line) {
    while (NextLine(line)) {
      if (!IsAscii(*line)) CheckUtf8Line(*line, line_no, source);
      const std::string_view trimmed = Trim(*line);
      if (trimmed.empty()) continue;
      if (trimmed[0] == '#') {
        if (comments.size() < comment_cap) comments.emplace_back(Trim(trimmed.substr(1)));
        continue;
      }
      if (header_line == 0) {
        ReadHeader(*line);
        continue;
      }
      return true;
    }
    return false;
  }

  void ReadHeader(std::string_view line) {
    header = HeaderNames(SplitCells(line), source + ":" + std::to_string(line_no));
    header_line = line_no;
    for (const auto& h : header)
      may_miss.push_back(std::find(options.missing_allowed.begin(), options.missing_allowed.end(),
                                   h) != options.missing_allowed.end());
  }

  void Start() {
    std::string_view line;
    // Up to the header: blank and comment lines, then the header row itself.
    while (header_line == 0 && NextLine(&line)) {
      if (!IsAscii(line)) CheckUtf8Line(line, line_no, source);
      const std::string_view trimmed = Trim(line);
      if (trimmed.empty()) continue;
      if (trimmed[0] == '#') {
        if (comments.size() < comment_cap) comments.emplace_back(Trim(trimmed.substr(1)));
        continue;
      }
      ReadHeader(line);
    }
    if (header_line == 0) throw InputError(source + ": empty file (no header row)");
  }

  // The cell count of a data row must be the header's.
  void CheckCellCount(std::string_view line) const {
    const auto cells = 1 + static_cast<std::size_t>(std::count(line.begin(), line.end(), ','));
    if (cells != header.size())
      throw InputError(source + ":" + std::to_string(line_no) + ": expected " +
                       std::to_string(header.size()) + " cells, found " + std::to_string(cells));
  }

  // End of the text: a table without rows is refused unless allowed.
  bool Finish() {
    if (!finished && rows == 0 && !options.allow_empty)
      throw InputError(source + ": table has no data rows");
    finished = true;
    return false;
  }

  void ParseRow(std::string_view line, double* row) const {
    for (std::size_t c = 0; c < header.size(); ++c) {
      const std::size_t comma = line.find(',');
      const std::string_view cell = Trim(line.substr(0, comma));
      line.remove_prefix(comma == std::string_view::npos ? line.size() : comma + 1);
      if (may_miss[c] && IsMissing(cell)) {
        row[c] = NAN;
      } else if (!FastDecimal(cell, &row[c])) {
        row[c] = CellNumber(std::string(cell), source + ":" + std::to_string(line_no) +
                                                   ": column " + std::to_string(c + 1) + " ('" +
                                                   header[c] + "')");
      }
    }
  }
};

CsvReader::CsvReader(const std::filesystem::path& path, const CsvOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->source = path.string();
  impl_->options = options;
  impl_->total = CheckInputFile(path);
  impl_->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (impl_->fd < 0)
    throw InputError("cannot open '" + path.string() + "': " + std::strerror(errno));
  impl_->comment_cap = kMaxCsvComments;
  impl_->Start();
}

CsvReader::CsvReader(std::string text, std::string source, const CsvOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->source = std::move(source);
  impl_->options = options;
  impl_->total = text.size();
  impl_->end = text.size();
  impl_->buf = std::move(text);
  impl_->eof = true;
  impl_->Start();
}

CsvReader::~CsvReader() = default;

const std::string& CsvReader::source() const { return impl_->source; }
const std::vector<std::string>& CsvReader::header() const { return impl_->header; }
int CsvReader::header_line() const { return impl_->header_line; }
const std::vector<std::string>& CsvReader::comments() const { return impl_->comments; }
long long CsvReader::rows() const { return impl_->rows; }
unsigned long long CsvReader::bytes_read() const { return impl_->consumed; }
unsigned long long CsvReader::total_bytes() const { return impl_->total; }

std::size_t CsvReader::ColumnIndex(const std::string& name) const {
  const auto& header = impl_->header;
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  std::string have;
  for (const auto& h : header) have += (have.empty() ? "" : ", ") + h;
  throw InputError(impl_->source + ": missing column '" + name + "' (have: " + have + ")");
}

bool CsvReader::HasColumn(const std::string& name) const {
  return std::find(impl_->header.begin(), impl_->header.end(), name) != impl_->header.end();
}

bool CsvReader::Next(double* row, int* line) {
  std::string_view text;
  if (!impl_->NextDataLine(&text)) return impl_->Finish();
  impl_->CheckCellCount(text);
  impl_->ParseRow(text, row);
  *line = impl_->line_no;
  ++impl_->rows;
  return true;
}

bool CsvReader::NextCell(std::size_t column, std::string* cell, int* line) {
  std::string_view text;
  if (!impl_->NextDataLine(&text)) return impl_->Finish();
  impl_->CheckCellCount(text);
  for (std::size_t c = 0; c < column; ++c) text.remove_prefix(text.find(',') + 1);
  cell->assign(Trim(text.substr(0, text.find(','))));
  *line = impl_->line_no;
  ++impl_->rows;
  return true;
}

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
  {  // the first byte that is not UTF-8, wherever it is, before any other error (as always)
    const std::string_view body =
        std::string_view(text).substr(text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0);
    const std::size_t bad = InvalidUtf8Offset(body);
    if (bad != std::string_view::npos) {
      const std::size_t newline = bad == 0 ? std::string_view::npos : body.rfind('\n', bad - 1);
      const std::size_t start = newline == std::string_view::npos ? 0 : newline + 1;
      const auto line = 1 + std::count(body.begin(), body.begin() + static_cast<std::ptrdiff_t>(start), '\n');
      CheckUtf8Line(body.substr(start, body.find('\n', bad) - start), static_cast<int>(line),
                    source);
    }
  }
  CsvReader reader(text, source, options);
  CsvTable t;
  t.source = source;
  t.header = reader.header();
  t.header_line = reader.header_line();
  std::vector<double> row(t.header.size());
  int line = 0;
  while (reader.Next(row.data(), &line)) {
    t.rows.push_back(row);
    t.line_numbers.push_back(line);
  }
  t.comments = reader.comments();
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
