"""A symbolic evaluation (→) shown alone, whose result Mathcad found as a number or a matrix
of numbers, is compared as a stored result of its expression; one with keywords (``float,
3`` rounds), or whose result is an expression, is not compared."""

from __future__ import annotations

from helpers.mathcad_xml import (
    ML,
    apply,
    at,
    check_sheet,
    define,
    ident,
    import_sheet,
    matrix,
    real,
)


def symbolic(rid: int, expr: str, found: str, keywords: str = "") -> str:
    inner = f"{expr}{keywords}<ml:symResult>{found}</ml:symResult>"
    body = f'<ml:symEval xmlns:ml="{ML}">{inner}</ml:symEval>'
    return f"<region {at(rid)}><math>{body}</math></region>"


def test_a_number_found_symbolically_is_compared(tmp_path, capsys):
    """a := 0.3; a·[2; -5] → [0.6; -1.5] and a - 1 → -0.7 (Mathcad's 20 digits) are three
    values reproduced; 2·a → 0.600 with `float, 3` and a·x → 0.3·x are not compared."""
    keywords = f"<ml:command>{apply('float', real(3))}</ml:command>"  # float, 3: a rounded result
    text = import_sheet(
        tmp_path,
        capsys,
        "sym",
        define(1, ident("a"), real(0.3)),
        symbolic(
            2,
            apply("mult", ident("a"), matrix(real(2), real(-5))),
            matrix(real("0.59999999999999997780"), apply("neg", real("1.4999999999999999445"))),
        ),
        symbolic(3, apply("minus", ident("a"), real(1)), apply("neg", real("0.7"))),
        symbolic(4, apply("mult", real(2), ident("a")), real("0.600"), keywords),
        symbolic(5, apply("mult", ident("a"), ident("x")), apply("mult", real(0.3), ident("x"))),
    )
    assert "result_4" not in text and "result_5" not in text  # not compared
    result = check_sheet(tmp_path, capsys, "sym")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]
