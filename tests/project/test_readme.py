"""The README's commands are the ones CI runs."""

from helpers.paths import ROOT


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    test_command = 'pip install ".[test]" && pytest'
    assert f"```bash\n{test_command}\n```" in readme
    lines = ci.rstrip().splitlines()
    assert f"{test_command} || exit" in lines  # a failure stops CI with its status
    assert lines[-1].startswith("pytest -m slow ")  # then the tests the default run leaves out
    assert "```bash\npip install . && workbook run concave-cam\n```" in readme
