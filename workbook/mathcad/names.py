"""Mathcad names as worksheet identifiers: subscripts as ``R_h``, Greek letters spelled out.

A Mathcad name is its text plus an optional literal subscript (``v`` with subscript ``b``);
``ρ`` becomes ``rho``, ``σ`` with subscript ``m.α.d`` becomes ``sigma_m_alpha_d``. Letters
outside ASCII that are not Greek are transliterated (Cyrillic, Danish); what is left over
becomes ``_``. Names that are Python keywords get a trailing ``_``.
"""

from __future__ import annotations

import keyword
import re
import unicodedata

GREEK = {
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "ε": "epsilon", "ζ": "zeta",
    "η": "eta", "θ": "theta", "ι": "iota", "κ": "kappa", "λ": "lambda", "μ": "mu",
    "ν": "nu", "ξ": "xi", "ο": "omicron", "π": "pi", "ρ": "rho", "σ": "sigma", "ς": "sigma",
    "τ": "tau", "υ": "upsilon", "φ": "phi", "ϕ": "phi", "χ": "chi", "ψ": "psi", "ω": "omega",
    "ϑ": "theta", "ϵ": "epsilon",
    "Α": "Alpha", "Β": "Beta", "Γ": "Gamma", "Δ": "Delta", "Ε": "Epsilon", "Ζ": "Zeta",
    "Η": "Eta", "Θ": "Theta", "Ι": "Iota", "Κ": "Kappa", "Λ": "Lambda", "Μ": "Mu",
    "Ν": "Nu", "Ξ": "Xi", "Ο": "Omicron", "Π": "Pi", "Ρ": "Rho", "Σ": "Sigma", "Τ": "Tau",
    "Υ": "Upsilon", "Φ": "Phi", "Χ": "Chi", "Ψ": "Psi", "Ω": "Omega",
}  # fmt: skip

OTHER = {
    "ø": "oe", "Ø": "Oe", "æ": "ae", "Æ": "Ae", "å": "aa", "Å": "Aa", "ß": "ss",
    "а": "a", "б": "b", "в": "v", "г": "g", "д": "d", "е": "e", "ё": "e", "ж": "zh",
    "з": "z", "и": "i", "й": "j", "к": "k", "л": "l", "м": "m", "н": "n", "о": "o",
    "п": "p", "р": "r", "с": "s", "т": "t", "у": "u", "ф": "f", "х": "h", "ц": "c",
    "ч": "ch", "ш": "sh", "щ": "shch", "ъ": "", "ы": "y", "ь": "", "э": "e", "ю": "yu",
    "я": "ya", "і": "i", "ї": "yi", "є": "ye", "ґ": "g", "'": "prime", "′": "prime",
}  # fmt: skip


def _letters(text: str) -> str:
    out = []
    for ch in text:
        if ch.isascii() and (ch.isalnum() or ch == "_"):
            out.append(ch)
        elif ch in GREEK:
            out.append(GREEK[ch])
        elif ch in OTHER or ch.lower() in OTHER:
            rep = OTHER.get(ch, OTHER.get(ch.lower(), ""))
            out.append(rep.capitalize() if ch not in OTHER else rep)
        else:
            plain = unicodedata.normalize("NFKD", ch).encode("ascii", "ignore").decode()
            out.append(plain if plain.isalnum() else "_")
    return "".join(out)


def identifier(text: str, subscript: str = "") -> str:
    """The worksheet identifier of a Mathcad name (text and literal subscript)."""
    base = _letters(text)
    if subscript:
        base += "_" + _letters(subscript.replace(".", "_").replace(",", "_"))
    base = re.sub(r"_+", "_", base).strip("_") or "x"
    if not base[0].isalpha():
        base = "v" + base
    if keyword.iskeyword(base):
        base += "_"
    return base


def mathcad_text(text: str, subscript: str = "") -> str:
    """How the name reads in Mathcad (for comments): text, then '.subscript'."""
    return f"{text}.{subscript}" if subscript else text
