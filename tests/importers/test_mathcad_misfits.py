"""One failure costs one value: a stored result whose unit or name does not fit what the
translation computes is listed as not computable with its reason, and every other value of
the worksheet is still compared (``check --json`` exits 0 or 1, never 2)."""

from __future__ import annotations

import pytest
from helpers.mathcad_xml import (
    apply,
    check_sheet,
    define,
    evaluate,
    ident,
    import_sheet,
    real,
    united,
)


@pytest.mark.slow
def test_a_unit_of_another_dimension_costs_that_value(tmp_path, capsys):
    """x := 2 shown as 2 m (a stored unit that does not fit a plain number), y := 3 shown as
    3: x is not computable with the reason, y is compared."""
    text = import_sheet(
        tmp_path,
        capsys,
        "dims",
        define(1, ident("x"), real(2)),
        define(2, ident("y"), real(3)),
        evaluate(3, ident("x"), united(2, ("m", 1))),
        evaluate(4, ident("y"), real(3)),
    )
    assert "Mathcad stored it in m ([length]), the translation computes dimensionless" in text
    result = check_sheet(tmp_path, capsys, "dims")
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (2, 1, 1)


@pytest.mark.slow
def test_a_unit_power_out_of_range_costs_that_value(tmp_path, capsys):
    """A stored unit m^14 (beyond the language's powers): that value only."""
    text = import_sheet(
        tmp_path,
        capsys,
        "power",
        define(1, ident("x"), real(2)),
        define(2, ident("y"), apply("mult", ident("x"), real(2))),
        evaluate(3, ident("x"), united(2, ("m", 14))),
        evaluate(4, ident("y"), real(4)),
    )
    assert "is not a unit the engine knows" in text
    result = check_sheet(tmp_path, capsys, "power")
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (2, 1, 1)


@pytest.mark.slow
def test_a_name_e_left_out_never_reads_the_constant(tmp_path, capsys):
    """e := h/2 = 14.2 m with h defined nowhere: the region is left out, and its stored
    value is not computable (never compared with Euler's number, dimensionless)."""
    shown = (
        f"<ml:eval>{apply('div', ident('h'), real(2))}"
        f"<ml:result>{united(14.2, ('m', 1))}</ml:result></ml:eval>"
    )
    import_sheet(
        tmp_path,
        capsys,
        "named_e",
        define(1, ident("e"), shown),
        define(2, ident("y"), real(3)),
        evaluate(4, ident("y"), real(3)),
    )
    result = check_sheet(tmp_path, capsys, "named_e")
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (2, 1, 1)
    assert "is not defined" in result["failures"][0]["error"]
