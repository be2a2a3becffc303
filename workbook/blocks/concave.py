"""Hand checks of the concave-cam sheet: stability, geometry, extreme inputs, derivatives.

Blocks (imported only by the concave-cam templates):

* ``concave.stability`` (table) / ``concave.stability_findings``: the lift formula (1)
  subtracts nearly equal numbers at small angles; its error and that of the stable form
  ``d^2 sin^2 x/(c + sqrt(c^2 - d^2 sin^2 x)) - 2 d sin^2(x/2)`` against a 50-digit mpmath
  reference of the same formula.
* ``concave.geometry_findings``: the paper against the geometry-consistent variant
  (templates/concave-cam-geometry.toml).
* ``concave.sweep`` (table) / ``concave.sweep_findings``: extreme geometries and speeds; each
  invalid case is reported with the reason, not computed.
* ``concave.derivatives`` (table) / ``concave.bench`` (bench) / ``concave.bench_findings``:
  velocity and acceleration from the lift by central differences, a five-point stencil,
  complex-step differentiation and the symbolic derivative, error against step and run time.
"""

from __future__ import annotations

import math
import time

import numpy as np

from . import Finding, bench_block, cached, findings_block, input_magnitude, table_block

STABILITY_ANGLES = (1e-6, 1e-3, 1.0)  # deg
BENCH_POINTS = (3.0, 8.0, 13.0, 18.0)  # deg, inside the flank 0 .. 22
MIN_ERROR = 1e-18  # errors that are exactly 0 are shown as this (log charts)


_mag = input_magnitude


def _deg(sheet) -> float:
    """The sheet's own degree in radians (pi/180 with the sheet's pi, if it has one)."""
    if "deg" in sheet.spec.definitions:
        return float(sheet.evaluate("deg").to("").magnitude)
    return math.pi / 180


# -- stability ----------------------------------------------------------------------------------
def lift_reference(sheet, phi_deg: float, digits: int = 50) -> float:
    """The sheet's h1 at phi (exact decimal inputs), evaluated with ``digits`` digits."""
    import sympy as sp

    from .. import symbolic

    expr = cached(
        sheet,
        "h1 sympy",
        lambda: symbolic.to_sympy(sheet, "h1", {"phi": symbolic.symbol("phi", real=False)}),
    )
    return float(
        expr.evalf(digits, subs={symbolic.symbol("phi", real=False): sp.Rational(repr(phi_deg))})
    )


def _stability(sheet):
    rows = []
    for phi in STABILITY_ANGLES:
        ref = lift_reference(sheet, phi)
        printed = float(sheet.evaluate("h1", phi=phi).to("mm").magnitude)
        stable = float(sheet.evaluate("h1_stable", phi=phi).to("mm").magnitude)
        rows.append(
            {
                "phi [deg]": phi,
                "reference h1 (50 digits) [mm]": ref,
                "formula (1) [mm]": printed,
                "formula (1) rel error": abs(printed - ref) / abs(ref),
                "stable form [mm]": stable,
                "stable form rel error": abs(stable - ref) / abs(ref),
            }
        )
    return rows


@table_block
def stability(sheet):
    """Lift formula (1) and its stable form against a 50-digit reference at small angles."""
    import pandas as pd

    return pd.DataFrame(cached(sheet, "stability", lambda: _stability(sheet)))


@findings_block
def stability_findings(sheet) -> list[Finding]:
    out = []
    for r in cached(sheet, "stability", lambda: _stability(sheet)):
        phi = r["phi [deg]"]
        out.append(
            Finding(
                "stability",
                f"lift formula (1) at phi = {phi:g} deg: relative error against 50 digits",
                r["formula (1) rel error"],
                "",
                "warning" if r["formula (1) rel error"] > 1e-6 else "info",
                f"h1 = {r['reference h1 (50 digits) [mm]']:.6e} mm; cancellation of (R1 + R3)*"
                f"(1 - 1/k) against R1 + Rp",
            )
        )
        out.append(
            Finding(
                "stability",
                f"stable form at phi = {phi:g} deg: relative error against 50 digits",
                r["stable form rel error"],
                "",
                "ok" if r["stable form rel error"] < 1e-14 else "warning",
                "d^2 sin^2 x/(c + sqrt(c^2 - d^2 sin^2 x)) - 2 d sin^2(x/2); "
                "used by concave-cam-geometry (hf)",
            )
        )
    return out


# -- geometry -----------------------------------------------------------------------------------
def geometry_numbers(sheet) -> dict:
    """Paper against exact on the geometry sheet (concave-cam-geometry): the template's
    definitions, and the flank and nose formulas on both sides of the transition."""

    def compute():
        def ev(name, unit="", **args):
            return float(sheet.evaluate(name, **args).to(unit).magnitude)

        phib = ev("phiB_geom", "deg")
        names = ("h_err_at", "v_paper_at")
        out = {n: ev(n) for n in names}
        units = {"h_err": "mm", "h_exact_max": "mm", "v_paper_peak": "m/s"}
        units.update({"v_exact_top": "m/s", "j_paper_max": "m/s^2", "j_exact_max": "m/s^2"})
        out.update({n: ev(n, u) for n, u in units.items()})
        hl, hr = (ev(n, "mm", phi=phib) for n in ("hf", "hn"))
        vl, vr = (ev(n, "m/s", phi=phib) for n in ("vf", "vn"))
        jl, jr = (ev(n, "m/s^2", phi=phib) for n in ("jf", "jn"))
        out.update(
            theta_geom=ev("theta_geom", "deg"),
            phiB_geom=phib,
            Theta=ev("Theta"),
            v_exact_peak=vl,  # v rises on the flank and falls on the nose: peak at phiB
            h_jump=hr - hl,
            v_jump=vr - vl,
            j_jump=jr - jl,
            hB=hl,
        )
        return out

    return cached(sheet, "geometry", compute)


@findings_block
def geometry_findings(sheet) -> list[Finding]:
    """How far the paper's Theta, transition, lift and peak velocity are from the geometry."""
    g = geometry_numbers(sheet)
    F = Finding
    return [
        F(
            "geometry",
            f"theta_geom (angle O3-O1-O2) against the paper's Theta = {g['Theta']:g} deg",
            g["theta_geom"],
            "deg",
            "info",
            f"the paper's Theta is {g['Theta'] - g['theta_geom']:+.3f} deg off",
        ),
        F(
            "geometry",
            "phiB_geom (roller centre crosses O3-O2) against the paper's 22 deg",
            g["phiB_geom"],
            "deg",
            "warning",
            f"the paper switches to the nose {22 - g['phiB_geom']:+.3f} deg late; "
            f"exact lift there {g['hB']:.4f} mm",
        ),
        F(
            "geometry",
            f"largest lift error of the paper (paper - exact), at phi = {g['h_err_at']:.2f} deg",
            g["h_err"],
            "mm",
            "warning",
            f"{abs(g['h_err']) / g['h_exact_max']:.2%} of the greatest exact lift "
            f"{g['h_exact_max']:.4f} mm",
        ),
        F(
            "geometry",
            f"peak velocity of the paper (at phi = {g['v_paper_at']:.2f} deg)",
            g["v_paper_peak"],
            "m/s",
            "warning",
            f"exact peak {g['v_exact_peak']:.4f} m/s at phi = {g['phiB_geom']:.3f} deg: "
            f"the paper is {g['v_paper_peak'] / g['v_exact_peak'] - 1:+.1%} off",
        ),
        F(
            "geometry",
            "exact peak velocity (at the flank-to-nose transition)",
            g["v_exact_peak"],
            "m/s",
            "info",
        ),
        F(
            "geometry",
            "exact lift at the transition: jump between flank and nose formulas",
            g["h_jump"],
            "mm",
            "ok" if abs(g["h_jump"]) < 1e-9 else "warning",
            "continuous",
        ),
        F(
            "geometry",
            "exact velocity at the transition: jump between flank and nose formulas",
            g["v_jump"],
            "m/s",
            "ok" if abs(g["v_jump"]) < 1e-9 else "warning",
            "continuous first derivative (tangent arcs)",
        ),
        F(
            "geometry",
            "exact acceleration at the transition: jump (curvature changes from concave to convex)",
            g["j_jump"],
            "m/s^2",
            "info",
        ),
        F(
            "geometry",
            "greatest acceleration: paper against exact",
            g["j_paper_max"],
            "m/s^2",
            "info",
            f"exact {g['j_exact_max']:.2f} m/s^2",
        ),
    ]


# -- extreme inputs -----------------------------------------------------------------------------
SWEEP = (
    ("as printed", {}),
    ("R3 close to Rp", {"R3": "10.5 mm"}),
    ("R3 = Rp", {"R3": "10 mm"}),
    ("R3 < Rp", {"R3": "8 mm"}),
    ("very large R3", {"R3": "10000 mm"}),
    ("lambda = 1.5 on the nose", {"a": "30 mm"}),
    ("lambda = 0.75 on the nose", {"a": "15 mm"}),
    ("omega x 10", {"omega": "1046 1/s"}),
    ("omega x 10, very large R3", {"omega": "1046 1/s", "R3": "10000 mm"}),
    ("nose inside the base circle", {"a": "5 mm"}),
)


def _sweep_case(sheet, label: str, changes: dict) -> dict:
    from ..errors import WorkbookError

    row = {
        "case": label,
        "inputs": ", ".join(f"{k} = {v}" for k, v in changes.items()) or "-",
        "status": "computed",
        "reason": "",
        "h max [mm]": None,
        "v max [m/s]": None,
        "j max [m/s^2]": None,
        "theta_geom [deg]": None,
        "phiB_geom [deg]": None,
    }
    reasons = []
    try:
        s = sheet.with_inputs(**changes)
    except WorkbookError as err:
        row.update(status="invalid", reason=err.message)
        return row
    geo = _geometry(sheet)
    same = {n: sheet.evaluate(n) for n in geo.spec.inputs if n in sheet.spec.inputs}
    geo = geo.with_inputs(**{**same, **changes})
    try:
        row["theta_geom [deg]"] = float(geo.evaluate("theta_geom").to("deg").magnitude)
        row["phiB_geom [deg]"] = float(geo.evaluate("phiB_geom").to("deg").magnitude)
    except WorkbookError as err:
        reasons.append(
            f"geometry: {err.message} (the circles R1 + R3 about O1 and R3 + R2 about O2 do "
            "not meet: there is no flank centre O3)"
        )
    lam = float(geo.evaluate("lam").magnitude)
    if abs(lam - 1) > 1e-12:
        reasons.append(
            f"lambda = a/(R2 + Rp) = {lam:g}: the sheet's nose formulas (5), (12), (13) "
            "hold for lambda = 1 only (a = R2 + Rp)"
        )
    if _mag(s, "R3", "mm") <= _mag(s, "Rp", "mm"):
        reasons.append("R3 <= Rp: the roller does not fit into the concave flank")
    try:
        df = s.table("curves")
        row["h max [mm]"] = float(df["h [mm]"].max())
        row["v max [m/s]"] = float(df["v [m/s]"].max())
        row["j max [m/s^2]"] = float(df["j [m/s^2]"].max())
    except WorkbookError as err:
        reasons.insert(0, f"engine: {err.message}")
    if reasons:
        row.update(status="invalid", reason="; ".join(reasons))
        row.update({"h max [mm]": None, "v max [m/s]": None, "j max [m/s^2]": None})
    return row


def _geometry(sheet):
    """The geometry of the same cam (concave-cam-geometry.toml beside the template)."""
    from .. import load

    return load(sheet.spec.path.parent / "concave-cam-geometry.toml")


def sweep_rows(sheet) -> list[dict]:
    import warnings

    def compute():
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return [_sweep_case(sheet, label, changes) for label, changes in SWEEP]

    return cached(sheet, "sweep", compute)


@table_block
def sweep(sheet):
    """Extreme geometries and speeds: computed, or reported invalid with the reason."""
    import pandas as pd

    return pd.DataFrame(sweep_rows(sheet), dtype=object)


@findings_block
def sweep_findings(sheet) -> list[Finding]:
    out = []
    for r in sweep_rows(sheet):
        if r["status"] == "computed":
            out.append(
                Finding(
                    "extreme inputs",
                    f"{r['case']} ({r['inputs']}): computed; greatest velocity",
                    r["v max [m/s]"],
                    "m/s",
                    "ok",
                    f"greatest acceleration {r['j max [m/s^2]']:.6g} m/s^2",
                )
            )
        else:
            out.append(
                Finding(
                    "extreme inputs",
                    f"{r['case']} ({r['inputs']}): invalid, not computed",
                    None,
                    "",
                    "warning",
                    r["reason"],
                )
            )
    return out


# -- derivatives: error against step and run time -------------------------------------------------
METHODS = ("central", "five-point", "complex-step", "symbolic")


def _steps(quick: bool):
    if quick:
        return [5.0, 1.0, 1e-1, 1e-2, 1e-3, 1e-4]
    return [float(f"{v:.3g}") for v in np.logspace(math.log10(5.0), -4, 19)]


def _best_time(fn, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _exact_derivatives(sheet, points):
    """v and j of the sheet's lift h1 (per the sheet's radian), 50 digits, as floats."""
    import sympy as sp

    from .. import symbolic

    expr = cached(
        sheet,
        "h1 sympy",
        lambda: symbolic.to_sympy(sheet, "h1", {"phi": symbolic.symbol("phi", real=False)}),
    )
    phi = symbolic.symbol("phi", real=False)
    d1 = sp.diff(expr, phi)
    d2 = sp.diff(d1, phi)
    own_pi = "pi" in sheet.spec.inputs
    deg = (sp.Rational(repr(_mag(sheet, "pi", ""))) if own_pi else sp.pi) / 180
    om = sp.Rational(repr(_mag(sheet, "omega", "1/s")))
    v, j = [], []
    for p in points:
        sub = {phi: sp.Rational(repr(float(p)))}
        v.append(float((om * d1 / deg).evalf(50, subs=sub)) / 1000)  # mm/s -> m/s
        j.append(float((om**2 * d2 / deg**2).evalf(50, subs=sub)) / 1000)
    return np.array(v), np.array(j), d1, d2


def _derivative_bench(sheet, quick: bool):
    import sympy as sp

    from .. import symbolic

    points = np.array(BENCH_POINTS)
    v_ex, j_ex, d1, d2 = _exact_derivatives(sheet, points)
    f = sheet.evaluator.function("h1")  # the engine's compiled lift, mm; complex-capable

    def h(x):
        return np.asarray(f({"phi": x}))

    deg = _deg(sheet)
    om = _mag(sheet, "omega", "1/s")
    kv, kj = om / deg / 1000, om**2 / deg**2 / 1000  # per degree -> per radian, mm -> m
    t0 = time.perf_counter()
    phi = symbolic.symbol("phi", real=False)
    fv = sp.lambdify([phi], d1, "numpy")
    fj = sp.lambdify([phi], d2, "numpy")
    setup = time.perf_counter() - t0
    w = np.exp(1j * math.pi / 4)

    def central(hs):
        fp, fm, f0 = h(points + hs), h(points - hs), h(points)
        return (fp - fm) / (2 * hs) * kv, (fp - 2 * f0 + fm) / hs**2 * kj

    def five(hs):
        f2, f1, f0 = h(points + 2 * hs), h(points + hs), h(points)
        g1, g2 = h(points - hs), h(points - 2 * hs)
        v = (-f2 + 8 * f1 - 8 * g1 + g2) / (12 * hs) * kv
        j = (-f2 + 16 * f1 - 30 * f0 + 16 * g1 - g2) / (12 * hs**2) * kj
        return v, j

    def cstep(hs):
        v = np.imag(h(points + 1j * hs)) / hs * kv
        j = np.imag(h(points + w * hs) + h(points - w * hs)) / hs**2 * kj
        return v, j

    def symbolic_(hs):
        return fv(points) * kv, fj(points) * kj

    run = {"central": central, "five-point": five, "complex-step": cstep, "symbolic": symbolic_}
    repeat = 3 if quick else 7
    rows = []
    vs, js = np.max(np.abs(v_ex)), np.max(np.abs(j_ex))
    for hs in _steps(quick):
        row = {"step [deg]": hs}
        for m in METHODS:
            v, j = run[m](hs)
            row[f"{m} v error"] = max(float(np.max(np.abs(v - v_ex))) / vs, MIN_ERROR)
            row[f"{m} j error"] = max(float(np.max(np.abs(j - j_ex))) / js, MIN_ERROR)
            row[f"{m} time [us]"] = _best_time(lambda m=m, hs=hs: run[m](hs), repeat) * 1e6
        rows.append(row)
    return rows, setup


@table_block
def derivatives(sheet):
    """Velocity and acceleration from the lift: relative error and run time against the step."""
    import pandas as pd

    rows, _ = cached(sheet, "bench full", lambda: _derivative_bench(sheet, quick=False))
    return pd.DataFrame(rows)


@bench_block
def bench(sheet, quick: bool = False):
    """``workbook bench concave-cam``: error against run time of four differentiation methods."""
    import pandas as pd

    rows, setup = cached(
        sheet, f"bench {'quick' if quick else 'full'}", lambda: _derivative_bench(sheet, quick)
    )
    out = []
    for r in rows:
        for m in METHODS:
            out.append(
                {
                    "step [deg]": r["step [deg]"],
                    "method": m,
                    "v rel error": r[f"{m} v error"],
                    "j rel error": r[f"{m} j error"],
                    "time [us]": r[f"{m} time [us]"],
                }
            )
    df = pd.DataFrame(out)
    df.attrs["note"] = f"symbolic derivative: sympy diff + lambdify took {setup * 1e3:.1f} ms once"
    return df


@findings_block
def bench_findings(sheet) -> list[Finding]:
    rows, setup = cached(sheet, "bench full", lambda: _derivative_bench(sheet, quick=False))
    out = []
    for m in METHODS:
        for q, label in (("v", "velocity"), ("j", "acceleration")):
            best = min(rows, key=lambda r: r[f"{m} {q} error"])
            out.append(
                Finding(
                    "derivatives",
                    f"{label} by {m}: smallest relative error (at step {best['step [deg]']:g} deg)",
                    best[f"{m} {q} error"],
                    "",
                    "info",
                    f"{best[f'{m} time [us]']:.1f} us for {len(BENCH_POINTS)} angles",
                )
            )
    out.append(
        Finding(
            "derivatives",
            "symbolic derivative: one-time cost of sympy diff + lambdify",
            setup * 1e3,
            "ms",
            "info",
        )
    )
    return out
