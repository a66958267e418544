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

// What every rule of one replay shares.
struct ReplayConfig {
  const MonitorOptions& o;
  double threshold_um, noise_variance;
  // patent, bayes drift: 1 for the intercept, then each feature's training range
  Eigen::VectorXd column_scale;
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

// One rule replayed on a run as its samples arrive (the control's view): the checks at the check
// interval, and after a failed check the refit measurements and the rule's update. The update
// applies from its sample on (the last measurement).
class OnlineRule {
 public:
  OnlineRule(UpdateRule rule, const ReplayConfig& in, Eigen::VectorXd b0, Eigen::MatrixXd p0,
             bool keep_samples)
      : in_(in), rule_(rule), b_(std::move(b0)), prior_(std::move(p0)), keep_(keep_samples) {
    s_.rule = rule;
  }

  // Monitoring starts at sample k (time t): the first check comes check_every after it.
  void Begin(int k, double t) {
    if (rule_ == UpdateRule::kStatic) return;
    mode_ = Mode::kCheck;
    last_ = k;
    next_ = t + in_.o.check_every;
  }

  // Sample k: its design row x = [1 f], the measured value y (noise included) and time t; the
  // events due at it, then its prediction by the coefficients in force.
  double Sample(int k, double t, const Eigen::RowVectorXd& x, double y) {
    if (rule_ == UpdateRule::kBayes) seen_.Add(x);  // the box of the samples 0..k
    if (mode_ == Mode::kCheck && k > last_ && t >= next_ - 1e-9) {
      last_ = k;
      rows_x_.clear();
      rows_y_.clear();
      rows_x_.push_back(x);
      rows_y_.push_back(y);
      if (Check(k, t, x, y)) {
        next_ = t + in_.o.check_every;
      } else if (in_.o.refit_samples == 0) {
        Update(k, t, x);
      } else {
        mode_ = Mode::kRefit;
        next_ = t + in_.o.refit_every;
      }
    } else if (mode_ == Mode::kRefit && k > last_ && t >= next_ - 1e-9) {
      last_ = k;
      MonitorEvent e = Measure(k, t, x, y, MonitorEvent::Kind::kRefitMeasurement);
      e.message = "refit measurement " + std::to_string(rows_y_.size()) + " of " +
                  std::to_string(in_.o.refit_samples) + ": measured " +
                  FormatDecimals(e.measured_um, 3) + ", predicted " +
                  FormatDecimals(e.predicted_um, 3) + " um";
      s_.events.push_back(e);
      rows_x_.push_back(x);
      rows_y_.push_back(y);
      if (static_cast<int>(rows_y_.size()) == in_.o.refit_samples + 1)
        Update(k, t, x);
      else
        next_ = t + in_.o.refit_every;
    }
    const double p = x.dot(b_);
    if (keep_) predicted_.push_back(p);
    return p;
  }

  // The run ended: refit measurements still missing are reported, with no update.
  StrategyResult Finish() {
    if (mode_ == Mode::kRefit) {
      MonitorEvent u;
      u.kind = MonitorEvent::Kind::kSkipped;
      u.sample = last_;
      u.time = last_time_;
      u.message = "the run ended after " + std::to_string(rows_y_.size() - 1) + " of " +
                  std::to_string(in_.o.refit_samples) + " refit measurements: no update";
      u.coefficients = b_;
      s_.events.push_back(u);
    }
    mode_ = Mode::kStopped;
    if (keep_)
      s_.predicted_um = Eigen::Map<const Eigen::VectorXd>(
          predicted_.data(), static_cast<Eigen::Index>(predicted_.size()));
    s_.final_coefficients = b_;
    s_.final_covariance = prior_;
    s_.stop_min = s_.measurements * in_.o.stop_min_per_measurement;
    return s_;
  }

 private:
  enum class Mode { kIdle, kCheck, kRefit, kStopped };

  // A measurement at sample k against the coefficients in force.
  MonitorEvent Measure(int k, double t, const Eigen::RowVectorXd& x, double y,
                       MonitorEvent::Kind kind) {
    MonitorEvent e;
    e.kind = kind;
    e.sample = k;
    e.time = t;
    e.measured_um = y;
    e.predicted_um = x.dot(b_);
    ++s_.measurements;
    last_time_ = t;
    return e;
  }

  // The check at sample k: valid when |measured - predicted| <= threshold.
  bool Check(int k, double t, const Eigen::RowVectorXd& x, double y) {
    MonitorEvent check = Measure(k, t, x, y, MonitorEvent::Kind::kCheck);
    check.threshold_um = in_.threshold_um;
    check.valid = std::abs(check.measured_um - check.predicted_um) <= in_.threshold_um;
    if (rule_ == UpdateRule::kBayes)
      innovations_.push_back(CheckInnovation(x, check.measured_um - check.predicted_um, prior_,
                                             in_.noise_variance, SeenScale()));
    check.message = CheckMessage(check.time, check.measured_um, check.predicted_um,
                                 in_.threshold_um, check.valid);
    ++s_.checks;
    s_.events.push_back(check);
    if (!check.valid) ++s_.invalid_checks;
    return check.valid;
  }

  // The rule's update from the measurements of this recalibration, at sample k (the last one).
  void Update(int k, double t, const Eigen::RowVectorXd& x) {
    Eigen::MatrixXd xs(static_cast<Eigen::Index>(rows_x_.size()), x.size());
    Eigen::VectorXd ys(xs.rows());
    for (std::size_t j = 0; j < rows_x_.size(); ++j) {
      xs.row(static_cast<Eigen::Index>(j)) = rows_x_[j];
      ys(static_cast<Eigen::Index>(j)) = rows_y_[j];
    }
    MonitorEvent u;
    u.kind = MonitorEvent::Kind::kUpdate;
    u.sample = k;
    u.time = t;
    const Eigen::VectorXd before = b_;
    int rank = 0;
    const std::string drift = AddDrift();
    u.coefficients =
        ApplyRule(rule_, xs, ys, before, &prior_, in_.noise_variance, &rank, in_.column_scale);
    u.predicted_um = x.dot(u.coefficients);
    u.message =
        UpdateMessage(rule_, xs, ys, before, u.coefficients, rank, in_.o.prior_scale, drift);
    s_.events.push_back(u);
    b_ = u.coefficients;
    ++s_.recalibrations;
    mode_ = Mode::kCheck;
    next_ = t + in_.o.check_every;
  }

  // bayes with estimate_drift: P += q^2 D^-2, q^2 from this run's checks (header comment);
  // returns the phrase for the update's event.
  std::string AddDrift() {
    if (rule_ != UpdateRule::kBayes || !in_.o.estimate_drift) return "";
    const double q2 = AddDriftVariance(innovations_, SeenScale(), &prior_);
    const std::string from = " (maximum likelihood from " + std::to_string(innovations_.size()) +
                             " checks)";
    if (!(q2 > 0)) return " + no drift: the checks' misfits are within noise and Cov(b)" + from;
    return " + drift q = " + FormatSignificant(std::sqrt(q2), 3) + " um per range seen" + from;
  }

  // D of the drift covariance: the box of the samples so far (DriftScale).
  Eigen::VectorXd SeenScale() const { return DriftScale(in_.column_scale, seen_); }

  const ReplayConfig& in_;
  const UpdateRule rule_;
  StrategyResult s_;
  Eigen::VectorXd b_;
  Eigen::MatrixXd prior_;
  bool keep_;
  std::vector<double> predicted_;
  Mode mode_ = Mode::kIdle;
  int last_ = 0;
  double next_ = 0, last_time_ = 0;
  std::vector<Eigen::RowVectorXd> rows_x_;  // the measurements of a recalibration
  std::vector<double> rows_y_;
  std::vector<Innovation> innovations_;  // bayes: every check's misfit (DriftVarianceMle)
  SeenBox seen_;                          // bayes: the features' box over the samples so far
};

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


// What a replay needs to know of its run before the first sample (a Run, or a file's layout and
// scan).
struct RunFacts {
  std::string name, source;
  long long rows = 0;
  bool time_from_index = false;
  double penultimate_time = 0, last_time = 0;
  std::vector<std::string> sensor_names, error_names, other_names;
};

std::string BaselineName(const DriftModel& b) {
  return b.SensorFree() && b.extra_inputs.empty() ? "time" : "duty:" + b.extra_inputs.front();
}

// The replay of every rule and baseline on one run, sample by sample (MonitorRun, MonitorFile):
// the evaluator's features, the measurement noise, the checks and updates of each rule, the
// baselines' predictions and the scores over the scored rows.
class Replayer {
 public:
  Replayer(const DriftModel& model, const MonitorOptions& o, RunFacts facts,
           const std::vector<NamedBaseline>& baselines, const std::vector<StrategyResult>* initial,
           bool keep, const MonitorSink& sink)
      : model_(model), o_(o), facts_(std::move(facts)), keep_(keep), sink_(sink), rng_(o.seed) {
    o.Validate();
    if (model.kind == ModelKind::kNetwork)
      throw InputError("monitor: the model of " + model.error_column +
                       " is a network: the updates need a model linear in its coefficients (mlr "
                       "or dynamic)");
    model.Validate();
    if (facts_.time_from_index != (model.time_unit == "sample"))
      throw InputError(facts_.source + ": " +
                       (facts_.time_from_index ? "has no recorded time" : "has a recorded time") +
                       " but the model's time unit is '" + model.time_unit + "'");
    inputs_ = ModelInputColumns(model, facts_.sensor_names, facts_.other_names, facts_.source);
    error_column_ = ErrorColumn();
    CheckStart();
    const double s = model.residual_std_um;
    const double noise_variance = s * s + o.noise_um * o.noise_um;
    const double threshold =
        o.threshold_um > 0 ? o.threshold_um : o.threshold_sigma * std::sqrt(noise_variance);
    if (!(threshold > 0))
      throw InputError(
          "monitor: threshold is 0 um (the model's residual std is 0 and no noise): "
          "give an absolute threshold");
    config_ = std::make_unique<ReplayConfig>(
        ReplayConfig{o, threshold, std::max(noise_variance, 1e-12), TrainingColumnScale(model)});
    const std::vector<UpdateRule> rules = ReplayedRules(o);
    for (std::size_t i = 0; i < rules.size(); ++i) {
      const bool carried = initial != nullptr && i < initial->size();
      rules_.emplace_back(rules[i], *config_,
                          carried ? (*initial)[i].final_coefficients : model.linear.coefficients,
                          carried && (*initial)[i].final_covariance.size() > 0
                              ? (*initial)[i].final_covariance
                              : Eigen::MatrixXd(o.prior_scale * model.linear.covariance),
                          keep);
    }
    for (const NamedBaseline& b : baselines) {
      baselines_.push_back(
          {b.name, std::make_unique<RunPredictor>(b.model, facts_.time_from_index, facts_.source,
                                                  o.reference),
           ModelInputColumns(b.model, facts_.sensor_names, facts_.other_names, facts_.source),
           {}, {}, {}});
      baselines_.back().raw.resize(static_cast<Eigen::Index>(
          baselines_.back().inputs.sensors.size() + baselines_.back().inputs.extras.size()));
    }
    if (model.zero.zero == ErrorZero::kFixed && !std::isfinite(model.zero.gauge_level_um))
      throw InputError(facts_.source + ": error zero 'fixed' needs a finite gauge level [um]");
    x_.resize(static_cast<Eigen::Index>(model.features.size()) + 1);
    raw_.resize(static_cast<Eigen::Index>(inputs_.sensors.size() + inputs_.extras.size()));
    sample_.predicted_um.resize(rules_.size());
    sample_.baseline_um.resize(baselines_.size());
    strategy_scores_.resize(rules_.size());
  }

  // One sample: its time and the run's rows of temperatures, errors and other columns.
  template <typename Row>
  void Add(double t, const Row& temps, const Row& errors, const Row& others) {
    const auto k = static_cast<int>(n_++);
    const double noise = o_.noise_um * rng_.Normal();  // one draw per sample, measured or not
    const double logged = errors(error_column_);
    if (k == 0)
      zero_ = model_.zero.zero == ErrorZero::kRunStart ? logged
              : model_.zero.zero == ErrorZero::kFixed  ? model_.zero.gauge_level_um
                                                       : 0.0;
    const double measured = logged - zero_;
    Eigen::Index c = 0;
    for (const int j : inputs_.sensors) raw_(c++) = temps(j);
    for (const int j : inputs_.extras) raw_(c++) = others(j);
    if (!evaluator_) {
      Eigen::VectorXd ref = model_.reference_C;
      if (o_.reference == ReferenceMode::kRunStart)
        ref = raw_.head(static_cast<Eigen::Index>(model_.sensors.size()));
      evaluator_ = std::make_unique<DriftEvaluator>(model_, ref);
      first_time_ = t;
    }
    evaluator_->Step(t, raw_);
    x_(0) = 1.0;
    x_.tail(x_.size() - 1) = evaluator_->features();
    if (start_ < 0 && t >= o_.start - 1e-9) Start(k, t);
    const Eigen::RowVectorXd xr = x_.transpose();
    for (std::size_t i = 0; i < rules_.size(); ++i)
      sample_.predicted_um[i] = rules_[i].Sample(k, t, xr, measured + noise);
    for (std::size_t i = 0; i < baselines_.size(); ++i) {
      Baseline& b = baselines_[i];
      Eigen::Index q = 0;
      for (const int j : b.inputs.sensors) b.raw(q++) = temps(j);
      for (const int j : b.inputs.extras) b.raw(q++) = others(j);
      sample_.baseline_um[i] = b.predictor->Step(t, b.raw);
    }
    Score(k, t, measured);
    if (keep_) Keep(t, measured, noise);
    if (sink_) {
      sample_.rows = facts_.rows;
      sample_.first_time = first_time_;
      sample_.last_time = facts_.last_time;
      sample_.index = k;
      sample_.time = t;
      sample_.measured_um = measured;
      sink_(sample_);
    }
    last_time_ = t;
  }

  MonitorResult Finish() {
    if (n_ != facts_.rows)
      throw InputError(facts_.source + ": " + std::to_string(n_) + " rows, but " +
                       std::to_string(facts_.rows) + " when it was scanned (did the file change?)");
    MonitorResult r;
    r.run = facts_.name;
    r.error_column = model_.error_column;
    r.model_kind = ToString(model_.kind);
    r.time_from_index = facts_.time_from_index;
    r.samples = n_;
    r.first_time = first_time_;
    r.last_time = last_time_;
    r.score_begin = score_begin_;
    r.score_end = score_end_;
    r.score_first_time = score_first_time_;
    r.score_last_time = score_last_time_;
    r.monitored_min = last_time_ - start_time_;
    r.threshold_um = config_->threshold_um;
    r.training_residual_std_um = model_.residual_std_um;
    r.none = none_.Stats();
    r.scored.emplace_back("none", none_);
    if (model_.zero.zero == ErrorZero::kAsLogged)
      r.warnings.push_back(model_.error_column +
                           ": the model file predates the error zero (schema 1): errors as logged");
    for (std::size_t i = 0; i < rules_.size(); ++i) {
      StrategyResult sr = rules_[i].Finish();
      sr.stop_share = sr.stop_min / (r.monitored_min + sr.stop_min);
      sr.score = strategy_scores_[i].Stats();
      r.scored.emplace_back(ToString(sr.rule), strategy_scores_[i]);
      r.strategies.push_back(std::move(sr));
    }
    for (Baseline& b : baselines_) {
      BaselineResult br;
      br.name = b.name;
      br.score = b.score.Stats();
      if (keep_)
        br.predicted_um = Eigen::Map<const Eigen::VectorXd>(
            b.kept.data(), static_cast<Eigen::Index>(b.kept.size()));
      r.scored.emplace_back(b.name, b.score);
      r.baselines.push_back(std::move(br));
    }
    if (keep_) {
      r.time = std::move(time_);
      r.measured_um = Eigen::Map<const Eigen::VectorXd>(measured_.data(),
                                                        static_cast<Eigen::Index>(measured_.size()));
      r.measurement_noise_um =
          Eigen::Map<const Eigen::VectorXd>(noise_.data(), static_cast<Eigen::Index>(noise_.size()));
    }
    if (facts_.time_from_index)
      r.warnings.push_back(facts_.name + ": no recorded time: intervals and stop share in samples");
    return r;
  }

 private:
  struct Baseline {
    std::string name;
    std::unique_ptr<RunPredictor> predictor;
    InputColumns inputs;
    ErrorStatsAccumulator score;
    std::vector<double> kept;
    Eigen::VectorXd raw;  // the model's raw inputs of the sample
  };

  Eigen::Index ErrorColumn() const {
    const auto& names = facts_.error_names;
    const auto it = std::find(names.begin(), names.end(), model_.error_column);
    if (it != names.end()) return it - names.begin();
    std::string have;
    for (const auto& n : names) have += (have.empty() ? "" : ", ") + n;
    throw InputError(facts_.source + ": no thermal-error (_um) column '" + model_.error_column +
                     "' (have: " + (have.empty() ? "none" : have) + ")");
  }

  // Monitoring needs a sample at or after the start with one more after it.
  void CheckStart() const {
    if (facts_.rows < 2 || !(facts_.penultimate_time >= o_.start - 1e-9))
      throw InputError("monitor option start = " + MessageNumber(o_.start) + ": the run " +
                       facts_.source + " ends at " + MessageNumber(facts_.last_time) +
                       ": nothing to monitor");
  }

  // Sample k (time t) is the first at or after the start: the scored window and the rules begin.
  void Start(int k, double t) {
    start_ = k;
    start_time_ = t;
    const double monitored = facts_.last_time - t;
    if (monitored / o_.check_every > kMaxMonitorChecks)
      throw InputError("monitor option check_every = " + MessageNumber(o_.check_every) +
                       ": over " + std::to_string(kMaxMonitorChecks) + " checks in " +
                       MessageNumber(monitored) + " (limit)");
    const auto n = static_cast<double>(facts_.rows);
    score_begin_ = std::max(k, static_cast<int>(o_.score_from * n));
    score_end_ = std::min(static_cast<int>(facts_.rows), static_cast<int>(o_.score_to * n));
    if (score_end_ <= score_begin_)
      throw InputError("monitor: no scored rows: rows [" + std::to_string(score_begin_) + ", " +
                       std::to_string(score_end_) + ") (start and score window)");
    for (OnlineRule& r : rules_) r.Begin(k, t);
  }

  void Score(int k, double t, double measured) {
    if (start_ < 0 || k < score_begin_ || k >= score_end_) return;
    if (k == score_begin_) score_first_time_ = t;
    score_last_time_ = t;
    none_.Add(measured);
    for (std::size_t i = 0; i < rules_.size(); ++i)
      strategy_scores_[i].Add(measured - sample_.predicted_um[i]);
    for (std::size_t i = 0; i < baselines_.size(); ++i)
      baselines_[i].score.Add(measured - sample_.baseline_um[i]);
  }

  void Keep(double t, double measured, double noise) {
    time_.push_back(t);
    measured_.push_back(measured);
    noise_.push_back(noise);
    for (std::size_t i = 0; i < baselines_.size(); ++i)
      baselines_[i].kept.push_back(sample_.baseline_um[i]);
  }

  const DriftModel& model_;
  const MonitorOptions& o_;
  RunFacts facts_;
  bool keep_;
  MonitorSink sink_;
  Rng rng_;
  std::unique_ptr<ReplayConfig> config_;
  std::vector<OnlineRule> rules_;
  std::vector<Baseline> baselines_;
  InputColumns inputs_;
  Eigen::Index error_column_ = 0;
  std::unique_ptr<DriftEvaluator> evaluator_;
  Eigen::VectorXd x_, raw_;
  MonitorSample sample_;
  long long n_ = 0;
  int start_ = -1, score_begin_ = 0, score_end_ = 0;
  double zero_ = 0, first_time_ = 0, last_time_ = 0, start_time_ = 0;
  double score_first_time_ = 0, score_last_time_ = 0;
  ErrorStatsAccumulator none_;
  std::vector<ErrorStatsAccumulator> strategy_scores_;
  std::vector<double> time_, measured_, noise_;
};

std::vector<NamedBaseline> Named(const std::vector<DriftModel>& baselines) {
  std::vector<NamedBaseline> out;
  for (const DriftModel& b : baselines) out.push_back({BaselineName(b), b});
  return out;
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

namespace {

MonitorResult ReplayRun(const DriftModel& model, const Run& run, const MonitorOptions& o,
                        const std::vector<NamedBaseline>& baselines,
                        const std::vector<StrategyResult>* initial) {
  RunFacts f{run.name, run.source, run.samples(), run.time_from_index,
             run.samples() > 1 ? run.time_min[run.time_min.size() - 2] : 0.0,
             run.time_min.empty() ? 0.0 : run.time_min.back(), run.sensor_names, run.error_names,
             run.other_names};
  Replayer replay(model, o, std::move(f), baselines, initial, true, {});
  for (int k = 0; k < run.samples(); ++k)
    replay.Add(run.time_min[static_cast<std::size_t>(k)], run.temperature_C.row(k),
               run.error_um.row(k), run.other.row(k));
  return replay.Finish();
}

}  // namespace

std::vector<UpdateRule> ReplayedRules(const MonitorOptions& o) {
  std::vector<UpdateRule> rules{UpdateRule::kStatic};
  for (UpdateRule u : o.rules)
    if (std::find(rules.begin(), rules.end(), u) == rules.end()) rules.push_back(u);
  return rules;
}

MonitorResult MonitorRun(const DriftModel& model, const Run& run, const MonitorOptions& o,
                         const std::vector<DriftModel>& baselines,
                         const std::vector<StrategyResult>* initial) {
  return ReplayRun(model, run, o, Named(baselines), initial);
}

MonitorResult MonitorFile(const DriftModel& model, const std::filesystem::path& path,
                          const MonitorOptions& o, const std::vector<NamedBaseline>& baselines,
                          const std::vector<StrategyResult>* initial, const MonitorSink& sink,
                          const StreamProgress& progress) {
  o.Validate();
  const RunScan scan = ScanRun(path);
  RunReader reader(path, RunState::kUnknown, scan.time_from_index);
  const RunLayout& l = reader.layout();
  RunFacts f{l.name, l.source, scan.rows, scan.time_from_index, scan.penultimate_time,
             scan.last_time, l.sensor_names, l.error_names, l.other_names};
  Replayer replay(model, o, std::move(f), baselines, initial, false, sink);
  RunRows b;
  const std::string step = "monitoring " + l.source;
  while (reader.Read(&b)) {
    for (int k = 0; k < b.count; ++k)
      replay.Add(b.time_min[static_cast<std::size_t>(k)], b.temperature_C.row(k),
                 b.error_um.row(k), b.other.row(k));
    if (progress) progress(step, reader.rows(), reader.fraction_read());
  }
  return replay.Finish();
}

namespace {

// Per name, its scored residuals' sums per day (count 0: the name does not exist that day).
using DayScores = std::vector<ErrorStatsAccumulator>;

// Adds day `d` of `r` per name (none, strategies, baselines).
void CollectScored(const MonitorResult& r, std::size_t d, std::size_t days,
                   std::vector<std::pair<std::string, DayScores>>* week) {
  for (const auto& [name, acc] : r.scored) {
    // C++17 cannot capture a structured binding (clang rejects it): an init-capture.
    auto it = std::find_if(week->begin(), week->end(),
                           [&n = name](const auto& p) { return p.first == n; });
    if (it == week->end()) it = week->insert(week->end(), {name, DayScores(days)});
    it->second[d] = acc;
  }
}

// Statistics of the days in `which` (all days when empty).
ErrorStats Pooled(const DayScores& res, const std::vector<int>& which) {
  ErrorStatsAccumulator all;
  for (std::size_t d = 0; d < res.size(); ++d)
    if (which.empty() || std::find(which.begin(), which.end(), static_cast<int>(d)) != which.end())
      all.Merge(res[d]);
  return all.Stats();
}

std::vector<int> CoveredDays(const DayScores& res) {
  std::vector<int> days;
  for (std::size_t d = 0; d < res.size(); ++d)
    if (res[d].count() > 0) days.push_back(static_cast<int>(d));
  return days;
}

// The week's rows, the strongest of the full rows and each partial row against them.
void RankWeek(const std::vector<std::pair<std::string, DayScores>>& scored, WeekResult* w) {
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

// The week's loop (MonitorWeek, MonitorWeekFiles): per day the baselines fitted on the day
// before (`fit(d, options)` fits day d), then `replay(d, baselines, carried)`.
WeekResult ReplayWeek(
    const DriftModel& model, std::size_t days,
    const std::function<DriftModel(std::size_t, const FitOptions&)>& fit,
    const std::function<DriftModel(const FitOptions&)>& first_time,
    const std::function<MonitorResult(std::size_t, const std::vector<NamedBaseline>&,
                                      const std::vector<StrategyResult>*)>& replay) {
  if (days == 0) throw InputError("monitor: give at least one day (--day)");
  CheckMonitorDays(days);
  WeekResult w;
  std::vector<std::pair<std::string, DayScores>> scored;
  FitOptions time_only;
  time_only.threads = 1;
  time_only.candidates = Candidates::kTime;
  time_only.zero = model.zero;
  const FitOptions previous_fit = PreviousRunOptions(model);
  for (std::size_t d = 0; d < days; ++d) {
    std::vector<NamedBaseline> baselines;
    DriftModel previous = model;
    if (d > 0) {
      previous = fit(d - 1, previous_fit);
      baselines.push_back({"time", fit(d - 1, time_only)});
    } else if (first_time) {
      baselines.push_back({"time", first_time(time_only)});
    }
    baselines.push_back({kPreviousRunBaseline, std::move(previous)});
    const std::vector<StrategyResult>* carried = d > 0 ? &w.days.back().strategies : nullptr;
    MonitorResult r = replay(d, baselines, carried);
    CollectScored(r, d, days, &scored);
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

}  // namespace

void CheckMonitorDays(std::size_t count) {
  if (count > static_cast<std::size_t>(kMaxMonitorDays))
    throw InputError("monitor: " + std::to_string(count) + " day files; at most " +
                     std::to_string(kMaxMonitorDays) +
                     " (a year of days) in one replay: replay fewer days at a time");
}

WeekResult MonitorWeek(const DriftModel& model, const std::vector<Run>& days,
                       const MonitorOptions& o, const std::vector<Run>& first_time_training) {
  CheckMonitorDays(days.size());
  long long samples = 0;
  for (const Run& d : days) samples += d.samples();
  if (samples > kMaxRunSamples)
    throw InputError("monitor: the " + std::to_string(days.size()) + " days hold " +
                     std::to_string(samples) + " samples together; at most " +
                     std::to_string(kMaxRunSamples) +
                     " (as one run file): replay fewer days at a time");
  std::function<DriftModel(const FitOptions&)> first;
  if (!first_time_training.empty())
    first = [&](const FitOptions& f) {
      return FitDriftModel(first_time_training, model.error_column, f).model;
    };
  return ReplayWeek(
      model, days.size(),
      [&](std::size_t d, const FitOptions& f) {
        return FitDriftModel({days[d]}, model.error_column, f).model;
      },
      first,
      [&](std::size_t d, const std::vector<NamedBaseline>& b, const std::vector<StrategyResult>* c) {
        return ReplayRun(model, days[d], o, b, c);
      });
}

WeekResult MonitorWeekFiles(const DriftModel& model, const std::vector<std::filesystem::path>& days,
                            const MonitorOptions& o,
                            const std::function<void(std::size_t, const MonitorSample&)>& sink,
                            const StreamProgress& progress) {
  return ReplayWeek(
      model, days.size(),
      [&](std::size_t d, const FitOptions& f) {
        return FitFiles({{days[d], RunState::kUnknown}}, model.error_column, f, progress).model;
      },
      {},
      [&](std::size_t d, const std::vector<NamedBaseline>& b, const std::vector<StrategyResult>* c) {
        MonitorSink day_sink;
        if (sink) day_sink = [&](const MonitorSample& s) { sink(d, s); };
        return MonitorFile(model, days[d], o, b, c, day_sink, progress);
      });
}

}  // namespace whirl::drift
