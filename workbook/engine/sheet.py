"""The Sheet: a loaded template with input values, evaluated lazily."""

from __future__ import annotations

import cmath
import contextlib
import math
from typing import Any

import numpy as np
import pint

from .. import limits_time
from ..errors import (
    DomainError,
    InputError,
    LimitError,
    OutOfBudget,
    TemplateError,
    WorkbookError,
)
from ..functions.constants import CONSTANTS
from ..functions.matrix import numbers
from ..functions.numerical import defining
from ..language import cellunit
from ..language import expr as ex
from ..language import typecheck as tc
from ..language import typed as ty
from ..language import units as un
from ..language.fields import nearest
from ..language.parts import resolve_parts, select_parts
from ..language.ranges import RangeSpec, log_range_values, range_values
from ..language.spec import ColumnSpec, SheetSpec
from ..language.template import check_input_value, column_node
from ..language.typed import TConst
from ..language.typedsheet import TypedSheet, printed_rows
from ..language.units import is_scaled_angle
from ..language.uses import dependencies, names_used
from ..limits import exhausted, matrix_work
from ..limits_time import check_time
from ..numerics.registry import BUILTINS
from . import runtime as rt
from .numeric import Evaluator
from .tabledata import Column, TableData

#: Values of a table with ``vary`` (curves x columns x points), checked before any is computed.
MAX_FAMILY_CELLS = 1_000_000


class Sheet:
    """A worksheet: inputs, definitions, tables. Evaluation follows only what is asked."""

    def __init__(
        self,
        spec: SheetSpec,
        values: dict[str, Any] | None = None,
        typer: tc.Typer | None = None,
        parts=None,
        typed: TypedSheet | None = None,
    ):
        self.full_spec = spec
        self.parts = resolve_parts(spec, parts)
        self.spec = select_parts(spec, self.parts)  # the sections this sheet computes and writes
        self.values = (
            dict(values) if values is not None else {n: i.value for n, i in spec.inputs.items()}
        )
        input_units = {n: (None if i.options else i.unit) for n, i in spec.inputs.items()}
        self.typer = typer or tc.Typer(spec, input_units, BUILTINS)
        self.defs = self.typer.defs  # the definitions' typed trees, read after the load
        # the trees typed at load besides the definitions' (shared by with_inputs, with_parts)
        self.typed = typed if typed is not None else TypedSheet()
        self._memo: dict[str, object] = {}
        # names evaluated through this sheet by a block table or a finding (within
        # ``recording_reads``): they count as used, without a hand-kept list in the template;
        # what a caller of the API evaluates does not, so the workbook is the same whatever
        # was evaluated before it was written
        self.reads: set[str] = set()
        self.recording = 0
        self.evaluator = Evaluator(
            self.typer, self.scalar_value, self.describe_call, self._column_values
        )
        self.evaluator.solve_at = self._solved_at
        if typer is None:
            self.check_units()

    # -- construction ---------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def file(self) -> str:
        return str(self.spec.path)

    def check_units(self) -> None:
        """Infer the unit of every definition, table column and chart series (load time)."""
        items = len(self.spec.definitions) + len(self.spec.inputs)
        limits_time.grow_default(limits_time.SECONDS_PER_ITEM * items, f"'{self.file}'")
        for block in self.spec.solves:
            from ..language.given_find import type_block

            try:
                self.check_not_circular(block)
                self.typed.keep(block, "solve", type_block(self.typer, block))
            except WorkbookError as err:
                raise err.located(file=self.file, line=block.line, definition=block.what) from None
        later = []  # functions whose body needs vectors: typed by the calls of the sheet
        for name, d in self.spec.definitions.items():
            try:
                t = self.typer.function(name) if d.is_function else self.typer.scalar(name)
                if d.limits is not None:  # a limit in another dimension is refused at load
                    d.limits.magnitudes(t.unit, d.unit, f"'{name}'")
            except WorkbookError as err:
                if not d.is_function:
                    raise err.located(file=self.file, line=d.line, definition=d.name) from None
                later.append(d)
            except RecursionError:
                raise LimitError(
                    "definitions and expressions nested too deeply for the engine",
                    file=self.file,
                    line=d.line,
                    definition=d.name,
                ) from None
        for t in self.full_spec.tables:  # every part is checked, chosen or not
            if t.range is not None:
                for col in t.columns:
                    self.typed_column(col, t.range.var, f"table {t.name}")
            for name, values in t.vary.items():
                self._check_vary(t, name, values)
        for c in self.full_spec.charts:
            for s in c.series:
                if s.table is None:
                    rng = s.range or c.range
                    if rng is None:
                        raise TemplateError(
                            f"chart {c.name}: a series needs a range", file=self.file, line=c.line
                        )
                    self.typed_column(s.y, rng.var, f"chart {c.name}")

        if self.full_spec.checks:
            from ..language.checkspec import type_checks

            type_checks(self)
        for d in later:  # typed at numbers, or by a call with vectors or matrices
            try:
                self.typer.function(d.name)
            except WorkbookError as err:
                raise err.located(file=self.file, line=d.line, definition=d.name) from None
        self._type_ranges_and_printed()

    def _type_ranges_and_printed(self) -> None:
        """Type at load the range bounds of every table and chart series, the x of each series
        over a range and the formulas of the printed values (the rows of their files, read
        once): the compute stage reads the trees. One that fails is left for the table, chart
        or check that shows its error."""
        ranges = [(t.range, None, f"table {t.name}") for t in self.full_spec.tables if t.range]
        for c in self.full_spec.charts:
            ranges += [
                (s.range or c.range, s.x or c.x, f"chart {c.name}")
                for s in c.series
                if s.table is None
            ]
        for rng, x, what in ranges:
            try:
                self.range_bounds(rng, what)
                if rng.points is not None:
                    self.range_points(rng, what)
                if x is not None:
                    self.typed_column(x, rng.var, what)
            except WorkbookError:
                pass
        for name, d in self.full_spec.definitions.items():
            if not d.is_function:
                try:
                    self.scalar_typed(name)
                except WorkbookError:
                    pass
        read = 0
        for p in self.full_spec.printed:
            try:
                rows = printed_rows(p)
            except WorkbookError:
                continue
            read += len(rows)
            items = len(self.spec.definitions) + len(self.spec.inputs) + read
            limits_time.grow_default(limits_time.SECONDS_PER_ITEM * items, f"'{self.file}'")
            for row in rows:
                at = None if math.isnan(row.at) else row.at
                try:
                    self.typed_printed(row.name, at, p.argument, row.unit)
                except WorkbookError:
                    pass

    def typed_printed(self, name: str, at: float | None, argument: str, unit: str) -> ty.T:
        """The formula of a printed value in its printed unit: ``name``, or the function
        ``name`` at ``at`` of its ``argument`` (typed at load)."""

        def typed() -> ty.T | WorkbookError:
            node = ex.Name(name)
            if at is not None and argument:
                node = ex.Call(name, (ex.Number(float(at)),))
            try:
                t = self.typer.expression(node, {}, f"check {name}")
                return self.typer.convert(t, un.unit(unit), "check")
            except WorkbookError as err:  # kept: the workbook writes the value as a number
                return err

        key = ("printed", name, at, bool(argument), unit)
        t = self.typed.get(None, key)
        if t is None:
            t = self.typed.keep(None, key, typed())
        if isinstance(t, WorkbookError):
            raise t.reworded(t.message)
        return t

    def check_not_circular(self, block) -> None:
        """Refuse a [[solve]] block whose equations use a definition that needs one of its
        unknowns: solving needs the definition, which needs the solution (it recursed until
        Python's limit, reported as "nested too deeply"). Load time, and the Mathcad
        importer's check of a translated block."""
        nodes = [n for lhs, rhs, _ in block.equations for n in (lhs, rhs)]
        nodes += [c for c, _ in block.conditions]
        used = sorted({n for node in nodes for n in ex.names(node)} - set(block.unknowns))
        for name in used:
            if name not in self.spec.definitions:
                continue
            needs = dependencies(self.spec, ex.parse(name, what=name)) & set(block.unknowns)
            if needs:
                x = sorted(needs)[0]
                raise TemplateError(
                    f"circular definition: {x} -> {name} -> {x} (the equations of [[solve]] "
                    f"use {name}, which needs the unknown {x}; write the equation with {x} "
                    f"itself, or make {name} a function of it)"
                )

    def _check_vary(self, t, name: str, values) -> None:
        where = dict(file=self.file, line=t.line, definition=f"table {t.name}")
        if name not in self.spec.inputs:
            raise InputError(
                f"vary: '{name}' is not an input{nearest(name, self.spec.inputs)}", **where
            )
        for v in values:
            try:
                coerce_input(self.spec.inputs[name], v, file=self.file)
            except WorkbookError as err:
                raise type(err)(f"vary.{name}: {err.message}", **where) from None

    def at_template_inputs(self, names=None) -> bool:
        """Are the inputs ``names`` (default: all) the template's own (the worked example it
        lists)?"""
        inputs = self.spec.inputs
        return all(bool(self.values[n] == inputs[n].value) for n in names or inputs)

    def with_inputs(self, **changes) -> Sheet:
        """A new Sheet with some inputs replaced (``"40 mm"``, a pint Quantity, or a number)."""
        values = dict(self.values)
        for name, raw in changes.items():
            spec = self.spec.inputs.get(name)
            if spec is None:
                known = ", ".join(self.spec.inputs)
                raise InputError(
                    f"'{name}' is not an input of {self.name}"
                    f"{nearest(name, self.spec.inputs)} (inputs: {known})",
                    file=self.file,
                )
            try:
                values[name] = coerce_input(spec, raw, file=self.file)
            except WorkbookError as err:  # point at the input's declaration (unit, bounds)
                raise err.located(file=self.file, line=spec.line, definition=name) from None
        return self.another(values, self.parts)

    def with_parts(self, *names: str) -> Sheet:
        """The same sheet computing and writing the optional parts ``names`` (``"all"``: every
        part; none: only what is not in a part). See ``[parts]`` in docs/language.md."""
        return self.another(self.values, names)

    def another(self, values: dict[str, Any], parts) -> Sheet:
        """A Sheet of the same template, typer and typed trees with other input values or
        parts (``with_inputs``, ``with_parts``); a subclass makes one of its own kind."""
        return Sheet(self.full_spec, values, self.typer, parts, self.typed)

    @contextlib.contextmanager
    def recording_reads(self):
        """Within the block, the names evaluated through this sheet are added to ``reads``
        (a block table's and a finding's)."""
        self.recording += 1
        try:
            yield
        finally:
            self.recording -= 1

    def once(self, key: tuple, make):
        """``make()``, made once per Sheet under ``key`` (a Sheet does not change: other
        inputs or parts are another Sheet)."""
        if key not in self._memo:
            self._memo[key] = make()
        return self._memo[key]

    def made(self, key: tuple):
        """What :meth:`once` made under ``key``, or None when nothing was made yet."""
        return self._memo.get(key)

    @property
    def left_out(self) -> list[str]:
        """Optional parts this sheet does not compute or write."""
        return [p for p in self.full_spec.parts if p not in self.parts]

    # -- evaluation -------------------------------------------------------------------
    def evaluate(self, name: str | list[str], *args, **kwargs):
        """Evaluate a definition (or an input) by name; function arguments by name or position.

        Plain numbers are taken in the unit the template declares for the argument. A list
        of names gives the list of their values, computed together: what they share (the
        same sub-expression of the same arguments) is computed once.
        """
        if not isinstance(name, str):
            kwargs = {
                k: self.argument_magnitude(k, v) if k in self.spec.arguments else v
                for k, v in kwargs.items()
            }
            with self.evaluator.sharing():
                return [self.evaluate(n, *args, **kwargs) for n in name]
        with self.evaluator.sharing():
            return self._evaluate(name, *args, **kwargs)

    def _evaluate(self, name: str, *args, **kwargs) -> pint.Quantity | str:
        Q = un.registry().Quantity
        if self.recording and (name in self.spec.inputs or name in self.spec.definitions):
            self.reads.add(name)
        if name in self.spec.inputs:
            return self.values[name]
        if name in CONSTANTS and name not in self.spec.definitions:  # pi, e, g
            return Q(CONSTANTS[name].value, CONSTANTS[name].unit)
        d = self.spec.definitions.get(name)
        block = self.spec.solve_of(name)
        if d is None and block is not None:
            return Q(self._solved(name), block.unknowns[name].units)
        if d is None:
            if name in self.spec.blocks:
                raise InputError(f"'{name}' is a block; evaluate a definition that calls it")
            raise InputError(
                f"'{name}' is not defined in {self.name}"
                f"{nearest(name, [*self.spec.inputs, *self.spec.definitions])}",
                file=self.file,
            )
        try:
            if not d.is_function:
                if args or kwargs:
                    raise InputError(f"'{name}' takes no arguments")
                return self.scalar_quantity(name)
            f = self.defs.function(name)
            if any(f.shapes):
                raise InputError(
                    f"{name}() takes vectors or matrices (its body is typed for the shapes of "
                    "its calls in the sheet); evaluate a definition that calls it"
                )
            env = self._bind(name, d.params, args, kwargs)
            out = self.evaluator.function(name)(env)
            if f.body.text or isinstance(out, str):  # a text, or an array's element that is one
                return out if np.ndim(out) == 0 else np.asarray(out, dtype=object)
            q = Q(numbers(out) if np.ndim(out) else numbers(out).item(), f.unit)
            return q.to(cellunit.stored_unit(f.body))
        except WorkbookError as err:
            raise err.located(file=self.file, line=d.line, definition=name) from None
        except OutOfBudget as exc:  # the command stops; its message names the definition
            exc.error.located(file=self.file, line=d.line, definition=name)
            raise
        except (RecursionError, MemoryError) as exc:
            raise exhausted(exc).located(file=self.file, line=d.line, definition=name) from None

    def scalar_typed(self, name: str) -> ty.T:
        """The typed tree of scalar definition ``name`` in the unit it is shown in: a
        dimensionless product of units (``kg*mm/m^2/Pa/s^2``) becomes a plain number."""
        key = ("scalar", name)
        t = self.typed.get(None, key)
        if t is None:
            try:
                t = cellunit.in_cell(self.typer.convert, self.defs.scalar(name), f"'{name}'")
            except WorkbookError as err:  # kept: the workbook and the report show it
                t = err
            self.typed.keep(None, key, t)
        if isinstance(t, WorkbookError):
            raise t.reworded(t.message)
        return t

    def scalar_quantity(self, name: str) -> pint.Quantity | str:
        """The value of scalar definition ``name`` in the unit it is shown in (a text as
        it is)."""
        t = self.defs.scalar(name)
        value = self.scalar_value(name, "definition")
        if t.text or isinstance(value, str):  # a text element of a run-time array, too
            return value
        return un.registry().Quantity(value, t.unit).to(cellunit.stored_unit(t))

    def _bind(self, fname: str, params, args, kwargs) -> dict:
        if len(args) > len(params):
            raise InputError(f"{fname}() takes {len(params)} argument(s), got {len(args)}")
        given = dict(zip(params, args))
        for k, v in kwargs.items():
            if k not in params:
                raise InputError(
                    f"{fname}() has no argument '{k}' (arguments: {', '.join(params)})"
                )
            if k in given:
                raise InputError(f"{fname}(): argument '{k}' given twice")
            given[k] = v
        missing = [p for p in params if p not in given]
        if missing:
            raise InputError(f"{fname}() needs argument(s) {', '.join(missing)}")
        return {p: self.argument_magnitude(p, given[p]) for p in params}

    def argument_magnitude(self, param: str, value) -> np.ndarray | float:
        """Magnitude of an argument value in its binding unit (degrees as plain numbers)."""
        spec = self.spec.arguments[param]
        if isinstance(value, pint.Quantity):
            try:
                mag = value.to(spec.unit).magnitude
            except pint.DimensionalityError:
                raise InputError(
                    f"argument {param} = {value:~} is not in {un.dims(spec.unit)} "
                    f"({un.pretty(spec.unit)})"
                ) from None
        elif isinstance(value, str):
            return self.argument_magnitude(param, un.quantity(value, str(spec.unit), what=param))
        else:
            try:
                mag = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"argument {param}: cannot read {value!r} as numbers") from None
        mag = np.asarray(mag, dtype=float)
        return float(mag) if mag.ndim == 0 else mag

    def scalar_value(self, name: str, kind: str):
        if kind == "input":
            return float(self.values[name].magnitude)
        if kind == "choice":
            return self.values[name]
        if kind == "builtin":  # a constant: pi, e, g
            return CONSTANTS[name].value
        if kind == "data":
            return self.spec.data[name].values
        if kind == "solve":
            return self._solved(name)
        if name not in self._memo:
            try:
                self._memo[name] = self._scalar(name)
            except WorkbookError as err:  # remembered: a table's rows ask again and again
                self._memo[name] = err
                raise
        if isinstance(self._memo[name], WorkbookError):
            raise self._memo[name]
        return self._memo[name]

    def _scalar(self, name: str):
        """The value of scalar definition ``name``, checked (finite, within its limits)."""
        d = self.spec.definitions[name]
        check_time(f"'{name}'")  # names the work, for the budget's alarm
        try:
            with defining(name, self.evaluator.records), matrix_work():
                value = self.evaluator.compile(self.defs.scalar(name))({})
        except WorkbookError as err:
            raise err.located(file=self.file, line=d.line, definition=name) from None
        except OutOfBudget as exc:  # the command stops; its message names the definition
            exc.error.located(file=self.file, line=d.line, definition=name)
            raise
        except (RecursionError, MemoryError) as exc:
            raise exhausted(exc).located(file=self.file, line=d.line, definition=name) from None
        if isinstance(value, str):
            pass  # a text: "OK"
        elif np.ndim(value) == 0:
            value = complex(value) if np.iscomplexobj(value) else float(value)
            if not cmath.isfinite(value):
                raise DomainError(
                    f"{name} is not a finite number ({value}); its formula is {d.text}",
                    file=self.file,
                    line=d.line,
                    definition=name,
                )
        elif not rt.all_finite(value):
            raise DomainError(
                f"{name} has elements that are not finite numbers; its formula is {d.text}",
                file=self.file,
                line=d.line,
                definition=name,
            )
        if d.limits is not None and not isinstance(value, str):
            self._check_limits(d, value)
        return value

    def _check_limits(self, d, value) -> None:
        """A scalar definition's value outside its declared limits is an error."""
        from .numeric import limits_error, outside_limits

        unit = self.defs.scalar(d.name).unit
        bad, _ = outside_limits(d, unit, value)
        if np.any(bad):
            first = float(np.ravel(value)[int(np.flatnonzero(np.ravel(bad))[0])])
            raise limits_error(d, unit, first).located(
                file=self.file, line=d.line, definition=d.name
            )

    def _solved(self, name: str) -> float:
        """An unknown of a [[solve]] block (the block is solved once per sheet)."""
        return self.solution(self.spec.solve_of(name))[name]

    def solution(self, block):
        """The solution of a [[solve]] block without parameters: solved once per sheet, and a
        failure remembered and raised again (with the block's line) instead of solved again."""
        from .solve_blocks import solve_block

        key = ("solve", block.index)
        if key not in self._memo:
            try:
                self._memo[key] = solve_block(self, block)
            except WorkbookError as err:  # remembered, not solved again by each value
                self._memo[key] = err.located(
                    file=self.file, line=block.line, definition=block.what
                )
        if isinstance(self._memo[key], WorkbookError):
            raise self._memo[key]
        return self._memo[key]

    def solutions_at(self, block) -> dict:
        """The solutions of a [[solve]] block with parameters, by point, as they are found."""
        return self._memo.setdefault(("solve at", block.index), {})

    def _solved_at(self, name: str, env: dict):
        """An unknown of a [[solve]] block with parameters, at their values in ``env``."""
        from .solve_blocks import solved_at

        return solved_at(self, self.spec.solve_of(name), name, env)

    def _column_values(self, table: str, column: str, unit: pint.Unit) -> np.ndarray:
        """Values of one column of a range table in ``unit``, the column's typed unit (for
        max_over/min_over), memoised."""
        key = ("column", table, column)
        if key not in self._memo:
            spec = next(t for t in self.full_spec.tables if t.name == table)  # any part
            col = next(c for c in spec.columns if c.text == column)
            what = f"table {table}"
            values = self.range_values(spec.range, what)
            column = self.column(col, spec.range.var, values, what)
            if column.failed:  # an aggregate over a column with holes would be wrong
                row = min(column.failed)
                raise DomainError(
                    f"column '{column.text}' of table {table} has no value in {len(column.failed)} "
                    f"row(s); the first: {column.failed[row]}",
                    definition=what,
                )
            # max_over() is typed in the column's unit, the column held as its cells hold it
            factor = cellunit.read_factor(ty.TConst(unit, value=1.0))
            self._memo[key] = column.values if factor == 1.0 else column.values * factor
        return self._memo[key]

    def describe_call(self, fname: str, params, env) -> str:
        parts = []
        for p in params:
            v = env.get(p)
            spec = self.spec.arguments[p]
            unit = un.pretty(spec.unit)
            arr = np.atleast_1d(np.asarray(v, dtype=float))
            if arr.size == 0:
                continue
            if arr.size == 1 or arr.min() == arr.max():
                parts.append(f"{p} = {arr.flat[0]:.6g} {unit}".rstrip())
            else:
                parts.append(
                    f"{p} from {arr.min():.6g} to {arr.max():.6g} {unit} "
                    f"({arr.size} points)".replace("  ", " ")
                )
        return "for " + ", ".join(parts) if parts else ""

    # -- tables ---------------------------------------------------------------------------
    def range_values(self, rng: RangeSpec, what: str = "range") -> np.ndarray:
        """The values of a range (numbers in the argument's declared unit)."""
        try:
            return self._range_values(rng, what)
        except WorkbookError as err:
            raise self._locate(err, what) from None

    def range_bounds(self, rng: RangeSpec, what: str = "range") -> list[ty.T | None]:
        """The typed first, second (or None) and last value of a range, in the range
        variable's declared unit (a plain number is taken as already in it); typed at load."""
        found = self.typed.get(rng, "bounds")
        return (
            found
            if found is not None
            else self.typed.keep(rng, "bounds", self._typed_bounds(rng, what))
        )

    def _typed_bounds(self, rng: RangeSpec, what: str) -> list[ty.T | None]:
        spec = self.spec.arguments.get(rng.var)
        out: list[ty.T | None] = []
        for node, unit in zip((rng.first, rng.second, rng.last), rng.units):
            if node is None:
                out.append(None)
                continue
            if unit is not None:  # a quantity bound ("25 N")
                t = TConst(unit, value=float(node.value))
            else:
                t = self.typer.expression(node, {}, what)
            if t.unit.dimensionality and spec is None:
                raise TemplateError(
                    f"{what}: range bound has units but '{rng.var}' has no declared unit"
                )
            if spec is not None and not (ty.is_bare(t) and not is_scaled_angle(spec.unit)):
                # the typer's one conversion, as for an argument of a call: a bare number is
                # in the declared unit (0, 5 .. 90 degrees), an expression with pi or a plain
                # number computed is in radians (a plain argument's bounds are plain numbers)
                t = self.typer.convert(t, spec.binding_unit, what)
            out.append(t)
        return out

    def _range_values(self, rng: RangeSpec, what: str) -> np.ndarray:
        nums = [
            None if t is None else float(self.evaluator.compile(t)({}))
            for t in self.range_bounds(rng, what)
        ]
        if rng.points is not None:  # logspace(first, last, points)
            points = self.range_points(rng, what)
            n = float(self.evaluator.compile(points)({}))
            return log_range_values(nums[0], nums[2], n, what=what)
        return range_values(nums[0], nums[1], nums[2], what=what)

    def range_points(self, rng: RangeSpec, what: str = "range") -> ty.T:
        """The typed number of points of a log range (``points``), typed at load."""
        found = self.typed.get(rng, "points")
        if found is None:
            t = self.typer.plain(self.typer.expression(rng.points, {}, what), what)
            found = self.typed.keep(rng, "points", t)
        return found

    def _scope(self, var: str) -> dict:
        spec = self.spec.arguments.get(var)
        return {var: spec.binding_unit if spec else un.registry().dimensionless}

    def column_node(self, col: ColumnSpec, var: str) -> ex.Node:
        """A bare function name as a column means that function of the range variable."""
        return column_node(self.spec, col, var)

    def typed_column(self, col: ColumnSpec, var: str, what: str) -> ty.T:
        """The typed tree of a table column or chart series over range variable ``var``, in
        the unit it is shown in (typed at load)."""
        found = self.typed.get(col, ("column", var))
        if found is None:
            found = self.typed.keep(col, ("column", var), self._typed_column(col, var, what))
        return found

    def _typed_column(self, col: ColumnSpec, var: str, what: str) -> ty.T:
        try:
            t = self.typer.expression(self.column_node(col, var), self._scope(var), what)
            if col.unit is not None:
                t = self.typer.convert(
                    t, col.unit, f"column '{col.text}' shown in {un.pretty(col.unit)}"
                )
            return cellunit.in_cell(self.typer.convert, t, what)
        except WorkbookError as err:
            raise self._locate(err, what) from None

    def _locate(self, err: WorkbookError, what: str) -> WorkbookError:
        """Give an error from a table or chart the line of the definition that failed, or else
        the line of the table or chart (``what`` is 'table NAME' or 'chart NAME')."""
        d = self.spec.definitions.get(err.definition or "")
        kind, _, name = what.partition(" ")
        items = {"table": self.spec.tables, "chart": self.spec.charts}.get(kind, [])
        line = d.line if d is not None else next((i.line for i in items if i.name == name), None)
        return err.located(file=self.file, line=line, definition=what)

    def column(self, col: ColumnSpec, var: str, values: np.ndarray, what: str) -> Column:
        t = self.typed_column(col, var, what)
        try:
            fn = self.evaluator.compile(t)
        except (RecursionError, MemoryError) as exc:  # functions inlined into one another
            raise self._locate(exhausted(exc), what) from None
        if ty.is_runtime(t.shape):  # a run-time value: each row's must be a number
            run = fn
            where = f"column '{col.text}'"
            fn = lambda env: np.array(  # noqa: E731
                [rt.number(run({var: float(v)}), where) for v in np.ravel(env[var])]
            ).reshape(np.shape(env[var]))
        elif t.shape is not None:
            raise self._locate(
                TemplateError(
                    f"column '{col.text}' is a vector or matrix; a column is one value a row "
                    f"(index it: {col.text}[i])"
                ),
                what,
            )
        failed: dict[int, str] = {}
        check_time(f"{what}: column '{col.text}'")  # names the work, for the budget's alarm
        try:
            with defining(f"{what}: {col.text}", self.evaluator.records), matrix_work():
                out = fn({var: values})
        except OutOfBudget as exc:
            exc.error.located(file=self.file, definition=what)
            raise
        except DomainError as err:  # some rows leave the domain: the others keep their values
            if t.text or values.ndim != 1:
                raise self._locate(err, what) from None
            out, failed = _rows_apart(fn, var, values, err)
            if len(failed) == values.size:  # no row has a value: the error as it was
                raise self._locate(err, what) from None
        except WorkbookError as err:
            raise self._locate(err, what) from None
        except (RecursionError, MemoryError) as exc:
            raise self._locate(exhausted(exc), what) from None
        if t.text:
            out = np.broadcast_to(np.asarray(out, dtype=object), values.shape).copy()
            return Column(col.title, t.unit, out, t, col.text)
        out = np.broadcast_to(numbers(out), values.shape).copy()
        bad = ~np.isfinite(out)
        for i in np.flatnonzero(bad).tolist()[: MAX_FAILED_ROWS + 1]:
            failed.setdefault(
                i, f"{col.text} is not a finite number ({out.flat[i]}) for {var} = {values[i]:g}"
            )
        if failed and (len(failed) > MAX_FAILED_ROWS or len(failed) == values.size):
            many = (
                "every row" if len(failed) == values.size else f"more than {MAX_FAILED_ROWS} rows"
            )
            first = failed[min(failed)]
            raise DomainError(
                f"column '{col.text}' has no value in {many}; the first: {first}",
                file=self.file,
                definition=what,
            )
        return Column(col.title, t.unit, out, t, col.text, failed)

    def table_spec(self, name: str):
        """The declaration of table ``name``; an error names a part that would add it."""
        spec = next((t for t in self.spec.tables if t.name == name), None)
        if spec is not None:
            return spec
        hidden = next((t for t in self.full_spec.tables if t.name == name), None)
        if hidden is not None:
            raise InputError(
                f"table '{name}' is in the optional part {hidden.part} of {self.name}: add it "
                f"with --part {hidden.part} (Python: sheet.with_parts({hidden.part!r}))",
                file=self.file,
            )
        names = [t.name for t in self.spec.tables]
        raise InputError(
            f"no table '{name}' in {self.name}{nearest(name, names)} (tables: "
            f"{', '.join(names) or 'none'})"
        )

    def table_data(self, table) -> TableData:
        """Evaluate one template table (only what it needs), once per Sheet: its name, or a
        table spec that is not in the template (a chart's data, which the writer writes as a
        table). A row whose value fails is NaN in its column, the cause in ``Column.failed``."""
        spec = self.table_spec(table) if isinstance(table, str) else table
        key = ("table", spec.name, id(spec))
        if key not in self._memo:  # the spec is kept with the data, so no id is reused
            self._memo[key] = (self._table_data(spec), spec)
        return self._memo[key][0]

    def _table_data(self, spec) -> TableData:
        name = spec.name
        if spec.range is None:
            raise InputError(f"table '{name}' is computed by a block; use sheet.block_table()")
        what = f"table {name}"
        values = self.range_values(spec.range, what)
        var = spec.range.var
        arg = self.spec.arguments.get(var)
        var_unit = arg.unit if arg else un.registry().dimensionless
        cols = [Column(var, var_unit, values, None, var)]
        with self.evaluator.sharing():  # what the columns share is computed once
            cols += [self.column(c, var, values, what) for c in spec.columns]
        return TableData(name, spec.title, var, var_unit, cols)

    def table(self, name: str):
        """A table as a pandas DataFrame, the unit in every column header: ``"h1 [mm]"``."""
        import pandas as pd

        spec = self.table_spec(name)
        if spec.block:
            return self.block_table(spec.block)
        if spec.vary:
            return self.family_table(spec)
        data = self.table_data(name)
        return pd.DataFrame({un.header(c.title, c.unit): c.values for c in data.columns})

    def block_table(self, ref: str):
        from .. import blocks

        with self.recording_reads():
            return blocks.get(ref, "table").func(self)

    def family_table(self, spec):
        """A table with ``vary = { NAME = [values] }``: its range, then each column at each
        value of the input NAME (headers ``"phi2 c1=1500 N/m [rad]"``), the other inputs as
        they are. The range is this sheet's, the same for every curve."""
        import pandas as pd

        (name, values), what = next(iter(spec.vary.items())), f"table {spec.name}"
        xs = self.range_values(spec.range, what)
        cells = len(xs) * len(values) * len(spec.columns)
        if cells > MAX_FAMILY_CELLS:  # before any curve is computed
            raise LimitError(
                f"{what}: {len(values)} values of {name} x {len(spec.columns)} columns x "
                f"{len(xs):,} points is {cells:,} values (limit {MAX_FAMILY_CELLS:,})",
                file=self.file,
                line=spec.line,
                definition=what,
            )
        var = spec.range.var
        arg = self.spec.arguments.get(var)
        out = {un.header(var, arg.unit if arg else un.registry().dimensionless): xs}
        curves = [self.with_inputs(**{name: v}) for v in values]
        columns = {}
        for v, s in zip(values, curves):
            with s.evaluator.sharing():
                columns[v] = [s.column(c, var, xs, f"{what} at {name} = {v}") for c in spec.columns]
            self.reads |= s.reads
        for j, c in enumerate(spec.columns):
            for v in values:
                col = columns[v][j]
                out[un.header(f"{c.title} {name}={v}", col.unit)] = col.values
        return pd.DataFrame(out)

    def computed_table(self, name: str):
        """The DataFrame of a computed table (a solver block's, or a family over an input's
        values), computed once per Sheet: the writer, its charts and the report read it."""
        key = ("computed table", name)
        if key not in self._memo:
            spec = next((t for t in self.spec.tables if t.name == name and t.computed), None)
            if spec is None:
                raise InputError(f"no block or family table '{name}' in {self.name}")
            self._memo[key] = (
                self.block_table(spec.block) if spec.block else self.family_table(spec)
            )
        return self._memo[key]

    def unused_inputs(self) -> list[str]:
        """Inputs that no table, chart, printed value, check or scalar definition (each is on
        the workbook's Results sheet) needs (in any part), nor anything evaluated through this
        sheet so far (``reads``: what the findings and block tables read; a check runs the
        findings first)."""
        shown = {n for n, d in self.full_spec.definitions.items() if not d.is_function}
        used = names_used(self.full_spec, hand_checks=True, reads=self.reads | shown)
        return [n for n in self.full_spec.inputs if n not in used]


#: A column with more failed rows than this is an error, not a table with error cells.
MAX_FAILED_ROWS = 1000


def _rows_apart(fn, var: str, values: np.ndarray, err: DomainError):
    """Evaluate a column whose vectorised evaluation failed in halves, down to the rows that
    fail: (values with NaN where a row fails, {row: the cause}); at most MAX_FAILED_ROWS + 1
    failed rows are looked for (a column with more is refused by the caller)."""
    out = np.full(values.shape, np.nan)
    failed: dict[int, str] = {}
    pending = [(0, values.size, err)]
    while pending and len(failed) <= MAX_FAILED_ROWS:
        lo, hi, why = pending.pop()
        if hi - lo == 1:
            failed[lo] = why.message
            continue
        for a, b in ((lo + hi) // 2, hi), (lo, (lo + hi) // 2):
            try:
                part = fn({var: values[a:b]})
            except DomainError as e:
                pending.append((a, b, e))
                continue
            try:
                out[a:b] = np.broadcast_to(np.asarray(part, dtype=float), (b - a,))
            except ValueError:  # not one number a row (an array): the column's own error
                raise err from None
    return out, failed


def coerce_input(spec, raw, *, file: str | None = None):
    """Turn a user-given value into the input's declared unit (with a clear error)."""
    if spec.options:
        value = str(raw)
        if value not in spec.options:
            raise InputError(
                f"{spec.name} = {value!r} is not one of {', '.join(spec.options)}",
                file=file,
                definition=spec.name,
            )
        return value
    q = un.quantity(raw, str(spec.unit) if spec.unit.dimensionless else None, what=spec.name)
    if isinstance(raw, (int, float)) and not isinstance(raw, bool):
        q = un.registry().Quantity(float(raw), spec.unit)
    try:
        q = q.to(spec.unit)
    except pint.DimensionalityError:
        kinds = (un.temperature_kind(q.units), un.temperature_kind(spec.unit))
        if q.units.dimensionality == spec.unit.dimensionality and "difference" in kinds:
            what = (
                "a temperature difference"
                if kinds[0] == "difference"
                else "an absolute temperature"
            )
            raise InputError(
                f"{spec.name} = {raw!s} is {what}, but {spec.name} is "
                f"{'an absolute temperature' if kinds[1] == 'absolute' else 'a difference'} "
                f"({un.pretty(spec.unit)}): give it in {un.pretty(spec.unit)} or K",
                file=file,
                definition=spec.name,
            ) from None
        raise InputError(
            f"{spec.name} = {raw!s} is {un.dims(q.units)}, but {spec.name} is "
            f"{un.dims(spec.unit)} ({un.pretty(spec.unit) or 'dimensionless'})",
            file=file,
            definition=spec.name,
        ) from None
    check_input_value(spec, q)
    return q
