#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"

namespace whirl::sim {
namespace {

// Double antiderivative of the indicator of (lo, hi): R'' = 1(lo < u < hi), R(u) = 0 for u <= lo.
double BoxR(double u, double lo, double hi) {
  if (u <= lo) return 0.0;
  if (u <= hi) return 0.5 * (u - lo) * (u - lo);
  return 0.5 * (hi - lo) * (hi - lo) + (hi - lo) * (u - hi);
}

// Integral over s in [s0, s1] of the overlap length of the box [s - w/2, s + w/2] with the cell
// [a, b] (all in metres): R(s1 - a) - R(s1 - b) - R(s0 - a) + R(s0 - b) with the box (-w/2, w/2).
double SweptOverlap(double s0, double s1, double w, double a, double b) {
  const double lo = -0.5 * w, hi = 0.5 * w;
  return BoxR(s1 - a, lo, hi) - BoxR(s1 - b, lo, hi) - BoxR(s0 - a, lo, hi) + BoxR(s0 - b, lo, hi);
}

// Tridiagonal system with constant coefficients, factored once (Thomas algorithm).
class Tridiagonal {
 public:
  // sub[i] couples i to i-1 (sub[0] unused), super[i] couples i to i+1 (super[n-1] unused).
  Tridiagonal(const std::vector<double>& sub, const std::vector<double>& diag,
              const std::vector<double>& super)
      : sub_(sub), cp_(diag.size()), inv_(diag.size()) {
    const std::size_t n = diag.size();
    double prev_cp = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double denom = diag[i] - (i > 0 ? sub[i] * prev_cp : 0.0);
      inv_[i] = 1.0 / denom;
      cp_[i] = (i + 1 < n ? super[i] : 0.0) * inv_[i];
      prev_cp = cp_[i];
    }
  }
  // Solves in place: rhs -> solution.
  void Solve(std::vector<double>& x) const {
    const std::size_t n = x.size();
    x[0] *= inv_[0];
    for (std::size_t i = 1; i < n; ++i) x[i] = (x[i] - sub_[i] * x[i - 1]) * inv_[i];
    for (std::size_t i = n - 1; i-- > 0;) x[i] -= cp_[i] * x[i + 1];
  }

 private:
  std::vector<double> sub_, cp_, inv_;
};

void CheckOption(bool ok, const char* field, double value, const char* rule) {
  if (!ok)
    throw InputError(std::string("simulation options: ") + field + " = " + FormatNumber(value) +
                     " breaks the rule: " + rule);
}

// Every rule of SimOptions and its PhysicsConstants that the simulation itself relies on.
void CheckSimOptions(const SimOptions& options) {
  CheckOption(options.cell_size_mm > 0 && std::isfinite(options.cell_size_mm), "cell_size_mm",
              options.cell_size_mm, "must be positive");
  CheckOption(options.time_step_s > 0 && std::isfinite(options.time_step_s), "time_step_s",
              options.time_step_s, "must be positive");
  CheckOption(options.sample_interval_s > 0 && std::isfinite(options.sample_interval_s),
              "sample_interval_s", options.sample_interval_s, "must be positive");
  CheckOption(options.duration_s >= 0 && std::isfinite(options.duration_s), "duration_s",
              options.duration_s, "must be >= 0 (0 = whole thread)");
  const PhysicsConstants& ph = options.physics;
  CheckOption(ph.density_kg_m3 > 0, "physics.density_kg_m3", ph.density_kg_m3, "must be positive");
  CheckOption(ph.specific_heat_j_kg_k > 0, "physics.specific_heat_j_kg_k", ph.specific_heat_j_kg_k,
              "must be positive");
  CheckOption(ph.conductivity_w_m_k > 0, "physics.conductivity_w_m_k", ph.conductivity_w_m_k,
              "must be positive");
  CheckOption(ph.heat_transfer_coefficient_w_m2_k >= 0, "physics.heat_transfer_coefficient_w_m2_k",
              ph.heat_transfer_coefficient_w_m2_k, "must be >= 0");
}

// The per-workpiece disturbances, drawn from `rng` in the documented order (DisturbanceOptions):
// the three draws are made whenever disturbances are enabled, whichever of them is used.
AppliedDisturbances DrawDisturbances(const DisturbanceOptions& d, Rng& rng) {
  AppliedDisturbances dist;
  if (!d.enabled) return dist;
  const double n_heat = rng.Normal(), n_alpha = rng.Normal(), n_drift = rng.Normal();
  if (d.workpiece_variation) {
    dist.heat_partition_factor = std::max(0.0, 1.0 + d.heat_partition_rel_std * n_heat);
    dist.expansion_factor = std::max(0.0, 1.0 + d.expansion_rel_std * n_alpha);
  }
  if (d.ambient_drift)
    dist.ambient_drift_k_per_h = std::isfinite(d.ambient_drift_fixed_k_per_h)
                                     ? d.ambient_drift_fixed_k_per_h
                                     : d.ambient_drift_std_k_per_h * n_drift;
  if (d.measurement_noise) dist.measurement_noise_std_um = d.measurement_noise_std_um;
  return dist;
}

// The blank as n finite-volume cells of length dx from the chuck face, with the heat capacity of a
// cell and the conductances that couple the cells, the chuck, the free end and the air (SI units).
struct Rod {
  int n = 0;
  double dx = 0;       // m
  double cap = 0;      // J/K per cell
  double g = 0;        // W/K between neighbouring cells
  double g_chuck = 0;  // W/K, centre of cell 0 to the chuck face held at ambient
  double g_end = 0;    // W/K, centre of the last cell through the free end face to the air
  double g_surf = 0;   // W/K, one cell's surface to the air
};

// Discretizes the blank; a cell size giving fewer than 3 or more than kMaxCells cells is refused.
Rod DiscretizeRod(const screw::Screw& screw, const PhysicsConstants& ph, double cell_size_mm) {
  const double length_m = screw.length_mm * 1e-3;
  const double cells = std::round(screw.length_mm / cell_size_mm);
  if (!(cells >= 3 && cells <= kMaxCells))
    throw InputError("simulation options: cell_size_mm = " + FormatNumber(cell_size_mm) +
                     " gives " + FormatNumber(cells) + " cells on the " +
                     FormatNumber(screw.length_mm) + " mm blank; the rule (resource limit): 3 to " +
                     FormatNumber(kMaxCells) + " cells, i.e. cell_size_mm within [" +
                     FormatNumber(screw.length_mm / kMaxCells) + ", " +
                     FormatNumber(screw.length_mm / 3) + "] mm");
  Rod rod;
  rod.n = static_cast<int>(cells);
  rod.dx = length_m / rod.n;
  const double d_m = screw.process.diameter_mm * 1e-3;
  const double area = kPi * d_m * d_m / 4.0;
  const double perimeter = kPi * d_m;
  rod.cap = ph.density_kg_m3 * ph.specific_heat_j_kg_k * area * rod.dx;
  rod.g = ph.conductivity_w_m_k * area / rod.dx;
  rod.g_chuck = 2.0 * rod.g;
  const double hh = ph.heat_transfer_coefficient_w_m2_k;
  rod.g_end = hh > 0 ? 1.0 / (1.0 / (hh * area) + 1.0 / (2.0 * rod.g)) : 0.0;
  rod.g_surf = hh * perimeter * rod.dx;
  return rod;
}

// The time grid: n_steps steps of dt up to the requested duration or the thread end, a sample
// every steps_per_sample steps (and at the last step).
struct TimeGrid {
  double dt = 0;  // s
  long n_steps = 0;
  long steps_per_sample = 1;
  SimTermination termination = SimTermination::kReachedThreadEnd;
};

// Plans the time steps; more than kMaxTimeSteps steps or kMaxCellSteps cell-steps are refused.
TimeGrid PlanTimeGrid(const screw::Kinematics& kin, const SimOptions& options, int n_cells) {
  TimeGrid grid;
  grid.dt = options.time_step_s;
  const double dt = grid.dt;
  double t_end = kin.cutting_time_s;
  grid.termination = SimTermination::kReachedThreadEnd;
  if (options.duration_s > 0 && options.duration_s < kin.cutting_time_s) {
    t_end = options.duration_s;
    grid.termination = SimTermination::kReachedDuration;
  }
  const double steps = std::max(1.0, std::floor(t_end / dt + 1e-9));
  if (!(steps <= kMaxTimeSteps && steps * n_cells <= kMaxCellSteps))
    throw InputError("simulation options: " + FormatNumber(t_end) +
                     " s of cutting at time_step_s = " + FormatNumber(dt) + " is " +
                     FormatNumber(steps) + " steps x " + std::to_string(n_cells) +
                     " cells; the rule (resource limit): at most " + FormatNumber(kMaxTimeSteps) +
                     " steps and " + FormatNumber(kMaxCellSteps) +
                     " cell-steps (raise time_step_s or cell_size_mm, or shorten duration_s)");
  grid.n_steps = static_cast<long>(steps);
  grid.steps_per_sample =
      std::max(1L, static_cast<long>(std::lround(options.sample_interval_s / dt)));
  return grid;
}

// Elongation of the section [0, xc_m] of the rod, um: alpha times the integral of the
// piecewise-linear profile through (0, amb_k) and the cell centres (theta), up to xc_m.
double ElongationUm(const std::vector<double>& theta, const Rod& rod, double alpha, double xc_m,
                    double amb_k) {
  const double xc = xc_m, dx = rod.dx;
  double integral = 0.0;
  double x_prev = 0.0, th_prev = amb_k;
  for (int i = 0; i < rod.n; ++i) {
    const double x_i = (i + 0.5) * dx;
    if (x_i >= xc) {
      const double f = (xc - x_prev) / (x_i - x_prev);
      const double th_c = th_prev + f * (theta[i] - th_prev);
      integral += 0.5 * (th_prev + th_c) * (xc - x_prev);
      return alpha * integral * 1e6;
    }
    integral += 0.5 * (th_prev + theta[i]) * (x_i - x_prev);
    x_prev = x_i;
    th_prev = theta[i];
  }
  // Cut point in the last half cell: hold the last centre value.
  integral += th_prev * (xc - x_prev);
  return alpha * integral * 1e6;
}

// Heat flow from the rod to the air and the chuck at the ambient rise amb_k, W.
double LossRateW(const std::vector<double>& theta, const Rod& rod, double amb_k) {
  const int n = rod.n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += theta[i] - amb_k;
  return rod.g_surf * sum + rod.g_chuck * (theta[0] - amb_k) + rod.g_end * (theta[n - 1] - amb_k);
}

// A heat source of uniform power over an axial box that rides with the cut (the cut itself, a
// steady rest): its power, W, the box's width, m, and its distance from the cut towards the
// chuck, m.
struct MovingBox {
  double power_w = 0;
  double offset_m = 0;
  double width_m = 1e-9;
};

// Deposits moving boxes into the right-hand side of the heat balance: for a time window
// [w0, w1], each cell gets the box's overlap with it averaged over the window (SweptOverlap),
// normalised over the cells inside the blank so that all of the heat enters the workpiece.
class SourceDeposit {
 public:
  SourceDeposit(const Rod& rod, const screw::Kinematics& kin, double dt)
      : rod_(rod),
        x_start_m_(kin.thread_start_position_mm * 1e-3),
        v_m_s_(kin.axial_feed_mm_s * 1e-3),
        dt_(dt),
        share_(rod.n) {}

  // Adds the box's power averaged over [w0, w1] to rhs (W per cell); returns the energy, J.
  double Deposit(const MovingBox& box, double w0, double w1, std::vector<double>& rhs) {
    const double power = box.power_w, offset = box.offset_m, width = box.width_m;
    const double dx = rod_.dx, dt = dt_;
    if (!(power > 0)) return 0.0;
    const double energy = power * (w1 - w0);
    const double s0 = x_start_m_ - offset - v_m_s_ * w1, s1 = x_start_m_ - offset - v_m_s_ * w0;
    const double lo = s0 - 0.5 * width, hi = s1 + 0.5 * width;
    const int i0 = std::max(0, static_cast<int>(std::floor(lo / dx)));
    const int i1 = std::min(rod_.n - 1, static_cast<int>(std::floor(hi / dx)));
    double total = 0.0;
    for (int i = i0; i <= i1; ++i) {
      const double ov = s1 > s0 ? SweptOverlap(s0, s1, width, i * dx, (i + 1) * dx)
                                : std::max(0.0, std::min((i + 1) * dx, s0 + 0.5 * width) -
                                                    std::max(i * dx, s0 - 0.5 * width));
      share_[i] = ov;
      total += ov;
    }
    if (!(total > 0)) return 0.0;
    for (int i = i0; i <= i1; ++i) rhs[i] += energy / dt * share_[i] / total;
    return energy;
  }

 private:
  const Rod& rod_;
  double x_start_m_, v_m_s_, dt_;
  std::vector<double> share_;
};

// The rod's temperature rise over time: theta' C = -K theta + b with the constant conductance
// matrix K factored once for implicit Euler (the first step) and for BDF2 (every later step).
class RodStepper {
 public:
  RodStepper(const Rod& rod, double dt)
      : rod_(rod),
        dt_(dt),
        solve_ie_(Factor(rod, rod.cap / dt)),
        solve_bdf2_(Factor(rod, 1.5 * rod.cap / dt)),
        theta_(rod.n, 0.0),
        theta_prev_(rod.n, 0.0),
        theta_new_(rod.n),
        rhs_(rod.n, 0.0) {}

  // Starts step `step` (from 1): the history terms and the ambient coupling at the ambient rise
  // amb_k; heat sources are then added to rhs().
  void BeginStep(long step, double amb_k) {
    const int n = rod_.n;
    const double cap = rod_.cap, dt = dt_;
    if (step == 1) {
      for (int i = 0; i < n; ++i) rhs_[i] = cap / dt * theta_[i] + rod_.g_surf * amb_k;
    } else {
      for (int i = 0; i < n; ++i)
        rhs_[i] = cap / dt * (2.0 * theta_[i] - 0.5 * theta_prev_[i]) + rod_.g_surf * amb_k;
    }
    rhs_[0] += rod_.g_chuck * amb_k;
    rhs_[n - 1] += rod_.g_end * amb_k;
  }
  std::vector<double>& rhs() { return rhs_; }

  // Solves step `step` for the new temperature rise.
  void FinishStep(long step) {
    theta_new_.assign(rhs_.begin(), rhs_.end());
    if (step == 1)
      solve_ie_.Solve(theta_new_);
    else
      solve_bdf2_.Solve(theta_new_);
    theta_prev_.swap(theta_);
    theta_.swap(theta_new_);
  }
  const std::vector<double>& theta() const { return theta_; }

 private:
  // K + c I with K's neighbours -g, its diagonal 2 g + g_surf (the ends: chuck and free end).
  static Tridiagonal Factor(const Rod& rod, double c_over_dt) {
    const int n = rod.n;
    const double g = rod.g;
    std::vector<double> sub(n, -g), super(n, -g), kdiag(n, 2.0 * g + rod.g_surf);
    kdiag[0] = g + rod.g_chuck + rod.g_surf;
    kdiag[n - 1] = g + rod.g_end + rod.g_surf;
    std::vector<double> diag(n);
    for (int i = 0; i < n; ++i) diag[i] = kdiag[i] + c_over_dt;
    return Tridiagonal(sub, diag, super);
  }

  const Rod& rod_;
  double dt_;
  Tridiagonal solve_ie_, solve_bdf2_;
  std::vector<double> theta_, theta_prev_, theta_new_, rhs_;
};

// What is applied to the rod over the cut: heat sources, expansion and the hall's drift.
struct CutLoads {
  MovingBox cut;             // the cut's heat (before tool wear)
  MovingBox steady_rest;     // power 0 = none
  double tool_wear_rel = 0;  // relative rise of the cut's heat by the thread end, -
  double heat_end_s = 0;     // the heat stops when the cut reaches the thread end, s
  double alpha_per_k = 0;    // expansion coefficient with its disturbance factor, 1/K
  double drift_k_per_s = 0;  // ambient temperature rise rate, K/s
};

// The heat history of one cut.
struct RodHistory {
  std::vector<double> time_s;         // sample times
  std::vector<double> elongation_um;  // noise-free elongation at the cut point at each sample
  std::vector<double> theta_k;        // final temperature rise of every cell, K
  double heat_in_j = 0, heat_lost_j = 0;
  double peak_rise_k = 0;  // largest cell rise over the samples, K
};

// Integrates the rod over the time grid: each step deposits the sources averaged over
// [t - dt/2, t + dt/2] (clipped to the heating period), so the deposit is centred on t (second
// order, consistent with BDF2) and moves continuously; the loss is integrated by the trapezoidal
// rule; the elongation at the cut point is recorded at t = 0 and at every sample.
RodHistory IntegrateCut(const Rod& rod, const TimeGrid& grid, const screw::Kinematics& kin,
                        const CutLoads& loads) {
  RodHistory h;
  const double dt = grid.dt;
  RodStepper stepper(rod, dt);
  SourceDeposit sources(rod, kin, dt);
  auto record = [&](double t) {
    h.time_s.push_back(t);
    h.elongation_um.push_back(ElongationUm(stepper.theta(), rod, loads.alpha_per_k,
                                           kin.CutPositionMm(t) * 1e-3, loads.drift_k_per_s * t));
  };
  record(0.0);
  double loss_prev = LossRateW(stepper.theta(), rod, loads.drift_k_per_s * 0.0);
  for (long step = 1; step <= grid.n_steps; ++step) {
    const double t = step * dt;
    const double amb = loads.drift_k_per_s * t;
    stepper.BeginStep(step, amb);
    const double w0 = std::max(0.0, t - 0.5 * dt), w1 = std::min(loads.heat_end_s, t + 0.5 * dt);
    if (w1 > w0) {
      const double wear =
          1.0 + loads.tool_wear_rel * 0.5 * (w0 + w1) / std::max(loads.heat_end_s, 1e-9);
      MovingBox cut = loads.cut;
      cut.power_w = loads.cut.power_w * wear;
      h.heat_in_j += sources.Deposit(cut, w0, w1, stepper.rhs());
      h.heat_in_j += sources.Deposit(loads.steady_rest, w0, w1, stepper.rhs());
    }
    stepper.FinishStep(step);
    const double loss = LossRateW(stepper.theta(), rod, amb);
    h.heat_lost_j += 0.5 * (loss + loss_prev) * dt;
    loss_prev = loss;
    if (step % grid.steps_per_sample == 0 || step == grid.n_steps) {
      record(t);
      for (double v : stepper.theta()) h.peak_rise_k = std::max(h.peak_rise_k, v);
    }
  }
  h.theta_k = stepper.theta();
  return h;
}

// The loads of one cut: the process model's heat (or the override) times the partition factor,
// the disturbances' tool wear and steady rest (only when disturbances are enabled).
CutLoads MakeCutLoads(const SimulationResult& r, const SimOptions& options,
                      const DisturbanceOptions& disturbances) {
  const AppliedDisturbances& dist = r.disturbances;
  const bool extra = disturbances.enabled;
  CutLoads loads;
  loads.cut.power_w = (options.heat_input_override_w >= 0 ? options.heat_input_override_w
                                                          : r.heat.heat_to_workpiece_w) *
                      dist.heat_partition_factor;
  loads.cut.offset_m = 0.0;
  loads.cut.width_m = std::max(r.heat.contact_width_mm * 1e-3, 1e-9);
  loads.steady_rest.power_w = extra ? std::max(0.0, disturbances.steady_rest_heat_w) : 0.0;
  loads.steady_rest.offset_m = disturbances.steady_rest_offset_mm * 1e-3;
  loads.steady_rest.width_m = std::max(disturbances.steady_rest_width_mm * 1e-3, 1e-9);
  loads.tool_wear_rel = extra ? disturbances.tool_wear_heat_rise_rel : 0.0;
  loads.heat_end_s = r.kinematics.cutting_time_s;
  loads.alpha_per_k = options.physics.expansion_per_k * dist.expansion_factor;
  loads.drift_k_per_s = dist.ambient_drift_k_per_h / 3600.0;
  return loads;
}

// The energy balance and the numbers it compared.
SimulationSummary Summarize(const RodHistory& h, const Rod& rod, const TimeGrid& grid,
                            const CutLoads& loads, const screw::Kinematics& kin) {
  SimulationSummary s;
  s.termination = grid.termination;
  s.time_steps = static_cast<int>(grid.n_steps);
  s.cells = rod.n;
  s.simulated_time_s = grid.n_steps * grid.dt;
  s.heat_in_j = h.heat_in_j;
  double stored = 0.0;
  for (double v : h.theta_k) stored += rod.cap * v;
  s.heat_stored_j = stored;
  s.heat_lost_j = h.heat_lost_j;
  const double heat_in = h.heat_in_j, heat_lost = h.heat_lost_j;
  s.energy_balance_rel_error = heat_in > 0 ? std::abs(heat_in - stored - heat_lost) / heat_in : 0.0;
  s.peak_temperature_rise_k = h.peak_rise_k;
  std::ostringstream msg;
  msg << "heat in " << FormatNumber(heat_in) << " J vs stored " << FormatNumber(stored)
      << " J + lost " << FormatNumber(heat_lost) << " J; q = " << FormatNumber(loads.cut.power_w)
      << " W, v_f = " << FormatNumber(kin.axial_feed_mm_min)
      << " mm/min, dx = " << FormatNumber(rod.dx * 1e3) << " mm, dt = " << FormatNumber(grid.dt)
      << " s";
  s.message = msg.str();
  return s;
}

}  // namespace

const char* ToString(SimTermination t) {
  switch (t) {
    case SimTermination::kReachedDuration:
      return "reached_duration";
    case SimTermination::kReachedThreadEnd:
      return "reached_thread_end";
  }
  return "unknown";
}

std::string SimulationSummary::BriefReport() const {
  std::ostringstream s;
  s << "simulation: " << time_steps << " steps x " << cells << " cells, " << simulated_time_s
    << " s, heat in " << heat_in_j << " J = stored " << heat_stored_j << " J + lost " << heat_lost_j
    << " J (balance error " << energy_balance_rel_error * 100 << " %), peak rise "
    << peak_temperature_rise_k << " K, " << ToString(termination);
  return s.str();
}

SimulationResult Simulate(const screw::Screw& screw, const SimOptions& options,
                          const DisturbanceOptions& disturbances) {
  CheckSimOptions(options);
  SimulationResult result;
  result.kinematics = screw::ComputeKinematics(screw);  // validates the screw
  const screw::Kinematics& kin = result.kinematics;
  result.heat = ComputeHeatInput(screw, kin, options.physics);
  Rng rng(disturbances.seed);
  result.disturbances = DrawDisturbances(disturbances, rng);

  const Rod rod = DiscretizeRod(screw, options.physics, options.cell_size_mm);
  const TimeGrid grid = PlanTimeGrid(kin, options, rod.n);
  const CutLoads loads = MakeCutLoads(result, options, disturbances);
  RodHistory history = IntegrateCut(rod, grid, kin, loads);

  // Measurement noise on the recorded curve (drawn after the noise-free truth).
  ElongationCurve& curve = result.curve;
  curve.time_s = std::move(history.time_s);
  curve.elongation_um = history.elongation_um;
  const double noise_std_um = result.disturbances.measurement_noise_std_um;
  if (noise_std_um > 0)
    for (double& e : curve.elongation_um) e += noise_std_um * rng.Normal();
  result.elongation_noise_free_um = std::move(history.elongation_um);

  result.summary = Summarize(history, rod, grid, loads, kin);
  if (options.keep_final_profile) {
    result.cell_center_mm.resize(rod.n);
    for (int i = 0; i < rod.n; ++i) result.cell_center_mm[i] = (i + 0.5) * rod.dx * 1e3;
    result.temperature_rise_k = history.theta_k;
  }
  if (curve.size() >= 10) result.features = fit::ExtractFeatures(curve, options.settle);
  return result;
}

}  // namespace whirl::sim
