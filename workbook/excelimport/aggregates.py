"""Excel's functions over lists of values (SUM, AVERAGE, MIN, MAX, COUNT, STDEV, ...) with
Excel's rules: of a reference (a range or one cell) only the cells that hold numbers count
(empty cells, texts and TRUE/FALSE are left out, as Excel leaves them out); a value written
in the formula counts as it is."""

from __future__ import annotations

from .formula_terms import FormulaProblem, holds_number

#: Excel function -> (the language's form of the list ``{0}``, its value when the list is empty
#: (None: Excel's #DIV/0!), the fewest values it takes (fewer: #DIV/0!))
AGGREGATES: dict[str, tuple[str, str | None, int]] = {
    "SUM": ("+", "0", 0),
    "AVERAGE": ("mean([{0}])", None, 1),
    "MIN": ("min", "0", 0),
    "MAX": ("max", "0", 0),
    "COUNT": ("count", "0", 0),
    "PRODUCT": ("product([{0}])", "0", 0),
    "MEDIAN": ("median([{0}])", None, 1),
    "STDEV": ("Stdev([{0}])", None, 2),
    "STDEV.S": ("Stdev([{0}])", None, 2),
    "STDEVP": ("stdev([{0}])", None, 1),
    "STDEV.P": ("stdev([{0}])", None, 1),
    "VAR": ("Var([{0}])", None, 2),
    "VAR.S": ("Var([{0}])", None, 2),
    "VARP": ("var([{0}])", None, 1),
    "VAR.P": ("var([{0}])", None, 1),
    "SUMSQ": ("sumsq", "0", 0),
}


#: the functions of a list that take ``IF(condition, range)`` in an array formula, element by
#: element (the elements whose condition is FALSE are left out, as Excel leaves FALSE out)
SELECTING = ("SUM", "AVERAGE", "MIN", "MAX", "COUNT")


def aggregate(ft, upper: str, args) -> str:
    """The translation of ``upper(args)`` by the formula translator ``ft``."""
    if len(args) == 1 and upper in SELECTING:
        selected = _selected(ft, upper, args[0])
        if selected is not None:
            return selected
    how, empty, fewest = AGGREGATES[upper]
    items: list[str] = []
    for a in args:
        cells = ft.cells_of(a, numbers_only=True)
        if cells is not None:
            items += cells
        elif a[0] == "leaf" and a[1] == "String":
            if upper == "COUNT":
                continue  # COUNT("abc") counts nothing
            items.append(ft.value(a, 1))
        else:
            items.append(ft.value(a, 1))
    if len(items) < max(fewest, 1):
        if empty is None or len(items) < fewest:
            return "(1/0)"  # #DIV/0! in Excel
        return empty
    if how == "count":
        return str(len(items))
    if how == "+":
        return "(" + " + ".join(items) + ")" if len(items) > 1 else items[0]
    if how == "sumsq":
        return "(" + " + ".join(f"({x})^2" for x in items) + ")"
    if how in ("min", "max"):
        return f"{how}({', '.join(items)})" if len(items) > 1 else items[0]
    return how.format(", ".join(items))


def _range_shape(ft, node) -> tuple[int, int] | None:
    if node[0] != "leaf" or node[1] != "Range" or ft.is_name_formula(node[2]):
        return None
    ref = ft.ref_of(node[2])
    return (ref.r2 - ref.r1 + 1, ref.c2 - ref.c1 + 1)


def _selected(ft, upper: str, node) -> str | None:
    """``MIN(IF(E15:E24>0, E15:E24))`` in an array formula: Excel evaluates the IF element by
    element and the function leaves out the FALSE ones. Each element's condition and cell:
    SUM adds ``(v if c otherwise 0)``, COUNT counts ``(1 if c otherwise 0)``, AVERAGE divides
    the two (none selected: #DIV/0!), and MIN takes the least of the values with those not
    selected replaced by the greatest of them (MAX: the least), 0 where none is selected, as
    Excel's MIN of no numbers. Only where the values are a range whose every cell holds a
    number; None where the argument is not such an IF."""
    if not ft.in_array or node[0] != "fn" or node[1].upper() != "IF" or len(node[2]) != 2:
        return None
    test, values = node[2]
    shape = _range_shape(ft, values)
    if shape is None or shape == (1, 1):
        return None

    names = ft.cells_of(values)
    ref = ft.ref_of(values[2])
    for r in range(ref.r1, ref.r2 + 1):
        for c in range(ref.c1, ref.c2 + 1):
            cell = ft.book.cell(ref.sheet, r, c)
            if not holds_number(cell) or isinstance(cell.value, str):
                raise FormulaProblem(f"{upper}(IF(...)) over a range of other than numbers")
    conditions = []
    for k in range(len(names)):
        ft.element = (shape, k)
        try:
            conditions.append(ft.condition(test))
        finally:
            ft.element = None
    picks = [f"({v} if {c} otherwise 0)" for v, c in zip(names, conditions)]
    counts = "(" + " + ".join(f"(1 if {c} otherwise 0)" for c in conditions) + ")"
    if upper == "SUM":
        return "(" + " + ".join(picks) + ")"
    if upper == "COUNT":
        return counts
    if upper == "AVERAGE":
        return f"(({' + '.join(picks)})/{counts})"
    other = f"{'max' if upper == 'MIN' else 'min'}({', '.join(names)})"
    chosen = [f"({v} if {c} otherwise {other})" for v, c in zip(names, conditions)]
    none = " and ".join(f"not ({c})" for c in conditions)
    return f"(0 if {none} otherwise {upper.lower()}({', '.join(chosen)}))"
