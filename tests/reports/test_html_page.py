"""``report.html`` in a real headless Chromium driven by selenium: the page loads with no
console error, a click on a front point shows that point's design (checked against
``front.json``, written independently of the page), and a screenshot is not blank.

Chromium is the system's (Debian ``chromium`` and ``chromium-driver``; ``.ci/run``
installs them). Without it the tests skip locally but fail under ``CI=true``, so CI
cannot skip them silently.
"""

from __future__ import annotations

import io
import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

from optdesign.cli import main

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")


def _need_browser():
    missing = []
    try:
        import selenium  # noqa: F401
    except ImportError:
        missing.append("selenium")
    if CHROMIUM is None:
        missing.append("chromium")
    if DRIVER is None:
        missing.append("chromedriver")
    if missing:
        why = f"browser test needs {', '.join(missing)}"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(why + " (CI=true: the browser tests may not be skipped)")
        pytest.skip(why)


@pytest.fixture(scope="module")
def browser():
    _need_browser()
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # Chromium's singleton socket lives under TMPDIR and the profile: a Unix socket's path
    # has at most 107 bytes, which the suite's nested temporary folders (CI's, pytest's,
    # an xdist worker's) exceed - Chromium then exits at once ("session not created").
    short = "/tmp" if os.access("/tmp", os.W_OK) else tempfile.gettempdir()
    profile = tempfile.mkdtemp(prefix="odc-", dir=short)
    saved_tmpdir = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = short  # inherited by chromedriver and Chromium
    for arg in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={profile}",
        "--window-size=1300,1700",
    ):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    try:
        driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    finally:
        if saved_tmpdir is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = saved_tmpdir
    driver.set_page_load_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def _open(driver, path: Path) -> None:
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.support.ui import WebDriverWait

    driver.get(path.as_uri())
    try:
        WebDriverWait(driver, 30).until(
            lambda d: d.execute_script("return document.body.dataset.ready") == "1"
        )
    except TimeoutException:
        pytest.fail(f"the page never got ready; console errors: {_console_errors(driver)}")


def _console_errors(driver) -> list[str]:
    return [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def _not_blank(driver) -> float:
    from PIL import Image

    img = Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("L")
    return float(np.asarray(img, dtype=float).std())


@pytest.fixture(scope="module")
def front_dir(tmp_path_factory):
    _need_browser()
    out = tmp_path_factory.mktemp("front")
    code = main(
        [
            "pareto",
            str(PROBLEMS / "cs_min_backlash.toml"),
            "--objectives",
            "backlash,size",
            "--points",
            "5",
            "--workers",
            "1",
            "--starts",
            "2",
            "--no-plot",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    return out


def test_front_report_click_shows_that_design(browser, front_dir):
    report = front_dir / "report.html"
    text = report.read_text()
    # no network needed: no script or stylesheet is loaded from anywhere
    assert "<script src=" not in text and "<link" not in text
    _open(browser, report)
    assert _console_errors(browser) == []
    points = json.loads((front_dir / "front.json").read_text())["fronts"][0]["points"]
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert len(markers) == len(points) >= 3
    shown = int(browser.execute_script("return document.body.dataset.selected"))
    k = 0 if shown != 0 else len(points) - 1  # a point that is not already shown
    ActionChains(browser).move_to_element(markers[k]).click().perform()
    assert int(browser.execute_script("return document.body.dataset.selected")) == k
    for name in ("R", "l", "d"):
        cell = browser.find_element(By.CSS_SELECTOR, f'#design td[data-var="{name}"]')
        assert float(cell.text) == pytest.approx(points[k]["design"][name], rel=1e-5)
    phi0 = browser.find_element(By.CSS_SELECTOR, '#design td[data-var="phi0"]')
    # the file writes phi0 in rad: shown in rad
    assert float(phi0.text) == pytest.approx(points[k]["design"]["phi0"], rel=1e-5, abs=1e-6)
    label = browser.find_element(By.ID, "selected-label").text
    assert label == f"epsilon point {k + 1}"
    # what each limit costs there, from the point's own solve (issue 35: it said "none")
    costs = browser.find_element(By.ID, "costs").text
    assert costs.startswith("costs in ") and " -> " in costs
    assert browser.find_elements(By.CSS_SELECTOR, "#sketch .scatterlayer .trace")
    assert browser.find_elements(By.CSS_SELECTOR, "#curves .scatterlayer .trace")
    assert _console_errors(browser) == []
    assert _not_blank(browser) > 10.0


def test_three_objective_front_report_draws_each_pair_and_a_click_shows_that_design(
    browser, tmp_path
):
    """The page's plotly.js is the basic bundle (no 3-D scatter): a front of three
    objectives is drawn as its three pairwise projections, each point in each, and a
    click on a point in any of them shows that design."""
    args = [
        "pareto",
        str(PROBLEMS / "cs_min_backlash.toml"),
        "--objectives",
        "ripple,backlash,size",
    ]
    args += ["--points", "4", "--workers", "1", "--starts", "1", "--no-plot"]
    assert main([*args, "--out", str(tmp_path)]) == 0
    points = json.loads((tmp_path / "front.json").read_text())["fronts"][0]["points"]
    _open(browser, tmp_path / "report.html")
    assert _console_errors(browser) == []
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert len(markers) == 3 * len(points) >= 9
    titles = browser.execute_script(
        "return Array.from(document.querySelectorAll('#front .g-xtitle, #front .g-x2title,"
        " #front .g-x3title'), (e) => e.textContent)"
    )
    assert titles == ["ripple (%)", "ripple (%)", "backlash (deg)"]
    shown = int(browser.execute_script("return document.body.dataset.selected"))
    # a point not shown yet, and where no other point lies (a front may hold a design
    # twice, digits apart: plotly picks the one on top)
    F = np.array([[p["objectives"][o] for o in ("ripple", "backlash", "size")] for p in points])
    apart = [
        all(np.max(np.abs(F[i] / F[j] - 1)) > 0.01 for i in range(len(F)) if i != j)
        for j in range(len(F))
    ]
    k = next(j for j in range(len(F)) if j != shown and apart[j])
    # the point's marker in the last panel (backlash against size)
    ActionChains(browser).move_to_element(markers[2 * len(points) + k]).click().perform()
    assert int(browser.execute_script("return document.body.dataset.selected")) == k
    cell = browser.find_element(By.CSS_SELECTOR, '#design td[data-var="R"]')
    assert float(cell.text) == pytest.approx(points[k]["design"]["R"], rel=1e-5)
    assert _not_blank(browser) > 10.0


def test_solve_report_shows_optimum_against_initial(browser, tmp_path):
    code = main(
        [
            "solve",
            str(PROBLEMS / "cs_min_backlash.toml"),
            "--starts",
            "2",
            "--no-ranges",
            "--no-plot",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    result = json.loads((tmp_path / "result.json").read_text())
    _open(browser, tmp_path / "report.html")
    assert _console_errors(browser) == []
    from selenium.webdriver.common.by import By

    assert browser.find_element(By.ID, "selected-label").text == "optimum"
    cell = browser.find_element(By.CSS_SELECTOR, '#design td[data-var="R"]')
    assert float(cell.text) == pytest.approx(result["design"]["R"]["value"], rel=1e-5)
    header = [th.text for th in browser.find_elements(By.CSS_SELECTOR, "#design th")]
    assert any(h.startswith("initial design") for h in header)
    limits = browser.find_element(By.ID, "limits").text
    assert "pin bearing pressure" in limits and "MPa" in limits
    assert not math.isnan(_not_blank(browser)) and _not_blank(browser) > 10.0


#: A name that breaks out of the page's data element (``<!--`` then ``<script`` swallowed
#: the rest of the page), out of an attribute (``"``), into plotly's markup and templates
#: (``<b>``, ``%{x}``), with a JavaScript line separator; the injected code would set
#: ``window.__pwned``.
HOSTILE = (
    "<!--<script>x</SCRIPT><script>window.__pwned=1</script>"
    '"><img src=x onerror="window.__pwned=2">\'\u2028&amp;<b>%{x}</b>'
)


@pytest.fixture(scope="module")
def hostile_dir(tmp_path_factory):
    _need_browser()
    out = tmp_path_factory.mktemp("hostile")
    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    path = out / "hostile.toml"
    path.write_text(src.replace('name = "cs_min_backlash"', "name = " + json.dumps(HOSTILE)))
    common = ["--starts", "1", "--no-plot"]
    code = main(["solve", str(path), *common, "--no-ranges", "--out", str(out / "solve")])
    assert code == 0
    args = ["pareto", str(path), "--objectives", "backlash,size", "--points", "4"]
    assert main([*args, *common, "--workers", "1", "--out", str(out / "front")]) == 0
    return out


def _every_string_hostile(page: Path, target: Path) -> dict:
    """The page of ``page`` again, with every string of its data that a user could name
    (variables, labels, limits, objectives, binding requirements, methods, axes) made
    hostile: the page's own script must show all of them as text."""
    from optdesign.reports.html_page import render

    text = page.read_text()
    start = text.index(">", text.index('id="report-data"')) + 1
    data = json.loads(text[start : text.index("</script>", start)])
    for d in data["designs"]:
        d["label"] = HOSTILE + " label"
        for k, row in enumerate(d["design"]):
            row.update(name=f"{HOSTILE}{k}", description=HOSTILE, unit=HOSTILE)
        d["limits"] = [HOSTILE + " limit"]
        d["violated"] = [HOSTILE + " violated"]
        for o in d["objectives"] + d["facts"]:
            o["text"] = HOSTILE + " objective"
        angles = [a for values in d["active_angles"].values() for a in values]
        d["active_angles"] = {HOSTILE + " req": angles} if angles else {}
    if data["front"]:
        data["front"]["axes"] = [f"{HOSTILE} axis {k}" for k in range(len(data["front"]["axes"]))]
        for t in data["front"]["traces"]:
            t["method"] = HOSTILE
    target.write_text(render(data, title=HOSTILE))
    return data


def _nothing_injected(driver) -> None:
    from selenium.webdriver.common.by import By

    assert driver.execute_script("return window.__pwned === undefined")
    assert driver.find_elements(By.TAG_NAME, "img") == []
    assert len(driver.find_elements(By.TAG_NAME, "script")) == 3
    # the tables the script builds carry their own attributes only (a name with a '"'
    # closed the data-var attribute and added its own, e.g. an onerror handler)
    attributes = driver.execute_script(
        "return Array.from(document.querySelectorAll('#design *, #limits *, #objectives *'),"
        " (e) => Array.from(e.attributes, (a) => a.name)).flat()"
    )
    assert set(attributes) <= {"class", "data-var"}
    assert _console_errors(driver) == []


def test_hostile_names_are_shown_as_text_and_run_nothing(browser, hostile_dir):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    from optdesign.text import printable

    points = json.loads((hostile_dir / "front" / "front.json").read_text())["fronts"][0]["points"]
    # the pages as the commands wrote them: the page renders its data
    for page in ("front", "solve"):
        _open(browser, hostile_dir / page / "report.html")
        _nothing_injected(browser)
        h1 = browser.find_element(By.TAG_NAME, "h1").text
        assert h1 == f"{printable(HOSTILE)} (crank-slider)"
        cells = browser.find_elements(By.CSS_SELECTOR, "#design td[data-var]")
        names = [c.get_attribute("data-var") for c in cells]
        assert names == ["R", "l", "n", "p", "phi0", "d", "i_a", "pin_length_ratio"]
        assert browser.find_elements(By.CSS_SELECTOR, "#curves .scatterlayer .trace")
    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert markers == []  # the solve page has no front
    _open(browser, hostile_dir / "front" / "report.html")
    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert len(markers) == len(points) >= 3
    # every string the page's script inserts, hostile: still text, nothing runs
    target = hostile_dir / "front" / "every_string.html"
    data = _every_string_hostile(hostile_dir / "front" / "report.html", target)
    _open(browser, target)
    _nothing_injected(browser)
    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert len(markers) == len(points)
    ActionChains(browser).move_to_element(markers[0]).click().perform()
    assert int(browser.execute_script("return document.body.dataset.selected")) == 0
    _nothing_injected(browser)
    cells = browser.find_elements(By.CSS_SELECTOR, "#design td[data-var]")
    assert [c.get_attribute("data-var") for c in cells] == [f"{HOSTILE}{k}" for k in range(8)]
    assert float(cells[0].text) == pytest.approx(points[0]["design"]["R"], rel=1e-5)
    text_of = "return document.getElementById(arguments[0]).textContent"
    assert browser.execute_script(text_of, "selected-label") == HOSTILE + " label"
    assert browser.execute_script(text_of, "limits") == HOSTILE + " limit"
    # plotly shows the names as written: no markup read, no template filled
    legend = browser.execute_script(
        "return Array.from(document.querySelectorAll('#curves .legendtext'), (e) => e.textContent)"
    )
    assert HOSTILE + " req binds" in legend
    axis = browser.execute_script("return document.querySelector('#front .xtitle').textContent")
    assert axis == data["front"]["axes"][0]
    assert _not_blank(browser) > 10.0


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    _need_browser()
    out = tmp_path_factory.mktemp("sweep")
    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    path = out / "hostile.toml"
    path.write_text(src.replace('name = "cs_min_backlash"', "name = " + json.dumps(HOSTILE)))
    args = ["sweep", str(path), "--vary", "requirements.hinge_moment=300..700N*m:3"]
    assert main([*args, "--starts", "1", "--no-progress", "--out", str(out / "s")]) == 0
    return out / "s"


def test_sweep_page_hover_a_point_or_a_row_shows_its_design(browser, sweep_dir):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    from optdesign.text import printable

    points = json.loads((sweep_dir / "sweep.json").read_text())["points"]
    _open(browser, sweep_dir / "sweep.html")
    _nothing_injected(browser)
    assert browser.find_element(By.TAG_NAME, "h1").text == f"{printable(HOSTILE)} (crank-slider)"
    attributes = browser.execute_script(
        "return Array.from(document.querySelectorAll('#sweep-table *'),"
        " (e) => Array.from(e.attributes, (a) => a.name)).flat()"
    )
    assert set(attributes) <= {"data-design"}
    rows = browser.find_elements(By.CSS_SELECTOR, "#sweep-table tr[data-design]")
    markers = browser.find_elements(By.CSS_SELECTOR, "#front .scatterlayer .trace .points path")
    assert len(rows) == len(markers) == len(points) == 3
    selected = "return document.body.dataset.selected"
    text_of = "return document.getElementById(arguments[0]).textContent"
    for k, target in ((2, rows[2]), (0, markers[0])):
        ActionChains(browser).move_to_element(target).click().perform()
        assert int(browser.execute_script(selected)) == k
        label = browser.execute_script(text_of, "selected-label")
        assert label == f"point {k}: hinge_moment [N*m] = {300 + 200 * k:g}"
        cell = browser.find_element(By.CSS_SELECTOR, '#design td[data-var="R"]')
        assert float(cell.text) == pytest.approx(points[k]["R [mm]"], rel=1e-5)
    _nothing_injected(browser)


def test_solve_report_of_a_loop_draws_its_step_response_and_cycle(browser, tmp_path):
    """The section "Time response" of fin_actuator_loop's optimum: both plots drawn,
    with their traces, and no console error."""
    from loop_optimum import loop_report

    path = tmp_path / "report.html"
    path.write_text(loop_report())
    _open(browser, path)
    from selenium.webdriver.support.ui import WebDriverWait

    WebDriverWait(browser, 30).until(
        lambda d: d.execute_script("return document.body.dataset.timeResponse") == "1"
    )
    assert _console_errors(browser) == []
    traces = browser.execute_script(
        "return ['step-response', 'limit-cycle'].map("
        "(id) => document.getElementById(id).data.map((t) => t.name))"
    )
    assert traces == [
        ["reference", "fin", "motor torque"],
        ["fin, simulated", "describing function (predicted)"],
    ]
