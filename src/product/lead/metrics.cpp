#include "lead/metrics.h"

#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl::lead {

namespace {

// Whether a position lies in the useful travel l_u = [x0 + m, x_end - m] of a margin m, with a
// tolerance against the rounding of its ends.
struct UsefulTravel {
  UsefulTravel(const LeadDeviation& lead, double end_margin_mm)
      : start(lead.position_mm.front() + end_margin_mm),
        end(lead.position_mm.back() - end_margin_mm),
        eps(1e-9 * std::max(1.0, std::abs(lead.position_mm.back()))) {}
  bool Holds(double x) const { return x >= start - eps && x <= end + eps; }
  double start, end, eps;
};

}  // namespace

void CheckEndMargin(const LeadDeviation& lead, double end_margin_mm, const std::string& name) {
  const std::string rule =
      name + ": " + FormatNumber(end_margin_mm) +
      " mm breaks the rule: a finite excess travel l_e >= 0 mm at each end "
      "that leaves at least 2 samples in the useful travel l_u = length - 2 l_e";
  if (!(end_margin_mm >= 0) || !std::isfinite(end_margin_mm)) throw InputError(rule);
  const UsefulTravel lu(lead, end_margin_mm);
  const auto n = static_cast<std::size_t>(std::count_if(
      lead.position_mm.begin(), lead.position_mm.end(), [&](double x) { return lu.Holds(x); }));
  if (n < 2)
    throw InputError(rule + "; on the curve [" + FormatNumber(lead.position_mm.front()) + ", " +
                     FormatNumber(lead.position_mm.back()) +
                     "] mm it leaves l_u = " + FormatNumber(lu.end - lu.start) + " mm holding " +
                     std::to_string(n) + " sample(s)");
}

LeadMetrics ComputeLeadMetrics(const LeadDeviation& lead, const LeadMetricOptions& options) {
  ValidateLeadDeviation(lead, "lead-deviation curve");
  CheckEndMargin(lead, options.end_margin_mm, "end_margin_mm");
  if (!(options.lead_mm >= 0) || !std::isfinite(options.lead_mm))
    throw InputError("lead_mm = " + FormatNumber(options.lead_mm) +
                     ": must be finite and >= 0 (0 = unknown)");
  if (!(options.window_300_mm > 0) || !(options.window_1000_mm > 0))
    throw InputError("window_300_mm = " + FormatNumber(options.window_300_mm) +
                     ", window_1000_mm = " + FormatNumber(options.window_1000_mm) +
                     ": windows must be > 0");
  const UsefulTravel lu(lead, options.end_margin_mm);
  std::vector<double> x, d;
  for (std::size_t i = 0; i < lead.size(); ++i) {
    if (lu.Holds(lead.position_mm[i])) {
      x.push_back(lead.position_mm[i]);
      d.push_back(lead.deviation_um[i]);
    }
  }

  LeadMetrics m;
  m.samples = x.size();
  m.useful_start_mm = x.front();
  m.useful_travel_mm = x.back() - x.front();

  // Least-squares mean travel line d ~ a + b (x - x0), centred for conditioning.
  const double n = static_cast<double>(x.size());
  double mx = 0, md = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    md += d[i];
  }
  mx /= n;
  md /= n;
  double sxx = 0, sxd = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxd += (x[i] - mx) * (d[i] - md);
  }
  const double slope = sxd / sxx;  // um per mm; sxx > 0 as x is strictly increasing
  const double offset_at_start = md + slope * (x.front() - mx);
  m.mean_line_slope_um_per_m = slope * 1000.0;
  m.mean_line_offset_um = offset_at_start;
  m.e_a_um = slope * m.useful_travel_mm;

  std::vector<double> r(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) r[i] = d[i] - (md + slope * (x[i] - mx));
  const auto [rmin, rmax] = std::minmax_element(r.begin(), r.end());
  m.v_u_um = *rmax - *rmin;
  m.v_300_um = MaxWindowRange(x, r, options.window_300_mm);
  if (options.lead_mm > 0) {
    std::vector<double> steps;
    for (std::size_t i = 1; i < x.size(); ++i) steps.push_back(x[i] - x[i - 1]);
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    if (steps[steps.size() / 2] <= options.lead_mm / 2)
      m.v_2pi_um = MaxWindowRange(x, r, options.lead_mm);
  }
  const auto [dmin, dmax] = std::minmax_element(d.begin(), d.end());
  m.accumulated_total_um = *dmax - *dmin;
  m.accumulated_1000_um = MaxWindowRange(x, d, options.window_1000_mm);
  return m;
}

void to_json(nlohmann::json& j, const LeadMetrics& m) {
  j = nlohmann::json{{"useful_travel_mm", m.useful_travel_mm},
                     {"useful_start_mm", m.useful_start_mm},
                     {"mean_line_offset_um", m.mean_line_offset_um},
                     {"mean_line_slope_um_per_m", m.mean_line_slope_um_per_m},
                     {"e_a_um", m.e_a_um},
                     {"v_u_um", m.v_u_um},
                     {"v_300_um", m.v_300_um},
                     {"v_2pi_um", m.v_2pi_um ? nlohmann::json(*m.v_2pi_um) : nlohmann::json()},
                     {"accumulated_1000_um", m.accumulated_1000_um},
                     {"accumulated_total_um", m.accumulated_total_um},
                     {"samples", m.samples}};
}

}  // namespace whirl::lead
