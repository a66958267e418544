// The report with hostile screw names: gnuplot still renders every plot, nothing a name
// says is ever executed, the page carries no markup from a name; and the evaluation's worker
// threads hand any exception to the caller.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "compare/compare.h"
#include "compare/evaluate.h"
#include "compare/report.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/run_program.h"
#include "support/scratch_dir.h"
#include "support/source_dir.h"

namespace whirl::compare {
namespace {
namespace fs = std::filesystem;

using test::kSource;

class ShippedModelReport : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path model = kSource / "models/default.json";
    const fs::path history = kSource / "datasets/whirling_train.csv";
    ASSERT_TRUE(fs::exists(model)) << model << " not shipped";
    ASSERT_TRUE(fs::exists(history)) << history << " not shipped";
    model_ = workpiece::LoadWorkpieceModel(model);
    rule_ = BuildExperienceRule(ReadProcessTable(history, true));
    iso_ = lead::ReadIsoToleranceTable(kSource / "datasets/standards/iso3408_3_lead_tolerances.csv");
  }
  workpiece::WorkpieceModel model_;
  ExperienceRule rule_;
  lead::IsoToleranceTable iso_;
};

TEST_F(ShippedModelReport, HostileScrewNamesRenderPlotsAndRunNothing) {
  if (!ProgramSucceeds({"gnuplot", "--version"})) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = whirl::test::ScratchDir() / "whirl_hostile report 'dir'";
  fs::remove_all(dir);
  const fs::path pwned = whirl::test::ScratchDir() / "whirl_PWNED";
  fs::remove(pwned);
  const std::vector<std::string> names = {
      "x'; system \"touch " + pwned.string() + "\"; set title '", "O'Brien",
      "back\\slash\nnew line\r\"double\" `touch " + pwned.string() + "`",
      "<script>alert('x')</script>", "$(touch " + pwned.string() + ") ^_@{}"};
  CompareOptions options;
  options.seed = 5;
  const ScrewComparison base = CompareScrew(screw::ReferenceScrew(), model_, rule_, iso_, options);
  std::vector<ScrewComparison> comparisons;
  for (const std::string& name : names) {
    comparisons.push_back(base);
    comparisons.back().screw.name = name;
  }
  const ReportResult r = WriteReport(dir, comparisons, {});
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  EXPECT_TRUE(r.plots_rendered);
  std::size_t pngs = 0;
  for (const auto& f : r.files) pngs += f.extension() == ".png" && fs::file_size(f) > 0;
  EXPECT_EQ(pngs, 3 * names.size());
  EXPECT_FALSE(fs::exists(pwned)) << "a screw name ran a command";
  const std::string html = ReadTextFile(dir / "index.html");
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;"), std::string::npos);
  EXPECT_NE(html.find("O&#39;Brien"), std::string::npos);
  // Every file name is a slug: no separator, quote or control character from a name.
  for (const auto& f : r.files) {
    const std::string name = f.filename().string();
    EXPECT_EQ(name.find_first_of("'\"\\\n\r$`<> "), std::string::npos) << name;
  }
  fs::remove_all(dir);
}

TEST_F(ShippedModelReport, AFailingReportLeavesNoFileBehind) {
  const fs::path dir = whirl::test::ScratchDir() / "whirl_report_all_or_nothing";
  fs::remove_all(dir);
  fs::create_directories(dir / "index.html");  // the last file cannot be written
  CompareOptions options;
  options.seed = 2;
  const ScrewComparison c = CompareScrew(screw::ReferenceScrew(), model_, rule_, iso_, options);
  ReportOptions ro;
  ro.plots = ProgramSucceeds({"gnuplot", "--version"});
  EXPECT_THROW(WriteReport(dir, {c}, ro), InputError);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
  ASSERT_EQ(left.size(), 1u) << left.back();  // no CSV, script, PNG, JSON or staging folder
  EXPECT_EQ(left[0], "index.html");
  fs::remove_all(dir / "index.html");
  const ReportResult r = WriteReport(dir, {c}, ro);
  EXPECT_EQ(r.files.back(), dir / "index.html");
  for (const auto& f : r.files) EXPECT_TRUE(fs::is_regular_file(f)) << f;
  fs::remove_all(dir);
}

// A rerun whose plots are not rendered removes the figures an earlier run left: the page that
// says "not rendered" never sits beside an old figure of the same screw.
TEST_F(ShippedModelReport, UnrenderedPlotLeavesNoOldFigure) {
  if (!ProgramSucceeds({"gnuplot", "--version"})) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = whirl::test::ScratchDir() / "whirl_report_stale_png";
  fs::remove_all(dir);
  CompareOptions options;
  options.seed = 3;
  const ScrewComparison c = CompareScrew(screw::ReferenceScrew(), model_, rule_, iso_, options);
  ASSERT_TRUE(WriteReport(dir, {c}, {}).plots_rendered);
  std::size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(dir)) pngs += e.path().extension() == ".png";
  ASSERT_EQ(pngs, 3u);
  ReportOptions ro;
  ro.gnuplot_command = "false";  // runs, fails, renders nothing
  const ReportResult r = WriteReport(dir, {c}, ro);
  EXPECT_FALSE(r.plots_rendered);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_NE(e.path().extension(), ".png") << e.path();
  fs::remove_all(dir);
}

TEST_F(ShippedModelReport, EvaluateHandsAnyWorkerExceptionToTheCaller) {
  const std::vector<screw::Screw> screws(4, screw::ReferenceScrew());
  EvaluateOptions options;
  options.threads = 2;
  const auto throwing = [](std::size_t, std::size_t) { throw std::logic_error("not InputError"); };
  EXPECT_THROW(EvaluateScrews(screws, model_, rule_, iso_, options, throwing), std::logic_error);
}

TEST_F(ShippedModelReport, EvaluateRecordsAnInfeasibleScrewAsFailed) {
  screw::Screw bad = screw::ReferenceScrew();
  bad.process.diameter_mm = -80;  // CompareScrew validates the screw: an InputError
  EvaluateOptions options;
  options.threads = 2;
  const Evaluation e = EvaluateScrews({screw::ReferenceScrew(), bad}, model_, rule_, iso_, options);
  ASSERT_EQ(e.screws.size(), 2u);
  EXPECT_TRUE(e.screws[0].ok);
  EXPECT_FALSE(e.screws[1].ok);
  EXPECT_NE(e.screws[1].error.find("diameter"), std::string::npos) << e.screws[1].error;
  EXPECT_EQ(e.summary.failed, 1u);
}

}  // namespace
}  // namespace whirl::compare
