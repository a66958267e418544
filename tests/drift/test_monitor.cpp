// On-line check and recalibration (Liu et al.'s patent): the replayed prediction equals the batch
// prediction, a planted change of coefficients is flagged by the next check and recovered within
// the noise, the false-alarm rate of a stationary run at 3 and 1 sigma matches the normal tails,
// the Bayesian update with a very weak prior equals the patent's least-squares refit, a strong
// prior keeps the coefficients, the offset rule recovers a planted offset, bad input is refused.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <functional>
#include <cmath>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/random.h"
#include "drift/fit.h"
#include "drift/monitor.h"
#include "drift/monitor_report.h"
#include "core/numbers.h"
#include "support/rfc4180.h"

namespace whirl::drift {
namespace {

// Latent rises [K] at minute t, far from collinear with each other and with a constant over any
// window of an hour or more (a slow first-order rise, a rise and cool-down, an oscillation).
double Latent(int k, double t) {
  switch (k) {
    case 0:
      return 8.0 * (1.0 - std::exp(-t / 200.0));
    case 1:
      return t < 300 ? t / 50.0 : 6.0 - (t - 300) / 60.0;
    default:
      return 3.0 * std::sin(t / 40.0) + 0.01 * t;
  }
}

// Three sensors with these latent shapes (rises exactly Latent(k, t), no sensor noise),
// one sample per minute; error = c + w . Latent + N(0, sigma), with w -> w_after and c -> c_after
// from minute change_min on.
struct Planted {
  Eigen::Vector3d w{1.0, 0.5, -1.0}, w_after{1.0, 0.5, -1.0};
  double c = 0.5, c_after = 0.5, sigma = 0.2, change_min = 1e9;
  int samples = 600;
};

Run MakeRun(const Planted& p, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Run r;
  r.name = r.source = "planted_change";
  r.sensor_names = {"a_C", "b_C", "c_C"};
  r.error_names = {"e_um"};
  r.temperature_C.resize(p.samples, 3);
  r.error_um.resize(p.samples, 1);
  r.other.resize(p.samples, 0);
  for (int q = 0; q < p.samples; ++q) {
    const double t = q;
    r.time_min.push_back(t);
    r.line_numbers.push_back(q + 2);
    const bool after = t >= p.change_min;
    double e = after ? p.c_after : p.c;
    for (int k = 0; k < 3; ++k) {
      r.temperature_C(q, k) = 20.0 + Latent(k, t);
      e += (after ? p.w_after : p.w)(k)*Latent(k, t);
    }
    r.error_um(q, 0) = e + p.sigma * n01(rng);
  }
  return r;
}

// The planted runs share one gauge (level c, never re-referenced): the fixed zero at 0, so no
// run's zero carries the noise of its first row.
DriftModel FitOn(const Run& run) {
  FitOptions f;
  f.zero = {ErrorZero::kFixed, 0.0};
  f.sensors = {"a_C", "b_C", "c_C"};
  return FitDriftModel({run}, "e_um", f).model;
}

const StrategyResult& Rule(const MonitorResult& r, UpdateRule u) {
  for (const auto& s : r.strategies)
    if (s.rule == u) return s;
  throw std::runtime_error("rule not replayed");
}

TEST(Monitor, StaticReplayEqualsBatchPrediction) {
  Planted p;
  const drift::Run run = MakeRun(p, 1);
  const DriftModel m = FitOn(run.Slice(0, 300, "train"));
  const MonitorResult r = MonitorRun(m, run, {});
  const RunPrediction batch = PredictRun(m, run);
  EXPECT_LT((Rule(r, UpdateRule::kStatic).predicted_um - batch.predicted_um).cwiseAbs().maxCoeff(),
            1e-9);
  // No change, no noise beyond the model's: the rules keep the static prediction until a check
  // fails, and the checks fall every check_every minutes from the start.
  const auto& patent = Rule(r, UpdateRule::kPatent);
  ASSERT_GE(patent.events.size(), 2u);
  EXPECT_EQ(patent.events[0].sample, 120);  // the default interval, 120 min
  EXPECT_EQ(patent.stop_min, patent.measurements * 1.0);
}

// Standard errors of least squares on the design rows of the measurements (sigma known).
Eigen::VectorXd StandardErrors(const Eigen::MatrixXd& x, double sigma) {
  const Eigen::MatrixXd xtx = x.transpose() * x;
  return (sigma * sigma * xtx.ldlt().solve(Eigen::MatrixXd::Identity(x.cols(), x.cols())))
      .diagonal()
      .cwiseSqrt();
}

TEST(Monitor, PlantedChangeIsFlaggedByTheNextCheckAndRecovered) {
  Planted p;
  p.change_min = 200;
  p.w_after = {1.6, 0.1, -0.4};
  p.c_after = -1.0;
  const drift::Run run = MakeRun(p, 7);
  const DriftModel m = FitOn(run.Slice(0, 200, "train"));
  MonitorOptions o;
  o.check_every = 60;
  o.refit_samples = 12;
  o.refit_every = 20;
  o.threshold_sigma = 3;
  // Bayes with the training posterior itself as the prior (scale 1) stays near the old
  // coefficients by design; with a weak prior it must recover the new ones like the refit.
  o.prior_scale = 1e4;
  const MonitorResult r = MonitorRun(m, run, o);
  Eigen::Vector4d truth;
  truth << p.c_after, p.w_after;
  const Eigen::MatrixXd x = MonitorDesign(m, run, ReferenceMode::kRunStart);
  for (UpdateRule u : {UpdateRule::kPatent, UpdateRule::kBayes}) {
    SCOPED_TRACE(ToString(u));
    const auto& s = Rule(r, u);
    // Checks at 60, 120, 180 are before the change and pass; the one at 240 flags the model.
    std::vector<const MonitorEvent*> checks;
    for (const auto& e : s.events)
      if (e.kind == MonitorEvent::Kind::kCheck) checks.push_back(&e);
    ASSERT_GE(checks.size(), 4u);
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(checks[static_cast<std::size_t>(i)]->valid) << i;
    EXPECT_EQ(checks[3]->sample, 240);
    EXPECT_FALSE(checks[3]->valid) << checks[3]->message;
    // The first update: coefficients within 4 standard errors of the planted ones.
    std::vector<int> rows;
    const MonitorEvent* update = nullptr;
    for (const auto& e : s.events) {
      if (e.sample >= 240 && e.kind != MonitorEvent::Kind::kUpdate && !update)
        rows.push_back(e.sample);
      if (e.kind == MonitorEvent::Kind::kUpdate && !update) update = &e;
    }
    ASSERT_NE(update, nullptr);
    ASSERT_EQ(rows.size(), 13u);
    Eigen::MatrixXd xs(13, 4);
    for (int j = 0; j < 13; ++j) xs.row(j) = x.row(rows[static_cast<std::size_t>(j)]);
    const Eigen::VectorXd se = StandardErrors(xs, p.sigma);
    for (int i = 0; i < 4; ++i)
      EXPECT_LT(std::abs(update->coefficients(i) - truth(i)), 4 * se(i) + 1e-9)
          << "coefficient " << i << " " << update->coefficients.transpose() << " truth "
          << truth.transpose() << " se " << se.transpose();
    // Better than the static model after the change.
    EXPECT_LT(s.score.rmse_um, Rule(r, UpdateRule::kStatic).score.rmse_um);
  }
}

TEST(Monitor, FalseAlarmRateOfAStationaryRunMatchesTheNormalTail) {
  // Train on one run, monitor another of the same process: the check residual is N(0, s^2)
  // plus the small estimation variance, so P(|z| > 3) = 0.27 % and P(|z| > 1) = 31.7 %.
  Planted p;
  int checks3 = 0, alarms3 = 0, checks1 = 0, alarms1 = 0;
  for (unsigned seed = 0; seed < 120; ++seed) {
    const DriftModel m = FitOn(MakeRun(p, 10000 + seed));
    const drift::Run run = MakeRun(p, seed);
    MonitorOptions o;
    o.check_every = 20;
    o.refit_samples = 3;
    o.rules = {UpdateRule::kOffset};
    o.threshold_sigma = 3;
    const MonitorResult r3 = MonitorRun(m, run, o);
    const auto& s3 = Rule(r3, UpdateRule::kOffset);
    o.threshold_sigma = 1;
    o.refit_samples = 1;
    // At 1 sigma the rule recalibrates often; count only the first check of each replay and the
    // checks before the first recalibration, whose residuals are those of the trained model.
    const MonitorResult r1 = MonitorRun(m, run, o);
    const auto& s1 = Rule(r1, UpdateRule::kOffset);
    checks3 += s3.checks;
    alarms3 += s3.invalid_checks;
    for (const auto& e : s1.events) {
      if (e.kind == MonitorEvent::Kind::kUpdate) break;
      if (e.kind != MonitorEvent::Kind::kCheck) continue;
      ++checks1;
      alarms1 += e.valid ? 0 : 1;
    }
  }
  const double rate3 = static_cast<double>(alarms3) / checks3;
  const double rate1 = static_cast<double>(alarms1) / checks1;
  RecordProperty("false_alarm_rate_3sigma", std::to_string(rate3));
  std::printf("false-alarm rate: 3 sigma %d of %d checks (%.3f %%), 1 sigma %d of %d (%.1f %%)\n",
              alarms3, checks3, 100 * rate3, alarms1, checks1, 100 * rate1);
  ASSERT_GT(checks3, 3000);
  EXPECT_LT(rate3, 0.008);  // 0.27 % expected; 0.8 % is 5 binomial standard deviations above
  EXPECT_NEAR(rate1, 0.317, 0.06);
}

TEST(Monitor, BayesWithAVeryWeakPriorEqualsThePatentRefit) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 6 + trial % 5, q = 4;
    Eigen::MatrixXd x(n, q);
    for (int i = 0; i < n; ++i) {
      x(i, 0) = 1;
      for (int j = 1; j < q; ++j) x(i, j) = 3 * n01(rng);
    }
    Eigen::VectorXd y(n), b(q);
    for (int i = 0; i < n; ++i) y(i) = 5 * n01(rng);
    for (int j = 0; j < q; ++j) b(j) = n01(rng);
    Eigen::MatrixXd a(q, q);
    for (int i = 0; i < a.size(); ++i) a.data()[i] = n01(rng);
    Eigen::MatrixXd prior = 1e9 * (a * a.transpose() + Eigen::MatrixXd::Identity(q, q));
    const Eigen::VectorXd ls = PatentRefit(x, y, b);
    const Eigen::VectorXd bayes = BayesUpdate(x, y, b, &prior, 0.04);
    EXPECT_LT((bayes - ls).cwiseAbs().maxCoeff(), 1e-5 * (1 + ls.cwiseAbs().maxCoeff()))
        << bayes.transpose() << " vs " << ls.transpose();
    // The normal equations hold for the patent's refit.
    EXPECT_LT((x.transpose() * (y - x * ls)).cwiseAbs().maxCoeff(), 1e-8 * y.norm() * x.norm());
  }
  // Through the replay: the same measurements, the same coefficients after the first update.
  Planted p;
  p.change_min = 200;
  p.w_after = {1.6, 0.1, -0.4};
  const drift::Run run = MakeRun(p, 3);
  MonitorOptions o;
  o.refit_samples = 8;
  o.refit_every = 20;
  o.prior_scale = 1e10;
  const MonitorResult r = MonitorRun(FitOn(run.Slice(0, 200, "train")), run, o);
  const MonitorEvent* up[2] = {nullptr, nullptr};
  for (int i = 0; i < 2; ++i)
    for (const auto& e : Rule(r, i ? UpdateRule::kBayes : UpdateRule::kPatent).events)
      if (e.kind == MonitorEvent::Kind::kUpdate && !up[i]) up[i] = &e;
  ASSERT_TRUE(up[0] && up[1]);
  EXPECT_EQ(up[0]->sample, up[1]->sample);
  // The rank-aware patent equals the full refit when the measurements identify every direction.
  if (up[0]->message.find("4 of 4 directions") != std::string::npos) {
    EXPECT_LT((up[0]->coefficients - up[1]->coefficients).cwiseAbs().maxCoeff(), 1e-4);
  }
}

TEST(Monitor, BayesWithAStrongPriorKeepsTheCoefficientsAndShrinksItsCovariance) {
  Eigen::MatrixXd x(3, 2);
  x << 1, 0.5, 1, 1.0, 1, 2.0;
  const Eigen::Vector3d y(10, 11, 12);
  const Eigen::Vector2d b(1, 2);
  Eigen::MatrixXd p = 1e-10 * Eigen::MatrixXd::Identity(2, 2);
  EXPECT_LT((BayesUpdate(x, y, b, &p, 1.0) - b).cwiseAbs().maxCoeff(), 1e-8);
  // One observation, scalar case by hand: P = 1, r = 1, x = 1: b+ = b + (y - b) / 2, P+ = 1/2.
  Eigen::MatrixXd p1 = Eigen::MatrixXd::Ones(1, 1);
  const Eigen::VectorXd b1 =
      BayesUpdate(Eigen::MatrixXd::Ones(1, 1), Eigen::VectorXd::Constant(1, 4.0),
                  Eigen::VectorXd::Constant(1, 2.0), &p1, 1.0);
  EXPECT_NEAR(b1(0), 3.0, 1e-12);
  EXPECT_NEAR(p1(0, 0), 0.5, 1e-12);
}

TEST(Monitor, OffsetRuleRecoversAPlantedOffset) {
  Planted p;
  p.change_min = 200;
  p.c_after = p.c + 4.0;
  const drift::Run run = MakeRun(p, 11);
  MonitorOptions o;
  o.rules = {UpdateRule::kOffset};
  o.refit_samples = 15;
  o.refit_every = 2;
  const DriftModel m = FitOn(run.Slice(0, 200, "train"));
  const MonitorResult r = MonitorRun(m, run, o);
  const auto& s = Rule(r, UpdateRule::kOffset);
  ASSERT_GE(s.recalibrations, 1);
  const double shift = s.final_coefficients(0) - m.linear.coefficients(0);
  // 16 measurements: the mean's std is sigma / 4 = 0.05 um; add the fit's own intercept error.
  EXPECT_NEAR(shift, 4.0, 4 * (p.sigma / 4 + m.linear.standard_errors(0)));
  EXPECT_LT((s.final_coefficients.tail(3) - m.linear.coefficients.tail(3)).norm(), 1e-12);
}

// The check bar's noise is the project's own normal stream (core/random.h: the same draws on
// every standard library), one draw per sample times noise_um.
TEST(Monitor, CheckBarNoiseIsOneDrawPerSampleOfTheProjectsNormalStream) {
  Planted p;
  const drift::Run run = MakeRun(p, 3);
  const DriftModel m = FitOn(run.Slice(0, 300, "train"));
  MonitorOptions o;
  o.noise_um = 0.5;
  o.seed = 42;
  const MonitorResult r = MonitorRun(m, run, o);
  ASSERT_EQ(r.measurement_noise_um.size(), run.samples());
  Rng rng(42);
  for (int k = 0; k < run.samples(); ++k)
    ASSERT_EQ(r.measurement_noise_um(k), 0.5 * rng.Normal()) << "sample " << k;
}

TEST(Monitor, RefusesBadInput) {
  Planted p;
  const drift::Run run = MakeRun(p, 1);
  const DriftModel m = FitOn(run.Slice(0, 300, "train"));
  MonitorOptions o;
  o.check_every = -1;
  try {
    MonitorRun(m, run, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("check_every = -1"), std::string::npos) << e.what();
  }
  o = {};
  o.start = 1e6;
  EXPECT_THROW(MonitorRun(m, run, o), InputError);
  o = {};
  o.score_from = 0.8;
  o.score_to = 0.6;
  EXPECT_THROW(MonitorRun(m, run, o), InputError);
  DriftModel net = m;
  net.kind = ModelKind::kNetwork;
  EXPECT_THROW(MonitorDesign(net, run, ReferenceMode::kRunStart), InputError);
  drift::Run no_error = run;
  no_error.error_names = {"other_um"};
  EXPECT_THROW(MonitorRun(m, no_error, {}), InputError);
  EXPECT_THROW(ParseUpdateRule("kalman"), InputError);
}

// The closed-form bound of one update from b with prior covariance P and observation variance r:
// |z'(b+ - b)| <= sqrt(z' P z) |y - X b| / sqrt(r) for every z (b+ minimises the posterior energy,
// Bishop, "Pattern Recognition and Machine Learning", eqs. 3.50-3.51). Written for any rule, so the
// same check run on the patent's change shows that it has no such bound.
double WorstBoundRatio(const std::function<Eigen::VectorXd(const Eigen::MatrixXd&,
                                                           const Eigen::VectorXd&,
                                                           const Eigen::VectorXd&,
                                                           Eigen::MatrixXd*, double)>& rule,
                       unsigned seed, int cases) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_int_distribution<int> qd(2, 6), nd(1, 8);
  double worst = 0;
  for (int c = 0; c < cases; ++c) {
    const int q = qd(rng), n = nd(rng);
    Eigen::MatrixXd x(n, q);
    for (int i = 0; i < n; ++i) {
      x(i, 0) = 1;
      for (int j = 1; j < q; ++j) x(i, j) = (c % 2 ? 1e-3 * n01(rng) + 1.0 : 3 * n01(rng));
    }
    Eigen::VectorXd y(n), b(q);
    for (int i = 0; i < n; ++i) y(i) = 10 * n01(rng);
    for (int j = 0; j < q; ++j) b(j) = n01(rng);
    Eigen::MatrixXd a(q, q);
    for (int i = 0; i < a.size(); ++i) a.data()[i] = n01(rng);
    const double scale = std::pow(10.0, -4 + 8 * (c % 9) / 8.0);
    const Eigen::MatrixXd p0 = scale * (a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(q, q));
    Eigen::MatrixXd p = p0;
    const double r = 0.04;
    const Eigen::VectorXd change = rule(x, y, b, &p, r) - b;
    const double misfit = (y - x * b).norm() / std::sqrt(r);
    for (int k = 0; k < 20; ++k) {
      Eigen::VectorXd z(q);
      for (int j = 0; j < q; ++j) z(j) = n01(rng);
      const double bound = std::sqrt(z.dot(p0 * z)) * misfit;
      worst = std::max(worst, std::abs(z.dot(change)) / bound);
    }
  }
  return worst;
}

TEST(MonitorProperty, BayesUpdateIsBoundedByPriorAndMisfit) {
  const auto bayes = [](const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                        const Eigen::VectorXd& b, Eigen::MatrixXd* p, double r) {
    return BayesUpdate(x, y, b, p, r);
  };
  EXPECT_LE(WorstBoundRatio(bayes, 1, 2000), 1.0 + 1e-9);
  // The check discriminates: the patent's change (no prior) breaks the bound.
  const auto patent = [](const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                         const Eigen::VectorXd& b, Eigen::MatrixXd*, double) {
    return PatentRefit(x, y, b);
  };
  EXPECT_GT(WorstBoundRatio(patent, 1, 2000), 1.0);
}

// Fewer measurements than coefficients: the rank-aware patent changes nothing in the null space
// of the (unit-scaled) rows, fits the misfit where it changes, and states the rank.
TEST(MonitorProperty, RankAwarePatentKeepsTheNullSpace) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int c = 0; c < 200; ++c) {
    const int q = 4 + c % 3, n = 1 + c % (q - 1);
    Eigen::MatrixXd x(n, q);
    for (int i = 0; i < n; ++i) {
      x(i, 0) = 1;
      for (int j = 1; j < q; ++j) x(i, j) = 5 * n01(rng);
    }
    Eigen::VectorXd y(n), b(q);
    for (int i = 0; i < n; ++i) y(i) = 10 * n01(rng);
    for (int j = 0; j < q; ++j) b(j) = n01(rng);
    int rank = -1;
    const Eigen::VectorXd after = PatentRefit(x, y, b, &rank);
    EXPECT_GE(rank, 1);
    EXPECT_LE(rank, n);
    Eigen::VectorXd scale = x.colwise().norm().transpose();
    const Eigen::MatrixXd xs = x * scale.cwiseInverse().asDiagonal();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(xs, Eigen::ComputeFullV);
    const Eigen::VectorXd change_scaled = scale.asDiagonal() * (after - b);
    const Eigen::MatrixXd null = svd.matrixV().rightCols(q - n);
    EXPECT_LE((null.transpose() * change_scaled).norm(), 1e-9 * (1 + change_scaled.norm()));
    if (rank == n) {
      EXPECT_LT((y - x * after).norm(), 1e-8 * (1 + y.norm()));
    }
  }
  // Through the replay: the update event states the rank.
  Planted p;
  p.change_min = 200;
  p.w_after = {1.6, 0.1, -0.4};
  const drift::Run run = MakeRun(p, 3);
  MonitorOptions o;
  o.check_every = 60;
  o.refit_samples = 1;
  const MonitorResult r = MonitorRun(FitOn(run.Slice(0, 200, "train")), run, o);
  bool stated = false;
  for (const auto& e : Rule(r, UpdateRule::kPatent).events)
    stated = stated || e.message.find("directions identified") != std::string::npos;
  EXPECT_TRUE(stated);
}

// 200 random runs whose coefficients change at a random minute and stay changed: gains
// x (1 + 0.5 N(0,1)), intercept + 2 N(0,1) um; trained on the first 200 min, monitored at the
// default options. Returns, per run, (RMSE_default - RMSE_static) / s and the ratio.
// `oscillating_gain`: whether the gain on the oscillating latent (3 sin(t/40): a period of
// 251 min, about two check intervals) changes too. Its change is a deviation that flips sign
// between checks: a check every 120 min samples a 251-min swing barely above the Nyquist rate,
// so the misfit at one check says nothing about the next, and no check-based rule follows it
// (the offset and patent rules lose to static on the same runs). A shop's persistent drifts
// (ageing, a changed fixture or coolant, the hall) change the error slowly against the checks;
// the strict property is stated for those, the mixed population for "never blows up".
struct PropertyStats {
  double mean_ratio = 0, worst_s = 0;
  int above_s = 0, runs = 0;
};
PropertyStats DefaultAgainstStatic(bool oscillating_gain, const MonitorOptions& o) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  PropertyStats st;
  st.runs = 200;
  st.worst_s = -1e300;
  for (int i = 0; i < st.runs; ++i) {
    Planted p;
    p.samples = 480 + static_cast<int>(480 * u01(rng));
    p.change_min = 200 + 200 * u01(rng);
    p.sigma = 0.2;
    for (int k = 0; k < 3; ++k) p.w_after(k) = p.w(k) * (1 + 0.5 * n01(rng));
    if (!oscillating_gain) p.w_after(2) = p.w(2);
    p.c_after = p.c + 2 * n01(rng);
    const drift::Run run = MakeRun(p, 100 + static_cast<unsigned>(i));
    const MonitorResult r = MonitorRun(FitOn(run.Slice(0, 200, "train")), run, o);
    const double stat = Rule(r, UpdateRule::kStatic).score.rmse_um;
    const double def = Rule(r, UpdateRule::kBayes).score.rmse_um;
    st.mean_ratio += def / stat / st.runs;
    st.above_s += def > stat + p.sigma;
    st.worst_s = std::max(st.worst_s, (def - stat) / p.sigma);
  }
  std::printf("default vs static (%s): mean ratio %.3f, %d of %d runs above by > s, worst %.2f s\n",
              oscillating_gain ? "every gain changes" : "slow gains and intercept change",
              st.mean_ratio, st.above_s, st.runs, st.worst_s);
  return st;
}

// Persistent changes: the default (bayes with the drift estimated from the checks) is not worse
// than the static model on average, rarely by more than the noise s, never by much. Without the
// drift estimate (prior scale 100 x Cov(b), the previous default) the updates extrapolate along
// Cov(b), large where the training latents were nearly collinear (worst 24 s on these runs).
TEST(MonitorProperty, DefaultIsNotWorseThanStaticOnPersistentRandomRuns) {
  const MonitorOptions o;  // defaults
  ASSERT_EQ(o.rules.size(), 3u);
  const PropertyStats slow = DefaultAgainstStatic(false, o);
  EXPECT_LE(slow.mean_ratio, 1.0);
  EXPECT_LE(slow.above_s, slow.runs / 50);
  EXPECT_LT(slow.worst_s, 8.0);
  // With the oscillating gain changed too: still better than static on average, never by much.
  const PropertyStats all = DefaultAgainstStatic(true, o);
  EXPECT_LE(all.mean_ratio, 1.0);
  EXPECT_LT(all.worst_s, 8.0);
}

// The maximum-likelihood drift variance: for one check the closed form max(0, (m^2 - v) / g);
// for checks with equal v and g, max(0, (mean m^2 - v) / g); misfits within the noise give 0.
TEST(MonitorProperty, DriftVarianceIsTheMaximumLikelihoodEstimate) {
  EXPECT_NEAR(DriftVarianceMle({{3.0, 1.0, 2.0}}), (9.0 - 1.0) / 2.0, 1e-6 * 4.0);
  EXPECT_EQ(DriftVarianceMle({{0.5, 1.0, 2.0}}), 0.0);
  const std::vector<Innovation> three{{1.0, 0.5, 4.0}, {-3.0, 0.5, 4.0}, {2.0, 0.5, 4.0}};
  EXPECT_NEAR(DriftVarianceMle(three), ((1.0 + 9.0 + 4.0) / 3.0 - 0.5) / 4.0, 1e-6);
  EXPECT_EQ(DriftVarianceMle({{0.1, 1.0, 1.0}, {-0.2, 1.0, 1.0}, {3.0, 1.0, 0.0}}), 0.0);
  EXPECT_EQ(DriftVarianceMle({}), 0.0);
}

// The drift covariance's pieces by hand: the training column scale (1 for a feature trained on
// one value), the box seen widening it, the check's variance and gain, and P += q^2 D^-2.
TEST(MonitorDriftScale, PiecesMatchAHandComputedExample) {
  DriftModel m;
  m.feature_min = Eigen::Vector2d(1.0, 5.0);
  m.feature_max = Eigen::Vector2d(3.0, 5.0);  // the second feature: one training value
  const Eigen::VectorXd scale = TrainingColumnScale(m);
  EXPECT_EQ(scale, Eigen::Vector3d(1.0, 2.0, 1.0));
  SeenBox seen;
  seen.Add(Eigen::RowVector3d(1.0, 2.0, 5.0));
  seen.Add(Eigen::RowVector3d(1.0, 6.0, 3.5));  // feature 1 spans 4 > 2, feature 2 spans 1.5 > 1
  seen.Add(Eigen::RowVector3d(1.0, 3.0, 4.0));
  const Eigen::VectorXd d = DriftScale(scale, seen);
  EXPECT_EQ(d, Eigen::Vector3d(1.0, 4.0, 1.5));
  const Eigen::RowVector3d x(1.0, 2.0, 3.0);
  const Eigen::Matrix3d p = Eigen::Vector3d(0.5, 0.25, 2.0).asDiagonal();
  const Innovation in = CheckInnovation(x, 2.5, p, 0.1, d);
  EXPECT_DOUBLE_EQ(in.misfit_um, 2.5);
  EXPECT_NEAR(in.variance_um2, 0.5 + 4 * 0.25 + 9 * 2.0 + 0.1, 1e-12);
  EXPECT_NEAR(in.gain, 1.0 + 0.25 + 4.0, 1e-12);  // 1 + (2/4)^2 + (3/1.5)^2
  Eigen::MatrixXd prior = p;
  const double q2 = AddDriftVariance({in}, d, &prior);
  EXPECT_NEAR(q2, (2.5 * 2.5 - in.variance_um2) > 0 ? (2.5 * 2.5 - in.variance_um2) / in.gain : 0,
              1e-6);
  const Innovation big = CheckInnovation(x, 30.0, p, 0.1, d);
  prior = p;
  const double q2_big = AddDriftVariance({big}, d, &prior);
  ASSERT_GT(q2_big, 0);
  EXPECT_NEAR(q2_big, (900.0 - big.variance_um2) / big.gain, 1e-6 * q2_big);
  for (int j = 0; j < 3; ++j)
    EXPECT_NEAR(prior(j, j), p(j, j) + q2_big / (d(j) * d(j)), 1e-9 * (1 + prior(j, j)));
  EXPECT_EQ(prior(0, 1), 0.0);
}

// A week: day d+1 starts from day d's final coefficients and covariance; stop minutes total the
// days; identical days on which the model is right give no update, so the week equals static.
TEST(MonitorWeek, CarriesStateAndTotals) {
  Planted p;
  const drift::Run train = MakeRun(p, 1);
  const DriftModel m = FitOn(train);
  MonitorOptions o;
  o.check_every = 100;
  std::vector<drift::Run> same{MakeRun(p, 2), MakeRun(p, 3)};
  const WeekResult quiet = MonitorWeek(m, same, o);
  ASSERT_EQ(quiet.days.size(), 2u);
  for (const auto& d : quiet.days)
    for (const auto& st : d.strategies) {
      EXPECT_EQ(st.recalibrations, 0);
      EXPECT_LE(st.checks, 6);
    }
  double stop = 0;
  for (const auto& d : quiet.days) stop += Rule(d, UpdateRule::kBayes).stop_min;
  EXPECT_DOUBLE_EQ(quiet.stop_min[2], stop);  // static, patent, bayes, offset
  // A changed machine: the second day's bayes starts where the first ended.
  Planted q = p;
  q.change_min = 0;
  q.w_after = {1.6, 0.1, -0.4};
  const WeekResult changed = MonitorWeek(m, {MakeRun(q, 4), MakeRun(q, 5)}, o);
  const StrategyResult& first = Rule(changed.days[0], UpdateRule::kBayes);
  ASSERT_GT(first.recalibrations, 0);
  const StrategyResult& second = Rule(changed.days[1], UpdateRule::kBayes);
  const MonitorEvent* check = nullptr;
  for (const auto& e : second.events)
    if (e.kind == MonitorEvent::Kind::kCheck) {
      check = &e;
      break;
    }
  ASSERT_NE(check, nullptr);
  const Eigen::MatrixXd x = MonitorDesign(m, MakeRun(q, 5), ReferenceMode::kRunStart);
  EXPECT_NEAR(check->predicted_um, x.row(check->sample).dot(first.final_coefficients), 1e-9);
  EXPECT_FALSE(changed.strongest.empty());
}

// A week of three days checked every 100 samples by a model fitted on a planted run: two days on
// a changed machine, then one like the training run.
struct ChangedWeekCase {
  MonitorOptions o;
  WeekResult w;
};
ChangedWeekCase ChangedWeek() {
  Planted p;
  const DriftModel m = FitOn(MakeRun(p, 1));
  ChangedWeekCase c;
  c.o.check_every = 100;
  Planted q = p;
  q.change_min = 0;
  q.w_after = {1.6, 0.1, -0.4};
  c.w = MonitorWeek(m, {MakeRun(q, 4), MakeRun(q, 5), MakeRun(p, 6)}, c.o);
  return c;
}

// The week's events table is every day's events under one header with the day in front, built
// row by row: a day named with a comma, a quote and a line break and a message holding a line
// break stay one cell each (an RFC 4180 reader written apart from whirl's reads them back).
TEST(MonitorWeek, EventsTableKeepsQuotedNamesAndMessagesWhole) {
  WeekResult w = ChangedWeek().w;
  w.days[0].run = "day, \"one\"\nof two";
  const std::string message = "reason, with a comma\nand a second line";
  std::size_t events = 0;
  for (auto& day : w.days)
    for (auto& st : day.strategies)
      for (auto& e : st.events) {
        e.message = message;
        ++events;
      }
  ASSERT_GT(events, 0u);
  std::string csv = WeekEventsCsv(w, {"a comment"});
  while (csv.rfind("#", 0) == 0) csv.erase(0, csv.find('\n') + 1);
  const auto records = test::ParseRfc4180(csv);
  ASSERT_EQ(records.size(), 1 + events);
  const std::vector<std::string>& header = records.front();
  EXPECT_EQ(header.front(), "day");
  EXPECT_EQ(header.back(), "message");
  std::size_t row = 1;
  for (const auto& day : w.days)
    for (const auto& st : day.strategies)
      for (std::size_t k = 0; k < st.events.size(); ++k, ++row) {
        ASSERT_EQ(records[row].size(), header.size()) << row;
        EXPECT_EQ(records[row].front(), day.run) << row;
        EXPECT_EQ(records[row][1], ToString(st.rule)) << row;
        EXPECT_EQ(records[row].back(), message) << row;
      }
}

// The week on the terminal: one compact row per day under one header - day, samples, the MAE of
// every row of the week in the week table's order (- where the day has none), the checking rules'
// checks, invalid checks and stop minutes, the day's strongest, the run - not a sentence per day.
TEST(MonitorWeek, TerminalShowsOneTableRowPerDay) {
  const ChangedWeekCase c = ChangedWeek();
  const WeekResult& w = c.w;
  const MonitorOptions& o = c.o;
  const std::string text = FormatWeek(w, o);
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  bool in_table = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  day  samples", 0) == 0) {
      in_table = true;
      continue;
    }
    if (!in_table || line.rfind("week ", 0) == 0) {
      in_table = false;
      continue;
    }
    std::istringstream words(line);
    rows.emplace_back();
    for (std::string word; words >> word;) rows.back().push_back(word);
  }
  ASSERT_EQ(rows.size(), w.days.size()) << text;
  for (std::size_t d = 0; d < w.days.size(); ++d) {
    const MonitorResult& day = w.days[d];
    const std::vector<std::string>& r = rows[d];
    ASSERT_GE(r.size(), 3 + w.week.size() + 3) << text;
    EXPECT_EQ(r[0], std::to_string(d + 1));
    EXPECT_EQ(r[1], std::to_string(day.samples));
    EXPECT_EQ(r[2], FormatDecimals(day.none.mae_um, 2));
    for (const StrategyResult& st : day.strategies) {
      std::size_t k = 0;
      while (k < w.week.size() && w.week[k].name != ToString(st.rule)) ++k;
      ASSERT_LT(k, w.week.size());
      EXPECT_EQ(r[2 + k], FormatDecimals(st.score.mae_um, 2)) << ToString(st.rule);
    }
    const std::size_t after = 2 + w.week.size();
    EXPECT_EQ(r[after], std::to_string(Rule(day, UpdateRule::kPatent).checks));
    std::vector<std::string> each;  // the checking rules' invalid checks, one when they agree
    for (const StrategyResult& st : day.strategies)
      if (st.rule != UpdateRule::kStatic) each.push_back(std::to_string(st.invalid_checks));
    std::string invalid = each.front();
    if (std::count(each.begin(), each.end(), each.front()) != static_cast<long>(each.size()))
      for (std::size_t k = 1; k < each.size(); ++k) invalid += "/" + each[k];
    EXPECT_EQ(r[after + 1], invalid) << text;
    EXPECT_EQ(r.back(), day.run);
  }
}

// Issue 45 item 7: --day had no bound (3,000 files were read); a replay takes at most a year of
// day files, checked before any is read, and together at most one run file's samples.
TEST(Monitor, DayFilesAreBounded) {
  EXPECT_NO_THROW(CheckMonitorDays(kMaxMonitorDays));
  try {
    CheckMonitorDays(3000);
    ADD_FAILURE() << "3000 day files accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3000 day files"), std::string::npos) << e.what();
  }
  // Days that hold more samples together than one run file may are refused before any replay.
  Planted p;
  const DriftModel m = FitOn(MakeRun(p, 1));
  p.samples = kMaxRunSamples / 2 + 1;
  const drift::Run big = MakeRun(p, 2);
  try {
    MonitorWeek(m, {big, big}, MonitorOptions{});
    ADD_FAILURE() << "2 x " << big.samples() << " samples accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("samples together"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace whirl::drift
