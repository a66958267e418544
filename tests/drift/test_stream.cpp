// The streamed drift commands (drift/stream.h, drift/run_file.h RunReader, SplitLogFile) against
// their in-memory counterparts on the same files, and the plots' M4 decimation (core/decimate.h).
// The files are longer than one reader block (4096 rows), so block boundaries are crossed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/decimate.h"
#include "core/numbers.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/run_file.h"
#include "drift/stream.h"
#include "support/scratch_dir.h"

namespace whirl::drift {
namespace {

namespace fs = std::filesystem;

// A log of `rows` 15-s samples: two temperatures as random walks, an error that follows them, and
// a spindle that starts every 700-1500 rows (the first rows idle).
std::string RandomLog(int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> step(0.0, 0.02);
  std::uniform_int_distribution<int> segment(700, 1500);
  std::string text = "time_min,a_C,b_C,ch1_um,spindle_rpm\n";
  double a = 20, b = 21;
  int next = segment(rng), rpm = 0;
  for (int k = 0; k < rows; ++k) {
    if (k == next) rpm = rpm ? 0 : 1000, next += segment(rng);
    a += step(rng) + (rpm ? 0.003 : -0.001);
    b += step(rng);
    const double e = 3.0 * (a - 20) - 1.5 * (b - 21) + step(rng);
    text += FormatNumber(0.25 * k) + "," + FormatNumber(a) + "," + FormatNumber(b) + "," +
            FormatNumber(e) + "," + std::to_string(rpm) + "\n";
  }
  return text;
}

fs::path WriteLog(const std::string& name, int rows, unsigned seed) {
  const fs::path p = test::ScratchDir() / name;
  WriteFileAtomic(p, RandomLog(rows, seed));
  return p;
}

TEST(Stream, ReadRunEqualsParseOfTheText) {
  const fs::path p = WriteLog("read.csv", 9000, 1);
  const drift::Run whole = ReadRun(p, RunState::kUnknown);
  RunReader reader(p, RunState::kUnknown, false);
  RunRows b;
  long long rows = 0;
  while (reader.Read(&b, 1000)) {
    for (int k = 0; k < b.count; ++k, ++rows) {
      ASSERT_EQ(b.time_min[static_cast<std::size_t>(k)], whole.time_min[static_cast<std::size_t>(rows)]);
      ASSERT_EQ(b.temperature_C(k, 1), whole.temperature_C(rows, 1));
      ASSERT_EQ(b.line_numbers[static_cast<std::size_t>(k)], whole.line_numbers[static_cast<std::size_t>(rows)]);
    }
  }
  EXPECT_EQ(rows, whole.samples());
  EXPECT_EQ(ScanRun(p).rows, whole.samples());
}

TEST(Stream, PredictFileEqualsPredictRun) {
  const fs::path p = WriteLog("predict.csv", 9000, 2);
  const drift::Run run = ReadRun(p, RunState::kUnknown);
  const DriftModel m = FitDriftModel({run}, "ch1_um", FitOptions{}).model;
  const RunPrediction whole = PredictRun(m, run);
  std::vector<double> streamed;
  const PredictionSummary s = PredictFile(m, p, ReferenceMode::kRunStart,
                                          [&](const PredictedSample& x) {
                                            streamed.push_back(x.predicted_um);
                                          });
  ASSERT_EQ(static_cast<Eigen::Index>(streamed.size()), whole.predicted_um.size());
  for (std::size_t k = 0; k < streamed.size(); ++k)
    ASSERT_NEAR(streamed[k], whole.predicted_um(static_cast<Eigen::Index>(k)), 1e-9) << k;
  const PredictionSummary w = Summarize(whole);
  EXPECT_EQ(s.samples, w.samples);
  EXPECT_NEAR(s.residual.mae_um, w.residual.mae_um, 1e-9);
  EXPECT_NEAR(s.residual.rmse_um, w.residual.rmse_um, 1e-9);
  EXPECT_NEAR(s.none.max_abs_um, w.none.max_abs_um, 1e-9);
}

// Runs that fit the search's sample whole: FitFiles is FitDriftModel on the runs read whole.
TEST(Stream, FitFilesOnShortRunsIsFitDriftModel) {
  const fs::path p1 = WriteLog("fit1.csv", 6000, 3), p2 = WriteLog("fit2.csv", 5000, 4);
  const FitReport a = FitFiles({{p1, RunState::kUnknown}, {p2, RunState::kUnknown}}, "ch1_um", {});
  const FitReport b = FitDriftModel(
      {ReadRun(p1, RunState::kUnknown), ReadRun(p2, RunState::kUnknown)}, "ch1_um", {});
  ASSERT_EQ(a.model.features.size(), b.model.features.size());
  for (std::size_t i = 0; i < a.model.features.size(); ++i)
    EXPECT_EQ(a.model.features[i].Name(a.model.time_unit), b.model.features[i].Name(b.model.time_unit));
  ASSERT_EQ(a.model.linear.coefficients.size(), b.model.linear.coefficients.size());
  for (Eigen::Index i = 0; i < a.model.linear.coefficients.size(); ++i)
    EXPECT_EQ(a.model.linear.coefficients(i), b.model.linear.coefficients(i));
}

// The streamed split writes the runs SplitAtStarts cuts, row for row.
TEST(Stream, SplitLogFileEqualsSplitAtStarts) {
  const fs::path p = WriteLog("split.csv", 12000, 5);
  const std::vector<drift::Run> cut = SplitAtStarts(ReadRun(p, RunState::kUnknown), "spindle_rpm");
  const fs::path dir = test::ScratchDir() / "split_out";
  const std::vector<SplitRun> files = SplitLogFile(p, "spindle_rpm", 0.0, dir, {"test"}, "dir");
  ASSERT_GT(cut.size(), 4u);
  ASSERT_EQ(files.size(), cut.size());
  for (std::size_t i = 0; i < cut.size(); ++i) {
    const drift::Run r = ReadRun(files[i].file, RunState::kUnknown);
    EXPECT_EQ(files[i].samples, cut[i].samples());
    EXPECT_EQ(r.time_min, cut[i].time_min) << i;
    EXPECT_TRUE(r.temperature_C == cut[i].temperature_C) << i;
    EXPECT_TRUE(r.other == cut[i].other) << i;
  }
}

// M4: in every pixel column the kept rows hold the first, last, smallest and largest value of
// every series, and there are at most (2 + 2 x series) rows per column.
TEST(Decimate, M4KeepsEachColumnsExtremes) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int n = 50000, columns = 100;
  std::vector<double> x(n);
  std::vector<std::vector<double>> series(2, std::vector<double>(n));
  for (int i = 0; i < n; ++i) {
    x[static_cast<std::size_t>(i)] = i * 0.5;
    series[0][static_cast<std::size_t>(i)] = noise(rng);
    series[1][static_cast<std::size_t>(i)] = std::sin(i * 1e-3) + 0.1 * noise(rng);
  }
  const std::vector<std::size_t> kept = M4Rows(x, series, columns);
  EXPECT_LE(kept.size(), static_cast<std::size_t>(6 * columns));
  EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
  const auto column = [&](std::size_t i) {
    return std::min(columns - 1, static_cast<int>(x[i] / x.back() * columns));
  };
  for (int c = 0; c < columns; ++c)
    for (std::size_t s = 0; s < series.size(); ++s) {
      double all_lo = INFINITY, all_hi = -INFINITY, kept_lo = INFINITY, kept_hi = -INFINITY;
      for (std::size_t i = 0; i < x.size(); ++i)
        if (column(i) == c)
          all_lo = std::min(all_lo, series[s][i]), all_hi = std::max(all_hi, series[s][i]);
      for (const std::size_t i : kept)
        if (column(i) == c)
          kept_lo = std::min(kept_lo, series[s][i]), kept_hi = std::max(kept_hi, series[s][i]);
      ASSERT_EQ(kept_lo, all_lo) << "column " << c;
      ASSERT_EQ(kept_hi, all_hi) << "column " << c;
    }
  EXPECT_EQ(kept.front(), 0u);
  EXPECT_EQ(kept.back(), x.size() - 1);
}

}  // namespace
}  // namespace whirl::drift
