#pragma once
// The vocabulary every module shares: the five process parameters of a hard-whirling job
// (network inputs) and the two features of its elongation curve (network targets).
// From Li, Ma and Jiang, "Thermal elongation prediction of whirlwind hard milling
// ballscrew based on BP neural network", section 2.1 (docs/references.md).
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/csv.h"

namespace whirl {

/// Network inputs, in the paper's order. Units are in the names.
struct ProcessInputs {
  double hardness_hrc = 0;         ///< workpiece hardness, HRC (paper range 60-65)
  double diameter_mm = 0;          ///< screw (blank) outer diameter, mm (50-100)
  double pitch_mm = 0;             ///< lead of the thread, mm (6-16)
  double raceway_radius_mm = 0;    ///< ball-groove (raceway) radius, mm (3-10)
  double cutting_speed_m_min = 0;  ///< cutting speed of the whirling tools, m/min (150-210)

  static constexpr int kCount = 5;
  std::array<double, kCount> ToArray() const;
  static ProcessInputs FromArray(const std::array<double, kCount>& a);
};

/// Network targets: the two features of an elongation curve (paper Fig. 2).
struct Features {
  double max_elongation_um = 0;  ///< plateau (maximum) elongation of the unmachined section, um
  double settle_time_s = 0;      ///< time after which the elongation stays on its plateau, s

  static constexpr int kCount = 2;
  std::array<double, kCount> ToArray() const;
  static Features FromArray(const std::array<double, kCount>& a);
};

/// CSV column names, with units, in network order.
extern const std::array<const char*, ProcessInputs::kCount> kInputColumns;
extern const std::array<const char*, Features::kCount> kTargetColumns;
/// Human names with units, for messages and model files ("hardness [HRC]").
extern const std::array<const char*, ProcessInputs::kCount> kInputUnits;
extern const std::array<const char*, Features::kCount> kTargetUnits;

/// A process-parameter table: inputs and (optionally) targets, row-aligned.
struct ProcessTable {
  std::string source;
  std::vector<ProcessInputs> inputs;
  std::vector<Features> targets;  ///< empty when the table has no target columns
  std::vector<int> line_numbers;
  std::vector<std::string> comments;
};

/// Reads a table with header row. The five input columns are required; target columns are
/// required when `require_targets`, otherwise read when both are present. Other columns are
/// ignored. Every row is checked against the physical limits of core/limits.h. Errors
/// (InputError) name the file, line and column.
ProcessTable ReadProcessTable(const std::filesystem::path& path, bool require_targets);

/// Writes inputs (and targets, if non-empty) as CSV with '#' provenance comments, atomically.
void WriteProcessTable(const std::filesystem::path& path, const ProcessTable& table);
/// The CSV text WriteProcessTable writes (for multi-file outputs written all-or-nothing).
std::string FormatProcessTable(const ProcessTable& table);

}  // namespace whirl
