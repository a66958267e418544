// The exact thermal network and the field machine's error functional (src/lab/machine/network.h,
// field.h): closed forms, steady state, energy balance, the fin decay of the Z screw, the linear
// scale taking the screw out of the loop.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "machine/field.h"
#include "machine/network.h"

namespace whirl::machine {
namespace {

// dT/dt = C^-1 (-G T + G_b T_b + Q) by classical Runge-Kutta with small steps: an independent
// reference for the exact discretization.
Eigen::VectorXd Rk4(const ThermalNetwork& n, Eigen::VectorXd t, const Eigen::VectorXd& tb,
                    const Eigen::VectorXd& q, double seconds, int steps) {
  const double h = seconds / steps;
  auto f = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    return ((-n.conductance() * x + n.boundary_conductance() * tb + q).array() /
            n.capacity().array()).matrix();
  };
  for (int i = 0; i < steps; ++i) {
    const Eigen::VectorXd k1 = f(t), k2 = f(t + h / 2 * k1), k3 = f(t + h / 2 * k2),
                          k4 = f(t + h * k3);
    t += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return t;
}

TEST(ThermalNetwork, SingleNodeMatchesTheClosedForm) {
  ThermalNetwork n;
  const int b = n.AddBoundary("hall");
  const int a = n.AddNode("a", 1000);
  n.CoupleBoundary(a, b, 10);
  n.Finalize();
  const Propagator p(n, 100);
  Eigen::VectorXd t = Eigen::VectorXd::Constant(1, 20);
  for (int k = 1; k <= 5; ++k) {
    t = p.Step(t, Eigen::VectorXd::Constant(1, 20), Eigen::VectorXd::Constant(1, 50));
    EXPECT_NEAR(t(0), 20 + 5 * (1 - std::exp(-10.0 * 100 * k / 1000)), 1e-12);
  }
}

TEST(ThermalNetwork, TwoNodesMatchRungeKutta) {
  ThermalNetwork n;
  const int hall = n.AddBoundary("hall");
  const int a = n.AddNode("a", 2e3), b = n.AddNode("b", 5e4);
  n.Couple(a, b, 7);
  n.CoupleBoundary(b, hall, 3);
  n.Finalize();
  const Eigen::VectorXd tb = Eigen::VectorXd::Constant(1, 21);
  const Eigen::Vector2d q(120, 0), t0(20, 25);
  const Eigen::VectorXd exact = Propagator(n, 3600).Step(t0, tb, q);
  const Eigen::VectorXd reference = Rk4(n, t0, tb, q, 3600, 20000);
  EXPECT_NEAR(exact(0), reference(0), 1e-9);
  EXPECT_NEAR(exact(1), reference(1), 1e-9);
}

TEST(ThermalNetwork, LongRunReachesTheSteadyState) {
  ThermalNetwork n;
  const int hall = n.AddBoundary("hall");
  const int a = n.AddNode("a", 1e3), b = n.AddNode("b", 3e3), c = n.AddNode("c", 500);
  n.Couple(a, b, 4);
  n.Couple(b, c, 2);
  n.CoupleBoundary(c, hall, 1.5);
  n.CoupleBoundary(a, hall, 0.5);
  n.Finalize();
  const Eigen::VectorXd tb = Eigen::VectorXd::Constant(1, 19);
  const Eigen::Vector3d q(30, 0, 10);
  const Eigen::VectorXd ss = n.SteadyState(tb, q);
  // G T = G_b T_b + Q
  EXPECT_LT((n.conductance() * ss - n.boundary_conductance() * tb - q).norm(), 1e-10);
  Eigen::VectorXd t = Eigen::Vector3d(19, 19, 19);
  const Propagator p(n, 3600);
  for (int i = 0; i < 200; ++i) t = p.Step(t, tb, q);
  EXPECT_LT((t - ss).norm(), 1e-9);
}

TEST(ThermalNetwork, EnergyBalanceOverADay) {
  const FieldMachine m(DefaultFieldMachine(), 7);
  const ThermalNetwork& n = m.network();
  Eigen::VectorXd t = n.SteadyState(Eigen::Vector2d(20, 25), Eigen::VectorXd::Zero(n.nodes()));
  const Eigen::VectorXd start = t;
  const Propagator p(n, 10);
  double heat_in = 0, heat_out = 0;
  const Eigen::VectorXd gb_row = n.boundary_conductance().rowwise().sum();
  for (int k = 0; k < 8640; ++k) {  // 24 h, sources switched every 2 h
    Eigen::VectorXd q = Eigen::VectorXd::Zero(n.nodes());
    if ((k / 720) % 2 == 0) q(0) = 400, q(5) = 20, q(10) = 3;
    const Eigen::Vector2d tb(20 + 0.5 * std::sin(k / 1000.0), 25);
    const Eigen::VectorXd next = p.Step(t, tb, q);
    // Losses to the boundaries, trapezoid in time (error O(dt^2) against the exact integral).
    const Eigen::VectorXd mean = 0.5 * (t + next);
    heat_out += 10 * (gb_row.cwiseProduct(mean) - n.boundary_conductance() * tb).sum();
    heat_in += 10 * q.sum();
    t = next;
  }
  const double stored = n.capacity().dot(t - start);
  EXPECT_NEAR(stored, heat_in - heat_out, 1e-6 * heat_in);
}

TEST(ThermalNetwork, NodeWithoutPathToABoundaryIsAnInputError) {
  ThermalNetwork n;
  const int hall = n.AddBoundary("hall");
  const int a = n.AddNode("a", 1e3);
  n.AddNode("island", 1e3);
  n.CoupleBoundary(a, hall, 1);
  try {
    n.Finalize();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'island'"), std::string::npos) << e.what();
  }
}

// The Z screw as a fin: heat at its fixed end decays with the fin's length 1/m, m = sqrt(h P /
// (k A)); in steady state all of it leaves through the surface, so integral dT ds = Q / (h P).
TEST(FieldMachine, ScrewHeatStaysLocalAsAFin) {
  FieldMachineConfig c = DefaultFieldMachine();
  c.capacity_spread = c.conductance_spread = c.length_spread = 0;
  const FieldMachine m(c, 1);
  const ThermalNetwork& n = m.network();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n.nodes());
  const int cell0 = n.NodeIndex("z_screw_0");
  q(cell0) = 2.0;
  const Eigen::VectorXd t = n.SteadyState(Eigen::Vector2d(20, 25), q);
  const double d = c.z.screw_diameter_mm / 1000, area = M_PI * d * d / 4;
  const double hp = c.z.screw_air_h * M_PI * d, fin_m = std::sqrt(hp / (c.steel_conductivity * area));
  // Decay per 0.1 m cell far from both ends equals exp(-m dx) within 2 %.
  const double ratio = (t(cell0 + 4) - 20) / (t(cell0 + 3) - 20);
  EXPECT_NEAR(ratio, std::exp(-fin_m * 0.1), 0.02 * ratio);
  // The growth beyond 1.5 m from the fixed end no longer depends on z (an offset, not a slope;
  // at 1 m the 0.1 m cells still carry 1.2 % of the fixed end's rise).
  const double near = m.Error(t, c.z.fixed_end_mm - 1500).z_um;
  const double far = m.Error(t, c.z.fixed_end_mm - 5000).z_um;
  EXPECT_NEAR(near, far, 0.01 * std::abs(far));
  EXPECT_GT(std::abs(far), 0.1);
}

// Linear-scale feedback: the screw, nut and Z motor leave the position loop; the error is the
// scale and bed integral alone (hand-computed on a uniform bed).
TEST(FieldMachine, LinearScaleIgnoresTheScrew) {
  FieldMachineConfig c = DefaultFieldMachine();
  c.z.feedback = ZFeedback::kScale;
  const FieldMachine m(c, 3);
  const ThermalNetwork& n = m.network();
  Eigen::VectorXd t = Eigen::VectorXd::Constant(n.nodes(), 20);
  for (int i = 0; i < c.bed.cells; ++i) t(n.NodeIndex("bed_" + std::to_string(i))) = 21;
  const double z = 4300;
  const double expected = -1e3 * (c.z.scale_expansion_per_k * (z - c.z.scale_datum_mm) +
                                  c.bed_expansion_per_k * c.z.scale_datum_mm);
  EXPECT_NEAR(m.Error(t, z).z_um, expected, 1e-9);
  Eigen::VectorXd hot = t;
  for (int i = 0; i < c.z.screw_cells; ++i) hot(n.NodeIndex("z_screw_" + std::to_string(i))) += 5;
  hot(n.NodeIndex("z_motor")) += 10;
  hot(n.NodeIndex("z_fixed_bearing")) += 10;
  EXPECT_EQ(m.Error(hot, z).z_um, m.Error(t, z).z_um);
  // With screw feedback the same screw heat moves the tool: the test above can fail.
  FieldMachineConfig screw = c;
  screw.z.feedback = ZFeedback::kScrew;
  const FieldMachine ms(screw, 3);
  EXPECT_GT(std::abs(ms.Error(hot, z).z_um - ms.Error(t, z).z_um), 10);
}

}  // namespace
}  // namespace whirl::machine
