"""The README's commands are the ones CI runs."""

from pathlib import Path

ROOT = Path(__file__).parent.parent


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    test_command = 'pip install ".[test]" && pytest'
    assert f"```bash\n{test_command}\n```" in readme
    assert ci.rstrip().splitlines()[-1] == test_command
    assert "```bash\npip install . && workbook run concave-cam\n```" in readme
