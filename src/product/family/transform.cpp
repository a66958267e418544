#include "family/transform.h"

#include <cmath>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::family {
namespace {

template <std::size_t N>
Eigen::MatrixXd TransformRows(const std::array<ColumnTransform, N>& t,
                              const std::array<const char*, N>& names, const Eigen::MatrixXd& x) {
  if (x.rows() != static_cast<Eigen::Index>(N))
    throw InputError("transform: " + std::to_string(x.rows()) + " rows, expected " +
                     std::to_string(N));
  Eigen::MatrixXd z(x.rows(), x.cols());
  for (std::size_t i = 0; i < N; ++i)
    for (Eigen::Index q = 0; q < x.cols(); ++q) {
      const double v = x(static_cast<Eigen::Index>(i), q);
      if (t[i] == ColumnTransform::kLog && !(v > 0 && std::isfinite(v)))
        throw InputError(std::string(names[i]) + " = " + MessageNumber(v) + " (sample " +
                         std::to_string(q + 1) + "): a log-transformed column needs values > 0");
      z(static_cast<Eigen::Index>(i), q) = Forward(t[i], v, names[i]);
    }
  return z;
}

template <std::size_t N>
nlohmann::json Names(const std::array<ColumnTransform, N>& t) {
  nlohmann::json a = nlohmann::json::array();
  for (ColumnTransform c : t) a.push_back(ToString(c));
  return a;
}

template <std::size_t N>
void ParseNames(const nlohmann::json& j, const char* key, std::array<ColumnTransform, N>* t) {
  if (!j.contains(key) || !j.at(key).is_array() || j.at(key).size() != N)
    throw InputError(std::string("transform: '") + key + "' must be an array of " +
                     std::to_string(N) + " names");
  for (std::size_t i = 0; i < N; ++i) {
    if (!j.at(key)[i].is_string())
      throw InputError(std::string("transform: '") + key + "'[" + std::to_string(i) +
                       "] must be a string");
    (*t)[i] = ParseColumnTransform(j.at(key)[i].get<std::string>());
  }
}

}  // namespace

std::string ToString(ColumnTransform t) { return t == ColumnTransform::kLog ? "log" : "identity"; }

ColumnTransform ParseColumnTransform(const std::string& s) {
  if (s == "identity") return ColumnTransform::kIdentity;
  if (s == "log") return ColumnTransform::kLog;
  throw InputError("transform '" + s + "': must be identity or log");
}

bool TableTransform::IsIdentity() const {
  for (ColumnTransform c : inputs)
    if (c != ColumnTransform::kIdentity) return false;
  for (ColumnTransform c : outputs)
    if (c != ColumnTransform::kIdentity) return false;
  return true;
}

std::string TableTransform::Describe() const {
  std::string logs;
  int count = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (inputs[i] == ColumnTransform::kLog)
      logs += (count++ ? ", " : "") + std::string(kInputColumns[i]);
  for (std::size_t k = 0; k < outputs.size(); ++k)
    if (outputs[k] == ColumnTransform::kLog)
      logs += (count++ ? ", " : "") + std::string(kTargetColumns[k]);
  if (count == 0) return "identity";
  if (count == ProcessInputs::kCount + Features::kCount) return "log of every input and output";
  return "log of " + logs + "; identity for the others";
}

TableTransform LogWherePositive(const ProcessTable& table) {
  TableTransform t;
  auto all_positive = [](auto get, const auto& rows) {
    for (const auto& r : rows)
      if (!(get(r) > 0)) return false;
    return !rows.empty();
  };
  for (std::size_t i = 0; i < t.inputs.size(); ++i)
    if (all_positive([i](const ProcessInputs& p) { return p.ToArray()[i]; }, table.inputs))
      t.inputs[i] = ColumnTransform::kLog;
  for (std::size_t k = 0; k < t.outputs.size(); ++k)
    if (all_positive([k](const Features& f) { return f.ToArray()[k]; }, table.targets))
      t.outputs[k] = ColumnTransform::kLog;
  return t;
}

double Forward(ColumnTransform t, double x, const char* column) {
  if (t == ColumnTransform::kIdentity) return x;
  if (!(x > 0) || !std::isfinite(x))
    throw InputError(std::string(column) + " = " + MessageNumber(x) +
                     ": a log-transformed column needs a finite value > 0");
  return std::log(x);
}

double Inverse(ColumnTransform t, double z) { return t == ColumnTransform::kLog ? std::exp(z) : z; }

double InverseDerivative(ColumnTransform t, double z) {
  return t == ColumnTransform::kLog ? std::exp(z) : 1.0;
}

Eigen::MatrixXd TransformInputs(const TableTransform& t, const Eigen::MatrixXd& x) {
  return TransformRows(t.inputs, kInputColumns, x);
}

Eigen::MatrixXd TransformTargets(const TableTransform& t, const Eigen::MatrixXd& y) {
  return TransformRows(t.outputs, kTargetColumns, y);
}

MeanSd MapBack(ColumnTransform t, double mean_z, double sd_z) {
  return {Inverse(t, mean_z), std::abs(InverseDerivative(t, mean_z)) * sd_z};
}

void to_json(nlohmann::json& j, const TableTransform& t) {
  j = {{"inputs", Names(t.inputs)}, {"outputs", Names(t.outputs)}};
}

void from_json(const nlohmann::json& j, TableTransform& t) {
  if (!j.is_object()) throw InputError("transform: must be a JSON object");
  ParseNames(j, "inputs", &t.inputs);
  ParseNames(j, "outputs", &t.outputs);
}

}  // namespace whirl::family
