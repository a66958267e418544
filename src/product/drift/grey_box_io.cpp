#include "drift/grey_box_io.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::drift {
namespace {

using nlohmann::json;

const char* const kWhat = "grey box model";

// A sensor's feature is T - 20; a duty input's the input as logged.
std::string FeatureName(const std::string& input, double tau, bool duty) {
  const std::string u = duty ? input : input + "-20";
  return tau == 0 ? u : "lag" + MessageNumber(tau) + "min(" + u + ")";
}

std::vector<std::string> Joined(std::vector<std::string> sensors,
                                const std::vector<std::string>& duty) {
  sensors.insert(sensors.end(), duty.begin(), duty.end());
  return sensors;
}

json Features(const std::vector<std::string>& sensors, const std::vector<std::string>& duty,
              const std::vector<double>& taus, const Eigen::VectorXd& c, const Eigen::VectorXd& lo,
              const Eigen::VectorXd& hi) {
  json out = json::array();
  Eigen::Index k = 0;
  const std::vector<std::string> inputs = Joined(sensors, duty);
  for (std::size_t i = 0; i < inputs.size(); ++i)
    for (std::size_t l = 0; l <= taus.size(); ++l, ++k) {
      const std::string& in = inputs[i];
      const double tau = l == 0 ? 0.0 : taus[l - 1];
      out.push_back({{"name", FeatureName(in, tau, i >= sensors.size())},
                     {"input", in},
                     {"tau_min", tau},
                     {"coefficient", c(k)},
                     {"train_min_k", lo(k)},
                     {"train_max_k", hi(k)}});
    }
  return out;
}

// One list of features: each object's input and tau must be those the sensors and lags imply.
void ReadFeatures(const json& j, const char* key, const std::vector<std::string>& inputs,
                  const std::vector<double>& taus, Eigen::VectorXd* c, Eigen::VectorXd* lo,
                  Eigen::VectorXd* hi) {
  const json& f = RequireArray(j, key, kWhat);
  const std::size_t n = inputs.size() * (1 + taus.size());
  if (f.size() != n)
    throw InputError(std::string(kWhat) + ": '" + key + "' has " + std::to_string(f.size()) +
                     " features, the sensors and time constants imply " + std::to_string(n));
  c->resize(static_cast<Eigen::Index>(n));
  lo->resize(c->size());
  hi->resize(c->size());
  for (std::size_t k = 0; k < n; ++k) {
    const std::string w = std::string(kWhat) + " '" + key + "'[" + std::to_string(k) + "]";
    const json& x = f[k];
    RejectUnknownKeys(x, {"name", "input", "tau_min", "coefficient", "train_min_k", "train_max_k"},
                      w);
    const std::string& input = inputs[k / (1 + taus.size())];
    const std::size_t l = k % (1 + taus.size());
    const double tau = l == 0 ? 0.0 : taus[l - 1];
    if (RequireString(x, "input", w) != input || RequireNumber(x, "tau_min", w) != tau)
      throw InputError(w + ": must be input '" + input + "' with tau_min " + MessageNumber(tau) +
                       " (input-major: each sensor's T - 20, then its lags; then each duty "
                       "input and its lags)");
    const auto i = static_cast<Eigen::Index>(k);
    (*c)(i) = RequireNumber(x, "coefficient", w);
    (*lo)(i) = RequireNumber(x, "train_min_k", w);
    (*hi)(i) = RequireNumber(x, "train_max_k", w);
  }
}

void CheckNames(const std::vector<std::string>& names, const char* field, const std::string& what) {
  std::set<std::string> seen;
  for (const std::string& n : names) {
    if (n.empty()) throw InputError(what + ": '" + field + "' holds an empty sensor name");
    if (!seen.insert(n).second)
      throw InputError(what + ": '" + field + "' names '" + n + "' twice");
  }
}

// The first `temperatures` features are temperatures (K against 20 degC); the rest duty inputs in
// their own unit.
void CheckCoefficients(const Eigen::VectorXd& c, const Eigen::VectorXd& lo,
                       const Eigen::VectorXd& hi, Eigen::Index temperatures, const char* field,
                       const char* unit) {
  for (Eigen::Index k = 0; k < c.size(); ++k) {
    const std::string f = std::string(field) + "[" + std::to_string(k) + "]";
    const Range range = k >= temperatures
                            ? Range{-kMaxGreyDutyValue, kMaxGreyDutyValue, false, "the input's unit"}
                            : kGreyFeatureRangeK;
    CheckRange(c(k), {-kMaxGreyCoefficient, kMaxGreyCoefficient, false, unit}, f + ".coefficient",
               kWhat);
    CheckRange(lo(k), range, f + ".train_min_k", kWhat);
    CheckRange(hi(k), {lo(k), range.max, false, range.unit, "at least train_min_k"},
               f + ".train_max_k", kWhat);
  }
}

std::map<std::string, double> ReadPriors(const json& j, const char* key,
                                         const std::vector<std::string>& sensors,
                                         const std::string& what) {
  std::map<std::string, double> out;
  if (!j.contains(key)) return out;
  const json& p = RequireObject(j, key, what);
  for (const auto& [name, v] : p.items()) {
    if (std::find(sensors.begin(), sensors.end(), name) == sensors.end())
      throw InputError(what + ": '" + key + "' names '" + name +
                       "', which is not one of its sensors (a prior for no input would be "
                       "ignored)");
    const double x = RequireFiniteValue(v, what + " '" + key + "' '" + name + "'");
    CheckRange(x, {-kMaxGreyCoefficient, kMaxGreyCoefficient, false, "um per K"},
               std::string(key) + "." + name, what);
    out[name] = x;
  }
  return out;
}

void CheckTimeConstants(const std::vector<double>& taus) {
  for (std::size_t l = 0; l < taus.size(); ++l) {
    CheckRange(taus[l], {0, kMaxTimeConstant, true, "min"}, "time_constants_min", kWhat);
    if (l > 0 && !(taus[l] > taus[l - 1]))
      throw InputError(std::string(kWhat) + ": 'time_constants_min' must increase strictly");
  }
}

}  // namespace

void ValidateGreyBox(const GreyBoxModel& m) {
  const std::string w = kWhat;
  if (m.offset_sensors.empty() && m.slope_sensors.empty())
    throw InputError(w + ": no offset or slope sensor");
  CheckNames(m.offset_sensors, "offset_sensors", w);
  CheckNames(m.slope_sensors, "slope_sensors", w);
  CheckNames(Joined(m.offset_sensors, m.offset_duty), "offset_sensors and offset_duty", w);
  CheckNames(Joined(m.slope_sensors, m.slope_duty), "slope_sensors and slope_duty", w);
  CheckTimeConstants(m.time_constants);
  CheckRange(m.z_ref_mm, kAxisPositionRange, "z_ref_mm", w);
  const auto per = static_cast<Eigen::Index>(1 + m.time_constants.size());
  const auto no = static_cast<Eigen::Index>(m.offset_sensors.size() + m.offset_duty.size()) * per;
  const auto ns = static_cast<Eigen::Index>(m.slope_sensors.size() + m.slope_duty.size()) * per;
  if (m.a.size() != no || m.offset_min.size() != no || m.offset_max.size() != no)
    throw InputError(w + ": 'offset_features' must hold " + std::to_string(no) +
                     " coefficients and ranges ((offset sensors + offset duty inputs) x (1 + time "
                     "constants))");
  if (m.g.size() != ns || m.slope_min.size() != ns || m.slope_max.size() != ns)
    throw InputError(w + ": 'slope_features' must hold " + std::to_string(ns) +
                     " coefficients and ranges ((slope sensors + slope duty inputs) x (1 + time "
                     "constants))");
  CheckCoefficients(m.a, m.offset_min, m.offset_max,
                    static_cast<Eigen::Index>(m.offset_sensors.size()) * per, "offset_features",
                    "um per K");
  CheckCoefficients(m.g, m.slope_min, m.slope_max,
                    static_cast<Eigen::Index>(m.slope_sensors.size()) * per, "slope_features",
                    "um per 1000 mm per K");
  CheckRange(m.slope_intercept_um_per_1000,
             {-kMaxGreyIntercept, kMaxGreyIntercept, false, "um per 1000 mm"},
             "slope_intercept_um_per_1000", w);
  if (!m.blank_sensor.empty()) {
    CheckRange(m.blank_tau_min, {0, kMaxTimeConstant, true, "min"}, "blank.tau_min", w);
    CheckRange(m.blank_um_per_1000_per_k,
               {-kMaxGreyCoefficient, kMaxGreyCoefficient, false, "um per 1000 mm per K"},
               "blank.um_per_1000_per_k", w);
    CheckRange(m.blank_min_c, kGreyBlankRangeC, "blank.train_min_c", w);
    CheckRange(m.blank_max_c,
               {m.blank_min_c, kGreyBlankRangeC.max, false, "degC", "at least train_min_c"},
               "blank.train_max_c", w);
  } else if (m.blank_um_per_1000_per_k != 0) {
    throw InputError(w + ": a blank coefficient without a blank sensor");
  }
  CheckRange(m.prior_strength, {0, 1e6, false, ""}, "fit.prior_strength", w);
  CheckRange(m.cv_rmse_um, {0, kMaxResidualStdUm, false, "um"}, "fit.cv_rmse_um", w);
  CheckRange(m.rows, {0, 1e9, false, ""}, "fit.rows", w);
}

void to_json(json& j, const GreyBoxModel& m) {
  json blank = nullptr;
  if (!m.blank_sensor.empty())
    blank = {{"tau_min", m.blank_tau_min},
             {"um_per_1000_per_k", m.blank_um_per_1000_per_k},
             {"train_min_c", m.blank_min_c},
             {"train_max_c", m.blank_max_c}};
  j = {{"format", kGreyBoxFormat},
       {"schema_version", kGreyBoxSchemaVersion},
       {"model",
        "K0 = a' phi_o [um]; G = g0 + g' phi_s + g_b (B(t0) - 20) [um per 1000 mm]; m(t, z) = K0 + "
        "G (z_ref - z) / 1000; phi: T - 20 degC and its first-order lags (L_0 = u_0); B: the lag "
        "blank.tau_min of blank_sensor, latched at the cut start (drift/grey_box.h)"},
       {"offset_sensors", m.offset_sensors},
       {"slope_sensors", m.slope_sensors},
       {"blank_sensor", m.blank_sensor},
       {"time_constants_min", m.time_constants},
       {"z_ref_mm", m.z_ref_mm},
       {"offset_features",
        Features(m.offset_sensors, m.offset_duty, m.time_constants, m.a, m.offset_min,
                 m.offset_max)},
       {"slope_features", Features(m.slope_sensors, m.slope_duty, m.time_constants, m.g,
                                   m.slope_min, m.slope_max)},
       {"slope_intercept_um_per_1000", m.slope_intercept_um_per_1000},
       {"blank", blank},
       {"fit",
        {{"prior_strength", m.prior_strength}, {"cv_rmse_um", m.cv_rmse_um}, {"rows", m.rows}}},
       {"training", {{"notes", m.notes}}}};
  // Written only when used: a model without duty inputs is the file it was before they existed.
  if (!m.offset_duty.empty()) j["offset_duty"] = m.offset_duty;
  if (!m.slope_duty.empty()) j["slope_duty"] = m.slope_duty;
}

void from_json(const json& j, GreyBoxModel& m) {
  if (!j.is_object() || !j.contains("format") || j["format"] != kGreyBoxFormat)
    throw InputError(std::string("not a grey box model (its 'format' is not '") + kGreyBoxFormat +
                     "'; write one with whirl drift fit-grey)");
  RejectUnknownKeys(j,
                    {"format", "schema_version", "model", "offset_sensors", "slope_sensors",
                     "blank_sensor", "offset_duty", "slope_duty", "time_constants_min",
                     "z_ref_mm", "offset_features",
                     "slope_features", "slope_intercept_um_per_1000", "blank", "fit", "training",
                     "mix"},
                    kWhat);
  // Version 2 exactly when the mix part is there (ReadGreyBoxFile reads it).
  RequireSchema(j, kGreyBoxFormat,
                j.contains("mix") ? kGreyBoxMixSchemaVersion : kGreyBoxSchemaVersion, kWhat,
                "format");
  m = GreyBoxModel{};
  m.offset_sensors = RequireStrings(j, "offset_sensors", kWhat, 1000);
  m.slope_sensors = RequireStrings(j, "slope_sensors", kWhat, 1000);
  m.blank_sensor = RequireString(j, "blank_sensor", kWhat);
  if (j.contains("offset_duty")) m.offset_duty = RequireStrings(j, "offset_duty", kWhat, 1000);
  if (j.contains("slope_duty")) m.slope_duty = RequireStrings(j, "slope_duty", kWhat, 1000);
  m.time_constants = RequireNumberArray(j, "time_constants_min", kWhat, 100);
  CheckTimeConstants(m.time_constants);  // before the features are matched against them
  m.z_ref_mm = RequireNumber(j, "z_ref_mm", kWhat);
  ReadFeatures(j, "offset_features", Joined(m.offset_sensors, m.offset_duty), m.time_constants,
               &m.a, &m.offset_min, &m.offset_max);
  ReadFeatures(j, "slope_features", Joined(m.slope_sensors, m.slope_duty), m.time_constants, &m.g,
               &m.slope_min, &m.slope_max);
  m.slope_intercept_um_per_1000 = RequireNumber(j, "slope_intercept_um_per_1000", kWhat);
  const json& b = RequireKey(j, "blank", kWhat);
  if (m.blank_sensor.empty() != b.is_null())
    throw InputError(std::string(kWhat) +
                     ": 'blank' must be null exactly when 'blank_sensor' is \"\"");
  if (!b.is_null()) {
    const std::string wb = std::string(kWhat) + " 'blank'";
    RejectUnknownKeys(b, {"tau_min", "um_per_1000_per_k", "train_min_c", "train_max_c"}, wb);
    m.blank_tau_min = RequireNumber(b, "tau_min", wb);
    m.blank_um_per_1000_per_k = RequireNumber(b, "um_per_1000_per_k", wb);
    m.blank_min_c = RequireNumber(b, "train_min_c", wb);
    m.blank_max_c = RequireNumber(b, "train_max_c", wb);
  }
  const std::string wf = std::string(kWhat) + " 'fit'";
  const json& f = RequireObject(j, "fit", kWhat);
  RejectUnknownKeys(f, {"prior_strength", "cv_rmse_um", "rows"}, wf);
  m.prior_strength = RequireNumber(f, "prior_strength", wf);
  m.cv_rmse_um = RequireNumber(f, "cv_rmse_um", wf);
  m.rows = static_cast<int>(RequireInteger(f, "rows", 0, 1000000000, wf));
  const json& t = RequireObject(j, "training", kWhat);
  m.notes = RequireStrings(t, "notes", std::string(kWhat) + " 'training'", 100000, 100000);
  ValidateGreyBox(m);
}

GreyBoxModel ReadGreyBoxModel(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  try {
    return j.get<GreyBoxModel>();
  } catch (const InputError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

void WriteGreyBoxModel(const std::filesystem::path& path, const GreyBoxModel& m) {
  ValidateGreyBox(m);
  WriteJsonFile(path, json(m));
}

namespace {

constexpr const char* kMixWhat = "grey box model 'mix'";

void ValidateMix(const GreyBoxMix& x) {
  if (!(x.weight >= kShortMixFloor && x.weight < 1))
    throw InputError(std::string(kMixWhat) + " 'weight' = " + std::to_string(x.weight) +
                     ": must lie within [" + std::to_string(kShortMixFloor) +
                     ", 1) (w = 1 is the grey box alone: no mix part)");
  if (x.rule != "warmup" && x.rule != "schedule")
    throw InputError(std::string(kMixWhat) + " 'rule' = '" + x.rule +
                     "': must be warmup or schedule");
  for (const auto& [key, m] : {std::pair{"rule_offset", &x.rule_offset}, {"rule_slope", &x.rule_slope}}) {
    if (!m->sensors.empty())
      throw InputError(std::string(kMixWhat) + " '" + key +
                       "': reads sensors; the mix runs with the grey box's reference (absolute "
                       "temperatures), so its rule must be sensor-free (warmup, schedule)");
    m->Validate();
  }
}

// The joint fit (drift/joint.h ToDriftModels) computes no variance inflation; a drift model file
// carries one per feature: 1, as GreyBoxControlModels writes.
DriftModel WithVif(DriftModel d) {
  const Eigen::Index nf = d.linear.coefficients.size() - 1;
  if (nf >= 0 && d.linear.vif.size() != nf) d.linear.vif = Eigen::VectorXd::Ones(nf);
  return d;
}

json MixJson(const GreyBoxMix& x) {
  return {{"weight", x.weight},
          {"rule", x.rule},
          {"rule_offset", json(WithVif(x.rule_offset))},
          {"rule_slope", json(WithVif(x.rule_slope))},
          {"guard",
           {{"days", x.guard.days},
            {"grey_rms_um", x.guard.grey_rms_um},
            {"rule_rms_um", x.guard.rule_rms_um},
            {"combination_weight", x.guard.combination_weight}}}};
}

GreyBoxMix MixOf(const json& j) {
  const std::string w = kMixWhat;
  RejectUnknownKeys(j, {"weight", "rule", "rule_offset", "rule_slope", "guard"}, w);
  GreyBoxMix x;
  x.weight = RequireNumber(j, "weight", w);
  x.rule = RequireString(j, "rule", w);
  for (const auto& [key, m] : {std::pair{"rule_offset", &x.rule_offset}, {"rule_slope", &x.rule_slope}}) {
    try {
      *m = RequireObject(j, key, w).get<DriftModel>();
    } catch (const InputError& e) {
      throw InputError(w + " '" + key + "': " + e.what());
    }
  }
  const std::string wg = w + " 'guard'";
  const json& g = RequireObject(j, "guard", w);
  RejectUnknownKeys(g, {"days", "grey_rms_um", "rule_rms_um", "combination_weight"}, wg);
  x.guard.days = static_cast<int>(RequireInteger(g, "days", 0, 1000000, wg));
  x.guard.grey_rms_um = RequireNumber(g, "grey_rms_um", wg);
  x.guard.rule_rms_um = RequireNumber(g, "rule_rms_um", wg);
  x.guard.combination_weight = RequireNumber(g, "combination_weight", wg);
  ValidateMix(x);
  return x;
}

}  // namespace

std::optional<GreyBoxMix> GreyBoxMixPart(const GreyMix& mix, const ShopRecord& record) {
  if (!mix.applies || mix.weight == 1.0) return std::nullopt;
  GreyBoxMix x;
  x.weight = mix.weight;
  x.rule = mix.rules.BaseName();
  const ShopControl c = ShopControlModels(mix.rules.Base(), record.day_logs);
  x.rule_offset = c.offset;
  x.rule_slope = c.slope;
  for (DriftModel* d : {&x.rule_offset, &x.rule_slope}) *d = WithVif(*d);
  x.guard = mix.guard;
  return x;
}

GreyBoxFile ReadGreyBoxFile(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  try {
    GreyBoxFile f{j.get<GreyBoxModel>(), std::nullopt};
    if (j.contains("mix")) f.mix = MixOf(j["mix"]);
    return f;
  } catch (const InputError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

void WriteGreyBoxFile(const std::filesystem::path& path, const GreyBoxFile& f) {
  ValidateGreyBox(f.model);
  json j(f.model);
  if (f.mix) {
    ValidateMix(*f.mix);
    j["schema_version"] = kGreyBoxMixSchemaVersion;
    j["mix"] = MixJson(*f.mix);
  }
  WriteJsonFile(path, j);
}

GreyBoxSpec ReadGreyBoxSpec(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  const std::string w = "grey box spec '" + path.string() + "'";
  if (!j.is_object() || !j.contains("format") || j["format"] != kGreyBoxSpecFormat)
    throw InputError(w + ": its 'format' must be '" + kGreyBoxSpecFormat + "'");
  RejectUnknownKeys(j,
                    {"format", "schema_version", "description", "offset_sensors", "slope_sensors",
                     "blank_sensor", "offset_duty", "slope_duty", "z_ref_mm",
                     "offset_prior_um_per_k",
                     "slope_prior_um_per_1000_per_k", "blank_prior_um_per_1000_per_k"},
                    w);
  RequireSchema(j, kGreyBoxSpecFormat, 1, w, "format");
  GreyBoxSpec s;
  s.offset_sensors = RequireStrings(j, "offset_sensors", w, 1000);
  s.slope_sensors = RequireStrings(j, "slope_sensors", w, 1000);
  s.blank_sensor = RequireString(j, "blank_sensor", w);
  CheckNames(s.offset_sensors, "offset_sensors", w);
  CheckNames(s.slope_sensors, "slope_sensors", w);
  if (j.contains("offset_duty")) s.offset_duty = RequireStrings(j, "offset_duty", w, 1000);
  if (j.contains("slope_duty")) s.slope_duty = RequireStrings(j, "slope_duty", w, 1000);
  CheckNames(Joined(s.offset_sensors, s.offset_duty), "offset_sensors and offset_duty", w);
  CheckNames(Joined(s.slope_sensors, s.slope_duty), "slope_sensors and slope_duty", w);
  if (s.offset_sensors.empty() && s.slope_sensors.empty())
    throw InputError(w + ": no offset or slope sensor");
  s.z_ref_mm = RequireNumberIn(j, "z_ref_mm", kAxisPositionRange, w);
  s.offset_prior = ReadPriors(j, "offset_prior_um_per_k", s.offset_sensors, w);
  s.slope_prior = ReadPriors(j, "slope_prior_um_per_1000_per_k", s.slope_sensors, w);
  s.blank_prior = RequireNumberIn(
      j, "blank_prior_um_per_1000_per_k",
      {-kMaxGreyCoefficient, kMaxGreyCoefficient, false, "um per 1000 mm per K"}, w);
  return s;
}

namespace {

DriftModel Channel(const std::string& column, const std::vector<std::string>& sensors,
                   const std::vector<std::string>& duty, const std::vector<double>& taus,
                   double intercept, const Eigen::VectorXd& b, const Eigen::VectorXd& lo,
                   const Eigen::VectorXd& hi) {
  DriftModel d;
  d.kind = taus.empty() ? ModelKind::kMlr : ModelKind::kDynamic;
  d.error_column = column;
  d.sensors = sensors;
  d.reference_C = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(sensors.size()), 20.0);
  d.extra_inputs = duty;  // as logged: the action's u = value, no reference
  d.time_constants = taus;
  for (const std::string& s : Joined(sensors, duty)) {
    d.features.push_back({s, 0.0});
    for (double t : taus) d.features.push_back({s, t});
  }
  d.feature_min = lo;
  d.feature_max = hi;
  const Eigen::Index nf = b.size();
  d.linear.coefficients.resize(nf + 1);
  d.linear.coefficients << intercept, b;
  d.linear.covariance = Eigen::MatrixXd::Zero(nf + 1, nf + 1);
  d.linear.standard_errors = Eigen::VectorXd::Zero(nf + 1);
  d.linear.xtx_inverse = d.linear.covariance;
  d.linear.vif = Eigen::VectorXd::Ones(nf);
  d.selection = "given (grey box)";
  d.Validate();
  return d;
}

}  // namespace

GreyBoxControl GreyBoxControlModels(const GreyBoxModel& m) {
  ValidateGreyBox(m);
  if (m.offset_sensors.empty() || m.slope_sensors.empty())
    throw InputError(
        "grey box: the 840D drift action needs at least one offset sensor (K0) and one slope "
        "sensor (SD43910); this model has " +
        std::to_string(m.offset_sensors.size()) + " and " + std::to_string(m.slope_sensors.size()));
  GreyBoxControl c;
  c.offset = Channel("grey_k0_um", m.offset_sensors, m.offset_duty, m.time_constants, 0.0, m.a,
                     m.offset_min, m.offset_max);
  c.slope = Channel("grey_slope_per_1000_um", m.slope_sensors, m.slope_duty, m.time_constants,
                    m.slope_intercept_um_per_1000, m.g, m.slope_min, m.slope_max);
  return c;
}

}  // namespace whirl::drift
