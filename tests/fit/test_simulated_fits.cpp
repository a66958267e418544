// The fits over simulated curves: kDefaultShapeK against a freshly simulated set (a reference,
// not a pin: loose tolerance), and the paper's finding that the arctan model fits best.
#include <gtest/gtest.h>

#include "core/error.h"
#include "fit/arctan_curve.h"
#include "fit/simulated_fits.h"

namespace whirl::fit {
namespace {

TEST(SimulatedFits, DefaultShapeIsNearTheMedianOfFreshSimulations) {
  SimulatedFitOptions o;
  o.count = 9;
  o.seed = 12345;  // not the seed the constant was derived with
  const SimulatedFitReport r = FitSimulatedCurves(o);
  ASSERT_EQ(r.shape.fits.size(), 9u);
  EXPECT_NEAR(r.shape.median_shape_k, kDefaultShapeK, 0.1 * kDefaultShapeK)
      << "re-derive kDefaultShapeK with 'whirl fit --simulated 25' if the simulator changed";
  EXPECT_GT(r.shape.median_r_squared, 0.99);
  // Paper seed 002 section 3: the arctangent fits the dynamic part better than parabola or sine.
  EXPECT_EQ(r.best_model, CurveModel::kArctan);
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
}  // namespace whirl::fit
