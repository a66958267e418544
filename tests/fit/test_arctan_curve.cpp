// The arctan curve (closed-form properties, derivatives against finite differences) and the curve
// fitter (recovers known parameters from poor starts, compares the three models).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/error.h"
#include "fit/arctan_curve.h"
#include "fit/curve_fit.h"

namespace whirl::fit {
namespace {

// Random curve; every fourth has p = 1 exactly (the plain arctangent in time).
ArctanCurve RandomCurve(std::mt19937& rng) {
  std::uniform_real_distribution<double> ul(5.0, 120.0), uts(60.0, 600.0), uk(0.5, 12.0),
      up(0.5, 1.0);
  std::uniform_int_distribution<int> plain(0, 3);
  const ArctanCurve c{ul(rng), uts(rng), uk(rng), up(rng)};
  return plain(rng) == 0 ? ArctanCurve{c.max_elongation_um, c.settle_time_s, c.shape_k, 1.0} : c;
}

ElongationCurve Sample(const std::function<double(double)>& f, double t_end, int n) {
  ElongationCurve c;
  for (int i = 0; i < n; ++i) {
    const double t = t_end * i / (n - 1);
    c.time_s.push_back(t);
    c.elongation_um.push_back(f(t));
  }
  return c;
}

TEST(ArctanCurve, ClosedFormProperties) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const ArctanCurve c = RandomCurve(rng);
    EXPECT_EQ(c.ElongationUm(0.0), 0.0);
    EXPECT_EQ(c.ElongationUm(-5.0), 0.0);
    EXPECT_NEAR(c.ElongationUm(c.settle_time_s * (1 - 1e-12)), c.max_elongation_um,
                1e-9 * c.max_elongation_um);  // continuous at t_s
    EXPECT_EQ(c.ElongationUm(2 * c.settle_time_s), c.max_elongation_um);
    // Slope at 0: L k/(t_s atan k) for p = 1, infinite for p < 1; just before t_s: L k p/(t_s
    // atan(k) (1 + k^2)).
    const double s0 = c.max_elongation_um * c.shape_k / (c.settle_time_s * std::atan(c.shape_k));
    if (c.time_exponent == 1.0)
      EXPECT_NEAR(c.SlopeUmPerS(0.0), s0, 1e-12 * s0);
    else
      EXPECT_EQ(c.SlopeUmPerS(0.0), std::numeric_limits<double>::infinity());
    EXPECT_NEAR(c.SlopeUmPerS(c.settle_time_s), s0 * c.time_exponent / (1 + c.shape_k * c.shape_k),
                1e-12 * s0);
    EXPECT_EQ(c.SlopeUmPerS(1.5 * c.settle_time_s), 0.0);
    // At the same fraction of t_s, atan(k r^p) is atan(k r) at r^p: the exponent only remaps time.
    const double r = 0.37;
    const ArctanCurve plain{c.max_elongation_um, c.settle_time_s, c.shape_k, 1.0};
    EXPECT_NEAR(c.ElongationUm(r * c.settle_time_s),
                plain.ElongationUm(std::pow(r, c.time_exponent) * c.settle_time_s),
                1e-12 * c.max_elongation_um);
    EXPECT_NEAR(plain.ElongationUm(r * c.settle_time_s),
                c.max_elongation_um * std::atan(c.shape_k * r) / std::atan(c.shape_k),
                1e-12 * c.max_elongation_um);
    // Monotone non-decreasing, within [0, L], and concave on [0, t_s] (second differences <= 0):
    // what the compensation-point placement relies on.
    double prev = -1;
    for (int i = 0; i <= 100; ++i) {
      const double t = 1.2 * c.settle_time_s * i / 100;
      const double v = c.ElongationUm(t);
      EXPECT_GE(v, prev);
      EXPECT_LE(v, c.max_elongation_um * (1 + 1e-12));
      prev = v;
      const double h = c.settle_time_s / 200;
      if (t >= h && t + h <= c.settle_time_s) {
        EXPECT_LE(c.ElongationUm(t + h) - 2 * v + c.ElongationUm(t - h),
                  1e-12 * c.max_elongation_um)
            << "not concave at t = " << t << " with p = " << c.time_exponent;
      }
    }
  }
}

TEST(ArctanCurve, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> frac(0.01, 0.99);
  for (int trial = 0; trial < 200; ++trial) {
    const ArctanCurve c = RandomCurve(rng);
    const double t = frac(rng) * c.settle_time_s;
    const double h = 1e-5 * c.settle_time_s;
    const double fd_t = (c.ElongationUm(t + h) - c.ElongationUm(t - h)) / (2 * h);
    EXPECT_NEAR(c.SlopeUmPerS(t), fd_t, 1e-6 * std::abs(fd_t) + 1e-10);
    double dl, dts, dk, dp;
    c.ParameterGradient(t, &dl, &dts, &dk, &dp);
    const double p = c.time_exponent;
    auto at = [&](double big_l, double ts, double k, double pp) {
      return ArctanCurve{big_l, ts, k, pp}.ElongationUm(t);
    };
    const double hl = 1e-6 * c.max_elongation_um, hts = 1e-6 * c.settle_time_s,
                 hk = 1e-6 * c.shape_k, hp = 1e-6;
    const double L = c.max_elongation_um, ts = c.settle_time_s, k = c.shape_k;
    EXPECT_NEAR(dl, (at(L + hl, ts, k, p) - at(L - hl, ts, k, p)) / (2 * hl), 1e-7);
    const double fd_ts = (at(L, ts + hts, k, p) - at(L, ts - hts, k, p)) / (2 * hts);
    EXPECT_NEAR(dts, fd_ts, 1e-6 * std::abs(fd_ts) + 1e-9);
    const double fd_k = (at(L, ts, k + hk, p) - at(L, ts, k - hk, p)) / (2 * hk);
    EXPECT_NEAR(dk, fd_k, 1e-6 * std::abs(fd_k) + 1e-9);
    const double fd_p = (at(L, ts, k, p + hp) - at(L, ts, k, p - hp)) / (2 * hp);
    EXPECT_NEAR(dp, fd_p, 1e-6 * std::abs(fd_p) + 1e-8);
    double dl3, dts3, dk3;  // the 3-parameter overload gives the same first three
    c.ParameterGradient(t, &dl3, &dts3, &dk3);
    EXPECT_EQ(dl3, dl);
    EXPECT_EQ(dts3, dts);
    EXPECT_EQ(dk3, dk);
  }
}

TEST(CurveModels, AnalyticGradientsMatchFiniteDifferences) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> frac(0.02, 0.98);
  for (CurveModel model : kAllCurveModels) {
    for (int trial = 0; trial < 100; ++trial) {
      const ArctanCurve c = RandomCurve(rng);
      Eigen::VectorXd p(model == CurveModel::kSine ? 2 : model == CurveModel::kArctan ? 4 : 3);
      p[0] = c.max_elongation_um;
      p[1] = c.settle_time_s;
      if (model == CurveModel::kArctan) {
        p[2] = c.shape_k;
        p[3] = std::min(c.time_exponent, 0.999);  // central differences stay inside (0, 1]
      }
      if (model == CurveModel::kParabola) p[2] = 1.3 * c.max_elongation_um / c.settle_time_s;
      const double t = frac(rng) * c.settle_time_s;
      Eigen::VectorXd g;
      EvaluateModel(model, p, t, &g);
      for (Eigen::Index j = 0; j < p.size(); ++j) {
        Eigen::VectorXd pp = p, pm = p;
        const double h = 1e-6 * std::abs(p[j]);
        pp[j] += h;
        pm[j] -= h;
        const double fd = (EvaluateModel(model, pp, t) - EvaluateModel(model, pm, t)) / (2 * h);
        EXPECT_NEAR(g[j], fd, 1e-6 * std::abs(fd) + 1e-8) << ToString(model) << " param " << j;
      }
    }
  }
}

TEST(CurveFit, ArctanFitRecoversParametersFromTheDataStart) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const ArctanCurve truth = RandomCurve(rng);
    const ElongationCurve data =
        Sample([&](double t) { return truth.ElongationUm(t); }, 2.5 * truth.settle_time_s, 301);
    CurveFitOptions o;
    o.initial_shape_k = 1.0;  // a poor start for k and p as well
    o.initial_time_exponent = 0.6;
    const CurveFit fit = FitCurveModel(data, CurveModel::kArctan, o);
    EXPECT_TRUE(fit.summary.Converged()) << fit.summary.BriefReport();
    EXPECT_NEAR(fit.parameters[0], truth.max_elongation_um, 1e-4 * truth.max_elongation_um)
        << fit.summary.BriefReport();
    // t_s is only pinned to within a sample step by data on a grid (the kink sits between samples).
    EXPECT_NEAR(fit.parameters[1], truth.settle_time_s, 2.5 * truth.settle_time_s / 300);
    EXPECT_NEAR(fit.parameters[2], truth.shape_k, 0.05 * truth.shape_k);
    EXPECT_NEAR(fit.parameters[3], truth.time_exponent, 0.02);
    EXPECT_GT(fit.r_squared, 0.99999);
    EXPECT_LT(fit.rms_residual_um, 1e-3 * truth.max_elongation_um);
  }
}

TEST(CurveFit, NoisyCurveGivesRmsNearTheNoiseAndArctanWins) {
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int trial = 0; trial < 10; ++trial) {
    ArctanCurve truth = RandomCurve(rng);
    truth.shape_k = 3.0 + trial;  // sharply bending curves, where the models differ clearly
    ElongationCurve data =
        Sample([&](double t) { return truth.ElongationUm(t); }, 2 * truth.settle_time_s, 400);
    for (double& v : data.elongation_um) v += noise(rng);
    const std::vector<CurveFit> fits = FitAllModels(data);
    ASSERT_EQ(fits.size(), 3u);
    EXPECT_NEAR(fits[0].rms_residual_um, 0.3, 0.06) << fits[0].summary.BriefReport();
    EXPECT_LT(fits[0].rms_residual_um, fits[1].rms_residual_um);
    EXPECT_LT(fits[0].rms_residual_um, fits[2].rms_residual_um);
    EXPECT_GT(fits[0].r_squared, fits[1].r_squared);
    EXPECT_GT(fits[0].r_squared, fits[2].r_squared);
  }
}

TEST(CurveFit, SineAndParabolaRecoverTheirOwnCurves) {
  // Each alternative model fits data generated by itself exactly: checks their formulas and fits.
  Eigen::VectorXd sine(2), parabola(3);
  sine << 40.0, 200.0;
  parabola << 40.0, 200.0, 0.35;  // b between L/t_s and 2L/t_s keeps the curve monotone
  const ElongationCurve ds =
      Sample([&](double t) { return EvaluateModel(CurveModel::kSine, sine, t); }, 500, 251);
  const ElongationCurve dp =
      Sample([&](double t) { return EvaluateModel(CurveModel::kParabola, parabola, t); }, 500, 251);
  // Tight stopping rule: the parabola's t_s creeps across sample kinks (see CurveFitOptions::lm).
  CurveFitOptions tight;
  tight.lm.cost_tolerance = 1e-15;
  tight.lm.max_iterations = 20000;
  const CurveFit fs = FitCurveModel(ds, CurveModel::kSine, tight);
  const CurveFit fp = FitCurveModel(dp, CurveModel::kParabola, tight);
  EXPECT_NEAR(fs.parameters[0], 40.0, 1e-3) << fs.summary.BriefReport();
  EXPECT_NEAR(fs.parameters[1], 200.0, 2.0);
  EXPECT_NEAR(fp.parameters[0], 40.0, 1e-3) << fp.summary.BriefReport();
  EXPECT_NEAR(fp.parameters[2], 0.35, 0.01);
  EXPECT_GT(fs.r_squared, 0.9999);
  EXPECT_GT(fp.r_squared, 0.9999);
}

TEST(CurveFit, ShapeFitWithFixedFeaturesRecoversKAndP) {
  std::mt19937 rng(8);
  std::vector<ElongationCurve> curves;
  std::vector<Features> features;
  std::vector<double> ks, ps;
  for (int trial = 0; trial < 15; ++trial) {
    const ArctanCurve truth = RandomCurve(rng);
    curves.push_back(
        Sample([&](double t) { return truth.ElongationUm(t); }, 2 * truth.settle_time_s, 200));
    features.push_back(truth.ToFeatures());
    ks.push_back(truth.shape_k);
    ps.push_back(truth.time_exponent);
    const ShapeFit fit = FitShape(curves.back(), features.back());
    EXPECT_NEAR(fit.shape_k, truth.shape_k, 1e-5 * truth.shape_k) << fit.summary.BriefReport();
    EXPECT_NEAR(fit.time_exponent, truth.time_exponent, 1e-5) << fit.summary.BriefReport();
  }
  // Mixed shapes: the pooled (k, p) is a compromise inside the per-curve ranges.
  const ShapeCalibration cal = CalibrateShape(curves, features);
  EXPECT_NEAR(cal.min_shape_k, *std::min_element(ks.begin(), ks.end()), 1e-4);
  EXPECT_NEAR(cal.max_time_exponent, *std::max_element(ps.begin(), ps.end()), 1e-5);
  EXPECT_GT(cal.shape_k, cal.min_shape_k);
  EXPECT_LT(cal.shape_k, cal.max_shape_k);
  EXPECT_GT(cal.time_exponent, cal.min_time_exponent);
  EXPECT_LT(cal.time_exponent, cal.max_time_exponent);
  EXPECT_THROW(CalibrateShape(curves, {}), InputError);
  EXPECT_THROW(CalibrateShape({}, {}), InputError);
}

TEST(CurveFit, PooledShapeRecoversACommonShapeAndIgnoresScale) {
  // Curves of one family (common k, p; different L, t_s, lengths and sample counts): the pooled
  // fit recovers (k, p).
  std::mt19937 rng(9);
  const double k = 4.1, p = 0.83;
  std::uniform_real_distribution<double> ul(5.0, 120.0), uts(60.0, 600.0), uend(1.5, 4.0);
  std::vector<ElongationCurve> curves;
  std::vector<Features> features;
  std::vector<double> ends;
  for (int i = 0; i < 8; ++i) {
    const ArctanCurve c{ul(rng), uts(rng), k, p};
    ends.push_back(uend(rng) * c.settle_time_s);
    curves.push_back(
        Sample([&](double t) { return c.ElongationUm(t); }, ends.back(), 100 + 37 * i));
    features.push_back(c.ToFeatures());
  }
  const ShapeCalibration exact = CalibrateShape(curves, features);
  EXPECT_NEAR(exact.shape_k, k, 1e-5) << exact.summary.BriefReport();
  EXPECT_NEAR(exact.time_exponent, p, 1e-6);
  EXPECT_GT(exact.median_r_squared, 0.999999);

  // Give curve 0 another shape: the pooled fit is now a compromise. Scaling that curve and its L
  // by 1000, or sampling it 5 times more densely, must not move the compromise (every curve is
  // normalized by its L and its sample count); without the normalization the odd curve would
  // pull the pool towards its own shape.
  const Features odd_features = features[0];
  auto odd_curve = [&](double scale, int samples) {
    const ArctanCurve c{scale * odd_features.max_elongation_um, odd_features.settle_time_s, 9.0,
                        0.6};
    return Sample([&](double t) { return c.ElongationUm(t); }, ends[0], samples);
  };
  const int n0 = static_cast<int>(curves[0].size());
  curves[0] = odd_curve(1.0, n0);
  const ShapeCalibration mixed = CalibrateShape(curves, features);
  EXPECT_GT(std::abs(mixed.shape_k - k), 0.02) << "the odd curve should move the pool a little";
  curves[0] = odd_curve(1000.0, n0);
  features[0].max_elongation_um *= 1000.0;
  const ShapeCalibration scaled = CalibrateShape(curves, features);
  EXPECT_NEAR(scaled.shape_k, mixed.shape_k, 1e-6 * mixed.shape_k);
  EXPECT_NEAR(scaled.time_exponent, mixed.time_exponent, 1e-7);
  curves[0] = odd_curve(1000.0, 5 * (n0 - 1) + 1);  // same span, 5x the samples
  const ShapeCalibration dense = CalibrateShape(curves, features);
  // The per-sample mean changes slightly with the sampling; the weight of the curve does not.
  EXPECT_NEAR(dense.shape_k, mixed.shape_k, 0.25 * std::abs(mixed.shape_k - k));
  EXPECT_NEAR(dense.time_exponent, mixed.time_exponent, 0.25 * std::abs(mixed.time_exponent - p));
}

TEST(ArctanCurve, ValidationNamesTheField) {
  try {
    ArctanCurve::FromFeatures({10.0, -3.0});
    FAIL() << "negative settle time accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("settle_time_s"), std::string::npos) << e.what();
  }
  EXPECT_THROW((ArctanCurve{10.0, 100.0, 0.0}.Validate()), InputError);
  for (double bad_p : {0.0, 0.45, 1.01, std::nan("")}) {
    try {
      ArctanCurve{10.0, 100.0, 3.0, bad_p}.Validate();
      FAIL() << "time exponent " << bad_p << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("time_exponent"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW((ArctanCurve{std::nan(""), 100.0, 3.0}.Validate()), InputError);
  EXPECT_NO_THROW((ArctanCurve{0.0, 100.0, 3.0}.Validate()));
  ElongationCurve tiny;
  tiny.time_s = {0, 1};
  tiny.elongation_um = {0, 1};
  EXPECT_THROW(FitCurveModel(tiny, CurveModel::kArctan), InputError);
  EXPECT_THROW(ParseCurveModel("cubic"), InputError);
}

}  // namespace
}  // namespace whirl::fit
