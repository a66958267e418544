#pragma once
// A shop's measurement records on disk (drift/measurements.h): what `whirl drift fit-grey` fits
// from. One JSON file lists the day logs (drift run files, drift/run_file.h: the sensors as the
// control logged them, <name>_C, and its duty signals) and the records read on them:
//
//   {"format": "whirl-measurement-records", "schema_version": 1,
//    "description": "...",                       optional: where the readings come from
//    "day_logs": ["day01.csv", "day02.csv"],     run files, relative to this file's folder
//    "records": [
//      {"name": "warm-up 1", "kind": "probe",    probe | laser | lead | setup_check
//       "day": 0,                                calendar day (0..100000): the CV's group
//       "log": 0,                                index into day_logs
//       "time_min": [0, 10, 20],                 each reading's time on the log's time axis
//       "z_mm": [150, 150, 150],                 tool position, mm from the chuck face
//       "value_um": [0, 3.1, 5.0],               the reading, um (one unknown zero per record)
//       "sigma_um": [1, 1, 1]}]}                 the instrument's standard deviation, um (> 0)
//
// A reading belongs to the last row of its log at or before its time; a time before the log's
// first row or after its last is an error. The four arrays of a record have one value per
// reading. lead: the measured lead deviation of a past screw at the tool's time and position
// (ISO 3408-3), plus the change of any machine compensation applied while it was cut.
// Limits: |z_mm| <= 100 m, |value_um| <= kMaxAbsErrorUm, 0 < sigma_um <= 1e4, at most 100000
// records and 10 million readings. Every error names the file, the record, the field and the
// rule; a log file's own errors name it (drift/run_file.h).
#include <filesystem>
#include <string>
#include <vector>

#include "drift/measurements.h"

namespace whirl::drift {

inline constexpr const char* kMeasurementRecordsFormat = "whirl-measurement-records";
inline constexpr double kMaxMeasurementSigmaUm = 1e4;

struct MeasurementFile {
  ShopRecord record;
  std::vector<std::string> log_paths;  ///< as the file names them
  std::string description;
};

MeasurementFile ReadMeasurementRecords(const std::filesystem::path& path);

/// The file's text for `record`, its day logs named `log_paths` (one per day log, relative to
/// where the file will be written); readings at their rows' time_min.
std::string FormatMeasurementRecords(const ShopRecord& record,
                                     const std::vector<std::string>& log_paths,
                                     const std::string& description);

}  // namespace whirl::drift
