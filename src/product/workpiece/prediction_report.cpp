#include "workpiece/prediction_report.h"

#include <cmath>
#include <cstdio>

#include "core/atomic_file.h"
#include "core/csv.h"

namespace whirl::workpiece {

TablePrediction PredictTable(const WorkpieceModel& model, const ProcessTable& table) {
  TablePrediction r;
  r.predictions = PredictBatch(model, table.inputs);
  r.outside = SummarizeOutsideDomain(r.predictions);
  r.have_targets = !table.targets.empty() && table.targets.size() == table.inputs.size();
  if (!r.have_targets) return r;
  std::array<double, Features::kCount> sq{}, ape{};
  for (std::size_t q = 0; q < r.predictions.size(); ++q) {
    const auto mean = r.predictions[q].mean.ToArray(), target = table.targets[q].ToArray();
    std::array<double, Features::kCount> e{};
    for (int k = 0; k < Features::kCount; ++k) {
      e[k] = mean[k] - target[k];
      sq[k] += e[k] * e[k];
      if (target[k] > 0) {
        ape[k] += std::abs(e[k]) / target[k];
        ++r.pct_rows[k];
      }
    }
    r.errors.push_back(Features::FromArray(e));
  }
  std::array<double, Features::kCount> rms{}, pct{};
  const double n = static_cast<double>(r.predictions.size());
  for (int k = 0; k < Features::kCount; ++k) {
    rms[k] = std::sqrt(sq[k] / n);
    pct[k] = r.pct_rows[k] > 0 ? 100 * ape[k] / r.pct_rows[k] : 0.0;
  }
  r.rms_error = Features::FromArray(rms);
  r.mean_abs_pct_error = Features::FromArray(pct);
  return r;
}

void WritePredictionCsv(const std::filesystem::path& path, const ProcessTable& table,
                        const TablePrediction& p, const std::vector<std::string>& comments) {
  std::vector<std::string> header(kInputColumns.begin(), kInputColumns.end());
  for (const char* c : {"max_elongation_um", "max_elongation_std_um", "settle_time_s",
                        "settle_time_std_s", "outside_domain"})
    header.push_back(c);
  std::vector<std::vector<double>> rows;
  for (std::size_t q = 0; q < p.predictions.size(); ++q) {
    const auto a = table.inputs[q].ToArray();
    const Prediction& r = p.predictions[q];
    std::vector<double> row(a.begin(), a.end());
    row.insert(row.end(), {r.mean.max_elongation_um, r.stddev.max_elongation_um,
                           r.mean.settle_time_s, r.stddev.settle_time_s,
                           r.outside_domain ? 1.0 : 0.0});
    rows.push_back(std::move(row));
  }
  WriteFileAtomic(path, FormatCsv(header, rows, comments));
}

nlohmann::json PredictionJson(const ProcessTable& table, const TablePrediction& p,
                              const std::string& model_path) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t q = 0; q < p.predictions.size(); ++q) {
    nlohmann::json inputs;
    const auto a = table.inputs[q].ToArray();
    for (int i = 0; i < ProcessInputs::kCount; ++i) inputs[kInputColumns[i]] = a[i];
    const Prediction& pr = p.predictions[q];
    nlohmann::json r = {{"inputs", inputs},
                        {"max_elongation_um", pr.mean.max_elongation_um},
                        {"max_elongation_std_um", pr.stddev.max_elongation_um},
                        {"settle_time_s", pr.mean.settle_time_s},
                        {"settle_time_std_s", pr.stddev.settle_time_s},
                        {"outside_domain", pr.outside_domain},
                        {"outside_domain_fields", pr.outside_domain_fields}};
    if (p.have_targets)
      r["error"] = {{"max_elongation_um", p.errors[q].max_elongation_um},
                    {"settle_time_s", p.errors[q].settle_time_s}};
    rows.push_back(r);
  }
  nlohmann::json j = {
      {"model", model_path}, {"predictions", rows}, {"outside_domain_count", p.outside.rows}};
  if (p.have_targets)
    j["rms_error"] = {{"max_elongation_um", p.rms_error.max_elongation_um},
                      {"settle_time_s", p.rms_error.settle_time_s}};
  return j;
}

std::string FormatPredictionTable(const ProcessTable& table, const TablePrediction& p,
                                  const std::string& table_name) {
  char line[400];
  std::snprintf(line, sizeof line, "%4s %8s %8s %7s %8s %9s | %22s | %18s | %s\n", "row", "HRC",
                "D [mm]", "P [mm]", "R [mm]", "v [m/min]", "max elongation [um]",
                "settle time [s]", "domain");
  std::string s = line;
  for (std::size_t q = 0; q < p.predictions.size(); ++q) {
    const auto& in = table.inputs[q];
    const Prediction& r = p.predictions[q];
    std::snprintf(line, sizeof line,
                  "%4zu %8.4g %8.4g %7.4g %8.4g %9.4g | %10.5g +- %-8.3g | %8.5g +- %-6.3g | %s\n",
                  q + 1, in.hardness_hrc, in.diameter_mm, in.pitch_mm, in.raceway_radius_mm,
                  in.cutting_speed_m_min, r.mean.max_elongation_um, r.stddev.max_elongation_um,
                  r.mean.settle_time_s, r.stddev.settle_time_s,
                  r.outside_domain ? "OUTSIDE" : "in");
    s += line;
  }
  s += "(+- one predictive standard deviation)\n";
  if (p.have_targets) {
    std::snprintf(line, sizeof line,
                  ": mean absolute error %.3g %% (max elongation, %d rows with a target > 0), "
                  "%.3g %% (settle time, %d rows)\n",
                  p.mean_abs_pct_error.max_elongation_um, p.pct_rows[0],
                  p.mean_abs_pct_error.settle_time_s, p.pct_rows[1]);
    s += "targets in " + table_name + line;
  }
  return s;
}

}  // namespace whirl::workpiece
