#pragma once
// Training a machine drift model only from what a shop can measure, on the legacy machine
// (machine/machine.h). The legacy protocol's training runs (idle warm-ups and cutting runs, one per
// day from cold) are measured with instruments instead of being read as exact channels:
//   probe   a check ring on the chuck read by a touch probe on the head at z = probe_z_mm every
//           probe_every_min (ISO 230-3 warm-up test; 1.0 um per reading: Renishaw OMP40-2
//           repeatability plus re-seating, estimate), one unknown zero per run;
//   laser   an interferometer at laser targets along Z every laser_every_min during the idle
//           warm-ups (ISO 230-2; 0.3 um + 0.3 ppm of the travel per reading: Renishaw XL-80),
//           one unknown zero per target and run.
// A reading is m(t, z) = offset + zscrew_per_1000 (z_fixed - z) / 1000 of the run at its sample,
// plus its noise and its record's zero (N(0, 50 um)): the instrument is the only reader of the
// run's error channels, and the day logs handed to the estimator have none. The day logs carry
// the sensors and the control's duty signals a SINUMERIK 840D has without wiring: power_on (0 at
// the first row: the power-on sample), ring_on, cutting, ring_load_pct (the legacy world's
// stand-in: 20 % idle, 20 + 60 v_c / 180 % cutting).
#include <cstdint>
#include <string>
#include <vector>

#include "drift/joint.h"
#include "drift/measurements.h"
#include "drift/run_file.h"

namespace whirl::machine_eval {

struct ShopProtocol {
  double probe_every_min = 10, probe_sigma_um = 1.0, probe_z_mm = 150;
  double laser_every_min = 20, laser_noise_um = 0.3, laser_noise_ppm = 0.3;
  std::vector<double> laser_targets_mm = {500, 3000, 5500};
  double record_zero_std_um = 50;
};

/// The run as a control logs it: sensors, time and the duty columns; no error channel.
drift::Run ControlDayLog(const drift::Run& run, double cutting_speed_m_min);

/// The measurement records of the training runs (calendar day = run index), day logs without
/// error channels; `z_fixed_mm` the Z screw's fixed bearing. The runs must hold offset_um and
/// zscrew_per_1000_um (read only at the readings' samples). `speeds` per run (cutting speed of
/// the cutting runs; ignored for idle runs).
drift::ShopRecord MeasureTrainingRuns(const std::vector<drift::Run>& runs,
                                      const std::vector<double>& speeds, double z_fixed_mm,
                                      const ShopProtocol& protocol, std::uint64_t seed);

/// The machine models a shop can fit from those records, every family with the same records
/// and the same estimator (drift/joint.h): warmup (lags of power_on: time since power-on),
/// schedule (lags of ring_on, cutting, ring_load_pct), and the sensor model: the candidate with
/// the smallest grouped cross-validated RMSE (leave one calendar day out) among
///   sensors             forward choice from all sensors, own lags;
///   sensors+<rule>      the better sensor-free rule's inputs and lags, sensors added while the
///                       CV falls by more than 1 %;
///   <rule>              the better sensor-free rule itself (warmup or schedule by CV),
/// so the sensor model is never worse than the sensor-free rules in cross-validation; a slope
/// is learned only over the range the Z-spanning readings cover (JointFitOptions).
struct ShopModels {
  drift::JointDriftModel sensors, warmup, schedule;
  std::string sensors_choice;  ///< which candidate the sensor model is (see above)
};
/// `schedule_inputs`: the control signals of the schedule rule (the legacy log has these three).
ShopModels FitShopModels(const drift::ShopRecord& record, double z_fixed_mm,
                         const std::vector<std::string>& schedule_inputs = {"ring_on", "cutting",
                                                                            "ring_load_pct"});

}  // namespace whirl::machine_eval
