"""The import pipeline: every region translated once, the translation typed once in memory by
the engine's typer, what the engine refuses listed with its reason (and what uses it), the
worksheet written once and loaded once."""

from __future__ import annotations

import pytest
from helpers.mathcad_xml import apply as _apply
from helpers.mathcad_xml import call as _call
from helpers.mathcad_xml import check_sheet as _check
from helpers.mathcad_xml import define as _define
from helpers.mathcad_xml import evaluate as _eval
from helpers.mathcad_xml import ident as _id
from helpers.mathcad_xml import import_sheet as _import
from helpers.mathcad_xml import real as _real

from workbook.engine import sheet as sheet_module
from workbook.mathcad import translate


@pytest.fixture
def counted(monkeypatch):
    """How many Sheets are built and translations run during a test."""
    n = {"sheets": 0, "translations": 0}
    init, run = sheet_module.Sheet.__init__, translate.Translator.run

    def sheet_init(self, *a, **k):
        n["sheets"] += 1
        init(self, *a, **k)

    def translator_run(self, *a, **k):
        n["translations"] += 1
        return run(self, *a, **k)

    monkeypatch.setattr(sheet_module.Sheet, "__init__", sheet_init)
    monkeypatch.setattr(translate.Translator, "run", translator_run)
    return n


def _length(value: float) -> str:
    return _apply("mult", _real(value), _id("m"))


@pytest.mark.slow
def test_refused_regions_are_found_in_one_pass(tmp_path, capsys, counted):
    """L := 2.5 m; r := round(L) and s := floor(L) (the engine refuses both: the result would
    depend on the unit); q := r*2 and t := s + 1 use them; a := 3 = 3 is kept. One
    translation, one typing pass and one load of the written worksheet, however many
    regions are refused (the import used to load and translate again for each)."""
    text = _import(
        tmp_path,
        capsys,
        "refused",
        _define(1, _id("L"), _length(2.5)),
        _define(2, _id("r"), _call("round", _id("L"))),
        _define(3, _id("s"), _call("floor", _id("L"))),
        _define(4, _id("q"), _apply("mult", _id("r"), _real(2))),
        _eval(5, _id("q"), _real(6)),
        _define(6, _id("t"), _apply("plus", _id("s"), _real(1))),
        _define(7, _id("a"), _real(3)),
        _eval(8, _id("a"), _real(3)),
    )
    listed = text.split("[sheet]")[0]
    assert "region 2: r := ...: the engine refuses it: round()" in listed
    assert "region 3: s := ...: the engine refuses it: floor()" in listed
    assert "region 4: q := ...: uses r, which is not translated: the engine refuses it" in listed
    assert "region 6: t := ...: uses s, which is not translated: the engine refuses it" in listed
    assert listed.index("region 2:") < listed.index("region 3:") < listed.index("region 4:")
    assert counted == {"sheets": 2, "translations": 1}
    result = _check(tmp_path, capsys, "refused")
    assert (result["printed"], result["reproduced"], result["failed"]) == (2, 1, 0), result


@pytest.mark.slow
def test_a_worksheet_the_engine_takes_is_loaded_once(tmp_path, capsys, counted):
    """Nothing refused: the typing pass is the only load (the document it typed is the data
    written, read back exactly)."""
    _import(
        tmp_path,
        capsys,
        "clean",
        _define(1, _id("L"), _real(2.5)),
        _define(2, _id("A"), _apply("pow", _id("L"), _real(2))),
        _eval(3, _id("A"), _real(6.25)),
    )
    assert counted == {"sheets": 1, "translations": 1}
    result = _check(tmp_path, capsys, "clean")
    assert (result["printed"], result["reproduced"]) == (1, 1), result


@pytest.mark.slow
def test_a_range_over_a_value_the_engine_computes(tmp_path, capsys):
    """L := 3.4 m; n := round(L/m) + 1; i := 0 .. n-1 and i*2 listed over it: the range's
    values (0, 1, 2, 3) are computed by the engine, with any of its built-ins (round)."""
    n = _apply("plus", _call("round", _apply("div", _id("L"), _id("m"))), _real(1))
    rng = f"<ml:range>{_real(0)}{_apply('minus', _id('n'), _real(1))}</ml:range>"
    listed = "<ml:matrix rows='4' cols='1'>" + "".join(_real(v) for v in (0, 2, 4, 6))
    text = _import(
        tmp_path,
        capsys,
        "ranged",
        _define(1, _id("L"), _length(3.4)),
        _define(2, _id("n"), n),
        _define(3, _id("i"), rng),
        _eval(4, _apply("mult", _id("i"), _real(2)), listed + "</ml:matrix>"),
    )
    assert "not translated" not in text.lower().split("[sheet]")[0], text
    result = _check(tmp_path, capsys, "ranged")
    assert (result["printed"], result["reproduced"], result["failed"]) == (4, 4, 0), result


@pytest.mark.slow
def test_a_chain_of_definitions_is_typed_once(tmp_path, capsys, monkeypatch):
    """x1 := x0/2, x2 := x1/2, ... (is an angle divided? the engine tells, for each link):
    what the engine typed once stands in as an input of its unit, so the worksheets written to
    type the chain hold a few definitions each, not the whole chain before."""
    from workbook.mathcad import writer

    rendered = []
    document = writer.document

    def counted(tr, *a, **k):
        rendered.append(len(tr.items))
        return document(tr, *a, **k)

    monkeypatch.setattr(writer, "document", counted)
    links = [_define(k + 1, _id(f"x{k}"), _apply("div", _id(f"x{k - 1}"), _real(2)))
             for k in range(1, 60)]  # fmt: skip
    _import(tmp_path, capsys, "chain", _define(0, _id("x0"), _length(1.0)), *links)
    at_import = rendered[:-1]  # the last: the whole worksheet, typed once
    assert len(at_import) >= 59 and max(at_import) <= 2, rendered
