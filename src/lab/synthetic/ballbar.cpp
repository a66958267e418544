#include "synthetic/ballbar.h"

#include <cmath>
#include <cstdio>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/random.h"

namespace whirl::synthetic {
namespace {

double Uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); }

// Rounds to a decimal step (0.1 um = 1e-4 mm, 0.01 K): round(x k) / k with k = 1 / step an exact
// integer, so the result is the double nearest to the decimal value and prints short.
double Round(double x, double step) {
  if (step <= 0) return x;
  const double k = std::round(1 / step);
  return std::round(x * k) / k;
}

ballbar::PivotCentres Layout(const WarmupOptions& o, Rng& rng) {
  const double h = o.bar_length_mm / std::sqrt(3.0), r = o.bar_length_mm * std::sqrt(2.0 / 3.0);
  ballbar::PivotCentres p;
  const double angles_deg[3] = {210, 330, 90};
  for (int i = 0; i < 3; ++i) {
    const double a = angles_deg[i] * kPi / 180;
    p[i] = o.ball_mm + Eigen::Vector3d(r * std::cos(a), r * std::sin(a), -h);
    p[i] += Eigen::Vector3d(Uniform(rng, -5, 5), Uniform(rng, -5, 5), Uniform(rng, -1, 1));
  }
  return p;
}

double BarTemperature(const WarmupOptions& o, double t) {
  return o.bar_start_C + o.bar_rise_K * (1 - std::exp(-t / o.bar_tau_min));
}

}  // namespace

void WarmupOptions::Validate() const {
  auto bad = [](const std::string& f, double v, const std::string& rule) {
    throw InputError(f + " = " + MessageNumber(v) + ": " + rule);
  };
  if (!(duration_min >= 60 && duration_min <= 720))
    bad("duration_min", duration_min, "must be in [60, 720] min");
  if (!(repeats >= 1 && repeats <= 10)) bad("repeats", repeats, "must be in [1, 10]");
  if (!(reading_step_min > 0 && reading_step_min <= 1))
    bad("reading_step_min", reading_step_min, "must be in (0, 1] min");
  const double block = 3 * repeats * reading_step_min;
  if (!(interval_min >= block + 2.5 && interval_min <= duration_min))
    bad("interval_min", interval_min,
        "must leave more than the 2 min block gap after a block of " + MessageNumber(block) +
            " min and be at most the duration");
  if (!(bar_noise_sd_um >= 0 && bar_noise_sd_um <= 10))
    bad("bar_noise_sd_um", bar_noise_sd_um, "must be in [0, 10] um");
  if (!(resolution_um >= 0 && resolution_um <= 1))
    bad("resolution_um", resolution_um, "must be in [0, 1] um");
  if (!(bar_length_mm >= 50 && bar_length_mm <= 600))
    bad("bar_length_mm", bar_length_mm, "must be in [50, 600] mm");
}

Eigen::Vector3d WarmupDrift(const WarmupSimulation& s, double t) {
  return s.final_drift_um.array() * (1 - (-t / s.tau_min.array()).exp());
}

WarmupSimulation SimulateWarmup(const WarmupOptions& o) {
  o.Validate();
  Rng rng(MixSeed(o.seed, 15));
  WarmupSimulation s;
  for (int a = 0; a < 2; ++a)
    s.final_drift_um(a) = (rng.Uniform() < 0.5 ? -1 : 1) * Uniform(rng, 2, 10);
  s.final_drift_um(2) = -Uniform(rng, 20, 60);
  for (int a = 0; a < 3; ++a) s.tau_min(a) = Uniform(rng, 40, 90);
  s.pivots_mm = Layout(o, rng);
  s.readings.source = "simulated";
  s.readings.has_bar_temperature = true;
  const int blocks = static_cast<int>(std::floor(o.duration_min / o.interval_min + 1e-9)) + 1;
  for (int b = 0; b < blocks; ++b) {
    double t_sum = 0;
    int k = 0;
    for (int pass = 0; pass < o.repeats; ++pass)
      for (int j = 0; j < 3; ++j, ++k) {
        const int pivot = pass % 2 == 0 ? j : 2 - j;  // 1 2 3 3 2 1 ...
        const double t = b * o.interval_min + k * o.reading_step_min;
        const Eigen::Vector3d ball = o.ball_mm + WarmupDrift(s, t) / 1000;
        const double temp = Round(BarTemperature(o, t), 0.01);
        const double true_len = (ball - s.pivots_mm[pivot]).norm();
        const double read = true_len / (1 + o.bar_alpha_per_K * (temp - 20)) +
                            o.bar_noise_sd_um * rng.Normal() / 1000;
        ballbar::Reading r;
        r.time_min = t;
        r.pivot = pivot + 1;
        r.length_mm = Round(read, o.resolution_um / 1000);
        r.bar_temperature_C = temp;
        r.line = static_cast<int>(s.readings.rows.size()) + 2;
        s.readings.rows.push_back(r);
        t_sum += t;
      }
    s.block_time_min.push_back(t_sum / k);
  }
  for (double t : s.block_time_min)
    s.truth_um.push_back(WarmupDrift(s, t) - WarmupDrift(s, s.block_time_min.front()));
  return s;
}

ballbar::CircleTrace SimulateCircle(const CirclePlant& p) {
  Rng rng(MixSeed(p.seed, 1500));
  const bool semi = p.plane != ballbar::Plane::kXY;
  const int n = semi ? p.samples / 2 + 1 : p.samples;
  const double span = semi ? 180.0 : 360.0 * (n - 1) / n;
  ballbar::CircleTrace c;
  c.source = "simulated";
  const double r_um = p.radius_mm * 1000;
  for (int i = 0; i < n; ++i) {
    const double deg = span * i / (n - 1), th = deg * kPi / 180;
    const double u = r_um * std::cos(th), v = r_um * std::sin(th);  // um
    const double up = p.centre_1_um + u * (1 + p.scale_1_um_per_m * 1e-6) +
                      p.squareness_urad * 1e-6 * v +
                      p.cyclic_1_um * std::sin(2 * kPi * u / (1000 * p.cyclic_period_1_mm) +
                                               p.cyclic_phase_1_deg * kPi / 180);
    const double vp = p.centre_2_um + v * (1 + p.scale_2_um_per_m * 1e-6) +
                      p.cyclic_2_um * std::sin(2 * kPi * v / (1000 * p.cyclic_period_2_mm) +
                                               p.cyclic_phase_2_deg * kPi / 180);
    c.angle_deg.push_back(deg);
    c.deviation_um.push_back(std::hypot(up, vp) - r_um + p.noise_sd_um * rng.Normal());
  }
  return c;
}

namespace {

struct DemoTrace {
  std::string file;
  std::string what;
  std::string fit_options;
  CirclePlant plant;
};

std::vector<DemoTrace> DemoTraces(std::uint64_t seed) {
  std::vector<DemoTrace> t(3);
  t[0] = {"circle_xy_scale.csv",
          "X scale grown by 30 um/m (about 2.6 K on a steel scale)",
          "--plane XY --radius-mm 100",
          {}};
  t[0].plant.scale_1_um_per_m = 30;
  t[1] = {"circle_xy_cyclic.csv",
          "X ball-screw cyclic error 1.5 um, period 10 mm, phase 30 deg",
          "--plane XY --radius-mm 100 --cyclic-period-1-mm 10",
          {}};
  t[1].plant.cyclic_1_um = 1.5;
  t[1].plant.cyclic_phase_1_deg = 30;
  t[2] = {"circle_xz_parallelism.csv",
          "Z travel leaning 40 urad towards +X (spindle / Z-guide parallelism), XZ semicircle",
          "--plane XZ --radius-mm 100",
          {}};
  t[2].plant.plane = ballbar::Plane::kXZ;
  t[2].plant.squareness_urad = 40;
  for (std::size_t i = 0; i < t.size(); ++i) t[i].plant.seed = MixSeed(seed, i);
  return t;
}

std::string Command(const WarmupOptions& o, const std::filesystem::path& dir) {
  return "whirl ballbar simulate --seed " + std::to_string(o.seed) + " --duration-min " +
         MessageNumber(o.duration_min) + " --interval-min " + MessageNumber(o.interval_min) +
         " --out-dir " + dir.string();
}

std::string Xyz(const Eigen::Vector3d& v) {
  return "X " + MessageNumber(v.x()) + ", Y " + MessageNumber(v.y()) + ", Z " +
         MessageNumber(v.z());
}

std::string Readme(const WarmupSimulation& s, const WarmupOptions& o, const std::string& command,
                   const std::vector<DemoTrace>& traces) {
  std::string r =
      "# Simulated ball-bar measurement (SIMULATED, not measured)\n\n"
      "Generated by `" +
      command +
      "` (model: `src/lab/synthetic/ballbar.h`).\n\n"
      "- `readings.csv`, `pivots.json`: a " +
      MessageNumber(o.duration_min) + " min spindle warm-up read every " +
      MessageNumber(o.interval_min) + " min, " + std::to_string(o.repeats) +
      " passes over the pivots per block (order 1 2 3 3 2 1), bar noise " +
      MessageNumber(o.bar_noise_sd_um) + " um, resolution " + MessageNumber(o.resolution_um) +
      " um, bar alpha " + MessageNumber(o.bar_alpha_per_K) + " /K warming " +
      MessageNumber(o.bar_rise_K) + " K from " + MessageNumber(o.bar_start_C) +
      " degC.\n"
      "- planted drift D (1 - exp(-t/tau)): D = " +
      Xyz(s.final_drift_um) + " um; tau = " + Xyz(s.tau_min) +
      " min.\n"
      "- `truth_drift.csv`: the planted drift at each block's mean time, relative to the cold "
      "block.\n"
      "  Check: `whirl ballbar drift --readings readings.csv --pivots pivots.json`.\n";
  for (const auto& t : traces)
    r += "- `" + t.file + "`: " + t.what +
         ", R 100 mm, noise 0.1 um. Check: `whirl ballbar circle --trace " + t.file + " " +
         t.fit_options + "`.\n";
  return r;
}

}  // namespace

nlohmann::json WriteSimulatedMeasurement(const std::filesystem::path& dir, const WarmupOptions& o) {
  const WarmupSimulation s = SimulateWarmup(o);
  const std::string command = Command(o, dir);
  const std::vector<std::string> provenance = {"SIMULATED ball-bar measurement: " + command,
                                               "model and planted values: README.md"};
  std::vector<std::pair<std::string, std::string>> files;
  ballbar::Readings readings = s.readings;
  readings.comments = provenance;
  files.push_back({"readings.csv", ballbar::FormatReadings(readings)});
  nlohmann::json pivots = ballbar::PivotsToJson(s.pivots_mm);
  pivots["comment"] = "SIMULATED: " + command;
  files.push_back({"pivots.json", pivots.dump(2) + "\n"});
  std::vector<std::vector<double>> truth;
  for (std::size_t b = 0; b < s.truth_um.size(); ++b)
    truth.push_back({s.block_time_min[b], s.truth_um[b].x(), s.truth_um[b].y(), s.truth_um[b].z()});
  files.push_back(
      {"truth_drift.csv",
       FormatCsv({"time_min", "drift_x_um", "drift_y_um", "drift_z_um"}, truth,
                 {provenance[0], "the planted drift (truth), relative to the cold block"})});
  const std::vector<DemoTrace> traces = DemoTraces(o.seed);
  for (const auto& t : traces) {
    ballbar::CircleTrace c = SimulateCircle(t.plant);
    c.comments = {provenance[0], "planted: " + t.what,
                  "fit: whirl ballbar circle --trace " + t.file + " " + t.fit_options};
    files.push_back({t.file, ballbar::FormatCircleTrace(c)});
  }
  files.push_back({"README.md", Readme(s, o, command, traces)});
  OutputDir out(dir, "output directory");
  for (const auto& [name, text] : files) out.Add(name, text);
  nlohmann::json written = nlohmann::json::array();
  for (const auto& path : out.Commit()) written.push_back(path.string());
  return {{"schema", "whirl.ballbar.simulation"},
          {"schema_version", 1},
          {"command", command},
          {"files", written},
          {"final_drift_um", {s.final_drift_um.x(), s.final_drift_um.y(), s.final_drift_um.z()}},
          {"tau_min", {s.tau_min.x(), s.tau_min.y(), s.tau_min.z()}},
          {"blocks", s.block_time_min.size()},
          {"readings", s.readings.rows.size()}};
}

}  // namespace whirl::synthetic
