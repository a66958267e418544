#pragma once
// The field machine: the whirling machine as a lumped thermal network (network.h) whose tool error
// is a fixed linear functional of node temperatures. Every magnitude, its reasoning and its source
// are in docs/machine-truth.md; the defaults below are those values.
//
// Nodes (ThermalNetwork names):
//   head      ring_bearing, ring_motor, ring_belt, head_housing; carriage
//   Z drive   z_motor, z_fixed_bearing, z_screw_0 .. z_screw_<n-1> (cells of screw_cell_mm from
//             the fixed end towards the chuck)
//   bed       bed_0 .. bed_<n-1> (cells of bed_cell_mm from bed_start_mm)
//   z_nut     not in the network: driven one way by the screw cell under it (first order, held
//             input), so the network stays time-invariant while the nut moves
//   boundary  hall, cabinet (cabinet air = cabinet_base_c + cabinet_hall_gain (hall - 20))
//
// Tool error m(t, z), um, positive = the groove lands further towards the chuck (compare/cut.h),
// z = tool distance from the chuck face, mm:
//   head  m_head = head_sign 1e6 sum_j alpha_s L_j (T_j - 20) over ring_bearing, head_housing,
//         carriage (the structural loop along Z from the nut bracket to the cutter plane);
//   Z, screw feedback: m_z = 1e6 [alpha_s int_{fixed end}^{nut} (T_screw - 20) ds
//                               - alpha_b int_0^{z_fixed} (T_bed(x) - 20) dx]
//         (screw growth towards the chuck minus the bed moving the fixed bearing away);
//   Z, linear scale:   m_z = -1e6 [alpha_sc int_{datum}^{z} (T_bed - 20) dx
//                               + alpha_b int_0^{datum} (T_bed - 20) dx]
//         (the screw leaves the position loop; a rigidly mounted scale follows the bed).
// Partial cells are interpolated (cell temperatures piecewise constant). Bryan, "International
// status of thermal error research (1990)", CIRP Annals 39(2): only differential expansion
// against the 20 degC reference matters; HEIDENHAIN, Technical Information "Accuracy of Feed
// Axes": a linear encoder removes the screw's expansion from the position loop.
#include <cstdint>
#include <string>
#include <vector>

#include "machine/network.h"
#include "machine/sensors.h"

namespace whirl::machine {

enum class ZFeedback { kScrew, kScale };
std::string ToString(ZFeedback f);            ///< "screw", "scale"
ZFeedback ParseZFeedback(const std::string&);  ///< inverse; InputError otherwise

/// Head group (whirling unit on the carriage). Capacities J/K, conductances W/K, powers W.
struct HeadParams {
  double bearing_capacity = 7e3, motor_capacity = 2.8e4, belt_capacity = 9e3;
  double housing_capacity = 2e5, carriage_capacity = 7.5e5;
  double bearing_housing = 80, motor_housing = 10, motor_air = 12, belt_housing = 8, belt_air = 6;
  double housing_air = 60, housing_carriage = 40, carriage_air = 25;
  double ref_ring_rpm = 667;      ///< n_ref (180 m/min on the 86 mm tool circle)
  double bearing_power = 400;     ///< ring bearing friction at n_ref, x (n/n_ref)^(5/3) (Palmgren)
  double motor_power = 500;       ///< ring drive no-load losses at n_ref, x (n/n_ref)^1.5
  double motor_cut_share = 0.05;  ///< + this share of P_cut (copper losses under load)
  double belt_power = 150;        ///< belt / gear losses at n_ref, x n/n_ref
  double tool_heat_share = 0.08;  ///< share of P_cut reaching the ring bearing via the tools
  double rated_drive_kw = 20;     ///< rated ring drive power (for ring_load_pct)
  double length_bearing_m = 0.03, length_housing_m = 0.12, length_carriage_m = 0.03;
  int sign = 1;                   ///< +1: head growth moves the tool towards the chuck
};

/// Z drive, screw and nut.
struct ZDriveParams {
  ZFeedback feedback = ZFeedback::kScrew;
  double fixed_end_mm = 6400;     ///< z of the fixed bearing (the screw grows from here)
  double screw_lead_mm = 20;      ///< lead of the Z feed screw
  double screw_diameter_mm = 63;
  int screw_cells = 66;
  double screw_cell_mm = 100;
  double motor_capacity = 1.2e4, bearing_capacity = 7e3, nut_capacity = 4.6e3;
  double motor_bearing = 2, bearing_bed = 3, bearing_screw = 3, motor_air = 3, bearing_air = 2;
  double screw_air_h = 12;        ///< W/(m^2 K), convection of the screw surface
  double nut_screw = 3, nut_air = 1;
  double motor_hold_power = 20;   ///< W while power is on (servo holding)
  double motor_power_per_100mm_min = 0.5;  ///< W per 100 mm/min of feed
  double bearing_torque_nm = 1.0;  ///< support bearing drag, T_b
  double nut_torque_nm = 1.5;      ///< preload + seal drag of the nut, T_n (half into the nut)
  double scale_datum_mm = 300;     ///< linear scale fixed point
  double scale_expansion_per_k = 10e-6;  ///< alpha_sc
};

/// Bed and the process heat that reaches it.
struct BedParams {
  int cells = 9;
  double cell_mm = 800;
  double start_mm = -400;
  double cell_capacity = 6e5, cell_air = 45, axial = 16;
  double chip_share = 0.05;        ///< share of P_cut left on the bed cell under the cut
  double headstock_power = 150;    ///< bed_0 while the workpiece turns (cutting)
};

struct FieldMachineConfig {
  std::string name = "whirling-field-machine";
  HeadParams head;
  ZDriveParams z;
  BedParams bed;
  double steel_expansion_per_k = 11.5e-6;  ///< alpha_s
  double bed_expansion_per_k = 10.5e-6;    ///< alpha_b (cast iron)
  double steel_conductivity = 38, steel_density = 7810, steel_heat = 465;  ///< screw material
  double cabinet_base_c = 25, cabinet_hall_gain = 0.3;
  double blank_tau_min = 45;  ///< a blank stored in the hall follows it with this lag (truth.h)
  /// > 0: each blank's own lag from its diameter instead of blank_tau_min, tau = rho c D / (4 h)
  /// (a long steel cylinder losing heat through its mantle; rho, c = steel_density,
  /// steel_heat; h in W/(m^2 K), 0..100; docs/machine-truth.md). 0: blank_tau_min (default).
  double blank_h_w_m2k = 0;
  /// Stock from a store or the gate: a blank's temperature at the cut start is the hall's
  /// lagged temperature plus N(0, this) K drawn per screw (0..10; 0: stored in the hall, the
  /// default).
  double stock_offset_std_k = 0;
  /// A contact thermometer on each blank at clamping (the start of its set-up): < 0 none (the
  /// default); 0..2: the reading, the blank's temperature then + N(0, this) K, is logged as the
  /// sensor column blank_contact_C from the clamping until the next one (20 before the day's
  /// first), instruments.h DayLog. A shop's surface probe reads to a few tenths of a K.
  double blank_contact_std_k = -1;
  double capacity_spread = 0.10;    ///< per machine: capacities x (1 + this N)
  double conductance_spread = 0.15; ///< per machine: conductances and source powers
  double length_spread = 0.10;      ///< per machine: the head's lengths L_j
  double power_spread = 0.10;       ///< per day: cutting power factor
  std::vector<FieldSensorSpec> sensors = DefaultSensorSpecs();
  SensorNoise noise;
  void Validate(const std::string& where) const;
};

FieldMachineConfig DefaultFieldMachine();

/// Error parts of one state, um.
struct ErrorParts {
  double head_um = 0;
  double z_um = 0;    ///< the Z-axis term (screw minus bed, or the scale term)
  double total() const { return head_um + z_um; }
};

/// One drawn machine: the network with its per-machine factors, the nut, the drawn sensors.
class FieldMachine {
 public:
  /// Draws the per-machine factors (MixSeed streams of machine_seed) and builds the network.
  FieldMachine(const FieldMachineConfig& config, std::uint64_t machine_seed);
  const FieldMachineConfig& config() const { return config_; }  ///< with the factors applied
  const ThermalNetwork& network() const { return network_; }
  const std::vector<DrawnSensor>& sensors() const { return sensors_; }
  std::uint64_t seed() const { return seed_; }
  /// m parts for node temperatures T, nut position z_mm.
  ErrorParts Error(const Eigen::VectorXd& t_c, double z_mm) const;
  /// Index of the screw cell under the nut at tool position z_mm (clamped to the screw).
  int ScrewCellAt(double z_mm) const;
  /// Index of the bed cell at z_mm (clamped).
  int BedCellAt(double z_mm) const;
  int node(const std::string& name) const { return network_.NodeIndex(name); }

 private:
  void Build();
  FieldMachineConfig config_;
  ThermalNetwork network_;
  std::vector<DrawnSensor> sensors_;
  std::uint64_t seed_;
};

}  // namespace whirl::machine
