#pragma once
// Run files of machine thermal drift (after Miao et al.): one CSV per run (a warm-up, a day, a
// batch) with a header row. Columns are recognized by name:
//   time_s or time_min   time of the sample [s] or [min] (at most one of them; optional). Cells
//                        may be empty or `nan` where the source did not record time: then the
//                        whole run uses the sample index as its time axis (Run::time_from_index,
//                        time_min = 0, 1, 2, ... in samples) and every output says so. Recorded
//                        times must increase strictly.
//   <name>_C             a temperature [degC], absolute or already a rise (at least one column).
//   <name>_um            a thermal-error (displacement) channel [um] (optional: a run to be
//                        predicted needs none).
//   anything else        an optional input carried along (e.g. spindle_rpm), used only when a
//                        model names it.
// Cells other than time must be finite numbers; '#' lines are comments (provenance), as in
// core/csv.h. A run's state (idle or cutting, Miao et al.'s two conditions) is not in the file: it
// comes from the command line (--idle / --cutting) or the caller.
// Limits (resource and plausibility, stated in the messages): kMaxRunColumns columns;
// temperatures within [-60, 400] degC; errors within +-100000 um; times within +-kMaxRunTimeMin (190
// years); every other column within +-kMaxAbsOtherValue. Rows: a run held whole in memory (Run, ReadRun: drift
// select, crossval, holdout, monitor --day, every library caller) has at most kMaxRunSamples; the
// commands that stream a file (RunReader: drift fit, predict, monitor --run, split, report) keep
// memory independent of its length and take up to kMaxStreamRows.
#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace whirl::drift {

inline constexpr int kMaxRunSamples = 2'000'000;
/// Rows of a run file streamed (RunReader): 10^9, 31 years of 1-s samples; the streaming commands'
/// memory does not grow with them (docs/security-and-limits.md).
inline constexpr long long kMaxStreamRows = 1'000'000'000;
inline constexpr int kMaxRunColumns = 512;
inline constexpr double kMinTemperatureC = -60.0;
inline constexpr double kMaxTemperatureC = 400.0;
inline constexpr double kMaxAbsErrorUm = 100000.0;
/// Largest |time| of a run [min] (time_s: 60 times it): 190 years, so even minutes or seconds
/// since 1970 fit; 1e300 min would be written back and break every time difference.
inline constexpr double kMaxRunTimeMin = 1e8;
/// Largest |value| of any other column (spindle_rpm, power, ... in their own units).
inline constexpr double kMaxAbsOtherValue = 1e15;

/// Miao et al.'s two operating conditions of a run (plus "not stated").
enum class RunState { kUnknown, kIdle, kCutting };
std::string ToString(RunState s);                 ///< "unknown", "idle", "cutting"
RunState ParseRunState(const std::string& text);  ///< inverse; InputError otherwise

struct Run {
  std::string name;    ///< label used in tables (file stem by default)
  std::string source;  ///< file name used in messages
  RunState state = RunState::kUnknown;
  /// Time of each sample [min]; the sample index when time_from_index.
  std::vector<double> time_min;
  bool time_from_index = false;   ///< true: the file recorded no (complete) time column
  std::vector<int> line_numbers;  ///< 1-based file line of each sample

  std::vector<std::string> sensor_names;  ///< the `_C` columns, in file order
  Eigen::MatrixXd temperature_C;          ///< samples x sensors [degC]
  std::vector<std::string> error_names;   ///< the `_um` columns, in file order
  Eigen::MatrixXd error_um;               ///< samples x error channels [um]
  std::vector<std::string> other_names;   ///< every other column
  Eigen::MatrixXd other;                  ///< samples x other columns (their own units)

  int samples() const { return static_cast<int>(time_min.size()); }
  /// Temperature rises relative to the run's first row: dT(k, s) = T(k, s) - T(0, s) [K].
  Eigen::MatrixXd Rises() const;
  /// Column index by name; InputError naming the run, the name and the available columns.
  int SensorIndex(const std::string& name) const;
  int ErrorIndex(const std::string& name) const;
  int OtherIndex(const std::string& name) const;
  /// Rows [begin, end) as a new run named `name` (its rises start again at its own first row).
  Run Slice(int begin, int end, const std::string& name) const;
};

/// The zero of the thermal error: what "no error" means, for the model and for every figure it is
/// compared with (no compensation, the sensor-free baselines). One convention per model, chosen
/// when it is fitted and stored in the model file; every evaluation applies the same one.
///   run-start  e(k) - e(0): the error gained since the run started, the counterpart of the rises
///              (the temperature reference of training, ReferenceMode::kRunStart); for a machine
///              that is referenced (homed or probed) at each run start, and for runs cut from a
///              longer log. A constant gauge level cancels exactly. The default.
///   fixed      e(k) - L: one gauge level L [um] for every run (default: the first row of the
///              first training run), for a machine that is never re-referenced.
///   as-logged  e(k) as in the file: only for models written before the convention existed
///              (schema 1); evaluations warn, since "no compensation" then moves with any gauge
///              level while the model's intercept absorbs it.
enum class ErrorZero { kRunStart, kFixed, kAsLogged };
std::string ToString(ErrorZero z);                 ///< "run-start", "fixed", "as-logged"
ErrorZero ParseErrorZero(const std::string& text);  ///< inverse (run-start, fixed); InputError

struct ZeroConvention {
  ErrorZero zero = ErrorZero::kRunStart;
  /// fixed: the gauge level L [um]; NaN: the first row of the first training run.
  double gauge_level_um = std::numeric_limits<double>::quiet_NaN();
};

/// The run with every error channel on the convention's zero (see ErrorZero). fixed needs a
/// finite gauge_level_um (InputError otherwise); as-logged returns the run unchanged.
Run ApplyErrorZero(const Run& run, const ZeroConvention& zero);
/// ApplyErrorZero(run, run-start).
Run ErrorsFromStart(const Run& run);

/// Parses run-file text; `source` names it in messages. InputError (file:line: column 'x': value
/// 'v': rule) on any broken rule.
Run ParseRun(const std::string& text, const std::string& source, RunState state);
/// Reads a run file; the run's name is the file stem.
Run ReadRun(const std::filesystem::path& path, RunState state);

/// Writes a run back in the same format (time_min column, or none when time_from_index) with
/// optional comment lines (the caller writes it with WriteFileAtomic).
std::string FormatRun(const Run& run, const std::vector<std::string>& comments = {});

/// Writes each run as <dir>/<Slug(name)>.csv (FormatRun with `comments` plus the run's own
/// source lines) through core/output_dir.h's OutputDir: `dir` follows the output-directory rule
/// (`what` names it in messages, e.g. "--out-dir"), and the files are written all or nothing.
/// Returns the paths in run order.
std::vector<std::filesystem::path> WriteRuns(const std::filesystem::path& dir,
                                             const std::vector<Run>& runs,
                                             const std::vector<std::string>& comments,
                                             const std::string& what = "run directory");

/// Most runs SplitAtStarts makes (one file each): a log of a year with ten machine starts a day
/// has 3650; more is a --threshold below the column's idle noise, not machine starts.
inline constexpr int kMaxSplitRuns = 10000;

/// Cuts one long log into runs, a new run starting at every sample where `column` (an `other`
/// column such as spindle_rpm) changes from <= threshold to > threshold (a machine start). The
/// first run also holds the rows before the first start. Names: "<run.name>_<k>" (k from 1).
/// More than kMaxSplitRuns starts is an InputError naming the file, the column and the count.
/// Memory: the runs together hold the log once (each Slice copies only its rows).
/// SplitLogFile streams the same rule.
std::vector<Run> SplitAtStarts(const Run& run, const std::string& column, double threshold = 0.0);

// ---- Streaming: run files longer than memory (a year of a machine's log) --------------------

/// A run file's columns sorted into the Run's groups (by name, as the header comment says).
struct RunLayout {
  std::string source, name;  ///< file name for messages; the run's name (file stem)
  RunState state = RunState::kUnknown;
  std::string time_column;  ///< "time_s", "time_min" or "" (none)
  std::vector<std::string> sensor_names, error_names, other_names;
  std::size_t time_index = 0;  ///< CSV column of the time (when time_column is set)
  std::vector<std::size_t> sensor_columns, error_columns, other_columns;  ///< CSV columns
  std::size_t columns = 0;  ///< all CSV columns
  int SensorIndex(const std::string& name) const;  ///< InputError as Run::SensorIndex
  /// A Run with this layout's source, name, state and column names, and no samples yet.
  Run EmptyRun() const;
  int ErrorIndex(const std::string& name) const;
  int OtherIndex(const std::string& name) const;
};

/// What a quick pass over a run file finds (only the time cells are read): the data rows, whether
/// every row recorded its time, and the first, second-to-last and last time [min; the sample
/// index when time_from_index]. The streaming commands scan first: a run's time axis (recorded or
/// the sample index) must be known before the first lag is computed.
struct RunScan {
  long long rows = 0;
  bool time_from_index = false;
  double first_time = 0, penultimate_time = 0, last_time = 0;
};
RunScan ScanRun(const std::filesystem::path& path);

/// A block of consecutive rows of a run (RunReader::Read): per group a rows x columns matrix.
struct RunRows {
  int count = 0;
  long long first = 0;           ///< index of the block's first row in the run
  std::vector<double> time_min;  ///< [min]; the row index with a sample-index time axis; NaN:
                                 ///< a missing cell when the axis is not decided yet
  Eigen::MatrixXd temperature_C, error_um, other;
  std::vector<int> line_numbers;
};

/// A run file read block by block with ParseRun's rules and messages (core/csv.h's CsvReader
/// underneath: memory independent of the file's length). The time axis: `time_from_index` true
/// (the sample index), false (recorded; every cell must be present) or unset (not decided yet:
/// missing cells read NaN and time_missing() says so; the strict increase of recorded times is
/// checked at the end, only when no cell was missing, as ParseRun). Errors name file, line,
/// column, value and rule; the end-of-file checks (no data rows, times not increasing, more than
/// kMaxStreamRows rows) come from the Read that returns false.
class RunReader {
 public:
  RunReader(const std::filesystem::path& path, RunState state,
            std::optional<bool> time_from_index);
  /// In-memory text named `source` (ParseRun).
  RunReader(std::string text, const std::string& source, RunState state,
            std::optional<bool> time_from_index);
  ~RunReader();
  RunReader(const RunReader&) = delete;
  RunReader& operator=(const RunReader&) = delete;

  const RunLayout& layout() const;
  /// Up to `max_rows` next rows into *block (its matrices resized); false at the end of the file.
  bool Read(RunRows* block, int max_rows = 4096);
  long long rows() const;     ///< rows read so far
  bool time_missing() const;  ///< a time cell was empty or nan (unset axis)
  double fraction_read() const;  ///< of the file's bytes, for progress

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The run-file text of a layout's columns as FormatRun writes them: comments, header
/// (time_min unless `time_from_index`, sensors, errors, others).
std::string FormatRunHeader(const RunLayout& layout, bool time_from_index,
                            const std::vector<std::string>& comments);
/// Appends row k of a block in FormatRun's format (FormatNumber cells, '\n').
void AppendRunRow(const RunRows& block, int k, bool time_from_index, std::string* out);

/// One run written by SplitLogFile.
struct SplitRun {
  std::string name;
  std::filesystem::path file;
  long long samples = 0;
  double start_min = 0, end_min = 0;  ///< first and last time [min; sample index without time]
  int first_line = 0, last_line = 0;
};
/// SplitAtStarts on a log file streamed row by row (fixed memory): each run is written as
/// <dir>/<Slug(name)>.csv as its rows arrive, through an OutputDir (all or nothing, `what` names
/// the directory); the same runs and files as SplitAtStarts + WriteRuns. `progress` (optional)
/// gets the rows read and the fraction of the file.
std::vector<SplitRun> SplitLogFile(const std::filesystem::path& log, const std::string& column,
                                   double threshold, const std::filesystem::path& dir,
                                   const std::vector<std::string>& comments,
                                   const std::string& what,
                                   const std::function<void(long long, double)>& progress = {});

}  // namespace whirl::drift
