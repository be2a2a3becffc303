"""Checks: printed values from the source paper, and findings of solver blocks."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pint

from .. import verdicts as V
from ..errors import DomainError, LimitError, TemplateError, UnitError, WorkbookError
from ..findings import Finding
from ..language import units as un
from ..language.printed import PrintedRow
from ..language.spec import PrintedSpec
from ..language.typedsheet import printed_rows


@dataclass
class CheckRow:
    source: str  # title of the printed set
    role: str  # check | information
    name: str
    argument: str
    at: float | None
    unit: str
    printed: float
    computed: float | None
    tolerance: float | None
    rel_tolerance: float | None
    verdict: str  # one of verdicts.ROW_VERDICTS
    note: str = ""
    computed_text: str | None = None  # what the sheet gives where a text is printed

    def __post_init__(self):
        if self.verdict not in V.ROW_VERDICTS:
            raise ValueError(
                f"printed value {self.name!r}: verdict {self.verdict!r} is not one of "
                f"{', '.join(V.ROW_VERDICTS)}"
            )

    @property
    def abs_error(self) -> float | None:
        if self.computed is None or isinstance(self.printed, str):
            return None
        return abs(self.computed - self.printed)

    @property
    def rel_error(self) -> float | None:
        if self.computed is None or isinstance(self.printed, str) or self.printed == 0:
            return None
        return abs(self.computed - self.printed) / abs(self.printed)


@dataclass
class Report:
    sheet: str
    rows: list[CheckRow] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)
    unused_inputs: list[str] = field(default_factory=list)

    @property
    def failed(self) -> list[CheckRow]:
        return [r for r in self.rows if r.verdict in V.ROW_FAILED]

    @property
    def ok(self) -> bool:
        return not self.failed and not any(f.verdict in V.FINDING_FAILED for f in self.findings)

    def summary(self) -> dict:
        """Counts of the checked printed values and the ones not reproduced (``check --json``):
        failed (computed, outside the tolerance) and not computable (an error)."""
        checked = [r for r in self.rows if r.role == "check"]
        bad = [r for r in checked if r.verdict in V.ROW_FAILED]
        return {
            "printed": len(checked),
            "reproduced": sum(r.verdict in V.REPRODUCED for r in checked),
            "failed": sum(r.verdict == "FAIL" for r in checked),
            "not_computable": sum(r.verdict == "error" for r in checked),
            "failures": [
                {
                    "name": r.name,
                    "at": r.at,
                    "printed": _json_number(r.printed),
                    "ours": r.computed_text
                    if r.computed_text is not None
                    else _json_number(r.computed),
                    "unit": r.unit,
                    **({"error": r.note} if r.verdict == "error" else {}),
                }
                for r in bad
            ],
        }

    def text(self) -> str:
        """The report as readable text (what ``workbook check`` prints)."""
        lines = [f"checks of {self.sheet}"]
        by_source: dict[str, list[CheckRow]] = {}
        for r in self.rows:
            by_source.setdefault(r.source, []).append(r)
        for source, rows in by_source.items():
            role = rows[0].role
            n_ok = sum(r.verdict in V.NOT_FAILED for r in rows)
            lines.append("")
            lines.append(
                f"{source} ({'information' if role == 'information' else 'checked'}): "
                f"{n_ok} of {len(rows)} reproduced"
            )
            lines.append(
                f"  {'name':<8}{'at':>8}  {'printed':>12}  {'computed':>12}  "
                f"{'abs err':>10}  {'rel err':>9}  verdict"
            )
            for r in rows:
                comp = "-" if r.computed is None else f"{r.computed:.6g}"
                if r.computed_text is not None:
                    comp = r.computed_text
                printed = r.printed if isinstance(r.printed, str) else f"{r.printed:.6g}"
                ae = "-" if r.abs_error is None else f"{r.abs_error:.2e}"
                re_ = "-" if r.rel_error is None else f"{100 * r.rel_error:.3f}%"
                at = "" if r.at is None else f"{r.at:g}"
                lines.append(
                    f"  {r.name:<8}{at:>8}  {printed:>12}  {comp:>12}  {ae:>10}  "
                    f"{re_:>9}  {r.verdict}{'  ' + r.note if r.note else ''}"
                )
        if self.findings:
            lines.append("")
            lines.append("findings:")
            topic = None
            for f in self.findings:
                if f.topic != topic:
                    topic = f.topic
                    lines.append(f"  [{topic}]")
                val = (
                    "" if f.value is None else f" = {f.value:.6g}{(' ' + f.unit) if f.unit else ''}"
                )
                note = f" ({f.note})" if f.note else ""
                lines.append(f"    {f.verdict:<7} {f.what}{val}{note}")
        if self.unused_inputs:
            lines.append("")
            lines.append("inputs that no output uses: " + ", ".join(self.unused_inputs))
        lines.append("")
        lines.append("result: " + self.verdict())
        return "\n".join(lines)

    def verdict(self) -> str:
        """One line: how many printed values are reproduced, and failing findings."""
        bad = self.failed
        checked = [r for r in self.rows if r.role == "check"]
        if bad:
            text = f"{len(bad)} printed value(s) NOT reproduced"
        elif checked:
            text = f"all printed values reproduced ({len(checked)})"
        else:
            text = "no printed values to check"
        failing = sum(f.verdict == "fail" for f in self.findings)
        warnings = sum(f.verdict == "warning" for f in self.findings)
        if failing:
            text += f"; {failing} finding(s) FAIL"
        if warnings:
            text += f"; {warnings} warning(s)"
        return text


def _json_number(value: float | str | None) -> float | str | None:
    if isinstance(value, str):
        return value
    return None if value is None or not math.isfinite(value) else value


def sheet_report(sheet) -> Report:
    """The sheet's check report, made once per Sheet (the workbook's and the report's Checks
    read it)."""
    return sheet.once(("check",), lambda: run_checks(sheet))


def run_checks(sheet) -> Report:
    """Compare every printed value with the engine, and collect block findings."""
    report = Report(sheet.name)
    for spec in sheet.spec.printed:
        for row in printed_rows(spec):
            report.rows.append(_check_row(sheet, spec, row))
    report.findings = collect_findings(sheet) + failed_values(sheet)
    if sheet.evaluator.records:  # after the values: their built-ins' estimates
        from ..numerics.estimates import estimate_findings

        report.findings += estimate_findings(sheet)
    if sheet.spec.relations or sheet.spec.meta.get("hand_checks"):
        from ..engine.analysis import findings as hand_checks  # relations, joins, domains, pi

        report.findings += hand_checks(sheet)
    report.unused_inputs = sheet.unused_inputs()
    return report


def collect_findings(sheet) -> list[Finding]:
    """The findings of the sheet's own checks, ODEs, solve blocks, declared checks and
    [[findings]] blocks; what they evaluate through the sheet counts as used."""
    with sheet.recording_reads():
        return _findings(sheet)


def _findings(sheet) -> list[Finding]:
    from .. import blocks
    from ..engine.angle_slips import angle_findings

    out: list[Finding] = angle_findings(sheet)
    if sheet.spec.odes:
        from ..engine.ode import sheet_findings

        out.extend(sheet_findings(sheet))
    if sheet.spec.solves:
        from ..engine.solve_blocks import solve_findings

        out.extend(solve_findings(sheet))
    if sheet.spec.checks:
        from .declared_checks import check_findings

        out.extend(check_findings(sheet))
    for entry in sheet.spec.findings:
        ref = entry.get("block")
        if not isinstance(ref, str):
            raise TemplateError('[[findings]] needs block = "module.function"', file=sheet.file)
        try:
            out.extend(blocks.get(ref, "findings").func(sheet))
        except WorkbookError as err:
            out.append(
                Finding(entry.get("title", ref), f"{ref} could not run", None, "", "fail", str(err))
            )
    return out


#: Errors of a value that fails where it is computed (a domain left, a solver that gives up, a
#: run over its budget); a piecewise value with no piece for its arguments does not exist there
#: by the worksheet's own declaration and is shown as such, not counted as a failure.
FAILURES = (DomainError, LimitError)
#: Failed rows of one column named in its finding (all are in the workbook's comments).
ROWS_NAMED = 5


def failed_values(sheet) -> list[Finding]:
    """A failing finding for every value the sheet cannot compute: scalar definitions and the
    unknowns of [[solve]] blocks (one finding per cause, naming every value it takes), a range
    table, the rows of a table column that fail."""
    out: list[Finding] = []
    causes: dict[str, list[str]] = {}  # the error, located where it arose -> the values
    for block in sheet.spec.solves:
        if block.parameters:  # a function of its parameters: its values are where it is used
            continue
        try:
            sheet.evaluate(next(iter(block.unknowns)))
        except WorkbookError as err:  # a value shown as an error in any case
            if isinstance(err, FAILURES):
                causes.setdefault(str(err), []).append(", ".join(block.unknowns))
    for name, d in sheet.spec.definitions.items():
        if d.is_function:
            continue
        try:
            sheet.scalar_quantity(name)
        except WorkbookError as err:  # a value shown as an error in any case
            if isinstance(err, FAILURES):
                causes.setdefault(str(err), []).append(name)
    for cause, names in causes.items():
        what = f"{', '.join(names)} {'has' if len(names) == 1 else 'have'} no value"
        out.append(Finding("failed values", what, None, "", "fail", cause))
    for t in sheet.spec.tables:
        if t.computed or t.range is None:
            continue
        try:
            data = sheet.table_data(t.name)
        except WorkbookError as err:
            out.append(
                Finding("failed values", f"table {t.name} has no value", None, "", "fail", str(err))
            )
            continue
        for col in data.columns[1:]:
            if not col.failed:
                continue
            rows = sorted(col.failed)
            named = "; ".join(
                f"{data.var} = {data.columns[0].values[i]:g}: {col.failed[i]}"
                for i in rows[:ROWS_NAMED]
            )
            more = f"; and {len(rows) - ROWS_NAMED} more" if len(rows) > ROWS_NAMED else ""
            out.append(
                Finding(
                    "failed values",
                    f"table {t.name}: {col.text} has no value in {len(rows)} of "
                    f"{len(col.values)} rows (error cells in the workbook)",
                    None,
                    "",
                    "fail",
                    named + more,
                )
            )
    return out


def _text_row(base: dict, row: PrintedRow, q) -> CheckRow:
    """A printed text (or a computed text where a number is printed): equal or FAIL."""
    ours = q if isinstance(q, str) else f"{q:~}"
    ok = isinstance(q, str) and q == row.value
    verdict = "info" if base["role"] == "information" else ("pass" if ok else "FAIL")
    note = "" if ok else f"computed {ours!r}"
    return CheckRow(**base, computed=None, verdict=verdict, note=note, computed_text=ours)


def _check_row(sheet, spec: PrintedSpec, row: PrintedRow) -> CheckRow:
    misprint = next((m for m in spec.misprints if m.name == row.name and m.at == row.at), None)
    base = dict(
        source=spec.title,
        role=spec.role,
        name=row.name,
        argument=spec.argument,
        at=None if math.isnan(row.at) else row.at,
        unit=row.unit,
        printed=row.value,
        tolerance=spec.tolerance,
        rel_tolerance=spec.rel_tolerance,
    )
    try:
        if spec.argument and not math.isnan(row.at):
            q = sheet.evaluate(row.name, **{spec.argument: row.at})
        else:
            q = sheet.evaluate(row.name)
        if isinstance(row.value, str) or isinstance(q, str):
            return _text_row(base, row, q)
        if getattr(q.magnitude, "ndim", 0):
            raise TemplateError(
                f"'{row.name}' is a vector or matrix and a printed value is one number: "
                f"check an element through a definition (e.g. {row.name}_0 = "
                f'"{row.name}[0]")',
                file=str(spec.file),
                line=row.line,
                definition=row.name,
            )
        if isinstance(q.magnitude, complex):
            raise TemplateError(
                f"'{row.name}' is complex and a printed value is one real number: check its "
                f'parts through definitions (e.g. {row.name}_re = "Re({row.name})", or '
                f"abs({row.name}), arg({row.name}))",
                file=str(spec.file),
                line=row.line,
                definition=row.name,
            )
        computed = float(q.to(un.unit(row.unit)).magnitude)
    except pint.DimensionalityError:
        raise UnitError(
            f"{row.name} is {un.dims(q.units)} ({un.pretty(q.units) or 'dimensionless'}), but "
            f"its printed unit {row.unit!r} is {un.dims(un.unit(row.unit))}",
            file=str(spec.file),
            line=row.line,
            definition=row.name,
        ) from None
    except WorkbookError as err:
        return CheckRow(**base, computed=None, verdict="error", note=str(err))
    ok = within(computed, row.value, spec.tolerance, spec.rel_tolerance)
    if spec.role == "information":
        return CheckRow(
            **base,
            computed=computed,
            verdict="info",
            note="" if ok else "outside the stated deviation",
        )
    if misprint is not None:
        if ok:
            return CheckRow(
                **base,
                computed=computed,
                verdict="pass",
                note="declared a misprint, but it is reproduced",
            )
        if misprint.corrected is not None and not within(
            computed, misprint.corrected, spec.tolerance, spec.rel_tolerance
        ):
            return CheckRow(
                **base,
                computed=computed,
                verdict="FAIL",
                note=f"misprint, and the corrected {misprint.corrected:g} is not reproduced either",
            )
        return CheckRow(**base, computed=computed, verdict="misprint", note=misprint.note)
    return CheckRow(**base, computed=computed, verdict="pass" if ok else "FAIL")


def tolerances(printed: float, tol: float | None, rel: float | None):
    """The (absolute, relative) bounds a check uses: without either, half a unit of the last
    printed digit; the absolute bound is widened by 1e-9 relative against binary rounding."""
    if tol is None and rel is None:
        tol = 0.5 * 10 ** -_decimals(printed)
    return (None if tol is None else tol * (1 + 1e-9)), rel


def within(computed: float, printed: float, tol: float | None, rel: float | None) -> bool:
    """True if computed agrees with printed within the absolute or the relative tolerance."""
    bound, rel = tolerances(printed, tol, rel)
    error = abs(computed - printed)
    if bound is not None and error <= bound:
        return True
    return rel is not None and error <= rel * abs(printed)


def _decimals(value: float) -> int:
    text = repr(value)
    return len(text.split(".")[1]) if "." in text and "e" not in text else 0
