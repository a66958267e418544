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

// The RFC 4180 rule quoted in every refusal of a quote.
constexpr const char* kQuoteRule =
    "(RFC 4180: a cell holding ',', '\"' or a line break is enclosed in double quotes, each '\"' "
    "in it doubled)";

// 1 + the commas of `text` outside double quotes (each '"' opens or closes a quoted cell; "" in
// one closes and reopens it): the CSV column of the byte after `text`.
std::size_t ColumnAfter(std::string_view text) {
  std::size_t column = 1;
  bool quoted = false;
  for (const char ch : text) {
    if (ch == '"') quoted = !quoted;
    column += !quoted && ch == ',';
  }
  return column;
}

// "source:line: column c, character k" of byte `offset` of a record starting on `first_line`
// (the text before it is UTF-8): the file line it is on, its CSV column, its character there.
std::string Place(std::string_view record, std::size_t offset, int first_line,
                  const std::string& source) {
  const std::string_view before = record.substr(0, offset);
  const std::size_t newline = before.rfind('\n');
  const std::string_view on_line =
      newline == std::string_view::npos ? before : before.substr(newline + 1);
  std::size_t character = 1;  // code points before the byte on its line
  for (const char ch : on_line) character += (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
  const auto line = first_line + std::count(before.begin(), before.end(), '\n');
  return source + ":" + std::to_string(line) + ": column " + std::to_string(ColumnAfter(before)) +
         ", character " + std::to_string(character);
}

// The text of a quoted cell whose '"' is at record[open], "" read as one '"'; *after is the
// index after its closing '"'. False when the cell is not closed.
bool QuotedCell(std::string_view record, std::size_t open, std::string* cell, std::size_t* after) {
  cell->clear();
  for (std::size_t i = open + 1; i < record.size(); ++i) {
    if (record[i] != '"') {
      *cell += record[i];
    } else if (i + 1 < record.size() && record[i + 1] == '"') {
      *cell += '"';
      ++i;
    } else {
      *after = i + 1;
      return true;
    }
  }
  return false;
}

// The cells of a record by RFC 4180 (section 2, rules 4-7): every ',' outside quotes ends one (a
// trailing ',' leaves an empty last cell); a cell in double quotes (blanks around them ignored)
// keeps its text as it is, ',' and line breaks included, "" read as '"'; any other cell is
// trimmed. A '"' inside an unquoted cell, text after a closing quote and a quote never closed
// are InputErrors naming the file, line, column, character and the rule.
std::vector<std::string> SplitCells(std::string_view record, int first_line,
                                    const std::string& source) {
  std::vector<std::string> cells;
  const auto refuse = [&](std::size_t at, const char* what) {
    throw InputError(Place(record, at, first_line, source) + ": " + what + " " + kQuoteRule);
  };
  for (std::size_t i = 0;;) {
    std::size_t start = i;
    while (start < record.size() && IsBlank(record[start])) ++start;
    std::size_t stop = 0;
    if (start < record.size() && record[start] == '"') {
      cells.emplace_back();
      if (!QuotedCell(record, start, &cells.back(), &stop))
        refuse(start, "the '\"' opening this cell is never closed");
      while (stop < record.size() && IsBlank(record[stop])) ++stop;
      if (stop < record.size() && record[stop] != ',')
        refuse(stop, "text after the closing '\"' of a quoted cell");
    } else {
      stop = std::min(record.find(',', i), record.size());
      const std::string_view cell = record.substr(i, stop - i);
      if (cell.find('"') != std::string_view::npos)
        refuse(i + cell.find('"'), "a '\"' inside a cell that does not start with one");
      cells.emplace_back(Trim(cell));
    }
    if (stop >= record.size()) return cells;
    i = stop + 1;
  }
}

// InputError at the first byte of a record (starting on file line `first_line`) that is not
// UTF-8: its line, CSV column and character position; nothing when the record is UTF-8.
void CheckUtf8(std::string_view record, int first_line, const std::string& source) {
  const std::size_t bad = InvalidUtf8Offset(record);
  if (bad == std::string_view::npos) return;
  char byte[8];
  std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(record[bad]));
  throw InputError(Place(record, bad, first_line, source) + ": byte " + byte +
                   " is not UTF-8 (save the file as UTF-8 text)");
}

// True when every byte is below 0x80 (the common case of a data row: no UTF-8 check needed).
bool IsAscii(std::string_view s) {
  unsigned char any = 0;
  for (const char ch : s) any |= static_cast<unsigned char>(ch);
  return any < 0x80;
}

// A header row without a ',' outside quotes but with a ';' or a tab there: a spreadsheet's export
// in a decimal-comma locale, named as such (not as one column called "a;b").
void CheckSeparator(std::string_view record, const std::string& where) {
  bool quoted = false;
  char separator = 0;
  for (const char ch : Trim(record)) {
    if (ch == '"') quoted = !quoted;
    if (quoted) continue;
    if (ch == ',') return;
    if ((ch == ';' || ch == '\t') && separator == 0) separator = ch;
  }
  if (separator != 0)
    throw InputError(where + ": the header is one column holding " +
                     (separator == ';' ? std::string("';'") : std::string("tabs")) +
                     ": whirl reads comma-separated files (',' between columns, '.' as the "
                     "decimal point); save the table as CSV with commas");
}

// Column names of the header row: none empty, none twice. The spreadsheet text marker whirl
// writes before a formula-like name (SpreadsheetCell) is not part of the name, as in a
// spreadsheet (SpreadsheetText).
std::vector<std::string> HeaderNames(std::vector<std::string> cells, const std::string& where) {
  std::set<std::string> seen;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (cells[c].empty())
      throw InputError(where + ": column " + std::to_string(c + 1) + " has an empty name");
    cells[c] = SpreadsheetText(cells[c]);
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

// Whether a record goes on past a line break: RFC 4180 lets a quoted cell hold one. The scan of
// the record so far, resumed line by line; a stray '"' counts as text here (SplitCells refuses
// it when the record is parsed).
struct QuoteScan {
  enum State { kCellStart, kUnquoted, kQuoted, kQuoteInQuoted } state = kCellStart;
  std::size_t opened = 0;  // offset of the '"' that opened the last quoted cell

  // Scans record[from, end): true when it ends inside a quoted cell.
  bool Open(std::string_view record, std::size_t from) {
    for (std::size_t i = from; i < record.size(); ++i) {
      const char ch = record[i];
      if (state == kCellStart && ch == '"') {
        state = kQuoted;
        opened = i;
      } else if (state == kCellStart) {
        state = ch == ',' || IsBlank(ch) ? kCellStart : kUnquoted;
      } else if (state == kUnquoted) {
        state = ch == ',' ? kCellStart : kUnquoted;
      } else if (state == kQuoted) {
        state = ch == '"' ? kQuoteInQuoted : kQuoted;
      } else {  // after a '"' in a quoted cell: "" goes on, anything else closed it
        state = ch == '"' ? kQuoted : ch == ',' ? kCellStart : kUnquoted;
      }
    }
    return state == kQuoted;
  }
};

}  // namespace

// The reader's state: the text (read in chunks from a file, or held), the record scanner and the
// header.
struct CsvReader::Impl {
  std::string source;
  CsvOptions options;
  int fd = -1;
  std::string buf;       // [pos, end) not yet scanned
  std::size_t pos = 0, end = 0;
  bool eof = false, first_line = true;
  unsigned long long consumed = 0, total = 0;
  std::size_t quote_from = std::string::npos, quote_at = 0, quote_end = 0;  // QuoteFrom's memo
  int line_no = 0;             // file lines read so far
  int record_line = 0;         // the first file line of the last record
  bool record_quoted = false;  // the last record holds a '"'
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
    if (pos > 0) {  // the unscanned rest (a partial record) to the front
      std::memmove(buf.data(), buf.data() + pos, end - pos);
      end -= pos;
      pos = 0;
      quote_from = std::string::npos;
    }
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

  // A UTF-8 byte-order mark at the start of the text is skipped (spreadsheets write one), so it
  // can neither hide the first column's name nor turn a first '#' line into the header.
  void SkipByteOrderMark() {
    first_line = false;
    while (end - pos < 3 && Fill()) {
    }
    if (std::string_view(buf.data() + pos, end - pos).substr(0, 3) == "\xEF\xBB\xBF") {
      pos += 3;
      consumed += 3;
    }
  }

  // The buffer index of the first '"' in buf[at, end), or `end` if none; memoized, so that a
  // text without quotes costs one memchr per chunk, not one per line.
  std::size_t QuoteFrom(std::size_t at) {
    if (at < quote_from || at > quote_at || (quote_at == quote_end && quote_end < end)) {
      const void* q = std::memchr(buf.data() + at, '"', end - at);
      quote_from = at;
      quote_end = end;
      quote_at = q ? static_cast<std::size_t>(static_cast<const char*>(q) - buf.data()) : end;
    }
    return quote_at;
  }

  // True when the line record[from, end) (record at buf[pos]) leaves the record inside a quoted
  // cell, so that the record goes on after the line break. A '#' comment line never does.
  bool Continues(std::string_view record, std::size_t from, QuoteScan* scan) {
    if (from == 0) {
      record_quoted = QuoteFrom(pos) < pos + record.size();
      if (!record_quoted) return false;
      const std::string_view trimmed = Trim(record);
      if (!trimmed.empty() && trimmed[0] == '#') return false;
    }
    return scan->Open(record, from);
  }

  // The buffer holds kMaxCsvLineBytes of one record that has not ended: the memory bound.
  [[noreturn]] void TooLong(std::string_view record, std::size_t from, QuoteScan* scan) const {
    const std::string mib = std::to_string(kMaxCsvLineBytes >> 20) + " MiB";
    if (from > 0 && scan->Open(record, from))
      throw InputError(Place(record, scan->opened, line_no + 1, source) +
                       ": the '\"' opening this cell is not closed within " + mib + " " +
                       kQuoteRule);
    throw InputError(source + ":" + std::to_string(line_no + 1) + ": a line longer than " + mib +
                     " (not a CSV table?)");
  }

  // The next record without its line break (and a '\r' before it): one line, or several when a
  // quoted cell holds line breaks; false at the end of the text.
  bool NextRecord(std::string_view* record) {
    if (first_line) SkipByteOrderMark();
    QuoteScan scan;
    std::size_t from = 0;  // the record's lines before `from` end inside a quoted cell
    for (;;) {
      const char* b = buf.data() + pos;
      const std::size_t avail = end - pos;
      const void* nl = std::memchr(b + from, '\n', avail - from);
      if (nl == nullptr && !eof && fd >= 0) {
        if (avail > kMaxCsvLineBytes) TooLong(std::string_view(b, avail), from, &scan);
        Fill();
        continue;
      }
      const std::size_t len = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - b) : avail;
      if (nl != nullptr && Continues(std::string_view(b, len), from, &scan)) {
        from = len + 1;
        continue;
      }
      if (nl == nullptr && len == 0) return false;
      *record = std::string_view(b, len);
      if (nl == nullptr && from == 0) record_quoted = QuoteFrom(pos) < pos + len;
      pos += len + (nl ? 1 : 0);
      consumed += len + (nl ? 1 : 0);
      record_line = line_no + 1;
      line_no = record_line +
                static_cast<int>(from > 0 ? std::count(record->begin(), record->end(), '\n') : 0);
      if (!record->empty() && record->back() == '\r') record->remove_suffix(1);
      return true;
    }
  }

  // Checks a record's UTF-8; true when it is blank or a '#' comment (kept in `comments`).
  bool Skip(std::string_view record) {
    if (!IsAscii(record)) CheckUtf8(record, record_line, source);
    const std::string_view trimmed = Trim(record);
    if (!trimmed.empty() && trimmed[0] != '#') return false;
    if (!trimmed.empty() && comments.size() < comment_cap)
      comments.emplace_back(Trim(trimmed.substr(1)));
    return true;
  }

  // The next record that is not blank or a comment; false at the end.
  bool NextDataRecord(std::string_view* record) {
    while (NextRecord(record))
      if (!Skip(*record)) return true;
    return false;
  }

  void ReadHeader(std::string_view record) {
    header_line = record_line;
    const std::string where = source + ":" + std::to_string(record_line);
    CheckSeparator(record, where);
    header = HeaderNames(SplitCells(record, record_line, source), where);
    for (const auto& h : header)
      may_miss.push_back(std::find(options.missing_allowed.begin(), options.missing_allowed.end(),
                                   h) != options.missing_allowed.end());
  }

  // Up to the header: blank and comment lines, then the header row itself.
  void Start() {
    std::string_view record;
    while (header_line == 0 && NextRecord(&record))
      if (!Skip(record)) ReadHeader(record);
    if (header_line == 0) throw InputError(source + ": empty file (no header row)");
  }

  // The cell count of a data row must be the header's.
  void CheckCellCount(std::size_t cells) const {
    if (cells != header.size())
      throw InputError(source + ":" + std::to_string(record_line) + ": expected " +
                       std::to_string(header.size()) + " cells, found " + std::to_string(cells));
  }

  // The cells of a record with quotes (SplitCells), as many as the header's.
  std::vector<std::string> QuotedCells(std::string_view record) const {
    std::vector<std::string> cells = SplitCells(record, record_line, source);
    CheckCellCount(cells.size());
    return cells;
  }

  // End of the text: a table without rows is refused unless allowed.
  bool Finish() {
    if (!finished && rows == 0 && !options.allow_empty)
      throw InputError(source + ": table has no data rows");
    finished = true;
    return false;
  }

  // Cell c of a data row (trimmed; a quoted cell's text) by the number rules of its column.
  void ParseCell(std::size_t c, std::string_view cell, double* row) const {
    if (may_miss[c] && IsMissing(cell)) {
      row[c] = NAN;
    } else if (!FastDecimal(cell, &row[c])) {
      row[c] = CellNumber(std::string(cell), source + ":" + std::to_string(record_line) +
                                                 ": column " + std::to_string(c + 1) + " ('" +
                                                 header[c] + "')");
    }
  }

  // A data record into row[0, header.size()): a record without quotes (the common one) is cut
  // at its commas in place, one with quotes goes through SplitCells.
  void ParseRow(std::string_view record, double* row) const {
    if (record_quoted) {
      const std::vector<std::string> cells = QuotedCells(record);
      for (std::size_t c = 0; c < header.size(); ++c) ParseCell(c, Trim(cells[c]), row);
      return;
    }
    CheckCellCount(1 + static_cast<std::size_t>(std::count(record.begin(), record.end(), ',')));
    for (std::size_t c = 0; c < header.size(); ++c) {
      const std::size_t comma = record.find(',');
      ParseCell(c, Trim(record.substr(0, comma)), row);
      record.remove_prefix(comma == std::string_view::npos ? record.size() : comma + 1);
    }
  }

  // The trimmed text of cell `column` of a data record (its cell count checked).
  std::string CellText(std::string_view record, std::size_t column) const {
    if (record_quoted) return std::string(Trim(QuotedCells(record)[column]));
    CheckCellCount(1 + static_cast<std::size_t>(std::count(record.begin(), record.end(), ',')));
    for (std::size_t c = 0; c < column; ++c) record.remove_prefix(record.find(',') + 1);
    return std::string(Trim(record.substr(0, record.find(','))));
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
  std::string_view record;
  if (!impl_->NextDataRecord(&record)) return impl_->Finish();
  impl_->ParseRow(record, row);
  *line = impl_->record_line;
  ++impl_->rows;
  return true;
}

bool CsvReader::NextCell(std::size_t column, std::string* cell, int* line) {
  std::string_view record;
  if (!impl_->NextDataRecord(&record)) return impl_->Finish();
  *cell = impl_->CellText(record, column);
  *line = impl_->record_line;
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
      CheckUtf8(body.substr(start, body.find('\n', bad) - start), static_cast<int>(line), source);
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
  // Comments and column names carry user text (names, paths), inert in a spreadsheet: a comment is
  // one line (SpreadsheetLine), a name one cell by RFC 4180 (CsvTextCell), which the reader above
  // gives back as it was.
  for (const auto& c : comments) out += "# " + SpreadsheetLine(c) + "\n";
  for (std::size_t i = 0; i < header.size(); ++i) out += (i ? "," : "") + CsvTextCell(header[i]);
  out += "\n";
  for (const auto& r : rows) {
    for (std::size_t i = 0; i < r.size(); ++i) out += (i ? "," : "") + FormatNumber(r[i]);
    out += "\n";
  }
  return out;
}

}  // namespace whirl
