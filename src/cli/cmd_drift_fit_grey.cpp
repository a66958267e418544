// whirl drift fit-grey: the grey-box machine estimator (drift/grey_box.h) fitted from a shop's
// measurement records (drift/measurement_file.h) to the sensors and priors of a spec
// (drift/grey_box_io.h), written as a grey box model file for `whirl drift nc --grey-model`.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/numbers.h"
#include "drift/grey_box.h"
#include "drift/grey_box_io.h"
#include "drift/grey_mix.h"
#include "drift/measurement_file.h"

namespace whirl::cli {
namespace {

struct FitGreyOptions {
  std::string records, spec, out;
  std::string validation = "forward-leads";
  bool json = false, grey_alone = false;
};

std::string FitGreyCounts(const drift::ShopRecord& r) {
  int counts[4] = {0, 0, 0, 0};
  for (const auto& m : r.records) ++counts[static_cast<int>(m.kind)];
  return std::to_string(counts[0]) + " probe, " + std::to_string(counts[1]) + " laser, " +
         std::to_string(counts[2]) + " lead, " + std::to_string(counts[3]) +
         " setup_check records on " + std::to_string(r.day_logs.size()) + " day logs";
}

void PrintFitGrey(const drift::GreyBoxModel& m) {
  std::printf("grey box: lags %s min, blank lag %s min, prior strength %s, validation RMSE %.2f "
              "um, %d readings\n",
              m.time_constants.empty() ? "none" : [&] {
                std::string s;
                for (double t : m.time_constants) s += (s.empty() ? "" : ", ") + MessageNumber(t);
                return s;
              }().c_str(),
              m.blank_sensor.empty() ? "-" : MessageNumber(m.blank_tau_min).c_str(),
              MessageNumber(m.prior_strength).c_str(), m.cv_rmse_um, m.rows);
  const auto per = static_cast<Eigen::Index>(1 + m.time_constants.size());
  // One line per input: its coefficients summed over its lags (each input's lags are stored
  // together; `first` is the position of names[0] among the part's inputs).
  const auto print_sums = [per](const char* part, const std::vector<std::string>& names,
                                const Eigen::VectorXd& coef, std::size_t first, const char* what) {
    for (std::size_t i = 0; i < names.size(); ++i)
      std::printf("  %-4s %-20s %9.3f %s\n", part, names[i].c_str(),
                  coef.segment(static_cast<Eigen::Index>(first + i) * per, per).sum(), what);
  };
  print_sums("K0", m.offset_sensors, m.a, 0, "um/K (sum over its lags)");
  print_sums("K0", m.offset_duty, m.a, m.offset_sensors.size(),
             "um per unit (duty input, sum over its lags)");
  std::printf("  G    intercept            %9.3f um per 1000 mm\n", m.slope_intercept_um_per_1000);
  print_sums("G", m.slope_sensors, m.g, 0, "um per 1000 mm per K (sum over its lags)");
  print_sums("G", m.slope_duty, m.g, m.slope_sensors.size(),
             "um per 1000 mm per unit (duty input, sum over its lags)");
  if (!m.blank_sensor.empty())
    std::printf("  G    blank (%s, latched) %9.3f um per 1000 mm per K\n", m.blank_sensor.c_str(),
                m.blank_um_per_1000_per_k);
}

// The mix part (drift/grey_mix.h) for a record of fewer than 2 x forward_days lead days, unless
// --grey-alone; the note line says w and why.
std::optional<drift::GreyBoxMix> FitGreyMixPart(const FitGreyOptions& o,
                                                const drift::MeasurementFile& records,
                                                const drift::GreyBoxSpec& spec,
                                                const drift::GreyBoxOptions& options,
                                                std::string* note) {
  const int days = static_cast<int>(drift::LeadDays(records.record).size());
  const std::string held = std::to_string(days) + " lead days";
  const std::string limit = std::to_string(2 * options.forward_days);
  if (o.grey_alone) {
    *note = "grey box alone (--grey-alone); the records hold " + held;
    return std::nullopt;
  }
  if (drift::LongRecord(records.record, options)) {
    *note = "grey box alone: the records hold " + held + " (>= " + limit + ")";
    return std::nullopt;
  }
  drift::GreyMix mix;
  try {
    drift::RequireRuleColumns(records.record, records.log_paths);
    mix = drift::FitGreyMix(records.record, spec, options);
  } catch (const InputError& e) {
    throw InputError("--records '" + o.records + "': " + e.what() +
                     "; log them, or give --grey-alone for the grey box alone");
  }
  const drift::GuardScore& g = mix.guard;
  const std::string why = "the records hold " + held + " (< " + limit +
                          "); the guard's combination weight " +
                          FormatFixed(g.combination_weight, 3) + " on the last " +
                          std::to_string(g.days) + " lead days (grey box RMS " +
                          FormatFixed(g.grey_rms_um, 2) + " um, " + mix.rules.BaseName() +
                          " rule " + FormatFixed(g.rule_rms_um, 2) + " um) clamped to [" +
                          FormatFixed(drift::kShortMixFloor, 1) + ", 1]";
  std::optional<drift::GreyBoxMix> part = drift::GreyBoxMixPart(mix, records.record);
  *note = part ? "mix: w = " + FormatFixed(mix.weight, 3) + " grey box + " +
                     FormatFixed(1 - mix.weight, 3) + " " + mix.rules.BaseName() + " rule: " + why
               : "grey box alone (w = 1): " + why;
  return part;
}

void RunFitGrey(const FitGreyOptions& o) {
  CheckOutputs({{"--records", o.records}, {"--spec", o.spec}}, {{"--out", o.out}});
  const drift::GreyBoxSpec spec = drift::ReadGreyBoxSpec(o.spec);
  const drift::MeasurementFile records = drift::ReadMeasurementRecords(o.records);
  drift::GreyBoxOptions options;
  if (o.validation == "forward-leads") options.validation = drift::GreyValidation::kForwardLeads;
  drift::GreyBoxFile file;
  drift::GreyBoxModel& m = file.model;
  try {
    m = drift::FitGreyBox(records.record, spec, options);
  } catch (const InputError& e) {
    throw InputError("--records '" + o.records + "' with --spec '" + o.spec + "': " + e.what());
  }
  std::string mix_note;
  file.mix = FitGreyMixPart(o, records, spec, options, &mix_note);
  m.notes.push_back("whirl drift fit-grey --records " + o.records + " --spec " + o.spec +
                    " --validation " + o.validation + (o.grey_alone ? " --grey-alone" : ""));
  m.notes.push_back(FitGreyCounts(records.record));
  if (!records.description.empty()) m.notes.push_back("records: " + records.description);
  m.notes.push_back(mix_note);
  drift::WriteGreyBoxFile(o.out, file);
  if (o.json) {
    nlohmann::json mix_json = nullptr;
    if (file.mix) mix_json = {{"weight", file.mix->weight}, {"rule", file.mix->rule}};
    PrintJson({{"schema", "whirl.drift_fit_grey"},
               {"schema_version", 1},
               {"model_file", o.out},
               {"model", nlohmann::json(m)},
               {"mix", mix_json},
               {"mix_note", mix_note}});
    return;
  }
  std::printf("%s\n", FitGreyCounts(records.record).c_str());
  PrintFitGrey(m);
  std::printf("%s\n", mix_note.c_str());
  std::printf("model written to %s\n", o.out.c_str());
}

}  // namespace

void RegisterDriftFitGrey(CLI::App* drift_app) {
  auto o = std::make_shared<FitGreyOptions>();
  auto* sub = drift_app->add_subcommand(
      "fit-grey",
      "Fit the grey-box machine drift estimator (the form the 840D applies) from a shop's\n"
      "measurement records and write it as a grey box model file (JSON) for whirl drift nc\n"
      "--grey-model:\n"
      "  K0 = a' phi_o [um],  G = g0 + g' phi_s + g_b (B(t0) - 20) [um per 1000 mm],\n"
      "  m(t, z) = K0 + G (z_ref - z) / 1000,\n"
      "phi: the spec's offset and slope sensors as T - 20 [K] with first-order lags (at most 2\n"
      "from 10-320 min, chosen by --validation), g0 a slope intercept, B the blank's estimate\n"
      "(a lag of the blank sensor, 30-240 min) latched at the cut start (lead records only). A\n"
      "ridge towards the spec's physical priors (alpha x lengths; strength 1e-3..1); the lead\n"
      "records carry 0.9 of the total weight. The records (--records) are what a\n"
      "shop measures: warm-up probe tests, laser tests, the measured leads of past screws and\n"
      "the probe readings at set-ups, each on its day log (the control's sensor log, a drift\n"
      "run file). Where the records hold fewer than 20 days with a lead, the file also carries\n"
      "the mix the control then runs (docs/840d.md): w grey box + (1 - w) the better\n"
      "sensor-free rule by its grouped CV (warmup: lags of power_on, 0 at the power-on row,\n"
      "then 1; schedule: lags of ring_on, cutting (0/1), ring_load_pct [%], z_speed_mm_min\n"
      "[mm/min]; columns the day logs must hold), w the least-squares combination weight of\n"
      "the two families' lead residuals on the last 2 lead days (each fitted on the days\n"
      "before it), clamped to [0.5, 1]; --grey-alone writes the grey box alone.");
  sub->add_option("--records", o->records,
                  "measurement records JSON (format whirl-measurement-records: day_logs = run "
                  "files relative to it; records with kind probe|laser|lead|setup_check, day, "
                  "log, time_min [min], z_mm [mm from the chuck face], value_um [um], sigma_um "
                  "[um])")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--spec", o->spec,
                  "grey box spec JSON (format whirl-grey-box-spec: offset_sensors, "
                  "slope_sensors, blank_sensor, z_ref_mm [mm], priors in um per K and um per "
                  "1000 mm per K; optional offset_duty, slope_duty: control signals of the day "
                  "logs, as logged, with the same lags, prior 0; e.g. "
                  "datasets/machines/field_grey_box_spec.json)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", o->out, "grey box model file to write (JSON)")->required();
  sub->add_option("--validation", o->validation,
                  "how the lags, the blank's lag and the prior's strength are chosen: "
                  "forward-leads (default: for each of the last 10 days with a measured lead, "
                  "fitted on the days before it, the RMS of that day's lead residuals [um]; "
                  "leave-one-day-out while fewer than 20 days hold a lead) or leave-one-day-out "
                  "(the grouped CV RMSE over every record, one calendar day held out at a time)")
      ->check(CLI::IsMember({"forward-leads", "leave-one-day-out"}));
  sub->add_flag("--grey-alone", o->grey_alone,
                "write the grey box alone, also where the records hold fewer than 20 lead days "
                "(2 x the forward-chaining days; default there: the mix w grey box + (1 - w) "
                "sensor-free rule, see above)");
  sub->add_flag("--json", o->json, "machine output on stdout");
  sub->callback([o] { RunFitGrey(*o); });
}

}  // namespace whirl::cli
