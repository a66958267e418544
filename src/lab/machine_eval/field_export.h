#pragma once
// A field world's days as files a user can feed to other tools (`whirl machine export`): one
// machine (machine/scenarios.h BuildMachineWorld) of a scenario, its shop record (field_history.h)
// and its test-window control logs, and its truth in files named as such. Every file is CSV
// (core/csv.h, numbers only; codes explained in the '#' lines):
//   days.csv             the calendar: day (0 = first test day), weekday (0 = Monday), role
//                        (0 warmup_test, 1 laser_test, 2 history, 3 test), sample_s, rows
//   day<d>_<role>.csv    a day's log as a drift run file (drift/run_file.h): time_min = absolute
//                        minutes (day x 1440 + clock), <sensor>_C as the sensors read (raw: the
//                        evaluation's control averages them over FieldProtocol::
//                        sensor_average_min, AverageSensors), the control's duty signals, and
//                        check_ring_um, a displacement sensor on the check ring at probe_z_mm
//                        zeroed at the day's first row (machine/instruments.h CheckRingLog's
//                        channel; a shop has it on warm-up tests, not while a screw is in the
//                        chuck: for trying `whirl drift fit --error check_ring_um`). History days
//                        (day < 0) at log_sample_s with the shop record's seeds, test days at the
//                        control sample with the evaluation's (machine/instruments.h ControlLog).
//   records.csv          the shop record's readings (drift/measurements.h): day, kind (0 probe,
//                        1 laser, 2 lead, 3 setup_check), id (lead: job index; laser: target mm;
//                        else 0), sample (row of the day's log), time_min, z_mm, value_um,
//                        sigma_um; a record is a run of rows with the same (day, kind, id)
//   records.json         the same readings as a whirl-measurement-records file
//                        (drift/measurement_file.h) naming the history day logs, for
//                        `whirl drift fit-grey`
//   cuts.csv             every cut as the shop planned it: day, job, start type (0 cold, 1 warm,
//                        2 interrupted, 3 long_pause), cut start and end [abs min], the screw
//   truth_day<d>_<role>.csv  TRUTH at the log's times: hall_true_C, the machine's error at the
//                        check ring (m_head_um, m_z_um, m_check_ring_um, no zero), the 840D form
//                        k0_um about z_ref and slope_um_per_1000 over [z_lo, z_hi] (truth.h)
//   truth_cuts.csv       TRUTH per cut: the blank's temperature at the cut start, the hall's slope
//                        over the cut, k0 and slope at the cut start
//   README.md            provenance: the command, seeds, the world's parameters, the files
// ReadFieldExport reads days.csv, the day logs and records.csv back (every value range-checked,
// errors naming file, line and column): the shop record it gives equals FieldShopRecord's with
// the same protocol (tests/machine_eval/test_export.cpp).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "drift/measurements.h"
#include "machine/scenarios.h"
#include "machine_eval/field_history.h"

namespace whirl::machine_eval {

/// The range of the exported slope truth and its reference.
struct ExportTruthRange {
  double z_ref_mm = 6400, z_lo_mm = 500, z_hi_mm = 5500;
};

/// The files of one machine world, (name, contents) in write order; `record_seed` is the
/// evaluation's (TrainFieldMachine's) seed of the shop record, `readme` the README's text.
/// FieldShopRecord with protocol.sensor_average_min = 0 gives the history logs' raw readings.
std::vector<std::pair<std::string, std::string>> FieldExportFiles(
    const machine::MachineTimeline& timeline, const FieldProtocol& protocol,
    const WorkpieceResidual& workpiece_residual, std::uint64_t record_seed,
    const ExportTruthRange& truth_range, const std::string& readme);

/// What ReadFieldExport gives back.
struct FieldExportData {
  drift::ShopRecord record;             ///< history day logs (averaged) and the readings
  std::vector<drift::Run> test_logs;    ///< the test days' control logs (averaged)
  std::vector<int> test_days;           ///< their day indices
};

/// Reads an export folder; every temperature column averaged over `sensor_average_min`
/// (AverageSensors) as the evaluation's control does; check_ring_um dropped from the logs.
/// InputError naming the file, line, column and rule.
FieldExportData ReadFieldExport(const std::filesystem::path& dir, double sensor_average_min);

/// The file name of a day's log: "day<d>_<role>.csv", d signed with 3 digits ("day-012_history").
std::string ExportDayFile(int day, machine::DayRole role);

}  // namespace whirl::machine_eval
