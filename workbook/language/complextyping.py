"""What typing refuses of complex values at load, and the kind of a typed value that a
reference or a call takes over (its shape, whether it is text, whether it is complex)."""

from __future__ import annotations

from ..errors import TemplateError
from . import expr as ex
from .typed import T


def value_kind(t: T) -> dict:
    """The shape, text and complex flags of ``t``, for a node that stands for its value (a
    reference to a definition, a call of a function)."""
    return {"shape": t.shape, "text": t.text, "complex": t.complex}


def real_only(name: str, entry, args) -> None:
    """Refuse complex arguments of a built-in of real numbers (its entry says which take them)."""
    if not entry.complex and any(a.complex for a in args):
        raise TemplateError(
            f"{name}() takes real numbers, and an argument is complex: pass Re(z), Im(z), "
            "abs(z) or arg(z)"
        )


def no_order(node: ex.Compare, typed) -> None:
    """Refuse ``<``, ``<=``, ``>``, ``>=`` between complex values (``==`` and ``!=`` stay)."""
    if any(t.complex for t in typed) and set(node.ops) - {"==", "!="}:
        raise TemplateError(
            f"{ex.to_text(node)!r}: complex numbers have no order; compare abs(z), Re(z) or Im(z)"
        )


def real_index(t: T, what: str, word: str) -> None:
    if t.complex:
        raise TemplateError(f"{what}: the {word} index is complex; an index is a number")


def real_in_program(t: T, node: ex.Node) -> T:
    """An expression of a program: complex values are not supported there."""
    if t.complex:
        raise TemplateError(
            f"{ex.to_text(node)!r}: complex values in a program are not supported; compute them "
            "in definitions"
        )
    return t
