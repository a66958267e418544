// The machine report's plots (machine_eval/machine_report.h): every strategy of both comparisons
// has its own look in the one style table (core/plot_style.h), the sensor plot has at most 8 lines
// per panel and every sensor once, and the lead plot ends at the thread's end.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "compare/compare.h"
#include "core/atomic_file.h"
#include "core/plot_style.h"
#include "machine/machine.h"
#include "machine_eval/machine_report.h"
#include "support/scratch_dir.h"

namespace whirl::machine_eval {
namespace {

TEST(ReportStyle, EveryStrategyHasItsOwnEntryInTheStyleTable) {
  for (compare::Strategy s : compare::kStrategies)
    EXPECT_NE(FindSeriesStyle(compare::ToString(s)), nullptr)
        << compare::ToString(s) << ": add it to core/plot_style.cpp";
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    const std::string name = ToString(static_cast<MachineStrategy>(k));
    EXPECT_NE(FindSeriesStyle(name), nullptr) << name << ": add it to core/plot_style.cpp";
  }
}

TEST(MachineReport, SensorPanelsHoldAtMostEightLinesAndLeadEndsAtTheThread) {
  MachineEvalScrew r;
  r.ok = true;
  r.screw = screw::ReferenceScrew();
  MachineScrewDetail d;
  const machine::MachineConfig c = machine::DefaultMachine();
  d.log = machine::SimulateRun(machine::MachineDay::Draw(c, 1, 1),
                               {"log", drift::RunState::kCutting, 20, 180, 1});
  const std::size_t sensors = d.log.sensor_names.size();
  ASSERT_GT(sensors, 8u);
  for (auto& l : d.leads) {
    l.position_mm = {0, 1000, r.screw.thread_length_mm};
    l.deviation_um = {0, 0.5, 1};
  }
  const std::filesystem::path dir = whirl::test::ScratchDir() /
                                    ("whirl_machine_report_plots_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  WriteMachineScrewReport(dir.string(), r, d, {d.log.sensor_names[0]}, {});
  // sensors.gp: one plot command per panel; columns 2..sensors+1 once each.
  std::istringstream gp(ReadTextFile(dir / "sensors.gp"));
  std::multiset<std::string> columns;
  int panels = 0;
  for (std::string line; std::getline(gp, line);) {
    if (line.rfind("plot ", 0) != 0) continue;
    ++panels;
    int lines = 0;
    for (std::size_t at = line.find("using 1:"); at != std::string::npos;
         at = line.find("using 1:", at + 1), ++lines)
      columns.insert(line.substr(at + 8, line.find(' ', at + 8) - at - 8));
    EXPECT_LE(lines, 8) << line;
  }
  EXPECT_EQ(panels, static_cast<int>((sensors + 7) / 8));  // the default machine packs tightly
  EXPECT_EQ(columns.size(), sensors);
  for (std::size_t s = 0; s < sensors; ++s) EXPECT_EQ(columns.count(std::to_string(s + 2)), 1u);
  // lead.gp: x from the thread start to its end; every strategy in its style.
  const std::string lead = ReadTextFile(dir / "lead.gp");
  EXPECT_NE(lead.find("set xrange [0:" + std::to_string(r.screw.thread_length_mm) + "]"),
            std::string::npos)
      << lead;
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    EXPECT_NE(lead.find(GnuplotWith(ToString(static_cast<MachineStrategy>(k)))), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace whirl::machine_eval
