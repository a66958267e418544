#pragma once
// An elongation curve over time: simulated, fitted, or measured (CSV `time_s,elongation_um`).
#include <filesystem>
#include <string>
#include <vector>

namespace whirl {

struct ElongationCurve {
  std::vector<double> time_s;         ///< strictly increasing, s
  std::vector<double> elongation_um;  ///< elongation of the unmachined section, um
  std::size_t size() const { return time_s.size(); }
};

/// Two columns of a curve file (the one reader of every such file: elongation over time, lead
/// deviation over position): `x_name` strictly increasing, `y_name`, other columns ignored, '#'
/// comments allowed, at least `min_rows` rows; InputError (file, line) otherwise: "<file>:
/// <what> needs at least <min_rows> rows, found <n>". `line_numbers` are the rows' file lines.
struct CurveColumns {
  std::string source;
  std::vector<double> x, y;
  std::vector<int> line_numbers;
};
CurveColumns ReadCurveColumns(const std::filesystem::path& path, const std::string& x_name,
                              const std::string& y_name, std::size_t min_rows,
                              const std::string& what);

/// Reads a measured or simulated curve: header with columns `time_s` and `elongation_um` (others
/// ignored), '#' comments allowed. Rejects (InputError, file and line): fewer than 3 samples,
/// non-increasing time, and gaps, i.e. a time step more than `max_gap_factor` times the median
/// step (a lost stretch of the recording).
ElongationCurve ReadElongationCurve(const std::filesystem::path& path,
                                    double max_gap_factor = 5.0);

/// Writes `time_s,elongation_um` with '#' comment lines, atomically.
void WriteElongationCurve(const std::filesystem::path& path, const ElongationCurve& curve,
                          const std::vector<std::string>& comments = {});

/// Linear interpolation at t (clamped to the first/last sample outside the range).
double InterpolateLinear(const std::vector<double>& x, const std::vector<double>& y, double t);

}  // namespace whirl
