#pragma once
// The "load onto the control" box of the drift and monitor reports (a box of a report document,
// core/report_document.h): these commands write no NC program; the box says which command writes
// the live drift action for a machine (whirl drift nc), what it needs from the control and which
// model it takes, so every report opens with what to take to the machine.
#include <string>
#include <vector>

#include "core/report_document.h"

namespace whirl::drift {

/// The box for a model of kind `model_kind` ("mlr", "dynamic", "network") predicting
/// `error_column` from `inputs` (the sensors and logged columns the action reads through analog
/// inputs; empty: "the inputs the model names"); `model_file` names the model JSON in the
/// command ("" for MODEL.json).
report::Box DriftLoadBox(const std::string& model_kind, const std::string& error_column,
                         const std::vector<std::string>& inputs,
                         const std::string& model_file = "");

}  // namespace whirl::drift
