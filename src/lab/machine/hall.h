#pragma once
// Hall air temperature over a machine's calendar (degC), a deterministic function of the absolute
// time abs_min = day * 1440 + clock_min (day signed: history < 0 <= test days).
//   kind "diurnal": T = 20 + offset_day + A sin(2 pi (clock - peak + 360) / 1440) + OU(t) + doors(t)
//     offset_day ~ N(0, day_offset_std) (linear between day centres), OU an Ornstein-Uhlenbeck
//     process (std ou_std, time constant ou_tau_min, exact AR(1) on a 10-min grid, linear between),
//     doors: Poisson door_events_per_day per working day, each a drop of door_drop_k for
//     door_duration_min (at a uniform clock time in the shift).
//   kind "ramp": T = 20 + r_d min(max(clock - 360, 0), ramp_hours 60) / 60 during the day, r_d ~
//     N(0, ramp_std_k_per_h), back to 20 linearly between 22:00 and 06:00 of the next day.
// Seasons (both kinds, off by default): + A_s cos(2 pi (abs_min / 1440 - peak_day) / 365.25), a
//   year's swing of a hall whose conditioning holds the day but not the season (an estimate: an
//   unconditioned hall in central Europe follows the outdoor monthly means of about +-9 K damped by
//   the building; a conditioned one a few K); over a calendar of weeks it shifts the test window
//   against the training weeks.
// Conditioned hall: A 0.5 K, peak 15:00, ou_std 0.2 K, day offset std 0.3 K, no doors.
// Unconditioned: A 2.5 K, ou_std 0.5 K, 1 door event per day of -1.5 K for 20 min.
// Bryan 1990 names the environment a leading thermal error source; ISO 230-3 tests it (ETVE);
// the amplitudes are estimates of a conditioned / unconditioned hall.
#include <cstdint>
#include <string>
#include <vector>

namespace whirl::machine {

struct HallOptions {
  std::string kind = "diurnal";  ///< "diurnal" or "ramp"
  double amplitude_k = 0.5;
  double peak_clock_min = 900;   ///< 15:00
  double ou_std_k = 0.2;
  double ou_tau_min = 60;
  double day_offset_std_k = 0.3;
  double door_events_per_day = 0;
  double door_drop_k = -1.5;
  double door_duration_min = 20;
  double ramp_std_k_per_h = 0.3;
  double ramp_hours = 4;
  double seasonal_amplitude_k = 0;  ///< A_s, K (0..15; 0: no seasons, the default)
  double seasonal_peak_day = 56;    ///< the warmest day (day 0 = the first test day)
  static HallOptions Conditioned();
  static HallOptions Unconditioned();
  static HallOptions Ramp();
};

class HallProfile {
 public:
  /// The hall over [first_day, last_day] (whole days), seeded.
  HallProfile(const HallOptions& options, int first_day, int last_day, std::uint64_t seed);
  double At(double abs_min) const;  ///< degC; clamped to the covered range
  /// Least-squares slope of the hall over [abs_begin, abs_end], K/h (the blank's ambient drift).
  double SlopeKPerH(double abs_begin_min, double abs_end_min) const;
  int first_day() const { return first_day_; }
  int last_day() const { return last_day_; }

 private:
  HallOptions options_;
  int first_day_, last_day_;
  std::vector<double> day_offset_k_, ramp_k_per_h_, ou_k_;  // ou on a 10-min grid
  struct Door { double start_abs_min, end_abs_min; };
  std::vector<Door> doors_;
};

}  // namespace whirl::machine
