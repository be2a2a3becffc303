"""Planetary roller reducer: tooth profile of the cam (template ``reducer-profile``).

The template holds formulas (1)-(5), their derivatives (``diff``), the curvature, the
smallest concave radius of curvature (``maximum``/``argmax``), the packing limit and the
closed profile table. What is left here is geometry over the whole closed curve that has no
formula of a fixed shape:

* closure: the distance of every point of rollers 1..n-1 from the trace of roller 0 (nearest
  point of a closed multi-lobed curve: a k-d tree over a dense trace, then Newton's method on
  the template's exact derivatives), also for the printed variants;
* undercut: the cusps and loops of the practical profile, as many as the values make;
* the table of every roller (two arguments, k and phi: a range table has one), the findings'
  prose and the CAD export (docs/reducer-profile.md says why each stays);
* the refusals of :func:`validate`, in words the language has not (its own: "no piece applies").
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, LimitError
from ..findings import Finding
from . import cached, export_block, findings_block, table_block

#: The closure finding passes when the traces agree to this distance (mm); no [[checks]] line:
#: the distance is this block's, not an expression of the sheet.
CLOSURE_TOL_MM = 1e-9
#: Rows of the table of every roller and of the closed profile: at most this many (n = 400
#: rollers at dphi = 2 deg, 72,400 rows, write in about 52 s of CPU).
MAX_ROWS = 75_000
#: Step of the dense sampling used to find nearest points and undercut intervals (deg of phi).
_SAMPLE_DEG = 0.25


def profile_values(sheet, name: str, k, phi_deg):
    """The sheet's profile function ``name(k, phi)`` or ``name(phi)`` (phi in deg) as numbers
    in the unit the template declares for it, broadcast."""
    spec = sheet.spec.definitions[name]
    args = {"k": k, "phi": phi_deg} if "k" in spec.params else {"phi": phi_deg}
    out = sheet.evaluate(name, **args).to(spec.unit or "").magnitude
    shape = np.broadcast(np.asarray(k), np.asarray(phi_deg)).shape
    return np.broadcast_to(np.asarray(out, dtype=float), shape)


def _mag(sheet, name: str, unit: str = "") -> float:
    return float(sheet.evaluate(name).to(unit).magnitude)


def validate(sheet) -> None:
    """Refuse inputs for which the mechanism does not exist, with a message saying why, and
    inputs whose tables would exceed ``MAX_ROWS`` (the template's ``rows``). The template's
    Z, turns and rp_packing have no piece for the first two, a message naming the condition."""
    n = _mag(sheet, "n")
    if abs(n - round(n)) > 1e-9:
        raise InputError(f"n = {n:g}: the number of rollers must be a whole number", definition="n")
    e1, r2 = _mag(sheet, "e1", "mm"), _mag(sheet, "r2", "mm")
    if e1 >= r2:
        raise InputError(
            f"e1 = {e1:g} mm is not smaller than r2 = {r2:g} mm: the eccentric would carry the "
            "roller-centre circle onto or across the cam axis, r2^2 - e1^2*sin^2 in (1) turns "
            "negative and the rollers have no position (the mechanism cannot be assembled); "
            "choose e1 < r2",
            definition="e1",
        )
    rows, dphi = int(_mag(sheet, "rows")), _mag(sheet, "dphi", "deg")  # the template's count
    if rows > MAX_ROWS:
        raise LimitError(
            f"n = {n:g} rollers at dphi = {dphi:g} deg make tables of {rows:,} rows (the "
            f"rollers over one turn, the closed profile; limit {MAX_ROWS:,}): use a larger "
            "dphi or fewer rollers",
            file=sheet.file,
            definition="dphi",
        )


def _grid(sheet, table: str) -> np.ndarray:
    """The eccentric angles (deg) of the template's range table ``table``."""
    return sheet.range_values(sheet.table_spec(table).range, f"table {table}")


def _rollers(sheet):
    """(k, phi) of every roller over one eccentric turn (the angles of the table roller0),
    roller by roller."""
    phi = _grid(sheet, "roller0")
    n = int(round(_mag(sheet, "n")))
    return np.repeat(np.arange(n), phi.size), np.tile(phi, n)


def distance_to_trace(sheet, px, py):
    """Distance of points (px, py) from the closed theoretical trace of roller 0.

    Nearest sample on a dense grid (k-d tree), then Newton's method on
    g(s) = (C(s) - P) . C'(s) with the exact first and second derivatives (the template's
    diff). Returns (distance, parameter s in deg).
    """
    from scipy.spatial import cKDTree

    period = _mag(sheet, "period", "deg")

    def build():
        s = np.arange(0.0, period, _SAMPLE_DEG)
        return s, cKDTree(
            np.column_stack(
                [profile_values(sheet, "x_t", 0, s), profile_values(sheet, "y_t", 0, s)]
            )
        )

    s_grid, tree = cached(sheet, "reducer trace", build)
    px, py = np.asarray(px, dtype=float).ravel(), np.asarray(py, dtype=float).ravel()
    d0, idx = tree.query(np.column_stack([px, py]))
    s = s_grid[idx].copy()
    for _ in range(12):
        x, y, dx, dy, ddx, ddy = (
            profile_values(sheet, n, 0, s) for n in ("x_t", "y_t", "dx_t", "dy_t", "ddx_t", "ddy_t")
        )
        g = (x - px) * dx + (y - py) * dy
        dg = dx * dx + dy * dy + (x - px) * ddx + (y - py) * ddy
        step = np.where(dg > 0, -g / np.where(dg > 0, dg, 1.0), 0.0)
        step = np.clip(step, -_SAMPLE_DEG, _SAMPLE_DEG)
        s = s + step
        if np.all(np.abs(step) < 1e-13 * max(1.0, period)):
            break
    d = np.hypot(profile_values(sheet, "x_t", 0, s) - px, profile_values(sheet, "y_t", 0, s) - py)
    return np.minimum(d, d0), s


def closure(sheet) -> dict:
    """Largest distance of the traces of rollers 1..n-1 (one eccentric turn) from roller 0's."""
    validate(sheet)
    K, PHI = _rollers(sheet)
    K, PHI = K[K > 0], PHI[K > 0]
    d, _ = distance_to_trace(
        sheet, profile_values(sheet, "x_t", K, PHI), profile_values(sheet, "y_t", K, PHI)
    )
    i = int(np.argmax(d))
    return {"max": float(d[i]), "k": int(K[i]), "phi": float(PHI[i]), "points": int(d.size)}


def undercut(sheet) -> dict:
    """Cusps (where rp*kappa_n = 1) and loop crossings of the practical profile, per tooth.

    The number of undercut teeth depends on the values, and a loop crossing is a solve for two
    eccentric angles from start points found by a segment-intersection scan: not a table of a
    range fixed by the inputs, so it is done here (on the template's offset_margin), every
    tooth at once.
    """
    validate(sheet)
    return cached(sheet, "reducer undercut", lambda: _undercut(sheet))


def _undercut(sheet) -> dict:
    L = _mag(sheet, "period", "deg")
    s = np.arange(0.0, L, _SAMPLE_DEG)
    g = profile_values(sheet, "offset_margin", 0, s)
    out = {"cusps": [], "loops": [], "teeth": 0}
    if _mag(sheet, "kappa_max", "1/mm") <= 0 or not np.any(g <= 0):
        return out
    # begin the scan at phi = 0, or where the offset is surely regular: teeth count from there
    start = 0 if g[0] > 0 else int(np.argmax(g))
    ss = np.concatenate([s[start:], s[:start] + L, [s[start] + L]])
    gg = np.concatenate([g[start:], g[:start], [g[start]]])
    crossings = np.nonzero(np.sign(gg[:-1]) != np.sign(gg[1:]))[0]
    roots = sign_changes(sheet, ss[crossings], ss[crossings + 1])
    pairs = [(roots[j], roots[j + 1]) for j in range(0, len(roots) - 1, 2)]
    out["teeth"] = len(pairs)
    if not pairs:
        return out
    c = np.array(pairs)  # teeth x 2
    xs, ys, psis = (profile_values(sheet, n, 0, c) for n in ("x_k", "y_k", "psi_k"))
    for tooth in range(len(pairs)):
        for side in (0, 1):
            x, y, psi = float(xs[tooth, side]), float(ys[tooth, side]), float(psis[tooth, side])
            phi = float(c[tooth, side]) % L
            out["cusps"].append({"tooth": tooth + 1, "phi": phi, "psi": psi, "x": x, "y": y})
    for tooth, loop in enumerate(_loop_crossings(sheet, c[:, 0], c[:, 1], L), start=1):
        if loop is not None:
            out["loops"].append(dict(loop, tooth=tooth))
    return out


def sign_changes(sheet, a: np.ndarray, b: np.ndarray, xtol: float = 1e-12) -> list[float]:
    """Where 1 - rp*kappa_n changes sign in each bracket [a, b] (one sign change each), all
    brackets at once: bisection to ``xtol`` deg (and 4 ulps), then the secant of the last
    bracket."""
    a, b = np.asarray(a, dtype=float).copy(), np.asarray(b, dtype=float).copy()
    if a.size == 0:
        return []
    fa, fb = (profile_values(sheet, "offset_margin", 0, x) for x in (a, b))
    # brentq's tolerance: xtol, and 4 ulps of the angle (far out, 1e-12 deg is below one ulp)
    while np.any(b - a > xtol + 4 * np.finfo(float).eps * np.abs(b)):
        m = 0.5 * (a + b)
        fm = profile_values(sheet, "offset_margin", 0, m)
        left = np.sign(fm) == np.sign(fa)
        a, fa = np.where(left, m, a), np.where(left, fm, fa)
        b, fb = np.where(left, b, m), np.where(left, fb, fm)
    with np.errstate(divide="ignore", invalid="ignore"):
        secant = a - fa * (b - a) / (fb - fa)
    inside = np.isfinite(secant) & (secant >= a) & (secant <= b)
    return [float(x) for x in np.where(inside, secant, 0.5 * (a + b))]


def _offset(sheet, s):
    return tuple(profile_values(sheet, n, 0, s) for n in ("x_k", "y_k", "dx_k", "dy_k"))


def _loop_crossings(sheet, c1: np.ndarray, c2: np.ndarray, L: float) -> list[dict | None]:
    """Self-intersection of the practical profile around each cusp pair (c1, c2): a scan of the
    segments of the two branches, then Newton's method on P(s1) = P(s2), every tooth at once."""
    half = min(180.0, L / 2)
    mid = 0.5 * (c1 + c2)
    left = np.linspace(mid - half, c1, 721, axis=1)  # teeth x 721
    right = np.linspace(c2, mid + half, 721, axis=1)
    XL, YL = _offset(sheet, left)[:2]
    XR, YR = _offset(sheet, right)[:2]
    start = np.full((len(c1), 2), np.nan)
    for k in range(len(c1)):
        start[k] = _segment_crossing(
            np.column_stack([XL[k], YL[k]]), np.column_stack([XR[k], YR[k]]), left[k], right[k]
        )
    found = ~np.isnan(start[:, 0])
    s1, s2 = start[found, 0], start[found, 1]
    active = np.ones(s1.size, dtype=bool)
    for _ in range(30):  # Newton on P(s1) - P(s2) = 0, a tooth stops when its step is tiny
        if not active.any():
            break
        x1, y1, dx1, dy1 = _offset(sheet, s1[active])
        x2, y2, dx2, dy2 = _offset(sheet, s2[active])
        J = np.stack([np.stack([dx1, -dx2], -1), np.stack([dy1, -dy2], -1)], -2)
        singular = np.linalg.det(J) == 0
        step = np.zeros((J.shape[0], 2))
        if (~singular).any():
            rhs = np.stack([x2 - x1, y2 - y1], -1)[~singular]
            step[~singular] = np.linalg.solve(J[~singular], rhs[..., None])[..., 0]
        idx = np.nonzero(active)[0]
        s1[idx[~singular]] += step[~singular, 0]
        s2[idx[~singular]] += step[~singular, 1]
        done = singular | (np.max(np.abs(step), axis=1) < 1e-12)
        active[idx[done]] = False
    out: list[dict | None] = [None] * len(c1)
    if s1.size:
        x, y = _offset(sheet, s1)[:2]
        psi = profile_values(sheet, "psi_k", 0, s1)
        for n, k in enumerate(np.nonzero(found)[0]):
            out[k] = {
                **{"phi1": float(s1[n]) % L, "phi2": float(s2[n]) % L},
                **{"psi": float(psi[n]), "x": float(x[n]), "y": float(y[n])},
            }
    return out


def _segment_crossing(A, B, left, right) -> tuple[float, float]:
    """(s1, s2) of the innermost crossing of the polylines A (at angles left) and B (right),
    NaN when they do not cross."""
    # segments P + t R of the left branch and Q + w U of the right one: t, w in [0, 1]
    P, R = A[:-1, None, :], np.diff(A, axis=0)[:, None, :]
    Q, U = B[None, :-1, :], np.diff(B, axis=0)[None, :, :]
    cross = R[..., 0] * U[..., 1] - R[..., 1] * U[..., 0]
    qp = Q - P
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * U[..., 1] - qp[..., 1] * U[..., 0]) / cross
        w = (qp[..., 0] * R[..., 1] - qp[..., 1] * R[..., 0]) / cross
    hit = (cross != 0) & (t >= 0) & (t <= 1) & (w >= 0) & (w <= 1)
    if not hit.any():
        return math.nan, math.nan
    ii, jj = np.nonzero(hit)
    best = int(np.argmin(right[jj] - left[ii]))  # the innermost crossing
    i, j = int(ii[best]), int(jj[best])
    s1 = left[i] + t[i, j] * (left[i + 1] - left[i])
    s2 = right[j] + w[i, j] * (right[j + 1] - right[j])
    return float(s1), float(s2)


@table_block
def roller_table(sheet):
    """Every roller over one turn of the eccentric: rho, theoretical and practical profile."""
    import pandas as pd

    validate(sheet)
    K, PHI = _rollers(sheet)
    cols = {"k": K, "phi [deg]": PHI, "a [deg]": profile_values(sheet, "a", K, PHI)}
    for name in ("rho", "x_t", "y_t", "x_k", "y_k"):
        cols[f"{name} [mm]"] = profile_values(sheet, name, K, PHI)
    return pd.DataFrame(cols)


@table_block
def undercut_table(sheet):
    """Cusps and loop crossings of the practical profile (no rows when it is regular)."""
    import pandas as pd

    uc = undercut(sheet)
    rows = [(c["tooth"], "cusp", c["phi"], None, c["psi"], c["x"], c["y"]) for c in uc["cusps"]]
    rows += [
        (c["tooth"], "loop crossing", c["phi1"], c["phi2"], c["psi"], c["x"], c["y"])
        for c in uc["loops"]
    ]
    cols = ["tooth", "kind", "phi [deg]", "phi2 [deg]", "psi [deg]", "x_k [mm]", "y_k [mm]"]
    df = pd.DataFrame(rows, columns=cols)
    df = df.sort_values(["tooth", "phi [deg]"], kind="stable").reset_index(drop=True)
    # a cusp has one angle: leave the second cell empty (None), not "nan"
    df["phi2 [deg]"] = df["phi2 [deg]"].astype(object).where(df["phi2 [deg]"].notna(), None)
    return df


def _verdict_text(sheet) -> str:
    """Why the practical profile is invalid ("" when it is regular)."""
    rp, packing = _mag(sheet, "rp", "mm"), _mag(sheet, "rp_packing", "mm")
    parts = []
    if _mag(sheet, "below_curvature") != 1:
        parts.append(
            f"rp = {rp:g} mm exceeds the smallest radius of curvature of the concave "
            f"parts of the theoretical profile, {_mag(sheet, 'rho_min', 'mm'):.6g} mm: the "
            f"practical profile is undercut (cusps and a loop on each of its "
            f"{undercut(sheet)['teeth']} teeth)"
        )
    if _mag(sheet, "below_packing") != 1:
        parts.append(
            f"rp = {rp:g} mm reaches the packing limit (r2 - e1)*sin(pi/n) = "
            f"{packing:.6g} mm: neighbouring rollers overlap"
        )
    return "; ".join(parts)


@findings_block
def findings(sheet) -> list[Finding]:
    """Closure of the n roller traces, the printed variants, and the undercut verdict."""
    out: list[Finding] = []

    def add(topic, what, value=None, unit="", verdict="info", note=""):
        out.append(Finding(topic, what, value, unit, verdict, note))

    try:
        validate(sheet)
    except (InputError, LimitError) as err:
        return [Finding("inputs", err.message, None, "", "fail")]
    if _mag(sheet, "e1", "mm") == 0:
        r2 = _mag(sheet, "r2", "mm")
        add(
            "profile",
            "e1 = 0: the theoretical profile is the circle of radius r2 (no teeth)",
            r2,
            "mm",
        )

    c, n = closure(sheet), int(round(_mag(sheet, "n")))
    what = f"largest distance of the traces of rollers 1..{n - 1} from the trace of roller 0"
    what += f" ({c['points']} points, one eccentric turn)"
    if c["max"] <= CLOSURE_TOL_MM:
        add("closure", what, c["max"], "mm", "ok", f"tolerance {CLOSURE_TOL_MM:g} mm")
    else:
        note = f"the traces do not coincide (worst: roller {c['k']} at phi = {c['phi']:g} deg): "
        add(
            "closure",
            what,
            c["max"],
            "mm",
            "fail",
            note + "the n rollers would cut n different cams",
        )
    if (sheet.evaluate("transform"), sheet.evaluate("ratio")) == ("rotation", "lobes"):
        for label, changes in (
            ("the printed transform (4)", {"transform": "printed"}),
            ("the printed ratio a = phi/n", {"ratio": "printed"}),
            ("the printed (4) and ratio together", {"transform": "printed", "ratio": "printed"}),
        ):
            d = closure(sheet.with_inputs(**changes))["max"]
            what = f"as printed, with {label}: largest distance between the roller traces"
            add(
                "closure",
                what,
                d,
                "mm",
                "info",
                "they do not coincide" if d > CLOSURE_TOL_MM else "",
            )

    if _mag(sheet, "kappa_max", "1/mm") > 0:
        phi = _mag(sheet, "phi_valley", "deg")
        x, y = (float(profile_values(sheet, name, 0, phi)) for name in ("x_t", "y_t"))
        what = "smallest radius of curvature of the concave parts of the theoretical profile "
        what += f"(roller 0 at phi = {phi:.6g} deg, x_t = {x:.6g} mm, y_t = {y:.6g} mm)"
        add("undercut", what, _mag(sheet, "rho_min", "mm"), "mm", "info", "rp must stay below it")
    else:
        what = "the theoretical profile has no concave part (Z^2*e1/r2 = "
        add("undercut", what + f"{_mag(sheet, 'concavity'):.6g} <= 1): no undercut whatever rp")
    rp, regular = _mag(sheet, "rp", "mm"), _mag(sheet, "regular") == 1
    if not regular:
        note = "the profile tables and the chart still show it"
        add("undercut", "INVALID PROFILE: " + _verdict_text(sheet), rp, "mm", "fail", note)
        uc = undercut(sheet)
        for c in uc["cusps"][:2]:
            what = f"tooth {c['tooth']}: cusp of the practical profile at phi = {c['phi']:.6g} deg"
            what += (
                f" (polar angle {c['psi']:.6g} deg), x_k = {c['x']:.6g} mm, y_k = {c['y']:.6g} mm"
            )
            add("undercut", what, c["phi"], "deg", "fail")
        for c in uc["loops"][:1]:
            what = f"tooth {c['tooth']}: the practical profile crosses itself (loop) at x_k = "
            what += f"{c['x']:.6g} mm, y_k = {c['y']:.6g} mm, polar angle {c['psi']:.6g} deg "
            what += f"(phi = {c['phi1']:.6g} and {c['phi2']:.6g} deg)"
            add("undercut", what, c["psi"], "deg", "fail")
        if uc["cusps"]:
            what = f"{len(uc['cusps'])} cusps and {len(uc['loops'])} loops in all"
            add("undercut", what + ": see the table 'undercut'", len(uc["cusps"]), "", "fail")

    # the practical profile must keep the distance rp from the theoretical one
    prof = _grid(sheet, "profile")
    d, _ = distance_to_trace(
        sheet, profile_values(sheet, "x_k", 0, prof), profile_values(sheet, "y_k", 0, prof)
    )
    gap = float(np.max(np.abs(d - rp)))
    what = (
        "distance of the practical profile from the theoretical profile: largest departure from rp"
    )
    if gap < 1e-9 * max(1.0, rp):
        add("undercut", what, gap, "mm", "ok")
    else:
        note = f"the practical profile comes as close as {float(np.min(d)):.6g} mm to the "
        note += "theoretical one: the roller would cut into the neighbouring flank"
        add("undercut", what, gap, "mm", "warning" if regular else "fail", note)
    return out


@export_block
def export_profile_csv(sheet, path, *, allow_invalid: bool = False, header: bool = True):
    """Write the closed practical profile as CSV points ``x,y,z`` in mm for CAD; returns the path.

    One point per step dphi of the eccentric over the turns that close the profile; the
    closing point (equal to the first) is left out. An undercut profile is refused unless
    ``allow_invalid`` (its loops would make a wrong CAD curve).
    """
    from pathlib import Path

    from ..outputs.atomic import check_target, replacing

    profile = sheet.table("profile").iloc[:-1]
    if _mag(sheet, "regular") != 1 and not allow_invalid:
        why = _verdict_text(sheet)
        raise InputError(
            f"the practical profile is invalid: {why}; reduce rp (or export anyway "
            "with allow_invalid=True)"
        )
    path = Path(path)
    check_target(path, kind="csv")
    lines = ["x_mm,y_mm,z_mm"] if header else []
    lines += [f"{x:.10f},{y:.10f},0" for x, y in zip(profile["x_k [mm]"], profile["y_k [mm]"])]
    with replacing(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path
