#include "machine/truth.h"

#include "core/error.h"
#include "machine/timeline_data.h"

namespace whirl::machine {

namespace {

const Job& CutJob(const MachineTimeline& timeline, const CutRef& cut) {
  const DayPlan& plan = timeline.Day(cut.day);
  if (cut.job < 0 || cut.job >= static_cast<int>(plan.jobs.size()))
    throw InputError("truth: day " + std::to_string(cut.day) + " has no job " +
                     std::to_string(cut.job));
  return plan.jobs[cut.job];
}

}  // namespace

TruthSample TrueError(const MachineTimeline& timeline, double abs_min, double z_mm) {
  const auto p = timeline.data().ErrorAt(abs_min, z_mm);
  return {abs_min, z_mm, p.head_um, p.z_um, p.extra_um};
}

std::vector<TruthSample> TrueCutError(const MachineTimeline& timeline, const CutRef& cut) {
  const Job& job = CutJob(timeline, cut);
  const double start = cut.day * 1440.0 + job.cut_start_min;
  const double end = cut.day * 1440.0 + job.cut_end_min;
  const double step = timeline.options().control_sample_s / 60;
  const double blank_c = detail::CutBlankC(timeline.data(), timeline.Day(cut.day), cut.job);
  std::vector<TruthSample> out;
  for (double t = start; t <= end + 1e-9; t += step) {
    const double z = job.kinematics.thread_start_position_mm -
                     job.kinematics.axial_feed_mm_min * (t - start);
    TruthSample p = TrueError(timeline, t, z);
    p.blank_um = detail::BlankReferenceUm(blank_c, z);
    out.push_back(p);
  }
  return out;
}

OffsetSlope TrueOffsetSlope(const MachineTimeline& timeline, double abs_min, double z_ref_mm,
                            double z_lo_mm, double z_hi_mm) {
  OffsetSlope o;
  o.k0_um = TrueError(timeline, abs_min, z_ref_mm).total_um();
  const int n = 21;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; ++i) {
    const double z = z_lo_mm + (z_hi_mm - z_lo_mm) * i / (n - 1);
    const double x = (z_ref_mm - z) / 1000, y = TrueError(timeline, abs_min, z).total_um();
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double den = n * sxx - sx * sx;
  o.slope_um_per_1000 = den > 0 ? (n * sxy - sx * sy) / den : 0;
  return o;
}

CutHall HallDuringCut(const MachineTimeline& timeline, const CutRef& cut) {
  const Job& job = CutJob(timeline, cut);
  const double start = cut.day * 1440.0 + job.cut_start_min;
  const double end = cut.day * 1440.0 + job.cut_end_min;
  return {detail::CutBlankC(timeline.data(), timeline.Day(cut.day), cut.job),
          timeline.hall().SlopeKPerH(start, end)};
}

}  // namespace whirl::machine
