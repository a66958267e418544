#pragma once
// The manual of the product's plan module: what `whirl plan` hands a shop. Here the one
// `whirl.plan` document (schema version 2, interp/sinumerik.h) and the one set of plan files,
// built once for every command that plans (`whirl plan`, `whirl demo`); the "load onto the
// control" data of a plan in plan/load.h. The document: the 840D plan of interp/sinumerik.h
// (settings, segments with SD43900 [mm], SD43910 [-], SD43920 [mm], counts, units) plus
//   provenance   one line: command, model or given features, curve
//   screw        the screw file's content (screw/screw.h)
//   kinematics   axial_feed_mm_min, cutting_time_s, workpiece_speed_rpm, ring_speed_rpm
//   curve        the arctangent curve l(t) = L atan(k (t/t_s)^p) / atan(k) (fit/arctan_curve.h)
//   prediction   model (file or description; null when the features were given),
//                max_elongation_um, settle_time_s and, from a model, max_elongation_std_um,
//                settle_time_std_s (predictive standard deviation, nn/model.h), outside_domain,
//                outside_domain_fields.
// Key spelling follows `whirl predict`: *_std_um / *_std_s for standard deviations.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"
#include "nn/model.h"
#include "screw/screw.h"

namespace whirl::plan {

/// Where the curve's features came from.
struct PlanSource {
  /// The model file (or "trained now from <table>"); empty when the user gave the features.
  std::string model;
  /// The model's prediction (mean and std); absent when the features were given.
  std::optional<nn::Prediction> prediction;
  /// The features the curve was built from (the prediction's mean, or the given values).
  Features features;
};

/// The `whirl.plan` document (see the header comment).
nlohmann::json PlanDocument(const interp::CompensationPlan& plan, const fit::ArctanCurve& curve,
                            const screw::Screw& screw, const screw::Kinematics& kinematics,
                            const PlanSource& source, const std::string& provenance);

/// Output paths of the plan files; an empty path is not written.
struct PlanOutputPaths {
  std::filesystem::path json;  ///< the whirl.plan document
  std::filesystem::path csv;   ///< the PLC table (interp::FormatPlcCsv)
  std::filesystem::path nc;    ///< the NC program (interp::FormatNcProgram)
  std::filesystem::path reset_nc;  ///< its reset program (interp::FormatNcResetProgram)
};

/// Renders and writes the requested plan files all-or-nothing (core/atomic_file.h
/// WriteFilesAtomic): one unwritable path leaves none of them written and previous files intact.
/// The NC headers name the programs by the files' stems, which must be SINUMERIK program names
/// and differ from each other (interp::ProgramNameOf, CheckDistinctProgramNames).
/// `curve_source` goes into the NC header; `provenance` into the PLC table's comments.
void WritePlanFiles(const PlanOutputPaths& paths, const nlohmann::json& document,
                    const interp::CompensationPlan& plan, const std::string& provenance,
                    const std::string& curve_source);

}  // namespace whirl::plan
