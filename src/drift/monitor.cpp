#include "drift/monitor.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

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
                          const Eigen::VectorXd& b, Eigen::MatrixXd* p, double r) {
  switch (rule) {
    case UpdateRule::kPatent:
      return PatentRefit(xs, ys);
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
                          const Eigen::VectorXd& before, const Eigen::VectorXd& after) {
  const auto rms = [&](const Eigen::VectorXd& b) {
    return std::sqrt((ys - xs * b).squaredNorm() / static_cast<double>(ys.size()));
  };
  return ToString(rule) + " update from " + std::to_string(ys.size()) +
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
    u.coefficients = ApplyRule(rule_, xs, ys, before, &prior_, in_.noise_variance);
    u.predicted_um = in_.x.row(*last).dot(u.coefficients);
    u.message = UpdateMessage(rule_, xs, ys, before, u.coefficients);
    s_.events.push_back(u);
    pieces_.push_back({*last, u.coefficients});
    ++s_.recalibrations;
    return true;
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

Eigen::VectorXd PatentRefit(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  return LeastSquaresCoefficients(x.rightCols(x.cols() - 1), y);
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

Eigen::VectorXd OffsetUpdate(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& b) {
  Eigen::VectorXd updated = b;
  updated(0) += (y - x * b).mean();
  return updated;
}

MonitorResult MonitorRun(const DriftModel& model, const Run& run, const MonitorOptions& o) {
  o.Validate();
  const Eigen::MatrixXd x = MonitorDesign(model, run, o.reference);
  MonitorResult r;
  r.run = run.name;
  r.error_column = model.error_column;
  r.model_kind = ToString(model.kind);
  r.time = run.time_min;
  r.time_from_index = run.time_from_index;
  r.measured_um = run.error_um.col(run.ErrorIndex(model.error_column));
  const int n = run.samples();
  const int start = SampleAt(r.time, o.start, 0);
  if (start < 0 || start >= n - 1)
    throw InputError("monitor option start = " + MessageNumber(o.start) + ": the run " +
                     run.source + " ends at " + MessageNumber(r.time.back()) +
                     ": nothing to monitor");
  r.monitored_min = r.time.back() - r.time[static_cast<std::size_t>(start)];
  if (r.monitored_min / o.check_every > kMaxMonitorChecks)
    throw InputError("monitor option check_every = " + MessageNumber(o.check_every) + ": over " +
                     std::to_string(kMaxMonitorChecks) + " checks in " +
                     MessageNumber(r.monitored_min) + " (limit)");
  r.score_begin = std::max(start, static_cast<int>(o.score_from * n));
  r.score_end = std::min(n, static_cast<int>(o.score_to * n));
  if (r.score_end <= r.score_begin)
    throw InputError("monitor: no scored rows: rows [" + std::to_string(r.score_begin) + ", " +
                     std::to_string(r.score_end) + ") (start and score window)");
  Rng rng(o.seed);
  r.measurement_noise_um.resize(n);
  for (int k = 0; k < n; ++k) r.measurement_noise_um(k) = o.noise_um * rng.Normal();
  const Eigen::VectorXd y = r.measured_um + r.measurement_noise_um;
  const double s = model.residual_std_um;
  const double noise_variance = s * s + o.noise_um * o.noise_um;
  r.threshold_um =
      o.threshold_um > 0 ? o.threshold_um : o.threshold_sigma * std::sqrt(noise_variance);
  if (!(r.threshold_um > 0))
    throw InputError(
        "monitor: threshold is 0 um (the model's residual std is 0 and no noise): "
        "give an absolute threshold");
  const Replay in{x,
                  y,
                  r.time,
                  o,
                  model.linear.coefficients,
                  o.prior_scale * model.linear.covariance,
                  r.threshold_um,
                  std::max(noise_variance, 1e-12),
                  start};
  const int m = r.score_end - r.score_begin;
  r.none = ComputeErrorStats(r.measured_um.segment(r.score_begin, m));
  std::vector<UpdateRule> rules{UpdateRule::kStatic};
  for (UpdateRule u : o.rules)
    if (std::find(rules.begin(), rules.end(), u) == rules.end()) rules.push_back(u);
  for (UpdateRule u : rules) {
    StrategyResult sr = RunRule(u, in);
    sr.stop_share = sr.stop_min / (r.monitored_min + sr.stop_min);
    sr.score = ComputeErrorStats(r.measured_um.segment(r.score_begin, m) -
                                 sr.predicted_um.segment(r.score_begin, m));
    r.strategies.push_back(std::move(sr));
  }
  if (run.time_from_index)
    r.warnings.push_back(run.name + ": no recorded time: intervals and stop share in samples");
  return r;
}

}  // namespace whirl::drift
