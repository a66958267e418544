#include "machine/magnitudes.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "core/window_range.h"
#include "machine/timeline_data.h"
#include "machine/truth.h"

namespace whirl::machine {

namespace {

double Range(const std::vector<double>& v) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

CutMagnitude MeasureCut(const MachineTimeline& timeline, const CutRef& cut) {
  const Job& job = timeline.Day(cut.day).jobs[cut.job];
  const double start = cut.day * 1440.0 + job.cut_start_min;
  std::vector<double> x, head, z, total;
  const double blank_c = detail::CutBlankC(timeline.data(), timeline.Day(cut.day), cut.job);
  const TruthSample at0 = TrueError(timeline, start, job.kinematics.thread_start_position_mm);
  for (double s = 0; s <= job.screw.thread_length_mm + 1e-9; s += 10) {
    const double t = start + s / job.kinematics.axial_feed_mm_min;
    const TruthSample p = TrueError(timeline, t, job.kinematics.thread_start_position_mm - s);
    x.push_back(s);
    head.push_back(p.head_um - at0.head_um);
    const double blank =
        detail::BlankReferenceUm(blank_c, p.z_mm) - detail::BlankReferenceUm(blank_c, at0.z_mm);
    z.push_back(p.z_um - at0.z_um + blank);  // the Z axis against the blank (both vs 20 degC)
    total.push_back(p.total_um() - at0.total_um() + blank);
  }
  CutMagnitude m;
  m.day = cut.day;
  m.job = cut.job;
  m.start_type = job.start_type;
  m.head_thread_um = Range(head), m.z_thread_um = Range(z), m.total_thread_um = Range(total);
  m.head_1000_um = MaxWindowRange(x, head, 1000);
  m.z_1000_um = MaxWindowRange(x, z, 1000);
  m.total_1000_um = MaxWindowRange(x, total, 1000);
  m.hall_slope_k_per_h = HallDuringCut(timeline, cut).slope_k_per_h;
  return m;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string Fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace

ScenarioMagnitudes MeasureMagnitudes(const FieldMachineConfig& config,
                                     const MachineScenario& scenario, std::uint64_t seed,
                                     int machines, const CalendarSpec& spec) {
  ScenarioMagnitudes out;
  out.scenario = scenario.name;
  for (int i = 0; i < machines; ++i) {
    const MachineWorld world = BuildMachineWorld(config, scenario, seed, i, spec);
    for (const DayPlan& plan : world.timeline.days()) {
      if (plan.role != DayRole::kTest) continue;
      for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
        CutMagnitude m = MeasureCut(world.timeline, {plan.day, j});
        m.machine = i;
        out.cuts.push_back(m);
      }
    }
  }
  return out;
}

std::string FormatMagnitudes(const std::vector<ScenarioMagnitudes>& rows, bool markdown) {
  const std::vector<std::string> head = {"scenario", "cuts", "head 1000 mm", "Z 1000 mm",
                                         "machine 1000 mm", "head thread", "Z thread",
                                         "machine thread", "machine thread by start type"};
  std::string text = markdown ? "| " : "";
  for (const auto& h : head) text += h + (markdown ? " | " : "  ");
  text += "\n";
  if (markdown) text += "|---|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const ScenarioMagnitudes& s : rows) {
    auto stat = [&](double CutMagnitude::*f) {
      std::vector<double> v;
      for (const auto& c : s.cuts) v.push_back(c.*f);
      return Fmt(Median(v)) + " / " + Fmt(v.empty() ? 0 : *std::max_element(v.begin(), v.end()));
    };
    std::map<std::string, std::vector<double>> by_start;
    for (const auto& c : s.cuts) by_start[ToString(c.start_type)].push_back(c.total_thread_um);
    std::string starts;
    for (const auto& [k, v] : by_start)
      starts += (starts.empty() ? "" : ", ") + k + " " + Fmt(Median(v)) + " (" +
                std::to_string(v.size()) + ")";
    const std::vector<std::string> cells = {
        s.scenario, std::to_string(s.cuts.size()), stat(&CutMagnitude::head_1000_um),
        stat(&CutMagnitude::z_1000_um), stat(&CutMagnitude::total_1000_um),
        stat(&CutMagnitude::head_thread_um), stat(&CutMagnitude::z_thread_um),
        stat(&CutMagnitude::total_thread_um), starts};
    if (markdown) text += "| ";
    for (const auto& c : cells) text += c + (markdown ? " | " : "  ");
    text += "\n";
  }
  text += "(um, median / worst over the test-day cuts; machine part only, truth side)\n";
  return text;
}

}  // namespace whirl::machine
