"""Unit inference: turn an expression tree into a typed tree with units resolved.

Every node gets the pint unit its value is in; every place where two units must
agree (sums, comparisons, piecewise branches, function arguments) gets an
explicit conversion factor (the rules: :mod:`workbook.language.unitrules`). Both back ends (numpy
and Excel) read this typed tree, so no back end converts a unit.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
from typing import TYPE_CHECKING

import pint

from ..errors import LimitError, ShapeError, TemplateError, UnitError, WorkbookError
from . import expr as ex
from . import units as un
from .complextyping import no_order, real_in_program, real_index, real_only, value_kind
from .fields import nearest
from .measured import column_vector
from .spec import Definition, SheetSpec
from .template import column_node
from .typearrays import ArrayTyping
from .typed import (
    RUNTIME,
    T,
    TAggregate,
    TBlock,
    TCall,
    TCompare,
    TConst,
    TIndex,
    TLogic,
    TMatrix,
    TOde,
    TParam,
    TPiecewise,
    TProgram,
    TRef,
    TText,
    TUnary,
    TypedFunction,
    is_runtime,
    is_zero,
    shape_text,
)
from .typeddefs import TypedDefinitions
from .unitrules import UnitRules, meeting
from .visitor import Visitor

if TYPE_CHECKING:  # the registry is above the language: the typer is given it
    from ..functions.entry import Builtins

#: Most elements of one matrix written out.
MAX_ELEMENTS = 10_000

#: Longest chain of definitions typed inside one another (a -> b -> c ...).
MAX_CHAIN = 100


class Typer(ArrayTyping, UnitRules, Visitor):
    """Types the definitions of one sheet (lazily, each once, with cycle detection).

    ``visit(node, scope)`` types an expression node (one ``visit_<Node>`` per kind of
    :mod:`workbook.language.expr` node) in a scope of parameters (name -> binding unit).
    """

    def __init__(
        self, spec: SheetSpec, input_units: dict[str, pint.Unit | None], builtins: Builtins
    ):
        self.spec = spec
        self.builtins = builtins
        builtins.refuse_functions_named(spec.function_names, str(spec.path))
        self.input_units = input_units
        # the typed trees, kept where the compute stage reads them without the typer
        self.defs = TypedDefinitions(self, spec)
        self.scalars = self.defs.scalars
        self.functions = self.defs.functions
        self._stack: list[str] = []
        self.dimensionless = un.registry().dimensionless
        # diff() calls typed so far, by id of EXPR's typed tree: each finds its derivative
        # (SymPy) the first time a back end needs it (workbook.numerics.derivative)
        self.derivatives = self.defs.derivatives
        # the parameters in scope of the binding built-in being typed (diff's variable must
        # be one of them: the derivative is a function of it)
        self.scope: dict[str, pint.Unit] = {}
        # functions typed only for the vectors and matrices they are called with
        self._at_numbers_fails: set[str] = set()
        # functions being typed, by specialization key: a call of one inside its own body
        # (recursion) reads the unit and shape assumed for it (see specialized)
        self._assumed: dict[str, TypedFunction] = {}
        self._recursive: set[str] = set()
        self.recursive = self.defs.recursive  # specialization keys of functions calling themselves
        # typings that failed, by specialization key (("scalar", name) for a scalar): asked
        # again, the same error is raised without typing again (see _remembered)
        self._failed: dict[object, WorkbookError] = {}
        self._assumption_reads = 0  # calls typed by an assumed unit (recursion), counted

    # -- public -------------------------------------------------------------------
    def scalar(self, name: str) -> T:
        """Typed body of a scalar definition."""
        if name not in self.scalars:
            d = self._definition(name)
            if d.is_function:
                raise TemplateError(f"'{name}' is a function of {', '.join(d.params)}")
            with self._remembered(("scalar", name)):
                body = self.typed_body(d, {})
                if d.unit is not None:
                    body = self.convert(body, d.unit, _declared(name, d.unit))
                elif not body.text and un.reduced(body.unit) != body.unit:  # rho*V: kg
                    body = self.convert(body, un.reduced(body.unit), f"the formula of '{name}'")
            self.scalars[name] = body
        return self.scalars[name]

    def function(self, name: str) -> TypedFunction:
        """Typed function ``name`` (or one of its specializations, by its key): its body with
        each parameter a number of its unit. A function whose body needs vectors or matrices
        (``P[0]``) has no such typing: then its first specialization typed (by a call with
        vectors or matrices) stands for it, or the error of its typing at numbers is raised."""
        if name in self.functions:
            return self.functions[name]
        if name not in self._at_numbers_fails:
            try:
                return self.specialized(name, ())
            except WorkbookError as at_numbers:
                if not any(_key_of(k) == name for k in self.functions):
                    if not isinstance(at_numbers, ShapeError):
                        raise
                    return self._stand_in(name, self._unspecialized(name, at_numbers))
                self._at_numbers_fails.add(name)
        return self._stand_in(
            name, next(f for k, f in self.functions.items() if _key_of(k) == name)
        )

    def _stand_in(self, name: str, f: TypedFunction) -> TypedFunction:
        """``f``, kept as the specialization that stands for function ``name``."""
        self.defs.stand_ins[name] = f.name
        return f

    def _unspecialized(self, name: str, at_numbers: WorkbookError) -> TypedFunction:
        """A function no formula calls with vectors or matrices, whose body fails at numbers:
        checked with each argument an array of a size known when it is called (its units are
        checked all the same); if that fails too, the error says what failed each way."""
        d = self._definition(name)
        try:
            return self.specialized(name, (RUNTIME,) * len(d.params))
        except WorkbookError as err:
            if at_numbers.message in err.message:  # the same mistake either way
                raise at_numbers from None
            raise err.reworded(
                f"no formula calls {name}() with a vector or matrix; with numbers: "
                f"{at_numbers.message}; with arrays: {err.message}"
            ) from None

    def specialized(self, name: str, shapes: tuple, complexes: tuple = ()) -> TypedFunction:
        """Function ``name`` typed with its parameters of ``shapes`` (None: a number; () for
        all numbers), complex where ``complexes`` says so, each in the unit declared in
        [arguments]; typed once per shapes."""
        key = specialization_key(name, shapes, complexes)
        if key in self._assumed:  # a call inside its own body: recursion
            d = self._definition(name)
            if d.program is None and d.branches is None:  # nothing can end it
                cycle = " -> ".join(self._stack[self._stack.index(name) :] + [name])
                raise TemplateError(f"circular definition: {cycle}", line=d.line, definition=name)
            self._recursive.add(key)
            self._assumption_reads += 1
            return self._assumed[key]
        if key not in self.functions:
            d = self._definition(name)
            shapes = tuple(shapes) or (None,) * len(d.params)
            units = tuple(self.spec.arguments[p].binding_unit for p in d.params)
            kinds = complexes or (False,) * len(d.params)
            scope = {
                p: (u, sh, "complex") if c else u if sh is None else (u, sh)
                for p, u, sh, c in zip(d.params, units, shapes, kinds)
            }
            with self._remembered(key):
                self.functions[key] = self._settled(d, key, units, scope, shapes)
        return self.functions[key]

    @contextlib.contextmanager
    def _remembered(self, key):
        """Type under ``key`` remembering a failure: asked again, the error is raised again
        without typing (a chain of functions over a failing one was typed through once per
        function, quadratic in its length). A failure that rests on the unit assumed for a
        call of a function inside its own body is not remembered (another assumption may
        hold). One made because definitions nest more than ``MAX_CHAIN`` deep is, wherever
        it happened in the chain: that chain is over the limit from any start."""
        failed = self._failed.get(key)
        if failed is not None:
            raise failed.reworded(failed.message)
        reads = self._assumption_reads
        try:
            yield
        except WorkbookError as err:
            if self._assumption_reads == reads:
                # a copy: callers may locate the one they catch
                self._failed[key] = err.reworded(err.message)
            raise

    def _settled(self, d: Definition, key: str, units, scope, shapes) -> TypedFunction:
        """Function ``d`` typed for one specialization. A function that calls itself (Mathcad
        allows it, ending the recursion under an ``if``) is typed with its own calls in an
        assumed unit: the unit it declares, else dimensionless, else the unit of one of its
        arguments (``halve(x)``); the first assumption the body's value agrees with is its
        unit. None agreeing is an error that asks for the unit to be declared."""
        candidates = [d.unit] if d.unit is not None else [self.dimensionless, *units]
        first_error = None
        for unit in dict.fromkeys(candidates):
            assumed = T(unit)
            self._assumed[key] = TypedFunction(key, d.params, units, assumed, shapes)
            self._recursive.discard(key)
            # what this attempt types (a function f calls, that calls f) rests on the
            # assumption: it is forgotten unless the assumption holds
            functions, scalars = set(self.functions), set(self.scalars)
            try:
                body = self.typed_body(d, scope)
                if d.unit is not None:
                    body = self.convert(body, d.unit, _declared(d.name, d.unit))
            except WorkbookError as err:
                if key not in self._recursive:
                    raise
                first_error = first_error or err
                self._forget(functions, scalars)
                continue
            finally:
                del self._assumed[key]
            if key not in self._recursive:
                return TypedFunction(key, d.params, units, body, shapes)
            if body.unit == unit and body.shape is None and not body.text:
                self.recursive.add(key)
                return TypedFunction(key, d.params, units, body, shapes)
            self._forget(functions, scalars)
        why = f": {first_error.message}" if first_error is not None else ""
        raise TemplateError(
            f"{d.name}() calls itself, and no unit of its value agrees with its own calls "
            f"(tried {', '.join(un.pretty(u) or '1' for u in dict.fromkeys(candidates))}); "
            f'declare its unit ({{ program = ..., unit = "..." }}){why}',
            line=d.line,
            definition=d.name,
        )

    def _forget(self, functions: set, scalars: set) -> None:
        """Drop the typings made since ``functions`` and ``scalars`` were the keys."""
        for k in set(self.functions) - functions:
            del self.functions[k]
        for k in set(self.scalars) - scalars:
            del self.scalars[k]
        for n, k in list(self.defs.stand_ins.items()):
            if k not in self.functions:
                del self.defs.stand_ins[n]

    def expression(self, node: ex.Node, scope: dict[str, pint.Unit], what: str) -> T:
        """Type a free expression (a table column, a chart series) in a scope of parameters."""
        try:
            return self.visit(node, scope)
        except WorkbookError as err:
            raise err.located(definition=what) from None

    def unit_of(self, name: str) -> pint.Unit:
        if name in self.spec.inputs:
            u = self.input_units[name]
            if u is None:
                raise TemplateError(f"'{name}' is a choice, not a number")
            return u
        d = self._definition(name)
        return self.function(name).unit if d.is_function else self.scalar(name).unit

    # -- internals ----------------------------------------------------------------
    def where(self) -> dict:
        """File, line and definition being typed (for an error found later, at first use)."""
        name = self._stack[-1] if self._stack else None
        d = self.spec.definitions.get(name) if name else None
        return {"file": str(self.spec.path), "line": d.line if d else None, "definition": name}

    def _definition(self, name: str) -> Definition:
        d = self.spec.definitions.get(name)
        if d is None:
            raise self._unknown("name", name)
        return d

    def _unknown(self, kind: str, name: str, scope=()) -> TemplateError:
        """``unknown name 'x'`` with the nearest names a formula of this sheet may use (none
        for a text that is no name: an imported value's label such as ``Sheet!G4 (not
        translated)``, named so that no formula reads it, among thousands of others)."""
        if not ex.is_identifier(name):
            return TemplateError(f"unknown {kind} '{name}'")
        spec, functions = self.spec, self.builtins.functions
        own = dict.fromkeys([*scope, *spec.inputs, *spec.definitions, *spec.arguments])
        known = {**own, **dict.fromkeys([*spec.blocks, *functions, *self.builtins.constants])}
        hint = nearest(name, known)
        if kind == "name":  # a value is meant: the sheet's names first (R1 is R_1, not Re())
            values = nearest(name, {k: v for k, v in known.items() if k not in functions})
            hint = values if values or un.is_unit_name(name) else hint
        if kind == "name" and un.is_unit_name(name):  # a unit's: the sheet's names like it, then
            near = nearest(name, own)[:-1]  # the unit's hint (not a built-in's: mm, gamma)
            hint = f"{near}; " if near else " ("
            hint += f"a unit is written after a number: 1 {name})"
        return TemplateError(f"unknown {kind} '{name}'{hint}")

    def typed_body(self, d: Definition, scope: dict[str, pint.Unit]) -> T:
        """The typed tree of definition ``d``'s body, its names in ``scope`` (a circular
        definition is refused)."""
        if d.name in self._stack:
            cycle = " -> ".join(self._stack[self._stack.index(d.name) :] + [d.name])
            raise TemplateError(f"circular definition: {cycle}", line=d.line, definition=d.name)
        if len(self._stack) >= MAX_CHAIN:
            raise LimitError(
                f"definitions refer to each other more than {MAX_CHAIN} deep "
                f"({' -> '.join(self._stack[:3])} -> ... -> {d.name})",
                line=d.line,
                definition=d.name,
            )
        self._stack.append(d.name)
        try:
            if d.program is not None:
                return self.program_body(d, scope)
            if d.ode is not None:
                return self.ode_body(d, scope)
            if d.branches is None:
                body = self.visit(d.body, scope)
                if body.boolean:
                    raise TemplateError("the value is a comparison, not a number")
                return body if body.text else self.not_text(body, f"'{d.name}'")
            return self._piecewise(d, scope)
        except WorkbookError as err:
            raise err.located(file=str(self.spec.path), line=d.line, definition=d.name) from None
        finally:
            self._stack.pop()

    def _piecewise(self, d: Definition, scope) -> T:
        conds, values, texts = [], [], []
        first_unit = None
        is_text = None
        typed = []
        for b in d.branches:
            v = self.visit(b.value, scope)
            if v.boolean:
                raise TemplateError(f"piece {b.text!r} has a condition as its value")
            if v.shape is not None:
                raise TemplateError(f"piece {b.text!r}: the pieces of a function are numbers")
            if is_text is None:
                is_text = v.text
            elif v.text != is_text:
                raise TemplateError(f"piece {b.text!r}: text and numbers mixed in one function")
            typed.append(v)
        if not is_text:
            typed = meeting(typed)  # "90 if ...", "theta otherwise": 90 is 90 deg
        for b, v in zip(d.branches, typed):
            if not v.text:
                self.not_text(v, f"piece {b.text!r}")
            if first_unit is None:
                first_unit = v.unit
            elif not v.text:
                v = self.convert(
                    v, first_unit, f"piece {b.text!r} (first piece is in {un.dims(first_unit)})"
                )
            c = None
            if b.condition is not None:
                c = self.visit(b.condition, scope)
                if not c.boolean:
                    raise TemplateError(f"the condition of piece {b.text!r} is not a comparison")
            conds.append(c)
            values.append(v)
            texts.append(b.text)
        return TPiecewise(
            first_unit,
            conditions=tuple(conds),
            values=tuple(values),
            texts=tuple(texts),
            text=bool(is_text),
        )

    def visit_Number(self, node: ex.Number, scope) -> T:
        return TConst(self.dimensionless, value=node.value)

    def visit_Imaginary(self, node: ex.Imaginary, scope) -> T:
        return TConst(self.dimensionless, value=complex(0.0, node.value))

    def visit_Quantity(self, node: ex.Quantity, scope) -> T:
        """``20 mm``: a constant in its unit, read by the reader of input values. A name joined
        to the unit (``2 m*x``) that is also a name of this sheet is refused: write a space."""
        shown = ex.to_text(node)
        joined = re.findall(r"[^\W\d][\w°µμΩ%]*", node.unit)[1:]
        known = {*scope, *self.spec.inputs, *self.spec.definitions, *self.spec.arguments}
        clash = next((n for n in joined if n in known), None)
        if clash is not None:
            at = re.search(rf"(?<![\w°µμΩ%]){re.escape(clash)}(?![\w°µμΩ%])", node.unit).start()
            head, tail = node.unit[: at - 1], node.unit[at - 1 :]
            raise TemplateError(
                f"{shown!r}: '{clash}' is read as part of the unit of the number, and it is a "
                f"name of this sheet; to multiply by '{clash}', put spaces around "
                f"'{tail[0]}': '{ex.number_text(node.value)} {head} {tail[0]} {tail[1:]}'"
            )
        try:
            unit = un.unit(node.unit, what=f"the quantity {shown!r}")
        except WorkbookError as err:
            if re.search(r"[*/]", node.unit):
                hint = "; a space ends the unit of a number (2 m * x is 2 m times x)"
                raise err.reworded(err.message + hint) from None
            raise
        return TConst(unit, value=node.value, derived=True)

    def visit_Text(self, node: ex.Text, scope) -> T:
        return TText(self.dimensionless, value=node.value, text=True)

    def visit_Name(self, node: ex.Name, scope) -> T:
        return self._name(node.id, scope)

    def visit_Unary(self, node: ex.Unary, scope) -> T:
        child = self.visit(node.operand, scope)
        if node.op == "not":
            if not child.boolean:
                raise TemplateError("'not' needs a comparison")
            return TUnary(child.unit, op="not", child=child, boolean=True)
        self.as_number(child, f"'{node.op}'")
        if node.op == "+":
            return child
        if isinstance(child, TConst):  # -10 degC written: a temperature below zero
            return TConst(child.unit, value=-child.value, derived=child.derived)
        if un.temperature_kind(child.unit) == "absolute":
            shown = un.pretty(child.unit)
            raise UnitError(
                f"the negative of an absolute temperature ({shown}) depends on its scale "
                f"(the negative of 25 degC would be -25 degC, and -1 times it is -298.15 K, as "
                f"products take kelvin); negate a difference, -(T - 0 {shown}), or a value in K"
            )
        return TUnary(child.unit, op="-", child=child, shape=child.shape)

    def visit_Logic(self, node: ex.Logic, scope) -> T:
        vals = tuple(self.visit(v, scope) for v in node.values)
        if not all(v.boolean for v in vals):
            raise TemplateError(f"'{node.op}' joins comparisons, not numbers")
        return TLogic(self.dimensionless, op=node.op, values=vals, boolean=True)

    def _name(self, name: str, scope) -> T:
        if name in scope:
            if isinstance(scope[name], tuple):  # (unit, shape), and "complex" for a complex one
                unit, shape, *kind = scope[name]
                return TParam(unit, name=name, shape=shape, complex=bool(kind))
            return TParam(scope[name], name=name)
        block = self.spec.solve_of(name)
        if block is not None:
            if not all(p in scope for p in block.parameters):
                raise TemplateError(
                    f"'{name}' is found by a [[solve]] block with parameters: it is a function, "
                    f"write {name}({', '.join(block.parameters)})"
                )
            return TRef(block.unknowns[name].units, name=name, kind="solve")
        if name in self.spec.data:  # a vector of the measured values, in the column's unit
            return column_vector(self.spec.data[name])
        if name in self.spec.inputs:
            u = self.input_units[name]
            if u is None:
                return TRef(self.dimensionless, name=name, kind="choice")
            return TRef(u, name=name, kind="input")
        if name in self.spec.definitions:
            d = self.spec.definitions[name]
            if d.is_function:
                raise TemplateError(
                    f"'{name}' is a function of {', '.join(d.params)}: "
                    f"write {name}({', '.join(d.params)})"
                )
            body = self.scalar(name)
            return TRef(body.unit, name=name, kind="definition", **value_kind(body))
        if name in self.spec.arguments:
            raise TemplateError(f"'{name}' is an argument, used here outside a function of {name}")
        if name in self.builtins.constants:  # the sheet's own pi, e or g came first
            return TRef(un.unit(self.builtins.constants[name].unit), name=name, kind="builtin")
        if name in self.builtins.functions or name in self.spec.blocks:
            raise TemplateError(f"'{name}' is a function: call it as {name}(...)")
        raise self._unknown("name", name, scope)

    def visit_Binary(self, node: ex.Binary, scope) -> T:
        left = self.as_number(self.visit(node.left, scope), f"'{node.op}'")
        right = self.as_number(self.visit(node.right, scope), f"'{node.op}'")
        op = node.op
        if left.shape is not None or right.shape is not None:
            return self.matrix_binary(op, left, right)
        return self.scalar_binary(op, left, right)

    def visit_Compare(self, node: ex.Compare, scope) -> T:
        ops = list(node.operands)
        typed = [self.visit(o, scope) for o in ops]
        if any(t.shape is not None and not is_runtime(t.shape) for t in typed):
            raise TemplateError("cannot compare a vector or matrix; compare its elements, v[i]")
        texts = [t.text or (isinstance(t, TRef) and t.kind == "choice") for t in typed]
        if any(texts):
            if len(typed) != 2 or node.ops[0] not in ("==", "!="):
                raise TemplateError('text is compared with == or != only: law == "stepped"')
            # an element of a run-time array may be text: compared when it runs
            if not all(x or is_runtime(t.shape) for x, t in zip(texts, typed)):
                raise TemplateError("cannot compare text with a number")
            for a, b in ((typed[0], typed[1]), (typed[1], typed[0])):
                if isinstance(a, TRef) and a.kind == "choice" and isinstance(b, TText):
                    opts = self.spec.inputs[a.name].options
                    if b.value not in opts:
                        raise TemplateError(
                            f"{b.value!r} is not one of the options of '{a.name}': "
                            f"{', '.join(opts)}"
                        )
            return TCompare(self.dimensionless, ops=node.ops, operands=tuple(typed), boolean=True)
        no_order(node, typed)
        typed = meeting(typed)
        first = next((t for t in typed if not is_zero(t)), typed[0])
        out = []
        for t in typed:
            self.as_number(t, "comparison")
            if t.unit.dimensionality != first.unit.dimensionality and not is_zero(t):
                raise UnitError(
                    f"cannot compare {un.dims(first.unit)} ({un.pretty(first.unit)}) "
                    f"with {un.dims(t.unit)} ({un.pretty(t.unit)})"
                )
            out.append(self.convert(t, first.unit, "comparison"))
        return TCompare(self.dimensionless, ops=node.ops, operands=tuple(out), boolean=True)

    def visit_Call(self, node: ex.Call, scope) -> T:
        name = node.func
        if name in AGGREGATES and name not in self.spec.definitions:
            return self._aggregate(node)
        entry = self.builtins.functions.get(name)
        local = name in self.spec.definitions or name in self.spec.blocks
        if name == "vectorize" and not local:
            return self.vectorize(node, scope)
        if entry is not None and entry.binds and not local and len(node.args) > max(entry.binds):
            return self._binding_call(node, scope)
        if entry is not None and entry.data_args and name not in self.spec.definitions:
            return self._data_call(node, scope)
        known = (
            name in self.spec.definitions
            or name in self.spec.blocks
            or name in self.builtins.functions
        )
        args = [self.visit(a, scope) for a in node.args] if known else []  # unknown: say so first
        if not (entry is not None and entry.texts and not local):
            for a in args:
                self.as_number(a, f"argument of {name}()")
        if name in self.spec.definitions:
            d = self.spec.definitions[name]
            if not d.is_function:
                raise TemplateError(f"'{name}' is not a function; write {name} without brackets")
            if len(args) != len(d.params):
                raise TemplateError(
                    f"{name}() takes {len(d.params)} argument(s) "
                    f"({', '.join(d.params)}), got {len(args)}"
                )
            shapes = tuple(a.shape for a in args)
            complexes = tuple(a.complex for a in args)
            if any(shapes) or any(complexes):
                f = self._called(node, shapes, complexes)
            else:
                f = self.specialized(name, ())
            conv = tuple(
                self._arg(a, u, d.params[i], name, self.spec.arguments[d.params[i]])
                for i, (a, u) in enumerate(zip(args, f.param_units))
            )
            return TCall(f.unit, name=f.name, args=conv, **value_kind(f.body))
        if name in self.spec.blocks:
            from .. import blocks

            blk = blocks.get(self.spec.blocks[name], "function")
            self._scalar_args(name, args)
            if len(args) != len(blk.args):
                raise TemplateError(
                    f"{name}() takes {len(blk.args)} argument(s) "
                    f"({', '.join(blk.args)}), got {len(args)}"
                )
            conv = tuple(
                self.convert(a, un.unit(u), f"argument '{p}' of {name}()")
                for a, (p, u) in zip(args, blk.args.items())
            )
            return TBlock(un.unit(blk.returns), name=name, ref=blk.ref, args=conv)
        if name not in self.builtins.functions:
            if name == "log":
                raise TemplateError(
                    "log() is not accepted (Mathcad's log is base 10, numpy's is natural): "
                    "write ln() or log10()"
                )
            if name in self.spec.inputs or name in scope:
                raise TemplateError(f"'{name}' is a value, not a function; write {name}")
            raise self._unknown("function", name, scope)
        entry = self.builtins.functions[name]
        entry.check_arity(len(args))
        args = [self.kelvin(a) for a in args]  # abs(T), max(T1, T2): as Mathcad, in kelvin
        if entry.arrays and any(is_runtime(a.shape) for a in args):
            if entry.runtime is None:
                raise TemplateError(
                    f"{name}() of an array whose size is known only when the program runs is "
                    "not supported"
                )
            return entry.runtime(self, name, tuple(args))
        real_only(name, entry, args)
        typed = entry.unit_rule(self, name, tuple(args))
        if entry.complex == "real" and typed.complex:  # abs(z): the modulus is real
            typed = dataclasses.replace(typed, complex=False)
        return typed if entry.arrays else self.elementwise_call(name, entry, tuple(args), typed)

    def _called(self, node: ex.Call, shapes: tuple, complexes: tuple = ()) -> TypedFunction:
        """The specialization of a function called with vectors or matrices, or with complex
        values; an error in its body for these arguments names the call as well as the
        definition."""
        name = node.func
        d = self.spec.definitions[name]
        if any(shapes) and (d.ode is not None or d.branches is not None):
            what = "the solution of an ode" if d.ode is not None else "defined by pieces"
            raise TemplateError(
                f"{ex.to_text(node)}: {name}() is {what}; its arguments are numbers "
                "(pass elements, v[i])"
            )
        try:
            return self.specialized(name, shapes, complexes)
        except WorkbookError as err:
            given = ", ".join(
                f"{p} a {'complex ' if c else ''}{shape_text(sh) if sh is not None else 'number'}"
                for p, sh, c in zip(d.params, shapes, complexes or (False,) * len(shapes))
                if sh is not None or c
            )
            message = f"{ex.to_text(node)} (with {given}): {err.message}"
            caller = self._stack[-1] if self._stack else None
            if caller is not None and caller != err.definition:
                message += f" (called in '{caller}')"
            raise err.reworded(message) from None

    def _scalar_args(self, name: str, args) -> None:
        for a in args:
            if a.shape is not None:
                raise TemplateError(
                    f"{name}() takes numbers; pass elements (v[i]) rather than a vector or matrix"
                )

    def _binding_call(self, node: ex.Call, scope) -> T:
        """A built-in that binds a variable: EXPR is typed with the variable in scope."""
        name, entry = node.func, self.builtins.functions[node.func]
        entry.check_arity(len(node.args))
        expr_at, var_at = entry.binds
        var = node.args[var_at]
        if not isinstance(var, ex.Name):
            raise TemplateError(
                f"{name}(): argument {var_at + 1} must be the name of the variable, "
                f"got {ex.to_text(var)!r}"
            )
        if var.id in self.spec.inputs or var.id in self.spec.definitions:
            raise TemplateError(
                f"{name}(): the variable '{var.id}' is already an input or a definition; "
                "choose another name"
            )
        arg = self.spec.arguments.get(var.id)
        unit = arg.binding_unit if arg is not None else self.dimensionless
        args: list[T] = []
        for i, a in enumerate(node.args):
            if i == var_at:
                args.append(TParam(unit, name=var.id))
            elif i == expr_at:
                body = self.visit(a, {**scope, var.id: unit})
                args.append(self.as_number(body, f"argument {i + 1} of {name}()"))
            else:
                args.append(self.as_number(self.visit(a, scope), f"argument {i + 1} of {name}()"))
        self.scope = scope
        real_only(name, entry, args)
        typed = entry.unit_rule(self, name, tuple(args))
        body = args[expr_at]
        if body.shape is not None and typed.shape is None:  # never a matrix taken as a number
            raise TemplateError(
                f"{name}(): the expression is a {shape_text(body.shape)}; {name}() takes an "
                "expression that is a number"
            )
        return typed

    def _data_call(self, node: ex.Call, scope) -> T:
        """A built-in reading [data] columns: those arguments are column names (their values)."""
        name, entry = node.func, self.builtins.functions[node.func]
        entry.check_arity(len(node.args))
        args: list[T] = []
        for i, a in enumerate(node.args):
            if i in entry.data_args:
                col = self.spec.data.get(a.id) if isinstance(a, ex.Name) else None
                defined = isinstance(a, ex.Name) and (
                    a.id in scope or a.id in self.spec.definitions
                )  # a vector of the sheet or of a program, named
                if col is None and (defined or not isinstance(a, ex.Name)):
                    typed = self.as_number(self.visit(a, scope), f"argument {i + 1} of {name}()")
                    if typed.shape is not None:  # a vector of the sheet or of a program
                        args.append(typed)
                        continue
                if col is None:
                    known = ", ".join(self.spec.data) or "none: add a [data] table"
                    raise TemplateError(
                        f"{name}(): argument {i + 1} must be a column of a [data] table "
                        f"(columns: {known}), got {ex.to_text(a)!r}"
                    )
                args.append(TRef(col.unit, name=a.id, kind="data"))
            else:
                args.append(self.as_number(self.visit(a, scope), f"argument {i + 1} of {name}()"))
        self.scope = scope
        return entry.unit_rule(self, name, tuple(args))

    def _aggregate(self, node: ex.Call) -> T:
        """``max_over(table, column)``: the largest value of a column of a range table."""
        name = node.func
        if len(node.args) != 2 or not all(isinstance(a, ex.Name) for a in node.args):
            raise TemplateError(f"write {name}(table, column), e.g. {name}(design, S0_req)")
        tname, cname = node.args[0].id, node.args[1].id
        table = next((t for t in self.spec.tables if t.name == tname), None)
        if table is None or table.range is None:
            raise TemplateError(f"{name}(): '{tname}' is not a range table of this sheet")
        col = next((c for c in table.columns if c.text == cname), None)
        if col is None:
            raise TemplateError(
                f"{name}(): table '{tname}' has no column '{cname}' (columns: "
                f"{', '.join(c.text for c in table.columns)})"
            )
        typed = column_type(self, col, table.range.var, f"{name}({tname}, {cname})")
        if typed.complex:
            raise TemplateError(
                f"{name}({tname}, {cname}): the column is complex, and complex numbers have no "
                "order; make a column of abs(z) or Re(z)"
            )
        return TAggregate(typed.unit, func=AGGREGATES[name], table=tname, column=cname)

    def _arg(self, a: T, unit: pint.Unit, param: str, fname: str, spec) -> T:
        where = f"argument '{param}' of {fname}() (declared in {un.pretty(spec.unit) or '1'})"
        return self.convert(a, unit, where)  # f(90) of an argument in deg is 90 deg

    # -- vectors, matrices, indexing, inline conditions, programs and ODE states ----------
    def visit_Matrix(self, node: ex.Matrix, scope) -> T:
        r, c = len(node.rows), len(node.rows[0])
        if r * c > MAX_ELEMENTS:
            raise TemplateError(f"a matrix of {r * c} elements (limit {MAX_ELEMENTS})")
        typed = [[self.visit(e, scope) for e in row] for row in node.rows]
        first = None
        nested = any(e.shape is not None for row in typed for e in row)
        # text beside numbers (a table of load kinds): its elements are looked at when it runs
        texts = any(e.text for row in typed for e in row)
        for i, row in enumerate(typed):
            for j, e in enumerate(row):
                where = f"element [{i}, {j}] of the matrix"
                if e.boolean:
                    raise TemplateError(f"{where} is a comparison; elements are numbers or text")
                if e.text:
                    continue
                self.as_number(e, where)
                if first is None and not is_zero(e):
                    first = (e, i, j)
        unit = first[0].unit if first else self.dimensionless
        rows = []
        for i, row in enumerate(typed):
            out = []
            for j, e in enumerate(row):
                if e.text:
                    out.append(e)
                    continue
                if not is_zero(e) and e.unit.dimensionality != unit.dimensionality:
                    f, fi, fj = first
                    raise UnitError(
                        f"a matrix has one unit: element [{i}, {j}] is {un.dims(e.unit)} "
                        f"({un.pretty(e.unit) or '1'}), element [{fi}, {fj}] is "
                        f"{un.dims(unit)} ({un.pretty(unit) or '1'}); split it into "
                        "matrices of one dimension each"
                    )
                out.append(self.convert(e, unit, f"element [{i}, {j}] of the matrix"))
            rows.append(tuple(out))
        # an array of arrays (Mathcad's nested array): its shape is looked at when it runs
        return TMatrix(unit, rows=tuple(rows), shape=RUNTIME if nested or texts else (r, c))

    def visit_Index(self, node: ex.Index, scope) -> T:
        target = self.visit(node.target, scope)
        if target.shape is None:
            raise ShapeError(
                f"{ex.to_text(node.target)} is not a vector or matrix; it cannot be indexed"
            )
        n = len(node.indices)
        if is_runtime(target.shape):  # its shape, and the element's, are known when it runs
            if n > 2:
                raise TemplateError(f"{ex.to_text(node)}: at most two indices, M[i, j]")
            words = ("row", "column") if n == 2 else ("element",)
            idx = tuple(
                self.typed_index(i, scope, None, w, ex.to_text(node))
                for i, w in zip(node.indices, words)
            )
            return TIndex(
                target.unit, target=target, indices=idx, origin=self.spec.origin, shape=RUNTIME
            )
        r, c = target.shape
        if n == 1 and c != 1:
            raise TemplateError(
                f"{ex.to_text(node.target)} is a {shape_text(target.shape)}: "
                "write M[i, j] (one index is for a vector)"
            )
        idx = []
        for k, (i, size) in enumerate(zip(node.indices, (r, c) if n == 2 else (r,))):
            word = ("row", "column")[k] if n == 2 else "element"
            idx.append(self.typed_index(i, scope, size, word, ex.to_text(node)))
        return TIndex(target.unit, target=target, indices=tuple(idx), origin=self.spec.origin)

    def typed_index(self, i: ex.Node, scope, size: int | None, word: str, what: str) -> T:
        """An index: a plain number; a constant one is checked against ``size`` here (None:
        a run-time array, checked when it runs)."""
        origin = self.spec.origin
        t = self.plain(self.as_number(self.visit(i, scope), "an index"), f"the {word} index")
        real_index(t, what, word)
        if t.shape is not None and not is_runtime(t.shape):
            raise TemplateError(f"the {word} index is a matrix; an index is a number")
        if isinstance(t, TConst) and size is not None:
            v = t.value
            if v != int(v) or not origin <= v < origin + size:
                raise TemplateError(
                    f"{what}: {word} index {v:g} is out of range "
                    f"({size} {word}s: {origin} .. {origin + size - 1} with origin {origin})"
                )
        return t

    def visit_IfElse(self, node: ex.IfElse, scope) -> T:
        value = self.visit(node.value, scope)
        other = self.visit(node.other, scope)
        cond = self.visit(node.condition, scope)
        if not cond.boolean:
            raise TemplateError(f"the condition of {ex.to_text(node)!r} is not a comparison")
        if value.boolean or other.boolean:
            raise TemplateError(f"{ex.to_text(node)!r} gives a comparison, not a value")
        runtime = is_runtime(value.shape) or is_runtime(other.shape)
        if not runtime and (value.shape is not None or other.shape is not None):
            raise TemplateError(f"{ex.to_text(node)!r}: the values of a condition are numbers")
        if runtime and any(v.shape is not None and not is_runtime(v.shape) for v in (value, other)):
            raise TemplateError(f"{ex.to_text(node)!r}: the values of a condition are numbers")
        if value.text != other.text:
            raise TemplateError(
                f"{ex.to_text(node)!r} gives text on one side, a number on the other"
            )
        unit = value.unit
        if not value.text:
            self.as_number(value, "a value")
            self.as_number(other, "a value")
            if is_zero(value) and not is_zero(other):
                unit = other.unit
            value = self.convert(value, unit, "the value if the condition holds")
            other = self.convert(other, unit, f"the value otherwise ({ex.to_text(node.other)})")
        texts = (ex.to_text(node.value) + " if " + ex.to_text(node.condition),)
        return TPiecewise(
            unit,
            conditions=(cond, None),
            values=(value, other),
            texts=texts + (ex.to_text(node.other) + " otherwise",),
            text=value.text,
            # a value known when it runs (an element of a run-time array): a number, checked
            shape=RUNTIME if runtime else None,
        )

    def vectorize(self, node: ex.Call, scope) -> T:
        """``vectorize(EXPR)``: ``* / ^`` inside work element by element."""
        if len(node.args) != 1:
            raise TemplateError(f"vectorize() takes 1 argument, got {len(node.args)}")
        self._elementwise += 1
        try:
            return self.visit(node.args[0], scope)
        finally:
            self._elementwise -= 1

    def program_body(self, d, scope: dict[str, pint.Unit]) -> T:
        from ..program import typer as pg

        def type_expr(node, sc):
            return real_in_program(self.visit(node, sc), node)

        def convert(t, unit, where):
            if t.text:
                raise TemplateError(f"{where}: text where a number is wanted")
            return self.convert(t, unit, where)

        typing = pg.ExprTyping(
            type_expr=type_expr,
            convert=convert,
            is_boolean=lambda t: t.boolean,
            is_text=lambda t: t.text,
            is_zero=is_zero,
            unit_of=lambda t: t.unit,
            shape_of=lambda t: t.shape,
            scope_entry=lambda unit, shape: unit if shape is None else (unit, shape),
            index=lambda i, sc, size, word: self.typed_index(i, sc, size, word, "an element"),
            origin=self.spec.origin,
        )
        reserved = frozenset(self.spec.inputs) | frozenset(self.spec.definitions)
        typed = pg.type_program(d.program, dict(scope), typing, reserved=reserved - set(scope))
        return TProgram(
            typed.unit,
            name=d.name,
            program=typed,
            params=tuple(d.params),
            matrices=tuple(p for p in d.params if isinstance(scope[p], tuple)),
            text=typed.text,
            shape=typed.shape,
        )

    def ode_body(self, d, scope: dict[str, pint.Unit]) -> T:
        name, k = d.ode
        typed = self.ode(name)
        (var,) = d.params
        t = TParam(scope[var], name=var)
        shape = typed.shapes[k] if typed.shapes else None
        return TOde(typed.units[k], ode=name, state=k, name=d.name, args=(t,), shape=shape)

    def ode(self, name: str):
        """The typed section ``[[ode]] name`` (units checked once)."""
        from .odes import type_ode

        cache = self.defs.odes
        if name not in cache:
            spec = self.spec.odes[name]
            key = f"ode {name}"
            if key in self._stack:
                raise TemplateError(f"ode '{name}' refers to its own solution")
            self._stack.append(key)
            try:
                cache[name] = type_ode(self, spec)
            finally:
                self._stack.pop()
        return cache[name]


AGGREGATES = {"max_over": "max", "min_over": "min"}


def specialization_key(name: str, shapes: tuple, complexes: tuple = ()) -> str:
    """The name of function ``name`` typed for arguments of ``shapes`` (``dist@2x1,2x1``;
    ``1`` for a number, ``c`` after a complex one: ``par@1c,1c``); ``name`` itself for real
    numbers only."""
    if not any(shapes) and not any(complexes):
        return name
    kinds = complexes or (False,) * len(shapes)
    return name + "@" + ",".join(_shape_key(s) + ("c" if c else "") for s, c in zip(shapes, kinds))


def _shape_key(shape) -> str:
    if shape is None:
        return "1"
    return "?" if is_runtime(shape) else f"{shape[0]}x{shape[1]}"


def _key_of(key: str) -> str:
    """The function a specialization key belongs to."""
    return key.split("@", 1)[0]


def column_type(typer: Typer, col, var: str, what: str) -> T:
    """Typed tree of a table column (in its declared unit, if any)."""
    arg = typer.spec.arguments.get(var)
    scope = {var: arg.binding_unit if arg else typer.dimensionless}
    t = typer.expression(column_node(typer.spec, col, var), scope, what)
    if col.unit is not None:
        t = typer.convert(t, col.unit, f"column '{col.text}' shown in {un.pretty(col.unit)}")
    return t


def _declared(name: str, unit: pint.Unit) -> str:
    """Where a formula's unit meets its declared one: the computed unit comes first."""
    return f"the formula of '{name}' (declared in {un.pretty(unit) or '1'})"
