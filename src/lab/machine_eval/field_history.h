#pragma once
// The measurement records a shop has of one field machine (machine/timeline.h) before its test
// window, and nothing else: what the machine models of the field evaluation learn from. Each
// history day of the calendar (machine/scenarios.h PlanCalendar) gives its day log (sensors and the
// control's duty signals, one row per log_sample_s, machine/instruments.h DayLog) and:
//   warm-up test  the check ring read by the probe at probe_z_mm every check_every_min from
//                 power-on to power-off (ISO 230-3), one record;
//   laser test    the interferometer at laser_targets_mm every laser_every_min (ISO 230-2), one
//                 record per target (zeroed per target);
//   production    each past screw's measured lead (ISO 3408-3; step lead_step_mm, 0.5 um per
//                 point, a scale error per screw), the tool at z = thread start - x when it cut x,
//                 thinned to the first point of every lead_sample_min of cutting time, taken with
//                 sigma lead_sigma_um (the points also carry the workpiece plan's own residual,
//                 which a machine model can only partly explain); and with setup_checks the probe
//                 reading at power-on and at the start of each set-up (the machine stands anyway),
//                 one record per day.
// Every reading goes through machine/instruments.h (noise, an unknown zero per record); the
// workpiece's part of a lead measurement, (e - c)(t), is supplied by the caller (the workpiece
// simulator and the plan the screw was cut with). No day of the test window (day >= 0) is read.
#include <cstdint>
#include <functional>
#include <vector>

#include "drift/measurements.h"
#include "drift/monitor.h"
#include "machine/instruments.h"
#include "machine/timeline.h"

namespace whirl::machine_eval {

struct FieldProtocol {
  double log_sample_s = 60;                 ///< day logs for training, s
  double check_every_min = 10;              ///< warm-up test probe interval, min
  double probe_sigma_um = 1.0, probe_z_mm = 150;
  double laser_every_min = 20;              ///< min
  double laser_noise_um = 0.3, laser_noise_ppm = 0.3;
  std::vector<double> laser_targets_mm = {500, 1500, 2500, 3500, 4500, 5500};
  double lead_step_mm = 10, lead_noise_um = 0.5, lead_scale_noise_um_per_m = 1.0;
  double lead_sample_min = 5;               ///< one lead point per this much cutting time, min
  double lead_sigma_um = 2.0;               ///< weight of a lead point in the fit, um
  bool setup_checks = true;
  /// The control's input filter: every temperature is the mean of its readings over the last
  /// sensor_average_min (causal; 0 = raw readings). A PLC averages its analog inputs; without it
  /// the 0.1 K noise of one reading goes straight into the compensation. Applied alike to the
  /// training logs and to the control log of the test days.
  double sensor_average_min = 5;
  /// both_shop_monitor (field_monitor.h): the test day's set-up checks (probe at probe_z_mm,
  /// sigma probe_sigma_um) update the sensor model's offset channel; threshold_sigma,
  /// threshold_um, prior_scale and estimate_drift are read, and bayes in rules switches the
  /// update on (rules without bayes: the row is both_shop).
  drift::MonitorOptions monitor;
  /// both_grey's slope sensors through their lags only (FieldGreyBoxOptions' `slope_lags_only`):
  /// an opt-in variant, off by default (docs/machine-history.md, sixth round).
  bool grey_slope_lags_only = false;
  /// both_grey with the field grey box's five physical sensors on a long record too (the model
  /// before the eleventh round, so that older figures reproduce): an opt-in, off by default.
  bool grey_five_sensors = false;
  /// Score the opt-in rows of OffsetCandidate (machine_eval.h) as well: both_grey's slope with
  /// warmup's offset, or with the mean of both offsets (docs/machine-history.md, seventh round).
  bool offset_candidates = false;
  /// Score the opt-in rows of GreyCandidate (machine_eval.h) as well, after the OffsetCandidate
  /// rows (computed with them): grey boxes of another structure (docs/machine-history.md,
  /// eighth round).
  bool grey_candidates = false;
  /// both_grey applies the fourteenth round's grey_short_mix line below 20 lead days (the field
  /// default since its adoption, docs/machine-history.md "Fourteenth round: adoption");
  /// false: the grey box's line alone, the figures before it bit for bit
  /// (--grey-without-short-mix).
  bool grey_short_mix = true;
};

/// The temperature columns of `log` replaced by their mean over the rows with time in
/// (t - window_min, t] (past and present rows only); window_min <= 0: unchanged.
drift::Run AverageSensors(drift::Run log, double window_min);

/// (e - c)(t_s) of a past screw, t_s from its cut start: the workpiece's elongation minus the
/// workpiece compensation it was cut with (the caller's simulator); nullptr = the screw failed
/// (its lead is not measured).
using WorkpieceResidual =
    std::function<std::function<double(double)>(const machine::Job& job, const machine::CutRef& cut)>;

/// The times of a production day's set-up checks [abs min]: the day's power-on first, then the
/// start of every set-up after it (the probe reads the check ring while the machine stands).
std::vector<double> SetupCheckTimes(const machine::DayPlan& plan);

/// A past screw's measured lead reduced to its least-squares slope over the thread (the pitch
/// error a shop reads off the lead chart), with the screw's type: diameter and lead.
struct PastLeadSlope {
  double diameter_mm = 0, lead_mm = 0;
  double slope_um_per_m = 0;  ///< of the measured d(x) over x (all points, full resolution)
};

/// The shop record of every day < 0 of the timeline (see the header comment), seeded;
/// `lead_slopes` (optional) receives the slope of every measured past screw.
drift::ShopRecord FieldShopRecord(const machine::MachineTimeline& timeline,
                                  const FieldProtocol& protocol,
                                  const WorkpieceResidual& workpiece_residual, std::uint64_t seed,
                                  std::vector<PastLeadSlope>* lead_slopes = nullptr);

/// The lead-slope rule (a pitch correction per screw type, learned from measured past screws
/// only): the mean slope of the past screws of the nearest type, types compared by
/// (ln D, ln lead) with equal weights, the k nearest screws (ties by record order); 0 without
/// past screws. The correction is applied on top of the workpiece plan as c(t) = b x(t) / 1000,
/// x = v_f t the cut length [mm] (an SD43910-like slope the operator types in: a positive slope
/// of d(x) is cancelled by a compensation growing the same way).
double LeadSlopeFor(const std::vector<PastLeadSlope>& past, double diameter_mm, double lead_mm,
                    int k = 3);

}  // namespace whirl::machine_eval
