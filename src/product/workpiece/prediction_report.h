#pragma once
// The predictions of a workpiece model for a table of processes, as `whirl predict` reports them:
// per row the mean and sd of both features (workpiece/model.h) and the training-domain flag; when
// the table has targets, per row the error (prediction - target) and over the rows
//   RMS error           sqrt(mean_q (prediction_q - target_q)^2), per output, its units;
//   mean |% error|      100 mean_q |prediction_q - target_q| / target_q over the rows whose target
//                       is > 0 (a zero target has no percentage error: left out, never divided by).
// The library formats; the command line prints.
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/process.h"
#include "workpiece/model.h"

namespace whirl::workpiece {

struct TablePrediction {
  std::vector<Prediction> predictions;  ///< one per row of the table
  nn::OutsideDomainSummary outside;     ///< rows outside the training domain
  bool have_targets = false;            ///< the table has a target for every row
  std::vector<Features> errors;         ///< prediction - target per row (have_targets)
  Features rms_error;                   ///< see the header comment (have_targets)
  Features mean_abs_pct_error;          ///< percent (have_targets; 0 when no row counts)
  std::array<int, Features::kCount> pct_rows{};  ///< rows counted in mean_abs_pct_error
};

/// Predicts every row of `table` and computes the figures of the header comment.
TablePrediction PredictTable(const WorkpieceModel& model, const ProcessTable& table);

/// The CSV `whirl predict --out` writes (inputs, max_elongation_um, max_elongation_std_um,
/// settle_time_s, settle_time_std_s, outside_domain 0/1), atomically, with `comments` on top.
void WritePredictionCsv(const std::filesystem::path& path, const ProcessTable& table,
                        const TablePrediction& p, const std::vector<std::string>& comments);

/// The JSON of `whirl predict --json`: {"model", "predictions": [{inputs, means, sds,
/// outside_domain, outside_domain_fields, error}], "outside_domain_count", "rms_error"}.
nlohmann::json PredictionJson(const ProcessTable& table, const TablePrediction& p,
                              const std::string& model_path);

/// The text table of `whirl predict`: one line per row (inputs, mean +- sd, domain), the note
/// on the sd and, with targets, the mean |% error| line naming `table_name`.
std::string FormatPredictionTable(const ProcessTable& table, const TablePrediction& p,
                                  const std::string& table_name);

}  // namespace whirl::workpiece
