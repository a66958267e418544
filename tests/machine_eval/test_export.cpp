// The field world's export (machine_eval/field_export.h): the files read back give the shop record
// and control logs the evaluation sees, so fitting from the files equals fitting in memory; bad
// files are refused naming file, line and column.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/random.h"
#include "machine/instruments.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/field_export.h"
#include "machine_eval/shop_models.h"
#include "machine_eval/trained_numbers.h"
#include "support/scratch_dir.h"

namespace whirl::machine_eval {
namespace {

using testing_support::TrainedNumbers;

machine::MachineWorld ExportWorld() {
  machine::CalendarSpec c;
  c.warmup_speeds_m_min = {180};
  c.past_days = 2;
  c.test_days = 1;
  return machine::BuildMachineWorld(machine::DefaultFieldMachine(),
                                    machine::FindMachineScenario("production"), 5, 0, c);
}

std::filesystem::path WriteExport(const machine::MachineWorld& w, const FieldProtocol& p,
                                  const std::string& name) {
  const auto dir = test::ScratchDir() / name;
  std::filesystem::create_directories(dir);
  for (const auto& [file, text] : FieldExportFiles(w.timeline, p, nullptr, 11, {}, "readme"))
    std::ofstream(dir / file) << text;
  return dir;
}

nlohmann::json GreyNumbers(const drift::GreyBoxModel& m) {
  return {std::vector<double>(m.a.data(), m.a.data() + m.a.size()),
          std::vector<double>(m.g.data(), m.g.data() + m.g.size()),
          m.slope_intercept_um_per_1000, m.blank_um_per_1000_per_k, m.blank_tau_min,
          m.prior_strength, m.cv_rmse_um};
}

const machine::MachineWorld& World() {
  static const machine::MachineWorld w = ExportWorld();
  return w;
}

// The shop record read from the files holds the same readings on the same (averaged) logs as
// FieldShopRecord's, and every model fitted from it has the same numbers.
TEST(FieldExport, FittingFromTheFilesEqualsFittingInMemory) {
  const FieldProtocol p;
  const auto dir = WriteExport(World(), p, "export_fit");
  const FieldExportData read = ReadFieldExport(dir, p.sensor_average_min);
  const drift::ShopRecord mem = FieldShopRecord(World().timeline, p, nullptr, 11);
  ASSERT_EQ(read.record.day_logs.size(), mem.day_logs.size());
  for (std::size_t i = 0; i < mem.day_logs.size(); ++i) {
    EXPECT_EQ(read.record.day_logs[i].time_min, mem.day_logs[i].time_min);
    EXPECT_EQ(read.record.day_logs[i].temperature_C, mem.day_logs[i].temperature_C);
    EXPECT_EQ(read.record.day_logs[i].other, mem.day_logs[i].other);
  }
  ASSERT_EQ(read.record.records.size(), mem.records.size());
  for (std::size_t i = 0; i < mem.records.size(); ++i) {
    const auto &a = read.record.records[i], &b = mem.records[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.log, b.log);
    ASSERT_EQ(a.rows.size(), b.rows.size());
    for (std::size_t k = 0; k < a.rows.size(); ++k) {
      EXPECT_EQ(a.rows[k].sample, b.rows[k].sample);
      EXPECT_EQ(a.rows[k].value_um, b.rows[k].value_um);
      EXPECT_EQ(a.rows[k].z_mm, b.rows[k].z_mm);
      EXPECT_EQ(a.rows[k].sigma_um, b.rows[k].sigma_um);
    }
  }
  const double z_ref = World().timeline.machine().config().z.fixed_end_mm;
  const ShopModels from_files = FitShopModels(read.record, z_ref);
  const ShopModels in_memory = FitShopModels(mem, z_ref);
  EXPECT_EQ(TrainedNumbers(from_files.sensors).dump(), TrainedNumbers(in_memory.sensors).dump());
  EXPECT_EQ(TrainedNumbers(from_files.schedule).dump(), TrainedNumbers(in_memory.schedule).dump());
  EXPECT_EQ(GreyNumbers(from_files.grey).dump(), GreyNumbers(in_memory.grey).dump());
  EXPECT_GT(in_memory.grey.a.size(), 0);  // the comparison compares something
}

// The test days' logs are the evaluation's control logs (10 s, averaged as the control does).
TEST(FieldExport, TestDayLogsAreTheEvaluationsControlLogs) {
  const FieldProtocol p;
  const auto dir = WriteExport(World(), p, "export_control");
  const FieldExportData read = ReadFieldExport(dir, p.sensor_average_min);
  ASSERT_EQ(read.test_days, std::vector<int>{0});
  const machine::DayPlan& plan = World().timeline.Day(0);
  const drift::Run control = AverageSensors(
      machine::ControlLog(World().timeline, 0, MixSeed(plan.seed, 0x63746c)), p.sensor_average_min);
  EXPECT_EQ(read.test_logs[0].temperature_C, control.temperature_C);
  EXPECT_EQ(read.test_logs[0].time_min, control.time_min);
}

// A damaged file is refused naming the file, the line and the column.
TEST(FieldExport, BadRecordsAreRefusedNamingFileLineAndColumn) {
  const FieldProtocol p;
  const auto dir = WriteExport(World(), p, "export_bad");
  std::ifstream in(dir / "records.csv");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  // The first data row: its kind (second cell) set to 7.
  std::size_t header = text.find("day,kind");
  std::size_t row = text.find('\n', header) + 1;
  std::size_t comma = text.find(',', row);
  std::string bad = text.substr(0, comma + 1) + "7" + text.substr(text.find(',', comma + 1));
  std::ofstream(dir / "records.csv") << bad;
  try {
    ReadFieldExport(dir, p.sensor_average_min);
    FAIL() << "kind 7 accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("records.csv:"), std::string::npos) << m;
    EXPECT_NE(m.find("column 'kind'"), std::string::npos) << m;
    EXPECT_NE(m.find("within 0..3"), std::string::npos) << m;
  }
}

// The field's grey box makes its choices (lags, the blank's lag, the strength) by forward chaining
// on the leads once the history holds 2 x 10 days of them (FieldGreyBoxOptions; the fourth round
// of issue 41), and FitShopModels fits it so: on a 4-day record with forward_days = 2 the
// field's options give FitGreyBox's forward-chained model, not the leave-one-day-out one.
TEST(FieldGreyBox, ItsChoicesAreByForwardChainingOnTheLeads) {
  const drift::GreyBoxOptions field = FieldGreyBoxOptions();
  EXPECT_EQ(field.validation, drift::GreyValidation::kForwardLeads);
  EXPECT_EQ(field.forward_days, 10);
  machine::CalendarSpec c;
  c.warmup_speeds_m_min = {180};
  c.past_days = 4;
  c.test_days = 1;
  const machine::MachineWorld w = machine::BuildMachineWorld(
      machine::DefaultFieldMachine(), machine::FindMachineScenario("production"), 5, 0, c);
  const drift::ShopRecord rec = FieldShopRecord(w.timeline, FieldProtocol{}, nullptr, 11);
  const double z_ref = w.timeline.machine().config().z.fixed_end_mm;
  drift::GreyBoxOptions forward = field;
  forward.forward_days = 2;
  drift::GreyBoxOptions lodo = forward;
  lodo.validation = drift::GreyValidation::kLeaveOneDayOut;
  EXPECT_NE(GreyNumbers(drift::FitGreyBox(rec, FieldGreyBoxSpec(z_ref), lodo)).dump(),
            GreyNumbers(drift::FitGreyBox(rec, FieldGreyBoxSpec(z_ref), forward)).dump());
  EXPECT_EQ(GreyNumbers(FitShopModels(rec, z_ref).grey).dump(),
            GreyNumbers(drift::FitGreyBox(rec, FieldGreyBoxSpec(z_ref), field)).dump());
}

// With a contact reading of each blank in the logs, the grey box latches that reading (no lag)
// instead of the hall's lag; without it, ambient as before.
TEST(FieldGreyContact, TheGreyBoxTakesTheContactReadingWhenTheLogsHoldIt) {
  machine::CalendarSpec c;
  c.warmup_speeds_m_min = {180};
  c.past_days = 3;
  c.test_days = 1;
  machine::FieldMachineConfig m = machine::DefaultFieldMachine();
  m.stock_offset_std_k = 3;
  const auto scenario = machine::FindMachineScenario("production");
  const machine::MachineWorld plain = machine::BuildMachineWorld(m, scenario, 5, 0, c);
  m.blank_contact_std_k = 0.3;
  const machine::MachineWorld read = machine::BuildMachineWorld(m, scenario, 5, 0, c);
  const FieldProtocol p;
  const double z_ref = read.timeline.machine().config().z.fixed_end_mm;
  const ShopModels a = FitShopModels(FieldShopRecord(plain.timeline, p, nullptr, 11), z_ref);
  const ShopModels b = FitShopModels(FieldShopRecord(read.timeline, p, nullptr, 11), z_ref);
  EXPECT_EQ(a.grey.blank_sensor, "ambient_C");
  EXPECT_EQ(b.grey.blank_sensor, kBlankContactSensor);
  EXPECT_EQ(b.grey.blank_tau_min, kBlankContactTauMin);
  // The lead records identify the blank's expansion near its physical -11.8 um per 1000 mm per K.
  EXPECT_NEAR(b.grey.blank_um_per_1000_per_k, -11.8, 3.0);
}

}  // namespace
}  // namespace whirl::machine_eval
