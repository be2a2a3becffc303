"""Mathcad built-ins and operators the importer translates, each against values computed
here independently (numpy, a Runge-Kutta written out in Python) and, where the corpora of
../shared store them, against Mathcad's own values (those tests skip without ../shared)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from helpers.mathcad_xml import (
    apply,
    array_cells,
    call,
    check_sheet,
    define,
    function,
    ident,
    import_sheet,
    index,
    matrix,
    prime_package,
    prime_region,
    prime_result,
    real,
    shown,
)
from helpers.paths import SHARED

from workbook.cli import main


@pytest.mark.slow
def test_the_determinant_operator_is_det(tmp_path, capsys):
    m = np.array([[6.5, 4.2, 4.7], [6.2, -1.5, -5.0], [6.3, 2.2, 4.9]])
    text = import_sheet(
        tmp_path,
        capsys,
        "det",
        define(1, ident("M"), array_cells(m)),
        define(2, ident("d"), shown(apply("determinant", ident("M")), real(np.linalg.det(m)))),
    )
    assert 'd = { expr = "det(M)"' in text
    assert check_sheet(tmp_path, capsys, "det")["reproduced"] == 1


@pytest.mark.slow
def test_inverse_and_reciprocal_hyperbolic_functions_against_mpmath(tmp_path, capsys):
    import mpmath

    mpmath.mp.dps = 50
    x = mpmath.mpf("0.3")
    calls = {
        "asinh": mpmath.asinh(x), "acosh": mpmath.acosh(1 + x), "atanh": mpmath.atanh(x),
        "coth": mpmath.coth(x), "sech": mpmath.sech(x), "csch": mpmath.csch(x),
        "asech": mpmath.asech(x), "acsch": mpmath.acsch(x),
    }  # fmt: skip
    regions = [define(1, ident("x"), real(0.3))]
    for k, (name, value) in enumerate(calls.items(), start=2):
        arg = apply("plus", real(1.0), ident("x")) if name == "acosh" else ident("x")
        regions.append(define(k, ident(f"y_{name}"), shown(call(name, arg), real(float(value)))))
    text = import_sheet(tmp_path, capsys, "hyperbolic", *regions)
    assert 'expr = "asinh(x)"' in text and 'expr = "acosh(1 + x)"' in text
    assert check_sheet(tmp_path, capsys, "hyperbolic")["reproduced"] == len(calls)


@pytest.mark.slow
def test_rkfixed_is_mathcad_runge_kutta(tmp_path, capsys):
    """u := rkfixed(y0, 0, 2, 10, D) with D(x, y) := [y1; -y0 - 0.3 y1 + sin x]: against the
    classical fourth-order Runge-Kutta written out here (x added step by step)."""

    def d(x, y):
        return np.array([y[1], -y[0] - 0.3 * y[1] + math.sin(x)])

    y, x, h, rows = np.array([1.0, 0.0]), 0.0, 2.0 / 10, []
    for _ in range(11):
        rows.append([x, *y])
        k1 = d(x, y)
        k2 = d(x + h / 2, y + h / 2 * k1)
        k3 = d(x + h / 2, y + h / 2 * k2)
        k4 = d(x + h, y + h * k3)
        y, x = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), x + h
    expected = np.array(rows)
    y0, y1 = index(ident("y"), real(0)), index(ident("y"), real(1))
    deriv = matrix(
        y1,
        apply(
            "plus",
            apply("minus", apply("neg", y0), apply("mult", real(0.3), y1)),
            call("sin", ident("x")),
        ),
    )
    rk = call("rkfixed", ident("y0"), real(0), real(2), real(10), ident("D"))
    import_sheet(
        tmp_path,
        capsys,
        "rk",
        function(1, "D", ["x", "y"], deriv),
        define(2, ident("y0"), matrix(real(1), real(0))),
        define(3, ident("u"), shown(rk, array_cells(expected))),
    )
    result = check_sheet(tmp_path, capsys, "rk")
    assert (result["printed"], result["reproduced"]) == (33, 33), result["failures"][:3]


@pytest.mark.slow
def test_histogram_of_a_matrix_counts_every_element(tmp_path, capsys):
    """histogram(4, M) of a 3 x 2 matrix: Mathcad counts its six values (numpy's counts)."""
    m = np.array([[0.5, 2.5], [1.5, 3.9], [0.1, 2.0]])
    counts, edges = np.histogram(m.flatten(), bins=4)
    mids = (edges[:-1] + edges[1:]) / 2
    stored = array_cells(np.column_stack([mids, counts]))
    import_sheet(
        tmp_path,
        capsys,
        "hist",
        define(1, ident("M"), array_cells(m)),
        define(2, ident("n"), real(4)),
        define(3, ident("H"), shown(call("histogram", ident("n"), ident("M")), stored)),
    )
    result = check_sheet(tmp_path, capsys, "hist")
    assert (result["printed"], result["reproduced"]) == (8, 8), result["failures"][:3]


@pytest.mark.slow
def test_a_random_number_is_not_computable_with_the_reason(tmp_path, capsys):
    text = import_sheet(
        tmp_path,
        capsys,
        "random",
        define(1, ident("r"), shown(call("rnd", real(1)), real(0.001251))),
        define(2, ident("s"), shown(real(2), real(2))),
    )
    assert "Mathcad's rnd() gives random numbers of Mathcad's own generator" in text
    result = check_sheet(tmp_path, capsys, "random")
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (2, 1, 1)


@pytest.mark.slow
def test_an_element_shown_is_compared_as_the_element(tmp_path, capsys):
    """x[1] := 6/3 = 2 (Mathcad shows the element): compared as 2, not as the vector x."""
    import_sheet(
        tmp_path,
        capsys,
        "element",
        define(1, index(ident("x"), real(1)), shown(apply("div", real(6), real(3)), real(2))),
    )
    result = check_sheet(tmp_path, capsys, "element")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


#: files of the corpora whose every stored value the catalogue above reproduces
GOLDEN = [
    "corpus-more/mathcad15-b/cramer-determinants.xmcd",
    "corpus-more/mathcad15-b/statistics-histogram.xmcd",
    "corpus-more/mathcad15-a/pyramid.xmcd",
]


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared is absent")
@pytest.mark.parametrize("name", GOLDEN)
def test_corpus_files_reproduce_every_stored_value(tmp_path, capsys, name):
    assert main(["import", str(SHARED / name), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    main(["check", str(tmp_path / (Path(name).stem + ".toml")), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert result["reproduced"] == result["printed"], result["failures"][:3]


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared is absent")
def test_rkfixed_reproduces_mathcad_stored_matrix(tmp_path, capsys):
    """ode-runge-kutta-spline's u := rkfixed(y0, 0, 6, 60, D), 61 x 2 values as stored."""
    src = SHARED / "corpus-more/mathcad15-b/ode-runge-kutta-spline.xmcd"
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    main(["check", str(tmp_path / "ode-runge-kutta-spline.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert result["failed"] == 0 and result["reproduced"] >= 122, result["failures"][:3]


@pytest.mark.slow
def test_prime_divides_a_number_by_a_vector_element_by_element(tmp_path, capsys):
    """Prime's T := 2 pi / w of a vector w stores the vector of quotients: vectorize."""
    w = [1.5, 2.0, 4.0]
    vec = matrix(*(real(v) for v in w))
    body = apply("div", apply("mult", real(2), "<ml:id>π</ml:id>"), "<ml:id>w</ml:id>")
    regions = prime_region(1, 1, f"<ml:define><ml:id>w</ml:id>{vec}</ml:define>") + prime_region(
        2, 2, f"<ml:define><ml:id>T</ml:id><ml:eval>{body}</ml:eval></ml:define>"
    )
    stored = matrix(*(real(2 * math.pi / v) for v in w))
    src = prime_package(
        tmp_path / "periods.mcdx", regions, prime_result(1) + prime_result(2, stored)
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    main(["check", str(tmp_path / "periods.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]


def test_linfit_is_the_least_squares_combination(tmp_path, capsys):
    """F(x) := [1; x; sin(x)]; c := linfit(vx, vy, F): against numpy's least squares."""
    vx = np.array([0.5, 1.0, 2.0, 3.5, 4.0, 6.0])
    vy = np.array([1.2, 2.3, 2.9, 4.1, 5.6, 6.2])
    design = np.stack([np.ones_like(vx), vx, np.sin(vx)], axis=1)
    want = np.linalg.lstsq(design, vy, rcond=None)[0]
    f_body = matrix(real(1), ident("x"), call("sin", ident("x")))
    fit = call("linfit", f"<ml:sequence>{ident('vx')}{ident('vy')}{ident('F')}</ml:sequence>")
    text = import_sheet(
        tmp_path,
        capsys,
        "linfit",
        define(1, ident("vx"), matrix(*(real(float(v)) for v in vx))),
        define(2, ident("vy"), matrix(*(real(float(v)) for v in vy))),
        function(3, "F", ["x"], f_body),
        define(4, ident("c"), shown(fit, matrix(*(real(repr(float(v))) for v in want)))),
    )
    assert "geninv(stack(transpose(F(vx[0]))" in text
    result = check_sheet(tmp_path, capsys, "linfit")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]


@pytest.mark.slow
def test_distributions_dbinom_plnorm_qweibull_against_scipy(tmp_path, capsys):
    """dbinom(k, n, p), plnorm(x, mu, sigma) and qweibull(p, s) of a Mathcad 15 worksheet
    become the language's of the same names; the values stored are SciPy's."""
    import scipy.stats

    def seq(*args):
        return f"<ml:sequence>{''.join(args)}</ml:sequence>"

    calls = {
        "dbinom": (seq(ident("k"), ident("n"), ident("p")), scipy.stats.binom.pmf(3, 10, 0.3)),
        "plnorm": (
            seq(real(2.5), real(0.3), real(1.7)),
            scipy.stats.lognorm.cdf(2.5, 1.7, 0, math.exp(0.3)),
        ),
        "qweibull": (seq(real(0.9), real(2.5)), scipy.stats.weibull_min.ppf(0.9, 2.5)),
    }
    regions = [define(1, ident("k"), real(3)), define(2, ident("n"), real(10))]
    regions.append(define(3, ident("p"), real(0.3)))
    for rid, (name, (args, value)) in enumerate(calls.items(), start=4):
        regions.append(
            define(rid, ident(f"y_{name}"), shown(call(name, args), real(repr(float(value)))))
        )
    text = import_sheet(tmp_path, capsys, "distributions", *regions)
    assert 'expr = "dbinom(k, n, p)"' in text and 'expr = "qweibull(0.9, 2.5)"' in text
    assert 'expr = "plnorm(2.5, 0.3, 1.7)"' in text
    result = check_sheet(tmp_path, capsys, "distributions")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]
