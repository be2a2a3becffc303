"""[[ode]] sections in a worksheet: units at load, the solution as functions of time against
closed forms, the automatic choice on a stiff system, blow-up and budget errors, findings."""

from __future__ import annotations

import numpy as np
import pytest

import workbook
from workbook.compute.checks import run_checks

HEAD = """
[inputs]
k = "2 1/s"
y0 = "1 m"
lam = "20000 1/s"

[arguments]
t = { unit = "s" }
"""


def ode(name, states, time="t := 0 .. 3", extra=""):
    rows = ",\n".join(
        f'  {{ name = "{n}", unit = "{u}", initial = "{i}", derivative = "{d}" }}'
        for n, u, i, d in states
    )
    return f'\n[[ode]]\nname = "{name}"\ntime = "{time}"\n{extra}\nstates = [\n{rows}\n]\n'


def test_solution_against_the_closed_form_in_a_table(sheet_from, tmp_path):
    sheet = sheet_from(
        HEAD
        + ode("decay", [("y", "m", "y0", "-k*y")], extra="rtol = 1e-10\natol = 1e-13")
        + '\n[[tables]]\nname = "sol"\nrange = "t := 0, 0.25 .. 3"\ncolumns = { y = "mm" }\n'
    )
    table = sheet.table("sol")
    t = table.iloc[:, 0].to_numpy()
    np.testing.assert_allclose(table.iloc[:, 1], 1000 * np.exp(-2 * t), rtol=1e-8)
    # the workbook writes the states as numbers with a comment (no formula exists)
    import openpyxl

    ws = openpyxl.load_workbook(sheet.write_xlsx(tmp_path / "o.xlsx"))["Listing"]
    header = next(c for c in ws[2] if c.value and str(c.value).startswith("y"))
    assert "solution of ode 'decay'" in header.comment.text
    cells = [ws.cell(row=r, column=header.column).value for r in range(3, 3 + len(table))]
    np.testing.assert_allclose(cells, table.iloc[:, 1], rtol=1e-12)


COOLING = """
[inputs]
T0 = "80 degC"
Ta = "20 degC"
h = "0.05 1/s"

[arguments]
t = { unit = "s" }

[definitions]
T60 = { expr = "T(60 s)", unit = "K" }

[[ode]]
name = "cool"
time = "t := 0 .. 120"
rtol = 1e-10
states = [
  { name = "T", unit = "degC", initial = "T0", derivative = "-h*(T - Ta)", atol = "1e-9 K" },
]

[[tables]]
name = "sol"
range = "t := 0, 30 .. 120"
columns = { T = "degF" }
"""


def test_a_temperature_state_changes_by_differences(sheet_from):
    """Newton's cooling with T in degC: T' is in delta_degC/s (the derivative was converted to
    degC/s, an internal error) and its atol a difference; T read in degF and K against the
    closed form Ta + (T0 - Ta) exp(-h t)."""
    sheet = sheet_from(COOLING, name="cool")
    celsius = 20 + 60 * np.exp(-0.05 * np.arange(0, 121, 30.0))
    table = sheet.table("sol")
    np.testing.assert_allclose(table.iloc[:, 1], celsius * 9 / 5 + 32, rtol=1e-10)
    assert sheet.evaluate("T60").to("K").magnitude == pytest.approx(
        20 + 60 * np.exp(-3.0) + 273.15, rel=1e-11
    )


def test_a_stiff_system_makes_auto_take_an_implicit_method(sheet_from):
    sheet = sheet_from(
        HEAD
        + ode(
            "stiff",
            [
                ("a", "m", "0", "-lam*(a - y0*cos(k*t))"),
                ("b", "m", "y0", "-k*b"),
            ],
            time="t := 0 .. 2",
            extra="rtol = 1e-8\natol = 1e-11",
        )
    )
    sol = sheet.evaluator.ode_solution("stiff")
    assert sol.method == "LSODA"
    assert "stiff" in sol.choice.reason
    findings = [f for f in run_checks(sheet).findings if f.topic == "ode stiff"]
    assert findings and "LSODA" in findings[0].note and "decay rate 2e+04" in findings[0].note
    np.testing.assert_allclose(
        sheet.evaluate("b", [0.5, 2]).to("m").magnitude, np.exp(-2 * np.array([0.5, 2])), rtol=1e-6
    )  # LSODA's global error at rtol 1e-8 is 1.1e-7 here


def test_units_of_derivatives_are_checked_at_load(sheet_from):
    with pytest.raises(workbook.WorkbookError, match=r"y' \(ode 'bad'\)") as info:
        sheet_from(HEAD + ode("bad", [("y", "m", "y0", "k")]), name="o")
    assert "o.toml" in str(info.value) and "cannot be converted" in str(info.value)
    with pytest.raises(workbook.WorkbookError, match="not one of auto"):
        sheet_from(
            HEAD + ode("bad", [("y", "m", "y0", "-k*y")], extra='method = "Euler"'), name="o"
        )
    with pytest.raises(workbook.WorkbookError, match="has no declared unit"):
        sheet_from(HEAD + ode("bad", [("y", "m", "y0", "-k*y")], time="tau := 0 .. 1"), name="o")


def test_a_solution_that_blows_up_is_stopped_and_said_why(sheet_from):
    sheet = sheet_from(HEAD + ode("boom", [("y", "m", "y0", "y^2/y0*k")], time="t := 0 .. 1"))
    with pytest.raises(workbook.WorkbookError, match="blows up") as info:
        sheet.evaluate("y", 0.9)
    assert "ode 'boom'" in str(info.value)
    report = run_checks(sheet)
    assert any(f.verdict == "fail" and "blows up" in f.note for f in report.findings)


def test_time_outside_the_range_is_an_error(sheet_from):
    sheet = sheet_from(HEAD + ode("decay", [("y", "m", "y0", "-k*y")]))
    with pytest.raises(workbook.WorkbookError, match="outside the time range"):
        sheet.evaluate("y", [1, 5])


MASS = """
[inputs]
m1 = "2 kg"
m2 = "1 kg"
k = "800 N/m"
c = "4 N*s/m"
x0 = "10 mm"
scheme = { value = "Radau", options = ["RK45", "DOP853", "Radau"] }
tol = "1e-10"

[arguments]
t = { unit = "s" }

[definitions]
M = "[[m1, 0], [0, m2]]"
K = "[[2*k, -k], [-k, k]]"
C = "[[c, 0], [0, c]]"
"x2(t)" = { expr = "x(t)[1]", unit = "mm" }

[[ode]]
name = "two_masses"
time = "t := 0 .. 0.5"
method = "scheme"
rtol = "tol"
states = [
  { name = "x", unit = "mm", initial = "[x0, 0]", derivative = "v", atol = "1e-9" },
  { name = "v", unit = "mm/s", initial = "[0, 0]", derivative = "lsolve(M, -K*x - C*v)" },
]
"""


@pytest.mark.slow
def test_vector_states_against_the_matrix_exponential(sheet_from):
    """M x'' + C x' + K x = 0 as two vector states, against expm of the first-order system
    written out here; the method is a choice input and rtol an input."""
    from scipy.linalg import expm

    sheet = sheet_from(MASS, name="m")
    M, K, C = np.diag([2.0, 1.0]), np.array([[1600.0, -800.0], [-800.0, 800.0]]), 4 * np.eye(2)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ts = np.array([0.05, 0.2, 0.5])
    ref = np.array([expm(A * t) @ [0.01, 0, 0, 0] for t in ts])  # m, m/s
    got = sheet.evaluate("x", ts).to("m").magnitude  # (2, 1, 3)
    assert got.shape == (2, 1, 3)
    np.testing.assert_allclose(got[:, 0, :].T, ref[:, :2], atol=1e-11)
    np.testing.assert_allclose(sheet.evaluate("x2", ts).to("m").magnitude, ref[:, 1], atol=1e-11)
    sol = sheet.evaluator.ode_solution("two_masses")
    assert sol.method == "Radau" and sol.run.rtol == 1e-10
    other = sheet.with_inputs(scheme="DOP853")
    assert other.evaluator.ode_solution("two_masses").method == "DOP853"


def test_vector_state_shapes_and_method_names_are_checked_at_load(sheet_from):
    with pytest.raises(workbook.WorkbookError, match="derivative of 'x' is a number"):
        sheet_from(MASS.replace('derivative = "v"', 'derivative = "v[0]"'), name="m")
    with pytest.raises(workbook.WorkbookError, match="not one of auto"):
        sheet_from(MASS.replace('method = "scheme"', 'method = "schema"'), name="m")
    with pytest.raises(workbook.WorkbookError, match="must give text"):
        sheet_from(MASS.replace('method = "scheme"', 'method = "tol"'), name="m")


@pytest.mark.slow
def test_run_sheet_returns_a_stopped_run_instead_of_raising(sheet_from):
    from workbook.engine import ode as wo

    sheet = sheet_from(MASS, name="m").with_inputs(scheme="RK45", tol="1e-9")
    ts = np.linspace(0, 0.5, 11)
    run = wo.run_sheet(sheet, "two_masses", t_eval=ts)
    assert run.ok and run.method == "RK45" and run.y.shape == (4, 11)
    np.testing.assert_allclose(run.y[:2, -1], sheet.evaluate("x", 0.5).magnitude[:, 0], atol=1e-5)
    capped = wo.run_sheet(sheet, "two_masses", t_eval=ts, max_steps=5)
    assert capped.stop_reason == "step cap" and not capped.ok


@pytest.mark.slow
def test_a_method_given_by_a_text_definition_is_checked_when_it_is_evaluated(sheet_from):
    text = MASS.replace('method = "scheme"', 'method = "pick"').replace(
        "[definitions]\n",
        '[definitions]\npick = "\\"Radau\\" if tol < 1e-6 otherwise \\"Euler\\""\n',
    )
    sheet = sheet_from(text, name="m")
    assert sheet.evaluator.ode_solution("two_masses").method == "Radau"
    with pytest.raises(workbook.WorkbookError, match="'Euler' is not one of auto"):
        sheet.with_inputs(tol="1e-3").evaluate("x", 0.1)
