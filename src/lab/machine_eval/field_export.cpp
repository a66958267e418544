#include "machine_eval/field_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"
#include "drift/measurement_file.h"
#include "machine/truth.h"

namespace whirl::machine_eval {

namespace {

using Kind = drift::MeasurementRecord::Kind;

constexpr double kMaxAbsDay = 1 << 20;  // DaySeed's range

int RoleCode(machine::DayRole r) { return static_cast<int>(r); }

std::string RoleName(int code) {
  return machine::ToString(static_cast<machine::DayRole>(code));
}

// The day's log with check_ring_um: the probe at probe_z_mm read at every row, zeroed at the
// first row (the reading's noise stays in every row).
drift::Run WithCheckRing(drift::Run log, const machine::MachineTimeline& tl,
                         const FieldProtocol& p, std::uint64_t seed) {
  const std::vector<machine::Reading> r =
      machine::ProbeReadings(tl, log.time_min, p.probe_z_mm, p.probe_sigma_um, seed);
  log.error_names = {"check_ring_um"};
  log.error_um.resize(log.samples(), 1);
  for (int k = 0; k < log.samples(); ++k)
    log.error_um(k, 0) = r[static_cast<std::size_t>(k)].value_um - r.front().value_um;
  return log;
}

std::string TruthDayFile(const machine::MachineTimeline& tl, const drift::Run& log,
                         const FieldProtocol& p, const ExportTruthRange& range) {
  std::vector<std::vector<double>> rows;
  for (double t : log.time_min) {
    const machine::TruthSample s = machine::TrueError(tl, t, p.probe_z_mm);
    const machine::OffsetSlope o =
        machine::TrueOffsetSlope(tl, t, range.z_ref_mm, range.z_lo_mm, range.z_hi_mm);
    rows.push_back({t, tl.hall().At(t), s.head_um, s.z_um, s.total_um(), o.k0_um,
                    o.slope_um_per_1000});
  }
  return FormatCsv({"time_min", "hall_true_C", "m_head_um", "m_z_um", "m_check_ring_um", "k0_um",
                    "slope_um_per_1000"},
                   rows,
                   {"TRUTH of the simulated machine (no instrument sees these values): at the day "
                    "log's times [abs min]",
                    "m_*_um: the tool error at the check ring z = " +
                        FormatNumber(p.probe_z_mm) + " mm (head, Z axis, sum), without a zero",
                    "k0_um: m at z_ref = " + FormatNumber(range.z_ref_mm) +
                        " mm; slope_um_per_1000: least-squares slope of m over z = " +
                        FormatNumber(range.z_lo_mm) + ".." + FormatNumber(range.z_hi_mm) +
                        " mm per 1000 mm of (z_ref - z)"});
}

void AddCuts(const machine::MachineTimeline& tl, const ExportTruthRange& range,
             std::vector<std::vector<double>>* cuts, std::vector<std::vector<double>>* truth) {
  for (const machine::DayPlan& plan : tl.days())
    for (std::size_t j = 0; j < plan.jobs.size(); ++j) {
      const machine::Job& job = plan.jobs[j];
      const double start = plan.day * 1440.0 + job.cut_start_min;
      const double end = plan.day * 1440.0 + job.cut_end_min;
      const ProcessInputs& in = job.screw.process;
      cuts->push_back({static_cast<double>(plan.day), static_cast<double>(j),
                       static_cast<double>(job.start_type), start, end, in.diameter_mm,
                       in.pitch_mm, job.screw.thread_length_mm, in.cutting_speed_m_min,
                       job.kinematics.axial_feed_mm_min, job.kinematics.thread_start_position_mm,
                       job.cutting_power_w});
      const machine::CutHall h = machine::HallDuringCut(tl, {plan.day, static_cast<int>(j)});
      const machine::OffsetSlope o =
          machine::TrueOffsetSlope(tl, start, range.z_ref_mm, range.z_lo_mm, range.z_hi_mm);
      truth->push_back({static_cast<double>(plan.day), static_cast<double>(j), h.start_c,
                        h.slope_k_per_h, o.k0_um, o.slope_um_per_1000});
    }
}

std::vector<double> RecordRow(const drift::MeasurementRecord& r, const drift::Measurement& m) {
  double id = 0;
  const auto us = r.name.rfind('_');
  if (r.kind == Kind::kLead || r.kind == Kind::kLaser) id = std::stod(r.name.substr(us + 1));
  return {static_cast<double>(r.day), static_cast<double>(r.kind), id,
          static_cast<double>(m.sample), m.time_min, m.z_mm, m.value_um, m.sigma_um};
}

std::string RecordName(int day, Kind kind, int id) {
  const std::string d = "day" + std::to_string(day) + "_";
  switch (kind) {
    case Kind::kProbe: return d + "warmup_probe";
    case Kind::kLaser: return d + "laser_" + std::to_string(id);
    case Kind::kLead: return d + "lead_" + std::to_string(id);
    case Kind::kSetupCheck: return d + "setup_checks";
  }
  return d;
}

// ---- Reading back --------------------------------------------------------------------------

// The value of a cell, checked: within [lo, hi] and (integer) a whole number.
double ExportCell(const CsvTable& t, std::size_t row, const std::string& column, double lo, double hi,
            bool integer) {
  const double v = t.rows[row][t.ColumnIndex(column)];
  if (!(v >= lo && v <= hi) || (integer && v != std::floor(v)))
    throw InputError(t.source + ":" + std::to_string(t.line_numbers[row]) + ": column '" + column +
                     "': value " + FormatNumber(v) + ": must be " +
                     (integer ? "a whole number " : "") + "within " + FormatNumber(lo) + ".." +
                     FormatNumber(hi));
  return v;
}

int ExportIntCell(const CsvTable& t, std::size_t row, const std::string& column, double lo, double hi) {
  return static_cast<int>(ExportCell(t, row, column, lo, hi, true));
}

drift::Run ReadDayLog(const std::filesystem::path& dir, int day, int role, int rows,
                      double average_min) {
  const bool idle = role == RoleCode(machine::DayRole::kWarmupTest) ||
                    role == RoleCode(machine::DayRole::kLaserTest);
  const std::string file = ExportDayFile(day, static_cast<machine::DayRole>(role));
  drift::Run log = drift::ReadRun(dir / file, idle ? drift::RunState::kIdle
                                                   : drift::RunState::kCutting);
  if (log.samples() != rows)
    throw InputError((dir / file).string() + ": " + std::to_string(log.samples()) +
                     " data rows, days.csv says " + std::to_string(rows));
  if (log.time_from_index)
    throw InputError((dir / file).string() + ": no time_min column (absolute minutes)");
  log.error_names.clear();
  log.error_um.resize(log.samples(), 0);
  return AverageSensors(std::move(log), average_min);
}

void ReadRecords(const std::filesystem::path& path, const std::map<int, int>& log_of_day,
                 drift::ShopRecord* rec) {
  const CsvTable t = ReadCsv(path, /*allow_empty=*/true);
  drift::MeasurementRecord* cur = nullptr;
  int cur_id = 0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const int day = ExportIntCell(t, i, "day", -kMaxAbsDay, -1);
    const Kind kind = static_cast<Kind>(ExportIntCell(t, i, "kind", 0, 3));
    const int id = ExportIntCell(t, i, "id", 0, 1e6);
    const auto log = log_of_day.find(day);
    if (log == log_of_day.end())
      throw InputError(t.source + ":" + std::to_string(t.line_numbers[i]) + ": column 'day': " +
                       std::to_string(day) + " is no history day of days.csv");
    if (!cur || cur->day != day || cur->kind != kind || cur_id != id) {
      rec->records.push_back({kind, day, log->second, RecordName(day, kind, id), {}});
      cur = &rec->records.back();
      cur_id = id;
    }
    const drift::Run& day_log = rec->day_logs[static_cast<std::size_t>(log->second)];
    drift::Measurement m;
    m.sample = ExportIntCell(t, i, "sample", 0, day_log.samples() - 1);
    m.time_min = ExportCell(t, i, "time_min", -drift::kMaxRunTimeMin, drift::kMaxRunTimeMin, false);
    m.z_mm = ExportCell(t, i, "z_mm", -20000, 20000, false);
    m.value_um = ExportCell(t, i, "value_um", -drift::kMaxAbsErrorUm, drift::kMaxAbsErrorUm, false);
    m.sigma_um = ExportCell(t, i, "sigma_um", 1e-6, 1000, false);
    cur->rows.push_back(m);
  }
}

// The record with its days counted from its first (a measurement-records file's days are >= 0;
// the cross-validation groups by day, so a shift changes nothing).
drift::ShopRecord FromDayZero(drift::ShopRecord record) {
  int first = 0;
  for (const drift::MeasurementRecord& r : record.records) first = std::min(first, r.day);
  for (drift::MeasurementRecord& r : record.records) r.day -= first;
  return record;
}

}  // namespace

std::string ExportDayFile(int day, machine::DayRole role) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "day%+04d_%s.csv", day, machine::ToString(role).c_str());
  return buf;
}

std::vector<std::pair<std::string, std::string>> FieldExportFiles(
    const machine::MachineTimeline& timeline, const FieldProtocol& protocol,
    const WorkpieceResidual& workpiece_residual, std::uint64_t record_seed,
    const ExportTruthRange& truth_range, const std::string& readme) {
  FieldProtocol raw = protocol;
  raw.sensor_average_min = 0;
  const drift::ShopRecord record =
      FieldShopRecord(timeline, raw, workpiece_residual, record_seed);
  std::vector<std::pair<std::string, std::string>> files;
  files.emplace_back("README.md", readme);
  std::vector<std::vector<double>> days;
  std::vector<std::string> history_files;  // record.day_logs' files, in order
  std::size_t history = 0;
  for (const machine::DayPlan& plan : timeline.days()) {
    const drift::Run log =
        plan.day < 0 ? record.day_logs.at(history++)
                     : machine::ControlLog(timeline, plan.day, MixSeed(plan.seed, 0x63746c));
    const drift::Run with_ring =
        WithCheckRing(log, timeline, protocol, MixSeed(plan.seed, 0x636872696e67));
    const std::string name = ExportDayFile(plan.day, plan.role);
    if (plan.day < 0) history_files.push_back(name);
    files.emplace_back(
        name, drift::FormatRun(
                  with_ring,
                  {"simulated day log of the field machine (whirl machine export; README.md): "
                   "day " + std::to_string(plan.day) + ", " + machine::ToString(plan.role),
                   "time_min: absolute minutes (day x 1440 + clock); <sensor>_C: the sensors' "
                   "raw readings; check_ring_um: a displacement sensor on the check ring, zeroed "
                   "at the first row"}));
    files.emplace_back("truth_" + name, TruthDayFile(timeline, log, protocol, truth_range));
    days.push_back({static_cast<double>(plan.day), static_cast<double>(machine::Weekday(plan.day)),
                    static_cast<double>(RoleCode(plan.role)),
                    log.samples() > 1 ? 60.0 * (log.time_min[1] - log.time_min[0]) : 0.0,
                    static_cast<double>(log.samples())});
  }
  files.emplace_back(
      "days.csv",
      FormatCsv({"day", "weekday", "role", "sample_s", "rows"}, days,
                {"the calendar of the exported machine; day 0 = the first test day; weekday 0 = "
                 "Monday; role 0 warmup_test, 1 laser_test, 2 history, 3 test; the day's log is "
                 "day<day>_<role>.csv (day signed, 3 digits)"}));
  std::vector<std::vector<double>> rows;
  for (const drift::MeasurementRecord& r : record.records)
    for (const drift::Measurement& m : r.rows) rows.push_back(RecordRow(r, m));
  files.emplace_back(
      "records.csv",
      FormatCsv({"day", "kind", "id", "sample", "time_min", "z_mm", "value_um", "sigma_um"}, rows,
                {"the shop record (what the models of the evaluation learn from): readings with "
                 "their instrument's noise and the record's unknown zero",
                 "kind 0 probe (warm-up test), 1 laser (id = target z mm), 2 lead (a past "
                 "screw's measured lead, id = job; z_mm = the tool position), 3 setup_check",
                 "sample: row of the day's log (0 = first data row); time_min: absolute minutes; "
                 "sigma_um: the weight's standard deviation"}));
  files.emplace_back("records.json", drift::FormatMeasurementRecords(
                                         FromDayZero(record), history_files,
                                         "the shop record of the simulated field machine (whirl "
                                         "machine export; README.md), the same readings as "
                                         "records.csv, for whirl drift fit-grey"));
  std::vector<std::vector<double>> cuts, truth;
  AddCuts(timeline, truth_range, &cuts, &truth);
  files.emplace_back(
      "cuts.csv",
      FormatCsv({"day", "job", "start_type", "cut_start_min", "cut_end_min", "diameter_mm",
                 "lead_mm", "thread_length_mm", "cutting_speed_m_min", "axial_feed_mm_min",
                 "thread_start_mm", "cutting_power_w"},
                cuts,
                {"every cut of the calendar as planned; start_type 0 cold, 1 warm, 2 "
                 "interrupted, 3 long_pause; times in absolute minutes; thread_start_mm: the "
                 "tool's z at the thread start (mm from the chuck face)"}));
  files.emplace_back(
      "truth_cuts.csv",
      FormatCsv({"day", "job", "blank_start_true_C", "hall_slope_true_k_per_h", "k0_um",
                 "slope_um_per_1000"},
                truth,
                {"TRUTH per cut: the blank's temperature at the cut start, the hall's slope over "
                 "the cut, the machine's k0 (z_ref " + FormatNumber(truth_range.z_ref_mm) +
                 " mm) and slope (over z = " + FormatNumber(truth_range.z_lo_mm) + ".." +
                 FormatNumber(truth_range.z_hi_mm) + " mm) at the cut start"}));
  return files;
}

FieldExportData ReadFieldExport(const std::filesystem::path& dir, double sensor_average_min) {
  const CsvTable days = ReadCsv(dir / "days.csv");
  FieldExportData out;
  std::map<int, int> log_of_day;
  int previous = -kMaxAbsDay - 1;
  for (std::size_t i = 0; i < days.rows.size(); ++i) {
    const int day = ExportIntCell(days, i, "day", -kMaxAbsDay, kMaxAbsDay);
    if (day <= previous)
      throw InputError(days.source + ":" + std::to_string(days.line_numbers[i]) +
                       ": column 'day': days must increase strictly");
    previous = day;
    const int role = ExportIntCell(days, i, "role", 0, 3);
    if ((day < 0) == (role == RoleCode(machine::DayRole::kTest)))
      throw InputError(days.source + ":" + std::to_string(days.line_numbers[i]) +
                       ": column 'role': " + RoleName(role) + " on day " + std::to_string(day) +
                       " (test days are day >= 0, every other role before)");
    const int rows = ExportIntCell(days, i, "rows", 1, drift::kMaxRunSamples);
    drift::Run log = ReadDayLog(dir, day, role, rows, sensor_average_min);
    if (day < 0) {
      log_of_day[day] = static_cast<int>(out.record.day_logs.size());
      out.record.day_logs.push_back(std::move(log));
    } else {
      out.test_logs.push_back(std::move(log));
      out.test_days.push_back(day);
    }
  }
  ReadRecords(dir / "records.csv", log_of_day, &out.record);
  out.record.Validate();
  return out;
}

}  // namespace whirl::machine_eval
