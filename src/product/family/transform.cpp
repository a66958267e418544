#include "family/transform.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::family {
namespace {

template <std::size_t N>
Eigen::MatrixXd TransformRows(const std::array<ColumnTransform, N>& t,
                              const std::array<const char*, N>& names, const Eigen::MatrixXd& x,
                              const bool* used = nullptr) {
  if (x.rows() != static_cast<Eigen::Index>(N))
    throw InputError("transform: " + std::to_string(x.rows()) + " rows, expected " +
                     std::to_string(N));
  Eigen::MatrixXd z = Eigen::MatrixXd::Zero(x.rows(), x.cols());
  for (std::size_t i = 0; i < N; ++i)
    for (Eigen::Index q = 0; q < x.cols() && (!used || used[i]); ++q) {
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

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The first row of `values` that rules out a log (<= 0, not finite, or below kNearZeroShare of
// the median); false if none.
bool FirstLogException(const std::vector<double>& values, LogException* e) {
  e->median = Median(values);
  for (std::size_t q = 0; q < values.size(); ++q) {
    const double v = values[q];
    if (!(v > 0) || !std::isfinite(v) || v < kNearZeroShare * e->median) {
      e->row = static_cast<int>(q);
      e->value = v;
      return true;
    }
  }
  return false;
}

}  // namespace

std::string LogException::Describe(const ProcessTable& table) const {
  const std::string name = input ? kInputColumns[column] : kTargetColumns[column];
  const std::string unit = input ? kInputUnits[column] : kTargetUnits[column];
  const std::string where =
      static_cast<std::size_t>(row) < table.line_numbers.size()
          ? "line " + std::to_string(table.line_numbers[row])
          : "row " + std::to_string(row + 1);
  const std::string why =
      value > 0 ? "below " + MessageNumber(kNearZeroShare) + " of the column's median " +
                      MessageNumber(median) + " " + unit +
                      ": on a log scale this one row would dominate the fit"
                : "a log scale needs values > 0";
  return name + " = " + MessageNumber(value) + " " + unit + " (" + table.source + " " + where +
         "): " + why;
}

std::vector<LogException> LogExceptions(const ProcessTable& table) {
  std::vector<LogException> out;
  for (int i = 0; i < ProcessInputs::kCount; ++i) {
    std::vector<double> v;
    for (const ProcessInputs& p : table.inputs) v.push_back(p.ToArray()[i]);
    LogException e;
    e.input = true;
    e.column = i;
    if (FirstLogException(v, &e)) out.push_back(e);
  }
  for (int k = 0; k < Features::kCount && table.targets.size() == table.inputs.size(); ++k) {
    std::vector<double> v;
    for (const Features& f : table.targets) v.push_back(f.ToArray()[k]);
    LogException e;
    e.column = k;
    if (FirstLogException(v, &e)) out.push_back(e);
  }
  return out;
}

namespace {

// Column `i` of `rows` (ProcessInputs or Features) has all values equal: relative spread <= 1e-12.
template <typename Row>
bool ColumnIsConstant(const std::vector<Row>& rows, int i) {
  double lo = rows.front().ToArray()[i], hi = lo;
  for (const Row& r : rows) {
    lo = std::min(lo, r.ToArray()[i]);
    hi = std::max(hi, r.ToArray()[i]);
  }
  return hi - lo <= 1e-12 * std::max({std::abs(lo), std::abs(hi), 1e-300});
}

}  // namespace

std::vector<int> LeaveOutConstantInputs(const ProcessTable& table, TableTransform* t) {
  std::vector<int> out;
  if (table.inputs.empty()) return out;
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    if (ColumnIsConstant(table.inputs, i)) {
      t->input_used[i] = false;
      out.push_back(i);
    }
  return out;
}

std::vector<int> ConstantTargets(const ProcessTable& table) {
  std::vector<int> out;
  if (table.targets.empty()) return out;
  for (int k = 0; k < Features::kCount; ++k)
    if (ColumnIsConstant(table.targets, k)) out.push_back(k);
  return out;
}

bool TableTransform::IsIdentity() const {
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (input_used[i] && inputs[i] != ColumnTransform::kIdentity) return false;
  for (ColumnTransform c : outputs)
    if (c != ColumnTransform::kIdentity) return false;
  return true;
}

int TableTransform::UsedInputCount() const {
  return static_cast<int>(std::count(input_used.begin(), input_used.end(), true));
}

std::string TableTransform::Describe() const {
  std::string logs, unused;
  int count = 0, columns = Features::kCount;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (!input_used[i]) {
      unused += (unused.empty() ? "" : ", ") + std::string(kInputColumns[i]);
      continue;
    }
    ++columns;
    if (inputs[i] == ColumnTransform::kLog)
      logs += (count++ ? ", " : "") + std::string(kInputColumns[i]);
  }
  for (std::size_t k = 0; k < outputs.size(); ++k)
    if (outputs[k] == ColumnTransform::kLog)
      logs += (count++ ? ", " : "") + std::string(kTargetColumns[k]);
  const std::string left_out = unused.empty() ? "" : "; left out (constant): " + unused;
  if (count == 0) return "identity" + left_out;
  if (count == columns)
    return (unused.empty() ? "log of every input and output" : "log of every column used") +
           left_out;
  return "log of " + logs + "; identity for the others" + left_out;
}

TableTransform LogWherePositive(const ProcessTable& table) {
  TableTransform t;
  t.inputs.fill(ColumnTransform::kLog);
  t.outputs.fill(ColumnTransform::kLog);
  for (const LogException& e : LogExceptions(table))
    (e.input ? t.inputs[e.column] : t.outputs[e.column]) = ColumnTransform::kIdentity;
  if (table.inputs.empty()) t.inputs.fill(ColumnTransform::kIdentity);
  if (table.targets.empty() || table.targets.size() != table.inputs.size())
    t.outputs.fill(ColumnTransform::kIdentity);
  LeaveOutConstantInputs(table, &t);
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
  return TransformRows(t.inputs, kInputColumns, x, t.input_used.data());
}

Eigen::MatrixXd UsedInputRows(const TableTransform& t, const Eigen::MatrixXd& z) {
  std::vector<Eigen::Index> rows;
  for (std::size_t i = 0; i < t.input_used.size(); ++i)
    if (t.input_used[i]) rows.push_back(static_cast<Eigen::Index>(i));
  return z(rows, Eigen::all);
}

Eigen::MatrixXd TransformTargets(const TableTransform& t, const Eigen::MatrixXd& y) {
  return TransformRows(t.outputs, kTargetColumns, y);
}

MeanSd MapBack(ColumnTransform t, double mean_z, double sd_z) {
  return {Inverse(t, mean_z), std::abs(InverseDerivative(t, mean_z)) * sd_z};
}

void to_json(nlohmann::json& j, const TableTransform& t) {
  j = {{"inputs", Names(t.inputs)}, {"outputs", Names(t.outputs)}};
  if (t.UsedInputCount() < ProcessInputs::kCount) j["inputs_used"] = t.input_used;
}

void from_json(const nlohmann::json& j, TableTransform& t) {
  if (!j.is_object()) throw InputError("transform: must be a JSON object");
  ParseNames(j, "inputs", &t.inputs);
  ParseNames(j, "outputs", &t.outputs);
  t.input_used.fill(true);
  if (!j.contains("inputs_used")) return;
  const nlohmann::json& u = j.at("inputs_used");
  if (!u.is_array() || u.size() != t.input_used.size())
    throw InputError("transform: 'inputs_used' must be an array of " +
                     std::to_string(t.input_used.size()) + " booleans");
  for (std::size_t i = 0; i < t.input_used.size(); ++i) {
    if (!u[i].is_boolean())
      throw InputError("transform: 'inputs_used'[" + std::to_string(i) + "] must be true or false");
    t.input_used[i] = u[i].get<bool>();
  }
  if (t.UsedInputCount() == 0) throw InputError("transform: 'inputs_used' leaves out every input");
}

}  // namespace whirl::family
