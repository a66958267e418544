#!/usr/bin/env python3
"""Writes a long synthetic machine log in the drift run-file format (docs/drift.md), for the
benchmarks of the streaming drift commands (scripts/bench_drift.sh) and for trying them at a
year's scale. Deterministic from --seed (Python's own Mersenne Twister, no other package).

What the log holds (a simulated machine, not a measured one):
  * a calendar: shifts 06:00-22:00 on weekdays, the machine off at night and at weekends (a
    cold start every morning, a long cool-down every weekend), a lunch stop 12:00-12:30;
  * duty changes inside a shift: the spindle speed jumps every 20-120 min between 0 (a pause),
    600, 1250, 2000 and 3000 rpm;
  * heat: three structure temperatures (spindle housing, column, bed) rise as first-order lags of
    the spindle power (time constants 15, 90 and 300 min) above an ambient that swings 2.5 K over
    the day, 3 K over the year and wanders slowly (an Ornstein-Uhlenbeck walk, 2 days);
  * sensors t1_C.. (degC, noise 0.02 K): the housing, the front bearing (8 min), the column, the
    bed and the hall air (more sensors repeat these with offsets);
  * the thermal error ch1_um (um, noise 0.3 um): a linear mix of the structure temperatures, the
    housing's part lagging it by 10 min, and of the ambient.
Columns: time_min, spindle_rpm, t1_C..t<k>_C, ch1_um (8 columns with the default 5 sensors).

Usage: scripts/make_long_log.py --rows N [--period-s 15] [--sensors 5] [--seed 1] [--out FILE]
"""
import argparse
import math
import random
import sys

LEVELS_RPM = [0, 600, 1250, 2000, 3000]
LEVEL_WEIGHTS = [1, 2, 3, 3, 2]


def lag_factor(dt_min, tau_min):
    """The first-order lag's step factor a = 1 - exp(-dt / tau) (zero-order hold)."""
    return 1.0 - math.exp(-dt_min / tau_min)


class Machine:
    """The simulated machine: schedule, ambient and the lagged heat of the spindle."""

    def __init__(self, rng, period_s):
        self.rng = rng
        self.dt_min = period_s / 60.0
        self.segment_end_s = -1.0
        self.segment_rpm = 0
        self.walk_K = 0.0
        self.housing = self.column = self.bed = self.bearing = 0.0
        self.housing_lag = 0.0
        self.amb_structure = None
        self.air = None
        self.a = {tau: lag_factor(self.dt_min, tau) for tau in (8, 10, 15, 90, 300, 10.5, 240)}
        self.walk_keep = math.exp(-self.dt_min / (2 * 1440.0))
        self.walk_step = 0.5 * math.sqrt(1 - self.walk_keep ** 2)

    def rpm(self, t_s):
        day, sod = divmod(t_s, 86400.0)
        weekday = int(day) % 7 < 5
        if not weekday or sod < 6 * 3600 or sod >= 22 * 3600 or 12 * 3600 <= sod < 12.5 * 3600:
            self.segment_end_s = -1.0  # the next shift starts a new segment
            return 0
        if t_s >= self.segment_end_s:
            self.segment_end_s = t_s + 60 * self.rng.uniform(20, 120)
            self.segment_rpm = self.rng.choices(LEVELS_RPM, LEVEL_WEIGHTS)[0]
        return self.segment_rpm

    def ambient(self, t_s):
        day = t_s / 86400.0
        self.walk_K = self.walk_keep * self.walk_K + self.walk_step * self.rng.gauss(0, 1)
        return (20.0 + 2.5 * math.sin(2 * math.pi * (day - 0.375)) +
                3.0 * math.sin(2 * math.pi * day / 365.0) + self.walk_K)

    def step(self, t_s):
        rpm = self.rpm(t_s)
        power = (rpm / 3000.0) ** 1.2
        amb = self.ambient(t_s)
        if self.amb_structure is None:
            self.amb_structure, self.air = amb, amb
        a = self.a
        self.amb_structure += a[240] * (amb - self.amb_structure)
        self.air += a[10.5] * (amb - self.air)
        self.housing += a[15] * (12.0 * power - self.housing)
        self.bearing += a[8] * (15.0 * power - self.bearing)
        self.column += a[90] * (5.0 * power - self.column)
        self.bed += a[300] * (2.0 * power - self.bed)
        self.housing_lag += a[10] * (self.housing - self.housing_lag)
        base = self.amb_structure
        sensors = [base + self.housing, base + 1.0 + self.bearing, base + self.column,
                   base - 0.5 + self.bed, self.air]
        error = (4.0 * self.housing_lag + 6.0 * self.column + 2.0 * self.bed +
                 1.5 * (self.amb_structure - 20.0))
        return rpm, sensors, error


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rows", type=int, required=True, help="data rows (1 .. 100,000,000)")
    p.add_argument("--period-s", type=float, default=15.0, help="sample period [s] (default 15)")
    p.add_argument("--sensors", type=int, default=5, help="temperature columns (1..64, default 5)")
    p.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    p.add_argument("--out", default="-", help="output CSV file (default: stdout)")
    args = p.parse_args()
    if not 1 <= args.rows <= 100_000_000:
        p.error("--rows must be 1 .. 100,000,000")
    if not 0.01 <= args.period_s <= 3600:
        p.error("--period-s must be 0.01 .. 3600 s")
    if not 1 <= args.sensors <= 64:
        p.error("--sensors must be 1 .. 64")
    rng = random.Random(args.seed)
    noise = random.Random(args.seed + 1_000_003)
    machine = Machine(rng, args.period_s)
    out = sys.stdout if args.out == "-" else open(args.out, "w", encoding="ascii")
    names = ["t%d_C" % (i + 1) for i in range(args.sensors)]
    out.write("# synthetic machine log written by scripts/make_long_log.py --rows %d --period-s %g "
              "--sensors %d --seed %d (simulated: shifts, duty changes, nights, weekends)\n"
              % (args.rows, args.period_s, args.sensors, args.seed))
    out.write(",".join(["time_min", "spindle_rpm"] + names + ["ch1_um"]) + "\n")
    gauss = noise.gauss
    lines = []
    for k in range(args.rows):
        t_s = k * args.period_s
        rpm, base, error = machine.step(t_s)
        cells = ["%.6f" % (t_s / 60.0), str(rpm)]
        for i in range(args.sensors):
            offset = 0.3 * (i // len(base))
            cells.append("%.3f" % (base[i % len(base)] + offset + gauss(0, 0.02)))
        cells.append("%.3f" % (error + gauss(0, 0.3)))
        lines.append(",".join(cells))
        if len(lines) >= 10000:
            out.write("\n".join(lines) + "\n")
            lines = []
    if lines:
        out.write("\n".join(lines) + "\n")
    if out is not sys.stdout:
        out.close()


if __name__ == "__main__":
    main()
