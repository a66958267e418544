#include "ballbar/drift.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"

namespace whirl::ballbar {
namespace {

std::string Where(const CsvTable& t, std::size_t row, const std::string& column) {
  return t.source + ":" + std::to_string(t.line_numbers[row]) + ": column '" + column + "'";
}

Reading ParseRow(const CsvTable& t, std::size_t r, bool has_t) {
  const auto& v = t.rows[r];
  Reading x;
  x.line = t.line_numbers[r];
  x.time_min = v[t.ColumnIndex("time_min")];
  const double pivot = v[t.ColumnIndex("pivot")];
  if (pivot != 1 && pivot != 2 && pivot != 3)
    throw InputError(Where(t, r, "pivot") + ": " + MessageNumber(pivot) + " is not 1, 2 or 3");
  x.pivot = static_cast<int>(pivot);
  x.length_mm = v[t.ColumnIndex("length_mm")];
  if (!(x.length_mm > 0 && x.length_mm <= kMaxBarLengthMm))
    throw InputError(Where(t, r, "length_mm") + ": " + MessageNumber(x.length_mm) +
                     " mm is outside (0, " + MessageNumber(kMaxBarLengthMm) + "] mm");
  if (has_t) {
    const double c = v[t.ColumnIndex("bar_temperature_C")];
    if (!(c >= kMinBarTemperatureC && c <= kMaxBarTemperatureC))
      throw InputError(Where(t, r, "bar_temperature_C") + ": " + MessageNumber(c) +
                       " degC is outside [" + MessageNumber(kMinBarTemperatureC) + ", " +
                       MessageNumber(kMaxBarTemperatureC) + "] degC");
    x.bar_temperature_C = c;
  }
  return x;
}

Readings ReadingsFromTable(const CsvTable& t) {
  const std::string& source = t.source;
  const bool has_t = t.HasColumn("bar_temperature_C");
  for (const auto& name : t.header)
    if (name != "time_min" && name != "pivot" && name != "length_mm" && name != "bar_temperature_C")
      throw InputError(source + ": unknown column '" + name +
                       "' (allowed: time_min, pivot, length_mm, bar_temperature_C)");
  for (const char* need : {"time_min", "pivot", "length_mm"}) t.ColumnIndex(need);
  if (t.rows.size() > kMaxReadings)
    throw InputError(source + ": " + std::to_string(t.rows.size()) + " readings, more than the " +
                     std::to_string(kMaxReadings) + " accepted");
  Readings out;
  out.source = source;
  out.has_bar_temperature = has_t;
  out.comments = t.comments;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    out.rows.push_back(ParseRow(t, r, has_t));
    if (r > 0 && out.rows[r].time_min < out.rows[r - 1].time_min)
      throw InputError(Where(t, r, "time_min") + ": " + MessageNumber(out.rows[r].time_min) +
                       " min after " + MessageNumber(out.rows[r - 1].time_min) +
                       " min (rule: time must not decrease)");
  }
  return out;
}

}  // namespace

Readings ParseReadings(const std::string& text, const std::string& source) {
  return ReadingsFromTable(ParseCsv(text, source));
}

Readings ReadReadings(const std::filesystem::path& path) {
  return ReadingsFromTable(ReadCsv(path));
}

std::string FormatReadings(const Readings& readings) {
  std::vector<std::string> header{"time_min", "pivot", "length_mm"};
  if (readings.has_bar_temperature) header.push_back("bar_temperature_C");
  std::vector<std::vector<double>> rows;
  for (const auto& r : readings.rows) {
    rows.push_back({r.time_min, static_cast<double>(r.pivot), r.length_mm});
    if (readings.has_bar_temperature) rows.back().push_back(r.bar_temperature_C.value_or(0));
  }
  return FormatCsv(header, rows, readings.comments);
}

PivotCentres PivotsFromJson(const nlohmann::json& j, const std::string& what) {
  RejectUnknownKeys(j, {"schema", "schema_version", "pivots_mm", "comment"}, what);
  RequireSchema(j, "whirl.ballbar.pivots", 1, what);
  if (!j.contains("pivots_mm") || !j["pivots_mm"].is_array() || j["pivots_mm"].size() != 3)
    throw InputError(what + ": \"pivots_mm\" must be an array of three [x, y, z] points (mm)");
  PivotCentres p;
  for (int i = 0; i < 3; ++i) {
    const auto& row = j["pivots_mm"][i];
    if (!row.is_array() || row.size() != 3)
      throw InputError(what + ": pivots_mm[" + std::to_string(i) + "] must be [x, y, z] (mm)");
    for (int k = 0; k < 3; ++k) {
      if (!row[k].is_number() || !std::isfinite(row[k].get<double>()) ||
          std::abs(row[k].get<double>()) > 1e5)
        throw InputError(what + ": pivots_mm[" + std::to_string(i) + "][" + std::to_string(k) +
                         "] must be a finite number within +-100000 mm");
      p[i](k) = row[k].get<double>();
    }
  }
  return p;
}

PivotCentres ReadPivots(const std::filesystem::path& path) {
  return PivotsFromJson(ReadJsonFile(path), "pivots file '" + path.string() + "'");
}

nlohmann::json PivotsToJson(const PivotCentres& p) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& b : p) rows.push_back({b.x(), b.y(), b.z()});
  return {{"schema", "whirl.ballbar.pivots"}, {"schema_version", 1}, {"pivots_mm", rows}};
}

void DriftOptions::Validate() const {
  auto bad = [](const std::string& field, double v, const std::string& rule) {
    throw InputError(field + " = " + MessageNumber(v) + ": " + rule);
  };
  if (!(block_gap_min > 0 && block_gap_min <= 1440))
    bad("block_gap_min", block_gap_min, "must be in (0, 1440] min");
  if (!(bar_sd_um >= 0 && bar_sd_um <= 100)) bad("bar_sd_um", bar_sd_um, "must be in [0, 100] um");
  if (!(bar_alpha_per_K >= 0 && bar_alpha_per_K <= 50e-6))
    bad("bar_alpha_per_K", bar_alpha_per_K, "must be in [0, 50e-6] 1/K");
  if (!(bar_alpha_sd_per_K >= 0 && bar_alpha_sd_per_K <= 50e-6))
    bad("bar_alpha_sd_per_K", bar_alpha_sd_per_K, "must be in [0, 50e-6] 1/K");
  if (!(bar_reference_C >= kMinBarTemperatureC && bar_reference_C <= kMaxBarTemperatureC))
    bad("bar_reference_C", bar_reference_C, "must be in [-20, 60] degC");
}

namespace {

struct Block {
  std::size_t begin = 0, end = 0;  // row range
};

std::vector<Block> SplitBlocks(const Readings& r, double gap_min) {
  std::vector<Block> blocks;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    if (i == 0 || r.rows[i].time_min - r.rows[i - 1].time_min > gap_min) blocks.push_back({i, i});
    blocks.back().end = i + 1;
  }
  for (const auto& b : blocks) {
    std::array<int, 3> n{};
    for (std::size_t i = b.begin; i < b.end; ++i) ++n[r.rows[i].pivot - 1];
    for (int p = 0; p < 3; ++p)
      if (n[p] == 0)
        throw InputError(r.source + ":" + std::to_string(r.rows[b.begin].line) + "-" +
                         std::to_string(r.rows[b.end - 1].line) + ": the block at " +
                         MessageNumber(r.rows[b.begin].time_min) + " min has no reading of pivot " +
                         std::to_string(p + 1) +
                         " (rule: every block reads all three pivots; blocks are split where "
                         "readings are more than " +
                         MessageNumber(gap_min) + " min apart)");
  }
  return blocks;
}

// Corrected length and temperature of one reading.
struct Corrected {
  double length_mm, temperature_C, time_min;
};
Corrected Correct(const Reading& x, const DriftOptions& o, bool correct) {
  const double t = x.bar_temperature_C.value_or(o.bar_reference_C);
  const double l =
      correct ? x.length_mm * (1 + o.bar_alpha_per_K * (t - o.bar_reference_C)) : x.length_mm;
  return {l, t, x.time_min};
}

// Per-pivot corrected readings of one block, in file order.
using PivotSeries = std::array<std::vector<Corrected>, 3>;

PivotSeries Gather(const Readings& r, const Block& b, const DriftOptions& o, bool correct) {
  PivotSeries s;
  for (std::size_t i = b.begin; i < b.end; ++i)
    s[r.rows[i].pivot - 1].push_back(Correct(r.rows[i], o, correct));
  return s;
}

std::string BlockWhere(const Readings& r, const Block& b) {
  return r.source + ":" + std::to_string(r.rows[b.begin].line) + "-" +
         std::to_string(r.rows[b.end - 1].line) + " (block at " +
         MessageNumber(r.rows[b.begin].time_min) + " min)";
}

DriftBlock Measure(const Readings& r, const Block& b, const PivotFrame& frame,
                   const PivotSeries& s) {
  DriftBlock d;
  d.first_line = r.rows[b.begin].line;
  d.last_line = r.rows[b.end - 1].line;
  for (std::size_t i = b.begin; i < b.end; ++i) d.time_min += r.rows[i].time_min;
  d.time_min /= static_cast<double>(b.end - b.begin);
  for (int p = 0; p < 3; ++p) {
    d.readings[p] = static_cast<int>(s[p].size());
    double l = 0, t = 0;
    for (const auto& c : s[p]) l += c.length_mm, t += c.temperature_C;
    d.mean_length_mm(p) = l / d.readings[p];
    d.mean_bar_temperature_C(p) = t / d.readings[p];
  }
  try {
    if (d.readings[0] == d.readings[1] && d.readings[1] == d.readings[2]) {
      d.averaging = "positions";
      d.position_mm.setZero();
      for (int k = 0; k < d.readings[0]; ++k)
        d.position_mm +=
            Trilaterate(frame, {s[0][k].length_mm, s[1][k].length_mm, s[2][k].length_mm});
      d.position_mm /= d.readings[0];
    } else {
      d.averaging = "lengths";
      d.position_mm = Trilaterate(frame, d.mean_length_mm);
    }
  } catch (const InputError& e) {
    throw InputError(BlockWhere(r, b) + ": " + e.what());
  }
  return d;
}

// Velocity of the tool ball at block i (mm/min) from the neighbouring blocks' positions.
Eigen::Vector3d Velocity(const std::vector<DriftBlock>& b, std::size_t i) {
  if (b.size() < 2) return Eigen::Vector3d::Zero();
  const std::size_t lo = i == 0 ? 0 : i - 1, hi = i + 1 < b.size() ? i + 1 : i;
  return (b[hi].position_mm - b[lo].position_mm) / (b[hi].time_min - b[lo].time_min);
}

// Pooled within-(block, pivot) scatter of the corrected lengths after removing the tool ball's
// motion within the block (rate of L_i = u_i . v): sum of squares (mm^2) and dof.
void Pool(const PivotSeries& s, const PivotFrame& f, const DriftBlock& d, const Eigen::Vector3d& v,
          double* ss_mm2, int* dof) {
  for (int p = 0; p < 3; ++p) {
    const auto& series = s[p];
    if (series.size() < 2) continue;
    const double rate = (d.position_mm - f.pivots_mm[p]).normalized().dot(v);
    std::vector<double> l;
    double mean = 0;
    for (const auto& c : series) {
      l.push_back(c.length_mm - rate * (c.time_min - d.time_min));
      mean += l.back() / static_cast<double>(series.size());
    }
    for (double x : l) *ss_mm2 += (x - mean) * (x - mean);
    *dof += static_cast<int>(series.size()) - 1;
  }
}

// Covariance (mm^2) of the block's position from bar noise, and dP/dalpha (mm per 1/K).
struct Sensitivity {
  Eigen::Matrix3d cov_mm2;
  Eigen::Vector3d dp_dalpha_mm;
};
Sensitivity Sense(const PivotFrame& frame, const DriftBlock& d, double sd_mm, const DriftOptions& o,
                  bool corrected) {
  const Eigen::Matrix3d j = PositionJacobian(frame.pivots_mm, d.position_mm);
  Eigen::Vector3d var;
  for (int p = 0; p < 3; ++p) var(p) = sd_mm * sd_mm / d.readings[p];
  Sensitivity s;
  s.cov_mm2 = j * var.asDiagonal() * j.transpose();
  const Eigen::Vector3d dl =
      corrected ? Eigen::Vector3d(d.mean_length_mm.array() *
                                  (d.mean_bar_temperature_C.array() - o.bar_reference_C))
                : Eigen::Vector3d::Zero();
  s.dp_dalpha_mm = j * dl;
  return s;
}

}  // namespace

DriftResult ComputeDrift(const Readings& readings, const PivotCentres& pivots_mm,
                         const DriftOptions& o) {
  o.Validate();
  if (readings.rows.empty()) throw InputError(readings.source + ": no readings");
  const PivotFrame frame = MakePivotFrame(pivots_mm, o.limits);
  DriftResult res;
  res.source = readings.source;
  res.options = o;
  res.bar_temperature_corrected = readings.has_bar_temperature && o.correct_bar_temperature;
  const std::vector<Block> blocks = SplitBlocks(readings, o.block_gap_min);
  std::vector<PivotSeries> series;
  for (const Block& b : blocks) {
    series.push_back(Gather(readings, b, o, res.bar_temperature_corrected));
    res.blocks.push_back(Measure(readings, b, frame, series.back()));
  }
  double ss = 0;
  for (std::size_t i = 0; i < blocks.size(); ++i)
    Pool(series[i], frame, res.blocks[i], Velocity(res.blocks, i), &ss, &res.pooled_dof);
  if (res.pooled_dof > 0) res.pooled_bar_sd_um = 1000 * std::sqrt(ss / res.pooled_dof);
  if (o.bar_sd_um > 0) {
    res.bar_sd_um = o.bar_sd_um;
    res.bar_sd_source = "given";
  } else if (res.pooled_bar_sd_um) {
    res.bar_sd_um = *res.pooled_bar_sd_um;
    res.bar_sd_source =
        "pooled from repeated readings (" + std::to_string(res.pooled_dof) + " degrees of freedom)";
  } else {
    throw InputError(readings.source +
                     ": no pivot was read twice within a block, so the bar's noise cannot be "
                     "estimated: give the sd of one reading (bar_sd_um, --bar-sd-um)");
  }
  const DriftBlock& cold = res.blocks.front();
  const Sensitivity s0 = Sense(frame, cold, res.bar_sd_um / 1000, o, res.bar_temperature_corrected);
  for (std::size_t i = 0; i < res.blocks.size(); ++i) {
    DriftBlock& d = res.blocks[i];
    d.drift_um = 1000 * (d.position_mm - cold.position_mm);
    if (i == 0) {
      d.drift_sd_um.setZero();
      continue;
    }
    const Sensitivity s = Sense(frame, d, res.bar_sd_um / 1000, o, res.bar_temperature_corrected);
    const Eigen::Vector3d g = s.dp_dalpha_mm - s0.dp_dalpha_mm;
    const Eigen::Matrix3d cov =
        s.cov_mm2 + s0.cov_mm2 + o.bar_alpha_sd_per_K * o.bar_alpha_sd_per_K * g * g.transpose();
    d.drift_sd_um = 1000 * cov.diagonal().cwiseSqrt();
  }
  res.placement = AdvisePlacement(frame, cold.position_mm);
  res.sd43900_mm = interp::SignFactor(o.sign) * res.blocks.back().drift_um / 1000;
  return res;
}

std::string FormatDriftCsv(const DriftResult& r, const std::vector<std::string>& comments) {
  std::vector<std::vector<double>> rows;
  for (const auto& b : r.blocks)
    rows.push_back({b.time_min, b.drift_um.x(), b.drift_um.y(), b.drift_um.z()});
  return FormatCsv({"time_min", "drift_x_um", "drift_y_um", "drift_z_um"}, rows, comments);
}

namespace {
nlohmann::json XyzJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

nlohmann::json ToJson(const DriftResult& r) {
  nlohmann::json blocks = nlohmann::json::array();
  for (const auto& b : r.blocks)
    blocks.push_back({{"time_min", b.time_min},
                      {"lines", {b.first_line, b.last_line}},
                      {"readings_per_pivot", b.readings},
                      {"averaging", b.averaging},
                      {"mean_length_mm", XyzJson(b.mean_length_mm)},
                      {"mean_bar_temperature_C", XyzJson(b.mean_bar_temperature_C)},
                      {"position_mm", XyzJson(b.position_mm)},
                      {"drift_um", XyzJson(b.drift_um)},
                      {"drift_sd_um", XyzJson(b.drift_sd_um)}});
  const auto& p = r.placement;
  nlohmann::json j = {
      {"schema", "whirl.ballbar.drift"},
      {"schema_version", 1},
      {"readings", r.source},
      {"axes", {"X", "Y", "Z"}},
      {"bar_sd_um", r.bar_sd_um},
      {"bar_sd_source", r.bar_sd_source},
      {"pooled_bar_sd_um", r.pooled_bar_sd_um ? nlohmann::json(*r.pooled_bar_sd_um) : nullptr},
      {"bar_temperature_corrected", r.bar_temperature_corrected},
      {"bar_alpha_per_K", r.options.bar_alpha_per_K},
      {"bar_alpha_sd_per_K", r.options.bar_alpha_sd_per_K},
      {"bar_reference_C", r.options.bar_reference_C},
      {"block_gap_min", r.options.block_gap_min},
      {"placement",
       {{"condition_number", p.condition_number},
        {"noise_gain", XyzJson(p.noise_gain)},
        {"height_mm", p.height_mm},
        {"mean_radius_mm", p.mean_radius_mm},
        {"ideal_height_mm", p.ideal_height_mm},
        {"ideal_radius_mm", p.ideal_radius_mm},
        {"rating", p.rating},
        {"advice", p.advice}}},
      {"blocks", blocks},
      {"sinumerik",
       {{"sign", interp::ToString(r.options.sign)},
        {"rule", "SD43900[axis] = s * drift_um / 1000 with s = -1 (subtract) or +1 (add)"},
        {"time_min", r.blocks.back().time_min},
        {"sd43900_mm",
         {{"X", r.sd43900_mm.x()}, {"Y", r.sd43900_mm.y()}, {"Z", r.sd43900_mm.z()}}}}}};
  return j;
}

}  // namespace whirl::ballbar
