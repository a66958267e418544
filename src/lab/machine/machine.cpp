#include "machine/machine.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/random.h"

namespace whirl::machine {

namespace {

double Rise(double t_min, double tau_min) { return 1.0 - std::exp(-t_min / tau_min); }

// Physical ranges of the machine file's fields (machine.h); far outside any real machine, so they
// only stop mistakes (a unit slip, a typo'd exponent, a corrupt file).
constexpr Range kPowerKw{0, 100, false, "kW"};          // a whirling head: a few kW
constexpr Range kGainUmPerKw{0, 1000, false, "um/kW"};  // 1 mm per kW: none moves that much
constexpr Range kTauMin{0, 10000, true, "min"};         // about a week
constexpr Range kExpansionPerK{0, 1e-4, false, "1/K"};  // metals 1e-5 to 2.5e-5
constexpr Range kRiseK{0, 100, false, "K"};             // steady rise of the Z screw
constexpr Range kFixedEndMm{0, kMaxAxisPositionMm, false, "mm"};
constexpr Range kRateKPerH{0, 10, false, "K/h"};         // ambient drift per hour
constexpr Range kStartC{-20, 50, false, "degC"};         // a workshop
constexpr Range kSpread{0, 1, false, "(relative std)"};  // 1 = 100 %
constexpr Range kSensorK{0, 10, false, "K"};             // noise, quantum
constexpr Range kSampleMin{0, 1440, true, "min"};        // at least one sample a day
constexpr Range kWeight{0, 1, false, ""};                // ambient weight a_i
constexpr Range kSensorGainKPerKw{0, 100, false, "K/kW"};
constexpr Range kSensorGainKPerK{0, 10, false, "K/K"};

SensorSpec Sensor(const char* name, double a, double motor, double process, double z, double tau) {
  return SensorSpec{name, a, {motor, process, z}, tau};
}

// Reads key into value when present (finite number), leaving the default otherwise.
void Optional(const nlohmann::json& j, const char* key, double& value, const std::string& what) {
  if (j.contains(key)) value = RequireNumber(j, key, what);
}
void OptionalBool(const nlohmann::json& j, const char* key, bool& value, const std::string& what) {
  if (!j.contains(key)) return;
  if (!j.at(key).is_boolean()) throw InputError(what + ": key '" + key + "' must be true or false");
  value = j.at(key).get<bool>();
}

}  // namespace

void MachineConfig::DisableAll() {
  head.enabled = false;
  z_screw.enabled = false;
  ambient.enabled = false;
}

void MachineConfig::Validate(const std::string& where) const {
  if (name.empty() || name.size() > 100 || std::any_of(name.begin(), name.end(), [](char ch) {
        return std::iscntrl(static_cast<unsigned char>(ch)) != 0;
      }))
    throw InputError(where +
                     ": name must be 1..100 characters without control characters (it "
                     "goes into file comments)");
  if (head.sign != 1 && head.sign != -1) throw InputError(where + ": head.sign must be +1 or -1");
  CheckRange(head.idle_power_kw, kPowerKw, "head.idle_power_kw", where);
  CheckRange(head.cutting_power_kw, kPowerKw, "head.cutting_power_kw", where);
  CheckRange(head.motor_gain_um_per_kw, kGainUmPerKw, "head.motor_gain_um_per_kw", where);
  CheckRange(head.process_gain_um_per_kw, kGainUmPerKw, "head.process_gain_um_per_kw", where);
  CheckRange(head.motor_tau_min, kTauMin, "head.motor_tau_min", where);
  CheckRange(head.process_tau_min, kTauMin, "head.process_tau_min", where);
  CheckRange(z_screw.expansion_per_k, kExpansionPerK, "z_screw.expansion_per_k", where);
  CheckRange(z_screw.steady_rise_k, kRiseK, "z_screw.steady_rise_k", where);
  CheckRange(z_screw.tau_min, kTauMin, "z_screw.tau_min", where);
  CheckRange(z_screw.fixed_end_mm, kFixedEndMm, "z_screw.fixed_end_mm", where);
  CheckRange(ambient.expansion_per_k, kExpansionPerK, "ambient.expansion_per_k", where);
  CheckRange(ambient.bed_tau_min, kTauMin, "ambient.bed_tau_min", where);
  CheckRange(ambient.rate_std_k_per_h, kRateKPerH, "ambient.rate_std_k_per_h", where);
  CheckRange(ambient.start_c, kStartC, "ambient.start_c", where);
  CheckRange(machine_spread, kSpread, "machine_spread", where);
  CheckRange(power_spread, kSpread, "power_spread", where);
  CheckRange(noise_std_k, kSensorK, "noise_std_k", where);
  CheckRange(quantum_k, kSensorK, "quantum_k", where);
  CheckRange(sample_min, kSampleMin, "sample_min", where);
  if (sensors.empty() || sensors.size() > 64)
    throw InputError(where + ": sensors: " + std::to_string(sensors.size()) +
                     " given, must be 1..64");
  for (const auto& s : sensors) {
    const bool plain = !s.name.empty() && s.name.size() <= 64 &&
                       std::all_of(s.name.begin(), s.name.end(), [](char ch) {
                         return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
                       });
    if (!plain)
      throw InputError(where + ": sensor name '" + s.name +
                       "': must be 1..64 letters, digits or '_' (it becomes a CSV column)");
    const std::string field = "sensor '" + s.name + "' ";
    CheckRange(s.ambient_weight, kWeight, field + "ambient_weight", where);
    CheckRange(s.gains[0], kSensorGainKPerKw, field + "motor_k_per_kw", where);
    CheckRange(s.gains[1], kSensorGainKPerKw, field + "process_k_per_kw", where);
    CheckRange(s.gains[2], kSensorGainKPerK, field + "z_screw_k_per_k", where);
    CheckRange(s.tau_min, kTauMin, field + "tau_min", where);
  }
}

MachineConfig DefaultMachine() {
  MachineConfig m;
  // name, ambient weight, K/kW motor, K/kW process, K/K z-screw heat, lag min
  m.sensors = {Sensor("ambient", 1.0, 0, 0, 0, 2),
               Sensor("bed_headstock", 1.0, 0.3, 0, 0, 60),
               Sensor("bed_middle", 1.0, 0, 0.2, 0.1, 80),
               Sensor("bed_tailstock", 1.0, 0, 0, 0.1, 90),
               Sensor("head_motor", 1.0, 4.0, 0, 0, 8),
               Sensor("head_bearing", 1.0, 1.5, 2.0, 0, 6),
               Sensor("head_housing", 1.0, 1.2, 0.6, 0, 25),
               Sensor("ring_gearbox", 1.0, 2.0, 0.3, 0, 15),
               Sensor("coolant_tank", 0.8, 0, 1.0, 0, 30),
               Sensor("z_nut", 1.0, 0, 0, 1.0, 5),
               Sensor("z_fixed_bearing", 1.0, 0, 0, 0.8, 15),
               Sensor("z_motor", 1.0, 0, 0, 1.5, 10),
               Sensor("cabinet", 0.5, 0.2, 0, 0, 30)};
  return m;
}

void to_json(nlohmann::json& j, const MachineConfig& m) {
  nlohmann::json sensors = nlohmann::json::array();
  for (const auto& s : m.sensors)
    sensors.push_back({{"name", s.name},
                       {"ambient_weight", s.ambient_weight},
                       {"motor_k_per_kw", s.gains[0]},
                       {"process_k_per_kw", s.gains[1]},
                       {"z_screw_k_per_k", s.gains[2]},
                       {"tau_min", s.tau_min}});
  const auto& h = m.head;
  const auto& z = m.z_screw;
  const auto& a = m.ambient;
  j = {{"schema", "whirl.machine_thermal"},
       {"schema_version", kMachineSchemaVersion},
       {"name", m.name},
       {"head",
        {{"enabled", h.enabled},
         {"sign", h.sign},
         {"idle_power_kw", h.idle_power_kw},
         {"cutting_power_kw", h.cutting_power_kw},
         {"motor_gain_um_per_kw", h.motor_gain_um_per_kw},
         {"motor_tau_min", h.motor_tau_min},
         {"process_gain_um_per_kw", h.process_gain_um_per_kw},
         {"process_tau_min", h.process_tau_min}}},
       {"z_screw",
        {{"enabled", z.enabled},
         {"expansion_per_k", z.expansion_per_k},
         {"steady_rise_k", z.steady_rise_k},
         {"tau_min", z.tau_min},
         {"fixed_end_mm", z.fixed_end_mm}}},
       {"ambient",
        {{"enabled", a.enabled},
         {"expansion_per_k", a.expansion_per_k},
         {"bed_tau_min", a.bed_tau_min},
         {"rate_std_k_per_h", a.rate_std_k_per_h},
         {"start_c", a.start_c}}},
       {"machine_spread", m.machine_spread},
       {"power_spread", m.power_spread},
       {"noise_std_k", m.noise_std_k},
       {"quantum_k", m.quantum_k},
       {"sample_min", m.sample_min},
       {"sensors", sensors}};
}

namespace {

void FromJson(const nlohmann::json& j, MachineConfig& m, const std::string& w) {
  RejectUnknownKeys(
      j,
      {"schema", "schema_version", "name", "head", "z_screw", "ambient", "machine_spread",
       "power_spread", "noise_std_k", "quantum_k", "sample_min", "sensors", "sources"},
      w);
  RequireSchema(j, "whirl.machine_thermal", kMachineSchemaVersion, w);
  if (j.contains("name")) m.name = RequireString(j, "name", w);
  if (j.contains("head")) {
    const auto& h = j.at("head");
    const std::string hw = w + " head";
    RejectUnknownKeys(
        h,
        {"enabled", "sign", "idle_power_kw", "cutting_power_kw", "motor_gain_um_per_kw",
         "motor_tau_min", "process_gain_um_per_kw", "process_tau_min"},
        hw);
    OptionalBool(h, "enabled", m.head.enabled, hw);
    if (h.contains("sign")) m.head.sign = static_cast<int>(RequireInteger(h, "sign", -1, 1, hw));
    Optional(h, "idle_power_kw", m.head.idle_power_kw, hw);
    Optional(h, "cutting_power_kw", m.head.cutting_power_kw, hw);
    Optional(h, "motor_gain_um_per_kw", m.head.motor_gain_um_per_kw, hw);
    Optional(h, "motor_tau_min", m.head.motor_tau_min, hw);
    Optional(h, "process_gain_um_per_kw", m.head.process_gain_um_per_kw, hw);
    Optional(h, "process_tau_min", m.head.process_tau_min, hw);
  }
  if (j.contains("z_screw")) {
    const auto& z = j.at("z_screw");
    const std::string zw = w + " z_screw";
    RejectUnknownKeys(z, {"enabled", "expansion_per_k", "steady_rise_k", "tau_min", "fixed_end_mm"},
                      zw);
    OptionalBool(z, "enabled", m.z_screw.enabled, zw);
    Optional(z, "expansion_per_k", m.z_screw.expansion_per_k, zw);
    Optional(z, "steady_rise_k", m.z_screw.steady_rise_k, zw);
    Optional(z, "tau_min", m.z_screw.tau_min, zw);
    Optional(z, "fixed_end_mm", m.z_screw.fixed_end_mm, zw);
  }
  if (j.contains("ambient")) {
    const auto& a = j.at("ambient");
    const std::string aw = w + " ambient";
    RejectUnknownKeys(
        a, {"enabled", "expansion_per_k", "bed_tau_min", "rate_std_k_per_h", "start_c"}, aw);
    OptionalBool(a, "enabled", m.ambient.enabled, aw);
    Optional(a, "expansion_per_k", m.ambient.expansion_per_k, aw);
    Optional(a, "bed_tau_min", m.ambient.bed_tau_min, aw);
    Optional(a, "rate_std_k_per_h", m.ambient.rate_std_k_per_h, aw);
    Optional(a, "start_c", m.ambient.start_c, aw);
  }
  Optional(j, "machine_spread", m.machine_spread, w);
  Optional(j, "power_spread", m.power_spread, w);
  Optional(j, "noise_std_k", m.noise_std_k, w);
  Optional(j, "quantum_k", m.quantum_k, w);
  Optional(j, "sample_min", m.sample_min, w);
  if (j.contains("sensors")) {
    if (!j.at("sensors").is_array()) throw InputError(w + ": 'sensors' must be an array");
    m.sensors.clear();
    for (const auto& s : j.at("sensors")) {
      const std::string sw = w + " sensor";
      RejectUnknownKeys(s,
                        {"name", "ambient_weight", "motor_k_per_kw", "process_k_per_kw",
                         "z_screw_k_per_k", "tau_min", "location"},
                        sw);
      SensorSpec spec;
      spec.name = RequireString(s, "name", sw);
      Optional(s, "ambient_weight", spec.ambient_weight, sw + " " + spec.name);
      Optional(s, "motor_k_per_kw", spec.gains[0], sw + " " + spec.name);
      Optional(s, "process_k_per_kw", spec.gains[1], sw + " " + spec.name);
      Optional(s, "z_screw_k_per_k", spec.gains[2], sw + " " + spec.name);
      Optional(s, "tau_min", spec.tau_min, sw + " " + spec.name);
      m.sensors.push_back(spec);
    }
  }
}

}  // namespace

void from_json(const nlohmann::json& j, MachineConfig& m) { FromJson(j, m, "machine"); }

MachineConfig ReadMachine(const std::string& path) {
  const std::string what = "machine file '" + path + "'";
  const nlohmann::json j = ReadJsonFile(path);
  MachineConfig m = DefaultMachine();
  try {
    FromJson(j, m, what);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": " + e.what());
  }
  m.Validate(what);
  return m;
}

MachineDay MachineDay::Draw(const MachineConfig& config, std::uint64_t machine_seed,
                            std::uint64_t day_seed) {
  config.Validate("machine '" + config.name + "'");
  MachineDay d;
  d.config = config;
  Rng machine_rng(MixSeed(machine_seed, 0x6d616368));
  auto factor = [&](double spread) { return std::max(0.2, 1.0 + spread * machine_rng.Normal()); };
  HeadComponent& h = d.config.head;
  h.motor_gain_um_per_kw *= factor(config.machine_spread);
  h.process_gain_um_per_kw *= factor(config.machine_spread);
  h.motor_tau_min *= factor(config.machine_spread);
  h.process_tau_min *= factor(config.machine_spread);
  d.config.z_screw.steady_rise_k *= factor(config.machine_spread);
  d.config.z_screw.tau_min *= factor(config.machine_spread);
  Rng day_rng(MixSeed(day_seed, 0x646179));
  d.ambient_rate_k_per_h = config.ambient.rate_std_k_per_h * day_rng.Normal();
  d.power_factor = std::max(0.2, 1.0 + config.power_spread * day_rng.Normal());
  return d;
}

double MachineDay::Source(machine::Source s, double t_min, bool cutting, double v_c) const {
  if (t_min <= 0) return 0.0;
  const HeadComponent& h = config.head;
  switch (s) {
    case Source::kMotor:
      return h.idle_power_kw * Rise(t_min, h.motor_tau_min);
    case Source::kProcess:
      return cutting ? h.cutting_power_kw * power_factor * (v_c / 180.0) *
                           Rise(t_min, h.process_tau_min)
                     : 0.0;
    case Source::kZScrew:
      return cutting ? config.z_screw.steady_rise_k * Rise(t_min, config.z_screw.tau_min) : 0.0;
    case Source::kAmbient:
      return ambient_rate_k_per_h / 60.0 * t_min;
  }
  return 0.0;
}

double MachineDay::BedRiseK(double t_min) const {
  if (t_min <= 0) return 0.0;
  const double tau = config.ambient.bed_tau_min;
  return ambient_rate_k_per_h / 60.0 * (t_min - tau * Rise(t_min, tau));
}

double MachineDay::HeadUm(double t_min, bool cutting, double v_c) const {
  const HeadComponent& h = config.head;
  if (!h.enabled) return 0.0;
  return h.sign * (h.motor_gain_um_per_kw * Source(Source::kMotor, t_min, cutting, v_c) +
                   h.process_gain_um_per_kw * Source(Source::kProcess, t_min, cutting, v_c));
}

double MachineDay::ZScrewPer1000Um(double t_min, bool cutting) const {
  if (!config.z_screw.enabled) return 0.0;
  const double bed = config.ambient.enabled ? BedRiseK(t_min) : 0.0;
  return 1e6 * config.z_screw.expansion_per_k * (Source(Source::kZScrew, t_min, cutting, 0) + bed);
}

double MachineDay::BedUm(double t_min) const {
  if (!config.ambient.enabled) return 0.0;
  return -1000.0 * config.ambient.expansion_per_k * BedRiseK(t_min) * config.z_screw.fixed_end_mm;
}

double MachineDay::DriftUm(double t_min, double z_mm, bool cutting, double v_c) const {
  return HeadUm(t_min, cutting, v_c) + BedUm(t_min) +
         ZScrewPer1000Um(t_min, cutting) * (config.z_screw.fixed_end_mm - z_mm) / 1000.0;
}

drift::Run SimulateRun(const MachineDay& day, const RunSpec& spec) {
  CheckRange(spec.duration_min, {0, 1e6, true, "min"}, "duration_min", "run '" + spec.name + "'");
  const MachineConfig& c = day.config;
  const double step = c.sample_min;
  const int samples = static_cast<int>(std::floor(spec.duration_min / step + 1e-9)) + 1;
  if (samples > drift::kMaxRunSamples)
    throw InputError("run '" + spec.name + "': " + std::to_string(samples) +
                     " samples exceed the limit " + std::to_string(drift::kMaxRunSamples));
  const bool cutting = spec.state == drift::RunState::kCutting;
  const double v_c = spec.cutting_speed_m_min;
  drift::Run run;
  run.name = spec.name;
  run.source = "the simulated log of machine '" + c.name + "'";
  run.state = spec.state;
  const std::size_t m = c.sensors.size();
  for (const auto& s : c.sensors) run.sensor_names.push_back(s.name + "_C");
  run.error_names = {"offset_um", "zscrew_per_1000_um"};
  run.temperature_C.resize(samples, static_cast<Eigen::Index>(m));
  run.error_um.resize(samples, 2);
  // Lag states per sensor and source (motor, process, z-screw, ambient).
  std::vector<std::array<double, kSourceCount>> lag(m, std::array<double, kSourceCount>{});
  Rng noise(MixSeed(spec.noise_seed, 0x73656e73));
  constexpr int kSub = 10;
  for (int k = 0; k < samples; ++k) {
    const double t = k * step;
    if (k > 0) {
      const double dt = step / kSub;
      for (int q = 1; q <= kSub; ++q) {
        const double tq = t - step + q * dt;
        std::array<double, kSourceCount> u{};
        for (int s = 0; s < kSourceCount; ++s)
          u[s] = day.Source(static_cast<Source>(s), tq - 0.5 * dt, cutting, v_c);
        if (!c.ambient.enabled) u[3] = 0.0;
        for (std::size_t i = 0; i < m; ++i) {
          const double a = 1.0 - std::exp(-dt / c.sensors[i].tau_min);
          for (int s = 0; s < kSourceCount; ++s) lag[i][s] += a * (u[s] - lag[i][s]);
        }
      }
    }
    run.time_min.push_back(t);
    run.line_numbers.push_back(k + 2);
    for (std::size_t i = 0; i < m; ++i) {
      const SensorSpec& s = c.sensors[i];
      double temp = c.ambient.start_c + s.ambient_weight * lag[i][3] + s.gains[0] * lag[i][0] +
                    s.gains[1] * lag[i][1] + s.gains[2] * lag[i][2] +
                    c.noise_std_k * noise.Normal();
      if (c.quantum_k > 0) temp = c.quantum_k * std::round(temp / c.quantum_k);
      run.temperature_C(k, static_cast<Eigen::Index>(i)) = temp;
    }
    run.error_um(k, 0) = day.HeadUm(t, cutting, v_c) + day.BedUm(t);
    run.error_um(k, 1) = day.ZScrewPer1000Um(t, cutting);
  }
  run.other.resize(samples, 0);
  return run;
}

std::vector<std::string> RunComments(const MachineDay& day, std::uint64_t machine_seed,
                                     std::uint64_t day_seed, const RunSpec& spec) {
  return {"simulated by whirl machine sensors (src/machine/machine.h), machine '" +
              day.config.name + "', machine seed " + std::to_string(machine_seed) + ", day seed " +
              std::to_string(day_seed) + ", noise seed " + std::to_string(spec.noise_seed),
          "state " + drift::ToString(spec.state) + ", cutting speed " +
              FormatNumber(spec.cutting_speed_m_min) + " m/min, ambient rate " +
              FormatNumber(day.ambient_rate_k_per_h) + " K/h, power factor " +
              FormatNumber(day.power_factor),
          "offset_um = head + bed drift (SD43900 part); zscrew_per_1000_um = Z screw growth over "
          "1000 mm towards the chuck (SD43910 part)"};
}

}  // namespace whirl::machine
