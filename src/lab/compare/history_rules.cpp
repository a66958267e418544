#include "compare/history_rules.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "compare/traditional.h"
#include "core/csv.h"
#include "core/error.h"

namespace whirl::compare {

std::string ToString(HistoryRule r) {
  static const char* kNames[] = {"class", "table", "nearest"};
  return kNames[static_cast<int>(r)];
}

namespace {

void RequireHistory(const ProcessTable& history, const char* what) {
  if (history.inputs.empty())
    throw InputError(history.source + ": the " + what + " needs past screws, the table is empty");
  if (history.targets.size() != history.inputs.size())
    throw InputError(history.source + ": the " + what +
                     " needs the measured targets (max_elongation_um, settle_time_s) of the "
                     "past screws");
}

int ClassIndex(double x, const std::array<double, 2>& edges) {
  return x <= edges[0] ? 0 : (x <= edges[1] ? 1 : 2);
}

void CheckEdges(const std::array<double, 2>& e, const char* name) {
  if (!(std::isfinite(e[0]) && std::isfinite(e[1]) && e[0] < e[1]))
    throw InputError(std::string(name) + " = " + FormatNumber(e[0]) + ", " + FormatNumber(e[1]) +
                     ": the two class edges must be finite and increasing");
}

Features Add(Features a, const Features& b, double sign = 1.0) {
  a.max_elongation_um += sign * b.max_elongation_um;
  a.settle_time_s += sign * b.settle_time_s;
  return a;
}

Features Scaled(const Features& a, double f) {
  return {a.max_elongation_um * f, a.settle_time_s * f};
}

}  // namespace

double LeaveOneOutRelativeError(const Features& p, const Features& t) {
  return 0.5 * (std::abs(p.max_elongation_um - t.max_elongation_um) / t.max_elongation_um +
                std::abs(p.settle_time_s - t.settle_time_s) / t.settle_time_s);
}

int ExperienceTable::CellOf(const ProcessInputs& in) const {
  return 9 * ClassIndex(in.raceway_radius_mm, options.raceway_edges_mm) +
         3 * ClassIndex(in.cutting_speed_m_min, options.speed_edges_m_min) +
         ClassIndex(in.pitch_mm, options.lead_edges_mm);
}

Features ExperienceTable::Predict(const ProcessInputs& inputs) const {
  const int cell = CellOf(inputs);
  if (count[cell] > 0) return Scaled(sum[cell], 1.0 / count[cell]);
  const int a = cell / 9, b = (cell / 3) % 3, c = cell % 3;
  for (int d = 1; d <= 2; ++d) {
    Features total;
    int cells = 0;
    for (int k = 0; k < 27; ++k) {
      const int dist = std::max({std::abs(k / 9 - a), std::abs((k / 3) % 3 - b),
                                 std::abs(k % 3 - c)});
      if (dist != d || count[k] == 0) continue;
      total = Add(total, Scaled(sum[k], 1.0 / count[k]));
      ++cells;
    }
    if (cells > 0) return Scaled(total, 1.0 / cells);
  }
  return {};  // an empty table (cannot be built)
}

ExperienceTable BuildExperienceTable(const ProcessTable& history,
                                     const ExperienceTableOptions& options) {
  RequireHistory(history, "experience table");
  CheckEdges(options.raceway_edges_mm, "raceway_edges_mm");
  CheckEdges(options.speed_edges_m_min, "speed_edges_m_min");
  CheckEdges(options.lead_edges_mm, "lead_edges_mm");
  ExperienceTable t;
  t.options = options;
  for (std::size_t r = 0; r < history.inputs.size(); ++r) {
    const int cell = t.CellOf(history.inputs[r]);
    t.sum[cell] = Add(t.sum[cell], history.targets[r]);
    ++t.count[cell];
  }
  return t;
}

Features NearestScrews::Predict(const ProcessInputs& q, int k, int skip) const {
  const auto x = q.ToArray();
  std::vector<std::pair<double, std::size_t>> d;
  for (std::size_t r = 0; r < inputs.size(); ++r) {
    if (static_cast<int>(r) == skip) continue;
    const auto y = inputs[r].ToArray();
    double s = 0;
    for (int i = 0; i < ProcessInputs::kCount; ++i) s += std::pow((x[i] - y[i]) / scale[i], 2);
    d.push_back({s, r});
  }
  const std::size_t n = std::min<std::size_t>(std::max(k, 1), d.size());
  if (n == 0) return {};
  std::stable_sort(d.begin(), d.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  Features total;
  for (std::size_t j = 0; j < n; ++j) total = Add(total, targets[d[j].second]);
  return Scaled(total, 1.0 / static_cast<double>(n));
}

NearestScrews BuildNearestScrews(const ProcessTable& history) {
  RequireHistory(history, "nearest-screws rule");
  NearestScrews n;
  n.inputs = history.inputs;
  n.targets = history.targets;
  for (int i = 0; i < ProcessInputs::kCount; ++i) {
    double lo = history.inputs[0].ToArray()[i], hi = lo;
    for (const auto& p : history.inputs) {
      lo = std::min(lo, p.ToArray()[i]);
      hi = std::max(hi, p.ToArray()[i]);
    }
    n.scale[i] = hi > lo ? hi - lo : 1.0;
  }
  return n;
}

namespace {

// The sum of the past screws' targets, for a leave-one-out score `what` (at least 2 screws).
Features LeaveOneOutTargetSum(const ProcessTable& history, const char* what) {
  RequireHistory(history, what);
  if (history.inputs.size() < 2)
    throw InputError(history.source + ": the " + what + " needs at least 2 past screws");
  return std::accumulate(history.targets.begin(), history.targets.end(), Features{},
                         [](Features a, const Features& b) { return Add(a, b); });
}

// Leave-one-out features of row r by the class rule: the class means without the row, the mean
// of all other screws for a class left empty.
Features ClassLeaveOneOut(const ExperienceRule& rule, const ProcessTable& h, std::size_t r,
                          const Features& all_sum) {
  const ExperienceClass& c = rule.ClassFor(h.inputs[r].diameter_mm);
  const double n = static_cast<double>(h.inputs.size());
  if (c.screws <= 1) return Scaled(Add(all_sum, h.targets[r], -1.0), 1.0 / (n - 1));
  const Features class_sum = Scaled({c.plateau_um, c.settle_time_s}, c.screws);
  return Scaled(Add(class_sum, h.targets[r], -1.0), 1.0 / (c.screws - 1));
}

}  // namespace

TraditionalChoice ChooseTraditional(const ProcessTable& history, const ExperienceRule& rule,
                                    const ExperienceTable& table, const NearestScrews& nearest) {
  const Features all_sum =
      LeaveOneOutTargetSum(history, "leave-one-out choice of the traditional rule");
  TraditionalChoice out;
  for (std::size_t r = 0; r < history.inputs.size(); ++r) {
    const Features& t = history.targets[r];
    ExperienceTable without = table;
    const int cell = without.CellOf(history.inputs[r]);
    without.sum[cell] = Add(without.sum[cell], t, -1.0);
    --without.count[cell];
    out.loo_relative_error[0] +=
        LeaveOneOutRelativeError(ClassLeaveOneOut(rule, history, r, all_sum), t);
    out.loo_relative_error[1] += LeaveOneOutRelativeError(without.Predict(history.inputs[r]), t);
    out.loo_relative_error[2] +=
        LeaveOneOutRelativeError(nearest.Predict(history.inputs[r], 3, static_cast<int>(r)), t);
  }
  for (double& e : out.loo_relative_error) e /= static_cast<double>(history.inputs.size());
  const auto best = std::min_element(out.loo_relative_error.begin(), out.loo_relative_error.end());
  out.chosen = static_cast<HistoryRule>(best - out.loo_relative_error.begin());
  return out;
}

double RampLeaveOneOutError(const ProcessTable& history, const ExperienceRule& rule) {
  const Features all_sum = LeaveOneOutTargetSum(history, "leave-one-out error of the ramp rule");
  const double others = static_cast<double>(history.inputs.size() - 1);
  double sum = 0;
  for (std::size_t r = 0; r < history.inputs.size(); ++r) {
    const Features& t = history.targets[r];
    const Features ramp{ClassLeaveOneOut(rule, history, r, all_sum).max_elongation_um,
                        (all_sum.settle_time_s - t.settle_time_s) / others};
    sum += LeaveOneOutRelativeError(ramp, t);
  }
  return sum / static_cast<double>(history.inputs.size());
}

}  // namespace whirl::compare
