// One error zero for a model and everything it is compared with; the time-only warm-up model as a
// baseline and as a fit candidate (variable projection); planted logs where elapsed time alone is
// the truth and where only a sensor explains the error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "core/error.h"
#include "drift/evaluation.h"
#include "drift/monitor.h"
#include "drift/regression.h"
#include "drift/documents.h"
#include "drift/report.h"
#include "support/scratch_dir.h"
#include "synthetic.h"

namespace whirl::drift {
namespace {

drift::Run Shifted(drift::Run r, double level_um) {
  r.error_um.array() += level_um;
  return r;
}

void ExpectSame(const ErrorStats& a, const ErrorStats& b, const std::string& what) {
  EXPECT_NEAR(a.rmse_um, b.rmse_um, 1e-7 * (1 + a.rmse_um)) << what;
  EXPECT_NEAR(a.mae_um, b.mae_um, 1e-7 * (1 + a.mae_um)) << what;
}

// A gauge level of 60 um on every run changes no figure under run-start, "none" included; under
// fixed with the level given, neither.
TEST(ZeroConvention, GaugeLevelCancels) {
  const std::vector<drift::Run> runs{synth::PlantedRun(1, 2, 2, {1.5, -0.5}, 200),
                              synth::PlantedRun(2, 2, 2, {1.2, -0.4}, 200)};
  std::vector<drift::Run> shifted;
  for (const drift::Run& r : runs) shifted.push_back(Shifted(r, 60));
  for (const ErrorZero z : {ErrorZero::kRunStart, ErrorZero::kFixed}) {
    FitOptions f;
    f.zero.zero = z;
    FitOptions g = f;
    if (z == ErrorZero::kFixed) f.zero.gauge_level_um = 0, g.zero.gauge_level_um = 60;
    const CrossRunResult a = CrossRun(runs, "e_um", f), b = CrossRun(shifted, "e_um", g);
    for (std::size_t i = 0; i < a.groups.size(); ++i) {
      ExpectSame(a.groups[i].none, b.groups[i].none, "none " + a.groups[i].name);
      ExpectSame(a.groups[i].model, b.groups[i].model, "model " + a.groups[i].name);
      ExpectSame(a.groups[i].time, b.groups[i].time, "time " + a.groups[i].name);
    }
    HoldoutOptions h;
    h.network = false;
    h.fit = f;
    HoldoutOptions hs = h;
    hs.fit = g;
    const HoldoutResult ha = Holdout(runs[0], h), hb = Holdout(shifted[0], hs);
    ASSERT_EQ(ha.rows_out.size(), hb.rows_out.size());
    for (std::size_t i = 0; i < ha.rows_out.size(); ++i)
      ExpectSame(ha.rows_out[i].test, hb.rows_out[i].test, "holdout " + ha.rows_out[i].method);
    const DriftModel ma = FitDriftModel({runs[0]}, "e_um", f).model;
    const DriftModel mb = FitDriftModel({shifted[0]}, "e_um", g).model;
    const MonitorResult ra = MonitorRun(ma, runs[1], {}), rb = MonitorRun(mb, shifted[1], {});
    ExpectSame(ra.none, rb.none, "monitor none");
    for (std::size_t i = 0; i < ra.strategies.size(); ++i)
      ExpectSame(ra.strategies[i].score, rb.strategies[i].score, "monitor rule");
  }
}

// The model file carries its zero; predict applies it to the measured errors; a schema 1 file is
// read as "as logged" and its predictions warn.
TEST(ZeroConvention, ModelCarriesItsZero) {
  const drift::Run run = Shifted(synth::PlantedRun(3, 2, 2, {1.0, 0.5}, 150), 60);
  FitOptions f;
  f.zero.zero = ErrorZero::kFixed;  // level from the first row
  const DriftModel m = FitDriftModel({run}, "e_um", f).model;
  EXPECT_EQ(m.zero.zero, ErrorZero::kFixed);
  EXPECT_DOUBLE_EQ(m.zero.gauge_level_um, run.error_um(0, 0));
  const DriftModel back = nlohmann::json(m).get<DriftModel>();
  EXPECT_EQ(back.zero.zero, ErrorZero::kFixed);
  EXPECT_DOUBLE_EQ(back.zero.gauge_level_um, m.zero.gauge_level_um);
  const RunPrediction p = PredictRun(back, run);
  EXPECT_NEAR(p.measured_um(5), run.error_um(5, 0) - run.error_um(0, 0), 1e-12);
  nlohmann::json old = nlohmann::json(FitDriftModel({run}, "e_um", FitOptions{}).model);
  old["schema_version"] = 1;
  for (const char* k : {"error_zero", "gauge_level_um", "elapsed_time_constants"}) old.erase(k);
  const DriftModel legacy = old.get<DriftModel>();
  EXPECT_EQ(legacy.zero.zero, ErrorZero::kAsLogged);
  const RunPrediction q = PredictRun(legacy, run);
  EXPECT_DOUBLE_EQ(q.measured_um(5), run.error_um(5, 0));
  EXPECT_FALSE(q.warnings.empty());
  FitOptions bad;
  bad.zero.zero = ErrorZero::kFixed;
  bad.zero.gauge_level_um = std::numeric_limits<double>::infinity();
  EXPECT_THROW(FitDriftModel({run}, "e_um", bad), InputError);
}

// Runs whose error is a first-order warm-up in time since start, A (1 - exp(-t / tau)), plus
// noise, and whose sensors follow other shapes (a planted run with zero weights).
drift::Run WarmUpRun(unsigned seed, double gain_um, double tau_min, int samples, double noise_um) {
  drift::Run r = synth::PlantedRun(seed, 3, 1, {0, 0, 0}, samples, 0.02, 0.0);
  std::mt19937_64 rng(seed + 100);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int k = 0; k < samples; ++k)
    r.error_um(k, 0) = gain_um * (1 - std::exp(-r.time_min[static_cast<std::size_t>(k)] / tau_min)) +
                       noise_um * n01(rng);
  return r;
}

TEST(WarmUpFit, VariableProjectionRecoversParameters) {
  // Hand example: 3 points, tau fixed by a 1-point grid is impossible, so check the closed form
  // through a noise-free run: t = 0, 10, 20 ... with tau = 37 (between grid points).
  const drift::Run r = WarmUpRun(4, 12.0, 37.0, 300, 0.0);
  const WarmUpFit f = FitWarmUp({r.time_min}, {r.error_um.col(0)}, 1);
  ASSERT_EQ(f.time_constants.size(), 1u);
  EXPECT_NEAR(f.time_constants[0], 37.0, 0.37);
  EXPECT_NEAR(f.coefficients(1), 12.0, 0.05);
  EXPECT_NEAR(f.coefficients(0), 0.0, 0.02);
  EXPECT_TRUE(f.identified);
  // Gains for fixed tau are least squares: the residual is orthogonal to [1, 1 - exp(-t/tau)].
  Eigen::MatrixXd x(r.samples(), 2);
  for (int k = 0; k < r.samples(); ++k)
    x(k, 0) = 1, x(k, 1) = 1 - std::exp(-r.time_min[static_cast<std::size_t>(k)] / f.time_constants[0]);
  EXPECT_LT((x.transpose() * (r.error_um.col(0) - x * f.coefficients)).norm(), 1e-6);
  // A time constant far beyond the run: held at the trained span, not identified, and said so.
  const drift::Run ramp = WarmUpRun(5, 12.0, 1e5, 200, 0.0);
  const WarmUpFit g = FitWarmUp({ramp.time_min}, {ramp.error_um.col(0)}, 1);
  EXPECT_FALSE(g.identified);
  EXPECT_LE(g.time_constants[0], ramp.time_min.back());
  EXPECT_GT(g.time_constants[0], 0.85 * ramp.time_min.back());
  EXPECT_NE(g.note.find("slower than the training"), std::string::npos) << g.note;
  EXPECT_THROW(FitWarmUp({{0.0, 1.0}}, {Eigen::Vector2d(0, 1)}, 1), InputError);
}

// Elapsed time alone is the truth (12 um, tau 60 min, noise 0.2 um on 3 runs): fit picks a
// time-only candidate with tau within 5 % and gain within 2 %; the hold-out lists it, at the noise
// level and better than the selected-sensor MLR.
TEST(Baselines, TimeOnlyIsTheTruth) {
  std::vector<drift::Run> runs;
  for (unsigned s = 1; s <= 3; ++s) runs.push_back(WarmUpRun(10 + s, 12.0, 60.0, 300, 0.2));
  const FitReport rep = FitDriftModel(runs, "e_um", FitOptions{});
  EXPECT_TRUE(rep.model.SensorFree()) << rep.chosen;
  ASSERT_FALSE(rep.model.elapsed_time_constants.empty());
  EXPECT_GE(rep.candidates.size(), 4u);  // time1, time2, sensors, sensors+time
  if (rep.model.elapsed_time_constants.size() == 1) {
    EXPECT_NEAR(rep.model.elapsed_time_constants[0], 60.0, 3.0);
    EXPECT_NEAR(rep.model.linear.coefficients(1), 12.0, 0.24);
  }
  const drift::Run log = WarmUpRun(20, 12.0, 60.0, 600, 0.2);
  HoldoutOptions h;
  h.network = false;
  const HoldoutResult hr = Holdout(log, h);
  double time_mae = -1, mlr_mae = -1;
  for (const auto& row : hr.rows_out) {
    const auto& methods = HoldoutMethods();  // the list the report's styles are checked against
    EXPECT_NE(std::find(methods.begin(), methods.end(), row.method), methods.end()) << row.method;
    if (row.method == "time") time_mae = row.test.mae_um;
    if (row.method == "mlr") mlr_mae = row.test.mae_um;
  }
  ASSERT_GE(time_mae, 0) << "no time row";
  EXPECT_LT(time_mae, 0.25);  // the noise: 0.2 um std, mean |N| = 0.16 um
  EXPECT_LT(time_mae, mlr_mae);
  ASSERT_EQ(hr.Strongest().size(), 1u);  // the table names one per channel
}

// Only sensor s2 (group 1) explains the error, with a different schedule in every run: fit picks
// a model containing it, and time alone validates far worse.
TEST(Baselines, OnlyASensorExplains) {
  std::vector<drift::Run> runs;
  for (unsigned s = 0; s < 3; ++s) {
    drift::Run r = synth::PlantedRun(30 + s, 3, 1, {0, 0, 0}, 300, 0.0, 0.0);
    std::mt19937_64 rng(s);
    std::normal_distribution<double> n01(0.0, 1.0);
    double temp = 0;
    for (int k = 0; k < r.samples(); ++k) {  // per-run duty: on/off with a run-specific period
      const bool on = std::fmod(k, 40.0 + 25.0 * s) < 20.0 + 5.0 * s;
      temp += ((on ? 6.0 : 0.0) - temp) * (1 - std::exp(-1.0 / 15.0));
      r.temperature_C(k, 1) = 20 + temp;
    }
    const Eigen::MatrixXd rise = r.Rises();
    for (int k = 0; k < r.samples(); ++k) r.error_um(k, 0) = 2.5 * rise(k, 1) + 0.1 * n01(rng);
    runs.push_back(r);
  }
  const FitReport rep = FitDriftModel(runs, "e_um", FitOptions{});
  const auto& s = rep.model.sensors;
  EXPECT_NE(std::find(s.begin(), s.end(), "g1s0_C"), s.end()) << rep.chosen;
  double sensor_cv = 0, time_cv = 1e300;
  for (const auto& c : rep.candidates) {
    if (c.name == "sensors") sensor_cv = c.cv_rmse_um;
    if (c.name.rfind("time", 0) == 0) time_cv = std::min(time_cv, c.cv_rmse_um);
  }
  EXPECT_GT(time_cv, 10 * sensor_cv);
}

// The cells of the baselines table row of `run` in a drift report: model, none, time only,
// previous run, strongest.
std::vector<std::string> BaselineRow(const std::string& html, const std::string& run) {
  const std::string table = html.substr(html.find("<h2>Baselines</h2>"));
  const std::string first = "<td>" + run + "</td>";
  std::size_t at = table.find(first);
  std::vector<std::string> cells;
  if (at == std::string::npos) return cells;
  at += first.size();
  const std::string row = table.substr(at, table.find("</tr>", at) - at);
  for (std::size_t p = row.find("<td>"); p != std::string::npos; p = row.find("<td>", p + 1))
    cells.push_back(row.substr(p + 4, row.find("</td>", p) - p - 4));
  return cells;
}

// drift report's page carries the baselines: where elapsed time is the truth, a sensor model's
// report names a sensor-free baseline the strongest (the time-only warm-up fitted on the model's
// training runs, or the previous run's default refit, which chooses time there); the first run
// has no previous run; without its training runs among those shown the time-only baseline is not
// invented, and the page says why.
TEST(Baselines, ModelReportShowsThemAndNamesTheStrongest) {
  std::vector<drift::Run> runs;
  for (unsigned s = 1; s <= 3; ++s) runs.push_back(WarmUpRun(10 + s, 12.0, 60.0, 300, 0.2));
  FitOptions f;
  f.candidates = Candidates::kSensors;
  const FitReport rep = FitDriftModel({runs[0], runs[1]}, "e_um", f);
  ASSERT_FALSE(rep.model.SensorFree());
  const auto dir = test::ScratchDir() / "report_baselines";
  const DriftReportResult r = WriteModelReport(dir, rep, runs, {"test"}, "whirl-no-gnuplot-here");
  std::ifstream in(r.index_html);
  std::stringstream html;
  html << in.rdbuf();
  ASSERT_NE(html.str().find("<h2>Baselines</h2>"), std::string::npos);
  const std::vector<std::string> first = BaselineRow(html.str(), runs[0].name);
  ASSERT_EQ(first.size(), 5u);
  EXPECT_EQ(first[3], "-");  // no previous run
  const std::vector<std::string> third = BaselineRow(html.str(), runs[2].name);
  ASSERT_EQ(third.size(), 5u);
  EXPECT_TRUE(third[4] == "time only" || third[4] == "previous run") << third[4];
  // The noise (0.2 um) and the run-start zero, which carries the first row's noise too.
  EXPECT_LT(std::stod(third[2]), 0.5);
  EXPECT_LT(std::stod(third[2]), std::stod(third[0]));
  EXPECT_NE(third[3], "-");  // drift fit's default on the second run
  EXPECT_LT(std::stod(third[3]), 0.5) << "the default refit chooses time where time is the truth";
  // The result (and the JSON of `drift report --json`) carries the same figures as the page.
  ASSERT_EQ(r.baselines.size(), 3u);
  EXPECT_EQ(r.baselines[2].strongest, third[4]);
  EXPECT_NEAR(r.baselines[2].time_only_mae_um, std::stod(third[2]), 0.005);
  EXPECT_NEAR(r.baselines[2].model_mae_um, std::stod(third[0]), 0.005);
  const nlohmann::json j = ReportBaselinesJson(r.baselines, r.baseline_notes);
  EXPECT_TRUE(j["runs"][0]["previous_run_mae_um"].is_null());
  EXPECT_EQ(j["runs"][2]["strongest"], third[4]);
  EXPECT_NEAR(j["runs"][2]["none_mae_um"].get<double>(), std::stod(third[1]), 0.005);
  // Only the third run shown: the training runs are absent, the time-only cell stays empty.
  const DriftReportResult r2 =
      WriteModelReport(dir, rep, {runs[2]}, {"test"}, "whirl-no-gnuplot-here");
  std::ifstream in2(r2.index_html);
  std::stringstream html2;
  html2 << in2.rdbuf();
  const std::vector<std::string> only = BaselineRow(html2.str(), runs[2].name);
  ASSERT_EQ(only.size(), 5u);
  EXPECT_EQ(only[2], "-");
  EXPECT_NE(html2.str().find("time only: not fitted"), std::string::npos);
}

// One "previous run" across drift report and drift monitor --day: drift fit at its defaults on
// the run before (PreviousRunOptions), the same name and the same figure for the same runs; the
// week ranks only rows covering every day (time has no fit for the first day).
TEST(Baselines, PreviousRunIsOneDefinitionInReportAndMonitor) {
  std::vector<drift::Run> runs;
  for (unsigned s = 1; s <= 3; ++s) runs.push_back(WarmUpRun(40 + s, 10.0, 50.0, 300, 0.2));
  FitOptions f;
  f.candidates = Candidates::kSensors;
  const FitReport rep = FitDriftModel({runs[0]}, "e_um", f);
  const auto dir = test::ScratchDir() / "report_previous";
  const DriftReportResult r = WriteModelReport(dir, rep, runs, {"test"}, "whirl-no-gnuplot-here");
  MonitorOptions o;
  o.check_every = 1e4;  // no check inside a run: only the baselines matter here
  const WeekResult w = MonitorWeek(rep.model, {runs[1], runs[2]}, o);
  for (std::size_t d = 0; d < 2; ++d) {
    const auto& b = w.days[d].baselines;
    const auto prev = std::find_if(b.begin(), b.end(), [](const BaselineResult& x) {
      return x.name == kPreviousRunBaseline;
    });
    ASSERT_NE(prev, b.end());
    if (d == 1) {  // day runs[2], previous run runs[1]: the report's third row
      EXPECT_NEAR(prev->score.mae_um, r.baselines[2].previous_run_mae_um, 1e-9);
    }
  }
  const DriftModel expected = FitDriftModel({runs[1]}, "e_um", PreviousRunOptions(rep.model)).model;
  EXPECT_NEAR(r.baselines[2].previous_run_mae_um,
              ComputeErrorStats(PredictRun(expected, runs[2]).measured_um -
                                PredictRun(expected, runs[2]).predicted_um)
                  .mae_um,
              1e-9);
  // The week: time covers the second day only and is not ranked; it is compared over that day.
  int time_days = -1;
  for (const WeekRow& row : w.week)
    if (row.name == "time") time_days = row.days;
  EXPECT_EQ(time_days, 1);
  EXPECT_NE(w.strongest, "time");
  ASSERT_EQ(w.partial.size(), 1u);
  EXPECT_EQ(w.partial[0].name, "time");
  EXPECT_EQ(w.partial[0].days, std::vector<int>{1});
  double best_full = 1e300;
  for (const WeekRow& row : w.week)
    if (row.days == 2) best_full = std::min(best_full, row.score.mae_um);
  for (const WeekRow& row : w.week)
    if (row.name == w.strongest) {
      EXPECT_DOUBLE_EQ(row.score.mae_um, best_full);
    }
}

}  // namespace
}  // namespace whirl::drift
