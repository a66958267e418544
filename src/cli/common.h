#pragma once
// Small helpers shared by the subcommands. The library never includes CLI11; this folder does.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}

namespace whirl::cli {

/// Parses the command line and runs the chosen subcommand's callback. Exit code: 0 on success
/// (and for --help/--version), 1 on a parse error or bad input ("error: <message>" on stderr),
/// CommandFailure::exit_code when a check ran and failed. Shared by whirl and whirl-torch.
int RunApp(CLI::App& app, int argc, char** argv);

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

/// A --seed option: a whole number in [0, 2^64 - 1] (unsigned 64 bit); "-1", "1.5" or a larger
/// number is a parse error naming the rule, never wrapped. Returns the option for chaining.
CLI::Option* AddSeedOption(CLI::App* sub, std::uint64_t* seed, const std::string& help);

/// Makes a number option refuse nan, inf and every form that is not a finite decimal number
/// (parse error "<flag>: '<text>' must be a finite number"). Returns the option for chaining.
CLI::Option* FiniteNumber(CLI::Option* option);

/// Machine output: JSON on stdout, pretty-printed, newline-terminated.
void PrintJson(const nlohmann::json& j);

/// Warning line on stderr: "warning: <text>".
void Warn(const std::string& text);

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
