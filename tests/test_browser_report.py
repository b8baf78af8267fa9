"""report.html in a real browser: Debian's Chromium (``/usr/bin/chromium``, installed by
``make test`` when missing) driven by playwright through ``executable_path`` (no browser
download).  The page is copied alone into an empty folder, so it must carry its images
(``data:`` URIs); every ``<img>`` must have loaded (``naturalWidth > 0``), the console must
stay free of errors, and no request may leave the page.  A full-page screenshot is kept under
the pytest tmp folder and the render time is recorded (``record_property``, printed).

Never skipped: without Chromium the test fails and says how to install it.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import pytest

from semianalytic.cli import main

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
# The machine's network is closed: no background traffic, no GPU, no sandbox (root in CI).
FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
# The render time is recorded (record_property) and printed, never asserted: a wall-time
# assertion would fail on a loaded machine for reasons that are not the page's.
# Every committed HTML report (reports/, the demo's output excluded: it is not committed).
COMMITTED = sorted(p for p in (ROOT / "reports").rglob("*.html") if "demo" not in p.relative_to(ROOT / "reports").parts)

# A small run of the Fig. 13 case: the velocity field (body-fitted figure and pyvista render).
CASE = (ROOT / "cases" / "fig13_ogive_velocity_field.toml").read_text().replace(
    'analyses = ["velocity_field", "fem_field"]', 'analyses = ["velocity_field"]'
).replace("field_grid = [61, 31]", "field_grid = [21, 9]\nfield_segments = 8")


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).is_file():
        pytest.fail(f"{CHROMIUM} is missing: `make test` installs it (apt-get install -y chromium)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def fresh_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("browser_run")
    case = d / "cases" / "fig13_small.toml"
    case.parent.mkdir()
    case.write_text(CASE)
    out = d / "out"
    assert main(["run", str(case), "--out", str(out)]) == 0
    return case, out


def _render(browser, html_file: Path, shot: Path) -> dict:
    """Open ``html_file`` alone; return the image states, console errors and render time."""
    page = browser.new_page(viewport={"width": 1100, "height": 900})
    errors, outside = [], []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))

    def gate(route):  # the page may load itself and data: URIs, nothing else
        url = route.request.url
        if url.startswith(("file:", "data:")):
            route.continue_()
        else:
            outside.append(url)
            route.abort()

    page.route("**/*", gate)
    t0 = time.perf_counter()
    page.goto(html_file.as_uri(), wait_until="load")
    images = page.evaluate(
        "Array.from(document.images).map(i => ({file: i.dataset.file, complete: i.complete,"
        " width: i.naturalWidth, inline: i.src.startsWith('data:')}))"
    )
    elapsed = time.perf_counter() - t0
    page.screenshot(path=str(shot), full_page=True)
    page.close()
    return {"images": images, "errors": errors, "outside": outside, "seconds": elapsed}


def _check(result: dict, shot: Path, n_images_min: int) -> None:
    imgs = result["images"]
    assert len(imgs) >= n_images_min
    assert all(i["inline"] for i in imgs), [i["file"] for i in imgs if not i["inline"]]
    assert all(i["complete"] and i["width"] > 0 for i in imgs), imgs
    assert result["errors"] == []
    assert result["outside"] == []
    assert shot.is_file() and shot.stat().st_size > 10_000


def test_fresh_report_renders_alone(browser, fresh_run, tmp_path, record_property):
    _, out = fresh_run
    alone = tmp_path / "mailed"
    alone.mkdir()
    shutil.copy(out / "report.html", alone / "report.html")  # without figures/ beside it
    shot = tmp_path / "report_screenshot.png"
    result = _render(browser, alone / "report.html", shot)
    record_property("render_seconds", round(result["seconds"], 3))
    (tmp_path / "render_time.json").write_text(json.dumps({"seconds": result["seconds"], "screenshot": shot.name}))
    print(f"report.html rendered in {result['seconds']:.2f} s; screenshot {shot}")
    res = json.loads((out / "results.json").read_text())
    _check(result, shot, len(res["figures"]))
    assert {i["file"] for i in result["images"]} == set(res["figures"])


def test_every_report_is_checked():
    names = {p.relative_to(ROOT / "reports").as_posix() for p in COMMITTED}
    assert {"fig12_velocity_field/report.html", "fig13_velocity_field/report.html", "validation.html",
            "calibration_piekutowski1999/report.html", "calibration_piekutowski1999_eroding/report.html"} <= names


@pytest.mark.parametrize("html_file", COMMITTED, ids=[p.relative_to(ROOT / "reports").as_posix() for p in COMMITTED])
def test_committed_report_renders_alone(browser, html_file, tmp_path, record_property):
    """Each committed HTML report, copied alone into an empty folder, shows all its figures."""
    alone = tmp_path / "mailed"
    alone.mkdir()
    shutil.copy(html_file, alone / "report.html")
    shot = tmp_path / "screenshot.png"
    result = _render(browser, alone / "report.html", shot)
    record_property("render_seconds", round(result["seconds"], 3))
    print(f"{html_file.name} rendered in {result['seconds']:.2f} s; screenshot {shot}")
    n_png = len({p for p in html_file.parent.glob("*.png")}) if html_file.name == "report.html" else 1
    _check(result, shot, min(n_png, 2) or 1)


def test_no_output_names_a_machine_path(fresh_run):
    """No output file (report.md/.html, results.json, the .vtu files, the PNGs) contains the
    absolute path of the case, of its folder or of the output folder; the case is named by
    its file name and SHA-256."""
    import hashlib

    case, out = fresh_run
    needles = {str(case.resolve()), str(case.parent.resolve()), str(out.resolve()), str(out.parent.resolve())}
    for f in out.rglob("*"):
        if f.is_file():
            data = f.read_bytes()
            for n in needles:
                assert n.encode() not in data, (f.relative_to(out), n)
    res = json.loads((out / "results.json").read_text())
    assert res["case"]["file"] == case.name
    assert res["case"]["sha256"] == hashlib.sha256(case.read_bytes()).hexdigest()
    md = (out / "report.md").read_text()
    assert f"`{case.name}` (sha256 `{res['case']['sha256'][:12]}`)" in md
    assert "Generated by `python -m semianalytic run fig13_small.toml" in md
