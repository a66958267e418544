#include "drift/measurement_file.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::drift {
namespace {

using nlohmann::json;

MeasurementRecord::Kind ParseKind(const std::string& k) {
  if (k == "probe") return MeasurementRecord::Kind::kProbe;
  if (k == "laser") return MeasurementRecord::Kind::kLaser;
  if (k == "lead") return MeasurementRecord::Kind::kLead;
  return MeasurementRecord::Kind::kSetupCheck;  // RequireOneOf has checked the text
}

// The last row of `log` at or before t; InputError outside the log's time span.
int SampleAt(const Run& log, double t, const std::string& where) {
  const std::vector<double>& time = log.time_min;
  if (time.empty() || t < time.front() || t > time.back())
    throw InputError(
        where + ": time_min " + MessageNumber(t) + " lies outside its day log '" + log.source +
        "' (" +
        (time.empty() ? std::string("no rows")
                      : MessageNumber(time.front()) + ".." + MessageNumber(time.back()) + " min") +
        ")");
  return static_cast<int>(std::upper_bound(time.begin(), time.end(), t) - time.begin()) - 1;
}

MeasurementRecord ReadRecord(const json& r, const std::string& where,
                             const std::vector<Run>& logs) {
  RejectUnknownKeys(r, {"name", "kind", "day", "log", "time_min", "z_mm", "value_um", "sigma_um"},
                    where);
  MeasurementRecord m;
  m.name = RequireString(r, "name", where);
  m.kind = ParseKind(RequireOneOf(r, "kind", {"probe", "laser", "lead", "setup_check"}, where));
  m.day = static_cast<int>(RequireInteger(r, "day", 0, 100000, where));
  m.log =
      static_cast<int>(RequireInteger(r, "log", 0, static_cast<long long>(logs.size()) - 1, where));
  const std::vector<double> t = RequireNumberArray(r, "time_min", where);
  const std::vector<double> z = RequireNumberArray(r, "z_mm", where);
  const std::vector<double> v = RequireNumberArray(r, "value_um", where);
  const std::vector<double> s = RequireNumberArray(r, "sigma_um", where);
  if (z.size() != t.size() || v.size() != t.size() || s.size() != t.size())
    throw InputError(where +
                     ": time_min, z_mm, value_um and sigma_um must have one value per "
                     "reading (" +
                     std::to_string(t.size()) + ", " + std::to_string(z.size()) + ", " +
                     std::to_string(v.size()) + ", " + std::to_string(s.size()) + ")");
  const Run& log = logs[static_cast<std::size_t>(m.log)];
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::string at = where + " reading " + std::to_string(k);
    CheckRange(z[k], kAxisPositionRange, "z_mm", at);
    CheckRange(v[k], {-kMaxAbsErrorUm, kMaxAbsErrorUm, false, "um"}, "value_um", at);
    CheckRange(s[k], {0, kMaxMeasurementSigmaUm, true, "um"}, "sigma_um", at);
    m.rows.push_back({SampleAt(log, t[k], at), t[k], z[k], v[k], s[k]});
  }
  return m;
}

}  // namespace

MeasurementFile ReadMeasurementRecords(const std::filesystem::path& path) {
  const json j = ReadJsonFile(path);
  const std::string w = "measurement records '" + path.string() + "'";
  if (!j.is_object() || !j.contains("format") || j["format"] != kMeasurementRecordsFormat)
    throw InputError(w + ": its 'format' must be '" + kMeasurementRecordsFormat + "'");
  RejectUnknownKeys(j, {"format", "schema_version", "description", "day_logs", "records"}, w);
  RequireSchema(j, kMeasurementRecordsFormat, 1, w, "format");
  MeasurementFile f;
  if (j.contains("description")) f.description = RequireString(j, "description", w, 100000);
  f.log_paths = RequireStrings(j, "day_logs", w, 100000, 4096);
  if (f.log_paths.empty()) throw InputError(w + ": 'day_logs' is empty");
  const std::filesystem::path dir = path.parent_path();
  for (const std::string& p : f.log_paths) {
    const std::filesystem::path full =
        std::filesystem::path(p).is_absolute() ? std::filesystem::path(p) : dir / p;
    f.record.day_logs.push_back(ReadRun(full, RunState::kUnknown));
  }
  const json& records = RequireArray(j, "records", w, 100000);
  std::size_t readings = 0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::string where = w + " 'records'[" + std::to_string(i) + "]";
    if (!records[i].is_object()) throw InputError(where + ": must be a JSON object");
    f.record.records.push_back(ReadRecord(records[i], where, f.record.day_logs));
    readings += f.record.records.back().rows.size();
    if (readings > 10000000) throw InputError(w + ": more than 10 million readings");
  }
  if (readings == 0) throw InputError(w + ": no reading");
  f.record.Validate();
  return f;
}

std::string FormatMeasurementRecords(const ShopRecord& record,
                                     const std::vector<std::string>& log_paths,
                                     const std::string& description) {
  if (log_paths.size() != record.day_logs.size())
    throw InputError("measurement records: one path per day log is needed");
  json records = json::array();
  for (const MeasurementRecord& r : record.records) {
    std::vector<double> t, z, v, s;
    for (const Measurement& m : r.rows) {
      t.push_back(m.time_min);
      z.push_back(m.z_mm);
      v.push_back(m.value_um);
      s.push_back(m.sigma_um);
    }
    records.push_back({{"name", r.name},
                       {"kind", ToString(r.kind)},
                       {"day", r.day},
                       {"log", r.log},
                       {"time_min", t},
                       {"z_mm", z},
                       {"value_um", v},
                       {"sigma_um", s}});
  }
  return JsonFileText({{"format", kMeasurementRecordsFormat},
                       {"schema_version", 1},
                       {"description", description},
                       {"day_logs", log_paths},
                       {"records", records}});
}

}  // namespace whirl::drift
