"""``workbook new NAME``: a commented starter worksheet that runs as it is."""

from __future__ import annotations

from pathlib import Path

from .errors import InputError

STARTER = """\
# {name}: a starter worksheet. Run it with
#     workbook run {file}
# and open reports/{name}.xlsx. Every line below is an example of the language;
# the reference with a tested example of each construct is docs/language.md.
# Example: a projectile thrown from a height, without air drag.

[sheet]
title = "{title}"
source = "write where the formulas come from (book, paper, standard)"
description = "A projectile thrown at speed v0 and angle alpha from height y0."

# Inputs: a number with a unit, a note, optional bounds. The workbook shows them as
# yellow cells; `workbook run {file} --set v0="25 m/s"` overrides one.
[inputs]
v0 = {{ value = "20 m/s", note = "launch speed", positive = true }}
alpha = {{ value = "40 deg", note = "launch angle", min = "0 deg", max = "90 deg" }}
y0 = {{ value = "1.5 m", note = "launch height", min = "0 m" }}
g = {{ value = "9.81 m/s^2", note = "gravity", positive = true }}
# A choice input: one of listed words, compared with == in conditions.
ground = {{ value = "flat", options = ["flat", "wall"], note = "stop at flat ground or at a wall" }}
wall = {{ value = "30 m", note = "distance of the wall (ground = wall)", positive = true }}

# Every function argument declares its unit once.
[arguments]
t = {{ unit = "s", note = "time since the throw" }}
x = {{ unit = "m", note = "horizontal distance" }}

[definitions]
# A value: units are checked when the sheet loads (adding m to m/s is an error).
vx = {{ expr = "v0*cos(alpha)", unit = "m/s", note = "horizontal speed" }}
vy0 = {{ expr = "v0*sin(alpha)", unit = "m/s", note = "initial vertical speed" }}
# ^ is the power operator; sqrt, sin, cos, ln, exp, min, max ... are built in.
t_flight = {{ expr = "(vy0 + sqrt(vy0^2 + 2*g*y0))/g", unit = "s", note = "time of flight" }}
range_flat = {{ expr = "vx*t_flight", unit = "m" }}
# A piecewise value: the first true condition wins; "otherwise" closes the list.
reach = ["min(range_flat, wall) if ground == \\"wall\\"", "range_flat otherwise"]
# Functions of an argument.
"y(t)" = {{ expr = "y0 + vy0*t - g*t^2/2", unit = "m", note = "height" }}
"xpos(t)" = {{ expr = "vx*t", unit = "m" }}
"v(t)" = {{ expr = "sqrt(vx^2 + (vy0 - g*t)^2)", unit = "m/s", note = "speed" }}
"height(x)" = {{ expr = "y0 + tan(alpha)*x - g*x^2/(2*vx^2)", unit = "m", note = "the path y(x)" }}

# A table: range variable t := first, second .. last (the last value is always included);
# a bare function name is that function of the range variable.
[[tables]]
name = "path"
title = "Flight every 0.1 s"
range = "t := 0, 0.1 .. t_flight"
columns = {{ xpos = "m", y = "m", v = "m/s" }}

# A chart: native Excel scatter chart of expressions over a range.
[[charts]]
name = "trajectory"
title = "Path of the projectile"
range = "x := 0, 0.25 .. reach"
x = {{ expr = "x", title = "distance x, m" }}
y_title = "height y, m"
series = [{{ y = "height", unit = "m", name = "height, m" }}]

# Sweep outputs: `workbook sweep {file} --vary alpha=10deg..80deg:15` tabulates and charts
# them over a grid of inputs. "max of EXPR over RANGE" reduces over a range (also min,
# mean, argmax, argmin).
[sweep]
outputs = {{ reach = "reach", top = "max of y(t) over t := 0, 0.01 .. t_flight" }}
units = {{ top = "m" }}
"""


def starter(name: str, file: str) -> str:
    title = name.replace("-", " ").replace("_", " ").strip().capitalize() or "New worksheet"
    return STARTER.format(name=name, file=file, title=title)


def write_starter(name: str, out: str | Path | None = None, *, force: bool = False) -> Path:
    """Write the starter worksheet ``NAME.toml`` (or ``out``); returns its path."""
    from .outputs.atomic import replacing

    if not name or any(c in name for c in '/\\:*?"<>|') or name.startswith("."):
        raise InputError(f"'{name}' is not a usable worksheet name (letters, digits, - and _)")
    stem = name[: -len(".toml")] if name.endswith(".toml") else name
    path = Path(out) if out else Path(f"{stem}.toml")
    if path.suffix != ".toml":
        raise InputError(f"{path}: a worksheet file ends with .toml")
    if path.is_dir():
        raise InputError(f"{path} is a directory")
    if not path.parent.exists():
        raise InputError(f"folder {path.parent} does not exist")
    if path.exists() and not force:
        raise InputError(f"{path} exists; use --force to overwrite it")
    shown = str(path) if ("/" in str(path) or "\\" in str(path)) else f"./{path}"
    with replacing(path) as tmp:
        tmp.write_text(starter(path.stem, shown), encoding="utf-8")
    return path


def cmd_new(args) -> int:
    path = write_starter(args.name, args.out, force=args.force)
    shown = str(path) if ("/" in str(path) or "\\" in str(path)) else f"./{path}"
    print(f"wrote {path}: a starter worksheet; next:")
    print(f"  workbook run {shown}          # writes reports/{path.stem}.xlsx")
    print(f"  workbook sweep {shown} --vary alpha=10deg..80deg:15")
    return 0
