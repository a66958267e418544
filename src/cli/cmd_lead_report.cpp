// whirl lead-report: metrics and ISO 3408-3 class of a measured (or simulated) lead-deviation CSV.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/common.h"
#include "lead/iso3408.h"
#include "lead/lead.h"
#include "lead/metrics.h"

namespace whirl::cli {
namespace {

struct LeadReportOptions {
  std::string lead_csv;
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  double lead_mm = 0;
  double end_margin_mm = 0;
  bool json = false;
};

void RunLeadReport(const LeadReportOptions& o) {
  const lead::LeadDeviation lead = lead::ReadLeadDeviation(o.lead_csv);
  lead::CheckEndMargin(lead, o.end_margin_mm, "--end-margin-mm");  // named by its flag
  lead::LeadMetricOptions mo;
  mo.lead_mm = o.lead_mm;
  mo.end_margin_mm = o.end_margin_mm;
  const lead::LeadMetrics m = lead::ComputeLeadMetrics(lead, mo);
  const lead::IsoToleranceTable table = lead::ReadIsoToleranceTable(o.iso_table);
  const lead::IsoVerdict v = lead::EvaluateIsoClass(m, table);
  if (!m.v_2pi_um)  // the class is then graded without one of its tolerances
    Warn(std::string("v_2pi not evaluated (") +
         (o.lead_mm > 0 ? "the samples are coarser than half a lead"
                        : "give --lead-mm, the screw's lead") +
         "): the ISO 3408-3 class is checked without it");
  if (o.json) {
    PrintJson({{"schema", "whirl.lead_report"},
               {"schema_version", 1},
               {"lead_csv", o.lead_csv},
               {"iso_table", o.iso_table},
               {"metrics", m},
               {"iso", v}});
    return;
  }
  std::printf("lead deviation: %s (%zu points, %.1f..%.1f mm)\n", o.lead_csv.c_str(), lead.size(),
              lead.position_mm.front(), lead.position_mm.back());
  std::printf("  useful travel l_u                      %10.1f mm (from %.1f mm)\n",
              m.useful_travel_mm, m.useful_start_mm);
  std::printf("  accumulated error within any 1000 mm   %10.2f um\n", m.accumulated_1000_um);
  std::printf("  accumulated error over l_u (max-min)   %10.2f um\n", m.accumulated_total_um);
  std::printf("  e_a  mean travel deviation             %10.2f um\n", m.e_a_um);
  std::printf("  v_u  band over l_u                     %10.2f um\n", m.v_u_um);
  std::printf("  v_300 band within 300 mm               %10.2f um\n", m.v_300_um);
  if (m.v_2pi_um)
    std::printf("  v_2pi band within one revolution       %10.2f um\n", *m.v_2pi_um);
  else
    std::printf("  v_2pi band within one revolution       not evaluated (%s)\n",
                o.lead_mm > 0 ? "samples coarser than half a lead" : "give --lead-mm");
  std::printf("ISO 3408-3 class reached: %s\n  %s\n", lead::ToString(v.reached).c_str(),
              v.message.c_str());
  if (!v.table_cells_confirmed && v.reached != lead::IsoClass::kNone)
    std::printf(
        "  note: some tolerance cells behind this verdict are recalled, not confirmed "
        "(see %s)\n",
        o.iso_table.c_str());
}

}  // namespace

void RegisterLeadReport(CLI::App& app) {
  auto o = std::make_shared<LeadReportOptions>();
  auto* sub = app.add_subcommand(
      "lead-report",
      "Lead-accuracy metrics of a lead-deviation curve and the ISO 3408-3 class it reaches.\n"
      "Input: CSV with columns position_mm (along the thread from its start, strictly increasing)\n"
      "and deviation_um (travel deviation = actual minus specified travel, um); '#' comments ok.\n"
      "Prints (um): accumulated error within any 1000 mm and over the useful travel (max - min of\n"
      "the deviation), e_a (mean travel deviation from the least-squares mean travel line), v_u,\n"
      "v_300 and v_2pi (band widths about that line over l_u, any 300 mm, one revolution), and\n"
      "the tightest class of P1, P3, P5, T7, T10 whose every tolerance holds.\n"
      "Limits (an error beyond them): |position_mm| <= 1e6 mm, positions >= 1e-6 mm apart,\n"
      "|deviation_um| <= 1e6 um.");
  sub->add_option("--lead", o->lead_csv, "measured lead-deviation CSV (position_mm,deviation_um)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--lead-mm", o->lead_mm,
                  "lead of the screw (one revolution of travel), mm; needed for v_2pi "
                  "(default 0: v_2pi not evaluated and left out of the class check)")
      ->check(NonNegativeNumber());
  sub->add_option("--end-margin-mm", o->end_margin_mm,
                  "excess travel l_e left out at each end, mm: l_u = length - 2 l_e (default 0)")
      ->check(NonNegativeNumber("mm"));
  sub->add_option("--iso-table", o->iso_table,
                  "ISO 3408-3 tolerance table CSV (default: the shipped "
                  "datasets/standards/iso3408_3_lead_tolerances.csv)")
      ->check(CLI::ExistingFile);
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { RunLeadReport(*o); });
}

}  // namespace whirl::cli
