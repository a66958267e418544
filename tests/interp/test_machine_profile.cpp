// Machine profiles (interp/machine_profile.h): the shipped files load, the drift action's slope
// object and hand-over slots are read and checked, every bad value is an InputError naming the
// file and the key, and the plan options it gives survive the plan JSON round trip.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "core/json_file.h"
#include "interp/machine_profile.h"

namespace whirl::interp {
namespace {
namespace fs = std::filesystem;

const fs::path kShipped = fs::path(WHIRL_SOURCE_DIR) / "datasets/machines/whirling_840d.json";

// The shipped profile changed by `edit`, written to a temporary file.
fs::path Edited(const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = ReadJsonFile(kShipped);
  edit(j);
  const fs::path p = fs::path(::testing::TempDir()) / "whirl_profile_test.json";
  std::ofstream(p) << j.dump(2);
  return p;
}

void ExpectRefused(const std::function<void(nlohmann::json&)>& edit, const std::string& word) {
  try {
    LoadMachineProfile(Edited(edit));
    ADD_FAILURE() << "accepted a profile with a bad '" << word << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("whirl_profile_test.json"), std::string::npos) << e.what();
  }
}

TEST(MachineProfile, ShippedProfilesLoadWithTheirDriftObjects) {
  const MachineProfile w = LoadMachineProfile(kShipped);
  ASSERT_TRUE(w.drift);
  EXPECT_TRUE(w.drift->has_slope);
  EXPECT_EQ(w.drift->slope_fixed_end_mm, 5587.5);
  EXPECT_EQ(w.drift->slope_growth_direction, -1);
  EXPECT_EQ(w.drift->workpiece_slope_param, 97);
  EXPECT_EQ(w.drift->inputs.size(), 13u);
  const MachineProfile e =
      LoadMachineProfile(fs::path(WHIRL_SOURCE_DIR) / "datasets/machines/example_840d.json");
  ASSERT_TRUE(e.drift);
  EXPECT_FALSE(e.drift->has_slope);
  EXPECT_EQ(e.drift->workpiece_slope_param, -1);
}

TEST(MachineProfile, BadSlopeObjectsAndSlotsAreRefusedByName) {
  ExpectRefused([](nlohmann::json& j) { j["drift"]["slope"]["fixed_end_mm"] = 1.0; },
                "fixed_end_mm");
  ExpectRefused([](nlohmann::json& j) { j["drift"]["slope"]["growth_direction"] = 0; },
                "growth_direction");
  ExpectRefused([](nlohmann::json& j) { j["drift"]["slope"].erase("fixed_end_position_mm"); },
                "fixed_end_position_mm");
  ExpectRefused([](nlohmann::json& j) { j["drift"].erase("workpiece_k0_param"); },
                "workpiece_slope_param");
  ExpectRefused([](nlohmann::json& j) { j["drift"]["workpiece_slope_param"] = 98; },
                "workpiece_slope_param");
  // The drift action's R<n>..R<n+4> must not overlap the plan's R<m>..R<m+3>.
  ExpectRefused([](nlohmann::json& j) { j["drift"]["save_r_first"] = 86; }, "R86");
  ExpectRefused([](nlohmann::json& j) { j["drift"]["missing_alarm"] = 69998; }, "missing_alarm");
}

TEST(MachineProfile, PlanOptionsCarryTheLivenessCheckThroughTheJsonRoundTrip) {
  const MachineProfile w = LoadMachineProfile(kShipped);
  PlanOptions standalone, combined;
  w.ApplyTo(standalone);
  EXPECT_EQ(standalone.drift_alive_param, 100);  // checks that no drift action runs beside it
  EXPECT_EQ(standalone.workpiece_k0_param, -1);
  w.ApplyCombinedTo(combined);
  EXPECT_EQ(combined.workpiece_k0_param, 99);
  EXPECT_EQ(combined.workpiece_slope_param, 97);
  EXPECT_EQ(combined.drift_alive_param, 100);
  combined.start_position_mm = 5600;
  nlohmann::json j = combined;
  PlanOptions back = j.get<PlanOptions>();
  EXPECT_EQ(back.workpiece_slope_param, 97);
  EXPECT_EQ(back.drift_alive_param, 100);
  EXPECT_EQ(back.drift_missing_alarm, combined.drift_missing_alarm);
  // A plan JSON from before the liveness check (drift_marker_r, no drift_alive_param) still loads.
  j.erase("drift_alive_param");
  j.erase("workpiece_slope_param");
  j["workpiece_k0_param"] = -1;
  j["drift_marker_r"] = -1;
  EXPECT_NO_THROW(j.get<PlanOptions>());
}

}  // namespace
}  // namespace whirl::interp
