"""Mathcad Prime's matrix(m, n, f), a function redefined from its previous definition and a
sum of matrices, imported from small packages this test writes, checked against the results
stored in them."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest
from helpers.mathcad import check_json as _check
from helpers.mathcad import prime_ident as _id
from helpers.mathcad_xml import PRIME_RESULTS as RESULTS
from helpers.mathcad_xml import PRIME_WS as WS
from helpers.mathcad_xml import prime_region as _region
from helpers.mathcad_xml import prime_result as _result

from workbook.cli import main


def _package(path: Path, regions: str, results: str, origin: int = 0) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("mathcad/worksheet.xml", WS.format(regions))
        z.writestr("mathcad/result.xml", RESULTS.format(results))
        z.writestr(
            "mathcad/settings/calculation.xml",
            '<calculation xmlns="http://schemas.ptc.com/mathcad/settings/calculation10">'
            f'<builtInVariables array-origin="{origin}" convergence-tolerance="0.001"/>'
            "</calculation>",
        )
    return path


def _real(v: float) -> str:
    if v < 0:
        return f"<ml:apply><ml:neg/><ml:real>{-v!r}</ml:real></ml:apply>"
    return f"<ml:real>{v!r}</ml:real>"


def _stored_matrix(rows: list[list[float]]) -> str:
    """A result matrix as Prime stores it: column by column."""
    cells = "".join(
        f"<ml:real>{rows[i][j]!r}</ml:real>" for j in range(len(rows[0])) for i in range(len(rows))
    )
    return f'<ml:matrix rows="{len(rows)}" cols="{len(rows[0])}">{cells}</ml:matrix>'


def _call(name: str, *args: str) -> str:
    return f"<ml:apply>{_id(name, 'FUNCTION')}<ml:sequence>{''.join(args)}</ml:sequence></ml:apply>"


def _function(rid: int, name: str, params: list[str], body: str) -> str:
    bound = "".join(_id(p) for p in params)
    return _region(
        rid,
        rid,
        f"<ml:define><ml:function>{_id(name)}<ml:boundVars>{bound}</ml:boundVars>"
        f"</ml:function>{body}</ml:define>",
    )


def _eval(rid: int, body: str) -> str:
    return _region(rid, rid, f"<ml:eval>{body}</ml:eval>")


def _f_of_indices() -> str:
    """f(x, y) := x^2 - y"""
    square = f"<ml:apply><ml:pow/>{_id('x')}<ml:real>2</ml:real></ml:apply>"
    body = f"<ml:apply><ml:minus/>{square}{_id('y')}</ml:apply>"
    return _function(1, "f", ["x", "y"], body)


@pytest.mark.slow
def test_matrix_of_a_function_counts_from_0(tmp_path, capsys):
    """matrix(3, 2, f) with f(x, y) = x^2 - y is [[0, -1], [1, 0], [4, 3]] (i and j from 0)."""
    want = [[i * i - j for j in range(2)] for i in range(3)]
    regions = _f_of_indices() + _eval(2, _call("matrix", _real(3), _real(2), _id("f")))
    results = _result(1) + _result(2, _stored_matrix(want))
    src = _package(tmp_path / "m.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "m.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (6, 6, 0), result


@pytest.mark.slow
def test_matrix_of_a_function_at_origin_1(tmp_path, capsys):
    """At ORIGIN 1, matrix(m, n, f) of a function of its indices is listed (which indices
    Mathcad gives f there is not known); of a function that ignores them, translated."""
    zero = _function(3, "g", ["x", "y"], "<ml:real>0</ml:real>")
    regions = (
        _f_of_indices()
        + _eval(2, _call("matrix", _real(2), _real(2), _id("f")))
        + zero
        + _eval(4, _call("matrix", _real(2), _real(3), _id("g")))
    )
    results = (
        _result(1)
        + _result(2, _stored_matrix([[0, -1], [1, 0]]))
        + _result(3)
        + _result(4, _stored_matrix([[0, 0, 0], [0, 0, 0]]))
    )
    src = _package(tmp_path / "m1.mcdx", regions, results, origin=1)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "m1.toml").read_text(encoding="utf-8")
    assert "matrix(m, n, f) at ORIGIN 1 of a function of its indices" in text
    result = _check(tmp_path / "m1.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (10, 6, 0), result


@pytest.mark.slow
def test_matrix_of_a_size_not_known_at_import_is_listed(tmp_path, capsys):
    regions = _f_of_indices() + _eval(2, _call("matrix", _id("n"), _real(2), _id("f")))
    results = _result(1) + _result(2, _stored_matrix([[0, -1]]))
    src = _package(tmp_path / "mn.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "mn.toml").read_text(encoding="utf-8")
    assert "region 2: an evaluation ( = ): matrix(m, n, f) whose size is not a number known" in text


@pytest.mark.slow
def test_a_function_redefined_from_its_previous_definition(tmp_path, capsys):
    """B(x) := x + 1, then B(x) := B(x)*2 (Mathcad reads the previous B): B(3) = 8; a
    function first defined calling itself stays Mathcad's recursion."""
    first = _function(
        1, "B", ["x"], f"<ml:apply><ml:plus/>{_id('x')}<ml:real>1</ml:real></ml:apply>"
    )
    again = _function(
        2, "B", ["x"], f"<ml:apply><ml:mult/>{_call('B', _id('x'))}<ml:real>2</ml:real></ml:apply>"
    )
    regions = first + again + _eval(3, _call("B", _real(3)))
    results = _result(1) + _result(2) + _result(3, "<ml:real>8</ml:real>")
    src = _package(tmp_path / "b.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "b.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (1, 1, 0), result


@pytest.mark.slow
def test_a_sum_of_matrices(tmp_path, capsys):
    """K := Σ_{j=1}^{3} M·j with M = [[1, 2], [3, 4]]: 6 M, a matrix (not a number)."""
    m = (
        '<ml:matrix rows="2" cols="2"><ml:real>1</ml:real><ml:real>3</ml:real>'
        "<ml:real>2</ml:real><ml:real>4</ml:real></ml:matrix>"
    )
    define_m = _region(1, 1, f"<ml:define>{_id('M')}{m}</ml:define>")
    lam = (
        f"<ml:lambda><ml:boundVars>{_id('j')}</ml:boundVars><ml:apply><ml:mult/>{_id('M')}"
        f"{_id('j')}</ml:apply></ml:lambda>"
    )
    total = (
        f"<ml:apply><ml:summation/>{lam}<ml:lowerBound><ml:real>1</ml:real></ml:lowerBound>"
        "<ml:upperBound><ml:real>3</ml:real></ml:upperBound></ml:apply>"
    )
    plus_m = f"<ml:apply><ml:plus/>{total}{_id('M')}</ml:apply>"
    regions = define_m + _eval(2, plus_m)
    results = _result(1) + _result(2, _stored_matrix([[7, 14], [21, 28]]))
    src = _package(tmp_path / "s.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "s.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (4, 4, 0), result


@pytest.mark.slow
def test_a_difference_is_compared_within_the_round_off_of_its_terms(tmp_path, capsys):
    """w := [2401; 1000.3], shown; Mathcad stored (w/7)*7 - w as round-off (5e-12, 6e-12),
    which is reproduced within 1e-9 of the largest term Mathcad showed (2401); a stored
    value 1e-3 off is not."""
    w = '<ml:matrix rows="2" cols="1"><ml:real>2401</ml:real><ml:real>1000.3</ml:real></ml:matrix>'
    define_w = _region(1, 1, f"<ml:define>{_id('w')}{w}</ml:define>")
    scaled = (
        f"<ml:apply><ml:mult/><ml:apply><ml:div/>{_id('w')}<ml:real>7</ml:real></ml:apply>"
        "<ml:real>7</ml:real></ml:apply>"
    )
    residual = f"<ml:apply><ml:minus/>{scaled}{_id('w')}</ml:apply>"
    regions = define_w + _eval(2, _id("w")) + _eval(3, residual) + _eval(4, residual)
    results = (
        _result(1)
        + _result(2, _stored_matrix([[2401], [1000.3]]))
        + _result(3, _stored_matrix([[5e-12], [-6e-12]]))
        + _result(4, _stored_matrix([[1e-3], [0]]))
    )
    src = _package(tmp_path / "d.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "d.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (6, 5, 1), result
    assert [f["name"] for f in result["failures"]] == ["result_4"]


def _local(lhs: str, rhs: str) -> str:
    return f"<ml:localDefine>{lhs}{rhs}</ml:localDefine>"


def _index(target: str, *at: str) -> str:
    inner = at[0] if len(at) == 1 else f"<ml:sequence>{''.join(at)}</ml:sequence>"
    return f"<ml:apply><ml:indexer/>{target}{inner}</ml:apply>"


@pytest.mark.slow
def test_a_program_with_a_local_function_and_an_element_matrix(tmp_path, capsys):
    """K[i] := | g(r, c) <- r + 10 c           (a local function)
                | K[i] <- matrix(2, 2, g)        (the local vector K, used only at i)
                | (K[i])[0, 1] <- i
                | K[i]
    over i := 0 .. 1 is the vector of [[0, i], [1, 11]]; K[1] = [[0, 1], [1, 11]]. A local
    function that reads a local the program gives once, before it, reads its one value."""
    g = f"<ml:function>{_id('g')}<ml:boundVars>{_id('r')}{_id('c')}</ml:boundVars></ml:function>"
    g_body = (
        f"<ml:apply><ml:plus/>{_id('r')}<ml:apply><ml:mult/><ml:real>10</ml:real>{_id('c')}"
        "</ml:apply></ml:apply>"
    )
    k_i = _index(_id("K"), _id("i"))
    program = (
        "<ml:program>"
        + _local(g, g_body)
        + _local(k_i, _call("matrix", _real(2), _real(2), _id("g")))
        + _local(_index(f"<ml:parens>{k_i}</ml:parens>", _real(0), _real(1)), _id("i"))
        + k_i
        + "</ml:program>"
    )
    rng = "<ml:range><ml:real>0</ml:real><ml:real>1</ml:real></ml:range>"
    regions = (
        _region(1, 1, f"<ml:define>{_id('i')}{rng}</ml:define>")
        + _region(2, 2, f"<ml:define>{k_i}{program}</ml:define>")
        + _eval(3, _index(_id("K"), _real(1)))
    )
    results = _result(1) + _result(2) + _result(3, _stored_matrix([[0, 1], [1, 11]]))
    src = _package(tmp_path / "p.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "p.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (4, 4, 0), result

    reads_local = (
        "<ml:program>"
        + _local(_id("a"), _real(2))
        + _local(g, f"<ml:apply><ml:plus/>{_id('r')}{_id('a')}</ml:apply>")
        + _call("g", _real(1), _real(1))
        + "</ml:program>"
    )
    src = _package(
        tmp_path / "q.mcdx",
        _region(1, 1, f"<ml:define>{_id('h')}{reads_local}</ml:define>") + _eval(2, _id("h")),
        _result(1) + _result(2, "<ml:real>3</ml:real>"),
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    # a, given once before g, has one value at every call of g: g(1, 1) = 1 + 2
    result = _check(tmp_path / "q.toml", capsys)
    assert (result["printed"], result["reproduced"]) == (1, 1), result


@pytest.mark.slow
def test_a_stored_zero_among_large_elements_is_round_off(tmp_path, capsys):
    """stack(M, (M/3)*3 - M) with M = [128822157.11805557; 0.1]: Mathcad stored exact zeros
    below, ours are 1.5e-8 and 0 (round-off of 1.3e8): compared within 1e-15 of the largest
    element, they pass; a stored 0 where the value is 1e-3 does not."""
    m = (
        '<ml:matrix rows="2" cols="1"><ml:real>128822157.11805557</ml:real>'
        "<ml:real>0.1</ml:real></ml:matrix>"
    )
    define_m = _region(1, 1, f"<ml:define>{_id('M')}{m}</ml:define>")
    third = (
        f"<ml:apply><ml:mult/><ml:apply><ml:div/>{_id('M')}<ml:real>3</ml:real></ml:apply>"
        "<ml:real>3</ml:real></ml:apply>"
    )
    residual = f"<ml:apply><ml:minus/>{third}{_id('M')}</ml:apply>"
    small = '<ml:matrix rows="1" cols="1"><ml:real>0.001</ml:real></ml:matrix>'
    regions = (
        define_m
        + _eval(2, _call("stack", _id("M"), residual))
        + _eval(3, _call("stack", _id("M"), small))
    )
    big = 128822157.11805557
    results = (
        _result(1)
        + _result(2, _stored_matrix([[big], [0.1], [0], [0]]))
        + _result(3, _stored_matrix([[big], [0.1], [0]]))
    )
    src = _package(tmp_path / "z.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "z.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (7, 6, 1), result
    assert [f["at"] for f in result["failures"]] == [2.0]


def _range_def(rid: int, name: str, first: float, last: float) -> str:
    rng = f"<ml:range>{_real(first)}{_real(last)}</ml:range>"
    return _region(rid, rid, f"<ml:define>{_id(name)}{rng}</ml:define>")


def _define_shown(rid: int, lhs: str, rhs: str) -> str:
    return _region(rid, rid, f"<ml:define>{lhs}<ml:eval>{rhs}</ml:eval></ml:define>")


@pytest.mark.slow
def test_a_column_of_a_computed_index_and_sorted_eigenvalues(tmp_path, capsys):
    """X[i, j] := D[i, j] - mean(D<j>) over i := 0..1, j := 0..2 (a column whose index is a
    parameter); sort(eigenvals(S)) (Prime's order of eigenvalues does not matter once they
    are sorted), while eigenvec and eigenvecs are listed (their sign is Mathcad's solver's)."""
    d = (
        '<ml:matrix rows="2" cols="3"><ml:real>1</ml:real><ml:real>4</ml:real>'
        "<ml:real>2</ml:real><ml:real>5</ml:real><ml:real>3</ml:real><ml:real>9</ml:real>"
        "</ml:matrix>"
    )
    s = (
        '<ml:matrix rows="2" cols="2"><ml:real>2</ml:real><ml:real>1</ml:real>'
        "<ml:real>1</ml:real><ml:real>2</ml:real></ml:matrix>"
    )
    column = f"<ml:apply><ml:matcol/>{_id('D')}{_id('j')}</ml:apply>"
    rhs = (
        f"<ml:apply><ml:minus/>{_index(_id('D'), _id('i'), _id('j'))}"
        f"{_call('mean', column)}</ml:apply>"
    )
    regions = (
        _region(1, 1, f"<ml:define>{_id('D')}{d}</ml:define>")
        + _range_def(2, "i", 0, 1)
        + _range_def(3, "j", 0, 2)
        + _define_shown(4, _index(_id("X"), _id("i"), _id("j")), rhs)
        + _region(5, 5, f"<ml:define>{_id('S')}{s}</ml:define>")
        + _eval(6, _call("sort", _call("eigenvals", _id("S"))))
        + _eval(7, _call("eigenvecs", _id("S")))
    )
    results = (
        _result(1)
        + _result(2)
        + _result(3)
        + _result(4, _stored_matrix([[-1.5, -1.5, -3], [1.5, 1.5, 3]]))
        + _result(5)
        + _result(6, _stored_matrix([[1], [3]]))
        + _result(
            7,
            _stored_matrix(
                [
                    [0.7071067811865475, -0.7071067811865475],
                    [0.7071067811865475, 0.7071067811865475],
                ]
            ),
        )
    )
    src = _package(tmp_path / "c.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "c.toml").read_text(encoding="utf-8")
    assert (
        "region 7: an evaluation ( = ): Mathcad's eigenvecs() gives eigenvectors whose sign" in text
    )
    result = _check(tmp_path / "c.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (12, 8, 0), result


@pytest.mark.slow
def test_elements_over_a_range_replace_a_vector_when_mathcad_shows_so(tmp_path, capsys):
    """x := [7; 8; 9], then x[j] := 2 j over j := 0..1, shown by Mathcad with 2 rows: Prime
    replaced x (it keeps no element of the old x), x = [0; 2]; shown with 3 rows, it kept
    x[2] (9)."""
    old = (
        '<ml:matrix rows="3" cols="1"><ml:real>7</ml:real><ml:real>8</ml:real>'
        "<ml:real>9</ml:real></ml:matrix>"
    )
    twice = f"<ml:apply><ml:mult/><ml:real>2</ml:real>{_id('j')}</ml:apply>"

    def sheet(name: str, shown: list[list[float]]) -> Path:
        regions = (
            _region(1, 1, f"<ml:define>{_id('x')}{old}</ml:define>")
            + _range_def(2, "j", 0, 1)
            + _define_shown(3, _index(_id("x"), _id("j")), twice)
            + _eval(4, _call("length", _id("x")))
        )
        results = (
            _result(1)
            + _result(2)
            + _result(3, _stored_matrix(shown))
            + _result(4, f"<ml:real>{len(shown)}</ml:real>")
        )
        return _package(tmp_path / f"{name}.mcdx", regions, results)

    for name, shown in (("replaced", [[0], [2]]), ("kept", [[0], [2], [9]])):
        assert main(["import", str(sheet(name, shown)), "--out", str(tmp_path)]) == 0
        result = _check(tmp_path / f"{name}.toml", capsys)
        n = len(shown) + 1
        assert (result["printed"], result["reproduced"], result["failed"]) == (n, n, 0), result


@pytest.mark.slow
def test_names_of_a_matrix_defined_by_a_program(tmp_path, capsys):
    """[a; b] := | x <- 2 ; [x; 3 x] : a = 2, b = 6."""
    lhs = f'<ml:matrix rows="2" cols="1">{_id("a")}{_id("b")}</ml:matrix>'
    value = (
        f'<ml:matrix rows="2" cols="1">{_id("x")}<ml:apply><ml:mult/><ml:real>3</ml:real>'
        f"{_id('x')}</ml:apply></ml:matrix>"
    )
    program = f"<ml:program>{_local(_id('x'), _real(2))}{value}</ml:program>"
    regions = (
        _region(1, 1, f"<ml:define>{lhs}{program}</ml:define>")
        + _eval(2, _id("a"))
        + _eval(3, _id("b"))
    )
    results = _result(1) + _result(2, "<ml:real>2</ml:real>") + _result(3, "<ml:real>6</ml:real>")
    src = _package(tmp_path / "ab.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "ab.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 2, 0), result


@pytest.mark.slow
def test_an_element_defined_from_its_previous_value(tmp_path, capsys):
    """v := [1; 2; 3]; v[1] := 10 v[1] (the right side reads the previous v, not the new one,
    which was a circular definition): v = [1; 20; 3]."""
    v = (
        '<ml:matrix rows="3" cols="1"><ml:real>1</ml:real><ml:real>2</ml:real>'
        "<ml:real>3</ml:real></ml:matrix>"
    )
    v1 = _index(_id("v"), _real(1))
    regions = (
        _region(1, 1, f"<ml:define>{_id('v')}{v}</ml:define>")
        + _region(
            2, 2, f"<ml:define>{v1}<ml:apply><ml:mult/>{_real(10)}{v1}</ml:apply></ml:define>"
        )
        + _eval(3, _id("v"))
    )
    results = _result(1) + _result(2) + _result(3, _stored_matrix([[1], [20], [3]]))
    src = _package(tmp_path / "v.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "v.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (3, 3, 0), result


@pytest.mark.slow
def test_vectorize_over_a_vector_of_a_length_known_when_computed(tmp_path, capsys):
    """v := g(b), g(x) := 1·x a function of the worksheet (its length not known at import:
    a function's arguments are typed at the end); →(v·v + 1) is the language's
    vectorize(v * v + 1): [5; 10]. u := lsolve(M, b) is of a length the engine gives at
    import: →(u·u + 1) is written out, [u[0] * u[0] + 1, ...]."""
    m = (
        '<ml:matrix rows="2" cols="2"><ml:real>1</ml:real><ml:real>0</ml:real>'
        "<ml:real>0</ml:real><ml:real>1</ml:real></ml:matrix>"
    )
    b = '<ml:matrix rows="2" cols="1"><ml:real>2</ml:real><ml:real>3</ml:real></ml:matrix>'
    square = f"<ml:apply><ml:mult/>{_id('v')}{_id('v')}</ml:apply>"
    body = f"<ml:apply><ml:vectorize/><ml:apply><ml:plus/>{square}{_real(1)}</ml:apply></ml:apply>"
    u_square = f"<ml:apply><ml:mult/>{_id('u')}{_id('u')}</ml:apply>"
    u_body = (
        f"<ml:apply><ml:vectorize/><ml:apply><ml:plus/>{u_square}{_real(1)}</ml:apply></ml:apply>"
    )
    g = (
        f"<ml:function>{_id('g')}<ml:boundVars>{_id('x')}</ml:boundVars></ml:function>"
        f"<ml:apply><ml:mult/>{_real(1)}{_id('x')}</ml:apply>"
    )
    regions = (
        _region(1, 1, f"<ml:define>{_id('M')}{m}</ml:define>")
        + _region(2, 2, f"<ml:define>{_id('b')}{b}</ml:define>")
        + _region(7, 7, f"<ml:define>{g}</ml:define>")
        + _region(3, 3, f"<ml:define>{_id('v')}{_call('g', _id('b'))}</ml:define>")
        + _eval(4, body)
        + _region(5, 5, f"<ml:define>{_id('u')}{_call('lsolve', _id('M'), _id('b'))}</ml:define>")
        + _eval(6, u_body)
    )
    results = (
        _result(1)
        + _result(2)
        + _result(3)
        + _result(4, _stored_matrix([[5], [10]]))
        + _result(5)
        + _result(6, _stored_matrix([[5], [10]]))
        + _result(7)
    )
    src = _package(tmp_path / "vec.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "vec.toml").read_text(encoding="utf-8")
    assert "vectorize(" in text and "u[0] * u[0] + 1" in text
    result = _check(tmp_path / "vec.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (4, 4, 0), result
