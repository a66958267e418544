#pragma once
// What a shop can measure of its machine's thermal drift, and nothing else: the records a machine
// drift model is trained from (drift/joint.h). A record is one series of readings taken with one
// zero, so its values are known only up to a constant of its own:
//   probe        a warm-up test (ISO 230-3): a touch probe on the head reads a check ring on the
//                chuck every few minutes at one axis position; zero = the first reading.
//   laser        one target of a laser-interferometer warm-up cycle along Z (ISO 230-2/230-3);
//                the interferometer is zeroed per target at the first cycle.
//   lead         the measured lead deviation of a past screw (ISO 3408-3) plus the change of any
//                machine compensation applied while it was cut, at the tool's time and position:
//                what the machine half must explain (it also holds the workpiece plan's residual).
//   setup_check  the probe readings of one production day (at power-on and at each set-up).
// Every reading carries the day log (sensor temperatures and the control's duty signals, a
// drift::Run) and the sample of that log it was taken at; no record holds an exact truth channel:
// values are readings with their instrument's noise, sigma_um its stated standard deviation.
#include <string>
#include <vector>

#include "drift/run_file.h"

namespace whirl::drift {

struct Measurement {
  int sample = 0;         ///< row of the record's day log at (or last before) the reading
  double time_min = 0;    ///< time of the reading on the day log's axis, min
  double z_mm = 0;        ///< tool position, mm from the chuck face
  double value_um = 0;    ///< reading, um (positive = the tool further towards the chuck)
  double sigma_um = 1.0;  ///< the instrument's standard deviation, um (> 0)
};

struct MeasurementRecord {
  enum class Kind { kProbe, kLaser, kLead, kSetupCheck };
  Kind kind = Kind::kProbe;
  int day = 0;  ///< calendar day (grouping of the cross-validation: one day held out at a time)
  int log = 0;  ///< index of its day log in ShopRecord::day_logs
  std::string name;
  std::vector<Measurement> rows;
};
std::string ToString(MeasurementRecord::Kind k);  ///< "probe", "laser", "lead", "setup_check"

struct ShopRecord {
  std::vector<Run> day_logs;  ///< temperatures (_C) and duty columns (other); no _um channel used
  std::vector<MeasurementRecord> records;
  /// InputError naming the record and row: a log index out of range, a sample outside its log,
  /// a non-finite value or a non-positive sigma.
  void Validate() const;
};

}  // namespace whirl::drift
