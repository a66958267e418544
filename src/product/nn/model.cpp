// The model file (nn/model.h): validation, JSON writing and reading with every key checked.
#include "nn/model.h"

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"

namespace whirl::nn {
namespace {

using nlohmann::json;

// The field checks of core/json_file.h under this file's short names: epochs of 1e30 or a layer
// of 2e9 neurons are errors, not allocations.
const json& Require(const json& j, const std::string& key, const std::string& where) {
  return RequireKey(j, key, where);
}
double RequireFinite(const json& v, const std::string& where) {
  return RequireFiniteValue(v, where);
}
int RequireInt(const json& v, const std::string& where, double lo, double hi) {
  return static_cast<int>(RequireWholeValue(v, where, lo, hi));
}

// `path` is the key path inside the model file, e.g. "layers[0].weights"; messages quote it.
Eigen::VectorXd ReadVector(const json& v, const std::string& path, Eigen::Index expected) {
  const std::string where = "model '" + path + "'";
  if (!v.is_array()) throw InputError(where + " must be an array of numbers, got " + v.dump());
  if (expected >= 0 && static_cast<Eigen::Index>(v.size()) != expected)
    throw InputError(where + " has " + std::to_string(v.size()) + " entries, expected " +
                     std::to_string(expected));
  Eigen::VectorXd out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    out(i) = RequireFinite(v[i], "model '" + path + "[" + std::to_string(i) + "]'");
  return out;
}

Eigen::MatrixXd ReadMatrix(const json& v, const std::string& path, Eigen::Index rows,
                           Eigen::Index cols) {
  const std::string where = "model '" + path + "'";
  if (!v.is_array()) throw InputError(where + " must be an array of rows, got " + v.dump());
  if (static_cast<Eigen::Index>(v.size()) != rows)
    throw InputError(where + " has " + std::to_string(v.size()) + " rows, expected " +
                     std::to_string(rows));
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r)
    m.row(r) = ReadVector(v[r], path + "[" + std::to_string(r) + "]", cols).transpose();
  return m;
}

json VectorJson(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

json MatrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) rows.push_back(VectorJson(m.row(r).transpose()));
  return rows;
}

json ScalingJson(const MapMinMax& s) {
  return json{{"min", VectorJson(s.xmin)}, {"max", VectorJson(s.xmax)}};
}

MapMinMax ReadScaling(const json& j, const std::string& key, Eigen::Index size) {
  const json& s = Require(j, key, "model");
  RejectUnknownKeys(s, {"min", "max"}, "model '" + key + "'");
  MapMinMax m;
  m.xmin = ReadVector(Require(s, "min", "model '" + key + "'"), key + ".min", size);
  m.xmax = ReadVector(Require(s, "max", "model '" + key + "'"), key + ".max", size);
  m.Validate(("model '" + key + "'").c_str());
  return m;
}

std::vector<VariableInfo> ReadVariables(const json& j, const std::string& key,
                                        const std::vector<VariableInfo>& expected) {
  const json& v = Require(j, key, "model");
  if (!v.is_array() || v.size() != expected.size())
    throw InputError("model '" + key + "': expected an array of " +
                     std::to_string(expected.size()) + " {name, unit} objects");
  std::vector<VariableInfo> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string where = "model '" + key + "[" + std::to_string(i) + "]'";
    RejectUnknownKeys(v[i], {"name", "unit"}, where);
    const json& name = Require(v[i], "name", where);
    const json& unit = Require(v[i], "unit", where);
    if (!name.is_string() || !unit.is_string())
      throw InputError(where + ": 'name' and 'unit' must be strings");
    out.push_back({name.get<std::string>(), unit.get<std::string>()});
    if (out.back().name != expected[i].name || out.back().unit != expected[i].unit)
      throw InputError(where + " is '" + out.back().name + "' [" + out.back().unit +
                       "], expected '" + expected[i].name + "' [" + expected[i].unit + "]");
  }
  return out;
}

json OptionsJson(const TrainOptions& o) {
  json j{{"epochs", o.epochs},
         {"goal", o.goal},
         {"mu", o.mu},
         {"mu_dec", o.mu_dec},
         {"mu_inc", o.mu_inc},
         {"mu_max", o.mu_max},
         {"min_grad", o.min_grad},
         {"regularization", ToString(o.regularization)}};
  if (o.change > 0) j["change"] = o.change;  // optional key: MATLAB-trainbr files stay as they were
  if (o.ard) j["ard"] = true;                // optional key, likewise
  return j;
}

TrainOptions ReadOptions(const json& j) {
  const std::string where = "model 'training.options'";
  RejectUnknownKeys(j,
                    {"epochs", "goal", "mu", "mu_dec", "mu_inc", "mu_max", "min_grad",
                     "regularization", "change", "ard"},
                    where);
  TrainOptions o;
  o.epochs = RequireInt(Require(j, "epochs", where), where + " 'epochs'", 0, kMaxEpochs);
  o.goal = RequireFinite(Require(j, "goal", where), where + " 'goal'");
  o.mu = RequireFinite(Require(j, "mu", where), where + " 'mu'");
  o.mu_dec = RequireFinite(Require(j, "mu_dec", where), where + " 'mu_dec'");
  o.mu_inc = RequireFinite(Require(j, "mu_inc", where), where + " 'mu_inc'");
  o.mu_max = RequireFinite(Require(j, "mu_max", where), where + " 'mu_max'");
  o.min_grad = RequireFinite(Require(j, "min_grad", where), where + " 'min_grad'");
  const json& regularization = Require(j, "regularization", where);
  if (!regularization.is_string()) throw InputError(where + " 'regularization': must be a string");
  o.regularization = ParseRegularization(regularization.get<std::string>());
  if (j.contains("change")) o.change = RequireFinite(j.at("change"), where + " 'change'");
  if (j.contains("ard")) {
    if (!j.at("ard").is_boolean()) throw InputError(where + " 'ard': must be true or false");
    o.ard = j.at("ard").get<bool>();
  }
  return o;
}

std::uint64_t ReadSeed(const json& v, const std::string& where) {
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
    throw InputError(where + " must be a non-negative integer, got " + v.dump());
  return v.get<std::uint64_t>();
}

// Largest magnitudes of a network file's numbers: far above any trainbr fit of whirl's tables,
// far below the values that overflow a prediction.
constexpr double kMaxWeight = 1e6;           // weights and biases (tansig inputs)
constexpr double kMaxScalingValue = 1e7;     // input and target scalings, original units
constexpr double kMaxNoiseNormalized = 1e4;  // noise variances, normalized targets in [-1, 1]
constexpr double kMaxPosteriorCovariance = 1e12;

// InputError "model '<key>[r][c]' = <x> breaks the rule: |x| <= <bound> (<why>)" for the first
// entry of m beyond the bound, indexed as in the file ([i] for a vector).
void CheckMagnitude(const Eigen::MatrixXd& m, double bound, const std::string& key,
                    const char* why) {
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      if (std::abs(m(r, c)) <= bound) continue;
      const std::string at = m.cols() == 1 ? "[" + std::to_string(r) + "]"
                                           : "[" + std::to_string(r) + "][" + std::to_string(c) + "]";
      throw InputError("model '" + key + at + "' = " + MessageNumber(m(r, c)) +
                       " breaks the rule: |x| <= " + MessageNumber(bound) + " (" + why + ")");
    }
}

void CheckMagnitudes(const Model& m) {
  for (int l = 0; l < m.network.LayerCount(); ++l) {
    const std::string at = "layers[" + std::to_string(l) + "]";
    CheckMagnitude(m.network.weights[l], kMaxWeight, at + ".weights", "a network weight");
    CheckMagnitude(m.network.biases[l], kMaxWeight, at + ".biases", "a network bias");
  }
  for (const auto& [s, key] : {std::pair{&m.input_scaling, "input_scaling"},
                               std::pair{&m.target_scaling, "target_scaling"}}) {
    CheckMagnitude(s->xmin, kMaxScalingValue, std::string(key) + ".min", "original units");
    CheckMagnitude(s->xmax, kMaxScalingValue, std::string(key) + ".max", "original units");
  }
  if (!(m.noise_variance <= kMaxNoiseNormalized))
    throw InputError("model 'uncertainty.noise_variance_normalized' = " +
                     MessageNumber(m.noise_variance) + " breaks the rule: |x| <= " +
                     MessageNumber(kMaxNoiseNormalized) + " (normalized target units)");
  CheckMagnitude(m.output_noise_variance, kMaxNoiseNormalized,
                 "uncertainty.output_noise_variance_normalized", "normalized target units");
  CheckMagnitude(m.posterior_covariance, kMaxPosteriorCovariance,
                 "uncertainty.posterior_covariance", "normalized weight units");
}

// TrainSummary::ard_alpha: only with options.ard, one finite alpha > 0 per input and the rest.
void ValidateArdAlpha(const Model& m) {
  const Eigen::VectorXd& a = m.training_summary.ard_alpha;
  if (a.size() == 0) return;
  if (!m.train_options.ard)
    throw InputError(
        "model 'training_summary.ard_alpha' is present but 'training.options.ard' is not true");
  if (a.size() != m.network.InputCount() + 1)
    throw InputError("model 'training_summary.ard_alpha' has " + std::to_string(a.size()) +
                     " values, needs " + std::to_string(m.network.InputCount() + 1) +
                     " (one per input, then one for all other weights)");
  for (Eigen::Index g = 0; g < a.size(); ++g)
    if (!std::isfinite(a(g)) || !(a(g) > 0) || a(g) > kArdAlphaMax)
      throw InputError("model 'training_summary.ard_alpha' value " + std::to_string(g + 1) + " = " +
                       MessageNumber(a(g)) +
                       ": must be finite, > 0 and <= " + MessageNumber(kArdAlphaMax));
}

// 'format' and 'schema_version': the file's schema, 1 to Model::kSchemaVersion.
int ReadSchemaVersion(const json& j) {
  const json& format = Require(j, "format", "model");
  if (!format.is_string() || format.get<std::string>() != Model::kFormat)
    throw InputError("model 'format' is " + format.dump() + ", expected \"" + Model::kFormat +
                     "\"");
  const json& version = Require(j, "schema_version", "model");
  if (!version.is_number_integer() || version.get<int>() < 1 ||
      version.get<int>() > Model::kSchemaVersion)
    throw InputError("model 'schema_version' is " + version.dump() + ", this whirl reads 1 to " +
                     std::to_string(Model::kSchemaVersion));
  return version.get<int>();
}

// 'layer_sizes', each within the limits of a model file (kMaxLayers, kMaxLayerSize,
// kMaxParameters), checked before anything is allocated.
std::vector<int> ReadLayerSizes(const json& j) {
  const json& sizes = Require(j, "layer_sizes", "model");
  if (!sizes.is_array() || sizes.size() < 2)
    throw InputError("model 'layer_sizes' must be an array of at least 2 sizes, got " +
                     sizes.dump());
  std::vector<int> layer_sizes;
  if (sizes.size() > kMaxLayers)
    throw InputError("model 'layer_sizes' has " + std::to_string(sizes.size()) +
                     " entries; the limit is " + std::to_string(kMaxLayers));
  double parameters = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    layer_sizes.push_back(
        RequireInt(sizes[i], "model 'layer_sizes[" + std::to_string(i) + "]'", 1, kMaxLayerSize));
    if (i > 0) parameters += (layer_sizes[i - 1] + 1.0) * layer_sizes[i];
  }
  if (parameters > kMaxParameters)
    throw InputError("model 'layer_sizes' " + sizes.dump() + " give " + FormatNumber(parameters) +
                     " weights and biases; the limit is " + FormatNumber(kMaxParameters));
  return layer_sizes;
}

// 'layers': the weights and biases of every layer of `layer_sizes`, tansig layers then purelin.
Network ReadNetwork(const json& j, const std::vector<int>& layer_sizes) {
  Network network = Network::Zeros(layer_sizes);
  const json& layers = Require(j, "layers", "model");
  if (!layers.is_array() || layers.size() + 1 != layer_sizes.size())
    throw InputError("model 'layers' must be an array of " +
                     std::to_string(layer_sizes.size() - 1) +
                     " layers (one fewer than layer_sizes)");
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const std::string prefix = "model 'layers[" + std::to_string(l) + "]";
    const std::string where = prefix + "'";
    RejectUnknownKeys(layers[l], {"weights", "biases", "transfer"}, where);
    const std::string transfer = l + 1 < layers.size() ? "tansig" : "purelin";
    const json& t = Require(layers[l], "transfer", where);
    if (!t.is_string() || t.get<std::string>() != transfer)
      throw InputError(prefix + ".transfer' is " + t.dump() + ", expected \"" + transfer + "\"");
    network.weights[l] =
        ReadMatrix(Require(layers[l], "weights", where),
                   "layers[" + std::to_string(l) + "].weights", layer_sizes[l + 1], layer_sizes[l]);
    network.biases[l] = ReadVector(Require(layers[l], "biases", where),
                                   "layers[" + std::to_string(l) + "].biases", layer_sizes[l + 1]);
  }
  return network;
}

// 'training_domain': min and max of every input of m.inputs, by name.
void ReadTrainingDomain(const json& j, Model& m) {
  const json& domain = Require(j, "training_domain", "model");
  if (!domain.is_object() || domain.size() != m.inputs.size())
    throw InputError("model 'training_domain' must have one {min, max} per input (" +
                     std::to_string(m.inputs.size()) + ")");
  m.domain_min.resize(m.inputs.size());
  m.domain_max.resize(m.inputs.size());
  for (std::size_t i = 0; i < m.inputs.size(); ++i) {
    const std::string where = "model 'training_domain." + m.inputs[i].name + "'";
    const json& d = Require(domain, m.inputs[i].name, "model 'training_domain'");
    RejectUnknownKeys(d, {"min", "max"}, where);
    m.domain_min(i) = RequireFinite(Require(d, "min", where), where + ".min");
    m.domain_max(i) = RequireFinite(Require(d, "max", where), where + ".max");
  }
}

// 'training_summary' and 'training': the chosen restart's summary, provenance, restarts and the
// trainbr options.
void ReadTraining(const json& j, Model& m) {
  try {
    m.training_summary = Require(j, "training_summary", "model").get<TrainSummary>();
  } catch (const json::exception& e) {
    throw InputError(std::string("model 'training_summary': ") + LibraryRule(e));
  }
  const json& training = Require(j, "training", "model");
  RejectUnknownKeys(training,
                    {"data", "samples", "restarts", "init_seed", "restart_runs", "stopping",
                     "hidden_selection", "options"},
                    "model 'training'");
  if (training.contains("stopping")) {
    const json& st = training.at("stopping");
    if (!st.is_string()) throw InputError("model 'training.stopping' must be a string");
    m.stopping = st.get<std::string>();
  }
  if (training.contains("hidden_selection")) {
    const json& hs = training.at("hidden_selection");
    if (!hs.is_string()) throw InputError("model 'training.hidden_selection' must be a string");
    m.hidden_selection = hs.get<std::string>();
  }
  const json& data = Require(training, "data", "model 'training'");
  if (!data.is_string()) throw InputError("model 'training.data' must be a string");
  m.training_data = data.get<std::string>();
  m.training_samples = RequireInt(Require(training, "samples", "model 'training'"),
                                  "model 'training.samples'", 0, 1e9);
  m.restarts = RequireInt(Require(training, "restarts", "model 'training'"),
                          "model 'training.restarts'", 0, 1e6);
  m.init_seed =
      ReadSeed(Require(training, "init_seed", "model 'training'"), "model 'training.init_seed'");
  try {
    m.restart_runs =
        Require(training, "restart_runs", "model 'training'").get<std::vector<RestartRecord>>();
  } catch (const json::exception& e) {
    throw InputError(std::string("model 'training.restart_runs': ") + LibraryRule(e) +
                     " (a list of {seed, epochs, gamma, sse_normalized, termination})");
  }
  m.train_options = ReadOptions(Require(training, "options", "model 'training'"));
}

// 'uncertainty': the noise levels (schema 1: trainbr's one level for both outputs; from schema 2:
// one calibrated level per output) and the posterior covariance of the weights.
void ReadUncertainty(const json& j, int schema, Model& m) {
  const json& u = Require(j, "uncertainty", "model");
  if (schema == 1)
    RejectUnknownKeys(u, {"method", "noise_variance_normalized", "posterior_covariance"},
                      "model 'uncertainty'");
  else
    RejectUnknownKeys(u,
                      {"method", "noise_variance_normalized", "output_noise_variance_normalized",
                       "noise_calibration", "posterior_covariance"},
                      "model 'uncertainty'");
  const json& method = Require(u, "method", "model 'uncertainty'");
  if (!method.is_string() || method.get<std::string>() != "laplace")
    throw InputError("model 'uncertainty.method' is " + method.dump() + ", expected \"laplace\"");
  m.noise_variance = RequireFinite(Require(u, "noise_variance_normalized", "model 'uncertainty'"),
                                   "model 'uncertainty.noise_variance_normalized'");
  const int S = m.network.OutputCount();
  if (schema == 1) {
    m.output_noise_variance = Eigen::VectorXd::Constant(S, m.noise_variance);
    m.noise_calibration = "schema 1 file: trainbr's one noise level for every output";
  } else {
    const json& v = Require(u, "output_noise_variance_normalized", "model 'uncertainty'");
    if (!v.is_array() || static_cast<int>(v.size()) != S)
      throw InputError("model 'uncertainty.output_noise_variance_normalized' must be an array of " +
                       std::to_string(S) + " numbers, got " + v.dump());
    m.output_noise_variance.resize(S);
    for (int k = 0; k < S; ++k)
      m.output_noise_variance(k) = RequireFinite(
          v[k], "model 'uncertainty.output_noise_variance_normalized[" + std::to_string(k) + "]'");
    const json& c = Require(u, "noise_calibration", "model 'uncertainty'");
    if (!c.is_string()) throw InputError("model 'uncertainty.noise_calibration' must be a string");
    m.noise_calibration = c.get<std::string>();
  }
  const int N = m.network.ParameterCount();
  m.posterior_covariance = ReadMatrix(Require(u, "posterior_covariance", "model 'uncertainty'"),
                                      "uncertainty.posterior_covariance", N, N);
}

}  // namespace

std::vector<VariableInfo> ExpectedInputs() {
  std::vector<VariableInfo> v;
  for (int i = 0; i < ProcessInputs::kCount; ++i) v.push_back({kInputColumns[i], kInputUnits[i]});
  return v;
}

std::vector<VariableInfo> ExpectedOutputs() {
  std::vector<VariableInfo> v;
  for (int k = 0; k < Features::kCount; ++k) v.push_back({kTargetColumns[k], kTargetUnits[k]});
  return v;
}

void Model::Validate() const {
  network.Validate("model 'layers'");
  if (network.InputCount() != ProcessInputs::kCount)
    throw InputError("model 'layer_sizes': " + std::to_string(network.InputCount()) +
                     " inputs, expected " + std::to_string(ProcessInputs::kCount));
  if (network.OutputCount() != Features::kCount)
    throw InputError("model 'layer_sizes': " + std::to_string(network.OutputCount()) +
                     " outputs, expected " + std::to_string(Features::kCount));
  input_scaling.Validate("model 'input_scaling'");
  target_scaling.Validate("model 'target_scaling'");
  if (input_scaling.size() != network.InputCount())
    throw InputError("model 'input_scaling' has " + std::to_string(input_scaling.size()) +
                     " entries, the network " + std::to_string(network.InputCount()) + " inputs");
  if (target_scaling.size() != network.OutputCount())
    throw InputError("model 'target_scaling' has " + std::to_string(target_scaling.size()) +
                     " entries, the network " + std::to_string(network.OutputCount()) + " outputs");
  if (domain_min.size() != network.InputCount() || domain_max.size() != network.InputCount())
    throw InputError("model 'training_domain': needs min and max of every input");
  for (int i = 0; i < network.InputCount(); ++i)
    if (!std::isfinite(domain_min(i)) || !std::isfinite(domain_max(i)) ||
        domain_min(i) > domain_max(i))
      throw InputError("model 'training_domain." + std::string(kInputColumns[i]) +
                       "': min and max must be finite with min <= max");
  if (error_space != "normalized")
    throw InputError("model 'error_space' is '" + error_space +
                     "', this version only knows 'normalized'");
  if (!(noise_variance >= 0) || !std::isfinite(noise_variance))
    throw InputError("model 'uncertainty.noise_variance_normalized' must be finite and >= 0");
  if (output_noise_variance.size() != network.OutputCount() || !output_noise_variance.allFinite() ||
      output_noise_variance.minCoeff() < 0)
    throw InputError(
        "model 'uncertainty.output_noise_variance_normalized' needs one finite value "
        ">= 0 per output (" +
        std::to_string(network.OutputCount()) + ")");
  const int N = network.ParameterCount();
  if (posterior_covariance.rows() != N || posterior_covariance.cols() != N)
    throw InputError("model 'uncertainty.posterior_covariance' must be " + std::to_string(N) + "x" +
                     std::to_string(N) + " (N of layer_sizes)");
  if (!posterior_covariance.allFinite())
    throw InputError("model 'uncertainty.posterior_covariance' is not finite");
  for (int i = 0; i < N; ++i) {
    if (!(posterior_covariance(i, i) >= 0))
      throw InputError("model 'uncertainty.posterior_covariance' has a negative diagonal entry " +
                       std::to_string(i));
    for (int k = 0; k < i; ++k)
      if (posterior_covariance(i, k) != posterior_covariance(k, i))
        throw InputError("model 'uncertainty.posterior_covariance' is not symmetric at (" +
                         std::to_string(i) + ", " + std::to_string(k) + ")");
  }
  CheckMagnitudes(*this);
  if (training_summary.parameter_count != N)
    throw InputError("model 'training_summary.parameter_count' = " +
                     std::to_string(training_summary.parameter_count) + ", layer_sizes give " +
                     std::to_string(N));
  ValidateArdAlpha(*this);
}

void to_json(nlohmann::json& j, const Model& m) {
  json layers = json::array();
  for (int l = 0; l < m.network.LayerCount(); ++l)
    layers.push_back(json{{"weights", MatrixJson(m.network.weights[l])},
                          {"biases", VectorJson(m.network.biases[l])},
                          {"transfer", l + 1 < m.network.LayerCount() ? "tansig" : "purelin"}});
  json inputs = json::array(), outputs = json::array(), domain = json::object();
  for (std::size_t i = 0; i < m.inputs.size(); ++i) {
    inputs.push_back(json{{"name", m.inputs[i].name}, {"unit", m.inputs[i].unit}});
    domain[m.inputs[i].name] = json{{"min", m.domain_min(i)}, {"max", m.domain_max(i)}};
  }
  for (const auto& o : m.outputs) outputs.push_back(json{{"name", o.name}, {"unit", o.unit}});
  j = json{{"format", Model::kFormat},
           {"schema_version", Model::kSchemaVersion},
           {"layer_sizes", m.network.layer_sizes},
           {"layers", layers},
           {"input_scaling", ScalingJson(m.input_scaling)},
           {"target_scaling", ScalingJson(m.target_scaling)},
           {"inputs", inputs},
           {"outputs", outputs},
           {"training_domain", domain},
           {"training_summary", m.training_summary},
           {"training", json{{"data", m.training_data},
                             {"samples", m.training_samples},
                             {"restarts", m.restarts},
                             {"init_seed", m.init_seed},
                             {"restart_runs", m.restart_runs},
                             {"stopping", m.stopping},
                             {"hidden_selection", m.hidden_selection},
                             {"options", OptionsJson(m.train_options)}}},
           {"seed", m.seed},
           {"error_space", m.error_space},
           {"uncertainty",
            json{{"method", "laplace"},
                 {"noise_variance_normalized", m.noise_variance},
                 {"output_noise_variance_normalized", VectorJson(m.output_noise_variance)},
                 {"noise_calibration", m.noise_calibration},
                 {"posterior_covariance", MatrixJson(m.posterior_covariance)}}}};
}

void from_json(const nlohmann::json& j, Model& m) {
  RejectUnknownKeys(j,
                    {"format", "schema_version", "layer_sizes", "layers", "input_scaling",
                     "target_scaling", "inputs", "outputs", "training_domain", "training_summary",
                     "training", "seed", "error_space", "uncertainty"},
                    "model");
  const int schema = ReadSchemaVersion(j);
  const std::vector<int> layer_sizes = ReadLayerSizes(j);
  m.network = ReadNetwork(j, layer_sizes);
  m.input_scaling = ReadScaling(j, "input_scaling", layer_sizes.front());
  m.target_scaling = ReadScaling(j, "target_scaling", layer_sizes.back());
  m.inputs = ReadVariables(j, "inputs", ExpectedInputs());
  m.outputs = ReadVariables(j, "outputs", ExpectedOutputs());
  ReadTrainingDomain(j, m);
  ReadTraining(j, m);
  m.seed = ReadSeed(Require(j, "seed", "model"), "model 'seed'");
  const json& space = Require(j, "error_space", "model");
  if (!space.is_string()) throw InputError("model 'error_space' must be a string");
  m.error_space = space.get<std::string>();
  ReadUncertainty(j, schema, m);
  m.Validate();
}

Model LoadModel(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  try {
    return j.get<Model>();
  } catch (const InputError& e) {
    throw InputError("model file '" + path.string() + "': " + e.what());
  } catch (const json::exception& e) {
    throw InputError("model file '" + path.string() + "': " + e.what());
  }
}

void SaveModel(const std::filesystem::path& path, const Model& model) {
  model.Validate();
  WriteJsonFile(path, json(model));
}

}  // namespace whirl::nn
