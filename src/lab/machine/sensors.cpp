#include "machine/sensors.h"

#include <algorithm>
#include <cmath>

#include "core/random.h"

namespace whirl::machine {

namespace {

FieldSensorSpec Node(const std::string& name, const std::string& node, double tau_min) {
  FieldSensorSpec s;
  s.name = name;
  s.kind = "node";
  s.node_a = node;
  s.tau_min = tau_min;
  return s;
}

FieldSensorSpec Pair(const std::string& name, const std::string& a, const std::string& b, double w,
                double tau_min) {
  FieldSensorSpec s = Node(name, a, tau_min);
  s.kind = "pair";
  s.node_b = b;
  s.weight = w;
  return s;
}

FieldSensorSpec Bed(const std::string& name, double position_mm, double tau_min) {
  FieldSensorSpec s;
  s.name = name;
  s.kind = "bed";
  s.position_mm = position_mm;
  s.tau_min = tau_min;
  return s;
}

FieldSensorSpec Boundary(const std::string& name, const std::string& boundary, double tau_min) {
  FieldSensorSpec s = Node(name, boundary, tau_min);
  s.kind = "boundary";
  return s;
}

}  // namespace

std::vector<FieldSensorSpec> DefaultSensorSpecs() {
  // Lags: a sensor screwed into a bore or clamped to a surface follows it within minutes
  // (estimates); the air sensors are faster.
  return {Boundary("ambient", "hall", 2),
          Bed("bed_headstock", 400, 5),
          Bed("bed_middle", 3200, 5),
          Bed("bed_tailstock", 6000, 5),
          Bed("chip_tray", 2500, 3),
          Pair("head_motor", "ring_motor", "head_housing", 0.8, 5),
          Pair("head_bearing", "ring_bearing", "head_housing", 0.6, 5),
          Node("head_housing", "head_housing", 5),
          Pair("ring_gearbox", "ring_belt", "head_housing", 0.8, 5),
          Node("z_nut", "z_nut", 5),
          Pair("z_fixed_bearing", "z_fixed_bearing", "z_motor", 0.8, 5),
          Pair("z_motor", "z_motor", "z_fixed_bearing", 0.9, 5),
          Boundary("cabinet", "cabinet", 3)};
}

FieldSensorSpec DrawPlacement(const FieldSensorSpec& nominal, const SensorNoise& noise, std::uint64_t seed,
                         double* gain, double* offset_k) {
  Rng rng(seed);
  FieldSensorSpec s = nominal;
  const double dw = rng.Uniform(-noise.placement_spread, noise.placement_spread);
  const double dx = rng.Uniform(-noise.position_spread_mm, noise.position_spread_mm);
  if (s.kind == "pair") s.weight = std::clamp(s.weight + dw, 0.0, 1.0);
  if (s.kind == "bed") s.position_mm += dx;
  s.tau_min *= std::exp(noise.tau_log_std * rng.Normal());
  *gain = noise.gain_std * rng.Normal();
  *offset_k = noise.offset_std_k * rng.Normal();
  return s;
}

double ReadSensor(const DrawnSensor& sensor, const SensorNoise& noise, double lagged_c,
                  double normal) {
  const double t = 20.0 + sensor.offset_k + (1.0 + sensor.gain) * (lagged_c - 20.0) +
                   noise.noise_std_k * normal;
  if (noise.quantum_k <= 0) return t;
  return noise.quantum_k * std::round(t / noise.quantum_k);
}

}  // namespace whirl::machine
