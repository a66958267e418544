#include "drift/documents.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/csv.h"
#include "core/numbers.h"

namespace whirl::drift {
namespace {

using nlohmann::json;

std::string JoinNames(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

std::string JoinNumbers(const std::vector<double>& v) {
  std::string out;
  for (double x : v) out += (out.empty() ? "" : ", ") + MessageNumber(x);
  return out;
}

std::vector<double> StdVector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// F values may be +inf (a partition into tight classes); JSON has no infinity.
json Finite(double v) { return std::isfinite(v) ? json(v) : json("inf"); }

// Per-fold figures: null where a fold could not be fitted.
json FiniteList(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(std::isfinite(x) ? json(x) : json(nullptr));
  return a;
}

std::string Classes(const Selection& s, const Partition& p) {
  std::vector<std::string> groups(static_cast<std::size_t>(p.classes));
  for (std::size_t i = 0; i < p.labels.size(); ++i) {
    std::string& g = groups[static_cast<std::size_t>(p.labels[i])];
    g += (g.empty() ? "" : " ") + s.sensor_names[i];
  }
  std::string out;
  for (const auto& g : groups) out += "{" + g + "}";
  return out;
}

}  // namespace

std::string CoefficientUnit(const DriftModel& m, const Feature& f) {
  if (f.input == "elapsed") return "um";
  for (const auto& s : m.sensors)
    if (s == f.input) return "um/K";
  const auto cut = f.input.rfind('_');
  if (cut != std::string::npos && cut + 1 < f.input.size())
    return "um/" + f.input.substr(cut + 1);
  return "um per unit of " + f.input;
}

json SelectionJson(const Selection& s) {
  json parts = json::array();
  for (const Partition& p : s.partitions) {
    json classes = json::array();
    for (int k = 0; k < p.classes; ++k) {
      std::vector<std::string> members;
      for (std::size_t i = 0; i < p.labels.size(); ++i)
        if (p.labels[i] == k) members.push_back(s.sensor_names[i]);
      classes.push_back(members);
    }
    json jp = {{"lambda", p.lambda}, {"classes", p.classes}, {"members", classes}};
    if (p.has_f) {
      jp["f"] = Finite(p.f);
      jp["f_critical"] = p.f_critical;
      jp["significant"] = p.significant();
    }
    parts.push_back(jp);
  }
  json grades = json::object();
  for (std::size_t i = 0; i < s.sensor_names.size(); ++i)
    grades[s.sensor_names[i]] = s.grades(static_cast<Eigen::Index>(i));
  json out = {{"sensors", s.sensor_names}, {"squarings", s.squarings},
              {"partitions", parts},       {"chosen_partition", s.chosen_partition},
              {"grey_grades", grades},     {"chosen_sensors", s.ChosenNames()},
              {"rule", s.message}};
  if (!s.left_out.empty()) out["left_out"] = s.left_out;
  if (!s.class_count_scores.empty()) {
    json scores = json::array();
    for (const auto& c : s.class_count_scores)
      scores.push_back({{"classes", c.classes}, {"cv_rmse_um", Finite(c.cv_rmse_um)}});
    out["class_count_scores"] = scores;
  }
  return out;
}

std::string FormatSelection(const Selection& s) {
  std::ostringstream o;
  o << "fuzzy equivalence matrix after " << s.squarings << " max-min squarings; lambda-cuts:\n";
  o << "  lambda    r          F     F_crit  sig  classes\n";
  for (std::size_t i = 0; i < s.partitions.size(); ++i) {
    const Partition& p = s.partitions[i];
    o << (static_cast<int>(i) == s.chosen_partition ? "* " : "  ") << FormatDecimals(p.lambda, 4)
      << PadLeft(FormatDecimals(p.classes, 0), 5) << "  "
      << (p.has_f ? PadLeft(FormatDecimals(p.f, 3), 9) + "  " +
                        PadLeft(FormatDecimals(p.f_critical, 3), 9) +
                        (p.significant() ? "  yes" : "   no")
                  : std::string(25, ' ') + "-")
      << "  " << Classes(s, p) << "\n";
  }
  o << "grey relational grades (rho 0.5):";
  for (std::size_t i = 0; i < s.sensor_names.size(); ++i)
    o << " " << s.sensor_names[i] << " "
      << FormatDecimals(s.grades(static_cast<Eigen::Index>(i)), 4);
  o << "\nclass count: " << s.message << "\nchosen sensors: " << JoinNames(s.ChosenNames()) << "\n";
  return o.str();
}

json ModelSummaryJson(const DriftModel& m) {
  json coeffs = json::array();
  const bool linear = m.kind != ModelKind::kNetwork;
  if (linear) {
    coeffs.push_back({{"feature", "intercept"},
                      {"value", m.linear.coefficients(0)},
                      {"standard_error", m.linear.standard_errors(0)}});
    for (std::size_t i = 0; i < m.features.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      coeffs.push_back({{"feature", m.features[i].Name(m.time_unit)},
                        {"unit", CoefficientUnit(m, m.features[i])},
                        {"value", m.linear.coefficients(k + 1)},
                        {"standard_error", m.linear.standard_errors(k + 1)},
                        {"vif", Finite(m.linear.vif(k))}});
    }
  }
  json j = {{"kind", ToString(m.kind)},
            {"error_column", m.error_column},
            {"sensors", m.sensors},
            {"reference_C", StdVector(m.reference_C)},
            {"extra_inputs", m.extra_inputs},
            {"time_unit", m.time_unit},
            {"time_constants", m.time_constants},
            {"elapsed_time_constants", m.elapsed_time_constants},
            {"error_zero", ToString(m.zero.zero)},
            {"r_squared", m.r_squared},
            {"residual_std_um", m.residual_std_um},
            {"training_runs", m.training_runs},
            {"state", ToString(m.state)},
            {"training_samples", m.training_samples},
            {"selection", m.selection},
            {"notes", m.notes}};
  if (linear)
    j["coefficients"] = coeffs;
  else
    j["layer_sizes"] = m.network.layer_sizes;
  return j;
}

std::string FormatModel(const DriftModel& m) {
  std::ostringstream o;
  std::vector<std::string> inputs = m.sensors;
  inputs.insert(inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  if (!m.elapsed_time_constants.empty()) inputs.push_back("elapsed time");
  o << ToString(m.kind) << " model of " << m.error_column << " on " << JoinNames(inputs) << "\n";
  o << "  error zero: " << ToString(m.zero.zero)
    << (m.zero.zero == ErrorZero::kFixed ? " (gauge level " + FormatDecimals(m.zero.gauge_level_um, 3) + " um)"
                                         : "")
    << "\n";
  if (!m.elapsed_time_constants.empty())
    o << "  elapsed-time constants: " << JoinNumbers(m.elapsed_time_constants) << " "
      << m.time_unit << "\n";
  o << "  sensors: " << m.selection << "\n";
  if (!m.time_constants.empty())
    o << "  lag time constants: " << JoinNumbers(m.time_constants) << " " << m.time_unit << "\n";
  for (const auto& n : m.notes) o << "  " << n << "\n";
  if (m.kind != ModelKind::kNetwork) {
    o << "  feature                        coefficient   std error        VIF\n";
    o << "  intercept [um]                "
      << PadLeft(FormatDecimals(m.linear.coefficients(0), 4), 12)
      << PadLeft(FormatDecimals(m.linear.standard_errors(0), 4), 12) << "\n";
    for (std::size_t i = 0; i < m.features.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      char name[64];
      std::snprintf(name, sizeof name, "%-30s",
                    (m.features[i].Name(m.time_unit) + " [" + CoefficientUnit(m, m.features[i]) +
                     "]").c_str());
      o << "  " << name << PadLeft(FormatDecimals(m.linear.coefficients(k + 1), 4), 12)
        << PadLeft(FormatDecimals(m.linear.standard_errors(k + 1), 4), 12)
        << PadLeft(FormatSignificant(m.linear.vif(k), 4), 11) << "\n";
    }
  } else {
    o << "  network " << m.network.layer_sizes[0] << "-" << m.network.layer_sizes[1] << "-1\n";
  }
  o << "  training: R^2 " << FormatDecimals(m.r_squared, 4) << ", residual std "
    << FormatDecimals(m.residual_std_um, 3) << " um, " << m.training_samples << " samples of "
    << JoinNames(m.training_runs) << " (state " << ToString(m.state) << ")\n";
  return o.str();
}

std::string PredictionCsvHeader(bool time_from_index, bool has_measured,
                                const std::vector<std::string>& comments) {
  std::vector<std::string> header{time_from_index ? "sample" : "time_min", "predicted_um",
                                  "compensation_um", "std_um"};
  if (has_measured) {
    header.push_back("measured_um");
    header.push_back("residual_um");
  }
  return FormatCsv(header, {}, comments);
}

void AppendPredictionRow(double time, double predicted, double std_um, const double* measured,
                         std::string* out) {
  const auto cell = [&](double v, char end) {
    out->append(FormatNumber(v));
    out->push_back(end);
  };
  cell(time, ',');
  cell(predicted, ',');
  cell(-predicted, ',');
  if (!measured) return cell(std_um, '\n');
  cell(std_um, ',');
  cell(*measured, ',');
  cell(*measured - predicted, '\n');
}

std::string PredictionCsv(const RunPrediction& p, const std::vector<std::string>& comments) {
  std::string out = PredictionCsvHeader(p.time_from_index, p.has_measured, comments);
  for (Eigen::Index k = 0; k < p.predicted_um.size(); ++k)
    AppendPredictionRow(p.time[static_cast<std::size_t>(k)], p.predicted_um(k), p.std_um(k),
                        p.has_measured ? &p.measured_um(k) : nullptr, &out);
  return out;
}

json ErrorStatsJson(const ErrorStats& s) {
  return {{"samples", s.samples},
          {"mae_um", s.mae_um},
          {"rmse_um", s.rmse_um},
          {"std_um", s.std_um},
          {"max_abs_um", s.max_abs_um}};
}

json PredictionJson(const PredictionSummary& p) {
  json j = {{"run", p.run},
            {"samples", p.samples},
            {"time_axis", p.time_from_index ? "sample index (no recorded time)" : "time_min"},
            {"predicted_um_range", {p.predicted_min_um, p.predicted_max_um}},
            {"outside_training_range_samples", p.outside_range_samples},
            {"warnings", p.warnings}};
  if (p.has_measured) {
    j["residual"] = ErrorStatsJson(p.residual);
    j["no_compensation"] = ErrorStatsJson(p.none);
  }
  return j;
}

json PredictionJson(const RunPrediction& p) { return PredictionJson(Summarize(p)); }

json CrossRunJson(const CrossRunResult& r) {
  json runs = json::array();
  for (std::size_t i = 0; i < r.runs.size(); ++i)
    runs.push_back(
        {{"name", r.runs[i]}, {"state", ToString(r.states[i])}, {"chosen_sensors", r.chosen[i]}});
  json cells = json::array();
  for (std::size_t i = 0; i < r.runs.size(); ++i)
    for (std::size_t j = 0; j < r.runs.size(); ++j)
      cells.push_back({{"train", r.runs[i]},
                       {"test", r.runs[j]},
                       {"model", ErrorStatsJson(r.cells[i][j].model)},
                       {"mlr_all_sensors", ErrorStatsJson(r.cells[i][j].all_sensors)},
                       {"no_compensation", ErrorStatsJson(r.cells[i][j].none)},
                       {"time_only", ErrorStatsJson(r.cells[i][j].time)}});
  json groups = json::array();
  for (const auto& g : r.groups)
    groups.push_back({{"group", g.name},
                      {"pairs", g.pairs},
                      {"model", ErrorStatsJson(g.model)},
                      {"mlr_all_sensors", ErrorStatsJson(g.all_sensors)},
                      {"no_compensation", ErrorStatsJson(g.none)},
                      {"time_only", ErrorStatsJson(g.time)},
                      {"strongest", g.Strongest()}});
  return {{"schema", "whirl.drift_crossval"},
          {"schema_version", 2},
          {"error_zero", ToString(r.zero.zero)},
          {"error_column", r.error_column},
          {"model", ToString(r.kind)},
          {"candidates", ToString(r.candidates)},
          {"runs", runs},
          {"pairs", cells},
          {"groups", groups}};
}

std::string FormatCrossRun(const CrossRunResult& r) {
  std::ostringstream o;
  o << "cross-run evaluation of " << r.error_column << " (" << ToString(r.kind)
    << " model of each run, candidates " << ToString(r.candidates)
    << "; statistics of measured - predicted [um])\n";
  for (std::size_t i = 0; i < r.runs.size(); ++i)
    o << "  " << r.runs[i] << " (" << ToString(r.states[i]) << "): " << JoinNames(r.chosen[i])
      << "\n";
  o << "RMSE [um], rows = model built on, columns = run predicted:\n" << std::string(16, ' ');
  for (const auto& n : r.runs) {
    char cell[32];
    std::snprintf(cell, sizeof cell, "%12.12s", n.c_str());
    o << cell;
  }
  o << "\n";
  for (std::size_t i = 0; i < r.runs.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%-16.16s", r.runs[i].c_str());
    o << name;
    for (std::size_t j = 0; j < r.runs.size(); ++j)
      o << PadLeft(FormatDecimals(r.cells[i][j].model.rmse_um, 2), 12);
    o << "\n";
  }
  o << "errors from zero '" << ToString(r.zero.zero)
    << "' for every column; time = sensor-free time-only warm-up of the training run\n";
  o << "group means (Miao et al. tab 6-8)   pairs |  model: RMSE    std    max | all sensors: "
       "RMSE    std    max | none: RMSE    std    max | time: RMSE | strongest\n";
  for (const auto& g : r.groups) {
    char line[320];
    std::snprintf(line, sizeof line,
                  "  %-32s %5d | %12.2f %6.2f %6.2f | %18.2f %6.2f %6.2f | %10.2f %6.2f %6.2f | "
                  "%10.2f | %s\n",
                  g.name.c_str(), g.pairs, g.model.rmse_um, g.model.std_um, g.model.max_abs_um,
                  g.all_sensors.rmse_um, g.all_sensors.std_um, g.all_sensors.max_abs_um,
                  g.none.rmse_um, g.none.std_um, g.none.max_abs_um, g.time.rmse_um,
                  g.Strongest().c_str());
    o << line;
  }
  return o.str();
}

json HoldoutJson(const HoldoutResult& r) {
  json rows = json::array();
  for (const auto& row : r.rows_out)
    rows.push_back({{"channel", row.channel},
                    {"method", row.method},
                    {"inputs", row.inputs},
                    {"time_constants_min", row.time_constants},
                    {"train", ErrorStatsJson(row.train)},
                    {"test", ErrorStatsJson(row.test)}});
  json strongest = json::object();
  for (const auto& [ch, method] : r.Strongest()) strongest[ch] = method;
  return {{"schema", "whirl.drift_holdout"},
          {"schema_version", 2},
          {"error_zero", ToString(r.zero.zero)},
          {"strongest_by_test_mae", strongest},
          {"log", r.log},
          {"rows", r.rows},
          {"train_rows", {0, r.train_end}},
          {"test_rows", {r.train_end, r.test_end}},
          {"time_axis", r.time_from_index ? "sample index (no recorded time)" : "time_min"},
          {"train_end_min", r.train_end_min},
          {"test_end_min", r.test_end_min},
          {"results", rows}};
}

std::string FormatHoldout(const HoldoutResult& r) {
  std::ostringstream o;
  auto when = [&](double t) {
    return r.time_from_index ? "sample " + FormatDecimals(t, 0) + " (no recorded time)"
                             : FormatDecimals(t / 60, 1) + " h";
  };
  o << "chronological hold-out on " << r.log << ": train rows [0, " << r.train_end << ") (to "
    << when(r.train_end_min) << "), test rows [" << r.train_end << ", " << r.test_end << ") (to "
    << when(r.test_end_min) << ")\n";
  o << "channel  method         test MAE  test RMSE  test max | train MAE | inputs (lags)\n";
  for (const auto& row : r.rows_out) {
    char line[160];
    std::snprintf(line, sizeof line, "%-8s %-13s %9.2f %10.2f %9.2f | %9.2f | ",
                  row.channel.c_str(), row.method.c_str(), row.test.mae_um, row.test.rmse_um,
                  row.test.max_abs_um, row.train.mae_um);
    o << line
      << (row.inputs.size() > 6 ? std::to_string(row.inputs.size()) + " sensors"
                                : JoinNames(row.inputs));
    if (!row.time_constants.empty())
      o << " (" << JoinNumbers(row.time_constants) << (r.time_from_index ? " samples)" : " min)");
    o << "\n";
  }
  o << "errors from zero '" << ToString(r.zero.zero)
    << "'; time = sensor-free warm-up in time since the log's start\n";
  for (const auto& [ch, method] : r.Strongest())
    o << "strongest on " << ch << " (lowest test MAE): " << method << "\n";
  return o.str();
}

json CandidatesJson(const FitReport& rep) {
  json c = json::array();
  for (const auto& s : rep.candidates)
    c.push_back({{"name", s.name},
                 {"elapsed_time_constants", s.time_constants},
                 {"parameters", s.parameters},
                 {"cv_rmse_um", Finite(s.cv_rmse_um)},
                 {"folds", s.folds},
                 {"fold_rmse_um", FiniteList(s.fold_rmse_um)},
                 {"sensor_free", s.sensor_free}});
  return c;
}

std::string FormatCandidates(const FitReport& rep) {
  if (rep.candidates.empty()) return "";
  std::ostringstream o;
  o << "candidates (validation RMSE, the whole fit redone in every fold):\n"
    << "  candidate       parameters  validation RMSE um  folds  RMSE per fold um\n";
  for (const auto& s : rep.candidates) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-15s %10d  %18s  %5d ", s.name.c_str(), s.parameters,
                  FormatDecimalsOr(std::isfinite(s.cv_rmse_um) ? s.cv_rmse_um : NAN, 3, "-").c_str(), s.folds);
    o << line;
    for (double f : s.fold_rmse_um) o << " " << FormatDecimalsOr(std::isfinite(f) ? f : NAN, 3, "-");
    o << "\n";
  }
  o << rep.chosen << "\n";
  return o.str();
}

}  // namespace whirl::drift

namespace whirl::drift {

nlohmann::json ReportBaselinesJson(const std::vector<ReportBaseline>& baselines,
                                   const std::vector<std::string>& notes) {
  const auto value = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json runs = json::array();
  for (const ReportBaseline& b : baselines)
    runs.push_back({{"run", b.run},
                    {"model_mae_um", value(b.model_mae_um)},
                    {"none_mae_um", value(b.none_mae_um)},
                    {"time_only_mae_um", value(b.time_only_mae_um)},
                    {"previous_run_mae_um", value(b.previous_run_mae_um)},
                    {"strongest", b.strongest}});
  return {{"runs", runs}, {"notes", notes}};
}

}  // namespace whirl::drift
