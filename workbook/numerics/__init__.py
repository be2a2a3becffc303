"""Numerical built-ins of the worksheet language, vectorised over the rows of a table.

Each primitive takes a function ``f(x, *args)`` that evaluates elementwise on arrays,
its bounds (arrays, one value per row) and the extra arguments (arrays of the same rows),
and solves every row in one call of a SciPy vectorised routine:

- :func:`roots.root_in` / :func:`roots.root_near`: ``scipy.optimize.elementwise.find_root``
  (after sampling the bracket for sign changes) and ``bracket_root``;
- :func:`quadrature.integrate`: ``scipy.integrate.tanhsinh``, split at given break points;
- :func:`extrema.extremum`: sampling, then ``scipy.optimize.elementwise.find_minimum`` on
  every local extremum found;
- :func:`workbook.numerics.series.reduce`: sums and products over integers;
- :func:`given.solve`: a Given/Find system (``scipy.optimize.root``);
- :func:`interpolate.interpolate`: linear and cubic-spline interpolation of measured data;
- :mod:`gauss`: fixed Gauss-Legendre rules (the integral's live Excel form);
- :mod:`reference`: other algorithms for the same built-ins (``workbook bench``'s
  reference); :mod:`intervals`, :mod:`isolate`, :mod:`globalmin`, :mod:`features`: interval
  enclosures of EXPR and what they prove (root counts, global extrema, features).

Every result carries an error estimate; every failure is a :class:`NumericsError` that says
what was sampled and found. This package knows nothing of worksheets (no typed tree): the
engine wraps it. SciPy is imported inside the functions, so importing this package is cheap.
"""
