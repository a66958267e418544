#pragma once
// Internal to src/lab/machine: the stored truth of a timeline. Included only by timeline.cpp,
// instruments.cpp and truth.cpp; training code never sees it.
#include <Eigen/Core>
#include <vector>

#include "machine/timeline.h"

namespace whirl::machine::detail {

struct TimelineData {
  FieldMachine machine;
  HallProfile hall;
  std::vector<DayPlan> days;
  TimelineOptions options;
  std::vector<double> abs_min;          ///< kept states, ascending
  std::vector<Eigen::VectorXd> temps;   ///< node temperatures, degC
  std::vector<double> nut_c, hall_c, cabinet_c;
  std::vector<DutyState> duty;
  std::vector<Eigen::VectorXd> lagged;  ///< sensor lag states y, degC (per DrawnSensor)
  /// Index of the latest kept state with abs_min <= t (0 if t is before the first).
  int Locate(double t) const;
  /// Error parts at t (linear in time between kept states) and z, plus the hook.
  struct Parts { double head_um, z_um, extra_um; };
  Parts ErrorAt(double t, double z_mm) const;
};

/// Temperature of a blank stored in the hall at abs_min: the hall air through a first-order lag
/// of tau_min (convolution over the preceding 8 time constants).
double BlankTemperatureC(const TimelineData& d, double abs_min, double tau_min);
/// The lag of the blank of job `job` of `plan`: FieldMachineConfig::blank_tau_min, or from its
/// diameter rho c D / (4 h) when blank_h_w_m2k > 0 [min].
double BlankTauMin(const TimelineData& d, const DayPlan& plan, int job);
/// The blank's temperature at the cut start of job `job` of `plan`: BlankTemperatureC with its
/// lag plus the stock offset N(0, stock_offset_std_k) of that screw (seeded by the day and job).
double CutBlankC(const TimelineData& d, const DayPlan& plan, int job);
/// The same blank at abs_min (its lag and stock offset; the contact reading's truth at clamping).
double BlankAtC(const TimelineData& d, const DayPlan& plan, int job, double abs_min);
/// The blank's part of the lead at 20 degC (Bryan 1990: only differential expansion against the
/// 20 degC reference matters): the workpiece simulator measures its elongation from the blank's
/// temperature T_0 at the cut start; measured at 20 degC a groove cut at z lies further towards
/// the chuck by alpha_blank (T_0 - 20) z, um (m's sign). alpha_blank of sim::PhysicsConstants.
double BlankReferenceUm(double blank_start_c, double z_mm);

/// Location temperature of a sensor in kept state k (before its lag).
double LocationC(const TimelineData& d, const DrawnSensor& s, int k);

}  // namespace whirl::machine::detail
