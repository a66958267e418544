#include "nn/model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/parallel.h"
#include "nn/selection.h"

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
  o.regularization = ParseRegularization(Require(j, "regularization", where).get<std::string>());
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
      throw InputError("model 'training_summary.ard_alpha' value " + std::to_string(g + 1) +
                       " = " + MessageNumber(a(g)) + ": must be finite, > 0 and <= " +
                       MessageNumber(kArdAlphaMax));
}

}  // namespace

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
  const json& format = Require(j, "format", "model");
  if (!format.is_string() || format.get<std::string>() != Model::kFormat)
    throw InputError("model 'format' is " + format.dump() + ", expected \"" + Model::kFormat +
                     "\"");
  const json& version = Require(j, "schema_version", "model");
  if (!version.is_number_integer() || version.get<int>() < 1 ||
      version.get<int>() > Model::kSchemaVersion)
    throw InputError("model 'schema_version' is " + version.dump() + ", this whirl reads 1 to " +
                     std::to_string(Model::kSchemaVersion));
  const int schema = version.get<int>();

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
  m.network = Network::Zeros(layer_sizes);
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
    m.network.weights[l] =
        ReadMatrix(Require(layers[l], "weights", where),
                   "layers[" + std::to_string(l) + "].weights", layer_sizes[l + 1], layer_sizes[l]);
    m.network.biases[l] =
        ReadVector(Require(layers[l], "biases", where), "layers[" + std::to_string(l) + "].biases",
                   layer_sizes[l + 1]);
  }
  m.input_scaling = ReadScaling(j, "input_scaling", layer_sizes.front());
  m.target_scaling = ReadScaling(j, "target_scaling", layer_sizes.back());
  m.inputs = ReadVariables(j, "inputs", ExpectedInputs());
  m.outputs = ReadVariables(j, "outputs", ExpectedOutputs());

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

  try {
    m.training_summary = Require(j, "training_summary", "model").get<TrainSummary>();
  } catch (const json::exception& e) {
    throw InputError(std::string("model 'training_summary': ") + e.what());
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
    throw InputError(std::string("model 'training.restart_runs': ") + e.what());
  }
  m.train_options = ReadOptions(Require(training, "options", "model 'training'"));
  m.seed = ReadSeed(Require(j, "seed", "model"), "model 'seed'");
  const json& space = Require(j, "error_space", "model");
  if (!space.is_string()) throw InputError("model 'error_space' must be a string");
  m.error_space = space.get<std::string>();

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

Eigen::MatrixXd InputMatrix(const std::vector<ProcessInputs>& inputs) {
  Eigen::MatrixXd x(ProcessInputs::kCount, inputs.size());
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    const auto a = inputs[q].ToArray();
    for (int i = 0; i < ProcessInputs::kCount; ++i) x(i, q) = a[i];
  }
  return x;
}

Eigen::MatrixXd TargetMatrix(const std::vector<Features>& targets) {
  Eigen::MatrixXd t(Features::kCount, targets.size());
  for (std::size_t q = 0; q < targets.size(); ++q) {
    const auto a = targets[q].ToArray();
    for (int k = 0; k < Features::kCount; ++k) t(k, q) = a[k];
  }
  return t;
}

std::vector<Prediction> PredictBatch(const Model& model, const std::vector<ProcessInputs>& inputs) {
  std::vector<Prediction> out(inputs.size());
  if (inputs.empty()) return out;
  const Eigen::MatrixXd x_raw = InputMatrix(inputs);
  if (!x_raw.allFinite()) throw InputError("predict: an input is NaN or infinite");
  const Eigen::MatrixXd x = model.input_scaling.Apply(x_raw);
  ForwardCache cache;
  model.network.Forward(x, &cache);
  const Eigen::MatrixXd y = model.target_scaling.Reverse(cache.output());
  Eigen::MatrixXd J;
  ErrorJacobian(model.network, cache, &J);  // rows q * S + k, = -dy/dw
  const Eigen::VectorXd half = model.target_scaling.HalfRange();
  const int S = model.network.OutputCount();
  Eigen::VectorXd Sg;
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    std::array<double, Features::kCount> mean{}, sd{}, noise{};
    for (int k = 0; k < S; ++k) {
      const auto g = J.row(static_cast<Eigen::Index>(q) * S + k).transpose();
      Sg.noalias() = model.posterior_covariance * g;
      const double var = model.output_noise_variance(k) + g.dot(Sg);
      mean[k] = y(k, q);
      sd[k] = std::sqrt(std::max(var, 0.0)) * half(k);
      noise[k] = std::sqrt(model.output_noise_variance(k)) * half(k);
    }
    Prediction& p = out[q];
    p.mean = Features::FromArray(mean);
    p.stddev = Features::FromArray(sd);
    p.noise_stddev = Features::FromArray(noise);
    for (int i = 0; i < ProcessInputs::kCount; ++i) {
      if (x_raw(i, q) < model.domain_min(i) || x_raw(i, q) > model.domain_max(i)) {
        p.outside_domain = true;
        p.outside_domain_fields.push_back(model.inputs[i].name);
      }
    }
  }
  return out;
}

OutsideDomainSummary SummarizeOutsideDomain(const Model& model,
                                            const std::vector<Prediction>& predictions) {
  OutsideDomainSummary s;
  for (const auto& v : model.inputs) s.input_names.push_back(v.name);
  s.per_input.assign(s.input_names.size(), 0);
  for (std::size_t q = 0; q < predictions.size(); ++q) {
    if (!predictions[q].outside_domain) continue;
    if (s.rows++ == 0) s.first_row = q;
    for (const auto& f : predictions[q].outside_domain_fields)
      for (std::size_t i = 0; i < s.input_names.size(); ++i)
        if (s.input_names[i] == f) ++s.per_input[i];
  }
  return s;
}

std::string OutsideDomainSummary::Describe(int total_rows, const std::string& first) const {
  std::string inputs;
  for (std::size_t i = 0; i < per_input.size(); ++i)
    if (per_input[i] > 0)
      inputs += (inputs.empty() ? "" : ", ") + input_names[i] + " in " +
                std::to_string(per_input[i]) + (per_input[i] == 1 ? " row" : " rows");
  if (total_rows == 1) return first + " lies outside the training domain in " + inputs;
  return std::to_string(rows) + " of " + std::to_string(total_rows) +
         " rows lie outside the training domain (" + inputs + "; first: " + first + ")";
}

Prediction Predict(const Model& model, const ProcessInputs& inputs) {
  return PredictBatch(model, {inputs}).front();
}

namespace {

// sigma^2: the smallest level at which +-1 predictive sigma (sqrt(sigma^2 + var_w[i])) covers
// 68.27 % of the held-out squared errors r2 (bisection; the coverage is monotone in sigma^2).
double NoiseForCoverage(const std::vector<double>& r2, const std::vector<double>& var_w) {
  constexpr double kOneSigma = 0.6827;
  auto coverage = [&](double s2) {
    int in = 0;
    for (std::size_t i = 0; i < r2.size(); ++i) in += r2[i] <= s2 + var_w[i] ? 1 : 0;
    return static_cast<double>(in) / static_cast<double>(r2.size());
  };
  double lo = 0.0, hi = *std::max_element(r2.begin(), r2.end()) + 1e-300;
  if (coverage(lo) >= kOneSigma) hi = 0.0;
  for (int it = 0; it < 200 && hi > lo; ++it) {
    const double mid = 0.5 * (lo + hi);
    (coverage(mid) >= kOneSigma ? hi : lo) = mid;
  }
  return hi;
}

// ModelTrainOptions::hidden_by_evidence: one fit per candidate size (in parallel, each on one
// thread; the choice happens after all fits, in candidate order: the same for any thread count).
Model TrainModelHiddenByEvidence(const ProcessTable& table, const ModelTrainOptions& options,
                                 const std::string& data_name) {
  const int rows = static_cast<int>(table.inputs.size());
  std::vector<Model> fits(options.hidden_candidates.size());
  ParallelFor(fits.size(), options.threads, [&](std::size_t i) {
    ModelTrainOptions one = options;
    one.hidden_candidates.clear();
    one.hidden_sizes = HiddenLayers(options.hidden_candidates[i]);
    // linear: every start reaches the same fit (to the stopping rule), so one is enough
    if (one.hidden_sizes.empty()) one.restarts = 1;
    one.noise_folds = 0;  // calibrated below, for the chosen size only
    one.threads = 1;
    fits[i] = TrainModel(table, one, data_name);
  });
  std::size_t best = 0;
  std::string tried;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    const double ev = fits[i].training_summary.log_evidence;
    tried += (tried.empty() ? "" : ", ") + std::to_string(options.hidden_candidates[i]) + ": " +
             MessageNumber(ev);
    if (ev > fits[best].training_summary.log_evidence) best = i;
  }
  Model m = std::move(fits[best]);
  const int size = options.hidden_candidates[best];
  m.hidden_selection = "hidden size " + std::to_string(size) + " of the highest log evidence (" +
                       tried + ")" + (size == 0 ? "; 0 = no hidden layer (linear)" : "");
  ModelTrainOptions chosen = options;
  chosen.hidden_candidates.clear();
  chosen.hidden_sizes = HiddenLayers(size);
  if (size == 0) chosen.restarts = 1;
  if (options.noise_folds > 0 && rows >= 4)
    CalibrateOutputNoise(table, chosen, std::min(options.noise_folds, rows), &m);
  return m;
}

// ModelTrainOptions::hidden_candidates: one tansig layer, size by k-fold CV (nn/selection.h).
Model TrainModelAutoHidden(const ProcessTable& table, const ModelTrainOptions& options,
                           const std::string& data_name, const ModelProgress& progress) {
  const int rows = static_cast<int>(table.inputs.size());
  ModelTrainOptions fixed = options;
  fixed.hidden_candidates.clear();
  if (rows < 4) {
    fixed.hidden_sizes = HiddenLayers(options.hidden_candidates.front());
    Model m = TrainModel(table, fixed, data_name, progress);
    m.hidden_selection = "hidden size " + std::to_string(options.hidden_candidates.front()) +
                         ", the first candidate: " + std::to_string(rows) +
                         " rows are too few to choose";
    return m;
  }
  if (options.hidden_by_evidence) return TrainModelHiddenByEvidence(table, options, data_name);
  SweepOptions sweep;
  sweep.folds = std::min(options.stopping_folds, rows);
  sweep.seed = options.seed;
  sweep.train = options.train;
  sweep.threads = options.threads;
  std::string tried;
  double best_cv = std::numeric_limits<double>::infinity();
  int best = options.hidden_candidates.front();
  for (int h : options.hidden_candidates) {
    sweep.hidden_min = sweep.hidden_max = h;
    const SweepRow row = HiddenSweep(table, sweep).front();
    tried += (tried.empty() ? "" : ", ") + std::to_string(h) + ": " +
             FormatSignificant(row.cv_rms_normalized, 4);
    if (row.cv_rms_normalized < best_cv) {
      best_cv = row.cv_rms_normalized;
      best = h;
    }
  }
  fixed.hidden_sizes = {best};
  Model m = TrainModel(table, fixed, data_name, progress);
  m.hidden_selection = "hidden size " + std::to_string(best) + " chosen by " +
                       std::to_string(sweep.folds) +
                       "-fold cross-validation (lowest cv_rms_normalized; " + tried + ")";
  return m;
}

}  // namespace

std::vector<int> HiddenLayers(int size) {
  return size == 0 ? std::vector<int>{} : std::vector<int>{size};
}

ModelTrainOptions DefaultTrainingOptions() {
  ModelTrainOptions o;
  o.hidden_candidates = {0, 4, 6, 8};
  o.hidden_by_evidence = true;
  o.train.change = kBrnnChange;
  return o;
}

Model TrainModel(const ProcessTable& table, const ModelTrainOptions& options,
                 const std::string& data_name, const ModelProgress& progress) {
  if (table.targets.size() != table.inputs.size())
    throw InputError(table.source + ": the training table needs the target columns " +
                     kTargetColumns[0] + " and " + kTargetColumns[1]);
  if (table.inputs.size() < 2)
    throw InputError(table.source + ": " + std::to_string(table.inputs.size()) +
                     " training rows; at least 2 are needed");
  for (std::size_t h = 0; h < options.hidden_sizes.size(); ++h)
    if (options.hidden_sizes[h] < 1)
      throw InputError("hidden size " + std::to_string(options.hidden_sizes[h]) + ": must be >= 1");
  if (!options.hidden_candidates.empty())
    return TrainModelAutoHidden(table, options, data_name, progress);
  const Eigen::MatrixXd x_raw = InputMatrix(table.inputs);
  const Eigen::MatrixXd t_raw = TargetMatrix(table.targets);
  Model m;
  m.hidden_selection =
      "fixed: " + std::to_string(options.hidden_sizes.size()) + " hidden layer(s) as given";
  m.input_scaling = MapMinMax::Fit(x_raw);
  m.target_scaling = MapMinMax::Fit(t_raw);
  TrainingData data{m.input_scaling.Apply(x_raw), m.target_scaling.Apply(t_raw), m.target_scaling};
  std::vector<int> sizes = {ProcessInputs::kCount};
  sizes.insert(sizes.end(), options.hidden_sizes.begin(), options.hidden_sizes.end());
  sizes.push_back(Features::kCount);
  if (options.train.regularization != Regularization::kBayesian)
    throw InputError("a model file needs Bayesian regularization (its Laplace uncertainty)");
  const int rows = static_cast<int>(table.inputs.size());
  TrainOptions train = options.train;
  m.stopping = "trainbr (MATLAB): run to its own stopping criteria, at most " +
               std::to_string(train.epochs) + " epochs";
  if (train.change > 0)
    m.stopping =
        "trainbr with R brnn's rule: stop when F = beta ssE + alpha ssX changed by less "
        "than " +
        FormatNumber(train.change) +
        " over the last 4 epochs, else MATLAB's "
        "criteria, at most " +
        std::to_string(train.epochs) + " epochs";
  if (options.stopping == Stopping::kCrossValidated && rows >= 4) {
    const int folds = std::min(options.stopping_folds, rows);
    train.epochs = ChooseEpochsByCrossValidation(table, options, folds);
    m.stopping = "epochs chosen by " + std::to_string(folds) +
                 "-fold cross-validation: " + std::to_string(train.epochs) + " of at most " +
                 std::to_string(options.train.epochs) +
                 " (the epoch count with the lowest summed held-out squared error, normalized)";
  }
  if (train.ard)
    m.stopping +=
        "; then the ARD stage (one alpha per input's weights, the same stopping rule "
        "and epoch limit, counted again), kept if it took a step and its log evidence "
        "is higher";
  RestartResult r = TrainBrRestarts(data, sizes, options.seed, options.restarts, train, progress,
                                    options.threads);
  m.network = std::move(r.best.network);
  m.inputs = ExpectedInputs();
  m.outputs = ExpectedOutputs();
  m.domain_min = x_raw.rowwise().minCoeff();
  m.domain_max = x_raw.rowwise().maxCoeff();
  m.training_summary = r.best.summary;
  m.seed = options.seed;
  m.init_seed = r.best.init_seed;
  m.restarts = options.restarts;
  m.restart_runs = r.runs;
  m.train_options = train;
  m.training_data = data_name;
  m.training_samples = static_cast<int>(table.inputs.size());
  m.noise_variance = r.best.summary.noise_variance;
  m.output_noise_variance = Eigen::VectorXd::Constant(Features::kCount, m.noise_variance);
  m.noise_calibration = "trainbr: one noise level 1/(2 beta) for every output";
  m.posterior_covariance = std::move(r.best.posterior_covariance);
  m.Validate();
  if (options.noise_folds > 0 && rows >= 4)
    CalibrateOutputNoise(table, options, std::min(options.noise_folds, rows), &m);
  return m;
}

std::vector<FlatOutput> FlatOutputs(const Model& model, const ProcessTable& table) {
  if (table.targets.size() != table.inputs.size() || table.inputs.empty())
    throw InputError(table.source + ": the flatness check needs the training rows with targets");
  const Eigen::MatrixXd x = model.input_scaling.Apply(InputMatrix(table.inputs));
  const Eigen::MatrixXd y = model.target_scaling.Reverse(model.network.Forward(x));
  const Eigen::MatrixXd t = TargetMatrix(table.targets);
  auto sd = [](const Eigen::RowVectorXd& v) {
    return std::sqrt((v.array() - v.mean()).square().mean());
  };
  std::vector<FlatOutput> flat;
  for (int k = 0; k < static_cast<int>(t.rows()); ++k) {
    const double target_sd = sd(t.row(k)), prediction_sd = sd(y.row(k));
    if (!(target_sd > 0)) continue;
    const double ratio = prediction_sd / target_sd;
    if (ratio < kFlatSpreadRatio) flat.push_back({k, ratio, prediction_sd, target_sd});
  }
  return flat;
}

std::string DescribeFlatOutputs(const Model& model, const std::vector<FlatOutput>& flat) {
  std::string names, ratios;
  for (std::size_t i = 0; i < flat.size(); ++i) {
    const std::string sep = i == 0 ? "" : (i + 1 == flat.size() ? " and " : ", ");
    names += sep + model.outputs.at(static_cast<std::size_t>(flat[i].output)).name;
    ratios += (i == 0 ? "" : ", ") + MessageNumber(flat[i].spread_ratio);
  }
  const auto& s = model.training_summary;
  return "the network is nearly flat in " + names + ": over the " +
         std::to_string(model.training_samples) +
         " training rows its predictions vary by less than " +
         MessageNumber(100 * kFlatSpreadRatio) + " % of the targets' spread (sd ratio " + ratios +
         "; gamma " + MessageNumber(s.gamma) + " of " + std::to_string(s.parameter_count) +
         "). " +
         (model.hidden_selection.find("highest log evidence") != std::string::npos
              ? "The evidence preferred it to every size tried, so it predicts "
              : "It predicts ") +
         "about one value for every process, with the cross-validated noise as its "
         "uncertainty. More training rows usually help (README 'Against its peers')";
}

int ChooseEpochsByCrossValidation(const ProcessTable& table, const ModelTrainOptions& options,
                                  int folds, std::vector<double>* curve) {
  const int rows = static_cast<int>(table.inputs.size());
  if (folds < 2 || rows < folds)
    throw InputError("stopping by cross-validation: " + std::to_string(folds) + " folds for " +
                     std::to_string(rows) + " rows; needs 2 <= folds <= rows");
  const int max_epochs = options.train.epochs;
  if (max_epochs < 1) return max_epochs;
  const Eigen::MatrixXd x_raw = InputMatrix(table.inputs);
  const Eigen::MatrixXd t_raw = TargetMatrix(table.targets);
  const Eigen::VectorXd half = MapMinMax::Fit(t_raw).HalfRange();
  std::vector<int> sizes = {ProcessInputs::kCount};
  sizes.insert(sizes.end(), options.hidden_sizes.begin(), options.hidden_sizes.end());
  sizes.push_back(Features::kCount);
  // fold_sse[f][e-1]: held-out squared error (normalized by the full table's half ranges) of
  // fold f's network after e epochs; a run that stops early keeps its last value.
  std::vector<std::vector<double>> fold_sse(static_cast<std::size_t>(folds));
  ParallelFor(static_cast<std::size_t>(folds), options.threads, [&](std::size_t fi) {
    std::vector<int> tr, te;
    for (int q = 0; q < rows; ++q) (q % folds == static_cast<int>(fi) ? te : tr).push_back(q);
    Eigen::MatrixXd xt(x_raw.rows(), tr.size()), tt(t_raw.rows(), tr.size());
    Eigen::MatrixXd xv(x_raw.rows(), te.size()), tv(t_raw.rows(), te.size());
    for (std::size_t c = 0; c < tr.size(); ++c) {
      xt.col(c) = x_raw.col(tr[c]);
      tt.col(c) = t_raw.col(tr[c]);
    }
    for (std::size_t c = 0; c < te.size(); ++c) {
      xv.col(c) = x_raw.col(te[c]);
      tv.col(c) = t_raw.col(te[c]);
    }
    const MapMinMax xs = MapMinMax::Fit(xt), ts = MapMinMax::Fit(tt);
    const TrainingData data{xs.Apply(xt), ts.Apply(tt), ts};
    const Eigen::MatrixXd xv_n = xs.Apply(xv);
    std::vector<double>& out = fold_sse[fi];
    out.reserve(static_cast<std::size_t>(max_epochs));
    Network net = Network::Zeros(sizes);
    InitNguyenWidrow(options.seed, &net);
    TrainOptions fold_train = options.train;
    fold_train.ard = false;  // the folds choose trainbr's epochs; the ARD stage follows them
    TrainBr(data, net, fold_train, [&](const EpochInfo& info) {
      const Eigen::MatrixXd y = ts.Reverse(info.network->Forward(xv_n));
      out.push_back(((tv - y).array().colwise() / half.array()).square().sum());
    });
    if (out.empty()) out.push_back(std::numeric_limits<double>::infinity());
    out.resize(static_cast<std::size_t>(max_epochs), out.back());
  });
  std::vector<double> total(static_cast<std::size_t>(max_epochs), 0.0);
  for (const auto& f : fold_sse)
    for (int e = 0; e < max_epochs; ++e) total[e] += f[e];
  const int best = static_cast<int>(std::min_element(total.begin(), total.end()) - total.begin());
  if (curve) *curve = total;
  return best + 1;
}

void CalibrateOutputNoise(const ProcessTable& table, const ModelTrainOptions& options, int folds,
                          Model* model) {
  const int rows = static_cast<int>(table.inputs.size());
  if (folds < 2 || rows < folds)
    throw InputError("noise calibration: " + std::to_string(folds) + " folds for " +
                     std::to_string(rows) + " rows; needs 2 <= folds <= rows");
  ModelTrainOptions fold_options = options;
  fold_options.noise_folds = 0;
  fold_options.restarts = std::min(options.restarts, 3);
  fold_options.stopping = Stopping::kTrainbrMatlab;  // the epochs the model was trained with
  fold_options.train = model->train_options;
  fold_options.threads = 1;
  const Eigen::VectorXd half = model->target_scaling.HalfRange();
  const int S = Features::kCount;
  // Per fold: (r^2, weight variance) per output and held-out row; gathered in fold order below.
  std::vector<std::vector<std::vector<std::pair<double, double>>>> per_fold(
      static_cast<std::size_t>(folds), std::vector<std::vector<std::pair<double, double>>>(S));
  ParallelFor(static_cast<std::size_t>(folds), options.threads, [&](std::size_t fi) {
    const int f = static_cast<int>(fi);
    ProcessTable train, held;
    train.source = held.source = table.source;
    for (int i = 0; i < rows; ++i) {
      ProcessTable& t = i % folds == f ? held : train;
      t.inputs.push_back(table.inputs[i]);
      t.targets.push_back(table.targets[i]);
    }
    const Model fm = TrainModel(train, fold_options, "fold");
    const std::vector<Prediction> p = PredictBatch(fm, held.inputs);
    const Eigen::VectorXd fold_half = fm.target_scaling.HalfRange();
    for (std::size_t i = 0; i < held.inputs.size(); ++i) {
      const auto mean = p[i].mean.ToArray(), sd = p[i].stddev.ToArray();
      const auto truth = held.targets[i].ToArray();
      for (int k = 0; k < S; ++k) {
        const double r = (truth[k] - mean[k]) / half(k);
        // Weight part of the fold model's variance, in the full model's normalized units.
        const double v =
            (sd[k] * sd[k] - fm.output_noise_variance(k) * fold_half(k) * fold_half(k)) /
            (half(k) * half(k));
        per_fold[fi][k].emplace_back(r * r, std::max(v, 0.0));
      }
    }
  });
  std::vector<std::vector<double>> r2(S), var_w(S);
  for (const auto& fold : per_fold)
    for (int k = 0; k < S; ++k)
      for (const auto& [a, b] : fold[k]) {
        r2[k].push_back(a);
        var_w[k].push_back(b);
      }
  model->output_noise_variance.resize(S);
  for (int k = 0; k < S; ++k) model->output_noise_variance(k) = NoiseForCoverage(r2[k], var_w[k]);
  model->noise_calibration =
      std::to_string(folds) +
      "-fold cross-validation on the training table: per output the "
      "smallest noise variance at which +-1 sigma (noise + weight variance of the fold model) "
      "covers 68.27 % of the held-out errors";
}

}  // namespace whirl::nn
