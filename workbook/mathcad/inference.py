"""What the translation reads from the whole worksheet once it has gone through it: the unit
of every function's argument (passed on from call to call), and the names whose values
Mathcad stored as complex numbers (their square roots are Mathcad 15's complex ones)."""

from __future__ import annotations

from ..language import expr as ex
from . import trees as tt
from .reader import MNode, Region
from .symbols import key as _key


def argument_units(tr) -> None:
    """Mathcad's functions are untyped: an argument takes the unit of the values the
    worksheet calls the function with (the first call whose unit is known). ``tr``: the
    worksheet's Translator, at the end of the translation."""
    at = tr.at_import()

    def unit_of(node: ex.Node) -> str | None:
        u = at.unit(node)
        return None if u is None else ("" if u.dimensionless else str(u))

    functions = [
        item
        for item in tr.out.items
        if item.kind == "function" and item.sym is not None and item.sym.kind != "helper"
    ]
    bound = [
        s
        for s in tr.out.syms
        if s.kind == "param" and (s.hint is not None or s.hint_sym is not None)
    ]
    # A call whose argument is a parameter of another function (``σ(z, e, k) :=
    # σ.c(ε(z, e, k))``) has that parameter's unit, known once that function's own calls
    # are: the units are passed on from call to call until none changes, and only then is
    # a parameter still open given the first call's unit as it reads (dimensionless). A
    # solve block's unknown passes no unit: the blocks whose functions it would type (of
    # integrals of piecewise functions) took the engine from 20 s to minutes of CPU
    # to solve, past the check's budget.
    open_params = {id(p) for item in functions for p in item.params if not p.unit} | {
        id(s) for s in bound if not s.unit
    }
    syms_by_token = {s.token(): s for s in tr.out.syms}
    at.settled |= {id(s) for s in tr.out.syms if s.kind == "param" and id(s) not in open_params}

    def settled(node: ex.Node) -> bool:
        return not any(
            id(syms_by_token[n]) in open_params for n in ex.names(node) if n in syms_by_token
        )

    def one_pass(strict: bool) -> bool:
        changed = False
        for item in functions:
            for k, param in enumerate(item.params):
                if id(param) not in open_params:
                    continue
                for args in tr.calls.get(item.sym, []):
                    if k < len(args) and (not strict or settled(args[k])):
                        unit = unit_of(args[k])
                        if unit is not None:
                            param.unit = unit
                            open_params.discard(id(param))
                            at.settled.add(id(param))
                            changed = True
                            break
        for sym in bound:  # variables bound by root, integral, diff
            if id(sym) not in open_params:
                continue
            if sym.hint is not None and (not strict or settled(sym.hint)):
                sym.unit = unit_of(sym.hint) or ""
            elif sym.hint_sym is not None and (not strict or id(sym.hint_sym) not in open_params):
                sym.unit = sym.hint_sym.unit
            else:
                continue
            open_params.discard(id(sym))
            at.settled.add(id(sym))
            changed = True
        return changed

    while one_pass(strict=True):
        pass
    one_pass(strict=False)


def defined_key(node: MNode) -> tuple[str, str] | None:
    """The name a definition region defines (a function's name), or None."""
    if node.tag not in ("define", "globalDefine") or not node.children:
        return None
    lhs = node.children[0]
    if lhs.tag == "function" and lhs.children:
        lhs = lhs.children[0]
    return _key(lhs) if lhs.tag == "id" else None


def shown_complex(regions: list[Region]) -> set[tuple[str, str]]:
    """The names (a variable, or the function of ``f(x) =``) of the evaluations whose stored
    result holds a complex number: Mathcad computed them in complex numbers."""
    out: set[tuple[str, str]] = set()
    for region in regions:
        node = region.math
        if node is None:
            continue
        for n in tt.walk(node):
            if n.tag != "eval" or not n.children:
                continue
            result = n.find("result")
            if result is None or not any(c.tag == "complex" for c in tt.walk(result)):
                continue
            shown = n.children[0]
            if shown.tag == "apply" and shown.children and shown.children[0].tag == "id":
                shown = shown.children[0]
            if shown.tag == "id":
                out.add(_key(shown))
            defined = defined_key(node)
            if defined is not None and node.children[-1] is n:
                out.add(defined)  # x := ... = a complex value
    return out
