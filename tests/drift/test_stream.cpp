// The streamed drift commands (drift/stream.h, drift/run_file.h RunReader, SplitLogFile) against
// their in-memory counterparts on the same files, and the plots' M4 decimation (core/decimate.h).
// The files are longer than one reader block (4096 rows), so block boundaries are crossed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <random>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/decimate.h"
#include "core/numbers.h"
#include "drift/documents.h"
#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/report.h"
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


// The carried values ride along with the kept rows without choosing any: the same rows as without
// them, each with its own carried value.
TEST(Decimate, CarriedValuesChooseNoRow) {
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int n = 20000;
  M4Decimator plain(1, 0, n - 1, 50), carried(1, 0, n - 1, 50, 1);
  std::vector<double> carry(n);
  for (int i = 0; i < n; ++i) {
    const double v[2] = {noise(rng), 1e6 * noise(rng)};  // the carried value: wild extremes
    carry[static_cast<std::size_t>(i)] = v[1];
    plain.Add(i, i, v);
    carried.Add(i, i, v);
  }
  ASSERT_EQ(plain.Finish(), carried.Finish());
  const std::vector<long long>& rows = carried.rows();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_EQ(carried.values()[2 * k], plain.values()[k]);
    ASSERT_EQ(carried.values()[2 * k + 1], carry[static_cast<std::size_t>(rows[k])]);
  }
}

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// RandomLog without its error column (a run shown that has no measured error).
std::string WithoutError(const std::string& log) {
  std::istringstream in(log);
  std::string line, out;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    cells.erase(cells.begin() + 3);  // ch1_um
    for (std::size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
    out += "\n";
  }
  return out;
}

bool Near(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b));
}

void ExpectStatsNear(const ErrorStats& a, const ErrorStats& b, const std::string& what) {
  EXPECT_EQ(a.samples, b.samples) << what;
  EXPECT_TRUE(Near(a.mae_um, b.mae_um)) << what << ": " << a.mae_um << " " << b.mae_um;
  EXPECT_TRUE(Near(a.rmse_um, b.rmse_um)) << what << ": " << a.rmse_um << " " << b.rmse_um;
  EXPECT_TRUE(Near(a.std_um, b.std_um)) << what << ": " << a.std_um << " " << b.std_um;
  EXPECT_EQ(a.max_abs_um, b.max_abs_um) << what;
}

// drift report on run files (each pass streamed: the model's, then one per baseline) against the
// report on the same runs in memory and against the figures computed directly (ComputeErrorStats
// on PredictRun of the model, of the time-only fit on the training runs and of drift fit's
// defaults on the previous run), over random logs: 2 to 4 runs of 300 to 9,000 rows (across the
// reader's 4,096-row blocks), any of them may lack the error column, the model's candidates and
// error zero vary. The statistics are equal up to rounding (running sums against Eigen's), the
// per-sample and plot CSVs byte for byte, the baselines' strongest the same.
TEST(ReportStream, StatisticsEqualTheInMemoryReportOnRandomLogs) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    const int count = std::uniform_int_distribution<int>(2, 4)(rng);
    std::vector<RunFile> files;
    std::vector<drift::Run> runs;
    const fs::path dir = test::ScratchDir() / ("report_stream_" + std::to_string(seed));
    fs::create_directories(dir);
    for (int i = 0; i < count; ++i) {
      const int rows = std::uniform_int_distribution<int>(300, 9000)(rng);
      std::string log = RandomLog(rows, 1000 * seed + static_cast<unsigned>(i));
      if (i >= 2 && rng() % 3 == 0) log = WithoutError(log);
      const fs::path p = dir / ("run" + std::to_string(i) + ".csv");
      WriteFileAtomic(p, log);
      files.push_back({p, RunState::kUnknown});
      runs.push_back(ReadRun(p, RunState::kUnknown));
    }
    FitOptions f;
    f.candidates = std::array{Candidates::kAuto, Candidates::kSensors, Candidates::kTime}[seed % 3];
    if (seed % 4 == 0) f.zero.zero = ErrorZero::kFixed, f.zero.gauge_level_um = 0.5;
    const FitReport fit = FitDriftModel({runs[0], runs[1]}, "ch1_um", f);
    const DriftReportResult mem =
        WriteModelReport(dir / "mem", fit, runs, {"test"}, "whirl-no-gnuplot-here");
    const DriftReportResult str =
        WriteModelReport(dir / "str", fit, files, {"test"}, "whirl-no-gnuplot-here");
    ASSERT_EQ(str.predictions.size(), runs.size());
    ASSERT_EQ(str.baselines.size(), runs.size());
    EXPECT_EQ(str.baseline_notes, mem.baseline_notes);
    const DriftModel time = [&] {
      FitOptions t;
      t.candidates = Candidates::kTime;
      t.zero = fit.model.zero;
      return FitDriftModel({runs[0], runs[1]}, "ch1_um", t).model;
    }();
    const auto direct_mae = [&](const DriftModel& m, const drift::Run& run) {
      const RunPrediction p = PredictRun(m, run);
      return ComputeErrorStats(p.measured_um - p.predicted_um).mae_um;
    };
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const PredictionSummary& s = str.predictions[i];
      const RunPrediction p = PredictRun(fit.model, runs[i]);
      EXPECT_EQ(s.run, runs[i].name);
      EXPECT_EQ(s.samples, runs[i].samples());
      EXPECT_EQ(s.predicted_min_um, p.predicted_um.minCoeff());
      EXPECT_EQ(s.predicted_max_um, p.predicted_um.maxCoeff());
      EXPECT_EQ(s.warnings, mem.predictions[i].warnings);
      ASSERT_EQ(s.has_measured, p.has_measured);
      const ReportBaseline& b = str.baselines[i];
      const ReportBaseline& m = mem.baselines[i];
      if (p.has_measured) {
        ExpectStatsNear(s.residual, ComputeErrorStats(p.measured_um - p.predicted_um), "model");
        ExpectStatsNear(s.none, ComputeErrorStats(p.measured_um), "none");
        EXPECT_TRUE(Near(b.time_only_mae_um, direct_mae(time, runs[i])));
        const auto& before = i > 0 ? runs[i - 1].error_names : std::vector<std::string>{};
        if (std::find(before.begin(), before.end(), "ch1_um") == before.end()) {
          EXPECT_TRUE(std::isnan(b.previous_run_mae_um));  // no previous run, or not fittable
        } else {
          const DriftModel previous =
              FitDriftModel({runs[i - 1]}, "ch1_um", PreviousRunOptions(fit.model)).model;
          EXPECT_TRUE(Near(b.previous_run_mae_um, direct_mae(previous, runs[i])))
              << b.previous_run_mae_um;
        }
      }
      for (const auto& [x, y] : {std::pair{b.model_mae_um, m.model_mae_um},
                                 {b.none_mae_um, m.none_mae_um},
                                 {b.time_only_mae_um, m.time_only_mae_um},
                                 {b.previous_run_mae_um, m.previous_run_mae_um}})
        EXPECT_TRUE(Near(x, y)) << x << " " << y;
      EXPECT_EQ(b.strongest, m.strongest);
      for (const char* suffix : {"_prediction.csv", "_plot.csv"}) {
        const std::string name = runs[i].name + suffix;
        EXPECT_EQ(ReadText(str.index_html.parent_path() / name),
                  ReadText(mem.index_html.parent_path() / name))
            << name;
      }
    }
  }
}

// The plot's rows of a streamed run are M4Rows of the whole prediction (the old in-memory path):
// its kept rows, each with time, prediction, std and measured.
TEST(ReportStream, PlotRowsAreTheM4RowsOfTheWholePrediction) {
  const fs::path p = WriteLog("report_plot.csv", 30000, 9);
  const drift::Run run = ReadRun(p, RunState::kUnknown);
  const FitReport fit = FitDriftModel({run}, "ch1_um", FitOptions{});
  const DriftReportResult r = WriteModelReport(test::ScratchDir() / "report_plot", fit,
                                               std::vector<RunFile>{{p, RunState::kUnknown}},
                                               {"test"}, "whirl-no-gnuplot-here");
  const RunPrediction w = PredictRun(fit.model, run);
  const auto n = static_cast<std::size_t>(w.predicted_um.size());
  std::vector<std::vector<double>> series(3, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    series[0][k] = w.predicted_um(i);
    series[1][k] = w.measured_um(i);
    series[2][k] = w.measured_um(i) - w.predicted_um(i);
  }
  std::string expected = PredictionCsvHeader(false, true, {"test"});
  const std::vector<std::size_t> kept = M4Rows(w.time, series);
  ASSERT_LT(kept.size(), n / 2);
  for (const std::size_t k : kept) {
    const auto i = static_cast<Eigen::Index>(k);
    AppendPredictionRow(w.time[k], w.predicted_um(i), w.std_um(i), &w.measured_um(i), &expected);
  }
  std::string plot = ReadText(r.index_html.parent_path() / "report_plot_plot.csv");
  // The comment lines differ (what the file is); the header and rows must not.
  const auto body = [](const std::string& csv) {
    std::istringstream in(csv);
    std::string line, out;
    while (std::getline(in, line))
      if (line.empty() || line[0] != '#') out += line + "\n";
    return out;
  };
  EXPECT_EQ(body(plot), body(expected));
}

}  // namespace
}  // namespace whirl::drift
