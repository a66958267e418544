// What the workpiece report shows (compare/report.h, plan/load.h LoadBox), checked against the
// comparison it is written from: the "load onto the control" box first, with the plan's setting
// data, the files and the programs' own prerequisites; every strategy in the data and the plots;
// the prediction's +-1 sd band around the prediction and each baseline's band from the history;
// each baseline's own features.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include "compare/compare.h"
#include "compare/report.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/numbers.h"
#include "interp/machine_profile.h"
#include "workpiece/model.h"
#include "support/scratch_dir.h"
#include "support/source_dir.h"

namespace whirl::compare {
namespace {
namespace fs = std::filesystem;

using test::kSource;

// The gnuplot scripts of one screw's figures, one after the other (core/report_render.h writes
// one per figure).
std::string Scripts(const fs::path& dir, const std::string& slug) {
  std::string gp;
  for (const char* figure : {"_elongation.gp", "_lead.gp", "_lead_start.gp"})
    gp += ReadTextFile(dir / (slug + figure));
  return gp;
}

class ReportContent : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const workpiece::WorkpieceModel model =
        workpiece::LoadWorkpieceModel(kSource / "models/default.json");
    const ExperienceRule rule =
        BuildExperienceRule(ReadProcessTable(kSource / "datasets/whirling_train.csv", true));
    const lead::IsoToleranceTable iso =
        lead::ReadIsoToleranceTable(kSource / "datasets/standards/iso3408_3_lead_tolerances.csv");
    profile_ = new interp::MachineProfile(
        interp::LoadMachineProfile(kSource / "datasets/machines/example_840d.json"));
    CompareOptions options;
    options.seed = 4;
    options.band = true;
    profile_->ApplyTo(options.plan);
    comparison_ =
        new ScrewComparison(CompareScrew(screw::ReferenceScrew(), model, rule, iso, options));
  }
  static void TearDownTestSuite() {
    delete comparison_;
    delete profile_;
  }
  // The report of the comparison in a fresh directory (no plots: the scripts are still written).
  static fs::path Write(const std::string& name, const ReportOptions& options) {
    const fs::path dir = whirl::test::ScratchDir() / name;
    fs::remove_all(dir);
    ReportOptions o = options;
    o.plots = false;
    WriteReport(dir, {*comparison_}, o);
    return dir;
  }
  static ScrewComparison* comparison_;
  static interp::MachineProfile* profile_;
};
ScrewComparison* ReportContent::comparison_ = nullptr;
interp::MachineProfile* ReportContent::profile_ = nullptr;

TEST_F(ReportContent, ControlBoxComesFirstWithSettingDataFilesAndPrerequisites) {
  ReportOptions o;
  o.control = {
      plan::PlanFilesLoad("../", "WHIRL_T", "t_plan.csv", "t_plan.json", comparison_->plan, profile_)};
  const std::string html = ReadTextFile(Write("whirl_report_box", o) / "index.html");
  const std::size_t box = html.find("<section class='control'");
  const std::size_t box_end = html.find("</section>");
  const std::size_t screw = html.find("<h2>" + comparison_->screw.name + "</h2>");
  ASSERT_NE(box, std::string::npos);
  ASSERT_NE(screw, std::string::npos);
  EXPECT_LT(box_end, screw) << "the box must come before the results";
  EXPECT_EQ(html.find("<h2>", html.find("<h1>")), html.find("<h2>", box))
      << "a section before the box";
  const std::string b = html.substr(box, box_end - box);
  for (const auto& s : comparison_->plan.segments) {
    EXPECT_NE(b.find(FormatFixed(s.sd43900_mm, interp::kDecimalsSd43900Mm)), std::string::npos);
    EXPECT_NE(b.find(FormatFixed(s.sd43910, interp::kDecimalsSd43910)), std::string::npos);
    EXPECT_NE(b.find(FormatFixed(s.sd43920_mm, interp::kDecimalsPositionMm)), std::string::npos);
  }
  for (const char* f : {"../WHIRL_T.SPF", "../WHIRL_T_RESET.SPF", "../t_plan.csv"})
    EXPECT_NE(b.find(std::string("href='") + f + "'"), std::string::npos) << f;
  EXPECT_NE(b.find("MD28254 " + std::to_string(profile_->control.ac_params)), std::string::npos);
  // The machine data the program needs, from the plan's data, each datum once with its threshold.
  for (const interp::ControlRequirement& r : interp::PlanRequirements(comparison_->plan, "WHIRL_T")) {
    const std::string line = "<li>" + r.datum;
    const std::size_t at = b.find(line);
    EXPECT_NE(at, std::string::npos) << r.datum;
    EXPECT_EQ(b.find(line, at + 1), std::string::npos) << r.datum << " listed twice";
  }
  EXPECT_NE(b.find("MD32750 $MA_TEMP_COMP_TYPE on axis Z: bits 0 and 1 set (= 3)"),
            std::string::npos);
  EXPECT_NE(b.find("After an aborted cut"), std::string::npos);
  EXPECT_NE(b.find("WHIRL_T_RESET"), std::string::npos);
  // The demo's plan is placed on the machine's axis by its profile: positions in MCS.
  EXPECT_NE(b.find("passes [mm, MCS]"), std::string::npos);
  // Without files the box still gives the setting data and says where the programs come from;
  // compare's plan has no machine profile: its positions count from the thread start, not MCS.
  const std::string bare = ReadTextFile(Write("whirl_report_bare", {}) / "index.html");
  EXPECT_NE(bare.find("writes no NC programs"), std::string::npos);
  EXPECT_NE(bare.find("SD43910 slope"), std::string::npos);
  const std::string bare_box = bare.substr(0, bare.find("</section>"));
  EXPECT_EQ(bare_box.find("MCS"), std::string::npos);
  EXPECT_NE(bare_box.find("passes [mm from the thread start]"), std::string::npos);
  EXPECT_NE(bare_box.find("SD43920 reference [mm from the thread start]"), std::string::npos);
}

TEST_F(ReportContent, EveryStrategyIsInTheDataAndThePlots) {
  const ScrewComparison& c = *comparison_;
  const fs::path dir = Write("whirl_report_strategies", {});
  const std::string slug = Slug(c.screw.name);
  const CsvTable lead = ReadCsv(dir / (slug + "_lead.csv"));
  const CsvTable el = ReadCsv(dir / (slug + "_elongation.csv"));
  const std::string gp = Scripts(dir, slug);
  for (const auto& o : c.outcomes) {
    const std::vector<double> dev = lead.Column(ToString(o.strategy) + "_deviation_um");
    ASSERT_EQ(dev.size(), o.lead.size());
    for (std::size_t i = 0; i < dev.size(); i += 97)
      EXPECT_NEAR(dev[i], o.lead.deviation_um[i], 1e-6);
    // Its column is plotted, in its style, in both lead plots.
    const std::size_t col = lead.ColumnIndex(ToString(o.strategy) + "_deviation_um") + 1;
    std::size_t n = 0;
    for (std::size_t at = gp.find("using 1:" + std::to_string(col) + " "); at != std::string::npos;
         at = gp.find("using 1:" + std::to_string(col) + " ", at + 1))
      ++n;
    EXPECT_GE(n, 2u) << ToString(o.strategy);
    if (o.strategy == Strategy::kNone) continue;
    const std::vector<double> comp = el.Column(ToString(o.strategy) + "_compensation_um");
    const auto& expected = c.compensation_um[static_cast<std::size_t>(o.strategy)];
    for (std::size_t i = 0; i < comp.size(); i += 97) EXPECT_NEAR(comp[i], expected[i], 1e-6);
  }
  // The lead axis ends at the thread's end.
  EXPECT_NE(gp.find("set xrange [0:" + FormatNumber(c.screw.thread_length_mm) + "]"),
            std::string::npos);
}

// The legend names the model's real family: the shipped network as "network", a power law as
// "power law" (never "network").
TEST_F(ReportContent, LegendNamesTheModelsFamily) {
  EXPECT_EQ(comparison_->model_family, "network");
  const auto legend = [](const ScrewComparison& c, const std::string& name) {
    const fs::path dir = whirl::test::ScratchDir() / name;
    fs::remove_all(dir);
    ReportOptions o;
    o.plots = false;
    WriteReport(dir, {c}, o);
    return Scripts(dir, Slug(c.screw.name));
  };
  EXPECT_NE(
      legend(*comparison_, "whirl_report_legend_network").find("'model (network, 840D plan)'"),
      std::string::npos);
  ScrewComparison power = *comparison_;
  power.model_family = "power law";
  const std::string gp = legend(power, "whirl_report_legend_power");
  EXPECT_NE(gp.find("'model (power law, 840D plan)'"), std::string::npos);
  EXPECT_NE(gp.find("'compensation: model (power law, 840D plan)'"), std::string::npos);
  EXPECT_EQ(gp.find("network"), std::string::npos);
}

TEST_F(ReportContent, PredictionBandContainsThePredictionAndWidensWithItsSd) {
  const ScrewComparison& c = *comparison_;
  ASSERT_GT(c.prediction.stddev.max_elongation_um, 0);
  const CsvTable el =
      ReadCsv(Write("whirl_report_band", {}) / (Slug(c.screw.name) + "_elongation.csv"));
  const auto t = el.Column("time_s"), p = el.Column("predicted_elongation_um"),
             lo = el.Column("predicted_minus_1sd_um"), hi = el.Column("predicted_plus_1sd_um");
  for (std::size_t i = 0; i < t.size(); ++i) {
    ASSERT_LE(lo[i], p[i] + 1e-9) << "t = " << t[i];
    ASSERT_GE(hi[i], p[i] - 1e-9) << "t = " << t[i];
  }
  // On the plateau the band is the plateau -+ its sd (hand check of the corner curves).
  const double l = c.prediction.mean.max_elongation_um, sd = c.prediction.stddev.max_elongation_um;
  EXPECT_NEAR(lo.back(), std::max(0.0, l - sd), 1e-3);
  EXPECT_NEAR(hi.back(), l + sd, 1e-3);
}

// The model's +-1 sd band on the lead plots: a larger compensation leaves a smaller deviation
// (d = [e(t) - c(t)] - [e(0) - c(0)], c(0) = 0), and the band curves lie below and above the
// prediction, so the +1 sd plan's deviation lies below the model's and the -1 sd plan's above it,
// up to the plans' chord tolerance (each within tolerance_um of its curve); the band CSV holds
// them and both panels of both lead plots draw it.
TEST_F(ReportContent, LeadBandBracketsTheModelUpToThePlansTolerance) {
  const ScrewComparison& c = *comparison_;
  const lead::LeadDeviation& model = c.Outcome(Strategy::kModel).lead;
  const lead::LeadDeviation& low = c.band_leads[0];
  const lead::LeadDeviation& high = c.band_leads[1];
  ASSERT_EQ(low.size(), model.size());
  ASSERT_EQ(high.size(), model.size());
  const double tol = 2 * c.plan.options.tolerance_um;
  double width = 0;
  for (std::size_t i = 0; i < model.size(); ++i) {
    ASSERT_GE(low.deviation_um[i], model.deviation_um[i] - tol) << model.position_mm[i];
    ASSERT_LE(high.deviation_um[i], model.deviation_um[i] + tol) << model.position_mm[i];
    width = std::max(width, low.deviation_um[i] - high.deviation_um[i]);
  }
  EXPECT_GT(width, 0.1) << "the band has no width";
  const fs::path dir = Write("whirl_report_lead_band", {});
  const CsvTable band = ReadCsv(dir / (Slug(c.screw.name) + "_lead_band.csv"));
  const auto lo = band.Column("model_minus_1sd_deviation_um");
  ASSERT_EQ(lo.size(), low.size());
  for (std::size_t i = 0; i < lo.size(); i += 97) EXPECT_NEAR(lo[i], low.deviation_um[i], 1e-6);
  const std::string gp = Scripts(dir, Slug(c.screw.name));
  std::size_t plotted = 0;
  for (std::size_t at = gp.find("_lead_band.csv"); at != std::string::npos;
       at = gp.find("_lead_band.csv", at + 1))
    ++plotted;
  EXPECT_EQ(plotted, 4u) << "the band in both panels of both lead plots";
}

TEST_F(ReportContent, EachBaselineShowsItsOwnFeaturesAndNoStaleProse) {
  const ScrewComparison& c = *comparison_;
  const std::string html = ReadTextFile(Write("whirl_report_features", {}) / "index.html");
  auto row = [&html](const std::string& start) {
    const std::size_t at = html.find("<tr><td>" + start);
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</tr>", at) - at);
  };
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0f", c.experience_ramp_time_s);
  EXPECT_NE(row("ramp (").find(std::string(buf) + " (linear ramp)"), std::string::npos);
  std::snprintf(buf, sizeof buf, "<td>%.0f</td>", c.traditional_features.settle_time_s);
  EXPECT_NE(row("traditional (").find(buf), std::string::npos) << row("traditional (");
  std::snprintf(buf, sizeof buf, "<td>%.0f</td>", c.regression_features.settle_time_s);
  EXPECT_NE(row("regression (").find(buf), std::string::npos) << row("regression (");
  EXPECT_EQ(html.find("three"), std::string::npos);
  EXPECT_EQ(html.find("traditional rule ("), std::string::npos);
}

// Every baseline's +-1 sd band comes from the history alone: its rule's leave-one-out error
// (ExperienceRule) times its plateau for this screw (traditional: its rule's; the model: the
// prediction's sd; none: no band); the elongation CSV holds each baseline's compensation times
// 1 -+ that error, and both lead plots shade each baseline's curve -+ its sd.
TEST_F(ReportContent, EachBaselineHasABandFromTheHistorysLeaveOneOutError) {
  const ScrewComparison& c = *comparison_;
  const ExperienceRule rule =
      BuildExperienceRule(ReadProcessTable(kSource / "datasets/whirling_train.csv", true));
  ASSERT_TRUE(rule.has_choice);
  const auto sd = [&c](Strategy s) { return c.band_sd_um[static_cast<std::size_t>(s)]; };
  const Strategy rules[] = {Strategy::kClass, Strategy::kTable, Strategy::kNearest};
  for (std::size_t k = 0; k < kHistoryRuleCount; ++k)
    EXPECT_DOUBLE_EQ(sd(rules[k]), rule.choice.loo_relative_error[k] *
                                       c.history_features[k].max_elongation_um);
  EXPECT_DOUBLE_EQ(sd(Strategy::kTraditional),
                   sd(rules[static_cast<std::size_t>(c.traditional_rule)]));
  EXPECT_DOUBLE_EQ(sd(Strategy::kRamp),
                   rule.ramp_loo_relative_error * c.experience_class.plateau_um);
  EXPECT_DOUBLE_EQ(sd(Strategy::kRegression), rule.regression_loo_relative_error *
                                                  c.regression_features.max_elongation_um);
  EXPECT_DOUBLE_EQ(sd(Strategy::kModel), c.prediction.stddev.max_elongation_um);
  EXPECT_EQ(sd(Strategy::kNone), 0.0);
  const fs::path dir = Write("whirl_report_baseline_bands", {});
  const std::string slug = Slug(c.screw.name);
  const CsvTable el = ReadCsv(dir / (slug + "_elongation.csv"));
  const CsvTable lead = ReadCsv(dir / (slug + "_lead.csv"));
  const std::string gp = ReadTextFile(dir / (slug + "_lead.gp")) +
                         ReadTextFile(dir / (slug + "_lead_start.gp"));
  for (Strategy s : kStrategies) {
    if (s == Strategy::kNone || s == Strategy::kModel) continue;
    const std::string name = ToString(s);
    ASSERT_GT(sd(s), 0) << name;
    const double rel = c.band_relative[static_cast<std::size_t>(s)];
    const auto comp = el.Column(name + "_compensation_um");
    const auto lo = el.Column(name + "_minus_1sd_um"), hi = el.Column(name + "_plus_1sd_um");
    double widest = 0;
    for (std::size_t i = 0; i < comp.size(); ++i) {
      ASSERT_NEAR(lo[i], comp[i] * (1 - rel), 1e-6) << name;
      ASSERT_NEAR(hi[i], comp[i] * (1 + rel), 1e-6) << name;
      widest = std::max(widest, (hi[i] - lo[i]) / 2);
    }
    // On the plateau the half-width is the sd (the curve within the plan's tolerance of it).
    EXPECT_NEAR(widest, sd(s), rel * c.plan.options.tolerance_um + 1e-9) << name;
    const std::string col = std::to_string(lead.ColumnIndex(name + "_deviation_um") + 1);
    const std::string band = "using 1:($" + col + "-" + FormatNumber(sd(s)) + "):($" + col + "+" +
                             FormatNumber(sd(s)) + ")";
    std::size_t n = 0;
    for (std::size_t at = gp.find(band); at != std::string::npos; at = gp.find(band, at + 1)) ++n;
    EXPECT_EQ(n, 2u) << name << ": its band in both lead plots";
  }
}

}  // namespace
}  // namespace whirl::compare
