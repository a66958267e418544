// whirl design: which screws to measure (src/product/design/design.h): the first design for the power
// law on log inputs, or the next screws from a trained model's uncertainty, with the stop rule.
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/process.h"
#include "design/design.h"
#include "workpiece/model.h"

namespace whirl::cli {
namespace {

struct DesignCliOptions {
  std::string candidates_path, model_path, out_path, measured_path;
  std::array<std::string, ProcessInputs::kCount> ranges;
  int count = 0, levels = 3, space_filling = 0, inside = design::kInsideAuto;
  std::string criterion = "d", variance = design::ToString(design::NextRule{}.model);
  std::string potential_terms = design::ToString(design::BayesPrior{}.terms);
  double tau = design::BayesPrior{}.tau;
  std::string fill_rule = design::ToString(design::SpaceFilling{}.rule);
  std::string fill_when = design::ToString(design::SpaceFilling{}.when);
  double departure_ratio = design::NextRule{}.departure_ratio;
  double length_scale = design::NextRule{}.length_scale;
  double switch_ratio = design::NextRule{}.switch_ratio;
  std::string evidence = design::ToString(design::NextRule{}.evidence);
  double tolerance_um = 0, tolerance_s = 0;
  bool json = false;
};

const std::array<const char*, ProcessInputs::kCount> kDesignRangeFlags = {
    "--hardness-hrc-range", "--diameter-mm-range", "--pitch-mm-range",
    "--raceway-radius-mm-range", "--cutting-speed-m-min-range"};

// "LO..HI" (or one value for an input the shop keeps fixed).
std::pair<double, double> ParseDesignRange(const std::string& flag, const std::string& text) {
  const auto dots = text.find("..");
  const auto lo = ParseDecimal(dots == std::string::npos ? text : text.substr(0, dots));
  const auto hi = dots == std::string::npos ? lo : ParseDecimal(text.substr(dots + 2));
  if (!lo || !hi)
    throw InputError(flag + " '" + text + "': expected LO..HI with two decimal numbers, e.g. 6..16");
  return {*lo, *hi};
}

// The candidate list and where each came from ("line N" of the CSV, or "grid").
struct DesignCandidates {
  std::string source;
  std::vector<ProcessInputs> inputs;
  std::vector<int> lines;  // empty for a grid
};

DesignCandidates ReadDesignCandidates(const DesignCliOptions& o) {
  DesignCandidates c;
  std::string given, missing;
  for (int j = 0; j < ProcessInputs::kCount; ++j)
    (o.ranges[j].empty() ? missing : given) += std::string(" ") + kDesignRangeFlags[j];
  if (!o.candidates_path.empty()) {
    if (!given.empty())
      throw InputError("design: give either --candidates CSV or the ranges, not both (got" +
                       given + ")");
    const ProcessTable t = ReadProcessTable(o.candidates_path, /*require_targets=*/false);
    if (t.inputs.empty())
      throw InputError(o.candidates_path + ": the candidate list is empty (a header and no rows)");
    c.source = o.candidates_path;
    c.inputs = t.inputs;
    c.lines = t.line_numbers;
    return c;
  }
  if (!missing.empty())
    throw InputError("design: give --candidates CSV or all five ranges (missing:" + missing + ")");
  design::InputRanges r;
  for (int j = 0; j < ProcessInputs::kCount; ++j)
    std::tie(r.lo[j], r.hi[j]) = ParseDesignRange(kDesignRangeFlags[j], o.ranges[j]);
  r.Validate(kDesignRangeFlags);
  c.inputs = design::GridCandidates(r, o.levels);
  c.source = "grid of " + std::to_string(o.levels) + " levels per input (log spacing), " +
             std::to_string(c.inputs.size()) + " candidates";
  return c;
}

std::string WhereFrom(const DesignCandidates& c, int i) {
  return c.lines.empty() ? "grid " + std::to_string(i + 1) : "line " + std::to_string(c.lines[i]);
}

nlohmann::json InputsJson(const ProcessInputs& x) {
  nlohmann::json j;
  const auto a = x.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i) j[kInputColumns[i]] = a[i];
  return j;
}

// The picks as JSON (both modes): rank, source, inputs, the mode's sd fields (`sd`), why.
nlohmann::json PicksJson(const DesignCandidates& c, const std::vector<design::Pick>& picks,
                         const std::function<void(const design::Pick&, nlohmann::json*)>& sd) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t r = 0; r < picks.size(); ++r) {
    const design::Pick& p = picks[r];
    nlohmann::json j = {{"rank", r + 1},
                        {"source", WhereFrom(c, p.candidate)},
                        {"inputs", InputsJson(c.inputs[p.candidate])},
                        {"why", p.why}};
    sd(p, &j);
    out.push_back(std::move(j));
  }
  return out;
}

// The CSV of the picks (both modes): rank, where, five inputs, the sd columns, why.
std::string DesignCsv(const DesignCandidates& c, const std::vector<design::Pick>& picks,
                      bool next, const std::string& command) {
  std::ostringstream s;
  s << "# whirl design: " << command << "\n# candidates: " << c.source << "\n";
  s << (next ? "# sd: predictive sd now and expected after measuring this screw and those ranked "
               "before it (um, s)\n"
             : "# sd_factor: sd of the power law's ln prediction at this screw in units of the "
               "relative measurement scatter, before and after it (in the ranked order)\n");
  s << "rank,source";
  for (auto* col : kInputColumns) s << "," << col;
  s << (next ? ",max_elongation_sd_now_um,max_elongation_sd_after_um,settle_time_sd_now_s,"
               "settle_time_sd_after_s"
             : ",sd_factor_before,sd_factor_after");
  s << ",why\n";
  for (std::size_t r = 0; r < picks.size(); ++r) {
    const auto& p = picks[r];
    s << r + 1 << "," << WhereFrom(c, p.candidate);
    for (double v : c.inputs[p.candidate].ToArray()) s << "," << FormatNumber(v);
    if (next)
      s << "," << FormatNumber(p.sd_now[0]) << "," << FormatNumber(p.sd_after[0]) << ","
        << FormatNumber(p.sd_now[1]) << "," << FormatNumber(p.sd_after[1]);
    else
      s << "," << (std::isfinite(p.sd_now[0]) ? FormatNumber(p.sd_now[0]) : "") << ","
        << FormatNumber(p.sd_after[0]);
    s << ",\"" << p.why << "\"\n";  // why: library text without quotes
  }
  return s.str();
}

std::string InputsText(const ProcessInputs& x) {
  const auto a = x.ToArray();
  std::string t;
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    t += (i ? " " : "") + FormatSignificant(a[i], 4);
  return t;
}

design::NextRule RuleOf(const DesignCliOptions& o) {
  design::NextRule rule;
  rule.model = design::ParseNextModel(o.variance);
  rule.departure_ratio = o.departure_ratio;
  rule.length_scale = o.length_scale;
  rule.switch_ratio = o.switch_ratio;
  rule.evidence = design::ParseEvidence(o.evidence);
  return rule;
}

// The first design's criterion as the text report names it.
std::string CriterionText(const DesignCliOptions& o) {
  if (o.criterion == "d") return "D-optimal";
  if (o.criterion == "i") return "I-optimal";
  return "Bayesian D-optimal, potential terms " + o.potential_terms + ", tau " +
         FormatSignificant(o.tau, 3) + ",";
}

void RunFirstDesign(const DesignCliOptions& o, const DesignCandidates& c) {
  const design::BayesPrior bayes{design::ParsePotentialTerms(o.potential_terms), o.tau};
  const auto d = design::DesignPowerLaw(c.inputs, o.count, design::ParseCriterion(o.criterion),
                                        o.space_filling, o.inside, RuleOf(o),
                                        design::ParseFillRule(o.fill_rule), bayes);
  const std::string csv = DesignCsv(c, d.picks, false, "first design, criterion " + o.criterion);
  if (!o.out_path.empty()) WriteFileAtomic(o.out_path, csv);
  if (o.json) {
    const nlohmann::json picks =
        PicksJson(c, d.picks, [](const design::Pick& p, nlohmann::json* j) {
          (*j)["sd_factor_before"] =
              std::isfinite(p.sd_now[0]) ? nlohmann::json(p.sd_now[0]) : nlohmann::json(nullptr);
          (*j)["sd_factor_after"] = p.sd_after[0];
        });
    nlohmann::json out = {{"mode", "first"}, {"criterion", o.criterion}, {"candidates", c.source},
               {"candidate_count", c.inputs.size()}, {"coefficients", d.coefficients},
               {"varying_inputs", d.inputs}, {"log_det_per_screw", d.log_det},
               {"space_filling", d.space_filling}, {"space_filling_rule", o.fill_rule},
               {"inside", d.inside},
               {"min_distance", d.min_distance},
               {"mean_sd_factor", d.mean_sd_factor}, {"max_sd_factor", d.max_sd_factor},
               {"picks", picks}};
    if (d.criterion == design::Criterion::kBayesD) {
      out["potential_terms"] = o.potential_terms;
      out["potential_columns"] = d.potential_terms;
      out["tau"] = o.tau;
      out["bayes_log_det"] = d.bayes_log_det;
    }
    PrintJson(out);
    return;
  }
  std::cout << "first design (" << CriterionText(o) << " for the power law "
            << "on log inputs"
            << (d.inside > 0 ? ", the last " + std::to_string(d.inside) +
                                   " of them inside the range by the power-gp variance"
                             : std::string())
            << "): " << o.count << " of " << c.inputs.size() << " candidates (" << c.source
            << ")\n";
  std::cout << "rank  source      " << JoinFields({kInputColumns.begin(), kInputColumns.end()})
            << "\n";
  for (std::size_t r = 0; r < d.picks.size(); ++r) {
    const auto& p = d.picks[r];
    std::printf("%4zu  %-10s  %s\n      why: %s\n", r + 1, WhereFrom(c, p.candidate).c_str(),
                InputsText(c.inputs[p.candidate]).c_str(), p.why.c_str());
  }
  std::cout << "expected prediction sd of ln y over the candidates: mean "
            << FormatSignificant(d.mean_sd_factor, 3) << ", max "
            << FormatSignificant(d.max_sd_factor, 3)
            << " times the relative measurement scatter (5 % scatter: mean "
            << FormatSignificant(5 * d.mean_sd_factor, 3) << " %), if the power law holds\n";
  if (o.count < 8)
    std::cout << "note: 'whirl train' needs at least 8 rows; measure " << 8 - o.count
              << " more (whirl design --model) before training\n";
  if (!o.out_path.empty()) std::cout << "written: " << o.out_path << "\n";
}

void RunNextScrews(const DesignCliOptions& o, const DesignCandidates& c) {
  const auto model = workpiece::LoadWorkpieceModel(o.model_path);
  design::StopRule rule;
  rule.tolerance = {o.tolerance_um, o.tolerance_s};
  design::SpaceFilling fill;
  fill.screws = o.space_filling;
  fill.rule = design::ParseFillRule(o.fill_rule);
  fill.when = design::ParseFillWhen(o.fill_when);
  if (!o.measured_path.empty()) {
    ProcessTable measured = ReadProcessTable(o.measured_path, /*require_targets=*/false);
    fill.measured = std::move(measured.inputs);
    fill.measured_targets = std::move(measured.targets);  // empty without target columns
  }
  design::NextDesign d;
  try {
    d = design::DesignNext(model, c.inputs, o.count, rule, c.lines, fill, RuleOf(o));
  } catch (const InputError& e) {
    throw InputError("design --model " + o.model_path + " --candidates " + c.source + ": " +
                     e.what());
  }
  const std::string csv = DesignCsv(c, d.picks, true, "next screws from " + o.model_path);
  if (!o.out_path.empty()) WriteFileAtomic(o.out_path, csv);
  if (o.json) {
    const nlohmann::json picks =
        PicksJson(c, d.picks, [](const design::Pick& p, nlohmann::json* j) {
          (*j)["max_elongation_sd_now_um"] = p.sd_now[0];
          (*j)["max_elongation_sd_after_um"] = p.sd_after[0];
          (*j)["settle_time_sd_now_s"] = p.sd_now[1];
          (*j)["settle_time_sd_after_s"] = p.sd_after[1];
        });
    nlohmann::json j = {{"mode", "next"}, {"model", o.model_path}, {"variance", o.variance},
                        {"model_describe", model.Describe()}, {"candidates", c.source},
                        {"candidate_count", c.inputs.size()}, {"picks", picks},
                        {"space_filling", d.space_filling}, {"space_filling_rule", o.fill_rule},
                        {"rms_sd_now", {{"max_elongation_um", d.rms_sd_now[0]},
                                        {"settle_time_s", d.rms_sd_now[1]}}},
                        {"rms_sd_after", {{"max_elongation_um", d.rms_sd_after[0]},
                                          {"settle_time_s", d.rms_sd_after[1]}}},
                        {"rms_sd_floor", {{"max_elongation_um", d.rms_sd_floor[0]},
                                          {"settle_time_s", d.rms_sd_floor[1]}}}};
    if (design::ParseNextModel(o.variance) == design::NextRule::Model::kSwitch) {
      j["lack_of_fit_ratio"] = {{"max_elongation_um", d.lack_of_fit_ratio[0]},
                                {"settle_time_s", d.lack_of_fit_ratio[1]}};
      j["departure"] = {{"max_elongation_um", d.departure[0]}, {"settle_time_s", d.departure[1]}};
      j["departure_evidence"] = o.evidence;
    }
    if (!d.stop.empty())
      j["stop"] = {{"decision", d.stop}, {"tolerance_um", o.tolerance_um},
                   {"tolerance_s", o.tolerance_s}, {"reason", d.stop_reason},
                   {"screws_to_tolerance", d.screws_to_tolerance}};
    PrintJson(j);
    return;
  }
  std::cout << "next screws (integrated variance reduction, --variance " << o.variance
            << "; model " << model.Describe() << "): "
            << o.count << " of " << c.inputs.size() << " candidates (" << c.source << ")\n";
  std::cout << "rank  source      inputs (" << JoinFields({kInputColumns.begin(), kInputColumns.end()})
            << ")\n      sd now -> after: max_elongation [um], settle_time [s]\n";
  for (std::size_t r = 0; r < d.picks.size(); ++r) {
    const auto& p = d.picks[r];
    std::printf("%4zu  %-10s  %s\n      sd %s -> %s um, %s -> %s s\n      why: %s\n", r + 1,
                WhereFrom(c, p.candidate).c_str(), InputsText(c.inputs[p.candidate]).c_str(),
                FormatSignificant(p.sd_now[0], 3).c_str(), FormatSignificant(p.sd_after[0], 3).c_str(),
                FormatSignificant(p.sd_now[1], 3).c_str(), FormatSignificant(p.sd_after[1], 3).c_str(),
                p.why.c_str());
  }
  std::cout << "RMS predictive sd over the list: max_elongation " << FormatSignificant(d.rms_sd_now[0], 3)
            << " -> " << FormatSignificant(d.rms_sd_after[0], 3) << " um (floor "
            << FormatSignificant(d.rms_sd_floor[0], 3) << "), settle_time "
            << FormatSignificant(d.rms_sd_now[1], 3) << " -> " << FormatSignificant(d.rms_sd_after[1], 3)
            << " s (floor " << FormatSignificant(d.rms_sd_floor[1], 3) << ")\n";
  if (!d.stop.empty()) std::cout << "stop rule: " << d.stop << ": " << d.stop_reason << "\n";
  if (fill.screws > 0 && d.space_filling == 0)
    std::cout << "note: --space-filling-when departure: no departure from the power law (lack-of-fit "
                 "ratio max_elongation "
              << FormatSignificant(d.lack_of_fit_ratio[0], 3) << ", settle_time "
              << FormatSignificant(d.lack_of_fit_ratio[1], 3) << ", both <= --switch-ratio "
              << FormatSignificant(RuleOf(o).switch_ratio, 3) << "): the " << fill.screws
              << " space-filling pick(s) were made by variance instead\n";
  if (!fill.measured.empty() &&
      static_cast<int>(fill.measured.size()) != model.training_samples)
    std::cout << "note: --measured " << o.measured_path << " holds " << fill.measured.size()
              << " screws, the model was trained on " << model.training_samples
              << " rows: are they the same table?\n";
  if (!o.out_path.empty()) std::cout << "written: " << o.out_path << "\n";
}

// --criterion bayes-d is a first design's; --potential-terms and --tau are its alone.
void CheckBayesOptions(const DesignCliOptions& o) {
  const design::BayesPrior defaults;
  const bool bayes = design::ParseCriterion(o.criterion) == design::Criterion::kBayesD;
  if (bayes && !o.model_path.empty())
    throw InputError("design: --criterion bayes-d is a first design's (without --model); the "
                     "next screws follow --variance");
  if (!bayes && (o.potential_terms != design::ToString(defaults.terms) || o.tau != defaults.tau))
    throw InputError("design: --potential-terms and --tau need --criterion bayes-d");
}

void RunDesign(const DesignCliOptions& o) {
  CheckOutputs({{"--candidates", o.candidates_path}, {"--model", o.model_path},
                {"--measured", o.measured_path}},
               {{"--out", o.out_path}});
  design::ParseFillRule(o.fill_rule);  // bad spellings before any file is read
  design::ParseFillWhen(o.fill_when);
  design::ParseEvidence(o.evidence);
  design::ParsePotentialTerms(o.potential_terms);
  CheckBayesOptions(o);
  if (o.model_path.empty() && (o.tolerance_um > 0 || o.tolerance_s > 0))
    throw InputError("design: --tolerance-um / --tolerance-s need --model (the stop rule judges a "
                     "trained model's predictive sd)");
  const design::NextRule defaults;
  if (o.model_path.empty() && o.variance != design::ToString(defaults.model))
    throw InputError("design: --variance needs --model (it chooses the next screws; a first "
                     "design is D- or I-optimal, --criterion, with --inside screws by power-gp)");
  if (!o.model_path.empty() && o.inside != design::kInsideAuto)
    throw InputError("design: --inside is a first design's (without --model); the next screws "
                     "follow --variance");
  if (o.model_path.empty() && o.evidence != design::ToString(defaults.evidence))
    throw InputError("design: --departure-evidence needs --model (it judges a trained model's "
                     "choice and the measured screws)");
  if (o.model_path.empty() && o.fill_when != design::ToString(design::SpaceFilling{}.when))
    throw InputError("design: --space-filling-when needs --model (a first design's space-filling "
                     "screws are always its last ones)");
  if (o.model_path.empty() && !o.measured_path.empty())
    throw InputError("design: --measured needs --model (a first design has no measured screws)");
  const DesignCandidates c = ReadDesignCandidates(o);
  if (o.model_path.empty()) {
    try {
      RunFirstDesign(o, c);
    } catch (const InputError& e) {
      throw InputError(c.source + ": " + e.what());
    }
  } else {
    RunNextScrews(o, c);
  }
}

}  // namespace

void RegisterDesign(CLI::App& app) {
  auto o = std::make_shared<DesignCliOptions>();
  auto* sub = app.add_subcommand(
      "design",
      "Which screws to measure (src/product/design/design.h; evidence in docs/design.md).\n"
      "First design (no --model): the --count screws that best determine the power law of the\n"
      "five inputs (D- or I-optimal on log inputs), the last --inside (2) of them where a\n"
      "smooth departure from it is least known (--criterion bayes-d instead: Bayesian\n"
      "D-optimal, a prior on squared log inputs), from --candidates CSV (the screw types the\n"
      "shop makes: columns hardness_hrc, diameter_mm, pitch_mm, raceway_radius_mm,\n"
      "cutting_speed_m_min; other columns ignored) or from a grid over the five ranges.\n"
      "Next screws (--model M.json from 'whirl train', --measured TABLE.csv: the screws measured\n"
      "so far, with their targets): the --count candidates whose measurement most reduces the\n"
      "prediction variance over the list (integrated variance reduction, greedy batch). Whose\n"
      "variance (--variance switch, the default): per output, the model's own while the power\n"
      "law fits the measured screws (its leave-one-out error at most --switch-ratio times that\n"
      "of a power law with a smooth departure), else that of the power law with a smooth\n"
      "departure (--variance power-gp: a GP on the log inputs whose mean is the power law, the\n"
      "departure's sd --departure-ratio times the scatter, length --length-scale), which also\n"
      "looks inside the range, where the model's own power law sends every screw to its edges\n"
      "(docs/design.md). Each pick with the model's predictive sd now and expected after.\n"
      "Stop rule (--tolerance-um, --tolerance-s with --model): says whether the RMS predictive\n"
      "sd over the list is within tolerance (measurements no longer pay), cannot get there\n"
      "(the scatter alone is above it), or about how many more screws it takes.\n"
      "Output: a text table with why each screw was picked; --json; --out FILE writes a CSV.");
  sub->add_option("--count", o->count, "number of screws to pick (first design: at least the "
                                       "power law's coefficients, 6)")
      ->required()
      ->check(NumberIn(1, 100000));
  sub->add_option("--candidates", o->candidates_path, "candidate screws (CSV, five input columns)")
      ->check(CLI::ExistingFile);
  const std::array<const char*, ProcessInputs::kCount> what = {
      "hardness range LO..HI [HRC]", "diameter range LO..HI [mm]", "pitch (lead) range LO..HI [mm]",
      "raceway radius range LO..HI [mm]", "cutting speed range LO..HI [m/min]"};
  for (int j = 0; j < ProcessInputs::kCount; ++j)
    sub->add_option(kDesignRangeFlags[j], o->ranges[j],
                    std::string(what[j]) + " (instead of --candidates; one value: fixed)");
  sub->add_option("--levels", o->levels,
                  "grid levels per input over the ranges, log spacing")
      ->capture_default_str()
      ->check(NumberIn(2, 9));
  sub->add_option("--criterion", o->criterion,
                  "first design: d (D-optimal: the power law's coefficients), i (I-optimal: its "
                  "mean prediction variance over the candidates) or bayes-d (Bayesian "
                  "D-optimal, DuMouchel & Jones: also hedges against the --potential-terms "
                  "bending the power law; --inside 0 by default)")
      ->capture_default_str();
  sub->add_option("--potential-terms", o->potential_terms,
                  "with --criterion bayes-d: squares (of the centred log inputs) or "
                  "squares+interactions (also their pairwise products)")
      ->capture_default_str();
  sub->add_option("--tau", o->tau,
                  "with --criterion bayes-d: the potential terms' prior sd in units of the "
                  "measurement scatter [ratio] (toward 0: the D-optimal design)")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_option("--space-filling", o->space_filling,
                  "screws of --count chosen for space filling [screws]: each the candidate of "
                  "largest distance (standardized log inputs) to the screws before it and, with "
                  "--model, to the --measured ones; first design: after the optimal ones")
      ->capture_default_str()
      ->check(NumberIn(0, 100000));
  sub->add_option("--space-filling-rule", o->fill_rule,
                  "how --space-filling picks: maximin (the candidate farthest from the screws "
                  "before it: the edges of the range) or coverage (the candidate that most "
                  "lowers the mean distance from the list's screws to their nearest measured "
                  "one: where the list is dense, a hedge against a model that is wrong)")
      ->capture_default_str();
  sub->add_option("--space-filling-when", o->fill_when,
                  "with --model: always, or departure (a batch holds its --space-filling screws "
                  "only where --variance switch finds a departure from the power law on an "
                  "output)")
      ->capture_default_str();
  sub->add_option("--inside", o->inside,
                  "first design: screws of --count picked after the optimal ones by the "
                  "power-gp variance (see --variance) given those before, so that the first "
                  "table sees inside the range [screws] (default: 2, fewer where --count leaves "
                  "no room beyond the power law's coefficients; 0 with --criterion bayes-d)")
      ->check(NumberIn(0, 100000));
  sub->add_option("--measured", o->measured_path,
                  "with --model: the screws measured so far (CSV, five input columns; e.g. the "
                  "training table), needed by --variance power-gp | sum | auto | switch and "
                  "--space-filling; --variance switch also needs its target columns "
                  "max_elongation_um and settle_time_s")
      ->check(CLI::ExistingFile);
  sub->add_option("--variance", o->variance,
                  "next screws: whose variance the picks reduce: power-gp (a GP on the "
                  "standardized log inputs whose mean is the power law: the power law plus a "
                  "smooth departure, given the --measured screws; needs --measured), chosen (the "
                  "model's chosen family's own variance), sum (both, weighed equally), auto (per "
                  "output the chosen family's where cross-validation chose a GP, else power-gp; "
                  "needs --measured) or switch (per output the chosen family's while the power "
                  "law fits the --measured screws' targets, power-gp once they depart from it: "
                  "the power law's leave-one-out RMSE of ln y over the power-gp's above "
                  "--switch-ratio)")
      ->capture_default_str();
  sub->add_option("--departure-ratio", o->departure_ratio,
                  "power-gp (and --inside): the departure's sd over the measurement scatter's "
                  "sd [ratio]")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_option("--length-scale", o->length_scale,
                  "power-gp (and --inside): the departure's length scale in log inputs "
                  "standardized over the list and the measured screws [sd]")
      ->capture_default_str()
      ->check(PositiveNumber("sd"));
  sub->add_option("--switch-ratio", o->switch_ratio,
                  "with --variance switch: an output departs from the power law when the power "
                  "law's leave-one-out RMSE over the power-gp's exceeds this [ratio]")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_option("--departure-evidence", o->evidence,
                  "with --variance switch: what shows a departure from the power law: "
                  "lack-of-fit (--switch-ratio alone) or choice (that, or the model's choice not "
                  "keeping the power law alone for the output)")
      ->capture_default_str();
  sub->add_option("--model", o->model_path,
                  "trained family model ('whirl train' default): next screws instead of a first "
                  "design")
      ->check(CLI::ExistingFile);
  sub->add_option("--tolerance-um", o->tolerance_um,
                  "stop rule: tolerated RMS predictive sd of max elongation over the list [um] "
                  "(default: no stop rule for it)")
      ->check(PositiveNumber("um"));
  sub->add_option("--tolerance-s", o->tolerance_s,
                  "stop rule: tolerated RMS predictive sd of settle time over the list [s] "
                  "(default: no stop rule for it)")
      ->check(PositiveNumber("s"));
  sub->add_option("--out", o->out_path, "write the picked screws as CSV (rank, source line, "
                                        "inputs, sd columns, why)");
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunDesign(*o); });
}

}  // namespace whirl::cli
