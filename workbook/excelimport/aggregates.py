"""Excel's functions over lists of values (SUM, AVERAGE, MIN, MAX, COUNT, STDEV, ...) with
Excel's rules: of a reference (a range or one cell) only the cells that hold numbers count
(empty cells, texts and TRUE/FALSE are left out, as Excel leaves them out); a value written
in the formula counts as it is."""

from __future__ import annotations

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


def aggregate(ft, upper: str, args) -> str:
    """The translation of ``upper(args)`` by the formula translator ``ft``."""
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
