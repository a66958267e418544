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
// Limits (resource and plausibility, stated in the messages): at most kMaxRunSamples rows and
// kMaxRunColumns columns; temperatures within [-60, 400] degC; errors within +-100000 um; times
// within +-kMaxRunTimeMin; other columns within +-kMaxAbsOtherValue.
#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace whirl::drift {

inline constexpr int kMaxRunSamples = 2'000'000;
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
std::vector<Run> SplitAtStarts(const Run& run, const std::string& column, double threshold = 0.0);

}  // namespace whirl::drift
