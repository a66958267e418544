#include "sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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

SimulationResult Simulate(const Screw& screw, const SimOptions& options,
                          const DisturbanceOptions& disturbances) {
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

  SimulationResult result;
  result.kinematics = ComputeKinematics(screw);  // validates the screw
  const Kinematics& kin = result.kinematics;
  result.heat = ComputeHeatInput(screw, kin, ph);

  // Disturbances, drawn in the documented order.
  AppliedDisturbances& dist = result.disturbances;
  Rng rng(disturbances.seed);
  if (disturbances.enabled) {
    const double n_heat = rng.Normal(), n_alpha = rng.Normal(), n_drift = rng.Normal();
    if (disturbances.workpiece_variation) {
      dist.heat_partition_factor =
          std::max(0.0, 1.0 + disturbances.heat_partition_rel_std * n_heat);
      dist.expansion_factor = std::max(0.0, 1.0 + disturbances.expansion_rel_std * n_alpha);
    }
    if (disturbances.ambient_drift)
      dist.ambient_drift_k_per_h = std::isfinite(disturbances.ambient_drift_fixed_k_per_h)
                                       ? disturbances.ambient_drift_fixed_k_per_h
                                       : disturbances.ambient_drift_std_k_per_h * n_drift;
    if (disturbances.measurement_noise)
      dist.measurement_noise_std_um = disturbances.measurement_noise_std_um;
  }

  const double q_w = (options.heat_input_override_w >= 0 ? options.heat_input_override_w
                                                         : result.heat.heat_to_workpiece_w) *
                     dist.heat_partition_factor;
  const double alpha = ph.expansion_per_k * dist.expansion_factor;
  const double drift_k_per_s = dist.ambient_drift_k_per_h / 3600.0;

  // Geometry in SI units.
  const double length_m = screw.length_mm * 1e-3;
  const double cells = std::round(screw.length_mm / options.cell_size_mm);
  if (!(cells >= 3 && cells <= kMaxCells))
    throw InputError("simulation options: cell_size_mm = " + FormatNumber(options.cell_size_mm) +
                     " gives " + FormatNumber(cells) + " cells on the " +
                     FormatNumber(screw.length_mm) + " mm blank; the rule (resource limit): 3 to " +
                     FormatNumber(kMaxCells) + " cells, i.e. cell_size_mm within [" +
                     FormatNumber(screw.length_mm / kMaxCells) + ", " +
                     FormatNumber(screw.length_mm / 3) + "] mm");
  const int n = static_cast<int>(cells);
  const double dx = length_m / n;
  const double d_m = screw.process.diameter_mm * 1e-3;
  const double area = kPi * d_m * d_m / 4.0;
  const double perimeter = kPi * d_m;
  const double cap = ph.density_kg_m3 * ph.specific_heat_j_kg_k * area * dx;  // J/K per cell
  const double g = ph.conductivity_w_m_k * area / dx;                         // W/K between cells
  const double g_chuck = 2.0 * g;  // centre of cell 0 to the chuck face held at ambient
  const double hh = ph.heat_transfer_coefficient_w_m2_k;
  const double g_end = hh > 0 ? 1.0 / (1.0 / (hh * area) + 1.0 / (2.0 * g)) : 0.0;
  const double g_surf = hh * perimeter * dx;
  const double w_m = std::max(result.heat.contact_width_mm * 1e-3, 1e-9);
  const double v_m_s = kin.axial_feed_mm_s * 1e-3;
  const double x_start_m = kin.thread_start_position_mm * 1e-3;
  const double t_heat_end = kin.cutting_time_s;

  const double dt = options.time_step_s;
  double t_end = kin.cutting_time_s;
  result.summary.termination = SimTermination::kReachedThreadEnd;
  if (options.duration_s > 0 && options.duration_s < kin.cutting_time_s) {
    t_end = options.duration_s;
    result.summary.termination = SimTermination::kReachedDuration;
  }
  const double steps = std::max(1.0, std::floor(t_end / dt + 1e-9));
  if (!(steps <= kMaxTimeSteps && steps * n <= kMaxCellSteps))
    throw InputError("simulation options: " + FormatNumber(t_end) +
                     " s of cutting at time_step_s = " + FormatNumber(dt) + " is " +
                     FormatNumber(steps) + " steps x " + std::to_string(n) +
                     " cells; the rule (resource limit): at most " + FormatNumber(kMaxTimeSteps) +
                     " steps and " + FormatNumber(kMaxCellSteps) +
                     " cell-steps (raise time_step_s or cell_size_mm, or shorten duration_s)");
  const long n_steps = static_cast<long>(steps);
  const long steps_per_sample =
      std::max(1L, static_cast<long>(std::lround(options.sample_interval_s / dt)));

  // Conductance matrix K (symmetric): theta' C = -K theta + b.
  std::vector<double> sub(n, -g), super(n, -g), kdiag(n, 2.0 * g + g_surf);
  kdiag[0] = g + g_chuck + g_surf;
  kdiag[n - 1] = g + g_end + g_surf;
  std::vector<double> diag_ie(n), diag_bdf2(n);
  for (int i = 0; i < n; ++i) {
    diag_ie[i] = kdiag[i] + cap / dt;
    diag_bdf2[i] = kdiag[i] + 1.5 * cap / dt;
  }
  const Tridiagonal solve_ie(sub, diag_ie, super);
  const Tridiagonal solve_bdf2(sub, diag_bdf2, super);

  std::vector<double> theta(n, 0.0), theta_prev(n, 0.0), rhs(n, 0.0);

  auto cut_position_m = [&](double t) { return kin.CutPositionMm(t) * 1e-3; };
  // Elongation integral: piecewise linear through (0, theta_amb) and the cell centres, to x_c.
  auto elongation_um = [&](double t) {
    const double xc = cut_position_m(t);
    const double amb = drift_k_per_s * t;
    double integral = 0.0;
    double x_prev = 0.0, th_prev = amb;
    for (int i = 0; i < n; ++i) {
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
  };
  auto loss_rate_w = [&](double t) {
    const double amb = drift_k_per_s * t;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += theta[i] - amb;
    return g_surf * sum + g_chuck * (theta[0] - amb) + g_end * (theta[n - 1] - amb);
  };

  std::vector<double> noise_free;
  ElongationCurve& curve = result.curve;
  auto record = [&](double t) {
    curve.time_s.push_back(t);
    noise_free.push_back(elongation_um(t));
  };
  record(0.0);

  double heat_in = 0.0, heat_lost = 0.0, loss_prev = loss_rate_w(0.0), peak = 0.0;
  std::vector<double> theta_new(n), share(n);
  const bool extra = disturbances.enabled;
  const double rest_w = extra ? std::max(0.0, disturbances.steady_rest_heat_w) : 0.0;
  const double rest_offset_m = disturbances.steady_rest_offset_mm * 1e-3;
  const double rest_width_m = std::max(disturbances.steady_rest_width_mm * 1e-3, 1e-9);
  // Deposits power (W) of a box of `width` centred `offset` towards the chuck from the cut,
  // averaged over [w0, w1], into rhs; returns the energy deposited, J.
  auto deposit = [&](double power, double offset, double width, double w0, double w1) {
    if (!(power > 0)) return 0.0;
    const double energy = power * (w1 - w0);
    const double s0 = x_start_m - offset - v_m_s * w1, s1 = x_start_m - offset - v_m_s * w0;
    const double lo = s0 - 0.5 * width, hi = s1 + 0.5 * width;
    const int i0 = std::max(0, static_cast<int>(std::floor(lo / dx)));
    const int i1 = std::min(n - 1, static_cast<int>(std::floor(hi / dx)));
    double total = 0.0;
    for (int i = i0; i <= i1; ++i) {
      const double ov = s1 > s0 ? SweptOverlap(s0, s1, width, i * dx, (i + 1) * dx)
                                : std::max(0.0, std::min((i + 1) * dx, s0 + 0.5 * width) -
                                                    std::max(i * dx, s0 - 0.5 * width));
      share[i] = ov;
      total += ov;
    }
    // Normalised over the cells inside the blank: all heat enters the workpiece.
    if (!(total > 0)) return 0.0;
    for (int i = i0; i <= i1; ++i) rhs[i] += energy / dt * share[i] / total;
    return energy;
  };
  for (long step = 1; step <= n_steps; ++step) {
    const double t = step * dt;
    const double amb = drift_k_per_s * t;
    // Right-hand side: history terms, ambient coupling.
    if (step == 1) {
      for (int i = 0; i < n; ++i) rhs[i] = cap / dt * theta[i] + g_surf * amb;
    } else {
      for (int i = 0; i < n; ++i)
        rhs[i] = cap / dt * (2.0 * theta[i] - 0.5 * theta_prev[i]) + g_surf * amb;
    }
    rhs[0] += g_chuck * amb;
    rhs[n - 1] += g_end * amb;
    // Heat sources: the box's overlap averaged over the window [t - dt/2, t + dt/2] (clipped to
    // the heating period), so the deposit is centred on t (second-order consistent with BDF2) and
    // moves continuously. The cut (tool wear scales it) and, if any, the steady rest.
    const double w0 = std::max(0.0, t - 0.5 * dt), w1 = std::min(t_heat_end, t + 0.5 * dt);
    if (w1 > w0) {
      const double wear_rel = extra ? disturbances.tool_wear_heat_rise_rel : 0.0;
      const double wear = 1.0 + wear_rel * 0.5 * (w0 + w1) / std::max(t_heat_end, 1e-9);
      heat_in += deposit(q_w * wear, 0.0, w_m, w0, w1);
      heat_in += deposit(rest_w, rest_offset_m, rest_width_m, w0, w1);
    }
    theta_new.assign(rhs.begin(), rhs.end());
    if (step == 1)
      solve_ie.Solve(theta_new);
    else
      solve_bdf2.Solve(theta_new);
    theta_prev.swap(theta);
    theta.swap(theta_new);
    const double loss = loss_rate_w(t);
    heat_lost += 0.5 * (loss + loss_prev) * dt;
    loss_prev = loss;
    if (step % steps_per_sample == 0 || step == n_steps) {
      record(t);
      for (double v : theta) peak = std::max(peak, v);
    }
  }

  // Measurement noise on the recorded curve (after the noise-free truth).
  curve.elongation_um = noise_free;
  if (dist.measurement_noise_std_um > 0)
    for (double& e : curve.elongation_um) e += dist.measurement_noise_std_um * rng.Normal();
  result.elongation_noise_free_um = std::move(noise_free);

  SimulationSummary& s = result.summary;
  s.time_steps = static_cast<int>(n_steps);
  s.cells = n;
  s.simulated_time_s = n_steps * dt;
  s.heat_in_j = heat_in;
  double stored = 0.0;
  for (double v : theta) stored += cap * v;
  s.heat_stored_j = stored;
  s.heat_lost_j = heat_lost;
  s.energy_balance_rel_error = heat_in > 0 ? std::abs(heat_in - stored - heat_lost) / heat_in : 0.0;
  s.peak_temperature_rise_k = peak;
  std::ostringstream msg;
  msg << "heat in " << FormatNumber(heat_in) << " J vs stored " << FormatNumber(stored)
      << " J + lost " << FormatNumber(heat_lost) << " J; q = " << FormatNumber(q_w)
      << " W, v_f = " << FormatNumber(kin.axial_feed_mm_min)
      << " mm/min, dx = " << FormatNumber(dx * 1e3) << " mm, dt = " << FormatNumber(dt) << " s";
  s.message = msg.str();

  if (options.keep_final_profile) {
    result.cell_center_mm.resize(n);
    for (int i = 0; i < n; ++i) result.cell_center_mm[i] = (i + 0.5) * dx * 1e3;
    result.temperature_rise_k = theta;
  }
  if (curve.size() >= 10) result.features = ExtractFeatures(curve, options.settle);
  return result;
}

}  // namespace whirl::sim
