#include "drift/evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/error.h"
#include "core/numbers.h"
#include "core/parallel.h"

namespace whirl::drift {
namespace {

// Appends the lines of `more` not yet in `lines` (a sensor left out by several fits is named once).
void AddOnce(std::vector<std::string>* lines, const std::vector<std::string>& more) {
  for (const auto& m : more)
    if (std::find(lines->begin(), lines->end(), m) == lines->end()) lines->push_back(m);
}

void Accumulate(ErrorStats* sum, const ErrorStats& s) {
  sum->samples += s.samples;
  sum->mae_um += s.mae_um;
  sum->rmse_um += s.rmse_um;
  sum->std_um += s.std_um;
  sum->max_abs_um += s.max_abs_um;
}

void Divide(ErrorStats* s, int n) {
  if (n == 0) return;
  s->mae_um /= n;
  s->rmse_um /= n;
  s->std_um /= n;
  s->max_abs_um /= n;
}

std::string GroupName(RunState train, RunState test) {
  return ToString(train) + " on " + ToString(test);
}

ErrorStats PredictionStats(const DriftModel& m, const Run& run) {
  const RunPrediction p = PredictRun(m, run);
  return ComputeErrorStats(p.measured_um - p.predicted_um);
}

}  // namespace

std::string CrossRunGroup::Strongest() const {
  std::string best = "model";
  double v = model.rmse_um;
  for (const auto& [name, s] : {std::pair<const char*, const ErrorStats*>{"mlr_all", &all_sensors},
                                {"none", &none},
                                {"time", &time}})
    if (s->rmse_um < v) best = name, v = s->rmse_um;
  return best;
}

const std::vector<std::string>& HoldoutMethods() {
  static const std::vector<std::string> kMethods = {"none",    "fit",     "time",   "mlr_all",
                                                    "mlr",     "dynamic", "network", "dynamic_extra"};
  return kMethods;
}

std::vector<std::pair<std::string, std::string>> HoldoutResult::Strongest() const {
  std::vector<std::pair<std::string, std::string>> out;
  std::map<std::string, const HoldoutRow*> best;
  std::vector<std::string> order;
  for (const HoldoutRow& r : rows_out) {
    auto it = best.find(r.channel);
    if (it == best.end()) {
      order.push_back(r.channel);
      best[r.channel] = &r;
    } else if (r.test.mae_um < it->second->test.mae_um) {
      it->second = &r;
    }
  }
  for (const auto& ch : order) out.emplace_back(ch, best[ch]->method);
  return out;
}

ErrorStats ComputeErrorStats(const Eigen::VectorXd& r) {
  ErrorStats s;
  s.samples = static_cast<int>(r.size());
  if (r.size() == 0) return s;
  const double n = static_cast<double>(r.size());
  s.mae_um = r.cwiseAbs().mean();
  s.rmse_um = std::sqrt(r.squaredNorm() / n);
  s.std_um = std::sqrt((r.array() - r.mean()).square().sum() / n);
  s.max_abs_um = r.cwiseAbs().maxCoeff();
  return s;
}

void ErrorStatsAccumulator::Merge(const ErrorStatsAccumulator& o) {
  if (o.n_ == 0) return;
  if (n_ == 0) {
    *this = o;
    return;
  }
  const double n = static_cast<double>(n_ + o.n_), d = o.mean_ - mean_;
  m2_ += o.m2_ + d * d * static_cast<double>(n_) * static_cast<double>(o.n_) / n;
  mean_ += d * static_cast<double>(o.n_) / n;
  n_ += o.n_;
  abs_ += o.abs_;
  sq_ += o.sq_;
  max_ = std::max(max_, o.max_);
}

ErrorStats ErrorStatsAccumulator::Stats() const {
  ErrorStats s;
  s.samples = static_cast<int>(std::min<long long>(n_, std::numeric_limits<int>::max()));
  if (n_ == 0) return s;
  const double n = static_cast<double>(n_);
  s.mae_um = abs_ / n;
  s.rmse_um = std::sqrt(sq_ / n);
  s.std_um = std::sqrt(std::max(m2_, 0.0) / n);
  s.max_abs_um = max_;
  return s;
}

CrossRunResult CrossRun(const std::vector<Run>& runs, const std::string& error_column,
                        const FitOptions& options) {
  if (runs.size() < 2) throw InputError("crossval: give at least 2 runs");
  const std::size_t n = runs.size();
  CrossRunResult res;
  res.error_column = error_column;
  res.kind = options.kind;
  res.chosen.resize(n);
  res.models.resize(n);
  res.cells.assign(n, std::vector<CrossRunCell>(n));
  for (const Run& r : runs) {
    res.runs.push_back(r.name);
    res.states.push_back(r.state);
    r.ErrorIndex(error_column);
  }
  FitOptions inner = options;
  inner.threads = 1;
  res.candidates = options.candidates;
  res.zero = options.zero;
  if (res.zero.zero == ErrorZero::kFixed && std::isnan(res.zero.gauge_level_um))
    res.zero.gauge_level_um = runs.front().error_um(0, runs.front().ErrorIndex(error_column));
  inner.zero = res.zero;
  FitOptions time_only = inner;
  time_only.kind = ModelKind::kMlr;
  time_only.candidates = Candidates::kTime;
  std::vector<std::vector<std::string>> left_out(n);
  ParallelFor(n, options.threads, [&](std::size_t i) {
    const FitReport rep = FitDriftModel({runs[i]}, error_column, inner);
    FitOptions all = inner;
    all.kind = ModelKind::kMlr;
    all.sensors = runs[i].sensor_names;
    all.extra_inputs.clear();
    const FitReport all_rep = FitDriftModel({runs[i]}, error_column, all);
    const DriftModel& all_model = all_rep.model;
    const DriftModel time_model = FitDriftModel({runs[i]}, error_column, time_only).model;
    left_out[i] = rep.warnings;
    left_out[i].insert(left_out[i].end(), all_rep.warnings.begin(), all_rep.warnings.end());
    res.models[i] = rep.model;
    res.chosen[i] = rep.model.sensors;
    if (!rep.model.elapsed_time_constants.empty()) {
      std::string taus;
      for (double t : rep.model.elapsed_time_constants)
        taus += (taus.empty() ? "" : ", ") + FormatSignificant(t, 4);
      res.chosen[i].push_back("elapsed time (tau " + taus + " " + rep.model.time_unit + ")");
    }
    for (std::size_t j = 0; j < n; ++j) {
      CrossRunCell& c = res.cells[i][j];
      c.model = PredictionStats(rep.model, runs[j]);
      c.all_sensors = PredictionStats(all_model, runs[j]);
      c.time = PredictionStats(time_model, runs[j]);
      c.none = ComputeErrorStats(
          ApplyErrorZero(runs[j], res.zero).error_um.col(runs[j].ErrorIndex(error_column)));
    }
  });
  for (const auto& w : left_out) AddOnce(&res.warnings, w);
  std::map<std::string, CrossRunGroup> groups;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const std::string name = i == j ? "own run" : GroupName(res.states[i], res.states[j]);
      CrossRunGroup& g = groups[name];
      g.name = name;
      ++g.pairs;
      Accumulate(&g.model, res.cells[i][j].model);
      Accumulate(&g.all_sensors, res.cells[i][j].all_sensors);
      Accumulate(&g.none, res.cells[i][j].none);
      Accumulate(&g.time, res.cells[i][j].time);
    }
  for (auto& [name, g] : groups) {
    Divide(&g.model, g.pairs);
    Divide(&g.all_sensors, g.pairs);
    Divide(&g.none, g.pairs);
    Divide(&g.time, g.pairs);
    res.groups.push_back(g);
  }
  return res;
}

namespace {

HoldoutRow Score(const std::string& channel, const std::string& method, const DriftModel& m,
                 const RunPrediction& p, int train_end, int test_end) {
  HoldoutRow row;
  row.channel = channel;
  row.method = method;
  row.inputs = m.sensors;
  row.inputs.insert(row.inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  row.time_constants = m.time_constants;
  if (!m.elapsed_time_constants.empty()) {
    row.inputs.push_back("elapsed");
    row.time_constants.insert(row.time_constants.end(), m.elapsed_time_constants.begin(),
                              m.elapsed_time_constants.end());
  }
  const Eigen::VectorXd r = p.measured_um - p.predicted_um;
  row.train = ComputeErrorStats(r.head(train_end));
  row.test = ComputeErrorStats(r.segment(train_end, test_end - train_end));
  return row;
}

}  // namespace

HoldoutResult Holdout(const Run& log, const HoldoutOptions& o,
                      const std::function<void(const std::string&)>& progress) {
  if (!(o.train_fraction > 0 && o.test_fraction > 0 && o.train_fraction + o.test_fraction <= 1))
    throw InputError("holdout: train fraction " + std::to_string(o.train_fraction) +
                     " and test fraction " + std::to_string(o.test_fraction) +
                     " must be > 0 with a sum <= 1");
  if (o.max_sensors < 0) throw InputError("holdout: max sensors must be >= 0 (0: no limit)");
  HoldoutResult res;
  res.log = log.name;
  res.time_from_index = log.time_from_index;
  res.rows = log.samples();
  res.train_end = static_cast<int>(std::floor(o.train_fraction * res.rows));
  res.test_end = static_cast<int>(std::floor((o.train_fraction + o.test_fraction) * res.rows));
  if (res.train_end < 10 || res.test_end - res.train_end < 1)
    throw InputError("holdout: " + std::to_string(res.rows) + " rows are too few to split");
  res.train_end_min = log.time_min[static_cast<std::size_t>(res.train_end - 1)];
  res.test_end_min = log.time_min[static_cast<std::size_t>(res.test_end - 1)];
  const Run train = log.Slice(0, res.train_end, log.name + "_train");
  const Run scored = log.Slice(0, res.test_end, log.name + "_train_test");
  const std::vector<std::string> channels = o.channels.empty() ? log.error_names : o.channels;
  res.zero = o.fit.zero;
  for (const std::string& ch : channels) {
    ZeroConvention zero = o.fit.zero;
    if (zero.zero == ErrorZero::kFixed && std::isnan(zero.gauge_level_um))
      zero.gauge_level_um = log.error_um(0, log.ErrorIndex(ch));
    auto add = [&](const std::string& method, FitOptions f) {
      if (progress) progress(ch + ": " + method);
      FitReport rep = FitDriftModel({train}, ch, f);
      AddOnce(&res.warnings, rep.warnings);
      DriftModel m = std::move(rep.model);
      RunPrediction p = PredictRun(m, scored);
      res.rows_out.push_back(Score(ch, method, m, p, res.train_end, res.test_end));
      res.models.push_back(std::move(m));
      res.predictions.push_back(std::move(p));
    };
    {  // no compensation
      HoldoutRow row;
      row.channel = ch;
      row.method = "none";
      const Eigen::VectorXd e = ApplyErrorZero(scored, zero).error_um.col(scored.ErrorIndex(ch));
      row.train = ComputeErrorStats(e.head(res.train_end));
      row.test = ComputeErrorStats(e.segment(res.train_end, res.test_end - res.train_end));
      res.rows_out.push_back(row);
      res.models.emplace_back();
      RunPrediction p;
      p.run = scored.name;
      p.time = scored.time_min;
      p.has_measured = true;
      p.measured_um = e;
      p.predicted_um = Eigen::VectorXd::Zero(e.size());
      p.std_um = Eigen::VectorXd::Zero(e.size());
      res.predictions.push_back(std::move(p));
    }
    FitOptions f = o.fit;
    f.zero = zero;
    f.extra_inputs.clear();
    f.kind = ModelKind::kMlr;
    f.selection.max_classes = 0;
    add("fit", f);  // drift fit as run by default: its candidates, no sensor cap
    f.candidates = Candidates::kTime;
    add("time", f);
    f.candidates = Candidates::kSensors;
    f.sensors = log.sensor_names;
    add("mlr_all", f);
    f.sensors.clear();
    f.selection.max_classes = o.max_sensors;
    add("mlr", f);
    f.kind = ModelKind::kDynamic;
    add("dynamic", f);
    if (o.network) {
      f.kind = ModelKind::kNetwork;
      add("network", f);
    }
    if (!o.fit.extra_inputs.empty()) {
      f.kind = ModelKind::kDynamic;
      f.extra_inputs = o.fit.extra_inputs;
      add("dynamic_extra", f);
    }
  }
  return res;
}

}  // namespace whirl::drift
