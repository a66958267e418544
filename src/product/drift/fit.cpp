// FitDriftModel: sensor selection, the lag search of the dynamic model by cross-validation, and
// the final least-squares or trainbr fit (drift/fit.h).
#include "drift/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"
#include "core/parallel.h"

namespace whirl::drift {
namespace {

struct Stacked {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;
  std::vector<int> fold;  // fold of each sample
  std::vector<int> run;   // run of each sample
  std::vector<double> elapsed;  // time since the run's start [min or samples]
  double sampling_step = std::numeric_limits<double>::quiet_NaN();  // FitOptions::sampling_step
};

Stacked Stack(const std::vector<Run>& runs, const std::string& error_column,
              const std::vector<std::string>& sensors, const std::vector<std::string>& extras,
              const std::vector<double>& taus, int folds,
              const std::vector<double>& elapsed_taus = {},
              double sampling_step = std::numeric_limits<double>::quiet_NaN()) {
  std::vector<Eigen::MatrixXd> parts;
  Eigen::Index total = 0, cols = 0;
  for (const Run& r : runs) {
    parts.push_back(BuildFeatures(r, sensors, extras, taus, elapsed_taus));
    total += r.samples();
    cols = parts.back().cols();
  }
  Stacked s;
  s.sampling_step = sampling_step;
  s.x.resize(total, cols);
  s.y.resize(total);
  s.fold.resize(static_cast<std::size_t>(total));
  s.run.resize(static_cast<std::size_t>(total));
  s.elapsed.resize(static_cast<std::size_t>(total));
  Eigen::Index at = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run& r = runs[i];
    s.x.middleRows(at, r.samples()) = parts[i];
    s.y.segment(at, r.samples()) = r.error_um.col(r.ErrorIndex(error_column));
    for (int k = 0; k < r.samples(); ++k) {
      const auto q = static_cast<std::size_t>(at + k);
      s.fold[q] = runs.size() > 1 ? static_cast<int>(i)
                                  : static_cast<int>(k * static_cast<long>(folds) / r.samples());
      s.run[q] = static_cast<int>(i);
      s.elapsed[q] = r.time_min[static_cast<std::size_t>(k)] - r.time_min.front();
    }
    at += r.samples();
  }
  return s;
}

Eigen::MatrixXd Rows(const Eigen::MatrixXd& m, const std::vector<Eigen::Index>& idx) {
  Eigen::MatrixXd out(static_cast<Eigen::Index>(idx.size()), m.cols());
  for (std::size_t i = 0; i < idx.size(); ++i)
    out.row(static_cast<Eigen::Index>(i)) = m.row(idx[i]);
  return out;
}

struct Split {
  std::vector<Eigen::Index> train, test;
};

// The folds' (train, test) rows: leave one fold out, or forward-chaining (train = earlier folds).
std::vector<Split> FoldSplits(const std::vector<int>& fold, bool forward) {
  const int nf = *std::max_element(fold.begin(), fold.end()) + 1;
  std::vector<Split> splits;
  for (int f = forward ? 1 : 0; f < nf; ++f) {
    Split sp;
    for (std::size_t i = 0; i < fold.size(); ++i) {
      if (fold[i] == f)
        sp.test.push_back(static_cast<Eigen::Index>(i));
      else if (!forward || fold[i] < f)
        sp.train.push_back(static_cast<Eigen::Index>(i));
    }
    if (!sp.test.empty()) splits.push_back(std::move(sp));
  }
  return splits;
}

// One candidate's validation: each fold predicted from a fit on the others (forward: the earlier
// ones only).
struct CvResult {
  double pooled_rmse_um = std::numeric_limits<double>::infinity();  ///< over the fitted folds
  std::vector<double> fold_rmse_um;  ///< per fold of FoldSplits; NaN: too few rows to fit
  Eigen::VectorXd oof;               ///< out-of-fold prediction per row; NaN: not predicted
};

// `predict` returns the test rows' predictions from a fit on the training rows; a fold with too
// few training rows for `parameters` is left out (NaN), and so are its rows from the pooled RMSE.
template <typename Predict>
CvResult CrossValidate(const Stacked& s, bool forward, int parameters, Predict predict) {
  CvResult r;
  r.oof = Eigen::VectorXd::Constant(s.y.size(), std::numeric_limits<double>::quiet_NaN());
  double sse = 0;
  Eigen::Index count = 0;
  for (const Split& sp : FoldSplits(s.fold, forward)) {
    if (sp.train.size() <= static_cast<std::size_t>(parameters)) {  // too few to fit
      r.fold_rmse_um.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    const Eigen::VectorXd p = predict(sp);
    const double fold_sse = (Rows(s.y, sp.test) - p).squaredNorm();
    for (std::size_t k = 0; k < sp.test.size(); ++k) r.oof(sp.test[k]) = p(static_cast<Eigen::Index>(k));
    r.fold_rmse_um.push_back(std::sqrt(fold_sse / static_cast<double>(sp.test.size())));
    sse += fold_sse;
    count += static_cast<Eigen::Index>(sp.test.size());
  }
  if (count == 0)
    throw InputError("cross-validation: no fold has enough training samples for " +
                     std::to_string(parameters) + " parameters");
  r.pooled_rmse_um = std::sqrt(sse / static_cast<double>(count));
  return r;
}

// The linear model on s.x validated fold by fold.
CvResult CrossValidateLinear(const Stacked& s, bool forward) {
  return CrossValidate(s, forward, static_cast<int>(s.x.cols()) + 1, [&](const Split& sp) {
    const Eigen::VectorXd b = LeastSquaresCoefficients(Rows(s.x, sp.train), Rows(s.y, sp.train));
    return EvaluateLinear(b, Rows(s.x, sp.test));
  });
}

// Pooled RMSE of predicting each fold from a fit on the others.
double CrossValidatedRmse(const Stacked& s, bool forward) {
  return CrossValidateLinear(s, forward).pooled_rmse_um;
}

// The warm-up fit (regression.h FitWarmUp) on rows `idx`, grouped by run, with s.x's columns as
// fixed regressors when `with_x`.
WarmUpFit WarmUpOnRows(const Stacked& s, const std::vector<Eigen::Index>& idx, int terms,
                       bool with_x) {
  std::vector<std::vector<double>> t;
  std::vector<std::vector<double>> e;
  int last = -1;
  for (const Eigen::Index i : idx) {
    const auto q = static_cast<std::size_t>(i);
    if (s.run[q] != last) t.emplace_back(), e.emplace_back(), last = s.run[q];
    t.back().push_back(s.elapsed[q]);
    e.back().push_back(s.y(i));
  }
  std::vector<Eigen::VectorXd> ev;
  for (const auto& v : e) ev.push_back(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  return FitWarmUp(t, ev, terms, with_x ? Rows(s.x, idx) : Eigen::MatrixXd(), s.sampling_step);
}

Eigen::VectorXd PredictWarmUp(const WarmUpFit& f, const Stacked& s,
                              const std::vector<Eigen::Index>& idx, bool with_x) {
  const Eigen::Index c = with_x ? s.x.cols() : 0;
  Eigen::MatrixXd x(static_cast<Eigen::Index>(idx.size()),
                    c + static_cast<Eigen::Index>(f.time_constants.size()));
  if (c > 0) x.leftCols(c) = Rows(s.x, idx);
  for (std::size_t k = 0; k < idx.size(); ++k)
    for (std::size_t j = 0; j < f.time_constants.size(); ++j)
      x(static_cast<Eigen::Index>(k), c + static_cast<Eigen::Index>(j)) =
          1.0 - std::exp(-s.elapsed[static_cast<std::size_t>(idx[k])] / f.time_constants[j]);
  return EvaluateLinear(f.coefficients, x);
}

// Validation of the warm-up model (time since start, `terms` terms, beside s.x's columns when
// `with_x`), its time constants searched again in every fold.
CvResult WarmUpCv(const Stacked& s, bool forward, int terms, bool with_x) {
  const int parameters = 1 + 2 * terms + (with_x ? static_cast<int>(s.x.cols()) : 0);
  return CrossValidate(s, forward, parameters, [&](const Split& sp) {
    return PredictWarmUp(WarmUpOnRows(s, sp.train, terms, with_x), s, sp.test, with_x);
  });
}

// Greedy forward choice of lag time constants (drift/model.h, kind dynamic).
std::vector<LagSearchStep> SearchLags(const std::vector<Run>& runs, const std::string& error_column,
                                      const std::vector<std::string>& sensors,
                                      const FitOptions& o) {
  auto score = [&](const std::vector<double>& taus) {
    return CrossValidatedRmse(Stack(runs, error_column, sensors, o.extra_inputs, taus, o.folds),
                              o.forward_cv && runs.size() == 1);
  };
  std::vector<LagSearchStep> steps{{{}, score({})}};
  while (static_cast<int>(steps.back().time_constants.size()) < o.max_lags) {
    const std::vector<double>& cur = steps.back().time_constants;
    std::vector<double> cand;
    for (double t : o.tau_grid)
      if (std::find(cur.begin(), cur.end(), t) == cur.end()) cand.push_back(t);
    if (cand.empty()) break;
    std::vector<double> rmse(cand.size(), std::numeric_limits<double>::infinity());
    ParallelFor(cand.size(), o.threads, [&](std::size_t i) {
      std::vector<double> taus = cur;
      taus.push_back(cand[i]);
      std::sort(taus.begin(), taus.end());
      try {
        rmse[i] = score(taus);
      } catch (const InputError&) {
        // collinear lag set (e.g. two nearly equal long lags): not a candidate
      }
    });
    const auto best =
        static_cast<std::size_t>(std::min_element(rmse.begin(), rmse.end()) - rmse.begin());
    if (!(rmse[best] < steps.back().cv_rmse_um)) break;
    std::vector<double> taus = cur;
    taus.push_back(cand[best]);
    std::sort(taus.begin(), taus.end());
    steps.push_back({taus, rmse[best]});
  }
  return steps;
}

void FitNetwork(const Stacked& s, const FitOptions& o, DriftModel* m, std::string* report) {
  const Eigen::Index q = s.x.rows();
  const Eigen::Index stride =
      std::max<Eigen::Index>(1, (q + o.max_train_samples - 1) / o.max_train_samples);
  std::vector<Eigen::Index> idx;
  for (Eigen::Index i = 0; i < q; i += stride) idx.push_back(i);
  const Eigen::MatrixXd x = Rows(s.x, idx).transpose();
  const Eigen::MatrixXd y = Rows(s.y, idx).transpose();
  nn::TrainingData data;
  m->input_scaling = nn::MapMinMax::Fit(x);
  m->target_scaling = nn::MapMinMax::Fit(y);
  data.inputs = m->input_scaling.Apply(x);
  data.targets = m->target_scaling.Apply(y);
  data.target_scaling = m->target_scaling;
  const std::vector<int> sizes{static_cast<int>(x.rows()), o.hidden, 1};
  const nn::RestartResult r = nn::TrainBrRestarts(data, sizes, o.seed, o.restarts, o.train);
  m->network = r.best.network;
  m->posterior_covariance = r.best.posterior_covariance;
  m->noise_variance = r.best.summary.noise_variance;
  *report = r.best.summary.BriefReport() + " (" + std::to_string(idx.size()) + " of " +
            std::to_string(q) + " samples, best of " + std::to_string(o.restarts) + " restarts)";
}

// The given sensors without the dead and duplicate ones (selection.h convention 8).
std::vector<std::string> UsableSensors(const std::vector<Run>& runs,
                                       const std::vector<std::string>& sensors,
                                       const SelectionMoments* all_rows,
                                       std::vector<std::string>* warnings) {
  if (all_rows != nullptr) {  // the moments of every row: the given sensors' part of them
    SelectionMoments given;
    const auto m = static_cast<Eigen::Index>(sensors.size());
    given.rows = all_rows->rows;
    given.mean.resize(m);
    given.max_abs.resize(m);
    given.cross.resize(m, m);
    std::vector<int> at;
    for (const auto& name : sensors) at.push_back(runs.front().SensorIndex(name));
    for (Eigen::Index i = 0; i < m; ++i) {
      given.mean(i) = all_rows->mean(at[static_cast<std::size_t>(i)]);
      given.max_abs(i) = all_rows->max_abs(at[static_cast<std::size_t>(i)]);
      for (Eigen::Index j = 0; j < m; ++j)
        given.cross(i, j) =
            all_rows->cross(at[static_cast<std::size_t>(i)], at[static_cast<std::size_t>(j)]);
    }
    for (const Run& r : runs)
      for (const auto& name : sensors) r.SensorIndex(name);
    const SensorScreen screen = ScreenSensors(given, sensors, RunSources(runs));
    *warnings = screen.left_out;
    std::vector<std::string> out;
    for (const int i : screen.usable) out.push_back(sensors[static_cast<std::size_t>(i)]);
    return out;
  }
  Eigen::Index total = 0;
  for (const Run& r : runs) total += r.samples();
  Eigen::MatrixXd rises(total, static_cast<Eigen::Index>(sensors.size()));
  Eigen::Index at = 0;
  for (const Run& r : runs) {
    const Eigen::MatrixXd all = r.Rises();
    for (std::size_t i = 0; i < sensors.size(); ++i)
      rises.block(at, static_cast<Eigen::Index>(i), r.samples(), 1) =
          all.col(r.SensorIndex(sensors[i]));
    at += r.samples();
  }
  const SensorScreen screen = ScreenSensors(rises, sensors, RunSources(runs));
  *warnings = screen.left_out;
  std::vector<std::string> out;
  for (const int i : screen.usable) out.push_back(sensors[static_cast<std::size_t>(i)]);
  return out;
}

}  // namespace

std::string ToString(Candidates c) {
  switch (c) {
    case Candidates::kSensors:
      return "sensors";
    case Candidates::kTime:
      return "time";
    case Candidates::kSensorsTime:
      return "sensors+time";
    case Candidates::kTime1:
      return "time1";
    case Candidates::kTime2:
      return "time2";
    case Candidates::kAuto:
      break;
  }
  return "auto";
}

Candidates ParseCandidates(const std::string& text) {
  for (Candidates c : {Candidates::kAuto, Candidates::kSensors, Candidates::kTime,
                       Candidates::kSensorsTime, Candidates::kTime1, Candidates::kTime2})
    if (ToString(c) == text) return c;
  throw InputError("candidates '" + text +
                   "': must be auto, sensors, time, time1, time2 or sensors+time");
}

void ChoiceRule::Validate() const {
  if (!(tolerance >= 0 && tolerance <= 1))
    throw InputError("choice tolerance " + MessageNumber(tolerance) + ": must be within 0..1");
  if (!(margin >= 0 && margin < 1))
    throw InputError("choice margin " + MessageNumber(margin) + ": must be within 0..1 (not 1)");
  if (!(consistency >= 0 && consistency <= 1))
    throw InputError("choice consistency " + MessageNumber(consistency) + ": must be within 0..1");
}

void FitOptions::Validate() const {
  selection.Validate();
  choice.Validate();
  if (max_lags < 1 || max_lags > 4)
    throw InputError("max lags " + std::to_string(max_lags) + ": must be 1..4");
  if (folds < 2 || folds > 20)
    throw InputError("folds " + std::to_string(folds) + ": must be 2..20");
  if (tau_grid.empty() || tau_grid.size() > 32)
    throw InputError("lag grid: give 1 to 32 time constants");
  for (double t : tau_grid)
    if (!(t > 0 && t <= 1e6))
      throw InputError("lag time constant " + FormatSignificant(t, 4) + ": must be in (0, 1e6]");
  if (hidden < 1 || hidden > 20)
    throw InputError("hidden " + std::to_string(hidden) + ": must be 1..20");
  if (restarts < 1 || restarts > 50)
    throw InputError("restarts " + std::to_string(restarts) + ": must be 1..50");
  if (!(std::isnan(sampling_step) || (sampling_step > 0 && std::isfinite(sampling_step))))
    throw InputError("sampling step " + MessageNumber(sampling_step) + ": must be > 0");
  if (!(dynamic_share >= 0 && dynamic_share <= 1))
    throw InputError("dynamic share " + MessageNumber(dynamic_share) + ": must be within 0..1");
  if (max_train_samples < 20 || max_train_samples > 20000)
    throw InputError("max train samples " + std::to_string(max_train_samples) +
                     ": must be 20..20000");
  train.Validate();
}

Selection SelectSensorsForFit(const std::vector<Run>& runs, const std::string& error_column,
                              const FitOptions& o) {
  const SelectionMoments* all = o.all_rows.get();
  if (o.selection.rule != ClassCountRule::kCrossValidated)
    return SelectSensors(runs, error_column, o.selection, all);
  SelectionOptions by_count = o.selection;
  by_count.rule = ClassCountRule::kLargestMargin;  // any rule that never throws: only the cuts
  const Selection cuts = SelectSensors(runs, error_column, by_count, all);  // the cuts on offer
  by_count.rule = ClassCountRule::kFixed;
  std::vector<int> counts;
  for (const Partition& p : cuts.partitions)
    if ((o.selection.max_classes <= 0 || p.classes <= o.selection.max_classes) &&
        std::find(counts.begin(), counts.end(), p.classes) == counts.end())
      counts.push_back(p.classes);
  std::sort(counts.begin(), counts.end());
  std::vector<Selection> candidates(counts.size());
  std::vector<double> rmse(counts.size(), std::numeric_limits<double>::infinity());
  const bool forward = o.forward_cv && runs.size() == 1;
  ParallelFor(counts.size(), o.threads, [&](std::size_t i) {
    SelectionOptions fixed = by_count;
    fixed.fixed_classes = counts[i];
    candidates[i] = SelectSensors(runs, error_column, fixed, all);
    try {
      rmse[i] = CrossValidatedRmse(
          Stack(runs, error_column, candidates[i].ChosenNames(), o.extra_inputs, {}, o.folds),
          forward);
    } catch (const InputError&) {
      // too few samples per fold for this many sensors: not a candidate
    }
  });
  if (counts.empty() || !std::isfinite(*std::min_element(rmse.begin(), rmse.end())))
    throw InputError("--classes cv: no class count can be cross-validated on " +
                     std::to_string(runs.size()) + " run(s) (too few samples per fold)");
  const auto best =
      static_cast<std::size_t>(std::min_element(rmse.begin(), rmse.end()) - rmse.begin());
  Selection chosen = candidates[best];
  std::string scores;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    chosen.class_count_scores.push_back({counts[i], rmse[i]});
    scores += (scores.empty() ? "" : ", ") + std::string("r = ") + std::to_string(counts[i]) +
              ": " + (std::isfinite(rmse[i]) ? FormatSignificant(rmse[i], 4) + " um" : "-");
  }
  chosen.message =
      "class count by cross-validated MLR RMSE (" +
      (runs.size() > 1
           ? std::string("leave one run out")
           : std::to_string(o.folds) + (forward ? " forward-chaining" : "") + " blocks") +
      "): r = " + std::to_string(counts[best]) + " (" + scores + "); " + chosen.message;
  return chosen;
}

namespace {

void CheckTrainingRuns(const std::vector<Run>& runs, const std::string& error_column) {
  if (runs.empty()) throw InputError("fit: no training run");
  for (const Run& r : runs) {
    r.ErrorIndex(error_column);
    if (r.time_from_index != runs.front().time_from_index)
      throw InputError(r.source + ": some training runs record time and others do not");
  }
}

// The model's sensors: chosen by the selection (FitOptions::sensors empty) or the given ones that
// are usable; left-out sensors become warnings.
void ChooseSensors(const std::vector<Run>& runs, const std::string& error_column,
                   const FitOptions& o, FitReport* rep) {
  DriftModel& m = rep->model;
  if (o.sensors.empty()) {
    rep->selected = true;
    rep->selection = SelectSensorsForFit(runs, error_column, o);
    m.sensors = rep->selection.ChosenNames();
    m.selection = "Miao et al. selection: " + rep->selection.message;
    rep->warnings = rep->selection.left_out;
  } else {
    m.sensors = UsableSensors(runs, o.sensors, o.all_rows.get(), &rep->warnings);
    m.selection = "given";
  }
}

// The reference temperatures (mean first sample of each sensor over the runs), the training
// runs and samples, and the machine state they share (unknown when they differ).
void SetTrainingProvenance(const std::vector<Run>& runs, DriftModel* model) {
  DriftModel& m = *model;
  m.reference_C = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.sensors.size()));
  for (const Run& r : runs) {
    for (std::size_t i = 0; i < m.sensors.size(); ++i)
      m.reference_C(static_cast<Eigen::Index>(i)) +=
          r.temperature_C(0, r.SensorIndex(m.sensors[i]));
    for (const auto& e : m.extra_inputs) r.OtherIndex(e);
    m.training_runs.push_back(r.name);
    m.training_samples += r.samples();
  }
  m.reference_C /= static_cast<double>(runs.size());
  m.state = runs.front().state;
  for (const Run& r : runs)
    if (r.state != m.state) m.state = RunState::kUnknown;
}

// ModelKind::kDynamic: the time constants of the lag search, each step noted with its score.
void ChooseTimeConstants(const std::vector<Run>& runs, const std::string& error_column,
                         const FitOptions& o, FitReport* rep) {
  DriftModel& m = rep->model;
  rep->lag_search = SearchLags(runs, error_column, m.sensors, o);
  m.time_constants = rep->lag_search.back().time_constants;
  for (const auto& st : rep->lag_search) {
    std::string t;
    for (double v : st.time_constants) t += (t.empty() ? "" : ", ") + FormatSignificant(v, 4);
    m.notes.push_back("lag search: time constants [" + t + "] " + m.time_unit +
                      ": cross-validated RMSE " + FormatSignificant(st.cv_rmse_um, 4) + " um");
  }
}

// The features: every sensor and extra input, as it is and lagged by each time constant.
void ListFeatures(DriftModel* model) {
  DriftModel& m = *model;
  std::vector<std::string> inputs = m.sensors;
  inputs.insert(inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  for (const auto& in : inputs) {
    m.features.push_back({in, 0.0});
    for (double t : m.time_constants) m.features.push_back({in, t});
  }
}

// Fits the network or the least-squares model on the stacked features; returns its fitted
// values on them. A rank-deficient linear fit is refused naming the runs and the features.
Eigen::VectorXd FitOnFeatures(const Stacked& s, const std::vector<Run>& runs,
                              const std::string& error_column, const FitOptions& o,
                              FitReport* rep) {
  DriftModel& m = rep->model;
  if (o.kind == ModelKind::kNetwork) {
    FitNetwork(s, o, &m, &rep->train_report);
    return m.target_scaling.Reverse(m.network.Forward(m.input_scaling.Apply(s.x.transpose())))
        .row(0)
        .transpose();
  }
  try {
    m.linear = FitLinear(s.x, s.y);
  } catch (const InputError& e) {
    std::string features;
    for (const Feature& f : m.features)
      features += (features.empty() ? "" : ", ") + f.Name(m.time_unit);
    throw InputError(RunSources(runs) + ": model of " + error_column + " on " + features + ": " +
                     e.what());
  }
  return EvaluateLinear(m.linear.coefficients, s.x);
}

}  // namespace

namespace {

// The final fit on the chosen sensors, sensor lags and elapsed-time constants (already in `rep`):
// features, ranges, coefficients, residual statistics.
void FitChosen(const std::vector<Run>& runs, const std::string& error_column, const FitOptions& o,
               FitReport* rep) {
  DriftModel& m = rep->model;
  ListFeatures(&m);
  for (double t : m.elapsed_time_constants) m.features.push_back({"elapsed", t});
  const Stacked s = Stack(runs, error_column, m.sensors, m.extra_inputs, m.time_constants, o.folds,
                          m.elapsed_time_constants);
  m.feature_min = s.x.colwise().minCoeff().transpose();
  m.feature_max = s.x.colwise().maxCoeff().transpose();
  const Eigen::VectorXd fitted = FitOnFeatures(s, runs, error_column, o, rep);
  const Eigen::VectorXd res = s.y - fitted;
  const double dof =
      o.kind == ModelKind::kNetwork ? static_cast<double>(res.size()) : m.linear.degrees_of_freedom;
  m.residual_std_um = std::sqrt(res.squaredNorm() / dof);
  const double tss = (s.y.array() - s.y.mean()).square().sum();
  m.r_squared = tss > 0 ? 1.0 - res.squaredNorm() / tss : 1.0;
}

// A report with the model's identity and training provenance (no sensors: sensor-free).
FitReport StartReport(const std::vector<Run>& runs, const std::string& error_column,
                      const FitOptions& o, bool sensors) {
  FitReport rep;
  DriftModel& m = rep.model;
  m.kind = o.kind;
  m.error_column = error_column;
  m.time_unit = runs.front().time_from_index ? "sample" : "min";
  if (sensors) {
    m.extra_inputs = o.extra_inputs;
    ChooseSensors(runs, error_column, o, &rep);
  } else {
    m.kind = ModelKind::kMlr;
    m.selection = "none (sensor-free)";
  }
  SetTrainingProvenance(runs, &m);
  return rep;
}

FitReport FitSensorModel(const std::vector<Run>& runs, const std::string& error_column,
                         const FitOptions& o) {
  FitReport rep = StartReport(runs, error_column, o, true);
  if (o.kind == ModelKind::kDynamic) ChooseTimeConstants(runs, error_column, o, &rep);
  FitChosen(runs, error_column, o, &rep);
  return rep;
}

// The time-only model: a warm-up of `terms` terms, its time constants fitted on every run.
FitReport FitTimeModel(const std::vector<Run>& runs, const std::string& error_column,
                       const FitOptions& o, int terms) {
  FitReport rep = StartReport(runs, error_column, o, false);
  const Stacked s = Stack(runs, error_column, {}, {}, {}, o.folds, {}, o.sampling_step);
  std::vector<Eigen::Index> all(s.fold.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Eigen::Index>(i);
  const WarmUpFit w = WarmUpOnRows(s, all, terms, false);
  rep.model.elapsed_time_constants = w.time_constants;
  if (!w.note.empty()) rep.model.notes.push_back(w.note);
  FitChosen(runs, error_column, o, &rep);
  return rep;
}

// The sensor model plus one elapsed-time term, its time constant fitted beside the features.
FitReport FitSensorTimeModel(const std::vector<Run>& runs, const std::string& error_column,
                             const FitOptions& o, FitReport rep) {
  DriftModel& m = rep.model;
  const Stacked s = Stack(runs, error_column, m.sensors, m.extra_inputs, m.time_constants, o.folds,
                          {}, o.sampling_step);
  std::vector<Eigen::Index> all(s.fold.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<Eigen::Index>(i);
  const WarmUpFit w = WarmUpOnRows(s, all, 1, true);
  m.elapsed_time_constants = w.time_constants;
  if (!w.note.empty()) m.notes.push_back(w.note);
  m.features.clear();
  FitChosen(runs, error_column, o, &rep);
  return rep;
}

std::string HowValidated(const std::vector<Run>& runs, const FitOptions& o) {
  return runs.size() > 1 ? "leave one run out, " + std::to_string(runs.size()) + " runs"
                         : std::to_string(o.folds) + (o.forward_cv ? " forward-chaining" : "") +
                               " blocks of one run";
}

// Scores every candidate family of o.candidates and fits the chosen one (model.h Candidates).
FitReport FitCandidates(const std::vector<Run>& runs, const std::string& error_column,
                        const FitOptions& o) {
  const bool forward = o.forward_cv && runs.size() == 1;
  const Stacked time_stack =
      Stack(runs, error_column, {}, {}, {}, o.folds, {}, o.sampling_step);
  std::vector<CandidateScore> scores;
  auto score = [&](const std::string& name, int parameters, bool sensor_free, auto cv) {
    CandidateScore c;
    c.name = name;
    c.parameters = parameters;
    c.sensor_free = sensor_free;
    c.folds = static_cast<int>(FoldSplits(time_stack.fold, forward).size());
    try {
      const CvResult r = cv();
      c.cv_rmse_um = r.pooled_rmse_um;
      c.fold_rmse_um = r.fold_rmse_um;
    } catch (const InputError&) {
      // too few samples per fold: not a candidate
    }
    scores.push_back(c);
  };
  const bool want_time1 = o.candidates == Candidates::kAuto || o.candidates == Candidates::kTime ||
                          o.candidates == Candidates::kTime1;
  const bool want_time2 = o.candidates == Candidates::kAuto || o.candidates == Candidates::kTime ||
                          o.candidates == Candidates::kTime2;
  const bool want_sensors = o.candidates == Candidates::kAuto;
  const bool want_mixed = o.candidates == Candidates::kSensorsTime ||
                          (o.candidates == Candidates::kAuto && runs.size() >= 3);
  if (want_time1) score("time1", 3, true, [&] { return WarmUpCv(time_stack, forward, 1, false); });
  if (want_time2) score("time2", 5, true, [&] { return WarmUpCv(time_stack, forward, 2, false); });
  FitReport sensors;
  if (want_sensors || want_mixed) {
    sensors = FitSensorModel(runs, error_column, o);
    const DriftModel& m = sensors.model;
    const Stacked ss =
        Stack(runs, error_column, m.sensors, m.extra_inputs, m.time_constants, o.folds, {},
              o.sampling_step);
    const int p = static_cast<int>(ss.x.cols()) + 1 + static_cast<int>(m.time_constants.size());
    if (want_sensors) score("sensors", p, false, [&] { return CrossValidateLinear(ss, forward); });
    if (want_mixed)
      score("sensors+time", p + 2, false, [&] { return WarmUpCv(ss, forward, 1, true); });
  }
  const CandidateChoice choice = ChooseCandidate(scores, o.choice);
  const std::string& name = scores[choice.pick].name;
  FitReport rep = name == "sensors"        ? sensors
                  : name == "sensors+time" ? FitSensorTimeModel(runs, error_column, o, sensors)
                                           : FitTimeModel(runs, error_column, o, name == "time1" ? 1 : 2);
  if (name != "sensors" && name != "sensors+time")  // the screen's warnings stand for every family
    rep.warnings = sensors.warnings;
  rep.candidates = scores;
  rep.candidates[choice.pick].time_constants = rep.model.elapsed_time_constants;
  rep.chosen = "chosen: " + name + ": " + choice.why + " (" + HowValidated(runs, o) + ")";
  rep.model.notes.push_back(rep.chosen);
  return rep;
}

}  // namespace

namespace {

// Finite RMSEs of two candidates on the folds both were fitted in: the count where `a` is lower.
int FoldWins(const CandidateScore& a, const CandidateScore& b, int* common) {
  int wins = 0;
  *common = 0;
  for (std::size_t k = 0; k < a.fold_rmse_um.size() && k < b.fold_rmse_um.size(); ++k) {
    if (!std::isfinite(a.fold_rmse_um[k]) || !std::isfinite(b.fold_rmse_um[k])) continue;
    ++*common;
    wins += a.fold_rmse_um[k] < b.fold_rmse_um[k];
  }
  return wins;
}

std::string Um(double v) { return std::isfinite(v) ? MessageNumber(v) + " um" : "-"; }

// The fewest parameters among `among` within (1 + tolerance) of their lowest RMSE (ties: the
// lower RMSE); `among` holds finite candidates only.
std::size_t FewestWithin(const std::vector<CandidateScore>& s, const std::vector<std::size_t>& among,
                         double tolerance, double* best) {
  *best = std::numeric_limits<double>::infinity();
  for (std::size_t i : among) *best = std::min(*best, s[i].cv_rmse_um);
  std::size_t pick = among.front();
  bool found = false;
  for (std::size_t i : among) {
    if (!(s[i].cv_rmse_um <= (1 + tolerance) * *best)) continue;
    if (!found || s[i].parameters < s[pick].parameters ||
        (s[i].parameters == s[pick].parameters && s[i].cv_rmse_um < s[pick].cv_rmse_um))
      pick = i, found = true;
  }
  return pick;
}

}  // namespace

CandidateChoice ChooseCandidate(const std::vector<CandidateScore>& s, const ChoiceRule& rule) {
  std::vector<std::size_t> finite;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (std::isfinite(s[i].cv_rmse_um)) finite.push_back(i);
  if (finite.empty())
    throw InputError("fit: no candidate model could be validated (too few samples per fold)");
  double best = 0;
  CandidateChoice c;
  c.pick = FewestWithin(s, finite, rule.tolerance, &best);
  const std::string tol = MessageNumber(100 * rule.tolerance) + " %";
  c.why = "validation RMSE " + Um(s[c.pick].cv_rmse_um) + ", the fewest parameters (" +
          std::to_string(s[c.pick].parameters) + ") within " + tol + " of the lowest (" + Um(best) +
          ")";
  // A sensor-free candidate replaces the sensor model only when it wins clearly and consistently.
  const auto sensors = std::find_if(s.begin(), s.end(), [](const CandidateScore& x) {
    return x.name == "sensors" && std::isfinite(x.cv_rmse_um);
  });
  if (!s[c.pick].sensor_free || sensors == s.end()) return c;
  int common = 0;
  const int wins = FoldWins(s[c.pick], *sensors, &common);
  const bool clearly = s[c.pick].cv_rmse_um <= (1 - rule.margin) * sensors->cv_rmse_um;
  const bool consistently = common > 0 && wins >= rule.consistency * common;
  const std::string record = s[c.pick].name + " " + Um(s[c.pick].cv_rmse_um) + " against sensors " +
                             Um(sensors->cv_rmse_um) + ", lower in " + std::to_string(wins) +
                             " of " + std::to_string(common) + " folds";
  if (clearly && consistently) {
    c.why += "; it replaces the sensor model, winning clearly and consistently (" + record + ")";
    return c;
  }
  c.pick = static_cast<std::size_t>(sensors - s.begin());
  c.why = "validation RMSE " + Um(sensors->cv_rmse_um) +
          "; the sensor model stays: a sensor-free model must be at least " +
          MessageNumber(100 * rule.margin) + " % lower and lower in " +
          MessageNumber(100 * rule.consistency) + " % of the folds to replace it (" + record + ")";
  return c;
}

namespace {

template <typename T>
void AddMissing(const std::vector<T>& from, std::vector<T>* to) {
  for (const T& v : from)
    if (std::find(to->begin(), to->end(), v) == to->end()) to->push_back(v);
}

// The index of each of `s`'s coefficients (intercept first) in the union model `m`.
std::vector<Eigen::Index> CoefficientIndex(const DriftModel& s, const DriftModel& m) {
  std::vector<Eigen::Index> at{0};
  for (const Feature& f : s.features) {
    const auto it = std::find_if(m.features.begin(), m.features.end(), [&](const Feature& g) {
      return g.input == f.input && g.tau == f.tau;
    });
    at.push_back(1 + (it - m.features.begin()));
  }
  return at;
}

void CheckBlendable(const DriftModel& a, const DriftModel& b, double share) {
  if (!(share >= 0 && share <= 1))
    throw InputError("blend share " + MessageNumber(share) + ": must be within 0..1");
  for (const DriftModel* x : {&a, &b})
    if (x->kind == ModelKind::kNetwork)
      throw InputError("blend: a network model is not linear in its features");
  if (a.error_column != b.error_column || a.time_unit != b.time_unit ||
      a.zero.zero != b.zero.zero)
    throw InputError("blend: the models differ in error column, time unit or error zero (" +
                     a.error_column + ", " + b.error_column + ")");
}

// The union model's inputs, lag and elapsed-time constants and features (drift/model.h order).
DriftModel UnionStructure(const DriftModel& a, const DriftModel& b) {
  DriftModel m;
  m.error_column = a.error_column;
  m.time_unit = a.time_unit;
  m.zero = a.zero;
  m.sensors = a.sensors;
  AddMissing(b.sensors, &m.sensors);
  m.extra_inputs = a.extra_inputs;
  AddMissing(b.extra_inputs, &m.extra_inputs);
  m.time_constants = a.time_constants;
  AddMissing(b.time_constants, &m.time_constants);
  std::sort(m.time_constants.begin(), m.time_constants.end());
  m.elapsed_time_constants = a.elapsed_time_constants;
  AddMissing(b.elapsed_time_constants, &m.elapsed_time_constants);
  std::sort(m.elapsed_time_constants.begin(), m.elapsed_time_constants.end());
  m.kind = m.time_constants.empty() ? ModelKind::kMlr : ModelKind::kDynamic;
  ListFeatures(&m);
  for (double t : m.elapsed_time_constants) m.features.push_back({"elapsed", t});
  m.selection = a.SensorFree() ? b.selection : a.selection;
  return m;
}

}  // namespace

DriftModel BlendModels(const DriftModel& a, const DriftModel& b, double share,
                       const std::vector<Run>& runs) {
  CheckBlendable(a, b, share);
  DriftModel m = UnionStructure(a, b);
  SetTrainingProvenance(runs, &m);
  const auto p = static_cast<Eigen::Index>(m.features.size()) + 1;
  Eigen::VectorXd c = Eigen::VectorXd::Zero(p);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  for (const auto& [s, w] : {std::pair<const DriftModel*, double>{&a, 1 - share}, {&b, share}}) {
    const std::vector<Eigen::Index> at = CoefficientIndex(*s, m);
    for (std::size_t i = 0; i < at.size(); ++i) {
      c(at[i]) += w * s->linear.coefficients(static_cast<Eigen::Index>(i));
      for (std::size_t j = 0; j < at.size(); ++j)
        cov(at[i], at[j]) += w * s->linear.covariance(static_cast<Eigen::Index>(i),
                                                      static_cast<Eigen::Index>(j));
    }
  }
  const Stacked st = Stack(runs, m.error_column, m.sensors, m.extra_inputs, m.time_constants, 2,
                           m.elapsed_time_constants);
  m.feature_min = st.x.colwise().minCoeff().transpose();
  m.feature_max = st.x.colwise().maxCoeff().transpose();
  const Eigen::VectorXd res = st.y - EvaluateLinear(c, st.x);
  LinearFit& f = m.linear;
  f.coefficients = c;
  f.covariance = cov;
  f.standard_errors = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  f.samples = static_cast<int>(st.y.size());
  f.degrees_of_freedom = std::max(1, f.samples - static_cast<int>(p));
  f.residual_std_um = std::sqrt(res.squaredNorm() / f.degrees_of_freedom);
  const double tss = (st.y.array() - st.y.mean()).square().sum();
  f.r_squared = tss > 0 ? 1.0 - res.squaredNorm() / tss : 1.0;
  f.xtx_inverse = f.residual_std_um > 0 ? Eigen::MatrixXd(cov / (f.residual_std_um * f.residual_std_um)) : cov;
  f.vif = VarianceInflation(st.x);
  m.residual_std_um = f.residual_std_um;
  m.r_squared = f.r_squared;
  return m;
}

namespace {

bool SameLinearModel(const DriftModel& a, const DriftModel& b) {
  if (a.time_constants != b.time_constants || a.sensors != b.sensors ||
      a.features.size() != b.features.size() ||
      a.elapsed_time_constants != b.elapsed_time_constants)
    return false;
  for (std::size_t i = 0; i < a.features.size(); ++i)
    if (a.features[i].input != b.features[i].input || a.features[i].tau != b.features[i].tau)
      return false;
  return a.linear.coefficients.size() == b.linear.coefficients.size() &&
         a.linear.coefficients == b.linear.coefficients;
}

// "chosen: NAME: why" -> NAME and why.
std::pair<std::string, std::string> SplitChosen(const std::string& chosen) {
  const std::size_t colon = chosen.find(':', 8);
  return {chosen.substr(8, colon - 8), chosen.substr(colon + 2)};
}

// FitOptions::dynamic_share: the mlr kind's choice `a` blended with the dynamic kind's.
FitReport BlendWithDynamic(const std::vector<Run>& runs, const std::string& error_column,
                           const FitOptions& o, FitReport a) {
  FitOptions od = o;
  od.kind = ModelKind::kDynamic;
  const FitReport b = FitCandidates(runs, error_column, od);
  const auto [name_a, why_a] = SplitChosen(a.chosen);
  const auto [name_b, why_b] = SplitChosen(b.chosen);
  if (a.model.SensorFree() || b.model.SensorFree()) {  // a time-only choice is not blended
    a.chosen += "; not blended with the dynamic kind's " + name_b +
                (a.model.SensorFree() ? " (the mlr choice is time-only)" : " (time-only)");
    a.model.notes.back() = a.chosen;
    return a;
  }
  if (SameLinearModel(a.model, b.model)) {  // the lag search added no lag
    a.chosen += "; the dynamic kind chose the same model (no lag)";
    a.model.notes.back() = a.chosen;
    return a;
  }
  FitReport rep = a;
  rep.blended = true;
  rep.model = BlendModels(a.model, b.model, o.dynamic_share, runs);
  rep.lag_search = b.lag_search;
  for (CandidateScore c : b.candidates)
    if (!c.sensor_free) c.name = "dynamic " + c.name, rep.candidates.push_back(c);
  const std::string pa = MessageNumber(100 * (1 - o.dynamic_share)) + " %";
  const std::string pb = MessageNumber(100 * o.dynamic_share) + " %";
  rep.chosen = "chosen: " + name_a + " " + pa + " + dynamic " + name_b + " " + pb +
               ": the default blends the mlr kind's choice with the dynamic kind's (lagged "
               "sensors shrunk towards the static model; docs/drift.md, issue 38). mlr: " +
               name_a + ", " + why_a + ". dynamic: " + name_b + ", " + why_b;
  rep.model.notes = {};
  for (const std::string& n : a.model.notes)
    if (n.rfind("chosen:", 0) != 0) rep.model.notes.push_back(n);
  for (const std::string& n : b.model.notes)
    if (n.rfind("chosen:", 0) != 0) rep.model.notes.push_back("dynamic kind: " + n);
  rep.model.notes.push_back(rep.chosen);
  return rep;
}

}  // namespace

FitOptions PreviousRunOptions(const DriftModel& m) {
  FitOptions f;
  f.threads = 1;
  f.zero = m.zero;
  f.kind = m.kind == ModelKind::kNetwork ? ModelKind::kMlr : m.kind;
  f.extra_inputs = m.extra_inputs;
  if (m.selection == "given") f.sensors = m.sensors;
  return f;
}

FitReport FitDriftModel(const std::vector<Run>& raw_runs, const std::string& error_column,
                        const FitOptions& o) {
  o.Validate();
  CheckTrainingRuns(raw_runs, error_column);
  ZeroConvention zero = o.zero;
  if (zero.zero == ErrorZero::kFixed && std::isnan(zero.gauge_level_um))
    zero.gauge_level_um = raw_runs.front().error_um(0, raw_runs.front().ErrorIndex(error_column));
  std::vector<Run> runs;
  for (const Run& r : raw_runs) runs.push_back(ApplyErrorZero(r, zero));
  const bool sensors_only = o.kind == ModelKind::kNetwork || o.candidates == Candidates::kSensors ||
                           (o.candidates == Candidates::kAuto && !o.sensors.empty());
  FitReport rep = sensors_only ? FitSensorModel(runs, error_column, o)
                      : FitCandidates(runs, error_column, o);
  if (!sensors_only && o.kind == ModelKind::kMlr && o.candidates == Candidates::kAuto &&
      o.dynamic_share > 0)
    rep = BlendWithDynamic(runs, error_column, o, std::move(rep));
  rep.model.zero = zero;
  return rep;
}

}  // namespace whirl::drift
