// Run files streamed block by block (drift/run_file.h RunReader, ScanRun, SplitLogFile), and
// ParseRun / ReadRun on top of the same reader, so every rule and message has one home.
#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/safe_text.h"
#include "drift/run_file.h"

namespace whirl::drift {
namespace {

bool HasSuffix(const std::string& s, const std::string& suffix) {
  return s.size() > suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string ColumnList(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "none" : out;
}

CsvOptions RunCsvOptions() {
  CsvOptions csv;
  csv.missing_allowed = {"time_s", "time_min"};
  return csv;
}

// The columns of a run file by name (run_file.h header): time, _C, _um, the rest.
RunLayout LayoutOf(const CsvReader& csv, RunState state) {
  RunLayout l;
  l.source = csv.source();
  l.name = std::filesystem::path(l.source).stem().string();
  l.state = state;
  const std::vector<std::string>& header = csv.header();
  l.columns = header.size();
  const bool s = csv.HasColumn("time_s"), m = csv.HasColumn("time_min");
  if (s && m)
    throw InputError(l.source + ":" + std::to_string(csv.header_line()) +
                     ": two time columns ('time_s' and 'time_min'): give time_s or time_min, not "
                     "both");
  l.time_column = s ? "time_s" : m ? "time_min" : "";
  if (header.size() > static_cast<std::size_t>(kMaxRunColumns))
    throw InputError(l.source + ": " + std::to_string(header.size()) +
                     " columns: a run file holds at most " + std::to_string(kMaxRunColumns));
  for (std::size_t c = 0; c < header.size(); ++c) {
    const std::string& h = header[c];
    if (h == l.time_column) {
      l.time_index = c;
    } else if (HasSuffix(h, "_C")) {
      l.sensor_columns.push_back(c);
      l.sensor_names.push_back(h);
    } else if (HasSuffix(h, "_um")) {
      l.error_columns.push_back(c);
      l.error_names.push_back(h);
    } else {
      l.other_columns.push_back(c);
      l.other_names.push_back(h);
    }
  }
  if (l.sensor_columns.empty())
    throw InputError(l.source +
                     ": no temperature column (a name ending in _C, degC) in the header (" +
                     ColumnList(header) + ")");
  return l;
}

int IndexIn(const std::vector<std::string>& names, const std::string& name,
            const std::string& source, const char* kind) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  throw InputError(source + ": no " + kind + " column '" + name + "' (have: " + ColumnList(names) +
                   ")");
}

}  // namespace

Run RunLayout::EmptyRun() const {
  Run r;
  r.source = source;
  r.name = name;
  r.state = state;
  r.sensor_names = sensor_names;
  r.error_names = error_names;
  r.other_names = other_names;
  return r;
}

int RunLayout::SensorIndex(const std::string& n) const {
  return IndexIn(sensor_names, n, source, "temperature (_C)");
}
int RunLayout::ErrorIndex(const std::string& n) const {
  return IndexIn(error_names, n, source, "thermal-error (_um)");
}
int RunLayout::OtherIndex(const std::string& n) const {
  return IndexIn(other_names, n, source, "input");
}

struct RunReader::Impl {
  std::unique_ptr<CsvReader> csv;
  RunLayout layout;
  std::optional<bool> from_index;
  std::vector<double> row;
  long long rows = 0;
  bool missing = false, finished = false;
  double previous = NAN;  // the last recorded time cell, in the file's unit
  std::string violation;  // the first time that does not increase (checked at the end)

  Impl(std::unique_ptr<CsvReader> reader, RunState state, std::optional<bool> axis)
      : csv(std::move(reader)), layout(LayoutOf(*csv, state)), from_index(axis) {
    row.resize(layout.columns);
    if (layout.time_column.empty()) from_index = true;
  }

  [[noreturn]] void Refuse(int line, std::size_t column, double v, const std::string& rule) const {
    throw InputError(layout.source + ":" + std::to_string(line) + ": column '" +
                     csv->header()[column] + "': value " + FormatNumber(v) + " " + rule);
  }

  void Check(int line, std::size_t column, double v, double lo, double hi,
             const char* rule) const {
    if (!(v >= lo && v <= hi)) Refuse(line, column, v, rule);
  }

  // The row's time [min] by the axis; the cell's checks (range, strict increase).
  double Time(int line) {
    if (layout.time_column.empty()) return static_cast<double>(rows - 1);
    const double cell = row[layout.time_index];
    if (std::isnan(cell)) {
      missing = true;
      if (from_index == false)
        throw InputError(layout.source + ":" + std::to_string(line) + ": column '" +
                         layout.time_column +
                         "': the time cell is missing, but it was present when the file was "
                         "scanned (did the file change while it was read?)");
    } else {
      const double unit = layout.time_column == "time_s" ? 60.0 : 1.0;
      Check(line, layout.time_index, cell, -kMaxRunTimeMin * unit, kMaxRunTimeMin * unit,
            "is outside +-1e8 min (+-6e9 s, 190 years: even a time since 1970 fits; a larger "
            "time is a broken cell)");
      if (!std::isnan(previous) && !(cell > previous) && violation.empty()) {
        violation = layout.source + ":" + std::to_string(line) + ": " + layout.time_column +
                    " must increase strictly (" + FormatNumber(cell) + " after " +
                    FormatNumber(previous) + ")";
        if (from_index == false) throw InputError(violation);
      }
      previous = cell;
    }
    if (from_index == true) return static_cast<double>(rows - 1);
    return std::isnan(cell) ? NAN : cell * (layout.time_column == "time_s" ? 1.0 / 60.0 : 1.0);
  }

  void Store(RunRows* b, int k, int line) {
    const auto at = static_cast<Eigen::Index>(k);
    b->time_min[static_cast<std::size_t>(k)] = Time(line);
    b->line_numbers[static_cast<std::size_t>(k)] = line;
    for (std::size_t j = 0; j < layout.sensor_columns.size(); ++j) {
      const double v = row[layout.sensor_columns[j]];
      Check(line, layout.sensor_columns[j], v, kMinTemperatureC, kMaxTemperatureC,
            "is outside the plausible temperature range [-60, 400] degC");
      b->temperature_C(at, static_cast<Eigen::Index>(j)) = v;
    }
    for (std::size_t j = 0; j < layout.error_columns.size(); ++j) {
      const double v = row[layout.error_columns[j]];
      Check(line, layout.error_columns[j], v, -kMaxAbsErrorUm, kMaxAbsErrorUm,
            "is outside the plausible thermal-error range +-100000 um");
      b->error_um(at, static_cast<Eigen::Index>(j)) = v;
    }
    for (std::size_t j = 0; j < layout.other_columns.size(); ++j) {
      const double v = row[layout.other_columns[j]];
      Check(line, layout.other_columns[j], v, -kMaxAbsOtherValue, kMaxAbsOtherValue,
            "is outside +-1e15 (no input of a run is that large: a broken cell)");
      b->other(at, static_cast<Eigen::Index>(j)) = v;
    }
  }

  // The checks of the whole file, at its end.
  void Finish() {
    if (finished) return;
    finished = true;
    if (!missing && !violation.empty() && from_index != true) throw InputError(violation);
  }
};

RunReader::RunReader(const std::filesystem::path& path, RunState state,
                     std::optional<bool> time_from_index)
    : impl_(std::make_unique<Impl>(std::make_unique<CsvReader>(path, RunCsvOptions()), state,
                                   time_from_index)) {}

RunReader::RunReader(std::string text, const std::string& source, RunState state,
                     std::optional<bool> time_from_index)
    : impl_(std::make_unique<Impl>(
          std::make_unique<CsvReader>(std::move(text), source, RunCsvOptions()), state,
          time_from_index)) {}

RunReader::~RunReader() = default;

const RunLayout& RunReader::layout() const { return impl_->layout; }
long long RunReader::rows() const { return impl_->rows; }
bool RunReader::time_missing() const { return impl_->missing; }
double RunReader::fraction_read() const {
  const auto total = impl_->csv->total_bytes();
  return total > 0 ? static_cast<double>(impl_->csv->bytes_read()) / static_cast<double>(total)
                   : 1.0;
}

bool RunReader::Read(RunRows* b, int max_rows) {
  Impl& s = *impl_;
  const RunLayout& l = s.layout;
  const auto n = static_cast<Eigen::Index>(std::max(1, max_rows));
  b->first = s.rows;
  b->time_min.resize(static_cast<std::size_t>(n));
  b->line_numbers.resize(static_cast<std::size_t>(n));
  b->temperature_C.resize(n, static_cast<Eigen::Index>(l.sensor_columns.size()));
  b->error_um.resize(n, static_cast<Eigen::Index>(l.error_columns.size()));
  b->other.resize(n, static_cast<Eigen::Index>(l.other_columns.size()));
  int k = 0, line = 0;
  while (k < n && !s.finished && s.csv->Next(s.row.data(), &line)) {
    if (++s.rows > kMaxStreamRows)
      throw InputError(l.source + ":" + std::to_string(line) + ": more than " +
                       std::to_string(kMaxStreamRows) +
                       " rows: a run file holds at most that many (split the log)");
    s.Store(b, k++, line);
  }
  if (k < n) {
    s.Finish();
    b->time_min.resize(static_cast<std::size_t>(k));
    b->line_numbers.resize(static_cast<std::size_t>(k));
    b->temperature_C.conservativeResize(k, Eigen::NoChange);
    b->error_um.conservativeResize(k, Eigen::NoChange);
    b->other.conservativeResize(k, Eigen::NoChange);
  }
  b->count = k;
  return k > 0;
}

RunScan ScanRun(const std::filesystem::path& path) {
  CsvReader csv(path, RunCsvOptions());
  const RunLayout l = LayoutOf(csv, RunState::kUnknown);
  RunScan scan;
  std::string cell;
  int line = 0;
  const std::size_t column = l.time_column.empty() ? 0 : l.time_index;
  const double scale = l.time_column == "time_s" ? 1.0 / 60.0 : 1.0;
  bool missing = l.time_column.empty();
  while (csv.NextCell(column, &cell, &line)) {
    ++scan.rows;
    if (missing) continue;
    const std::optional<double> v = ParseDecimal(cell);
    if (!v) {  // missing (empty or nan), or a bad cell the real pass names
      std::string lower = cell;
      for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      missing = cell.empty() || lower == "nan";
      continue;
    }
    if (scan.rows == 1) scan.first_time = *v * scale;
    scan.penultimate_time = scan.last_time;
    scan.last_time = *v * scale;
  }
  scan.time_from_index = missing;
  if (missing) {
    scan.first_time = 0;
    scan.last_time = static_cast<double>(scan.rows - 1);
    scan.penultimate_time = static_cast<double>(scan.rows - 2);
  }
  return scan;
}

namespace {

// Every row of a reader into one Run (ParseRun, ReadRun: a run held whole, kMaxRunSamples).
Run CollectRun(RunReader& reader) {
  const RunLayout& l = reader.layout();
  std::vector<double> time, temps, errors, others;
  std::vector<int> lines;
  RunRows b;
  while (reader.Read(&b)) {
    if (reader.rows() > kMaxRunSamples)
      throw InputError(l.source + ": more than " + std::to_string(kMaxRunSamples) +
                       " rows: a run held whole in memory has at most that many (split the log "
                       "into runs; drift fit, predict, monitor --run, split and report stream "
                       "longer files)");
    for (int k = 0; k < b.count; ++k) {
      time.push_back(b.time_min[static_cast<std::size_t>(k)]);
      lines.push_back(b.line_numbers[static_cast<std::size_t>(k)]);
      for (Eigen::Index j = 0; j < b.temperature_C.cols(); ++j) temps.push_back(b.temperature_C(k, j));
      for (Eigen::Index j = 0; j < b.error_um.cols(); ++j) errors.push_back(b.error_um(k, j));
      for (Eigen::Index j = 0; j < b.other.cols(); ++j) others.push_back(b.other(k, j));
    }
  }
  Run r = l.EmptyRun();
  r.line_numbers = std::move(lines);
  const auto n = static_cast<Eigen::Index>(time.size());
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const auto matrix = [&](const std::vector<double>& v, std::size_t cols) {
    return Eigen::MatrixXd(
        Eigen::Map<const RowMajor>(v.data(), n, static_cast<Eigen::Index>(cols)));
  };
  r.temperature_C = matrix(temps, l.sensor_names.size());
  r.error_um = matrix(errors, l.error_names.size());
  r.other = matrix(others, l.other_names.size());
  r.time_from_index = l.time_column.empty() || reader.time_missing();
  r.time_min = std::move(time);
  if (r.time_from_index)
    for (std::size_t i = 0; i < r.time_min.size(); ++i) r.time_min[i] = static_cast<double>(i);
  return r;
}

}  // namespace

Run ParseRun(const std::string& text, const std::string& source, RunState state) {
  RunReader reader(text, source, state, std::nullopt);
  return CollectRun(reader);
}

Run ReadRun(const std::filesystem::path& path, RunState state) {
  RunReader reader(path, state, std::nullopt);
  return CollectRun(reader);
}

std::string FormatRunHeader(const RunLayout& l, bool time_from_index,
                            const std::vector<std::string>& comments) {
  std::vector<std::string> header;
  if (!time_from_index) header.push_back("time_min");
  for (const auto& v : {l.sensor_names, l.error_names, l.other_names})
    header.insert(header.end(), v.begin(), v.end());
  return FormatCsv(header, {}, comments);
}

void AppendRunRow(const RunRows& b, int k, bool time_from_index, std::string* out) {
  bool first = true;
  const auto cell = [&](double v) {
    if (!first) out->push_back(',');
    first = false;
    out->append(FormatNumber(v));
  };
  if (!time_from_index) cell(b.time_min[static_cast<std::size_t>(k)]);
  for (const Eigen::MatrixXd* m : {&b.temperature_C, &b.error_um, &b.other})
    for (Eigen::Index j = 0; j < m->cols(); ++j) cell((*m)(k, j));
  out->push_back('\n');
}

namespace {

// One run of SplitLogFile while its rows arrive: its rows are held as text up to 8 MiB, the rest
// goes to a scratch file in the staging folder; when it ends, the run file is its comments and
// header, then the rows.
class SplitPiece {
 public:
  SplitPiece(const std::filesystem::path& staging, const RunLayout& l, int number,
             bool time_from_index)
      : staging_(staging), time_from_index_(time_from_index) {
    run_.name = l.name + "_" + std::to_string(number);
    run_.file = Slug(run_.name) + ".csv";
  }

  void Add(const RunRows& b, int k) {
    if (run_.samples == 0) {
      run_.first_line = b.line_numbers[static_cast<std::size_t>(k)];
      run_.start_min = b.time_min[static_cast<std::size_t>(k)];
    }
    ++run_.samples;
    run_.last_line = b.line_numbers[static_cast<std::size_t>(k)];
    run_.end_min = b.time_min[static_cast<std::size_t>(k)];
    AppendRunRow(b, k, time_from_index_, &text_);
    if (text_.size() < (8u << 20)) return;
    if (!body_)
      body_ = std::make_unique<StreamedFile>(staging_ / ("body-" + run_.file.string()));
    body_->Append(text_);
    text_.clear();
  }

  // Writes the run file (beside <staging>/<file>) and hands it to `out`.
  SplitRun Finish(OutputDir& out, const RunLayout& l, const std::vector<std::string>& comments) {
    std::vector<std::string> c{run_.name + ": lines " + std::to_string(run_.first_line) + " to " +
                               std::to_string(run_.last_line) + " of " + l.source};
    c.insert(c.end(), comments.begin(), comments.end());
    StreamedFile file(staging_ / run_.file);
    file.Append(FormatRunHeader(l, time_from_index_, c));
    if (body_) {
      const std::filesystem::path body = body_->Finish(false);
      file.AppendFile(body);
      std::error_code ec;
      std::filesystem::remove(body, ec);
    }
    file.Append(text_);
    out.AddReady(run_.file.string(), file.Finish());
    return run_;
  }

 private:
  std::filesystem::path staging_;
  bool time_from_index_;
  SplitRun run_;
  std::string text_;
  std::unique_ptr<StreamedFile> body_;
};

}  // namespace

std::vector<SplitRun> SplitLogFile(const std::filesystem::path& log, const std::string& column,
                                   double threshold, const std::filesystem::path& dir,
                                   const std::vector<std::string>& comments,
                                   const std::string& what,
                                   const std::function<void(long long, double)>& progress) {
  if (!std::isfinite(threshold))
    throw InputError("split threshold " + FormatNumber(threshold) + ": must be a finite number");
  const RunScan scan = ScanRun(log);
  RunReader reader(log, RunState::kUnknown, scan.time_from_index);
  const RunLayout& l = reader.layout();
  const int c = l.OtherIndex(column);
  OutputDir out(dir, what);
  const std::filesystem::path staging = out.Staging();
  std::vector<SplitRun> runs;
  std::unique_ptr<SplitPiece> piece;
  double first = NAN, previous = NAN;
  bool seen_start = false;
  long long count = 0;  // runs begun (SplitAtStarts' starts)
  RunRows b;
  while (reader.Read(&b)) {
    for (int k = 0; k < b.count; ++k) {
      const double v = b.other(k, c);
      const bool start = !std::isnan(previous) && previous <= threshold && v > threshold;
      previous = v;
      if (std::isnan(first)) first = v;
      // The rows before the first start belong to the first run (SplitAtStarts): a log that
      // begins with the machine off does not cut there.
      const bool merge = start && !seen_start && first <= threshold;
      seen_start = seen_start || start;
      if (!piece || (start && !merge)) {
        ++count;
        if (count > kMaxSplitRuns) continue;  // only counted: the error below names the count
        if (piece) runs.push_back(piece->Finish(out, l, comments));
        piece = std::make_unique<SplitPiece>(staging, l, static_cast<int>(runs.size()) + 1,
                                             scan.time_from_index);
      }
      if (count <= kMaxSplitRuns) piece->Add(b, k);
    }
    if (progress) progress(reader.rows(), reader.fraction_read());
  }
  if (reader.rows() != scan.rows)
    throw InputError(l.source + ": " + std::to_string(reader.rows()) + " rows, but " +
                     std::to_string(scan.rows) + " when it was scanned (did the file change?)");
  if (count > kMaxSplitRuns)
    throw InputError(l.source + ": column '" + column + "' rises above " +
                     FormatNumber(threshold) + " " + std::to_string(count) +
                     " times: drift split writes at most " + std::to_string(kMaxSplitRuns) +
                     " run files (one per machine start); raise --threshold, choose another "
                     "--at column, or split a shorter part of the log");
  runs.push_back(piece->Finish(out, l, comments));
  for (SplitRun& r : runs) r.file = dir / r.file;
  out.Commit();
  return runs;
}

}  // namespace whirl::drift
