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
"""

from __future__ import annotations

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
from .geometry import cube_limits
from .statics import Solver
from .view import axis_ticks, figure, plotly_js_path, scene_traces, to_json

__all__ = ["Input", "LiveCase", "inputs", "make_server", "serve"]


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
        new = dict(self.values)
        for name, text in query.items():
            item = self.by_name.get(name)
            if item is None:
                raise BadRequest(f"unknown input {name!r}; known inputs: "
                                 f"{', '.join(self.by_name)}")
            try:
                value = float(text)
            except ValueError:
                raise BadRequest(f"{name} must be a number, got {text!r}") from None
            if not math.isfinite(value):
                raise BadRequest(f"{name} must be a finite number, got {text!r}")
            if not item.low <= value <= item.high:
                raise BadRequest(f"{name} must be in [{format_value(item.low)}, "
                                 f"{format_value(item.high)}] {item.unit}, got "
                                 f"{format_value(value)}".rstrip())
            if item.component is None and value not in (0.0, 1.0):
                raise BadRequest(f"{name} must be 0 (off) or 1 (on), got {text!r}")
            new[name] = value
        self.values = new

    def loads(self) -> tuple:
        """The case's loads with the current input values (switched-off loads left out)."""
        return tuple(self.current(i) for i in range(len(self.case.loads))
                     if self.values[f"l{i + 1}.on"])

    def current(self, i: int):
        """Load i of the case with the current input values (whether on or off)."""
        load = self.case.loads[i]
        fields = _fields(load, i, self.values, 1.0)
        return load.replace(**fields) if fields else load

    def headings(self) -> dict:
        """Each load's heading on the page, with its current values (the switches' labels)."""
        return {f"l{i + 1}.on": f"{i + 1}: {self.current(i).describe()}"
                for i in range(len(self.case.loads))}

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


def _with_all_loads(result, loads, values):
    """``result`` with its loads in the case's order, so that arrow keys (load index, field)
    stay the same whichever loads are switched off (switched-off loads as zero vectors)."""
    import dataclasses

    full = []
    for i, load in enumerate(loads):
        fields = _fields(load, i, values, values[f"l{i + 1}.on"])
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


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>softarm app: {name}</title>
<link rel="icon" href="data:,">
<style>
body {{ font-family: sans-serif; margin: 0; display: flex; overflow: hidden; }}
#controls {{ width: 330px; padding: 10px; font-size: 13px; height: 100vh; overflow-y: auto;
  box-sizing: border-box; background: #f6f6f6; }}
#plot {{ flex: 1; min-width: 0; height: 100vh; }}
fieldset {{ margin: 0 0 8px 0; border: 1px solid #ccc; }}
label {{ display: block; margin-top: 4px; }}
input[type=range] {{ width: 100%; }}
#status {{ font-family: monospace; font-size: 12px; white-space: pre-wrap; margin-top: 8px; }}
#error {{ color: #b00; font-size: 12px; margin-top: 6px; }}
</style></head>
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
const box = document.getElementById("inputs");
let fieldset = null;
for (const item of INPUTS) {{
  if (item.component === null) {{
    fieldset = document.createElement("fieldset");
    const legend = document.createElement("legend");
    const check = document.createElement("input");
    check.type = "checkbox"; check.id = item.name; check.checked = item.value === 1;
    check.addEventListener("change", request);
    legend.append(check, " " + item.label);
    fieldset.append(legend);
    box.append(fieldset);
    continue;
  }}
  const label = document.createElement("label");
  const out = document.createElement("span");
  out.id = item.name + ".out";
  label.append(item.label + " = ", out, " " + item.unit);
  const slider = document.createElement("input");
  slider.type = "range"; slider.id = item.name;
  slider.min = item.low; slider.max = item.high; slider.step = "any";
  slider.value = item.value;
  out.textContent = Number(item.value).toPrecision(4);
  slider.addEventListener("input", () => {{
    out.textContent = Number(slider.value).toPrecision(4); request(); }});
  fieldset.append(label, slider);
}}
function query() {{
  return INPUTS.map(item => {{
    const el = document.getElementById(item.name);
    const value = item.component === null ? (el.checked ? 1 : 0) : el.value;
    return encodeURIComponent(item.name) + "=" + encodeURIComponent(value);
  }}).join("&");
}}
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
        name=html.escape(case.name), description=html.escape(case.description or ""),
        inputs=json.dumps(items).replace("</", "<\\/"),
        figure=to_json(fig).replace("</", "<\\/")).encode("utf-8")


class _Handler(BaseHTTPRequestHandler):
    server_version = "softarm-app"
    protocol_version = "HTTP/1.1"  # keep-alive: a slider's requests reuse one connection
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
        except BadRequest as error:
            self._json(400, {"error": str(error)})
        except Exception as error:  # never let one request stop the app
            self._json(500, {"error": _one_line(f"{type(error).__name__}: {error}")})

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


def serve(case: Case, *, port: int = 8050, browser: bool = True, stream=None) -> int:
    """Run the app for ``case`` until Ctrl-C (KeyboardInterrupt propagates after the server
    is closed, for the command's exit status 130)."""
    stream = sys.stdout if stream is None else stream
    live = LiveCase(case)
    server = make_server(live, port)
    try:
        # (a kernel compiled here for the first time says so itself, with this machine's
        # time: softarm._jit; a cached one loads in a fraction of a second)
        live.solve()
        host, port = server.server_address[:2]
        address = f"http://{host}:{port}/"
        print(f"softarm app for {case.name} at {address}  (Ctrl-C stops it)", file=stream,
              flush=True)
        if browser:
            threading.Thread(target=webbrowser.open, args=(address,), daemon=True).start()
        server.serve_forever(poll_interval=0.2)
    finally:
        server.server_close()
    return 0
