// whirl surface: thermal error over the worktable: synthetic fields, cubic polynomial or
// B-spline surfaces, prediction at any position, the choice between the two, and the 840D line per
// axis. The library is src/product/surface (its header surface/surface.h is the manual).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/output_dir.h"
#include "drift/fit.h"
#include "surface/choice.h"
#include "drift/run_file.h"
#include "surface/drift_adapter.h"
#include "surface/line840d.h"
#include "surface/report.h"
#include "surface/surface.h"
#include "synthetic/surface.h"

namespace whirl::cli {
namespace {

using namespace whirl::surface;

// --- synth -------------------------------------------------------------------------------------

struct SynthCli {
  synthetic::SyntheticOptions synth;
  std::string field = "smooth";
  std::string out;
  bool json = false;
};

void RunSynth(const SynthCli& o) {
  CheckOutputs({}, {{"--out", o.out}});
  synthetic::SyntheticOptions s = o.synth;
  s.field = synthetic::ParseSyntheticField(o.field);
  const auto points = synthetic::SyntheticPoints(s);
  WriteFileAtomic(o.out, FormatPointsCsv(points, synthetic::SyntheticProvenance(s)));
  if (o.json)
    PrintJson({{"schema", "whirl.surface_synth"},
               {"schema_version", 1},
               {"out", o.out},
               {"field", o.field},
               {"point_count", points.size()}});
  else
    std::printf("wrote %s: %zu points (%s field, %d x %d grid, noise %.2f um, seed %llu)\n",
                o.out.c_str(), points.size(), o.field.c_str(), s.nx, s.ny, s.noise_um,
                static_cast<unsigned long long>(s.seed));
}

void SetupSynth(CLI::App& parent) {
  auto o = std::make_shared<SynthCli>();
  auto* sub = parent.add_subcommand(
      "synth",
      "Write a documented synthetic thermal-error field as a points CSV (x_mm,y_mm,error_um).\n"
      "No public whole-table measurements exist; formulas in src/lab/synthetic/surface.h:\n"
      "  smooth: 10 + 10 s + 6 t + 4 s^2 + 3 s t - 2 t^2 + 5 s^3 + 2 s t^2 um, s = x/Lx, t = y/Ly\n"
      "  bump:   smooth + A exp(-r^2/(2 sigma^2)) at (0.7 Lx, 0.35 Ly), sigma = f Lx\n"
      "plus normal noise; the file's '#' lines record the field, options and seed.");
  sub->add_option("--field", o->field, "smooth | bump (default smooth)")
      ->check(CLI::IsMember({"smooth", "bump"}));
  sub->add_option("--nx", o->synth.nx,
                  "grid columns along X (2..200, default 9; nx * ny <= 10000, the points limit)")
      ->check(NumberIn(2, 200));
  sub->add_option("--ny", o->synth.ny, "grid rows along Y (2..200, default 7)")
      ->check(NumberIn(2, 200));
  sub->add_option("--length-x-mm", o->synth.length_x_mm, "table travel in X, mm (default 800)")
      ->check(NumberIn(1e-3, kMaxCoordinateMm));
  sub->add_option("--length-y-mm", o->synth.length_y_mm, "table travel in Y, mm (default 500)")
      ->check(NumberIn(1e-3, kMaxCoordinateMm));
  sub->add_option("--noise-um", o->synth.noise_um,
                  "standard deviation of the measurement noise, um (0..10, default 1)")
      ->check(NumberIn(0.0, 10.0));
  sub->add_option("--bump-um", o->synth.bump_um, "bump amplitude A, um (0..100, default 15)")
      ->check(NumberIn(0.0, 100.0));
  sub->add_option("--bump-sigma-fraction", o->synth.bump_sigma_fraction,
                  "bump width sigma / Lx (0.01..1, default 0.1)")
      ->check(NumberIn(0.01, 1.0));
  AddSeedOption(sub, &o->synth.seed, "noise seed (default 1)");
  sub->add_option("--out", o->out, "points CSV to write")->required();
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunSynth(*o); });
}

// --- fit ---------------------------------------------------------------------------------------

struct FitCli {
  std::string points, method = "cubic", out, report;
  int degree = 3;
  bool json = false, no_plots = false;
};

void RunFit(const FitCli& o, const std::string& command) {
  CheckOutputs({{"--points", o.points}}, {{"--out", o.out}}, {{"--out-dir", o.report}});
  const auto points = ReadSurfacePoints(o.points);
  SurfaceFit fit = FitSurface(points, {ParseMethod(o.method), o.degree});
  fit.provenance = {command + " --points " + o.points + " --method " + o.method + " --degree " +
                    std::to_string(o.degree)};
  std::optional<MethodComparison> choice;
  std::vector<AxisLine> lines;
  if (!o.report.empty()) {
    ChoiceOptions co;
    co.degree = o.degree;
    choice = CompareMethods(points, co);
    for (char along : {'x', 'y'}) {
      AxisLineOptions lo;
      lo.along = along;
      lo.axis = along == 'x' ? "X" : "Y";
      lines.push_back(FitAxisLine(fit.surface, lo));
    }
  }
  const nlohmann::json j = SurfaceFitToJson(fit);
  if (!o.report.empty()) {
    SurfaceReportOptions ro;
    ro.provenance = fit.provenance;
    ro.plots = !o.no_plots;
    if (!o.out.empty()) ro.also_write = {{o.out, JsonFileText(j)}};  // with the report or neither
    const auto r = WriteSurfaceReport(o.report, fit, choice ? &*choice : nullptr, lines, ro);
    for (const auto& w : r.warnings) Warn(w);
    std::cerr << "report: " << r.index_html.string() << "\n";
  } else if (!o.out.empty()) {
    WriteJsonFile(o.out, j);
  }
  if (o.json)
    PrintJson(j);
  else
    std::printf("%s%s", FormatFitText(fit).c_str(),
                o.out.empty() ? "" : ("wrote " + o.out + "\n").c_str());
}

void SetupFit(CLI::App& parent, const std::string& command) {
  auto o = std::make_shared<FitCli>();
  auto* sub = parent.add_subcommand(
      "fit",
      "Fit a thermal-error surface to the points of one moment.\n"
      "Input: CSV x_mm,y_mm,error_um (positions mm, error um), one row per measured point.\n"
      "cubic:   dE = a0 + a1 X + a2 Y + a3 X^2 + a4 XY + a5 Y^2 + a6 X^3 + a7 X^2Y + a8 XY^2\n"
      "         + a9 Y^3 by least squares (QR, in normalized coordinates); needs >= 10 distinct\n"
      "         positions not on one cubic curve; reports the condition number, the residual\n"
      "         and the leave-one-out error per point (um).\n"
      "bspline: tensor-product B-spline of degree p interpolating a complete rectangular grid\n"
      "         (>= p + 1 rows and columns, <= 200 each); clamped knots by averaging; no\n"
      "         extrapolation; leave-one-out by dropping the point's row or column.\n"
      "At most 10000 points; |x|,|y| <= 100000 mm.");
  sub->add_option("--points", o->points, "points CSV (x_mm,y_mm,error_um)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--method", o->method, "cubic | bspline (default cubic)")
      ->check(CLI::IsMember({"cubic", "bspline"}));
  sub->add_option("--degree", o->degree, "B-spline degree p in X and Y (1..5, default 3)")
      ->check(NumberIn(1, kMaxDegree));
  sub->add_option("--out", o->out, "surface JSON to write (schema whirl.surface)");
  auto* report = sub->add_option("--out-dir", o->report,
                                 "directory for an HTML page: map of the surface with the measured "
                                 "points, cubic-vs-B-spline choice, 840D line per axis (" +
                                     std::string(kOutputDirRule) + ")");
  AddDeprecatedAlias(sub, report, "--report");
  sub->add_flag("--no-plots", o->no_plots, "with --out-dir: skip gnuplot (page without the map)");
  sub->add_flag("--json", o->json, "machine output: the surface JSON on stdout");
  sub->callback([o, command] { RunFit(*o, command); });
}

// --- predict -----------------------------------------------------------------------------------

struct PredictCli {
  std::string surface, input, out;
  double x = NAN, y = NAN;
  bool json = false;
};

void RunPredict(const PredictCli& o) {
  const bool single = !std::isnan(o.x) || !std::isnan(o.y);
  if (single == !o.input.empty())
    throw InputError("surface predict: give either --x-mm X --y-mm Y or --input XY.csv");
  if (single && (std::isnan(o.x) || std::isnan(o.y)))
    throw InputError("surface predict: --x-mm and --y-mm go together");
  CheckOutputs({{"--surface", o.surface}, {"--input", o.input}}, {{"--out", o.out}});
  const Surface s = ReadSurfaceFile(o.surface);
  const auto xy =
      single ? std::vector<std::pair<double, double>>{{o.x, o.y}} : ReadPositions(o.input);
  const auto p = Predict(s, xy);
  std::size_t outside = 0;
  for (const auto& q : p) outside += q.inside ? 0 : 1;
  if (outside)
    Warn(std::to_string(outside) + " of " + std::to_string(p.size()) +
         " positions lie outside the measured rectangle: the cubic extrapolates there");
  if (!o.out.empty())
    WriteFileAtomic(
        o.out, FormatPredictionsCsv(p, {" predicted by whirl surface predict from " + o.surface}));
  if (o.json) {
    PrintJson(PredictionsToJson(s, p));
    return;
  }
  std::printf("%12s %12s %12s\n", "x_mm", "y_mm", "error_um");
  for (const auto& q : p)
    std::printf("%12.3f %12.3f %12.4f%s\n", q.x_mm, q.y_mm, q.error_um,
                q.inside ? "" : "  (extrapolated)");
}

void SetupPredict(CLI::App& parent) {
  auto o = std::make_shared<PredictCli>();
  auto* sub = parent.add_subcommand(
      "predict",
      "Thermal error (um) at table positions (mm) from a surface file.\n"
      "B-spline surfaces refuse positions outside the measured grid; cubic surfaces extrapolate\n"
      "with a warning (inside_measured_rectangle false in --json).");
  sub->add_option("--surface", o->surface, "surface JSON from 'whirl surface fit'")
      ->required()
      ->check(CLI::ExistingFile);
  AddDeprecatedAlias(
      sub,
      sub->add_option("--x-mm", o->x, "table X, mm (with --y-mm, instead of --input)")
          ->check(NumberIn(kAxisPositionRange)),
      "--x");
  AddDeprecatedAlias(
      sub,
      sub->add_option("--y-mm", o->y, "table Y, mm (with --x-mm, instead of --input)")
          ->check(NumberIn(kAxisPositionRange)),
      "--y");
  sub->add_option("--input", o->input, "CSV of positions x_mm,y_mm (at most 10000 rows)")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", o->out, "CSV to write: x_mm,y_mm,error_um");
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunPredict(*o); });
}

// --- compare -----------------------------------------------------------------------------------

struct CompareCli {
  std::string points;
  ChoiceOptions choice;
  bool json = false;
};

void RunCompare(const CompareCli& o) {
  const MethodComparison c = CompareMethods(ReadSurfacePoints(o.points), o.choice);
  if (o.json)
    PrintJson(ComparisonToJson(c));
  else
    std::printf("%s", FormatComparisonText(c).c_str());
}

void SetupCompare(CLI::App& parent) {
  auto o = std::make_shared<CompareCli>();
  auto* sub = parent.add_subcommand(
      "compare",
      "Cubic polynomial or B-spline? Leave-one-out error (um) of both on the measured points,\n"
      "compared on the points where both are defined (not the grid corners), the\n"
      "recommendation (lower RMS; the cubic on a tie or for scattered points) and a note when\n"
      "the cubic oscillates at the edges (edge LOO RMS > ratio x interior, or the cubic leaves\n"
      "the measured range by more than a fraction of it; both by more than --min-excess-um).");
  sub->add_option("--points", o->points, "points CSV (x_mm,y_mm,error_um)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--degree", o->choice.degree, "B-spline degree (1..5, default 3)")
      ->check(NumberIn(1, kMaxDegree));
  sub->add_option("--edge-ratio", o->choice.edge_ratio,
                  "edge / interior LOO RMS that flags oscillation (> 1, default 1.5)")
      ->check(NumberIn(Range{1, std::numeric_limits<double>::max(), true}));
  sub->add_option("--overshoot-fraction", o->choice.overshoot_fraction,
                  "overshoot / measured range that flags oscillation (> 0, default 0.1)")
      ->check(PositiveNumber());
  sub->add_option("--min-excess-um", o->choice.min_excess_um,
                  "smallest excess that flags oscillation, um (default 0.5)")
      ->check(NonNegativeNumber("um"));
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunCompare(*o); });
}

// --- line --------------------------------------------------------------------------------------

struct LineCli {
  std::string surface, along = "x", sign = "subtract";
  AxisLineOptions line;
  double at_mm = NAN, ref_mm = NAN;
  bool json = false;
};

void RunLine(const LineCli& o) {
  AxisLineOptions lo = o.line;
  lo.along = o.along[0];
  lo.sign = interp::ParseSignConvention(o.sign);
  if (!std::isnan(o.at_mm)) lo.at_mm = o.at_mm;
  if (!std::isnan(o.ref_mm)) lo.ref_position_mm = o.ref_mm;
  const AxisLine l = FitAxisLine(ReadSurfaceFile(o.surface), lo);
  if (l.slope_capped)
    Warn("the line's slope exceeds MD32760; SD43910 is capped at +-" + FormatNumber(lo.md32760));
  if (o.json)
    PrintJson(AxisLineToJson(l));
  else
    std::printf("%s", FormatAxisLineText(l).c_str());
}

void SetupLine(CLI::App& parent) {
  auto o = std::make_shared<LineCli>();
  auto* sub = parent.add_subcommand(
      "line",
      "SINUMERIK 840D temperature compensation is linear per axis: dK = K0 + tan(beta)(P - P0).\n"
      "The least-squares line of the surface's error along one axis's travel (over the whole\n"
      "measured table, or one traverse with --at-mm) gives SD43900 (mm), SD43910 (-, capped by\n"
      "MD32760) and SD43920 (mm, MCS), with interp's sign convention (dK = s line / 1000).\n"
      "Reports what the line leaves uncorrected: max and RMS, um.");
  sub->add_option("--surface", o->surface, "surface JSON from 'whirl surface fit'")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--along", o->along, "surface coordinate the axis moves along: x | y")
      ->check(CLI::IsMember({"x", "y"}));
  sub->add_option("--axis", o->line.axis,
                  "840D axis name for $SA_...[axis]: a letter, then letters, digits or '_' "
                  "(default X)")
      ->check(AxisName());
  sub->add_option("--at-mm", o->at_mm,
                  "one traverse at this fixed other coordinate, mm (default: the whole table)")
      ->check(FiniteNumber());
  sub->add_option("--ref-position-mm", o->ref_mm,
                  "reference position P0 in surface coordinates, mm (default: travel start)")
      ->check(NumberIn(kAxisPositionRange));
  sub->add_option("--machine-offset-mm", o->line.machine_offset_mm,
                  "MCS position of the surface's coordinate origin on this axis, mm (default 0)")
      ->check(NumberIn(kAxisPositionRange));
  sub->add_option("--sign", o->sign, "subtract (dK = -line, default) | add")
      ->check(CLI::IsMember({"subtract", "add"}));
  sub->add_option("--md32760", o->line.md32760,
                  "MD32760 $MA_COMP_ADD_VELO_FACTOR: cap on |SD43910| (0..0.10, default 0.01)")
      ->check(Md32760Number());
  sub->add_option("--samples", o->line.samples, "samples per direction (2..1001, default 101)")
      ->check(NumberIn(2, 1001));
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunLine(*o); });
}

// --- points (per-point models, the surface method's first step) --------------------------------

struct PointsCli {
  std::string run, manifest, method = "cubic", out, predictions, state = "cutting";
  std::vector<std::string> train, sensors;
  double time_min = NAN;
  int degree = 3;
  bool json = false;
};

void RunPoints(const PointsCli& o) {
  std::vector<FlagPath> inputs{{"--run", o.run}, {"--manifest", o.manifest}};
  for (const auto& t : o.train) inputs.push_back({"--train", t});
  CheckOutputs(inputs, {{"--out", o.out}, {"--predictions", o.predictions}});
  const drift::RunState state = drift::ParseRunState(o.state);
  const drift::Run target = drift::ReadRun(o.run, state);
  std::vector<drift::Run> training;
  for (const auto& t : o.train) training.push_back(drift::ReadRun(t, state));
  if (training.empty()) training.push_back(target);
  const auto points = o.manifest.empty() ? PointColumnsFromHeader(target.error_names, o.run)
                                         : ReadPointManifest(o.manifest, target.error_names);
  drift::FitOptions fo;
  fo.sensors = o.sensors;
  DriftPointNotes notes;
  std::cerr << "fitting " << points.size() << " per-point models\n";
  const PointPredictions p =
      PredictAllPoints(points, DriftPointModel(training, target, fo, &notes), 0);
  const std::size_t k = NearestSample(target.time_min, o.time_min);
  SurfaceFit fit = FitSurface(PointsAtSample(p, k), {ParseMethod(o.method), o.degree});
  fit.provenance = {
      "whirl surface points --run " + o.run + " at time " + FormatNumber(target.time_min[k]) +
          (target.time_from_index ? " (sample index)" : " min"),
      "per-point models: " +
          std::string(o.sensors.empty() ? "Miao et al. selection + " : "given sensors, ") +
          "MLR (src/product/drift), trained on " +
          (o.train.empty() ? o.run : std::to_string(o.train.size()) + " run(s)")};
  for (const auto& pc : points)
    fit.provenance.push_back(pc.column + ": " + notes.by_column[pc.column]);
  std::vector<std::pair<std::filesystem::path, std::string>> files;  // both or neither
  if (!o.predictions.empty())
    files.emplace_back(o.predictions,
                       FormatPointPredictionsCsv(
                           p, target.time_min, target.time_from_index ? "sample" : "time_min",
                           {" per-point predictions, whirl surface points --run " + o.run}));
  if (!o.out.empty()) files.emplace_back(o.out, JsonFileText(SurfaceFitToJson(fit)));
  WriteFilesAtomic(files);
  if (o.json) {
    PrintJson(SurfaceFitToJson(fit));
    return;
  }
  for (const auto& line : fit.provenance) std::printf("%s\n", line.c_str());
  std::printf("%s", FormatFitText(fit).c_str());
}

void SetupPoints(CLI::App& parent) {
  auto o = std::make_shared<PointsCli>();
  auto* sub = parent.add_subcommand(
      "points",
      "Per-point models, then a surface: each error column of a position-tagged run\n"
      "file (drift run format: time_s|time_min, *_C temperatures, *_um errors, each error\n"
      "column named <name>_x<X>_y<Y>_um with X, Y in mm, or placed by --manifest) gets its own\n"
      "model from its sensitive temperatures (Miao et al.'s selection + MLR, src/product/drift) fitted on\n"
      "--train runs (default: the run itself); the P predictions at --time-min become the points\n"
      "of a cubic or B-spline surface (as 'surface fit').");
  sub->add_option("--run", o->run, "run file to predict (CSV)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--train", o->train, "training run file(s) (default: --run itself)")
      ->check(CLI::ExistingFile);
  sub->add_option("--manifest", o->manifest, "JSON placing error columns (surface/per_point.h)")
      ->check(CLI::ExistingFile);
  sub->add_option("--state", o->state,
                  "idle | cutting | unknown: state of the runs (default cutting)")
      ->check(CLI::IsMember({"idle", "cutting", "unknown"}));
  sub->add_option("--sensors", o->sensors,
                  "temperature columns to use (default: Miao et al.'s selection)")
      ->delimiter(',');
  sub->add_option("--time-min", o->time_min, "moment of the surface, min (nearest sample)")
      ->check(FiniteNumber())
      ->required();
  sub->add_option("--method", o->method, "cubic | bspline (default cubic)")
      ->check(CLI::IsMember({"cubic", "bspline"}));
  sub->add_option("--degree", o->degree, "B-spline degree (1..5, default 3)")
      ->check(NumberIn(1, kMaxDegree));
  sub->add_option("--out", o->out, "surface JSON to write");
  sub->add_option("--predictions", o->predictions,
                  "CSV of every point's prediction per sample, um");
  sub->add_flag("--json", o->json, "machine output: the surface JSON on stdout");
  sub->callback([o] { RunPoints(*o); });
}

}  // namespace

void RegisterSurface(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "surface",
      "Thermal error over the whole worktable: cubic polynomial or B-spline surface\n"
      "from the errors at measured points, prediction anywhere on the table, the choice between\n"
      "the two, and the 840D per-axis line (SD43900/SD43910/SD43920).");
  sub->require_subcommand(1);
  SetupSynth(*sub);
  SetupFit(*sub, "whirl surface fit");
  SetupPredict(*sub);
  SetupCompare(*sub);
  SetupLine(*sub);
  SetupPoints(*sub);
}

}  // namespace whirl::cli
