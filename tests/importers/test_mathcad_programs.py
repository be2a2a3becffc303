"""Mathcad's program idioms as the importer translates them: comparisons as numbers, numbers
as conditions, destructuring, column assignment, locals that start at 0, a break outside a
loop, elements of a vector defined one by one, nested array results, areas read in order."""

from __future__ import annotations

import json

import pytest
from helpers.mathcad_xml import ML
from helpers.mathcad_xml import apply as _apply
from helpers.mathcad_xml import call as _call
from helpers.mathcad_xml import define as _define
from helpers.mathcad_xml import evaluate as _eval
from helpers.mathcad_xml import for_loop as _for
from helpers.mathcad_xml import function as _function
from helpers.mathcad_xml import ident as _id
from helpers.mathcad_xml import if_then as _if
from helpers.mathcad_xml import import_sheet as _import
from helpers.mathcad_xml import index as _index
from helpers.mathcad_xml import local as _local
from helpers.mathcad_xml import matrix as _matrix
from helpers.mathcad_xml import otherwise as _otherwise
from helpers.mathcad_xml import program as _program
from helpers.mathcad_xml import real as _real
from helpers.mathcad_xml import worksheet as _worksheet

from workbook.cli import main


def _translated(tmp_path, name: str, *regions: str, origin: int = 0):
    """The worksheet text and printed values as translated, before the engine loads them
    (for what the language is still being given)."""
    from workbook.mathcad import read, regions_with_references, writer
    from workbook.mathcad.translate import Translator

    src = tmp_path / f"{name}.xmcd"
    src.write_text(_worksheet(*regions, origin=origin), encoding="utf-8")
    ws = read(src)
    return writer.render(Translator().run(ws, regions_with_references(ws)), name, src)


def _check(tmp_path, capsys, name: str) -> dict:
    main(["check", str(tmp_path / f"{name}.toml"), "--json"])
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_comparison_as_a_number_and_numbers_as_conditions(tmp_path, capsys):
    """f(x) := (x > 2)*3 + 1 (Mathcad's comparison is 1 or 0); g(a, b) := | if (a = 1)*(b = 1):
    10 / otherwise: 20 | (a product of comparisons is Mathcad's and); h(a) := | s <- a ; if s:
    1 / otherwise: 2 | (a number as a condition); f(3) = 4, g(1, 1) = 10, g(1, 2) = 20,
    h(0) = 2 as stored."""
    f = _apply(
        "plus", _apply("mult", _apply("greaterThan", _id("x"), _real(2)), _real(3)), _real(1)
    )
    both = _apply("mult", _apply("equal", _id("a"), _real(1)), _apply("equal", _id("b"), _real(1)))
    g = _program(_local(_id("s"), _real(0)), _if(both, _real(10)), _otherwise(_real(20)))
    h = _program(_local(_id("s"), _id("a")), _if(_id("s"), _real(1)), _otherwise(_real(2)))
    text = _import(
        tmp_path,
        capsys,
        "cmp",
        _function(1, "f", ["x"], f),
        _function(2, "g", ["a", "b"], g),
        _function(3, "h", ["a"], h),
        _eval(4, _call("f", _real(3)), _real(4)),
        _eval(5, _call("g", _real(1), _real(1)), _real(10)),
        _eval(6, _call("g", _real(1), _real(2)), _real(20)),
        _eval(7, _call("h", _real(0)), _real(2)),
    )
    assert '"(1 if x > 2 otherwise 0) * 3 + 1"' in text
    assert "10 if a == 1 and b == 1" in text
    assert "1 if s != 0" in text
    result = _check(tmp_path, capsys, "cmp")
    assert (result["printed"], result["reproduced"]) == (4, 4), result["failures"]


@pytest.mark.slow
def test_ranged_inequality_is_a_chain(tmp_path, capsys):
    """Mathcad stores a <= t <= b as a comparison whose left side is a comparison: the chain
    1 <= t <= 3 (not (1 <= t) <= 3, which is always true); in(5) = 0, in(2) = 1."""
    cond = _apply("lessOrEqual", _apply("lessOrEqual", _real(1), _id("t")), _real(3))
    body = _program(_local(_id("r"), _real(0)), _if(cond, _local(_id("r"), _real(1))), _id("r"))
    text = _import(
        tmp_path,
        capsys,
        "chain",
        _function(1, "in", ["t"], body),
        _eval(2, _call("in", _real(5)), _real(0)),
        _eval(3, _call("in", _real(2)), _real(1)),
    )
    assert "r := 1 if 1 <= t <= 3" in text
    result = _check(tmp_path, capsys, "chain")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


@pytest.mark.slow
def test_destructuring_takes_each_element_at_origin(tmp_path, capsys):
    """| [a; b] <- pair(x) ; a - b | at ORIGIN 1: a fresh local, then a := parts[1],
    b := parts[2]; d(5) = 5 - 10 = -5 as stored."""
    pair = _matrix(_id("x"), _apply("mult", _real(2), _id("x")))
    body = _program(_local(_matrix(_id("a"), _id("b")), _call("pair", _id("x"))),
                    _apply("minus", _id("a"), _id("b")))  # fmt: skip
    text = _import(
        tmp_path,
        capsys,
        "parts",
        _function(1, "pair", ["x"], pair),
        _function(2, "d", ["x"], body),
        _eval(3, _call("d", _real(5)), _real(-5)),
        origin=1,
    )
    assert "parts := pair(x)\na := parts[1]\nb := parts[2]\na - b" in text
    result = _check(tmp_path, capsys, "parts")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


@pytest.mark.slow
def test_column_assignment_is_a_loop(tmp_path, capsys):
    """| M<1> <- v ; M<0> <- 2 v ; M | (ORIGIN 0): each column element by element, a loop of
    a fresh name over the vector (the engine grows M where its length is known)."""
    col = "<ml:apply><ml:matcol/>{}{}</ml:apply>"
    body = _program(
        _local(col.format(_id("M"), _real(1)), _id("v")),
        _local(col.format(_id("M"), _real(0)), _apply("mult", _real(2), _id("v"))),
        _id("M"),
    )
    call = _call("cols2", _matrix(_real(1), _real(2)))
    stored = _matrix(_real(2), _real(4), _real(1), _real(2), cols=2)  # column by column
    text = _import(
        tmp_path, capsys, "col", _function(1, "cols2", ["v"], body), _eval(2, call, stored)
    )
    assert "for k in 0 .. rows(v) - 1\n    M[k, 1] := v[k]" in text
    assert "column := 2 * v\nfor k_2 in 0 .. rows(column) - 1\n    M[k_2, 0] := column[k_2]" in text
    result = _check(tmp_path, capsys, "col")
    assert (result["printed"], result["reproduced"]) == (4, 4), result["failures"]


@pytest.mark.slow
def test_locals_start_at_zero_where_read_first(tmp_path, capsys):
    """| for i in 1..n: s <- s + i ; s | (Mathcad's s starts at 0) gets s := 0 first; a local
    given on every path before it is read does not; s(4) = 10 as stored."""
    body = _program(
        _for("i", _real(1), _id("n"), _local(_id("s"), _apply("plus", _id("s"), _id("i")))),
        _local(_id("q"), _id("s")),
        _id("q"),
    )
    text = _import(
        tmp_path, capsys, "zero", _function(1, "s", ["n"], body),
        _eval(2, _call("s", _real(4)), _real(10)),
    )  # fmt: skip
    assert '"s(n)" = { program = """\ns_2 := 0\nfor i in 1 .. n' in text
    assert "q := 0" not in text
    result = _check(tmp_path, capsys, "zero")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


@pytest.mark.slow
def test_local_set_in_one_branch_starts_at_zero(tmp_path, capsys):
    """f_kon set only where a <= 0, then read: f_kon := 0 on the first line; g(1) = 5."""
    body = _program(
        _if(_apply("lessOrEqual", _id("a"), _real(0)), _local(_id("f"), _real(1))),
        _if(_apply("notEqual", _id("f"), _real(1)), _real(5)),
        _otherwise(_real(6)),
    )
    text = _import(
        tmp_path, capsys, "branch", _function(1, "g", ["a"], body),
        _eval(2, _call("g", _real(1)), _real(5)),
    )  # fmt: skip
    assert '"g(a)" = { program = """\nf := 0\nf := 1 if a <= 0' in text
    result = _check(tmp_path, capsys, "branch")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


@pytest.mark.slow
def test_break_outside_a_loop(tmp_path, capsys):
    """| y <- 2 x ; if y > 0: y / otherwise: break | ends without a value where y <= 0: the
    break is dropped (the engine says so); a break before the program's end is listed."""
    last = _program(
        _local(_id("y"), _apply("mult", _real(2), _id("x"))),
        _if(_apply("greaterThan", _id("y"), _real(0)), _id("y")),
        _otherwise("<ml:break/>"),
    )
    inner = _program(
        _local(_id("y"), _id("x")),
        _if(_apply("lessThan", _id("y"), _real(0)), "<ml:break/>"),
        _otherwise(_local(_id("y"), _real(1))),
        _id("y"),
    )
    text = _import(
        tmp_path,
        capsys,
        "stop",
        _function(1, "pos", ["x"], last),
        _function(2, "early", ["x"], inner),
        _eval(3, _call("pos", _real(2)), _real(4)),
    )
    assert '"pos(x)" = { program = """\ny := 2 * x\ny if y > 0\n"""' in text
    assert "region 2: early(...) := ...: a break outside any loop" in text
    result = _check(tmp_path, capsys, "stop")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]
    (tmp_path / "stop2.toml").write_text(
        text.split("[[printed]]")[0] + 'z = { expr = "pos(-1)" }\n', encoding="utf-8"
    )
    main(["run", str(tmp_path / "stop2.toml")])
    assert "without a value" in capsys.readouterr().out


@pytest.mark.slow
def test_break_in_the_first_branch_keeps_the_other(tmp_path, capsys):
    """| if f = 0: break / otherwise: | ... | at the end: `if f != 0` over the other branch."""
    body = _program(
        _local(_id("f"), _id("x")),
        _if(_apply("equal", _id("f"), _real(0)), "<ml:break/>"),
        _otherwise(_program(_local(_id("r"), _apply("mult", _id("f"), _real(3))), _id("r"))),
    )
    text = _import(
        tmp_path, capsys, "keep", _function(1, "k", ["x"], body),
        _eval(2, _call("k", _real(2)), _real(6)),
    )  # fmt: skip
    assert "f := x\nif f != 0\n    r := f * 3\n    r\n" in text
    result = _check(tmp_path, capsys, "keep")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


@pytest.mark.slow
def test_parameter_set_by_elements_is_a_local_copy(tmp_path, capsys):
    """| A[1] <- 7 ; A | sets an element of Mathcad's own copy of the argument: A_local."""
    body = _program(_local(_index(_id("A"), _real(1)), _real(7)), _id("A"))
    text = _import(tmp_path, capsys, "copy", _function(1, "set", ["A"], body))
    assert "A_local := A\nA_local[1] := 7\nA_local" in text


@pytest.mark.slow
def test_elements_defined_one_by_one(tmp_path, capsys):
    """v[0] := 5, w := 1, v[1] := 7 (ORIGIN 0): each a new definition of v that copies the
    previous one and sets its element; v = [5, 7] as stored."""
    text = _import(
        tmp_path,
        capsys,
        "elems",
        _define(1, _index(_id("v"), _real(0)), _real(5)),
        _define(2, _id("w"), _real(1)),
        _define(3, _index(_id("v"), _real(1)), _real(7)),
        _eval(4, _id("v"), _matrix(_real(5), _real(7))),
    )
    assert 'v = { program = """\nv_3[0] := 5\nv_3\n"""' in text
    assert 'v_2 = { program = """\nv_3 := v\nv_3[1] := 7\nv_3\n"""' in text
    result = _check(tmp_path, capsys, "elems")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


@pytest.mark.slow
def test_nested_array_result_is_one_value_per_leaf(tmp_path, capsys):
    """T := [pair(1); pair(2)] with pair(n) := [n; [10 n; 10 n + 1]]: Mathcad stores T as a
    vector of [number; vector] pairs; one printed value per number, read by chained indices,
    a function of the outer index for each place inside."""
    pair = _matrix(
        _id("n"),
        _matrix(_apply("mult", _real(10), _id("n")),
                _apply("plus", _apply("mult", _real(10), _id("n")), _real(1))),
    )  # fmt: skip
    stored = _matrix(
        *[_matrix(_real(n), _matrix(_real(10 * n), _real(10 * n + 1))) for n in (1, 2)]
    )
    table = _matrix(_call("pair", _real(1)), _call("pair", _real(2)))
    literal = _matrix(_matrix(_real(1), _real(2)), _matrix(_real(3), _real(4)))
    text = _import(
        tmp_path,
        capsys,
        "nest",
        _function(1, "pair", ["n"], pair),
        _define(2, _id("T"), table),
        _eval(3, _id("T"), stored),
        _define(4, _id("U"), literal),  # a column of literal vectors: [[1, 2], [3, 4]] is a
    )  # matrix by rows in the language, so it is listed
    csv = (tmp_path / "nest.mathcad.index.csv").read_text(encoding="utf-8")
    assert "result_3_0,1.0,2.0," in csv and "result_3_1_1,1.0,21.0," in csv
    assert len([line for line in csv.splitlines() if line.startswith("result_3")]) == 6
    assert '"result_3_1_1(index)" = { expr = "T[index][1][1]"' in text
    assert "region 4: U := ...: a column whose every element is a vector written out" in text
    result = _check(tmp_path, capsys, "nest")
    assert (result["printed"], result["reproduced"]) == (6, 6), result["failures"]


@pytest.mark.slow
def test_collapsed_area_is_read_at_its_place(tmp_path, capsys):
    """A collapsed area's regions lie, in the file, below the region after the area; Mathcad
    reads them at the area's place: f defined inside the area is defined before g uses it."""
    area = (
        f'<region region-id="1" left="0" top="10" align-y="10"><area is-collapsed="true">'
        f"{_function(5, 'f', ['x'], _apply('mult', _real(2), _id('x')))}</area></region>"
    )  # f at 10 + 100 inside the area
    after = (
        f'<region region-id="2" left="0" top="30" align-y="30"><math>'
        f'<ml:define xmlns:ml="{ML}"><ml:function>{_id("g")}<ml:boundVars>{_id("x")}'
        f"</ml:boundVars></ml:function>{_call('f', _id('x'))}</ml:define></math></region>"
    )
    text = _import(tmp_path, capsys, "area", area, after, _eval(9, _call("g", _real(2)), _real(4)))
    assert "not defined" not in text and "neither defined" not in text
    result = _check(tmp_path, capsys, "area")
    assert result["reproduced"] == 1, result["failures"]


@pytest.mark.slow
def test_two_locals_whose_identifiers_meet_stay_two(tmp_path, capsys):
    """x.LN and x.LN_ (Mathcad: two names) are two locals of one program."""
    body = _program(
        _local(_id("x", "LN_"), _real(1)),
        _local(_id("x", "LN"), _real(2)),
        _apply("minus", _id("x", "LN_"), _id("x", "LN")),
    )
    text = _import(
        tmp_path, capsys, "two", _function(1, "f", ["a"], body),
        _eval(2, _call("f", _real(0)), _real(-1)),
    )  # fmt: skip
    assert "x_LN := 1\nx_LN_2 := 2\nx_LN - x_LN_2" in text
    result = _check(tmp_path, capsys, "two")
    assert result["reproduced"] == 1, result["failures"]


@pytest.mark.slow
def test_top_level_destructuring(tmp_path, capsys):
    """[a; b] := pair(3) (ORIGIN 1): the value a definition of its own, each name an element;
    b = 6 as stored."""
    pair = _matrix(_id("x"), _apply("mult", _real(2), _id("x")))
    text = _import(
        tmp_path,
        capsys,
        "top",
        _function(1, "pair", ["x"], pair),
        _define(2, _matrix(_id("a"), _id("b")), _call("pair", _real(3))),
        _eval(3, _id("b"), _real(6)),
        origin=1,
    )
    assert 'parts = { expr = "pair(3)"' in text and 'b = { expr = "parts[2]"' in text
    assert "->" not in text.split("[sheet]")[0]  # parts is no Mathcad name that changed
    result = _check(tmp_path, capsys, "top")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


@pytest.mark.slow
def test_break_inside_a_loop_stays_and_continue_outside_is_listed(tmp_path, capsys):
    """A break inside a while loop is the loop's; a continue outside any loop is listed; an
    element assignment at i + 1 over a range variable i sets v[1..3] (v[0] is 0)."""
    loop = (
        f"<ml:while>{_apply('lessThan', _id('s'), _real(100))}"
        + _program(
            _local(_id("s"), _apply("plus", _id("s"), _id("x"))),
            _if(_apply("greaterThan", _id("s"), _real(10)), "<ml:break/>"),
        )
        + "</ml:while>"
    )
    found = _program(_local(_id("s"), _real(0)), loop, _id("s"))
    skip = _program(_local(_id("s"), _id("x")), "<ml:continue/>", _id("s"))
    rng = f"<ml:range>{_real(0)}{_real(2)}</ml:range>"
    text = _import(
        tmp_path,
        capsys,
        "loops",
        _function(1, "first", ["x"], found),
        _function(2, "skip", ["x"], skip),
        _define(3, _id("i"), rng),
        _define(4, _index(_id("v"), _apply("plus", _id("i"), _real(1))), _id("i")),
        _eval(5, _call("first", _real(4)), _real(12)),
    )
    assert "while s < 100\n    s := s + x\n    break if s > 10\ns\n" in text
    assert "region 2: skip(...) := ...: a continue outside any loop" in text
    assert 'v = { expr = "[0, v_of(0), v_of(1), v_of(2)]"' in text
    result = _check(tmp_path, capsys, "loops")
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


def test_a_program_as_the_value_of_a_local(tmp_path, capsys):
    """f(n) := | k <- (| 4 if n = 4 ; 3 if n = 3 ; 9 if n > 3) ; k + 1: the inner program's
    value is that of the last line it ran (a false `if` line runs nothing), so f(4) = 10
    (its third line ran after its first) and f(3) = 4; f(2) runs no value line, and its
    stored 1 (what a value of 0 would give) is not computable, never reproduced."""
    inner = _program(
        _if(_apply("equal", _id("n"), _real(4)), _real(4)),
        _if(_apply("equal", _id("n"), _real(3)), _real(3)),
        _if(_apply("greaterThan", _id("n"), _real(3)), _real(9)),
    )
    body = _program(_local(_id("k"), inner), _apply("plus", _id("k"), _real(1)))
    _import(
        tmp_path,
        capsys,
        "inner",
        _function(1, "f", ["n"], body),
        _eval(2, _call("f", _real(4)), _real(10)),
        _eval(3, _call("f", _real(3)), _real(4)),
        _eval(4, _call("f", _real(2)), _real(1)),
    )
    result = _check(tmp_path, capsys, "inner")
    counts = (result["reproduced"], result["failed"], result["not_computable"])
    assert counts == (2, 0, 1), result["failures"]


def test_a_local_program_that_reads_a_local_is_refused(tmp_path, capsys):
    """g(n) := | s <- n ; k <- (| s if s > 1 ; 0 otherwise) ; k: the inner program reads the
    local s, which it would need as an argument: the function is listed as not translated."""
    inner = _program(_if(_apply("greaterThan", _id("s"), _real(1)), _id("s")), _otherwise(_real(0)))
    body = _program(_local(_id("s"), _id("n")), _local(_id("k"), inner), _id("k"))
    text = _import(
        tmp_path,
        capsys,
        "reads",
        _function(1, "g", ["n"], body),
        _eval(2, _call("g", _real(3)), _real(3)),
    )
    assert "a program as the value of a local that reads or sets the program's s" in text


def _seq(*args: str) -> str:
    return f"<ml:sequence>{''.join(args)}</ml:sequence>"


def test_matrix_of_a_size_the_program_computes(tmp_path, capsys):
    """n := 10 on the sheet; f(n) := | c <- 2n ; g(x, y) <- c ; M <- matrix(n, 2, g) ;
    [a; b] <- [matrix(n, 1, g); 7] ; M[n-1, 1] + rows(a) + b: the size is the parameter n
    (never the sheet's 10), the elements g(i, j) = c (a local given once before g), so
    f(3) = 6 + 3 + 7 = 16 and f(4) = 8 + 4 + 7 = 19."""
    n = _id("n")
    body = _program(
        _local(_id("c"), _apply("mult", _real(2), n)),
        _local(_function_lhs("g", "x", "y"), _id("c")),
        _local(_id("M"), _call("matrix", _seq(n, _real(2), _id("g")))),
        _local(
            _matrix(_id("a"), _id("b")),
            _matrix(_call("matrix", _seq(n, _real(1), _id("g"))), _real(7)),
        ),
        _apply(
            "plus",
            _apply(
                "plus",
                _index(_id("M"), _apply("minus", n, _real(1)), _real(1)),
                _call("rows", _id("a")),
            ),
            _id("b"),
        ),
    )
    text = _import(
        tmp_path,
        capsys,
        "sized",
        _define(1, _id("n"), _real(10)),
        _function(2, "f", ["n"], body),
        _eval(3, _call("f", _real(3)), _real(16)),
        _eval(4, _call("f", _real(4)), _real(19)),
    )
    assert "for j in 0 .. 2 - 1" in text  # the elements set one by one
    result = _check(tmp_path, capsys, "sized")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


def test_a_local_function_reading_a_local_set_twice_is_refused(tmp_path, capsys):
    """h(n) := | c <- n ; c <- c + 1 ; g(x) <- c ; g(0): c has two values in the program,
    and which one Mathcad's g reads where it is called is not known: not translated."""
    body = _program(
        _local(_id("c"), _id("n")),
        _local(_id("c"), _apply("plus", _id("c"), _real(1))),
        _local(_function_lhs("g", "x"), _id("c")),
        _call("g", _real(0)),
    )
    text = _import(
        tmp_path,
        capsys,
        "twice",
        _function(1, "h", ["n"], body),
        _eval(2, _call("h", _real(1)), _real(2)),
    )
    assert "a local function that reads the program's c, which the program sets more" in text


def _function_lhs(name: str, *params: str) -> str:
    bound = "".join(_id(p) for p in params)
    return f"<ml:function>{_id(name)}<ml:boundVars>{bound}</ml:boundVars></ml:function>"


def test_a_matrix_of_names_defined_with_its_value_shown(tmp_path, capsys):
    """[a; b] := [3; 4·2] = [3; 8] (Prime shows the right side's value): the value compared
    element by element, and a + b = 11 reads the names."""
    lhs = _matrix(_id("a"), _id("b"))
    rhs = _matrix(_real(3), _apply("mult", _real(4), _real(2)))
    shown = f"<ml:eval>{rhs}<ml:result>{_matrix(_real(3), _real(8))}</ml:result></ml:eval>"
    _import(
        tmp_path,
        capsys,
        "names",
        _define(1, lhs, shown),
        _eval(2, _apply("plus", _id("a"), _id("b")), _real(11)),
    )
    result = _check(tmp_path, capsys, "names")
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]
