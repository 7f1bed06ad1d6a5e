#!/usr/bin/env python3
"""A small simulator of its own, as a user might already have one: a quarter
car (one sprung mass on a spring and a damper) crossing a one-cosine bump,
integrated with the classical fourth-order Runge-Kutta method at a fixed step.

Usage: quarter_car.py INPUT RESULTS
  INPUT    lines "name = value" (stiffness_n_per_m, damping_n_s_per_m)
  RESULTS  written as JSON: values, series and time (docs/external.md)

Deterministic: the same input gives the same bytes. Numbers are written with
Python's repr, the shortest text that reads back to the same double.
"""
import json
import math
import sys

MASS_KG = 300.0
SPEED_M_PER_S = 10.0
BUMP_HEIGHT_M = 0.08
BUMP_LENGTH_M = 2.0
BUMP_START_S = 0.2
END_TIME_S = 2.0
STEPS = 2000           # 1 ms steps
REPORT_EVERY = 10      # results every 10 ms


def road(t):
    """Height, and its rate, of the road under the wheel at time t."""
    duration = BUMP_LENGTH_M / SPEED_M_PER_S
    if t < BUMP_START_S or t > BUMP_START_S + duration:
        return 0.0, 0.0
    phase = 2.0 * math.pi * (t - BUMP_START_S) / duration
    height = 0.5 * BUMP_HEIGHT_M * (1.0 - math.cos(phase))
    rate = 0.5 * BUMP_HEIGHT_M * math.sin(phase) * 2.0 * math.pi / duration
    return height, rate


def acceleration(t, x, v, k, c):
    y, ydot = road(t)
    return -(k * (x - y) + c * (v - ydot)) / MASS_KG


def read_input(path):
    values = {}
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.split("#")[0].strip()
            if not line:
                continue
            name, sep, text = line.partition("=")
            if not sep:
                sys.exit(f"{path}:{number}: expected 'name = value'")
            values[name.strip()] = float(text)
    for name in ("stiffness_n_per_m", "damping_n_s_per_m"):
        if name not in values:
            sys.exit(f"{path}: missing {name}")
    return values["stiffness_n_per_m"], values["damping_n_s_per_m"]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    k, c = read_input(sys.argv[1])
    if k <= 0.0 or c < 0.0:
        # The driver's failure marker: the analysis fails, the optimizer goes on.
        print("SIMULATION FAILED: stiffness must be positive and damping not negative")
        return 0
    h = END_TIME_S / STEPS
    x = v = 0.0
    times, accelerations, travels = [], [], []
    for i in range(STEPS + 1):
        t = i * h
        if i % REPORT_EVERY == 0:
            times.append(t)
            accelerations.append(acceleration(t, x, v, k, c))
            travels.append(x - road(t)[0])
        if i == STEPS:
            break
        k1x, k1v = v, acceleration(t, x, v, k, c)
        k2x, k2v = v + 0.5 * h * k1v, acceleration(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v, k, c)
        k3x, k3v = v + 0.5 * h * k2v, acceleration(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v, k, c)
        k4x, k4v = v + h * k3v, acceleration(t + h, x + h * k3x, v + h * k3v, k, c)
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
    results = {
        "values": {"peak_acceleration_m_per_s2": max(abs(a) for a in accelerations)},
        "series": {"acceleration_m_per_s2": accelerations, "travel_m": travels},
        "time": times,
    }
    with open(sys.argv[2], "w") as f:
        json.dump(results, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
