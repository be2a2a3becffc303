"""The importer's maps (names, units, functions) and its handling of Mathcad's order."""

from __future__ import annotations

import base64
import gzip
import json
import math
import struct

import pytest
from helpers.mathcad import bare_worksheet as _worksheet
from helpers.mathcad import region as _region
from helpers.mathcad_xml import apply as _apply
from helpers.mathcad_xml import ident as _id
from helpers.mathcad_xml import real as _real
from helpers.paths import SHARED

from workbook.cli import main
from workbook.language import units as un
from workbook.mathcad.functions import MATHCAD_FUNCTIONS
from workbook.mathcad.names import identifier
from workbook.mathcad.units import FORMULA_UNITS


@pytest.mark.parametrize(
    "text, sub, expected",
    [
        ("v", "b", "v_b"),
        ("ρ", "", "rho"),
        ("σ", "m.α.d", "sigma_m_alpha_d"),
        ("f", "m.d.Ø", "f_m_d_Oe"),
        ("z", "0.II", "z_0_II"),
        ("in", "", "in_"),
        ("Δ", "", "Delta"),
        ("точка", "", "tochka"),
    ],
)
def test_names(text, sub, expected):
    assert identifier(text, sub) == expected


@pytest.mark.parametrize("name", sorted(FORMULA_UNITS))
def test_every_mathcad_unit_is_a_pint_unit(name):
    un.registry().Unit(FORMULA_UNITS[name])


def test_mathcad_units_agree_with_their_definitions():
    q = un.registry().Quantity
    assert q(1, FORMULA_UNITS["kgf"]).to("N").magnitude == pytest.approx(9.80665, rel=1e-12)
    assert q(1, FORMULA_UNITS["L"]).to("m**3").magnitude == pytest.approx(1e-3, rel=1e-12)
    assert q(1, FORMULA_UNITS["psi"]).to("Pa").magnitude == pytest.approx(6894.757, rel=1e-6)


def test_function_map_is_one_to_one_onto_names():
    targets = [t for t, _ in MATHCAD_FUNCTIONS.values()]
    assert all(t.isidentifier() for t in targets)
    assert MATHCAD_FUNCTIONS["log"][0] == "log10"  # Mathcad's log is base 10
    assert MATHCAD_FUNCTIONS["atan2"] == ("atan2", None)  # atan2(x, y) in both


ML = "http://schemas.mathsoft.com/math30"


def _eval(rid: int, body: str, result: str) -> str:
    return (
        f'<region region-id="{rid}" left="0" top="{rid * 20}" align-y="{rid * 20}">'
        f'<math><ml:eval xmlns:ml="{ML}">{body}<ml:result>{result}</ml:result></ml:eval>'
        "</math></region>"
    )


@pytest.mark.slow
def test_redefinitions_read_the_definition_in_force(tmp_path, capsys):
    """x := 2, y := x^2, x := 5, then y = and x*y = : Mathcad's order decides."""
    src = tmp_path / "order.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("x") + _real(2)),
            _region(2, _id("y") + _apply("pow", _id("x"), _real(2))),
            _region(3, _id("x") + _real(5)),
            _eval(4, _id("y"), _real(4)),
            _eval(5, _apply("mult", _id("x"), _id("y")), _real(20)),
            _eval(6, _id("q"), _real(1)),  # q is defined nowhere: listed, not computable
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "1 regions not translated" in capsys.readouterr().out
    main(["check", str(tmp_path / "order.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (3, 2, 1)
    text = (tmp_path / "order.toml").read_text(encoding="utf-8")
    assert "region 6: an evaluation ( = ): q is not defined before it is used" in text


def _function(rid: int, name: str, params: list[str], body: str) -> str:
    bound = "".join(_id(p) for p in params)
    return (
        f'<region region-id="{rid}" left="0" top="{rid * 20}" align-y="{rid * 20}"><math>'
        f'<ml:define xmlns:ml="{ML}"><ml:function>{_id(name)}<ml:boundVars>{bound}'
        f"</ml:boundVars></ml:function>{body}</ml:define></math></region>"
    )


@pytest.mark.slow
def test_function_argument_takes_the_unit_it_is_called_with(tmp_path, capsys):
    """M(x) := q*x*(L - x)/2 with q = 10 kN/m, L = 6 m; M(3 m) = 45 kN*m as Mathcad stored."""
    stored = (
        '<ml:unitedValue><ml:real>45</ml:real><u:unitMonomial xmlns:u="http://schemas.mathsoft.'
        'com/units10"><u:unitReference unit="kilonewton"/><u:unitReference unit="meter"/>'
        "</u:unitMonomial></ml:unitedValue>"
    )
    call = f"<ml:apply>{_id('M')}{_apply('mult', _real(3), _id('m'))}</ml:apply>"
    src = tmp_path / "beam.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("q") + _apply("mult", _real(10), _apply("div", _id("kN"), _id("m")))),
            _region(2, _id("L") + _apply("mult", _real(6), _id("m"))),
            _function(
                3,
                "M",
                ["x"],
                _apply(
                    "div",
                    _apply(
                        "mult",
                        _apply("mult", _id("q"), _id("x")),
                        _apply("minus", _id("L"), _id("x")),
                    ),
                    _real(2),
                ),
            ),
            _eval(4, call, stored),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "beam.toml").read_text(encoding="utf-8")
    assert 'x = { unit = "m" }' in text
    assert 'm_unit = { value = "1 m"' in text  # m and M are one name in Excel
    capsys.readouterr()
    main(["check", str(tmp_path / "beam.toml"), "--json"])
    assert json.loads(capsys.readouterr().out)["reproduced"] == 1


@pytest.mark.slow
def test_printed_text_where_the_sheet_computes_a_number_fails(tmp_path, capsys):
    """A printed text ("OK", as Mathcad shows) is compared as text: a number is a FAIL."""
    (tmp_path / "t.toml").write_text(
        '[inputs]\nx = "2"\n\n[[printed]]\nfile = "t.csv"\n', encoding="utf-8"
    )
    (tmp_path / "t.csv").write_text('name,argument,value,unit\nx,,"OK",\nx,,2,\n', encoding="utf-8")
    assert main(["check", str(tmp_path / "t.toml"), "--json"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 1, 1)
    assert result["failures"][0]["printed"] == "OK"


@pytest.mark.slow
def test_given_find_in_one_unknown_is_a_root_from_the_guess(tmp_path, capsys):
    """x := 1, Given x^2 = 2, s := Find(x) = sqrt(2): root(x^2 - 2, x, guess)."""
    import math

    given = '<region region-id="2" left="0" top="40" align-y="40"><math>' + (
        f'<ml:id xmlns:ml="{ML}">Given</ml:id></math></region>'
    )
    equation = '<region region-id="3" left="0" top="60" align-y="60"><math>' + (
        f'<ml:apply xmlns:ml="{ML}"><ml:equal/>{_apply("pow", _id("x"), _real(2))}'
        f"{_real(2)}</ml:apply></math></region>"
    )
    find = f"<ml:apply><ml:Find/>{_id('x')}</ml:apply>"
    src = tmp_path / "solve.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("x") + _real(1)),
            given,
            equation,
            _region(
                4,
                _id("s") + f"<ml:eval>{find}<ml:result>{_real(math.sqrt(2))}</ml:result></ml:eval>",
            ),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "0 regions not translated" in capsys.readouterr().out
    text = (tmp_path / "solve.toml").read_text(encoding="utf-8")
    assert 'unknowns = { x_2 = "1.0" }' in text and 'equations = ["x_2^2 == 2"]' in text
    assert 's = { expr = "x_2"' in text
    main(["check", str(tmp_path / "solve.toml"), "--json"])
    assert json.loads(capsys.readouterr().out)["reproduced"] == 1


@pytest.mark.slow
def test_program_with_a_loop(tmp_path, capsys):
    """s(n) := | a <- 0 ; for i in 1..n: a <- a + i ; a |, and s(4) = 10 as stored."""
    loop = (
        f"<ml:for>{_id('i')}<ml:range>{_real(1)}{_id('n')}</ml:range>"
        f"<ml:localDefine>{_id('a')}{_apply('plus', _id('a'), _id('i'))}</ml:localDefine>"
        "</ml:for>"
    )
    start = f"<ml:localDefine>{_id('a')}{_real(0)}</ml:localDefine>"
    program = f"<ml:program>{start}{loop}{_id('a')}</ml:program>"
    call = f"<ml:apply>{_id('s')}{_real(4)}</ml:apply>"
    src = tmp_path / "loop.xmcd"
    src.write_text(
        _worksheet(_function(1, "s", ["n"], program), _eval(2, call, _real(10))),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "0 regions not translated" in capsys.readouterr().out
    text = (tmp_path / "loop.toml").read_text(encoding="utf-8")
    assert "for i in 1 .. n" in text
    main(["check", str(tmp_path / "loop.toml"), "--json"])
    assert json.loads(capsys.readouterr().out)["reproduced"] == 1


@pytest.mark.slow
def test_element_assignment_makes_and_grows_a_vector(tmp_path, capsys):
    """Mathcad makes v by v[2] <- n (the gap filled with 0): g(5) = [0, 0, 5] as Mathcad
    stored it; v[n] <- n (a length known only when the program runs) is a run-time array."""

    def grow(index: str) -> str:
        return (
            f"<ml:program><ml:localDefine><ml:apply><ml:indexer/>{_id('v')}{index}</ml:apply>"
            f"{_id('n')}</ml:localDefine>{_id('v')}</ml:program>"
        )

    call = "<ml:apply>" + _id("g") + _real(5) + "</ml:apply>"
    src = tmp_path / "grow.xmcd"
    src.write_text(
        _worksheet(
            _function(1, "g", ["n"], grow(_real(2))),
            _function(2, "h", ["n"], grow(_id("n"))),
            _eval(3, call, _matrix_result(0, 0, 5)),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "grow.toml").read_text(encoding="utf-8")
    assert "v[2] := n" in text
    assert "v[n] := n" in text and "region 2: h" not in text
    main(["check", str(tmp_path / "grow.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (3, 3), result["failures"]


@pytest.mark.slow
def test_matrix_column_is_a_submatrix(tmp_path, capsys):
    """M := [[1, 2], [3, 4], [5, 6]] (stored column by column), max(M<1>) = 6 and the column
    itself, at ORIGIN 0: Mathcad's stored values are reproduced."""
    matrix = '<ml:matrix rows="3" cols="2">' + "".join(_real(v) for v in (1, 3, 5, 2, 4, 6))
    src = tmp_path / "col.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("M") + matrix + "</ml:matrix>"),
            _eval(2, _apply("matcol", _id("M"), _real(1)), _matrix_result(2, 4, 6)),
            _eval(
                3,
                "<ml:apply>" + _id("max") + _apply("matcol", _id("M"), _real(1)) + "</ml:apply>",
                _real(6),
            ),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "col.toml").read_text(encoding="utf-8")
    assert "max(submatrix(M, 0, rows(M) - 1, 1, 1))" in text
    main(["check", str(tmp_path / "col.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (4, 4), result["failures"]


def _matrix_result(*values) -> str:
    cells = "".join(_real(v) for v in values)
    return f'<ml:matrix rows="{len(values)}" cols="1">{cells}</ml:matrix>'


def _extremum(op: str, f: str, x: str) -> str:
    return (
        f'<ml:apply><ml:{op} method="conjugate"/><ml:sequence>{_id(f)}{_id(x)}'
        "</ml:sequence></ml:apply>"
    )


@pytest.mark.slow
def test_maximize_and_minimize_from_a_guess(tmp_path, capsys):
    """f(x) := x (10 - x) - 4 has its largest value at 5 (a root of its slope where it curves
    down), g(x) := cos(x) from the guess 2 its smallest at pi (not 0 or 2 pi, maxima); the
    stored results are Mathcad's values."""
    f = _apply("minus", _apply("mult", _id("x"), _apply("minus", _real(10), _id("x"))), _real(4))
    src = tmp_path / "extremum.xmcd"
    src.write_text(
        _worksheet(
            _function(1, "f", ["x"], f),
            _function(2, "g", ["x"], "<ml:apply>" + _id("cos") + _id("x") + "</ml:apply>"),
            _region(3, _id("x") + _real(1)),
            _eval(4, _extremum("Maximize", "f", "x"), _real(5)),
            _region(5, _id("x") + _real(2)),
            _eval(6, _extremum("Minimize", "g", "x"), _real(3.1415926535897931)),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "extremum.toml").read_text(encoding="utf-8")
    assert 'conditions = ["f_curvature(x_2) < 0"]' in text
    main(["check", str(tmp_path / "extremum.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


def _metres(inner: str) -> str:
    return (
        f'<ml:unitedValue>{inner}<u:unitMonomial xmlns:u="http://schemas.mathsoft.com/units10">'
        '<u:unitReference unit="meter"/></u:unitMonomial></ml:unitedValue>'
    )


@pytest.mark.slow
def test_functions_of_vectors_translate(tmp_path, capsys):
    """P := (3, 4) m, Q := (0, 1) m, dist(a, b) := |a - b|, y(v) := v[1], twice(v) := 2 v:
    Mathcad's |x| of a vector is its length; the stored results are reproduced."""

    def vec(*values) -> str:
        cells = "".join(_real(v) for v in values)
        return f'<ml:matrix rows="{len(values)}" cols="1">{cells}</ml:matrix>'

    def call(f, *args) -> str:
        return f"<ml:apply>{_id(f)}{''.join(args)}</ml:apply>"

    src = tmp_path / "points.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("P") + _apply("mult", vec(3, 4), _id("m"))),
            _region(2, _id("Q") + _apply("mult", vec(0, 1), _id("m"))),
            _function(3, "dist", ["a", "b"], _apply("absval", _apply("minus", _id("a"), _id("b")))),
            _function(4, "y", ["v"], _apply("indexer", _id("v"), _real(1))),
            _function(5, "twice", ["v"], _apply("mult", _real(2), _id("v"))),
            _eval(6, call("dist", _id("P"), _id("Q")), _metres(_real(math.sqrt(18)))),
            _eval(7, call("y", _id("P")), _metres(_real(4))),
            _eval(8, call("twice", _id("P")), _metres(vec(6, 8))),
            _eval(9, _apply("absval", _real(-2)), _real(2)),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "points.toml").read_text(encoding="utf-8")
    assert "mag(a - b)" in text and "abs(-2)" in text
    main(["check", str(tmp_path / "points.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (5, 5), result["failures"]


@pytest.mark.slow
def test_writeprn_is_the_value_written(tmp_path, capsys):
    """WRITEPRN("a.prn", M) = M (Mathcad 15's form) and WRITEPRN("b.prn") := v (older
    worksheets): each value written is a definition of its own with a note naming the file,
    and Mathcad's stored result of the first is compared; no file is written."""
    matrix = '<ml:matrix rows="2" cols="2">' + "".join(_real(v) for v in (1, 3, 2, 4))
    matrix += "</ml:matrix>"
    call = (
        f"<ml:apply>{_id('WRITEPRN')}<ml:sequence><ml:str>a.prn</ml:str>"
        f"{_id('M')}</ml:sequence></ml:apply>"
    )
    old = f"<ml:apply>{_id('WRITECSV')}<ml:str>b.csv</ml:str></ml:apply>"
    src = tmp_path / "write.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("M") + matrix),
            _eval(2, call, matrix),
            _region(3, old + _apply("mult", _real(2), _id("M"))),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "0 regions not translated" in capsys.readouterr().out
    text = (tmp_path / "write.toml").read_text(encoding="utf-8")
    assert 'written_1 = { expr = "M"' in text and 'written_2 = { expr = "2 * M"' in text
    assert 'WRITEPRN wrote this value to the file "a.prn"' in text
    assert 'WRITECSV wrote this value to the file "b.csv"' in text
    main(["check", str(tmp_path / "write.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (4, 4), result["failures"]
    assert not (tmp_path / "a.prn").exists() and not (tmp_path / "b.csv").exists()


@pytest.mark.slow
def test_writeprn_of_another_value_fails_the_check(tmp_path, capsys):
    """A stored result that is not the value written is reported as failed, not passed."""
    call = (
        f"<ml:apply>{_id('WRITEPRN')}<ml:sequence><ml:str>a.prn</ml:str>"
        f"{_real(2)}</ml:sequence></ml:apply>"
    )
    src = tmp_path / "wrong.xmcd"
    src.write_text(_worksheet(_eval(1, call, _real(3))), encoding="utf-8")
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    main(["check", str(tmp_path / "wrong.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["failed"]) == (1, 1), result


def _compound_file(contents: bytes) -> bytes:
    """A minimal OLE compound file (version 3) whose stream Contents lies in the mini
    stream in pieces stored in reverse order (read by its mini FAT chain, not in place)."""
    end, free = 0xFFFFFFFE, 0xFFFFFFFF
    pieces = [contents[i : i + 64].ljust(64, b"\0") for i in range(0, len(contents), 64)]
    n = len(pieces)
    slots = list(reversed(range(n)))  # piece k is stored in mini sector slots[k]
    ministream = bytearray(64 * n)
    minifat = [free] * 128
    for k, slot in enumerate(slots):
        ministream[slot * 64 : (slot + 1) * 64] = pieces[k]
        minifat[slot] = slots[k + 1] if k + 1 < n else end
    ministream = bytes(ministream).ljust(-(-len(ministream) // 512) * 512, b"\0")
    n_mini_sectors = len(ministream) // 512
    fat = [0xFFFFFFFD, end, end] + [4 + i for i in range(n_mini_sectors - 1)] + [end]
    fat += [free] * (128 - len(fat))

    def entry(name: str, kind: int, start: int, size: int) -> bytes:
        raw = (name + "\0").encode("utf-16-le")
        e = raw.ljust(64, b"\0") + struct.pack("<HBB", len(raw), kind, 1)
        e += struct.pack("<III", free, free, 1 if kind == 5 else free)
        return e.ljust(116, b"\0") + struct.pack("<III", start, size, 0)

    directory = entry("Root Entry", 5, 3, 64 * n) + entry("Contents", 2, slots[0], len(contents))
    header = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(16)
    header += struct.pack("<HHHHH6sIIII", 0x3E, 3, 0xFFFE, 9, 6, bytes(6), 0, 1, 1, 0)
    header += struct.pack("<IIIII", 4096, 2, 1, end, 0)
    header += struct.pack("<109I", 0, *[free] * 108)
    sectors = [struct.pack("<128I", *fat), directory.ljust(512, b"\0")]
    sectors += [struct.pack("<128I", *minifat), ministream]
    return header + b"".join(sectors)


def _table_item(rows: list[list[float]], count: int | None = None) -> str:
    """A data table's binary item (base64 of gzip), its cells stored column by column."""
    values = [rows[r][c] for c in range(len(rows[0])) for r in range(len(rows))]
    count = len(values) if count is None else count
    block = bytes.fromhex("00548cc93163d011a68d00a024cf05d1")
    block += struct.pack("<9I", 1, 1, 8, 2, 0, 0, len(rows[0]) - 1, len(rows) - 1, count)
    block += struct.pack(f"<{len(values)}d", *values)
    contents = b"formatting" + struct.pack("<I", len(block)) + block + b"end"
    cfb = _compound_file(contents)
    return base64.b64encode(gzip.compress(b"record" + struct.pack("<I", len(cfb)) + cfb)).decode()


TABLE = "01350081-1122-11DB-9380-000D56C6051A"


def _component(rid: int, item: int, name: str, clsid: str = TABLE) -> str:
    return (
        f'<region region-id="{rid}" left="0" top="{rid * 20}" align-y="{rid * 20}">'
        f'<component clsid-buddy="{clsid}" item-idref="{item}" disable-calc="false"><inputs/>'
        f'<outputs><ml:id xmlns:ml="{ML}">{name}</ml:id></outputs></component></region>'
    )


def _with_items(sheet: str, items: dict[int, str]) -> str:
    body = "".join(
        f'<item item-id="{k}" content-encoding="gzip">{v}</item>' for k, v in items.items()
    )
    return sheet.replace("</worksheet>", f"<binaryContent>{body}</binaryContent></worksheet>")


@pytest.mark.slow
def test_data_table_is_a_matrix(tmp_path, capsys):
    """S, a data table of 2 x 3 numbers (a negative one, fractions), and v, one of a single
    column: S becomes a matrix by rows, v a column vector; Mathcad's stored S = and v[1] =
    are reproduced; a component of another kind and a table whose cell count does not
    match its grid stay untranslated, with their reason."""
    s_rows = [[1.5, -2.0, 3.0], [4.0, 0.25, 6e-3]]
    v_rows = [[10.0], [20.0], [30.0]]
    stored = '<ml:matrix rows="2" cols="3">' + "".join(
        _real(s_rows[r][c]) for c in range(3) for r in range(2)
    )
    src = tmp_path / "table.xmcd"
    sheet = _worksheet(
        _component(1, 1, "S"),
        _component(2, 2, "v"),
        _component(3, 3, "X", clsid="00000000-0000-0000-0000-000000000000"),
        _component(4, 4, "B"),
        _eval(5, _id("S"), stored + "</ml:matrix>"),
        _eval(6, _apply("indexer", _id("v"), _real(1)), _real(20)),
    )
    items = {
        1: _table_item(s_rows),
        2: _table_item(v_rows),
        3: _table_item(v_rows),
        4: _table_item(v_rows, count=2),
    }
    src.write_text(_with_items(sheet, items), encoding="utf-8")
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "2 regions not translated" in capsys.readouterr().out
    text = (tmp_path / "table.toml").read_text(encoding="utf-8")
    assert 'S = { expr = "[[1.5, -2, 3], [4, 0.25, 0.006]]"' in text
    assert 'v = { expr = "[10, 20, 30]"' in text
    assert "region 3: a component defining X: not translated" in text
    assert "region 4: a component defining B: a data table whose binary item" in text
    main(["check", str(tmp_path / "table.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (7, 7), result["failures"]


@pytest.mark.parametrize(
    "data, reason",
    [
        (b"not gzip at all", "a data table whose binary item is not gzip"),
        (gzip.compress(b"a record and no compound file", mtime=0), "no OLE compound file"),
        (
            gzip.compress(b"rec\x00\x10\x00\x00\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1", mtime=0),
            "cut short",
        ),
    ],
    ids=["not gzip", "no compound file", "cut short"],  # the same ids in every process
)
def test_broken_data_table_is_listed_with_why(data, reason):
    """A table item that is not gzip, holds no compound file, or is cut short: refused with
    the reason, never a guessed grid."""
    from workbook.mathcad.symbols import Untranslatable
    from workbook.mathcad.table import grid

    encoded = base64.b64encode(data).decode()
    with pytest.raises(Untranslatable, match=reason):
        grid(encoded)


def test_data_table_with_a_cyclic_sector_chain_is_refused():
    """A mini FAT chain that loops back on itself ends with a clear reason, in bounded time."""
    from workbook.mathcad.symbols import Untranslatable
    from workbook.mathcad.table import grid

    raw = base64.b64decode(_table_item([[1.0, 2.0], [3.0, 4.0]]))
    data = gzip.decompress(raw)
    at = data.index(b"\xd0\xcf\x11\xe0")
    minifat = at + 512 + 2 * 512  # the third sector: the mini FAT
    # two pieces, stored in mini sectors 1 then 0: 0 ends the chain; make it point to 1
    assert struct.unpack_from("<2I", data, minifat) == (0xFFFFFFFE, 0)
    looped = data[:minifat] + struct.pack("<I", 1) + data[minifat + 4 :]
    with pytest.raises(Untranslatable, match="broken sector chain"):
        grid(base64.b64encode(gzip.compress(looped)).decode())


@pytest.mark.slow
def test_a_function_that_calls_itself_is_a_recursion(tmp_path, capsys):
    """fact(n) := 1 if n <= 1, n*fact(n - 1) otherwise; fact(6) = 720 as Mathcad stored."""
    program = (
        "<ml:program><ml:ifThen>"
        + _apply("lessOrEqual", _id("n"), _real(1))
        + _real(1)
        + "</ml:ifThen><ml:otherwise>"
        + _apply(
            "mult",
            _id("n"),
            "<ml:apply>" + _id("fact") + _apply("minus", _id("n"), _real(1)) + "</ml:apply>",
        )
        + "</ml:otherwise></ml:program>"
    )
    src = tmp_path / "fact.xmcd"
    call = "<ml:apply>" + _id("fact") + _real(6) + "</ml:apply>"
    src.write_text(
        _worksheet(_function(1, "fact", ["n"], program), _eval(2, call, _real(720))),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    assert "0 regions not translated" in capsys.readouterr().out
    main(["check", str(tmp_path / "fact.toml"), "--json"])
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"]) == (1, 1), result["failures"]


def test_compound_result_unit_names():
    from workbook.mathcad.units import result_unit

    assert un.registry().Unit(result_unit("kiloNewton_meter")) == un.registry().Unit("kN*m")
    assert result_unit("Ms") == "Ms"  # a symbol is never lowered (Ms is not ms)


@pytest.mark.slow
def test_a_result_in_an_unknown_unit_costs_only_that_result(tmp_path, capsys):
    """x := 2 (stored in a unit no registry knows) and y := 3 (stored plainly): the check
    compares y, lists x's result, and does not stop."""
    odd = (
        '<ml:unitedValue><ml:real>2</ml:real><u:unitMonomial xmlns:u="http://schemas.mathsoft.'
        'com/units10"><u:unitReference unit="furlongFortnightXyz"/></u:unitMonomial>'
        "</ml:unitedValue>"
    )
    src = tmp_path / "odd.xmcd"
    src.write_text(
        _worksheet(
            _region(1, _id("x") + _real(2)),
            _region(2, _id("y") + _real(3)),
            _eval(3, _id("x"), odd),
            _eval(4, _id("y"), _real(3)),
        ),
        encoding="utf-8",
    )
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "odd.toml").read_text(encoding="utf-8")
    assert "its unit 'furlongfortnightxyz' is not a unit the engine knows" in text
    capsys.readouterr()
    assert main(["check", str(tmp_path / "odd.toml"), "--json"]) == 1  # one not computable
    result = json.loads(capsys.readouterr().out)
    assert (result["printed"], result["reproduced"], result["not_computable"]) == (2, 1, 1)


@pytest.mark.skipif(not SHARED.is_dir(), reason="../shared is absent")
def test_every_unit_name_of_both_corpora_is_mapped():
    """Every unit named in a stored result (unitReference) and every name Prime labels a
    unit in a formula, in ../shared/mathcad and ../shared/mathcad-prime, is a pint unit."""
    import re
    import zipfile

    from workbook.mathcad.units import result_unit

    texts = [p.read_text("utf-8", "replace") for p in (SHARED / "mathcad").rglob("*.xmcd")]
    for p in (SHARED / "mathcad-prime").glob("*.mcdx"):
        with zipfile.ZipFile(p) as z:
            texts += [z.read(n).decode("utf-8-sig") for n in z.namelist() if n.endswith(".xml")]
    results = {n for t in texts for n in re.findall(r'unitReference unit="([^"]+)"', t)}
    formulas = {
        n for t in texts for n in re.findall(r'<ml:id[^>]*labels="UNIT"[^>]*>([^<]+)</ml:id>', t)
    }
    assert len(results) > 5 and len(formulas) > 5
    for name in sorted(results):
        un.registry().Unit(result_unit(name))
    assert sorted(formulas - set(FORMULA_UNITS)) == []


def test_g_is_the_acceleration_of_gravity_and_gm_the_gram(tmp_path, capsys):
    """Mathcad's unit list: g is the acceleration of gravity (9.80665 m/s^2) and gm the gram;
    W := 2 kg·g = 19.6133 N, m := 500 gm = 0.5 kg."""
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

    kg_g = apply("mult", apply("mult", real(2), ident("kg")), ident("g"))
    import_sheet(
        tmp_path,
        capsys,
        "gravity",
        define(1, ident("W"), kg_g),
        define(2, ident("m"), apply("mult", real(500), ident("gm"))),
        evaluate(3, ident("W"), united(2 * 9.80665, ("kg", 1), ("m", 1), ("s", -2))),
        evaluate(4, ident("m"), united(0.5, ("kg", 1))),
    )
    result = check_sheet(tmp_path, capsys, "gravity")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]


def test_strlen_and_substr_are_mathcads_text_functions(tmp_path, capsys):
    """Mathcad's substr(S, m, n) counts positions from 0 whatever ORIGIN is, as the
    language's; the stored results of both are reproduced."""
    from helpers.mathcad_xml import check_sheet, define, evaluate, ident, import_sheet, real

    text = "<ml:str>{}</ml:str>".format
    cut = f"<ml:apply>{ident('substr')}<ml:sequence>{ident('s')}{real(1)}{real(3)}</ml:sequence></ml:apply>"  # noqa: E501
    size = f"<ml:apply>{ident('strlen')}{ident('s')}</ml:apply>"
    toml = import_sheet(
        tmp_path,
        capsys,
        "strings",
        define(1, ident("s"), text("abcdef")),
        evaluate(2, cut, text("bcd")),
        evaluate(3, size, real(6)),
        origin=1,
    )
    assert "substr(s, 1, 3)" in toml and "strlen(s)" in toml
    result = check_sheet(tmp_path, capsys, "strings")
    assert (result["printed"], result["reproduced"]) == (2, 2), result["failures"]
