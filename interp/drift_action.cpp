#include "interp/drift_action.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"
#include "core/safe_text.h"
#include "drift/grey_box_io.h"

namespace whirl::interp {
namespace {

constexpr std::size_t kMaxNcLine = 512;

// Text from files the user supplies (a model's column names, a path) in a comment line:
// control characters (a newline would start a new NC block) and ',' become spaces.
std::string Text(std::string t) {
  for (char& ch : t)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f || ch == ',') ch = ' ';
  return t;
}

// Text in a cell of its own in the PLC table: the name as it is, quoted by RFC 4180 where it
// holds ',', '"', CR or LF, and no formula when opened in a spreadsheet (CsvTextCell).
std::string Cell(const std::string& t) { return CsvTextCell(t); }

std::string P(int n) { return "$AC_PARAM[" + std::to_string(n) + "]"; }
std::string Rp(int n) { return "R" + std::to_string(n); }
// "+x" or "-x": a term appended to an expression (never "+-x", which a control may refuse).
std::string Term(double v, int decimals) {
  const std::string text = FormatFixed(v, decimals);
  return text[0] == '-' ? text : "+" + text;
}

// The sign s of dK = s * e / 1000 (see the header comment).
double DriftSign(const DriftActionOptions& o) {
  return (o.control_dk == ControlDk::kAdded ? -1.0 : 1.0) * o.error_direction;
}

void CheckModel(const drift::DriftModel& m) {
  if (m.kind == drift::ModelKind::kNetwork)
    throw InputError(
        "drift action: a network model cannot be evaluated by synchronized actions "
        "here; fit the channel with --model mlr or --model dynamic");
  if ((!m.time_constants.empty() || !m.elapsed_time_constants.empty()) && m.time_unit != "min")
    throw InputError("drift action: the model's lag time constants are in '" + m.time_unit +
                     "' (its training runs had no time column): refit on runs with time_s or "
                     "time_min so the lags can be run per interpolation cycle");
}

std::vector<std::string> Inputs(const drift::DriftModel& m) {
  std::vector<std::string> in = m.sensors;
  in.insert(in.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  return in;
}

const AnalogInput& Input(const DriftActionOptions& o, const std::string& name) {
  const auto it = o.inputs.find(name);
  if (it == o.inputs.end())
    throw InputError("drift action: no analog input mapped for the model's input '" + name +
                     "' (give --input " + name +
                     "=INDEX:SCALE:OFFSET or the profile's "
                     "drift.analog_inputs)");
  return it->second;
}

// a = 1 - exp(-T_ipo / tau): the lag factor per interpolation cycle, tau in minutes.
double LagFactor(const DriftActionOptions& o, double tau_min) {
  return 1.0 - std::exp(-o.ipo_cycle_ms / 60000.0 / tau_min);
}

std::string Reading(const AnalogInput& a) {
  return FormatFixed(a.scale, kDecimalsDriftCoefficient) + "*$A_INA[" + std::to_string(a.index) +
         "]" + Term(a.offset, 4);
}

// Slots of one model: its features (input-major, then the elapsed-time features, as
// DriftModel::features), one reference per sensor, the init flag.
// A sum of more terms than this is accumulated in a slot over several actions (each line of a
// program must stay within the control's 512 characters).
constexpr int kMaxTermsPerAction = 8;

struct Layout {
  int per = 1;  // slots per input: value + lags
  int features = 0, elapsed = 0, elapsed_count = 0, ref = 0, flag = 0;
  int sum = -1;  // the partial sums of a model of more than kMaxTermsPerAction features
  int Last() const { return std::max(flag, sum); }
};

Layout MakeLayout(const drift::DriftModel& m, int first) {
  Layout l;
  l.per = 1 + static_cast<int>(m.time_constants.size());
  l.features = first;
  l.elapsed = l.features + m.InputCount() * l.per;
  l.elapsed_count = static_cast<int>(m.elapsed_time_constants.size());
  l.ref = l.features + static_cast<int>(m.features.size());
  l.flag = l.ref + static_cast<int>(m.sensors.size());
  if (static_cast<int>(m.features.size()) > kMaxTermsPerAction) l.sum = l.flag + 1;
  return l;
}

// One component as the program runs it: its models, weight and slots.
struct Part {
  const drift::DriftModel* m = nullptr;  // the offset (K0) model
  const drift::DriftModel* g = nullptr;  // the slope model, or none
  const BlankTerm* blank = nullptr;
  double weight = 1;
  Layout offset, slope;
  int s_m = -1;  // its S_j (one component: the program's S_m), -1 without a slope model
  int k0 = -1;   // its K_j, only with more than one component
};

// Slots of one program: liveness, per component the offset model's, the slope model's and its
// S_j (and, mixed, its K_j), then (mixed) the program's S_m, then the blank's flag.
struct Slots {
  int alive = 0;
  std::vector<Part> parts;
  int s_m = -1;  // $AC_PARAM holding S_m, -1 without a slope model
  int last = 0;
  const BlankTerm* blank = nullptr;  // the grey box's blank term
  int blank_flag = -1;               // B's init flag (B and its latch: options.blank_param)
  bool Mixed() const { return parts.size() > 1; }
};

void CheckComponents(const std::vector<DriftComponent>& c) {
  if (c.empty()) throw InputError("drift action: no model to run (no component)");
  double sum = 0;
  int blanks = 0;
  for (std::size_t j = 0; j < c.size(); ++j) {
    const std::string which = "drift action: component " + std::to_string(j + 1);
    if (!c[j].offset) throw InputError(which + " has no offset (K0) model");
    if (!(c[j].weight > 0 && c[j].weight <= 1))
      throw InputError(which + "'s weight " + MessageNumber(c[j].weight) +
                       " must be within (0, 1]");
    sum += c[j].weight;
    blanks += c[j].blank ? 1 : 0;
  }
  if (std::abs(sum - 1.0) > 1e-9)
    throw InputError("drift action: the components' weights sum to " + MessageNumber(sum) +
                     ", not 1 (a mixed line is a weighted mean of the components' lines)");
  if (blanks > 1)
    throw InputError("drift action: " + std::to_string(blanks) +
                     " components carry a blank term; the profile's blank_param holds one");
}

Slots MakeSlots(const std::vector<DriftComponent>& c, int first) {
  CheckComponents(c);
  Slots s;
  s.alive = first;
  int next = first + 1;
  const bool mixed = c.size() > 1;
  for (const DriftComponent& dc : c) {
    Part p{dc.offset, dc.slope, dc.blank, dc.weight, {}, {}, -1, -1};
    p.offset = MakeLayout(*p.m, next);
    next = p.offset.Last() + 1;
    if (p.g) {
      p.slope = MakeLayout(*p.g, next);
      p.s_m = p.slope.Last() + 1;
      next = p.s_m + 1;
    }
    if (mixed) p.k0 = p.offset.sum >= 0 ? p.offset.sum : next++;
    if (p.blank) s.blank = p.blank;
    s.parts.push_back(p);
  }
  if (!mixed)
    s.s_m = s.parts[0].s_m;
  else if (std::any_of(c.begin(), c.end(), [](const DriftComponent& dc) { return dc.slope; }))
    s.s_m = next++;
  s.last = next - 1;
  if (s.blank) {
    s.blank_flag = s.last + 1;
    s.last = s.blank_flag;
  }
  return s;
}

std::vector<DriftComponent> One(const drift::DriftModel& m, const drift::DriftModel* g,
                                const BlankTerm* blank) {
  return {DriftComponent{&m, g, blank, 1.0}};
}

// The highest $AC_PARAM index the program touches (its own slots, the blank latch).
int LastSlotUsed(const DriftActionOptions& o, const Slots& s) {
  return s.blank ? std::max(s.last, o.blank_param + 1) : s.last;
}

std::string Line(const std::string& text) {
  if (text.size() > kMaxNcLine)
    throw InputError("drift action: an NC line would be " + std::to_string(text.size()) +
                     " characters, above the control's " + std::to_string(kMaxNcLine) +
                     ": use fewer sensors or lags");
  return text + "\n";
}

// The longest action body: a program line is "IDS=<id> " (at most 8 characters) and the body.
constexpr std::size_t kMaxActionBody = kMaxNcLine - sizeof("IDS=255 ") + 1;

// Assignments packed into as few actions as their lines allow, in order: `head` ("DO" or
// "WHENEVER <condition> DO") and then the assignments, each body within kMaxActionBody (one
// assignment longer than that stays alone, and Line refuses it). A synchronized action's DO
// part holds several actions (Siemens, SINUMERIK 840D sl Synchronized Actions Function Manual,
// "Definition of a synchronized action": DO <action 1 ... n>); the callers pack only assignments
// that do not read each other, so what each computes does not depend on their order in the line.
std::vector<std::string> Packed(const std::string& head, const std::vector<std::string>& items) {
  std::vector<std::string> bodies;
  std::string body;
  for (const std::string& item : items) {
    if (!body.empty() && body.size() + 1 + item.size() > kMaxActionBody) {
      bodies.push_back(body);
      body.clear();
    }
    body += (body.empty() ? head : std::string()) + " " + item;
  }
  if (!body.empty()) bodies.push_back(body);
  return bodies;
}

void Append(std::vector<std::string>* to, const std::vector<std::string>& more) {
  to->insert(to->end(), more.begin(), more.end());
}

// The actions that turn one model's inputs into its features (rises, lags), in execution order:
// [the references, once] -> the rises -> [the elapsed-time updates] -> once: each lag from its
// input, each elapsed-time feature 0, then the init flag (in the last of these actions, so each
// of them still sees the flag 0 in the start's cycle) -> the lag updates. Each step's
// assignments are packed (Packed): none reads another of the same step.
std::vector<std::string> FeatureBodies(const drift::DriftModel& m, const DriftActionOptions& o,
                                       const Layout& l) {
  const std::vector<std::string> in = Inputs(m);
  const int ns = static_cast<int>(m.sensors.size());
  const std::string once = "WHENEVER " + P(l.flag) + "==0 DO";
  std::vector<std::string> bodies;
  if (o.reference == DriftReference::kStart && ns > 0) {
    std::vector<std::string> refs;
    for (int i = 0; i < ns; ++i) refs.push_back(P(l.ref + i) + "=" + Reading(Input(o, in[i])));
    Append(&bodies, Packed(once, refs));
  }
  std::vector<std::string> rises;
  for (int i = 0; i < static_cast<int>(in.size()); ++i) {
    std::string ref;
    if (i < ns)
      ref = o.reference == DriftReference::kStart ? "-" + P(l.ref + i) : Term(-m.reference_C(i), 4);
    rises.push_back(P(l.features + i * l.per) + "=" + Reading(Input(o, in[i])) + ref);
  }
  Append(&bodies, Packed("DO", rises));
  std::vector<std::string> elapsed;  // the lag of a unit step at the start: the time since it
  for (int j = 0; j < l.elapsed_count; ++j) {  // (before the init below: the start's cycle x = 0)
    const std::string y = P(l.elapsed + j);
    elapsed.push_back(y + "=" + y +
                      Term(LagFactor(o, m.elapsed_time_constants[static_cast<std::size_t>(j)]),
                           kDecimalsLagFactor) +
                      "*(1-" + y + ")");
  }
  Append(&bodies, Packed("DO", elapsed));
  std::vector<std::string> init;
  for (int i = 0; i < static_cast<int>(in.size()); ++i)
    for (int k = 1; k < l.per; ++k)
      init.push_back(P(l.features + i * l.per + k) + "=" + P(l.features + i * l.per));
  for (int j = 0; j < l.elapsed_count; ++j) init.push_back(P(l.elapsed + j) + "=0");
  init.push_back(P(l.flag) + "=1");
  Append(&bodies, Packed(once, init));
  std::vector<std::string> lags;
  for (int i = 0; l.per > 1 && i < static_cast<int>(in.size()); ++i) {
    const std::string u = P(l.features + i * l.per);
    for (int k = 1; k < l.per; ++k) {
      const std::string y = P(l.features + i * l.per + k);
      lags.push_back(y + "=" + y + Term(LagFactor(o, m.time_constants[k - 1]), kDecimalsLagFactor) +
                     "*(" + u + "-" + y + ")");
    }
  }
  Append(&bodies, Packed("DO", lags));
  return bodies;
}

// c_0 + sum c_f x_f over the layout's feature slots: one expression, or, with more than
// kMaxTermsPerAction features, actions appended to `bodies` that accumulate it in
// $AC_PARAM[target] kMaxTermsPerAction terms at a time, and then that slot.
std::string Linear(const Eigen::VectorXd& c, const Layout& l, int decimals, int target,
                   std::vector<std::string>* bodies) {
  std::string out = FormatFixed(c(0), decimals);
  const bool split = c.size() - 1 > kMaxTermsPerAction;
  for (Eigen::Index f = 1; f < c.size(); ++f) {
    out += Term(c(f), decimals) + "*" + P(l.features + static_cast<int>(f) - 1);
    if (split && (f % kMaxTermsPerAction == 0 || f + 1 == c.size())) {
      bodies->push_back("DO " + P(target) + "=" + out);
      out = P(target);
    }
  }
  return out;
}

bool SlopeMode(const DriftActionOptions& o, const Slots& s) {
  return s.s_m >= 0 || o.workpiece_slope_param >= 0;
}

// sum_j w_j $AC_PARAM[slot_j] over the components with such a slot.
std::string Weighted(const Slots& s, int Part::*slot) {
  std::string out;
  for (const Part& p : s.parts)
    if (p.*slot >= 0)
      out += (out.empty() ? "" : "+") + FormatFixed(p.weight, kDecimalsDriftWeight) + "*" +
             P(p.*slot);
  return out;
}

// The setting-data writes (see the header comment for the composition); partial sums of a
// long model are appended to `bodies` first.
std::string OutputBody(const DriftActionOptions& o, const Slots& s,
                       std::vector<std::string>* bodies) {
  const std::string ax = "[" + o.axis + "]";
  const std::string mode = s.blank ? "3" : "2";
  const Part& one = s.parts[0];
  std::string k0 = s.Mixed() ? Weighted(s, &Part::k0)
                             : Linear(DriftControlCoefficients(*one.m, o), one.offset,
                                      kDecimalsDriftCoefficient, one.offset.sum, bodies);
  if (o.workpiece_k0_param >= 0) k0 += "+" + P(o.workpiece_k0_param);
  if (!SlopeMode(o, s))
    return "DO $$SA_TEMP_COMP_ABS_VALUE" + ax + "=" + k0 + " " + P(s.alive) + "=1";
  std::string slope, ref;
  if (o.workpiece_slope_param >= 0) {
    const std::string p_w = P(o.workpiece_slope_param + 1);
    slope = P(o.workpiece_slope_param);
    ref = p_w;
    if (s.s_m >= 0) {
      slope = P(s.s_m) + "+" + slope;
      k0 += "+" + P(s.s_m) + "*(" + p_w + Term(-o.slope_fixed_end_mm, kDecimalsPositionMm) + ")";
    }
  } else {
    slope = P(s.s_m);
    ref = FormatFixed(o.slope_fixed_end_mm, kDecimalsPositionMm);
  }
  return "DO $$SA_TEMP_COMP_SLOPE" + ax + "=" + slope + " $$SA_TEMP_COMP_REF_POSITION" + ax + "=" +
         ref + " $$SA_TEMP_COMP_ABS_VALUE" + ax + "=" + k0 + " " + P(s.alive) + "=" + mode;
}

// B, the blank estimate: once its input's value, then its lag every cycle, in
// $AC_PARAM[blank_param] (the plan latches it into blank_param + 1 at the cut start).
std::vector<std::string> BlankBodies(const DriftActionOptions& o, const Slots& s) {
  const std::string b = P(o.blank_param);
  const std::string reading = Reading(Input(o, s.blank->sensor));
  return {
      "WHENEVER " + P(s.blank_flag) + "==0 DO " + b + "=" + reading + " " + P(s.blank_flag) + "=1",
      "DO " + b + "=" + b + Term(LagFactor(o, s.blank->tau_min), kDecimalsLagFactor) + "*(" +
          reading + "-" + b + ")"};
}

// One component's actions: its features, its slope S_j (with its blank term) and, mixed, its
// K_j accumulated in its own slot.
void PartBodies(const Part& p, const DriftActionOptions& o, const Slots& s,
                std::vector<std::string>* bodies) {
  Append(bodies, FeatureBodies(*p.m, o, p.offset));
  if (p.g) {
    Append(bodies, FeatureBodies(*p.g, o, p.slope));
    std::string s_m = Linear(DriftSlopeCoefficients(*p.g, o), p.slope,
                             kDecimalsDriftSlopeCoefficient, p.s_m, bodies);
    if (p.blank) {
      Append(bodies, BlankBodies(o, s));
      s_m += Term(DriftBlankCoefficient(*p.blank, o), kDecimalsDriftSlopeCoefficient) + "*(" +
             P(o.blank_param + 1) + Term(-kBlankNeutralC, 4) + ")";
    }
    if (s_m != P(p.s_m)) bodies->push_back("DO " + P(p.s_m) + "=" + s_m);
  }
  if (p.k0 < 0) return;  // one component: K_m is written with the output
  const std::string k0 =
      Linear(DriftControlCoefficients(*p.m, o), p.offset, kDecimalsDriftCoefficient, p.k0, bodies);
  if (k0 != P(p.k0)) bodies->push_back("DO " + P(p.k0) + "=" + k0);
}

// The static actions, in execution order.
std::vector<std::string> ActionBodies(const DriftActionOptions& o, const Slots& s) {
  std::vector<std::string> bodies;
  for (const Part& p : s.parts) PartBodies(p, o, s, &bodies);
  if (s.Mixed() && s.s_m >= 0) bodies.push_back("DO " + P(s.s_m) + "=" + Weighted(s, &Part::s_m));
  const std::string output = OutputBody(o, s, &bodies);
  bodies.push_back(output);
  return bodies;
}

std::string CancelRange(int first, int last) {
  std::string out;
  for (int id = first; id <= last; ++id) out += "CANCEL(" + std::to_string(id) + ")\n";
  return out;
}

bool RangesOverlap(int a0, int a1, int b0, int b1) { return a0 <= b1 && b0 <= a1; }

}  // namespace

std::string ToString(DriftReference r) { return r == DriftReference::kStart ? "start" : "model"; }

DriftReference ParseDriftReference(const std::string& s) {
  if (s == "model") return DriftReference::kModel;
  if (s == "start") return DriftReference::kStart;
  throw InputError("drift reference '" + s +
                   "': must be 'model' (the model's reference "
                   "temperatures) or 'start' (the temperatures when the action starts)");
}

void ControlLimits::Validate() const {
  if (!Stated()) return;
  if (!(analog_inputs >= 0 && analog_inputs <= kMaxAnalogIndex))
    throw InputError("MD10300 analog inputs " + std::to_string(analog_inputs) +
                     ": must be within 0.." + std::to_string(kMaxAnalogIndex));
  if (!(sync_elements >= 1))
    throw InputError("MD28250 synchronized-action elements " + std::to_string(sync_elements) +
                     ": must be at least 1");
  if (!(ac_params >= 1 && ac_params <= 10000))
    throw InputError("MD28254 $AC_PARAM count " + std::to_string(ac_params) +
                     ": must be within 1..10000");
}

namespace {

void CheckAnalogInput(const std::string& name, const AnalogInput& a, const ControlLimits& c) {
  const int max_index = c.Stated() ? c.analog_inputs : kMaxAnalogIndex;
  const std::string w = "analog input for '" + Text(name) + "'";
  if (!(a.index >= 1 && a.index <= max_index))
    throw InputError(w + ": index " + std::to_string(a.index) + " must be within 1.." +
                     std::to_string(max_index) +
                     (c.Stated() ? " (MD10300 $MN_FASTIO_ANA_NUM_INPUTS of the control)"
                                 : std::string()));
  if (!(std::abs(a.scale) >= kMinAnalogScale && std::abs(a.scale) <= kMaxAnalogScale))
    throw InputError(w + ": scale " + MessageNumber(a.scale) + " must satisfy " +
                     MessageNumber(kMinAnalogScale) + " <= |scale| <= " +
                     MessageNumber(kMaxAnalogScale) +
                     " per input unit (a smaller one prints as zero: the sensor would be gone)");
  if (!(std::abs(a.offset) <= kMaxAnalogOffset))
    throw InputError(w + ": offset " + MessageNumber(a.offset) + " must be within +-" +
                     MessageNumber(kMaxAnalogOffset));
}

// Every $AC_PARAM slot the options name lies below MD28254 (when stated).
void CheckSlotsBelowCount(const DriftActionOptions& o) {
  if (!o.control.Stated()) return;
  const int last = std::max({o.param_last < 0 ? o.param_first : o.param_last, o.workpiece_k0_param,
                             o.workpiece_slope_param < 0 ? -1 : o.workpiece_slope_param + 1,
                             o.blank_param < 0 ? -1 : o.blank_param + 1});
  if (last >= o.control.ac_params)
    throw InputError("drift $AC_PARAM slot " + std::to_string(last) +
                     " does not exist: MD28254 $MC_MM_NUM_AC_PARAM is " +
                     std::to_string(o.control.ac_params) + " (slots 0.." +
                     std::to_string(o.control.ac_params - 1) + ")");
}

}  // namespace

void DriftActionOptions::Validate() const {
  PlanOptions axis_check;
  axis_check.axis = axis;
  axis_check.sign = ExpectedSign(axis_check.direction, axis_check.control_dk);
  axis_check.Validate();
  control.Validate();
  CheckProgramName(program_name, "drift program name");
  CheckProgramName(reset_program_name, "drift reset program name");
  CheckDistinctProgramNames(program_name, reset_program_name);
  if (error_direction != 1 && error_direction != -1)
    throw InputError("drift error_direction " + std::to_string(error_direction) +
                     ": must be +1 or -1");
  if (!(ipo_cycle_ms >= kMinIpoCycleMs && ipo_cycle_ms <= kMaxIpoCycleMs))
    throw InputError("drift ipo_cycle_ms " + MessageNumber(ipo_cycle_ms) + ": must be within " +
                     MessageNumber(kMinIpoCycleMs) + ".." + MessageNumber(kMaxIpoCycleMs) + " ms");
  if (!(sync_id_first >= 1 && sync_id_first <= sync_id_last && sync_id_last <= 255))
    throw InputError("drift synchronized-action IDs " + std::to_string(sync_id_first) + ".." +
                     std::to_string(sync_id_last) + ": must satisfy 1 <= first <= last <= 255");
  if (!(param_first >= 0 && param_first <= 9999))
    throw InputError("drift param_first " + std::to_string(param_first) +
                     ": must be within 0..9999");
  if (param_last >= 0 && !(param_last >= param_first + 3 && param_last <= 9999))
    throw InputError("drift param_last " + std::to_string(param_last) + ": must be within " +
                     std::to_string(param_first + 3) +
                     "..9999 (param_first + 3: liveness, one feature, one reference, the flag)");
  if (!(save_r_first >= 0 && save_r_first <= 9998))
    throw InputError("drift save_r_first " + std::to_string(save_r_first) +
                     ": must be within 0..9998");
  if (!(missing_alarm >= kUserAlarmFirst && missing_alarm <= kUserAlarmLast - 3))
    throw InputError("drift missing_alarm " + std::to_string(missing_alarm) + ": must be within " +
                     std::to_string(kUserAlarmFirst) + ".." + std::to_string(kUserAlarmLast - 3) +
                     " (user cycle alarms, 60000..64999 belong to Siemens' cycles; it and the "
                     "next three numbers are used)");
  if (workpiece_k0_param > 9999)
    throw InputError("drift workpiece_k0_param " + std::to_string(workpiece_k0_param) +
                     ": must be within 0..9999");
  if (workpiece_slope_param >= 0 && !(workpiece_k0_param >= 0 && workpiece_slope_param <= 9998 &&
                                      (workpiece_k0_param < workpiece_slope_param ||
                                       workpiece_k0_param > workpiece_slope_param + 1)))
    throw InputError("drift workpiece_slope_param " + std::to_string(workpiece_slope_param) +
                     ": needs workpiece_k0_param (the plan hands over K0 and slope together), "
                     "must be within 0..9998, and its two slots must not hold workpiece_k0_param");
  if (blank_param >= 0 &&
      !(blank_param <= 9998 && workpiece_slope_param >= 0 &&
        !RangesOverlap(blank_param, blank_param + 1, workpiece_k0_param, workpiece_k0_param) &&
        !RangesOverlap(blank_param, blank_param + 1, workpiece_slope_param,
                       workpiece_slope_param + 1)))
    throw InputError("drift blank_param " + std::to_string(blank_param) +
                     ": must be within 0..9998, needs workpiece_slope_param (the blank term is "
                     "part of the slope this action owns) and its two slots must not hold a "
                     "workpiece slot");
  if (save_r_first > 9995)
    throw InputError("drift save_r_first " + std::to_string(save_r_first) +
                     ": must be within 0..9995 (R<n>..R<n+4> are used)");
  if (has_slope && (!(std::abs(slope_fixed_end_mm) <= kMaxPositionMm) ||
                    (slope_growth_direction != 1 && slope_growth_direction != -1)))
    throw InputError("drift slope: fixed_end_position_mm must be finite within +-" +
                     MessageNumber(kMaxPositionMm) + " mm and growth_direction +1 or -1");
  CheckSlotsBelowCount(*this);
  for (const auto& [name, a] : inputs) CheckAnalogInput(name, a, control);
}

int DriftParamCount(const drift::DriftModel& m, const drift::DriftModel* g,
                    const BlankTerm* blank) {
  return MakeSlots(One(m, g, blank), 0).last + 1;
}

std::vector<DriftComponent> GreyMixComponents(const GreyBoxAction& grey,
                                              const drift::DriftModel& rule_offset,
                                              const drift::DriftModel& rule_slope,
                                              double grey_weight) {
  if (grey_weight == 1.0) return {{&grey.offset, &grey.slope, grey.Blank(), 1.0}};
  if (!rule_offset.sensors.empty() || !rule_slope.sensors.empty())
    throw InputError(
        "mixed drift action: the rule's models read sensors (rises from power-on), the grey "
        "box's absolute temperatures; the program runs one reference: mix the grey box only "
        "with a sensor-free rule (warmup, schedule)");
  return {{&grey.offset, &grey.slope, grey.Blank(), grey_weight},
          {&rule_offset, &rule_slope, nullptr, 1.0 - grey_weight}};
}

GreyBoxAction GreyBoxActionModels(const drift::GreyBoxModel& model) {
  const drift::GreyBoxControl c = drift::GreyBoxControlModels(model);
  GreyBoxAction a;
  a.offset = c.offset;
  a.slope = c.slope;
  a.has_blank = !model.blank_sensor.empty();
  if (a.has_blank)
    a.blank = {model.blank_sensor, model.blank_tau_min, model.blank_um_per_1000_per_k,
               model.blank_min_c, model.blank_max_c};
  return a;
}

double DriftBlankCoefficient(const BlankTerm& b, const DriftActionOptions& o) {
  return RoundTo(DriftSign(o) * o.slope_growth_direction * b.um_per_1000_per_k / 1e6,
                 kDecimalsDriftSlopeCoefficient);
}

Eigen::VectorXd DriftControlCoefficients(const drift::DriftModel& m, const DriftActionOptions& o) {
  CheckModel(m);
  const double s = DriftSign(o);
  Eigen::VectorXd c = m.linear.coefficients;
  for (Eigen::Index i = 0; i < c.size(); ++i)
    c(i) = RoundTo(s * c(i) / 1000.0, kDecimalsDriftCoefficient);
  return c;
}

Eigen::VectorXd DriftSlopeCoefficients(const drift::DriftModel& g, const DriftActionOptions& o) {
  CheckModel(g);
  const double s = DriftSign(o) * o.slope_growth_direction;
  Eigen::VectorXd c = g.linear.coefficients;
  for (Eigen::Index i = 0; i < c.size(); ++i)
    c(i) = RoundTo(s * c(i) / 1e6, kDecimalsDriftSlopeCoefficient);
  return c;
}

double DriftSlopeBound(const drift::DriftModel& g, const DriftActionOptions& o,
                       const BlankTerm* blank) {
  const Eigen::VectorXd c = DriftSlopeCoefficients(g, o);
  double bound = std::abs(c(0));
  if (blank)
    bound +=
        std::abs(DriftBlankCoefficient(*blank, o)) *
        std::max(std::abs(blank->min_c - kBlankNeutralC), std::abs(blank->max_c - kBlankNeutralC));
  for (Eigen::Index f = 1; f < c.size(); ++f)
    bound +=
        std::abs(c(f)) * std::max(std::abs(g.feature_min(f - 1)), std::abs(g.feature_max(f - 1)));
  return bound;
}

namespace {

bool BlankWithoutSlope(const Slots& s) {
  return std::any_of(s.parts.begin(), s.parts.end(),
                     [](const Part& p) { return p.blank && !p.g; });
}

void CheckBlank(const DriftActionOptions& o, const Slots& s) {
  if (!s.blank) return;
  if (BlankWithoutSlope(s))
    throw InputError("drift action: the blank term is part of the slope: it needs a slope model");
  if (o.blank_param < 0)
    throw InputError(
        "drift action: the grey box's blank term needs the profile's drift.blank_param (its "
        "estimate B in $AC_PARAM[n], the value latched at the cut start in [n + 1])");
  if (o.reference != DriftReference::kModel)
    throw InputError(
        "drift action: the grey box reads absolute temperatures (referred to 20 degC): "
        "reference 'model', not 'start'");
  if (!(s.blank->tau_min > 0) || !std::isfinite(s.blank->um_per_1000_per_k))
    throw InputError("drift action: the blank term's tau_min must be > 0, its coefficient finite");
  if (RangesOverlap(o.blank_param, o.blank_param + 1, o.param_first, s.last))
    throw InputError("drift action: blank_param " + std::to_string(o.blank_param) + ", + 1 " +
                     "lie in the action's own $AC_PARAM slots " + std::to_string(o.param_first) +
                     ".." + std::to_string(s.last));
}

void CheckSlope(const DriftActionOptions& o, const Slots& s) {
  CheckBlank(o, s);
  const bool g = s.s_m >= 0;
  if (g && !o.has_slope)
    throw InputError(
        "drift action: a slope model needs the profile's drift.slope object "
        "(fixed_end_position_mm, growth_direction)");
  if (g && o.workpiece_k0_param >= 0 && o.workpiece_slope_param < 0)
    throw InputError(
        "drift action: a slope model combined with a plan needs the profile's "
        "drift.workpiece_slope_param, so the plan hands its SD43910/SD43920 over "
        "(else two writers would fight over SD43910)");
  for (const auto& [name, slot] :
       {std::pair{"workpiece_k0_param", o.workpiece_k0_param},
        {"workpiece_slope_param", o.workpiece_slope_param},
        {"workpiece_slope_param + 1",
         o.workpiece_slope_param < 0 ? -1 : o.workpiece_slope_param + 1}})
    if (slot >= 0 && RangesOverlap(slot, slot, o.param_first, s.last))
      throw InputError("drift action: " + std::string(name) + " " + std::to_string(slot) +
                       " lies in the action's own $AC_PARAM slots " +
                       std::to_string(o.param_first) + ".." + std::to_string(s.last));
}

// Part-program lines: save what is found once, reset the flags and the plan's slots.
std::string Preamble(const DriftActionOptions& o, bool slope_mode, const Slots& s) {
  const int r = o.save_r_first;
  const std::string ax = "[" + o.axis + "]";
  std::string nc = "IF " + Rp(r + 1) + "<>1\n" + Rp(r) + "=$SA_TEMP_COMP_ABS_VALUE" + ax + "\n" +
                   Rp(r + 1) + "=1\nENDIF\n";
  if (slope_mode)
    nc += "IF " + Rp(r + 4) + "<>1\n" + Rp(r + 2) + "=$SA_TEMP_COMP_SLOPE" + ax + "\n" + Rp(r + 3) +
          "=$SA_TEMP_COMP_REF_POSITION" + ax + "\n" + Rp(r + 4) + "=1\nENDIF\n";
  else  // an aborted slope run left its slope behind: give the found one back
    nc += "IF " + Rp(r + 4) + "==1\n$SA_TEMP_COMP_SLOPE" + ax + "=" + Rp(r + 2) +
          "\n$SA_TEMP_COMP_REF_POSITION" + ax + "=" + Rp(r + 3) + "\n" + Rp(r + 4) + "=0\nENDIF\n";
  nc += P(s.alive) + "=0\n";
  for (const Part& p : s.parts) {
    nc += P(p.offset.flag) + "=0\n";
    if (p.g) nc += P(p.slope.flag) + "=0\n";
  }
  if (s.blank)  // B starts again; no blank term until a cut start latches one
    nc += P(s.blank_flag) + "=0\n" + P(o.blank_param + 1) + "=" + FormatFixed(kBlankNeutralC, 4) +
          "\n";
  if (o.workpiece_k0_param >= 0) nc += P(o.workpiece_k0_param) + "=0\n";
  if (o.workpiece_slope_param >= 0)  // no plan yet: slope 0 about the fixed end
    nc += P(o.workpiece_slope_param) + "=0\n" + P(o.workpiece_slope_param + 1) + "=" +
          FormatFixed(o.has_slope ? o.slope_fixed_end_mm : 0.0, kDecimalsPositionMm) + "\n";
  return nc;
}

std::string ModelLine(const std::string& what, const drift::DriftModel& m) {
  std::string line = what + drift::ToString(m.kind) + " of " + Text(m.error_column) + " from " +
                     std::to_string(m.sensors.size()) + " sensors";
  if (!m.elapsed_time_constants.empty())
    line += " and " + std::to_string(m.elapsed_time_constants.size()) +
            " elapsed-time warm-up term(s)";
  return line;
}

// The elapsed-time features: what the control counts and from when.
std::string ElapsedNote(const Slots& s) {
  if (std::none_of(s.parts.begin(), s.parts.end(), [](const Part& p) {
        return !p.m->elapsed_time_constants.empty() ||
               (p.g && !p.g->elapsed_time_constants.empty());
      }))
    return "";
  return "; elapsed time is counted here from this program's start (run it when the machine "
         "starts, as the model's training runs started): x = 1 - exp(-t / tau) by the recursion "
         "x <- x + a (1 - x), x = 0 at the start, every interpolation cycle; beyond the longest "
         "training run the warm-up goes on to its plateau b0 + sum of its gains, never past it\n";
}

// The blank term: what the action computes and who latches it.
std::string BlankNote(const DriftActionOptions& o, const Slots& s) {
  if (!s.blank) return "";
  const std::string b = P(o.blank_param), l = P(o.blank_param + 1);
  return Line("; blank term (grey box): S_m also adds s * sigma * g_b (" + l +
              " - 20) / 1e6, g_b = " + FormatFixed(s.blank->um_per_1000_per_k, 4) +
              " um per 1000 mm per K; " + b + " = B, the lag " + FormatFixed(s.blank->tau_min, 3) +
              " min of " + Text(s.blank->sensor) + " [degC], run every cycle") +
         "; " + l +
         " = B latched at the cut start: the whirling plan (profile drift.blank_param) "
         "copies " +
         b +
         " into it at the thread start and writes 20 back at the thread end; "
         "without a plan the part program does: STOPRE, " +
         l + "=" + b + " before the cut, " + l +
         "=20 after it (20: no blank term); this program sets it to 20\n";
}

// The largest $A_INA index the program reads.
int LargestAnalogIndex(const DriftActionOptions& o, const Slots& s) {
  int largest = 0;
  for (const Part& p : s.parts) {
    for (const std::string& name : Inputs(*p.m)) largest = std::max(largest, Input(o, name).index);
    if (p.g)
      for (const std::string& name : Inputs(*p.g))
        largest = std::max(largest, Input(o, name).index);
  }
  if (s.blank) largest = std::max(largest, Input(o, s.blank->sensor).index);
  return largest;
}

// The control's limits the program depends on, with the values the profile states.
std::string Prerequisites(const DriftActionOptions& o, const Slots& s, std::size_t actions) {
  const ControlLimits& c = o.control;
  auto stated = [&](int v) {
    return c.Stated() ? " (profile: " + std::to_string(v) + ")" : std::string(" (not stated)");
  };
  const int largest = LargestAnalogIndex(o, s);
  return "; requires MD10300 $MN_FASTIO_ANA_NUM_INPUTS >= " + std::to_string(largest) +
         (largest == 0 ? " (no analog input read)" : "") + stated(c.analog_inputs) +
         ", MD28254 $MC_MM_NUM_AC_PARAM >= " + std::to_string(LastSlotUsed(o, s) + 1) +
         stated(c.ac_params) + ", MD28250 $MC_MM_NUM_SYNC_ELEMENTS room for " +
         std::to_string(actions) + " static actions" + stated(c.sync_elements) +
         "; no FCTDEF (MD28252) used\n";
}

// The model's slots within the profile's range param_first..param_last and below MD28254.
void CheckSlotRange(const DriftActionOptions& o, const Slots& s) {
  if (o.param_last >= 0 && s.last > o.param_last)
    throw InputError("drift action needs $AC_PARAM[" + std::to_string(o.param_first) + ".." +
                     std::to_string(s.last) + "], the profile reserves " +
                     std::to_string(o.param_first) + ".." + std::to_string(o.param_last) +
                     " (drift.param_last): use fewer sensors or lags, or widen the range");
  if (o.control.Stated() && LastSlotUsed(o, s) >= o.control.ac_params)
    throw InputError("drift action needs $AC_PARAM up to index " +
                     std::to_string(LastSlotUsed(o, s)) + ", the control has " +
                     std::to_string(o.control.ac_params) + " (MD28254 $MC_MM_NUM_AC_PARAM)");
}

// A mixed line's slope bound: sum_j w_j times component j's (one component: its own).
double SlopeBound(const DriftActionOptions& o, const Slots& s) {
  double bound = 0;
  for (const Part& p : s.parts)
    if (p.g) bound += p.weight * DriftSlopeBound(*p.g, o, p.blank);
  return bound;
}

// The model lines: one model, or each component with its weight and slots.
std::string ModelLines(const std::string& model_source, const Slots& s) {
  const std::string source = model_source.empty() ? std::string() : ", file " + Text(model_source);
  if (!s.Mixed()) {
    const Part& p = s.parts[0];
    return Line(ModelLine("; model: ", *p.m) + source) +
           (p.g ? Line(ModelLine("; slope model: ", *p.g)) : std::string());
  }
  std::string nc = Line("; mixed line of " + std::to_string(s.parts.size()) +
                        " components: K_m = sum_j w_j K_j, S_m = sum_j w_j S_j" + source);
  for (std::size_t j = 0; j < s.parts.size(); ++j) {
    const Part& p = s.parts[j];
    const std::string c = "; component " + std::to_string(j + 1) + ", w = " +
                          FormatFixed(p.weight, kDecimalsDriftWeight) + ": ";
    nc += Line(ModelLine(c + "model ", *p.m) + ", K_j in " + P(p.k0));
    if (p.g)
      nc += Line(ModelLine(c + "slope model ", *p.g) + ", S_j in " + P(p.s_m) +
                 (p.blank ? " (with the blank term)" : ""));
  }
  return nc;
}

std::string Header(const DriftActionOptions& o, const std::string& model_source, const Slots& s,
                   std::size_t actions) {
  const int r = o.save_r_first;
  const bool slope_mode = SlopeMode(o, s);
  const std::string j = s.Mixed() ? "_j" : "";
  std::string nc = "; " + o.program_name +
                   ": SINUMERIK 840D live machine-drift compensation of axis " + o.axis + "\n";
  nc += ModelLines(model_source, s);
  nc += std::string(s.Mixed() ? "; K_j" : "; SD43900") + " = s * (b0 + sum b_f x_f) / 1000 mm, s = " +
        FormatFixed(DriftSign(o), 0) + " (control_dk " + ToString(o.control_dk) +
        ", error_direction " + std::to_string(o.error_direction) + "); reference " +
        ToString(o.reference) + "; interpolation cycle " + FormatFixed(o.ipo_cycle_ms, 3) +
        " ms\n";
  if (s.s_m >= 0)
    nc += "; slope S" + (s.Mixed() ? j : "_m") + " = s * sigma * (g0 + sum g_f x_f) / 1e6 (sigma = " +
          std::to_string(o.slope_growth_direction) + ") about the fixed end " +
          FormatFixed(o.slope_fixed_end_mm, kDecimalsPositionMm) +
          " mm (MCS); |S_m| <= " + FormatFixed(SlopeBound(o, s), kDecimalsSd43910) +
          " over the training ranges: the plan's slopes plus this must stay within MD32760\n";
  const std::string saved = slope_mode
                                ? Rp(r) + ".." + Rp(r + 4) + " (SD43900-43920 found, markers)"
                                : Rp(r) + " (SD43900 found), " + Rp(r + 1) +
                                      " (1 while active), " + Rp(r + 2) + ".." + Rp(r + 4) +
                                      " (a slope left by an earlier run)";
  nc += "; uses static actions IDS=" + std::to_string(o.sync_id_first) + ".." +
        std::to_string(o.sync_id_last) + " (cancelled first), $AC_PARAM[" +
        std::to_string(o.param_first) + ".." + std::to_string(s.last) + "] (liveness $AC_PARAM[" +
        std::to_string(s.alive) + "] = " +
        (s.blank           ? "3"
         : SlopeMode(o, s) ? "2"
                           : "1") +
        " while running), " + saved + "\n";
  nc += BlankNote(o, s);
  if (o.workpiece_k0_param >= 0)
    nc += "; adds the whirling plan's K0 from $AC_PARAM[" + std::to_string(o.workpiece_k0_param) +
          "]: this action is the only writer of SD43900 on axis " + o.axis + "\n";
  if (o.workpiece_slope_param >= 0)
    nc += "; and the plan's SD43910/SD43920 from $AC_PARAM[" +
          std::to_string(o.workpiece_slope_param) + "], [" +
          std::to_string(o.workpiece_slope_param + 1) +
          "]: SD43920 = P_w, SD43910 = S_w + S_m, SD43900 = K0_w + K_m + S_m (P_w - P_b)\n";
  nc += ElapsedNote(s);
  nc += "; requires MD32750 $MA_TEMP_COMP_TYPE bit 0" +
        std::string(slope_mode ? " and bit 1" : "") + " for axis " + o.axis + "; stop it with " +
        o.reset_program_name + " (restores what it found)\n";
  return nc + Prerequisites(o, s, actions);
}

}  // namespace

namespace {

// The program's slots after the checks every writer makes (options, models, slope and blank).
Slots CheckedSlots(const std::vector<DriftComponent>& c, const DriftActionOptions& o) {
  o.Validate();
  for (const DriftComponent& dc : c) {
    if (dc.offset) CheckModel(*dc.offset);
    if (dc.slope) CheckModel(*dc.slope);
  }
  const Slots s = MakeSlots(c, o.param_first);
  CheckSlope(o, s);
  return s;
}

}  // namespace

std::string FormatDriftNcProgram(const drift::DriftModel& m, const DriftActionOptions& o,
                                 const std::string& model_source, const drift::DriftModel* g,
                                 const BlankTerm* blank) {
  return FormatDriftNcProgram(One(m, g, blank), o, model_source);
}

std::string FormatDriftNcProgram(const std::vector<DriftComponent>& c,
                                 const DriftActionOptions& o, const std::string& model_source) {
  const Slots s = CheckedSlots(c, o);
  CheckSlotRange(o, s);
  const std::vector<std::string> bodies = ActionBodies(o, s);
  const int available = o.sync_id_last - o.sync_id_first + 1;
  if (static_cast<int>(bodies.size()) > available)
    throw InputError("drift action needs " + std::to_string(bodies.size()) +
                     " synchronized-action IDs, the range " + std::to_string(o.sync_id_first) +
                     ".." + std::to_string(o.sync_id_last) + " has " + std::to_string(available));
  std::string nc = Header(o, model_source, s, bodies.size());
  const bool check = o.plan_marker_r >= 0;
  if (check)  // a plan's own compensation is still on the control: reset it first
    nc += "; after the alarm the program jumps to " + std::string(kProgramEndLabel) +
          " and cancels, saves and writes nothing, whatever the alarm's response\n" +
          CheckOrAlarm(Rp(o.plan_marker_r) + "<>1", o.missing_alarm + 3, "WHIRL_NO_PLAN_ACTIVE");
  nc += CancelRange(o.sync_id_first, o.sync_id_last) + "STOPRE\n";
  nc += Preamble(o, SlopeMode(o, s), s) + "STOPRE\n";
  for (std::size_t k = 0; k < bodies.size(); ++k)
    nc += Line("IDS=" + std::to_string(o.sync_id_first + static_cast<int>(k)) + " " + bodies[k]);
  if (check) nc += std::string(kProgramEndLabel) + ":\n";
  nc += "M17\n";
  return nc;
}

std::string FormatDriftNcResetProgram(const DriftActionOptions& o) {
  o.Validate();
  const int r = o.save_r_first;
  const std::string ax = "[" + o.axis + "]";
  std::string nc = "; " + o.reset_program_name + ": stops the live drift compensation of axis " +
                   o.axis +
                   " and restores the setting data found before it started (SD43900 if " +
                   Rp(r + 1) + " = 1, SD43910/SD43920 if " + Rp(r + 4) + " = 1)\n";
  nc += CancelRange(o.sync_id_first, o.sync_id_last) + "STOPRE\n";
  nc += P(o.param_first) + "=0\n";  // liveness: no action runs any more
  // The slope first: every intermediate state is then a constant offset (sinumerik.h).
  nc += "IF " + Rp(r + 4) + "==1\n$SA_TEMP_COMP_SLOPE" + ax + "=" + Rp(r + 2) +
        "\n$SA_TEMP_COMP_REF_POSITION" + ax + "=" + Rp(r + 3) + "\n" + Rp(r + 4) + "=0\nENDIF\n";
  nc += "IF " + Rp(r + 1) + "==1\n$SA_TEMP_COMP_ABS_VALUE" + ax + "=" + Rp(r) + "\n" + Rp(r + 1) +
        "=0\nENDIF\n";
  nc += "STOPRE\nM17\n";
  return nc;
}

namespace {

// Rows of one model's PLC table: intercept, then one row per feature.
std::string PlcRows(const std::string& output, const drift::DriftModel& m,
                    const DriftActionOptions& o, const Eigen::VectorXd& c, int decimals) {
  const std::vector<std::string> in = Inputs(m);
  const int ns = static_cast<int>(m.sensors.size());
  std::string out = output + ",intercept,,,,,,,," + FormatFixed(c(0), decimals) + "\n";
  const int inputs = m.InputCount();
  for (std::size_t f = 0; f < m.features.size(); ++f) {
    const drift::Feature& feat = m.features[f];
    const int input = static_cast<int>(f) / (1 + static_cast<int>(m.time_constants.size()));
    const std::string tau = feat.tau > 0 ? FormatFixed(feat.tau, 3) : "";
    const std::string af = feat.tau > 0 ? FormatFixed(LagFactor(o, feat.tau), kDecimalsLagFactor) : "";
    std::string source = ",,,";  // an elapsed-time feature reads no input (header comment)
    if (input < inputs) {
      const AnalogInput& a = Input(o, in[static_cast<std::size_t>(input)]);
      source = std::to_string(a.index) + "," + FormatFixed(a.scale, kDecimalsDriftCoefficient) +
               "," + FormatFixed(a.offset, 4) + "," +
               (input < ns ? FormatFixed(m.reference_C(input), 4) : "");
    }
    out += output + "," + Cell(feat.Name(m.time_unit)) + "," + Cell(feat.input) + "," + source +
           "," + tau + "," + af + "," + FormatFixed(c(static_cast<Eigen::Index>(f) + 1), decimals) +
           "\n";
  }
  return out;
}

}  // namespace

namespace {

// The blank term's PLC row (a last slope row of its component).
std::string BlankRow(const BlankTerm& blank, const DriftActionOptions& o) {
  const AnalogInput& a = Input(o, blank.sensor);
  return "slope,blank_latched," + Cell(blank.sensor) + "," + std::to_string(a.index) + "," +
         FormatFixed(a.scale, kDecimalsDriftCoefficient) + "," + FormatFixed(a.offset, 4) + "," +
         FormatFixed(kBlankNeutralC, 4) + "," + FormatFixed(blank.tau_min, 3) + "," +
         FormatFixed(LagFactor(o, blank.tau_min), kDecimalsLagFactor) + "," +
         FormatFixed(DriftBlankCoefficient(blank, o), kDecimalsDriftSlopeCoefficient) + "\n";
}

// One component's rows: k0_mm, slope, the blank term.
std::string PartRows(const Part& p, const DriftActionOptions& o) {
  std::string out =
      PlcRows("k0_mm", *p.m, o, DriftControlCoefficients(*p.m, o), kDecimalsDriftCoefficient);
  if (p.g)
    out += PlcRows("slope", *p.g, o, DriftSlopeCoefficients(*p.g, o),
                   kDecimalsDriftSlopeCoefficient);
  if (p.blank) out += BlankRow(*p.blank, o);
  return out;
}

// Every line of `rows` with `prefix` in front.
std::string Prefixed(const std::string& rows, const std::string& prefix) {
  std::string out;
  for (std::size_t at = 0, end; at < rows.size(); at = end + 1) {
    end = rows.find('\n', at);
    out += prefix + rows.substr(at, end - at + 1);
  }
  return out;
}

// The PLC table's comment on the models: one model, or the mixed line's components.
std::string PlcModelComment(const DriftActionOptions& o, const Slots& s) {
  const std::string sign = "sign applied (s = " + FormatFixed(DriftSign(o), 0) +
                           "); interpolation cycle " + FormatFixed(o.ipo_cycle_ms, 3) + " ms\n";
  const std::string sd =
      "SD43910[" + o.axis + "] = S_m, SD43920 = " +
      FormatFixed(o.slope_fixed_end_mm, kDecimalsPositionMm) +
      " mm, SD43900 = K_m (with a plan: SD43920 = P_w, SD43910 = S_w + S_m, SD43900 = K0_w + "
      "K_m + S_m (P_w - fixed end))\n";
  if (!s.Mixed()) {
    const Part& p = s.parts[0];
    std::string out = "# model " + drift::ToString(p.m->kind) + " of " + Text(p.m->error_column) +
                      "; " + sign;
    if (p.g)
      return out + "# slope model " + drift::ToString(p.g->kind) + " of " +
             Text(p.g->error_column) + ": S_m (mm/mm) = sum of the slope rows likewise; " + sd;
    return out + "# SD43900[" + o.axis + "] = K_m\n";
  }
  std::string out = "# mixed line of " + std::to_string(s.parts.size()) +
                    " components (columns component, weight): K_m = sum of weight * each "
                    "component's k0_mm sum, S_m (mm/mm) = sum of weight * each component's slope "
                    "sum; " + sign;
  for (std::size_t j = 0; j < s.parts.size(); ++j) {
    const Part& p = s.parts[j];
    out += "# component " + std::to_string(j + 1) + ": model " + drift::ToString(p.m->kind) +
           " of " + Text(p.m->error_column) +
           (p.g ? "; slope model " + drift::ToString(p.g->kind) + " of " + Text(p.g->error_column)
                : std::string()) +
           "\n";
  }
  return out + "# " + (s.s_m >= 0 ? sd : "SD43900[" + o.axis + "] = K_m\n");
}

}  // namespace

std::string FormatDriftPlcCsv(const drift::DriftModel& m, const DriftActionOptions& o,
                              const drift::DriftModel* g, const BlankTerm* blank) {
  return FormatDriftPlcCsv(One(m, g, blank), o);
}

std::string FormatDriftPlcCsv(const std::vector<DriftComponent>& c, const DriftActionOptions& o) {
  o.Validate();
  const Slots s = MakeSlots(c, o.param_first);
  if (s.s_m >= 0 && !o.has_slope)
    throw InputError("drift PLC table: a slope model needs the profile's drift.slope object");
  CheckBlank(o, s);
  std::string out;
  out +=
      "# whirl drift action as a PLC table: every cycle T = scale * AIN[ain_index] + offset; "
      "u = T - reference_C (sensors; extra inputs: u = T);\n";
  out +=
      "# lagged features L <- L + a_per_cycle * (u - L) (L = u at start); K_m (mm) = sum of "
      "the k0_mm rows' coefficient_per_unit * feature value, intercept included\n";
  if (std::any_of(s.parts.begin(), s.parts.end(), [](const Part& p) {
        return !p.m->elapsed_time_constants.empty() ||
               (p.g && !p.g->elapsed_time_constants.empty());
      }))
    out +=
        "# input 'elapsed' (no analog input): time since the start counted by the PLC, "
        "L <- L + a_per_cycle * (1 - L) (L = 0 at start) = 1 - exp(-t / tau_min)\n";
  out += PlcModelComment(o, s);
  if (s.blank)
    out +=
        "# blank_latched (grey box): B <- B + a_per_cycle * (T - B) (B = T at start) every "
        "cycle; at the cut start hold B for the whole cut; S_m += coefficient_per_unit * (B "
        "held - reference_C); between cuts that term is 0\n";
  const std::string columns =
      "output,feature,input,ain_index,scale,offset,reference_C,tau_min,a_per_cycle,"
      "coefficient_per_unit\n";
  if (!s.Mixed()) return out + columns + PartRows(s.parts[0], o);
  out += "component,weight," + columns;
  for (std::size_t j = 0; j < s.parts.size(); ++j)
    out += Prefixed(PartRows(s.parts[j], o),
                    std::to_string(j + 1) + "," +
                        FormatFixed(s.parts[j].weight, kDecimalsDriftWeight) + ",");
  return out;
}

std::vector<ControlRequirement> DriftRequirements(const drift::DriftModel& m,
                                                  const DriftActionOptions& o,
                                                  const drift::DriftModel* g,
                                                  const BlankTerm* blank) {
  return DriftRequirements(One(m, g, blank), o);
}

double DriftSlopeBound(const std::vector<DriftComponent>& c, const DriftActionOptions& o) {
  return SlopeBound(o, MakeSlots(c, o.param_first));
}

std::vector<ControlRequirement> DriftRequirements(const std::vector<DriftComponent>& components,
                                                  const DriftActionOptions& o) {
  const Slots s = CheckedSlots(components, o);
  const auto actions = static_cast<double>(ActionBodies(o, s).size());
  const ControlLimits& c = o.control;
  const double unstated = std::numeric_limits<double>::quiet_NaN();
  auto stated = [&](int v) { return c.Stated() ? static_cast<double>(v) : unstated; };
  const std::string program = " (" + o.program_name + ")";
  std::vector<ControlRequirement> out;
  const bool slope_mode = SlopeMode(o, s);
  ControlRequirement type = MakeRequirement(
      "MD32750 $MA_TEMP_COMP_TYPE", o.axis, RequirementRule::kBits, RequirementMerge::kUnion,
      slope_mode ? 3.0 : 1.0, 0,
      (slope_mode ? std::string("SD43900 and SD43910/SD43920") : "SD43900") + program);
  out.push_back(type);
  if (s.s_m >= 0) {
    ControlRequirement velo =
        MakeRequirement("MD32760 $MA_COMP_ADD_VELO_FACTOR", o.axis, RequirementRule::kAtLeast,
                        RequirementMerge::kSum, SlopeBound(o, s), kDecimalsSd43910,
                        "the machine slope's bound over the training ranges" + program);
    out.push_back(velo);
  }
  ControlRequirement sync = MakeRequirement(
      "MD28250 $MC_MM_NUM_SYNC_ELEMENTS", "", RequirementRule::kAtLeast, RequirementMerge::kSum,
      actions, 0,
      FormatFixed(actions, 0) + " static actions, IDS=" + std::to_string(o.sync_id_first) + ".." +
          std::to_string(o.sync_id_first + static_cast<int>(actions) - 1) + " of the range " +
          std::to_string(o.sync_id_first) + ".." + std::to_string(o.sync_id_last) +
          " it cancels first" + program);
  sync.stated = stated(c.sync_elements);
  out.push_back(sync);
  ControlRequirement ac =
      MakeRequirement("MD28254 $MC_MM_NUM_AC_PARAM", "", RequirementRule::kAtLeast,
                      RequirementMerge::kMax, static_cast<double>(LastSlotUsed(o, s) + 1), 0,
                      "$AC_PARAM up to index " + std::to_string(LastSlotUsed(o, s)) + program);
  ac.stated = stated(c.ac_params);
  out.push_back(ac);
  ControlRequirement ain = MakeRequirement(
      "MD10300 $MN_FASTIO_ANA_NUM_INPUTS", "", RequirementRule::kAtLeast, RequirementMerge::kMax,
      static_cast<double>(LargestAnalogIndex(o, s)), 0,
      "analog inputs up to $A_INA[" + std::to_string(LargestAnalogIndex(o, s)) + "]" +
          program);
  ain.stated = stated(c.analog_inputs);
  out.push_back(ain);
  const int r = o.save_r_first;
  ControlRequirement rp =
      MakeRequirement("MD28050 $MC_MM_NUM_R_PARAM", "", RequirementRule::kAtLeast,
                      RequirementMerge::kMax, static_cast<double>(r + 5), 0,
                      Rp(r) + ".." + Rp(r + 4) + ": setting data found, markers" + program);
  out.push_back(rp);
  return out;
}

}  // namespace whirl::interp
