#include "machine_eval/strategies.h"

#include <algorithm>

#include "core/error.h"

namespace whirl::machine_eval {

std::size_t HeldSamples::IndexAt(double t_min) const {
  const auto it = std::upper_bound(time_min.begin(), time_min.end(), t_min);
  return it == time_min.begin() ? 0 : static_cast<std::size_t>(it - time_min.begin()) - 1;
}

HeldSamples RunCausally(const drift::JointDriftModel& model, const drift::Run& log) {
  HeldSamples h;
  drift::JointEvaluator ev(model);
  const Eigen::MatrixXd u = drift::JointRawInputs(model, log);
  for (int k = 0; k < log.samples(); ++k) {
    const drift::JointEvaluator::Output o =
        ev.Step(log.time_min[static_cast<std::size_t>(k)], u.row(k).transpose());
    h.time_min.push_back(log.time_min[static_cast<std::size_t>(k)]);
    h.k0_um.push_back(o.k0_um);
    h.slope_um_per_1000.push_back(o.slope_um_per_1000);
  }
  return h;
}

HeldSamples RunCausally(const drift::GreyBoxModel& model, const drift::Run& log) {
  HeldSamples h;
  drift::GreyBoxEvaluator ev(model);
  const Eigen::MatrixXd u = drift::GreyBoxRawInputs(model, log);
  for (int k = 0; k < log.samples(); ++k) {
    const double t = log.time_min[static_cast<std::size_t>(k)];
    const drift::GreyBoxEvaluator::Output o = ev.Step(t, u.row(k).transpose());
    h.time_min.push_back(t);
    h.k0_um.push_back(o.k0_um);
    h.slope_um_per_1000.push_back(o.slope_um_per_1000);
    h.blank_slope_um_per_1000.push_back(ev.BlankSlope(o.blank_c));
  }
  return h;
}

HeldSamples WithOffsetOf(HeldSamples slope_model, const HeldSamples& offset_model, double share) {
  if (slope_model.time_min != offset_model.time_min)
    throw InputError("WithOffsetOf: the two models were not stepped through the same log (" +
                     std::to_string(slope_model.time_min.size()) + " and " +
                     std::to_string(offset_model.time_min.size()) + " samples)");
  for (std::size_t k = 0; k < slope_model.k0_um.size(); ++k)
    slope_model.k0_um[k] = share == 1.0 ? offset_model.k0_um[k]
                                        : (1.0 - share) * slope_model.k0_um[k] +
                                              share * offset_model.k0_um[k];
  return slope_model;
}

HeldSamples MixedLines(HeldSamples grey, const HeldSamples& rule, double w) {
  if (!(w >= 0 && w <= 1))
    throw InputError("MixedLines: the grey box's weight " + std::to_string(w) +
                     " is outside [0, 1]");
  if (grey.time_min != rule.time_min)
    throw InputError("MixedLines: the two models were not stepped through the same log (" +
                     std::to_string(grey.time_min.size()) + " and " +
                     std::to_string(rule.time_min.size()) + " samples)");
  if (w == 1.0) return grey;
  const auto mix = [w](double g, double r) { return w * g + (1.0 - w) * r; };
  for (std::size_t k = 0; k < grey.k0_um.size(); ++k) {
    grey.k0_um[k] = mix(grey.k0_um[k], rule.k0_um[k]);
    grey.slope_um_per_1000[k] = mix(grey.slope_um_per_1000[k], rule.slope_um_per_1000[k]);
  }
  if (grey.blank_slope_um_per_1000.empty() && !rule.blank_slope_um_per_1000.empty())
    grey.blank_slope_um_per_1000.assign(grey.time_min.size(), 0.0);
  for (std::size_t k = 0; k < grey.blank_slope_um_per_1000.size(); ++k)
    grey.blank_slope_um_per_1000[k] =
        mix(grey.blank_slope_um_per_1000[k],
            rule.blank_slope_um_per_1000.empty() ? 0.0 : rule.blank_slope_um_per_1000[k]);
  return grey;
}

compare::CompensationFunction CausalMachineLine(HeldSamples samples, double cut_start_min,
                                                double z_ref_mm,
                                                std::function<double(double)> z_of_t) {
  const double blank = samples.blank_slope_um_per_1000.empty()
                          ? 0.0
                          : samples.blank_slope_um_per_1000[samples.IndexAt(cut_start_min)];
  return [samples = std::move(samples), cut_start_min, z_ref_mm, blank,
          z_of_t = std::move(z_of_t)](double t_s) {
    if (samples.time_min.empty()) return 0.0;
    const std::size_t k = samples.IndexAt(cut_start_min + t_s / 60.0);
    return samples.k0_um[k] +
           (samples.slope_um_per_1000[k] + blank) * (z_ref_mm - z_of_t(t_s)) / 1000.0;
  };
}

}  // namespace whirl::machine_eval
