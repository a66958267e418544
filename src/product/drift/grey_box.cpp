#include "drift/grey_box.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "drift/model.h"

namespace whirl::drift {

void GreyBoxOptions::Validate() const {
  auto positive = [](const std::vector<double>& v, const char* name) {
    if (v.empty()) throw InputError(std::string("grey box: ") + name + " is empty");
    for (double x : v)
      if (!(x > 0) || !std::isfinite(x))
        throw InputError(std::string("grey box: ") + name + " holds " + std::to_string(x) +
                         ": each value must be finite and > 0");
  };
  positive(tau_grid, "tau_grid");
  positive(blank_tau_grid, "blank_tau_grid");
  positive(strength_grid, "strength_grid");
  if (!short_record_strength_grid.empty())
    positive(short_record_strength_grid, "short_record_strength_grid");
  if (short_record_offset_lags < -1 || short_record_offset_lags > 4)
    throw InputError("grey box: short_record_offset_lags = " +
                     std::to_string(short_record_offset_lags) + ": must be -1 (off) or 0..4");
  if (max_lags < 0 || max_lags > 4)
    throw InputError("grey box: max_lags = " + std::to_string(max_lags) + ": must be within 0..4");
  if (forward_days < 2 || forward_days > 100)
    throw InputError("grey box: forward_days = " + std::to_string(forward_days) +
                     ": must be within 2..100");
  if (!(lead_share > 0 && lead_share < 1))
    throw InputError("grey box: lead_share = " + std::to_string(lead_share) +
                     ": must lie in (0, 1)");
}

std::vector<std::string> GreyBoxSpec::Inputs() const {
  std::vector<std::string> in = offset_sensors;
  in.insert(in.end(), slope_sensors.begin(), slope_sensors.end());
  if (!blank_sensor.empty()) in.push_back(blank_sensor);
  return in;
}

namespace {
std::vector<std::string> Concatenated(std::vector<std::string> a,
                                      const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}
}  // namespace

std::vector<std::string> GreyBoxSpec::DutyInputs() const {
  return Concatenated(offset_duty, slope_duty);
}

std::vector<std::string> GreyBoxModel::DutyInputs() const {
  return Concatenated(offset_duty, slope_duty);
}

std::vector<std::string> GreyBoxModel::Inputs() const {
  std::vector<std::string> in = offset_sensors;
  in.insert(in.end(), slope_sensors.begin(), slope_sensors.end());
  if (!blank_sensor.empty()) in.push_back(blank_sensor);
  return in;
}

Eigen::MatrixXd AbsoluteFeatures(const Run& run, const std::vector<std::string>& sensors,
                                 const std::vector<double>& taus) {
  Eigen::MatrixXd f = BuildFeatures(run, sensors, {}, taus);
  const auto per = static_cast<Eigen::Index>(1 + taus.size());
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    const double first = run.temperature_C(0, run.SensorIndex(sensors[i])) - 20.0;
    f.middleCols(static_cast<Eigen::Index>(i) * per, per).array() += first;
  }
  return f;
}

Eigen::MatrixXd GreyChannelFeatures(const Run& run, const std::vector<std::string>& sensors,
                                    const std::vector<std::string>& duty,
                                    const std::vector<double>& taus) {
  const Eigen::MatrixXd t = AbsoluteFeatures(run, sensors, taus);
  if (duty.empty()) return t;
  const Eigen::MatrixXd d = BuildFeatures(run, {}, duty, taus);
  Eigen::MatrixXd f(t.rows(), t.cols() + d.cols());
  f << t, d;
  return f;
}

namespace grey_box_detail {

struct Choice {
  std::vector<double> taus;
  double blank_tau = 60;
  double strength = 1e-2;
};

// The stacked, record-demeaned design: columns [phi_o | phi_s dz | dz | (B0 - 20) dz], dz =
// (z_ref - z) / 1000; the prior of every column; weights (lead_share applied) and days.
struct Design {
  Eigen::MatrixXd x;
  Eigen::VectorXd y, w, prior;
  std::vector<int> day;
  std::vector<bool> lead;       ///< the row is a lead reading
  Eigen::Index po = 0, ps = 0;  ///< offset and slope feature counts
};

struct LogFeatures {
  Eigen::MatrixXd off, slope;
  Eigen::VectorXd blank_c;  ///< B(t) per sample (20 without a blank sensor)
};

// Which columns of each sensor a channel keeps (per input: the instant column, then one per
// lag), by the options and the record's length; none is dropped without a lag.
struct Columns {
  std::vector<bool> offset, slope;
};

std::vector<bool> KeptColumns(std::size_t taus, bool instant, std::size_t lags) {
  std::vector<bool> keep(1 + taus, false);
  keep[0] = instant || lags == 0;
  for (std::size_t l = 0; l < std::min(lags, taus); ++l) keep[1 + l] = true;
  return keep;
}

Columns ColumnsOf(const GreyBoxOptions& o, const Choice& c, bool long_record) {
  const std::size_t taus = c.taus.size();
  const bool cut = o.short_record_offset_lags >= 0 && !long_record;
  const std::size_t offset_lags =
      cut ? std::min(taus, static_cast<std::size_t>(o.short_record_offset_lags)) : taus;
  return {KeptColumns(taus, o.instant_offset_inputs, offset_lags),
          KeptColumns(taus, o.instant_slope_inputs, taus)};
}

// Zeroes the columns `keep` drops of each of the first `inputs` inputs.
void ZeroDropped(Eigen::MatrixXd* f, std::size_t inputs, const std::vector<bool>& keep) {
  for (std::size_t i = 0; i < inputs; ++i)
    for (std::size_t k = 0; k < keep.size(); ++k)
      if (!keep[k]) f->col(static_cast<Eigen::Index>(i * keep.size() + k)).setZero();
}

LogFeatures FeaturesOf(const Run& log, const GreyBoxSpec& spec, const Choice& c,
                       const Columns& cols) {
  LogFeatures f;
  f.off = GreyChannelFeatures(log, spec.offset_sensors, spec.offset_duty, c.taus);
  f.slope = GreyChannelFeatures(log, spec.slope_sensors, spec.slope_duty, c.taus);
  ZeroDropped(&f.off, spec.offset_sensors.size(), cols.offset);
  ZeroDropped(&f.slope, spec.slope_sensors.size(), cols.slope);
  f.blank_c = Eigen::VectorXd::Constant(log.samples(), 20.0);
  if (!spec.blank_sensor.empty())
    f.blank_c = AbsoluteFeatures(log, {spec.blank_sensor}, {c.blank_tau}).col(1).array() + 20.0;
  return f;
}

// Each input's prior spread equally over the columns `keep` holds.
Eigen::VectorXd Priors(const std::vector<std::string>& inputs,
                       const std::map<std::string, double>& prior, const std::vector<bool>& keep) {
  const auto per = static_cast<Eigen::Index>(keep.size());
  const auto kept = static_cast<double>(std::count(keep.begin(), keep.end(), true));
  Eigen::VectorXd p = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(inputs.size()) * per);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto it = prior.find(inputs[i]);
    if (it == prior.end()) continue;
    for (Eigen::Index k = 0; k < per; ++k)
      if (keep[static_cast<std::size_t>(k)])
        p(static_cast<Eigen::Index>(i) * per + k) = it->second / kept;
  }
  return p;
}

Design BuildDesign(const ShopRecord& rec, const GreyBoxSpec& spec, const Choice& c,
                   const GreyBoxOptions& o) {
  const double lead_share = o.lead_share;
  const Columns cols = ColumnsOf(o, c, LongRecord(rec, o));
  std::vector<LogFeatures> logs(rec.day_logs.size());
  std::vector<bool> built(rec.day_logs.size(), false);
  std::size_t n = 0;
  for (const auto& r : rec.records) n += r.rows.size();
  Design d;
  const std::size_t per = 1 + c.taus.size();
  d.po = static_cast<Eigen::Index>((spec.offset_sensors.size() + spec.offset_duty.size()) * per);
  d.ps = static_cast<Eigen::Index>((spec.slope_sensors.size() + spec.slope_duty.size()) * per);
  const Eigen::Index p = d.po + d.ps + 2;
  d.x.resize(static_cast<Eigen::Index>(n), p);
  d.y.resize(static_cast<Eigen::Index>(n));
  d.w.resize(static_cast<Eigen::Index>(n));
  double lead_w = 0, other_w = 0;
  Eigen::Index row = 0;
  for (const auto& r : rec.records) {
    const auto l = static_cast<std::size_t>(r.log);
    if (!built[l]) logs[l] = FeaturesOf(rec.day_logs[l], spec, c, cols), built[l] = true;
    const LogFeatures& f = logs[l];
    const bool lead = r.kind == MeasurementRecord::Kind::kLead;
    const double blank = lead && !r.rows.empty() ? f.blank_c(r.rows.front().sample) - 20.0 : 0.0;
    const Eigen::Index begin = row;
    for (const Measurement& m : r.rows) {
      const double dz = (spec.z_ref_mm - m.z_mm) / 1000.0;
      d.x.row(row) << f.off.row(m.sample), f.slope.row(m.sample) * dz, dz, blank * dz;
      d.y(row) = m.value_um;
      d.w(row) = 1.0 / (m.sigma_um * m.sigma_um);
      (lead ? lead_w : other_w) += d.w(row);
      d.day.push_back(r.day);
      d.lead.push_back(lead);
      ++row;
    }
    const Eigen::Index len = row - begin;
    if (len == 0) continue;
    const auto wr = d.w.segment(begin, len);
    const double sw = wr.sum();
    const Eigen::RowVectorXd mx =
        (d.x.middleRows(begin, len).array().colwise() * wr.array()).colwise().sum() / sw;
    d.x.middleRows(begin, len).rowwise() -= mx;
    d.y.segment(begin, len).array() -= wr.dot(d.y.segment(begin, len)) / sw;
  }
  // The leads' share of the weight (both kinds present), the total kept.
  if (lead_w > 0 && other_w > 0) {
    const double total = lead_w + other_w;
    row = 0;
    for (const auto& r : rec.records) {
      const bool lead = r.kind == MeasurementRecord::Kind::kLead;
      const double f = lead ? lead_share * total / lead_w : (1 - lead_share) * total / other_w;
      for (std::size_t k = 0; k < r.rows.size(); ++k) d.w(row++) *= f;
    }
  }
  d.prior.resize(p);
  const auto duty_cols = [&](const std::vector<std::string>& duty) {
    return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(duty.size() * per));
  };
  d.prior << Priors(spec.offset_sensors, spec.offset_prior, cols.offset),
      duty_cols(spec.offset_duty), Priors(spec.slope_sensors, spec.slope_prior, cols.slope),
      duty_cols(spec.slope_duty), 0.0, spec.blank_prior;
  return d;
}

// min sum w (y - x b)^2 + lambda sum_j s_j^2 (b_j - p_j)^2, lambda = strength sum w.
Eigen::VectorXd Solve(const Design& d, const Eigen::VectorXd& w, double strength) {
  const Eigen::Index k = d.x.cols();
  const double sw = w.sum();
  if (!(sw > 0)) return d.prior;
  Eigen::VectorXd scale(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    scale(j) = std::sqrt(w.dot(d.x.col(j).cwiseAbs2()) / sw);
    if (!(scale(j) > 1e-12)) scale(j) = 1.0;
  }
  const Eigen::MatrixXd xs = d.x * scale.cwiseInverse().asDiagonal();
  Eigen::MatrixXd a = xs.transpose() * w.asDiagonal() * xs;
  const double lambda = strength * sw;
  a.diagonal().array() += lambda;
  const Eigen::VectorXd rhs =
      xs.transpose() * (w.asDiagonal() * d.y) + lambda * d.prior.cwiseProduct(scale);
  return Eigen::LDLT<Eigen::MatrixXd>(a).solve(rhs).cwiseQuotient(scale);
}

// Adds to *num and *den the weighted squared residuals of the rows `scored` picks, the fit
// trained on the rows `trained` picks (the held-out part of one cross-validation fold).
template <class Trained, class Scored>
void AddHeldOut(const Design& d, double strength, Trained trained, Scored scored, double* num,
                double* den) {
  const auto n = d.x.rows();
  Eigen::VectorXd wt = d.w;
  for (Eigen::Index i = 0; i < n; ++i)
    if (!trained(static_cast<std::size_t>(i))) wt(i) = 0;
  const Eigen::VectorXd b = Solve(d, wt, strength);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!scored(static_cast<std::size_t>(i))) continue;
    const double r = d.y(i) - d.x.row(i).dot(b);
    *num += d.w(i) * r * r;
    *den += d.w(i);
  }
}

// Leave one calendar day out (weighted RMS of the held-out residuals); one day: training RMS.
double CvRmse(const Design& d, double strength) {
  const std::set<int> days(d.day.begin(), d.day.end());
  if (days.size() < 2) {
    const Eigen::VectorXd r = d.y - d.x * Solve(d, d.w, strength);
    return std::sqrt(d.w.dot(r.cwiseAbs2()) / d.w.sum());
  }
  double num = 0, den = 0;
  for (int day : days)
    AddHeldOut(d, strength, [&](std::size_t i) { return d.day[i] != day; },
               [&](std::size_t i) { return d.day[i] == day; }, &num, &den);
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

// Forward chaining on the leads: each of the last `days` of `lead_days` (LeadDays, at least
// `days` of them), fitted on the rows of the earlier days; NaN when no lead row is scored.
double ForwardLeadRmse(const Design& d, double strength, std::vector<int> chosen, int days) {
  chosen.erase(chosen.begin(), chosen.end() - days);
  double num = 0, den = 0;
  for (int day : chosen)
    AddHeldOut(d, strength, [&](std::size_t i) { return d.day[i] < day; },
               [&](std::size_t i) { return d.day[i] == day && d.lead[i]; }, &num, &den);
  return den > 0 ? std::sqrt(num / den) : std::nan("");
}

double Score(const ShopRecord& rec, const GreyBoxSpec& spec, const Choice& c,
             const GreyBoxOptions& o) {
  const Design d = BuildDesign(rec, spec, c, o);
  if (ScoresForward(rec, o)) {
    const double e = ForwardLeadRmse(d, c.strength, LeadDays(rec), o.forward_days);
    if (std::isfinite(e)) return e;
  }
  return CvRmse(d, c.strength);
}

// Lags greedy (accepted while the CV falls), then the blank's lag, then the strength.
Choice Choose(const ShopRecord& rec, const GreyBoxSpec& spec, const GreyBoxOptions& o,
              double* cv) {
  Choice c;
  const std::vector<double>& strengths = StrengthGrid(rec, o);
  c.blank_tau = o.blank_tau_grid[o.blank_tau_grid.size() / 2];
  c.strength = strengths[strengths.size() / 2];
  double current = Score(rec, spec, c, o);
  while (static_cast<int>(c.taus.size()) < o.max_lags) {
    double best = current, pick = 0;
    for (double tau : o.tau_grid) {
      if (std::find(c.taus.begin(), c.taus.end(), tau) != c.taus.end()) continue;
      Choice t = c;
      t.taus.push_back(tau);
      std::sort(t.taus.begin(), t.taus.end());
      const double e = Score(rec, spec, t, o);
      if (e < best) best = e, pick = tau;
    }
    if (pick <= 0) break;
    c.taus.push_back(pick);
    std::sort(c.taus.begin(), c.taus.end());
    current = best;
  }
  auto pick_best = [&](double Choice::*field, const std::vector<double>& grid) {
    for (double v : grid) {
      Choice t = c;
      t.*field = v;
      const double e = Score(rec, spec, t, o);
      if (e < current) current = e, c = t;
    }
  };
  if (!spec.blank_sensor.empty()) pick_best(&Choice::blank_tau, o.blank_tau_grid);
  pick_best(&Choice::strength, strengths);
  *cv = current;
  return c;
}

}  // namespace grey_box_detail

std::vector<int> LeadDays(const ShopRecord& record) {
  std::set<int> days;
  for (const MeasurementRecord& r : record.records)
    if (r.kind == MeasurementRecord::Kind::kLead && !r.rows.empty()) days.insert(r.day);
  return {days.begin(), days.end()};
}

bool LongRecord(const ShopRecord& record, const GreyBoxOptions& options) {
  return LeadDays(record).size() >= 2 * static_cast<std::size_t>(options.forward_days);
}

bool ScoresForward(const ShopRecord& record, const GreyBoxOptions& options) {
  return options.validation == GreyValidation::kForwardLeads && LongRecord(record, options);
}

const std::vector<double>& StrengthGrid(const ShopRecord& record, const GreyBoxOptions& options) {
  return !LongRecord(record, options) && !options.short_record_strength_grid.empty()
             ? options.short_record_strength_grid
             : options.strength_grid;
}

GreyBoxModel FitGreyBox(const ShopRecord& record, const GreyBoxSpec& spec,
                        const GreyBoxOptions& options) {
  record.Validate();
  options.Validate();
  if (spec.offset_sensors.empty() && spec.slope_sensors.empty())
    throw InputError("grey box: no offset or slope sensor given");
  for (const Run& log : record.day_logs) {
    for (const auto& s : spec.Inputs()) (void)log.SensorIndex(s);  // InputError naming it
    for (const auto& s : spec.DutyInputs()) (void)log.OtherIndex(s);
  }
  double cv = 0;
  const grey_box_detail::Choice c = grey_box_detail::Choose(record, spec, options, &cv);
  const grey_box_detail::Design d = grey_box_detail::BuildDesign(record, spec, c, options);
  if (d.x.rows() <= d.x.cols())
    throw InputError("grey box: " + std::to_string(d.x.rows()) + " readings for " +
                     std::to_string(d.x.cols()) + " coefficients");
  const Eigen::VectorXd b = grey_box_detail::Solve(d, d.w, c.strength);
  GreyBoxModel m;
  m.offset_sensors = spec.offset_sensors;
  m.slope_sensors = spec.slope_sensors;
  m.blank_sensor = spec.blank_sensor;
  m.offset_duty = spec.offset_duty;
  m.slope_duty = spec.slope_duty;
  m.time_constants = c.taus;
  m.z_ref_mm = spec.z_ref_mm;
  m.a = b.head(d.po);
  m.g = b.segment(d.po, d.ps);
  m.slope_intercept_um_per_1000 = b(d.po + d.ps);
  m.blank_tau_min = c.blank_tau;
  m.blank_um_per_1000_per_k = spec.blank_sensor.empty() ? 0.0 : b(d.po + d.ps + 1);
  m.prior_strength = c.strength;
  m.cv_rmse_um = cv;
  m.rows = static_cast<int>(d.x.rows());
  SetGreyBoxRanges(&m, record.day_logs);
  return m;
}

void SetGreyBoxRanges(GreyBoxModel* m, const std::vector<Run>& logs) {
  const auto per = static_cast<Eigen::Index>(1 + m->time_constants.size());
  const auto no = static_cast<Eigen::Index>(m->offset_sensors.size() + m->offset_duty.size()) * per;
  const auto ns = static_cast<Eigen::Index>(m->slope_sensors.size() + m->slope_duty.size()) * per;
  m->offset_min = m->offset_max = Eigen::VectorXd::Zero(no);
  m->slope_min = m->slope_max = Eigen::VectorXd::Zero(ns);
  m->blank_min_c = m->blank_max_c = 20;
  bool first = true;
  for (const Run& log : logs) {
    if (log.samples() == 0) continue;
    const Eigen::MatrixXd o =
        GreyChannelFeatures(log, m->offset_sensors, m->offset_duty, m->time_constants);
    const Eigen::MatrixXd s =
        GreyChannelFeatures(log, m->slope_sensors, m->slope_duty, m->time_constants);
    const Eigen::VectorXd omin = o.colwise().minCoeff(), omax = o.colwise().maxCoeff();
    const Eigen::VectorXd smin = s.colwise().minCoeff(), smax = s.colwise().maxCoeff();
    m->offset_min = first ? omin : m->offset_min.cwiseMin(omin);
    m->offset_max = first ? omax : m->offset_max.cwiseMax(omax);
    m->slope_min = first ? smin : m->slope_min.cwiseMin(smin);
    m->slope_max = first ? smax : m->slope_max.cwiseMax(smax);
    if (!m->blank_sensor.empty()) {
      const Eigen::VectorXd b =
          AbsoluteFeatures(log, {m->blank_sensor}, {m->blank_tau_min}).col(1).array() + 20.0;
      m->blank_min_c = first ? b.minCoeff() : std::min(m->blank_min_c, b.minCoeff());
      m->blank_max_c = first ? b.maxCoeff() : std::max(m->blank_max_c, b.maxCoeff());
    }
    first = false;
  }
}

std::vector<double> PredictGreyRecord(const GreyBoxModel& m, const ShopRecord& record,
                                      const MeasurementRecord& r) {
  const Run& log = record.day_logs.at(static_cast<std::size_t>(r.log));
  GreyBoxEvaluator ev(m);
  const Eigen::MatrixXd u = GreyBoxRawInputs(m, log);
  std::vector<GreyBoxEvaluator::Output> out;
  for (int k = 0; k < log.samples(); ++k)
    out.push_back(ev.Step(log.time_min[static_cast<std::size_t>(k)], u.row(k).transpose()));
  const bool lead = r.kind == MeasurementRecord::Kind::kLead && !r.rows.empty();
  const double blank =
      lead ? ev.BlankSlope(out[static_cast<std::size_t>(r.rows.front().sample)].blank_c) : 0.0;
  std::vector<double> v;
  for (const Measurement& x : r.rows) {
    const auto& o = out[static_cast<std::size_t>(x.sample)];
    v.push_back(o.k0_um + (o.slope_um_per_1000 + blank) * (m.z_ref_mm - x.z_mm) / 1000.0);
  }
  return v;
}

GreyBoxEvaluator::GreyBoxEvaluator(const GreyBoxModel& model) : model_(&model) {}

GreyBoxEvaluator::Output GreyBoxEvaluator::Step(double time_min, const Eigen::VectorXd& raw) {
  const GreyBoxModel& m = *model_;
  const auto nt = static_cast<Eigen::Index>(m.time_constants.size());
  const auto nos = static_cast<Eigen::Index>(m.offset_sensors.size());
  const auto nss = static_cast<Eigen::Index>(m.slope_sensors.size());
  const auto nod = static_cast<Eigen::Index>(m.offset_duty.size());
  const auto nsd = static_cast<Eigen::Index>(m.slope_duty.size());
  const Eigen::Index no = nos + nod, ns = nss + nsd, nb = m.blank_sensor.empty() ? 0 : 1;
  // Channel order [offset sensors | offset duty | slope sensors | slope duty]; raw order
  // [offset sensors | slope sensors | blank | offset duty | slope duty].
  auto raw_of = [&](Eigen::Index i) {
    if (i < nos) return raw(i) - 20.0;
    if (i < no) return raw(nos + nss + nb + (i - nos));
    if (i < no + nss) return raw(nos + (i - no)) - 20.0;
    return raw(nos + nss + nb + nod + (i - no - nss));
  };
  if (!started_) lag_ = Eigen::VectorXd::Zero((no + ns) * nt);
  Eigen::VectorXd phi((no + ns) * (1 + nt));
  for (Eigen::Index i = 0; i < no + ns; ++i) {
    const double u = raw_of(i);
    phi(i * (1 + nt)) = u;
    for (Eigen::Index l = 0; l < nt; ++l) {
      double& y = lag_(i * nt + l);
      const double tau = m.time_constants[static_cast<std::size_t>(l)];
      y = started_ ? y + (1.0 - std::exp(-(time_min - last_time_) / tau)) * (u - y) : u;
      phi(i * (1 + nt) + 1 + l) = y;
    }
  }
  if (!m.blank_sensor.empty()) {
    const double u = raw(nos + nss);
    blank_ = started_
                 ? blank_ + (1.0 - std::exp(-(time_min - last_time_) / m.blank_tau_min)) * (u - blank_)
                 : u;
  }
  started_ = true;
  last_time_ = time_min;
  const Eigen::Index po = no * (1 + nt);
  Output o;
  o.k0_um = phi.head(po).dot(m.a);
  o.slope_um_per_1000 = m.slope_intercept_um_per_1000 + phi.tail(ns * (1 + nt)).dot(m.g);
  o.blank_c = blank_;
  return o;
}

double GreyBoxEvaluator::BlankSlope(double latched_blank_c) const {
  return model_->blank_um_per_1000_per_k * (latched_blank_c - 20.0);
}

Eigen::MatrixXd GreyBoxRawInputs(const GreyBoxModel& m, const Run& run) {
  const std::vector<std::string> in = m.Inputs(), duty = m.DutyInputs();
  Eigen::MatrixXd u(run.samples(), static_cast<Eigen::Index>(in.size() + duty.size()));
  Eigen::Index c = 0;
  for (const std::string& s : in) u.col(c++) = run.temperature_C.col(run.SensorIndex(s));
  for (const std::string& s : duty) u.col(c++) = run.other.col(run.OtherIndex(s));
  return u;
}

}  // namespace whirl::drift
