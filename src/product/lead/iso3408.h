#pragma once
// ISO 3408-3 (JIS B 1192, GB/T 17587.3) lead-accuracy classes: the tolerance table, loaded from one
// data file (datasets/standards/iso3408_3_lead_tolerances.csv), and the best class a lead-deviation
// curve reaches (datasets/standards/README.md). CAVEAT: only some cells of the table are confirmed
// by a source (flags in the file); the rest are recalled values. Treat a verdict as indicative.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lead/metrics.h"

namespace whirl::lead {

/// Classes in order from the tightest to the loosest. kNone = no class holds.
enum class IsoClass { kP1, kP3, kP5, kT7, kT10, kNone };

std::string ToString(IsoClass c);                   ///< "P1", "P3", "P5", "T7", "T10", "none"
IsoClass IsoClassFromString(const std::string& s);  ///< inverse; InputError otherwise

/// The tolerances of one class at one useful travel, um. An unset optional = not specified for the
/// class (T7/T10 have no v_up and no v_2pi; their e_p is derived as (l_u/300) v_300p).
struct IsoTolerances {
  IsoClass iso_class = IsoClass::kNone;
  double e_p_um = 0;                 ///< +- tolerance on e_a, um
  std::optional<double> v_up_um;     ///< band width over l_u, um
  double v_300p_um = 0;              ///< band width within any 300 mm, um
  std::optional<double> v_2pi_p_um;  ///< band width within one revolution, um
  bool all_cells_confirmed = false;  ///< every cell used was confirmed by a source
};

/// One row of the data file: a class over a range (lu_min_mm, lu_max_mm] of useful travel.
struct IsoToleranceRow {
  IsoClass iso_class = IsoClass::kNone;
  double lu_min_mm = 0, lu_max_mm = 0;
  double e_p_um = -1, v_up_um = -1, v_300p_um = -1,
         v_2pi_p_um = -1;  ///< -1 = not specified/derived
  bool confirmed_e_p = false, confirmed_v_up = false, confirmed_v_300p = false,
       confirmed_v_2pi_p = false;
};

struct IsoToleranceTable {
  std::string source;
  std::vector<IsoToleranceRow> rows;
  std::vector<std::string> comments;  ///< the file's '#' lines (provenance and caveat)

  /// Tolerances of `c` at useful travel `useful_travel_mm`; nullopt if the table has no row for it
  /// (e.g. P1 beyond 6300 mm): the class cannot be reached at that length.
  std::optional<IsoTolerances> Lookup(IsoClass c, double useful_travel_mm) const;
};

/// Reads the table. Rejects (InputError naming file, line and column): missing columns, an unknown
/// class number, lu_max <= lu_min, negative tolerances other than the -1 marker, a missing
/// v_300p, a P class with a -1 in e_p/v_up/v_2pi_p, flags other than 0/1, and overlapping or
/// gapped l_u ranges within a class (each class must start at 0 and be contiguous).
IsoToleranceTable ReadIsoToleranceTable(const std::filesystem::path& path);

/// The check of one tolerance: metric, actual, permitted, passed.
struct IsoCheck {
  std::string metric;  ///< "e_a", "v_u", "v_300", "v_2pi"
  double actual_um = 0;
  double permitted_um = 0;
  bool passed = false;
};

struct IsoVerdict {
  IsoClass reached = IsoClass::kNone;  ///< the tightest class whose every applicable check holds
  std::vector<IsoCheck> checks;        ///< the checks of the reached class (of T10 if none)
  bool v_2pi_evaluated = false;        ///< false: v_2pi was unknown and left out of the P checks
  bool table_cells_confirmed = false;  ///< every cell behind the verdict is confirmed
  std::string message;                 ///< e.g. "P5 (e_a 12.3 <= 170, v_u ...); P3 fails v_300 ..."
};

/// The tightest class of P1, P3, P5, T7, T10 whose applicable tolerances all hold for `metrics`:
/// |e_a| <= e_p, v_u <= v_up, v_300 <= v_300p, v_2pi <= v_2pi_p (left out if v_2pi is unknown).
/// The target travel compensation c of ISO 3408-3 is taken as 0 (the specified lead is nominal).
IsoVerdict EvaluateIsoClass(const LeadMetrics& metrics, const IsoToleranceTable& table);

void to_json(nlohmann::json& j, const IsoCheck& c);
void to_json(nlohmann::json& j, const IsoVerdict& v);

}  // namespace whirl::lead
