#pragma once
// An independent, deliberately strict replay of the NC programs whirl writes: it parses the text
// (not the plan), executes the part-program lines as the control's preprocessing would, and then
// runs the synchronized actions along the axis travel, interpolation cycle by cycle (WHEN fires
// once, actions in ID order). A line it does not understand fails the test, so the writer cannot
// emit something the replay silently ignores.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace whirl::interp::replay {

struct Control {
  double abs_value_mm = 0;     // SD43900
  double slope = 0;            // SD43910
  double ref_position_mm = 0;  // SD43920
  std::map<int, double> r;     // R parameters

  double DkMm(double p_mm) const { return abs_value_mm + slope * (p_mm - ref_position_mm); }
};

struct Write {
  std::string target;  // "ABS", "SLOPE", "REF" or "R<n>"
  std::string value;   // a number or "R<n>"
};

struct SyncAction {
  int id = 0;
  bool greater_equal = true;  // >= or <=
  double threshold_mm = 0;
  std::vector<Write> writes;
  bool fired = false;
};

struct Replay {
  Control control;
  std::map<int, SyncAction> actions;  // by ID: executed in ID order
  std::string axis = "Z";

  double Value(const std::string& v) const {
    if (v[0] == 'R')
      return control.r.count(std::stoi(v.substr(1))) ? control.r.at(std::stoi(v.substr(1))) : 0.0;
    return std::stod(v);
  }

  void Apply(const Write& w) {
    const double v = Value(w.value);
    if (w.target == "ABS")
      control.abs_value_mm = v;
    else if (w.target == "SLOPE")
      control.slope = v;
    else if (w.target == "REF")
      control.ref_position_mm = v;
    else
      control.r[std::stoi(w.target.substr(1))] = v;
  }

  static std::string SdTarget(const std::string& name) {
    if (name == "ABS_VALUE") return "ABS";
    if (name == "SLOPE") return "SLOPE";
    if (name == "REF_POSITION") return "REF";
    ADD_FAILURE() << "unknown setting datum " << name;
    return "?";
  }

  // Runs the part program's preprocessing; fails the test on any unknown line.
  void RunProgram(const std::string& text) {
    static const std::regex kComment(R"(^;.*$)");
    static const std::regex kCancel(R"(^CANCEL\((\d+)\)$)");
    static const std::regex kIf(R"(^IF R(\d+)(<>|==)([-0-9.]+)$)");
    static const std::regex kAssignR(
        R"(^R(\d+)=(\$SA_TEMP_COMP_(ABS_VALUE|SLOPE|REF_POSITION)\[(\w+)\]|[-0-9.]+)$)");
    static const std::regex kAssignSd(
        R"(^\$SA_TEMP_COMP_(ABS_VALUE|SLOPE|REF_POSITION)\[(\w+)\]=(R\d+|[-0-9.]+)$)");
    static const std::regex kSync(R"(^ID=(\d+) WHEN \$AA_IM\[(\w+)\](>=|<=)([-0-9.]+) DO (.*)$)");
    static const std::regex kSyncWrite(
        R"(\$\$SA_TEMP_COMP_(ABS_VALUE|SLOPE|REF_POSITION)\[(\w+)\]=(\$R\d+|[-0-9.]+)|\$R(\d+)=([-0-9.]+))");
    std::istringstream in(text);
    std::string line;
    std::vector<bool> skipping;
    bool ended = false;
    while (std::getline(in, line)) {
      ASSERT_FALSE(ended) << "text after M17: " << line;
      std::smatch m;
      const bool skip = !skipping.empty() && skipping.back();
      if (line == "ENDIF") {
        ASSERT_FALSE(skipping.empty()) << "ENDIF without IF";
        skipping.pop_back();
      } else if (std::regex_match(line, m, kIf)) {
        const double r = Value("R" + m[1].str());
        const double c = std::stod(m[3]);
        const bool holds = m[2] == "==" ? r == c : r != c;
        skipping.push_back(skip || !holds);
      } else if (skip || std::regex_match(line, kComment) || line == "STOPRE") {
      } else if (line == "M17") {
        ended = true;
      } else if (std::regex_match(line, m, kCancel)) {
        actions.erase(std::stoi(m[1]));
      } else if (std::regex_match(line, m, kAssignR)) {
        const int n = std::stoi(m[1]);
        if (m[3].matched) {
          ASSERT_EQ(m[4].str(), axis);
          const std::string t = SdTarget(m[3]);
          control.r[n] = t == "ABS"     ? control.abs_value_mm
                         : t == "SLOPE" ? control.slope
                                        : control.ref_position_mm;
        } else {
          control.r[n] = std::stod(m[2]);
        }
      } else if (std::regex_match(line, m, kAssignSd)) {
        ASSERT_EQ(m[2].str(), axis);
        Apply({SdTarget(m[1]), m[3]});
      } else if (std::regex_match(line, m, kSync)) {
        ASSERT_EQ(m[2].str(), axis);
        SyncAction a;
        a.id = std::stoi(m[1]);
        a.greater_equal = m[3] == ">=";
        a.threshold_mm = std::stod(m[4]);
        const std::string body = m[5];
        std::string rest;
        for (std::sregex_iterator it(body.begin(), body.end(), kSyncWrite), end; it != end; ++it) {
          const std::smatch& w = *it;
          if (w[1].matched) {
            ASSERT_EQ(w[2].str(), axis);
            std::string v = w[3];
            if (v[0] == '$') v = v.substr(1);
            a.writes.push_back({SdTarget(w[1]), v});
          } else {
            a.writes.push_back({"R" + w[4].str(), w[5]});
          }
          rest += w.str() + " ";
        }
        ASSERT_EQ(rest, body + " ") << "unparsed part of the action: " << body;
        actions[a.id] = a;
      } else {
        FAIL() << "line the replay does not understand: '" << line << "'";
      }
    }
    ASSERT_TRUE(ended) << "no M17";
    ASSERT_TRUE(skipping.empty()) << "IF without ENDIF";
  }

  // One interpolation cycle with the axis at p_mm: every action in ID order.
  void Cycle(double p_mm) {
    for (auto& [id, a] : actions) {
      if (a.fired) continue;
      const bool holds = a.greater_equal ? p_mm >= a.threshold_mm : p_mm <= a.threshold_mm;
      if (!holds) continue;
      for (const Write& w : a.writes) Apply(w);
      a.fired = true;
    }
  }

  // Program end or reset: modal (ID=) actions are gone.
  void EndProgram() { actions.clear(); }
};

}  // namespace whirl::interp::replay
