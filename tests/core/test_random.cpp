// The project's random stream (core/random.h): the engine is the standard's mt19937_64 (its
// 10000th output from the default seed is fixed by the C++ standard, [rand.predef]), the uniform
// and normal mappings are the documented ones, and they behave like their distributions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "core/random.h"

namespace whirl {
namespace {

TEST(Rng, UniformIsTheStandardEngineOutputShiftedTo53Bits) {
  Rng rng(5489u);  // std::mt19937_64's default seed
  for (int i = 1; i < 10000; ++i) rng.Uniform();
  // The standard: the 10000th invocation of a default-constructed mt19937_64 gives
  // 9981545732273789042.
  EXPECT_EQ(rng.Uniform(), static_cast<double>(9981545732273789042ull >> 11) * 0x1.0p-53);
  Rng a(7), b(7);
  EXPECT_EQ(a.Uniform(2.0, 5.0), 2.0 + 3.0 * b.Uniform());
}

TEST(Rng, UniformIsInRangeWithMeanOneHalf) {
  Rng rng(3);
  double sum = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);
}

TEST(Rng, NormalIsBoxMullerOfTwoUniformsBothValuesInOrder) {
  std::mt19937_64 engine(11);
  const auto uniform = [&engine] { return static_cast<double>(engine() >> 11) * 0x1.0p-53; };
  Rng rng(11);
  for (int pair = 0; pair < 100; ++pair) {
    const double u1 = uniform(), u2 = uniform();  // u1 = 0 has probability 2^-53
    const double r = std::sqrt(-2.0 * std::log(u1)), angle = 2.0 * M_PI * u2;
    EXPECT_DOUBLE_EQ(rng.Normal(), r * std::cos(angle));
    EXPECT_DOUBLE_EQ(rng.Normal(), r * std::sin(angle));
  }
}

TEST(Rng, NormalHasMeanZeroVarianceOneAndNormalTails) {
  Rng rng(1);
  const int n = 200000;
  double sum = 0, sum_sq = 0;
  int beyond_2 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = rng.Normal();
    sum += z;
    sum_sq += z * z;
    beyond_2 += std::abs(z) > 2.0 ? 1 : 0;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);      // standard error 0.0022
  EXPECT_NEAR(sum_sq / n, 1.0, 0.015);  // standard error 0.0032
  // P(|z| > 2) = 4.55 %, standard error of the share 0.047 %.
  EXPECT_NEAR(static_cast<double>(beyond_2) / n, 0.0455, 0.002);
}

}  // namespace
}  // namespace whirl
