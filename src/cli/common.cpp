#include "cli/common.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli/terminal.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/safe_text.h"
#include "fit/arctan_curve.h"
#include "interp/machine_profile.h"
#include "interp/sinumerik.h"

namespace whirl::cli {

void AddCurveShapeOptions(CLI::App* sub, double* shape_k, double* time_exponent) {
  sub->add_option("--shape-k", *shape_k,
                  "shape k of the arctangent curve l(t) = L atan(k (t/t_s)^p)/atan(k) [-] "
                  "(default: fitted on simulated curves, 'whirl fit --simulated 25')")
      ->capture_default_str()
      ->check(NumberIn(fit::kMinShapeK, fit::kMaxShapeK));
  sub->add_option("--time-exponent", *time_exponent,
                  "time exponent p of that curve, in [0.5, 1]; 1 = the plain arctangent in time "
                  "[-] (default: fitted with k). Below about 0.7 the curve starts so steeply that "
                  "the first segment's SD43910 can exceed the MD32760 cap (an error)")
      ->capture_default_str()
      ->check(NumberIn(fit::kMinTimeExponent, fit::kMaxTimeExponent));
}

void AddCurveSourceOptions(CLI::App* sub, CurveSourceArgs* a, bool screw_required) {
  sub->add_option("--model", a->model_path, "model file written by 'whirl train'")
      ->check(CLI::ExistingFile);
  auto* screw = sub->add_option("--screw", a->screw_path,
                                "screw file (JSON, see 'whirl simulate --help'): process inputs, "
                                "thread length and settings that give the axial feed")
                    ->check(CLI::ExistingFile);
  if (screw_required) screw->required();
  auto* max_elongation = sub->add_option("--max-elongation-um", a->max_elongation_um,
                                         "instead of --model: plateau elongation L [um]")
                             ->check(NumberIn(0, kMaxElongationUm, "um"));
  AddDeprecatedAlias(sub, max_elongation, "--max-elongation");
  auto* settle_time = sub->add_option("--settle-time-s", a->settle_time_s,
                                      "instead of --model: settle time t_s [s]")
                          ->check(NumberIn(Range{kMinPlanSettleTimeS, kMaxSettleTimeS, false, "s",
                                                 "at least 1 s, so the check grid stays bounded"}));
  AddDeprecatedAlias(sub, settle_time, "--settle-time");
  AddCurveShapeOptions(sub, &a->shape_k, &a->time_exponent);
  sub->add_flag("--allow-extrapolation", a->allow_extrapolation,
                "use the prediction even if the screw lies outside the model's training domain");
}

CLI::Option* AddSeedOption(CLI::App* sub, std::uint64_t* seed, const std::string& help,
                           const std::string& flag) {
  const auto rule = [](std::string& text) -> std::string {
    const bool digits = !text.empty() && text.size() <= 20 &&
                        text.find_first_not_of("0123456789") == std::string::npos;
    errno = 0;
    if (digits) (void)std::strtoull(text.c_str(), nullptr, 10);
    if (digits && errno == 0) return "";
    return "'" + text + "' breaks the rule: a whole number in [0, 18446744073709551615]";
  };
  return sub->add_option(flag, *seed, help)->check(CLI::Validator(rule, "[0, 2^64-1]"));
}

namespace {

// "[0.001, 10000]"; without an upper bound "> 0" or ">= 0"; "" for any finite number.
std::string Bounds(const Range& range) {
  constexpr double kLargest = std::numeric_limits<double>::max();
  if (range.max < kLargest)
    return std::string(range.min_open ? "(" : "[") + MessageNumber(range.min) + ", " +
           MessageNumber(range.max) + "]";
  if (range.min > -kLargest)
    return std::string(range.min_open ? "> " : ">= ") + MessageNumber(range.min);
  return "";
}

}  // namespace

CLI::Validator NumberIn(const Range& range) {
  const std::string bounds = Bounds(range);
  const std::string unit = *range.unit ? std::string(" ") + range.unit : "";
  const std::string text = (bounds.empty() ? "finite" : bounds) + unit;  // shown in --help
  const std::string rule = "a finite number" +
                           (bounds.empty() ? "" : (bounds[0] == '>' ? " " : " in ") + bounds) +
                           unit + (*range.note ? std::string(" (") + range.note + ")" : "");
  const auto check = [range, rule](std::string& value) -> std::string {
    const auto x = ParseDecimal(value);
    if (x && range.Contains(*x)) return "";
    return (x ? value : "'" + value + "'") + " breaks the rule: " + rule;  // as typed
  };
  return CLI::Validator(check, text);
}

CLI::Validator NumberIn(double min, double max, const char* unit) {
  return NumberIn(Range{min, max, false, unit});
}

CLI::Validator PositiveNumber(const char* unit) {
  return NumberIn(Range{0, std::numeric_limits<double>::max(), true, unit});
}

CLI::Validator NonNegativeNumber(const char* unit) {
  return NumberIn(0, std::numeric_limits<double>::max(), unit);
}

CLI::Validator FiniteNumber(const char* unit) {
  return NumberIn(-std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), unit);
}

CLI::Validator Md32760Number() {
  return NumberIn(
      Range{0, interp::kMd32760Max, true, "", "MD32760 on the 840D must be in (0, 0.10]"});
}

CLI::Validator AxisName() {
  const auto check = [](std::string& value) -> std::string {
    try {
      interp::CheckAxisName(value, "axis");
      return "";
    } catch (const InputError&) {
      return "'" + value.substr(0, interp::kMaxAxisNameLength) +
             (value.size() > interp::kMaxAxisNameLength ? "...'" : "'") +
             " breaks the rule: an 840D axis name (a letter, then letters, digits or '_', at "
             "most " +
             std::to_string(interp::kMaxAxisNameLength) + " characters)";
    }
  };
  return CLI::Validator(check, "AXIS");
}

void AddToleranceOption(CLI::App* sub, double* tolerance_um) {
  sub->add_option("--tolerance-um", *tolerance_um,
                  "largest |840D chord - predicted curve| of the plan along the thread [um]; at "
                  "least 1 nm, the resolution of SD43900")
      ->capture_default_str()
      ->check(NumberIn(kPlanToleranceRange));
}

namespace {

// The old spellings typed in this run, as {current name, old name}: an error raised after parsing
// (a folder refused, a file not found) names the flag by its current name; RunApp shows the
// spelling the user typed beside it (NameTypedFlags).
std::vector<std::pair<std::string, std::string>>& TypedOldSpellings() {
  static std::vector<std::pair<std::string, std::string>> typed;
  return typed;
}

bool IsFlagChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_';
}

// "--out-dir 'x': ..." -> "--report (now --out-dir) 'x': ..." for each old spelling typed.
std::string NameTypedFlags(std::string message) {
  for (const auto& [now, old] : TypedOldSpellings()) {
    const std::string shown = old + " (now " + now + ")";
    for (std::size_t at = message.find(now); at != std::string::npos;
         at = message.find(now, at + 1)) {
      const bool starts = at == 0 || !IsFlagChar(message[at - 1]);
      const std::size_t end = at + now.size();
      if (!starts || (end < message.size() && IsFlagChar(message[end]))) continue;
      message.replace(at, now.size(), shown);
      at += shown.size() - 1;
    }
  }
  return message;
}

// The value(s) `values` of the old spelling `old_flag` handed to `current` (AddDeprecatedAlias);
// `use` is what the deprecation line tells the user to type instead.
void ForwardDeprecated(CLI::Option* current, const std::string& old_flag, const std::string& use,
                       const std::vector<std::string>& values) {
  const std::string now = current->get_name();
  if (current->count() > 0)
    throw CLI::ValidationError(
        old_flag, "give " + now + " only (" + old_flag + " is its deprecated spelling), not both");
  // The alias is hidden, so CLI11's own "At Most 1 required but received 2" would name no flag.
  const int most = current->get_expected_max() * current->get_type_size_max();
  if (most > 0 && static_cast<int>(values.size()) > most)
    throw CLI::ValidationError(old_flag, "given more than once (" +
                                             std::to_string(values.size()) + " values, at most " +
                                             std::to_string(most) +
                                             "): give it once (it is the deprecated spelling of " +
                                             now + ")");
  std::fprintf(stderr, "whirl: %s is deprecated, use %s\n", old_flag.c_str(), use.c_str());
  TypedOldSpellings().emplace_back(now, old_flag);
  for (const auto& v : values) current->add_result(v);
  try {
    current->run_callback();            // current's checks and conversion, as if it had been typed
  } catch (const CLI::ParseError& e) {  // "--new: 1e999 breaks the rule ..." under --old
    std::string message = e.what();
    if (message.rfind(now + ": ", 0) == 0) message.erase(0, now.size() + 2);
    throw CLI::ValidationError(old_flag, message);
  }
}

}  // namespace

CLI::Option* AddDeprecatedAlias(CLI::App* sub, CLI::Option* current, const std::string& old_flag) {
  const std::string now = current->get_name();
  CLI::Option* alias = nullptr;
  if (current->get_expected_max() == 0) {  // a flag
    alias = sub->add_flag_callback(old_flag, [current, old_flag, now] {
      ForwardDeprecated(current, old_flag, now, {current->get_flag_value(now, "")});
    });
  } else {
    alias = sub->add_option(old_flag,
                            [current, old_flag, now](const CLI::results_t& r) {
                              ForwardDeprecated(current, old_flag, now, r);
                              return true;
                            })
                ->type_size(current->get_type_size_min(), current->get_type_size_max())
                ->expected(current->get_expected_min(), current->get_expected_max())
                ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);  // counted above
  }
  return alias->group("");  // hidden from --help
}

CLI::Option* AddDeprecatedAlias(CLI::App* sub, CLI::Option* current, const std::string& old_flag,
                                const std::string& implied_value) {
  const std::string use = current->get_name() + " " + implied_value;
  return sub
      ->add_flag_callback(old_flag,
                          [current, old_flag, use, implied_value] {
                            ForwardDeprecated(current, old_flag, use, {implied_value});
                          })
      ->group("");  // hidden from --help
}

std::string ClosestName(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const auto& c : candidates) {
    // Levenshtein distance, one row at a time.
    std::vector<std::size_t> row(c.size() + 1);
    for (std::size_t j = 0; j <= c.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= word.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= c.size(); ++j) {
        const std::size_t above = row[j];
        row[j] =
            std::min({row[j] + 1, row[j - 1] + 1, diagonal + (word[i - 1] == c[j - 1] ? 0 : 1)});
        diagonal = above;
      }
    }
    if (row[c.size()] < best_distance) best_distance = row[c.size()], best = c;
  }
  return best;
}

namespace {

// "drift fit": a command's words below the program.
std::string CommandPath(const CLI::App* app) {
  std::string path;
  for (; app != nullptr && app->get_parent() != nullptr; app = app->get_parent())
    path = app->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

std::vector<std::string> SubcommandNames(const CLI::App* app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app->get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  return names;
}

// The description's first sentence on one line (up to ". ", ": " or "; ").
std::string FirstSentence(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::size_t end = text.size();
  for (const char* stop : {". ", ": ", "; "}) end = std::min(end, text.find(stop));
  text.resize(end);
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text;
}

// Lists subcommands one line each: the summary, and a group's own subcommands.
class OneLineFormatter : public CLI::Formatter {
 public:
  explicit OneLineFormatter(CommandSummaries summaries) : summaries_(std::move(summaries)) {}
  std::string make_subcommand(const CLI::App* sub) const override {
    const auto it = summaries_.find(CommandPath(sub));
    std::string line = it != summaries_.end() ? it->second : FirstSentence(sub->get_description());
    const std::vector<std::string> names = SubcommandNames(sub);
    if (!names.empty()) line += " (" + JoinFields(names) + ")";
    std::stringstream out;
    CLI::detail::format_help(out, sub->get_display_name(true), line, column_width_);
    return out.str();
  }

 private:
  CommandSummaries summaries_;
};

// The docs page that explains a command's terms, methods and figures: its command path, else
// its first word, else the index.
std::string CommandDocsPage(const CLI::App* app) {
  static const std::map<std::string, std::string> pages = {
      {"demo", "README.md"},
      {"dataset", "simulator.md"},
      {"simulate", "simulator.md"},
      {"train", "workpiece-model.md"},
      {"predict", "workpiece-model.md"},
      {"design", "design.md"},
      {"curve", "methods.md"},
      {"fit", "methods.md"},
      {"plan", "840d.md"},
      {"compare", "results.md"},
      {"evaluate", "results.md"},
      {"lead-report", "methods.md"},
      {"ballbar", "ballbar.md"},
      {"surface", "surface.md"},
      {"drift", "drift-sensors.md"},
      {"drift split", "drift.md"},
      {"drift fit-grey", "machine-evaluation.md"},
      {"drift nc", "840d.md"},
      {"machine", "machine.md"},
      {"machine truth", "machine-truth.md"},
      {"machine evaluate", "machine-evaluation.md"},
      {"machine export", "machine-evaluation.md"},
      {"machine ceiling", "machine-evaluation.md"},
      {"crosscheck", "network.md"},
      {"export", "network.md"}};
  const std::string path = CommandPath(app);
  auto it = pages.find(path);
  if (it == pages.end()) it = pages.find(path.substr(0, path.find(' ')));
  return "docs/" + (it != pages.end() ? it->second : std::string("README.md"));
}

void SetHelpRecursively(CLI::App* app, const std::shared_ptr<CLI::FormatterBase>& formatter) {
  app->formatter(formatter);
  // Every --help names the page that explains the command (in whirl's source tree) and says
  // where the shipped files come from (and how to point at them).
  if (app->get_footer().empty())
    app->footer("Documentation: " + CommandDocsPage(app) +
                " (terms, methods, figures); every flag: docs/commands.md.\n" + kShippedFilesHelp);
  for (CLI::App* sub : app->get_subcommands([](CLI::App*) { return true; }))
    SetHelpRecursively(sub, formatter);
}

// The command words of argv must each name a command of the one before (options end the
// walk): an unknown one is an error naming it and the closest command.
void CheckCommandWords(const CLI::App& app, int argc, char** argv) {
  const CLI::App* current = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    const std::vector<std::string> names = SubcommandNames(current);
    if (word.empty() || word[0] == '-' || names.empty()) return;
    if (!current->get_options([](const CLI::Option* o) { return o->get_positional(); }).empty())
      return;  // the word may be a positional argument
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : current->get_subcommands([](const CLI::App*) { return true; }))
      if (sub->check_name(word)) next = sub;
    if (next == nullptr) {
      const std::string prefix = current == &app ? "" : CommandPath(current) + " ";
      throw CLI::ValidationError(
          "unknown command '" + prefix + word + "'; did you mean '" + prefix +
          ClosestName(word, names) + "'? The commands" +
          (prefix.empty() ? "" : " of '" + prefix.substr(0, prefix.size() - 1) + "'") + ": " +
          JoinFields(names));
    }
    current = next;
  }
}

// The command argv names: its command words from argv[1] on; `*first_option` is the first
// argument after them.
const CLI::App* CommandOf(const CLI::App& app, int argc, char** argv, int* first_option) {
  const CLI::App* current = &app;
  int i = 1;
  for (; i < argc; ++i) {
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : current->get_subcommands([](const CLI::App*) { return true; }))
      if (sub->check_name(argv[i])) next = sub;
    if (next == nullptr) break;
    current = next;
  }
  *first_option = i;
  return current;
}

// Whether `flag` is an option of `command` or of a command above it (hidden deprecated
// spellings included); `listed` gets the names their --help lists.
bool KnownOption(const CLI::App* command, const std::string& flag,
                 std::vector<std::string>* listed) {
  for (const CLI::App* a = command; a != nullptr; a = a->get_parent())
    for (const CLI::Option* o : a->get_options()) {
      if (o->check_name(flag)) return true;
      if (!o->get_group().empty())
        for (const auto& n : o->get_lnames()) listed->push_back("--" + n);
    }
  return false;
}

// The option words of argv ("--name" or "--name=value") must each name an option of the command
// they follow or of a command above it: an unknown one is an error naming the word typed and the
// closest option the command's --help lists. Without this CLI11 reports a missing required
// option first ("--data is required" for "--dta x.csv") or "arguments were not expected"
// without a suggestion.
void CheckOptionWords(const CLI::App& app, int argc, char** argv) {
  int i = 0;
  const CLI::App* command = CommandOf(app, argc, argv, &i);
  if (command->get_prefix_command() || command->get_allow_extras()) return;  // passed through
  for (; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") return;  // positional arguments follow
    if (arg.rfind("--", 0) != 0 || arg.size() < 3) continue;
    const std::string flag = arg.substr(0, arg.find('='));
    std::vector<std::string> listed;
    if (KnownOption(command, flag, &listed) || listed.empty()) continue;
    const std::string name = command == &app ? "whirl" : "whirl " + CommandPath(command);
    throw CLI::ValidationError("unknown option '" + flag + "' for '" + name + "'; did you mean '" +
                               ClosestName(flag, listed) + "'? ('" + name +
                               " --help' lists its options)");
  }
}

}  // namespace

int RunApp(CLI::App& app, int argc, char** argv, const CommandSummaries& summaries) {
  GuardTerminalOutput();  // user text in messages never reaches the terminal as a control
  SetHelpRecursively(&app, std::make_shared<OneLineFormatter>(summaries));
  try {
    CheckCommandWords(app, argc, argv);
    CheckOptionWords(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A bad option or value: the same "error: " prefix as every other failure.
    std::fprintf(stderr, "error: %s\nRun with --help for more information.\n", e.what());
    return 1;
  } catch (const CommandFailure& e) {
    std::fprintf(stderr, "failed: %s\n", NameTypedFlags(e.what()).c_str());
    return e.exit_code;
  } catch (const std::exception& e) {  // InputError and anything else: bad input or failure
    std::fprintf(stderr, "error: %s\n", NameTypedFlags(e.what()).c_str());
    return 1;
  }
  return 0;
}

std::string JoinFields(const std::vector<std::string>& fields) {
  std::string out;
  for (const auto& f : fields) out += (out.empty() ? "" : ", ") + f;
  return out;
}

void GuardTrainingDomain(bool outside_domain, const std::vector<std::string>& fields,
                         const std::string& screw_path, bool allow_extrapolation) {
  if (!outside_domain) return;
  if (!allow_extrapolation)
    throw InputError("screw " + screw_path + " lies outside the model's training domain in " +
                     JoinFields(fields) +
                     ": pass --allow-extrapolation to use the prediction anyway");
  Warn("screw " + screw_path + " lies outside the training domain in " + JoinFields(fields) +
       " (extrapolating)");
}

void PrintJson(const nlohmann::json& j) { std::cout << DumpJson(j) << std::endl; }

void Warn(const std::string& text) { std::cerr << "warning: " << text << std::endl; }

void WarnIllustrativeProfile(const interp::MachineProfile& profile) {
  if (!profile.Illustrative()) return;
  Warn("machine profile " + profile.source + " is the shipped example (its name: \"" +
       profile.name +
       "\"): its axis, offsets, IDs, R parameters and alarms are illustrative, not your "
       "machine's; replace every value and the name before these programs go onto a control");
}

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total == 0 ? 1 : total), tty_(::isatty(2) != 0) {}

void Progress::Update(std::size_t done, const std::string& detail) {
  most_done_ = std::max(most_done_, std::min(done, total_));
  done = most_done_;
  const double frac = static_cast<double>(done) / static_cast<double>(total_);
  if (tty_) {
    const int width = 30;
    const int filled = static_cast<int>(frac * width + 0.5);
    // Raw stderr for the carriage return; the label and detail are made inert here.
    std::fprintf(RawStderr(), "\r%s [%s%s] %zu/%zu %s", TerminalText(label_).c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(), done,
                 total_, TerminalText(detail).c_str());
    std::fflush(RawStderr());
  } else {
    const int decile = static_cast<int>(frac * 10);
    if (decile != last_decile_) {
      last_decile_ = decile;
      std::fprintf(stderr, "%s: %zu/%zu %s\n", label_.c_str(), done, total_, detail.c_str());
    }
  }
}

void Progress::Finish(const std::string& detail) {
  if (finished_) return;
  finished_ = true;
  if (tty_) {
    Update(total_, detail);
    std::fprintf(RawStderr(), "\n");
  } else {
    std::fprintf(stderr, "%s: done %s\n", label_.c_str(), detail.c_str());
  }
}

std::filesystem::path ShippedFilesRoot() {
  namespace fs = std::filesystem;
  const char* home = std::getenv("WHIRL_HOME");
  if (home != nullptr && *home != '\0') return home;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {  // installed: <prefix>/bin/whirl finds <prefix>/share/whirl
    const fs::path installed = exe.parent_path() / WHIRL_DATA_FROM_BIN;
    if (fs::is_directory(installed / "models", ec)) return installed.lexically_normal();
  }
  return WHIRL_SOURCE_DIR;  // run from the build tree
}

std::string ProjectPath(const std::string& relative) {
  return (ShippedFilesRoot() / relative).string();
}

}  // namespace whirl::cli
