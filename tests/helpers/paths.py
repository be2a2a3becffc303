"""Where the tests find the repository, their data and the third-party corpora (``../shared``
beside the repository, absent outside CI): the same from every test folder."""

from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
ROOT = TESTS.parent
DATA = TESTS / "data"
SHARED = ROOT.parent / "shared"
