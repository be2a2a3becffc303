"""Worksheets several test modules compute (ratios of units in cells, frozen cells, hard
numerics, an AC circuit in complex numbers, the smallest sheet with a function), written to a
folder by :func:`write_template`; the text of a table of definitions (:func:`definitions`);
the property tests' Hypothesis settings."""

from pathlib import Path

RATIOS = """
[sheet]
title = "Ratios of prefixed units"

[inputs]
P1 = "1.5 kW"
P2 = "2000 W"
d = "10 mm"
D = "0.6 m"
E = "200 GPa"
Sy = "250 MPa"
eta = "85 %"
theta = "30 deg"
T1 = "20 degC"
k = "3"
dT = "10 delta_degC"

[arguments]
x = { unit = "" }

[definitions]
r = "P1/P2"
y = "2*r"
s = "d/D"
s1 = "s + 1"
lam = "sqrt(E/Sy)"
mode = "\\"Euler\\" if lam > 20 otherwise \\"Johnson\\""
Pcr = "1000*r/lam^2 if lam > 20 otherwise 1000*r*(1 - lam/60)"
q = { expr = "r*eta", unit = "%" }
q1 = { expr = "P1/P2", unit = "" }
ang = { expr = "theta*r", unit = "deg" }
c = "cos(theta)*s"
T2 = { expr = "T1 + dT*q1", unit = "degC" }
T3 = { expr = "T2", unit = "K" }
n = "k*r"
"f(x)" = "x*r"
"g(x)" = "x*P1/P2"
"h(x)" = "x*d/D + r"
m = "max_over(T, g)"
m2 = "m*2"

[[tables]]
name = "T"
range = "x := 0, 0.25 .. 1"
columns = ["x", "f(x)", "g", "h"]
"""


FROZEN = """
[inputs]
a = "2 m"
n = "4"

[definitions]
y = "2*S + a"
z = "y/3"
w = "a*3"
total = "sum(i*a, i, 1, n)"

[[solve]]
unknowns = { S = "1 m" }
equations = ["S^2 == 20*a^2 + a*S"]
conditions = ["S > 0"]
"""


HARD_SHEET = """
[sheet]
title = "hard cases"
[definitions]
peak = "maximum(exp(-((x - 0.3)/1e-4)^2), x, 0, 1)"
wave = "maximum(sin(100*x)*exp(-x), x, 0, 10)"
narrow = "integral(exp(-((x - 3.7)/1e-2)^2), x, 0, 10)"
step = "integral(tanh(1e3*x), x, -1, 2)"
lorentz = "integral(1/(1 + ((x - 0.4)/1e-3)^2), x, 0, 1)"
cusp = "integral(1/sqrt(abs(x - 0.3)), x, 0, 1)"
triple = "root(x^3 - 3*x^2 + 3*x - 1, x, 0, 1.7)"
sqrt2 = "root(x^2 - 2, x, 0, 2)"
where = "argmax(sin(100*x)*exp(-x), x, 0, 10)"
"""


# -- units ------------------------------------------------------------------------------------
AC = """[inputs]
R = "10 ohm"
L = "50 mH"
C = "100 uF"
f = "50 Hz"
V = "230 V"

[arguments]
a = { unit = "ohm" }
b = { unit = "ohm" }
fr = { unit = "Hz" }

[definitions]
omega = "2*pi*f"
Z = { expr = "R + 1i*omega*L + 1/(1i*omega*C)", unit = "ohm" }
Zk = { expr = "Z", unit = "kohm" }
I = { expr = "V/Z", unit = "A" }
I_mag = { expr = "abs(I)", unit = "mA" }
phi = { expr = "arg(Z)", unit = "deg" }
"par(a, b)" = "a*b/(a + b)"
"Zf(fr)" = "R + 1i*2*pi*fr*L"
Zp = "par(Z, 1i*omega*L)"
Zr = "par(R, R)"
P = "polar(V, 30 deg)"
S = { expr = "V*conj(I)", unit = "W" }
Y = "[[1/R + 1/(1i*omega*L), -1/R], [-1/R, 1/R + 1i*omega*C]]"

[[tables]]
name = "sweep"
range = "fr := 10 Hz, 20 Hz .. 100 Hz"
columns = { "Zf(fr)" = "ohm", "abs(Zf(fr))" = "ohm", "arg(Zf(fr))" = "deg" }
"""


# The smallest sheet with an input, an argument and a function: tests add tables and charts.
SINE = """
[inputs]
R = "10 mm"

[arguments]
phi = { unit = "deg" }

[definitions]
"y(phi)" = "R*sin(phi)"
"""

SINE_TABLE = (
    SINE
    + """
[[tables]]
name = "t"
range = "phi := 0, 10 .. 90"
columns = { y = "mm" }
"""
)


def definitions(values: dict[str, str]) -> str:
    """The text of a ``[definitions]`` table: one ``name = "expression"`` line a definition
    (the text for the ``sheet_from`` fixture)."""
    return "[definitions]\n" + "".join(f'{k} = "{v}"\n' for k, v in values.items())


def write_template(tmp_path: Path, text: str, name: str = "t.toml") -> Path:
    """``text`` written as ``tmp_path/name``: the path to load."""
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def fuzz_settings(examples: int):
    """Hypothesis settings of the property tests: reproducible, no deadline, no database."""
    from hypothesis import HealthCheck, settings

    return settings(
        max_examples=examples,
        derandomize=True,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
