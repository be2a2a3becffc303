"""A built-in of numbers called with one vector applies to each element: for every entry of
the registry that is ``of_numbers``, the vector's result is the element-by-element results
(a function of several numbers called with a vector is refused with its reason, never
computed). The Mathcad importer's vectorize reads the same field."""

from __future__ import annotations

import numpy as np
import pytest

from workbook.errors import TemplateError
from workbook.numerics.registry import REGISTRY

OF_NUMBERS = sorted(name for name, entry in REGISTRY.items() if entry.of_numbers)
#: Arguments in every domain: whole numbers for the counting functions and Bessel orders.
WHOLE = {"combin", "permut", "factorial"}
#: functions of arguments of at least 1
FROM_ONE = {"acosh", "asec", "acsc", "acoth"}


def _arity(name: str) -> int:
    arity = REGISTRY[name].arity
    return arity if isinstance(arity, int) else arity[0]


def _text(name: str, xs: tuple[float, ...]) -> str:
    rest = ["1"] * (_arity(name) - 1)
    defs = {"v": "[" + ", ".join(map(repr, xs)) + "]"}
    defs["y"] = f"{name}(" + ", ".join(["v", *rest]) + ")"
    for i, x in enumerate(xs):
        defs[f"y{i}"] = f"{name}(" + ", ".join([repr(x), *rest]) + ")"
    lines = "".join(f'{k} = "{v}"\n' for k, v in defs.items())
    return f'[sheet]\nname = "ew"\n\n[definitions]\n{lines}'


def _magnitude(q) -> np.ndarray:
    return np.asarray(getattr(q, "magnitude", q))


def test_the_functions_of_numbers_are_the_elementary_and_special_ones():
    assert {"sin", "sqrt", "erf", "gamma", "atan2", "pnorm"} <= set(OF_NUMBERS)
    assert not {"max", "sum", "eigenvals", "integral", "concat", "rows"} & set(OF_NUMBERS)


@pytest.mark.parametrize("name", OF_NUMBERS)
def test_a_vector_argument_gives_each_elements_value(name, sheet_from):
    xs = (1.0, 2.0, 3.0) if name in WHOLE | FROM_ONE else (0.1, 0.3, 0.6)
    if name == "acoth":
        xs = (1.5, 2.0, 3.0)
    if _arity(name) > 1:
        with pytest.raises(TemplateError, match="takes numbers, not a vector"):
            sheet_from(_text(name, xs)).evaluate("y")
        return
    sheet = sheet_from(_text(name, xs))
    got = _magnitude(sheet.evaluate("y")).ravel()
    each = np.array([_magnitude(sheet.evaluate(f"y{i}")).item() for i in range(len(xs))])
    assert got.shape == each.shape and np.allclose(got, each, rtol=1e-13, atol=0), (got, each)
