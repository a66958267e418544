// Network invariants: Jacobian vs central finite differences, flat order, mapminmax, initnw.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/random.h"
#include "nn/network.h"
#include "support/eigen_near.h"

namespace whirl::nn {
namespace {

Network RandomNetwork(const std::vector<int>& sizes, std::uint64_t seed, double scale) {
  Network net = Network::Zeros(sizes);
  Rng rng(seed);
  Eigen::VectorXd w(net.ParameterCount());
  for (int i = 0; i < w.size(); ++i) w(i) = rng.Uniform(-scale, scale);
  net.SetParameters(w);
  return net;
}

Eigen::MatrixXd RandomMatrix(int rows, int cols, Rng* rng) {
  Eigen::MatrixXd m(rows, cols);
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) m(r, c) = rng->Uniform(-1.0, 1.0);
  return m;
}

// e = t - y flattened sample-major; t = 0 here (J does not depend on t).
Eigen::VectorXd Errors(const Network& net, const Eigen::MatrixXd& x) {
  const Eigen::MatrixXd y = -net.Forward(x);
  return Eigen::Map<const Eigen::VectorXd>(y.data(), y.size());
}

TEST(Network, JacobianMatchesCentralDifferencesOnRandomNetworks) {
  const std::vector<std::vector<int>> shapes = {{5, 6, 2},    {5, 6, 2}, {5, 4, 2}, {3, 1, 1},
                                                {5, 8, 3, 2}, {2, 2},    {5, 10, 2}};
  int cases = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const auto& sizes = shapes[seed % shapes.size()];
    const Network net = RandomNetwork(sizes, seed, 1.5);
    Rng rng(1000 + seed);
    const Eigen::MatrixXd x = RandomMatrix(sizes.front(), 7, &rng);
    ForwardCache cache;
    net.Forward(x, &cache);
    Eigen::MatrixXd J;
    ErrorJacobian(net, cache, &J);
    const Eigen::VectorXd w = net.GetParameters();
    Eigen::MatrixXd J_fd(J.rows(), J.cols());
    for (int i = 0; i < w.size(); ++i) {
      const double h = 1e-5 * std::max(1.0, std::abs(w(i)));
      Network plus = net, minus = net;
      Eigen::VectorXd wp = w, wm = w;
      wp(i) += h;
      wm(i) -= h;
      plus.SetParameters(wp);
      minus.SetParameters(wm);
      J_fd.col(i) = (Errors(plus, x) - Errors(minus, x)) / (2 * h);
    }
    const double rel = (J - J_fd).norm() / J_fd.norm();
    EXPECT_LT(rel, 1e-6) << "seed " << seed;
    EXPECT_TRUE(whirl::test::AllNear(J, J_fd, 1e-6, 1e-9 * J_fd.cwiseAbs().maxCoeff()))
        << "seed " << seed;
    ++cases;
  }
  EXPECT_EQ(cases, 40);
}

// The structured Gram matrix (one hidden layer) and the fallback (other depths) against J J'.
TEST(Network, ErrorGramEqualsJacobianTimesItsTranspose) {
  const std::vector<std::vector<int>> shapes = {{5, 6, 2}, {5, 4, 2},    {3, 1, 1}, {5, 10, 3},
                                                {2, 7, 1}, {5, 8, 3, 2}, {2, 2}};
  for (std::uint64_t seed = 1; seed <= 35; ++seed) {
    const auto& sizes = shapes[seed % shapes.size()];
    const Network net = RandomNetwork(sizes, seed, 1.5);
    Rng rng(1000 + seed);
    const Eigen::MatrixXd x = RandomMatrix(sizes.front(), 1 + static_cast<int>(seed % 23), &rng);
    ForwardCache cache;
    net.Forward(x, &cache);
    Eigen::MatrixXd J, G;
    ErrorJacobian(net, cache, &J);
    ErrorGram(net, cache, J, &G);
    const Eigen::MatrixXd reference = J * J.transpose();
    EXPECT_TRUE(whirl::test::AllNear(G, reference, 1e-12, 1e-12 * reference.norm()))
        << "seed " << seed;
    EXPECT_EQ(G, G.transpose()) << "seed " << seed;
  }
}

TEST(Network, FlatOrderIsBiasThenColumnMajorWeightsPerLayer) {
  Network net = Network::Zeros({5, 6, 2});
  EXPECT_EQ(net.ParameterCount(), 50);
  Eigen::VectorXd w(50);
  for (int i = 0; i < 50; ++i) w(i) = i;
  net.SetParameters(w);
  EXPECT_EQ(net.biases[0](0), 0);
  EXPECT_EQ(net.biases[0](5), 5);
  EXPECT_EQ(net.weights[0](0, 0), 6);
  EXPECT_EQ(net.weights[0](1, 0), 7);  // column-major
  EXPECT_EQ(net.weights[0](0, 1), 12);
  EXPECT_EQ(net.biases[1](0), 36);
  EXPECT_EQ(net.weights[1](0, 0), 38);
  EXPECT_EQ(net.weights[1](1, 5), 49);
  for (int l = 0; l < 2; ++l)
    for (int r = 0; r < net.layer_sizes[l + 1]; ++r) {
      EXPECT_EQ(net.BiasIndex(l, r), net.biases[l](r));
      for (int c = 0; c < net.layer_sizes[l]; ++c)
        EXPECT_EQ(net.WeightIndex(l, r, c), net.weights[l](r, c));
    }
  EXPECT_EQ(net.GetParameters(), w);
  EXPECT_THROW(net.SetParameters(Eigen::VectorXd::Zero(49)), InputError);
}

TEST(Network, ForwardMatchesClosedForm) {
  Network net = Network::Zeros({2, 2, 1});
  net.weights[0] << 0.5, -1.0, 2.0, 0.25;
  net.biases[0] << 0.1, -0.2;
  net.weights[1] << 1.5, -0.7;
  net.biases[1] << 0.3;
  Eigen::MatrixXd x(2, 1);
  x << 0.4, -0.6;
  const double h0 = std::tanh(0.5 * 0.4 - 1.0 * -0.6 + 0.1);
  const double h1 = std::tanh(2.0 * 0.4 + 0.25 * -0.6 - 0.2);
  EXPECT_DOUBLE_EQ(net.Forward(x)(0, 0), 1.5 * h0 - 0.7 * h1 + 0.3);
}

TEST(MapMinMax, RoundTripsAndMapsRangeToMinusOneOne) {
  Rng rng(7);
  Eigen::MatrixXd x(3, 9);
  for (int c = 0; c < 9; ++c) {
    x(0, c) = rng.Uniform(60, 65);
    x(1, c) = rng.Uniform(50, 100);
    x(2, c) = 4.0;  // constant variable
  }
  const MapMinMax m = MapMinMax::Fit(x);
  const Eigen::MatrixXd y = m.Apply(x);
  EXPECT_DOUBLE_EQ(y.row(0).minCoeff(), -1.0);
  EXPECT_DOUBLE_EQ(y.row(0).maxCoeff(), 1.0);
  EXPECT_DOUBLE_EQ(y.row(1).minCoeff(), -1.0);
  EXPECT_DOUBLE_EQ(y.row(1).maxCoeff(), 1.0);
  EXPECT_EQ(y.row(2), x.row(2));  // passed through unchanged
  EXPECT_TRUE(whirl::test::AllNear(m.Reverse(y), x, 1e-14));
  EXPECT_DOUBLE_EQ(m.HalfRange()(2), 1.0);
  EXPECT_DOUBLE_EQ(m.HalfRange()(0), 0.5 * (m.xmax(0) - m.xmin(0)));
  Eigen::MatrixXd bad = x;
  bad(1, 3) = std::nan("");
  EXPECT_THROW(MapMinMax::Fit(bad), InputError);
}

TEST(InitNguyenWidrow, FollowsInitnwAndIsSeeded) {
  for (const std::vector<int>& sizes : {std::vector<int>{5, 6, 2}, {5, 1, 2}, {3, 4, 3, 1}}) {
    Network a = Network::Zeros(sizes), b = Network::Zeros(sizes), c = Network::Zeros(sizes);
    InitNguyenWidrow(42, &a);
    InitNguyenWidrow(42, &b);
    InitNguyenWidrow(43, &c);
    EXPECT_EQ(a.GetParameters(), b.GetParameters());
    EXPECT_NE(a.GetParameters(), c.GetParameters());
    for (int l = 0; l + 1 < a.LayerCount(); ++l) {
      const int S = sizes[l + 1], R = sizes[l];
      const double w_mag = 0.7 * std::pow(double(S), 1.0 / R);
      for (int r = 0; r < S; ++r) {
        EXPECT_NEAR(a.weights[l].row(r).norm(), 2 * w_mag, 1e-12);
        const double lin = S == 1 ? 1.0 : -1.0 + 2.0 * r / (S - 1);
        const double sign = a.weights[l](r, 0) > 0 ? 1.0 : -1.0;
        EXPECT_NEAR(a.biases[l](r), 2 * w_mag * lin * sign, 1e-12);
      }
    }
    const int L = a.LayerCount() - 1;
    EXPECT_LE(a.weights[L].cwiseAbs().maxCoeff(), 1.0);
    EXPECT_LE(a.biases[L].cwiseAbs().maxCoeff(), 1.0);
  }
}

}  // namespace
}  // namespace whirl::nn
