#include "drift/grey_mix.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "drift/monitor.h"

namespace whirl::drift {

std::vector<std::string> ScheduleInputs() {
  return {"ring_on", "cutting", "ring_load_pct", "z_speed_mm_min"};
}

JointSpec SensorFreeRuleSpec(double z_ref_mm, std::vector<std::string> inputs) {
  JointSpec s;
  s.z_ref_mm = z_ref_mm;
  s.other_inputs = std::move(inputs);
  return s;
}

JointFitOptions SensorFreeRuleOptions() {
  JointFitOptions o;
  o.require_lag = true;
  return o;
}

BaseRules FitBaseRules(const ShopRecord& record, double z_ref_mm,
                       const std::vector<std::string>& schedule_inputs) {
  BaseRules r;
  const JointFitOptions lagged = SensorFreeRuleOptions();
  r.warmup = FitJoint(record, SensorFreeRuleSpec(z_ref_mm, {kWarmupInput}), lagged).model;
  r.schedule = FitJoint(record, SensorFreeRuleSpec(z_ref_mm, schedule_inputs), lagged).model;
  r.is_schedule = r.schedule.cv_rmse_um <= r.warmup.cv_rmse_um;
  return r;
}

namespace {

// The records of the days before `day` (every day log kept: records index them).
ShopRecord Before(const ShopRecord& record, int day) {
  ShopRecord r;
  r.day_logs = record.day_logs;
  for (const MeasurementRecord& m : record.records)
    if (m.day < day) r.records.push_back(m);
  return r;
}

// A lead record's residuals about their weighted mean (w = 1 / sigma^2: a lead is known up to a
// constant), each scaled by 1 / sigma (so a sum of squares is the weighted one), and the sum of w.
std::pair<std::vector<double>, double> Demeaned(const MeasurementRecord& r,
                                                const std::vector<double>& predicted) {
  double sw = 0, swe = 0;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const double w = 1 / (r.rows[i].sigma_um * r.rows[i].sigma_um);
    sw += w, swe += w * (r.rows[i].value_um - predicted[i]);
  }
  std::vector<double> e(r.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i)
    e[i] = (r.rows[i].value_um - predicted[i] - swe / sw) / r.rows[i].sigma_um;
  return {std::move(e), sw};
}

// The pooled sums the guard and the combination weight need, over the scored lead records.
struct PooledResiduals {
  double grey_ss = 0, rule_ss = 0, sw = 0;
  double cross = 0, spread = 0;  ///< sum e_r (e_r - e_g), sum (e_r - e_g)^2
  void Add(const std::vector<double>& grey, const std::vector<double>& rule) {
    for (std::size_t i = 0; i < grey.size(); ++i) {
      const double d = rule[i] - grey[i];
      grey_ss += grey[i] * grey[i], rule_ss += rule[i] * rule[i];
      cross += rule[i] * d, spread += d * d;
    }
  }
};

}  // namespace

GuardScore GuardGreyBox(const ShopRecord& record, const GreyBoxSpec& grey,
                        const GreyBoxOptions& grey_options, const JointSpec& rule,
                        const JointFitOptions& rule_options, int held_days) {
  const std::vector<int> lead_days = LeadDays(record);
  if (held_days < 1)
    throw InputError("grey guard: held_days = " + std::to_string(held_days) + ": must be >= 1");
  const std::size_t held = static_cast<std::size_t>(held_days);
  const std::size_t first = lead_days.size() > held ? lead_days.size() - held : 0;
  PooledResiduals p;
  GuardScore g;
  for (std::size_t k = first; k < lead_days.size(); ++k) {
    const ShopRecord past = Before(record, lead_days[k]);
    if (past.records.empty()) continue;
    GreyBoxModel gm;
    JointDriftModel rm;
    try {
      gm = FitGreyBox(past, grey, grey_options);
      rm = FitJoint(past, rule, rule_options).model;
    } catch (const InputError&) {
      continue;  // too few readings before this day: not scored
    }
    for (const MeasurementRecord& r : record.records) {
      if (r.kind != MeasurementRecord::Kind::kLead || r.day != lead_days[k]) continue;
      const auto [grey_e, w] = Demeaned(r, PredictGreyRecord(gm, record, r));
      p.Add(grey_e, Demeaned(r, PredictRecord(rm, record, r)).first);
      p.sw += w;
    }
    ++g.days;
  }
  if (g.days == 0 || p.sw <= 0) return g;
  g.grey_rms_um = std::sqrt(p.grey_ss / p.sw);
  g.rule_rms_um = std::sqrt(p.rule_ss / p.sw);
  g.keep_grey = g.grey_rms_um <= g.rule_rms_um;
  if (p.spread > 0) g.combination_weight = p.cross / p.spread;
  return g;
}

double ShortMixWeight(bool long_record, const GuardScore& guard) {
  return long_record ? 1.0 : std::clamp(guard.combination_weight, kShortMixFloor, 1.0);
}

void RequireRuleColumns(const ShopRecord& record, const std::vector<std::string>& log_sources,
                        const std::vector<std::string>& schedule_inputs) {
  std::vector<std::string> need = {kWarmupInput};
  need.insert(need.end(), schedule_inputs.begin(), schedule_inputs.end());
  for (std::size_t i = 0; i < record.day_logs.size(); ++i) {
    const std::vector<std::string>& have = record.day_logs[i].other_names;
    for (const std::string& c : need)
      if (std::find(have.begin(), have.end(), c) == have.end())
        throw InputError(
            "day log '" + (i < log_sources.size() ? log_sources[i] : record.day_logs[i].source) +
            "' has no column '" + c +
            "': on a record of fewer than 2 x forward_days lead days the grey box is mixed with "
            "a sensor-free rule (warmup reads power_on, schedule ring_on, cutting, "
            "ring_load_pct, z_speed_mm_min; the control's own signals)");
  }
}

GreyMix FitGreyMix(const ShopRecord& record, const GreyBoxSpec& spec, const GreyBoxOptions& options,
                   const std::vector<std::string>& schedule_inputs) {
  GreyMix m;
  if (LongRecord(record, options)) return m;
  m.applies = true;
  m.rules = FitBaseRules(record, spec.z_ref_mm, schedule_inputs);
  m.guard =
      GuardGreyBox(record, spec, options,
                   SensorFreeRuleSpec(spec.z_ref_mm, m.rules.is_schedule
                                                         ? schedule_inputs
                                                         : std::vector<std::string>{kWarmupInput}),
                   SensorFreeRuleOptions());
  m.weight = ShortMixWeight(false, m.guard);
  return m;
}

ShopControl ShopControlModels(const JointDriftModel& model, const std::vector<Run>& training_logs) {
  ShopControl c;
  std::tie(c.offset, c.slope) = ToDriftModels(model);
  const Eigen::Index p = model.features();
  if (p == 0) return c;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, 1e300), hi = -lo;
  for (const Run& log : training_logs) {
    if (log.samples() == 0) continue;
    const Eigen::MatrixXd x = MonitorDesign(c.offset, log, ReferenceMode::kRunStart);
    lo = lo.cwiseMin(x.rightCols(p).colwise().minCoeff().transpose());
    hi = hi.cwiseMax(x.rightCols(p).colwise().maxCoeff().transpose());
  }
  if (!(lo.array() <= hi.array()).all()) return c;
  for (DriftModel* m : {&c.offset, &c.slope}) {
    m->feature_min = lo;
    m->feature_max = hi;
  }
  c.ranged = true;
  return c;
}

}  // namespace whirl::drift
