// Sensors of the field machine (src/lab/machine/sensors.h): each reads its own location; noise,
// quantum and per-machine draws as documented.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/random.h"
#include "machine/instruments.h"
#include "machine/timeline.h"

namespace whirl::machine {
namespace {

// A machine with only the Z motor's holding heat (power on, nothing moves), a constant hall and
// ideal sensors (no noise, quantum, gain or offset).
MachineTimeline ZMotorOnly() {
  FieldMachineConfig c = DefaultFieldMachine();
  c.noise = SensorNoise{0, 0, 0, 0, 0, 0, 0};
  c.head.bearing_power = c.head.motor_power = c.head.belt_power = 0;
  c.bed.headstock_power = 0;
  const FieldMachine machine(c, 11);
  HallOptions flat;
  flat.amplitude_k = flat.ou_std_k = flat.day_offset_std_k = 0;
  const HallProfile hall(flat, 0, 1, 5);
  DayPlan day = WarmupTestDay(0, 11, 360, 0.0, 480, 0);
  return SimulateCalendar(machine, hall, {day});
}

TEST(FieldSensors, ASensorReadsItsOwnLocation) {
  const MachineTimeline tl = ZMotorOnly();
  const drift::Run log = DayLog(tl, 0, {}, 3);
  ASSERT_GT(log.samples(), 400);
  const int last = log.samples() - 1;
  for (const char* head : {"head_motor_C", "head_bearing_C", "head_housing_C", "ring_gearbox_C"}) {
    const int s = log.SensorIndex(head);
    for (int k = 0; k < log.samples(); ++k) EXPECT_NEAR(log.temperature_C(k, s), 20.0, 1e-12) << head;
  }
  EXPECT_GT(log.temperature_C(last, log.SensorIndex("z_motor_C")) - 20, 0.3);
  EXPECT_GT(log.temperature_C(last, log.SensorIndex("z_fixed_bearing_C")) - 20, 0.1);
  EXPECT_EQ(log.temperature_C(last, log.SensorIndex("ambient_C")), 20.0);
}

TEST(FieldSensors, NoiseAndQuantumAsDocumented) {
  const SensorNoise noise;  // 0.1 K, 1/16 K
  DrawnSensor s;
  Rng rng(42);
  double sum = 0, sum2 = 0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    const double r = ReadSensor(s, noise, 23.3, rng.Normal());
    EXPECT_NEAR(r / noise.quantum_k, std::round(r / noise.quantum_k), 1e-9);
    sum += r, sum2 += r * r;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(sd, 0.1, 0.01);
  EXPECT_NEAR(mean, 23.3, 0.01);
}

TEST(FieldSensors, PerMachineDrawsWithinTheirRanges) {
  const SensorNoise noise;
  const auto specs = DefaultSensorSpecs();
  double g_sum2 = 0, o_sum2 = 0;
  int count = 0;
  std::set<double> distinct;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    const FieldMachine m(DefaultFieldMachine(), seed);
    ASSERT_EQ(m.sensors().size(), specs.size());
    for (std::size_t i = 0; i < specs.size(); ++i) {
      const DrawnSensor& s = m.sensors()[i];
      if (specs[i].kind == "pair") {
        EXPECT_LE(std::abs(s.spec.weight - std::clamp(specs[i].weight, 0.0, 1.0)), 0.15 + 1e-12);
        distinct.insert(s.spec.weight);
      }
      if (specs[i].kind == "bed") {
        EXPECT_LE(std::abs(s.spec.position_mm - specs[i].position_mm), 400);
      }
      EXPECT_GT(s.spec.tau_min, 0);
      g_sum2 += s.gain * s.gain, o_sum2 += s.offset_k * s.offset_k, ++count;
    }
  }
  EXPECT_NEAR(std::sqrt(g_sum2 / count), noise.gain_std, 0.1 * noise.gain_std);
  EXPECT_NEAR(std::sqrt(o_sum2 / count), noise.offset_std_k, 0.1 * noise.offset_std_k);
  EXPECT_GT(distinct.size(), 100u);  // placement differs from machine to machine
}

}  // namespace
}  // namespace whirl::machine
