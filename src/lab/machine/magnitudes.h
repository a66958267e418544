#pragma once
// Uncompensated machine error per cut of a field scenario, split by source (truth side, for the
// documentation of magnitudes and for checking the world before any strategy result). For each
// test-day cut the machine's part of the lead deviation, d_p(x) = m_p(t(x), z(x)) - m_p(0, z_0)
// with the tool at z(x) = z_start - x at t(x) = x / v_f, for p = head, Z axis and their sum; the
// figures are the band width (max - min) over the thread and the worst band width within any
// 1000 mm (core/window_range.h), um. The workpiece's own part comes from the
// workpiece simulator and is not in these figures.
#include <cstdint>
#include <string>
#include <vector>

#include "machine/scenarios.h"

namespace whirl::machine {

struct CutMagnitude {
  int machine = 0, day = 0, job = 0;
  StartType start_type = StartType::kCold;
  double head_thread_um = 0, z_thread_um = 0, total_thread_um = 0;
  double head_1000_um = 0, z_1000_um = 0, total_1000_um = 0;
  double hall_slope_k_per_h = 0;
};

struct ScenarioMagnitudes {
  std::string scenario;
  std::vector<CutMagnitude> cuts;
};

/// The test-day cuts of `machines` machines of a field scenario (seeds as BuildMachineWorld).
ScenarioMagnitudes MeasureMagnitudes(const FieldMachineConfig& config,
                                     const MachineScenario& scenario, std::uint64_t seed,
                                     int machines, const CalendarSpec& spec);

/// Table: per scenario the median and worst over cuts of each figure, and the median of the
/// total over the thread per start type. Markdown or aligned text.
std::string FormatMagnitudes(const std::vector<ScenarioMagnitudes>& rows, bool markdown);

}  // namespace whirl::machine
