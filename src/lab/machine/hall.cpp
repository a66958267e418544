#include "machine/hall.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"

namespace whirl::machine {

namespace {
constexpr double kGridMin = 10;  // OU grid
}  // namespace

HallOptions HallOptions::Conditioned() { return {}; }

HallOptions HallOptions::Unconditioned() {
  HallOptions h;
  h.amplitude_k = 2.5;
  h.ou_std_k = 0.5;
  h.door_events_per_day = 1;
  return h;
}

HallOptions HallOptions::Ramp() {
  HallOptions h;
  h.kind = "ramp";
  return h;
}

HallProfile::HallProfile(const HallOptions& options, int first_day, int last_day,
                         std::uint64_t seed)
    : options_(options), first_day_(first_day), last_day_(last_day) {
  if (last_day < first_day) throw InputError("hall: last day before the first day");
  if (options.kind != "diurnal" && options.kind != "ramp")
    throw InputError("hall: kind '" + options.kind + "' must be 'diurnal' or 'ramp'");
  if (!(options.seasonal_amplitude_k >= 0 && options.seasonal_amplitude_k <= 15) ||
      !(std::abs(options.seasonal_peak_day) <= 1e6))
    throw InputError("hall: seasonal amplitude " + FormatNumber(options.seasonal_amplitude_k) +
                     " K must be within 0..15 and the peak day within +-1e6");
  Rng rng(seed);
  const int days = last_day - first_day + 2;  // one extra for the night after the last day
  for (int d = 0; d < days; ++d) {
    day_offset_k_.push_back(options.day_offset_std_k * rng.Normal());
    ramp_k_per_h_.push_back(options.ramp_std_k_per_h * rng.Normal());
  }
  // Ornstein-Uhlenbeck process, exact AR(1) on the grid.
  const int steps = static_cast<int>(days * 1440 / kGridMin) + 1;
  const double a = std::exp(-kGridMin / options.ou_tau_min);
  double x = options.ou_std_k * rng.Normal();
  for (int k = 0; k < steps; ++k) {
    ou_k_.push_back(x);
    x = a * x + options.ou_std_k * std::sqrt(1 - a * a) * rng.Normal();
  }
  // Doors: Poisson count per working day (inversion), uniform in the first shift.
  for (int d = first_day; d <= last_day; ++d) {
    if (((d % 7) + 7) % 7 >= 5) continue;
    double u = rng.Uniform(), p = std::exp(-options.door_events_per_day), cum = p;
    int count = 0;
    while (u > cum && count < 20) p *= options.door_events_per_day / ++count, cum += p;
    for (int i = 0; i < count; ++i) {
      const double start = d * 1440.0 + rng.Uniform(360, 870);
      doors_.push_back({start, start + options.door_duration_min});
    }
  }
}

double HallProfile::At(double abs_min) const {
  const double t0 = first_day_ * 1440.0;
  const double t = std::clamp(abs_min, t0, (last_day_ + 2) * 1440.0 - 1e-9);
  const double rel = t - t0;
  const double season =
      options_.seasonal_amplitude_k *
      std::cos(2 * kPi * (t / 1440.0 - options_.seasonal_peak_day) / 365.25);
  if (options_.kind == "ramp") {
    const int d = static_cast<int>(std::floor(rel / 1440));
    const double clock = rel - d * 1440.0;
    const double ramp_end = 360 + 60 * options_.ramp_hours;
    auto day_value = [&](int i, double c) {
      return ramp_k_per_h_[i] * std::clamp(c - 360, 0.0, ramp_end - 360) / 60;
    };
    if (clock >= 360 && clock <= 1320) return 20 + season + day_value(d, clock);
    // Night: linear from the day's value at 22:00 back to 20 at 06:00.
    const double from = clock > 1320 ? day_value(d, 1320) : (d > 0 ? day_value(d - 1, 1320) : 0);
    const double into = clock > 1320 ? clock - 1320 : clock + 120;
    return 20 + season + from * (1 - into / 480);
  }
  const double clock = std::fmod(rel, 1440.0);
  const double u = rel / 1440 - 0.5;  // day centres at noon
  const int i = std::clamp(static_cast<int>(std::floor(u)), 0, (int)day_offset_k_.size() - 2);
  const double w = std::clamp(u - i, 0.0, 1.0);
  const double offset = (1 - w) * day_offset_k_[i] + w * day_offset_k_[i + 1];
  const double diurnal =
      options_.amplitude_k * std::sin(2 * kPi * (clock - options_.peak_clock_min + 360) / 1440);
  const double g = rel / kGridMin;
  const int k = std::min(static_cast<int>(g), (int)ou_k_.size() - 2);
  const double ou = ou_k_[k] + (g - k) * (ou_k_[k + 1] - ou_k_[k]);
  double doors = 0;
  for (const Door& door : doors_)
    if (abs_min >= door.start_abs_min && abs_min < door.end_abs_min) doors += options_.door_drop_k;
  return 20 + season + offset + diurnal + ou + doors;
}

double HallProfile::SlopeKPerH(double a, double b) const {
  if (!(b > a)) return 0;
  const int n = 50;
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = (a + (b - a) * i / n) / 60, y = At(a + (b - a) * i / n);
    st += t, sy += y, stt += t * t, sty += t * y;
  }
  const double m = n + 1;
  return (m * sty - st * sy) / (m * stt - st * st);
}

}  // namespace whirl::machine
