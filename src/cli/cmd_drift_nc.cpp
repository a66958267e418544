// whirl drift nc: the live machine-drift compensation on the control (interp/drift_action.h):
// an NC program of static synchronized actions that evaluates a drift model from the analog
// inputs every interpolation cycle into SD43900, its reset program and the same model as a PLC
// table.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "drift/grey_box_io.h"
#include "drift/grey_mix.h"
#include "drift/model.h"
#include "interp/drift_action.h"
#include "interp/machine_profile.h"

namespace whirl::cli {
namespace {

struct DriftNcOptions {
  std::string model_path, slope_model_path, grey_model_path, machine_path, reference = "model";
  std::vector<std::string> inputs;  // NAME=INDEX:SCALE:OFFSET
  std::string nc_path, reset_path, csv_path;
  bool json = false;
};

// "t3_C=3:0.1:-20" -> {t3_C, {3, 0.1, -20}}; InputError naming the text and the rule.
std::pair<std::string, interp::AnalogInput> ParseInput(const std::string& text) {
  const auto eq = text.find('=');
  const std::string rule = "--input '" + text +
                           "': must be NAME=INDEX:SCALE:OFFSET (value = SCALE "
                           "* $A_INA[INDEX] + OFFSET, e.g. t3_C=3:0.1:0)";
  if (eq == std::string::npos || eq == 0) throw InputError(rule);
  interp::AnalogInput a;
  char tail = 0;
  if (std::sscanf(text.c_str() + eq + 1, "%d:%lf:%lf%c", &a.index, &a.scale, &a.offset, &tail) != 3)
    throw InputError(rule);
  return {text.substr(0, eq), a};
}

// An --input for a name the models do not read would be silently ignored: refused.
void CheckKnownInput(const std::string& text, const std::string& name,
                     const std::vector<const drift::DriftModel*>& models) {
  if (name == "elapsed")
    throw InputError("--input '" + text +
                     "': elapsed time is counted by the control itself from the program's "
                     "start (interp/drift_action.h); it reads no analog input");
  std::string known;
  for (const drift::DriftModel* m : models) {
    if (!m) continue;
    for (const auto* list : {&m->sensors, &m->extra_inputs})
      for (const std::string& input : *list) {
        if (input == name) return;
        known += (known.empty() ? "" : ", ") + input;
      }
  }
  throw InputError("--input '" + text + "': the model has no input '" + name +
                   "' (its inputs: " + known + ")");
}

// The models the action runs: a drift model (and slope model) or a grey box (its offset, slope
// and blank term, drift/grey_box_io.h).
struct DriftNcModels {
  drift::DriftModel model;
  std::optional<drift::DriftModel> slope;
  std::optional<interp::GreyBoxAction> grey;
  std::optional<drift::GreyBoxMix> mix;  ///< fit-grey's mix part (drift/grey_box_io.h)
  const drift::DriftModel* Slope() const { return slope ? &*slope : nullptr; }
  /// The mixed line's components (pointing into this object): the grey box with w and the rule
  /// with 1 - w (the same as the lab report's, interp::GreyMixComponents).
  std::vector<interp::DriftComponent> MixComponents() const {
    return interp::GreyMixComponents(*grey, mix->rule_offset, mix->rule_slope, mix->weight);
  }
  const interp::BlankTerm* Blank() const { return grey ? grey->Blank() : nullptr; }
};

DriftNcModels ReadDriftNcModels(const DriftNcOptions& o) {
  if (o.model_path.empty() == o.grey_model_path.empty())
    throw InputError(
        "give either --model (a drift model, with --slope-model optional) or "
        "--grey-model (a grey box: offset, slope and the latched blank)");
  DriftNcModels m;
  if (!o.grey_model_path.empty()) {
    if (!o.slope_model_path.empty())
      throw InputError("--slope-model with --grey-model: the grey box carries its own slope");
    if (o.reference != "model")
      throw InputError("--reference " + o.reference +
                       " with --grey-model: the grey box reads absolute temperatures referred to "
                       "20 degC (reference model)");
    try {
      drift::GreyBoxFile file = drift::ReadGreyBoxFile(o.grey_model_path);
      m.grey = interp::GreyBoxActionModels(file.model);
      m.mix = std::move(file.mix);
    } catch (const InputError& e) {
      throw InputError("--grey-model '" + o.grey_model_path + "': " + e.what());
    }
    m.model = m.grey->offset;
    m.slope = m.grey->slope;
    return m;
  }
  m.model = drift::ReadDriftModel(o.model_path);
  if (!o.slope_model_path.empty()) m.slope = drift::ReadDriftModel(o.slope_model_path);
  return m;
}

void Run(const DriftNcOptions& o) {
  CheckOutputs({{"--model", o.model_path},
                {"--slope-model", o.slope_model_path},
                {"--grey-model", o.grey_model_path},
                {"--machine", o.machine_path}},
               {{"--nc", o.nc_path}, {"--reset-nc", o.reset_path}, {"--csv", o.csv_path}});
  const DriftNcModels models = ReadDriftNcModels(o);
  const drift::DriftModel& model = models.model;
  const drift::DriftModel* g = models.Slope();
  const interp::BlankTerm* blank = models.Blank();
  const std::string source = o.grey_model_path.empty() ? o.model_path : o.grey_model_path;
  const interp::MachineProfile machine = interp::LoadMachineProfile(o.machine_path);
  WarnIllustrativeProfile(machine);
  interp::DriftActionOptions options = machine.DriftOptions();
  options.reference = interp::ParseDriftReference(o.reference);
  for (const std::string& text : o.inputs) {
    const auto [name, a] = ParseInput(text);
    if (!(blank && name == blank->sensor)) {
      std::vector<const drift::DriftModel*> read = {&model, g};
      if (models.mix) read.insert(read.end(), {&models.mix->rule_offset, &models.mix->rule_slope});
      CheckKnownInput(text, name, read);
    }
    options.inputs[name] = a;
    try {  // the profile's bounds and the control's analog input count (MD10300)
      options.Validate();
    } catch (const InputError& e) {
      throw InputError("--input '" + text + "' (machine profile '" + o.machine_path +
                       "'): " + e.what());
    }
  }
  if (!o.nc_path.empty()) options.program_name = interp::ProgramNameOf(o.nc_path, "--nc");
  if (!o.reset_path.empty())
    options.reset_program_name = interp::ProgramNameOf(o.reset_path, "--reset-nc");
  // Render everything first (a model the control cannot run fails here), then write all or none.
  const std::string nc =
      models.mix ? interp::FormatDriftNcProgram(models.MixComponents(), options, source)
                 : interp::FormatDriftNcProgram(model, options, source, g, blank);
  const std::string reset = interp::FormatDriftNcResetProgram(options);
  const std::string csv = models.mix ? interp::FormatDriftPlcCsv(models.MixComponents(), options)
                                     : interp::FormatDriftPlcCsv(model, options, g, blank);
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  if (!o.nc_path.empty()) files.emplace_back(o.nc_path, nc);
  if (!o.reset_path.empty()) files.emplace_back(o.reset_path, reset);
  if (!o.csv_path.empty()) files.emplace_back(o.csv_path, csv);
  WriteFilesAtomic(files);
  if (o.json) {
    const Eigen::VectorXd c = interp::DriftControlCoefficients(model, options);
    nlohmann::json slope_json = nullptr;
    if (g) {
      const Eigen::VectorXd cg = interp::DriftSlopeCoefficients(*g, options);
      slope_json = {{"model", o.slope_model_path},
                    {"fixed_end_position_mm", options.slope_fixed_end_mm},
                    {"growth_direction", options.slope_growth_direction},
                    {"coefficients", std::vector<double>(cg.data(), cg.data() + cg.size())}};
    }
    nlohmann::json blank_json = nullptr;
    if (blank)
      blank_json = {{"sensor", blank->sensor},
                    {"tau_min", blank->tau_min},
                    {"coefficient_mm_per_mm_per_k", interp::DriftBlankCoefficient(*blank, options)},
                    {"estimate_param", options.blank_param},
                    {"latched_param", options.blank_param + 1}};
    nlohmann::json mix_json = nullptr;
    if (models.mix)
      mix_json = {{"grey_weight", models.mix->weight},
                  {"rule", models.mix->rule},
                  {"rule_weight", 1 - models.mix->weight}};
    PrintJson({{"model", source},
               {"grey_box", !o.grey_model_path.empty()},
               {"mix", mix_json},
               {"blank", blank_json},
               {"axis", options.axis},
               {"coefficients_mm", std::vector<double>(c.data(), c.data() + c.size())},
               {"slope", slope_json},
               {"nc", o.nc_path},
               {"reset_nc", o.reset_path},
               {"csv", o.csv_path}});
    return;
  }
  std::printf("drift action for axis %s: %s model of %s from %zu sensors%s, reference %s\n",
              options.axis.c_str(), drift::ToString(model.kind).c_str(), model.error_column.c_str(),
              model.sensors.size(),
              model.elapsed_time_constants.empty()
                  ? ""
                  : (" and " + std::to_string(model.elapsed_time_constants.size()) +
                     " elapsed-time term(s) counted from the program's start")
                        .c_str(),
              o.reference.c_str());
  if (g)
    std::printf("  slope (SD43910) from the %s model of %s, fixed end %.4f mm (MCS)%s\n",
                drift::ToString(g->kind).c_str(), g->error_column.c_str(),
                options.slope_fixed_end_mm,
                options.workpiece_slope_param >= 0 ? ", plus the plan's slope" : "");
  for (const auto& [path, what] : {std::pair{o.nc_path, "NC program"},
                                   {o.reset_path, "NC reset program"},
                                   {o.csv_path, "PLC table"}})
    if (!path.empty()) std::printf("written: %s (%s)\n", path.c_str(), what);
  if (models.mix)
    std::printf(
        "  mixed line (the model file's mix part, whirl drift fit-grey): %.3f x the grey box + "
        "%.3f x the %s rule (its K0 and slope; control signals as logged)\n",
        models.mix->weight, 1 - models.mix->weight, models.mix->rule.c_str());
  if (blank)
    std::printf(
        "  blank term: lag %.1f min of %s in $AC_PARAM[%d], latched at the cut start in "
        "$AC_PARAM[%d] (the whirling plan, or your part program: see the program's "
        "header)\n",
        blank->tau_min, blank->sensor.c_str(), options.blank_param, options.blank_param + 1);
}

}  // namespace

void RegisterDriftNc(CLI::App* drift_app) {
  auto o = std::make_shared<DriftNcOptions>();
  auto* sub = drift_app->add_subcommand(
      "nc",
      "The live machine-drift compensation on a SINUMERIK 840D: static synchronized actions\n"
      "(IDS) that read the model's sensors from analog inputs, T = scale * $A_INA[index] +\n"
      "offset [degC], form the rises against the model's reference temperatures (or those at\n"
      "the start), run the lag filters every interpolation cycle (L += a (u - L), a = 1 -\n"
      "exp(-T_ipo / tau)) and write SD43900 = s * (b0 + sum b_f x_f) / 1000 [mm]; s = -1 when\n"
      "the control adds dK and the model's error is the tool's displacement along +axis. The\n"
      "machine profile (--machine, its 'drift' object) gives the ID range, $AC_PARAM slots, R\n"
      "parameters, interpolation cycle and analog inputs. With a whirling plan on the same axis\n"
      "(whirl plan --with-drift-action) this action is the only writer of SD43900 and adds the\n"
      "plan's K0. With --slope-model (e.g. the Z feed screw's growth, um per 1000 mm from the\n"
      "fixed bearing; profile 'drift.slope') it also writes SD43910 = S_m = s * sigma * g / 1e6\n"
      "[mm/mm] about SD43920 = the fixed end [mm]; combined with a plan that hands its slope\n"
      "over (profile 'drift.workpiece_slope_param') it owns SD43900-43920: SD43920 = P_w,\n"
      "SD43910 = S_w + S_m, SD43900 = K0_w + K_m + S_m (P_w - P_b). Models of kind mlr or\n"
      "dynamic (a network is refused), with or without elapsed-time warm-up terms (drift fit's\n"
      "time1, time2, sensors+time): the actions count the time since the program's start\n"
      "themselves, x = 1 - exp(-t / tau) by x <- x + a (1 - x) every cycle, so run the program\n"
      "when the machine starts. The reset program (--reset-nc) cancels the actions and\n"
      "restores the setting data found. Files are .SPF subprograms (M17). With --grey-model\n"
      "(whirl drift fit-grey) the action runs the grey box: K0 and the slope from absolute\n"
      "temperatures (T - 20 degC) and their lags, the slope intercept, and the blank term\n"
      "g_b (B - 20): B, a lag of the blank sensor, runs in $AC_PARAM[drift.blank_param] and\n"
      "the whirling plan latches it into [blank_param + 1] at the thread start (back to 20\n"
      "at the thread end). A grey box file with a mix part (fit-grey on fewer than 20 lead\n"
      "days) gives the mixed line K_m = w K_grey + (1 - w) K_rule, S_m likewise, each\n"
      "component with its own slots (the rule's control signals need analog inputs).\n"
      "Not verified on a control: main-run write access to SD43900-43920.");
  sub->add_option("--model", o->model_path, "drift model JSON (whirl drift fit); or --grey-model")
      ->check(CLI::ExistingFile);
  sub->add_option("--grey-model", o->grey_model_path,
                  "grey box model JSON (whirl drift fit-grey) instead of --model/--slope-model: "
                  "K0 [um] from the offset sensors, the slope [um per 1000 mm] from the slope "
                  "sensors, its intercept and the blank's estimate latched at the cut start "
                  "(profile drift.slope and drift.blank_param; reference model: T - 20 degC)")
      ->check(CLI::ExistingFile);
  sub->add_option("--slope-model", o->slope_model_path,
                  "drift model JSON of the machine's slope, um per 1000 mm of distance from the "
                  "profile's drift.slope fixed end (e.g. channel zscrew_per_1000_um)")
      ->check(CLI::ExistingFile);
  sub->add_option("--machine", o->machine_path, "machine profile JSON with a 'drift' object")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--input", o->inputs,
                  "NAME=INDEX:SCALE:OFFSET: analog input of a model input, overriding the "
                  "profile (value = SCALE * $A_INA[INDEX] + OFFSET, degC for a sensor; INDEX "
                  "1..the profile's MD10300, 1e-6 <= |SCALE| <= 1e3, |OFFSET| <= 1e4; a name "
                  "the model does not read is refused)");
  sub->add_option("--reference", o->reference,
                  "rises against the model's reference temperatures (model) or those when the "
                  "action starts (start)")
      ->capture_default_str()
      ->check(CLI::IsMember({"model", "start"}));
  sub->add_option("--nc", o->nc_path,
                  "write the NC program here (.SPF); its file name without the extension is the "
                  "program name on the control: two letters, then letters, digits or '_', at "
                  "most 24 characters");
  sub->add_option("--reset-nc", o->reset_path,
                  "write the reset program here (.SPF; a program name as for --nc, not the same)");
  sub->add_option("--csv", o->csv_path, "write the PLC table here (CSV)");
  sub->add_flag("--json", o->json, "machine output on stdout");
  sub->callback([o] { Run(*o); });
}

}  // namespace whirl::cli
