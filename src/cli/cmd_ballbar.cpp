// whirl ballbar drift|circle|simulate: spindle thermal drift from ball-bar readings (Shang, Ruan
// and Zhang), circle-test diagnostics, and the documented simulated measurement.
#include <cstdio>
#include <memory>

#include "ballbar/circle.h"
#include "ballbar/drift.h"
#include "synthetic/ballbar.h"
#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/output_dir.h"

namespace whirl::cli {
namespace {

struct DriftCmd {
  std::string readings, pivots, out, sign = "subtract";
  bool json = false, no_temperature = false;
  ballbar::DriftOptions o;
};

void PrintDrift(const ballbar::DriftResult& r) {
  std::printf("ball-bar drift: %s (%zu blocks; bar sd %.3f um, %s; bar expansion %s)\n",
              r.source.c_str(), r.blocks.size(), r.bar_sd_um, r.bar_sd_source.c_str(),
              r.bar_temperature_corrected ? "corrected" : "NOT corrected");
  std::printf("%9s %18s %18s %18s\n", "time_min", "drift_x_um", "drift_y_um", "drift_z_um");
  for (const auto& b : r.blocks)
    std::printf("%9.2f %9.3f +- %5.3f %9.3f +- %5.3f %9.3f +- %5.3f\n", b.time_min, b.drift_um.x(),
                b.drift_sd_um.x(), b.drift_um.y(), b.drift_sd_um.y(), b.drift_um.z(),
                b.drift_sd_um.z());
  const auto& p = r.placement;
  std::printf("pivot layout: condition number %.2f (%s), noise gain X %.2f Y %.2f Z %.2f\n  %s\n",
              p.condition_number, p.rating.c_str(), p.noise_gain.x(), p.noise_gain.y(),
              p.noise_gain.z(), p.advice.c_str());
  std::printf("840D SD43900 $SA_TEMP_COMP_ABS_VALUE at %.2f min (sign %s: %s drift / 1000), mm:\n",
              r.blocks.back().time_min, interp::ToString(r.options.sign).c_str(),
              r.options.sign == interp::SignConvention::kSubtract ? "-" : "+");
  std::printf("  X %.6f  Y %.6f  Z %.6f\n", r.sd43900_mm.x(), r.sd43900_mm.y(), r.sd43900_mm.z());
}

void RunDrift(DriftCmd c) {
  CheckOutputs({{"--readings", c.readings}, {"--pivots", c.pivots}}, {{"--out", c.out}});
  c.o.sign = interp::ParseSignConvention(c.sign);
  c.o.correct_bar_temperature = !c.no_temperature;
  const ballbar::DriftResult r =
      ballbar::ComputeDrift(ballbar::ReadReadings(c.readings), ballbar::ReadPivots(c.pivots), c.o);
  if (!c.out.empty()) {
    WriteFileAtomic(c.out,
                    ballbar::FormatDriftCsv(
                        r, {"spindle thermal drift from ball-bar readings (Shang, Ruan and Zhang, "
                            "eq. 18)",
                            "readings: " + c.readings + ", pivots: " + c.pivots,
                            "drift = tool-ball position now - cold block, MCS, um"}));
    std::fprintf(stderr, "wrote %s\n", c.out.c_str());
  }
  if (c.json)
    PrintJson(ballbar::ToJson(r));
  else
    PrintDrift(r);
}

void AddDrift(CLI::App& parent) {
  auto c = std::make_shared<DriftCmd>();
  auto* sub = parent.add_subcommand(
      "drift",
      "Spindle thermal drift from ball-bar readings to three table pivots (Shang, Ruan and\n"
      "Zhang, eqs. 11-18).\n"
      "Readings CSV: time_min (min, non-decreasing), pivot (1, 2, 3), length_mm "
      "(centre-to-centre,\n"
      "mm, at most 2000), optional bar_temperature_C (degC, -20..60); at most 1e6 rows. Readings\n"
      "closer than --block-gap-min form one block (one position); the first block is the cold\n"
      "reference. Pivots JSON: {\"schema\": \"whirl.ballbar.pivots\", \"schema_version\": 1,\n"
      "\"pivots_mm\": [[x,y,z],[x,y,z],[x,y,z]]} in machine coordinates (mm).\n"
      "Prints the drift per block and axis (um) with its sd (bar noise through the "
      "trilateration's\n"
      "Jacobian, plus the bar-expansion coefficient's sd), the pivot layout's condition number\n"
      "with advice, and the current SD43900 per axis (mm): -drift/1000 with --sign subtract.");
  sub->add_option("--readings", c->readings, "readings CSV")->required()->check(CLI::ExistingFile);
  sub->add_option("--pivots", c->pivots, "pivots JSON (MCS, mm)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", c->out,
                  "write the run file time_min,drift_x_um,drift_y_um,drift_z_um (drift commands "
                  "read it as error columns)");
  sub->add_option("--block-gap-min", c->o.block_gap_min,
                  "a reading more than this after the previous one starts a new block, min "
                  "(default 2)")
      ->check(NumberIn(1e-6, 1440.0));
  sub->add_option("--bar-sd-um", c->o.bar_sd_um,
                  "sd of one bar reading, um (default 0: pooled from repeated readings of a pivot "
                  "within blocks)")
      ->check(NumberIn(0.0, 100.0));
  auto* bar_alpha_per_k =
      sub->add_option(
             "--bar-alpha-per-k", c->o.bar_alpha_per_K,
             "bar expansion coefficient, 1/K (default 12e-6: 1.8 um/K on 150 mm); a reading "
             "is corrected to L (1 + alpha (T - T_ref))")
          ->check(NumberIn(0.0, 50e-6, "1/K"));
  AddDeprecatedAlias(sub, bar_alpha_per_k, "--bar-alpha-per-K");
  auto* bar_alpha_sd_per_k =
      sub->add_option("--bar-alpha-sd-per-k", c->o.bar_alpha_sd_per_K,
                      "sd of that coefficient, 1/K (default 1e-6; 0 for a calibrated bar)")
          ->check(NumberIn(0.0, 50e-6, "1/K"));
  AddDeprecatedAlias(sub, bar_alpha_sd_per_k, "--bar-alpha-sd-per-K");
  auto* bar_reference_c = sub->add_option("--bar-reference-c", c->o.bar_reference_C,
                                          "bar calibration temperature T_ref, degC (default 20)")
                              ->check(NumberIn(-20.0, 60.0, "degC"));
  AddDeprecatedAlias(sub, bar_reference_c, "--bar-reference-C");
  sub->add_flag("--no-bar-temperature", c->no_temperature,
                "ignore bar_temperature_C (no expansion correction)");
  sub->add_option("--sign", c->sign,
                  "SD43900 = s drift/1000: subtract (s = -1, default: compensation = minus the "
                  "drift) or add (s = +1); see docs/840d.md")
      ->check(CLI::IsMember({"subtract", "add"}));
  sub->add_flag("--json", c->json, "machine output: JSON on stdout");
  sub->callback([c] { RunDrift(*c); });
}

struct CircleCmd {
  std::string trace, plane = "XY";
  bool json = false;
  ballbar::CircleOptions o;
};

void RunCircle(CircleCmd c) {
  c.o.plane = ballbar::ParsePlane(c.plane);
  const ballbar::CircleDiagnostics d = ballbar::FitCircle(ballbar::ReadCircleTrace(c.trace), c.o);
  if (c.json) return PrintJson(ballbar::ToJson(d));
  std::printf("circle test %s: plane %s, R %.3f mm, %d samples over %.1f deg\n", c.trace.c_str(),
              ballbar::ToString(d.plane).c_str(), d.radius_mm, d.samples, d.span_deg);
  for (const auto& t : d.terms)
    std::printf("  %-32s %12.4f +- %-9.4f %s\n", t.name.c_str(), t.value, t.sd, t.unit.c_str());
  if (d.cyclic_amplitude_1_um > 0 || d.cyclic_amplitude_2_um > 0)
    std::printf("  cyclic phase (axis 1, axis 2)    %12.2f %12.2f deg\n", d.cyclic_phase_1_deg,
                d.cyclic_phase_2_deg);
  std::printf("  fit residual RMS %.4f um, max %.4f um; circular deviation G %.4f um\n",
              d.residual_rms_um, d.residual_max_um, d.circular_deviation_um);
}

void AddCircle(CLI::App& parent) {
  auto c = std::make_shared<CircleCmd>();
  auto* sub = parent.add_subcommand(
      "circle",
      "Circle-test diagnostics of a ball-bar trace (ISO 230-4 style), least squares.\n"
      "Trace CSV: angle_deg (from axis 1 towards axis 2, strictly increasing, span 180..360 deg),\n"
      "deviation_um (measured minus nominal radius, um, within +-10000); 16 to 1e6 samples.\n"
      "Prints, each with its sd: radius offset (um), centre offset per axis (um), scale mismatch\n"
      "axis1-axis2 (um/m), squareness (urad; the axes enclose 90 deg - alpha), cyclic amplitude\n"
      "per axis at the given period (um), in XZ the parallelism of the Z travel to the spindle\n"
      "(urad), the fit residual (um) and the circular deviation G (um).");
  sub->add_option("--trace", c->trace, "trace CSV")->required()->check(CLI::ExistingFile);
  sub->add_option("--plane", c->plane, "XY, XZ or YZ (default XY)")
      ->check(CLI::IsMember({"XY", "XZ", "YZ", "xy", "xz", "yz"}));
  sub->add_option("--radius-mm", c->o.radius_mm, "nominal radius (bar length), mm (default 100)")
      ->check(NumberIn(1.0, 2000.0));
  sub->add_option("--cyclic-period-1-mm", c->o.cyclic_period_1_mm,
                  "period of axis 1's cyclic error (its screw lead), mm (default 0: not fitted)")
      ->check(NumberIn(0.0, 1000.0));
  sub->add_option("--cyclic-period-2-mm", c->o.cyclic_period_2_mm,
                  "period of axis 2's cyclic error, mm (default 0: not fitted)")
      ->check(NumberIn(0.0, 1000.0));
  sub->add_option("--spindle-tram-urad", c->o.spindle_tram_urad,
                  "XZ only: measured tilt of the spindle axis from square to the X travel, urad "
                  "(default 0); parallelism = XZ squareness - tram")
      ->check(NumberIn(-1e5, 1e5));
  sub->add_flag("--json", c->json, "machine output: JSON on stdout");
  sub->callback([c] { RunCircle(*c); });
}

struct SimulateCmd {
  std::string out_dir;
  bool json = false;
  synthetic::WarmupOptions o;
};

void AddSimulate(CLI::App& parent) {
  auto c = std::make_shared<SimulateCmd>();
  auto* sub = parent.add_subcommand(
      "simulate",
      "Writes the documented SIMULATED ball-bar measurement (src/lab/synthetic/ballbar.h): a spindle\n"
      "warm-up (drift 2-10 um in X, Y and 20-60 um in Z, seeded) read with bar noise 0.1 um at\n"
      "0.1 um resolution and a warming bar (readings.csv, pivots.json, truth_drift.csv), circle\n"
      "traces with a planted scale mismatch, cyclic error and XZ parallelism, and a README.md.");
  sub->add_option("--out-dir", c->out_dir, std::string("output directory: ") + kOutputDirRule)
      ->required();
  AddSeedOption(sub, &c->o.seed, "random seed (default 1)");
  sub->add_option("--duration-min", c->o.duration_min, "warm-up length, min (default 240)")
      ->check(NumberIn(60.0, 720.0));
  sub->add_option("--interval-min", c->o.interval_min, "time between blocks, min (default 15)")
      ->check(NumberIn(4.0, 720.0));
  sub->add_flag("--json", c->json, "machine output: JSON on stdout");
  sub->callback([c] {
    CheckOutputs({}, {}, {{"--out-dir", c->out_dir}});
    const nlohmann::json j = synthetic::WriteSimulatedMeasurement(c->out_dir, c->o);
    if (c->json) return PrintJson(j);
    for (const auto& f : j["files"]) std::printf("wrote %s\n", f.get<std::string>().c_str());
  });
}

}  // namespace

void RegisterBallbar(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "ballbar", "Ball-bar measurement of spindle thermal drift and circle-test diagnostics.");
  sub->require_subcommand(1);
  AddDrift(*sub);
  AddCircle(*sub);
  AddSimulate(*sub);
}

}  // namespace whirl::cli
