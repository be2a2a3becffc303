"""Sweeps: chosen outputs of a sheet over a grid of inputs, as a table and a chart.

An output is an expression over the sheet (``r0``, ``phi2(104.6)``, ``h(22)``) or a
reduction over a range: ``max of v(phi) over phi := 0, 0.5 .. 104`` (``max``, ``min``,
``mean``, ``argmax``, ``argmin``; argmax/argmin give the range variable where the
expression is largest/smallest). Outputs are declared in the template::

    [sweep]
    outputs = { v_peak = "max of v(phi) over phi := 0 .. 104" }
    units = { v_peak = "m/s" }          # optional: the unit a column is shown in

or given on the command line as ``--output NAME=EXPR`` (``--output "NAME[m/s]=EXPR"``).

How the cases run (``mode``):

* ``vector``: every case at once in numpy arrays (the swept inputs become arrays that
  travel with the range variable, so piecewise functions stay masked per point);
  chosen automatically when the outputs need no solver block;
* ``processes``: one case per task in a ``ProcessPoolExecutor`` (the task carries the
  template path and the input overrides, never a Sheet); chosen automatically when an
  output needs a solver block;
* ``serial``: one case after the other in this process;
* with ``scheduler`` (an address or a ``dask.distributed.Client``): the same tasks on a
  Dask cluster (dask is imported only then).

A case that fails is recorded with its error (column ``error``); the others go on.
"""

from .driver import Progress, SweepResult, sweep
from .grid import MAX_CASES, Vary, grid, parse_vary
from .outputs import REDUCTIONS, Output, evaluate_outputs, parse_output_option, template_outputs
from .runners import run_case
from .vector import vector_blockers
from .writer import write

__all__ = [
    "MAX_CASES",
    "REDUCTIONS",
    "Output",
    "Progress",
    "SweepResult",
    "Vary",
    "evaluate_outputs",
    "grid",
    "parse_output_option",
    "parse_vary",
    "run_case",
    "sweep",
    "template_outputs",
    "vector_blockers",
    "write",
]
