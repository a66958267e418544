#pragma once
// The field world's optional parts (issue 41), one set of flags for 'whirl machine evaluate',
// 'export' and 'ceiling': every part off by default, so the documented figures stay reproducible.
#include <string>
#include <vector>

#include "cli/common.h"
#include "core/error.h"
#include "core/numbers.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"

namespace whirl::cli {

struct FieldWorldFlags {
  double blank_h_w_m2k = 0, stock_offset_std_k = 0;
  double blank_contact_std_k = -1;  ///< < 0: no contact reading
  double seasonal_amplitude_k = 0;
  int seasonal_peak_day = 56;
  std::string test_shift_of;  ///< empty: the test days keep the scenario's day rules
};

inline void AddFieldWorldOptions(CLI::App* e, FieldWorldFlags* w) {
  e->add_option("--blank-h-w-m2-per-k", w->blank_h_w_m2k,
                "each blank's thermal lag from its diameter, tau = rho c D / (4 h), with this "
                "convection coefficient h [W/(m^2 K)] (0..100; default 0: every blank 45 min)")
      ->check(NumberIn(0.0, 100.0));
  e->add_option("--stock-offset-std-k", w->stock_offset_std_k,
                "stock from a store or the gate: each blank's temperature at the cut start is the "
                "hall's lagged one plus N(0, this) [K] (0..10; default 0: stored in the hall)")
      ->check(NumberIn(0.0, 10.0));
  e->add_option("--blank-contact-std-k", w->blank_contact_std_k,
                "a contact thermometer reads each blank at clamping with this noise [K] "
                "(0..2; logged as the sensor blank_contact_C; default: no reading)")
      ->check(NumberIn(0.0, 2.0));
  e->add_option("--seasonal-amplitude-k", w->seasonal_amplitude_k,
                "the hall's seasonal swing A_s [K]: + A_s cos(2 pi (day - peak) / 365.25) "
                "(0..15; default 0: no seasons)")
      ->check(NumberIn(0.0, 15.0));
  e->add_option("--seasonal-peak-day", w->seasonal_peak_day,
                "the warmest day of the seasons [day; 0 = the first test day] (-400..400, "
                "default 56)")
      ->check(NumberIn(-400, 400));
  e->add_option("--test-shift-of", w->test_shift_of,
                "a shift-pattern change: the test days follow this scenario's day rules (shift "
                "times, breaks, stops), the training weeks their own (default: no change)");
}

/// The flags applied to the evaluation's options and to the scenarios' halls.
inline void ApplyFieldWorld(const FieldWorldFlags& w, machine_eval::FieldEvalOptions* f,
                            std::vector<machine::MachineScenario>* scenarios) {
  f->machine.blank_h_w_m2k = w.blank_h_w_m2k;
  f->machine.stock_offset_std_k = w.stock_offset_std_k;
  f->machine.blank_contact_std_k = w.blank_contact_std_k;
  if (w.test_shift_of.find(',') != std::string::npos || w.test_shift_of == "all")
    throw InputError("--test-shift-of '" + w.test_shift_of + "': one scenario name");
  if (!w.test_shift_of.empty())
    f->calendar.test_day_options =
        machine::SelectMachineScenarios(w.test_shift_of, "--test-shift-of").at(0).day;
  for (machine::MachineScenario& s : *scenarios) {
    s.hall.seasonal_amplitude_k = w.seasonal_amplitude_k;
    s.hall.seasonal_peak_day = w.seasonal_peak_day;
  }
}

/// The flags as they would be typed (only those that differ from the defaults), for provenance.
inline std::string FieldWorldCommandLine(const FieldWorldFlags& w) {
  std::string s;
  if (w.blank_h_w_m2k > 0) s += " --blank-h-w-m2-per-k " + FormatNumber(w.blank_h_w_m2k);
  if (w.stock_offset_std_k > 0) s += " --stock-offset-std-k " + FormatNumber(w.stock_offset_std_k);
  if (w.blank_contact_std_k >= 0)
    s += " --blank-contact-std-k " + FormatNumber(w.blank_contact_std_k);
  if (w.seasonal_amplitude_k > 0)
    s += " --seasonal-amplitude-k " + FormatNumber(w.seasonal_amplitude_k) +
         " --seasonal-peak-day " + std::to_string(w.seasonal_peak_day);
  if (!w.test_shift_of.empty()) s += " --test-shift-of " + w.test_shift_of;
  return s;
}

}  // namespace whirl::cli
