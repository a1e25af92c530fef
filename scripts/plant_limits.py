#!/usr/bin/env python3
"""What no controller can beat on the simulated rig's plants (docs/control.md, "What the plants
reach"): the pump alone, with no camera, tracker or valve delay and a perfect controller.

  step:  full pumping from vented until the angle comes within 1 deg of the target (then the
         vent takes the pressure to the final value at once): the shortest settling time;
  sine:  the pressure that makes the lagged bend follow the sine exactly, followed as closely as
         the pump (inflating) and the vent orifice (venting) allow: the smallest RMS error.

The plant is src/control/plant.h's: p' = p_atm / V * (Q_pump (1 - p / stall) or -Q_vent
sqrt(p / 10 kPa)), bend = slope (p - bend start) through a first-order lag (no play). Angles at
the middle marker with the default markers (0.4 deg of angle per deg of bend).

Usage: scripts/plant_limits.py   (prints the figures for issue 23's plants)
"""
import math

ATM_KPA = 101.325
DT = 1e-4


def pump_rate(p, volume_ml, pump_l_min=1.0, stall_kpa=120.0):
    return ATM_KPA / (volume_ml * 1e-3) * pump_l_min / 60.0 * max(0.0, 1.0 - p / stall_kpa)


def vent_rate(p, volume_ml, vent_l_min=2.0):
    return ATM_KPA / (volume_ml * 1e-3) * vent_l_min / 60.0 * math.sqrt(max(p, 0.0) / 10.0)


def fastest_step(bend_deg_per_kpa, volume_ml, lag_s, step_deg=40.0, bias_kpa=3.0):
    k = 0.4 * bend_deg_per_kpa  # Angle per kPa.
    p = x = t = 0.0
    while x < step_deg - 1.0:
        p += pump_rate(p, volume_ml) * DT
        x += (k * max(0.0, p - bias_kpa) - x) * DT / lag_s
        t += DT
    return t


def best_sine_rms(bend_deg_per_kpa, volume_ml, lag_s, centre=155.0, amp=20.0, hz=0.5,
                  bias_kpa=3.0, settle_s=2.0, end_s=8.0):
    k = 0.4 * bend_deg_per_kpa
    w = 2 * math.pi * hz
    p = bias_kpa + (180.0 - centre) / k
    x = 180.0 - centre
    t, sq, n = 0.0, 0.0, 0
    while t < end_s:
        bend = 180.0 - (centre - amp * math.sin(w * t))
        bend_rate = amp * w * math.cos(w * t)
        wanted = bias_kpa + (bend + lag_s * bend_rate) / k
        rate = min(max(500.0 * (wanted - p), -vent_rate(p, volume_ml)), pump_rate(p, volume_ml))
        p += rate * DT
        x += (k * max(0.0, p - bias_kpa) - x) * DT / lag_s
        if t > settle_s:
            sq += ((180.0 - x) - (180.0 - bend)) ** 2
            n += 1
        t += DT
    return math.sqrt(sq / n)


if __name__ == "__main__":
    print("stiff, big, laggy (3 deg/kPa, 60 ml, 0.4 s): fastest 40 deg step %.2f s, "
          "best 0.5 Hz sine %.2f deg RMS" % (fastest_step(3, 60, 0.4), best_sine_rms(3, 60, 0.4)))
    print("big chamber (6 deg/kPa, 60 ml, 0.15 s): best 0.5 Hz sine %.2f deg RMS"
          % best_sine_rms(6, 60, 0.15))
    print("big_laggy in process (6 deg/kPa, 55 ml, 0.4 s): best 0.25 Hz sine around 140 deg "
          "%.2f deg RMS" % best_sine_rms(6, 55, 0.4, centre=140.0, hz=0.25))
