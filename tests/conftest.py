import gc
import os
import sys
from pathlib import Path

import pytest

import workbook

TESTS = Path(__file__).parent
sys.path.insert(0, str(TESTS))  # the tests' own modules: helpers

from helpers.sheets import write_template  # noqa: E402
from hypothesis import settings  # noqa: E402

# Property tests draw the same examples on every run (a run's time and verdict do not depend
# on luck); WORKBOOK_EXPLORE=1 draws new ones, to look for what the fixed ones miss.
settings.register_profile("reproducible", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("explore" if os.environ.get("WORKBOOK_EXPLORE") else "reproducible")

# Run from a source checkout without installing (python -m pytest): the tests' subprocesses
# start in temporary folders, so they find the package through PYTHONPATH.
_SOURCE = TESTS.parent
if Path(workbook.__file__).resolve().parent.parent == _SOURCE.resolve():
    os.environ["PYTHONPATH"] = os.pathsep.join(
        filter(None, [str(_SOURCE), os.environ.get("PYTHONPATH", "")])
    )


def pytest_collection(session):
    """No collection while the tests are collected (what they import stays alive anyway)."""
    gc.disable()


def pytest_collection_finish(session):
    """What collection leaves alive (the libraries, the test modules and their tables) lives
    to the end of the run: frozen out of the garbage collector's sight, each full collection
    no longer walks it, and a test costs its own work instead of a walk over the heap that the
    tests collected before it built (measured: the complex-number import tests take 0.7 s each
    in the whole run without it, 0.05 s with it)."""
    gc.collect()
    gc.freeze()
    gc.enable()


@pytest.fixture(scope="session")
def concave():
    import workbook

    return workbook.load("concave-cam")


@pytest.fixture(scope="module")
def sheet(request, tmp_path_factory):
    """The test module's worksheet: its ``SHEET`` text, written to a folder of its own and
    loaded once per module (a module with another sheet defines its own ``sheet``)."""
    import workbook

    folder = tmp_path_factory.mktemp(request.module.__name__)
    return workbook.load(write_template(folder, request.module.SHEET))


@pytest.fixture
def sheet_from(tmp_path):
    """``sheet_from(text)``: a Sheet from template text (workbook.loads); files the text
    names ([data] CSV) are read from the test's tmp_path."""
    import workbook

    def load(text: str, name: str = "sheet", parts=None):
        return workbook.loads(text, name=name, folder=tmp_path, parts=parts)

    return load


@pytest.fixture(scope="session")
def load_text(tmp_path_factory):
    """``load_text(text)``: a Sheet from template text (workbook.loads), for a module-scoped
    fixture that loads its sheet once per module (``sheet_from`` is per test); files the text
    names are read from ``folder`` (by default a folder of the session's)."""
    import workbook

    session = tmp_path_factory.mktemp("load_text")

    def load(text: str, name: str = "sheet", folder=None, parts=None):
        return workbook.loads(text, name=name, folder=folder or session, parts=parts)

    return load
