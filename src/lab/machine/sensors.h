#pragma once
// Temperature sensors of the field machine. A sensor reads the temperature of its own location
// (never a mix of heat sources): one network node, a point between two nodes, or a position along
// the bed. Reading at control sample k:
//   y_k = first-order lag (tau) of T_loc (exact for T_loc held over a step),
//   T_read = 20 + offset + (1 + gain) (y_k - 20) + N(0, noise_std_k^2), rounded to quantum_k.
// Per machine drawn once (DrawSensor): placement weight w + U(-0.15, 0.15) (clamped to [0, 1]),
// bed position + U(-400, 400) mm, tau x lognormal(0, 0.4), gain N(0, 0.02), offset N(0, 0.3 K).
// Sources: noise of the order of 0.1 K (a PLC analog input in a shop: estimate); quantum 1/16 K
// of a 12-bit digital sensor (Maxim DS18B20 datasheet); offset of a class A PT100
// +-(0.15 + 0.002 |t|) K (IEC 60751); lags, placement and gain spread: estimates.
#include <cstdint>
#include <string>
#include <vector>

namespace whirl::machine {

/// Where a sensor sits. kind "node": `node_a`; "pair": w T(node_a) + (1 - w) T(node_b);
/// "bed": the bed at position_mm (linear between cell centres); "boundary": hall or cabinet air.
struct FieldSensorSpec {
  std::string name;      ///< column name without the _C suffix (names of the 840D profile)
  std::string kind = "node";
  std::string node_a, node_b;
  double weight = 1.0;   ///< w towards node_a ("pair")
  double position_mm = 0;  ///< "bed"
  double tau_min = 5;    ///< nominal lag, min (> 0)
};

struct SensorNoise {
  double noise_std_k = 0.1;       ///< sigma per reading, K
  double quantum_k = 0.0625;      ///< resolution, K (0 = none)
  double placement_spread = 0.15; ///< w +- this (uniform)
  double position_spread_mm = 400;///< bed position +- this (uniform)
  double tau_log_std = 0.4;       ///< tau x exp(N(0, this))
  double gain_std = 0.02;         ///< gain N(0, this)
  double offset_std_k = 0.3;      ///< offset N(0, this), K
};

/// DrawnSensor::index_a of a sensor on the Z nut (not a network node, see field.h).
inline constexpr int kNutSensorIndex = -1000;

/// A sensor as mounted on one machine (resolved node indices, drawn errors).
struct DrawnSensor {
  FieldSensorSpec spec;        ///< with the drawn weight / position / tau
  int index_a = -1, index_b = -1;  ///< network node indices (-1: unused); boundary: -2 - index
  int bed_a = -1, bed_b = -1;      ///< "bed": the two cells and weight towards bed_a
  double bed_weight = 1.0;
  double gain = 0, offset_k = 0;
};

/// The 13 default sensors: ambient (hall, 2 min), bed_headstock (bed 400 mm), bed_middle
/// (3200), bed_tailstock (6000), chip_tray (bed 2500, 3 min), head_motor (motor|housing 0.8),
/// head_bearing (bearing|housing 0.6), head_housing, ring_gearbox (belt|housing 0.8), z_nut,
/// z_fixed_bearing (bearing|motor 0.8), z_motor (motor|bearing 0.9), cabinet (cabinet air).
std::vector<FieldSensorSpec> DefaultSensorSpecs();

/// Placement, lag, gain and offset of one sensor on one machine (stream of the machine's seed).
FieldSensorSpec DrawPlacement(const FieldSensorSpec& nominal, const SensorNoise& noise, std::uint64_t seed,
                         double* gain, double* offset_k);

/// Reading of a lagged location temperature y (degC) through the sensor's gain/offset, the noise
/// value `normal` (a standard normal draw) and the quantum.
double ReadSensor(const DrawnSensor& sensor, const SensorNoise& noise, double lagged_c,
                  double normal);

}  // namespace whirl::machine
