"""The built-ins of complex numbers: ``Re``, ``Im``, ``arg``, ``conj`` and ``polar``, and the
Excel forms (the IM* functions) of the operators and built-ins over the complex plane.

A complex value in a written workbook is Excel's complex text (``"3+4i"``), which Excel and
LibreOffice both compute with: ``COMPLEX(3, 4)``, ``IMSUM``, ``IMPRODUCT``... take numbers
and such texts alike.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NotLive
from ..language import typed as ty
from ..language.expr import PREC
from .entry import Builtin, UnitContext, register
from .excel_functions import stored

ATOM = PREC["atom"]

#: Excel's function of each operator over the complex plane
OPERATORS = {"+": "IMSUM", "-": "IMSUB", "*": "IMPRODUCT", "/": "IMDIV"}


def excel_text(z: complex) -> str:
    """``z`` as Excel's complex text: ``3+4i``, ``-2.5i``, ``i``, ``7`` (parts with 15
    significant digits, as Excel and LibreOffice write them)."""
    re, im = _part(z.real), _part(z.imag)
    if z.imag == 0:
        return re
    unit = "i" if im == "1" else "-i" if im == "-1" else im + "i"
    if z.real == 0:
        return unit
    return re + (unit if unit.startswith("-") else "+" + unit)


def _part(x: float) -> str:
    if x == 0:
        return "0"
    text = f"{x:.15g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}E{int(exponent):+03d}"
    return text


def parse_text(text: str) -> complex | None:
    """Excel's complex text (``3+4i``, ``-i``, ``2.5j``, ``7``) as a complex number; None for
    a text that is not one."""
    body = text.strip().replace(" ", "")
    if body[-1:] in ("i", "j"):
        body = body[:-1]
        if body == "" or body[-1] in "+-":
            body += "1"
        body += "j"
    try:
        return complex(body)
    except ValueError:
        return None


def readable(z: complex, digits: int = 6, polar: bool = False) -> str:
    """``z`` as a person writes it: ``10 - 16.123i``, ``2i``, ``-7`` (``digits``
    significant digits in each part), or with ``polar`` as ``18.9883∠-58.1915°``."""
    z = complex(z)
    if polar:
        r, phi = abs(z), math.degrees(math.atan2(z.imag, z.real)) + 0.0
        return f"{r:.{digits}g}\u2220{phi:.{digits}g}\u00b0"
    re, im = f"{z.real + 0.0:.{digits}g}", f"{abs(z.imag):.{digits}g}"
    if z.imag == 0:
        return re
    if z.real == 0:
        return ("-" if z.imag < 0 else "") + im + "i"
    return f"{re} {'-' if z.imag < 0 else '+'} {im}i"


def power(base: str, exponent: str, real_exponent: bool) -> str:
    """``base^exponent`` over the complex plane: IMPOWER takes a real exponent; a complex
    one is exp(exponent * ln(base))."""
    if real_exponent:
        return f"IMPOWER({base}, {exponent})"
    return f"IMEXP(IMPRODUCT({exponent}, IMLN({base})))"


def constant(z: complex) -> str:
    """A complex constant as a live formula."""
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        raise NotLive(f"{z} cannot be written in a formula")
    return f"COMPLEX({_number(z.real)}, {_number(z.imag)})"


def _number(x: float) -> str:
    if float(x).is_integer() and abs(x) < 1e15:
        return str(int(x))
    return repr(float(x)).replace("e", "E")


def im_call(function: str):
    """The Excel function ``function`` of the printed arguments (the IM* functions)."""
    name = stored(function)  # a newer one with its stored prefix

    def printed(args: list[str]) -> tuple[str, int]:
        return f"{name}({', '.join(args)})", ATOM

    return printed


def _exps(z: str) -> tuple[str, str]:
    return f"IMEXP({z})", f"IMEXP(IMSUB(0, {z}))"


# tan, sinh, cosh and tanh by the classic IM* functions: Excel's IMTAN, IMSINH and IMCOSH
# (2013) are #NAME? in LibreOffice's reading of an xlsx file, and Excel has no IMTANH
def im_sinh(z: str) -> str:
    return "IMDIV(IMSUB({}, {}), 2)".format(*_exps(z))


def im_cosh(z: str) -> str:
    return "IMDIV(IMSUM({}, {}), 2)".format(*_exps(z))


def im_tan(z: str) -> str:
    return f"IMDIV(IMSIN({z}), IMCOS({z}))"


def im_tanh(z: str) -> str:
    return f"IMDIV({im_sinh(z)}, {im_cosh(z)})"


def classic(form):
    """The Excel form of a built-in of a complex argument from ``form`` (im_tan, ...)."""

    def printed(args: list[str]) -> tuple[str, int]:
        return form(args[0]), ATOM

    return printed


# -- the unit rules -----------------------------------------------------------------------------
def _part_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """Re(z), Im(z): real, in z's unit."""
    return ty.TFunc(args[0].unit, func=name, args=args, complex=False)


def _arg_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """arg(z): the angle of z in radians, a plain number."""
    return ty.TFunc(ctx.dimensionless, func=name, args=args, complex=False)


def _conj_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    return ty.TFunc(args[0].unit, func=name, args=args)


def _polar_unit(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """polar(r, phi): r*e^(i*phi), in r's unit; phi an angle (a plain number in radians)."""
    r, phi = args
    phi = ctx.plain(phi, "polar(r, phi): the angle phi")
    return ty.TFunc(r.unit, func=name, args=(r, phi), complex=True)


def _polar_numpy(r, phi):
    return r * np.exp(1j * np.asarray(phi, dtype=float))


def _polar_excel(args: list[str]) -> tuple[str, int]:
    r, phi = args
    return f"IMPRODUCT({r}, IMEXP(COMPLEX(0, {phi})))", ATOM


def _entry(name, rule, numpy, excel, sympy, doc, kind, **display) -> None:
    register(
        Builtin(
            name,
            1 if name != "polar" else 2,
            rule,
            numpy,
            excel,
            sympy,
            doc=doc,
            complex=kind,
            complex_excel=excel,
            **display,
        )
    )


_entry(
    "Re",
    _part_unit,
    np.real,
    im_call("IMREAL"),
    lambda sp, z: sp.re(z),
    "the real part of a complex number",
    "real",
    mathcad=("Re",),
)
_entry(
    "Im",
    _part_unit,
    np.imag,
    im_call("IMAGINARY"),
    lambda sp, z: sp.im(z),
    "the imaginary part of a complex number",
    "real",
    mathcad=("Im",),
)
_entry(
    "arg",
    _arg_unit,
    np.angle,
    im_call("IMARGUMENT"),
    lambda sp, z: sp.arg(z),
    "the angle of a complex number, -pi < arg(z) <= pi (in radians)",
    "real",
    mathcad=("arg",),
)
_entry(
    "conj",
    _conj_unit,
    np.conj,
    im_call("IMCONJUGATE"),
    lambda sp, z: sp.conjugate(z),
    "the complex conjugate",
    "complex",
    mathml="<mover>{0}<mo>\u00af</mo></mover>",
)
_entry(
    "polar",
    _polar_unit,
    _polar_numpy,
    _polar_excel,
    lambda sp, r, phi: r * sp.exp(sp.I * phi),
    "polar(r, phi): the complex number of modulus r and angle phi, r*e^(i*phi)",
    "complex",
)
