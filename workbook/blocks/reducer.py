"""Planetary roller reducer: tooth profile of the cam (template ``reducer-profile``).

Kireev, Kovalev, Ershov (2003), formulas (1)-(5). The template defines the theoretical
profile ``x_t(k, phi)``, ``y_t(k, phi)`` of roller k, their symbolic derivatives (``diff``),
the practical profile (5) ``x_k``, ``y_k`` and the curvature ``kappa_n``. This module reads
them through the sheet and

* tabulates the theoretical and practical profile of every roller (block tables);
* checks closure (the traces of all n rollers must coincide) by the distance of every
  point of rollers 1..n-1 from the trace of roller 0 (nearest point on the curve, refined by
  Newton's method on the exact derivatives);
* checks undercut: the smallest radius of curvature of the concave parts of the theoretical
  profile, the packing limit, and where the practical profile gets cusps and loops.

scipy is imported inside functions (the engine imports this module only when a template
asks for it).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from . import Finding, export_block, findings_block, table_block

#: The closure check passes when the traces agree to this distance (mm).
CLOSURE_TOL_MM = 1e-9
#: Step of the dense sampling used to find nearest points and curvature extremes (deg of phi).
_SAMPLE_DEG = 0.25


@dataclass
class Undercut:
    concave: bool  # the theoretical profile has concave parts (seen from the roller side)
    rho_min: float  # smallest radius of curvature of the concave parts, mm (inf if none)
    phi_at: float  # eccentric angle of roller 0 where it occurs, deg
    point: tuple[float, float]  # (x_t, y_t) there, mm
    packing: float  # (r2 - e1) sin(pi/n), mm
    cusps: list = field(default_factory=list)  # dicts: tooth, phi, psi, x, y
    loops: list = field(default_factory=list)  # dicts: tooth, phi1, phi2, psi, x, y
    bad_intervals: int = 0

    def regular(self, rp: float) -> bool:
        return rp < self.rho_min and rp < self.packing


_UNITS = {"x_t": "mm", "y_t": "mm", "dx_t": "mm/deg", "dy_t": "mm/deg"}
_UNITS.update({"ddx_t": "mm/deg^2", "ddy_t": "mm/deg^2", "x_k": "mm", "y_k": "mm"})
_UNITS.update({"dx_k": "mm/deg", "dy_k": "mm/deg", "kappa_n": "1/mm"})


@dataclass
class Model:
    """The sheet's profile functions of (k, phi in deg) as numbers, and the scene's data."""

    sheet: object
    n: int
    Z: float
    i_a: float
    turns: int  # eccentric turns after which roller 0 has traced the whole closed profile
    e1: float
    r2: float
    rp_s: float
    dphi: float
    memo: dict = field(default_factory=dict)

    def __call__(self, name: str, k, phi_deg):
        shape = np.broadcast(np.asarray(k), np.asarray(phi_deg)).shape
        out = self.sheet.evaluate(name, k=k, phi=phi_deg).to(_UNITS[name]).magnitude
        return np.broadcast_to(np.asarray(out, dtype=float), shape)

    def derivs(self, k, phi_deg):
        """x_t, y_t and their first and second derivatives per degree of phi (arrays)."""
        names = ("x_t", "y_t", "dx_t", "dy_t", "ddx_t", "ddy_t")
        return tuple(self(n, k, phi_deg) for n in names)

    def practical(self, k, phi_deg):
        """(x_k, y_k) of (5)."""
        return self("x_k", k, phi_deg), self("y_k", k, phi_deg)

    def kappa_n(self, k, phi_deg):
        """Curvature of the theoretical profile toward the offset side, 1/mm."""
        return self("kappa_n", k, phi_deg)

    def offset_point_and_tangent(self, phi_deg, k=0):
        """Practical-profile point and its derivative per degree (exact, from diff)."""
        return tuple(self(n, k, phi_deg) for n in ("x_k", "y_k", "dx_k", "dy_k"))

    @property
    def period(self) -> float:
        return 360.0 * self.turns


_MODELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _mag(sheet, name: str, unit: str) -> float:
    return float(sheet.evaluate(name).to(unit).magnitude)


def model(sheet) -> Model:
    """The model of ``sheet`` (built once, cached per Sheet object)."""
    m = _MODELS.get(sheet)
    if m is None:
        m = _build(sheet)
        _MODELS[sheet] = m
    return m


def validate(sheet) -> None:
    """Refuse inputs for which the mechanism does not exist, with a message saying why."""
    n = _mag(sheet, "n", "")
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


def _build(sheet) -> Model:
    validate(sheet)
    i_a = _mag(sheet, "i_a", "")
    if i_a == 0:
        raise InputError("the cam does not turn (a/phi = 0): no profile is traced")
    turns = int(round(1 / abs(i_a)))
    if abs(turns * abs(i_a) - 1) > 1e-9:
        raise InputError(f"a/phi = {i_a:g} is not 1/(whole number): the trace never closes")
    return Model(
        sheet=sheet,
        n=int(round(_mag(sheet, "n", ""))),
        Z=_mag(sheet, "Z", ""),
        i_a=i_a,
        turns=turns,
        e1=_mag(sheet, "e1", "mm"),
        r2=_mag(sheet, "r2", "mm"),
        rp_s=_mag(sheet, "rp_s", "mm"),
        dphi=_mag(sheet, "dphi", "deg"),
    )


def _grid(last_deg: float, step_deg: float) -> np.ndarray:
    from ..ranges import range_values

    return range_values(0.0, step_deg, last_deg, what="reducer grid")


# ----------------------------------------------------------------------------------------
# nearest points, closure, undercut
# ----------------------------------------------------------------------------------------


def distance_to_trace(m: Model, px, py, k_ref: int = 0):
    """Distance of points (px, py) from the closed theoretical trace of roller ``k_ref``.

    Nearest sample on a dense grid (k-d tree), then Newton's method on
    g(s) = (C(s) - P) . C'(s) with the exact first and second derivatives.
    Returns (distance, parameter s in deg).
    """
    from scipy.spatial import cKDTree

    key = ("trace", k_ref)
    if key not in m.memo:
        s = np.arange(0.0, m.period, _SAMPLE_DEG)
        x, y, *_ = m.derivs(k_ref, s)
        m.memo[key] = (s, cKDTree(np.column_stack([x, y])))
    s_grid, tree = m.memo[key]
    px, py = np.asarray(px, dtype=float).ravel(), np.asarray(py, dtype=float).ravel()
    d0, idx = tree.query(np.column_stack([px, py]))
    s = s_grid[idx].copy()
    for _ in range(12):
        x, y, dx, dy, ddx, ddy = m.derivs(k_ref, s)
        g = (x - px) * dx + (y - py) * dy
        dg = dx * dx + dy * dy + (x - px) * ddx + (y - py) * ddy
        step = np.where(dg > 0, -g / np.where(dg > 0, dg, 1.0), 0.0)
        step = np.clip(step, -_SAMPLE_DEG, _SAMPLE_DEG)
        s = s + step
        if np.all(np.abs(step) < 1e-13 * max(1.0, m.period)):
            break
    x, y, *_ = m.derivs(k_ref, s)
    d = np.hypot(x - px, y - py)
    return np.minimum(d, d0), s


def closure(m: Model) -> dict:
    """Largest distance of the traces of rollers 1..n-1 (one eccentric turn) from roller 0's."""
    phi = _grid(360.0, m.dphi)
    K = np.repeat(np.arange(1, m.n), phi.size)
    PHI = np.tile(phi, m.n - 1)
    x, y, *_ = m.derivs(K, PHI)
    d, _ = distance_to_trace(m, x, y, 0)
    i = int(np.argmax(d))
    return {"max": float(d[i]), "k": int(K[i]), "phi": float(PHI[i]), "points": int(d.size)}


def closed_form_deviation(m: Model) -> float:
    """Largest |radius - R_closed(psi)| over all rollers and one turn (psi: polar angle)."""
    sheet = m.sheet
    phi = _grid(360.0, m.dphi)
    K = np.repeat(np.arange(m.n), phi.size)
    PHI = np.tile(phi, m.n)
    x, y, *_ = m.derivs(K, PHI)
    psi = np.degrees(np.arctan2(y, x))
    R = sheet.evaluate("R_closed", psi=psi).to("mm").magnitude
    return float(np.max(np.abs(np.hypot(x, y) - R)))


def undercut(m: Model) -> Undercut:
    """Smallest concave radius of curvature, cusps and loops of the practical profile."""
    if "undercut" in m.memo:
        return m.memo["undercut"]
    from scipy.optimize import brentq, minimize_scalar

    packing = _mag(m.sheet, "rp_packing", "mm")
    L = m.period
    s = np.arange(0.0, L, _SAMPLE_DEG)
    kap = m.kappa_n(0, s)
    # the first tooth where the curvature is largest (all teeth are alike when the traces close)
    i = int(np.argmax(kap >= kap.max() - 1e-9 * abs(kap.max())))
    if kap[i] > 0:
        res = minimize_scalar(
            lambda t: -float(m.kappa_n(0, t)),
            bounds=(s[i] - _SAMPLE_DEG, s[i] + _SAMPLE_DEG),
            method="bounded",
            options={"xatol": 1e-10},
        )
        phi_at = float(res.x) % L
        kmax = max(float(m.kappa_n(0, phi_at)), float(kap[i]))
        x, y, *_ = m.derivs(0, phi_at)
        out = Undercut(True, 1.0 / kmax, phi_at, (float(x), float(y)), packing)
    else:
        out = Undercut(False, math.inf, math.nan, (math.nan, math.nan), packing)
    rp = abs(m.rp_s)
    g = 1.0 - rp * kap
    if out.concave and np.any(g <= 0):
        # begin the scan at phi = 0, or where the offset is surely regular: teeth count from there
        start = 0 if g[0] > 0 else int(np.argmax(g))
        ss = np.concatenate([s[start:], s[:start] + L, [s[start] + L]])
        gg = np.concatenate([g[start:], g[:start], [g[start]]])

        def gfun(t):
            return 1.0 - rp * float(m.kappa_n(0, t))

        crossings = np.nonzero(np.sign(gg[:-1]) != np.sign(gg[1:]))[0]
        roots = [brentq(gfun, ss[j], ss[j + 1], xtol=1e-12) for j in crossings]
        pairs = [(roots[j], roots[j + 1]) for j in range(0, len(roots) - 1, 2)]
        out.bad_intervals = len(pairs)
        for tooth, (c1, c2) in enumerate(pairs, start=1):
            for c in (c1, c2):
                xk, yk = m.practical(0, c)
                out.cusps.append(
                    {
                        "tooth": tooth,
                        "phi": c % L,
                        "psi": math.degrees(math.atan2(float(yk), float(xk))),
                        "x": float(xk),
                        "y": float(yk),
                    }
                )
            loop = _loop_crossing(m, c1, c2, L)
            if loop is not None:
                loop["tooth"] = tooth
                out.loops.append(loop)
    m.memo["undercut"] = out
    return out


def _loop_crossing(m: Model, c1: float, c2: float, L: float):
    """Self-intersection of the practical profile around the cusp pair (c1, c2)."""
    half = min(180.0, L / 2)
    mid = 0.5 * (c1 + c2)
    left = np.linspace(mid - half, c1, 721)
    right = np.linspace(c2, mid + half, 721)
    ax, ay, *_ = m.offset_point_and_tangent(left)
    bx, by, *_ = m.offset_point_and_tangent(right)
    p, r = (
        np.column_stack([ax[:-1], ay[:-1]]),
        np.column_stack([ax[1:] - ax[:-1], ay[1:] - ay[:-1]]),
    )
    q, u = (
        np.column_stack([bx[:-1], by[:-1]]),
        np.column_stack([bx[1:] - bx[:-1], by[1:] - by[:-1]]),
    )
    # segments p + t r and q + w u: solve for t, w in [0, 1]
    P, R = p[:, None, :], r[:, None, :]
    Q, U = q[None, :, :], u[None, :, :]
    cross = R[..., 0] * U[..., 1] - R[..., 1] * U[..., 0]
    qp = Q - P
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * U[..., 1] - qp[..., 1] * U[..., 0]) / cross
        w = (qp[..., 0] * R[..., 1] - qp[..., 1] * R[..., 0]) / cross
    hit = (cross != 0) & (t >= 0) & (t <= 1) & (w >= 0) & (w <= 1)
    if not hit.any():
        return None
    ii, jj = np.nonzero(hit)
    best = int(np.argmin(right[jj] - left[ii]))  # the innermost crossing
    i, j = int(ii[best]), int(jj[best])
    s1 = left[i] + t[i, j] * (left[i + 1] - left[i])
    s2 = right[j] + w[i, j] * (right[j + 1] - right[j])
    for _ in range(30):  # Newton on P(s1) - P(s2) = 0
        x1, y1, dx1, dy1 = (float(v) for v in m.offset_point_and_tangent(s1))
        x2, y2, dx2, dy2 = (float(v) for v in m.offset_point_and_tangent(s2))
        F = np.array([x1 - x2, y1 - y2])
        J = np.array([[dx1, -dx2], [dy1, -dy2]])
        try:
            step = np.linalg.solve(J, -F)
        except np.linalg.LinAlgError:
            break
        s1, s2 = s1 + step[0], s2 + step[1]
        if np.max(np.abs(step)) < 1e-12:
            break
    x, y, *_ = m.offset_point_and_tangent(s1)
    return {
        "phi1": s1 % L,
        "phi2": s2 % L,
        "psi": math.degrees(math.atan2(float(y), float(x))),
        "x": float(x),
        "y": float(y),
    }


# ----------------------------------------------------------------------------------------
# blocks
# ----------------------------------------------------------------------------------------


@table_block
def roller_table(sheet):
    """Every roller over one turn of the eccentric: rho, theoretical and practical profile."""
    import pandas as pd

    m = model(sheet)
    phi = _grid(360.0, m.dphi)
    K = np.repeat(np.arange(m.n), phi.size)
    PHI = np.tile(phi, m.n)
    xt, yt = m("x_t", K, PHI), m("y_t", K, PHI)
    xk, yk = m.practical(K, PHI)
    return pd.DataFrame(
        {
            "k": K,
            "phi [deg]": PHI,
            "a [deg]": sheet.evaluate("a", phi=PHI).to("deg").magnitude,
            "rho [mm]": sheet.evaluate("rho", k=K, phi=PHI).to("mm").magnitude,
            "x_t [mm]": xt,
            "y_t [mm]": yt,
            "x_k [mm]": xk,
            "y_k [mm]": yk,
        }
    )


@table_block
def profile_table(sheet):
    """The closed cam profile: roller 0 over the eccentric turns that close its trace."""
    import pandas as pd

    m = model(sheet)
    phi = _grid(m.period, m.dphi)
    xt, yt = m("x_t", 0, phi), m("y_t", 0, phi)
    xk, yk = m.practical(0, phi)
    kap = m.kappa_n(0, phi)
    regular = (1.0 - abs(m.rp_s) * kap > 0).astype(int)
    df = pd.DataFrame(
        {
            "phi [deg]": phi,
            "psi [deg]": np.degrees(np.arctan2(yt, xt)),
            "x_t [mm]": xt,
            "y_t [mm]": yt,
            "x_k [mm]": xk,
            "y_k [mm]": yk,
            "kappa_n [1/mm]": kap,
            "regular": regular,
        }
    )
    uc = undercut(m)
    if not uc.regular(abs(m.rp_s)):
        df.attrs["invalid"] = _verdict_text(m, uc)
    return df


@table_block
def undercut_table(sheet):
    """Cusps and loop crossings of the practical profile (no rows when it is regular)."""
    import pandas as pd

    m = model(sheet)
    uc = undercut(m)
    rows = []
    for c in uc.cusps:
        rows.append(
            {
                "tooth": c["tooth"],
                "kind": "cusp",
                "phi [deg]": c["phi"],
                "phi2 [deg]": math.nan,
                "psi [deg]": c["psi"],
                "x_k [mm]": c["x"],
                "y_k [mm]": c["y"],
            }
        )
    for c in uc.loops:
        rows.append(
            {
                "tooth": c["tooth"],
                "kind": "loop crossing",
                "phi [deg]": c["phi1"],
                "phi2 [deg]": c["phi2"],
                "psi [deg]": c["psi"],
                "x_k [mm]": c["x"],
                "y_k [mm]": c["y"],
            }
        )
    cols = ["tooth", "kind", "phi [deg]", "phi2 [deg]", "psi [deg]", "x_k [mm]", "y_k [mm]"]
    df = pd.DataFrame(rows, columns=cols)
    df = df.sort_values(["tooth", "phi [deg]"], kind="stable").reset_index(drop=True)
    # a cusp has one angle: leave the second cell empty (None), not "nan"
    df["phi2 [deg]"] = df["phi2 [deg]"].astype(object).where(df["phi2 [deg]"].notna(), None)
    return df


def _verdict_text(m: Model, uc: Undercut) -> str:
    rp = abs(m.rp_s)
    parts = []
    if rp >= uc.rho_min:
        parts.append(
            f"rp = {rp:g} mm exceeds the smallest radius of curvature of the concave "
            f"parts of the theoretical profile, {uc.rho_min:.6g} mm: the practical "
            f"profile is undercut (cusps and a loop on each of its "
            f"{uc.bad_intervals} teeth)"
        )
    if rp >= uc.packing:
        parts.append(
            f"rp = {rp:g} mm reaches the packing limit (r2 - e1)*sin(pi/n) = "
            f"{uc.packing:.6g} mm: neighbouring rollers overlap"
        )
    return "; ".join(parts)


@findings_block
def findings(sheet) -> list[Finding]:
    """Closure of the n roller traces, the printed variants, and the undercut verdict."""
    out: list[Finding] = []
    try:
        m = model(sheet)
    except InputError as err:
        return [Finding("inputs", err.message, None, "", "fail")]
    variant = (sheet.evaluate("transform"), sheet.evaluate("ratio"))
    corrected = variant == ("rotation", "lobes")
    out.append(
        Finding(
            "profile",
            f"Z = {m.Z:g} lobes; the cam turns by a = {m.i_a:+.6g}*phi; transform "
            f"(4): {variant[0]}; ratio: {variant[1]}",
            m.Z,
            "",
            "info",
            "" if corrected else "a printed variant, kept to show what the paper's formulas give",
        )
    )
    if m.e1 == 0:
        out.append(
            Finding(
                "profile",
                "e1 = 0: the theoretical profile is the circle of radius r2 (no teeth)",
                m.r2,
                "mm",
                "info",
            )
        )

    c = closure(m)
    ok = c["max"] <= CLOSURE_TOL_MM
    out.append(
        Finding(
            "closure",
            f"largest distance of the traces of rollers 1..{m.n - 1} from the trace of "
            f"roller 0 ({c['points']} points, one eccentric turn)",
            c["max"],
            "mm",
            "ok" if ok else "fail",
            f"tolerance {CLOSURE_TOL_MM:g} mm"
            if ok
            else f"the traces do not coincide (worst: roller {c['k']} at phi = {c['phi']:g} deg): "
            "the n rollers would cut n different cams",
        )
    )
    if corrected:
        dev = closed_form_deviation(m)
        out.append(
            Finding(
                "closure",
                "largest deviation from the closed form "
                "R(psi) = e1*cos(Z*psi) + sqrt(r2^2 - e1^2*sin(Z*psi)^2)",
                dev,
                "mm",
                "ok" if dev < 1e-9 else "warning",
            )
        )
        for label, changes in (
            ("the printed transform (4)", {"transform": "printed"}),
            ("the printed ratio a = phi/n", {"ratio": "printed"}),
            ("the printed (4) and ratio together", {"transform": "printed", "ratio": "printed"}),
        ):
            try:
                other = closure(model(sheet.with_inputs(**changes)))["max"]
            except InputError as err:
                out.append(
                    Finding("closure", f"as printed, with {label}", None, "", "info", err.message)
                )
                continue
            out.append(
                Finding(
                    "closure",
                    f"as printed, with {label}: largest distance between the roller traces",
                    other,
                    "mm",
                    "info",
                    "they do not coincide" if other > CLOSURE_TOL_MM else "",
                )
            )

    uc = undercut(m)
    rp = abs(m.rp_s)
    if uc.concave:
        out.append(
            Finding(
                "undercut",
                f"smallest radius of curvature of the concave parts of the theoretical "
                f"profile (roller 0 at phi = {uc.phi_at:.6g} deg, x_t = {uc.point[0]:.6g} mm, "
                f"y_t = {uc.point[1]:.6g} mm)",
                uc.rho_min,
                "mm",
                "info",
                "rp must stay below it",
            )
        )
    else:
        out.append(
            Finding(
                "undercut",
                "the theoretical profile has no concave part (Z^2*e1/r2 = "
                f"{m.Z**2 * m.e1 / m.r2:.6g} <= 1): no undercut whatever rp",
                None,
                "",
                "info",
            )
        )
    out.append(
        Finding(
            "undercut",
            "packing limit (r2 - e1)*sin(pi/n)",
            uc.packing,
            "mm",
            "info",
            "neighbouring rollers touch when rp reaches it",
        )
    )
    if uc.regular(rp):
        margin = min(uc.rho_min, uc.packing) - rp
        out.append(
            Finding(
                "undercut",
                f"rp = {rp:g} mm is below both limits: the practical "
                "profile is regular (no cusps, no loops)",
                margin,
                "mm",
                "ok",
                "margin to the nearer limit",
            )
        )
    else:
        out.append(
            Finding(
                "undercut",
                "INVALID PROFILE: " + _verdict_text(m, uc),
                rp,
                "mm",
                "fail",
                "the profile tables and the chart still show it",
            )
        )
        for cusp in uc.cusps[:2]:
            out.append(
                Finding(
                    "undercut",
                    f"tooth {cusp['tooth']}: cusp of the practical profile at phi = "
                    f"{cusp['phi']:.6g} deg (polar angle {cusp['psi']:.6g} deg), "
                    f"x_k = {cusp['x']:.6g} mm, y_k = {cusp['y']:.6g} mm",
                    cusp["phi"],
                    "deg",
                    "fail",
                )
            )
        for loop in uc.loops[:1]:
            out.append(
                Finding(
                    "undercut",
                    f"tooth {loop['tooth']}: the practical profile crosses itself "
                    f"(loop) at x_k = {loop['x']:.6g} mm, y_k = {loop['y']:.6g} mm, polar angle "
                    f"{loop['psi']:.6g} deg (phi = {loop['phi1']:.6g} and {loop['phi2']:.6g} deg)",
                    loop["psi"],
                    "deg",
                    "fail",
                )
            )
        if uc.cusps:
            out.append(
                Finding(
                    "undercut",
                    f"{len(uc.cusps)} cusps and {len(uc.loops)} loops in "
                    "all: see the table 'undercut'",
                    len(uc.cusps),
                    "",
                    "fail",
                )
            )

    # the practical profile must keep the distance rp from the theoretical one
    prof = _grid(m.period, m.dphi)
    xk, yk = m.practical(0, prof)
    d, _ = distance_to_trace(m, xk, yk, 0)
    gap = float(np.max(np.abs(d - rp)))
    ok = gap < 1e-9 * max(1.0, rp)
    out.append(
        Finding(
            "undercut",
            "distance of the practical profile from the theoretical profile: largest "
            "departure from rp",
            gap,
            "mm",
            "ok" if ok else ("fail" if not uc.regular(rp) else "warning"),
            ""
            if ok
            else f"the practical profile comes as close as {float(np.min(d)):.6g} mm to "
            "the theoretical one: the roller would cut into the neighbouring flank",
        )
    )
    return out


# ----------------------------------------------------------------------------------------
# CAD export (workbook run reducer-profile --export PATH)
# ----------------------------------------------------------------------------------------


@export_block
def export_profile_csv(sheet, path, *, allow_invalid: bool = False, header: bool = True):
    """Write the closed practical profile as CSV points ``x,y,z`` in mm for CAD; returns the path.

    One point per step dphi of the eccentric over the turns that close the profile; the
    closing point (equal to the first) is left out. An undercut profile is refused unless
    ``allow_invalid`` (its loops would make a wrong CAD curve).
    """
    from pathlib import Path

    from ..atomic import check_target, replacing

    m = model(sheet)
    uc = undercut(m)
    if not uc.regular(abs(m.rp_s)) and not allow_invalid:
        raise InputError(
            "the practical profile is invalid: "
            + _verdict_text(m, uc)
            + "; reduce rp (or export anyway with allow_invalid=True)"
        )
    phi = _grid(m.period, m.dphi)[:-1]
    xk, yk = m.practical(0, phi)
    path = Path(path)
    check_target(path, kind="csv")
    lines = ["x_mm,y_mm,z_mm"] if header else []
    lines += [f"{x:.10f},{y:.10f},0" for x, y in zip(xk, yk)]
    with replacing(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path
