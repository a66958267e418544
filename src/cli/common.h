#pragma once
// Small helpers shared by the subcommands. The library never includes CLI11; this folder does.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/limits.h"
#include "fit/arctan_curve.h"

namespace CLI {
class App;
class Option;
class Validator;
}

namespace whirl::interp {
struct MachineProfile;
}  // namespace whirl::interp

namespace whirl::cli {

/// One line per command in a --help listing, keyed by the command's words below the program
/// ("plan", "drift fit"). A command without an entry shows its description's first sentence; a
/// command with subcommands also lists their names on that line.
using CommandSummaries = std::map<std::string, std::string>;

/// Parses the command line and runs the chosen subcommand's callback. Exit code: 0 on success
/// (and for --help/--version), 1 on a parse error or bad input ("error: <message>" on stderr),
/// CommandFailure::exit_code when a check ran and failed. A word where a command is expected
/// that names none is an error naming it and the closest command ("unknown command 'fitt';
/// did you mean 'fit'?"). Every --help lists subcommands one line each (`summaries`). Shared
/// by whirl and whirl-torch.
int RunApp(CLI::App& app, int argc, char** argv, const CommandSummaries& summaries = {});

/// "fit": the name in `candidates` closest to `word` by edit distance (Levenshtein: insertions,
/// deletions and substitutions count 1; ties go to the earlier candidate). "" if none.
std::string ClosestName(const std::string& word, const std::vector<std::string>& candidates);

/// An old spelling of the flag `current` kept working for scripts: hidden from --help, it hands
/// its value (or, for a flag, its presence) to `current` as if `current` had been typed, so
/// `current`'s checks, defaults and relations (excludes, required) apply, and it prints one line
/// "whirl: --old is deprecated, use --new" on stderr. Giving both is a parse error; a value the
/// check refuses is reported under the spelling typed. Returns the hidden option.
CLI::Option* AddDeprecatedAlias(CLI::App* sub, CLI::Option* current, const std::string& old_flag);
/// The same for an old flag without a value that stood for `current` with one value
/// (--errors-from-start for --error-zero run-start): its presence hands `implied_value` to
/// `current`, and the deprecation line says "use --new <implied_value>".
CLI::Option* AddDeprecatedAlias(CLI::App* sub, CLI::Option* current, const std::string& old_flag,
                                const std::string& implied_value);

/// A command that ran but whose result is a failure (e.g. a cross-check that disagrees):
/// main prints the message and exits with `exit_code` (never 0).
struct CommandFailure : std::runtime_error {
  int exit_code;
  CommandFailure(const std::string& message, int code = 2)
      : std::runtime_error(message), exit_code(code) {}
};

/// "a, b, c": the fields of a prediction outside the model's training domain, for messages.
std::string JoinFields(const std::vector<std::string>& fields);

/// The training-domain guard of commands that act on one screw's prediction (curve, plan): if
/// `outside_domain`, an InputError naming the screw file and the fields unless
/// `allow_extrapolation`, which turns it into a warning.
void GuardTrainingDomain(bool outside_domain, const std::vector<std::string>& fields,
                         const std::string& screw_path, bool allow_extrapolation);

/// The shape options of the arctangent curve, shared by curve, plan, compare and evaluate:
/// --shape-k K and --time-exponent P, with their ranges and defaults (fit/arctan_curve.h).
void AddCurveShapeOptions(CLI::App* sub, double* shape_k, double* time_exponent);

/// Where the arctangent curve of `curve` and `plan` comes from: a model's prediction for a screw
/// (--model M --screw S.json) or given features (--max-elongation-um L --settle-time-s T), its
/// shape, and whether a screw outside the model's training domain may be used
/// (GuardTrainingDomain).
struct CurveSourceArgs {
  std::string model_path, screw_path;
  double max_elongation_um = NAN;  ///< um; NAN: not given
  double settle_time_s = NAN;      ///< s; NAN: not given
  double shape_k = fit::kDefaultShapeK;
  double time_exponent = fit::kDefaultTimeExponent;
  bool allow_extrapolation = false;
};

/// --model, --screw (required when `screw_required`), --max-elongation-um, --settle-time-s (old
/// spellings --max-elongation, --settle-time), the shape options (AddCurveShapeOptions) and
/// --allow-extrapolation.
void AddCurveSourceOptions(CLI::App* sub, CurveSourceArgs* a, bool screw_required);

/// A --seed option (or `flag`): a whole number in [0, 2^64 - 1] (unsigned 64 bit); "-1", "1.5"
/// or a larger number is a parse error naming the rule, never wrapped. Returns the option.
CLI::Option* AddSeedOption(CLI::App* sub, std::uint64_t* seed, const std::string& help,
                           const std::string& flag = "--seed");

/// The one check of every numeric flag: the text must be a finite decimal number (core/csv.h
/// ParseDecimal: "nan", "inf", "1e999", "0x1p3" and "1,5" are refused) inside `range`. CLI11
/// names the flag in front of the message: "--tolerance-um: 1e-9 breaks the rule: a finite
/// number in [0.001, 10000] um (...)", the value as typed, the range written as in every message
/// (MessageNumber). A whole-number flag also needs its text to convert, which CLI11 checks after.
/// The range shows in --help after the type: "FLOAT:[0.001, 10000] um", "FLOAT:> 0 s" (no upper
/// bound), "FLOAT:finite".
CLI::Validator NumberIn(const Range& range);
/// NumberIn of the closed range [min, max] with `unit` ("" for counts and ratios).
CLI::Validator NumberIn(double min, double max, const char* unit = "");
/// NumberIn over (0, largest double]: a positive finite number.
CLI::Validator PositiveNumber(const char* unit = "");
/// NumberIn over [0, largest double]: a finite number >= 0.
CLI::Validator NonNegativeNumber(const char* unit = "");
/// NumberIn over the whole double range: any finite number.
CLI::Validator FiniteNumber(const char* unit = "");

/// NumberIn over (0, interp::kMd32760Max]: the MD32760 factor of every --md32760 flag.
CLI::Validator Md32760Number();

/// The check of every --axis flag (interp::CheckAxisName): "--axis: '1X' breaks the rule: an
/// 840D axis name (a letter, then letters, digits or '_', at most 32 characters)".
CLI::Validator AxisName();

/// --tolerance-um, shared by plan, compare and evaluate: the largest |840D chord - predicted
/// curve| of a plan [um], in kPlanToleranceRange (core/limits.h) (checked again by
/// PlanOptions::Validate with the same rule), default interp::PlanOptions's.
void AddToleranceOption(CLI::App* sub, double* tolerance_um);

/// Machine output: JSON on stdout, pretty-printed, newline-terminated.
void PrintJson(const nlohmann::json& j);

/// Warning line on stderr: "warning: <text>".
void Warn(const std::string& text);
/// Warns when the machine profile is still the shipped illustrative example
/// (its name says so): its offsets, IDs, R parameters and alarms are not the user's machine's.
void WarnIllustrativeProfile(const interp::MachineProfile& profile);

/// Progress bar on stderr. On a terminal it redraws one line; otherwise it prints a line at every
/// 10 % so logs stay short. Finish() ends the line.
class Progress {
 public:
  Progress(std::string label, std::size_t total);
  void Update(std::size_t done, const std::string& detail = "");
  void Finish(const std::string& detail = "");

 private:
  std::string label_;
  std::size_t total_;
  bool tty_;
  int last_decile_ = -1;
  std::size_t most_done_ = 0;  ///< the bar never moves back (parallel workers report out of order)
  bool finished_ = false;
};

/// The shop's history of past screws (process table with targets), relative to the project: the
/// table the shipped model is trained on (scripts/train_default.sh) and the default history of the
/// traditional experience rule in compare/evaluate/demo, so both strategies learn from the same
/// past screws.
inline constexpr const char* kHistoryTable = "datasets/whirling_500.csv";

/// Where the shipped files (models/, datasets/ with screws/ and standards/) live, in this order:
/// $WHIRL_HOME if set and not empty; <dir of the executable>/../share/whirl when it holds
/// models/ (an installed whirl: cmake --install build --prefix P puts them in P/share/whirl);
/// else the source tree this binary was built from (running build/whirl). Used by `whirl demo`
/// and defaults such as kHistoryTable. Described to users in `whirl --help` (kShippedFilesHelp).
std::filesystem::path ShippedFilesRoot();
inline constexpr const char* kShippedFilesHelp =
    "Shipped files (models/default.json, datasets/...) are looked up in $WHIRL_HOME if set, else\n"
    "in <prefix>/share/whirl next to an installed <prefix>/bin/whirl, else in the source tree\n"
    "the binary was built from.";
std::string ProjectPath(const std::string& relative);

}  // namespace whirl::cli
