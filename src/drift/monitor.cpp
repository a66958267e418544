#include "drift/monitor.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"
#include "drift/regression.h"

namespace whirl::drift {
namespace {

std::string Vec(const Eigen::VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + FormatSignificant(v(i), 4);
  return s + "]";
}

void Require(bool ok, const std::string& option, double value, const std::string& rule) {
  if (!ok)
    throw InputError("monitor option " + option + " = " + MessageNumber(value) + ": " + rule);
}

// First sample at or after `time`, not before `min_sample`; -1 when the run ends first.
int SampleAt(const std::vector<double>& t, double time, int min_sample) {
  const auto it = std::lower_bound(t.begin(), t.end(), time - 1e-9);
  const int k = std::max(static_cast<int>(it - t.begin()), min_sample);
  return k < static_cast<int>(t.size()) ? k : -1;
}

// The inputs of one rule's replay.
struct Replay {
  const Eigen::MatrixXd& x;  // samples x (1 + features)
  const Eigen::VectorXd& y;  // measured with noise
  const std::vector<double>& t;
  const MonitorOptions& o;
  Eigen::VectorXd b0;  // the model's coefficients
  Eigen::MatrixXd p0;  // bayes prior
  double threshold_um, noise_variance;
  int start_sample;
  // patent, bayes drift: 1 for the intercept, then each feature's training range
  Eigen::VectorXd column_scale;
};

struct Piece {
  int from;
  Eigen::VectorXd b;
};

std::string CheckMessage(double t, double y, double p, double thr, bool valid) {
  return "check at " + FormatDecimals(t, 1) + ": |measured " + FormatDecimals(y, 3) +
         " - predicted " + FormatDecimals(p, 3) + "| = " + FormatDecimals(std::abs(y - p), 3) +
         " um " + (valid ? "<=" : ">") + " threshold " + FormatDecimals(thr, 3) + " um: model " +
         (valid ? "valid" : "invalid");
}

Eigen::VectorXd ApplyRule(UpdateRule rule, const Eigen::MatrixXd& xs, const Eigen::VectorXd& ys,
                          const Eigen::VectorXd& b, Eigen::MatrixXd* p, double r, int* rank,
                          const Eigen::VectorXd& scale) {
  switch (rule) {
    case UpdateRule::kPatent:
      return PatentRefit(xs, ys, b, rank, scale);
    case UpdateRule::kBayes:
      return BayesUpdate(xs, ys, b, p, r);
    case UpdateRule::kOffset:
      return OffsetUpdate(xs, ys, b);
    case UpdateRule::kStatic:
      break;
  }
  return b;
}

std::string UpdateMessage(UpdateRule rule, const Eigen::MatrixXd& xs, const Eigen::VectorXd& ys,
                          const Eigen::VectorXd& before, const Eigen::VectorXd& after, int rank,
                          double prior_scale, const std::string& drift) {
  const auto rms = [&](const Eigen::VectorXd& b) {
    return std::sqrt((ys - xs * b).squaredNorm() / static_cast<double>(ys.size()));
  };
  std::string how;
  if (rule == UpdateRule::kPatent)
    how = ": " + std::to_string(rank) + " of " + std::to_string(before.size()) +
          " directions identified" +
          (rank < before.size() ? " (the others keep the current coefficients)" : "");
  if (rule == UpdateRule::kBayes)
    how = ": prior scale " + MessageNumber(prior_scale) + " x Cov(b)" + drift;
  return ToString(rule) + how + "; update from " + std::to_string(ys.size()) +
         " measurements: RMS misfit on them " + FormatDecimals(rms(before), 3) + " -> " +
         FormatDecimals(rms(after), 3) + " um; coefficients " + Vec(before) + " -> " + Vec(after);
}

// One rule replayed on a run: the checks at the check interval, and after a failed check the
// refit measurements and the rule's update; the coefficients in force are kept as pieces.
class RuleReplay {
 public:
  RuleReplay(UpdateRule rule, const Replay& in)
      : in_(in), rule_(rule), pieces_{{0, in.b0}}, prior_(in.p0) {
    s_.rule = rule;
  }

  StrategyResult Run() {
    double next = in_.t[static_cast<std::size_t>(in_.start_sample)] + in_.o.check_every;
    int last = in_.start_sample;
    while (rule_ != UpdateRule::kStatic) {
      const int k = SampleAt(in_.t, next, last + 1);
      if (k < 0) break;
      last = k;
      if (!Check(k) && !Recalibrate(&last)) break;
      next = in_.t[static_cast<std::size_t>(last)] + in_.o.check_every;
    }
    Predict();
    s_.final_coefficients = pieces_.back().b;
    s_.final_covariance = prior_;
    s_.stop_min = s_.measurements * in_.o.stop_min_per_measurement;
    return s_;
  }

 private:
  // A measurement at sample k against the coefficients in force.
  MonitorEvent Measure(int k, MonitorEvent::Kind kind) {
    MonitorEvent e;
    e.kind = kind;
    e.sample = k;
    e.time = in_.t[static_cast<std::size_t>(k)];
    e.measured_um = in_.y(k);
    e.predicted_um = in_.x.row(k).dot(pieces_.back().b);
    ++s_.measurements;
    return e;
  }

  // The check at sample k: valid when |measured - predicted| <= threshold.
  bool Check(int k) {
    MonitorEvent check = Measure(k, MonitorEvent::Kind::kCheck);
    check.threshold_um = in_.threshold_um;
    check.valid = std::abs(check.measured_um - check.predicted_um) <= in_.threshold_um;
    if (rule_ == UpdateRule::kBayes)
      innovations_.push_back(CheckInnovation(in_.x.row(k), check.measured_um - check.predicted_um,
                                             prior_, in_.noise_variance, SeenDriftScale(k)));
    check.message = CheckMessage(check.time, check.measured_um, check.predicted_um,
                                 in_.threshold_um, check.valid);
    ++s_.checks;
    s_.events.push_back(check);
    if (!check.valid) ++s_.invalid_checks;
    return check.valid;
  }

  // After a failed check at *last: refit_samples more measurements at the refit interval, then
  // the rule's update from all of them; *last becomes the last sample measured. Returns false
  // when the run ends before the measurements are complete (no update).
  bool Recalibrate(int* last) {
    std::vector<int> rows{*last};
    for (int j = 0; j < in_.o.refit_samples; ++j) {
      const int q =
          SampleAt(in_.t, in_.t[static_cast<std::size_t>(*last)] + in_.o.refit_every, *last + 1);
      if (q < 0) break;
      MonitorEvent e = Measure(q, MonitorEvent::Kind::kRefitMeasurement);
      e.message = "refit measurement " + std::to_string(j + 1) + " of " +
                  std::to_string(in_.o.refit_samples) + ": measured " +
                  FormatDecimals(e.measured_um, 3) + ", predicted " +
                  FormatDecimals(e.predicted_um, 3) + " um";
      s_.events.push_back(e);
      rows.push_back(q);
      *last = q;
    }
    MonitorEvent u;
    u.sample = *last;
    u.time = in_.t[static_cast<std::size_t>(*last)];
    if (static_cast<int>(rows.size()) < in_.o.refit_samples + 1) {
      u.kind = MonitorEvent::Kind::kSkipped;
      u.message = "the run ended after " + std::to_string(rows.size() - 1) + " of " +
                  std::to_string(in_.o.refit_samples) + " refit measurements: no update";
      u.coefficients = pieces_.back().b;
      s_.events.push_back(u);
      return false;
    }
    Eigen::MatrixXd xs(static_cast<Eigen::Index>(rows.size()), in_.x.cols());
    Eigen::VectorXd ys(xs.rows());
    for (std::size_t j = 0; j < rows.size(); ++j) {
      xs.row(static_cast<Eigen::Index>(j)) = in_.x.row(rows[j]);
      ys(static_cast<Eigen::Index>(j)) = in_.y(rows[j]);
    }
    const Eigen::VectorXd before = pieces_.back().b;
    u.kind = MonitorEvent::Kind::kUpdate;
    int rank = 0;
    const std::string drift = AddDrift(*last);
    u.coefficients =
        ApplyRule(rule_, xs, ys, before, &prior_, in_.noise_variance, &rank, in_.column_scale);
    u.predicted_um = in_.x.row(*last).dot(u.coefficients);
    u.message =
        UpdateMessage(rule_, xs, ys, before, u.coefficients, rank, in_.o.prior_scale, drift);
    s_.events.push_back(u);
    pieces_.push_back({*last, u.coefficients});
    ++s_.recalibrations;
    return true;
  }

  // bayes with estimate_drift: P += q^2 D^-2, q^2 from this run's checks (header comment);
  // returns the phrase for the update's event.
  std::string AddDrift(int k) {
    if (rule_ != UpdateRule::kBayes || !in_.o.estimate_drift) return "";
    const double q2 = AddDriftVariance(innovations_, SeenDriftScale(k), &prior_);
    const std::string from = " (maximum likelihood from " + std::to_string(innovations_.size()) +
                             " checks)";
    if (!(q2 > 0)) return " + no drift: the checks' misfits are within noise and Cov(b)" + from;
    return " + drift q = " + FormatSignificant(std::sqrt(q2), 3) + " um per range seen" + from;
  }

  // D of the drift covariance through sample k: the box of the samples 0..k (DriftScale).
  Eigen::VectorXd SeenDriftScale(int k) {
    for (; seen_to_ <= k; ++seen_to_) seen_.Add(in_.x.row(seen_to_));
    return DriftScale(in_.column_scale, seen_);
  }

  // The prediction over the whole run, each piece's coefficients from its sample on.
  void Predict() {
    const int n = static_cast<int>(in_.t.size());
    s_.predicted_um.resize(n);
    for (std::size_t i = 0; i < pieces_.size(); ++i) {
      const int from = pieces_[i].from;
      const int to = i + 1 < pieces_.size() ? pieces_[i + 1].from : n;
      s_.predicted_um.segment(from, to - from) = in_.x.middleRows(from, to - from) * pieces_[i].b;
    }
  }

  const Replay& in_;
  const UpdateRule rule_;
  StrategyResult s_;
  std::vector<Piece> pieces_;
  Eigen::MatrixXd prior_;
  std::vector<Innovation> innovations_;  // bayes: every check's misfit (DriftVarianceMle)
  SeenBox seen_;                          // bayes: the features' box over samples [0, seen_to_)
  int seen_to_ = 0;
};

StrategyResult RunRule(UpdateRule rule, const Replay& in) { return RuleReplay(rule, in).Run(); }


}  // namespace

std::string ToString(UpdateRule r) {
  switch (r) {
    case UpdateRule::kStatic:
      return "static";
    case UpdateRule::kPatent:
      return "patent";
    case UpdateRule::kBayes:
      return "bayes";
    case UpdateRule::kOffset:
      return "offset";
  }
  return "?";
}

UpdateRule ParseUpdateRule(const std::string& text) {
  for (UpdateRule r :
       {UpdateRule::kStatic, UpdateRule::kPatent, UpdateRule::kBayes, UpdateRule::kOffset})
    if (ToString(r) == text) return r;
  throw InputError("update rule '" + text + "': must be patent, bayes or offset");
}

std::string ToString(MonitorEvent::Kind k) {
  switch (k) {
    case MonitorEvent::Kind::kCheck:
      return "check";
    case MonitorEvent::Kind::kRefitMeasurement:
      return "refit-measurement";
    case MonitorEvent::Kind::kUpdate:
      return "update";
    case MonitorEvent::Kind::kSkipped:
      return "skipped";
  }
  return "?";
}

void MonitorOptions::Validate() const {
  Require(std::isfinite(check_every) && check_every > 0, "check_every", check_every, "must be > 0");
  Require(std::isfinite(refit_every) && refit_every > 0, "refit_every", refit_every, "must be > 0");
  Require(std::isfinite(stop_min_per_measurement) && stop_min_per_measurement >= 0,
          "stop_min_per_measurement", stop_min_per_measurement, "must be >= 0 min");
  Require(std::isfinite(threshold_um) && threshold_um >= 0, "threshold_um", threshold_um,
          "must be >= 0 um (0: use threshold_sigma)");
  Require(std::isfinite(threshold_sigma) && threshold_sigma > 0, "threshold_sigma", threshold_sigma,
          "must be > 0");
  Require(refit_samples >= 0 && refit_samples <= kMaxRefitSamples, "refit_samples", refit_samples,
          "must be 0.." + std::to_string(kMaxRefitSamples));
  Require(std::isfinite(noise_um) && noise_um >= 0, "noise_um", noise_um, "must be >= 0 um");
  Require(std::isfinite(prior_scale) && prior_scale > 0, "prior_scale", prior_scale, "must be > 0");
  Require(std::isfinite(start), "start", start, "must be finite");
  Require(score_from >= 0 && score_from < score_to && score_to <= 1, "score_from", score_from,
          "need 0 <= score_from < score_to <= 1 (score_to = " + MessageNumber(score_to) + ")");
}

Eigen::MatrixXd MonitorDesign(const DriftModel& model, const Run& run, ReferenceMode reference) {
  if (model.kind == ModelKind::kNetwork)
    throw InputError("monitor: the model of " + model.error_column +
                     " is a network: the updates need a model linear in its coefficients (mlr or "
                     "dynamic)");
  model.Validate();
  if (run.time_from_index != (model.time_unit == "sample"))
    throw InputError(run.source + ": " +
                     (run.time_from_index ? "has no recorded time" : "has a recorded time") +
                     " but the model's time unit is '" + model.time_unit + "'");
  const Eigen::MatrixXd u = RawInputs(model, run);
  Eigen::VectorXd ref = model.reference_C;
  if (reference == ReferenceMode::kRunStart)
    ref = u.row(0).head(static_cast<Eigen::Index>(model.sensors.size())).transpose();
  DriftEvaluator ev(model, ref);
  Eigen::MatrixXd x(run.samples(), static_cast<Eigen::Index>(model.features.size()) + 1);
  for (int k = 0; k < run.samples(); ++k) {
    ev.Step(run.time_min[static_cast<std::size_t>(k)], u.row(k).transpose());
    x(k, 0) = 1.0;
    x.row(k).tail(x.cols() - 1) = ev.features().transpose();
  }
  return x;
}

Eigen::VectorXd PatentRefit(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& b, int* rank,
                            const Eigen::VectorXd& column_scale) {
  Eigen::VectorXd scale =
      column_scale.size() == x.cols() ? column_scale : Eigen::VectorXd(x.colwise().norm().transpose());
  for (Eigen::Index j = 0; j < scale.size(); ++j)
    if (!(scale(j) > 0)) scale(j) = 1;
  const Eigen::MatrixXd xs = x * scale.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(xs, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  const Eigen::VectorXd misfit = y - x * b;
  Eigen::VectorXd change_scaled = Eigen::VectorXd::Zero(x.cols());
  int k = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    if (!(s(i) >= 0.05 * s(0)) || !(s(i) > 0)) continue;
    change_scaled += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(misfit) / s(i));
    ++k;
  }
  if (rank) *rank = k;
  return b + scale.cwiseInverse().asDiagonal() * change_scaled;
}

Eigen::VectorXd BayesUpdate(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& b, Eigen::MatrixXd* p, double noise_variance) {
  // Information form: the gain form K = P X' (X P X' + r I)^-1 loses the digits of the data
  // when the prior is weak and n > q (X P X' is then a huge matrix of rank q).
  const Eigen::Index q = b.size();
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(q, q);
  Eigen::MatrixXd precision = p->ldlt().solve(identity);
  precision.noalias() += x.transpose() * x / noise_variance;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(precision);
  const Eigen::VectorXd updated = b + ldlt.solve(x.transpose() * (y - x * b) / noise_variance);
  const Eigen::MatrixXd next = ldlt.solve(identity);
  *p = 0.5 * (next + next.transpose());
  return updated;
}

double DriftVarianceMle(const std::vector<Innovation>& checks) {
  double unit = std::numeric_limits<double>::infinity();
  for (const Innovation& c : checks)
    if (c.gain > 0) unit = std::min(unit, std::max(c.variance_um2, 1e-300) / c.gain);
  if (!std::isfinite(unit)) return 0;
  const auto log_likelihood = [&](double q2) {
    double sum = 0;
    for (const Innovation& c : checks) {
      const double v = std::max(c.variance_um2 + q2 * c.gain, 1e-300);
      sum -= 0.5 * (std::log(v) + c.misfit_um * c.misfit_um / v);
    }
    return sum;
  };
  // Log grid in decades of `unit`, then golden section on the log between the best point's
  // neighbours (the likelihood is unimodal in q^2 for one check; the grid guards the rest).
  const double lo = -6, hi = 8, step = 0.02;
  double best_e = lo, best = log_likelihood(unit * std::pow(10.0, lo));
  for (double e = lo + step; e <= hi + 1e-9; e += step) {
    const double v = log_likelihood(unit * std::pow(10.0, e));
    if (v > best) best = v, best_e = e;
  }
  double a = best_e - step, b = best_e + step;
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  for (int i = 0; i < 40; ++i) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (log_likelihood(unit * std::pow(10.0, c)) > log_likelihood(unit * std::pow(10.0, d)))
      b = d;
    else
      a = c;
  }
  const double q2 = unit * std::pow(10.0, 0.5 * (a + b));
  return log_likelihood(q2) > log_likelihood(0.0) ? q2 : 0.0;
}

Eigen::VectorXd TrainingColumnScale(const DriftModel& m) {
  Eigen::VectorXd s(m.feature_max.size() + 1);
  s(0) = 1;
  for (Eigen::Index j = 0; j < m.feature_max.size(); ++j) {
    const double range = m.feature_max(j) - m.feature_min(j);
    s(j + 1) = range > 0 ? range : 1;
  }
  return s;
}

void SeenBox::Add(const Eigen::RowVectorXd& row) {
  if (lo.size() == 0) {
    lo = hi = row.transpose();
    return;
  }
  lo = lo.cwiseMin(row.transpose());
  hi = hi.cwiseMax(row.transpose());
}

Eigen::VectorXd DriftScale(const Eigen::VectorXd& column_scale, const SeenBox& seen) {
  Eigen::VectorXd d = column_scale.cwiseMax(seen.hi - seen.lo);
  d(0) = 1;
  return d;
}

Innovation CheckInnovation(const Eigen::RowVectorXd& x, double misfit_um,
                           const Eigen::MatrixXd& prior_covariance, double noise_variance,
                           const Eigen::VectorXd& drift_scale) {
  return {misfit_um, x.dot(prior_covariance * x.transpose()) + noise_variance,
          x.cwiseQuotient(drift_scale.transpose()).squaredNorm()};
}

double AddDriftVariance(const std::vector<Innovation>& checks, const Eigen::VectorXd& drift_scale,
                        Eigen::MatrixXd* prior_covariance) {
  const double q2 = DriftVarianceMle(checks);
  prior_covariance->diagonal() += q2 * drift_scale.cwiseAbs2().cwiseInverse();
  return q2;
}

Eigen::VectorXd OffsetUpdate(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& b) {
  Eigen::VectorXd updated = b;
  updated(0) += (y - x * b).mean();
  return updated;
}

namespace {

// The result's run, rows, scored window and threshold (MonitorRun's checks of its inputs).
MonitorResult StartResult(const DriftModel& model, const Run& run, const MonitorOptions& o,
                          int* start) {
  MonitorResult r;
  r.run = run.name;
  r.error_column = model.error_column;
  r.model_kind = ToString(model.kind);
  r.time = run.time_min;
  r.time_from_index = run.time_from_index;
  r.measured_um = ApplyErrorZero(run, model.zero).error_um.col(run.ErrorIndex(model.error_column));
  const int n = run.samples();
  *start = SampleAt(r.time, o.start, 0);
  if (*start < 0 || *start >= n - 1)
    throw InputError("monitor option start = " + MessageNumber(o.start) + ": the run " +
                     run.source + " ends at " + MessageNumber(r.time.back()) +
                     ": nothing to monitor");
  r.monitored_min = r.time.back() - r.time[static_cast<std::size_t>(*start)];
  if (r.monitored_min / o.check_every > kMaxMonitorChecks)
    throw InputError("monitor option check_every = " + MessageNumber(o.check_every) + ": over " +
                     std::to_string(kMaxMonitorChecks) + " checks in " +
                     MessageNumber(r.monitored_min) + " (limit)");
  r.score_begin = std::max(*start, static_cast<int>(o.score_from * n));
  r.score_end = std::min(n, static_cast<int>(o.score_to * n));
  if (r.score_end <= r.score_begin)
    throw InputError("monitor: no scored rows: rows [" + std::to_string(r.score_begin) + ", " +
                     std::to_string(r.score_end) + ") (start and score window)");
  Rng rng(o.seed);
  r.measurement_noise_um.resize(n);
  for (int k = 0; k < n; ++k) r.measurement_noise_um(k) = o.noise_um * rng.Normal();
  if (model.zero.zero == ErrorZero::kAsLogged)
    r.warnings.push_back(model.error_column +
                         ": the model file predates the error zero (schema 1): errors as logged");
  return r;
}

std::vector<UpdateRule> RulesOf(const MonitorOptions& o) {
  std::vector<UpdateRule> rules{UpdateRule::kStatic};
  for (UpdateRule u : o.rules)
    if (std::find(rules.begin(), rules.end(), u) == rules.end()) rules.push_back(u);
  return rules;
}

}  // namespace

std::string MonitorResult::Strongest() const {
  std::string best = "none";
  double v = none.mae_um;
  for (const auto& st : strategies)
    if (st.score.mae_um < v) best = ToString(st.rule), v = st.score.mae_um;
  for (const auto& b : baselines)
    if (b.score.mae_um < v) best = b.name, v = b.score.mae_um;
  return best;
}

MonitorResult MonitorRun(const DriftModel& model, const Run& run, const MonitorOptions& o,
                         const std::vector<DriftModel>& baselines,
                         const std::vector<StrategyResult>* initial) {
  o.Validate();
  const Eigen::MatrixXd x = MonitorDesign(model, run, o.reference);
  int start = 0;
  MonitorResult r = StartResult(model, run, o, &start);
  const Eigen::VectorXd y = r.measured_um + r.measurement_noise_um;
  const double s = model.residual_std_um;
  const double noise_variance = s * s + o.noise_um * o.noise_um;
  r.threshold_um =
      o.threshold_um > 0 ? o.threshold_um : o.threshold_sigma * std::sqrt(noise_variance);
  if (!(r.threshold_um > 0))
    throw InputError(
        "monitor: threshold is 0 um (the model's residual std is 0 and no noise): "
        "give an absolute threshold");
  const int m = r.score_end - r.score_begin;
  r.none = ComputeErrorStats(r.measured_um.segment(r.score_begin, m));
  const std::vector<UpdateRule> rules = RulesOf(o);
  for (std::size_t i = 0; i < rules.size(); ++i) {
    const bool carried = initial != nullptr && i < initial->size();
    const Replay in{x,
                    y,
                    r.time,
                    o,
                    carried ? (*initial)[i].final_coefficients : model.linear.coefficients,
                    carried && (*initial)[i].final_covariance.size() > 0
                        ? (*initial)[i].final_covariance
                        : Eigen::MatrixXd(o.prior_scale * model.linear.covariance),
                    r.threshold_um,
                    std::max(noise_variance, 1e-12),
                    start,
                    TrainingColumnScale(model)};
    StrategyResult sr = RunRule(rules[i], in);
    sr.stop_share = sr.stop_min / (r.monitored_min + sr.stop_min);
    sr.score = ComputeErrorStats(r.measured_um.segment(r.score_begin, m) -
                                 sr.predicted_um.segment(r.score_begin, m));
    r.strategies.push_back(std::move(sr));
  }
  for (const DriftModel& b : baselines) {
    BaselineResult br;
    br.name = b.SensorFree() && b.extra_inputs.empty() ? "time" : "duty:" + b.extra_inputs.front();
    br.predicted_um = PredictRun(b, run, o.reference).predicted_um;
    br.score = ComputeErrorStats(r.measured_um.segment(r.score_begin, m) -
                                 br.predicted_um.segment(r.score_begin, m));
    r.baselines.push_back(std::move(br));
  }
  if (run.time_from_index)
    r.warnings.push_back(run.name + ": no recorded time: intervals and stop share in samples");
  return r;
}

namespace {

// The scored residuals of one name, per day (empty: the name does not exist that day).
using DayResiduals = std::vector<std::vector<double>>;

// Appends the scored residuals of day `d` of `r` per name (none, strategies, baselines).
void CollectScored(const MonitorResult& r, std::size_t d, std::size_t days,
                   std::vector<std::pair<std::string, DayResiduals>>* week) {
  auto add = [&](const std::string& name, const Eigen::VectorXd& predicted) {
    auto it = std::find_if(week->begin(), week->end(), [&](const auto& p) { return p.first == name; });
    if (it == week->end()) it = week->insert(week->end(), {name, DayResiduals(days)});
    for (int k = r.score_begin; k < r.score_end; ++k)
      it->second[d].push_back(r.measured_um(k) - (predicted.size() ? predicted(k) : 0.0));
  };
  add("none", Eigen::VectorXd());
  for (const auto& st : r.strategies) add(ToString(st.rule), st.predicted_um);
  for (const auto& b : r.baselines) add(b.name, b.predicted_um);
}

// Statistics of the residuals of the days in `which` (all days when empty).
ErrorStats Pooled(const DayResiduals& res, const std::vector<int>& which) {
  std::vector<double> all;
  for (std::size_t d = 0; d < res.size(); ++d)
    if (which.empty() || std::find(which.begin(), which.end(), static_cast<int>(d)) != which.end())
      all.insert(all.end(), res[d].begin(), res[d].end());
  return ComputeErrorStats(
      Eigen::Map<const Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size())));
}

std::vector<int> CoveredDays(const DayResiduals& res) {
  std::vector<int> days;
  for (std::size_t d = 0; d < res.size(); ++d)
    if (!res[d].empty()) days.push_back(static_cast<int>(d));
  return days;
}

// The week's rows, the strongest of the full rows and each partial row against them.
void RankWeek(const std::vector<std::pair<std::string, DayResiduals>>& scored, WeekResult* w) {
  double best = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(w->days.size());
  for (const auto& [name, res] : scored) {
    const std::vector<int> covered = CoveredDays(res);
    w->week.push_back({name, Pooled(res, covered), static_cast<int>(covered.size())});
    if (static_cast<int>(covered.size()) == n && w->week.back().score.mae_um < best)
      best = w->week.back().score.mae_um, w->strongest = name;
  }
  for (const auto& [name, res] : scored) {
    const std::vector<int> covered = CoveredDays(res);
    if (static_cast<int>(covered.size()) == n || covered.empty()) continue;
    WeekPartial p{name, covered, Pooled(res, covered).mae_um, "",
                  std::numeric_limits<double>::infinity()};
    for (const auto& [other, ores] : scored) {
      if (static_cast<int>(CoveredDays(ores).size()) != n) continue;
      const double mae = Pooled(ores, covered).mae_um;
      if (mae < p.strongest_mae_um) p.strongest_mae_um = mae, p.strongest = other;
    }
    w->partial.push_back(p);
  }
}

}  // namespace

void CheckMonitorDays(std::size_t count) {
  if (count > static_cast<std::size_t>(kMaxMonitorDays))
    throw InputError("monitor: " + std::to_string(count) + " day files; at most " +
                     std::to_string(kMaxMonitorDays) +
                     " (a year of days) in one replay: replay fewer days at a time");
}

WeekResult MonitorWeek(const DriftModel& model, const std::vector<Run>& days,
                       const MonitorOptions& o, const std::vector<Run>& first_time_training) {
  if (days.empty()) throw InputError("monitor: give at least one day (--day)");
  CheckMonitorDays(days.size());
  long long samples = 0;
  for (const Run& d : days) samples += d.samples();
  if (samples > kMaxRunSamples)
    throw InputError("monitor: the " + std::to_string(days.size()) + " days hold " +
                     std::to_string(samples) + " samples together; at most " +
                     std::to_string(kMaxRunSamples) +
                     " (as one run file): replay fewer days at a time");
  WeekResult w;
  std::vector<std::pair<std::string, DayResiduals>> scored;
  FitOptions time_only;
  time_only.threads = 1;
  time_only.candidates = Candidates::kTime;
  time_only.zero = model.zero;
  const FitOptions previous_fit = PreviousRunOptions(model);
  for (std::size_t d = 0; d < days.size(); ++d) {
    std::vector<DriftModel> baselines;
    DriftModel previous = model;
    if (d > 0) {
      previous = FitDriftModel({days[d - 1]}, model.error_column, previous_fit).model;
      baselines.push_back(FitDriftModel({days[d - 1]}, model.error_column, time_only).model);
    } else if (!first_time_training.empty()) {
      baselines.push_back(FitDriftModel(first_time_training, model.error_column, time_only).model);
    }
    const std::vector<StrategyResult>* carried = d > 0 ? &w.days.back().strategies : nullptr;
    MonitorResult r = MonitorRun(model, days[d], o, baselines, carried);
    BaselineResult prev;
    prev.name = kPreviousRunBaseline;
    prev.predicted_um = PredictRun(previous, days[d], o.reference).predicted_um;
    prev.score = ComputeErrorStats(
        r.measured_um.segment(r.score_begin, r.score_end - r.score_begin) -
        prev.predicted_um.segment(r.score_begin, r.score_end - r.score_begin));
    r.baselines.push_back(std::move(prev));
    CollectScored(r, d, days.size(), &scored);
    w.days.push_back(std::move(r));
  }
  w.measurements.assign(w.days.front().strategies.size(), 0);
  w.stop_min.assign(w.days.front().strategies.size(), 0.0);
  for (const auto& r : w.days)
    for (std::size_t i = 0; i < r.strategies.size(); ++i) {
      w.measurements[i] += r.strategies[i].measurements;
      w.stop_min[i] += r.strategies[i].stop_min;
    }
  RankWeek(scored, &w);
  return w;
}

}  // namespace whirl::drift
