#pragma once
// Command-line options of Miao et al.'s sensor selection (drift/selection.h), shared by the
// commands that fit drift models: whirl drift fit/crossval/holdout/... and whirl machine evaluate.
#include <CLI/CLI.hpp>
#include <string>

#include "drift/selection.h"
#include "drift/stream.h"

namespace whirl::cli {

struct SelectionArgs {
  double alpha = 0.05;
  std::string classes = "fewest";
  int max_sensors = 0;
};

/// --alpha, --classes, --max-sensors.
void AddSelectionOptions(CLI::App* sub, SelectionArgs* s);

/// The library's options; InputError for a --classes that is not fewest, margin, cv or a number.
drift::SelectionOptions ToSelection(const SelectionArgs& a);

/// A drift quantity on the run's time axis: minutes on runs that record time, samples on runs
/// that do not (their time is the sample index). The flag pair --<name>-min and
/// --<name>-samples, and the old spelling --<name> (a hidden deprecated alias of --<name>-min,
/// AddDeprecatedAlias) that meant either, as the run's time axis.
struct TimeAxisFlags {
  CLI::Option* min = nullptr;
  CLI::Option* samples = nullptr;
  CLI::Option* old = nullptr;  ///< nullptr: no old spelling
};

/// Which flag's value applies to a run with (`time_from_index` false) or without recorded time:
/// kNone (neither given: the default), kMin (the -min flag's variable; on a run without time
/// this can only be the old spelling, read in samples as it always was, with a warning) or
/// kSamples. A -min flag on a run without time, or a -samples flag on a run with time, is an
/// InputError naming the flag and the one to use.
enum class TimeAxisValue { kNone, kMin, kSamples };
TimeAxisValue ChooseTimeAxis(const TimeAxisFlags& f, bool time_from_index);

/// --progress: progress on stderr also when it is not a terminal or with --json.
void AddProgressFlag(CLI::App* sub, bool* progress);

/// Progress of a long drift command on stderr (drift/stream.h StreamProgress): nothing for the
/// first 2 s, then the step, the rows read and the share of the file, redrawn in place on a
/// terminal (at most 4 times a second), a line every 5 s otherwise. Shown when asked
/// (--progress) or, without --json, when stderr is a terminal; quiet otherwise.
class RowProgress {
 public:
  RowProgress(bool asked, bool json);
  ~RowProgress();
  RowProgress(const RowProgress&) = delete;
  RowProgress& operator=(const RowProgress&) = delete;
  void Update(const std::string& step, long long rows, double fraction);
  /// A callback for the drift library (valid while this object lives).
  drift::StreamProgress Callback();
  void Finish();  ///< ends a redrawn line

 private:
  bool enabled_, tty_, shown_ = false;
  double start_s_, last_s_ = -1e9;
};

}  // namespace whirl::cli
