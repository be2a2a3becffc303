"""Running cases one by one: in this process, in a process pool, or on a Dask cluster.

Only plain data crosses process boundaries (the template's path and text, the input
overrides, the output texts); each process loads the Sheet once.
"""

from __future__ import annotations

import os
import re
import time
from pathlib import Path

import numpy as np

from ..errors import InputError, WorkbookError
from ..language import units as un
from .outputs import Output, evaluate_outputs

_SHEETS: dict[tuple[str, str], object] = {}


def _sheet_for(path: str, text: str):
    """The template's Sheet (with its own defaults), loaded once per process.

    The task carries the template's text too: a worker that cannot read the same file
    (a remote Dask worker) loads a copy of it.
    """
    import hashlib

    key = (path, hashlib.sha256(text.encode("utf-8")).hexdigest())
    if key not in _SHEETS:
        import workbook

        p = Path(path)
        try:
            same = p.is_file() and p.read_text(encoding="utf-8") == text
        except OSError:
            same = False
        if not same:
            import tempfile

            p = Path(tempfile.mkdtemp(prefix="workbook-sweep-")) / Path(path).name
            p.write_text(text, encoding="utf-8")
        _SHEETS[key] = workbook.load(p)
    return _SHEETS[key]


def _prime(sheet) -> tuple[str, str]:
    """Put ``sheet``'s template into this process's cache (forked workers inherit it)."""
    import hashlib

    from ..engine.sheet import Sheet

    path = str(Path(sheet.spec.path).resolve())
    text = sheet.spec.text
    key = (path, hashlib.sha256(text.encode("utf-8")).hexdigest())
    if key not in _SHEETS:
        _SHEETS[key] = Sheet(sheet.full_spec, None, sheet.typer, sheet.parts)
    return path, text


def _overrides(values: dict) -> dict:
    out = {}
    for name, v in values.items():
        if isinstance(v, tuple):
            mag, unit = v
            if isinstance(mag, str):  # a choice
                out[name] = mag
            else:
                out[name] = un.registry().Quantity(float(mag), unit) if unit else float(mag)
        else:
            out[name] = v
    return out


def run_case(task: tuple) -> tuple[int, dict | None, str | None, float]:
    """One case: ``(index, (template_path, template_text), base_values, case_values, outputs)``.

    Only plain data crosses process boundaries; the Sheet is loaded (once per process)
    from the template path. Returns (index, values or None, error or None, seconds).
    """
    index, (path, text), base, case, outputs = task
    start = time.perf_counter()
    try:
        sheet = _sheet_for(path, text)
        sheet = sheet.with_inputs(**_overrides({**base, **case}))
        outs = [Output.parse(n, text, unit) for n, text, unit in outputs]
        with np.errstate(all="ignore"):  # a domain error is reported as this case's error
            values = evaluate_outputs(sheet, outs)
        return index, values, None, time.perf_counter() - start
    except WorkbookError as err:
        return index, None, getattr(err, "message", str(err)), time.perf_counter() - start
    except Exception as err:  # noqa: BLE001 - a worker's last resort: any failure of one case is
        # returned to the driver as that case's error (named by its type), which the sweep
        # reports; raised in a pool process, it would stop every case
        return index, None, f"{type(err).__name__}: {err}", time.perf_counter() - start


def base_values(sheet) -> dict:
    """The sheet's input values as plain data (magnitude and unit text, or a choice)."""
    out = {}
    for name, v in sheet.values.items():
        out[name] = v if isinstance(v, str) else (float(v.magnitude), str(v.units))
    return out


def make_tasks(sheet, outs: list[Output], cases: list[dict]) -> list[tuple]:
    """One plain-data task per case (see :func:`run_case`)."""
    template = _prime(sheet)
    base = base_values(sheet)
    spec = tuple((o.name, o.text, o.unit_text) for o in outs)
    return [(i, template, base, case, spec) for i, case in enumerate(cases)]


def run_tasks(tasks: list[tuple], mode: str, scheduler, workers: int | None, timeout: float = 20.0):
    """Run the tasks serially, in a process pool or on Dask; yield run_case's results."""
    if mode == "serial" or (mode == "processes" and len(tasks) == 1):
        for task in tasks:
            yield run_case(task)
        return
    if mode == "processes":
        import multiprocessing as mp
        import threading
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from concurrent.futures.process import BrokenProcessPool

        # fork (the workers inherit the loaded sheet) when this process has no other
        # threads to copy in a half-held state (a notebook or a Dask client has some)
        methods = mp.get_all_start_methods()
        if "fork" in methods and threading.active_count() == 1:
            method = "fork"
        else:
            method = "forkserver" if "forkserver" in methods else "spawn"
        n = max(1, min(pool_size(workers), len(tasks)))
        pool = ProcessPoolExecutor(max_workers=n, mp_context=mp.get_context(method))
        futures = {pool.submit(run_case, t): t[0] for t in tasks}
        try:
            for fut in as_completed(futures):
                try:
                    yield fut.result()
                except BrokenProcessPool as err:  # a worker died (crash, out of memory)
                    yield futures[fut], None, f"worker process died: {err}", 0.0
        except BaseException:  # Ctrl-C or an error: do not wait for the queued cases
            pool.shutdown(wait=False, cancel_futures=True)
            raise
        pool.shutdown(wait=True)
        return
    if mode == "dask":
        yield from _run_dask(tasks, scheduler, timeout)
        return
    raise InputError(f"unknown sweep mode {mode!r}")


def _run_dask(tasks: list[tuple], scheduler, timeout: float = 20.0):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise InputError(
            "--scheduler needs dask.distributed: pip install 'workbook[dask]'"
        ) from None
    own = not isinstance(scheduler, Client)
    options = {}
    if own:
        check_scheduler(scheduler, timeout)
        if str(scheduler).strip().startswith("tls://"):
            options["security"] = tls_security(scheduler)
    try:
        client = Client(scheduler, timeout=f"{timeout}s", **options) if own else scheduler
    except OSError as err:
        raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {err}") from None
    try:
        futures = client.map(run_case, tasks, pure=False)
        for fut in as_completed(futures):
            if fut.status == "error":
                exc = fut.exception()
                index = futures.index(fut)
                yield index, None, f"{type(exc).__name__}: {exc}", 0.0
            else:
                yield fut.result()
    finally:
        if own:
            client.close()


def tls_security(address: str):
    """The client's TLS settings for a ``tls://`` scheduler, from Dask's configuration
    (``distributed.comm.tls.ca-file``, ``.client.cert``, ``.client.key``, or the
    ``DASK_DISTRIBUTED__COMM__TLS__...`` environment variables). Dask's TLS is mutual: without
    a CA file and a client certificate there is no TLS context, and the address is refused."""
    from distributed.security import Security

    needs = (
        f"--scheduler {address}: a tls:// scheduler needs Dask's TLS settings, the CA file and "
        "the client's certificate (and key): distributed.comm.tls.ca-file, .client.cert and "
        ".client.key in the Dask configuration, or DASK_DISTRIBUTED__COMM__TLS__CA_FILE, "
        "..._CLIENT__CERT and ..._CLIENT__KEY"
    )
    try:
        security = Security()
        context = security.get_connection_args("client")["ssl_context"]
    except (OSError, ValueError) as err:
        raise InputError(f"{needs} ({err})") from None
    if context is None:
        raise InputError(needs)
    return security


def pool_size(workers: int | None) -> int:
    """Processes of the local pool: ``workers``, at most the CPU count (more would only
    queue; a process per case of a large grid would exhaust memory)."""
    cpus = os.cpu_count() or 1
    if workers is None:
        return cpus
    if workers < 1:
        raise InputError(f"--workers {workers}: give at least 1")
    if workers > cpus:
        import sys

        print(
            f"workbook: --workers {workers} is more than the {cpus} CPUs; using {cpus} processes",
            file=sys.stderr,
        )
    return min(workers, cpus)


_ADDRESS = re.compile(
    r"^(?:(tcp|tls)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9][A-Za-z0-9.-]*):(\d{1,5})$"
)


def check_scheduler(address, timeout: float) -> None:
    """Refuse an address that is not ``[tcp|tls]://HOST:PORT``, and a TCP server that is not a
    Dask scheduler: a scheduler sends its handshake as soon as it accepts a connection; a
    server that says nothing within ``timeout`` seconds (a web server waits for a request)
    would make the client wait forever."""
    import socket

    text = str(address).strip()
    m = _ADDRESS.match(text)
    if not isinstance(address, str) or m is None or not 0 < int(m.group(3)) < 65536:
        raise InputError(
            f"--scheduler {text[:100]!r}: write the Dask scheduler's address as "
            "tcp://HOST:PORT (or tls://HOST:PORT)"
        )
    if m.group(1) == "tls":
        return  # a TLS server waits for the client: nothing to probe before the client's timeout
    host = m.group(2).strip("[]")
    try:
        conn = socket.create_connection((host, int(m.group(3))), timeout=timeout)
    except OSError as err:
        raise InputError(f"cannot reach the Dask scheduler at {text}: {err}") from None
    try:
        conn.settimeout(timeout)
        first = conn.recv(8)
    except TimeoutError:
        raise InputError(
            f"--scheduler {text}: the server there sent no Dask handshake within {timeout:g} s "
            "(is it a Dask scheduler?)"
        ) from None
    except OSError as err:
        raise InputError(f"cannot reach the Dask scheduler at {text}: {err}") from None
    finally:
        conn.close()
    if not first:
        raise InputError(f"--scheduler {text}: the server closed the connection at once")
