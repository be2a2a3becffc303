"""The verdicts of a check report, in one place (docs/architecture.md, Words).

A printed value (a row of the report) is ``pass`` (reproduced within its tolerance), ``FAIL``
(computed, outside it), ``misprint`` (a declared misprint; its correction, if given, is
reproduced), ``info`` (a set listed for information, never failing) or ``error`` (it could
not be computed). A finding is ``ok``, ``info``, ``warning`` or ``fail``. ``FAIL`` is in
capitals so that it stands out in the text report.
"""

from __future__ import annotations

ROW_VERDICTS = ("pass", "FAIL", "misprint", "info", "error")
FINDING_VERDICTS = ("ok", "info", "warning", "fail")

REPRODUCED = frozenset({"pass", "misprint"})  # a checked printed value the engine reproduces
NOT_FAILED = frozenset({"pass", "misprint", "info"})  # shown as good
ROW_FAILED = frozenset({"FAIL", "error"})  # makes `workbook check` exit 1
FINDING_FAILED = frozenset({"fail"})  # makes `workbook check` exit 1
FINDING_FLAGGED = frozenset({"warning", "fail"})  # printed on stderr by `workbook run`
