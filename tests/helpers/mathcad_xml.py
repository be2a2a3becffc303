"""Builders of small Mathcad 15 worksheets (.xmcd XML) for the importer's tests, and the
import and check steps the tests run on them."""

from __future__ import annotations

import json

from workbook.cli import main

ML = "http://schemas.mathsoft.com/math30"
UNITS = "http://schemas.mathsoft.com/units10"


def real(v) -> str:
    return f"<ml:real>{v}</ml:real>"


def ident(name, sub=None) -> str:
    s = f' subscript="{sub}"' if sub else ""
    return f"<ml:id{s}>{name}</ml:id>"


def apply(op, *args) -> str:
    return f"<ml:apply><ml:{op}/>{''.join(args)}</ml:apply>"


def call(name, *args) -> str:
    return f"<ml:apply>{ident(name)}{''.join(args)}</ml:apply>"


def index(target, *at) -> str:
    inner = at[0] if len(at) == 1 else f"<ml:sequence>{''.join(at)}</ml:sequence>"
    return f"<ml:apply><ml:indexer/>{target}{inner}</ml:apply>"


def matrix(*cells, cols=1) -> str:
    """A matrix of ``cells`` as Mathcad stores them: column by column."""
    rows = len(cells) // cols
    return f'<ml:matrix rows="{rows}" cols="{cols}">{"".join(cells)}</ml:matrix>'


def array_cells(m) -> str:
    """A numpy matrix as Mathcad stores it (column by column)."""
    return matrix(*(real(v) for v in m.T.flatten()), cols=m.shape[1])


def local(lhs, rhs) -> str:
    return f"<ml:localDefine>{lhs}{rhs}</ml:localDefine>"


def if_then(cond, body) -> str:
    return f"<ml:ifThen>{cond}{body}</ml:ifThen>"


def otherwise(body) -> str:
    return f"<ml:otherwise>{body}</ml:otherwise>"


def for_loop(var, first, last, body) -> str:
    return f"<ml:for>{ident(var)}<ml:range>{first}{last}</ml:range>{body}</ml:for>"


def program(*lines) -> str:
    return f"<ml:program>{''.join(lines)}</ml:program>"


def united(value, *units: tuple[str, int]) -> str:
    """A stored value with units: ``united(2, ("m", 1), ("s", -2))``."""
    refs = "".join(
        f'<u:unitReference unit="{u}"' + (f' power-numerator="{p}"' if p != 1 else "") + "/>"
        for u, p in units
    )
    return (
        f'<ml:unitedValue>{real(value)}<u:unitMonomial xmlns:u="{UNITS}">{refs}'
        "</u:unitMonomial></ml:unitedValue>"
    )


def at(rid: int) -> str:
    return f'region-id="{rid}" left="0" top="{rid * 20}" align-y="{rid * 20}"'


def define(rid: int, lhs: str, rhs: str) -> str:
    body = f'<ml:define xmlns:ml="{ML}">{lhs}{rhs}</ml:define>'
    return f"<region {at(rid)}><math>{body}</math></region>"


def function(rid: int, name: str, params: list[str], body: str) -> str:
    bound = "".join(ident(p) for p in params)
    lhs = f"<ml:function>{ident(name)}<ml:boundVars>{bound}</ml:boundVars></ml:function>"
    return define(rid, lhs, body)


def evaluate(rid: int, body: str, result: str) -> str:
    return (
        f'<region {at(rid)}><math><ml:eval xmlns:ml="{ML}">{body}'
        f"<ml:result>{result}</ml:result></ml:eval></math></region>"
    )


def worksheet(*regions: str, origin: int = 0) -> str:
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n<worksheet '
        'xmlns="http://schemas.mathsoft.com/worksheet30" '
        f'xmlns:ml="{ML}"><settings><calculation><builtInVariables array-origin="{origin}"/>'
        f"</calculation></settings><regions>{''.join(regions)}</regions></worksheet>"
    )


def import_sheet(tmp_path, capsys, name: str, *regions: str, origin: int = 0) -> str:
    """Write the worksheet, import it (exit 0), and give the written TOML's text."""
    src = tmp_path / f"{name}.xmcd"
    src.write_text(worksheet(*regions, origin=origin), encoding="utf-8")
    assert main(["import", str(src), "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    return (tmp_path / f"{name}.toml").read_text(encoding="utf-8")


def check_sheet(tmp_path, capsys, name: str) -> dict:
    """``workbook check NAME.toml --json`` (exit 0 or 1), its JSON."""
    assert main(["check", str(tmp_path / f"{name}.toml"), "--json"]) in (0, 1)
    return json.loads(capsys.readouterr().out)


# Mathcad Prime (.mcdx): a zip package of XML parts

PRIME_WS = (
    '<worksheet xmlns="http://schemas.mathsoft.com/worksheet50" '
    'xmlns:ml="http://schemas.mathsoft.com/math50" '
    'xmlns:u="http://schemas.mathsoft.com/units10"><regions>{}</regions></worksheet>'
)
PRIME_RESULTS = (
    '<resultsList xmlns="http://schemas.mathsoft.com/result10" '
    'xmlns:ml="http://schemas.mathsoft.com/math50" '
    'xmlns:u="http://schemas.mathsoft.com/units10">{}</resultsList>'
)


def prime_region(rid: int, ref: int, body: str) -> str:
    return f'<region region-id="{rid}"><math resultRef="{ref}">{body}</math></region>'


def prime_result(ref: int, value: str = "") -> str:
    inner = f"<ml:result>{value}</ml:result>" if value else ""
    return f'<resultData result-id="{ref}" calculation-status="Synchronized">{inner}</resultData>'


def prime_package(path, regions: str, results: str, extra: dict | None = None):
    """Write a Prime package of ``regions`` and stored ``results`` at ``path``."""
    import zipfile

    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("mathcad/worksheet.xml", PRIME_WS.format(regions))
        z.writestr("mathcad/result.xml", PRIME_RESULTS.format(results))
        z.writestr(
            "mathcad/settings/calculation.xml",
            '<calculation xmlns="http://schemas.ptc.com/mathcad/settings/calculation10">'
            '<builtInVariables array-origin="0" convergence-tolerance="0.001"/></calculation>',
        )
        for name, data in (extra or {}).items():
            z.writestr(name, data)
    return path


def math_region(rid: int, body: str) -> str:
    """A math region of one expression (``Given``, an equation of a solve block)."""
    return f"<region {at(rid)}><math>{body}</math></region>"


def shown(body: str, result: str) -> str:
    """The right side of ``x := body =`` (a definition whose value Mathcad shows)."""
    return f"<ml:eval>{body}<ml:result>{result}</ml:result></ml:eval>"


def derivative(var: str, body: str, degree: str | None = None) -> str:
    """Mathcad's d/dvar body (with ``degree``, the n-th derivative's order element)."""
    lam = f"<ml:lambda><ml:boundVars>{ident(var)}</ml:boundVars>{body}</ml:lambda>"
    order = f"<ml:degree>{degree}</ml:degree>" if degree is not None else ""
    return f"<ml:apply><ml:derivative/>{lam}{order}</ml:apply>"


def prime_solve_block(rid: int, guesses: list[str], constraints: list[str], solver: str) -> str:
    """A Prime solve block (region ``rid``): its guess values, constraints and solver regions
    (ids and result references from ``rid + 1``), each a math body."""
    parts = [("guess-value", g) for g in guesses] + [("constraint", c) for c in constraints]
    inner = "".join(
        f'<region region-id="{rid + k}" solve-block-category="{kind}">'
        f'<math resultRef="{rid + k}">{body}</math></region>'
        for k, (kind, body) in enumerate([*parts, ("solver", solver)], start=1)
    )
    return f'<region region-id="{rid}"><solveblock><regions>{inner}</regions></solveblock></region>'
