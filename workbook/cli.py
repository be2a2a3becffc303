"""Command line: ``workbook list | run | check | import | bench | sweep | new | report | serve |
lsp``.

Exit status: 0 success, 1 printed values not reproduced (check), 2 bad input
(template, units, values, paths), 3 internal error (a bug), 130 interrupted, 141 the reader
of the output closed it (``| head``). No traceback unless --debug.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from pathlib import Path

EXIT_OK, EXIT_CHECK, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 3


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="workbook",
        description="Unit-checked engineering worksheets that write live Excel workbooks.",
    )
    p.add_argument("--debug", action="store_true", help="show Python tracebacks")
    p.add_argument("--version", action="store_true", help="print the version")
    sub = p.add_subparsers(dest="command")
    sub.add_parser("list", help="list the installed templates")
    _run_parser(sub)
    chk = sub.add_parser("check", help="compare with the printed values; exit 1 if any fails")
    _sheet_args(chk)
    _part_args(chk, "all")
    chk.add_argument(
        "--json", action="store_true", help="print one JSON object (counts and failures)"
    )
    imp = sub.add_parser(
        "import",
        help="translate a Mathcad worksheet (.xmcd, Prime's .mcdx) or an Excel workbook",
    )
    imp.add_argument("file", help="the .xmcd or .mcdx file, or the .xlsm/.xlsx/.xls workbook")
    imp.add_argument(
        "--vba", action="append", default=[], help="VBA from an add-in or a .bas/.cls module"
    )
    imp.add_argument("--out", default=".", help="folder to write NAME.toml into (default: .)")
    imp.add_argument("--force", action="store_true", help="replace existing files")
    bench = sub.add_parser("bench", help="error against run time of the sheet's numerical methods")
    _sheet_args(bench)
    bench.add_argument("--quick", action="store_true", help="a small, fast version")
    _sweep_parser(sub)
    _report_parser(sub)
    srv = sub.add_parser(
        "serve", help="a live page of the report, computed again as the file or an input changes"
    )
    srv.add_argument(
        "name", nargs="?", help="template name, .toml file or folder (default: this folder)"
    )
    srv.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default: any free)")
    srv.add_argument("--no-browser", action="store_true", help="print the URL, open no browser")
    sub.add_parser("lsp", help="a language server for editors (LSP over stdin and stdout)")
    new = sub.add_parser("new", help="write a commented starter worksheet that runs as it is")
    new.add_argument("name", help="name of the new worksheet (writes NAME.toml)")
    new.add_argument("--out", help="file to write (default ./NAME.toml)")
    new.add_argument("--force", action="store_true", help="overwrite an existing file")
    for command in sub.choices.values():  # `workbook run X --debug` and `workbook --debug run X`
        command.add_argument(
            "--debug", action="store_true", default=argparse.SUPPRESS, help="show Python tracebacks"
        )
        command.add_argument(
            "--time-limit",
            metavar="SECONDS",
            default=None,
            help="the command's budget in seconds of CPU time (default 20, at most 3600; "
            "wall-clock time is bounded at 5 times it)",
        )
    return p


def _sheet_args(sp) -> None:
    sp.add_argument("name", help="template name (see 'workbook list') or path to a .toml file")
    sp.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help='override an input, e.g. --set R3="40 mm" (repeatable)',
    )


def _part_args(sp, default: str) -> None:
    sp.add_argument(
        "--part",
        action="append",
        default=[],
        metavar="PART",
        help=f"an optional part of the worksheet, e.g. hand-checks, or 'all' (repeatable; "
        f"default: {default})",
    )


def _run_parser(sub) -> None:
    run = sub.add_parser("run", help="compute a worksheet and write its Excel workbook")
    _sheet_args(run)
    _part_args(run, "none: what is in no part")
    run.add_argument("--out", help="output .xlsx (default reports/NAME.xlsx)")
    run.add_argument("--force", action="store_true", help="overwrite a file that is not an xlsx")
    run.add_argument(
        "--inputs",
        metavar="XLSX",
        help="read the inputs back from the Inputs sheet of an edited workbook",
    )
    run.add_argument(
        "--export",
        metavar="PATH",
        help="also write the sheet's export file (reducer-profile: the practical profile "
        "as CSV points x,y,z in mm for CAD)",
    )
    run.add_argument(
        "--csv",
        metavar="TABLE",
        action="append",
        default=[],
        help="also write table TABLE as CSV beside the workbook (repeatable)",
    )
    run.add_argument(
        "--first",
        metavar="N",
        type=int,
        help="print only the first N results (default: every result; all are on the Results sheet)",
    )


def _sweep_parser(sub) -> None:
    sw = sub.add_parser("sweep", help="chosen outputs over a grid of inputs: a table and a chart")
    _sheet_args(sw)
    sw.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="NAME=FIRST..LAST:COUNT",
        help="an input and its values, e.g. --vary R3=40mm..60mm:21 or R3=40mm,50mm (repeatable)",
    )
    sw.add_argument(
        "--output",
        action="append",
        default=[],
        metavar="NAME=EXPR",
        help='an output, e.g. "v_peak=max of v(phi) over phi := 0 .. 104" (default: the '
        "template's [sweep] outputs)",
    )
    sw.add_argument("--out", help="output .xlsx or .csv (default reports/NAME.sweep.xlsx)")
    sw.add_argument("--force", action="store_true", help="overwrite a file of another kind")
    sw.add_argument(
        "--mode",
        default="auto",
        choices=["auto", "vector", "serial", "processes"],
        help="how cases run locally (auto: vector for formulas, processes for solvers)",
    )
    sw.add_argument("--workers", type=int, help="processes of the local pool (default: CPUs)")
    sw.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask cluster (tcp://...)")


def _report_parser(sub) -> None:
    rep = sub.add_parser(
        "report", help="the calculation as a document: reports/NAME.html (and --pdf)"
    )
    _sheet_args(rep)
    _part_args(rep, "none: what is in no part")
    rep.add_argument("--out", help="output .html (default reports/NAME.html)")
    rep.add_argument(
        "--pdf", action="store_true", help="also print it to PDF beside the HTML (Chromium)"
    )
    rep.add_argument(
        "--full-tables",
        action="store_true",
        help="every row of long tables (default: first and last rows above 1,000)",
    )
    rep.add_argument("--force", action="store_true", help="overwrite a file of another kind")


def parse_sets(items: list[str]) -> dict[str, str]:
    from .errors import InputError

    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise InputError(f'--set {item!r}: write NAME=VALUE, e.g. --set R3="40 mm"')
        out[name.strip()] = value.strip()
    return out


def load_sheet(args, parts=None):
    import workbook

    sheet = workbook.load(args.name, parts=parts)
    _sheet_time_limit(sheet, args)
    if getattr(args, "inputs", None):
        from .roundtrip import changed_inputs

        changed = changed_inputs(sheet, args.inputs)  # checked like --set; --set wins
        args.set = [f"{k}={v}" for k, v in changed.items()] + list(args.set)
    sets = parse_sets(args.set)
    if sets:
        sheet = sheet.with_inputs(**sets)
    return sheet


def _sheet_time_limit(sheet, args) -> None:
    """A worksheet's ``[sheet] time_limit``: it may lower the default budget, not raise it
    (``--time-limit`` on the command line wins)."""
    from . import limits_time
    from .errors import LimitError

    raw = sheet.spec.meta.get("time_limit")
    if raw is None or getattr(args, "time_limit", None) is not None:
        return
    where = f"{sheet.file}: [sheet] time_limit"
    seconds = limits_time.check_seconds(raw, where)
    if seconds > limits_time.DEFAULT_SECONDS:
        raise LimitError(
            f"{where} = {raw!r}: a worksheet may lower the time budget (at most "
            f"{limits_time.DEFAULT_SECONDS:g} s), not raise it; give more time on the command "
            "line with --time-limit SECONDS"
        )
    limits_time.set_seconds(seconds, "[sheet] time_limit")


def _command_line(args) -> str:
    parts = ["workbook", "run", args.name]
    parts += [f"--part {p}" for p in args.part]
    for item in args.set:
        name, _, value = item.partition("=")
        parts.append(f'--set {name}="{value}"' if " " in value else f"--set {item}")
    return " ".join(parts)


def cmd_list(args) -> int:
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    import workbook

    for name, path in workbook.list_templates().items():
        try:
            meta = tomllib.loads(path.read_text(encoding="utf-8")).get("sheet", {})
            title = meta.get("title", "") if isinstance(meta, dict) else "(cannot read)"
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):  # still listed
            title = "(cannot read)"
        print(f"{name}\t{title}")
    return EXIT_OK


def cmd_run(args) -> int:
    """Compute, then write the workbook and every --csv and --export file as one: all targets
    are checked and all contents computed before any file is replaced. Findings with verdict
    warning or fail are printed; exit 1 (after writing) when one fails. Printed values that an
    override (--set) no longer reproduces are counted in the summary, not an error."""
    from .compute.computed import compute
    from .errors import InputError
    from .limits_time import check_time
    from .outputs.atomic import Outputs, write_csv
    from .outputs.xlsx import write_workbook

    if args.out and Path(args.out).suffix.lower() != ".xlsx":
        raise InputError(
            f"--out {args.out}: workbook run writes an Excel workbook; name it *.xlsx "
            "(a table as CSV: --csv TABLE)"
        )
    sheet = load_sheet(args, args.part or None)
    out = Path(args.out) if args.out else Path("reports") / f"{sheet.name}.xlsx"
    if not args.out:
        out.parent.mkdir(parents=True, exist_ok=True)
    exporter = None
    if args.export:
        from . import blocks

        ref = sheet.spec.meta.get("export")
        if not ref:
            raise InputError(f'{sheet.name} has no export ([sheet] export = "module.func")')
        exporter = blocks.get(ref, "export").func
    csv_paths = {table: out.with_name(f"{out.stem}.{table}.csv") for table in args.csv}
    with Outputs(force=args.force) as outs:
        xlsx_tmp = outs.add(out, "xlsx")
        csv_tmps = {table: outs.add(path, "csv") for table, path in csv_paths.items()}
        export_tmp = outs.add(Path(args.export), "csv") if exporter else None
        for table in args.csv:  # a table that is not there is said before any work
            sheet.table_spec(table)
        computed = compute(sheet, excel=True, command=_command_line(args))
        report = computed.check_report()
        for table in args.csv:
            write_csv(computed.frame(table), csv_tmps[table])
        if exporter is not None:
            exporter(sheet, export_tmp)
        check_time("writing the workbook")  # names the work, for the budget's alarm
        write_workbook(computed, xlsx_tmp, force=True)
        refusals = computed.excel.refusals
    for path in csv_paths.values():
        print(f"wrote {path}")
    if exporter is not None:
        print(f"wrote {args.export}")
    n_checked = sum(r.role == "check" for r in report.rows)
    from .verdicts import REPRODUCED

    n_ok = sum(r.role == "check" and r.verdict in REPRODUCED for r in report.rows)
    summary = f"{len(sheet.spec.tables)} tables, {len(sheet.spec.charts)} charts"
    if n_checked:
        summary += f", {n_ok} of {n_checked} printed values reproduced"
    print(f"wrote {out}: {summary}")
    for r in refusals:  # a live formula that an independent evaluation does not confirm
        print(f"written as a value: {r.where}: {r.disagreement}")
    _print_scalars(sheet, args.first)
    for name in sheet.left_out:
        part = sheet.full_spec.parts[name]
        print(f"left out part {name} ({part.title}): add it with --part {name}")
    _estimates_after_writing(sheet, report)
    return _print_findings(report)


def _estimates_after_writing(sheet, report) -> None:
    """The built-ins' estimate and assumption findings of the values computed after the
    check (the writer and the scalars computed the rest), each once."""
    from .numerics.estimates import estimate_findings

    known = {(f.topic, f.what) for f in report.findings}
    report.findings += [f for f in estimate_findings(sheet) if (f.topic, f.what) not in known]


def _print_scalars(sheet, first: int | None = None) -> None:
    """Every result, one a line (the first ``first`` of them when given); a vector or matrix
    as aligned rows of numbers, its unit after the first row."""
    from .errors import InputError, WorkbookError
    from .language.units import pretty

    if first is not None and first < 0:
        raise InputError(f"--first {first}: give a number of results, 0 or more")
    unknowns = [  # [[solve]] results (a block with parameters is a function)
        n for block in sheet.spec.solves if not block.parameters for n in block.unknowns
    ]
    names = unknowns + [n for n, d in sheet.spec.definitions.items() if not d.is_function]
    shown = names if first is None else names[:first]
    for name in shown:
        try:
            q = sheet.evaluate(name) if name in unknowns else sheet.scalar_quantity(name)
            if isinstance(q, str):  # a text: "OK"
                print(f'  {name} = "{q}"')
                continue
            if getattr(q.magnitude, "ndim", 0):  # a vector or matrix: aligned rows
                print("\n".join(matrix_lines(f"  {name} = ", q.magnitude, pretty(q.units))))
                continue
            if isinstance(q.magnitude, complex):  # a + bi
                from .functions.complexes import readable

                shown = readable(q.magnitude, polar=sheet.spec.polar)
                print(f"  {name} = {shown} {pretty(q.units)}".rstrip())
                continue
            value = float(q.magnitude) + 0.0  # -0 shows as 0
            print(f"  {name} = {value:.6g} {pretty(q.units)}".rstrip())
        except WorkbookError as err:
            print(f"  {name}: error: {err.message}")
    if len(shown) < len(names):
        print(f"  ... and {len(names) - len(shown)} more on the Results sheet")


def matrix_lines(lead: str, values, unit: str) -> list[str]:
    """A vector or matrix as text for people: one bracketed line a row, the columns aligned
    (numbers on their right edge, 6 significant digits), the unit after the first row::

        M = [ 4     1 ] N/mm
            [ 2  -3.5 ]
    """
    import numpy as np

    arr = np.asarray(values, dtype=object)
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    cells = [[_element_text(v) for v in row] for row in arr]
    widths = [max(len(r[j]) for r in cells) for j in range(arr.shape[1])] if cells else []
    pad = " " * len(lead)
    out = []
    for i, row in enumerate(cells):
        text = "[ " + "  ".join(c.rjust(w) for c, w in zip(row, widths)) + " ]"
        out.append((lead if i == 0 else pad) + text + (f" {unit}" if i == 0 and unit else ""))
    return out or [f"{lead}[ ] {unit}".rstrip()]


def _element_text(v) -> str:
    import numpy as np

    if isinstance(v, str):
        return f'"{v}"'
    if np.ndim(v):  # an array inside an array
        r, c = np.shape(v) if np.ndim(v) == 2 else (np.size(v), 1)
        return f"{{{r}x{c}}}"
    if np.iscomplexobj(v):  # a + bi
        from .functions.complexes import readable

        return readable(complex(v))
    return f"{float(v) + 0.0:.6g}"


def _print_findings(report) -> int:
    """Print the findings with verdict warning or fail (stderr); EXIT_CHECK if one fails."""
    from .verdicts import FINDING_FAILED, FINDING_FLAGGED

    for f in report.findings:
        if f.verdict in FINDING_FLAGGED:
            note = f" ({f.note})" if f.note else ""
            print(f"workbook: {f.verdict}: [{f.topic}] {f.what}{note}", file=sys.stderr)
    return EXIT_CHECK if any(f.verdict in FINDING_FAILED for f in report.findings) else EXIT_OK


def cmd_report(args) -> int:
    from .compute.computed import compute
    from .outputs.report import regenerate_command, report_targets, write_report

    sheet = load_sheet(args, args.part or None)
    command = regenerate_command(sheet, parse_sets(args.set))
    if args.full_tables:
        command += " --full-tables"
    if args.pdf:
        command += " --pdf"
    path, _ = report_targets(
        sheet.name, Path(args.out) if args.out else None, pdf=args.pdf, force=args.force
    )
    written = write_report(
        compute(sheet),
        path,
        pdf=args.pdf,
        force=args.force,
        command=command,
        full_tables=args.full_tables,
    )
    for path in written:
        print(f"wrote {path}")
    for name in sheet.left_out:
        part = sheet.full_spec.parts[name]
        print(f"left out part {name} ({part.title}): add it with --part {name}")
    return EXIT_OK


def cmd_check(args) -> int:
    sheet = load_sheet(args, args.part or "all")
    report = sheet.check()
    if args.json:
        import json

        print(json.dumps(report.summary(), ensure_ascii=False))
    else:
        print(report.text())
    return EXIT_OK if report.ok else EXIT_CHECK


def cmd_import(args) -> int:
    if Path(args.file).suffix.lower() in (".xlsm", ".xlsx", ".xls", ".xlam", ".xla"):
        from .excelimport import import_file as excel_import

        print(excel_import(args.file, args.out, vba=args.vba, force=args.force).line())
        return EXIT_OK
    from .mathcad import import_file

    print(import_file(args.file, args.out, force=args.force).line())
    return EXIT_OK


def cmd_bench(args) -> int:
    from . import blocks
    from .errors import InputError

    sheet = load_sheet(args)
    ref = sheet.spec.meta.get("bench")
    from .numerics import bench

    lines = bench.run(sheet, repeats=1 if args.quick else bench.REPEATS)
    if lines:
        print(bench.text(sheet, lines))
    if not ref and not sheet.spec.odes:
        if lines:
            return EXIT_OK
        raise InputError(
            f"{sheet.name} uses no numerical built-in (root, integral, maximum, ...), has no "
            '[[ode]] and declares no benchmark ([sheet] bench = "module.func")'
        )
    import pandas as pd

    tables = []
    if sheet.spec.odes:
        from .engine.ode import sheet_bench

        tables.append(pd.DataFrame(sheet_bench(sheet, quick=args.quick)))
    if ref:
        tables.append(blocks.get(ref, "bench").func(sheet, quick=args.quick))
    with pd.option_context(
        "display.max_rows", 500, "display.width", 200, "display.max_columns", 50
    ):
        print("\n\n".join(df.to_string(index=False) for df in tables))
    return EXIT_OK


def cmd_sweep(args) -> int:
    """``workbook sweep NAME --vary R3=40mm..60mm:21 [--output NAME=EXPR] [--out FILE]``."""
    import math

    from .errors import InputError
    from .outputs.atomic import check_target
    from .sweep import Progress, parse_output_option, parse_vary, sweep, write

    sheet = load_sheet(args)
    if not args.vary:
        raise InputError("give at least one --vary NAME=FIRST..LAST:COUNT, e.g. R3=40mm..60mm:21")
    varies = [parse_vary(item, sheet) for item in args.vary]
    outputs = [parse_output_option(o) for o in args.output] if args.output else None
    out = Path(args.out) if args.out else Path("reports") / f"{sheet.name}.sweep.xlsx"
    if not args.out:
        out.parent.mkdir(parents=True, exist_ok=True)
    check_target(out, kind="csv" if out.suffix.lower() == ".csv" else "xlsx", force=args.force)
    progress = Progress(math.prod(len(v.values) for v in varies))
    result = sweep(
        sheet,
        varies,
        outputs,
        mode=args.mode,
        scheduler=args.scheduler,
        workers=args.workers,
        progress=progress,
    )
    write(result, out, force=args.force, command=_sweep_command_line(args))
    print(f"wrote {out}: {result.summary()}")
    for i, err in enumerate(result.table["error"]):
        if err is not None:
            case = ", ".join(
                f"{h} = {result.table.iloc[i][h]}" for h in result.table.columns[: len(varies)]
            )
            print(f"  case {i + 1} ({case}) failed: {err}", file=sys.stderr)
    return EXIT_OK


def _sweep_command_line(args) -> str:
    parts = ["workbook", "sweep", args.name]
    parts += [f'--set "{s}"' for s in args.set]
    parts += [f"--vary {v}" for v in args.vary]
    parts += [f'--output "{o}"' for o in args.output]
    return " ".join(parts)


def cmd_serve(args) -> int:
    from .serve import serve

    return serve(args.name, port=args.port, open_browser=not args.no_browser)


def cmd_lsp(args) -> int:
    from .lsp import main as lsp_main

    return lsp_main()


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.version:
        from .version import __version__

        print(__version__)
        return EXIT_OK
    if not args.command:
        _parser().print_help()
        return EXIT_INPUT
    if args.command == "new":
        from .scaffold import cmd_new as handler
    else:
        handler = {
            "list": cmd_list,
            "run": cmd_run,
            "check": cmd_check,
            "bench": cmd_bench,
            "sweep": cmd_sweep,
            "import": cmd_import,
            "report": cmd_report,
            "serve": cmd_serve,
            "lsp": cmd_lsp,
        }[args.command]

    if not args.debug:  # the engine reports non-finite results itself, with the arguments
        import warnings

        warnings.simplefilter("ignore", RuntimeWarning)
    with _quiet_file_errors(args.debug):
        return run_command(handler, args)


@contextlib.contextmanager
def _quiet_file_errors(debug: bool):
    """A file left open by a writer that stopped on a full disk fails again when it is
    closed by the garbage collector ("Exception ignored in ... OSError"): that second report
    of the error already said is dropped (shown with --debug)."""
    import gc

    previous = sys.unraisablehook

    def hook(unraisable):
        if debug or not isinstance(unraisable.exc_value, OSError):
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        gc.collect()
        sys.unraisablehook = previous


def _grow_for_file(limits_time, path) -> None:
    """The default budget of an import grows with the size of the file imported."""
    try:
        size = os.path.getsize(path)
    except OSError:  # the import itself says what is wrong with the path
        return
    limits_time.grow_default(limits_time.SECONDS_PER_KILOBYTE * size / 1024, f"'{path}'")


def run_command(handler, args) -> int:
    """``handler(args)`` within the command's budget; every error as its exit status."""
    from . import limits_time
    from .errors import OutOfBudget, WorkbookError
    from .outputs.atomic import MOVED, Terminated, sigterm_as_interrupt

    moved = len(MOVED)
    try:
        seconds, source = limits_time.DEFAULT_SECONDS, "the default"
        if getattr(args, "time_limit", None) is not None:
            seconds = limits_time.check_seconds(args.time_limit, "--time-limit")
            source = "--time-limit"
        if args.command in ("serve", "lsp"):  # long-lived: each has no end to budget
            with sigterm_as_interrupt():
                return handler(args)
        with sigterm_as_interrupt(), limits_time.command_budget(seconds, source):
            if args.command == "import" and getattr(args, "file", None):
                _grow_for_file(limits_time, args.file)
            return handler(args)
    except WorkbookError as err:
        if args.debug:
            raise
        print(f"workbook: {err}", file=sys.stderr)
        return EXIT_INPUT
    except OutOfBudget as exc:  # the time or memory budget of the command ran out
        limits_time.disarm()
        if args.debug:
            raise
        print(f"workbook: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (RecursionError, MemoryError) as exc:  # a last resort behind the documented limits
        if args.debug:
            raise
        what = "nested too deeply" if isinstance(exc, RecursionError) else "too large for memory"
        print(
            f"workbook: limit exceeded: the worksheet is {what} (see docs/errors.md)",
            file=sys.stderr,
        )
        return EXIT_INPUT
    except KeyboardInterrupt as exc:
        if MOVED[moved:]:  # the signal came while they were moved into place: held till done
            names = ", ".join(str(p) for p in MOVED[moved:])
            print(f"workbook: interrupted after writing {names} (complete)", file=sys.stderr)
        else:
            print("workbook: interrupted; no output file was changed", file=sys.stderr)
        return 143 if isinstance(exc, Terminated) else 130
    except BrokenPipeError:  # the reader of the output went away (``workbook check | head``)
        # as the Python documentation says: stdout to devnull, so that the flush at exit
        # does not fail again; 141 is a shell's status of a command ended by SIGPIPE
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except Exception as exc:  # a bug of the engine or of a solver block, not of the worksheet
        if args.debug:
            raise
        print(
            f"workbook: internal error ({type(exc).__name__}: {exc}); this is a bug in workbook, "
            "not in your worksheet; no file was left half-written. Rerun with --debug for the "
            "traceback and report it.",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
