#include "cli/drift_args.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cli/common.h"
#include "cli/terminal.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/safe_text.h"

namespace whirl::cli {

void AddSelectionOptions(CLI::App* sub, SelectionArgs* s) {
  sub->add_option("--alpha", s->alpha, "significance level of the F test (default 0.05)")
      ->check(NumberIn(1e-6, 0.5));
  sub->add_option("--classes", s->classes,
                  "class count: 'fewest' (Miao et al.: fewest classes with a significant F, "
                  "default), 'margin' (largest (F - F_crit)/F_crit), 'cv' (the count whose "
                  "sensors' MLR has the lowest cross-validated RMSE: leave one run out, or "
                  "forward-chaining blocks of one run) or a number");
  sub->add_option("--max-sensors", s->max_sensors,
                  "at most this many classes = chosen sensors (default 0: no limit, the same in "
                  "every drift command; the fewest rule rarely reaches a cap, --classes cv may "
                  "keep many sensors)")
      ->check(NumberIn(0, 64));
}

drift::SelectionOptions ToSelection(const SelectionArgs& a) {
  drift::SelectionOptions o;
  o.alpha = a.alpha;
  o.max_classes = a.max_sensors;
  if (a.classes == "fewest" || a.classes == "margin" || a.classes == "cv") {
    o.rule = drift::ParseClassCountRule(a.classes);
  } else {
    o.rule = drift::ClassCountRule::kFixed;
    try {
      std::size_t used = 0;
      o.fixed_classes = std::stoi(a.classes, &used);
      if (used != a.classes.size()) throw std::invalid_argument(a.classes);
    } catch (const std::exception&) {
      throw InputError("--classes '" + a.classes + "': must be fewest, margin, cv or a number");
    }
  }
  return o;
}

namespace {

// "5,10,20": an option's values as typed, for messages.
std::string Typed(const CLI::Option* o) {
  std::string text;
  for (const auto& r : o->results()) text += (text.empty() ? "" : ",") + r;
  return text;
}

}  // namespace

TimeAxisValue ChooseTimeAxis(const TimeAxisFlags& f, bool time_from_index) {
  const bool old = f.old != nullptr && f.old->count() > 0;
  const bool min = f.min->count() > 0, samples = f.samples->count() > 0;
  if (old && time_from_index) {
    Warn("--" + f.old->get_lnames().front() +
         ": the run has no recorded time, so the value is read in samples; use " +
         f.samples->get_name());
    return TimeAxisValue::kMin;
  }
  if (min && time_from_index)
    throw InputError(f.min->get_name() + " " + Typed(f.min) +
                     ": the run has no recorded time (its time is the sample index): use " +
                     f.samples->get_name());
  if (samples && !time_from_index)
    throw InputError(f.samples->get_name() + " " + Typed(f.samples) +
                     ": the run records time: use " + f.min->get_name());
  return min ? TimeAxisValue::kMin : samples ? TimeAxisValue::kSamples : TimeAxisValue::kNone;
}

void AddProgressFlag(CLI::App* sub, bool* progress) {
  sub->add_flag("--progress", *progress,
                "progress on stderr (step, rows read, share of the file) also when stderr is not "
                "a terminal or with --json; shown on a terminal anyway once a step takes over 2 s");
}

namespace {

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// "1,234,567": rows for people.
std::string Grouped(long long n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

}  // namespace

RowProgress::RowProgress(bool asked, bool json)
    : enabled_(asked || (!json && ::isatty(2) != 0)), tty_(::isatty(2) != 0),
      start_s_(NowSeconds()) {}

RowProgress::~RowProgress() { Finish(); }

void RowProgress::Update(const std::string& step, long long rows, double fraction) {
  if (!enabled_) return;
  const double now = NowSeconds();
  if (now - start_s_ < 2.0 || now - last_s_ < (tty_ ? 0.25 : 5.0)) return;
  last_s_ = now;
  std::string line = TerminalText(step) + ": " + Grouped(rows) + " rows";
  if (std::isfinite(fraction)) line += " (" + FormatDecimals(100 * fraction, 0) + " % of the file)";
  line += ", " + FormatDecimals(now - start_s_, 0) + " s";
  if (tty_) {
    std::fprintf(RawStderr(), "\r%s\033[K", line.c_str());
    std::fflush(RawStderr());
    shown_ = true;
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
}

drift::StreamProgress RowProgress::Callback() {
  return [this](const std::string& step, long long rows, double fraction) {
    Update(step, rows, fraction);
  };
}

void RowProgress::Finish() {
  if (!shown_) return;
  shown_ = false;
  std::fprintf(RawStderr(), "\r\033[K");
  std::fflush(RawStderr());
}

}  // namespace whirl::cli
