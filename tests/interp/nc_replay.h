#pragma once
// An independent, deliberately strict replay of the NC programs whirl writes: it parses the text
// (not the plan or model behind it), executes the part-program lines as the control's
// preprocessing would, and then runs the synchronized actions interpolation cycle by cycle, in ID
// order: WHEN fires once, WHENEVER every cycle while its condition holds, no condition every
// cycle; ID= actions end with the program, IDS= actions stay until CANCEL; a dwell (G4) runs one
// cycle with the axis where it stands (axis_mm, the last cycle's position); a part-program IF on
// $AA_IM reads axis_mm (a test that runs such a program must place the axis first);
// PowerOn() drops actions and $AC_PARAM. Expressions: numbers,
// + - * / and parentheses over $AC_PARAM[n], $A_INA[n], R parameters and the setting data. A line
// it does not understand fails the test, so the writer cannot emit something the replay ignores.
// Jumps: "GOTOF <label>" and "IF <condition> GOTOF <label>" go forward to "<label>:" (a label
// that does not exist, lies behind the jump or is defined twice fails the test, and so does a
// jump out of or into an IF block, which the writers avoid). SETAL raises the alarm and the
// program goes on: whether a cycle alarm stops the interpreter depends on the machine's alarm
// configuration, so the replay assumes it does not, and a program is safe only if it jumps past
// everything it must not do after a failed check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace whirl::interp::replay {

struct Control {
  double abs_value_mm = 0;         // SD43900
  double slope = 0;                // SD43910
  double ref_position_mm = 0;      // SD43920
  std::map<int, double> r;         // R parameters
  std::map<int, double> ac_param;  // $AC_PARAM
  std::map<int, double> ain;       // $A_INA (set by the test)
  int alarm = 0;                   // last SETAL
  std::vector<int> alarms;         // every SETAL, in order

  double DkMm(double p_mm) const { return abs_value_mm + slope * (p_mm - ref_position_mm); }
};

struct Write {
  std::string target;  // "ABS", "SLOPE", "REF", "R<n>" or "P<n>" ($AC_PARAM)
  std::string expr;
};

struct SyncAction {
  int id = 0;
  bool is_static = false;  // IDS
  enum class Mode { kEveryCycle, kWhen, kWhenever } mode = Mode::kEveryCycle;
  std::string lhs, op, rhs;  // condition
  std::vector<Write> writes;
  bool fired = false;
};

// Recursive-descent evaluation of the expressions the writers emit.
class Expr {
 public:
  Expr(const std::string& text, const Control& c, const std::string& axis)
      : s_(text), c_(c), axis_(axis) {}
  double Eval() {
    const double v = Sum();
    if (i_ != s_.size()) ADD_FAILURE() << "trailing text in expression '" << s_ << "'";
    return v;
  }

 private:
  double Sum() {
    double v = Product();
    while (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) {
      const char op = s_[i_++];
      const double w = Product();
      v = op == '+' ? v + w : v - w;
    }
    return v;
  }
  double Product() {
    double v = Factor();
    while (i_ < s_.size() && (s_[i_] == '*' || s_[i_] == '/')) {
      const char op = s_[i_++];
      const double w = Factor();
      v = op == '*' ? v * w : v / w;
    }
    return v;
  }
  int Index(const std::string& prefix) {  // "<prefix>[n]" at i_, returns n
    i_ += prefix.size();
    const std::size_t close = s_.find(']', i_);
    const int n = std::stoi(s_.substr(i_, close - i_));
    i_ = close + 1;
    return n;
  }
  bool Take(const std::string& word) {
    if (s_.compare(i_, word.size(), word) != 0) return false;
    return true;
  }
  static double Get(const std::map<int, double>& m, int n) {
    const auto it = m.find(n);
    return it == m.end() ? 0.0 : it->second;
  }
  double Factor() {
    if (i_ < s_.size() && s_[i_] == '-') {
      ++i_;
      return -Factor();
    }
    if (i_ < s_.size() && s_[i_] == '(') {
      ++i_;
      const double v = Sum();
      if (i_ >= s_.size() || s_[i_] != ')') ADD_FAILURE() << "missing ) in '" << s_ << "'";
      ++i_;
      return v;
    }
    if (Take("$AC_PARAM[")) return Get(c_.ac_param, Index("$AC_PARAM["));
    if (Take("$A_INA[")) return Get(c_.ain, Index("$A_INA["));
    const std::string sd = "$SA_TEMP_COMP_";
    if (Take(sd)) {
      i_ += sd.size();
      const std::size_t open = s_.find('[', i_);
      const std::string name = s_.substr(i_, open - i_);
      i_ = open;
      const std::size_t close = s_.find(']', i_);
      if (s_.substr(i_ + 1, close - i_ - 1) != axis_) ADD_FAILURE() << "axis in '" << s_ << "'";
      i_ = close + 1;
      if (name == "ABS_VALUE") return c_.abs_value_mm;
      if (name == "SLOPE") return c_.slope;
      if (name == "REF_POSITION") return c_.ref_position_mm;
      ADD_FAILURE() << "unknown setting datum " << name;
      return 0;
    }
    if (i_ < s_.size() &&
        (s_[i_] == 'R' || (s_[i_] == '$' && i_ + 1 < s_.size() && s_[i_ + 1] == 'R'))) {
      i_ += s_[i_] == '$' ? 2 : 1;
      std::size_t end = i_;
      while (end < s_.size() && std::isdigit(static_cast<unsigned char>(s_[end]))) ++end;
      const int n = std::stoi(s_.substr(i_, end - i_));
      i_ = end;
      return Get(c_.r, n);
    }
    std::size_t end = i_;
    while (end < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[end])) || s_[end] == '.'))
      ++end;
    if (end == i_) {
      ADD_FAILURE() << "cannot read '" << s_.substr(i_) << "' in '" << s_ << "'";
      i_ = s_.size();
      return 0;
    }
    const double v = std::stod(s_.substr(i_, end - i_));
    i_ = end;
    return v;
  }

  std::string s_;
  std::size_t i_ = 0;
  const Control& c_;
  std::string axis_;
};

struct Replay {
  Control control;
  std::map<int, SyncAction> actions;  // by ID: executed in ID order
  std::string axis = "Z";
  // Called after each part-program assignment: the main run goes on between blocks, so a test can
  // run interpolation cycles there and see the states a program passes through.
  std::function<void()> between_blocks;
  double axis_mm = NAN;  // where the axis stands: set by the test or by the last Cycle()

  double Value(const std::string& expr) const { return Expr(expr, control, axis).Eval(); }

  // "$$SA_TEMP_COMP_ABS_VALUE[Z]" / "$SA_..." / "$AC_PARAM[3]" / "$R93" / "R93" -> target code.
  std::string Target(const std::string& lhs) const {
    static const std::regex kSd(R"(^\$?\$SA_TEMP_COMP_(ABS_VALUE|SLOPE|REF_POSITION)\[(\w+)\]$)");
    static const std::regex kParam(R"(^\$AC_PARAM\[(\d+)\]$)");
    static const std::regex kR(R"(^\$?R(\d+)$)");
    std::smatch m;
    if (std::regex_match(lhs, m, kSd)) {
      EXPECT_EQ(m[2].str(), axis);
      return m[1] == "ABS_VALUE" ? "ABS" : m[1] == "SLOPE" ? "SLOPE" : "REF";
    }
    if (std::regex_match(lhs, m, kParam)) return "P" + m[1].str();
    if (std::regex_match(lhs, m, kR)) return "R" + m[1].str();
    ADD_FAILURE() << "unknown assignment target '" << lhs << "'";
    return "?";
  }

  void Assign(const std::string& target, double v) {
    if (target == "ABS")
      control.abs_value_mm = v;
    else if (target == "SLOPE")
      control.slope = v;
    else if (target == "REF")
      control.ref_position_mm = v;
    else if (target[0] == 'R')
      control.r[std::stoi(target.substr(1))] = v;
    else if (target[0] == 'P')
      control.ac_param[std::stoi(target.substr(1))] = v;
  }

  // "a=b c=d ..." (no spaces inside an expression, as the writers emit).
  std::vector<Write> ParseWrites(const std::string& body) const {
    std::vector<Write> out;
    std::istringstream in(body);
    std::string item;
    while (in >> item) {
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0) {
        ADD_FAILURE() << "not an assignment: '" << item << "'";
        continue;
      }
      out.push_back({Target(item.substr(0, eq)), item.substr(eq + 1)});
    }
    return out;
  }

  static bool Compare(double l, const std::string& op, double r) {
    if (op == ">=") return l >= r;
    if (op == "<=") return l <= r;
    if (op == ">") return l > r;
    if (op == "<") return l < r;
    if (op == "==") return l == r;
    if (op == "<>") return l != r;
    ADD_FAILURE() << "operator " << op;
    return false;
  }

  bool Holds(const SyncAction& a, double p_mm) const {
    if (a.mode == SyncAction::Mode::kEveryCycle) return true;
    const double l = a.lhs == "$AA_IM[" + axis + "]" ? p_mm : Value(a.lhs);
    return Compare(l, a.op, Value(a.rhs));
  }

  // A part-program condition's left side: R<n>, $AC_PARAM[n] or the axis position $AA_IM[axis].
  double ProgramValue(const std::string& lhs) const {
    if (lhs.rfind("$AA_IM[", 0) != 0) return Value(lhs);
    EXPECT_EQ(lhs, "$AA_IM[" + axis + "]");
    EXPECT_FALSE(std::isnan(axis_mm)) << "the program reads $AA_IM: place the axis first";
    return axis_mm;
  }

  // Runs the part program's preprocessing; fails the test on any unknown line or jump (see the
  // header comment). Returns false if the program raised an alarm (SETAL) on its way to M17.
  bool RunProgram(const std::string& text) {
    static const std::regex kCancel(R"(^CANCEL\((\d+)\)$)");
    static const std::regex kIf(
        R"(^IF (R\d+|\$AC_PARAM\[\d+\]|\$AA_IM\[\w+\])(<>|==|>=|<=|<|>)([-0-9.]+)$)");
    static const std::regex kIfJump(
        R"(^IF (R\d+|\$AC_PARAM\[\d+\]|\$AA_IM\[\w+\])(<>|==|>=|<=|<|>)([-0-9.]+) GOTOF (\w+)$)");
    static const std::regex kJump(R"(^GOTOF (\w+)$)");
    static const std::regex kLabel(R"(^([A-Z_]{2}[A-Z0-9_]{0,30}):$)");
    static const std::regex kDwell(R"(^G4 F[0-9.]+$)");
    static const std::regex kSetal(R"(^SETAL\((\d+)\)$)");
    static const std::regex kAssign(R"(^(\$?\$?[A-Z_]+(\[\w+\])?|R\d+)=(\S+)$)");
    static const std::regex kSync(
        R"(^(ID|IDS)=(\d+) (?:(WHEN|WHENEVER) (\S+?)(>=|<=|==)(\S+) )?DO (.*)$)");
    std::vector<std::string> lines;
    {
      std::istringstream in(text);
      for (std::string line; std::getline(in, line);) lines.push_back(line);
    }
    // Labels and the IF depth they stand at.
    std::map<std::string, std::pair<std::size_t, int>> labels;
    int depth = 0;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      std::smatch m;
      if (std::regex_match(lines[k], m, kIf)) ++depth;
      if (lines[k] == "ENDIF") --depth;
      if (std::regex_match(lines[k], m, kLabel) &&
          !labels.emplace(m[1].str(), std::pair{k, depth}).second)
        ADD_FAILURE() << "label " << m[1] << " defined twice";
    }
    std::vector<bool> skipping;
    bool ended = false, raised = false;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      const std::string& line = lines[k];
      EXPECT_FALSE(ended) << "text after M17: " << line;
      std::smatch m;
      const bool skip = !skipping.empty() && skipping.back();
      std::string jump_to;
      if (line == "ENDIF") {
        EXPECT_FALSE(skipping.empty()) << "ENDIF without IF";
        if (!skipping.empty()) skipping.pop_back();
      } else if (std::regex_match(line, m, kIf)) {
        skipping.push_back(skip || !Compare(ProgramValue(m[1]), m[2], std::stod(m[3])));
      } else if (skip || (!line.empty() && line[0] == ';') || line == "STOPRE" ||
                 std::regex_match(line, m, kLabel)) {
      } else if (std::regex_match(line, m, kIfJump)) {
        if (Compare(ProgramValue(m[1]), m[2], std::stod(m[3]))) jump_to = m[4];
      } else if (std::regex_match(line, m, kJump)) {
        jump_to = m[1];
      } else if (std::regex_match(line, m, kDwell)) {  // the main run goes on: one cycle
        Cycle(axis_mm);
        if (between_blocks) between_blocks();
      } else if (line == "M17") {
        ended = true;
      } else if (std::regex_match(line, m, kSetal)) {
        control.alarm = std::stoi(m[1]);
        control.alarms.push_back(control.alarm);
        raised = true;  // and on: the alarm is assumed not to stop the interpreter
      } else if (std::regex_match(line, m, kCancel)) {
        actions.erase(std::stoi(m[1]));
      } else if (std::regex_match(line, m, kSync)) {
        SyncAction a;
        a.is_static = m[1] == "IDS";
        a.id = std::stoi(m[2]);
        if (m[3].matched) {
          a.mode = m[3] == "WHEN" ? SyncAction::Mode::kWhen : SyncAction::Mode::kWhenever;
          a.lhs = m[4];
          a.op = m[5];
          a.rhs = m[6];
        }
        a.writes = ParseWrites(m[7]);
        actions[a.id] = a;
      } else if (std::regex_match(line, m, kAssign)) {
        Assign(Target(m[1]), Value(m[3]));
        if (between_blocks) between_blocks();
      } else {
        ADD_FAILURE() << "line the replay does not understand: '" << line << "'";
      }
      if (jump_to.empty()) continue;
      const auto it = labels.find(jump_to);
      if (it == labels.end() || it->second.first <= k || it->second.second != 0 ||
          !skipping.empty()) {
        ADD_FAILURE() << "jump '" << line << "': the label must exist, lie ahead and outside "
                      << "every IF block, and the jump must not leave one";
        return false;
      }
      k = it->second.first;  // the label line itself does nothing
    }
    EXPECT_TRUE(ended) << "no M17";
    EXPECT_TRUE(skipping.empty()) << "IF without ENDIF";
    return !raised;
  }

  // One interpolation cycle with the axis at p_mm: every action in ID order.
  void Cycle(double p_mm) {
    axis_mm = p_mm;
    for (auto& [id, a] : actions) {
      if (a.mode == SyncAction::Mode::kWhen && a.fired) continue;
      if (!Holds(a, p_mm)) continue;
      for (const Write& w : a.writes) Assign(w.target, Value(w.expr));
      a.fired = true;
    }
  }

  // Moves the axis from `from_mm` up to, not onto, `to_mm` in `steps` cycles; returns the
  // largest |applied dK - reference's dK| on the way, mm.
  double WorstDeviationOnApproach(double from_mm, double to_mm, int steps,
                                  const Control& reference) {
    double worst_mm = 0;
    for (int i = 0; i < steps; ++i) {
      const double p = from_mm + (to_mm - from_mm) * i / static_cast<double>(steps);
      Cycle(p);
      worst_mm = std::max(worst_mm, std::abs(control.DkMm(p) - reference.DkMm(p)));
    }
    return worst_mm;
  }

  // Power off and on: every synchronized action and $AC_PARAM is gone; R parameters and setting
  // data are retentive.
  void PowerOn() {
    actions.clear();
    control.ac_param.clear();
  }

  // Program end or reset: modal (ID=) actions are gone, static (IDS=) ones stay.
  void EndProgram() {
    for (auto it = actions.begin(); it != actions.end();)
      it = it->second.is_static ? std::next(it) : actions.erase(it);
  }
};

}  // namespace whirl::interp::replay
