"""Error types the engine raises for user mistakes.

Every error carries where it happened (template file, line, definition) so that
the command line can print one actionable paragraph instead of a traceback.
"""

from __future__ import annotations

import copy


class WorkbookError(Exception):
    """Base class: a user-facing error with a location."""

    kind = "error"

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        definition: str | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.file = file
        self.line = line
        self.definition = definition

    def located(self, *, file=None, line=None, definition=None) -> WorkbookError:
        """Fill in location fields that are still unknown; returns self."""
        self.file = self.file or file
        self.line = self.line or line
        self.definition = self.definition or definition
        return self

    def reworded(self, message: str) -> WorkbookError:
        """A copy of this error (its type, location and fields) with ``message`` for its own:
        an error caught to add what the caller knows is raised again as a new value, and the
        one caught (perhaps remembered) is left as it was."""
        out = copy.copy(self)
        out.__dict__ = dict(self.__dict__)
        out.message = message
        out.args = (message,)
        return out

    def __str__(self) -> str:
        where = []
        if self.file:
            where.append(f"{self.file}:{self.line}" if self.line else self.file)
        if self.definition:
            where.append(f"in '{self.definition}'")
        prefix = ", ".join(where)
        return (
            f"{prefix}: {self.kind}: {self.message}" if prefix else f"{self.kind}: {self.message}"
        )


class TemplateError(WorkbookError):
    """The worksheet text is malformed: syntax, unknown names, bad structure."""

    kind = "template error"


class ShapeError(TemplateError):
    """A number where a vector or matrix is needed (indexed, or given to rows()): a function
    whose body is typed at numbers says so when nothing calls it with arrays."""


class UnitError(WorkbookError):
    """Dimensions do not agree."""

    kind = "unit error"


class DomainError(WorkbookError):
    """A formula left its mathematical domain (sqrt of a negative, 0/0, ...)."""

    kind = "domain error"


class InputError(WorkbookError):
    """A value given by the user (input override, --set, argument) is unusable."""

    kind = "input error"


class LimitError(WorkbookError):
    """A documented resource limit was hit (size, depth, iterations, time)."""

    kind = "limit exceeded"


class OutOfBudget(BaseException):
    """The command's budget of time or memory ran out (workbook.limits_time): the command
    stops. A BaseException, as KeyboardInterrupt, so that no handler that turns a
    WorkbookError into a value that fails keeps it; ``error`` is the LimitError that says
    where and what to change (the command line prints it and exits 2)."""

    def __init__(self, error: LimitError):
        super().__init__(str(error))
        self.error = error

    def __str__(self) -> str:
        return str(self.error)


class NotSymbolic(WorkbookError):
    """The expression contains something SymPy cannot represent (a solver block)."""

    kind = "not symbolic"


class NotLive(Exception):
    """An expression cannot be a live Excel formula (a solver block, or too long).

    Not a user error: the writer then writes the value as a number, with a note.
    """
