// Machine profiles (interp/machine_profile.h): the shipped files load, the drift action's slope
// object and hand-over slots are read and checked, every bad value is an InputError naming the
// file and the key, and the plan options it gives survive the plan JSON round trip.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <vector>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "core/json_file.h"
#include "interp/machine_profile.h"
#include "interp/profile_uses.h"
#include "support/scratch_dir.h"

namespace whirl::interp {
namespace {
namespace fs = std::filesystem;

const fs::path kShipped = fs::path(WHIRL_SOURCE_DIR) / "datasets/machines/whirling_840d.json";

// The shipped profile changed by `edit`, written to a temporary file.
fs::path Edited(const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = ReadJsonFile(kShipped);
  edit(j);
  const fs::path p = whirl::test::ScratchDir() / "whirl_profile_test.json";
  std::ofstream(p) << j.dump(2);
  return p;
}

using J = nlohmann::json;

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
  EXPECT_EQ(w.drift->inputs.size(), 18u);  // 13 sensors, 5 duty signals
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
  EXPECT_EQ(back.blank_param, 95);  // the grey box's blank latch (drift.blank_param)
  EXPECT_EQ(back.drift_alive_param, 100);
  EXPECT_EQ(back.drift_missing_alarm, combined.drift_missing_alarm);
  // A plan JSON from before the liveness check (drift_marker_r, no drift_alive_param) still loads.
  j.erase("drift_alive_param");
  j.erase("workpiece_slope_param");
  j.erase("blank_param");
  j["workpiece_k0_param"] = -1;
  j["drift_marker_r"] = -1;
  EXPECT_NO_THROW(j.get<PlanOptions>());
}

const fs::path kExample = fs::path(WHIRL_SOURCE_DIR) / "datasets/machines/example_840d.json";

TEST(MachineProfile, ShippedProfilesStateTheControlsLimits) {
  for (const fs::path& path : {kShipped, kExample}) {
    const MachineProfile m = LoadMachineProfile(path);
    EXPECT_EQ(m.schema_version, 2);
    ASSERT_TRUE(m.control.Stated()) << path;
    ASSERT_TRUE(m.drift);
    for (const auto& [name, a] : m.drift->inputs)
      EXPECT_LE(a.index, m.control.analog_inputs) << name;
    EXPECT_LT(m.drift->param_last, m.control.ac_params);
    EXPECT_GE(m.start_alarm, kUserAlarmFirst);
    EXPECT_NO_THROW(testing::UseProfileEverywhere(m)) << path;
  }
  EXPECT_EQ(LoadMachineProfile(kExample).control.analog_inputs, 8);
}

// A profile of schema version 1 (the example as shipped before the control's limits were stated)
// still loads, with the documented defaults, and every command accepts it.
TEST(MachineProfile, Version1LoadsWithTheDocumentedDefaults) {
  const MachineProfile v1 =
      LoadMachineProfile(fs::path(WHIRL_SOURCE_DIR) / "tests/interp/data/example_840d_v1.json");
  EXPECT_EQ(v1.schema_version, 1);
  EXPECT_FALSE(v1.control.Stated());
  ASSERT_TRUE(v1.drift);
  EXPECT_EQ(v1.start_alarm, v1.drift->missing_alarm + 4);
  EXPECT_EQ(v1.drift->param_last, 9999) << "no workpiece slot above param_first";
  EXPECT_EQ(v1.drift->inputs.size(), 16u);
  EXPECT_NO_THROW(testing::UseProfileEverywhere(v1));
}

// The sections against each other and the control's limits: each contradiction that one command
// accepted and another refused, or that no command checked, is refused at load, naming the key.
TEST(MachineProfile, CrossChecksAndBoundsAreRefusedByName) {
  // Workpiece slots inside the drift action's own $AC_PARAM range.
  ExpectRefused([](J& j) { j["drift"]["workpiece_k0_param"] = 101; }, "workpiece_k0_param");
  ExpectRefused([](J& j) { j["drift"]["workpiece_slope_param"] = 250; }, "workpiece_slope_param");
  // Ranges too small for the smallest program.
  ExpectRefused([](J& j) { j["drift"]["sync_id_last"] = 201; }, "sync_id_last");
  ExpectRefused([](J& j) { j["drift"]["param_last"] = 103; }, "param_last");
  ExpectRefused([](J& j) { j["sync_id_last"] = 100; }, "sync_id_last");
  // Alarms: only the user cycle alarms, each number once.
  for (int alarm : {60000, 62000, 64999, 69997})
    ExpectRefused([&](J& j) { j["drift"]["missing_alarm"] = alarm; }, "missing_alarm");
  ExpectRefused([](J& j) { j["start_alarm"] = 64000; }, "start_alarm");
  ExpectRefused([](J& j) { j["start_alarm"] = 65003; }, "start_alarm");
  // Physical bounds.
  ExpectRefused([](J& j) { j["drift"]["analog_inputs"]["ambient_C"]["scale"] = 1e-12; }, "scale");
  ExpectRefused([](J& j) { j["drift"]["analog_inputs"]["ambient_C"]["offset"] = -1e9; },
                "offset");
  ExpectRefused([](J& j) { j["drift"]["ipo_cycle_ms"] = 1e-9; }, "ipo_cycle_ms");
  ExpectRefused([](J& j) { j["machine_offset_mm"] = 1e308; }, "machine_offset_mm");
  ExpectRefused([](J& j) { j["drift"]["slope"]["fixed_end_position_mm"] = 2e5; },
                "fixed_end_position_mm");
  // The control's own limits: analog inputs (MD10300), $AC_PARAM (MD28254), elements (MD28250).
  ExpectRefused([](J& j) { j["control"]["md10300_analog_inputs"] = 8; }, "MD10300");
  ExpectRefused([](J& j) { j["drift"]["analog_inputs"]["cabinet_C"]["index"] = 19; }, "MD10300");
  ExpectRefused([](J& j) { j["control"]["md28254_ac_params"] = 250; }, "MD28254");
  ExpectRefused([](J& j) { j["control"]["md28250_sync_elements"] = 50; }, "MD28250");
  ExpectRefused([](J& j) { j["control"]["md10300_analog_inputs"] = 1000; }, "MD10300");
  // Version 2 states them; version 1 may not claim version 2's keys half-way.
  ExpectRefused([](J& j) { j.erase("control"); }, "control");
  ExpectRefused([](J& j) { j.erase("start_alarm"); }, "start_alarm");
  ExpectRefused([](J& j) { j["drift"].erase("param_last"); }, "param_last");
  ExpectRefused([](J& j) { j["schema_version"] = 3; }, "schema_version");
  // A slope object beside a plan that keeps SD43910: two writers.
  ExpectRefused([](J& j) { j["drift"].erase("workpiece_slope_param"); }, "workpiece_slope_param");
}

// Issue 45 item 3: no value in a profile switches the checks of the control's limits off. -1 in
// control.md10300_analog_inputs once meant "not stated" and let MD28250 = 5 and MD28254 = 50
// through although the programs need far more; each machine datum is now checked where it is
// read, and every slot bound (param_last) and optional slot is a real slot or absent.
TEST(MachineProfile, NoProfileValueSwitchesTheControlChecksOff) {
  ExpectRefused(
      [](J& j) {
        j["control"]["md10300_analog_inputs"] = -1;
        j["control"]["md28250_sync_elements"] = 5;
        j["control"]["md28254_ac_params"] = 50;
      },
      "MD10300");
  for (const char* key : {"md10300_analog_inputs", "md28250_sync_elements", "md28254_ac_params"})
    for (double v : {-1.0, -1000.0, 0.5, 1e9})
      ExpectRefused([&](J& j) { j["control"][key] = v; }, key);
  ExpectRefused([](J& j) { j["control"]["md28250_sync_elements"] = 0; }, "MD28250");
  ExpectRefused([](J& j) { j["control"]["md28254_ac_params"] = 0; }, "MD28254");
  // With MD10300 stated, MD28250 and MD28254 below what the ranges need are refused by name.
  ExpectRefused([](J& j) { j["control"]["md28250_sync_elements"] = 5; }, "MD28250");
  ExpectRefused([](J& j) { j["control"]["md28254_ac_params"] = 50; }, "MD28254");
  for (const char* key : {"param_last", "workpiece_k0_param", "workpiece_slope_param"})
    ExpectRefused([&](J& j) { j["drift"][key] = -1; }, key);
}

// One validation for every command: random edits of the shipped profiles either are refused at
// load (an InputError naming the file) or are accepted by every use (plan, combined plan, drift
// programs with the smallest models, resets, PLC tables).
TEST(MachineProfile, AProfileThatLoadsIsAcceptedByEveryCommand) {
  std::mt19937 rng(2601);
  const std::vector<std::vector<std::string>> keys = {
      {"sync_id_first"}, {"sync_id_last"}, {"save_r_first"}, {"start_alarm"},
      {"machine_offset_mm"}, {"md32760"}, {"control", "md10300_analog_inputs"},
      {"control", "md28250_sync_elements"}, {"control", "md28254_ac_params"},
      {"drift", "sync_id_first"}, {"drift", "sync_id_last"}, {"drift", "param_first"},
      {"drift", "param_last"}, {"drift", "save_r_first"}, {"drift", "ipo_cycle_ms"},
      {"drift", "workpiece_k0_param"}, {"drift", "workpiece_slope_param"},
      {"drift", "missing_alarm"}, {"drift", "analog_inputs", "ambient_C", "index"},
      {"drift", "analog_inputs", "ambient_C", "scale"}};
  const std::vector<double> values = {-1, 0,   1,    2,    3,     8,     13,    80,     89,    95,
                                      97,  98,   99,   100,   101,   103,   107,    140,   149,
                                      150, 199,  200,  201,   202,   205,   240,    250,   255,
                                      256, 299,  300,  1e-6,  1e-7,  0.05,  65000,  65003, 65004,
                                      64999, 69996, 69999, 9995, 9999, 1e5, -1e5, 2e5};
  int loaded = 0, refused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const fs::path base = trial % 2 ? kShipped : kExample;
    nlohmann::json j = ReadJsonFile(base);
    for (int e = 0; e < 1 + static_cast<int>(rng() % 3); ++e) {
      const auto& key = keys[rng() % keys.size()];
      nlohmann::json* node = &j;
      for (const std::string& k : key) {
        if (!node->contains(k)) break;
        node = &(*node)[k];
      }
      if (node->is_number()) *node = values[rng() % values.size()];
    }
    const fs::path p = whirl::test::ScratchDir() / "whirl_profile_random.json";
    std::ofstream(p) << j.dump(2);
    MachineProfile m;
    try {
      m = LoadMachineProfile(p);
    } catch (const InputError& err) {
      ++refused;
      EXPECT_NE(std::string(err.what()).find("whirl_profile_random.json"), std::string::npos)
          << err.what();
      continue;
    }
    ++loaded;
    try {
      testing::UseProfileEverywhere(m);
    } catch (const InputError& err) {
      ADD_FAILURE() << "loaded, then refused by a command: " << err.what() << "\n" << j.dump();
    }
  }
  EXPECT_GT(loaded, 50);
  EXPECT_GT(refused, 50);
}

}  // namespace
}  // namespace whirl::interp
