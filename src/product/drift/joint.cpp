#include "drift/joint.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/error.h"
#include "drift/regression.h"

namespace whirl::drift {

namespace {

// The stacked design of every reading: X = [phi | psi] demeaned within each record (weighted),
// y demeaned the same way, the weights and the calendar day of each row.
struct Design {
  Eigen::MatrixXd x;
  Eigen::VectorXd y, w;
  std::vector<int> day;
  Eigen::MatrixXd phi;          ///< features before demeaning (rises since power-on)
  std::vector<bool> slope_row;  ///< the row's log has readings >= kSlopeSpanMm apart along z
  double coverage = 0.5;        ///< JointFitOptions::slope_coverage
};

// Readings this far apart along Z on one day log (or in one record) see the slope.
constexpr double kSlopeSpanMm = 1000;

// Per day log: whether its readings span at least kSlopeSpanMm along Z.
std::vector<bool> SlopeLogs(const ShopRecord& rec) {
  std::vector<double> lo(rec.day_logs.size(), 1e300), hi(rec.day_logs.size(), -1e300);
  for (const auto& r : rec.records)
    for (const Measurement& m : r.rows) {
      const auto l = static_cast<std::size_t>(r.log);
      lo[l] = std::min(lo[l], m.z_mm);
      hi[l] = std::max(hi[l], m.z_mm);
    }
  std::vector<bool> out(rec.day_logs.size());
  for (std::size_t l = 0; l < out.size(); ++l) out[l] = hi[l] - lo[l] >= kSlopeSpanMm;
  return out;
}

struct ChosenInputs {
  std::vector<std::string> sensors, others;
  std::vector<double> taus;
};

Design BuildDesign(const ShopRecord& rec, const ChosenInputs& in, double z_ref_mm,
                   double coverage) {
  const std::vector<bool> slope_logs = SlopeLogs(rec);
  std::vector<Eigen::MatrixXd> phi(rec.day_logs.size());
  std::size_t n = 0;
  for (const auto& r : rec.records) {
    const auto l = static_cast<std::size_t>(r.log);
    if (phi[l].size() == 0) {
      phi[l] = BuildFeatures(rec.day_logs[l], in.sensors, in.others, in.taus);
      // A control signal enters through its lags only (a warm-up clock is 1 - exp(-t / tau),
      // not the power-on step itself): its static column would fit each record's first
      // reading and, in the slope part, a z-linear term no lag supports.
      const std::size_t per = 1 + in.taus.size();
      if (!in.taus.empty())
        for (std::size_t i = 0; i < in.others.size(); ++i)
          phi[l].col(static_cast<Eigen::Index>((in.sensors.size() + i) * per)).setZero();
    }
    n += r.rows.size();
  }
  const Eigen::Index p = static_cast<Eigen::Index>(
      (in.sensors.size() + in.others.size()) * (1 + in.taus.size()));
  Design d;
  d.coverage = coverage;
  d.x.resize(static_cast<Eigen::Index>(n), 2 * p);
  d.phi.resize(static_cast<Eigen::Index>(n), p);
  d.y.resize(static_cast<Eigen::Index>(n));
  d.w.resize(static_cast<Eigen::Index>(n));
  Eigen::Index row = 0;
  for (const auto& r : rec.records) {
    const Eigen::Index begin = row;
    const Eigen::MatrixXd& f = phi[static_cast<std::size_t>(r.log)];
    for (const Measurement& m : r.rows) {
      const Eigen::RowVectorXd ph = f.row(m.sample);
      d.x.row(row) << ph, ph * ((z_ref_mm - m.z_mm) / 1000.0);
      d.phi.row(row) = ph;
      d.slope_row.push_back(slope_logs[static_cast<std::size_t>(r.log)]);
      d.y(row) = m.value_um;
      d.w(row) = 1.0 / (m.sigma_um * m.sigma_um);
      d.day.push_back(r.day);
      ++row;
    }
    const Eigen::Index len = row - begin;
    if (len == 0) continue;
    const auto wr = d.w.segment(begin, len);
    const double sw = wr.sum();
    const Eigen::RowVectorXd mx = (d.x.middleRows(begin, len).array().colwise() * wr.array())
                                      .colwise()
                                      .sum() / sw;
    d.x.middleRows(begin, len).rowwise() -= mx;
    d.y.segment(begin, len).array() -= wr.dot(d.y.segment(begin, len)) / sw;
  }
  return d;
}

// Columns of X the weighted solve can estimate (rows with w > 0): every phi column with spread,
// and a psi column only when (i) its part outside the span of the phi columns is not negligible
// and (ii) the rows that see the slope (day logs with readings >= kSlopeSpanMm apart along Z)
// cover the feature's range: max |phi_j| over those rows >= coverage x max |phi_j| over all rows.
// Without (ii) a slope learned on idle laser tests, where a sensor barely moves, is applied to
// the rises that sensor takes while cutting: an extrapolation no reading supports.
std::vector<bool> Identified(const Design& d, const Eigen::VectorXd& w) {
  const Eigen::MatrixXd& x = d.x;
  const Eigen::Index p = x.cols() / 2;
  const Eigen::VectorXd sw = w.array().sqrt();
  const Eigen::MatrixXd xw = x.array().colwise() * sw.array();
  std::vector<bool> ok(static_cast<std::size_t>(x.cols()), false);
  for (Eigen::Index j = 0; j < x.cols(); ++j) ok[j] = xw.col(j).norm() > 1e-12;
  if (p == 0) return ok;
  const Eigen::MatrixXd a = xw.leftCols(p);
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(a);
  for (Eigen::Index j = 0; j < p; ++j) {
    const Eigen::VectorXd gj = xw.col(p + j);
    const double norm = gj.norm();
    ok[static_cast<std::size_t>(p + j)] = false;
    if (norm <= 1e-12) continue;
    double all = 0, seen = 0;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      if (!(w(i) > 0)) continue;
      const double v = std::abs(d.phi(i, j));
      all = std::max(all, v);
      if (d.slope_row[static_cast<std::size_t>(i)]) seen = std::max(seen, v);
    }
    if (seen < d.coverage * all) continue;
    const Eigen::VectorXd resid = gj - a * cod.solve(gj);
    ok[static_cast<std::size_t>(p + j)] = resid.norm() > 1e-6 * norm;
  }
  return ok;
}

// Weighted ridge least squares on the standardized kept columns; coefficients (0 for dropped
// columns) and, optionally, their covariance (X'WX + ridge)^-1 in the original units.
Eigen::VectorXd Solve(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                      const Eigen::VectorXd& w, const std::vector<bool>& keep,
                      Eigen::MatrixXd* covariance = nullptr) {
  std::vector<Eigen::Index> cols;
  for (Eigen::Index j = 0; j < x.cols(); ++j)
    if (keep[static_cast<std::size_t>(j)]) cols.push_back(j);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(x.cols());
  if (covariance) *covariance = Eigen::MatrixXd::Zero(x.cols(), x.cols());
  if (cols.empty() || w.sum() <= 0) return b;
  const auto k = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd xs(x.rows(), k);
  Eigen::VectorXd scale(k);
  for (Eigen::Index c = 0; c < k; ++c) {
    const Eigen::VectorXd col = x.col(cols[static_cast<std::size_t>(c)]);
    scale(c) = std::sqrt(w.dot(col.cwiseProduct(col)) / w.sum());
    if (!(scale(c) > 0)) scale(c) = 1.0;
    xs.col(c) = col / scale(c);
  }
  Eigen::MatrixXd a = xs.transpose() * w.asDiagonal() * xs;
  const double ridge = 1e-8 * a.trace() / static_cast<double>(k);
  a.diagonal().array() += std::max(ridge, 1e-300);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
  const Eigen::VectorXd bs = ldlt.solve(xs.transpose() * w.asDiagonal() * y);
  for (Eigen::Index c = 0; c < k; ++c) b(cols[static_cast<std::size_t>(c)]) = bs(c) / scale(c);
  if (covariance) {
    const Eigen::MatrixXd inv = ldlt.solve(Eigen::MatrixXd::Identity(k, k));
    for (Eigen::Index r = 0; r < k; ++r)
      for (Eigen::Index c = 0; c < k; ++c)
        (*covariance)(cols[r], cols[c]) = inv(r, c) / (scale(r) * scale(c));
  }
  return b;
}

// Leave one calendar day out: the weighted RMS of the held-out rows' residuals, um. With a single
// day, the training RMS (no hold-out possible).
double GroupedCvRmse(const Design& d) {
  std::set<int> days(d.day.begin(), d.day.end());
  double num = 0, den = 0;
  const auto n = d.x.rows();
  if (days.size() < 2) {
    const Eigen::VectorXd b = Solve(d.x, d.y, d.w, Identified(d, d.w));
    const Eigen::VectorXd r = d.y - d.x * b;
    return std::sqrt(d.w.dot(r.cwiseProduct(r)) / d.w.sum());
  }
  for (int day : days) {
    Eigen::VectorXd wt = d.w;
    for (Eigen::Index i = 0; i < n; ++i)
      if (d.day[static_cast<std::size_t>(i)] == day) wt(i) = 0;
    const Eigen::VectorXd b = Solve(d.x, d.y, wt, Identified(d, wt));
    for (Eigen::Index i = 0; i < n; ++i) {
      if (d.day[static_cast<std::size_t>(i)] != day) continue;
      const double r = d.y(i) - d.x.row(i).dot(b);
      num += d.w(i) * r * r;
      den += d.w(i);
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

double Score(const ShopRecord& rec, const ChosenInputs& in, double z_ref, double coverage) {
  return GroupedCvRmse(BuildDesign(rec, in, z_ref, coverage));
}

// Greedy forward choice of sensors from the pool (static features), while the CV RMSE falls by
// more than 1 %.
void ChooseSensors(const ShopRecord& rec, const JointSpec& spec, const JointFitOptions& o,
                   ChosenInputs* in, JointFitReport* report) {
  double current = Score(rec, *in, spec.z_ref_mm, o.slope_coverage);
  while (static_cast<int>(in->sensors.size()) < o.max_sensors) {
    double best = current;
    std::string pick;
    for (const auto& s : spec.sensor_pool) {
      if (std::find(in->sensors.begin(), in->sensors.end(), s) != in->sensors.end()) continue;
      ChosenInputs trial = *in;
      trial.sensors.push_back(s);
      const double e = Score(rec, trial, spec.z_ref_mm, o.slope_coverage);
      if (e < best) best = e, pick = s;
    }
    if (pick.empty() || !(best < 0.99 * current)) break;
    in->sensors.push_back(pick);
    current = best;
    report->search.push_back({"sensor " + pick, best});
  }
}

// Greedy forward choice of time constants, while the CV RMSE falls (the first one always when
// a lag is required).
void ChooseLags(const ShopRecord& rec, const JointSpec& spec, const JointFitOptions& o,
                ChosenInputs* in, JointFitReport* report) {
  double current = Score(rec, *in, spec.z_ref_mm, o.slope_coverage);
  while (static_cast<int>(in->taus.size()) < o.max_lags) {
    double best = 1e300, pick = 0;
    for (double tau : o.tau_grid) {
      if (std::find(in->taus.begin(), in->taus.end(), tau) != in->taus.end()) continue;
      ChosenInputs trial = *in;
      trial.taus.push_back(tau);
      std::sort(trial.taus.begin(), trial.taus.end());
      const double e = Score(rec, trial, spec.z_ref_mm, o.slope_coverage);
      if (e < best) best = e, pick = tau;
    }
    const bool forced = o.require_lag && in->taus.empty();
    if (pick <= 0 || (!forced && !(best < current))) break;
    in->taus.push_back(pick);
    std::sort(in->taus.begin(), in->taus.end());
    current = best;
    report->search.push_back({"lag " + std::to_string(pick) + " min", best});
  }
}

}  // namespace

JointFitReport FitJoint(const ShopRecord& record, const JointSpec& spec,
                        const JointFitOptions& options) {
  record.Validate();
  if (options.max_lags < 0 || options.max_lags > 4)
    throw InputError("max_lags = " + std::to_string(options.max_lags) + ": must be within 0..4");
  JointFitReport report;
  ChosenInputs in{spec.sensors, spec.other_inputs, spec.time_constants};
  std::sort(in.taus.begin(), in.taus.end());
  if (!spec.sensor_pool.empty()) ChooseSensors(record, spec, options, &in, &report);
  if (in.sensors.empty() && in.others.empty())
    throw InputError("joint drift fit: no input (no sensor given or chosen, no control signal)");
  ChooseLags(record, spec, options, &in, &report);
  const Design d = BuildDesign(record, in, spec.z_ref_mm, options.slope_coverage);
  if (d.x.rows() <= d.x.cols() / 2)
    throw InputError("joint drift fit: " + std::to_string(d.x.rows()) +
                     " readings for " + std::to_string(d.x.cols() / 2) + " features");
  JointDriftModel& m = report.model;
  m.sensors = in.sensors;
  m.other_inputs = in.others;
  m.time_constants = in.taus;
  m.z_ref_mm = spec.z_ref_mm;
  const std::vector<bool> keep = Identified(d, d.w);
  const Eigen::VectorXd b = Solve(d.x, d.y, d.w, keep, &m.covariance);
  const Eigen::Index p = d.x.cols() / 2;
  m.a = b.head(p);
  m.g = b.tail(p);
  for (Eigen::Index j = 0; j < p; ++j) m.slope_identified.push_back(keep[p + j]);
  if (std::none_of(m.slope_identified.begin(), m.slope_identified.end(), [](bool v) { return v; }))
    report.notes.push_back("no record identifies a slope (every reading at one axis position?): "
                           "the slope channel is 0");
  m.cv_rmse_um = GroupedCvRmse(d);
  m.rows = static_cast<int>(d.x.rows());
  return report;
}

std::vector<double> PredictRecord(const JointDriftModel& m, const ShopRecord& record,
                                  const MeasurementRecord& r) {
  const Eigen::MatrixXd f = BuildFeatures(record.day_logs.at(static_cast<std::size_t>(r.log)),
                                          m.sensors, m.other_inputs, m.time_constants);
  std::vector<double> out;
  for (const Measurement& x : r.rows)
    out.push_back(f.row(x.sample).dot(m.a) +
                  f.row(x.sample).dot(m.g) * (m.z_ref_mm - x.z_mm) / 1000.0);
  return out;
}

JointEvaluator::JointEvaluator(const JointDriftModel& model) : model_(&model) {}

JointEvaluator::Output JointEvaluator::Step(double time_min, const Eigen::VectorXd& raw) {
  const JointDriftModel& m = *model_;
  const auto ns = static_cast<Eigen::Index>(m.sensors.size());
  const auto ni = ns + static_cast<Eigen::Index>(m.other_inputs.size());
  const auto per = 1 + static_cast<Eigen::Index>(m.time_constants.size());
  if (!started_) {
    reference_ = raw.head(ns);
    lag_ = Eigen::VectorXd::Zero(ni * per);
  }
  Eigen::VectorXd phi(ni * per);
  for (Eigen::Index i = 0; i < ni; ++i) {
    const double u = i < ns ? raw(i) - reference_(i) : raw(i);
    phi(i * per) = u;
    for (std::size_t l = 0; l < m.time_constants.size(); ++l) {
      double& y = lag_(i * per + 1 + static_cast<Eigen::Index>(l));
      y = started_ ? y + (1.0 - std::exp(-(time_min - last_time_) / m.time_constants[l])) * (u - y)
                   : u;
      phi(i * per + 1 + static_cast<Eigen::Index>(l)) = y;
    }
  }
  started_ = true;
  last_time_ = time_min;
  return {phi.dot(m.a), phi.dot(m.g)};
}

Eigen::MatrixXd JointRawInputs(const JointDriftModel& m, const Run& run) {
  Eigen::MatrixXd u(run.samples(),
                    static_cast<Eigen::Index>(m.sensors.size() + m.other_inputs.size()));
  Eigen::Index c = 0;
  for (const auto& s : m.sensors) u.col(c++) = run.temperature_C.col(run.SensorIndex(s));
  for (const auto& o : m.other_inputs) u.col(c++) = run.other.col(run.OtherIndex(o));
  return u;
}

std::pair<DriftModel, DriftModel> ToDriftModels(const JointDriftModel& m) {
  auto make = [&m](const Eigen::VectorXd& coef, Eigen::Index offset, const char* column) {
    DriftModel d;
    d.kind = ModelKind::kDynamic;
    d.error_column = column;
    d.sensors = m.sensors;
    d.reference_C = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.sensors.size()));
    d.extra_inputs = m.other_inputs;
    d.time_constants = m.time_constants;
    std::vector<std::string> inputs = m.sensors;
    inputs.insert(inputs.end(), m.other_inputs.begin(), m.other_inputs.end());
    for (const auto& in : inputs) {
      d.features.push_back({in, 0.0});
      for (double t : m.time_constants) d.features.push_back({in, t});
    }
    const Eigen::Index p = coef.size();
    d.feature_min = Eigen::VectorXd::Constant(p, -1e9);
    d.feature_max = Eigen::VectorXd::Constant(p, 1e9);
    d.linear.coefficients = Eigen::VectorXd::Zero(p + 1);
    d.linear.coefficients.tail(p) = coef;
    d.linear.covariance = Eigen::MatrixXd::Zero(p + 1, p + 1);
    if (m.covariance.rows() == 2 * p)
      d.linear.covariance.bottomRightCorner(p, p) = m.covariance.block(offset, offset, p, p);
    d.linear.xtx_inverse = d.linear.covariance;
    d.linear.standard_errors = d.linear.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    d.selection = "joint fit from shop measurements (drift/joint.h)";
    return d;
  };
  return {make(m.a, 0, "k0_um"), make(m.g, m.a.size(), "slope_per_1000_um")};
}

}  // namespace whirl::drift
