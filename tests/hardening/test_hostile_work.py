"""Hostile amounts of work inside the documented limits: matrix products, long chains of
definitions, many names, many redefinitions. Each finishes or is refused with a message naming
the definition; none is quadratic.

The heavy cases run the real command line in a fresh interpreter (tests/hardening/test_hostile.py's
guard: an address-space limit, a CPU-time limit and a wall-clock timeout as a hang guard, never
a timing assertion); the fast ones check the linear algorithms against the scans they replace.
"""

from __future__ import annotations

import copy
import itertools
import random
import types

import mpmath
import numpy as np
import openpyxl
import pytest
from helpers.hostile import guarded

import workbook
from workbook import limits
from workbook.cli import main
from workbook.compute import excelform
from workbook.errors import LimitError
from workbook.functions.excel_names import ExcelNames, needs_change
from workbook.language.fields import find_line, scan_for_line
from workbook.mathcad import writer

# -- matrix work ------------------------------------------------------------------------------


def products(n_products: int, size: int) -> str:
    """A program multiplying identity(size) into a matrix ``n_products`` times."""
    return (
        '[arguments]\nn = { unit = "" }\n\n[definitions]\n"p(n)" = { program = """\n'
        f"M := identity({size}) + 1\nP := M\nfor k in 1 .. n\n    P := P*M\nP[0, 1]\n"
        '""" }\n'
        f's = "p({n_products})"\n'
    )


def test_matrix_work_is_refused_before_it_is_done(tmp_path, monkeypatch):
    # 1,000 products of 2000 x 2000 matrices ran for minutes: only their sizes were bounded
    monkeypatch.setattr(limits, "MAX_MATRIX_WORK", 10 * 40**3)
    done = []
    real = np.matmul
    monkeypatch.setattr(np, "matmul", lambda a, b: done.append(1) or real(a, b))
    path = tmp_path / "m.toml"
    path.write_text(products(1000, 40), encoding="utf-8")
    with pytest.raises(LimitError) as err:
        workbook.load(path).evaluate("s")
    assert (err.value.definition, err.value.line) == ("s", 12)
    assert f"limit {10 * 40**3:,}" in str(err.value)
    assert "a product of 40 x 40 by 40 x 40 matrices" in str(err.value)
    # the budget holds: the work done stayed within it (each product is 40^3)
    assert len(done) * 40**3 <= 10 * 40**3

    path.write_text(products(3, 40), encoding="utf-8")  # within the budget: computed
    m = np.identity(40) + 1
    expected = np.linalg.matrix_power(m, 4)[0, 1]
    assert float(workbook.load(path).evaluate("s")) == pytest.approx(expected, rel=1e-14)


def test_matrix_work_of_formulas_and_decompositions_is_counted(sheet_from, monkeypatch):
    monkeypatch.setattr(limits, "MAX_MATRIX_WORK", 4 * 30**3)
    text = (
        '[definitions]\nA = "identity(30) + 1"\nB = "A*A*A*A*A*A*A"\nb = "B[0, 0]"\n'
        'e = "eigenvals(A)[0]"\nd = "det(A)"\n'
    )
    sheet = sheet_from(text, name="f")
    with pytest.raises(LimitError, match="product of 30 x 30 by 30 x 30") as err:
        sheet.evaluate("b")
    assert (err.value.definition, err.value.line) == ("B", 3)
    with pytest.raises(LimitError, match=r"eigenvals\(\)") as err:
        sheet.evaluate("e")
    assert err.value.definition == "e"
    # a determinant (one LU) is within the budget; each evaluation has a budget of its own
    assert float(sheet.evaluate("d")) == pytest.approx(31.0, rel=1e-12)


def test_a_matrix_product_agrees_with_mpmath():
    # the product is numpy's BLAS matmul over the table's range axes (it was an einsum loop)
    from workbook.functions import matrix as mx

    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(4, 3, 6)), rng.normal(size=(3, 5, 6))  # 6 range points
    got = mx.matmul(a, b)
    assert got.shape == (4, 5, 6)
    mpmath.mp.dps = 50
    for p in range(6):
        exact = mpmath.matrix(a[:, :, p].tolist()) * mpmath.matrix(b[:, :, p].tolist())
        for i, j in itertools.product(range(4), range(5)):
            assert abs(got[i, j, p] - float(exact[i, j])) <= 1e-14 * (1 + abs(exact[i, j]))


@pytest.mark.slow  # five products of 2000 x 2000 matrices before the refusal
def test_a_thousand_products_of_large_matrices_are_refused(tmp_path):
    out = guarded(tmp_path, products(1000, 2000))
    assert out.returncode == 1, out.stderr[-2000:]
    shown = out.stdout + out.stderr
    assert f"limit {limits.MAX_MATRIX_WORK:,}" in shown and "in 's'" in shown, shown[-2000:]
    assert "Traceback" not in out.stderr


# -- linear where it was quadratic ------------------------------------------------------------


def test_the_line_index_finds_what_the_scan_finds():
    # one pass over the template instead of a scan per key (30,000 definitions took minutes)
    random.seed(1)
    alphabet = ["a", "b", " ", '"', "'", "=", "[", "]", ".", "\t", "x", "\n", "\u00a0"]
    keys = ["a", "b", "ab", "a b", "x", "a.b", "[a]", 'a"b', "ba", '"a"', " a", "a=b"]
    sections = [None, "a", "b", "a.b", "x"]
    for _ in range(1000):
        text = "".join(random.choice(alphabet) for _ in range(random.randint(0, 60)))
        for key, section in itertools.product(keys, sections):
            assert find_line(text, key, section) == scan_for_line(text, key, section)


def _names_by_scan(names: list[str]) -> dict[str, str]:
    """Defined names as ExcelNames chose them before it remembered its suffixes."""
    mapping, taken = {}, set()
    names = list(dict.fromkeys(names))
    for name in names:
        if not needs_change(name) and name.lower() not in taken:
            mapping[name] = name
            taken.add(name.lower())
    for name in names:
        if name in mapping:
            continue
        base = name[:247]
        for n in itertools.count(1):
            candidate = f"{base}_" if n == 1 else f"{base}_{n}"
            if candidate.lower() not in taken and not needs_change(candidate):
                break
        mapping[name] = candidate
        taken.add(candidate.lower())
    return mapping


def test_names_alike_but_for_case_are_renamed_as_by_the_scan():
    random.seed(3)
    for _ in range(300):
        names = [
            "".join(random.choice("aAbB_") for _ in range(random.randint(1, 4)))
            for _ in range(random.randint(1, 30))
        ]
        names = [n for n in names if n[0] != "_"] or ["a"]
        assert ExcelNames(names).mapping == _names_by_scan(names)
    alike = ["".join(c.upper() if b else c for c, b in zip("abcdefghijklm", bits)) for bits in
             itertools.islice(itertools.product([0, 1], repeat=13), 5000)]  # fmt: skip
    names = ExcelNames(alike)
    assert len({v.lower() for v in names.mapping.values()}) == 5000
    assert names.why(alike[1]).endswith(f"'{alike[1]}' and '{alike[0]}' would be one name)")


def _assign_by_scan(syms) -> None:
    """writer.assign_identifiers's choice of identifiers, each number tried from the first."""
    reserved = set(writer.language_functions()) | {"pi"}
    taken, lower = {}, set()

    def claim(sym, share=None, alt=True):
        base = sym.base if sym.base not in reserved else sym.base + "_"
        candidates = [base] + ([base + "_"] if share is not None and alt else [])
        if sym.kind == "unit":
            candidates.append(base + "_unit")
        n = 1
        while True:
            name = candidates.pop(0) if candidates else f"{base}_{n}"
            other = taken.get(name)
            if other is None and name.lower() not in lower:
                break
            if other is not None and share is not None and share(other):
                break
            n += 1
        sym.final = name
        taken[name] = sym
        lower.add(name.lower())

    arguments = [s for s in syms if s.kind == "param" or s.is_range]
    for sym in syms:
        if sym.kind in ("var", "func", "helper") and not sym.is_range:
            claim(sym)
    for sym in syms:
        if sym.kind == "local":
            claim(
                sym, share=lambda o, s=sym: o.kind == "local" and o.mathcad == s.mathcad, alt=False
            )
    for sym in arguments:
        claim(sym, share=lambda o, s=sym: (o.kind == "param" or o.is_range) and o.unit == s.unit)
    for sym in syms:
        if sym.kind == "unit":
            claim(sym)


def test_imported_names_are_chosen_as_by_the_scan():
    # 20,000 redefinitions of one Mathcad name tried 2e8 identifiers
    random.seed(2)
    bases = ["x", "X", "x_2", "kN", "kN_unit", "x_", "sin", "y", "x_3"]
    kinds = ["var", "func", "helper", "local", "param", "unit"]
    for _ in range(400):
        syms = [
            types.SimpleNamespace(
                base=random.choice(bases),
                kind=random.choice(kinds),
                unit=random.choice(["m", "s"]),
                mathcad=random.choice(["a", "b"]),
                is_range=random.random() < 0.1,
                final=None,
                broken=False,
            )
            for _ in range(random.randint(1, 40))
        ]
        mine, theirs = copy.deepcopy(syms), copy.deepcopy(syms)
        writer.assign_identifiers(types.SimpleNamespace(syms=mine))
        _assign_by_scan(theirs)
        assert [s.final for s in mine] == [s.final for s in theirs]


ML = "http://schemas.mathsoft.com/math30"


def _mathcad(definitions: list[tuple[str, str]]) -> str:
    """An .xmcd worksheet of ``name := body`` regions (body in Mathcad's XML)."""
    regions = "".join(
        f'<region region-id="{i}" left="0" top="{i * 20}" align-y="{i * 20}"><math>'
        f'<ml:define xmlns:ml="{ML}"><ml:id>{name}</ml:id>{body}</ml:define></math></region>'
        for i, (name, body) in enumerate(definitions, start=1)
    )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<worksheet xmlns="http://schemas.mathsoft.com/'
        f'worksheet30" xmlns:ml="{ML}"><regions>{regions}</regions></worksheet>'
    )


def _plus_one(name: str) -> str:
    return f"<ml:apply><ml:plus/><ml:id>{name}</ml:id><ml:real>1</ml:real></ml:apply>"


# -- tables written to a workbook, engine refusals of an import -------------------------------


def table(rows: int, columns: int = 1) -> str:
    cols = ", ".join(f'"{k + 1}*f(x)" = "mm"' for k in range(columns))
    return (
        '[inputs]\na = "2 mm"\n[arguments]\nx = { unit = "" }\n'
        '[definitions]\n"f(x)" = { expr = "a*x", unit = "mm" }\n'
        f'[[tables]]\nname = "t"\nrange = "x := 1 .. {rows}"\ncolumns = {{ {cols} }}\n'
    )


def test_tables_past_the_cells_of_a_workbook_are_refused_before_they_are_written(
    tmp_path, monkeypatch
):
    # a table of 1,000,001 rows took 75 s to write; the cells of a workbook's tables are bounded
    monkeypatch.setattr(excelform, "MAX_TABLE_CELLS", 300)
    path = tmp_path / "t.toml"
    path.write_text(table(100, 2), encoding="utf-8")  # 100 rows x 3 columns: 300 cells
    workbook.load(path).write_xlsx(tmp_path / "t.xlsx")
    book = openpyxl.load_workbook(tmp_path / "t.xlsx", data_only=True)
    assert [tuple(r)[:3] for r in book["Listing"].iter_rows(values_only=True)][-1] == (
        100,
        200,
        400,
    )
    path.write_text(table(100, 3), encoding="utf-8")  # 400 cells
    with pytest.raises(LimitError) as err:
        workbook.load(path).write_xlsx(tmp_path / "u.xlsx")
    assert (err.value.definition, err.value.line) == ("table t", 8)
    assert "100 rows x 4 columns" in str(err.value) and "limit 300" in str(err.value)
    assert "--csv" in str(err.value)
    assert not (tmp_path / "u.xlsx").exists() and not list(tmp_path.glob(".*partial*"))


@pytest.mark.slow
def test_an_import_of_two_thousand_refused_definitions_is_one_pass(tmp_path, capsys):
    # 125/250/500/2,000 refused definitions took 2.8/9.3/37/>60 s: the import was retried once
    # for each refusal, and each retry loaded the whole worksheet
    plus = "<ml:apply><ml:plus/><ml:id>m</ml:id><ml:id>s</ml:id></ml:apply>"
    src = tmp_path / "refused.xmcd"
    src.write_text(_mathcad([(f"a{i}", plus) for i in range(2000)]), encoding="utf-8")
    assert main(["import", str(src), "--out", str(tmp_path / "out")]) == 0
    assert "2000 regions not translated" in capsys.readouterr().out
    text = (tmp_path / "out" / "refused.toml").read_text(encoding="utf-8")
    assert text.count("the engine refuses it: cannot add [time] (s) to [length] (m)") == 2000


# -- the heavy cases, each in a fresh guarded interpreter --------------------------------------

ALIKE = [
    "".join(c.upper() if b else c for c, b in zip("abcdefghijklm", bits))
    for bits in itertools.islice(itertools.product([0, 1], repeat=13), 5000)
]
VARY = ", ".join(f'"{1000 + 10 * i} N/m"' for i in range(50))
HEAVY = {
    # (worksheet text or {file: text}, command line, exit status, text of the output)
    "chain_of_30000": (
        '[definitions]\nd0 = "1"\n' + "".join(f'd{i} = "d{i - 1} + 1"\n' for i in range(1, 30_000)),
        ("run", "hostile.toml"),
        0,
        "d29999 = 30000",  # every result is printed (--first N cuts the list)
    ),
    "names_alike_but_for_case": (
        "[definitions]\n" + "".join(f'{n} = "{i}"\n' for i, n in enumerate(ALIKE)),
        ("run", "hostile.toml"),
        0,
        "wrote",
    ),
    "appends_100000": (
        '[arguments]\nn = { unit = "" }\n\n[definitions]\n"p(n)" = { program = """\nw := 0\n'
        'for k in 1 .. n\n    w[rows(w)] := k\nrows(w)\n""" }\ns = "p(100000)"\n',
        ("run", "hostile.toml"),
        0,
        "s = 100000",
    ),
    "family_of_50_curves_of_2e6_points": (
        '[inputs]\nk = "2000 N/m"\nm = "0.5 kg"\n[arguments]\nt = { unit = "s" }\n'
        '[definitions]\n"x(t)" = { expr = "cos(sqrt(k/m)*t)", unit = "" }\n'
        '[[tables]]\nname = "stiffness"\nrange = "t := 0, 1e-6 .. 1.999999"\n'
        f'vary = {{ k = [{VARY}] }}\ncolumns = {{ x = "" }}\n',
        ("run", "hostile.toml"),
        2,
        "2,000,000 rows",
    ),
    "sweep_maximum_over_1.9e6_points_x_1e4_cases": (
        '[inputs]\nR = "10 mm"\nomega = "100 1/s"\n[arguments]\nt = { unit = "s" }\n'
        '[definitions]\n"x(t)" = { expr = "R*cos(omega*t)", unit = "mm" }\n'
        '[sweep]\noutputs = { x_max = "max of x(t) over t := 0, 1e-6 .. 1.899999" }\n',
        ("sweep", "hostile.toml", "--vary", "R=1mm..100mm:10000", "--out", "s.csv"),
        2,
        "(limit 50,000,000)",
    ),
    "table_of_1000001_rows": (
        table(1_000_001),
        ("run", "hostile.toml"),
        2,
        f"(limit {limits.MAX_TABLE_CELLS:,}). Write it as CSV instead",
    ),
    "import_20000_redefinitions": (
        {"r.xmcd": _mathcad([("x", "<ml:real>1</ml:real>")] + [("x", _plus_one("x"))] * 20_000)},
        ("import", "r.xmcd", "--out", "out"),
        0,
        "20001 definitions",
    ),
    "import_chain_of_30000": (
        {
            "c.xmcd": _mathcad(
                [("y0", "<ml:real>1</ml:real>")]
                + [(f"y{i + 1}", _plus_one(f"y{i}")) for i in range(30_000)]
            )
        },
        ("import", "c.xmcd", "--out", "out"),
        0,
        "30001 definitions",
    ),
}


@pytest.mark.slow  # 5 to 20 s each on a loaded machine
@pytest.mark.parametrize("name", sorted(HEAVY))
def test_a_heavy_worksheet_finishes_or_is_refused(tmp_path, name):
    text, args, status, expected = HEAVY[name]
    if isinstance(text, dict):
        for file, content in text.items():
            (tmp_path / file).write_text(content, encoding="utf-8")
        text = ""
    out = guarded(tmp_path, text, *args)  # a hang guard: the subprocess's timeout
    assert out.returncode == status, (out.returncode, out.stderr[-2000:])
    assert expected in out.stdout + out.stderr, (out.stdout[-2000:], out.stderr[-2000:])
    assert "Traceback" not in out.stderr
    if name == "names_alike_but_for_case":
        book = openpyxl.load_workbook(tmp_path / "reports" / "hostile.xlsx")
        names = [n.lower() for n in book.defined_names]
        assert len(names) == len(set(names)) >= 5000
