#pragma once
// Thermal drift of the spindle from ball-bar readings (Shang et al., eq. 18), with its uncertainty.
//
// Files.
// - Readings CSV, header `time_min,pivot,length_mm` and optionally `bar_temperature_C`, one row per
//   reading, '#' lines are comments:
//     time_min            time of the reading from the start of the warm-up, min (non-decreasing)
//     pivot               1, 2 or 3: the pivot ball the bar ran to
//     length_mm           centre-to-centre bar length, mm (0 < L <= kMaxBarLengthMm)
//     bar_temperature_C   the bar's temperature at the reading, degC (-20..60)
//   At most kMaxReadings rows. Readings are grouped into blocks (one measurement of the tool ball's
//   position): a new block starts where the time since the previous reading exceeds
//   `block_gap_min`. Every block needs at least one reading of each pivot. The first block is the
//   cold reference. Take the readings of a block in a palindromic order (1 2 3 3 2 1): then every
//   pivot's mean reading time is the block's mean time and a drift linear in time cancels.
// - Pivots JSON: {"schema": "whirl.ballbar.pivots", "schema_version": 1,
//                 "pivots_mm": [[x, y, z], [x, y, z], [x, y, z]]}: B1, B2, B3 in MCS, mm.
//
// Per block (eqs. 11-18 of Shang, Ruan and Zhang, trilateration.h):
//   - bar expansion: the bar's body grows with its temperature, so a warm bar reads short; each
//     reading is corrected to L = L_read (1 + alpha (T - T_ref)), alpha the bar's expansion
//     coefficient (1/K; 12e-6: 1.8 um/K on a 150 mm bar, a typical ball bar's figure), T_ref the
//     temperature at which the bar was calibrated (20 degC, ISO 1);
//   - averaging (eq. 18's mean position): if every pivot has the same number n of readings, the
//     k-th readings of pivots 1, 2, 3 form triplet k, each triplet is trilaterated (eqs. 11-17) and
//     the n positions are averaged, as in the paper; otherwise the lengths of each pivot are
//     averaged and trilaterated once (the two agree to second order in the noise, ~1e-10 mm);
//   - drift (eq. 18): D = P_block - P_cold, per MCS axis, um.
// Uncertainty (beyond the paper), first order through the Jacobian J = J_P_L (trilateration.h):
//   Cov(D) = J_b S_b J_b' + J_0 S_0 J_0' + u_alpha^2 g g',  S = diag(sigma^2 / n_i),
//   g = dD/dalpha = J_b (L_b (T_b - T_ref)) - J_0 (L_0 (T_0 - T_ref))   (per-pivot means),
// sigma the sd of one reading (given, or pooled from the scatter of repeated readings of a pivot
// within blocks after removing the tool ball's motion during the block: L_i changes at u_i . v,
// v the ball's velocity from the neighbouring blocks' positions), u_alpha the sd of alpha.
// Pivot-centre errors cancel to first order in D.
//
// What D is: the tool ball relative to the pivots, i.e. spindle drift relative to the table at the
// pivots. Growth of the table between the pivots is not separated (it changes LB1..LB3 and is read
// as a small drift); measure the pivots' centres cold and keep the pivots close together.
//
// 840D (docs/840d.md; Siemens K3 function manual): the position-independent
// compensation of axis a is SD43900 $SA_TEMP_COMP_ABS_VALUE[a] = s * D_a / 1000 mm with s = -1
// (SignConvention kSubtract, the default: compensation = minus the drift) or +1 (kAdd); D of the
// last block is the current value.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "ballbar/trilateration.h"
#include "interp/sinumerik.h"

namespace whirl::ballbar {

inline constexpr double kMaxBarLengthMm = 2000;  ///< longest accepted bar length, mm
inline constexpr std::size_t kMaxReadings = 1000000;
inline constexpr double kMinBarTemperatureC = -20, kMaxBarTemperatureC = 60;

struct Reading {
  double time_min = 0;
  int pivot = 1;  ///< 1, 2 or 3
  double length_mm = 0;
  std::optional<double> bar_temperature_C;
  int line = 0;  ///< 1-based line in the file
};

struct Readings {
  std::string source;  ///< file name for messages
  std::vector<Reading> rows;
  bool has_bar_temperature = false;
  std::vector<std::string> comments;
};

/// Strict reader (file:line:column errors): the columns above and no others, pivot 1..3, lengths
/// and temperatures in range, time non-decreasing.
Readings ReadReadings(const std::filesystem::path& path);
/// The same from text (`source` names it in messages).
Readings ParseReadings(const std::string& text, const std::string& source);
/// Readings CSV text (header as above; the temperature column if has_bar_temperature).
std::string FormatReadings(const Readings& readings);

/// Pivots JSON file (schema above); InputError naming the file, key and rule.
PivotCentres ReadPivots(const std::filesystem::path& path);
nlohmann::json PivotsToJson(const PivotCentres& pivots_mm);
PivotCentres PivotsFromJson(const nlohmann::json& j, const std::string& what);

struct DriftOptions {
  /// A reading more than this after the previous one starts a new block, min (> 0).
  double block_gap_min = 2.0;
  /// sd of one bar reading, um; 0 = pooled from repeated readings within blocks (then at least
  /// one pivot in one block must have two readings).
  double bar_sd_um = 0;
  /// Correct the bar's expansion when the file has bar_temperature_C.
  bool correct_bar_temperature = true;
  double bar_alpha_per_K = 12e-6;    ///< expansion coefficient of the bar, 1/K (0..50e-6)
  double bar_alpha_sd_per_K = 1e-6;  ///< its sd, 1/K (0 for a calibrated bar)
  double bar_reference_C = 20;       ///< temperature of the bar's calibration, degC
  GeometryLimits limits;
  interp::SignConvention sign = interp::SignConvention::kSubtract;

  void Validate() const;  ///< InputError naming the field, value and rule
};

struct DriftBlock {
  double time_min = 0;  ///< mean time of the block's readings, min
  int first_line = 0, last_line = 0;
  std::array<int, 3> readings{};           ///< count per pivot
  std::string averaging;                   ///< "positions" (eq. 18 triplets) or "lengths"
  Eigen::Vector3d mean_length_mm;          ///< corrected, per pivot
  Eigen::Vector3d mean_bar_temperature_C;  ///< per pivot (T_ref without the column)
  Eigen::Vector3d position_mm;             ///< tool ball, MCS
  Eigen::Vector3d drift_um;                ///< eq. 18, MCS
  Eigen::Vector3d drift_sd_um;             ///< sqrt(diag Cov(D))
};

struct DriftResult {
  std::string source;
  std::vector<DriftBlock> blocks;          ///< the first one is the cold reference (drift 0)
  double bar_sd_um = 0;                    ///< sd used for the uncertainty
  std::string bar_sd_source;               ///< "given" or "pooled from N repeated readings"
  std::optional<double> pooled_bar_sd_um;  ///< estimate from the scatter, when available
  int pooled_dof = 0;
  bool bar_temperature_corrected = false;
  DriftOptions options;
  PlacementAdvice placement;   ///< at the cold block's position
  Eigen::Vector3d sd43900_mm;  ///< s * D_last / 1000 per axis, mm
};

/// Blocks, trilateration, drift and its uncertainty, placement advice, SD43900.
DriftResult ComputeDrift(const Readings& readings, const PivotCentres& pivots_mm,
                         const DriftOptions& options = {});

/// The run file: `time_min,drift_x_um,drift_y_um,drift_z_um` (one row per block, the drift
/// module's run format: time column and error columns ending _um), '#' comment lines first.
std::string FormatDriftCsv(const DriftResult& result, const std::vector<std::string>& comments);

nlohmann::json ToJson(const DriftResult& result);

}  // namespace whirl::ballbar
