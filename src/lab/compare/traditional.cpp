#include "compare/traditional.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl::compare {

const ExperienceClass& ExperienceRule::ClassFor(double diameter_mm) const {
  if (classes.empty()) throw InputError("experience rule has no diameter classes");
  for (const auto& c : classes)
    if (diameter_mm <= c.upper_mm) return c;
  return classes.back();
}

double ExperienceRule::CompensationUm(double diameter_mm, double t_s) const {
  if (t_s <= 0) return 0.0;
  const double ramp = ramp_time_s > 0 ? std::min(1.0, t_s / ramp_time_s) : 1.0;
  return ClassFor(diameter_mm).plateau_um * ramp;
}

Features ExperienceRule::ClassFeatures(double diameter_mm) const {
  const ExperienceClass& c = ClassFor(diameter_mm);
  return {c.plateau_um, c.settle_time_s};
}

Features ExperienceRule::HistoryFeatures(HistoryRule r, const ProcessInputs& inputs) const {
  switch (r) {
    case HistoryRule::kTable:
      return table.Predict(inputs);
    case HistoryRule::kNearest:
      return nearest.Predict(inputs);
    case HistoryRule::kClass:
      break;
  }
  return ClassFeatures(inputs.diameter_mm);
}

Features ExperienceRule::TraditionalFeatures(const ProcessInputs& inputs) const {
  return HistoryFeatures(has_choice ? choice.chosen : HistoryRule::kClass, inputs);
}

Features LogLinearFeatures::Predict(const ProcessInputs& inputs) const {
  const auto x = inputs.ToArray();
  std::array<double, 2> y{};
  for (int k = 0; k < 2; ++k) {
    double v = coef[k][0];
    for (int i = 0; i < ProcessInputs::kCount; ++i) v += coef[k][i + 1] * std::log(x[i]);
    y[k] = std::exp(v);
  }
  return {y[0], y[1]};
}

LogLinearFeatures FitLogLinear(const ProcessTable& history) {
  const int n = static_cast<int>(history.inputs.size()), p = ProcessInputs::kCount + 1;
  if (n < p || history.targets.size() != history.inputs.size())
    throw InputError(history.source + ": the regression baseline needs at least " +
                     std::to_string(p) + " past screws with targets, the table has " +
                     std::to_string(n));
  Eigen::MatrixXd a(n, p);
  Eigen::MatrixXd y(n, 2);
  for (int r = 0; r < n; ++r) {
    const auto x = history.inputs[r].ToArray();
    const double t[2] = {history.targets[r].max_elongation_um, history.targets[r].settle_time_s};
    a(r, 0) = 1.0;
    for (int i = 0; i < ProcessInputs::kCount; ++i) {
      if (!(x[i] > 0))
        throw InputError(history.source + " row " + std::to_string(r + 1) + ": " +
                         kInputColumns[i] + " = " + FormatNumber(x[i]) +
                         " must be > 0 for the log-linear regression baseline");
      a(r, i + 1) = std::log(x[i]);
    }
    for (int k = 0; k < 2; ++k) {
      if (!(t[k] > 0))
        throw InputError(history.source + " row " + std::to_string(r + 1) + ": " +
                         kTargetColumns[k] + " = " + FormatNumber(t[k]) +
                         " must be > 0 for the log-linear regression baseline");
      y(r, k) = std::log(t[k]);
    }
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < p)
    throw InputError(history.source + ": the regression baseline's design has rank " +
                     std::to_string(qr.rank()) + " < " + std::to_string(p) +
                     " (a constant input column?)");
  const Eigen::MatrixXd b = qr.solve(y);
  LogLinearFeatures f;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < p; ++i) f.coef[k][i] = b(i, k);
  return f;
}

double RegressionLeaveOneOutError(const ProcessTable& history) {
  const std::size_t n = history.inputs.size();
  if (n < ProcessInputs::kCount + 3 || history.targets.size() != n) return NAN;
  double sum = 0;
  for (std::size_t r = 0; r < n; ++r) {
    ProcessTable others;
    others.source = history.source;
    for (std::size_t i = 0; i < n; ++i) {
      if (i == r) continue;
      others.inputs.push_back(history.inputs[i]);
      others.targets.push_back(history.targets[i]);
    }
    sum += LeaveOneOutRelativeError(FitLogLinear(others).Predict(history.inputs[r]),
                                    history.targets[r]);
  }
  return sum / static_cast<double>(n);
}

ExperienceRule BuildExperienceRule(const ProcessTable& history,
                                   const ExperienceRuleOptions& options) {
  if (history.inputs.empty())
    throw InputError(history.source +
                     ": the experience rule needs past screws, the table is empty");
  if (history.targets.size() != history.inputs.size())
    throw InputError(history.source +
                     ": the experience rule needs the measured targets (max_elongation_um, "
                     "settle_time_s) of the past screws");
  const auto& d = options.class_diameters_mm;
  if (d.empty()) throw InputError("class_diameters_mm: needs at least one diameter");
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!(d[i] > 0) || !std::isfinite(d[i]))
      throw InputError("class_diameters_mm[" + std::to_string(i) + "] = " + FormatNumber(d[i]) +
                       ": must be finite and > 0");
    if (i > 0 && !(d[i] > d[i - 1]))
      throw InputError("class_diameters_mm[" + std::to_string(i) + "] = " + FormatNumber(d[i]) +
                       ": must be greater than the previous " + FormatNumber(d[i - 1]));
  }
  ExperienceRule rule;
  rule.source = history.source;
  for (std::size_t i = 0; i < d.size(); ++i) {
    ExperienceClass c;
    c.nominal_diameter_mm = d[i];
    c.lower_mm = i == 0 ? 0.0 : std::sqrt(d[i - 1] * d[i]);
    c.upper_mm = i + 1 == d.size() ? 1e9 : std::sqrt(d[i] * d[i + 1]);
    rule.classes.push_back(c);
  }
  std::vector<double> sum(d.size(), 0.0), sum_settle(d.size(), 0.0);
  double all_plateau = 0, all_settle = 0;
  for (std::size_t r = 0; r < history.inputs.size(); ++r) {
    const double dia = history.inputs[r].diameter_mm;
    for (std::size_t i = 0; i < rule.classes.size(); ++i) {
      if (dia <= rule.classes[i].upper_mm || i + 1 == rule.classes.size()) {
        sum[i] += history.targets[r].max_elongation_um;
        sum_settle[i] += history.targets[r].settle_time_s;
        rule.classes[i].screws += 1;
        break;
      }
    }
    all_plateau += history.targets[r].max_elongation_um;
    all_settle += history.targets[r].settle_time_s;
  }
  const double n = static_cast<double>(history.inputs.size());
  rule.machine_plateau_um = all_plateau / n;
  rule.ramp_time_s = all_settle / n;
  for (std::size_t i = 0; i < rule.classes.size(); ++i) {
    ExperienceClass& c = rule.classes[i];
    c.plateau_um = c.screws > 0 ? sum[i] / c.screws : rule.machine_plateau_um;
    c.settle_time_s = c.screws > 0 ? sum_settle[i] / c.screws : rule.ramp_time_s;
  }
  rule.table = BuildExperienceTable(history);
  rule.nearest = BuildNearestScrews(history);
  if (history.inputs.size() >= 2) {
    rule.choice = ChooseTraditional(history, rule, rule.table, rule.nearest);
    rule.has_choice = true;
    rule.ramp_loo_relative_error = RampLeaveOneOutError(history, rule);
  }
  try {
    rule.regression = FitLogLinear(history);
    rule.has_regression = true;
    // Without one screw the design can turn singular (a value only that screw has): no score.
    rule.regression_loo_relative_error = RegressionLeaveOneOutError(history);
  } catch (const InputError& e) {
    if (!rule.has_regression) rule.regression_error = e.what();
  }
  return rule;
}

void to_json(nlohmann::json& j, const ExperienceRule& rule) {
  nlohmann::json classes = nlohmann::json::array();
  for (const auto& c : rule.classes)
    classes.push_back({{"nominal_diameter_mm", c.nominal_diameter_mm},
                       {"lower_mm", c.lower_mm},
                       {"upper_mm", c.upper_mm},
                       {"plateau_um", c.plateau_um},
                       {"settle_time_s", c.settle_time_s},
                       {"screws", c.screws}});
  j = nlohmann::json{{"rule", "c(t) = P_class * min(1, t / T)"},
                     {"ramp_time_s", rule.ramp_time_s},
                     {"machine_plateau_um", rule.machine_plateau_um},
                     {"classes", classes},
                     {"source", rule.source}};
  if (rule.has_choice) {
    nlohmann::json loo = nlohmann::json::object();
    for (std::size_t k = 0; k < kHistoryRuleCount; ++k)
      loo[ToString(static_cast<HistoryRule>(k))] = rule.choice.loo_relative_error[k];
    j["traditional"] = {{"chosen", ToString(rule.choice.chosen)},
                        {"leave_one_out_mean_relative_error", loo}};
  }
  if (std::isfinite(rule.ramp_loo_relative_error))
    j["ramp_leave_one_out_mean_relative_error"] = rule.ramp_loo_relative_error;
  if (std::isfinite(rule.regression_loo_relative_error))
    j["regression_leave_one_out_mean_relative_error"] = rule.regression_loo_relative_error;
  if (rule.has_regression) {
    nlohmann::json reg = nlohmann::json::object();
    for (int k = 0; k < 2; ++k) reg[kTargetColumns[k]] = rule.regression.coef[k];
    j["regression"] = {{"form", "ln y = b0 + sum_i b_i ln x_i (inputs in kInputColumns order)"},
                       {"coefficients", reg}};
  }
}

}  // namespace whirl::compare
