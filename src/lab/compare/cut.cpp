#include "compare/cut.h"

#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl::compare {

CompensationFunction NoCompensation() {
  return [](double) { return 0.0; };
}

lead::LeadDeviation CutLeadDeviation(const ElongationCurve& truth,
                               const CompensationFunction& compensation_um, double axial_feed_mm_s,
                               double thread_length_mm, double lead_mm, const CutOptions& options) {
  auto positive = [](double value, const char* name) {
    if (!(value > 0) || !std::isfinite(value))
      throw InputError(std::string(name) + " = " + FormatNumber(value) +
                       ": must be finite and > 0");
  };
  positive(axial_feed_mm_s, "axial_feed_mm_s");
  positive(thread_length_mm, "thread_length_mm");
  positive(lead_mm, "lead_mm");
  if (options.sample_step_mm != 0) positive(options.sample_step_mm, "sample_step_mm");
  if (truth.size() < 2 || truth.elongation_um.size() != truth.size())
    throw InputError(
        "truth elongation curve: needs at least 2 samples of time_s and elongation_um");
  const double cutting_time_s = thread_length_mm / axial_feed_mm_s;
  const double last_step = truth.time_s.back() - truth.time_s[truth.size() - 2];
  if (truth.time_s.back() < cutting_time_s - last_step - 1e-9 * cutting_time_s)
    throw InputError("truth elongation curve ends at " + FormatNumber(truth.time_s.back()) +
                     " s, before the cut ends at " + FormatNumber(cutting_time_s) +
                     " s (thread_length_mm / axial_feed_mm_s): simulate the whole thread");

  const double step =
      options.sample_step_mm > 0 ? options.sample_step_mm : std::min(1.0, lead_mm / 10.0);
  const std::size_t intervals = static_cast<std::size_t>(std::ceil(thread_length_mm / step - 1e-9));
  lead::LeadDeviation lead;
  lead.position_mm.reserve(intervals + 1);
  lead.deviation_um.reserve(intervals + 1);
  auto residual = [&](double t_s) {
    return InterpolateLinear(truth.time_s, truth.elongation_um, t_s) - compensation_um(t_s);
  };
  const double r0 = residual(0.0);
  for (std::size_t k = 0; k <= intervals; ++k) {
    const double x = k == intervals ? thread_length_mm : static_cast<double>(k) * step;
    lead.position_mm.push_back(x);
    lead.deviation_um.push_back(residual(x / axial_feed_mm_s) - r0);
  }
  return lead;
}

}  // namespace whirl::compare
