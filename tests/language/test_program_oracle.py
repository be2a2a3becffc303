"""Random programs against a plain Python run of the same program.

Without loops (locals, if / else if / otherwise blocks, returns, one-line ``return X if C``):
the engine's value, and the live nested IF the workbook writes, recalculated by an independent
Excel evaluator (the `formulas` package). With ``for`` loops (nested, stepped up and down,
``break`` and ``continue``): the engine's value, the loops run as Mathcad's (never beyond the
last value). Slow: the first writes and reads a workbook an example."""

from __future__ import annotations

import random
from collections.abc import Callable
from pathlib import Path

import numpy as np
import openpyxl
import pytest
from helpers.sheets import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

import workbook

pytestmark = pytest.mark.slow

LOCALS = ("a", "b", "c")
XS = np.arange(-3, 3.0001, 0.5)  # the table's range s := -3, -2.5 .. 3
Term = tuple[str, Callable[[dict], float]]


class _Return(Exception):
    def __init__(self, value: float):
        self.value = value


class _Break(Exception):
    pass


class _Continue(Exception):
    pass


def _expr(rng: random.Random, names: list[str], depth: int = 0) -> Term:
    """(text, Python function of the locals) of a random expression."""
    if depth > 2 or rng.random() < 0.3:
        k = rng.random()
        if k < 0.4:
            return "s", lambda e: e["s"]
        if k < 0.75 and names:
            n = rng.choice(names)
            return n, lambda e: e[n]
        c = rng.choice([0.5, 1, 2, 3, 1.25, 10])
        return repr(c), lambda e: c
    kind = rng.choice(["+", "-", "*", "/", "abs", "neg", "max", "min"])
    a, fa = _expr(rng, names, depth + 1)
    if kind == "abs":
        return f"abs({a})", lambda e: abs(fa(e))
    if kind == "neg":
        return f"-({a})", lambda e: -fa(e)
    b, fb = _expr(rng, names, depth + 1)
    if kind in ("max", "min"):
        pick = max if kind == "max" else min
        return f"{kind}({a}, {b})", lambda e: pick(fa(e), fb(e))
    if kind == "/":
        return f"({a})/(1 + abs({b}))", lambda e: fa(e) / (1 + abs(fb(e)))
    ops = {"+": lambda x, y: x + y, "-": lambda x, y: x - y, "*": lambda x, y: x * y}
    return f"({a}) {kind} ({b})", lambda e: ops[kind](fa(e), fb(e))


def _condition(rng: random.Random, names: list[str]) -> Term:
    a, fa = _expr(rng, names, 1)
    b, fb = _expr(rng, names, 1)
    op = rng.choice(["<", ">", "<=", ">="])
    tests = {
        "<": lambda x, y: x < y,
        ">": lambda x, y: x > y,
        "<=": lambda x, y: x <= y,
        ">=": lambda x, y: x >= y,
    }
    text, f = f"{a} {op} {b}", lambda e: tests[op](fa(e), fb(e))
    if rng.random() < 0.2:
        other, g = _condition(rng, names)
        if rng.random() < 0.5:
            return f"({text}) and ({other})", lambda e: f(e) and g(e)
        return f"({text}) or ({other})", lambda e: f(e) or g(e)
    return text, f


def _program(rng: random.Random) -> tuple[str, Callable[[float], float]]:
    """The text of a random program of ``s`` and a Python run of it."""
    lines: list[str] = []
    steps: list = []
    names: list[str] = []
    for n in LOCALS[: rng.randint(1, 3)]:  # every local is given a value first
        text, f = _expr(rng, names)
        lines.append(f"{n} := {text}")
        steps.append(("assign", n, f))
        names.append(n)
    for _ in range(rng.randint(0, 3)):
        if rng.random() < 0.4:
            n = rng.choice(names)
            text, f = _expr(rng, names)
            lines.append(f"{n} := {text}")
            steps.append(("assign", n, f))
            continue
        cond, fc = _condition(rng, names)
        lines.append(f"if {cond}")
        body = []
        for _ in range(rng.randint(1, 2)):
            text, f = _expr(rng, names)
            if rng.random() < 0.6:
                n = rng.choice(names)
                lines.append(f"    {n} := {text}")
                body.append(("assign", n, f))
            else:
                lines.append(f"    return {text}")
                body.append(("return", None, f))
                break
        branches = []
        while rng.random() < 0.3:
            c2, f2 = _condition(rng, names)
            text, f = _expr(rng, names)
            lines.append(f"else if {c2}")
            if rng.random() < 0.5:
                n = rng.choice(names)
                lines.append(f"    {n} := {text}")
                branches.append((f2, [("assign", n, f)]))
            else:
                lines.append(f"    return {text}")
                branches.append((f2, [("return", None, f)]))
        otherwise: list = []
        if rng.random() < 0.4:
            n = rng.choice(names)
            text, f = _expr(rng, names)
            lines += ["otherwise", f"    {n} := {text}"]
            otherwise = [("assign", n, f)]
        for f2, block in reversed(branches):
            otherwise = [("if", f2, block, otherwise)]
        steps.append(("if", fc, body, otherwise))
        if rng.random() < 0.25:
            c3, f3 = _condition(rng, names)
            text, f = _expr(rng, names)
            lines.append(f"return {text} if {c3}")
            steps.append(("if", f3, [("return", None, f)], []))
    text, f = _expr(rng, names)
    lines.append(text)
    steps.append(("value", None, f))

    def run(s: float) -> float:
        env: dict = {"s": s}

        def block(todo):
            for step in todo:
                if step[0] == "assign":
                    env[step[1]] = step[2](env)
                elif step[0] == "return":
                    raise _Return(step[2](env))
                elif step[0] == "value":
                    env["value"] = step[2](env)
                else:
                    block(step[2] if step[1](env) else step[3])

        try:
            block(steps)
        except _Return as done:
            return done.value
        return env["value"]

    return "\n".join(lines), run


def _checked(text: str, run: Callable[[float], float]):
    """The sheet of the program ``p(s)`` tabulated over XS, its values checked against a
    Python run; (the sheet, the values of the run)."""
    sheet = workbook.loads(
        '[arguments]\ns = { unit = "" }\n[definitions]\n'
        f'"p(s)" = {{ program = """\n{text}\n""" }}\n\n'
        '[[tables]]\nname = "t"\nrange = "s := -3, -2.5 .. 3"\ncolumns = { p = "" }\n'
    )
    expected = np.array([run(float(x)) for x in XS])
    engine = np.asarray(sheet.table("t").iloc[:, 1], dtype=float)
    np.testing.assert_allclose(engine, expected, rtol=1e-12, atol=1e-12, err_msg=text)
    return sheet, expected


def _recalculated(path: Path) -> dict[str, object]:
    """Cell -> value of the Listing sheet, recalculated by the formulas package."""
    import formulas

    solution = formulas.ExcelModel().loads(str(path)).finish().calculate()
    out = {}
    for key, value in solution.items():
        if "]LISTING'!" in key.upper() and ":" not in key.split("!")[1]:
            out[key.split("!")[1].upper()] = value.value[0, 0]
    return out


@fuzz_settings(40)
@given(st.randoms(use_true_random=False))
def test_a_program_the_engine_python_and_its_live_formula_agree(tmp_path_factory, rng):
    text, run = _program(rng)
    sheet, expected = _checked(text, run)
    path = sheet.write_xlsx(tmp_path_factory.mktemp("program") / "p.xlsx")
    listing = openpyxl.load_workbook(path)["Listing"]
    cells = [f"B{3 + k}" for k in range(len(XS))]
    assert all(str(listing[c].value).startswith("=") for c in cells), text  # live, not values
    got = _recalculated(path)
    recalculated = np.array([float(got[c]) for c in cells])
    np.testing.assert_allclose(recalculated, expected, rtol=1e-9, atol=1e-12, err_msg=text)


def _mathcad_loop(first: int, second: int | None, last: int) -> list[int]:
    """Mathcad's values of ``for k in first, second .. last``: never beyond ``last``."""
    step = (second - first) if second is not None else (1 if last >= first else -1)
    return list(range(first, last + (1 if step > 0 else -1), step))


def _loops(rng: random.Random, names: list[str], depth: int, lines: list[str]) -> list:
    """The steps of a block at ``depth`` (0: the program's top level), its lines appended."""
    steps: list = []
    pad = "    " * depth
    for _ in range(rng.randint(1, 3)):
        k = rng.random()
        if k < 0.45 or depth >= 2:
            n = rng.choice([m for m in names if m not in ("k", "m")])
            text, f = _expr(rng, names)
            lines.append(f"{pad}{n} := {text}")
            steps.append(("assign", n, f))
        elif k < 0.6 and depth > 0:
            cond, fc = _condition(rng, names)
            word = rng.choice(["break", "continue"])
            lines.append(f"{pad}{word} if {cond}")
            steps.append((word, fc))
        elif k < 0.7:
            cond, fc = _condition(rng, names)
            text, f = _expr(rng, names)
            lines.append(f"{pad}return {text} if {cond}")
            steps.append(("return if", fc, f))
        else:
            var = ("k", "m")[depth]
            first, last = rng.randint(-3, 3), rng.randint(-3, 6)
            second = None
            if rng.random() < 0.4:
                second = first + rng.choice([1, 2, 3]) * (1 if last >= first else -1)
            bounds = f"{first} .. {last}" if second is None else f"{first}, {second} .. {last}"
            lines.append(f"{pad}for {var} in {bounds}")
            body = _loops(rng, [*names, var], depth + 1, lines)
            steps.append(("for", var, _mathcad_loop(first, second, last), body))
    return steps


def _loop_program(rng: random.Random) -> tuple[str, Callable[[float], float]]:
    lines: list[str] = []
    names: list[str] = []
    steps: list = []
    for n in LOCALS[: rng.randint(1, 2)]:
        text, f = _expr(rng, names)
        lines.append(f"{n} := {text}")
        steps.append(("assign", n, f))
        names.append(n)
    steps += _loops(rng, names, 0, lines)
    text, f = _expr(rng, names)
    lines.append(text)
    steps.append(("value", f))

    def run(s: float) -> float:
        env: dict = {"s": s}

        def block(todo):
            for step in todo:
                kind = step[0]
                if kind == "assign":
                    env[step[1]] = step[2](env)
                elif kind == "value":
                    env["value"] = step[1](env)
                elif kind in ("break", "continue") and step[1](env):
                    raise _Break() if kind == "break" else _Continue()
                elif kind == "return if" and step[1](env):
                    raise _Return(step[2](env))
                elif kind == "for":
                    for v in step[2]:
                        env[step[1]] = float(v)
                        try:
                            block(step[3])
                        except _Continue:
                            continue
                        except _Break:
                            break

        try:
            block(steps)
        except _Return as done:
            return done.value
        return env["value"]

    return "\n".join(lines), run


@fuzz_settings(200)
@given(st.randoms(use_true_random=False))
def test_a_program_with_loops_the_engine_and_python_agree(rng):
    _checked(*_loop_program(rng))
