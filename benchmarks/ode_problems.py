"""The ODE test problems that benchmarks/bench_ode.py times and tests/numerics/test_ode_stiffness.py
checks method "auto" on (the test imports this module by a path insert): a Kepler orbit
(not stiff: a saddle pair of +-4 at the perihelion), Robertson's kinetics, HIRES, Van der
Pol at mu = 1000 (stiff), and a rate that switches on at t = 5 (stiff from there)."""

from __future__ import annotations

import numpy as np

#: the Kepler orbit's eccentricity, and its start at the perihelion (period 2 pi)
E = 0.5
KEPLER_Y0 = [1 - E, 0.0, 0.0, float(np.sqrt((1 + E) / (1 - E)))]
HIRES_Y0 = [1, 0, 0, 0, 0, 0, 0, 0.0057]


def kepler(t, y):
    x, yy, vx, vy = y
    r3 = (x * x + yy * yy) ** 1.5
    return np.array([vx, vy, -x / r3, -yy / r3])


def robertson(t, y):
    y1, y2, y3 = y
    return np.array(
        [-0.04 * y1 + 1e4 * y2 * y3, 0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2**2, 3e7 * y2**2]
    )


def hires(t, y):
    y1, y2, y3, y4, y5, y6, y7, y8 = y
    return np.array(
        [
            -1.71 * y1 + 0.43 * y2 + 8.32 * y3 + 0.0007,
            1.71 * y1 - 8.75 * y2,
            -10.03 * y3 + 0.43 * y4 + 0.035 * y5,
            8.32 * y2 + 1.71 * y3 - 1.12 * y4,
            -1.745 * y5 + 0.43 * y6 + 0.43 * y7,
            -280 * y6 * y8 + 0.69 * y4 + 1.71 * y5 - 0.43 * y6 + 0.69 * y7,
            280 * y6 * y8 - 1.81 * y7,
            -280 * y6 * y8 + 1.81 * y7,
        ]
    )


def vdp(t, y):
    return np.array([y[1], 1000.0 * (1 - y[0] ** 2) * y[1] - y[0]])


def late(t, y):
    """y1 follows cos t at a rate that switches from 1 to 1e4 around t = 5."""
    k = 1 + 1e4 / (1 + np.exp(-10 * (t - 5)))
    return np.array([-k * (y[0] - np.cos(t)) - np.sin(t), y[0]])


PROBLEMS = {  # name: (f, span, y0, stiff)
    "Kepler, e = 0.5, 50 periods": (kepler, (0.0, 100 * np.pi), KEPLER_Y0, False),
    "Robertson to t = 40": (robertson, (0.0, 40.0), [1.0, 0.0, 0.0], True),
    "HIRES to t = 321.8122": (hires, (0.0, 321.8122), HIRES_Y0, True),
    "Van der Pol, mu = 1000, to t = 3000": (vdp, (0.0, 3000.0), [2.0, 0.0], True),
}
