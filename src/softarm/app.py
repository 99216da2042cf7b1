"""``softarm app CASE.toml``: explore a case live in the browser.

A small local web app on 127.0.0.1 (the standard library's ``http.server``; plotly.js is served
from the installed plotly package, so no network is needed): a slider for every component of
every load vector of the case and a switch per load; each move re-solves the arm with a
prepared :class:`softarm.statics.Solver`, which follows the arm *quasi-statically* from its
previous equilibrium (as a slowly driven arm moves), and redraws it. "Reset" returns the
solver to the unloaded arm.

Endpoints: ``GET /`` the page; ``GET /plotly.min.js``; ``GET /solve?NAME=VALUE&...`` the
equilibrium for these inputs (names as listed by ``GET /inputs``; absent ones keep their last
value) as JSON ``{"data": [...traces], "ranges", "ticks", "title", "tip": [x, y, z],
"solve_ms", "method", "residual", "stability"}`` (``data``: only what changes of each 3D
trace of the page's figure, in its order, see :func:`softarm.view.scene_traces`; ``ticks``:
each axis's tick values, see :func:`softarm.view.axis_ticks`; ``stability``: the verdict in
words); ``GET /reset`` the same after returning to the unloaded arm. A bad request (an
unknown name, a value that is not a finite number or is out of its slider's range) gets
HTTP 400 with ``{"error": message}``; a load the solver cannot follow (a fold, a load too large
for the arm) gets HTTP 422 with the message, and the arm stays where it was.

``softarm app CASE.toml --dynamic``: the arm in motion (:class:`LiveMotion`, see "dynamic
mode" below; endpoints ``/state``, ``/reset``, ``/history``: docs/cli.md).
"""

from __future__ import annotations

import collections
import contextlib
import errno
import html
import json
import math
import sys
import threading
import time
import webbrowser
from dataclasses import dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qsl, urlsplit

import numpy as np

from ._validate import format_value
from .case import Case, CaseError
from .errors import ConvergenceError
from .geometry import contacts, cube_limits, station_radii
from .statics import Solver
from .view import axis_ticks, figure, plotly_js_path, scene_traces, to_json

__all__ = ["Dynamics", "Input", "LiveCase", "LiveMotion", "inputs", "make_server", "serve"]


@dataclass(frozen=True)
class Input:
    """One control of the app: a slider for a component of a load vector (``component`` 0, 1,
    2), a slider for a load's magnitude (a tension, a pressure: ``component`` -1), or a switch
    turning a whole load on and off (``component`` None, values 0 and 1)."""

    name: str
    label: str
    unit: str
    low: float
    high: float
    value: float
    load: int
    field: str | None = None
    component: int | None = None

    @property
    def step(self) -> float:
        return (self.high - self.low) / 200.0 if self.component is not None else 1.0


def _nice(x: float) -> float:
    """The smallest of 1, 2, 5 × 10^k that is >= x (x > 0)."""
    k = math.floor(math.log10(x))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10.0**k >= x * (1 - 1e-12):
            return m * 10.0**k
    return 10.0 ** (k + 1)  # pragma: no cover


def _bending(arm) -> float:
    """The smallest bending stiffness of the arm's segments, N m²."""
    return min(min(a.rigidities.EIy, a.rigidities.EIz) for a in arm.segments)


def _default_range(unit: str, arm) -> float:
    """A slider half-range for a vector that is zero in the case file: the load that bends
    the arm by about a radian (EI/L² for a tip force, EI/L for a moment, ...)."""
    EI, L = _bending(arm), float(arm.length)
    return {"N": EI / L**2, "N m": EI / L, "N/m": EI / L**3, "N m/m": EI / L**2,
            "m/s²": 20.0}.get(unit, 1.0)


def inputs(case: Case) -> list[Input]:
    """The app's controls for ``case``: for each load a switch and, for each of its vector
    fields, three sliders (x, y, z) over ±2 × the file's magnitude (rounded up to 1, 2 or 5 ×
    10^k), or over ±(the load that bends the arm by about a radian) for a zero vector; a
    swept component's slider spans the sweep's range too."""
    out = []
    for i, load in enumerate(case.loads):
        kind = load.kind
        out.append(Input(f"l{i + 1}.on", f"{i + 1}: {load.describe()}", "", 0.0, 1.0, 1.0, i))
        for name, unit, shape in load.arrays:
            if shape != () or getattr(load, name) is None:  # (a tendon's unused control)
                continue
            value = float(np.asarray(getattr(load, name), dtype=float))
            reach = None if value != 0.0 else load.routing.bound(float(case.arm.length)) or 1.0
            if value != 0.0:
                half = _nice(2.0 * abs(value))
            elif unit == "m":  # a tendon's displacement: about a radian of bending, ρ
                half = _nice(reach)
            else:  # about a radian of bending: τ ρ L / EI ≈ 1 (p A for a chamber)
                half = _nice(_bending(case.arm) / (float(case.arm.length) * reach
                                                   * getattr(load, "area", 1.0)))
            low = 0.0 if value >= 0.0 and unit != "m" else -half  # a displacement: either way
            out.append(Input(f"l{i + 1}.{name}", f"{kind} {name}", unit, low, half, value, i,
                             name, -1))
        for name, unit in load.vectors:
            vector = np.asarray(getattr(load, name), dtype=float)
            norm = float(np.linalg.norm(vector))
            half = _nice(2.0 * norm if norm > 0 else _default_range(unit, case.arm))
            for c, axis in enumerate("xyz"):
                low, high = -half, half
                sweep = case.sweep
                if sweep is not None and sweep.load == i and sweep.field == name:
                    values = np.asarray(sweep.values, dtype=float)
                    if sweep.component == "magnitude":
                        values = values[:, None] * vector / max(norm, 1e-300)
                        values = values[:, c]
                    elif sweep.component != axis:
                        values = np.array([vector[c]])
                    low, high = min(low, float(values.min())), max(high, float(values.max()))
                frame = "material" if getattr(load, "follower", False) else "spatial"
                out.append(Input(f"l{i + 1}.{name}.{axis}", f"{kind} {name} {axis} ({frame})",
                                 unit, low, high, float(vector[c]), i, name, c))
    return out


class BadRequest(ValueError):
    """A request the app cannot serve (HTTP 400)."""


class LiveCase:
    """A case being explored: its controls, their current values and a prepared Solver.

    Not thread-safe by itself; the server serialises calls with a lock.
    """

    def __init__(self, case: Case):
        self.case = case
        self.inputs = inputs(case)
        self.by_name = {item.name: item for item in self.inputs}
        self.values = {item.name: item.value for item in self.inputs}
        self.solver = Solver(case.arm, s=int(case.solve.stations), tol=float(case.solve.tol))
        length = float(case.arm.length)
        # arrows: a component at the end of its slider is drawn 0.35 L long (0.2 L for
        # distributed loads and gravity, drawn as several arrows)
        self.scales = {}
        for item in self.inputs:
            if item.field is not None:
                largest = max(abs(item.low), abs(item.high))
                several = case.loads[item.load].kind not in ("tip", "point")
                self.scales[(item.load, item.field)] = \
                    (0.2 if several else 0.35) * length / largest
        # the axis cube (equal scaling) only grows, so that the view does not jump while the
        # sliders move; set around the first drawing
        self.limits = None

    def update(self, query: dict[str, str]) -> None:
        """Set inputs from a request's query (BadRequest naming the first bad one)."""
        self.values = _updated(self.by_name, self.values, query)

    def loads(self) -> tuple:
        """The case's loads with the current input values (switched-off loads left out)."""
        return tuple(self.current(i) for i in range(len(self.case.loads))
                     if self.values[f"l{i + 1}.on"])

    def current(self, i: int):
        """Load i of the case with the current input values (whether on or off)."""
        return _current_load(self.case.loads[i], i, self.values)

    def headings(self) -> dict:
        """Each load's heading on the page, with its current values (the switches' labels)."""
        return _headings(self.case, self.values)

    def solve(self) -> dict:
        """Solve for the current inputs from the previous equilibrium; the reply's body."""
        loads = self.loads()
        start = time.perf_counter()
        result = self.solver.solve(loads)
        seconds = time.perf_counter() - start
        result = _with_all_loads(result, self.case.loads, self.values)
        self.result = result
        self._grow_limits(result)
        centre, half = self.limits
        ranges = [[centre[k] - half, centre[k] + half] for k in range(3)]
        return {"ranges": ranges, "ticks": [axis_ticks(*bounds) for bounds in ranges],
                "data": scene_traces(result, self.scales, changing=True),
                "title": _title(self.case, loads),
                "tip": np.asarray(result.tip_position).tolist(),
                "headings": self.headings(),
                "solve_ms": 1e3 * seconds, "method": result.method,
                "residual": float(np.max(result.residual)),
                "stability": None if result.stability is None else
                result.stability.describe()}

    def _grow_limits(self, result) -> None:
        """Enlarge the axis cube to hold the drawing of ``result`` (with a 30 % margin the
        first time and whenever it grows)."""
        from .geometry import load_arrows, station_radii

        poses = np.asarray(result.poses)
        radii = station_radii(result.arm, result.s)
        reach = 0.0 if radii is None else float(np.max(radii))
        points = [poses[:, :3, 3] + reach, poses[:, :3, 3] - reach]
        for arrow in load_arrows(result.loads, poses, result.s, result.arm):
            points.append(arrow.origins + arrow.vectors * self.scales.get(arrow.key, 0.0))
        points = np.concatenate(points)
        if self.limits is not None:
            centre, half = self.limits
            if np.all(np.abs(points - centre) <= half):
                return
            points = np.concatenate([points, [centre - half, centre + half]])
        self.limits = cube_limits(points, margin=1.3)

    def figure(self) -> dict:
        """The page's first figure: the current equilibrium (solved once, from unloaded)."""
        body = self.solve()
        fig = figure(self.result, name=self.case.name, scales=self.scales, limits=self.limits,
                     height=None)  # as high as the page (#plot)
        fig["layout"]["title"]["text"] = body["title"]
        return fig


def _updated(by_name: dict, values: dict, query: dict[str, str]) -> dict:
    """``values`` with a request's query set (BadRequest naming the first bad input)."""
    new = dict(values)
    for name, text in query.items():
        item = by_name.get(name)
        if item is None:
            raise BadRequest(f"unknown input {name!r}; known inputs: {', '.join(by_name)}")
        try:
            value = float(text)
        except ValueError:
            raise BadRequest(f"{name} must be a number, got {text!r}") from None
        if not math.isfinite(value):
            raise BadRequest(f"{name} must be a finite number, got {text!r}")
        if item.component is None and value not in (0.0, 1.0):  # (a switch)
            raise BadRequest(f"{name} must be 0 (off) or 1 (on), got {format_value(value)}")
        if not item.low <= value <= item.high:
            unit = f" {item.unit}" if item.unit else ""
            raise BadRequest(f"{name} must be in [{format_value(item.low)}, "
                             f"{format_value(item.high)}]{unit}, got {format_value(value)}")
        new[name] = value
    return new


def _current_load(load, i: int, values: dict, on: float = 1.0):
    """Load i of a case with the inputs' ``values`` (times ``on``)."""
    fields = _fields(load, i, values, on)
    return load.replace(**fields) if fields else load


def _headings(case: Case, values: dict) -> dict:
    """Each load's heading on the page, with its current values (the switches' labels)."""
    return {f"l{i + 1}.on": f"{i + 1}: {_current_load(load, i, values).describe()}"
            for i, load in enumerate(case.loads)}


def _with_all_loads(result, loads, values):
    """``result`` with its loads in the case's order, so that arrow keys (load index, field)
    stay the same whichever loads are switched off (switched-off loads as zero vectors);
    a contact as solved (with the contact law the solver chose, which its forces need)."""
    import dataclasses

    solved = contacts(result.loads)
    full = []
    for i, load in enumerate(loads):
        fields = _fields(load, i, values, values[f"l{i + 1}.on"])
        if load.kind == "contact" and solved:
            load = solved[0]
        full.append(load.replace(**fields) if fields else load)
    return dataclasses.replace(result, loads=tuple(full))


def _fields(load, i: int, values: dict, on: float) -> dict:
    """Load i's slider-controlled fields at the current values (times ``on``)."""
    fields = {name: [values[f"l{i + 1}.{name}.{axis}"] * on for axis in "xyz"]
              for name, _ in load.vectors}
    fields.update({name: values[f"l{i + 1}.{name}"] * on for name, _, shape in load.arrays
                   if shape == () and getattr(load, name) is not None})
    return fields


def _title(case: Case, loads) -> str:
    text = " + ".join(load.describe() for load in loads) or "no load"
    return f"{case.name}: {text}"


# The page's look and its controls (a switch per load, a slider per input; a change calls the
# page's request()), shared by the static and the dynamic mode's pages.
_STYLE = """
body { font-family: sans-serif; margin: 0; display: flex; overflow: hidden; }
#controls { width: 330px; padding: 10px; font-size: 13px; height: 100vh; overflow-y: auto;
  box-sizing: border-box; background: #f6f6f6; }
#plot { flex: 1; min-width: 0; height: 100vh; }
fieldset { margin: 0 0 8px 0; border: 1px solid #ccc; }
label { display: block; margin-top: 4px; }
input[type=range] { width: 100%; }
#status { font-family: monospace; font-size: 12px; white-space: pre-wrap; margin-top: 8px; }
#error { color: #b00; font-size: 12px; margin-top: 6px; }
"""

_CONTROLS = """const box = document.getElementById("inputs");
let fieldset = null;
for (const item of INPUTS) {
  if (item.component === null) {
    fieldset = document.createElement("fieldset");
    const legend = document.createElement("legend");
    const check = document.createElement("input");
    check.type = "checkbox"; check.id = item.name; check.checked = item.value === 1;
    check.addEventListener("change", request);
    legend.append(check, " " + item.label);
    fieldset.append(legend);
    box.append(fieldset);
    continue;
  }
  const label = document.createElement("label");
  const out = document.createElement("span");
  out.id = item.name + ".out";
  label.append(item.label + " = ", out, " " + item.unit);
  const slider = document.createElement("input");
  slider.type = "range"; slider.id = item.name;
  slider.min = item.low; slider.max = item.high; slider.step = "any";
  slider.value = item.value;
  out.textContent = Number(item.value).toPrecision(4);
  slider.addEventListener("input", () => {
    out.textContent = Number(slider.value).toPrecision(4); request(); });
  fieldset.append(label, slider);
}
function query() {
  return INPUTS.map(item => {
    const el = document.getElementById(item.name);
    const value = item.component === null ? (el.checked ? 1 : 0) : el.value;
    return encodeURIComponent(item.name) + "=" + encodeURIComponent(value);
  }).join("&");
}
"""


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>softarm app: {name}</title>
<link rel="icon" href="data:,">
<style>{style}</style></head>
<body><div id="controls"><h3 style="margin:4px 0">softarm: {name}</h3>
<div style="color:#555">{description}</div>
<div id="inputs"></div>
<button id="reset" title="return to the unloaded arm and solve again">reset</button>
<div id="status"></div><div id="error"></div></div>
<div id="plot"></div>
<script src="/plotly.min.js"></script>
<script>
const INPUTS = {inputs};
const FIGURE = {figure};
window.softarmTimings = [];
{controls}
const layout = FIGURE.layout;
const cube = FIGURE.data.find(trace => trace.name === "axis cube");  // see view._cube_anchor
// WebGL at the screen's own resolution, as in softarm.view (see _DRAW there)
const CONFIG = {{responsive: true, displaylogo: false,
  plotGlPixelRatio: Math.min(2, Math.max(1, Math.round(window.devicePixelRatio || 1)))}};
const status = document.getElementById("status");
const error = document.getElementById("error");
let busy = false, pending = null;
async function send(path) {{
  if (busy) {{ pending = path; return; }}
  busy = true;
  const t0 = performance.now();
  try {{
    const reply = await fetch(path);
    const body = await reply.json();
    const t1 = performance.now();
    if (!reply.ok) {{ error.textContent = body.error; return; }}
    error.textContent = "";
    // body.data holds only what changed in each scene trace (coordinates, hover data): merged
    // into the drawn traces, so that the unchanging parts (the tube's triangles, colours,
    // hover templates) are neither sent nor parsed again. Plotly.react with a new
    // datarevision redraws the figure once with the new title and axis ranges too (for a 3D
    // scene plotly.js recomputes every trace on any data change, so restyling only the
    // changed traces would cost as much, in two calls).
    body.data.forEach((trace, i) => Object.assign(FIGURE.data[i], trace));
    layout.title.text = body.title;
    for (const [name, text] of Object.entries(body.headings)) {{  // each load's values now
      const check = document.getElementById(name);
      if (check) check.parentElement.lastChild.textContent = " " + text;
    }}
    ["xaxis", "yaxis", "zaxis"].forEach((axis, k) => {{
      layout.scene[axis].range = body.ranges[k];
      layout.scene[axis].tickvals = body.ticks[k];  // see softarm.view.axis_ticks
      cube["xyz"[k]] = body.ranges[k]; }});
    layout.datarevision = (layout.datarevision || 0) + 1;
    await Plotly.react("plot", FIGURE.data, layout, CONFIG);
    await new Promise(done => requestAnimationFrame(() => requestAnimationFrame(done)));
    const t2 = performance.now();
    const tip = body.tip.map(v => v.toPrecision(4)).join(", ");
    status.textContent = "tip  (" + tip + ") m\\nsolve  " + body.solve_ms.toFixed(2) +
      " ms (" + body.method + ")\\nserver round trip  " + (t1 - t0).toFixed(1) +
      " ms\\nredraw  " + (t2 - t1).toFixed(1) + " ms" +
      (body.stability ? "\\nstability  " + body.stability : "");
    status.dataset.tip = JSON.stringify(body.tip);
    window.softarmTimings.push({{solve: body.solve_ms, fetch: t1 - t0, redraw: t2 - t1,
                                total: t2 - t0}});
  }} catch (e) {{
    error.textContent = "no answer from the softarm app (stopped?): " + e;
  }} finally {{
    busy = false;
    if (pending !== null) {{ const next = pending; pending = null; send(next); }}
  }}
}}
function request() {{ send("/solve?" + query()); }}
document.getElementById("reset").addEventListener("click", () => send("/reset?" + query()));
Plotly.newPlot("plot", FIGURE.data, layout, CONFIG)
  .then(request);
</script></body></html>
"""


def _page(live: LiveCase) -> bytes:
    fig = live.figure()
    items = [{"name": i.name, "label": i.label, "unit": i.unit, "low": i.low, "high": i.high,
              "value": i.value, "step": i.step, "component": i.component}
             for i in live.inputs]
    case = live.case
    return _PAGE.format(
        style=_STYLE, controls=_CONTROLS, name=html.escape(case.name),
        description=html.escape(case.description or ""),
        inputs=json.dumps(items).replace("</", "<\\/"),
        figure=to_json(fig).replace("</", "<\\/")).encode("utf-8")


class _Handler(BaseHTTPRequestHandler):
    server_version = "softarm-app"
    protocol_version = "HTTP/1.1"  # keep-alive: a slider's requests reuse one connection
    # TCP_NODELAY: a reply's headers and body go out in two writes; with Nagle's algorithm
    # the body waited for the client's delayed acknowledgement of the headers (about 40 ms
    # on Linux), which held the dynamic mode to some 15 frames a second
    disable_nagle_algorithm = True
    live: LiveCase
    lock: threading.Lock
    plotly_js: bytes
    quiet = True

    def log_message(self, format, *args):
        if not self.quiet:
            super().log_message(format, *args)

    def _send(self, status: int, body: bytes, content_type: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store" if "json" in content_type else
                         "max-age=3600")
        self.end_headers()
        with contextlib.suppress(BrokenPipeError, ConnectionResetError):
            self.wfile.write(body)

    def _json(self, status: int, value) -> None:
        self._send(status, json.dumps(value).encode("utf-8") if not isinstance(value, bytes)
                   else value, "application/json")

    def do_GET(self):
        url = urlsplit(self.path)
        try:
            if isinstance(self.live, LiveMotion):
                self._motion(url)
            else:
                self._still(url)
        except BadRequest as error:
            self._json(400, {"error": str(error)})
        except Exception as error:  # never let one request stop the app
            self._json(500, {"error": _one_line(f"{type(error).__name__}: {error}")})

    def _still(self, url) -> None:
        """The static mode's endpoints."""
        if url.path == "/":
            with self.lock:
                page = _page(self.live)
            self._send(200, page, "text/html; charset=utf-8")
        elif url.path == "/plotly.min.js":
            self._send(200, self.plotly_js, "text/javascript; charset=utf-8")
        elif url.path == "/inputs":
            self._json(200, [i.__dict__ | {"step": i.step} for i in self.live.inputs])
        elif url.path in ("/solve", "/reset"):
            query = _query(url.query)
            # one solve at a time (they share the Solver and its last equilibrium); the
            # reply is encoded and sent after the lock is let go
            failure = None
            with self.lock:
                old = self.live.values
                self.live.update(query)
                if url.path == "/reset":
                    self.live.solver.reset()
                try:
                    body = self.live.solve()
                except (ConvergenceError, ValueError) as error:
                    self.live.values = old
                    failure = f"cannot solve for these inputs: {error}"
            if failure is not None:
                self._json(422, {"error": _one_line(failure)})
            else:
                self._send(200, to_json(body).encode("utf-8"), "application/json")
        else:
            self._json(404, {"error": f"no such page: {url.path}"})

    def _motion(self, url) -> None:
        """The dynamic mode's endpoints: ``/`` the page, ``/state?after=INDEX&NAME=VALUE...``
        the newest state once newer than INDEX (waiting up to a second), the inputs set
        first; ``/reset`` back to the start; ``/history`` the actuators' inputs per step;
        ``/inputs``, ``/plotly.min.js`` as in the static mode."""
        live = self.live
        if url.path == "/":
            self._send(200, live.page(), "text/html; charset=utf-8")
        elif url.path == "/inputs":
            self._json(200, [i.__dict__ | {"step": i.step} for i in live.inputs])
        elif url.path in ("/state", "/reset"):
            query = _query(url.query)
            after = query.pop("after", "-1")
            try:
                after = int(after)
            except ValueError:
                raise BadRequest(f"after must be a state index, got {after!r}") from None
            with live._lock:
                if url.path == "/reset":
                    live.reset()
                try:
                    live.update(query)
                except (ConvergenceError, ValueError) as error:
                    if isinstance(error, BadRequest):
                        raise
                    body = None
                    failure = _one_line(f"cannot continue with these inputs: {error}")
                else:
                    body, failure = live.states_after(after), None
            if failure is not None:
                self._json(422, {"error": failure})
            else:
                self._json(200, body)
        elif url.path == "/history":
            with live._lock:
                self._json(200, {"history": live.history, "replayable": live.replayable,
                                 "index": live.index, "dt": live.dynamics.dt})
        elif url.path == "/plotly.min.js":
            self._send(200, self.plotly_js, "text/javascript; charset=utf-8")
        else:
            self._json(404, {"error": f"no such page: {url.path}"})

    def do_POST(self):
        self._json(HTTPStatus.METHOD_NOT_ALLOWED, {"error": "use GET"})


def _query(text: str) -> dict[str, str]:
    try:
        pairs = parse_qsl(text, keep_blank_values=True, strict_parsing=bool(text))
    except ValueError:
        raise BadRequest(f"malformed query {text!r}") from None
    names = [name for name, _ in pairs]
    if len(set(names)) != len(names):
        raise BadRequest("an input is given twice")
    return dict(pairs)


def _one_line(text: str, limit: int = 400) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


class _Server(ThreadingHTTPServer):
    """The app's server: a thread per connection (a solve waits for the app's lock, see
    _Handler; the page's script, plotly.js and /inputs do not), a listen queue long enough
    for a burst of connections, and a client that goes away (a reset or closed connection,
    at any point of its request) is no error of the app's.

    The standard library's listen backlog is 5: a burst of 200 requests overflowed it, and
    the kernel dropped the connections beyond it, which the clients saw as waits of seconds
    (their connection attempts repeated after 1, 3, 7, ... s), resets or no answer at all."""

    request_queue_size = 1024  # the kernel caps it at net.core.somaxconn
    daemon_threads = True

    def handle_error(self, request, client_address):
        if isinstance(sys.exc_info()[1], ConnectionError):  # reset, broken pipe, aborted
            return
        super().handle_error(request, client_address)  # pragma: no cover - a bug of ours


def make_server(live: LiveCase, port: int = 8050) -> ThreadingHTTPServer:
    """An HTTP server on 127.0.0.1:``port`` (0: any free port) serving ``live``; CaseError if
    the port is taken or not allowed."""
    handler = type("Handler", (_Handler,), {"live": live, "lock": threading.Lock(),
                                            "plotly_js": plotly_js_path().read_bytes()})
    try:
        server = _Server(("127.0.0.1", port), handler)
    except OSError as error:
        if error.errno == errno.EADDRINUSE:
            raise CaseError(f"port {port} on 127.0.0.1 is already in use (another softarm app "
                            f"or server?); choose another with --port, e.g. --port "
                            f"{port + 1 if port < 65535 else 8050}, or --port 0 for any free "
                            "port") from None
        if error.errno == errno.EACCES:
            raise CaseError(f"port {port}: not allowed ({error.strerror}); use a port above "
                            "1023, e.g. --port 8050") from None
        raise
    return server


def serve(case: Case, *, port: int = 8050, browser: bool = True, stream=None,
          dynamics: Dynamics | None = None) -> int:
    """Run the app for ``case`` until Ctrl-C (KeyboardInterrupt propagates after the server
    is closed, for the command's exit status 130); ``dynamics``: the dynamic mode with
    these settings (:class:`LiveMotion`), else the static one (:class:`LiveCase`)."""
    stream = sys.stdout if stream is None else stream
    live = LiveCase(case) if dynamics is None else LiveMotion(case, dynamics)
    server = make_server(live, port)
    try:
        # (a kernel compiled here for the first time says so itself, with this machine's
        # time: softarm._jit; a cached one loads in a fraction of a second)
        if dynamics is None:
            live.solve()
        else:
            live.start()
        host, port = server.server_address[:2]
        address = f"http://{host}:{port}/"
        print(f"softarm app for {case.name} at {address}  (Ctrl-C stops it)", file=stream,
              flush=True)
        if browser:
            threading.Thread(target=webbrowser.open, args=(address,), daemon=True).start()
        server.serve_forever(poll_interval=0.2)
    finally:
        server.server_close()
        if dynamics is not None:
            live.stop()
    return 0


# --------------------------------------------------------------------------- dynamic mode
#
# ``softarm app CASE --dynamic``: the arm in motion. A Simulator steps in a thread of the
# server (LiveMotion._run), keeping its time on the wall clock's (real time: as many steps of
# Δt as the time elapsed; slower when a step costs more than Δt, which the page shows); the
# sliders set the actuators' inputs (tensions, pressures, fields: Simulator inputs, from the
# next step on) and the other loads' values (a new Simulator continuing from the current
# state, since a Simulator's loads are fixed). The page asks for the newest state as soon as it
# has drawn the last one (GET /state?after=INDEX waits for a newer one), and draws it on a 2D
# canvas of its own (a shaded tube in orthographic projection, dragged to turn): plotly.js's
# 3D scene redraws in about 90 ms in software WebGL (about 10 frames a second), the canvas in
# about a millisecond, so the frame rate is that of the states' round trip.


@dataclass(frozen=True)
class Dynamics:
    """The settings of the dynamic mode (``softarm app --dynamic``, or a case's
    ``[simulate]`` table: :meth:`of`): the time step ``dt`` (s), the ``stations``, ``tol``
    and ``alpha`` of :class:`softarm.Simulator`, its Kelvin–Voigt ``damping`` (a
    :class:`softarm.Damping`, a retardation time τ in s, or None: undamped), where it starts
    (``initial``: "equilibrium", the case's loads balanced at rest, or "rest", the unloaded
    arm at rest) and the playback ``rate`` (1: real time)."""

    dt: float = 2e-3
    stations: int = 41
    damping: object = None
    initial: str = "equilibrium"
    rate: float = 1.0
    tol: float = 1e-6
    alpha: float = -0.5

    def __post_init__(self):
        for name in ("dt", "rate"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"Dynamics.{name} must be a positive number, got {value!r}")
        if isinstance(self.damping, (int, float)) and not isinstance(self.damping, bool):
            if not (math.isfinite(self.damping) and self.damping >= 0):
                raise ValueError(f"Dynamics.damping must be a retardation time >= 0 s, a "
                                 f"softarm.Damping or None, got {self.damping!r}")
        if self.initial not in ("equilibrium", "rest"):
            raise ValueError(f"Dynamics.initial must be 'equilibrium' or 'rest', got "
                             f"{self.initial!r}")

    @classmethod
    def of(cls, case: Case, **overrides) -> Dynamics:
        """The settings of ``case``'s ``[simulate]`` table (its dt, stations, tol, alpha,
        damping and initial state; its input schedules and base motion are not used: the
        sliders drive the arm), with ``overrides``; the defaults without a table."""
        table = case.simulation
        settings = {} if table is None else {
            "dt": table.dt, "stations": table.stations, "tol": table.tol,
            "alpha": table.alpha, "damping": table.damping, "initial": table.initial}
        settings.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**settings)

    def damping_law(self):
        """The :class:`softarm.Damping` (or None)."""
        from .dynamics import Damping

        if self.damping is None or isinstance(self.damping, Damping):
            return self.damping
        return Damping(retardation=float(self.damping))


#: The longest a request for a newer state waits, s.
_WAIT = 1.0
#: A chunk of steps covers at most this much time, s (wall clock times the rate).
_CHUNK = 0.05
#: The compute time of a chunk of steps at most (when there is that much to do), s: a new
#: state at least this often (a chunk's cost is mostly per call for a few steps: about 5 ms
#: with three tendons, 0.6 ms per step at 41 stations on a 2-core machine).
_FRAME = 0.02
#: How far the simulation runs ahead of the wall clock, s (the states of a chunk are shown as
#: their time comes; an input takes effect about this much later).
_AHEAD = 0.06
#: With no request for this long (no page open), the simulation pauses, s.
_IDLE = 5.0


class LiveMotion:
    """A case in motion: its controls (:func:`inputs`), a :class:`softarm.Simulator` stepped
    in a thread on the wall clock, and the newest state for the page.

    ``start()`` runs the thread, ``stop()`` ends it; :meth:`states_after` waits for states
    newer than an index. ``history`` lists (step index, inputs) of each change of the
    actuators' inputs: the steps after the index use them (the simulation reproduces with
    :meth:`softarm.Simulator.step`)."""

    def __init__(self, case: Case, dynamics: Dynamics = Dynamics()):
        from .dispatch import solve
        from .dynamics import Simulator

        self.case, self.dynamics = case, dynamics
        self.inputs = inputs(case)
        self.by_name = {item.name: item for item in self.inputs}
        self.values = {item.name: item.value for item in self.inputs}
        self._actuated = [i for i, load in enumerate(case.loads) if load.inputs]
        self._damping = dynamics.damping_law()
        self._Simulator = Simulator
        # at rest in the equilibrium of the case's loads (the arm moves when a slider does),
        # or the unloaded arm at rest (the loads act from t = 0)
        self._initial = solve(case.arm, case.loads) if dynamics.initial == "equilibrium" \
            else None
        self._lock = threading.Condition()
        self._thread = None
        self._running = False
        self.step_ms = None  # the compute time of a step in the thread, ms
        self.published = 0  # states published by the thread
        self.failure = None  # why the simulation stopped (a step that cannot be solved)
        self.index = 0  # the steps taken, never going back (the page asks for newer ones)
        with self._lock:
            self._build(initial=self._initial)
        self.radii = station_radii(case.arm, self.simulator.s)

    # -- the simulation (callers hold self._lock) -------------------------------------------

    def _passive(self) -> list:
        values = self.values
        return [_current_load(self.case.loads[i], i, values) for i in range(len(self.case.loads))
                if i not in self._actuated and values[f"l{i + 1}.on"]]

    def _inputs_now(self) -> np.ndarray:
        """The actuators' inputs for the current slider values (a switched-off one: 0)."""
        values = self.values
        return np.array([v for i in self._actuated
                         for load in [_current_load(self.case.loads[i], i, values,
                                                    values[f"l{i + 1}.on"])]
                         for name in load.inputs
                         for v in np.ravel(np.asarray(getattr(load, name), dtype=float))])

    def _build(self, initial) -> None:
        """A Simulator for the current values of the passive loads, from ``initial``."""
        if hasattr(self, "simulator"):  # a new start, after the states already served
            self.index += 1
        d = self.dynamics
        actuators = [self.case.loads[i] for i in self._actuated]
        self.simulator = self._Simulator(self.case.arm, actuators, self._passive(), dt=d.dt,
                                         damping=self._damping, initial=initial,
                                         stations=d.stations, tol=d.tol, alpha=d.alpha)
        self._q = self._inputs_now() if actuators else None
        if initial is self._initial:  # from the start: the steps from here on
            self.history = [(self.index, None if self._q is None else self._q.tolist())]
            self.replayable = True
        self._publish(self.simulator.state)

    def _publish(self, state) -> None:
        """A new start (the first state, a reset, a load change): the buffer holds ``state``
        alone, shown at once."""
        self._state = state
        self._buffer = collections.deque([self._entry(self.index, state.time,
                                                      state.positions, state.rotations[-1])])
        self._anchor()
        self._lock.notify_all()

    @staticmethod
    def _entry(index, t, positions, tip_rotation) -> dict:
        return {"index": int(index), "time": float(t),
                "positions": np.asarray(positions).tolist(),
                "rotations": np.asarray(tip_rotation).tolist()}

    def _extend(self, trajectory, steps: int) -> None:
        """The states of a chunk of ``steps`` steps, into the buffer (shown as their time
        comes, :meth:`_shown`)."""
        first = self.index
        self.index += steps
        self._state = trajectory.final
        for k in range(1, steps + 1):
            self._buffer.append(self._entry(first + k, trajectory.times[k],
                                            trajectory.positions[k],
                                            trajectory.rotations[k, -1]))
        self._lock.notify_all()

    def _clock(self) -> float:
        """The simulation time the wall clock says now (s)."""
        return self._time0 + (time.perf_counter() - self._wall0) * self.dynamics.rate

    def _shown(self) -> dict:
        """The state to show now: the last buffered one whose time has come (the older ones
        leave the buffer), else the first."""
        now = self._clock()
        while len(self._buffer) > 1 and self._buffer[1]["time"] <= now:
            self._buffer.popleft()
        return self._buffer[0]

    @property
    def newest(self) -> dict:
        """The state shown now (callers hold the lock)."""
        return self._shown()

    def update(self, query: dict[str, str]) -> None:
        """Set inputs from a request's query (BadRequest naming a bad one): the actuators'
        from the thread's next chunk of steps on; a change of another load continues from
        the current state with a new Simulator (:class:`ConvergenceError` or ValueError if
        it cannot)."""
        old = self.values
        self.values = _updated(self.by_name, old, query)
        passive = [name for name in query if self.by_name[name].load not in self._actuated]
        if any(self.values[name] != old[name] for name in passive):
            try:
                self._build(initial=self._state)
            except Exception:
                self.values = old
                raise
            self.replayable = False  # (the history holds the actuators' inputs only)
        if self._q is not None:  # (from the thread's next chunk on, see _run)
            self._q = self._inputs_now()

    def reset(self) -> None:
        """Back to the case's equilibrium at rest, with the case's values."""
        self.values = {item.name: item.value for item in self.inputs}
        self._build(initial=self._initial)
        self._anchor()

    # -- the thread -------------------------------------------------------------------------

    def _anchor(self) -> None:
        self._wall0, self._time0 = time.perf_counter(), self._state.time

    def start(self) -> None:
        with self._lock:
            self._running = True
            self._seen = time.perf_counter()
            self._anchor()
        self._thread = threading.Thread(target=self._run, name="softarm-dynamics",
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        with self._lock:
            self._running = False
            self._lock.notify_all()
        if self._thread is not None:
            self._thread.join()

    def _run(self) -> None:
        """The thread: keeps the buffer of states _AHEAD s ahead of the wall clock, in chunks
        run outside the lock (the compiled steps release the GIL: requests are answered
        meanwhile); a chunk of a Simulator replaced meanwhile (a load changed, a reset) is
        dropped. A simulation slower than real time shows each chunk's last state as soon as
        it is computed (the clock is set back to it)."""
        dt, rate = self.dynamics.dt, self.dynamics.rate
        while True:
            with self._lock:
                if not self._running:
                    return
                now = time.perf_counter()
                if now - self._seen > _IDLE:  # no page: pause (and keep no debt of time)
                    self._lock.wait(0.2)
                    self._anchor()
                    continue
                clock, end = self._clock(), self._state.time
                if clock > end:  # behind: the buffer ran out, the clock waits for the steps
                    self._time0, self._wall0 = end, now
                    clock = end
                if end - clock > 0.5 * _AHEAD * rate:  # ahead enough: wait
                    self._lock.wait((end - clock - 0.5 * _AHEAD * rate) / rate)
                    continue
                due = int((clock + _AHEAD * rate - end) / dt)
                most = max(1, int(_CHUNK * rate / dt))
                if self.step_ms is not None:  # and a chunk computed in about _FRAME
                    most = min(most, max(1, int(1e3 * _FRAME / self.step_ms)))
                steps, simulator, q = max(1, min(due, most)), self.simulator, self._q
                if q is not None and q.tolist() != self.history[-1][1]:
                    self.history.append((self.index, q.tolist()))
            start = time.perf_counter()
            try:
                inputs = None if q is None else np.broadcast_to(q, (steps + 1, q.size))
                trajectory = simulator.run(steps, inputs)
            except Exception as error:  # a step that cannot be solved: stop there
                with self._lock:
                    self.failure = _one_line(f"the simulation stopped: {error}")
                    self._running = False
                    self._lock.notify_all()
                return
            with self._lock:
                if simulator is not self.simulator:
                    continue
                self._extend(trajectory, steps)
                self.step_ms = 1e3 * (time.perf_counter() - start) / steps
                self.published += 1

    def states_after(self, index: int, timeout: float = _WAIT) -> dict:
        """The states computed after step ``index`` (waiting up to ``timeout`` s for one),
        from the one shown now on, including those whose time has not come yet (the page
        shows each at its time, on the clock sent along), at most one per 1/120 s; with
        the page's read-outs (callers hold the lock)."""
        self._seen = time.perf_counter()
        end = self._seen + timeout
        self._shown()
        while self._buffer[-1]["index"] <= index and self._running:
            left = end - time.perf_counter()
            if left <= 0:
                break
            self._lock.wait(left)
            self._shown()
        spacing = self.dynamics.rate / 120.0
        states, last = [], -math.inf
        for k, entry in enumerate(self._buffer):
            final = k == len(self._buffer) - 1
            if entry["index"] > index and (entry["time"] >= last + spacing or final):
                states.append(entry)
                last = entry["time"]
        slow = self.step_ms is not None and self.step_ms > 1e3 * self.dynamics.dt / \
            self.dynamics.rate
        return {"states": states, "clock": self._clock(), "rate": self.dynamics.rate,
                "headings": _headings(self.case, self.values), "step_ms": self.step_ms,
                "stopped": self.failure,
                "behind": (f"a step of {1e3 * self.dynamics.dt:g} ms takes "
                           f"{self.step_ms:.2f} ms") if slow else None}

    def page(self) -> bytes:
        """The dynamic mode's page."""
        items = [{"name": i.name, "label": i.label, "unit": i.unit, "low": i.low,
                  "high": i.high, "value": i.value, "step": i.step, "component": i.component}
                 for i in self.inputs]
        case, d = self.case, self.dynamics
        with self._lock:
            first = self.states_after(-1)
        scene = {"length": float(case.arm.length), "s": self.simulator.s.tolist(),
                 "radii": None if self.radii is None else self.radii.tolist(),
                 "base": first["states"][0]["positions"][0], "dt": d.dt, "rate": d.rate}
        damping = self._damping
        settings = (f"dynamic: Δt = {d.dt:g} s, {d.stations} stations, "
                    + ("undamped" if damping is None else
                       f"damping τ = {damping.retardation:g} s" if damping.matrix is None
                       else "damping B (6 × 6)")
                    + ("" if d.rate == 1 else f", {d.rate:g} × real time"))
        table = case.simulation
        if table is not None and (table.inputs or table.base is not None):
            settings += ("; the [simulate] table's input schedules and base motion are not "
                         "used here (the sliders drive the arm)")
        return _MOTION_PAGE.format(
            style=_STYLE, name=html.escape(case.name),
            description=html.escape(case.description or ""), settings=html.escape(settings),
            controls=_CONTROLS, inputs=json.dumps(items).replace("</", "<\\/"),
            scene=json.dumps(scene), first=json.dumps(first)).encode("utf-8")



# The dynamic mode's page: the controls, and the arm drawn on a canvas (see the note at
# "dynamic mode" above). The states are asked for as soon as the last ones arrived (GET
# /state?after=INDEX, with the inputs if a control changed: the server's states after INDEX,
# some of them ahead of its clock); each animation frame draws the last one whose time has
# come on the server's clock. window.softarmFrames lists [state index, time, round trip,
# drawing] (ms) of each drawn frame (the browser tests count them).
_MOTION_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>softarm app: {name} (dynamic)</title>
<link rel="icon" href="data:,">
<style>{style}
#plot {{ position: relative; }} canvas {{ display: block; cursor: grab; }}
</style></head>
<body><div id="controls"><h3 style="margin:4px 0">softarm: {name}</h3>
<div style="color:#555">{description}</div>
<div style="color:#555; margin-top: 4px">{settings}</div>
<div id="inputs"></div>
<button id="reset" title="back to the case's equilibrium at rest">reset</button>
<div id="status"></div><div id="error"></div></div>
<div id="plot"><canvas id="arm"></canvas></div>
<script>
const INPUTS = {inputs};
const SCENE = {scene};
window.softarmFrames = [];
{controls}
let changed = null;  // the inputs' query when a control changed, sent with the next request
function request() {{ changed = query(); }}
const canvas = document.getElementById("arm"), ctx = canvas.getContext("2d");
const status = document.getElementById("status"), error = document.getElementById("error");
// the camera: orthographic, turned about the vertical by az and tilted by el (drag to turn,
// wheel to zoom), looking at the base from the side plotly's figures start from
let az = Math.atan2(-1.84, 1.27), el = 0.38, zoom = 1, shown = null;
const L = SCENE.length, base = SCENE.base, trail = [];
function size() {{
  const box = canvas.parentElement.getBoundingClientRect(), ratio = window.devicePixelRatio || 1;
  canvas.width = box.width * ratio; canvas.height = box.height * ratio;
  canvas.style.width = box.width + "px"; canvas.style.height = box.height + "px";
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  if (shown) draw(shown);
}}
function project(p) {{
  const w = canvas.clientWidth, h = canvas.clientHeight, k = 0.4 * Math.min(w, h) / L * zoom;
  const d = [p[0] - base[0] - 0.3 * L, p[1] - base[1], p[2] - base[2]];
  const ca = Math.cos(az), sa = Math.sin(az), ce = Math.cos(el), se = Math.sin(el);
  const x = -sa * d[0] + ca * d[1];
  const y = -se * ca * d[0] - se * sa * d[1] + ce * d[2];
  return [w / 2 + k * x, h / 2 - k * y, k];
}}
function line(a, b, color, width) {{
  const p = project(a), q = project(b);
  ctx.strokeStyle = color; ctx.lineWidth = width;
  ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
}}
function draw(body) {{
  shown = body;
  const w = canvas.clientWidth, h = canvas.clientHeight, P = body.positions;
  ctx.clearRect(0, 0, w, h);
  ctx.lineCap = "round"; ctx.lineJoin = "round";
  // a floor grid a length below the base, and the spatial axes at the base
  const z = base[2] - L, n = 8;
  for (let i = 0; i <= n; i++) {{
    const u = -L + 2 * L * i / n + 0.3 * L;
    line([base[0] + u, base[1] - L, z], [base[0] + u, base[1] + L, z], "#e3e3e3", 1);
    line([base[0] - 0.7 * L, base[1] - L + 2 * L * i / n, z],
         [base[0] + 1.3 * L, base[1] - L + 2 * L * i / n, z], "#e3e3e3", 1);
  }}
  ["#dc2828", "#28a028", "#2850dc"].forEach((color, k) => {{
    const end = base.slice(); end[k] += 0.2 * L; line(base, end, color, 1.5); }});
  // the tip's path over the last seconds
  if (trail.length > 1) {{
    ctx.strokeStyle = "#9a9a9a"; ctx.lineWidth = 1.5; ctx.beginPath();
    trail.forEach((p, i) => {{ const q = project(p);
      if (i) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]); }});
    ctx.stroke();
  }}
  // the tube: an outline, the body, a highlight (segment by segment: the radius may change)
  const k = project(P[0])[2];
  const width = i => Math.max(3, 2 * (SCENE.radii ? SCENE.radii[i] : 0) * k);
  [["#8a3c00", 2], ["#ff7f0e", 0], ["#ffc48a", -1]].forEach(([color, extra]) => {{
    for (let i = 0; i + 1 < P.length; i++) {{
      const wide = width(i + 1);
      line(P[i], P[i + 1], color, extra < 0 ? wide / 3 : wide + extra);
    }}
  }});
  // the tip's material frame (e1 e2 e3: red, green, blue)
  const tip = P[P.length - 1], R = body.rotations;
  ["#dc2828", "#28a028", "#2850dc"].forEach((color, k) => {{
    line(tip, [0, 1, 2].map(j => tip[j] + 0.15 * L * R[j][k]), color, 2.5); }});
  const b = project(base);
  ctx.fillStyle = "#505050"; ctx.fillRect(b[0] - 5, b[1] - 5, 10, 10);
  ctx.fillStyle = "#222"; ctx.font = "14px sans-serif";
  ctx.fillText("t = " + body.time.toFixed(3) + " s", 12, 22);
}}
let dragging = null;
canvas.addEventListener("pointerdown", e => {{ dragging = [e.clientX, e.clientY];
  canvas.setPointerCapture(e.pointerId); }});
canvas.addEventListener("pointerup", () => {{ dragging = null; }});
canvas.addEventListener("pointermove", e => {{
  if (!dragging) return;
  az -= 0.01 * (e.clientX - dragging[0]);
  el = Math.max(-1.5, Math.min(1.5, el + 0.01 * (e.clientY - dragging[1])));
  dragging = [e.clientX, e.clientY];
  if (shown) draw(shown);
}});
canvas.addEventListener("wheel", e => {{ e.preventDefault();
  zoom *= Math.exp(-0.001 * e.deltaY); if (shown) draw(shown); }}, {{passive: false}});
window.addEventListener("resize", size);
let index = -1, resetting = false, offset = null, drawn = -1;
const queue = [];  // states received and not drawn yet, in order
async function fetchState(after) {{
  const parts = resetting ? [] : ["after=" + after];
  if (changed) parts.push(changed);
  const path = (resetting ? "/reset?" : "/state?") + parts.join("&");
  if (resetting) {{ queue.length = 0; drawn = -1; }}
  changed = null; resetting = false;
  const sent = performance.now(), reply = await fetch(path), body = await reply.json();
  if (!reply.ok) throw new Error(body.error);
  body.wait = performance.now() - sent;
  return body;
}}
document.getElementById("reset").addEventListener("click", () => {{
  INPUTS.forEach(item => {{ const el = document.getElementById(item.name);
    if (item.component === null) el.checked = item.value === 1; else el.value = item.value;
    const out = document.getElementById(item.name + ".out");
    if (out) out.textContent = Number(item.value).toPrecision(4); }});
  changed = null; resetting = true; trail.length = 0; }});
let info = null;
function receive(body) {{
  for (const state of body.states) {{
    if (state.index > index) {{ queue.push(state); index = state.index; }}
  }}
  // the simulation's clock: its time now is (performance.now() / 1000) * rate + offset
  offset = body.clock - performance.now() / 1000 * body.rate;
  info = body;
}}
async function poll() {{  // the states, as soon as the server has new ones
  for (;;) {{
    try {{ receive(await fetchState(index)); error.textContent = ""; }}
    catch (e) {{
      error.textContent = String(e.message || e);
      await new Promise(done => setTimeout(done, 300));
    }}
  }}
}}
function frame() {{  // each animation frame: the last received state whose time has come
  requestAnimationFrame(frame);
  if (offset === null || !queue.length) return;
  const clock = performance.now() / 1000 * info.rate + offset;
  let state = null;
  while (queue.length && (queue[0].time <= clock || state === null && queue.length > 40))
    state = queue.shift();
  if (state === null || state.index <= drawn) return;
  const start = performance.now(), tip = state.positions[state.positions.length - 1];
  trail.push(tip); if (trail.length > 120) trail.shift();
  draw(state);
  drawn = state.index;
  const now = performance.now();
  // [state index, drawn at, the last request's round trip, drawing] ms
  window.softarmFrames.push([state.index, now, info.wait, now - start]);
  for (const [name, text] of Object.entries(info.headings)) {{
    const check = document.getElementById(name);
    if (check) check.parentElement.lastChild.textContent = " " + text;
  }}
  const frames = window.softarmFrames;
  const back = frames.length > 30 ? frames[frames.length - 31] : null;
  status.textContent = "t  " + state.time.toFixed(3) + " s (step " + state.index +
    ")\\ntip  (" + tip.map(v => v.toPrecision(4)).join(", ") + ") m" +
    (info.step_ms === null ? "" : "\\nstep  " + info.step_ms.toFixed(2) + " ms") +
    (back ? "\\nframes  " + (30000 / (now - back[1])).toFixed(0) + " per second" : "") +
    (info.behind ? "\\nslower than real time: " + info.behind : "");
  if (info.stopped) error.textContent = info.stopped;
}}
size();
receive({first});
draw(queue[0]);
poll();
requestAnimationFrame(frame);
</script></body></html>
"""
