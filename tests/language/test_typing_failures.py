"""A failed typing is remembered: asked again (a chain of functions over it, the load's
second pass over the functions that failed), the typer raises the same error without typing
the chain through again."""

from __future__ import annotations

import pytest

from workbook.errors import LimitError, WorkbookError
from workbook.language import typecheck

HEAD = '[inputs]\nR1 = "20 mm"\n\n[arguments]\nx = { unit = "" }\n\n[definitions]\n'


def _chain(n: int) -> str:
    """f0 -> f1 -> ... -> fn: more than MAX_CHAIN deep when n is."""
    lines = "".join(f'"f{i}(x)" = "f{i + 1}(x) + 1"\n' for i in range(n)) + f'"f{n}(x)" = "x"\n'
    return HEAD + lines + '\n[[tables]]\nname = "t"\nrange = "x := 0 .. 3"\ncolumns = { f0 = "" }\n'


def _typings(monkeypatch, sheet_from, text: str):
    """Load ``text``; (the error, how many definition bodies were typed)."""
    calls = []
    real = typecheck.Typer.typed_body

    def counted(self, d, scope):
        calls.append(d.name)
        return real(self, d, scope)

    monkeypatch.setattr(typecheck.Typer, "typed_body", counted)
    with pytest.raises(WorkbookError) as caught:
        sheet_from(text)
    return caught.value, len(calls)


def test_a_chain_over_the_limit_is_typed_through_once(monkeypatch, sheet_from):
    n = 3 * typecheck.MAX_CHAIN
    err, typed = _typings(monkeypatch, sheet_from, _chain(n))
    assert isinstance(err, LimitError)
    assert f"more than {typecheck.MAX_CHAIN} deep" in err.message
    assert err.definition == f"f{typecheck.MAX_CHAIN}"
    # each function once (and the chain's first descent): without the memory every function
    # of the first 2*MAX_CHAIN typed the next MAX_CHAIN again, about 20,000 bodies
    assert typed <= n + 2 * typecheck.MAX_CHAIN, typed


def test_a_remembered_error_is_raised_as_it_was_made(monkeypatch, sheet_from):
    """The second pass over a function typed at numbers and with arrays says what failed each
    way, as the first did (the remembered errors are copies: the message rewritten for the
    first raise is not rewritten again)."""
    text = '[inputs]\nL = "2 m"\n[arguments]\nP = { unit = "m" }\n[definitions]\n'
    err, _ = _typings(monkeypatch, sheet_from, text + '"f(P)" = "P[0]*nosuch"\n')
    assert err.message == (
        "no formula calls f() with a vector or matrix; with numbers: P is not a vector or "
        "matrix; it cannot be indexed; with arrays: unknown name 'nosuch' (did you mean sech, "
        "csch, cosh?)"
    )


def test_an_error_caught_to_add_context_is_raised_as_a_new_value():
    from workbook.errors import UnitError

    err = UnitError("cannot add", file="a.toml", line=3, definition="y")
    new = err.reworded("f(x): cannot add")
    assert type(new) is UnitError
    assert (new.file, new.line, new.definition) == ("a.toml", 3, "y")
    assert str(new) == "a.toml:3, in 'y': unit error: f(x): cannot add"
    assert (err.message, err.args) == ("cannot add", ("cannot add",))
