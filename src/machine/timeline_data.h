#pragma once
// Internal to src/machine: the stored truth of a timeline. Included only by timeline.cpp,
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

/// Location temperature of a sensor in kept state k (before its lag).
double LocationC(const TimelineData& d, const DrawnSensor& s, int k);

}  // namespace whirl::machine::detail
