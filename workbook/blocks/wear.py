"""Blocks of the cam-wear sheets (Ivashko, Buikus, Osuchukwu 2006).

Every formula is the template's, read through the sheet; the time-sections are the template's
integrals, split where the integrand has a kink. Valve (templates/cam-wear-valve.toml):

* ``measured_lift`` (table): a worn lift given as measured points (CSV with units in the
  header); velocity and acceleration by a Savitzky-Golay filter whose noise gain is reported.
* ``valve_findings``: validity of (3), port cap, (1) and (2) against (3), wear deeper than the
  lift, the measured-lift time-section and noise gains.

Pump (cam-wear-pump.toml): ``pump_findings``.

Brake (cam-wear-brake.toml): ``brake_findings``.

scipy is imported inside the functions.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from . import Finding, cached, findings_block, input_magnitude, table_block


def _valve_numbers(sheet) -> dict:
    q = functools.partial(input_magnitude, sheet)
    return dict(
        d=q("d", "mm"),
        d1=q("d1", "mm"),
        alpha=q("alpha", "rad"),
        d_stem=q("d_stem", "mm"),
        H=q("H", "mm"),
        Phi=q("Phi", "deg"),
        p=q("p", ""),
        cases={
            "unworn": (0.0, 0.0),
            "worn 1": (q("w_b1", "mm"), q("w_n1", "mm")),
            "worn 2": (q("w_b2", "mm"), q("w_n2", "mm")),
        },
    )


# ---------------------------------------------------------------------------------------------
# Valve: measured lift
# ---------------------------------------------------------------------------------------------
SG_WINDOW = 15  # points (30 deg at a 2 deg spacing); cubic Savitzky-Golay
SG_ORDER = 3


def measured_points(sheet):
    """The measured lift of the template's [data.measured_lift] (phi in deg, h in mm), checked
    for what the Savitzky-Golay filter needs: enough points, increasing in equal steps."""
    from .. import units as un
    from ..errors import InputError

    phi, h = (sheet.spec.data[n] for n in ("phi_m", "h_m"))
    where = f"{phi.file.name} ([data.measured_lift])"
    phi = phi.values * un.factor(phi.unit, un.unit("deg"))
    h = h.values * un.factor(h.unit, un.unit("mm"))
    if len(phi) < 2 * SG_WINDOW:
        raise InputError(f"{where}: {len(phi)} points; at least {2 * SG_WINDOW} are needed")
    step = np.diff(phi)
    if np.any(step <= 0) or np.ptp(step) > 1e-6 * step.mean():
        raise InputError(f"{where}: the angles must increase in equal steps")
    return phi, h


def _measured(sheet):
    def make():
        from scipy.signal import savgol_coeffs, savgol_filter

        phi, h = measured_points(sheet)
        dphi = float(phi[1] - phi[0])
        omega = float(sheet.evaluate("n").to("deg/s").magnitude)
        hs = savgol_filter(h, SG_WINDOW, SG_ORDER, mode="interp")
        d1 = savgol_filter(h, SG_WINDOW, SG_ORDER, deriv=1, delta=dphi, mode="interp")
        d2 = savgol_filter(h, SG_WINDOW, SG_ORDER, deriv=2, delta=dphi, mode="interp")
        g0 = math.sqrt(float(np.sum(savgol_coeffs(SG_WINDOW, SG_ORDER) ** 2)))
        g1 = math.sqrt(float(np.sum(savgol_coeffs(SG_WINDOW, SG_ORDER, deriv=1, delta=dphi) ** 2)))
        g2 = math.sqrt(float(np.sum(savgol_coeffs(SG_WINDOW, SG_ORDER, deriv=2, delta=dphi) ** 2)))
        # central differences (numpy.gradient, twice) for comparison
        c1 = 1 / (math.sqrt(2) * dphi)
        c2 = math.sqrt(6) / (4 * dphi**2)
        # residual of a linear smoother: E|(I - S)e|^2 = sigma^2*(1 - c0) per point, c0 = g0^2
        mid = np.abs(phi - phi.mean()) < np.ptp(phi) / 3
        sigma = float(np.sqrt(np.mean((h - hs)[mid] ** 2) / (1 - g0**2)))
        truth = {k: sheet.evaluate(k, phi=phi) for k in ("h_w2", "v_w2", "a_w2")}
        return dict(
            phi=phi,
            h=h,
            hs=hs,
            v=d1 * omega * 1e-3,
            a=d2 * omega**2 * 1e-3,
            vc=np.gradient(h, dphi) * omega * 1e-3,
            ac=np.gradient(np.gradient(h, dphi), dphi) * omega**2 * 1e-3,
            gain=(g0, g1, g2),
            central=(c1, c2),
            sigma=sigma,
            dphi=dphi,
            omega=omega,
            h_true=truth["h_w2"].to("mm").magnitude,
            v_true=truth["v_w2"].to("m/s").magnitude,
            a_true=truth["a_w2"].to("m/s^2").magnitude,
        )

    return cached(sheet, "measured", make)


@table_block
def measured_lift(sheet):
    """Measured worn lift: Savitzky-Golay velocity and acceleration against the wear formula."""
    import pandas as pd

    m = _measured(sheet)
    return pd.DataFrame(
        {
            "phi [deg]": m["phi"],
            "h measured [mm]": m["h"],
            "h smoothed [mm]": m["hs"],
            "h formula [mm]": m["h_true"],
            "v Savitzky-Golay [m/s]": m["v"],
            "v central differences [m/s]": m["vc"],
            "v formula [m/s]": m["v_true"],
            "a Savitzky-Golay [m/s^2]": m["a"],
            "a central differences [m/s^2]": m["ac"],
            "a formula [m/s^2]": m["a_true"],
        }
    )


def measured_time_section(sheet) -> float:
    """Time-section (mm^2*deg) of the measured lift: trapezoid of (3) at the measured points."""
    m = _measured(sheet)
    area = sheet.evaluate("f3", h=np.maximum(m["h"], 0.0)).to("mm^2").magnitude
    return float(np.sum((area[1:] + area[:-1]) / 2 * np.diff(m["phi"])))


# ---------------------------------------------------------------------------------------------
# Valve: findings
# ---------------------------------------------------------------------------------------------
@findings_block
def valve_findings(sheet):
    """Validity of (3), port cap, (1)/(2) against (3), wear against lift, measured lift."""
    out = []
    mm = lambda name: float(sheet.evaluate(name).to("mm").magnitude)  # noqa: E731
    num = _valve_numbers(sheet)
    H, Phi = num["H"], num["Phi"]
    h_lim, h_port = mm("h_lim"), mm("h_port")
    topic = "validity of (3)"
    if H > h_lim:
        phi_lim = float(sheet.evaluate("phi_lim").to("deg").magnitude)
        out.append(
            Finding(
                topic,
                "the lift passes the validity limit of (3), (d1 - d)/sin(2a),",
                h_lim,
                "mm",
                "warning",
                f"H = {H:g} mm; (3) holds for phi < {phi_lim:.1f} deg and after "
                f"{Phi - phi_lim:.1f} deg. The paper's time-sections use (3) over the "
                "whole lift; TS_eff uses the second regime above the limit",
            )
        )
        ts3, tse = (float(sheet.evaluate(k).to("mm^2*deg").magnitude) for k in ("TS0", "TS0_eff"))
        out.append(
            Finding(
                topic,
                "(3) beyond its limit, against the second regime, changes the unworn "
                "time-section by",
                100 * (ts3 / tse - 1),
                "%",
                "info",
                f"{ts3:.0f} against {tse:.0f} mm^2*deg with the second regime",
            )
        )
    else:
        out.append(
            Finding(topic, "the whole lift is within the validity limit of (3)", h_lim, "mm", "ok")
        )
    if H >= h_port:
        out.append(
            Finding(
                "port cap",
                "the flow area reaches the port area at the lift",
                h_port,
                "mm",
                "info",
                "above it the port, not the seat, limits the flow",
            )
        )
    else:
        out.append(
            Finding(
                "port cap",
                "the port area would cap the flow above the lift",
                h_port,
                "mm",
                "ok",
                f"not reached: H = {H:g} mm",
            )
        )
    for h in (1.0, 5.0, H):
        f1, f2, f3 = (
            float(sheet.evaluate(k, h=h).to("mm^2").magnitude) for k in ("f1", "f2", "f3")
        )
        out.append(
            Finding(
                "(1) and (2) against (3)",
                f"at h = {h:g} mm, (1) with the fixed d1 differs from (3) by",
                100 * (f1 / f3 - 1),
                "%",
                "info",
                f"(2) as printed by {100 * (f2 / f3 - 1):+.2f} %; (1) equals (3) "
                f"only with d1 = d + 2h sin(a)cos(a) = "
                f"{float(sheet.evaluate('d1_eq', h=h).to('mm').magnitude):.3f} mm",
            )
        )
    for label, (w_b, w_n) in num["cases"].items():
        if label == "unworn":
            continue
        at = dict(wb=w_b, wn=w_n)
        top = float(sheet.evaluate("top", **at).to("mm").magnitude)
        nose = float(sheet.evaluate("h_raw", phi=Phi / 2, **at).to("mm").magnitude)  # h0 = H
        if top <= 0:
            out.append(
                Finding(
                    "wear against lift",
                    f"{label}: the wear is deeper than the lift "
                    "everywhere: the worn cam never opens the valve",
                    top,
                    "mm",
                    "fail",
                    "its time-section is zero",
                )
            )
            continue
        o, c = (float(sheet.evaluate(k, **at).to("deg").magnitude) for k in ("phi_o", "phi_c"))
        if nose <= 0:
            out.append(
                Finding(
                    "wear against lift",
                    f"{label}: the wear at the nose ({w_n:g} mm) "
                    f"is deeper than the lift ({H:g} mm): the worn lift dips to zero "
                    "at the nose and the valve opens twice",
                    top,
                    "mm",
                    "warning",
                    f"greatest worn lift; open for {2 * (c - o):.1f} deg in all",
                )
            )
            continue
        out.append(
            Finding(
                "wear against lift",
                f"{label}: the valve opens for",
                Phi - 2 * o,
                "deg",
                "info",
                f"unworn {Phi:g} deg; greatest worn lift {top:.3f} mm",
            )
        )
    for k in ("dTS1", "dTS2"):
        out.append(
            Finding(
                "time-section",
                f"change of the time-section by wear ({k})",
                float(sheet.evaluate(k).to("percent").magnitude),
                "%",
                "info",
            )
        )
    try:
        m = _measured(sheet)
    except Exception as exc:  # a missing or bad table is reported, not fatal to the checks
        out.append(
            Finding(
                "measured lift", "the measured lift could not be read", None, "", "fail", str(exc)
            )
        )
        return out
    ts_m = measured_time_section(sheet)
    ts_f = float(sheet.evaluate("TS2").to("mm^2*deg").magnitude)
    out.append(
        Finding(
            "measured lift",
            "time-section of the measured lift (trapezoid)",
            ts_m,
            "mm^2*deg",
            "info",
            (
                f"{100 * (ts_m / ts_f - 1):+.2f} % against the wear formula (worn 2)"
                if ts_f
                else "the wear formula (worn 2) gives zero"
            ),
        )
    )
    g0, g1, g2 = m["gain"]
    c1, c2 = m["central"]
    out.append(
        Finding(
            "measured lift",
            "noise estimated from the residual of the smoothing",
            1e3 * m["sigma"],
            "um",
            "info",
        )
    )
    out.append(
        Finding(
            "measured lift",
            "noise gain of the velocity (Savitzky-Golay, "
            f"{SG_WINDOW} points, cubic; sigma_v = gain*sigma_h*omega)",
            g1,
            "1/deg",
            "info",
            f"central differences: {c1:.4f} 1/deg, {c1 / g1:.1f} times more noise",
        )
    )
    out.append(
        Finding(
            "measured lift",
            "noise gain of the acceleration (sigma_a = gain*sigma_h*omega^2)",
            g2,
            "1/deg^2",
            "info",
            f"central differences twice: {c2:.4f} 1/deg^2, {c2 / g2:.0f} times more",
        )
    )
    away = np.abs(m["phi"] - Phi / 2) < Phi / 3
    err_v = float(np.sqrt(np.mean((m["v"] - m["v_true"])[away] ** 2)))
    err_vc = float(np.sqrt(np.mean((m["vc"] - m["v_true"])[away] ** 2)))
    err_a = float(np.sqrt(np.mean((m["a"] - m["a_true"])[away] ** 2)))
    err_ac = float(np.sqrt(np.mean((m["ac"] - m["a_true"])[away] ** 2)))
    out.append(
        Finding(
            "measured lift",
            "rms velocity error against the formula (middle two thirds)",
            err_v,
            "m/s",
            "info",
            f"central differences {err_vc:.3g} m/s",
        )
    )
    out.append(
        Finding(
            "measured lift",
            "rms acceleration error against the formula",
            err_a,
            "m/s^2",
            "info",
            f"central differences {err_ac:.3g} m/s^2; peak "
            f"|a| {float(np.max(np.abs(m['a_true']))):.3g} m/s^2",
        )
    )
    return out


# ---------------------------------------------------------------------------------------------
# Pump
# ---------------------------------------------------------------------------------------------
@findings_block
def pump_findings(sheet):
    """Active stroke within the acceleration section; (4)-(6) as printed; delivery with wear."""
    ev = lambda name, unit: float(sheet.evaluate(name).to(unit).magnitude)  # noqa: E731
    out = []
    h_1, h_gn, h_gk = ev("h_1", "mm"), ev("h_gn", "mm"), ev("h_gk", "mm")
    if h_gn <= 0:
        out.append(
            Finding(
                "delivery",
                "the port closes before the rise starts (dh > h_1)",
                h_gn,
                "mm",
                "fail",
                "choose dh smaller than the lift at the end of acceleration",
            )
        )
        return out  # the delivery angles and speeds do not exist
    if h_gk <= h_1:
        out.append(
            Finding(
                "delivery",
                "the active stroke lies inside the acceleration section, "
                "as (4)-(6) assume: end of delivery at the lift",
                h_gk,
                "mm",
                "ok",
                f"acceleration ends at {h_1:.4g} mm",
            )
        )
    else:
        out.append(
            Finding(
                "delivery",
                "the active stroke runs into the deceleration section: "
                "(4)-(6) do not hold; the angles here come from the cam itself",
                h_gk,
                "mm",
                "warning",
                f"acceleration ends at {h_1:.4g} mm",
            )
        )
    d4 = ev("phi_gk_4_printed", "deg") - ev("phi_gk", "deg")
    out.append(
        Finding(
            "(4)-(6) as printed",
            "(4) as printed puts the end of delivery late by",
            d4,
            "deg",
            "info",
            "0.5*phi_na is counted twice; with the mean speed c_na the printed form is right",
        )
    )
    out.append(
        Finding(
            "(4)-(6) as printed",
            "(6) as printed gives, in the m/s it claims",
            ev("c_na_6_printed", "mm/s"),
            "m/s",
            "info",
            f"1000 times too large: it is mm/s; with units {ev('c_na_6', 'm/s'):.4f} m/s",
        )
    )
    out.append(
        Finding(
            "(4)-(6) as printed",
            "(5): both printed forms agree, difference",
            ev("h_gk_5a", "mm") - ev("h_gk_5b", "mm"),
            "mm",
            "ok",
        )
    )
    out.append(
        Finding(
            "(4)-(6) as printed",
            "(7) is garbled and dimensionally wrong (it adds "
            "deg^2 to (m/s)^2): not evaluated; the speeds come from the cam",
            None,
            "",
            "info",
        )
    )
    H_pw = ev("H_pw", "mm")
    if H_pw <= h_gk:
        out.append(
            Finding(
                "wear",
                "the worn cam no longer reaches the geometric end of "
                "delivery: the delivery is cut short",
                H_pw,
                "mm",
                "fail",
                f"worn stroke {H_pw:.3f} mm, end of delivery at {h_gk:.3f} mm",
            )
        )
        return out
    out.append(
        Finding(
            "wear",
            "the geometric start of delivery comes later by",
            ev("dphi_gn", "deg"),
            "deg",
            "info",
            "cam shaft degrees: the injection timing retards",
        )
    )
    out.append(
        Finding(
            "wear",
            "active stroke duration, unworn -> worn",
            ev("phi_na_w", "deg"),
            "deg",
            "info",
            f"unworn {ev('phi_na', 'deg'):.3f} deg; mean speed "
            f"{ev('c_na', 'm/s'):.3f} -> {ev('c_na_w', 'm/s'):.3f} m/s",
        )
    )
    return out


# ---------------------------------------------------------------------------------------------
# Brake
# ---------------------------------------------------------------------------------------------
def _brake_numbers(sheet):
    q = functools.partial(input_magnitude, sheet)
    return dict(
        r=q("r", "mm"),
        s=q("s", "mm"),
        alpha0=q("alpha0", "rad"),
        alpha1=q("alpha1", "rad"),
        phi1=q("phi1", "rad"),
        phi2=q("phi2", "rad"),
        mu=q("mu", ""),
    )


@findings_block
def brake_findings(sheet):
    """A, B against quadrature; printed (10), (11); self-locking; (8) and (12); wear; units."""
    out = []
    b = _brake_numbers(sheet)
    df = sheet.table("shoe_integrals")
    worst = float(max(df["A difference"].max(), df["B difference"].max()))
    out.append(
        Finding(
            "shoe factors",
            "A and B closed forms against the integrals of the shoe forces: largest difference",
            worst,
            "",
            "ok" if worst < 1e-9 else "fail",
        )
    )
    for _, row in df.iterrows():
        out.append(
            Finding(
                "shoe factors",
                f"shoe {int(row['shoe'])}: (10) as printed against A",
                100 * (row["A (10) printed"] / row["A closed form"] - 1),
                "%",
                "info",
                f"(11) as printed against B: "
                f"{100 * (row['B (11) printed'] / row['B closed form'] - 1):+.1f} %",
            )
        )
    ev = lambda name, unit="": float(sheet.evaluate(name).to(unit).magnitude)  # noqa: E731
    lock = ev("lock1")
    if lock >= 1:
        out.append(
            Finding(
                "self-locking",
                "mu*B/A of the leading shoe is 1 or more: the "
                "leading shoe self-locks (its cam force (8) is not positive and "
                "its torque has no bound)",
                lock,
                "",
                "fail",
                f"mu = {b['mu']:g}; it locks from mu = {ev('A1') / ev('B1'):.3f}",
            )
        )
    else:
        out.append(
            Finding(
                "self-locking",
                "mu*B/A of the leading shoe (self-locks at 1)",
                lock,
                "",
                "ok",
                f"it would lock from mu = {ev('A1') / ev('B1'):.3f}",
            )
        )
    for name, psi in (("shoe 1", b["phi1"]), ("shoe 2", -b["phi2"])):
        lo = min(b["alpha0"] + psi, b["alpha1"] + psi)
        hi = max(b["alpha0"] + psi, b["alpha1"] + psi)
        if lo < -1e-12 or hi > math.pi + 1e-12:
            out.append(
                Finding(
                    "pressure",
                    f"{name}: sin(alpha + psi) is negative on part of "
                    "the lining: the lining would lift off there, the A and B of "
                    "this model do not hold",
                    math.degrees(psi),
                    "deg",
                    "warning",
                )
            )
    x_max, x_0, x_lost = ev("x_max", "mm"), ev("x_0", "mm"), ev("x_lost", "mm")
    out.append(
        Finding(
            "wear",
            "pushrod travel lost to the cam wear, l_k*w/(d_k/2)",
            x_lost,
            "mm",
            "info",
            f"free travel {x_0:.2f} mm unworn, {x_0 + x_lost:.2f} mm worn; "
            "the torque curve moves right by this much, its slope is unchanged",
        )
    )
    if x_0 + x_lost >= x_max:
        out.append(
            Finding(
                "wear",
                "the worn cam reaches the tip of its profile before the "
                "shoes touch the drum: no braking",
                x_0 + x_lost,
                "mm",
                "fail",
                f"travel to the tip {x_max:.1f} mm",
            )
        )
    else:
        out.append(
            Finding(
                "wear",
                "travel left for braking after the clearance, worn cam",
                x_max - x_0 - x_lost,
                "mm",
                "info",
                f"unworn {x_max - x_0:.1f} mm (to the tip of the profile)",
            )
        )
    g0 = ev("gamma0", "rad")
    out.append(
        Finding(
            "units",
            "roll angle gamma0 of (9), in radians",
            g0,
            "rad",
            "ok",
            f"= {math.degrees(g0):.2f} deg; give it with its unit ('0.5 rad' or "
            "'28.6 deg'): a bare number is read as radians",
        )
    )
    xs = np.array([x_0 + 10.0])
    f8 = float(sheet.evaluate("F1_8", x=xs).to("kN").magnitude[0])
    f1 = float(sheet.evaluate("F1", x=xs).to("kN").magnitude[0])
    out.append(
        Finding(
            "(8)",
            "with the radius r_s as the arm, (8) as printed differs from the "
            "corrected force (10 mm after contact) by",
            100 * (f8 / f1 - 1),
            "%",
            "info",
            "the involute's normal is tangent to the base circle: the arm "
            "is d_k/2 whatever the contact radius",
        )
    )
    xs = np.array([x_0 + 10.0])
    m, m12 = (float(sheet.evaluate(k, x=xs).to("kN*m").magnitude[0]) for k in ("M", "M_12"))
    out.append(
        Finding(
            "(12)",
            "(12) with the mean A against the sum of the shoe torques",
            100 * (m12 / m - 1),
            "%",
            "info",
            "exact when both shoes have the same A and B",
        )
    )
    return out
