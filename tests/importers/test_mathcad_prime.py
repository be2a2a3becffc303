"""`workbook import` of Mathcad Prime worksheets (.mcdx), checked against Prime's stored results."""

from __future__ import annotations

import io
import re
import zipfile
from pathlib import Path

import pytest
from helpers.mathcad import check_json as _check
from helpers.mathcad import prime_ident as _id
from helpers.mathcad_xml import prime_package as _package
from helpers.mathcad_xml import prime_region as _region
from helpers.mathcad_xml import prime_result as _result
from helpers.paths import SHARED

from workbook.cli import main

PRIME = SHARED / "mathcad-prime"
needs_corpus = pytest.mark.skipif(not PRIME.is_dir(), reason=f"{PRIME} is absent")

SPAN = (
    '<Span xmlns="http://schemas.microsoft.com/winfx/2006/xaml/presentation" '
    'xmlns:pw="clr-namespace:Ptc.Wpf;assembly=Ptc.Core">{}<pw:Subscript>{}</pw:Subscript></Span>'
)


def _unit(name: str) -> str:
    return f'<ml:id labels="UNIT">{name}</ml:id>'


@pytest.mark.slow
def test_prime_results_in_their_displayed_unit(tmp_path, capsys):
    """q_k := 15.8 kg/m * 10 N/kg = ? kN/m stores 0.158 (the override's unit); M := 637 kN *
    1.92 m = ? kN stores 1223.04 with the residual unit meter; K := 2500 = ? 10^3 stores 2.5;
    a := 103.2 deg = stores radians; L := 2 m = (no unit typed) stores meters."""
    name = SPAN.format("q", "k")
    q_body = (
        "<ml:apply><ml:mult/><ml:apply><ml:div/><ml:apply><ml:scale/><ml:real>15.8</ml:real>"
        f"{_unit('kg')}</ml:apply>{_unit('m')}</ml:apply><ml:apply><ml:div/><ml:apply>"
        f"<ml:scale/><ml:real>10</ml:real>{_unit('N')}</ml:apply>{_unit('kg')}</ml:apply>"
        "</ml:apply>"
    )
    kn_per_m = f"<ml:apply><ml:div/>{_unit('kN')}{_unit('m')}</ml:apply>"
    m_body = (
        f"<ml:apply><ml:mult/><ml:apply><ml:scale/><ml:real>637</ml:real>{_unit('kN')}"
        f"</ml:apply><ml:apply><ml:scale/><ml:real>1.92</ml:real>{_unit('m')}</ml:apply>"
        "</ml:apply>"
    )
    thousand = "<ml:apply><ml:pow/><ml:real>10</ml:real><ml:real>3</ml:real></ml:apply>"
    regions = "".join(
        [
            _region(
                1,
                1,
                f'<ml:define><ml:id labels="VARIABLE">{name}</ml:id><ml:eval>{q_body}'
                f"<ml:unitOverride>{kn_per_m}</ml:unitOverride></ml:eval></ml:define>",
            ),
            _region(
                2,
                2,
                f'<ml:define><ml:id labels="VARIABLE">M</ml:id><ml:eval>{m_body}'
                f"<ml:unitOverride>{_unit('kN')}</ml:unitOverride></ml:eval></ml:define>",
            ),
            _region(
                3,
                3,
                '<ml:define><ml:id labels="VARIABLE">K</ml:id><ml:eval><ml:real>2500</ml:real>'
                f"<ml:unitOverride>{thousand}</ml:unitOverride></ml:eval></ml:define>",
            ),
            _region(
                4,
                4,
                '<ml:define><ml:id labels="VARIABLE">a</ml:id><ml:eval><ml:apply><ml:scale/>'
                f"<ml:real>103.2</ml:real>{_unit('deg')}</ml:apply><ml:unitOverride>"
                "<ml:placeholder/></ml:unitOverride></ml:eval></ml:define>",
            ),
            _region(
                5,
                5,
                '<ml:define><ml:id labels="VARIABLE">L</ml:id><ml:eval><ml:apply><ml:scale/>'
                f"<ml:real>2</ml:real>{_unit('m')}</ml:apply><ml:unitOverride><ml:placeholder/>"
                "</ml:unitOverride></ml:eval></ml:define>",
            ),
        ]
    )
    meter = (
        '<u:unitMonomial><u:unitReference unit="meter" power-numerator="1" '
        'power-denominator="1"/></u:unitMonomial>'
    )
    results = "".join(
        [
            _result(1, "<ml:real>0.158</ml:real>"),
            _result(2, f"<ml:unitedValue><ml:real>1223.04</ml:real>{meter}</ml:unitedValue>"),
            _result(3, "<ml:real>2.5</ml:real>"),
            _result(4, "<ml:real>1.8011797880581482</ml:real>"),
            _result(5, f"<ml:unitedValue><ml:real>2</ml:real>{meter}</ml:unitedValue>"),
        ]
    )
    src = _package(tmp_path / "units.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "units.toml").read_text(encoding="utf-8")
    assert "q_k = " in text  # the literal subscript of Prime's XAML name
    result = _check(tmp_path / "units.toml", capsys)
    assert (result["printed"], result["reproduced"]) == (5, 5), result["failures"]


@pytest.mark.slow
def test_a_wrong_stored_value_is_a_failure_not_a_pass(tmp_path, capsys):
    """The comparison is real: 0.159 kN/m stored for 0.158 fails."""
    regions = _region(
        1,
        1,
        '<ml:define><ml:id labels="VARIABLE">q</ml:id><ml:eval><ml:apply><ml:scale/>'
        f"<ml:real>158</ml:real>{_unit('N')}</ml:apply><ml:unitOverride>{_unit('kN')}"
        "</ml:unitOverride></ml:eval></ml:define>",
    )
    src = _package(tmp_path / "wrong.mcdx", regions, _result(1, "<ml:real>0.159</ml:real>"))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "wrong.toml", capsys)
    assert (result["printed"], result["failed"]) == (1, 1)


def _bomb() -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("mathcad/worksheet.xml", b" " * 70_000_000)
    return buf.getvalue()


def _many() -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for k in range(5_001):
            z.writestr(f"p{k}", b"")
    return buf.getvalue()


def _with(worksheet: bytes) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("mathcad/worksheet.xml", worksheet)
    return buf.getvalue()


@pytest.mark.slow
@pytest.mark.parametrize(
    "data, message",
    [
        (b"not a zip", "not a Mathcad Prime worksheet"),
        (_bomb(), "unpacks to 70,000,000 bytes"),
        (_many(), "5,001 parts"),
        (_with(b"<x/>"), "the root element of mathcad/worksheet.xml is x"),
        (_with(b'<!DOCTYPE x [<!ENTITY a "b">]><x>&a;</x>'), "declares a DTD or entities"),
        (_with(b"<worksheet"), "not well-formed"),
    ],
    ids=["not-zip", "bomb", "members", "not-prime", "dtd", "truncated"],
)
def test_hostile_package_is_refused(data, message, tmp_path, capsys):
    src = tmp_path / "hostile.mcdx"
    src.write_bytes(data)
    assert main(["import", str(src), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert message in err and "hostile.mcdx" in err


SMALL = {  # file: (values stored, reproduced) as measured
    "api-basic-test.mcdx": (10, 10),
    "beam-elastic-foundation.mcdx": (4, 4),
    "nm-to-compression-tension.mcdx": (5, 5),
    "interpolation-task.mcdx": (21, 21),
}


@pytest.mark.slow
@needs_corpus
@pytest.mark.parametrize("name", sorted(SMALL))
def test_small_prime_worksheets_reproduce(name, tmp_path, capsys):
    assert main(["import", str(PRIME / name), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / (Path(name).stem + ".toml"), capsys)
    assert result["failed"] == 0, result["failures"]
    printed, reproduced = SMALL[name]
    assert result["printed"] == printed
    assert result["reproduced"] >= reproduced, result["failures"]


@needs_corpus
@pytest.mark.slow
@pytest.mark.parametrize(
    "name", sorted(p.name for p in PRIME.glob("*.mcdx")) if PRIME.is_dir() else []
)
def test_every_prime_worksheet_imports_and_none_is_wrong(name, tmp_path, capsys):
    """Every file imports (exit 0); every stored value is reproduced or not computable (its
    region listed), none different; no internal token of a name reaches the text."""
    assert main(["import", str(PRIME / name), "--out", str(tmp_path)]) == 0
    toml = tmp_path / (Path(name).stem + ".toml")
    assert not re.search(r"\\u0000|\x00", toml.read_text(encoding="utf-8"))
    result = _check(toml, capsys)
    assert result["reproduced"] + result["not_computable"] == result["printed"], result["failures"]


def _eval(rid: int, body: str) -> str:
    return _region(
        rid, rid, f"<ml:eval>{body}<ml:unitOverride><ml:placeholder/></ml:unitOverride></ml:eval>"
    )


@pytest.mark.slow
def test_constants_labels_and_if_chains(tmp_path, capsys):
    """g labelled CONSTANT is standard gravity (not the gram), g labelled VARIABLE and not
    defined is not a unit either (listed); f(x) := if x > 2: 10 else if x > 0: 20 else 30 takes
    the first true branch: f(3) = 10, f(1) = 20, f(-1) = 30."""
    branch = "<ml:then><ml:program>{}</ml:program></ml:then>"
    chain = (
        f"<ml:if><ml:test><ml:apply><ml:greaterThan/>{_id('x')}<ml:real>2</ml:real></ml:apply>"
        f"</ml:test>{branch.format('<ml:real>10</ml:real>')}<ml:elseif><ml:test><ml:apply>"
        f"<ml:greaterThan/>{_id('x')}<ml:real>0</ml:real></ml:apply></ml:test>"
        f"{branch.format('<ml:real>20</ml:real>')}</ml:elseif><ml:else><ml:program>"
        "<ml:real>30</ml:real></ml:program></ml:else></ml:if>"
    )
    f_def = _region(
        1,
        1,
        f"<ml:define><ml:function>{_id('f')}<ml:boundVars>{_id('x')}</ml:boundVars>"
        f"</ml:function>{chain}</ml:define>",
    )

    def call(v: str) -> str:
        return f"<ml:apply>{_id('f', 'FUNCTION')}<ml:sequence>{v}</ml:sequence></ml:apply>"

    minus_one = "<ml:apply><ml:neg/><ml:real>1</ml:real></ml:apply>"
    regions = f_def + "".join(
        [
            _eval(2, call("<ml:real>3</ml:real>")),
            _eval(3, call("<ml:real>1</ml:real>")),
            _eval(4, call(minus_one)),
            _eval(5, _id("g", "CONSTANT")),
            _eval(6, _id("g")),
        ]
    )
    per_s2 = (
        '<u:unitMonomial><u:unitReference unit="meter"/><u:unitReference unit="second" '
        'power-numerator="-2"/></u:unitMonomial>'
    )
    results = "".join(
        [
            _result(1),
            _result(2, "<ml:real>10</ml:real>"),
            _result(3, "<ml:real>20</ml:real>"),
            _result(4, "<ml:real>30</ml:real>"),
            _result(5, f"<ml:unitedValue><ml:real>9.80665</ml:real>{per_s2}</ml:unitedValue>"),
            _result(6, "<ml:real>1</ml:real>"),
        ]
    )
    src = _package(tmp_path / "labels.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    text = (tmp_path / "labels.toml").read_text(encoding="utf-8")
    assert "region 6: an evaluation ( = ): g is not defined before it is used" in text
    result = _check(tmp_path / "labels.toml", capsys)
    assert (result["printed"], result["reproduced"], result["failed"]) == (5, 4, 0), result


@pytest.mark.slow
def test_if_blocks_in_a_program(tmp_path, capsys):
    """f(x) := | if x > 10: (y <- 100; y) / else if x > 0: (y <- 2 x; y + 0) / else: -x |
    in a program with a line after the first: f(20) = 100, f(3) = 6, f(-2) = 2."""
    x = _id("x")
    y = _id("y")

    def block(*lines: str) -> str:
        return f"<ml:program>{''.join(lines)}</ml:program>"

    def local(name: str, value: str) -> str:
        return f"<ml:localDefine>{_id(name)}{value}</ml:localDefine>"

    def test(limit: str) -> str:
        compare = f"<ml:apply><ml:greaterThan/>{x}<ml:real>{limit}</ml:real></ml:apply>"
        return f"<ml:test>{compare}</ml:test>"

    twice = f"<ml:apply><ml:mult/><ml:real>2</ml:real>{x}</ml:apply>"
    chain = (
        f"<ml:if>{test('10')}<ml:then>{block(local('y', '<ml:real>100</ml:real>'), y)}</ml:then>"
        f"<ml:elseif>{test('0')}<ml:then>{block(local('y', twice), y)}</ml:then></ml:elseif>"
        f"<ml:else>{block(f'<ml:apply><ml:neg/>{x}</ml:apply>')}</ml:else></ml:if>"
    )
    body = block(local("z", "<ml:real>1</ml:real>"), chain)
    f_def = _region(
        1,
        1,
        f"<ml:define><ml:function>{_id('f')}<ml:boundVars>{x}</ml:boundVars></ml:function>"
        f"{body}</ml:define>",
    )

    def call(v: str) -> str:
        return f"<ml:apply>{_id('f', 'FUNCTION')}<ml:sequence>{v}</ml:sequence></ml:apply>"

    minus_two = "<ml:apply><ml:neg/><ml:real>2</ml:real></ml:apply>"
    regions = f_def + "".join(
        [
            _eval(2, call("<ml:real>20</ml:real>")),
            _eval(3, call("<ml:real>3</ml:real>")),
            _eval(4, call(minus_two)),
        ]
    )
    results = "".join(
        [
            _result(1),
            _result(2, "<ml:real>100</ml:real>"),
            _result(3, "<ml:real>6</ml:real>"),
            _result(4, "<ml:real>2</ml:real>"),
        ]
    )
    src = _package(tmp_path / "blocks.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "blocks.toml", capsys)
    assert (result["printed"], result["reproduced"]) == (3, 3), result


def _combo(selected: int, cols: int, *values: float) -> str:
    reals = "".join(f"<ml:real>{v}</ml:real>" for v in values)
    places = "<ml:placeholder/>" * cols
    return (
        f'<ml:ComboBoxControl rows="{len(values) // cols}" cols="{cols}" '
        f'SelectedRow="{selected}"><ml:ComboBoxRowNames/><ml:ComboBoxScaleFactors>{places}'
        f"</ml:ComboBoxScaleFactors><ml:ComboBoxValues>{reals}</ml:ComboBoxValues>"
        "</ml:ComboBoxControl>"
    )


@pytest.mark.slow
def test_combo_box_is_the_selected_row(tmp_path, capsys):
    """f_yk from a combo box of 410, 500, 550 with SelectedRow 2 (counted from 0) is 550;
    [a; b] from rows (1, 2) and (3, 4) with SelectedRow 1 is a = 3, b = 4."""
    pair = '<ml:matrix rows="2" cols="1">' + _id("a") + _id("b") + "</ml:matrix>"
    regions = "".join(
        [
            _region(1, 1, f"<ml:define>{_id('f')}{_combo(2, 1, 410, 500, 550)}</ml:define>"),
            _region(2, 2, f"<ml:define>{pair}{_combo(1, 2, 1, 2, 3, 4)}</ml:define>"),
            _eval(3, _id("f")),
            _eval(4, _id("a")),
            _eval(5, _id("b")),
        ]
    )
    results = "".join(
        [_result(1), _result(2)]
        + [_result(k, f"<ml:real>{v}</ml:real>") for k, v in ((3, 550), (4, 3), (5, 4))]
    )
    src = _package(tmp_path / "combo.mcdx", regions, results)
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "combo.toml", capsys)
    assert (result["printed"], result["reproduced"]) == (3, 3), result


@pytest.mark.slow
def test_bounds_of_a_sum(tmp_path, capsys):
    """Prime writes a sum's bounds as lowerBound and upperBound: Σ_{i=1}^{4} i^2 = 30."""
    lam = (
        f"<ml:lambda><ml:boundVars>{_id('i')}</ml:boundVars><ml:apply><ml:pow/>{_id('i')}"
        "<ml:real>2</ml:real></ml:apply></ml:lambda>"
    )
    total = (
        f"<ml:apply><ml:summation/>{lam}<ml:lowerBound><ml:real>1</ml:real></ml:lowerBound>"
        "<ml:upperBound><ml:real>4</ml:real></ml:upperBound></ml:apply>"
    )
    src = _package(tmp_path / "sum.mcdx", _eval(1, total), _result(1, "<ml:real>30</ml:real>"))
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    result = _check(tmp_path / "sum.toml", capsys)
    assert (result["printed"], result["reproduced"]) == (1, 1), result
