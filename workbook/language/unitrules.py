"""The unit rules of typed trees: conversions between units, the rules of the arithmetic
operators, temperatures and angles in degrees.

:class:`UnitRules` is the base of :class:`workbook.language.typecheck.Typer` and the context a
built-in's unit rule receives (``convert``, ``plain``, ``meeting``:
:class:`workbook.functions.entry.UnitContext`). Nothing here types an expression: the rules take
typed trees and return typed trees, so the typer, the array rules and the registry's entries call
down into this module, never back up."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import pint
from pint.util import to_units_container

from ..errors import TemplateError, UnitError
from . import units as un
from .typed import T, TBinary, TCall, TConst, TRef, TScale, children, is_bare, is_zero
from .units import angle_in, is_scaled_angle

if TYPE_CHECKING:
    from .spec import SheetSpec


class UnitRules:
    """Conversions and operator rules on typed trees (the base of the typer)."""

    spec: SheetSpec  # the sheet being typed: names the options of a choice input
    dimensionless: pint.Unit

    def convert(self, t: T, target: pint.Unit, where: str, *, angle: bool = False) -> T:
        """``t`` in the unit ``target`` (an explicit factor), or a UnitError naming ``where``.

        ``angle``: ``t`` is used as an angle (the argument of sin, cos...). A bare number
        wanted as an angle in degrees (any angle unit) is in that unit: a bound 180, ``f(90)``,
        a shown ``90`` are 180, 90 and 90 degrees, not radians."""
        if t.unit == target:
            return t
        if is_bare(t) and is_scaled_angle(target):
            return TConst(target, value=t.value)
        if not angle:
            self._no_bare_ratio(t, target, where)
        if t.text:
            raise TemplateError(f"{where}: text where a number is wanted")
        if is_zero(t):  # a literal 0 is zero in any unit: h > 0, "0 otherwise"
            return TConst(target, value=0.0)
        if t.unit.dimensionality != target.dimensionality:
            raise UnitError(
                f"{where}: {un.dims(t.unit)} ({un.pretty(t.unit) or '1'}) cannot be converted "
                f"to {un.dims(target)} ({un.pretty(target) or '1'})"
            )
        kinds = (sum_kind(t.unit), sum_kind(target))
        if "absolute" in kinds:
            return self._temperature(t, target, kinds, where)
        f = un.factor(t.unit, target)
        if f == 1.0:
            return _with_unit(t, target)
        if isinstance(t, TConst) and t.unit.dimensionality:  # 20 mm in m: 0.02, as Excel shows
            return TConst(target, value=t.value * f, derived=True)
        return TScale(target, child=t, factor=f, shape=t.shape)

    def _temperature(self, t: T, target: pint.Unit, kinds, where: str) -> T:
        """An absolute temperature in another scale: ``t*factor + offset`` (20 degC is
        293.15 K); a difference is never shown as an absolute temperature, nor the reverse."""
        if "difference" in kinds:
            shown = (un.pretty(t.unit), un.pretty(target))
            if kinds[0] == "difference":
                raise UnitError(
                    f"{where}: a temperature difference ({shown[0]}) cannot be shown as an "
                    f"absolute temperature ({shown[1]}); show it in "
                    f"{un.pretty(un.difference_unit(target))} or K"
                )
            raise UnitError(
                f"{where}: an absolute temperature ({shown[0]}) cannot be shown as a "
                f"difference ({shown[1]}); a difference is written T - T0, or show it in K"
            )
        kelvin = un.registry().kelvin
        if kinds[0] == "kelvin" and un.temperature_kind(t.unit) is None:  # q/h in kW*K/W
            t = self.convert(t, kelvin, where)  # pint converts no compound unit to degC
        if kinds[1] == "kelvin" and un.temperature_kind(target) is None:
            return self.convert(self.convert(t, kelvin, where), target, where)
        f, offset = un.affine(t.unit, target)
        if isinstance(t, TConst):
            return TConst(target, value=t.value * f + offset, derived=True)
        scaled = _with_unit(t, target) if f == 1.0 else TScale(target, child=t, factor=f)
        if offset == 0.0:
            return scaled
        op = "+" if offset > 0 else "-"
        const = TConst(target, value=abs(offset))
        return TBinary(target, op=op, left=scaled, right=const, shape=t.shape)

    def kelvin(self, t: T) -> T:
        """An absolute temperature with an offset (degC, degF) in kelvin, as a product, a
        quotient, a power or a built-in takes it (Mathcad's rule: 2*T is 2*293.15 K at
        20 degC); any other value as it is."""
        if un.temperature_kind(t.unit) != "absolute":
            return t
        return self.convert(t, un.registry().kelvin, "an absolute temperature in kelvin")

    def meeting(self, values) -> list[T]:
        """Bare numbers among ``values`` next to an angle in degrees take its unit."""
        return meeting(values)

    def plain(self, t: T, where: str) -> T:
        """Convert to a plain number (radians for angles); refuse dimensioned values."""
        if t.boolean:
            raise TemplateError(f"{where}: a comparison cannot be used as a number")
        if t.unit.dimensionality:
            raise UnitError(
                f"{where} needs a dimensionless argument, got {un.dims(t.unit)} "
                f"({un.pretty(t.unit)})"
            )
        return self.convert(t, self.dimensionless, where, angle=True)

    def as_number(self, t: T, where: str) -> T:
        if t.boolean:
            raise TemplateError(f"{where}: a comparison cannot be used as a number")
        return self.not_text(t, where)

    def not_text(self, t: T, where: str) -> T:
        """Refuse text and choice inputs where a number is needed (found by the fuzz test)."""
        if t.text:
            raise TemplateError(
                f"{where}: text is not a number (text can only be compared with == and !=)"
            )
        if isinstance(t, TRef) and t.kind == "choice":
            opts = ", ".join(self.spec.inputs[t.name].options)
            raise TemplateError(
                f"{where}: '{t.name}' is a choice ({opts}), not a number; "
                f'compare it: {t.name} == "..."'
            )
        return t

    def scalar_binary(self, op: str, left: T, right: T) -> T:
        """``left op right`` of numbers: the unit rules of the operators (constants folded)."""
        if op in "+-":
            left, right = meeting((left, right))
            if is_zero(left) and not is_zero(right):
                left = TConst(right.unit, value=0.0)
            if right.unit.dimensionality != left.unit.dimensionality and not is_zero(right):
                self.mismatch(op, left, right)
            if not is_zero(left) and not is_zero(right):
                left, right, unit = self.temperature_sum(op, left, right)
                if unit is not None:
                    return TBinary(unit, op=op, left=left, right=right)
            right = self.convert(right, left.unit, "sum")
            if isinstance(left, TConst) and isinstance(right, TConst):
                v = left.value + right.value if op == "+" else left.value - right.value
                return TConst(left.unit, value=v, derived=derived_from(left, right))
            return TBinary(left.unit, op=op, left=left, right=right)
        left, right = self.kelvin(left), self.kelvin(right)
        if op == "*":
            if isinstance(left, TConst) and isinstance(right, TConst):
                v = left.value * right.value
                return TConst(left.unit * right.unit, value=v, derived=derived_from(left, right))
            return TBinary(left.unit * right.unit, op=op, left=left, right=right)
        if op == "/":
            if isinstance(left, TConst) and isinstance(right, TConst) and right.value != 0:
                v = left.value / right.value
                return TConst(left.unit / right.unit, value=v, derived=derived_from(left, right))
            return TBinary(left.unit / right.unit, op=op, left=left, right=right)
        # power
        if not right.unit.dimensionless or right.unit.dimensionality:
            raise UnitError(f"an exponent must be dimensionless, got {un.dims(right.unit)}")
        right = self.convert(right, self.dimensionless, "exponent")
        if left.unit.dimensionality:
            if right.complex:
                raise UnitError(
                    f"{un.dims(left.unit)} raised to a complex power has no unit; make the "
                    "base dimensionless (e.g. divide by a reference value)"
                )
            if not isinstance(right, TConst):
                raise UnitError(
                    f"{un.dims(left.unit)} raised to a variable power has no fixed unit; "
                    "make the base dimensionless (e.g. divide by a reference value)"
                )
            n = right.value
            if abs(n) > 1000:
                raise UnitError(f"exponent {n:g} of a dimensioned value is out of range")
            return TBinary(left.unit**n, op="^", left=left, right=right)
        left = self.convert(left, self.dimensionless, "base of a power")
        if isinstance(left, TConst) and isinstance(right, TConst):
            try:
                if left.complex or right.complex:  # over the complex plane (0^z is 0 or 1)
                    v = complex(left.value) ** right.value
                else:
                    v = math.pow(left.value, right.value)
            except (OverflowError, ValueError, ZeroDivisionError):
                raise TemplateError(
                    f"{left.value:g}^{right.value:g} is not a finite number"
                ) from None
            return TConst(self.dimensionless, value=v, derived=derived_from(left, right))
        return TBinary(self.dimensionless, op="^", left=left, right=right)

    def temperature_sum(self, op: str, left: T, right: T) -> tuple[T, T, pint.Unit | None]:
        """Sums and differences of temperatures as Mathcad reads them: absolute minus
        absolute is a difference (delta_degC); absolute plus or minus anything else in kelvin
        (a difference, K, degR, q/h in K, 88 % of a difference) is absolute, in the scale of
        the absolute one (22 degC - 12.5 K is 9.5 degC); two absolute temperatures are not
        added, and a difference minus an absolute temperature is refused. Returns the
        operands converted and the unit of the result, or the operands and None when no
        temperature rule applies (see :func:`sum_kind`)."""
        kinds = (sum_kind(left.unit), sum_kind(right.unit))
        if "absolute" not in kinds and kinds not in (
            ("difference", "kelvin"),
            ("kelvin", "difference"),
        ):
            return left, right, None
        shown = f"{un.pretty(left.unit)} {op} {un.pretty(right.unit)}"
        if kinds == ("difference", "absolute") and op == "-":
            raise UnitError(
                f"{shown}: a temperature difference minus an absolute temperature is not a "
                "temperature; write the absolute one first (T - dT)"
            )
        if kinds[0] == "absolute" and kinds[1] != "absolute":  # T + dT, T - 5 K: in T's scale
            return left, self.convert(right, un.difference_unit(left.unit), "sum"), left.unit
        if kinds[0] != "absolute" and kinds[1] == "absolute" and op == "+":  # 5 K + T
            return self.convert(left, un.difference_unit(right.unit), "sum"), right, right.unit
        if kinds[1] == "difference":  # K + dT: in kelvin, as pint
            return left, self.convert(right, left.unit, "sum"), left.unit
        if kinds[0] == "difference":  # dT + K
            return self.convert(left, right.unit, "sum"), right, right.unit
        if op == "+":
            raise UnitError(
                f"{shown}: two absolute temperatures cannot be added (20 degC + 20 degC is "
                "not 40 degC); add a difference (T + 5 delta_degC; T1 + (T2 - T1)/2 is their "
                "mean), or convert both to K"
            )
        if kinds[0] == "kelvin":  # 300 K - 20 degC: kelvin minus kelvin, a difference in K
            kelvin = un.registry().kelvin
            if un.temperature_kind(left.unit) != "kelvin":  # q/h in kW*K/W: in K first
                left = self.convert(left, kelvin, "difference")
            return left, self.convert(right, left.unit, "difference"), left.unit
        # absolute - absolute: a difference, in the scale of the left one
        return left, self.convert(right, left.unit, "difference"), un.difference_unit(left.unit)

    def _no_bare_ratio(self, t: T, target: pint.Unit, where: str) -> None:
        """An angle in degrees divided by a plain number (theta/90) is a plain number of
        degrees: used as a plain number (or in mm...) it would silently be in radians."""
        u = angle_in(t.unit)
        if not u or angle_in(target):
            return
        ratio = _bare_ratio(t)
        if ratio is None:
            return
        raise UnitError(
            f"{where}: an angle in {u} divided by the plain number {ratio:g} is a plain number "
            f"of {u}, not a ratio (at 90 {u}, theta/90 is 0.01745 as a plain number); divide "
            f'by an angle (an input right = "90 {u}", then theta/right), or declare the '
            f"argument plain = true (plain numbers, as Mathcad)"
        )

    def mismatch(self, op, left, right):
        verb = "add" if op == "+" else "subtract"
        raise UnitError(
            f"cannot {verb} {un.dims(right.unit)} ({un.pretty(right.unit) or '1'}) "
            f"{'to' if op == '+' else 'from'} {un.dims(left.unit)} ({un.pretty(left.unit) or '1'})"
        )


def sum_kind(unit: pint.Unit) -> str | None:
    """What a value in ``unit`` is in a sum with a temperature: ``"absolute"`` (degC,
    degF), ``"difference"`` (delta_degC, or a unit made with one: 88 % of a difference),
    ``"kelvin"`` (K, degR, or any other unit of a temperature: q/h in kW*K/W); None for
    units that are not temperatures."""
    kind = un.temperature_kind(unit)
    if kind is not None:
        return kind
    if unit.dimensionality != un.registry().kelvin.dimensionality:
        return None
    names = [str(n) for n in to_units_container(unit)]
    return "difference" if any(n.startswith("delta_") for n in names) else "kelvin"


def _bare_ratio(t: T) -> float | None:
    """The plain number that divides an angle in degrees somewhere in ``t`` (None: none)."""
    if isinstance(t, TBinary) and t.op == "/":
        for angle, bare in ((t.left, t.right), (t.right, t.left)):
            if is_bare(bare) and not is_bare(angle) and angle_in(angle.unit):
                return bare.value
    if isinstance(t, TCall):
        return None  # a function's body is checked where it is typed
    for c in children(t):
        found = _bare_ratio(c)
        if found is not None:
            return found
    return None


def meeting(values) -> list[T]:
    """Bare numbers among values that meet an angle (deg, ...) take its unit: theta <= 90."""
    angle = next((v.unit for v in values if not is_bare(v) and is_scaled_angle(v.unit)), None)
    if angle is None:
        return list(values)
    return [TConst(angle, value=v.value) if is_bare(v) else v for v in values]


def _with_unit(t: T, unit: pint.Unit) -> T:
    """Same node, relabelled with an equal unit (factor exactly 1)."""
    if isinstance(t, TConst):
        return TConst(unit, value=t.value, derived=t.derived or t.unit != unit)
    return TScale(unit, child=t, factor=1.0, shape=t.shape)


def derived_from(*consts: TConst) -> bool:
    """A constant folded from these is derived when one of them is, or has a unit."""
    dimensionless = un.registry().dimensionless
    return any(c.derived or c.unit != dimensionless for c in consts)
