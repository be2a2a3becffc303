"""`workbook serve` as a person uses it: the command started in a terminal of its own (a
subprocess), a real Chromium (headless, driven by selenium through Debian's chromedriver)
on its page; the test edits the file and an input and waits for the page to show the new
numbers, opens every template's page and compares the numbers shown with the engine's, then
stops the server with Ctrl-C and finds nothing left behind."""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.paths import ROOT

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")

if os.environ.get("CI") == "true" and not (CHROMIUM and DRIVER):
    raise RuntimeError("CI must run the live page in Chromium: install chromium chromium-driver")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not (CHROMIUM and DRIVER), reason="chromium and chromedriver needed"),
]

SHEET = """[inputs]
R = { value = "2 mm", positive = true }
L = "30 mm"

[definitions]
A = { expr = "pi*R^2", note = "area" }
V = { expr = "A*L", unit = "mm^3" }
"""


def _serve(folder: Path) -> tuple[subprocess.Popen, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            # Ctrl-C as at a terminal: a test worker (pytest-xdist) or a shell that runs the
            # tests in the background starts children with SIGINT ignored
            "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
            "from workbook.cli import main; sys.exit(main())",
            "serve",
            str(folder),
            "--no-browser",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=folder,
    )
    line = proc.stdout.readline()
    m = re.search(r"(http://127\.0\.0\.1:\d+/\?token=\S+)", line)
    assert m, line + proc.stderr.read()
    return proc, m.group(1)


@pytest.fixture
def browser(tmp_path):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in (
        "--headless=new",
        "--disable-gpu",
        "--no-first-run",
        "--window-size=1200,900",
        f"--user-data-dir={tmp_path / 'profile'}",
    ):
        options.add_argument(arg)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        options.add_argument("--no-sandbox")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    yield driver
    driver.quit()


def _shown(driver, name: str) -> str | None:
    """The number the page shows as the result of ``name`` (its sign and digits), or None."""
    text = driver.execute_script(
        'const e = document.querySelector("#wb-report .result[data-name=\'" + arguments[0] +'
        ' "\']"); return e ? e.textContent : null;',
        name,
    )
    if text is None:
        return None
    m = re.match(r"\s*([\u2212-]?)\s*([0-9.]+(?:\u00d7)?)", text)
    return (m.group(1) + m.group(2)) if m else text


def _wait(driver, what, timeout: float = 60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = what()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("the page did not change")


def _number(text: str | None) -> float | None:
    if text is None:
        return None
    return float(text.replace("\u2212", "-"))


def test_live_page_follows_the_file_and_the_form(browser, tmp_path):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    folder = tmp_path / "sheets"
    folder.mkdir()
    path = folder / "cyl.toml"
    path.write_text(SHEET, encoding="utf-8")
    before = sorted(p.name for p in folder.iterdir())
    proc, url = _serve(folder)
    try:
        port = int(re.search(r":(\d+)/", url).group(1))
        browser.get(url)  # the folder's list
        browser.find_element(By.LINK_TEXT, "cyl.toml").click()
        v = _wait(browser, lambda: _number(_shown(browser, "V")))
        assert v == pytest.approx(math.pi * 4 * 30, rel=1e-5)
        # the file edited in another program: the page shows the new number, no reload
        marker = browser.execute_script("window.wbMarker = 1; return window.wbMarker;")
        browser.execute_script("window.wbA = document.getElementById('def-A');")
        path.write_text(SHEET.replace('expr = "A*L"', 'expr = "2*A*L"'), encoding="utf-8")
        v = _wait(browser, lambda: (x := _number(_shown(browser, "V"))) != v and x)
        assert v == pytest.approx(2 * math.pi * 4 * 30, rel=1e-5)
        assert browser.execute_script("return window.wbMarker;") == marker  # not reloaded
        # only what changed is replaced: the element of A, which did not, is the same one
        assert browser.execute_script("return document.getElementById('def-A') === window.wbA;")
        # an edit that breaks it: the error at its line, the last numbers stay
        path.write_text(SHEET.replace('expr = "A*L"', 'expr = "A + L"'), encoding="utf-8")
        banner = browser.find_element(By.ID, "wb-error")
        _wait(browser, lambda: banner.is_displayed() and banner.text)
        assert "cyl.toml:7, in 'V': unit error" in banner.text
        stopped = browser.find_elements(By.CSS_SELECTOR, "#wb-report .wb-stopped")
        assert [e.get_attribute("id") for e in stopped] == ["def-V"]
        assert _number(_shown(browser, "V")) == pytest.approx(v, rel=1e-9)
        path.write_text(SHEET, encoding="utf-8")
        _wait(browser, lambda: not banner.is_displayed())
        # an input changed on the page
        field = browser.find_element(By.CSS_SELECTOR, "input[name='R']")
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys("3", Keys.TAB)
        a = _wait(browser, lambda: (x := _number(_shown(browser, "A"))) and abs(x - 28.2743) < 1e-3)
        assert a
        assert _number(_shown(browser, "V")) == pytest.approx(math.pi * 9 * 30, rel=1e-5)
        assert path.read_text(encoding="utf-8") == SHEET  # the file is not touched
        field = browser.find_element(By.CSS_SELECTOR, "input[name='R']")
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys("-1", Keys.TAB)
        note = browser.find_element(By.CSS_SELECTOR, "label[data-input='R'] .wb-input-error")
        _wait(browser, lambda: note.text)
        assert "must be positive" in note.text
        refused = [
            e for e in browser.get_log("browser") if "Content Security Policy" in e["message"]
        ]
        assert refused == []
    finally:
        proc.send_signal(signal.SIGINT)  # Ctrl-C
        status = proc.wait(timeout=30)
    assert status == 0
    assert sorted(p.name for p in folder.iterdir()) == before  # nothing left behind
    with pytest.raises(ConnectionRefusedError):  # nothing listens on the port any more
        socket.create_connection(("127.0.0.1", port), timeout=5).close()


def test_every_template_page_shows_the_engines_numbers(browser, tmp_path):
    import workbook
    from workbook.compute.computed import compute

    folder = tmp_path / "templates"
    folder.mkdir()
    names = list(workbook.list_templates())
    for name in names:
        src = workbook.list_templates()[name]
        for f in src.parent.glob(name + ".*"):
            shutil.copy(f, folder / f.name)
    proc, url = _serve(folder)
    try:
        token = url.split("token=")[1]
        base = url.split("/?")[0]
        for name in names:
            browser.get(f"{base}/sheet/{name}.toml?token={token}")
            computed = compute(workbook.load(folder / f"{name}.toml"))
            checked = 0
            for n, s in computed.scalars.items():
                if s.error is not None or isinstance(s.value, str) or s.value.ndim:
                    continue
                shown = _wait(browser, lambda n=n: _shown(browser, n), timeout=120)
                if "\u00d7" in shown or not re.fullmatch(r"\u2212?[0-9.]+", shown):
                    continue  # a power of ten: the number is across elements
                value = float(s.value.magnitude)
                assert float(shown.replace("\u2212", "-")) == pytest.approx(
                    value, rel=1e-5, abs=1e-9
                ), (name, n)
                checked += 1
            assert checked or not computed.scalars, name
            shot = tmp_path / f"{name}.png"
            assert browser.save_screenshot(str(shot)), name
            _assert_not_blank(shot, name)
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=60) == 0


def _assert_not_blank(png: Path, name: str) -> None:
    """The screenshot shows something: more than one colour, and dark pixels (text) on it."""
    from PIL import Image

    with Image.open(png) as im:
        grey = im.convert("L")
        assert grey.size == (1200, 900) or grey.size[0] > 600, (name, grey.size)
        low, high = grey.getextrema()
        assert high - low > 100, (name, low, high)  # not all one colour
        dark = sum(grey.histogram()[:100])
        assert dark > 500, (name, dark)  # text: dark pixels on the light page
