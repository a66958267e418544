#include "core/process.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/limits.h"

namespace whirl {

const std::array<const char*, ProcessInputs::kCount> kInputColumns = {
    "hardness_hrc", "diameter_mm", "pitch_mm", "raceway_radius_mm", "cutting_speed_m_min"};
const std::array<const char*, Features::kCount> kTargetColumns = {"max_elongation_um",
                                                                  "settle_time_s"};
const std::array<const char*, ProcessInputs::kCount> kInputUnits = {"HRC", "mm", "mm", "mm",
                                                                    "m/min"};
const std::array<const char*, Features::kCount> kTargetUnits = {"um", "s"};

std::array<double, ProcessInputs::kCount> ProcessInputs::ToArray() const {
  return {hardness_hrc, diameter_mm, pitch_mm, raceway_radius_mm, cutting_speed_m_min};
}

ProcessInputs ProcessInputs::FromArray(const std::array<double, kCount>& a) {
  return {a[0], a[1], a[2], a[3], a[4]};
}

std::array<double, Features::kCount> Features::ToArray() const {
  return {max_elongation_um, settle_time_s};
}

Features Features::FromArray(const std::array<double, kCount>& a) { return {a[0], a[1]}; }

ProcessTable ReadProcessTable(const std::filesystem::path& path, bool require_targets) {
  const CsvTable csv = ReadCsv(path);
  ProcessTable t;
  t.source = csv.source;
  t.line_numbers = csv.line_numbers;
  t.comments = csv.comments;
  std::array<std::size_t, ProcessInputs::kCount> in_idx{};
  for (int i = 0; i < ProcessInputs::kCount; ++i) in_idx[i] = csv.ColumnIndex(kInputColumns[i]);
  const bool has_targets = csv.HasColumn(kTargetColumns[0]) || csv.HasColumn(kTargetColumns[1]);
  const bool read_targets = require_targets || has_targets;
  std::array<std::size_t, Features::kCount> out_idx{};
  if (read_targets)
    for (int k = 0; k < Features::kCount; ++k) out_idx[k] = csv.ColumnIndex(kTargetColumns[k]);
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    const auto& row = csv.rows[r];
    const std::string where = csv.source + ":" + std::to_string(csv.line_numbers[r]);
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = row[in_idx[i]];
    t.inputs.push_back(ProcessInputs::FromArray(a));
    CheckProcessInputs(t.inputs.back(), where);
    if (read_targets) {
      std::array<double, Features::kCount> b{};
      for (int k = 0; k < Features::kCount; ++k) b[k] = row[out_idx[k]];
      t.targets.push_back(Features::FromArray(b));
      CheckFeatures(t.targets.back(), where);
    }
  }
  return t;
}

void WriteProcessTable(const std::filesystem::path& path, const ProcessTable& table) {
  WriteFileAtomic(path, FormatProcessTable(table));
}

std::string FormatProcessTable(const ProcessTable& table) {
  std::vector<std::string> header(kInputColumns.begin(), kInputColumns.end());
  const bool with_targets = !table.targets.empty();
  if (with_targets) {
    if (table.targets.size() != table.inputs.size())
      throw InputError("WriteProcessTable: inputs and targets differ in length");
    header.insert(header.end(), kTargetColumns.begin(), kTargetColumns.end());
  }
  std::vector<std::vector<double>> rows;
  for (std::size_t r = 0; r < table.inputs.size(); ++r) {
    const auto a = table.inputs[r].ToArray();
    std::vector<double> row(a.begin(), a.end());
    if (with_targets) {
      const auto b = table.targets[r].ToArray();
      row.insert(row.end(), b.begin(), b.end());
    }
    rows.push_back(std::move(row));
  }
  return FormatCsv(header, rows, table.comments);
}

}  // namespace whirl
