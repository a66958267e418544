#include "drift/run_file.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "core/safe_text.h"

namespace whirl::drift {
namespace {

std::string Join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "none" : out;
}

int FindIndex(const std::vector<std::string>& names, const std::string& name,
              const std::string& run, const char* kind) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  throw InputError(run + ": no " + kind + " column '" + name + "' (have: " + Join(names) + ")");
}

}  // namespace

std::string ToString(RunState s) {
  switch (s) {
    case RunState::kIdle:
      return "idle";
    case RunState::kCutting:
      return "cutting";
    case RunState::kUnknown:
      break;
  }
  return "unknown";
}

RunState ParseRunState(const std::string& text) {
  if (text == "idle") return RunState::kIdle;
  if (text == "cutting") return RunState::kCutting;
  if (text == "unknown") return RunState::kUnknown;
  throw InputError("run state '" + text + "': must be idle, cutting or unknown");
}

Eigen::MatrixXd Run::Rises() const {
  Eigen::MatrixXd r = temperature_C;
  if (r.rows() > 0) r.rowwise() -= temperature_C.row(0);
  return r;
}

int Run::SensorIndex(const std::string& name) const {
  return FindIndex(sensor_names, name, source, "temperature (_C)");
}
int Run::ErrorIndex(const std::string& name) const {
  return FindIndex(error_names, name, source, "thermal-error (_um)");
}
int Run::OtherIndex(const std::string& name) const {
  return FindIndex(other_names, name, source, "input");
}

Run Run::Slice(int begin, int end, const std::string& new_name) const {
  if (begin < 0 || end > samples() || end - begin < 1)
    throw InputError(source + ": rows [" + std::to_string(begin) + ", " + std::to_string(end) +
                     ") are not a non-empty part of its " + std::to_string(samples()) + " rows");
  // The metadata only: copying the whole run first (Run r = *this) made cutting a log into k
  // runs cost k times the log (drift split's memory grew with the square of the runs).
  Run r;
  r.name = new_name;
  r.source = source;
  r.state = state;
  r.time_from_index = time_from_index;
  r.sensor_names = sensor_names;
  r.error_names = error_names;
  r.other_names = other_names;
  const int n = end - begin;
  r.time_min.assign(time_min.begin() + begin, time_min.begin() + end);
  r.line_numbers.assign(line_numbers.begin() + begin, line_numbers.begin() + end);
  r.temperature_C = temperature_C.middleRows(begin, n);
  r.error_um = error_um.middleRows(begin, n);
  r.other = other.middleRows(begin, n);
  return r;
}

std::string ToString(ErrorZero z) {
  switch (z) {
    case ErrorZero::kFixed:
      return "fixed";
    case ErrorZero::kAsLogged:
      return "as-logged";
    case ErrorZero::kRunStart:
      break;
  }
  return "run-start";
}

ErrorZero ParseErrorZero(const std::string& text) {
  if (text == "run-start") return ErrorZero::kRunStart;
  if (text == "fixed") return ErrorZero::kFixed;
  if (text == "as-logged") return ErrorZero::kAsLogged;
  throw InputError("error zero '" + text + "': must be run-start or fixed");
}

Run ApplyErrorZero(const Run& run, const ZeroConvention& zero) {
  Run r = run;
  if (r.error_um.rows() == 0) return r;
  if (zero.zero == ErrorZero::kRunStart) {
    r.error_um.rowwise() -= run.error_um.row(0);
  } else if (zero.zero == ErrorZero::kFixed) {
    if (!std::isfinite(zero.gauge_level_um))
      throw InputError(run.source + ": error zero 'fixed' needs a finite gauge level [um]");
    r.error_um.array() -= zero.gauge_level_um;
  }
  return r;
}

Run ErrorsFromStart(const Run& run) { return ApplyErrorZero(run, {ErrorZero::kRunStart, 0.0}); }

std::string FormatRun(const Run& run, const std::vector<std::string>& comments) {
  std::vector<std::string> header;
  if (!run.time_from_index) header.push_back("time_min");
  for (const auto& v : {run.sensor_names, run.error_names, run.other_names})
    header.insert(header.end(), v.begin(), v.end());
  std::vector<std::vector<double>> rows(static_cast<std::size_t>(run.samples()));
  for (int k = 0; k < run.samples(); ++k) {
    auto& row = rows[static_cast<std::size_t>(k)];
    if (!run.time_from_index) row.push_back(run.time_min[static_cast<std::size_t>(k)]);
    for (const Eigen::MatrixXd* m : {&run.temperature_C, &run.error_um, &run.other})
      for (Eigen::Index j = 0; j < m->cols(); ++j) row.push_back((*m)(k, j));
  }
  return FormatCsv(header, rows, comments);
}

std::vector<std::filesystem::path> WriteRuns(const std::filesystem::path& dir,
                                             const std::vector<Run>& runs,
                                             const std::vector<std::string>& comments,
                                             const std::string& what) {
  OutputDir out(dir, what);
  for (const Run& r : runs) {
    std::vector<std::string> c{r.name + ": lines " + std::to_string(r.line_numbers.front()) +
                               " to " + std::to_string(r.line_numbers.back()) + " of " + r.source};
    c.insert(c.end(), comments.begin(), comments.end());
    out.Add(Slug(r.name) + ".csv", FormatRun(r, c));
  }
  return out.Commit();
}

std::vector<Run> SplitAtStarts(const Run& run, const std::string& column, double threshold) {
  const int c = run.OtherIndex(column);
  if (!std::isfinite(threshold))
    throw InputError("split threshold " + FormatNumber(threshold) + ": must be a finite number");
  std::vector<int> starts{0};
  for (int k = 1; k < run.samples(); ++k)
    if (run.other(k - 1, c) <= threshold && run.other(k, c) > threshold && k > starts.back())
      starts.push_back(k);
  if (starts.size() > 1 && run.other(0, c) <= threshold) {
    // rows before the first start belong to the first run
    starts.erase(starts.begin() + 1);
  }
  if (starts.size() > static_cast<std::size_t>(kMaxSplitRuns))
    throw InputError(run.source + ": column '" + column + "' rises above " +
                     FormatNumber(threshold) + " " + std::to_string(starts.size()) +
                     " times: drift split writes at most " + std::to_string(kMaxSplitRuns) +
                     " run files (one per machine start); raise --threshold, choose another "
                     "--at column, or split a shorter part of the log");
  starts.push_back(run.samples());
  std::vector<Run> runs;
  runs.reserve(starts.size() - 1);
  for (std::size_t i = 0; i + 1 < starts.size(); ++i)
    runs.push_back(run.Slice(starts[i], starts[i + 1], run.name + "_" + std::to_string(i + 1)));
  return runs;
}

}  // namespace whirl::drift
