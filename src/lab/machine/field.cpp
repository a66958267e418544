#include "machine/field.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"

namespace whirl::machine {

namespace {

// Integral over [a, b] (mm) of a piecewise-constant profile: cell i covers [x0 + i dx, x0 +
// (i + 1) dx); outside the cells the nearest cell's value continues. Returns value x mm.
double CellIntegral(const Eigen::VectorXd& excess, int first, int cells, double x0, double dx,
                    double a, double b) {
  const double sign = b >= a ? 1.0 : -1.0;
  const double lo = std::min(a, b), hi = std::max(a, b);
  double sum = 0;
  for (int i = 0; i < cells; ++i) {
    double c_lo = x0 + i * dx, c_hi = c_lo + dx;
    if (i == 0) c_lo = std::min(c_lo, lo);
    if (i == cells - 1) c_hi = std::max(c_hi, hi);
    const double overlap = std::min(hi, c_hi) - std::max(lo, c_lo);
    if (overlap > 0) sum += overlap * excess(first + i);
  }
  return sign * sum;
}

// Per-machine factor 1 + spread N, clamped to >= 0.3.
double Factor(Rng& rng, double spread) { return std::max(0.3, 1.0 + spread * rng.Normal()); }

void DrawHead(HeadParams& h, const FieldMachineConfig& c, Rng& rng) {
  for (double* cap : {&h.bearing_capacity, &h.motor_capacity, &h.belt_capacity,
                      &h.housing_capacity, &h.carriage_capacity})
    *cap *= Factor(rng, c.capacity_spread);
  for (double* g : {&h.bearing_housing, &h.motor_housing, &h.motor_air, &h.belt_housing,
                    &h.belt_air, &h.housing_air, &h.housing_carriage, &h.carriage_air,
                    &h.bearing_power, &h.motor_power, &h.belt_power, &h.tool_heat_share})
    *g *= Factor(rng, c.conductance_spread);
  for (double* l : {&h.length_bearing_m, &h.length_housing_m, &h.length_carriage_m})
    *l *= Factor(rng, c.length_spread);
}

void DrawZAndBed(ZDriveParams& z, BedParams& b, const FieldMachineConfig& c, Rng& rng) {
  for (double* cap : {&z.motor_capacity, &z.bearing_capacity, &z.nut_capacity, &b.cell_capacity})
    *cap *= Factor(rng, c.capacity_spread);
  for (double* g : {&z.motor_bearing, &z.bearing_bed, &z.bearing_screw, &z.motor_air,
                    &z.bearing_air, &z.screw_air_h, &z.nut_screw, &z.nut_air,
                    &z.motor_hold_power, &z.bearing_torque_nm, &z.nut_torque_nm, &b.cell_air,
                    &b.axial, &b.headstock_power, &b.chip_share})
    *g *= Factor(rng, c.conductance_spread);
}

}  // namespace

std::string ToString(ZFeedback f) { return f == ZFeedback::kScale ? "scale" : "screw"; }

ZFeedback ParseZFeedback(const std::string& text) {
  if (text == "screw") return ZFeedback::kScrew;
  if (text == "scale") return ZFeedback::kScale;
  throw InputError("Z feedback '" + text + "': must be 'screw' or 'scale'");
}

FieldMachineConfig DefaultFieldMachine() { return {}; }

void FieldMachineConfig::Validate(const std::string& where) const {
  if (z.screw_cells < 2 || z.screw_cells > 400 || !(z.screw_cell_mm > 0))
    throw InputError(where + ": z.screw_cells must be 2-400 and z.screw_cell_mm > 0");
  if (bed.cells < 2 || bed.cells > 100 || !(bed.cell_mm > 0))
    throw InputError(where + ": bed.cells must be 2-100 and bed.cell_mm > 0");
  if (z.fixed_end_mm > bed.start_mm + bed.cells * bed.cell_mm || z.fixed_end_mm <= 0)
    throw InputError(where + ": z.fixed_end_mm must lie on the bed");
  if (head.sign != 1 && head.sign != -1) throw InputError(where + ": head.sign must be +1 or -1");
  for (double s : {capacity_spread, conductance_spread, length_spread, power_spread})
    if (!(s >= 0 && s <= 1)) throw InputError(where + ": spreads must be in [0, 1]");
  if (!(blank_h_w_m2k >= 0 && blank_h_w_m2k <= 100))
    throw InputError(where + ": blank_h_w_m2k = " + std::to_string(blank_h_w_m2k) +
                     ": must be within 0..100 W/(m^2 K)");
  if (!(stock_offset_std_k >= 0 && stock_offset_std_k <= 10))
    throw InputError(where + ": stock_offset_std_k = " + std::to_string(stock_offset_std_k) +
                     ": must be within 0..10 K");
  if (!(blank_contact_std_k < 0 || blank_contact_std_k <= 2))
    throw InputError(where + ": blank_contact_std_k = " + std::to_string(blank_contact_std_k) +
                     ": must be within 0..2 K (or negative: no contact reading)");
}

FieldMachine::FieldMachine(const FieldMachineConfig& config, std::uint64_t machine_seed)
    : config_(config), seed_(machine_seed) {
  config_.Validate("field machine '" + config.name + "'");
  Rng rng(MixSeed(machine_seed, 0x6669656c64));
  DrawHead(config_.head, config_, rng);
  DrawZAndBed(config_.z, config_.bed, config_, rng);
  Build();
}

void FieldMachine::Build() {
  const HeadParams& h = config_.head;
  const ZDriveParams& z = config_.z;
  const BedParams& b = config_.bed;
  ThermalNetwork& n = network_;
  const int hall = n.AddBoundary("hall");
  n.AddBoundary("cabinet");
  const int bearing = n.AddNode("ring_bearing", h.bearing_capacity);
  const int motor = n.AddNode("ring_motor", h.motor_capacity);
  const int belt = n.AddNode("ring_belt", h.belt_capacity);
  const int housing = n.AddNode("head_housing", h.housing_capacity);
  const int carriage = n.AddNode("carriage", h.carriage_capacity);
  n.Couple(bearing, housing, h.bearing_housing);
  n.Couple(motor, housing, h.motor_housing);
  n.CoupleBoundary(motor, hall, h.motor_air);
  n.Couple(belt, housing, h.belt_housing);
  n.CoupleBoundary(belt, hall, h.belt_air);
  n.CoupleBoundary(housing, hall, h.housing_air);
  n.Couple(housing, carriage, h.housing_carriage);
  n.CoupleBoundary(carriage, hall, h.carriage_air);
  const int zm = n.AddNode("z_motor", z.motor_capacity);
  const int zb = n.AddNode("z_fixed_bearing", z.bearing_capacity);
  n.Couple(zm, zb, z.motor_bearing);
  n.CoupleBoundary(zm, hall, z.motor_air);
  n.CoupleBoundary(zb, hall, z.bearing_air);
  const double d_m = z.screw_diameter_mm / 1000, dx_m = z.screw_cell_mm / 1000;
  const double area = kPi * d_m * d_m / 4;
  const double cell_cap = area * dx_m * config_.steel_density * config_.steel_heat;
  for (int i = 0; i < z.screw_cells; ++i) {
    const int cell = n.AddNode("z_screw_" + std::to_string(i), cell_cap);
    n.CoupleBoundary(cell, hall, z.screw_air_h * kPi * d_m * dx_m);
    if (i > 0) n.Couple(cell - 1, cell, config_.steel_conductivity * area / dx_m);
  }
  n.Couple(zb, n.NodeIndex("z_screw_0"), z.bearing_screw);
  for (int i = 0; i < b.cells; ++i) {
    const int cell = n.AddNode("bed_" + std::to_string(i), b.cell_capacity);
    n.CoupleBoundary(cell, hall, b.cell_air);
    if (i > 0) n.Couple(cell - 1, cell, b.axial);
  }
  n.Couple(zb, n.NodeIndex("bed_" + std::to_string(BedCellAt(z.fixed_end_mm))), z.bearing_bed);
  n.Finalize();
  (void)carriage;
  for (std::size_t i = 0; i < config_.sensors.size(); ++i) {
    DrawnSensor s;
    s.spec = DrawPlacement(config_.sensors[i], config_.noise, MixSeed(seed_, 0x5e00 + i), &s.gain,
                           &s.offset_k);
    if (s.spec.kind == "boundary") {
      s.index_a = s.spec.node_a == "hall" ? -2 : -3;
    } else if (s.spec.kind == "bed") {
      const double u = (s.spec.position_mm - b.start_mm) / b.cell_mm - 0.5;
      const double c = std::clamp(u, 0.0, b.cells - 1.0);
      s.bed_a = std::min(static_cast<int>(c), b.cells - 2);
      s.bed_b = s.bed_a + 1;
      s.bed_weight = 1.0 - (c - s.bed_a);
      s.bed_a = n.NodeIndex("bed_" + std::to_string(s.bed_a));
      s.bed_b = n.NodeIndex("bed_" + std::to_string(s.bed_b));
    } else {
      s.index_a = s.spec.node_a == "z_nut" ? kNutSensorIndex : n.NodeIndex(s.spec.node_a);
      if (s.spec.kind == "pair") s.index_b = n.NodeIndex(s.spec.node_b);
    }
    sensors_.push_back(s);
  }
}

int FieldMachine::ScrewCellAt(double z_mm) const {
  const double s = config_.z.fixed_end_mm - z_mm;
  const int i = static_cast<int>(std::floor(s / config_.z.screw_cell_mm));
  return std::clamp(i, 0, config_.z.screw_cells - 1);
}

int FieldMachine::BedCellAt(double z_mm) const {
  const int i = static_cast<int>(std::floor((z_mm - config_.bed.start_mm) / config_.bed.cell_mm));
  return std::clamp(i, 0, config_.bed.cells - 1);
}

ErrorParts FieldMachine::Error(const Eigen::VectorXd& t_c, double z_mm) const {
  const HeadParams& h = config_.head;
  const ZDriveParams& z = config_.z;
  const BedParams& b = config_.bed;
  const Eigen::VectorXd excess = t_c.array() - 20.0;
  const int bearing = 0, housing = 3, carriage = 4;  // Build() order
  ErrorParts parts;
  parts.head_um = h.sign * 1e6 * config_.steel_expansion_per_k *
                  (h.length_bearing_m * excess(bearing) + h.length_housing_m * excess(housing) +
                   h.length_carriage_m * excess(carriage));
  const int screw0 = 7, bed0 = screw0 + z.screw_cells;
  // integrals in K mm; x 1e-3 m/mm x 1e6 um/m = x 1e3
  if (z.feedback == ZFeedback::kScrew) {
    const double s_nut = std::clamp(z.fixed_end_mm - z_mm, 0.0, z.screw_cells * z.screw_cell_mm);
    const double screw = CellIntegral(excess, screw0, z.screw_cells, 0, z.screw_cell_mm, 0, s_nut);
    const double bed = CellIntegral(excess, bed0, b.cells, b.start_mm, b.cell_mm, 0, z.fixed_end_mm);
    parts.z_um = 1e3 * (config_.steel_expansion_per_k * screw - config_.bed_expansion_per_k * bed);
  } else {
    const double scale =
        CellIntegral(excess, bed0, b.cells, b.start_mm, b.cell_mm, z.scale_datum_mm, z_mm);
    const double base =
        CellIntegral(excess, bed0, b.cells, b.start_mm, b.cell_mm, 0, z.scale_datum_mm);
    parts.z_um = -1e3 * (z.scale_expansion_per_k * scale + config_.bed_expansion_per_k * base);
  }
  return parts;
}

}  // namespace whirl::machine
