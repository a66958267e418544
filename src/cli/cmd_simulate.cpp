// whirl simulate: the hard-whirling thermal simulator for one screw (src/lab/sim/simulator.h).
#include <cstdio>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/csv.h"
#include "core/curve.h"
#include "core/limits.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "screw/screw.h"
#include "sim/simulator.h"

namespace whirl::cli {
namespace {

struct SimulateOptions {
  std::string screw_path;
  std::string out_path;
  double duration_s = 0.0;
  bool no_disturbances = false;
  std::uint64_t seed = 1;
  double cell_size_mm = sim::SimOptions{}.cell_size_mm;
  double time_step_s = sim::SimOptions{}.time_step_s;
  bool json = false;
};

nlohmann::json ResultJson(const screw::Screw& screw, const sim::SimulationResult& r,
                          const fit::SettleAnalysis& settle, const SimulateOptions& o) {
  const auto& k = r.kinematics;
  nlohmann::json j;
  j["screw"] = screw;
  j["kinematics"] = {{"tool_circle_diameter_mm", k.tool_circle_diameter_mm},
                     {"ring_speed_rpm", k.ring_speed_rpm},
                     {"workpiece_speed_rpm", k.workpiece_speed_rpm},
                     {"axial_feed_mm_min", k.axial_feed_mm_min},
                     {"cutting_time_s", k.cutting_time_s},
                     {"groove_depth_mm", k.groove.depth_mm},
                     {"groove_width_mm", k.groove.width_mm},
                     {"groove_area_mm2", k.groove.area_mm2},
                     {"material_removal_rate_mm3_s", k.material_removal_rate_mm3_s}};
  j["heat"] = {{"specific_energy_j_mm3", r.heat.specific_energy_j_mm3},
               {"cutting_power_w", r.heat.cutting_power_w},
               {"heat_partition", r.heat.heat_partition},
               {"heat_to_workpiece_w", r.heat.heat_to_workpiece_w}};
  j["disturbances"] = {{"enabled", !o.no_disturbances},
                       {"seed", o.seed},
                       {"heat_partition_factor", r.disturbances.heat_partition_factor},
                       {"expansion_factor", r.disturbances.expansion_factor},
                       {"ambient_drift_k_per_h", r.disturbances.ambient_drift_k_per_h},
                       {"measurement_noise_std_um", r.disturbances.measurement_noise_std_um}};
  j["features"] = {{"max_elongation_um", r.features.max_elongation_um},
                   {"settle_time_s", r.features.settle_time_s},
                   {"settled_before_tail", settle.settled_before_tail},
                   {"settle_message", settle.message}};
  const auto& s = r.summary;
  j["summary"] = {{"time_steps", s.time_steps},
                  {"cells", s.cells},
                  {"simulated_time_s", s.simulated_time_s},
                  {"heat_in_j", s.heat_in_j},
                  {"heat_stored_j", s.heat_stored_j},
                  {"heat_lost_j", s.heat_lost_j},
                  {"energy_balance_rel_error", s.energy_balance_rel_error},
                  {"peak_temperature_rise_k", s.peak_temperature_rise_k},
                  {"termination", sim::ToString(s.termination)},
                  {"message", s.message}};
  if (!o.out_path.empty()) j["curve_file"] = o.out_path;
  return j;
}

void Run(const SimulateOptions& o) {
  CheckOutputs({{"--screw", o.screw_path}}, {{"--out", o.out_path}});
  const screw::Screw screw = screw::ReadScrew(o.screw_path);
  sim::SimOptions options;
  options.duration_s = o.duration_s;
  options.cell_size_mm = o.cell_size_mm;
  options.time_step_s = o.time_step_s;
  sim::DisturbanceOptions dist;
  dist.enabled = !o.no_disturbances;
  dist.seed = o.seed;
  const sim::SimulationResult r = sim::Simulate(screw, options, dist);
  const fit::SettleAnalysis settle = fit::AnalyzeSettle(r.curve, options.settle);
  if (!settle.settled_before_tail)
    Warn("the curve has not settled before the last " +
         std::to_string(static_cast<int>(options.settle.tail_fraction * 100)) +
         " % of the record; simulate longer (--duration-s)");
  if (!o.out_path.empty()) {
    std::ostringstream cmd;
    cmd << " command: whirl simulate --screw " << o.screw_path << " --duration-s " << o.duration_s
        << (o.no_disturbances ? " --no-disturbances" : " --seed " + std::to_string(o.seed))
        << " --out " << o.out_path;
    WriteElongationCurve(o.out_path, r.curve,
                         {" SIMULATED elongation of the unmachined section at the cut point (um)",
                          cmd.str(), " " + r.summary.BriefReport()});
  }
  if (o.json) {
    PrintJson(ResultJson(screw, r, settle, o));
    return;
  }
  // Human output rounds to what a process engineer reads (4 significant digits); --json and the
  // curve file keep full precision.
  const auto g = [](double x) { return FormatSignificant(x, 4); };
  const auto& k = r.kinematics;
  std::cout << "screw " << screw.name << ": " << g(screw.process.diameter_mm) << " mm x "
            << g(screw.process.pitch_mm) << " mm lead, thread " << g(screw.thread_length_mm)
            << " mm\n"
            << "  ring " << g(k.ring_speed_rpm) << " r/min on a " << g(k.tool_circle_diameter_mm)
            << " mm tool circle, workpiece " << g(k.workpiece_speed_rpm) << " r/min, axial feed "
            << g(k.axial_feed_mm_min) << " mm/min, whole thread " << g(k.cutting_time_s / 3600.0)
            << " h\n"
            << "  cutting power " << g(r.heat.cutting_power_w) << " W, into the workpiece "
            << g(r.heat.heat_to_workpiece_w * r.disturbances.heat_partition_factor) << " W\n"
            << "  max_elongation_um " << g(r.features.max_elongation_um) << "\n  settle_time_s "
            << g(r.features.settle_time_s) << "\n  " << r.summary.BriefReport() << "\n";
  if (!o.out_path.empty()) std::cout << "  curve written to " << o.out_path << "\n";
}

}  // namespace

void RegisterSimulate(CLI::App& app) {
  auto opts = std::make_shared<SimulateOptions>();
  auto* sub = app.add_subcommand(
      "simulate",
      "Simulate the thermal elongation (um) of the unmachined section of a screw during hard\n"
      "whirling (1D transient heat conduction with a moving source, src/lab/sim/simulator.h) and\n"
      "print its features: max_elongation_um (plateau) and settle_time_s.\n"
      "Disturbances (workpiece variation, ambient drift, +-0.5 um sensor noise) are ON unless\n"
      "--no-disturbances; they are seeded by --seed.\n"
      "Resource limits (an error beyond them): cells = length_mm / --cell-size-mm in [3, 200000],\n"
      "time steps = simulated time / --time-step-s <= 2e6 and cells x steps <= 2e9; a blank is at\n"
      "most 20000 mm long.\n" +
          ProcessLimitsHelp());
  sub->add_option("--screw", opts->screw_path,
                  "screw JSON (schema_version 1: the five inputs hardness_hrc, diameter_mm, "
                  "pitch_mm, raceway_radius_mm, cutting_speed_m_min; length_mm, thread_length_mm; "
                  "optional process {tool_count, feed_per_tooth_mm, tool_circle_margin_mm, "
                  "thread_start_offset_mm, ambient_temperature_c}); see "
                  "datasets/screws/reference_80x10x6000.json")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", opts->out_path,
                  "write the recorded curve as CSV time_s,elongation_um (s, um), atomically");
  sub->add_option("--duration-s", opts->duration_s,
                  "simulated cutting time in s; 0 = the whole thread (hours)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  sub->add_flag("--no-disturbances", opts->no_disturbances,
                "pure physics: no workpiece variation, ambient drift or measurement noise");
  AddSeedOption(sub, &opts->seed, "seed of the disturbances (default 1)");
  sub->add_option("--cell-size-mm", opts->cell_size_mm, "finite-volume cell size in mm")
      ->check(PositiveNumber())
      ->capture_default_str();
  sub->add_option("--time-step-s", opts->time_step_s, "BDF2 time step in s")
      ->check(PositiveNumber())
      ->capture_default_str();
  sub->add_flag("--json", opts->json, "print the result as JSON on stdout");
  sub->callback([opts] { Run(*opts); });
}

}  // namespace whirl::cli
