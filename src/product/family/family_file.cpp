// The JSON of a fitted family model and of a family choice (family/family.h): what the workpiece
// model file (workpiece/model.h) stores for a model that is not a network.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/json_file.h"
#include "family/family.h"

namespace whirl::family {
namespace {

using nlohmann::json;

template <typename T>
std::vector<T> Fits(const json& j, const char* key, const std::string& what) {
  const json& a = RequireKey(j, key, what);
  if (!a.is_array() || a.size() != static_cast<std::size_t>(Features::kCount))
    throw InputError(what + ": '" + key + "' must hold one fit per output (" +
                     std::to_string(Features::kCount) + ")");
  std::vector<T> out;
  for (std::size_t k = 0; k < a.size(); ++k) {
    try {
      out.push_back(a[k].get<T>());
    } catch (const InputError& e) {
      throw InputError(what + ": '" + key + "'[" + std::to_string(k) + "] (" + kTargetColumns[k] +
                       "): " + e.what());
    }
  }
  return out;
}

// Every per-output fit takes the inputs the transform uses.
template <typename T>
void CheckInputCount(const std::vector<T>& fits, const TableTransform& t, const std::string& what) {
  for (const T& f : fits)
    if (f.input_shift.size() != t.UsedInputCount())
      throw InputError(what + ": a fit has " + std::to_string(f.input_shift.size()) +
                       " inputs, the transform uses " + std::to_string(t.UsedInputCount()));
}

std::array<int, Features::kCount> Indices(const json& j, const char* key, int count,
                                          const std::string& what) {
  const json& a = RequireKey(j, key, what);
  std::array<int, Features::kCount> out{};
  if (!a.is_array() || a.size() != out.size())
    throw InputError(what + ": '" + key + "' must hold one index per output");
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (!a[k].is_number_integer() || a[k].get<int>() < 0 || a[k].get<int>() >= count)
      throw InputError(what + ": '" + key + "' entries must be whole numbers in [0, " +
                       std::to_string(count) + ")");
    out[k] = a[k].get<int>();
  }
  return out;
}

}  // namespace

void to_json(json& j, const FamilyModel& m) {
  j = {{"candidate", m.candidate.Name()},
       {"transform", m.transform},
       {"calibration", m.calibration}};
  if (m.candidate.family == Family::kLinear) j["linears"] = m.linears;
  if (m.candidate.family == Family::kGaussianProcess) j["gps"] = m.gps;
  if (m.candidate.family == Family::kNetwork) j["network"] = m.network;
}

void from_json(const json& j, FamilyModel& m) {
  const std::string what = "family model";
  const json& name = RequireKey(j, "candidate", what);
  if (!name.is_string()) throw InputError(what + ": 'candidate' must be a string");
  m.candidate = ParseCandidate(name.get<std::string>());
  m.transform = RequireKey(j, "transform", what).get<TableTransform>();
  if (!m.transform.IsIdentity() && !m.candidate.log)
    throw InputError(what + ": 'transform' (" + m.transform.Describe() +
                     ") disagrees with the candidate " + m.candidate.Name());
  const json& calibration = RequireKey(j, "calibration", what);
  if (!calibration.is_string()) throw InputError(what + ": 'calibration' must be a string");
  m.calibration = calibration.get<std::string>();
  m.linears.clear();
  m.gps.clear();
  if (m.candidate.family == Family::kLinear) {
    m.linears = Fits<LinearModel>(j, "linears", what);
    CheckInputCount(m.linears, m.transform, what);
  } else if (m.candidate.family == Family::kGaussianProcess) {
    m.gps = Fits<gp::Gp>(j, "gps", what);
    CheckInputCount(m.gps, m.transform, what);
  } else {
    m.network = RequireKey(j, "network", what).get<nn::Model>();
  }
}

void from_json(const json& j, CvRow& r) {
  const std::string what = "choice table row";
  const json& name = RequireKey(j, "candidate", what);
  if (!name.is_string()) throw InputError(what + ": 'candidate' must be a string");
  r.candidate = ParseCandidate(name.get<std::string>());
  const json& rmse = RequireKey(j, "cv_rmse", what);
  if (!rmse.is_array() || rmse.size() != static_cast<std::size_t>(Features::kCount))
    throw InputError(what + ": 'cv_rmse' must hold one value per output");
  r.cv_rmse.resize(Features::kCount);
  // Held-out RMSE in the output's units and a sum of MSE / variance: >= 0 and finite. A
  // candidate whose held-out predictions diverge (a log-linear fit extrapolated through exp on
  // few rows) legitimately reaches 1e16 and more; the table keeps it, so the bound only keeps
  // the number far from overflow.
  constexpr Range kErrorRange{0, 1e100, false, "", "a held-out error"};
  for (int k = 0; k < Features::kCount; ++k) {
    r.cv_rmse(k) = RequireFiniteValue(rmse[k], what + ": 'cv_rmse'[" + std::to_string(k) + "]");
    CheckRange(r.cv_rmse(k), kErrorRange, "cv_rmse[" + std::to_string(k) + "]", what);
  }
  r.score = RequireNumberIn(j, "score", kErrorRange, what);
  if (j.contains("fit_ms")) r.fit_ms = RequireNumber(j, "fit_ms", what);
}

void to_json(json& j, const Choice& c) {
  j = {{"describe", c.Describe()},
       {"table", c.table},
       {"chosen", c.chosen},
       {"model_of_output", c.model_of_output},
       {"models", c.models}};
  if (std::any_of(c.weights.begin(), c.weights.end(), [](const auto& w) { return !w.empty(); }))
    j["weights"] = c.weights;
  if (j.contains("weights") ||
      std::any_of(c.sd_scale.begin(), c.sd_scale.end(), [](double s) { return s != 1.0; }))
    j["sd_scale"] = c.sd_scale;
}

namespace {
// Choice::weights from "weights" (optional): per output an empty array or one weight >= 0 per
// model, summing to 1, the largest on the output's model.
void ReadWeights(const json& j, const std::string& what, Choice* c) {
  if (!j.contains("weights")) return;
  const json& w = j.at("weights");
  if (!w.is_array() || w.size() != static_cast<std::size_t>(Features::kCount))
    throw InputError(what + ": 'weights' must hold one array per output");
  for (int k = 0; k < Features::kCount; ++k) {
    const std::string at = what + ": 'weights' of " + kTargetColumns[k];
    if (!w[k].is_array()) throw InputError(at + " must be an array");
    if (w[k].empty()) continue;
    if (w[k].size() != c->models.size())
      throw InputError(at + " must hold one weight per model (" +
                       std::to_string(c->models.size()) + ")");
    double sum = 0;
    for (const json& v : w[k]) {
      if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0)
        throw InputError(at + " must be finite numbers >= 0");
      c->weights[k].push_back(v.get<double>());
      sum += v.get<double>();
    }
    if (std::abs(sum - 1.0) > 1e-9) throw InputError(at + " must sum to 1");
    const auto top = std::max_element(c->weights[k].begin(), c->weights[k].end());
    if (*top != c->weights[k][c->model_of_output[k]])
      throw InputError(at + ": the largest weight must be on the model of 'model_of_output'");
  }
}

// Choice::sd_scale (optional; files of earlier versions have none: 1), CoverageScale's range.
void ReadSdScale(const json& j, const std::string& what, Choice* c) {
  if (!j.contains("sd_scale")) return;
  const json& s = j.at("sd_scale");
  if (!s.is_array() || s.size() != static_cast<std::size_t>(Features::kCount))
    throw InputError(what + ": 'sd_scale' must hold one number per output");
  for (int k = 0; k < Features::kCount; ++k) {
    if (!s[k].is_number() || !(s[k].get<double>() >= 0.25 && s[k].get<double>() <= 4.0))
      throw InputError(what + ": 'sd_scale' of " + kTargetColumns[k] +
                       " must be a number in [0.25, 4]");
    c->sd_scale[k] = s[k].get<double>();
  }
}
}  // namespace


void from_json(const json& j, Choice& c) {
  const std::string what = "family choice";
  const json& table = RequireKey(j, "table", what);
  const json& models = RequireKey(j, "models", what);
  if (!table.is_array() || table.empty() || !models.is_array() || models.empty() ||
      models.size() > std::max<std::size_t>(Features::kCount, table.size()))
    throw InputError(what + ": 'table' must be a non-empty array and 'models' hold 1 to " +
                     std::to_string(Features::kCount) + " models (a stack: up to one per row " +
                     "of 'table')");
  c.table = table.get<std::vector<CvRow>>();
  c.models.clear();
  for (std::size_t i = 0; i < models.size(); ++i) {
    try {
      c.models.push_back(models[i].get<FamilyModel>());
    } catch (const InputError& e) {
      throw InputError(what + ": 'models'[" + std::to_string(i) + "]: " + e.what());
    }
  }
  c.chosen = Indices(j, "chosen", static_cast<int>(c.table.size()), what);
  c.model_of_output = Indices(j, "model_of_output", static_cast<int>(c.models.size()), what);
  for (int k = 0; k < Features::kCount; ++k) {
    const std::string chosen = c.table[c.chosen[k]].candidate.Name();
    const std::string used = c.models[c.model_of_output[k]].candidate.Name();
    if (chosen != used)
      throw InputError(what + ": output " + kTargetColumns[k] + " is predicted by " + used +
                       " but 'chosen' names " + chosen);
  }
  ReadWeights(j, what, &c);
  ReadSdScale(j, what, &c);
}

}  // namespace whirl::family
