#include "drift/model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"
#include "core/parallel.h"
#include "drift/grey_box_io.h"
#include "nn/model.h"

namespace whirl::drift {
namespace {

using nlohmann::json;

json VectorJson(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

// Every read below goes through core/json_file.h, so a wrong field is named with its rule.
Eigen::VectorXd ReadVector(const json& j, const char* key, Eigen::Index size,
                           const std::string& what = "drift model") {
  const auto v = RequireNumberArray(j, key, what);
  if (size >= 0 && static_cast<Eigen::Index>(v.size()) != size)
    throw InputError(what + ": '" + key + "' has " + std::to_string(v.size()) +
                     " values, expected " + std::to_string(size));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

json MatrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(VectorJson(m.row(i).transpose()));
  return rows;
}

Eigen::MatrixXd ReadMatrix(const json& j, const char* key, Eigen::Index n,
                           const std::string& what = "drift model") {
  const json& rows = RequireArray(j, key, what);
  if (static_cast<Eigen::Index>(rows.size()) != n)
    throw InputError(what + ": '" + key + "' must be " + std::to_string(n) + "x" +
                     std::to_string(n));
  Eigen::MatrixXd m(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string row = what + ": '" + key + "' row " + std::to_string(i);
    const std::vector<double> r = RequireNumbers(rows[static_cast<std::size_t>(i)], row);
    if (static_cast<Eigen::Index>(r.size()) != n)
      throw InputError(row + " must have " + std::to_string(n) + " values");
    for (Eigen::Index k = 0; k < n; ++k) m(i, k) = r[static_cast<std::size_t>(k)];
  }
  return m;
}

bool IsLinear(ModelKind k) { return k != ModelKind::kNetwork; }

int FindColumn(const std::vector<std::string>& names, const std::string& name,
               const std::string& source, const char* kind) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  std::string have;
  for (const auto& n : names) have += (have.empty() ? "" : ", ") + n;
  throw InputError(source + ": no " + kind + " column '" + name + "' (have: " +
                   (have.empty() ? "none" : have) + ")");
}

const char* const kElapsedInput = "elapsed";

std::vector<Feature> MakeFeatures(const std::vector<std::string>& inputs,
                                  const std::vector<double>& taus,
                                  const std::vector<double>& elapsed_taus) {
  std::vector<Feature> f;
  for (const auto& in : inputs) {
    f.push_back({in, 0.0});
    for (double t : taus) f.push_back({in, t});
  }
  for (double t : elapsed_taus) f.push_back({kElapsedInput, t});
  return f;
}

std::vector<std::string> Inputs(const std::vector<std::string>& sensors,
                                const std::vector<std::string>& extras) {
  std::vector<std::string> all = sensors;
  all.insert(all.end(), extras.begin(), extras.end());
  return all;
}

// Raw inputs minus reference, then lags, for one run: the batch form of DriftEvaluator::Step.
Eigen::MatrixXd FeaturesFromInputs(const Eigen::MatrixXd& u, const std::vector<double>& t,
                                   const std::vector<double>& taus) {
  const Eigen::Index per = 1 + static_cast<Eigen::Index>(taus.size());
  Eigen::MatrixXd f(u.rows(), u.cols() * per);
  for (Eigen::Index i = 0; i < u.cols(); ++i) {
    f.col(i * per) = u.col(i);
    for (std::size_t l = 0; l < taus.size(); ++l)
      f.col(i * per + 1 + static_cast<Eigen::Index>(l)) = FirstOrderLag(u.col(i), t, taus[l]);
  }
  return f;
}

// Schema 2's error zero and elapsed-time features; a schema 1 file has neither (as-logged).
void ReadZeroAndElapsed(const json& j, bool schema1, DriftModel* m) {
  if (schema1) {
    m->zero.zero = ErrorZero::kAsLogged;
    return;
  }
  m->elapsed_time_constants = RequireNumberArray(j, "elapsed_time_constants", "drift model");
  m->zero.zero = ParseErrorZero(RequireOneOf(j, "error_zero", {"run-start", "fixed"}, "drift model"));
  if (m->zero.zero == ErrorZero::kFixed)
    m->zero.gauge_level_um = RequireNumber(j, "gauge_level_um", "drift model");
}

}  // namespace

std::string ToString(ModelKind k) {
  switch (k) {
    case ModelKind::kDynamic:
      return "dynamic";
    case ModelKind::kNetwork:
      return "network";
    case ModelKind::kMlr:
      break;
  }
  return "mlr";
}

ModelKind ParseModelKind(const std::string& text) {
  if (text == "mlr") return ModelKind::kMlr;
  if (text == "dynamic") return ModelKind::kDynamic;
  if (text == "network") return ModelKind::kNetwork;
  throw InputError("model kind '" + text + "': must be mlr, dynamic or network");
}

std::string ToString(ReferenceMode m) { return m == ReferenceMode::kModel ? "model" : "run-start"; }

ReferenceMode ParseReferenceMode(const std::string& text) {
  if (text == "run-start") return ReferenceMode::kRunStart;
  if (text == "model") return ReferenceMode::kModel;
  throw InputError("reference '" + text + "': must be run-start or model");
}

std::string Feature::Name(const std::string& time_unit) const {
  if (tau == 0) return input;
  return input + "_lag" + MessageNumber(tau) + time_unit;
}

void DriftModel::Validate() const {
  const auto nf = static_cast<Eigen::Index>(features.size());
  if (sensors.empty() && extra_inputs.empty() && elapsed_time_constants.empty())
    throw InputError("drift model has no input");
  if (reference_C.size() != static_cast<Eigen::Index>(sensors.size()))
    throw InputError("drift model 'reference_C' must have one value per sensor");
  if (nf != InputCount() * (1 + static_cast<Eigen::Index>(time_constants.size())) +
                static_cast<Eigen::Index>(elapsed_time_constants.size()))
    throw InputError(
        "drift model 'features' must be inputs x (1 + time constants) + elapsed time constants");
  if (time_unit != "min" && time_unit != "sample")
    throw InputError("drift model 'time_unit' '" + time_unit + "': must be min or sample");
  for (double t : time_constants)
    CheckRange(t, {0, kMaxTimeConstant, true, time_unit.c_str()}, "time_constants", "drift model");
  for (double t : elapsed_time_constants)
    CheckRange(t, {0, kMaxTimeConstant, true, time_unit.c_str()}, "elapsed_time_constants",
               "drift model");
  if (zero.zero == ErrorZero::kFixed && !std::isfinite(zero.gauge_level_um))
    throw InputError("drift model 'gauge_level_um' must be a finite number with error zero fixed");
  CheckRange(residual_std_um, {0, kMaxResidualStdUm, false, "um"}, "residual_std_um",
             "drift model");
  CheckRange(r_squared, {-1e6, 1, false, ""}, "r_squared", "drift model");
  if (feature_min.size() != nf || feature_max.size() != nf)
    throw InputError("drift model training ranges must have one value per feature");
  if (IsLinear(kind)) {
    if (linear.coefficients.size() != nf + 1 || linear.covariance.rows() != nf + 1)
      throw InputError("drift model coefficients must be 1 + " + std::to_string(nf));
  } else {
    network.Validate("drift model network");
    CheckRange(noise_variance, {0, 1e6, false, "(normalized)"}, "network.noise_variance_normalized",
               "drift model");
    if (network.InputCount() != nf || network.OutputCount() != 1)
      throw InputError("drift model network must have one input per feature and one output");
    if (posterior_covariance.rows() != network.ParameterCount())
      throw InputError("drift model network posterior covariance has the wrong size");
  }
}

void to_json(json& j, const DriftModel& m) {
  json features = json::array();
  for (std::size_t i = 0; i < m.features.size(); ++i)
    features.push_back({{"name", m.features[i].Name(m.time_unit)},
                        {"input", m.features[i].input},
                        {"tau", m.features[i].tau},
                        {"train_min", m.feature_min(static_cast<Eigen::Index>(i))},
                        {"train_max", m.feature_max(static_cast<Eigen::Index>(i))}});
  j = {{"format", DriftModel::kFormat},
       {"schema_version", DriftModel::kSchemaVersion},
       {"kind", ToString(m.kind)},
       {"error_column", m.error_column},
       {"error_unit", "um"},
       {"sensors", m.sensors},
       {"reference_C", VectorJson(m.reference_C)},
       {"extra_inputs", m.extra_inputs},
       {"time_unit", m.time_unit},
       {"time_constants", m.time_constants},
       {"elapsed_time_constants", m.elapsed_time_constants},
       {"error_zero", ToString(m.zero.zero)},
       {"gauge_level_um", m.zero.zero == ErrorZero::kFixed ? json(m.zero.gauge_level_um)
                                                           : json(nullptr)},
       {"features", features},
       {"residual_std_um", m.residual_std_um},
       {"r_squared", m.r_squared},
       {"training",
        {{"runs", m.training_runs},
         {"state", ToString(m.state)},
         {"samples", m.training_samples},
         {"selection", m.selection},
         {"notes", m.notes}}}};
  if (IsLinear(m.kind)) {
    j["linear"] = {{"coefficients", VectorJson(m.linear.coefficients)},
                   {"coefficient_units",
                    "b0 in um, then per feature: um/K for rises and their lags, um per the "
                    "input's unit for other inputs, um for elapsed-time features"},
                   {"standard_errors", VectorJson(m.linear.standard_errors)},
                   {"covariance", MatrixJson(m.linear.covariance)},
                   {"xtx_inverse", MatrixJson(m.linear.xtx_inverse)},
                   {"vif", VectorJson(m.linear.vif)},
                   {"samples", m.linear.samples},
                   {"degrees_of_freedom", m.linear.degrees_of_freedom}};
  } else {
    j["network"] = {{"layer_sizes", m.network.layer_sizes},
                    {"parameters", VectorJson(m.network.GetParameters())},
                    {"input_min", VectorJson(m.input_scaling.xmin)},
                    {"input_max", VectorJson(m.input_scaling.xmax)},
                    {"target_min", VectorJson(m.target_scaling.xmin)},
                    {"target_max", VectorJson(m.target_scaling.xmax)},
                    {"noise_variance_normalized", m.noise_variance},
                    {"posterior_covariance", MatrixJson(m.posterior_covariance)}};
  }
}

void from_json(const json& j, DriftModel& m) {
  if (j.is_object() && j.contains("format") && j["format"] == kGreyBoxFormat)
    throw InputError(std::string("a grey-box model ('format' '") + kGreyBoxFormat +
                     "', written by whirl drift fit-grey), not a drift model: put it on the "
                     "control with whirl drift nc --grey-model FILE");
  if (!j.is_object() || !j.contains("format") || j["format"] != DriftModel::kFormat)
    throw InputError(std::string("not a drift model (its 'format' is not '") + DriftModel::kFormat +
                     "'; write one with whirl drift fit)");
  RejectUnknownKeys(j,
                    {"format", "schema_version", "kind", "error_column", "error_unit", "sensors",
                     "reference_C", "extra_inputs", "time_unit", "time_constants", "features",
                     "residual_std_um", "r_squared", "training", "linear", "network",
                     "elapsed_time_constants", "error_zero", "gauge_level_um"},
                    "drift model");
  const bool schema1 = j.contains("schema_version") && j["schema_version"] == 1;
  RequireSchema(j, DriftModel::kFormat, schema1 ? 1 : DriftModel::kSchemaVersion, "drift model",
                "format");
  m = DriftModel{};
  const std::string w = "drift model";
  m.kind = ParseModelKind(RequireString(j, "kind", w));
  m.error_column = RequireString(j, "error_column", w);
  m.sensors = RequireStrings(j, "sensors", w);
  m.reference_C = ReadVector(j, "reference_C", static_cast<Eigen::Index>(m.sensors.size()));
  m.extra_inputs = RequireStrings(j, "extra_inputs", w);
  m.time_unit = RequireString(j, "time_unit", w);
  m.time_constants = RequireNumberArray(j, "time_constants", w);
  ReadZeroAndElapsed(j, schema1, &m);
  m.features =
      MakeFeatures(Inputs(m.sensors, m.extra_inputs), m.time_constants, m.elapsed_time_constants);
  const auto nf = static_cast<Eigen::Index>(m.features.size());
  const json& fj = RequireArray(j, "features", w);
  if (fj.size() != m.features.size())
    throw InputError("drift model 'features' must list " + std::to_string(nf) + " features");
  m.feature_min.resize(nf);
  m.feature_max.resize(nf);
  for (Eigen::Index i = 0; i < nf; ++i) {
    const json& f = fj[static_cast<std::size_t>(i)];
    const std::string wf = w + " 'features'[" + std::to_string(i) + "]";
    m.feature_min(i) = RequireNumber(f, "train_min", wf);
    m.feature_max(i) = RequireNumber(f, "train_max", wf);
  }
  m.residual_std_um = RequireNumber(j, "residual_std_um", w);
  m.r_squared = RequireNumber(j, "r_squared", w);
  const json& t = RequireObject(j, "training", w);
  const std::string wt = w + " 'training'";
  m.training_runs = RequireStrings(t, "runs", wt, 100000, 4096);
  m.state = ParseRunState(RequireString(t, "state", wt));
  m.training_samples = static_cast<int>(RequireInteger(t, "samples", 0, 1000000000, wt));
  m.selection = RequireString(t, "selection", wt, 100000);
  m.notes = RequireStrings(t, "notes", wt, 100000, 100000);
  if (IsLinear(m.kind)) {
    const json& l = RequireObject(j, "linear", w);
    const std::string wl = w + " 'linear'";
    m.linear.coefficients = ReadVector(l, "coefficients", nf + 1, wl);
    m.linear.standard_errors = ReadVector(l, "standard_errors", nf + 1, wl);
    m.linear.covariance = ReadMatrix(l, "covariance", nf + 1, wl);
    m.linear.xtx_inverse = ReadMatrix(l, "xtx_inverse", nf + 1, wl);
    m.linear.vif = ReadVector(l, "vif", nf, wl);
    m.linear.samples = static_cast<int>(RequireInteger(l, "samples", 0, 1000000000, wl));
    m.linear.degrees_of_freedom =
        static_cast<int>(RequireInteger(l, "degrees_of_freedom", 0, 1000000000, wl));
    m.linear.residual_std_um = m.residual_std_um;
    m.linear.r_squared = m.r_squared;
  } else {
    const json& n = RequireObject(j, "network", w);
    const std::string wn = w + " 'network'";
    const auto sizes = RequireIntegers(n, "layer_sizes", 1, static_cast<long long>(nn::kMaxLayerSize),
                                       wn, nn::kMaxLayers);
    m.network = nn::Network::Zeros(std::vector<int>(sizes.begin(), sizes.end()));
    m.network.SetParameters(ReadVector(n, "parameters", m.network.ParameterCount(), wn));
    m.input_scaling.xmin = ReadVector(n, "input_min", nf, wn);
    m.input_scaling.xmax = ReadVector(n, "input_max", nf, wn);
    m.target_scaling.xmin = ReadVector(n, "target_min", 1, wn);
    m.target_scaling.xmax = ReadVector(n, "target_max", 1, wn);
    m.noise_variance = RequireNumber(n, "noise_variance_normalized", wn);
    m.posterior_covariance = ReadMatrix(n, "posterior_covariance", m.network.ParameterCount(), wn);
  }
  m.Validate();
}

DriftModel ReadDriftModel(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  try {
    return j.get<DriftModel>();
  } catch (const InputError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
}

void WriteDriftModel(const std::filesystem::path& path, const DriftModel& m) {
  m.Validate();
  WriteJsonFile(path, json(m));
}

DriftEvaluator::DriftEvaluator(const DriftModel& model, const Eigen::VectorXd& reference_C)
    : model_(&model), reference_(reference_C) {
  if (reference_.size() != static_cast<Eigen::Index>(model.sensors.size()))
    throw InputError("drift evaluator: one reference temperature per sensor is needed");
  features_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.features.size()));
}

double DriftEvaluator::Step(double time, const Eigen::VectorXd& raw) {
  const DriftModel& m = *model_;
  const Eigen::Index ns = reference_.size();
  const Eigen::Index per = 1 + static_cast<Eigen::Index>(m.time_constants.size());
  for (Eigen::Index i = 0; i < m.InputCount(); ++i) {
    const double u = i < ns ? raw(i) - reference_(i) : raw(i);
    features_(i * per) = u;
    for (std::size_t l = 0; l < m.time_constants.size(); ++l) {
      double& y = features_(i * per + 1 + static_cast<Eigen::Index>(l));
      if (!started_) {
        y = u;
      } else {
        y += (1.0 - std::exp(-(time - last_time_) / m.time_constants[l])) * (u - y);
      }
    }
  }
  const Eigen::Index ne = static_cast<Eigen::Index>(m.elapsed_time_constants.size());
  for (Eigen::Index l = 0; l < ne; ++l) {
    double& y = features_(features_.size() - ne + l);
    y = started_ ? y + (1.0 - std::exp(-(time - last_time_) /
                                       m.elapsed_time_constants[static_cast<std::size_t>(l)])) *
                           (1.0 - y)
                 : 0.0;
  }
  started_ = true;
  last_time_ = time;
  if (IsLinear(m.kind))
    return m.linear.coefficients(0) + features_.dot(m.linear.coefficients.tail(features_.size()));
  const Eigen::MatrixXd x = m.input_scaling.Apply(features_);
  return m.target_scaling.Reverse(m.network.Forward(x))(0, 0);
}

double DriftEvaluator::StdDev() const {
  const DriftModel& m = *model_;
  if (IsLinear(m.kind)) {
    Eigen::VectorXd x1(features_.size() + 1);
    x1 << 1.0, features_;
    return std::sqrt(m.residual_std_um * m.residual_std_um + x1.dot(m.linear.covariance * x1));
  }
  const Eigen::VectorXd x = m.input_scaling.Apply(features_);
  const Eigen::VectorXd g = nn::OutputJacobian(m.network, x).row(0).transpose();
  const double var = m.noise_variance + g.dot(m.posterior_covariance * g);
  return std::sqrt(std::max(var, 0.0)) * m.target_scaling.HalfRange()(0);
}

double TrainedElapsed(const DriftModel& m) {
  double trained = 0;
  const std::size_t ne = m.elapsed_time_constants.size();
  if (ne == 0) return std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < ne; ++j) {
    const double x = m.feature_max(static_cast<Eigen::Index>(m.features.size() - ne + j));
    // x = 1 - exp(-T / tau); x = 1 in double: T beyond 37 tau, where the plateau is reached.
    const double t = x < 1 ? -m.elapsed_time_constants[j] * std::log1p(-std::max(x, 0.0))
                           : std::numeric_limits<double>::infinity();
    trained = std::max(trained, t);
  }
  return trained;
}

double WarmUpPlateau(const DriftModel& m) {
  if (!IsLinear(m.kind) || m.elapsed_time_constants.empty()) return 0;
  const auto ne = static_cast<Eigen::Index>(m.elapsed_time_constants.size());
  const double gains = m.linear.coefficients.tail(ne).sum();
  return m.SensorFree() && m.extra_inputs.empty() ? m.linear.coefficients(0) + gains : gains;
}

Eigen::MatrixXd RawInputs(const DriftModel& model, const Run& run) {
  Eigen::MatrixXd u(run.samples(), model.InputCount());
  Eigen::Index c = 0;
  for (const auto& s : model.sensors) u.col(c++) = run.temperature_C.col(run.SensorIndex(s));
  for (const auto& e : model.extra_inputs) u.col(c++) = run.other.col(run.OtherIndex(e));
  return u;
}

Eigen::MatrixXd ElapsedFeatures(const std::vector<double>& t, const std::vector<double>& taus) {
  Eigen::MatrixXd f(static_cast<Eigen::Index>(t.size()), static_cast<Eigen::Index>(taus.size()));
  for (std::size_t l = 0; l < taus.size(); ++l)
    for (std::size_t k = 0; k < t.size(); ++k)
      f(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(l)) =
          1.0 - std::exp(-(t[k] - t.front()) / taus[l]);
  return f;
}

Eigen::MatrixXd BuildFeatures(const Run& run, const std::vector<std::string>& sensors,
                              const std::vector<std::string>& extra_inputs,
                              const std::vector<double>& time_constants,
                              const std::vector<double>& elapsed_time_constants) {
  Eigen::MatrixXd u(run.samples(), static_cast<Eigen::Index>(sensors.size() + extra_inputs.size()));
  Eigen::Index c = 0;
  for (const auto& s : sensors) {
    const int i = run.SensorIndex(s);
    u.col(c++) = run.temperature_C.col(i).array() - run.temperature_C(0, i);
  }
  for (const auto& e : extra_inputs) u.col(c++) = run.other.col(run.OtherIndex(e));
  const Eigen::MatrixXd f = FeaturesFromInputs(u, run.time_min, time_constants);
  if (elapsed_time_constants.empty()) return f;
  Eigen::MatrixXd all(f.rows(), f.cols() + static_cast<Eigen::Index>(elapsed_time_constants.size()));
  all << f, ElapsedFeatures(run.time_min, elapsed_time_constants);
  return all;
}

RunPredictor::RunPredictor(const DriftModel& model, bool time_from_index,
                           const std::string& source, ReferenceMode reference)
    : model_(&model), time_from_index_(time_from_index), reference_(reference) {
  model.Validate();
  if (time_from_index != (model.time_unit == "sample"))
    throw InputError(source + ": " +
                     (time_from_index ? "has no recorded time" : "has a recorded time") +
                     " but the model's time unit is '" + model.time_unit +
                     "': its lag time constants would be misread");
  // The input features' training ranges; the elapsed-time features (last) have their own test:
  // time beyond the longest training run.
  input_features_ =
      static_cast<Eigen::Index>(model.features.size() - model.elapsed_time_constants.size());
  trained_ = TrainedElapsed(model);
}

double RunPredictor::Step(double t, const Eigen::VectorXd& raw) {
  const DriftModel& model = *model_;
  if (!evaluator_) {
    Eigen::VectorXd ref = model.reference_C;
    if (reference_ == ReferenceMode::kRunStart)
      ref = raw.head(static_cast<Eigen::Index>(model.sensors.size()));
    evaluator_ = std::make_unique<DriftEvaluator>(model, ref);
    first_time_ = t;
  }
  const double predicted = evaluator_->Step(t, raw);
  const Eigen::Index ni = input_features_;
  const auto f = evaluator_->features().head(ni);
  const double span = 1e-9;
  if (((f - model.feature_max.head(ni)).array() > span).any() ||
      ((model.feature_min.head(ni) - f).array() > span).any())
    ++outside_;
  beyond_ += t - first_time_ > trained_ * (1 + 1e-9);
  return predicted;
}

std::vector<std::string> RunPredictor::Warnings(const std::string& run, long long samples,
                                                bool has_measured) const {
  const DriftModel& model = *model_;
  std::vector<std::string> w;
  if (has_measured && model.zero.zero == ErrorZero::kAsLogged)
    w.push_back(model.error_column +
                ": the model file predates the error zero (schema 1): errors as "
                "logged; refit for one zero for the model and its comparisons");
  if (outside_ > 0)
    w.push_back(run + ": " + std::to_string(outside_) + " of " + std::to_string(samples) +
                " samples have an input outside the model's training range "
                "(extrapolation)");
  if (beyond_ > 0)
    w.push_back(
        run + ": " + std::to_string(beyond_) + " of " + std::to_string(samples) +
        " samples lie beyond the longest training run (" + MessageNumber(trained_) + " " +
        model.time_unit + " since its start): the elapsed-time warm-up is extrapolated there; it " +
        (model.SensorFree() && model.extra_inputs.empty()
             ? "approaches its plateau " + MessageNumber(WarmUpPlateau(model)) + " um"
             : "approaches its plateau (" + MessageNumber(WarmUpPlateau(model)) +
                   " um, the warm-up part)") +
        " and never passes it");
  if (time_from_index_)
    w.push_back(run + ": no recorded time: the sample index is the time axis");
  return w;
}

InputColumns ModelInputColumns(const DriftModel& model,
                               const std::vector<std::string>& sensor_names,
                               const std::vector<std::string>& other_names,
                               const std::string& source) {
  InputColumns c;
  for (const auto& s : model.sensors)
    c.sensors.push_back(FindColumn(sensor_names, s, source, "temperature (_C)"));
  for (const auto& e : model.extra_inputs)
    c.extras.push_back(FindColumn(other_names, e, source, "input"));
  return c;
}

RunPrediction PredictRun(const DriftModel& model, const Run& run, ReferenceMode reference) {
  RunPredictor predictor(model, run.time_from_index, run.source, reference);
  const Eigen::MatrixXd u = RawInputs(model, run);
  RunPrediction p;
  p.run = run.name;
  p.time = run.time_min;
  p.time_from_index = run.time_from_index;
  p.predicted_um.resize(run.samples());
  p.std_um.resize(run.samples());
  for (int k = 0; k < run.samples(); ++k) {
    p.predicted_um(k) = predictor.Step(run.time_min[static_cast<std::size_t>(k)], u.row(k).transpose());
    p.std_um(k) = predictor.StdDev();
  }
  p.outside_range_samples = static_cast<int>(predictor.outside_range_samples());
  p.beyond_trained_time_samples = static_cast<int>(predictor.beyond_trained_time_samples());
  const auto& names = run.error_names;
  if (std::find(names.begin(), names.end(), model.error_column) != names.end()) {
    p.has_measured = true;
    p.measured_um = ApplyErrorZero(run, model.zero).error_um.col(run.ErrorIndex(model.error_column));
  }
  p.warnings = predictor.Warnings(run.name, run.samples(), p.has_measured);
  return p;
}

}  // namespace whirl::drift
