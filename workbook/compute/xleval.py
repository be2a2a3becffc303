"""A second, fast evaluator of Excel formula text for the live-cell check.

It reads the formula as Excel does (its own tokenizer and parser of the text the printer
wrote, Excel's precedence: negation above ``^``, ``^`` left to right, ``&``, comparisons
last) and computes it with Excel's rules for the functions the workbook writer uses:
errors propagate (``1/0`` is ``#DIV/0!``, ``SQRT(-1)`` is ``#NUM!``), ``IF`` evaluates only
the branch it takes, ``ATAN2(x, y)`` is atan2(y, x), ``MOD`` takes the sign of the
divisor, ``ROUND`` rounds half away from zero, ``SUM`` and ``MAX`` skip text in ranges,
operations on arrays go element by element. It shares nothing with the printer or the
engine. A formula that uses anything else raises :class:`Unsupported` when it is
compiled, and the check computes it with the `formulas` package instead
(:mod:`workbook.compute.livecheck`); tests/outputs/test_live_everywhere.py computes every formula
of the templates both ways.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable

import numpy as np


class Unsupported(Exception):
    """A formula this evaluator does not compute (the `formulas` package does)."""


class XlError(str):
    """An Excel error value (``#DIV/0!``, ``#NUM!``, ``#VALUE!``, ``#N/A``)."""


class _Err(Exception):
    def __init__(self, code: str):
        self.code = code


_TOKEN = re.compile(
    r"\s*(?:"
    r'(?P<str>"(?:[^"]|"")*")'
    r'|(?P<const>\{[^{}"]*\})'
    r"|(?P<num>(?:\d+\.?\d*|\.\d+)(?:[Ee][+-]?\d+)?)"
    r"|(?P<ref>(?:'[^']+'|[A-Za-z_][\w.]*)!\$?[A-Z]{1,3}\$?\d+(?::\$?[A-Z]{1,3}\$?\d+)?"
    r"|\$?[A-Z]{1,3}\$?\d+:\$?[A-Z]{1,3}\$?\d+|\$[A-Z]{1,3}\$?\d+|[A-Z]{1,3}\$\d+)"
    r"|(?P<name>[A-Za-z_\\][\w.]*)"
    r"|(?P<op><=|>=|<>|[-+*/^&=<>%,;(){}:])"
    r")"
)

Resolve = Callable[[str], object]
Fn = Callable[[Resolve], object]


def _tokens(text: str) -> list[tuple[str, str]]:
    out, at, text = [], 0, text.strip()
    while at < len(text):
        m = _TOKEN.match(text, at)
        if m is None or m.end() == at:
            raise Unsupported(f"cannot read {text[at : at + 20]!r}")
        at = m.end()
        kind = m.lastgroup
        out.append((kind, m[kind]))
    return out


def compile_formula(text: str) -> Fn:
    """``text`` (``=...``) as a function of a resolver of the names and references it reads
    (``resolve(key)``: a number, text, bool, None for an empty cell, or a 2-D object array
    of them for a range); the function returns a number, text, bool, :class:`XlError` or a
    2-D array."""
    parser = _Parser(_tokens(text.lstrip("=")))
    node = parser.expression(0)
    if parser.at != len(parser.toks):
        raise Unsupported(f"unexpected {parser.toks[parser.at][1]!r}")

    def run(resolve: Resolve):
        try:
            return _result(node(resolve))
        except _Err as err:
            return XlError(err.code)

    return run


def _result(v):
    if isinstance(v, np.ndarray):
        return v
    if isinstance(v, float) and not math.isfinite(v):
        return XlError("#NUM!")
    return v


# -- coercion -------------------------------------------------------------------------------
def _num(v) -> float:
    if type(v) is float and v - v == 0.0:
        return v
    if isinstance(v, bool):
        return 1.0 if v else 0.0
    if isinstance(v, (float, int)):
        f = float(v)
        if not math.isfinite(f):
            raise _Err("#NUM!")
        return f
    if v is None:
        return 0.0
    if isinstance(v, XlError):
        raise _Err(str(v))
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            raise _Err("#VALUE!") from None
    if isinstance(v, np.ndarray):
        if v.size == 1:
            return _num(v.flat[0])
        raise _Err("#VALUE!")
    raise _Err("#VALUE!")


def _array(v) -> np.ndarray:
    """A value as a 2-D float array (errors and text as nan)."""
    if isinstance(v, np.ndarray):
        if v.dtype == float:
            return v
        out = np.empty(v.shape, dtype=float)
        for idx, x in np.ndenumerate(v):
            try:
                out[idx] = _num(x)
            except _Err:
                out[idx] = math.nan
        return out
    return np.array([[_num(v)]])


def _bool(v) -> bool:
    if isinstance(v, bool):
        return v
    if isinstance(v, str) and not isinstance(v, XlError):
        up = v.upper()
        if up in ("TRUE", "FALSE"):
            return up == "TRUE"
        raise _Err("#VALUE!")
    return _num(v) != 0.0


def _text(v) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, XlError):
        raise _Err(str(v))
    if isinstance(v, str):
        return v
    if v is None:
        return ""
    f = _num(v)
    return str(int(f)) if f.is_integer() and abs(f) < 1e15 else f"{f:.15g}"


def _numbers(args) -> list[float]:
    """The numbers of arguments as SUM and MAX read them: a range's text, bools and empty
    cells skipped; a direct argument coerced."""
    out: list[float] = []
    for a in args:
        if isinstance(a, np.ndarray):
            for x in a.flat:
                if isinstance(x, XlError):
                    raise _Err(str(x))
                if isinstance(x, float) and not math.isfinite(x):
                    raise _Err("#NUM!")
                if isinstance(x, (float, int)) and not isinstance(x, bool):
                    out.append(float(x))
        else:
            out.append(_num(a))
    return out


# -- operators ------------------------------------------------------------------------------
def _arith(op: str, a: float, b: float) -> float:
    if op == "+":
        r = a + b
    elif op == "-":
        r = a - b
    elif op == "*":
        r = a * b
    elif op == "/":
        if b == 0.0:
            raise _Err("#DIV/0!")
        r = a / b
    else:  # ^
        if a == 0.0 and b < 0:
            raise _Err("#DIV/0!")
        if a == 0.0 and b == 0.0:
            raise _Err("#NUM!")
        if a < 0 and not float(b).is_integer():
            raise _Err("#NUM!")
        try:
            r = a**b
        except OverflowError:
            raise _Err("#NUM!") from None
    if not math.isfinite(r):
        raise _Err("#NUM!")
    return r


_NP_OPS = {
    "+": np.add,
    "-": np.subtract,
    "*": np.multiply,
    "/": np.divide,
    "^": np.power,
    "=": np.equal,
    "<>": np.not_equal,
    "<": np.less,
    ">": np.greater,
    "<=": np.less_equal,
    ">=": np.greater_equal,
}


def _rank(v):
    """Excel's order of values of different kinds: numbers < text < booleans."""
    if isinstance(v, bool):
        return (2, v)
    if isinstance(v, str):
        if isinstance(v, XlError):
            raise _Err(str(v))
        return (1, v.upper())
    return (0, _num(v))


def _compare(op: str, a, b) -> bool:
    ra, rb = _rank(a), _rank(b)
    if op == "=":
        return ra == rb
    if op == "<>":
        return ra != rb
    if op == "<":
        return ra < rb
    if op == ">":
        return ra > rb
    if op == "<=":
        return ra <= rb
    return ra >= rb


_FAST = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
}


def _binary(op: str, left: Fn, right: Fn) -> Fn:
    fast = _FAST.get(op)

    def run(r):
        a, b = left(r), right(r)
        if fast is not None and type(a) is float and type(b) is float:
            x = fast(a, b)
            if x - x == 0.0:  # finite (an inf or nan operand gives nan here)
                return x
            raise _Err("#NUM!")
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            if op == "&":
                raise Unsupported("& on arrays")
            with np.errstate(all="ignore"):
                out = _NP_OPS[op](_array(a), _array(b))
            return out.astype(float) if op not in "+-*/^" else out
        if op == "&":
            return _text(a) + _text(b)
        if op in _NP_OPS and op not in "+-*/^":
            return _compare(op, a, b)
        return _arith(op, _num(a), _num(b))

    return run


# -- functions ------------------------------------------------------------------------------
def _domain(fn: Callable[[float], float]) -> Callable[[float], float]:
    def run(x: float) -> float:
        try:
            r = fn(x)
        except (ValueError, OverflowError, ZeroDivisionError):
            raise _Err("#NUM!") from None
        if not math.isfinite(r):
            raise _Err("#NUM!")
        return r

    return run


def _round(x: float, d: float = 0.0) -> float:
    p = 10.0 ** int(d)
    return math.copysign(math.floor(abs(x) * p + 0.5) / p, x)


def _trunc(x: float, d: float = 0.0) -> float:
    p = 10.0 ** int(d)
    return math.trunc(x * p) / p


def _mod(a: float, b: float) -> float:
    if b == 0.0:
        raise _Err("#DIV/0!")
    return a - b * math.floor(a / b)


def _atan2(x: float, y: float) -> float:
    if x == 0.0 and y == 0.0:
        raise _Err("#DIV/0!")
    return math.atan2(y, x)


def _log(x: float, base: float = 10.0) -> float:
    if x <= 0 or base <= 0 or base == 1:
        raise _Err("#NUM!" if base != 1 else "#DIV/0!")
    return math.log(x) / math.log(base)


def _sign(x: float) -> float:
    return float((x > 0) - (x < 0))


#: functions of numbers, applied element by element to an array
_SCALAR: dict[str, Callable] = {
    "ABS": abs,
    "ACOS": _domain(math.acos),
    "ASIN": _domain(math.asin),
    "ATAN": math.atan,
    "COS": _domain(math.cos),
    "COSH": _domain(math.cosh),
    "EXP": _domain(math.exp),
    "INT": lambda x: float(math.floor(x)),
    "LN": _domain(math.log),
    "LOG10": _domain(math.log10),
    "SIN": _domain(math.sin),
    "SINH": _domain(math.sinh),
    "SQRT": _domain(math.sqrt),
    "TAN": _domain(math.tan),
    "TANH": math.tanh,
    "SIGN": _sign,
    "ATAN2": _atan2,
    "MOD": _mod,
    "POWER": lambda a, b: _arith("^", a, b),
    "ROUND": _round,
    "TRUNC": _trunc,
    "LOG": _log,
}


#: the same functions on arrays, as numpy computes them (a domain error is nan)
_UFUNC: dict[str, Callable] = {
    "ABS": np.abs,
    "ACOS": np.arccos,
    "ASIN": np.arcsin,
    "ATAN": np.arctan,
    "COS": np.cos,
    "COSH": np.cosh,
    "EXP": np.exp,
    "INT": np.floor,
    "LN": np.log,
    "LOG10": np.log10,
    "SIN": np.sin,
    "SINH": np.sinh,
    "SQRT": np.sqrt,
    "TAN": np.tan,
    "TANH": np.tanh,
    "SIGN": np.sign,
}


def _elementwise(fn: Callable, args: list, ufunc: Callable | None = None):
    if not any(isinstance(a, np.ndarray) for a in args):
        return fn(*(_num(a) for a in args))
    if ufunc is not None:
        with np.errstate(all="ignore"):
            out = ufunc(_array(args[0]))
        out[~np.isfinite(out)] = math.nan
        return out
    arrays = np.broadcast_arrays(*(_array(a) for a in args))
    out = np.empty(arrays[0].shape, dtype=float)
    for idx in np.ndindex(out.shape):
        try:
            out[idx] = fn(*(float(a[idx]) for a in arrays))
        except _Err:
            out[idx] = math.nan
    return out


def _index(args: list):
    arr, rest = args[0], [int(_num(a)) for a in args[1:]]
    a = arr if isinstance(arr, np.ndarray) else np.array([[arr]], dtype=object)
    if not rest or len(rest) > 2 or min(rest) < 1:
        raise Unsupported("INDEX with a whole row or column")
    if len(rest) == 1:
        i = rest[0] - 1
        if a.shape[0] == 1:
            r, c = 0, i
        elif a.shape[1] == 1:
            r, c = i, 0
        else:
            raise Unsupported("INDEX of a matrix with one index")
    else:
        r, c = rest[0] - 1, rest[1] - 1
    if r >= a.shape[0] or c >= a.shape[1]:
        raise _Err("#REF!")
    v = a[r, c]
    return float(v) if isinstance(v, np.floating) else v


def _match(args: list):
    value, arr = args[0], args[1]
    kind = int(_num(args[2])) if len(args) > 2 else 1
    items = list(arr.flat) if isinstance(arr, np.ndarray) else [arr]
    if kind == 0:
        for i, x in enumerate(items):
            if x is not None and _rank(x) == _rank(value):
                return float(i + 1)
        raise _Err("#N/A")
    found = None
    for i, x in enumerate(items):  # a sorted list: the last item on the right side of value
        if x is None:
            continue
        if (kind > 0 and _rank(x) <= _rank(value)) or (kind < 0 and _rank(x) >= _rank(value)):
            found = i
        else:
            break
    if found is None:
        raise _Err("#N/A")
    return float(found + 1)


def _sumproduct(args: list) -> float:
    arrays = [a if isinstance(a, np.ndarray) else np.array([[a]], dtype=object) for a in args]
    if any(a.shape != arrays[0].shape for a in arrays):
        raise _Err("#VALUE!")
    total = np.ones(arrays[0].shape)
    for a in arrays:
        vals = np.zeros(a.shape)
        for idx, x in np.ndenumerate(a):
            if isinstance(x, XlError):
                raise _Err(str(x))
            if isinstance(x, (float, int, np.floating)) and not isinstance(x, bool):
                if not math.isfinite(x):
                    raise _Err("#NUM!")
                vals[idx] = x
        total = total * vals
    return float(total.sum())


def _matrix(v) -> np.ndarray:
    a = _array(v)
    if np.isnan(a).any():
        raise _Err("#VALUE!")
    return a


def _minverse(a) -> np.ndarray:
    m = _matrix(a)
    if m.shape[0] != m.shape[1]:
        raise _Err("#VALUE!")
    if np.linalg.matrix_rank(m) < m.shape[0]:
        raise _Err("#NUM!")
    return np.linalg.inv(m)


def _mmult(a, b) -> np.ndarray:
    x, y = _matrix(a), _matrix(b)
    if x.shape[1] != y.shape[0]:
        raise _Err("#VALUE!")
    return x @ y


def _max(args: list) -> float:
    n = _numbers(args)
    return max(n) if n else 0.0


def _min(args: list) -> float:
    n = _numbers(args)
    return min(n) if n else 0.0


def _product(args: list) -> float:
    n = _numbers(args)
    return math.prod(n) if n else 0.0


def _and(args: list) -> bool:
    return all(_bools(args))


def _or(args: list) -> bool:
    return any(_bools(args))


def _bools(args: list) -> list[bool]:
    out = []
    for a in args:
        if isinstance(a, np.ndarray):
            out.extend(_bool(x) for x in a.flat if x is not None and not isinstance(x, str))
        else:
            out.append(_bool(a))
    return out


def _na(args: list):
    raise _Err("#N/A")


#: functions of whole arguments (ranges and arrays as they are)
_AGGREGATE: dict[str, Callable[[list], object]] = {
    "SUM": lambda args: math.fsum(_numbers(args)),
    "SUMSQ": lambda args: math.fsum(x * x for x in _numbers(args)),
    "PRODUCT": _product,
    "MAX": _max,
    "MIN": _min,
    "AND": _and,
    "OR": _or,
    "NOT": lambda args: not _bool(args[0]),
    "PI": lambda args: math.pi,
    "NA": _na,
    "INDEX": _index,
    "MATCH": _match,
    "SUMPRODUCT": _sumproduct,
    "MMULT": lambda args: _mmult(args[0], args[1]),
    "MINVERSE": lambda args: _minverse(args[0]),
    "MDETERM": lambda args: float(np.linalg.det(_matrix(args[0]))),
    "TRANSPOSE": lambda args: args[0].T if isinstance(args[0], np.ndarray) else args[0],
}


def _if(args: list[Fn]) -> Fn:
    cond = args[0]
    yes = args[1] if len(args) > 1 else (lambda r: True)
    no = args[2] if len(args) > 2 else (lambda r: False)

    def run(r):
        c = cond(r)
        if isinstance(c, np.ndarray):
            a, b = yes(r), no(r)
            mask = _array(c) != 0
            return np.where(mask, _array(a), _array(b))
        return yes(r) if _bool(c) else no(r)

    return run


def _choose(args: list[Fn]) -> Fn:
    def run(r):
        index = args[0](r)
        if isinstance(index, np.ndarray):  # an array of choices: element by element
            picks = _array(index)
            values = [_array(a(r)) for a in args[1:]]
            out = np.full(picks.shape, math.nan)
            for idx, k in np.ndenumerate(picks):
                if 1 <= k <= len(values):
                    v = values[int(k) - 1]
                    out[idx] = v[tuple(min(i, n - 1) for i, n in zip(idx, v.shape))]
            return out
        i = int(_num(index))
        if i < 1 or i >= len(args):
            raise _Err("#VALUE!")
        return args[i](r)

    return run


def _call(name: str, args: list[Fn]) -> Fn:
    if name == "IF":
        return _if(args)
    if name == "CHOOSE":
        return _choose(args)
    if name in _SCALAR:
        fn, ufunc = _SCALAR[name], _UFUNC.get(name)
        return lambda r: _elementwise(fn, [a(r) for a in args], ufunc)
    if name in _AGGREGATE:
        fn2 = _AGGREGATE[name]
        return lambda r: fn2([a(r) for a in args])
    raise Unsupported(f"function {name}")


# -- the parser -----------------------------------------------------------------------------
_BINARY = {"=": 1, "<>": 1, "<": 1, ">": 1, "<=": 1, ">=": 1, "&": 2, "+": 3, "-": 3}
_BINARY.update({"*": 4, "/": 4, "^": 5})


class _Parser:
    def __init__(self, toks: list[tuple[str, str]]):
        self.toks, self.at = toks, 0

    def peek(self) -> tuple[str, str]:
        return self.toks[self.at] if self.at < len(self.toks) else ("end", "")

    def take(self, value: str | None = None) -> tuple[str, str]:
        tok = self.peek()
        if value is not None and tok[1] != value:
            raise Unsupported(f"expected {value!r}, found {tok[1]!r}")
        self.at += 1
        return tok

    def expression(self, level: int) -> Fn:
        left = self.unary()
        while True:
            kind, op = self.peek()
            prec = _BINARY.get(op) if kind == "op" else None
            if prec is None or prec <= level:
                return left
            self.take()
            left = _binary(op, left, self.expression(prec))

    def unary(self) -> Fn:
        kind, op = self.peek()
        if kind == "op" and op in "+-":
            self.take()
            child = self.unary()
            if op == "+":
                return child
            return lambda r: _negate(child(r))
        node = self.primary()
        while self.peek() == ("op", "%"):
            self.take()
            inner = node
            node = _binary("/", inner, lambda r: 100.0)
        return node

    def primary(self) -> Fn:
        kind, text = self.take()
        if kind == "num":
            value = float(text)
            return lambda r: value
        if kind == "str":
            s = text[1:-1].replace('""', '"')
            return lambda r: s
        if kind == "ref":
            return lambda r: r(text)
        if kind == "name":
            if self.peek() == ("op", "("):
                return self.call(text.upper())
            up = text.upper()
            if up in ("TRUE", "FALSE"):
                b = up == "TRUE"
                return lambda r: b
            return lambda r: r(text)
        if text == "(":
            inner = self.expression(0)
            self.take(")")
            return inner
        if kind == "const":
            value = _constant(text)
            return lambda r: value
        raise Unsupported(f"unexpected {text!r}")

    def call(self, name: str) -> Fn:
        name = name.removeprefix("_XLFN.")
        self.take("(")
        args: list[Fn] = []
        if self.peek() != ("op", ")"):
            while True:
                args.append(self.expression(0))
                if self.peek() == ("op", ","):
                    self.take()
                    continue
                break
        self.take(")")
        return _call(name, args)


@functools.lru_cache(maxsize=512)
def _constant(text: str) -> np.ndarray:
    """An array constant ``{1,2;3,4}`` (numbers and TRUE/FALSE; rows split by ``;``)."""
    rows = [row.split(",") for row in text[1:-1].split(";")]
    if any(len(row) != len(rows[0]) for row in rows):
        raise Unsupported("ragged array constant")

    def element(x: str):
        x = x.strip()
        if x.upper() in ("TRUE", "FALSE"):
            return x.upper() == "TRUE"
        try:
            return float(x)
        except ValueError:
            raise Unsupported(f"array constant element {x!r}") from None

    value = np.array([[element(x) for x in row] for row in rows], dtype=object)
    if all(isinstance(x, float) for x in value.flat):
        value = value.astype(float)
    value.flags.writeable = False
    return value


def _negate(v):
    if isinstance(v, np.ndarray):
        return -_array(v)
    return -_num(v)
