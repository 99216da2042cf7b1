"""Browser-side figures of the viewer and the live app, in headless Debian chromium (software
WebGL: --disable-gpu), printed as a small table:

- the size of the HTML files of `softarm view` (one equilibrium, an 11-step sweep) and of
  the notebook displays (the first of a session embeds plotly.js, later ones do not);
- sweep slider move -> redrawn frame in the viewer (plotly_sliderchange to two animation
  frames after the figure's plotly_afterplot);
- app slider move -> redrawn arm (the input event to two animation frames after Plotly.react),
  split into the solve on the server, the HTTP round trip and the redraw;
- the app's dynamic mode: new states drawn a second, the round trip, the drawing.

Run: python benchmarks/browser.py [--moves 20]   (needs chromium, chromium-driver, selenium
and plotly; see tests/_browser.py). Times depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import _browser  # noqa: E402

import softarm  # noqa: E402
from softarm import app, io, view  # noqa: E402
from softarm.case import solve_case  # noqa: E402


def _wait(driver, script, timeout=60.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = driver.execute_script(script)
        if value:
            return value
        time.sleep(0.02)
    raise TimeoutError(script)


def _sweep_case(folder: Path) -> softarm.Case:
    text = (ROOT / "examples" / "demo.toml").read_text(encoding="utf-8")
    text += ('\n[sweep]\nload = 2\nfield = "force"\ncomponent = "magnitude"\nstart = 0.0\n'
             'stop = 1.0\nsteps = 11\nname = "payload pull"\n')
    path = folder / "demo_sweep.toml"
    path.write_text(text, encoding="utf-8")
    return softarm.load_case(path)


def sweep_redraws(driver, page: Path, moves: int) -> list[float]:
    driver.get(page.as_uri())
    _wait(driver, "const gd = document.getElementById('softarm-view');"
          "return gd && gd._fullLayout && gd.querySelector('.slider-rail-rect') !== null;")
    driver.execute_script("""
        const gd = document.getElementById('softarm-view');
        window.redraws = [];
        window.t0 = null;
        gd.on('plotly_sliderchange', () => { window.t0 = performance.now(); });
        gd.on('plotly_afterplot', () => { if (window.t0 === null) return;
            const t0 = window.t0; window.t0 = null;
            requestAnimationFrame(() => requestAnimationFrame(
                () => window.redraws.push(performance.now() - t0))); });""")
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    rail = driver.find_element(By.CSS_SELECTOR, ".slider-rail-rect")
    width = rail.size["width"]
    for k in range(moves):
        step = 10 - (k + 1) % 11 if k % 2 else (k + 1) % 11  # never the step shown
        active = driver.execute_script(
            "return document.getElementById('softarm-view')._fullLayout.sliders[0].active")
        if step == active:
            step = (step + 3) % 11
        x = int((step / 10 - 0.5) * width * 0.96)
        count = len(driver.execute_script("return window.redraws"))
        ActionChains(driver).move_to_element_with_offset(rail, x, 0).click().perform()
        _wait(driver, f"return window.redraws.length > {count}")
    return driver.execute_script("return window.redraws")


def app_redraws(driver, moves: int) -> list[dict]:
    live = app.LiveCase(softarm.load_case(ROOT / "examples" / "demo.toml"))
    server = app.make_server(live, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        driver.get(f"http://127.0.0.1:{server.server_address[1]}/")
        _wait(driver, "return window.softarmTimings && window.softarmTimings.length > 0")
        for k in range(moves):
            count = driver.execute_script("return window.softarmTimings.length")
            value = -0.9 + 1.8 * (k % 10) / 9
            driver.execute_script(
                "const s = document.getElementById('l2.force.y'); s.value = arguments[0];"
                "s.dispatchEvent(new Event('input'));", str(value))
            _wait(driver, f"return window.softarmTimings.length > {count}")
        return driver.execute_script("return window.softarmTimings.slice(1)")
    finally:
        server.shutdown()
        server.server_close()


def motion_frames(driver, seconds: float = 4.0):
    """The dynamic mode (softarm app --dynamic) on the demo case with a tip pull: the frames
    drawn in the last ``seconds`` - 1 s ([state index, time, round trip, wait for the animation
    frame, drawing] ms each) and the server's step time."""
    live = app.LiveMotion(softarm.load_case(ROOT / "examples" / "demo.toml"),
                          app.Dynamics(dt=2e-3, damping=0.02))
    server = app.make_server(live, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    live.start()
    try:
        driver.get(f"http://127.0.0.1:{server.server_address[1]}/")
        _wait(driver, "return window.softarmFrames && window.softarmFrames.length > 5")
        driver.execute_script("const s = document.getElementById('l2.force.y');"
                              "s.value = s.max; s.dispatchEvent(new Event('input'));")
        time.sleep(seconds)
        frames = driver.execute_script("return window.softarmFrames")
        return [f for f in frames if f[1] >= frames[-1][1] - 1e3 * (seconds - 1)], live.step_ms
    finally:
        live.stop()
        server.shutdown()
        server.server_close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--moves", type=int, default=20)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        demo = softarm.load_case(ROOT / "examples" / "demo.toml")
        single = view.write_html(softarm.solve(demo.arm, demo.loads), folder / "demo.html",
                                 name="demo")
        case = _sweep_case(folder)
        io.save_result(solve_case(case), folder / "sweep.npz", case)
        sweep = view.view_result_file(io.load_saved(folder / "sweep.npz"), folder / "sweep.html")
        print(f"HTML size: one equilibrium {single.stat().st_size / 1e6:.2f} MB, "
              f"11-step sweep {sweep.stat().st_size / 1e6:.2f} MB "
              f"(plotly.js {view.plotly_js_path().stat().st_size / 1e6:.2f} MB of it)")
        view._notebook["embedded"] = False  # a fresh kernel session
        equilibrium = softarm.solve(demo.arm, demo.loads)
        first = len(equilibrium._repr_html_().encode())
        again = len(equilibrium._repr_html_().encode())
        swept = len(io.load_saved(folder / "sweep.npz").result._repr_html_().encode())
        print(f"notebook display: first of the session {first / 1e6:.2f} MB (plotly.js "
              f"embedded), then one equilibrium {again / 1e3:.0f} kB, 11-step sweep "
              f"{swept / 1e3:.0f} kB")
        driver = _browser.chromium()
        try:
            redraws = sweep_redraws(driver, sweep, args.moves)
            print(f"viewer sweep slider -> redraw: median {statistics.median(redraws):.0f} ms, "
                  f"min {min(redraws):.0f}, max {max(redraws):.0f} ({len(redraws)} moves)")
            timings = app_redraws(driver, args.moves)
            frames, step_ms = motion_frames(driver)
        finally:
            driver.quit()
    for key, what in (("total", "slider -> redrawn"), ("solve", "solve (server)"),
                      ("fetch", "HTTP round trip"), ("redraw", "Plotly.react + paint")):
        values = [t[key] for t in timings]
        print(f"app {what}: median {statistics.median(values):.1f} ms, min {min(values):.1f}, "
              f"max {max(values):.1f} ({len(values)} moves)")
    span = (frames[-1][1] - frames[0][1]) / 1e3
    new = len({f[0] for f in frames})
    print(f"app --dynamic (demo, dt 2 ms, 41 stations): {(len(frames) - 1) / span:.1f} frames a "
          f"second, {new} new states of {len(frames)} drawn; median round trip "
          f"{statistics.median(f[2] for f in frames):.1f} ms, drawing "
          f"{statistics.median(f[4] for f in frames):.1f} ms; last step {step_ms:.2f} ms")


if __name__ == "__main__":
    main()
