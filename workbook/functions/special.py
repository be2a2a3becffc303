"""Special functions as Mathcad names them: the gamma function (Mathcad's ``Γ``), the error
function and its complement (``erf``, ``erfc``), the Bessel functions of whole order
(``bessel_j``, ``bessel_y``, ``bessel_i``, ``bessel_k``: Mathcad's ``Jn``, ``Yn``, ``In``,
``Kn``, and ``J0``, ``J1``, ... their orders 0 and 1), and the counting functions
``factorial`` (Mathcad's operator ``n!``), ``combin`` and ``permut``.

Every argument is a plain number (SciPy computes them). Where the function is not defined (a
pole of gamma, an order that is not a whole number, a count that is not a whole number) the
value is not a number, and the engine names the argument that is outside (the ``domain`` of
each entry). In Excel each is its worksheet function: ``GAMMA``, ``ERF``, ``ERFC``,
``BESSELJ(x, n)`` (x first), ``FACT``, ``COMBIN`` and ``PERMUT``; Excel truncates an order or
a count to a whole number, and the domain checks here refuse one that is not whole first.
"""

from __future__ import annotations

import numpy as np

from ..language import typed as ty
from ..language.expr import PREC
from .entry import Builtin, Domain, UnitContext, register
from .excel_functions import stored


def _special():
    import scipy.special

    return scipy.special


def _plain_numbers(ctx: UnitContext, name: str, args: tuple) -> ty.T:
    """Every argument a plain number, and the result."""
    plain = tuple(ctx.plain(a, f"{name}()") for a in args)
    return ty.TFunc(ctx.dimensionless, func=name, args=plain)


def _not_whole(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(v) | (v != np.round(v))


def _negative_or_not_whole(v: np.ndarray) -> np.ndarray:
    return _not_whole(v) | (np.asarray(v, dtype=float) < 0)


def _pole(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return (v <= 0) & (v == np.round(v))


def _not_positive(v: np.ndarray) -> np.ndarray:
    return np.asarray(v, dtype=float) <= 0


# -- numpy (SciPy) --------------------------------------------------------------------------------
def gamma(x):
    """The gamma function; not a number at its poles (0, -1, -2, ...)."""
    x = np.asarray(x, dtype=float)
    return np.where(_pole(x), np.nan, _special().gamma(x))


def factorial(n):
    """n! of a whole number n >= 0 (gamma(n + 1)); not a number otherwise."""
    n = np.asarray(n, dtype=float)
    bad = _negative_or_not_whole(n)
    return np.where(bad, np.nan, _special().gamma(np.where(bad, 0.0, n) + 1))


def _counts(n, k):
    n, k = np.broadcast_arrays(np.asarray(n, dtype=float), np.asarray(k, dtype=float))
    bad = _negative_or_not_whole(n) | _negative_or_not_whole(k) | (k > n)
    return np.where(bad, 0.0, n), np.where(bad, 0.0, k), bad


def combin(n, k):
    """The number of subsets of k of n things, n!/(k!(n - k)!), whole 0 <= k <= n."""
    n, k, bad = _counts(n, k)
    return np.where(bad, np.nan, np.round(_special().comb(n, k, exact=False)))


def permut(n, k):
    """The number of orderings of k of n things, n!/(n - k)!, whole 0 <= k <= n."""
    n, k, bad = _counts(n, k)
    return np.where(bad, np.nan, np.round(_special().perm(n, k, exact=False)))


def _bessel(kind: str):
    def f(n, x):
        n, x = np.broadcast_arrays(np.asarray(n, dtype=float), np.asarray(x, dtype=float))
        bad = _not_whole(n)
        if kind in ("y", "k"):
            bad = bad | (x <= 0)
        order = np.where(bad, 0.0, n)
        at = np.where(bad, 1.0, x)
        s = _special()
        if kind == "j":
            value = s.jv(order, at)
        elif kind == "y":
            value = s.yn(order.astype(int), at)
        elif kind == "i":
            value = s.iv(order, at)
        else:
            value = s.kn(order.astype(int), at)
        return np.where(bad, np.nan, value)

    return f


# -- Excel ----------------------------------------------------------------------------------------
def _excel(function: str, template: str = "{}"):
    def printed(args: list[str]) -> tuple[str, int]:
        return f"{stored(function)}({template.format(*args)})", PREC["atom"]

    return printed


# -- the entries ----------------------------------------------------------------------------------
_WHOLE_ORDER = "an order that is not a whole number"
_ONE = (
    ("gamma", gamma, _excel("GAMMA"), lambda sp, x: sp.gamma(x),
     (Domain("gamma at a pole (0, -1, -2, ...)", _pole, "gamma({})"),),
     "gamma(x): the gamma function, gamma(n + 1) = n! (Mathcad's Γ)",
     # Γ(a, x), the incomplete gamma function, is not translated: its first argument only
     {"mathcad": ("Γ",), "mathcad_order": (0,)}),
    ("erf", lambda x: _special().erf(x), _excel("ERF"),
     lambda sp, x: sp.erf(x), (),
     "erf(x): the error function, 2/sqrt(pi) times the integral of exp(-t^2) from 0 to x",
     {"mathcad": ("erf",)}),
    ("erfc", lambda x: _special().erfc(x), _excel("ERFC"), lambda sp, x: sp.erfc(x), (),
     "erfc(x): the complementary error function, 1 - erf(x)", {"mathcad": ("erfc",)}),
    ("factorial", factorial, _excel("FACT"), lambda sp, n: sp.factorial(n),
     (Domain("factorial of a number that is not a whole number >= 0", _negative_or_not_whole,
             "factorial({})"),),
     "factorial(n): n! = 1 * 2 * ... * n of a whole number n >= 0 (Mathcad's operator n!)",
     {"mathcad_operator": "factorial"}),
)  # fmt: skip

_TWO = (
    ("combin", combin, _excel("COMBIN", "{}, {}"), lambda sp, n, k: sp.binomial(n, k),
     "combin(n, k): the number of ways to choose k of n things, n!/(k! (n - k)!)"),
    ("permut", permut, _excel("PERMUT", "{}, {}"), lambda sp, n, k: sp.ff(n, k),
     "permut(n, k): the number of ordered choices of k of n things, n!/(n - k)!"),
)  # fmt: skip

_BESSEL = (
    ("j", "BESSELJ", "besselj", "of the first kind, J_n(x) (Mathcad's Jn; J0, J1: n = 0, 1)"),
    ("y", "BESSELY", "bessely", "of the second kind, Y_n(x), x > 0 (Mathcad's Yn, Y0, Y1)"),
    ("i", "BESSELI", "besseli", "modified, of the first kind, I_n(x) (Mathcad's In, I0, I1)"),
    ("k", "BESSELK", "besselk", "modified, of the second kind, K_n(x), x > 0 (Mathcad's Kn)"),
)


def _count_domains(name: str) -> tuple[Domain, ...]:
    whole = "a count that is not a whole number >= 0"
    return (
        Domain(f"{name} of {whole}", _negative_or_not_whole, f"{name}({{}}, k)", arg=0),
        Domain(f"{name} of {whole}", _negative_or_not_whole, f"{name}(n, {{}})", arg=1),
    )


def _register() -> None:
    for name, numpy, excel, sympy, domain, doc, mathcad in _ONE:
        register(Builtin(name, 1, _plain_numbers, numpy, excel, sympy, domain, doc, **mathcad))
    for name, numpy, excel, sympy, doc in _TWO:  # Mathcad's functions of the same names
        register(
            Builtin(name, 2, _plain_numbers, numpy, excel, sympy, _count_domains(name), doc,
                    mathcad=(name,))
        )  # fmt: skip
    for kind, excel, sympy_name, what in _BESSEL:
        name = f"bessel_{kind}"
        domain = [Domain(f"{name} of {_WHOLE_ORDER}", _not_whole, f"{name}({{}}, x)", arg=0)]
        if kind in ("y", "k"):
            domain.append(Domain(f"{name} of x <= 0", _not_positive, f"{name}(n, {{}})", arg=1))
        register(
            Builtin(
                name,
                2,
                _plain_numbers,
                _bessel(kind),
                _excel(excel, "{1}, {0}"),
                lambda sp, n, x, f=sympy_name: getattr(sp, f)(n, x),
                tuple(domain),
                f"{name}(n, x): the Bessel function {what}, n a whole number",
                mathcad=(f"{kind.upper()}n",),  # Jn, Yn, In, Kn
            )
        )


_register()

#: The names of the special-function built-ins.
NAMES = frozenset([e[0] for e in _ONE] + [e[0] for e in _TWO] + [f"bessel_{b[0]}" for b in _BESSEL])
