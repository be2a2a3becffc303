"""Programs: a function body written as a few statements, as Mathcad's program regions.

One statement a line; a block is the lines indented under its header (as in Python).
The text is split into statements here and every expression goes through
:func:`workbook.language.expr.parse`, so nothing is ever evaluated by Python::

    a := x^2                      # a local (Mathcad's a <- x^2; '←' is read too)
    v := [0, 0, 0]                # a local vector; v[i] := ... sets an element
    w[i] := i^2                   # w not given: it is made, and grown, by its elements
    for i in 1 .. n               # Mathcad's range form: first[, second] .. last
        a := a + i
        break if a > 100          # any simple statement may end in 'if CONDITION'
    while a > 1
        a := a/2
    if a > 10                     # block form: if / else if / otherwise (or else)
        return a
    else if a > 5
        return 2*a
    "small" if a < 0              # one-line form, as Mathcad's 'value if condition'
    a otherwise
    try                           # Prime's try / on error: an error raised in the first
        a := 1/a                  # block (a division by zero there too) runs the second,
    on error                      # from where it was raised; a limit is no such error
        a := 0

The value of a program is the value of the ``return`` that ends it or, without one, of the
last value line it executed (an expression line, or the value of a one-line ``if`` /
``otherwise``). Assignments and loops are not values. A program that ends without a value is
an error, never a silent 0; so is a loop that runs more than :data:`.run.MAX_STEPS` statements.

One module per stage: :mod:`.statements` (the statement nodes and walks over them),
:mod:`.parse` (text to statements), :mod:`.typer` (units and shapes, through the typer's
callbacks), :mod:`.run` (a closure per program for the numeric back end) and :mod:`.excel`
(a program without loops as one nested IF).
"""
