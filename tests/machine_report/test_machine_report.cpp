// The report of one screw (machine_report/machine_report.h), written from the screw a field
// evaluation kept: every strategy has its own look in the one style table (core/plot_style.h),
// the sensor plot has at most 8 lines per panel and every sensor once, the lead plot ends at the
// thread's end, hostile names stay text, and the programs handed over are those of the models a
// shop can train, with each machine datum listed once in the box.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "compare/compare.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/plot_style.h"
#include "core/process.h"
#include "drift/evaluation.h"
#include "drift/joint.h"
#include "drift/monitor.h"
#include "core/safe_text.h"
#include "interp/drift_action.h"
#include "machine/scenarios.h"
#include "machine/sensors.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/shop_models.h"
#include "machine_report/machine_report.h"
#include "support/scratch_dir.h"
#include "workpiece/model.h"

namespace whirl::machine_report {
namespace {

using machine_eval::kMachineStrategyCount;
using machine_eval::MachineStrategy;
using machine_eval::ReportScrew;

std::string ReportSource(const std::string& rel) {
  return std::string(WHIRL_SOURCE_DIR) + "/" + rel;
}

// The first test-day screw of a small production world (one warm-up test, one laser test, two
// past days, one test day), evaluated once for every test here.
const ReportScrew& KeptScrew() {
  static const ReportScrew* kept = [] {
    machine_eval::FieldEvalOptions o;
    o.machines = 1;
    o.threads = 1;
    o.calendar.warmup_speeds_m_min = {180};
    o.calendar.past_days = 2;
    o.calendar.test_days = 1;
    o.keep_report_screw = true;
    const workpiece::WorkpieceModel model =
        workpiece::LoadWorkpieceModel(ReportSource("models/default.json"));
    const compare::ExperienceRule rule = compare::BuildExperienceRule(
        ReadProcessTable(ReportSource("datasets/whirling_500.csv"), true));
    const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(
        ReportSource("datasets/standards/iso3408_3_lead_tolerances.csv"));
    const machine_eval::MachineEvaluation e = machine_eval::EvaluateFieldScenario(
        machine::FindMachineScenario("production"), model, rule, iso, o);
    if (!e.report) throw std::runtime_error("no report screw");
    return new ReportScrew(*e.report);
  }();
  return *kept;
}

std::filesystem::path ReportDir(const std::string& name) {
  const std::filesystem::path dir =
      whirl::test::ScratchDir() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(ReportStyle, EveryStrategyHasItsOwnEntryInTheStyleTable) {
  for (compare::Strategy s : compare::kStrategies)
    EXPECT_NE(FindSeriesStyle(compare::ToString(s)), nullptr)
        << compare::ToString(s) << ": add it to core/plot_style.cpp";
  for (MachineStrategy s : machine_eval::MachineStrategies()) {
    const std::string name = machine_eval::ToString(s);
    EXPECT_NE(FindSeriesStyle(name), nullptr) << name << ": add it to core/plot_style.cpp";
  }
}

// No two strategies of the workpiece and the machine comparison share a colour (the two lists
// overlap and a name means one strategy in both), and no two names of the drift hold-out's
// methods or the monitor's rules share one within their list; every name has its own entry.
TEST(ReportStyle, NoTwoStrategiesShareAColour) {
  std::vector<std::string> strategies;
  for (compare::Strategy s : compare::kStrategies) strategies.push_back(compare::ToString(s));
  for (MachineStrategy s : machine_eval::MachineStrategies())
    if (std::find(strategies.begin(), strategies.end(), machine_eval::ToString(s)) ==
        strategies.end())
      strategies.push_back(machine_eval::ToString(s));
  std::vector<std::string> rules;
  for (drift::UpdateRule r : {drift::UpdateRule::kStatic, drift::UpdateRule::kPatent,
                              drift::UpdateRule::kBayes, drift::UpdateRule::kOffset})
    rules.push_back(drift::ToString(r));
  for (const std::vector<std::string>& list : {strategies, drift::HoldoutMethods(), rules}) {
    std::map<std::string_view, std::string> colour_of;
    for (const std::string& name : list) {
      const SeriesStyle* style = FindSeriesStyle(name);
      ASSERT_NE(style, nullptr) << name << ": add it to core/plot_style.cpp";
      const auto [it, added] = colour_of.emplace(style->colour, name);
      EXPECT_TRUE(added) << name << " and " << it->second << " share " << style->colour;
    }
  }
}

TEST(MachineReport, SensorPanelsHoldAtMostEightLinesAndLeadEndsAtTheThread) {
  const ReportScrew& r = KeptScrew();
  const std::size_t sensors = r.log.sensor_names.size();
  ASSERT_GT(sensors, 8u);
  const std::filesystem::path dir = ReportDir("whirl_machine_report_plots");
  WriteMachineScrewReport(dir.string(), r, nullptr);
  // sensors.gp: one plot command per panel; columns 2..sensors+1 once each.
  std::istringstream gp(ReadTextFile(dir / "sensors.gp"));
  std::multiset<std::string> columns;
  int panels = 0;
  for (std::string line; std::getline(gp, line);) {
    if (line.rfind("plot ", 0) != 0) continue;
    ++panels;
    int lines = 0;
    for (std::size_t at = line.find("using 1:"); at != std::string::npos;
         at = line.find("using 1:", at + 1), ++lines)
      columns.insert(line.substr(at + 8, line.find(' ', at + 8) - at - 8));
    EXPECT_LE(lines, 8) << line;
  }
  EXPECT_GE(panels, static_cast<int>((sensors + 7) / 8));
  EXPECT_EQ(columns.size(), sensors);
  for (std::size_t s = 0; s < sensors; ++s) EXPECT_EQ(columns.count(std::to_string(s + 2)), 1u);
  // lead.gp: x from the thread start to its end; every strategy in its style.
  const std::string lead = ReadTextFile(dir / "lead.gp");
  const double thread = r.result.screw.thread_length_mm;
  EXPECT_NE(lead.find("set xrange [0:" + FormatNumber(thread) + "]"), std::string::npos) << lead;
  for (MachineStrategy s : machine_eval::MachineStrategies())
    EXPECT_NE(lead.find(GnuplotWith(machine_eval::ToString(s))), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(MachineReport, HostileNamesStayText) {
  const std::string hostile = "a'b\"c\\d\n<script>alert(1)</script>";
  ReportScrew r = KeptScrew();
  r.result.screw.name = hostile;
  r.log.sensor_names.front() = hostile;  // past the machine's name rule, to test escaping
  r.sensors = {hostile};
  const std::filesystem::path dir = ReportDir("whirl_machine_report_hostile");
  const std::string index = WriteMachineScrewReport(dir.string(), r, nullptr).index_html;
  const std::string html = ReadTextFile(index);
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;"), std::string::npos);
  const std::string script = ReadTextFile(dir / "sensors.gp");
  EXPECT_NE(script.find(GnuplotString(hostile)), std::string::npos);
  EXPECT_NE(script.find("noenhanced"), std::string::npos);
  // A second report replaces whirl's own; a file that is not whirl's refuses the folder and stays.
  EXPECT_NO_THROW(WriteMachineScrewReport(dir.string(), r, nullptr));
  WriteFileAtomic(dir / "notes.txt", "mine");
  EXPECT_THROW(WriteMachineScrewReport(dir.string(), r, nullptr), InputError);
  EXPECT_TRUE(std::filesystem::exists(dir / "notes.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir.string() + ".partial"));
  std::filesystem::remove_all(dir);
}

// The threshold after `datum` on the header lines of an NC program ("; requires ...").
int HeaderAtLeast(const std::string& nc, const std::string& datum) {
  std::smatch m;
  const std::regex re(datum + R"( \S+ >= (\d+))");
  return std::regex_search(nc, m, re) ? std::stoi(m[1]) : -1;
}

// The programs handed over are those of the models a shop can train: the drift program is the
// sensor model's (the report screw's offset and slope channels), not a model of the simulator's
// truth; the box lists each machine datum once, MD28254 with the larger of the two programs'
// thresholds. Without a profile the report stands without programs and says why.
TEST(MachineReport, TheProgramsAreTheShopTrainedModelsAndTheBoxListsEachDatumOnce) {
  const ReportScrew& r = KeptScrew();
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ReportSource("datasets/machines/whirling_840d.json"));
  const std::filesystem::path dir = ReportDir("whirl_machine_report_programs");
  const MachineReport written = WriteMachineScrewReport(dir.string(), r, &profile);
  ASSERT_TRUE(written.programs) << written.programs_note;
  const std::string drift_nc = ReadTextFile(dir / "WHIRL_DRIFT_COMP.SPF");
  const std::string plan_nc = ReadTextFile(dir / "WHIRL_TEMP_COMP.SPF");
  interp::DriftActionOptions d = profile.DriftOptions();
  d.reference = interp::DriftReference::kStart;
  auto statements = [](const std::string& nc) {  // the program without its comment lines
    std::string out;
    std::istringstream in(nc);
    for (std::string line; std::getline(in, line);)
      if (line.rfind(";", 0) != 0) out += line + "\n";
    return out;
  };
  EXPECT_EQ(statements(drift_nc),
            statements(interp::FormatDriftNcProgram(r.offset, d, "", &r.slope)))
      << "the drift program applies the sensor model's channels";
  EXPECT_NE(drift_nc.find("trained only from shop measurements"), std::string::npos);
  const std::string html = ReadTextFile(dir / "index.html");
  for (const char* datum : {"MD10300", "MD28050", "MD28250", "MD28254", "MD32750", "MD32760"}) {
    const std::size_t at = html.find(std::string("<li>") + datum);
    EXPECT_NE(at, std::string::npos) << datum;
    EXPECT_EQ(html.find(std::string("<li>") + datum, at + 1), std::string::npos)
        << datum << " listed twice";
  }
  const int both = std::max(HeaderAtLeast(drift_nc, "MD28254"), HeaderAtLeast(plan_nc, "MD28254"));
  ASSERT_GT(both, 0);
  EXPECT_NE(HeaderAtLeast(drift_nc, "MD28254"), HeaderAtLeast(plan_nc, "MD28254"));
  EXPECT_NE(html.find("<li>MD28254 $MC_MM_NUM_AC_PARAM &gt;= " + std::to_string(both) + ":"),
            std::string::npos);
  std::filesystem::remove_all(dir);
  const MachineReport bare = WriteMachineScrewReport(dir.string(), r, nullptr);
  EXPECT_FALSE(bare.programs);
  EXPECT_NE(bare.programs_note.find("no machine profile"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "WHIRL_DRIFT_COMP.SPF"));
  std::filesystem::remove_all(dir);
}

// Where the programs' model is both_grey, the programs are the grey box's: the drift program runs
// its offset, slope and blank term (reference model), the plan latches the blank at the thread
// start, and the page says which model and why; a profile without drift.blank_param falls back
// to both_shop's programs and says so.
TEST(MachineReport, WhereTheProgramsModelIsTheGreyBoxItsProgramsAreHandedOut) {
  ReportScrew r = KeptScrew();
  ASSERT_FALSE(r.grey.Inputs().empty());
  r.programs_strategy = MachineStrategy::kBothGrey;
  r.programs_reason = "both_grey: picked by the test";
  // The default since the fourteenth round: both_grey applies grey_short_mix's line on a short
  // record, and its programs are the mix's (here with w = 0.6, so both components show).
  ASSERT_TRUE(r.mix_computed && r.mix_applied);
  const ReportScrew mixed = [&] {
    ReportScrew m = r;
    m.mix_weight = 0.6;
    return m;
  }();
  r.mix_applied = false;  // the grey box's line alone (--grey-without-short-mix)
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ReportSource("datasets/machines/whirling_840d.json"));
  const std::filesystem::path dir = ReportDir("whirl_machine_report_grey");
  const MachineReport written = WriteMachineScrewReport(dir.string(), r, &profile);
  ASSERT_TRUE(written.programs) << written.programs_note;
  EXPECT_TRUE(written.programs_grey);
  EXPECT_EQ(written.programs_reason, "both_grey: picked by the test");
  const std::string drift_nc = ReadTextFile(dir / "WHIRL_DRIFT_COMP.SPF");
  const interp::GreyBoxAction a = interp::GreyBoxActionModels(r.grey);
  interp::DriftActionOptions d = profile.DriftOptions();
  d.reference = interp::DriftReference::kModel;
  auto statements = [](const std::string& nc) {
    std::string out;
    std::istringstream in(nc);
    for (std::string line; std::getline(in, line);)
      if (line.rfind(";", 0) != 0) out += line + "\n";
    return out;
  };
  EXPECT_EQ(statements(drift_nc),
            statements(interp::FormatDriftNcProgram(a.offset, d, "", &a.slope, a.Blank())));
  EXPECT_NE(ReadTextFile(dir / "WHIRL_TEMP_COMP.SPF").find("$AC_PARAM[96]=$AC_PARAM[95]"),
            std::string::npos);
  EXPECT_NE(ReadTextFile(dir / "index.html").find("both_grey: picked by the test"),
            std::string::npos);
  interp::MachineProfile no_blank = profile;
  no_blank.drift->blank_param = -1;
  std::filesystem::remove_all(dir);
  const MachineReport fallback = WriteMachineScrewReport(dir.string(), r, &no_blank);
  ASSERT_TRUE(fallback.programs);
  EXPECT_FALSE(fallback.programs_grey);
  EXPECT_NE(fallback.programs_note.find("drift.blank_param"), std::string::npos)
      << fallback.programs_note;
  EXPECT_NE(fallback.programs_reason.find("both_shop"), std::string::npos);
  std::filesystem::remove_all(dir);
  const MachineReport mix = WriteMachineScrewReport(dir.string(), mixed, &profile);
  ASSERT_TRUE(mix.programs && mix.programs_grey) << mix.programs_note;
  EXPECT_FALSE(mix.mix_programs);  // the programs themselves: no second drift action
  EXPECT_EQ(statements(ReadTextFile(dir / "WHIRL_DRIFT_COMP.SPF")),
            statements(interp::FormatDriftNcProgram(
                {{&a.offset, &a.slope, a.Blank(), 0.6},
                 {&mixed.mix_rule_offset, &mixed.mix_rule_slope, nullptr, 0.4}},
                d)));
  std::filesystem::remove_all(dir);
}

// The programs' model is fixed before the test days: the grey box wherever it was fitted, whatever
// the test screws' medians say (they are quoted for information), else both_shop.
TEST(MachineReport, TheProgramsModelIsTheGreyBoxWhereverItWasFitted) {
  std::array<machine_eval::SeedStats, kMachineStrategyCount> s{};
  auto& shop = s[static_cast<std::size_t>(MachineStrategy::kBothShop)];
  auto& grey = s[static_cast<std::size_t>(MachineStrategy::kBothGrey)];
  shop.screws = grey.screws = 12;
  shop.total_median_um = 10.0;
  grey.total_median_um = 8.0;
  std::string why;
  EXPECT_EQ(machine_eval::ProgramsStrategy(s, true, &why), MachineStrategy::kBothGrey);
  EXPECT_NE(why.find("both_grey 8.0 um, both_shop 10.0 um"), std::string::npos) << why;
  EXPECT_EQ(machine_eval::ProgramsStrategy(s, false, &why), MachineStrategy::kBothShop);
  EXPECT_EQ(why.rfind("both_shop", 0), 0u) << why;
  grey.total_median_um = 12.0;  // worse on the test screws: the rule does not look
  EXPECT_EQ(machine_eval::ProgramsStrategy(s, true, &why), MachineStrategy::kBothGrey);
  EXPECT_NE(why.find("both_grey 12.0 um, both_shop 10.0 um"), std::string::npos) << why;
}

// The largest drift action the default field grey box can produce fits the default profile: every
// sensor of the field machine (machine::DefaultSensorSpecs, as its logs name them) on both
// channels (FieldGreyCandidate, the model both_grey takes on a long record), as many lags as the
// fit may choose (FieldGreyBoxOptions().max_lags) at the longest time constants of its grid, and
// the blank term. The generator's own counts (DriftRequirements: MD28250's static actions, the
// last $AC_PARAM) against the profile's drift IDs, parameter range and control limits, and the
// program is written (IDs, slots and every line within the control's 512 characters).
TEST(MachineReport, TheDefaultProfileHoldsTheLargestFieldGreyBoxDriftAction) {
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ReportSource("datasets/machines/whirling_840d.json"));
  std::vector<std::string> sensors;
  for (const machine::FieldSensorSpec& s : machine::DefaultSensorSpecs())
    sensors.push_back(s.name + "_C");
  ASSERT_EQ(sensors.size(), 13u);
  const machine_eval::GreyCandidateFit all =
      machine_eval::FieldGreyCandidate(6400, false, sensors);
  ASSERT_EQ(all.spec.offset_sensors, sensors);
  ASSERT_EQ(all.spec.slope_sensors, sensors);
  const drift::GreyBoxOptions fit = machine_eval::FieldGreyBoxOptions();
  ASSERT_GE(fit.max_lags, 1);
  ASSERT_GE(fit.tau_grid.size(), static_cast<std::size_t>(fit.max_lags));
  drift::GreyBoxModel m;
  m.offset_sensors = all.spec.offset_sensors;
  m.slope_sensors = all.spec.slope_sensors;
  m.blank_sensor = all.spec.blank_sensor;
  ASSERT_FALSE(m.blank_sensor.empty());
  m.time_constants.assign(fit.tau_grid.end() - fit.max_lags, fit.tau_grid.end());
  const Eigen::Index n = static_cast<Eigen::Index>(sensors.size()) * (1 + fit.max_lags);
  m.a = Eigen::VectorXd::Constant(n, -0.0123);
  m.g = Eigen::VectorXd::Constant(n, 0.0045);
  m.slope_intercept_um_per_1000 = 1.5;
  m.blank_um_per_1000_per_k = -11.8;
  m.offset_min = m.slope_min = Eigen::VectorXd::Constant(n, -5.0);
  m.offset_max = m.slope_max = Eigen::VectorXd::Constant(n, 15.0);
  m.blank_min_c = 15, m.blank_max_c = 30;
  const interp::GreyBoxAction a = interp::GreyBoxActionModels(m);
  interp::DriftActionOptions d = profile.DriftOptions();
  d.reference = interp::DriftReference::kModel;
  double actions = -1, last_slot = -1;
  for (const interp::ControlRequirement& r :
       interp::DriftRequirements(a.offset, d, &a.slope, a.Blank())) {
    if (r.datum.rfind("MD28250", 0) == 0) actions = r.value;
    if (r.datum.rfind("MD28254", 0) == 0) last_slot = r.value - 1;
  }
  EXPECT_LE(actions, d.sync_id_last - d.sync_id_first + 1);
  EXPECT_LE(actions, d.control.sync_elements);
  EXPECT_LE(last_slot, d.param_last);
  EXPECT_LT(last_slot, d.control.ac_params);
  // The action's slots hold every feature of both channels (13 x 3 each): the model is this big.
  EXPECT_GT(last_slot, d.param_first + 2 * n);
  std::string nc;
  ASSERT_NO_THROW(nc = interp::FormatDriftNcProgram(a.offset, d, "", &a.slope, a.Blank()));
  EXPECT_NE(nc.find("IDS=" + std::to_string(d.sync_id_first + static_cast<int>(actions) - 1) + " "),
            std::string::npos);
  EXPECT_EQ(nc.find("IDS=" + std::to_string(d.sync_id_first + static_cast<int>(actions)) + " "),
            std::string::npos);
}

// The largest grey_short_mix drift action the field can ask for (the mix acts below 20 lead days,
// where the grey box has FieldGreyBoxSpec's five sensors; from 20 lead days on w = 1 and the
// programs are the grey box's, checked above): the five-sensor grey box with the most lags its fit
// allows, mixed with the larger sensor-free rule, schedule (every duty signal with the most lags
// drift::JointFitOptions allows), fits the default profile's IDs and slots by the generator's
// own counts, and the program is written.
TEST(MachineReport, TheDefaultProfileHoldsTheLargestShortMixDriftAction) {
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ReportSource("datasets/machines/whirling_840d.json"));
  const drift::GreyBoxSpec spec = machine_eval::FieldGreyBoxSpec(6400);
  const drift::GreyBoxOptions fit = machine_eval::FieldGreyBoxOptions();
  ASSERT_EQ(spec.offset_sensors.size() + spec.slope_sensors.size(), 5u);
  drift::GreyBoxModel m;
  m.offset_sensors = spec.offset_sensors;
  m.slope_sensors = spec.slope_sensors;
  m.blank_sensor = spec.blank_sensor;
  ASSERT_FALSE(m.blank_sensor.empty());
  m.time_constants.assign(fit.tau_grid.end() - fit.max_lags, fit.tau_grid.end());
  const auto per = static_cast<Eigen::Index>(1 + fit.max_lags);
  const Eigen::Index n_k = static_cast<Eigen::Index>(m.offset_sensors.size()) * per;
  const Eigen::Index n_g = static_cast<Eigen::Index>(m.slope_sensors.size()) * per;
  m.a = Eigen::VectorXd::Constant(n_k, -0.0123);
  m.g = Eigen::VectorXd::Constant(n_g, 0.0045);
  m.slope_intercept_um_per_1000 = 1.5;
  m.blank_um_per_1000_per_k = -11.8;
  m.offset_min = Eigen::VectorXd::Constant(n_k, -5.0);
  m.offset_max = Eigen::VectorXd::Constant(n_k, 15.0);
  m.slope_min = Eigen::VectorXd::Constant(n_g, -5.0);
  m.slope_max = Eigen::VectorXd::Constant(n_g, 15.0);
  m.blank_min_c = 15, m.blank_max_c = 30;
  const interp::GreyBoxAction a = interp::GreyBoxActionModels(m);
  drift::JointDriftModel rule;
  rule.other_inputs = machine_eval::ScheduleInputs();
  const drift::JointFitOptions joint;
  rule.time_constants.assign(joint.tau_grid.end() - joint.max_lags, joint.tau_grid.end());
  const auto n_r =
      static_cast<Eigen::Index>(rule.other_inputs.size()) * (1 + joint.max_lags);
  rule.a = Eigen::VectorXd::Constant(n_r, 0.031);
  rule.g = Eigen::VectorXd::Constant(n_r, -0.0007);
  auto [rule_k, rule_g] = drift::ToDriftModels(rule);
  for (drift::DriftModel* d : {&rule_k, &rule_g}) {
    d->feature_min = Eigen::VectorXd::Constant(n_r, 0.0);
    d->feature_max = Eigen::VectorXd::Constant(n_r, 200.0);
  }
  interp::DriftActionOptions d = profile.DriftOptions();
  d.reference = interp::DriftReference::kModel;
  const std::vector<interp::DriftComponent> parts = {
      {&a.offset, &a.slope, a.Blank(), machine_eval::kShortMixFloor},
      {&rule_k, &rule_g, nullptr, 1 - machine_eval::kShortMixFloor}};
  double actions = -1, last_slot = -1, single = -1;
  for (const interp::ControlRequirement& r : interp::DriftRequirements(parts, d)) {
    if (r.datum.rfind("MD28250", 0) == 0) actions = r.value;
    if (r.datum.rfind("MD28254", 0) == 0) last_slot = r.value - 1;
  }
  for (const interp::ControlRequirement& r :
       interp::DriftRequirements(a.offset, d, &a.slope, a.Blank()))
    if (r.datum.rfind("MD28250", 0) == 0) single = r.value;
  EXPECT_GT(actions, single + 6) << "the rule's actions are counted";
  EXPECT_LE(actions, d.sync_id_last - d.sync_id_first + 1);
  EXPECT_LE(actions, d.control.sync_elements);
  EXPECT_LE(last_slot, d.param_last);
  EXPECT_LT(last_slot, d.control.ac_params);
  EXPECT_GT(last_slot, d.param_first + n_k + n_g + 2 * n_r);  // every feature has its slot
  std::string nc;
  ASSERT_NO_THROW(nc = interp::FormatDriftNcProgram(parts, d));
  const int last_id = d.sync_id_first + static_cast<int>(actions) - 1;
  EXPECT_NE(nc.find("IDS=" + std::to_string(last_id) + " "), std::string::npos);
  EXPECT_EQ(nc.find("IDS=" + std::to_string(last_id + 1) + " "), std::string::npos);
}

}  // namespace
}  // namespace whirl::machine_report
