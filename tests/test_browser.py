"""The viewer and the live app in a real browser: Debian's headless chromium via selenium and
the system chromedriver (tests/_browser.py; they skip, saying how to install it, without).

Checked: the page opens without console errors, the screenshot shows the arm (pixel
statistics), moving the sweep slider redraws the tip of that step, moving an app slider
re-solves and shows the new tip, and a malformed request gets a 400 while the app keeps
serving. Times are measured by benchmarks/browser.py, never asserted here.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm.case import solve_case

pytest.importorskip("plotly", reason="the viewer needs plotly: pip install 'softarm[view]'")

import _browser

from softarm import app, io, view

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# a real browser: in pytest -m slow (and CI), not in a plain pytest
pytestmark = pytest.mark.slow


def wait_for(driver, script, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = driver.execute_script(script)
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for: {script}")


def tip_js(div: str) -> str:
    """Script returning the last point of the drawn centreline in the figure ``div``."""
    return (f"const t = document.getElementById('{div}')._fullData.find("
            "d => d.name === 'centreline'); const n = t.x.length - 1;"
            "return [t.x[n], t.y[n], t.z[n]];")


def orange_pixels(png: bytes) -> int:
    """Pixels of the tube's orange (255, 127, 14) under its shading (the tube is opaque):
    clearly red-orange, neither grey nor white."""
    rgb = _browser.png_pixels(png).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(np.sum((r > 150) & (r - b > 70) & (g > 60) & (g < r - 25)))


def test_view_page_draws_the_arm(browser, tmp_path):
    case = softarm.load_case(EXAMPLES / "demo.toml")
    result = softarm.solve(case.arm, case.loads)
    page = view.write_html(result, tmp_path / "demo.html", name=case.name)
    browser.get(page.as_uri())
    wait_for(browser, "const gd = document.getElementById('softarm-view');"
             "return gd && gd._fullLayout && gd.querySelector('canvas') !== null;")
    time.sleep(1.0)  # let WebGL paint
    png = browser.get_screenshot_as_png()
    (tmp_path / "demo.png").write_bytes(png)
    assert _browser.severe_console_messages(browser) == []
    rgb = _browser.png_pixels(png)
    assert rgb.std() > 10, "blank screenshot"
    assert orange_pixels(png) > 2000, "no tube in the screenshot"
    # what the browser holds is the equilibrium: its centreline ends at the tip
    tip = browser.execute_script(tip_js("softarm-view"))
    np.testing.assert_allclose(tip, result.tip_position, atol=1e-6)


def test_sweep_slider_moves_the_drawn_tip(browser, tmp_path):
    case = softarm.load_case(EXAMPLES / "fig2_sweep.toml")
    saved_path = tmp_path / "sweep.npz"
    io.save_result(solve_case(case), saved_path, case)
    saved = io.load_saved(saved_path)
    page = view.view_result_file(saved, tmp_path / "sweep.html")
    browser.get(page.as_uri())
    wait_for(browser, "const gd = document.getElementById('softarm-view');"
             "return gd && gd._fullLayout && gd.querySelector('.slider-rail-rect') !== null;")
    before = browser.execute_script(tip_js("softarm-view"))
    np.testing.assert_allclose(before, saved.result.tip_position[0], atol=1e-6)
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    rail = browser.find_element(By.CSS_SELECTOR, ".slider-rail-rect")
    width = rail.size["width"]
    ActionChains(browser).move_to_element_with_offset(rail, int(0.45 * width), 0).click() \
        .perform()
    active = wait_for(browser, "const s = document.getElementById('softarm-view')"
                      "._fullLayout.sliders[0].active; return s > 0 ? s : null;")
    assert active == len(saved.sweep_values) - 1  # clicked near the right end of the rail
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        after = browser.execute_script(tip_js("softarm-view"))
        if not np.allclose(after, before):
            break
        time.sleep(0.05)
    # the drawn tip is that of the last step (τ = 5 N m, from the result file)
    np.testing.assert_allclose(after, saved.result.tip_position[active], atol=1e-6)
    # the tip plot rings the shown step's tip coordinates
    shown = browser.execute_script(
        "const t = document.getElementById('softarm-view-tips')._fullData[3];"
        "return [Array.from(t.x), Array.from(t.y)];")
    np.testing.assert_allclose(shown[0], [saved.sweep_values[active]] * 3)
    np.testing.assert_allclose(shown[1], saved.result.tip_position[active], atol=1e-6)
    # back to the first step, then play: the frames run to the last one
    ActionChains(browser).move_to_element_with_offset(rail, -int(0.45 * width), 0).click() \
        .perform()
    wait_for(browser, "return document.getElementById('softarm-view')"
             "._fullLayout.sliders[0].active === 0")
    browser.execute_script("const gd = document.getElementById('softarm-view');"
                           "window.seen = []; gd.on('plotly_afterplot', "
                           "() => window.seen.push(gd._fullLayout.sliders[0].active));")
    play = browser.find_elements(By.CSS_SELECTOR, ".updatemenu-button")[0]
    ActionChains(browser).move_to_element(play).click().perform()
    wait_for(browser, "return document.getElementById('softarm-view')._fullLayout"
             f".sliders[0].active === {active}", timeout=60)
    wait_for(browser, f"{tip_js('softarm-view')[:-1].replace('return ', 'const p = ')};"
             f"return Math.abs(p[0] - {saved.result.tip_position[active][0]}) < 1e-6;")
    np.testing.assert_allclose(browser.execute_script(tip_js("softarm-view")),
                               saved.result.tip_position[active], atol=1e-6)
    seen = browser.execute_script("return window.seen")
    assert sorted(set(seen)) == list(range(1, active + 1))  # every step on the way, in turn
    assert _browser.severe_console_messages(browser) == []


@pytest.fixture()
def live_server():
    live = app.LiveCase(softarm.load_case(EXAMPLES / "demo.toml"))
    httpd = app.make_server(live, port=0)
    thread = threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.05},
                              daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}/", live
    httpd.shutdown()
    httpd.server_close()


def test_app_slider_resolves_and_redraws(browser, live_server, tmp_path):
    url, live = live_server
    browser.get(url)
    wait_for(browser, "return window.softarmTimings && window.softarmTimings.length > 0")
    count = browser.execute_script("return window.softarmTimings.length")
    # drag the tip force's y component to 0.8 N (an input event, as a slider drag sends)
    browser.execute_script(
        "const s = document.getElementById('l2.force.y'); s.value = '0.8';"
        "s.dispatchEvent(new Event('input'));")
    wait_for(browser, f"return window.softarmTimings.length > {count}", timeout=30)
    shown = browser.execute_script(
        "return JSON.parse(document.getElementById('status').dataset.tip)")
    case = live.case
    loads = (case.loads[0], case.loads[1].replace(force=[0.0, 0.8, -0.4]))
    expected = softarm.solve(case.arm, loads).tip_position  # from unloaded, another route
    np.testing.assert_allclose(shown, expected, atol=1e-6)
    drawn = browser.execute_script(tip_js("plot"))
    np.testing.assert_allclose(drawn, expected, atol=1e-6)
    # the load's heading says its values now, not the case file's
    heading = browser.execute_script(
        "return document.getElementById('l2.on').parentElement.textContent")
    assert heading.strip() == "2: " + loads[1].describe()
    png = browser.get_screenshot_as_png()
    (tmp_path / "app.png").write_bytes(png)
    assert orange_pixels(png) > 1000, "no tube in the screenshot"
    assert _browser.severe_console_messages(browser) == []
    # a malformed request from the page: 400 with a message; the app keeps serving
    status = browser.execute_async_script(
        "const done = arguments[0];"
        "fetch('/solve?l2.force.y=oops').then(r => r.json().then(b => done([r.status, "
        "b.error])));")
    assert status[0] == 400 and "must be a number" in status[1]
    count = browser.execute_script("return window.softarmTimings.length")
    browser.execute_script(
        "const s = document.getElementById('l1.on'); s.checked = false;"
        "s.dispatchEvent(new Event('change'));")
    wait_for(browser, f"return window.softarmTimings.length > {count}", timeout=30)
    shown = browser.execute_script(
        "return JSON.parse(document.getElementById('status').dataset.tip)")
    weightless = softarm.solve(case.arm, loads[1:]).tip_position  # gravity switched off
    np.testing.assert_allclose(shown, weightless, atol=1e-6)
    errors = _browser.severe_console_messages(browser)
    assert len(errors) == 1 and "oops" in errors[0] and "400" in errors[0]  # the one we sent


RECT = ("const r = e => { const b = e.getBoundingClientRect(); "
        "return [b.left, b.top, b.right, b.bottom]; };")


def overlap(a, b) -> bool:
    """Whether two rectangles [left, top, right, bottom] share an area."""
    return min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1])


def test_pages_fill_the_window_and_the_controls_stay_off_the_scene(browser, live_server,
                                                                  tmp_path):
    # In a 1200 x 900 window the figures were 650 px (the viewer) and 700 px (the app) high,
    # leaving the rest blank, and the sweep's play and pause buttons lay over the 3D scene.
    browser.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
        "width": 1200, "height": 900, "deviceScaleFactor": 1, "mobile": False})
    try:
        case = softarm.load_case(EXAMPLES / "demo.toml")
        page = view.write_html(softarm.solve(case.arm, case.loads), tmp_path / "demo.html")
        browser.get(page.as_uri())
        wait_for(browser, "const gd = document.getElementById('softarm-view');"
                 "return gd && gd._fullLayout && gd.querySelector('canvas') !== null;")
        drawn = browser.execute_script(
            RECT + "const gd = document.getElementById('softarm-view');"
            "return [r(gd), gd._fullLayout.height, r(gd._fullLayout.scene._scene.container)]")
        assert drawn[0] == [0, 0, 1200, 900] and drawn[1] == 900
        assert drawn[2][3] >= 900 - 20  # the scene reaches down to the bottom margin
        # the sweep: 3D figure, tip plot, slider and buttons, none over the scene
        sweep_case = softarm.load_case(EXAMPLES / "fig2_sweep.toml")
        io.save_result(solve_case(sweep_case), tmp_path / "sweep.npz", sweep_case)
        page = view.view_result_file(io.load_saved(tmp_path / "sweep.npz"),
                                     tmp_path / "sweep.html")
        browser.get(page.as_uri())
        wait_for(browser, "const gd = document.getElementById('softarm-view');"
                 "return !!(gd && gd._fullLayout && gd.querySelector('.updatemenu-button') "
                 "&& document.getElementById('softarm-view-tips')._fullLayout);")
        parts = browser.execute_script(
            RECT + "const gd = document.getElementById('softarm-view');"
            "return {figure: r(gd), height: gd._fullLayout.height,"
            " scene: r(gd._fullLayout.scene._scene.container),"
            " buttons: Array.from(gd.querySelectorAll('.updatemenu-button')).map(r),"
            " rail: r(gd.querySelector('.slider-rail-rect')),"
            " tips: r(document.getElementById('softarm-view-tips'))};")
        (tmp_path / "sweep.png").write_bytes(browser.get_screenshot_as_png())
        assert parts["figure"] == [0, 0, 1200, 900] and parts["height"] == 900
        assert len(parts["buttons"]) == 2
        for part in [*parts["buttons"], parts["rail"], parts["tips"]]:
            assert not overlap(part, parts["scene"]), (part, parts["scene"])
        for button in parts["buttons"]:  # left of the rail, on its row
            assert button[2] <= parts["rail"][0] and button[1] <= parts["rail"][1] <= button[3]
        # the app: the figure as high as the window too
        url, _ = live_server
        browser.get(url)
        wait_for(browser, "return window.softarmTimings && window.softarmTimings.length > 0")
        plot = browser.execute_script(
            RECT + "const gd = document.getElementById('plot');"
            "return [r(gd), gd._fullLayout.height]")
        assert plot[0][1] == 0 and plot[0][3] == 900 and plot[1] == 900
        assert _browser.severe_console_messages(browser) == []
    finally:
        browser.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})


def test_notebook_outputs_share_one_plotly_js(browser, tmp_path, monkeypatch):
    # Outputs as a notebook page holds them: only the first display of the kernel session
    # embeds plotly.js. A view above it on the page (drawn before the library arrives) waits
    # for it; one below uses it; one without any embedding output on the page says why it
    # is blank instead of failing.
    case = softarm.load_case(EXAMPLES / "demo.toml")
    result = softarm.solve(case.arm, case.loads)
    monkeypatch.setitem(view._notebook, "embedded", False)
    first, second, third = (result._repr_html_() for _ in range(3))
    page = tmp_path / "notebook.html"
    page.write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'></head><body>"
                    f"{second}{first}{third}</body></html>", encoding="utf-8")
    browser.get(page.as_uri())
    drawn = ("return Array.from(document.querySelectorAll('.plotly-graph-div'))"
             ".filter(gd => gd._fullLayout && gd.querySelector('canvas')).length;")
    assert wait_for(browser, f"{drawn.removesuffix(';')} === 3 ? 3 : 0") == 3
    ids = browser.execute_script("return Array.from(document.querySelectorAll("
                                 "'.plotly-graph-div')).map(gd => gd.id)")
    assert len(set(ids)) == 3
    for div in ids:  # each draws the equilibrium: its centreline ends at the tip
        np.testing.assert_allclose(browser.execute_script(tip_js(div)), result.tip_position,
                                   atol=1e-6)
    assert _browser.severe_console_messages(browser) == []
    alone = tmp_path / "alone.html"
    alone.write_text(f"<!DOCTYPE html><html><body>{third}</body></html>", encoding="utf-8")
    browser.get(alone.as_uri())
    text = wait_for(browser, "return document.querySelector('.plotly-graph-div').textContent")
    assert "waiting for plotly.js" in text and "NOTEBOOK_PLOTLYJS = 'always'" in text
    assert _browser.severe_console_messages(browser) == []
