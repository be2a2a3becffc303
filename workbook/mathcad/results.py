"""The results Mathcad stored, as printed values: an evaluation (``=``) of a number, of a
vector or matrix (one value per element), of a nested array (one per number in it), a result
that is round-off of a larger size, and a standalone evaluation of an expression."""

from __future__ import annotations

from ..language import expr as ex
from . import names as nm
from . import trees as tt
from .expressions import ExprTranslator
from .reader import MNode, Region
from .symbols import Sym, Untranslatable
from .symbols import key as _key
from .translation import Item, Result

#: Absolute tolerance of a stored 0 (in its unit), and of a value of a difference relative to
#: its terms' size, and of an array's element relative to its largest element: Mathcad's value
#: where terms cancel is round-off of their size (a residual N x - w: 5e-12 for terms up to
#: 2401; an element of a sum of stiffness matrices stored as 0 is -5.8e-11 here, of 1.3e8).
ZERO_TOLERANCE = 1e-12
DIFFERENCE_TOLERANCE = 1e-9
MATRIX_ZERO_TOLERANCE = 1e-15


class ResultsMixin:
    """The :class:`~workbook.mathcad.translate.Translator`'s evaluations."""

    def evaluation(self, region: Region, node: MNode, target: Sym | None) -> None:
        """An `expr =` with its stored result: a printed value (or several)."""
        result = node.find("result")
        if result is None or not result.children:
            return  # Mathcad stored nothing (not calculated, or an error)
        expr = node.children[0]
        mathcad = self.describe_expr(expr)
        if tt.is_nested(result.children[0]):
            self.nested(region, expr, target, result.children[0], mathcad)
            return
        try:
            unit, values = tt.stored(result.children[0])
            shape = tt.shape(result.children[0])
        except Untranslatable as why:
            self.out.results.append(Result(region.id, None, mathcad, "", []))
            self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        writer = tt.writer(expr, 2) if target is None else None  # WRITEPRN("file", M) =
        if writer is not None:
            self.written(region, *writer[:2], writer[2], node)
            return
        if any(isinstance(v, complex) for v in values):
            self.complex_result(region, expr, target, unit, values, shape, mathcad)
            return
        self.remember_shown(expr, target, unit, values)
        before = len(self.out.results)
        try:
            self.evaluation_values(region, expr, target, unit, values, shape, mathcad)
        finally:
            for res in self.out.results[before:]:
                res.round_off = self.round_off(expr, unit, values)

    def round_off(self, expr: MNode, unit: str, values) -> tuple[float, str] | None:
        """The absolute tolerance of an evaluation whose stored values include round-off of a
        larger size than 1e-12 (the tolerance of a stored 0), and why; None: there is none."""
        size = self.terms_size(expr, unit)
        if size is not None and DIFFERENCE_TOLERANCE * size > ZERO_TOLERANCE:
            return DIFFERENCE_TOLERANCE * size, (
                f"a difference, within {DIFFERENCE_TOLERANCE:g} of its terms' size ({size:g}, "
                "as Mathcad showed a term)"
            )
        numbers = [abs(v) for v in values if isinstance(v, float)]
        if len(numbers) > 1 and 0.0 in numbers:
            largest = max(numbers)
            if MATRIX_ZERO_TOLERANCE * largest > ZERO_TOLERANCE:
                return MATRIX_ZERO_TOLERANCE * largest, (
                    f"an array with elements stored as 0, within {MATRIX_ZERO_TOLERANCE:g} of "
                    f"its largest element ({largest:g})"
                )
        return None

    def remember_shown(self, expr: MNode, target: Sym | None, unit: str, values) -> None:
        """The values Mathcad stored for a name (``w =``, or ``w := ... =``)."""
        expr = tt.unparen(expr)
        sym = target
        if sym is None and expr.tag == "id":
            sym = self.scope.get(_key(expr))
        numbers = [v for v in values if isinstance(v, float)]
        if sym is not None and numbers:
            self.shown[sym.token()] = (unit, numbers)

    def terms_size(self, expr: MNode, unit: str) -> float | None:
        """For a difference ``a - b`` (or a sum) of which a or b is a name whose values Mathcad
        stored, in the same unit: the largest of them. Mathcad's value of a difference whose
        terms cancel is round-off of that size (a residual ``N x - w`` stores 5e-12 for terms
        near 2401), which no other computation reproduces digit for digit."""
        expr = tt.unparen(expr)
        if expr.tag != "apply" or len(expr.children) != 3:
            return None
        if expr.children[0].tag not in ("minus", "plus"):
            return None
        sizes = []
        for term in expr.children[1:]:
            term = tt.unparen(term)
            sym = self.scope.get(_key(term)) if term.tag == "id" else None
            shown = self.shown.get(sym.token()) if sym is not None else None
            if shown is not None and shown[0] == unit:
                sizes.append(max(abs(v) for v in shown[1]))
        return max(sizes) if sizes else None

    def evaluation_values(self, region: Region, expr: MNode, target, unit, values, shape, mathcad):
        """The printed values of an evaluation whose stored values are read."""
        if target is not None:  # a definition with its value shown: x := ... = value
            if len(values) == 1:
                self.out.results.append(
                    Result(region.id, target, mathcad, unit, [(None, values[0])])
                )
                return
            try:
                if target.broken:
                    raise Untranslatable(target.broken)
                self.array_result(region, ex.Name(target.token()), shape, values, unit, mathcad)
            except Untranslatable as why:
                self.broken_result(region, mathcad, unit, values, str(why))
                if not target.broken:
                    self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        try:
            self.standalone(region, expr, unit, values, mathcad, shape)
        except Untranslatable as why:
            self.broken_result(region, mathcad, unit, values, str(why))
            raise

    def complex_result(self, region: Region, expr: MNode, target, unit, values, shape, mathcad):
        """A result with complex numbers: its real parts and its imaginary parts, each a
        printed value of ``Re(...)`` and ``Im(...)`` of what Mathcad evaluated (a real
        element's imaginary part is 0)."""
        if any(isinstance(v, str) for v in values):
            raise Untranslatable("a stored result of texts and complex numbers")
        parts = [(complex(v).real, complex(v).imag) for v in values]
        try:
            if target is not None:
                if target.broken:
                    raise Untranslatable(target.broken)
                base: ex.Node = ex.Name(target.token())
            else:
                et = ExprTranslator(self)
                base = et.value(expr)
                if et.ranges:
                    self.complex_over_range(
                        region, base, list(dict.fromkeys(et.ranges)), unit, parts, mathcad
                    )
                    return
            if not isinstance(base, ex.Name):  # one definition, read by both parts
                whole = self.new_sym("helper", f"result_{region.id}_value", mathcad, region.id)
                self.out.items.append(Item("definition", region.id, sym=whole, body=base))
                base = ex.Name(whole.token())
            for k, part in enumerate(("Re", "Im")):
                numbers, what = [p[k] for p in parts], f"{part}({mathcad})"
                if len(values) > 1:
                    self.array_result(region, base, shape, numbers, unit, what, part)
                    continue
                sym = self.new_sym("helper", f"result_{region.id}_{part.lower()}", what, region.id)
                call = ex.Call(part, (base,))
                self.out.items.append(Item("definition", region.id, sym=sym, body=call))
                self.out.results.append(Result(region.id, sym, what, unit, [(None, numbers[0])]))
        except Untranslatable as why:  # each number Mathcad stored counts once, as a text
            texts = [f"{a!r}{'-' if b < 0 else '+'}{abs(b)!r}i" for a, b in parts]
            self.broken_result(region, mathcad, unit, texts, str(why))
            if target is None:
                raise
            if not target.broken:
                self.skip(region.id, f"the result of {mathcad}", str(why))

    def complex_over_range(self, region: Region, body: ex.Node, ranges, unit, parts, mathcad):
        """A complex result of an expression over one range variable: the real and the
        imaginary part at each of the range's values, each a function of it."""
        if len(ranges) > 1:
            raise Untranslatable("an evaluation over two range variables (a matrix)")
        var = ranges[0]
        at = next(i for i in self.out.items if i.sym is var).range_values
        if len(at) != len(parts):
            raise Untranslatable(
                f"Mathcad lists {len(parts)} values of the range {var.mathcad}, which has {len(at)}"
            )
        for k, part in enumerate(("Re", "Im")):
            param = self.new_sym("param", var.base, var.mathcad, unit=var.unit)
            what = f"{part}({mathcad})"
            sym = self.new_sym("helper", f"result_{region.id}_{part.lower()}", what, region.id)
            inner = ex.Call(part, (tt.rename(body, {var.token(): param.token()}),))
            self.out.items.append(Item("function", region.id, sym=sym, params=[param], body=inner))
            values = list(zip(at, (p[k] for p in parts)))
            self.out.results.append(Result(region.id, sym, what, unit, values, param))

    def broken_result(self, region: Region, mathcad: str, unit: str, values, why: str) -> None:
        """Stored values whose evaluation is not translated: kept, so they count."""
        sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
        sym.broken = why
        self.out.results.append(Result(region.id, sym, mathcad, unit, [(None, v) for v in values]))

    def index_sym(self) -> Sym:
        if self._index is None:
            self._index = self.new_sym("param", "index", "an index", unit="")
        return self._index

    def array_result(
        self, region: Region, base: ex.Node, shape, values, unit, mathcad, part: str = ""
    ) -> None:
        """A vector or matrix Mathcad shows: each element a printed value of a function of
        its index (for a matrix, of the element's number row by row from 0); ``part``: "Re"
        or "Im", the real or imaginary part of each element."""
        rows, cols = shape
        if rows * cols != len(values):
            raise Untranslatable("an array result whose size does not match its values")
        if not isinstance(base, ex.Name):
            whole = self.new_sym("helper", f"result_{region.id}_value", mathcad, region.id)
            self.out.items.append(Item("definition", region.id, sym=whole, body=base))
            base = ex.Name(whole.token())
        k = self.index_sym()
        kn = ex.Name(k.token())
        o = ex.Number(float(self.sheet_origin))
        if cols == 1:
            body = ex.Index(base, (kn,))
            at = [(self.sheet_origin + r, values[r]) for r in range(rows)]
        else:
            row = ex.Call("floor", (ex.Binary("/", kn, ex.Number(float(cols))),))
            col = ex.Binary("-", kn, ex.Binary("*", ex.Number(float(cols)), row))
            body = ex.Index(base, (ex.Binary("+", o, row), ex.Binary("+", o, col)))
            at = [
                (float(r * cols + c), values[c * rows + r])
                for r in range(rows)
                for c in range(cols)
            ]
        if part:
            body = ex.Call(part, (body,))
        name = f"result_{region.id}" + (f"_{part.lower()}" if part else "")
        sym = self.new_sym("helper", name, mathcad, region.id)
        self.out.items.append(Item("function", region.id, sym=sym, params=[k], body=body))
        self.out.results.append(Result(region.id, sym, mathcad, unit, at, k))

    def nested(self, region: Region, expr: MNode, target: Sym | None, stored: MNode, mathcad):
        """A nested array Mathcad shows (a vector of vectors...): each leaf a printed value,
        read by chained indices; the leaves at one place inside the outer elements
        (``TT[i][2][1]`` for every i) are a function of the outer index, as an array
        result's elements are."""
        try:
            leaves = list(tt.leaves(stored))
        except Untranslatable as why:
            self.out.results.append(Result(region.id, None, mathcad, "", []))
            self.skip(region.id, f"the result of {mathcad}", str(why))
            return
        try:
            if target is not None:
                if target.broken:
                    raise Untranslatable(target.broken)
                base = ex.Name(target.token())
            else:
                et = ExprTranslator(self)
                base = et.value(expr)
                if et.ranges:
                    raise Untranslatable("an evaluation of a nested array over a range variable")
            self.nested_result(region, base, leaves, mathcad)
        except Untranslatable as why:
            unit = next((u for _, u, _ in leaves if u), "")
            self.broken_result(region, mathcad, unit, [v for _, _, v in leaves], str(why))
            if target is None or not target.broken:
                self.skip(region.id, f"the result of {mathcad}", str(why))

    def nested_result(self, region: Region, base: ex.Node, leaves, mathcad: str) -> None:
        if not isinstance(base, ex.Name):
            whole = self.new_sym("helper", f"result_{region.id}_value", mathcad, region.id)
            self.out.items.append(Item("definition", region.id, sym=whole, body=base))
            base = ex.Name(whole.token())
        o = self.sheet_origin
        k = self.index_sym()
        kn = ex.Name(k.token())
        groups: dict[tuple, list] = {}
        for path, unit, value in leaves:
            row, col, _, cols = path[0]
            groups.setdefault(path[1:], []).append((float(row * cols + col), unit, value))
        _, _, _, cols = leaves[0][0][0]
        if cols == 1:  # the index of the element itself
            outer: tuple = (kn,)
        else:  # the element's number row by row from 0
            row = ex.Call("floor", (ex.Binary("/", kn, ex.Number(float(cols))),))
            col = ex.Binary("-", kn, ex.Binary("*", ex.Number(float(cols)), row))
            first = ex.Number(float(o))
            outer = (ex.Binary("+", first, row), ex.Binary("+", first, col))
        for tail, rows in groups.items():
            body: ex.Node = ex.Index(base, outer)
            text = suffix = ""
            for r, c, _, ncols in tail:
                at = [o + a for a in ((r,) if ncols == 1 else (r, c))]
                body = ex.Index(body, tuple(ex.Number(float(a)) for a in at))
                text += "[" + ", ".join(map(str, at)) + "]"
                suffix += "_" + "_".join(map(str, at))
            what = f"{mathcad}[...]{text}"
            sym = self.new_sym("helper", f"result_{region.id}{suffix}", what, region.id)
            self.out.items.append(Item("function", region.id, sym=sym, params=[k], body=body))
            at = [(a + o if cols == 1 else a, v) for a, _, v in rows]
            unit = next((u for _, u, _ in rows if u), "")
            self.out.results.append(Result(region.id, sym, what, unit, at, k))

    def standalone(self, region: Region, expr: MNode, unit: str, values, mathcad: str, shape):
        et = ExprTranslator(self)
        body = et.value(expr)
        ranges = list(dict.fromkeys(et.ranges))
        if not ranges:
            if len(values) != 1:
                self.array_result(region, body, shape, values, unit, mathcad)
                return
            sym = None
            if isinstance(body, ex.Name) and body.id.startswith("\x00"):
                sym = next(s for s in self.out.syms if s.token() == body.id)
                if sym.kind == "unit":
                    sym = None
            if sym is None:
                sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
                self.out.items.append(Item("definition", region.id, sym=sym, body=body, unit=unit))
            self.out.results.append(Result(region.id, sym, mathcad, unit, [(None, values[0])]))
            return
        if len(ranges) > 1:
            raise Untranslatable("an evaluation over two range variables (a matrix)")
        var = ranges[0]
        item = next(i for i in self.out.items if i.sym is var)
        at = item.range_values
        if len(at) != len(values):
            raise Untranslatable(
                f"Mathcad lists {len(values)} values of the range {var.mathcad}, which has "
                f"{len(at)}"
            )
        if (
            isinstance(body, ex.Call)
            and len(body.args) == 1
            and body.args[0] == ex.Name(var.token())
        ):
            fsym = next(s for s in self.out.syms if s.token() == body.func)
            fitem = next(i for i in self.out.items if i.sym is fsym)
            if fitem.params[0].unit == var.unit:
                self.out.results.append(
                    Result(region.id, fsym, mathcad, unit, list(zip(at, values)), fitem.params[0])
                )
                return
        param = self.new_sym("param", var.base, var.mathcad, unit=var.unit)
        sym = self.new_sym("helper", f"result_{region.id}", mathcad, region.id)
        body = tt.rename(body, {var.token(): param.token()})
        self.out.items.append(Item("function", region.id, sym=sym, params=[param], body=body))
        self.out.results.append(Result(region.id, sym, mathcad, unit, list(zip(at, values)), param))

    def describe_expr(self, node: MNode) -> str:
        if node.tag == "id":
            return nm.mathcad_text(*_key(node))
        if node.tag == "apply" and node.children[0].tag == "id":
            return nm.mathcad_text(*_key(node.children[0])) + "(...)"
        return "an expression"
