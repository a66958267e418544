#pragma once
// One machine's continuous time line: every planned day and the off time between them (nights,
// weekends: cooling) integrated exactly (network.h) from equilibrium with the hall at 00:00 of the
// first day. While the power is on the state is kept at every control sample (control_sample_s,
// default 10 s); while off on a night_step_s grid (600 s). Heat sources follow the plan (field.h,
// docs/machine-truth.md), inputs held over each step.
//
// The timeline is opaque: the truth in it (node temperatures, m) is read only by instruments.h
// (measurements with their noise) and by truth.h (scoring). Training code takes measurement
// records (drift side) and never includes truth.h.
#include <functional>
#include <memory>
#include <vector>

#include "machine/day.h"
#include "machine/field.h"
#include "machine/hall.h"

namespace whirl::machine {

namespace detail {
struct TimelineData;
}

struct TimelineOptions {
  double control_sample_s = 10;   ///< state kept every this many seconds while on (1-60)
  double night_step_s = 600;      ///< step while off
  /// Verification hook: added to every error the timeline reports (instruments and truth) at
  /// (abs_min, z_mm) without touching any temperature; empty = none. Tests use it to plant
  /// errors that the instruments must or must not see.
  std::function<double(double abs_min, double z_mm)> extra_error_um;
  /// Verification hooks for the test window (abs_min >= 0): source powers x this, hall + this.
  double test_window_power_factor = 1.0;
  double test_window_hall_offset_k = 0.0;
};

/// Duty state of the machine at a control sample (what the control knows of itself).
struct DutyState {
  bool power_on = false, ring_on = false, cutting = false;
  double ring_rpm = 0, drive_power_w = 0, z_speed_mm_min = 0, z_position_mm = 0;
  int job = -1;
};

class MachineTimeline {
 public:
  MachineTimeline() = default;
  const std::vector<DayPlan>& days() const;
  const FieldMachine& machine() const;
  const HallProfile& hall() const;
  const TimelineOptions& options() const;
  /// The plan of day d; InputError if d is not in the calendar.
  const DayPlan& Day(int day) const;
  /// Duty state at abs_min (the latest control sample <= abs_min).
  DutyState Duty(double abs_min) const;
  const detail::TimelineData& data() const { return *data_; }  ///< for instruments/truth only

 private:
  friend MachineTimeline SimulateCalendar(const FieldMachine&, const HallProfile&,
                                          std::vector<DayPlan>, const TimelineOptions&);
  std::shared_ptr<const detail::TimelineData> data_;
};

/// Simulates the calendar (days sorted by index; ClassifyStarts applied). The hall must cover it.
MachineTimeline SimulateCalendar(const FieldMachine& machine, const HallProfile& hall,
                                 std::vector<DayPlan> days, const TimelineOptions& options = {});

}  // namespace whirl::machine
