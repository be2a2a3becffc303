"""The cam-wear valve sheet's own analysis (Ivashko, Buikus, Osuchukwu 2006): the derivatives
of a measured lift by a Savitzky-Golay filter. Every formula, check and time-section is the
template's (templates/cam-wear-valve.toml); the wear formula is read through the sheet.

* ``measured_lift`` (table): the worn lift given as measured points (``[data.measured_lift]``);
  velocity and acceleration by a Savitzky-Golay filter, beside central differences and the
  formula.
* ``measured_findings``: the noise, the filter's noise gains and its errors against the formula.

scipy is imported inside the functions.
"""

from __future__ import annotations

import math

import numpy as np

from ..findings import Finding
from . import cached, findings_block, input_magnitude, table_block

SG_WINDOW = 15  # points (30 deg at a 2 deg spacing); cubic Savitzky-Golay
SG_ORDER = 3


def measured_points(sheet):
    """The measured lift of the template's [data.measured_lift] (phi in deg, h in mm), checked
    for what the Savitzky-Golay filter needs: enough points, increasing in equal steps."""
    from ..errors import InputError
    from ..language import units as un

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


def filtered_lift(sheet):
    """The measured lift filtered (Savitzky-Golay): its derivatives, the noise, the filter's
    noise gains and errors against the true lift, computed once per sheet."""

    def make():
        from scipy.signal import savgol_coeffs, savgol_filter

        from ..language import units as un

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
        # the filter's derivatives are in mm/deg and mm/deg^2; omega in deg/s
        to_v = un.factor(un.unit("mm/s"), un.unit("m/s"))
        to_a = un.factor(un.unit("mm/s^2"), un.unit("m/s^2"))
        return dict(
            phi=phi,
            h=h,
            hs=hs,
            v=d1 * omega * to_v,
            a=d2 * omega**2 * to_a,
            vc=np.gradient(h, dphi) * omega * to_v,
            ac=np.gradient(np.gradient(h, dphi), dphi) * omega**2 * to_a,
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

    m = filtered_lift(sheet)
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


@findings_block
def measured_findings(sheet):
    """The measured lift: the noise, the filter's noise gains and errors."""
    from ..errors import WorkbookError

    out = []
    Phi = input_magnitude(sheet, "Phi", "deg")
    try:
        m = filtered_lift(sheet)
    except WorkbookError as exc:  # a bad table is reported, not fatal to the checks
        out.append(
            Finding(
                "measured lift", "the measured lift could not be read", None, "", "fail", str(exc)
            )
        )
        return out
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
