"""report.html: numbers equal map.json, nothing remote, untrusted IDs inert, and it
really renders in headless Chromium (software WebGL)."""

from __future__ import annotations

import fcntl
import html
import json
import os
import queue
import re
import shutil
import subprocess
import threading
import time
from decimal import Decimal

import numpy as np
import pytest
from hypothesis import given, strategies as st

from swarmtopo.log import EncounterLog, state_labels
from swarmtopo.pipeline import MapConfig, map_encounters
from swarmtopo.viz.report import write_map
from swarmtopo.viz.report_html import MAX_ANIMATION_AGENTS, script_json
from swarmtopo.viz.text import format_confidence

EVIL = "<script>alert(1)</script>"
EVIL_IMG = "<img src=x onerror=alert(2)>"


@pytest.fixture(scope="module")
def demo(demo_run, demo_map, tmp_path_factory):
    """The demo scenario (one hole, 200 agents, 30 s) mapped, with truth and trajectories."""
    sim, tmap, arena = demo_run, demo_map, demo_run.arena
    out = tmp_path_factory.mktemp("report")
    write_map(tmap, out, log=sim.log, truth=sim.truth, arena=arena, trajectories=sim.trajectories)
    return {"sim": sim, "arena": arena, "out": out, "html": (out / "report.html").read_text(encoding="utf-8"),
            "map": json.loads((out / "map.json").read_text(encoding="utf-8"))}


@pytest.fixture(scope="module")
def evil(demo, tmp_path_factory):
    """The demo's log with every agent ID and the metadata carrying HTML and script text."""
    sim = demo["sim"]
    log = sim.log
    # One common prefix, zero-padded numbers: the text IDs sort like the integer codes,
    # so the events keep their order and the ground truth stays aligned with them.
    ids = np.array([EVIL] + [f"{EVIL}{i:03d}" for i in range(1, log.n_agents)], dtype=object)
    evil_log = EncounterLog.from_records(
        log.t, ids[log.a], ids[log.b],
        status=(log.status_t, ids[log.status_agent], state_labels(log.status_state)),
        meta={"name": EVIL_IMG, "note": "</script><script>alert(3)</script>", EVIL: "key"})
    assert np.array_equal(evil_log.a, log.a) and np.array_equal(evil_log.b, log.b)
    trajectories = dict(sim.trajectories, agent=ids[sim.trajectories["agent"]])
    tmap = map_encounters(evil_log, MapConfig(seed=0))
    out = tmp_path_factory.mktemp("evil")
    write_map(tmap, out, log=evil_log, truth=sim.truth, arena=demo["arena"], trajectories=trajectories)
    return {"out": out, "html": (out / "report.html").read_text(encoding="utf-8")}


def _attr_values(page: str, cls: str) -> list[dict]:
    """Elements of class ``cls``: their data-* attributes and their text."""
    found = []
    # a class is a whole space-separated word: "betti" must not match "true-betti"
    for m in re.finditer(rf'<(?:span|td) class="(?:[^"]* )?{cls}(?: [^"]*)?"([^>]*)>(.*?)</(?:span|td)>', page):
        attrs = dict(re.findall(r'data-([a-z]+)="([^"]*)"', m.group(1)))
        found.append({**attrs, "text": m.group(2)})
    return found


def _figure(page: str, target: str) -> dict:
    m = re.search(rf'<script type="application/json" class="figure" data-target="{target}">(.*?)</script>', page,
                  re.S)
    assert m, f"no figure {target}"
    return json.loads(m.group(1))


def _without_plotly(page: str) -> str:
    """The page without the inline plotly.js bundle (checked to be exactly plotly's own)."""
    from plotly.offline import get_plotlyjs

    start = page.index('<script id="plotly-js">') + len('<script id="plotly-js">')
    end = page.index("</script>", start)
    assert page[start:end] == get_plotlyjs()
    return page[:start] + page[end:]


# -- content -------------------------------------------------------------------------------
def test_verdict_numbers_equal_map_json(demo):
    page, doc = demo["html"], demo["map"]
    assert page.index('id="verdict"') < page.index('id="persistence"') < page.index('id="cloud"') \
        < page.index('id="arena"') < page.index('id="animation"') < page.index('id="parameters"')
    betti = {int(e["dim"]): int(e["value"]) for e in _attr_values(page, "betti")}
    assert betti == {int(k): v for k, v in doc["betti"].items()}
    confidence = _attr_values(page, "confidence")
    assert len(confidence) == len(doc["confidence"])
    for e in confidence:
        expected = doc["confidence"][e["dim"]]
        assert float(e["value"]) == expected and e["text"] == format_confidence(expected)
    true_betti = {int(e["dim"]): int(e["value"]) for e in _attr_values(page, "true-betti")}
    assert true_betti == dict(enumerate(demo["arena"].betti)) == {0: 1, 1: 1}


def test_confidence_format_never_rounds_to_certainty_or_to_zero():
    cases = {0.3618177769791703: "36.2%", 1.0: "100.0%", 0.0: "0.0%", 0.99949: "99.9%", 0.99996: "99.996%",
             0.9995: "99.95%",  # the float 0.9995 is 0.99950000000000005...: 100.0% at one decimal
             1e-5: "0.001%", 0.0004: "0.04%", 1 - 2 ** -53: "99.99999999999999%"}
    assert {p: format_confidence(p) for p in cases} == cases


@given(st.floats(0, 1, exclude_min=True, exclude_max=True))
def test_confidence_format_is_the_nearest_strictly_inside_0_and_100(p):
    text = format_confidence(p)
    assert text.endswith("%")
    shown = Decimal(text[:-1])
    places = -shown.as_tuple().exponent
    assert 0 < shown < 100 and places >= 1
    assert abs(shown - Decimal(p) * 100) <= Decimal(5) / 10 ** (places + 1)


def test_thresholds_and_timings_equal_map_json(demo):
    page, doc = demo["html"], demo["map"]
    thresholds = _attr_values(page, "threshold")
    expected = {(str(k), n): v for k, r in enumerate(doc["regions"]) for n, v in r["thresholds"].items()}
    assert {(e["region"], e["dim"]): float(e["value"]) for e in thresholds} == expected
    timings = _attr_values(page, "timing")
    assert {e["stage"]: float(e["value"]) for e in timings} == doc["timings"]
    assert all(e["text"] == f"{doc['timings'][e['stage']]:.3f} s" for e in timings)


def test_threshold_is_drawn_in_the_diagram(demo):
    doc = demo["map"]
    fig = _figure(demo["html"], "plot-persistence-0")
    tau = doc["regions"][0]["thresholds"]["1"]
    line = next(t for t in fig["data"] if t.get("name", "").startswith("H1 threshold"))
    # death = birth + tau: the line starts at (0, tau) and keeps that offset.
    assert line["x"][0] == 0 and line["y"][0] == tau and line["y"][1] - line["x"][1] == pytest.approx(tau)
    segment = next(t for t in fig["data"] if t.get("xaxis") == "x2" and t.get("x") == [0, tau])
    assert segment["line"]["dash"] == "dash"
    # the note names the formula the value comes from: tau_n l_q (the shipped classifier's), by hand
    theta = doc["classifier"]["theta"]["1"]
    finite = [b[1] - b[0] for b in doc["regions"][0]["diagrams"]["1"] if b[1] is not None]
    assert tau == pytest.approx(theta["tau"] * np.quantile(finite, theta["q"]))
    assert doc["classifier"]["threshold"] == "tau_n l_q"
    assert "threshold &tau;<sub>n</sub> l<sub>q</sub> (" in demo["html"] and "&Delta;" not in demo["html"]
    # The diagram's H1 points are map.json's finite H1 bars.
    h1 = [b for b in doc["regions"][0]["diagrams"]["1"] if b[1] is not None]
    points = next(t for t in fig["data"] if t.get("name", "").startswith("H1 ("))
    assert points["x"] == pytest.approx([b[0] for b in h1], abs=1e-6)


def test_cloud_and_arena_figures(demo):
    doc, sim = demo["map"], demo["sim"]
    cloud = _figure(demo["html"], "plot-cloud-0")
    scatter = [t for t in cloud["data"] if t["type"] == "scatter3d"]
    assert len(scatter) == 2  # by time and by true position
    assert all(len(t["x"]) == doc["regions"][0]["landmarks"] for t in scatter)
    arena_fig = _figure(demo["html"], "plot-arena-0")
    loops = [t for t in arena_fig["data"] if t.get("name", "").startswith("loop")]
    cycles = doc["regions"][0]["cycles"]
    assert len(loops) == len(cycles) >= 1
    first = cycles[0]["events"][0]
    x = (sim.truth["xa"][first] + sim.truth["xb"][first]) / 2
    assert loops[0]["x"][0] == pytest.approx(x, abs=0.01) and loops[0]["x"][-1] == loops[0]["x"][0]


@pytest.mark.parametrize("embed_dim", [2, 0])
def test_real_data_report_has_no_ground_truth_sections(demo, embed_dim):
    """A deployment's log: no arena, truth or trajectories -> no true Betti numbers,
    no arena or animation; a 2-D MDS picture is a plain scatter, embed_dim 0 none."""
    from swarmtopo.viz.report_html import report_html

    tmap = map_encounters(demo["sim"].log, MapConfig(seed=0, embed_dim=embed_dim, cycles=False))
    page = report_html(tmap, log=demo["sim"].log)
    assert "true-betti" not in page and 'id="arena"' not in page and 'id="animation"' not in page
    assert ('id="cloud"' in page) == (embed_dim > 0)
    if embed_dim:
        assert [t["type"] for t in _figure(page, "plot-cloud-0")["data"]] == ["scatter"]
    betti = {int(e["dim"]): int(e["value"]) for e in _attr_values(page, "betti")}
    assert betti == tmap.betti


def test_every_figure_has_its_own_div(demo):
    page = demo["html"]
    targets = re.findall(r'class="figure" data-target="([^"]+)"', page)
    assert len(targets) == 5  # timeline, persistence, cloud, arena, animation of the one region
    for target in targets:
        assert len(re.findall(rf'\bid="{target}"', page)) == 1
        assert re.search(rf'<div id="{target}" class="plot', page)


def test_animation_is_subsampled_true_positions(demo):
    traj = demo["sim"].trajectories
    fig = _figure(demo["html"], "plot-animation")
    times = np.unique(traj["t"])
    assert len(fig["frames"]) == len(times)  # 31 samples: under the frame cap, all kept
    swarm = fig["frames"][0]["traces"][0]
    agents = fig["data"][swarm]["text"]
    assert len(agents) == MAX_ANIMATION_AGENTS < 200
    # the note says the swarm's size and that the picture shows a share of it
    assert f"{MAX_ANIMATION_AGENTS} of the 200 agents at 31 sampled times (evenly spaced)" in demo["html"]
    # Frame k, point j is agent agents[j] at times[k].
    k, j = 7, 5
    agent = int(agents[j].split()[-1])
    row = np.flatnonzero((traj["t"] == times[k]) & (traj["agent"] == agent))[0]
    assert fig["frames"][k]["data"][0]["x"][j] == pytest.approx(traj["x"][row], abs=0.05)
    assert fig["frames"][k]["data"][0]["y"][j] == pytest.approx(traj["y"][row], abs=0.05)


def test_no_remote_resources(demo):
    rest = _without_plotly(demo["html"])
    assert "http://" not in rest and "https://" not in rest
    assert not re.search(r"""(?:src|href|action|poster)\s*=\s*["']?\s*//""", rest)
    assert "@import" not in rest and "url(" not in rest


def test_script_json_cannot_close_the_script_element():
    obj = {"id": "</script><script>alert(1)</script><!--", "x": ["\u2028", "a/b & c"]}
    text = script_json(obj)
    assert "<" not in text and ">" not in text and "/" not in text.replace("\\/", "") and "\u2028" not in text
    assert json.loads(text) == obj


def test_hostile_ids_and_metadata_render_as_text(evil):
    page = evil["html"]
    rest = _without_plotly(page)
    for raw in (EVIL, EVIL_IMG, "<script>alert(3)", "<img"):
        assert raw not in rest
    assert html.escape(EVIL) in rest and html.escape(EVIL_IMG) in rest  # shown, as text
    # Hover text reaches plotly HTML-escaped (plotly shows entities as characters).
    hover = _figure(page, "plot-cloud-0")["data"][0]["text"]
    assert any(html.escape(EVIL) in h for h in hover)
    assert not any(EVIL in h for h in hover)
    assert _figure(page, "plot-animation")["data"][-4]["text"][0] == f"agent {html.escape(EVIL)}"
    # Only the report's own three kinds of script elements exist.
    scripts = re.findall(r"<script\b([^>]*)>", page)
    assert all(s in ('', ' id="plotly-js"') or s.startswith(' type="application/json" class="figure"')
               for s in scripts)


# -- headless Chromium ---------------------------------------------------------------------
BROWSER_FLAGS = ("--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--enable-webgl",
                 "--ignore-gpu-blocklist", "--no-first-run", "--no-default-browser-check", "--disable-extensions",
                 "--disable-dev-shm-usage", "--window-size=1280,1600", "--remote-debugging-pipe")

# Run before the page's scripts: WebGL contexts keep their drawing buffer, so the
# probe can read the 3-D plot's pixels after they were composited.
KEEP_WEBGL_BUFFER = r"""
(() => {
  const getContext = HTMLCanvasElement.prototype.getContext;
  HTMLCanvasElement.prototype.getContext = function (kind, options) {
    if (/webgl/.test(kind)) options = Object.assign({}, options, {preserveDrawingBuffer: true});
    return getContext.call(this, kind, options);
  };
})();
"""

# Waits for the report's plots, then counts saturated pixels (markers: grid lines
# and background are grey or white) and distinct colours on the 3-D plot's canvases.
CANVAS_PROBE = r"""
new Promise((resolve) => {
  const start = performance.now();
  (function poll() {
    if (document.body.dataset.plotsReady !== 'true' && performance.now() - start < 30000) {
      setTimeout(poll, 100);
      return;
    }
    requestAnimationFrame(() => requestAnimationFrame(() => {
      let coloured = 0;
      const colours = new Set();
      document.querySelectorAll('#cloud canvas').forEach((canvas) => {
        if (!canvas.width || !canvas.height) return;
        const copy = document.createElement('canvas');
        copy.width = canvas.width;
        copy.height = canvas.height;
        const ctx = copy.getContext('2d', {willReadFrequently: true});
        ctx.drawImage(canvas, 0, 0);
        const px = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
        for (let i = 0; i < px.length; i += 4) {
          const r = px[i], g = px[i + 1], b = px[i + 2];
          if (px[i + 3] > 0 && Math.max(r, g, b) - Math.min(r, g, b) > 60) {
            coloured++;
            colours.add((r >> 4) + ',' + (g >> 4) + ',' + (b >> 4));
          }
        }
      });
      const placed = [...document.querySelectorAll('script.figure')].every((block) => {
        const div = document.getElementById(block.dataset.target);
        return div.tagName === 'DIV' && div.classList.contains('js-plotly-plot');
      });
      resolve({ready: document.body.dataset.plotsReady === 'true', placed: placed,
               coloured: coloured, colours: colours.size,
               verdict: (document.getElementById('verdict') || {}).innerText || '',
               text: document.body.innerText});
    }));
  })();
})
"""


def _chromium() -> str:
    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    if binary is None:
        reason = "headless browser test not run: Debian's chromium is not installed (apt-get install chromium)"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(reason + "; under CI=true this test must run")
        pytest.skip(reason)
    return binary


class DevTools:
    """Chromium driven over the DevTools protocol on a pipe (fds 3 and 4 of the
    browser, NUL-terminated JSON messages): no WebSocket library needed."""

    def __init__(self, binary: str, profile) -> None:
        command_read, command_write = os.pipe()
        reply_read, reply_write = os.pipe()
        # Copies at fd >= 10, so moving them to 3 and 4 in the child cannot clobber each other.
        child_in = fcntl.fcntl(command_read, fcntl.F_DUPFD, 10)
        child_out = fcntl.fcntl(reply_write, fcntl.F_DUPFD, 10)

        def place_fds():
            os.dup2(child_in, 3)
            os.dup2(child_out, 4)

        flags = [*BROWSER_FLAGS, f"--user-data-dir={profile}"] + (["--no-sandbox"] if os.geteuid() == 0 else [])
        self.process = subprocess.Popen([binary, *flags, "about:blank"], preexec_fn=place_fds, pass_fds=(3, 4),
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for fd in (command_read, reply_write, child_in, child_out):
            os.close(fd)
        self.commands = os.fdopen(command_write, "wb", buffering=0)
        self.inbox: queue.Queue = queue.Queue()
        self.events: list[dict] = []
        self.last_id = 0
        threading.Thread(target=self._read, args=(reply_read,), daemon=True).start()

    def _read(self, fd: int) -> None:
        buffer = b""
        with os.fdopen(fd, "rb", buffering=0) as replies:
            while chunk := replies.read(1 << 16):
                buffer += chunk
                *messages, buffer = buffer.split(b"\0")
                for message in messages:
                    self.inbox.put(json.loads(message))
        self.inbox.put(None)

    def _next(self, deadline: float) -> dict:
        try:
            message = self.inbox.get(timeout=max(0.01, deadline - time.monotonic()))
        except queue.Empty:
            raise TimeoutError("Chromium did not answer in time") from None
        if message is None:
            raise RuntimeError("Chromium closed the DevTools pipe")
        return message

    def send(self, method: str, params: dict | None = None, session: str | None = None, timeout: float = 40):
        self.last_id += 1
        message = {"id": self.last_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        self.commands.write(json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._next(deadline)
            if reply.get("id") == self.last_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 40) -> dict:
        deadline = time.monotonic() + timeout
        seen = [e for e in self.events if e.get("method") == method]
        while not seen:
            event = self._next(deadline)
            self.events.append(event)
            seen = [event] if event.get("method") == method else []
        return seen[0]

    def open(self, path) -> dict:
        """Load a file in a fresh tab; run the canvas probe; return its result and the
        tab's console errors, exceptions, dialogs and requested URLs."""
        self.events.clear()
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Runtime", "Log", "Network", "Page"):
            self.send(f"{domain}.enable", session=session)
        self.send("Page.addScriptToEvaluateOnNewDocument", {"source": KEEP_WEBGL_BUFFER}, session=session)
        self.send("Page.navigate", {"url": path.as_uri()}, session=session)
        self.wait_for("Page.loadEventFired")
        probe = self.send("Runtime.evaluate", {"expression": CANVAS_PROBE, "awaitPromise": True,
                                               "returnByValue": True}, session=session)
        errors = []
        for event in self.events:
            method, params = event.get("method"), event.get("params", {})
            if method == "Runtime.consoleAPICalled" and params["type"] in ("error", "assert"):
                errors.append(" ".join(str(a.get("value", a.get("description"))) for a in params["args"]))
            elif method == "Runtime.exceptionThrown":
                errors.append(params["exceptionDetails"].get("text", "exception"))
            elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
                errors.append(params["entry"]["text"])
        return {"probe": probe["result"].get("value"), "errors": errors,
                "dialogs": [e for e in self.events if e.get("method") == "Page.javascriptDialogOpening"],
                "urls": [e["params"]["request"]["url"] for e in self.events
                         if e.get("method") == "Network.requestWillBeSent"]}

    def close(self) -> None:
        self.process.kill()
        self.process.wait()


@pytest.mark.slow
def test_report_renders_in_headless_chromium(demo, evil, tmp_path):
    """Both reports load without console errors or network requests; the verdict is
    there; the 3-D cloud's WebGL canvas has coloured points; hostile IDs run nothing."""
    browser = DevTools(_chromium(), tmp_path / "profile")
    try:
        page = browser.open(demo["out"] / "report.html")
        hostile = browser.open(evil["out"] / "report.html")
    finally:
        browser.close()
    for result, path in ((page, demo["out"]), (hostile, evil["out"])):
        probe = result["probe"]
        assert result["errors"] == []
        assert result["urls"] == [(path / "report.html").as_uri()]  # the page itself, nothing else
        assert probe["ready"] and probe["placed"]
        # Rendered markers: about 3e4 coloured pixels in over 100 colours measured; a
        # blank or failed WebGL canvas has none (SwiftShader draws the same as a GPU).
        assert probe["coloured"] > 2000 and probe["colours"] > 30, probe
    doc = demo["map"]
    verdict = page["probe"]["verdict"]
    for n, b in doc["betti"].items():
        assert f"β{n} = {b} ({format_confidence(doc['confidence'][n])} confidence)" in verdict
    assert "true (from the arena): β0 = 1, β1 = 1" in verdict
    assert hostile["dialogs"] == []
    assert EVIL in hostile["probe"]["text"] and EVIL_IMG in hostile["probe"]["text"]  # shown as text


def test_a_contact_trace_report_speaks_of_contact_loops_not_obstacles(demo):
    from swarmtopo.experiments.sweep import contact_trace
    from swarmtopo.viz.report_html import report_html
    from swarmtopo.viz.summary import map_json

    log = contact_trace(demo["sim"].log)
    tmap = map_encounters(log, MapConfig(seed=0, embed_dim=2, cycles=False))
    assert map_json(tmap)["log"]["contact_trace"] is True
    page = report_html(tmap, log=log)
    assert "loops of the contact graph" in page and "(obstacles)" not in page
    assert "A loop of the contact graph shows as a loop" in page and "A hole in the arena" not in page
    # a log with status changes keeps the arena's words
    assert "(obstacles)" in demo["html"] and "A hole in the arena shows as a loop" in demo["html"]
