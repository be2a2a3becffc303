"""Property-based test: generated expressions never let anything but the engine's errors escape.

Each generated expression is parsed, typed (units) and, if it is accepted, evaluated on an
array of arguments, exactly as a worksheet definition would be. Any outcome is allowed except
an exception that is not a :class:`workbook.WorkbookError` (a crash, a traceback for a user).

The budget is fixed (``FUZZ_EXAMPLES``, 12,000 by default, >= 10^4 as the issue asks) and the
run is deterministic (``derandomize``), so CI sees the same expressions every time.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbook import WorkbookError
from workbook import expr as ex
from workbook.builtins import REGISTRY
from workbook.sheet import Sheet
from workbook.template import load_spec

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "12000"))
PER_TEST = EXAMPLES // 2

TEMPLATE = """
[inputs]
R1 = "20 mm"
omega = "104.6 1/s"
law = { value = "stepped", options = ["stepped", "harmonic"] }
n = "3"

[arguments]
phi = { unit = "deg" }
t = { unit = "s" }
x = { unit = "" }

[definitions]
"h(phi)" = "R1*sin(phi)"
"g(x)" = ["x if x < 1", "2 - x otherwise"]
k = "omega*R1"
"""

NAMES = ["R1", "omega", "law", "n", "phi", "t", "x", "k", "pi", "h", "g", "sin", "nope", "__x"]
FUNCS = sorted(REGISTRY) + ["h", "g", "k", "R1", "log", "nope", "eval", "open"]
ATOMS = ["0", "1", "2.5", "1e308", "1e-320", "-3", "0.0", "1e999", "10", '"stepped"', '"x"']
OPS = ["+", "-", "*", "/", "^", "**", "<", "<=", ">", ">=", "==", "!=", " and ", " or ", "%", "//"]
JUNK = ["(", ")", ",", ".", "[", "]", ":", "lambda", " if ", " else ", "'", "__", "@", "\\", "\n"]


@pytest.fixture(scope="module")
def sheet(tmp_path_factory):
    path = tmp_path_factory.mktemp("fuzz") / "fuzz.toml"
    path.write_text(TEMPLATE, encoding="utf-8")
    return Sheet(load_spec(path))


def expressions():
    """Well-formed trees of the language, with wrong units, arities and names mixed in."""
    leaf = st.sampled_from(NAMES + ATOMS)

    def extend(inner):
        return st.one_of(
            st.tuples(inner, st.sampled_from(OPS), inner).map(lambda t: f"({t[0]}{t[1]}{t[2]})"),
            st.tuples(st.sampled_from(["-", "+", "not "]), inner).map(lambda t: t[0] + t[1]),
            st.tuples(st.sampled_from(FUNCS), st.lists(inner, max_size=3)).map(
                lambda t: f"{t[0]}({', '.join(t[1])})"
            ),
            st.tuples(
                inner, st.sampled_from(["<", "<="]), inner, st.sampled_from(["<", "<="]), inner
            ).map(lambda t: f"{t[0]} {t[1]} {t[2]} {t[3]} {t[4]}"),
        )

    return st.recursive(leaf, extend, max_leaves=12)


def garbage():
    """Token soup: broken syntax, Python constructs the language refuses, odd characters."""
    token = st.sampled_from(NAMES + ATOMS + OPS + JUNK + FUNCS)
    return st.one_of(
        st.lists(token, max_size=12).map("".join),
        st.text(max_size=30),
    )


def check(sheet: Sheet, text: str) -> None:
    scope = {"phi": sheet.spec.arguments["phi"].binding_unit, "x": sheet.typer.dimensionless}
    values = {"phi": np.array([0.0, 30.0, 90.0, 180.0]), "x": np.array([-1.0, 0.0, 0.5, 2.0])}
    try:
        node = ex.parse(text, what="fuzz")
        typed = sheet.typer.expression(node, scope, "fuzz")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            sheet.evaluator.compile(typed)(values)
        ex.to_text(node)
    except WorkbookError as err:
        assert str(err)  # a message exists
    except Exception as exc:  # pragma: no cover - the property
        pytest.fail(f"{type(exc).__name__} escaped for {text!r}: {exc}")


FUZZ = settings(
    max_examples=PER_TEST,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
)


@pytest.mark.slow
@FUZZ
@given(text=expressions())
def test_generated_expressions(sheet, text):
    check(sheet, text)


@pytest.mark.slow
@FUZZ
@given(text=garbage())
def test_generated_garbage(sheet, text):
    check(sheet, text)


def test_budget_is_at_least_ten_thousand():
    assert PER_TEST * 2 >= 10_000
