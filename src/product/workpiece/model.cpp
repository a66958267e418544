#include "workpiece/model.h"

#include <algorithm>
#include <array>
#include <utility>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::workpiece {
namespace {

using nlohmann::json;

std::vector<double> ToStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

json Variables(const std::vector<nn::VariableInfo>& vars) {
  json a = json::array();
  for (const auto& v : vars) a.push_back({{"name", v.name}, {"unit", v.unit}});
  return a;
}

// "inputs"/"outputs" must list exactly `expected` (names and units, in order).
void CheckVariables(const json& j, const char* key, const std::vector<nn::VariableInfo>& expected) {
  if (!j.contains(key) || j.at(key) != Variables(expected))
    throw InputError(std::string("'") + key + "' must be " + Variables(expected).dump());
}

Eigen::VectorXd DomainVector(const json& domain, const char* key) {
  if (!domain.is_object() || !domain.contains(key) || !domain.at(key).is_array() ||
      domain.at(key).size() != static_cast<std::size_t>(ProcessInputs::kCount))
    throw InputError(std::string("'domain.") + key + "' must hold one number per input (" +
                     std::to_string(ProcessInputs::kCount) + ")");
  Eigen::VectorXd v(ProcessInputs::kCount);
  for (int i = 0; i < ProcessInputs::kCount; ++i) {
    const json& e = domain.at(key)[i];
    if (!e.is_number() || !std::isfinite(e.get<double>()))
      throw InputError(std::string("'domain.") + key + "' must hold finite numbers");
    v(i) = e.get<double>();
  }
  return v;
}

json FamilyJson(const WorkpieceModel& m) {
  return {{"format", WorkpieceModel::kFormat},
          {"schema_version", WorkpieceModel::kSchemaVersion},
          {"kind", "family"},
          {"describe", m.Describe()},
          {"inputs", Variables(nn::ExpectedInputs())},
          {"outputs", Variables(nn::ExpectedOutputs())},
          {"domain", {{"min", ToStd(m.domain_min)}, {"max", ToStd(m.domain_max)}}},
          {"training", {{"data", m.training_data}, {"samples", m.training_samples}}},
          {"choice", m.choice}};
}

WorkpieceModel FamilyFromJson(const json& j) {
  RejectUnknownKeys(j,
                    {"format", "schema_version", "kind", "describe", "inputs", "outputs", "domain",
                     "training", "choice"},
                    "workpiece model");
  RequireInteger(j, "schema_version", WorkpieceModel::kSchemaVersion,
                 WorkpieceModel::kSchemaVersion, "workpiece model");
  RequireOneOf(j, "kind", {"family"}, "workpiece model");
  CheckVariables(j, "inputs", nn::ExpectedInputs());
  CheckVariables(j, "outputs", nn::ExpectedOutputs());
  WorkpieceModel m;
  m.kind = WorkpieceModel::Kind::kFamily;
  const json& domain = RequireKey(j, "domain", "workpiece model");
  m.domain_min = DomainVector(domain, "min");
  m.domain_max = DomainVector(domain, "max");
  if (!(m.domain_min.array() <= m.domain_max.array()).all())
    throw InputError("'domain.min' must not exceed 'domain.max'");
  for (const auto& [v, key] : {std::pair{&m.domain_min, "domain.min"},
                               std::pair{&m.domain_max, "domain.max"}}) {
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = (*v)(i);
    CheckProcessInputs(ProcessInputs::FromArray(a), std::string("'") + key + "'");
  }
  const json& training = RequireObject(j, "training", "workpiece model");
  m.training_data = RequireString(training, "data", "workpiece model 'training'");
  m.training_samples = static_cast<int>(
      RequireInteger(training, "samples", 4, 100000000, "workpiece model 'training'"));
  m.choice = RequireKey(j, "choice", "workpiece model").get<family::Choice>();
  return m;
}

// Largest |mean| and sd a model may predict inside its training domain: 1000 times the output's
// physical limit (core/limits.h).
constexpr double kPredictionBound[Features::kCount] = {1e3 * kMaxElongationUm, 1e3 * kMaxSettleTimeS};

// The corners and the centre of the training domain (33 processes).
std::vector<ProcessInputs> DomainProbe(const WorkpieceModel& m) {
  std::vector<ProcessInputs> probe;
  for (int corner = 0; corner <= (1 << ProcessInputs::kCount); ++corner) {
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i)
      a[i] = corner == (1 << ProcessInputs::kCount)
                 ? 0.5 * (m.domain_min(i) + m.domain_max(i))
                 : ((corner >> i) & 1 ? m.domain_max(i) : m.domain_min(i));
    probe.push_back(ProcessInputs::FromArray(a));
  }
  return probe;
}

// InputError unless every mean and sd of `p` (one per process of DomainProbe) is finite, within
// kPredictionBound and the sd >= 0; `what` names the model.
void CheckProbe(const std::vector<Features>& mean, const std::vector<Features>& sd,
                const std::string& what) {
  for (std::size_t q = 0; q < mean.size(); ++q)
    for (int k = 0; k < Features::kCount; ++k) {
      const double m = mean[q].ToArray()[k], s = sd[q].ToArray()[k];
      if (std::abs(m) <= kPredictionBound[k] && s >= 0 && s <= kPredictionBound[k]) continue;
      throw InputError(what + " predicts " + kTargetColumns[k] + " = " + MessageNumber(m) +
                       " +- " + MessageNumber(s) + " " + kTargetUnits[k] +
                       " at the training domain's " +
                       (q + 1 == mean.size() ? std::string("centre")
                                             : "corner " + std::to_string(q + 1)) +
                       "; a valid model predicts finite values within +-" +
                       MessageNumber(kPredictionBound[k]) + " " + kTargetUnits[k] +
                       " (1000 times the output's limit) with an sd >= 0 there");
    }
}

// The predictions of a loaded model at DomainProbe, model by model: numbers that pass every field
// rule of the file can still combine into nonsense.
void CheckDomainPredictions(const WorkpieceModel& m) {
  const std::vector<ProcessInputs> probe = DomainProbe(m);
  std::vector<Features> mean, sd;
  if (m.IsNetwork()) {
    for (const nn::Prediction& p : nn::PredictBatch(m.network, probe)) {
      mean.push_back(p.mean);
      sd.push_back(p.stddev);
    }
    return CheckProbe(mean, sd, "the network");
  }
  for (std::size_t j = 0; j < m.choice.models.size(); ++j) {
    mean.clear();
    sd.clear();
    for (const family::FamilyPrediction& p : family::PredictFamily(m.choice.models[j], probe)) {
      mean.push_back(p.mean);
      sd.push_back(p.stddev);
    }
    CheckProbe(mean, sd, "'choice.models'[" + std::to_string(j) + "] (" +
                             m.choice.models[j].candidate.Name() + ")");
  }
}

// InputError unless every mean and sd of `p` is finite (a damaged file or an overflow).
void CheckFinite(const std::vector<Prediction>& p) {
  for (std::size_t q = 0; q < p.size(); ++q)
    for (int k = 0; k < Features::kCount; ++k)
      if (!std::isfinite(p[q].mean.ToArray()[k]) || !std::isfinite(p[q].stddev.ToArray()[k]))
        throw InputError("the model predicts " + std::string(kTargetColumns[k]) + " = " +
                         MessageNumber(p[q].mean.ToArray()[k]) + " +- " +
                         MessageNumber(p[q].stddev.ToArray()[k]) + " for process " +
                         std::to_string(q + 1) + ": not a finite value (a damaged model file?)");
}

}  // namespace

std::string WorkpieceModel::Describe() const {
  if (kind == Kind::kFamily) return choice.Describe();
  std::string sizes;
  for (int n : network.network.layer_sizes)
    sizes += (sizes.empty() ? "" : "-") + std::to_string(n);
  return "network " + sizes;
}

namespace {

std::string FamilyWords(const family::Candidate& c) {
  switch (c.family) {
    case family::Family::kLinear:
      return c.log ? "power law" : "linear";
    case family::Family::kNetwork:
      return "network";
    case family::Family::kGaussianProcess:
      return "Gaussian process";
  }
  return c.Name();
}

}  // namespace

std::string WorkpieceModel::FamilyLabel() const {
  if (kind == Kind::kNetwork) return "network";
  std::array<std::string, Features::kCount> words;
  for (std::size_t k = 0; k < words.size(); ++k) {
    const auto m = static_cast<std::size_t>(choice.model_of_output[k]);
    if (!choice.weights[k].empty())
      words[k] = "stack";
    else if (m < choice.models.size())
      words[k] = FamilyWords(choice.models[m].candidate);
    else
      words[k] = FamilyWords(choice.table.at(static_cast<std::size_t>(choice.chosen[k])).candidate);
  }
  return words[0] == words[1] ? words[0] : words[0] + " / " + words[1];
}

WorkpieceModel FromNetwork(nn::Model network) {
  WorkpieceModel m;
  m.kind = WorkpieceModel::Kind::kNetwork;
  m.domain_min = network.domain_min;
  m.domain_max = network.domain_max;
  m.training_data = network.training_data;
  m.training_samples = network.training_samples;
  m.network = std::move(network);
  return m;
}

WorkpieceModel FromChoice(family::Choice choice, const ProcessTable& table,
                          const std::string& data_name) {
  if (table.inputs.empty()) throw InputError(data_name + ": no training rows");
  WorkpieceModel m;
  m.kind = WorkpieceModel::Kind::kFamily;
  m.choice = std::move(choice);
  const Eigen::MatrixXd x = nn::InputMatrix(table.inputs);
  m.domain_min = x.rowwise().minCoeff();
  m.domain_max = x.rowwise().maxCoeff();
  m.training_data = data_name;
  m.training_samples = static_cast<int>(table.inputs.size());
  return m;
}

std::vector<Prediction> PredictBatch(const WorkpieceModel& model,
                                     const std::vector<ProcessInputs>& inputs) {
  if (model.IsNetwork()) {
    std::vector<Prediction> out = nn::PredictBatch(model.network, inputs);
    CheckFinite(out);
    return out;
  }
  const Eigen::MatrixXd x = nn::InputMatrix(inputs);
  if (!x.allFinite()) throw InputError("predict: an input is NaN or infinite");
  const std::vector<family::FamilyPrediction> f = family::PredictChoice(model.choice, inputs);
  std::vector<Prediction> out(inputs.size());
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    out[q].mean = f[q].mean;
    out[q].stddev = f[q].stddev;
    for (int i = 0; i < ProcessInputs::kCount; ++i)
      if (x(i, q) < model.domain_min(i) || x(i, q) > model.domain_max(i)) {
        out[q].outside_domain = true;
        out[q].outside_domain_fields.push_back(kInputColumns[i]);
      }
  }
  CheckFinite(out);
  return out;
}

Prediction Predict(const WorkpieceModel& model, const ProcessInputs& inputs) {
  return PredictBatch(model, {inputs}).front();
}

nn::OutsideDomainSummary SummarizeOutsideDomain(const std::vector<Prediction>& predictions) {
  nn::OutsideDomainSummary s;
  s.input_names.assign(kInputColumns.begin(), kInputColumns.end());
  s.per_input.assign(s.input_names.size(), 0);
  for (std::size_t q = 0; q < predictions.size(); ++q) {
    if (!predictions[q].outside_domain) continue;
    if (s.rows++ == 0) s.first_row = q;
    for (const std::string& f : predictions[q].outside_domain_fields) {
      const auto it = std::find(s.input_names.begin(), s.input_names.end(), f);
      if (it != s.input_names.end()) ++s.per_input[it - s.input_names.begin()];
    }
  }
  return s;
}

WorkpieceModel LoadWorkpieceModel(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  // Another whirl file (a drift model, a surface, a profile) is named as what it is.
  for (const char* key : {"format", "schema"})
    if (j.is_object() && j.contains(key) && j.at(key).is_string() &&
        j.at(key) != WorkpieceModel::kFormat && j.at(key) != nn::Model::kFormat)
      throw InputError("model file '" + path.string() + "' is a " + DumpJson(j.at(key), -1) +
                       " file, not a workpiece model (whirl train writes one)");
  try {
    const bool family =
        j.is_object() && j.contains("format") && j.at("format") == WorkpieceModel::kFormat;
    // A network file: nn::LoadModel names the file and the key on errors.
    const WorkpieceModel m = family ? FamilyFromJson(j) : FromNetwork(nn::LoadModel(path));
    CheckDomainPredictions(m);
    return m;
  } catch (const InputError& e) {
    const std::string prefix = "model file '" + path.string() + "': ";
    const std::string what = e.what();
    throw InputError(what.rfind(prefix, 0) == 0 ? what : prefix + what);
  } catch (const json::exception& e) {
    throw InputError("model file '" + path.string() + "': " + LibraryRule(e));
  }
}

void SaveWorkpieceModel(const std::filesystem::path& path, const WorkpieceModel& model) {
  try {  // the rules a reader applies, so that every file written loads
    CheckDomainPredictions(model);
    if (!model.IsNetwork()) FamilyFromJson(FamilyJson(model));
  } catch (const InputError& e) {
    throw InputError("model file '" + path.string() + "' not written: " + e.what());
  }
  if (model.IsNetwork()) {
    nn::SaveModel(path, model.network);
    return;
  }
  WriteJsonFile(path, FamilyJson(model));
}

nn::Model LoadNetworkModel(const std::filesystem::path& path, const std::string& command) {
  WorkpieceModel m = LoadWorkpieceModel(path);
  if (!m.IsNetwork())
    throw InputError("model file '" + path.string() + "': " + command +
                     " needs a network model; this file holds " + m.Describe() +
                     ", which is not a network (train one with 'whirl train --family network')");
  return std::move(m.network);
}

FamilyFlag ParseFamilyFlag(const std::string& s) {
  if (s == "auto") return FamilyFlag::kAuto;
  if (s == "network") return FamilyFlag::kNetwork;
  if (s == "gp") return FamilyFlag::kGaussianProcess;
  if (s == "linear") return FamilyFlag::kLinear;
  throw InputError("--family '" + s + "': must be auto, network, gp or linear");
}

TransformFlag ParseTransformFlag(const std::string& s) {
  if (s == "auto") return TransformFlag::kAuto;
  if (s == "log") return TransformFlag::kLog;
  if (s == "identity") return TransformFlag::kIdentity;
  throw InputError("--transform '" + s + "': must be auto, log or identity");
}

std::vector<family::Candidate> Candidates(FamilyFlag family, TransformFlag transform) {
  std::vector<family::Candidate> all;
  if (family == FamilyFlag::kAuto) all = family::ChoiceOptions::DefaultCandidates();
  const std::string body = family == FamilyFlag::kLinear            ? "linear"
                           : family == FamilyFlag::kGaussianProcess ? "gp-matern52-"
                                                                    : "network-evidence";
  const bool gp = family == FamilyFlag::kGaussianProcess;  // a power-law mean on log columns
  if (family != FamilyFlag::kAuto)
    for (const char* t : {"/log", "/identity"})
      all.push_back(family::ParseCandidate(
          body + (gp ? (std::string(t) == "/log" ? "linear" : "constant") : "") + t));
  std::vector<family::Candidate> out;
  for (const family::Candidate& c : all)
    if (transform == TransformFlag::kAuto || c.log == (transform == TransformFlag::kLog))
      out.push_back(c);
  return out;
}

WorkpieceModel TrainWorkpieceModel(const ProcessTable& table, const TrainOptions& options,
                                   const std::string& data_name,
                                   const nn::ModelProgress& progress) {
  if (options.family == FamilyFlag::kNetwork && options.transform == TransformFlag::kIdentity)
    return FromNetwork(nn::TrainModel(table, options.network, data_name, progress));
  if (options.transform == TransformFlag::kLog) {
    ProcessTable named = table;
    named.source = data_name;
    const std::vector<family::LogException> raw = family::LogExceptions(named);
    if (!raw.empty())
      throw InputError("--transform log: " + raw.front().Describe(named) +
                       "; use --transform auto (the log candidates then keep that column on its "
                       "raw scale and say so) or --transform identity, or correct the row");
  }
  family::ChoiceOptions choice = options.choice;
  choice.candidates = Candidates(options.family, options.transform);
  ProcessTable named = table;
  named.source = data_name;
  return FromChoice(family::ChooseFamily(named, choice), table, data_name);
}

nlohmann::json ChoiceTableJson(const family::Choice& choice) {
  json table = json::array();
  for (const family::CvRow& r : choice.table) {
    json row = r;
    row["fit_ms"] = r.fit_ms;
    table.push_back(row);
  }
  return table;
}

std::string FormatChoiceTable(const family::Choice& choice) {
  std::string s = "  candidate                         cv_rmse_um  cv_rmse_s     score  fit_ms\n";
  char line[200];
  for (std::size_t c = 0; c < choice.table.size(); ++c) {
    const family::CvRow& r = choice.table[c];
    std::string mark;
    for (int k = 0; k < Features::kCount; ++k)
      if (choice.chosen[k] == static_cast<int>(c))
        mark += std::string(mark.empty() ? "  <- " : ", ") + kTargetColumns[k];
    std::snprintf(line, sizeof line, "  %-32s %10.4g %10.4g %9.4g %7.2f%s\n",
                  r.candidate.Name().c_str(), r.cv_rmse(0), r.cv_rmse(1), r.score, r.fit_ms,
                  mark.c_str());
    s += line;
  }
  for (const std::string& note : choice.notes)
    if (!note.empty()) s += "  note: " + note + "\n";
  if (!choice.rows_note.empty()) s += "  note: " + choice.rows_note + "\n";
  return s;
}

}  // namespace whirl::workpiece
