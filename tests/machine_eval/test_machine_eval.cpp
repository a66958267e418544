// The machine evaluation (machine_eval/machine_eval.h): with every machine component off each
// strategy equals its workpiece-only counterpart of the strategy comparison exactly, and the
// report of one screw keeps hostile names as text.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/process.h"
#include "core/safe_text.h"
#include "machine/machine.h"
#include "machine_eval/machine_eval.h"
#include "machine_eval/machine_report.h"
#include "workpiece/model.h"
#include "screw/screw.h"
#include "support/scratch_dir.h"

namespace whirl::machine_eval {
namespace {

struct Fixture {
  workpiece::WorkpieceModel model =
      workpiece::LoadWorkpieceModel(std::string(WHIRL_SOURCE_DIR) + "/models/default.json");
  compare::ExperienceRule rule = compare::BuildExperienceRule(
      ReadProcessTable(std::string(WHIRL_SOURCE_DIR) + "/datasets/whirling_500.csv", true));
  lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(
      std::string(WHIRL_SOURCE_DIR) + "/datasets/standards/iso3408_3_lead_tolerances.csv");
};

TEST(MachineEvaluation, EveryComponentOffEqualsTheWorkpieceOnlyComparisonExactly) {
  Fixture f;
  machine::MachineConfig off = machine::DefaultMachine();
  off.DisableAll();
  const machine::MachineDay day = machine::MachineDay::Draw(off, 2, 3);
  const MachineModels none;  // nothing fitted when the machine does not drift
  const screw::Screw screw = compare::RandomFeasibleScrews(screw::ReferenceScrew(), 1, 5).front();
  compare::CompareOptions co;
  co.seed = 9;
  const MachineEvalScrew m = EvaluateScrewOnMachine(screw, f.model, f.rule, f.iso, day, none, co);
  const compare::ScrewComparison c = compare::CompareScrew(screw, f.model, f.rule, f.iso, co);
  auto same = [](const lead::LeadMetrics& a, const lead::LeadMetrics& b) {
    EXPECT_EQ(a.accumulated_1000_um, b.accumulated_1000_um);
    EXPECT_EQ(a.accumulated_total_um, b.accumulated_total_um);
    EXPECT_EQ(a.e_a_um, b.e_a_um);
    EXPECT_EQ(a.v_300_um, b.v_300_um);
  };
  same(m.metrics[0], c.Outcome(compare::Strategy::kNone).metrics);
  same(m.metrics[1], c.Outcome(compare::Strategy::kTraditional).metrics);
  same(m.metrics[2], c.Outcome(compare::Strategy::kModel).metrics);
  same(m.metrics[3], c.Outcome(compare::Strategy::kNone).metrics);
  same(m.metrics[4], c.Outcome(compare::Strategy::kModel).metrics);
  EXPECT_EQ(m.source_total_um[1], 0.0);
  EXPECT_EQ(m.source_total_um[2], 0.0);
  EXPECT_EQ(m.source_total_um[3], 0.0);
  // And with the machine on, the truth differs (the test above can fail).
  const machine::MachineDay on = machine::MachineDay::Draw(machine::DefaultMachine(), 2, 3);
  const MachineEvalScrew w = EvaluateScrewOnMachine(screw, f.model, f.rule, f.iso, on, none, co);
  EXPECT_GT(std::abs(w.metrics[0].accumulated_total_um - m.metrics[0].accumulated_total_um), 1.0);
}

}  // namespace
}  // namespace whirl::machine_eval

namespace whirl::machine_eval {
namespace {

TEST(MachineReport, HostileNamesStayText) {
  const std::string hostile = "a'b\"c\\d\n<script>alert(1)</script>";
  MachineEvalScrew r;
  r.ok = true;
  r.screw.name = hostile;
  MachineScrewDetail d;
  machine::MachineConfig c = machine::DefaultMachine();
  d.log = machine::SimulateRun(machine::MachineDay::Draw(c, 1, 1),
                               {"log", drift::RunState::kCutting, 20, 180, 1});
  d.log.sensor_names.front() = hostile;  // past the machine file's name rule, to test escaping
  c.sensors.front().name = hostile;
  EXPECT_THROW(c.Validate("test"), InputError);
  for (auto& l : d.leads) {
    l.position_mm = {0, 1, 2};
    l.deviation_um = {0, 0.5, 1};
  }
  const std::filesystem::path dir = whirl::test::ScratchDir() /
                                    ("whirl_machine_report_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::string index = WriteMachineScrewReport(dir.string(), r, d, {hostile}, {});
  std::ifstream in(index);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;"), std::string::npos);
  std::ifstream gp(dir / "sensors.gp");
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  EXPECT_NE(script.find(GnuplotString(hostile)), std::string::npos);
  EXPECT_NE(script.find("noenhanced"), std::string::npos);
  // A second report replaces whirl's own; a file that is not whirl's refuses the folder and stays.
  EXPECT_NO_THROW(WriteMachineScrewReport(dir.string(), r, d, {}, {}));
  { std::ofstream(dir / "notes.txt") << "mine"; }
  EXPECT_THROW(WriteMachineScrewReport(dir.string(), r, d, {}, {}), InputError);
  EXPECT_TRUE(std::filesystem::exists(dir / "notes.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir.string() + ".partial"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace whirl::machine_eval
