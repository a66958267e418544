#include "plan/plan_document.h"

#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/json_file.h"

namespace whirl::plan {

nlohmann::json PlanDocument(const interp::CompensationPlan& plan, const fit::ArctanCurve& curve,
                            const screw::Screw& screw, const screw::Kinematics& kinematics,
                            const PlanSource& source, const std::string& provenance) {
  nlohmann::json prediction = {
      {"model", source.model.empty() ? nlohmann::json(nullptr) : nlohmann::json(source.model)},
      {"max_elongation_um", source.features.max_elongation_um},
      {"settle_time_s", source.features.settle_time_s}};
  if (source.prediction) {
    const nn::Prediction& p = *source.prediction;
    prediction["max_elongation_std_um"] = p.stddev.max_elongation_um;
    prediction["settle_time_std_s"] = p.stddev.settle_time_s;
    prediction["outside_domain"] = p.outside_domain;
    prediction["outside_domain_fields"] = p.outside_domain_fields;
  }
  nlohmann::json j = plan;
  j["provenance"] = provenance;
  j["screw"] = screw;
  j["kinematics"] = {{"axial_feed_mm_min", kinematics.axial_feed_mm_min},
                     {"cutting_time_s", kinematics.cutting_time_s},
                     {"workpiece_speed_rpm", kinematics.workpiece_speed_rpm},
                     {"ring_speed_rpm", kinematics.ring_speed_rpm}};
  j["curve"] = curve;
  j["prediction"] = prediction;
  return j;
}

void WritePlanFiles(const PlanOutputPaths& paths, const nlohmann::json& document,
                    const interp::CompensationPlan& plan, const std::string& provenance,
                    const std::string& curve_source) {
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  if (!paths.json.empty()) files.emplace_back(paths.json, JsonFileText(document));
  if (!paths.csv.empty()) files.emplace_back(paths.csv, interp::FormatPlcCsv(plan, {provenance}));
  interp::NcProgramInfo info;
  info.curve_source = curve_source;
  // The headers name the programs as the control will know them: the files' stems.
  if (!paths.nc.empty()) info.program_name = interp::ProgramNameOf(paths.nc.string(), "--nc");
  if (!paths.reset_nc.empty())
    info.reset_program_name = interp::ProgramNameOf(paths.reset_nc.string(), "--reset-nc");
  if (!paths.nc.empty()) files.emplace_back(paths.nc, interp::FormatNcProgram(plan, info));
  if (!paths.reset_nc.empty())
    files.emplace_back(paths.reset_nc, interp::FormatNcResetProgram(plan.options, info));
  if (!files.empty()) WriteFilesAtomic(files);
}

}  // namespace whirl::plan
