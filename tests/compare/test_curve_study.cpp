// The fits over simulated curves: kDefaultShapeK and kDefaultTimeExponent against a freshly
// simulated set (a reference, not a pin: loose tolerance), and the paper's finding that the
// arctan model fits best.
#include <gtest/gtest.h>

#include "compare/curve_study.h"
#include "core/error.h"
#include "fit/arctan_curve.h"

namespace whirl::compare {
namespace {

TEST(SimulatedFits, DefaultShapeIsNearThePooledFitOfFreshSimulations) {
  SimulatedFitOptions o;
  o.count = 9;
  o.seed = 12345;  // not the seed the constant was derived with
  const SimulatedFitReport r = FitSimulatedCurves(o);
  ASSERT_EQ(r.shape.fits.size(), 9u);
  EXPECT_TRUE(r.shape.summary.Converged()) << r.shape.summary.BriefReport();
  EXPECT_NEAR(r.shape.shape_k, fit::kDefaultShapeK, 0.1 * fit::kDefaultShapeK)
      << "re-derive the defaults with 'whirl fit --simulated 25' if the simulator changed";
  // The settle time is itself the least-squares t_s of this shape plus a drift
  // (fit/features.h), so the calibration with the features fixed is partly circular and lands at
  // p = 0.91 (k = 4.61) on the window the features come from.
  EXPECT_NEAR(r.shape.time_exponent, fit::kDefaultTimeExponent, 0.04)
      << "re-derive the defaults with 'whirl fit --simulated 25' if the simulator changed";
  EXPECT_GT(r.shape.median_r_squared, 0.99);
  // (Earlier the pooled (k, p) beat the best plain arctangent by more than 20 % here; with
  // the features fitted with the pooled shape the two are within about 20 % either way, so that
  // comparison no longer tests the exponent. The evaluation does: docs/results.md, p = 1 row.)
  // Li, Ma and Jiang, section 3: the arctangent fits the dynamic part better than parabola or sine.
  EXPECT_EQ(r.best_model, fit::CurveModel::kArctan);
  ASSERT_EQ(r.models.size(), 3u);
  EXPECT_LT(r.models[0].median_rms_residual_um, r.models[1].median_rms_residual_um);
  EXPECT_LT(r.models[0].median_rms_residual_um, r.models[2].median_rms_residual_um);
  EXPECT_EQ(r.features.size(), 9u);
}

TEST(SimulatedFits, BadOptionsThrow) {
  SimulatedFitOptions o;
  o.count = 0;
  EXPECT_THROW(FitSimulatedCurves(o), InputError);
  o.count = 1;
  o.fit_window_factor = 1.0;
  EXPECT_THROW(FitSimulatedCurves(o), InputError);
}

}  // namespace
}  // namespace whirl::compare
