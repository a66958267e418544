#pragma once
// The output documents of the drift commands, built once here: JSON for --json, text tables for
// the terminal, and the per-sample prediction CSV. The command line only prints or writes them.
// Units are in every name (_um, _C, _min).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/report.h"
#include "drift/selection.h"
#include "drift/stream.h"

namespace whirl::drift {

/// Lambda levels with partitions and F values, grades and the chosen sensors.
nlohmann::json SelectionJson(const Selection& s);
std::string FormatSelection(const Selection& s);

/// A model's summary: kind, sensors, time constants, coefficients with standard errors and VIF,
/// R^2, residual std, training runs, lag search.
nlohmann::json ModelSummaryJson(const DriftModel& m);
std::string FormatModel(const DriftModel& m);
/// The unit of a feature's coefficient: rises and their lags um/K, elapsed-time terms um, other
/// inputs um per the unit their name ends in (spindle_rpm: um/rpm).
std::string CoefficientUnit(const DriftModel& m, const Feature& f);

/// Per sample: time_min (or sample), predicted_um, compensation_um (= -predicted), std_um, and
/// measured_um, residual_um when the run has the error column.
std::string PredictionCsv(const RunPrediction& p, const std::vector<std::string>& comments);
/// The same CSV written row by row (a streamed run): the comments and header ...
std::string PredictionCsvHeader(bool time_from_index, bool has_measured,
                                const std::vector<std::string>& comments);
/// ... and one row per sample (`measured` null when the run has no measured error).
void AppendPredictionRow(double time, double predicted_um, double std_um, const double* measured_um,
                         std::string* out);
/// Summary of a prediction (statistics of the residual when measured, warnings).
nlohmann::json PredictionJson(const RunPrediction& p);
nlohmann::json PredictionJson(const PredictionSummary& p);

nlohmann::json ErrorStatsJson(const ErrorStats& s);
nlohmann::json CrossRunJson(const CrossRunResult& r);
std::string FormatCrossRun(const CrossRunResult& r);
nlohmann::json HoldoutJson(const HoldoutResult& r);
std::string FormatHoldout(const HoldoutResult& r);
/// drift fit's candidate table (empty when one family was asked for) and the choice.
nlohmann::json CandidatesJson(const FitReport& rep);
/// The model report's baselines per run (MAE um; null where a baseline does not exist) and why
/// one is missing.
nlohmann::json ReportBaselinesJson(const std::vector<ReportBaseline>& baselines,
                                   const std::vector<std::string>& notes);
std::string FormatCandidates(const FitReport& rep);

}  // namespace whirl::drift
