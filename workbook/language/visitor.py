"""One way to walk a tree: dispatch on the node's class name, refuse nodes nobody handles.

Every back end (numpy, Excel, sympy, MathML, text) and every analysis that walks the
expression tree (``workbook.language.expr``) or the typed tree (``workbook.language.typecheck``)
subclasses
:class:`Visitor` and writes one ``visit_<NodeClass>`` method per node kind. A node kind
without a method is an error (:class:`UnhandledNode`), never a silent default.
"""

from __future__ import annotations

from typing import Any


class UnhandledNode(TypeError):
    """A visitor met a node kind it has no method for (a bug of the engine)."""


class Visitor:
    """Base of all tree walkers: ``visit(node, *args)`` calls ``visit_<ClassName>``."""

    def visit(self, node: Any, *args: Any, **kwargs: Any) -> Any:
        method = getattr(self, "visit_" + type(node).__name__, None)
        if method is None:
            raise UnhandledNode(
                f"{type(self).__name__} has no visit_{type(node).__name__} "
                f"for {type(node).__name__} nodes"
            )
        return method(node, *args, **kwargs)
