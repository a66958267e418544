#include "core/curve.h"

#include <algorithm>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"

namespace whirl {

CurveColumns ReadCurveColumns(const std::filesystem::path& path, const std::string& x_name,
                              const std::string& y_name, std::size_t min_rows,
                              const std::string& what) {
  const CsvTable csv = ReadCsv(path);
  CurveColumns c{csv.source, csv.IncreasingColumn(x_name), csv.Column(y_name), csv.line_numbers};
  if (c.x.size() < min_rows)
    throw InputError(csv.source + ": " + what + " needs at least " + std::to_string(min_rows) +
                     " rows, found " + std::to_string(c.x.size()));
  return c;
}

ElongationCurve ReadElongationCurve(const std::filesystem::path& path, double max_gap_factor) {
  const CurveColumns csv = ReadCurveColumns(path, "time_s", "elongation_um", 3, "a curve");
  ElongationCurve c{csv.x, csv.y};
  std::vector<double> steps;
  for (std::size_t i = 1; i < c.size(); ++i) {
    steps.push_back(c.time_s[i] - c.time_s[i - 1]);
  }
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i] > max_gap_factor * median)
      throw InputError(csv.source + ":" + std::to_string(csv.line_numbers[i + 1]) +
                       ": gap in the recording: time step " + FormatNumber(steps[i]) +
                       " s is more than " + FormatNumber(max_gap_factor) + " x the median step " +
                       FormatNumber(median) + " s");
  }
  return c;
}

void WriteElongationCurve(const std::filesystem::path& path, const ElongationCurve& curve,
                          const std::vector<std::string>& comments) {
  std::vector<std::vector<double>> rows;
  rows.reserve(curve.size());
  for (std::size_t i = 0; i < curve.size(); ++i)
    rows.push_back({curve.time_s[i], curve.elongation_um[i]});
  WriteFileAtomic(path, FormatCsv({"time_s", "elongation_um"}, rows, comments));
}

double InterpolateLinear(const std::vector<double>& x, const std::vector<double>& y, double t) {
  if (x.empty()) return 0.0;
  if (t <= x.front()) return y.front();
  if (t >= x.back()) return y.back();
  const auto it = std::upper_bound(x.begin(), x.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - x.begin());
  const double w = (t - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + w * (y[i] - y[i - 1]);
}

}  // namespace whirl
