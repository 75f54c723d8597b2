"""Real-browser test: JupyterLab + headless Chromium draw the pythreejs viewer and react to a slider.

JupyterLab (from this environment: ``sys.executable -m jupyter lab``) serves a temporary copy of
``tests/browser/viewer_check.ipynb`` on 127.0.0.1, on a free port, without a token. Playwright for
Python drives Debian's Chromium (``/usr/bin/chromium``; ``playwright install`` is never used). The
test runs all cells, checks that the WebGL canvases drew meshes (non-background pixels), drags a
latent slider and clicks the 2D pad, and checks that the explorer's canvas changed each time.
Screenshots go to ``build/browser/``. Skipped, with the reason, only where Chromium is missing or
cannot be launched.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
import uuid
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "tests" / "browser" / "viewer_check.ipynb"
SHOTS = ROOT / "build" / "browser"
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
#: a canvas "drew a mesh" when at least this fraction of its pixels differ from the background.
MIN_DRAWN_FRACTION = 0.02
#: a canvas "changed" when at least this fraction of its pixels changed.
MIN_CHANGED_FRACTION = 0.003
#: per-channel difference (0-255) below which two pixels count as equal.
PIXEL_TOL = 12

pytestmark = pytest.mark.browser


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_http(url: str, proc: subprocess.Popen, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"jupyter lab exited early with code {proc.returncode}")
        try:
            with urllib.request.urlopen(url, timeout=2) as r:
                if r.status == 200:
                    return
        except OSError:
            pass
        time.sleep(0.3)
    raise TimeoutError(f"jupyter lab did not answer {url} within {timeout} s")


@pytest.fixture(scope="module")
def chromium_path() -> str:
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is missing: install Debian's chromium (make browser) to run the browser test")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        pytest.skip("playwright (python) is not installed")
    return CHROMIUM


class LabServer:
    """A running ``jupyter lab`` process: ``base`` URL, ``aux`` folder, ``wait_ready()``."""

    def __init__(self, proc: subprocess.Popen, base: str, aux: Path):
        self.proc, self.base, self.aux = proc, base, aux
        self.started = time.monotonic()
        self.ready_after: float | None = None

    def wait_ready(self, timeout: float = 45.0) -> None:
        if self.ready_after is None:
            _wait_http(f"{self.base}/api/status", self.proc, timeout=timeout)
            self.ready_after = time.monotonic() - self.started

    def shutdown_kernels(self) -> None:
        """Ask the server to stop its kernels (fast, graceful); errors are ignored."""
        try:
            with urllib.request.urlopen(f"{self.base}/api/kernels", timeout=5) as r:
                kernels = json.load(r)
            for k in kernels:
                req = urllib.request.Request(f"{self.base}/api/kernels/{k['id']}", method="DELETE")
                urllib.request.urlopen(req, timeout=10).close()
        except (OSError, ValueError):
            pass


@pytest.fixture(scope="module")
def lab_server(tmp_path_factory):
    """A JupyterLab server on a free port serving a copy of the check notebook; always killed.

    The fixture does not wait for the server: the test launches Chromium meanwhile and then calls
    ``wait_ready()``.
    """
    root = tmp_path_factory.mktemp("lab")
    aux = tmp_path_factory.mktemp("lab-aux")  # settings, runtime, logs: outside the served tree
    shutil.copy(NOTEBOOK, root / NOTEBOOK.name)
    settings = aux / "settings"
    notif = settings / "@jupyterlab" / "apputils-extension"
    notif.mkdir(parents=True)
    (notif / "notification.jupyterlab-settings").write_text(json.dumps({"fetchNews": "false", "checkForUpdates": False}))
    port = _free_port()
    env = {k: v for k, v in os.environ.items() if k != "MESHVAE_VIEWER"}
    env.update(JUPYTER_RUNTIME_DIR=str(aux / "runtime"), OMP_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    log = open(aux / "server.log", "wb")
    cmd = [
        sys.executable, "-m", "jupyter", "lab", "--no-browser", "--allow-root",
        "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}", "--ServerApp.port_retries=0",
        "--IdentityProvider.token=", "--ServerApp.password=", "--ServerApp.disable_check_xsrf=True",
        f"--ServerApp.root_dir={root}", f"--LabApp.workspaces_dir={aux / 'workspaces'}",
        f"--LabApp.user_settings_dir={settings}", "--LabApp.expose_app_in_browser=True",
    ]
    proc = subprocess.Popen(cmd, cwd=root, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    server = LabServer(proc, f"http://127.0.0.1:{port}", aux)
    try:
        yield server
    finally:
        if proc.poll() is None:
            if server.ready_after is not None:
                server.shutdown_kernels()
            try:
                os.killpg(proc.pid, signal.SIGTERM)
                proc.wait(timeout=10)
            except (ProcessLookupError, subprocess.TimeoutExpired):
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                proc.wait(timeout=5)
        log.close()
        SHOTS.mkdir(parents=True, exist_ok=True)
        shutil.copy(aux / "server.log", SHOTS / "jupyter-server.log")


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def _drawn_fraction(img: np.ndarray) -> float:
    """Fraction of pixels that differ from the most common (background) colour."""
    flat = img.reshape(-1, 3)
    colors, counts = np.unique(flat, axis=0, return_counts=True)
    bg = colors[np.argmax(counts)]
    return float(np.mean(np.abs(flat - bg).max(axis=1) > PIXEL_TOL))


def _changed_fraction(a: np.ndarray, b: np.ndarray) -> float:
    if a.shape != b.shape:
        return 1.0
    return float(np.mean(np.abs(a - b).max(axis=2) > PIXEL_TOL))


def _shot(locator, name: str) -> np.ndarray:
    png = locator.screenshot(timeout=10_000)
    (SHOTS / name).write_bytes(png)
    return _pixels(png)


def _poll(fn, timeout: float, interval: float = 0.3):
    """Call fn until it returns a truthy value or the timeout passes; return its last value."""
    deadline = time.monotonic() + timeout
    value = fn()
    while not value and time.monotonic() < deadline:
        time.sleep(interval)
        value = fn()
    return value


def _dismiss_kernel_dialog(page) -> None:
    """Accept a 'Select Kernel' dialog if the start-up race shows one."""
    from playwright.sync_api import Error as PlaywrightError

    dialog = page.locator(".jp-Dialog")
    try:
        if dialog.count() and "Kernel" in (dialog.first.inner_text(timeout=2_000) or ""):
            page.locator(".jp-Dialog .jp-mod-accept").first.click(timeout=5_000)
    except PlaywrightError:  # the dialog closed between the check and the click: nothing to do
        pass


def test_viewer_and_latent_explorer_in_jupyterlab(chromium_path, lab_server):
    from playwright.sync_api import Error as PlaywrightError
    from playwright.sync_api import sync_playwright

    aux = lab_server.aux
    SHOTS.mkdir(parents=True, exist_ok=True)
    console: list[str] = []
    t_start = time.monotonic()
    phases: list[tuple[str, float]] = []

    def phase(name: str) -> None:
        phases.append((name, time.monotonic() - t_start))
    with sync_playwright() as pw:
        try:
            context = pw.chromium.launch_persistent_context(
                str(aux / "chromium-profile"), executable_path=chromium_path, headless=True,
                args=CHROMIUM_FLAGS, viewport={"width": 1280, "height": 1400},
            )
        except PlaywrightError as err:
            pytest.skip(f"playwright could not launch {chromium_path}: {str(err).splitlines()[0]}")
        try:
            phase("chromium launched")
            lab_server.wait_ready()
            base = lab_server.base
            phase(f"server ready ({lab_server.ready_after:.1f} s after its start)")
            page = context.pages[0] if context.pages else context.new_page()
            page.on("console", lambda m: console.append(f"{m.type}: {m.text}"))
            page.on("pageerror", lambda e: console.append(f"pageerror: {e}"))
            workspace = f"check-{uuid.uuid4().hex[:8]}"
            page.goto(f"{base}/lab/workspaces/{workspace}/tree/{NOTEBOOK.name}?reset", timeout=30_000)
            page.wait_for_selector(".jp-NotebookPanel", timeout=30_000)
            page.wait_for_function("() => window.jupyterapp !== undefined", timeout=15_000)
            # Wait for the kernel; accept the "Select Kernel" dialog when the start-up race shows it.
            ready = _poll(lambda: (_dismiss_kernel_dialog(page), page.evaluate(
                "() => { const w = window.jupyterapp.shell.currentWidget;"
                " const k = w && w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel;"
                " return !!k && k.connectionStatus === 'connected' && k.status === 'idle'; }"))[1], timeout=30)
            assert ready, "the notebook's kernel did not become idle within 30 s"
            phase("notebook open, kernel idle")
            page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
            page.wait_for_selector("text=viewer-check-ready threejs threejs", timeout=40_000)
            phase("all cells ran")

            viewer_canvas = page.locator(".meshvae-viewer canvas").first
            explorer_canvas = page.locator(".meshvae-latent-explorer .meshvae-viewer canvas").first
            pad_canvas = page.locator(".meshvae-latent-pad canvas").first
            for loc in (viewer_canvas, explorer_canvas, pad_canvas):
                loc.wait_for(state="visible", timeout=20_000)
                loc.scroll_into_view_if_needed(timeout=5_000)

            # 1. The WebGL canvases drew something: meshes, not just the background.
            last = {}

            def drawn(loc, name):
                last[name] = _shot(loc, name)
                return _drawn_fraction(last[name]) > MIN_DRAWN_FRACTION

            ok = _poll(lambda: drawn(viewer_canvas, "01-viewer.png"), 20)
            assert ok, (f"the viewer's canvas is blank: only {_drawn_fraction(last['01-viewer.png']):.4f} "
                        f"of pixels differ from the background")
            explorer_canvas.scroll_into_view_if_needed(timeout=5_000)
            ok = _poll(lambda: drawn(explorer_canvas, "02-explorer.png"), 20)
            assert ok, (f"the latent explorer's canvas is blank: only "
                        f"{_drawn_fraction(last['02-explorer.png']):.4f} of pixels differ from the background")
            before = last["02-explorer.png"]
            phase("canvases drawn")

            # 2. Drag the z[2] slider: the readout and the canvas change.
            readout = page.locator(".meshvae-z2 .widget-readout").first
            old_text = readout.inner_text(timeout=5_000)
            handle = page.locator(".meshvae-z2 .noUi-handle").first
            handle.scroll_into_view_if_needed(timeout=5_000)
            box = handle.bounding_box()
            assert box is not None, "the z[2] slider handle is not on screen"
            x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
            page.mouse.move(x, y)
            page.mouse.down()
            page.mouse.move(x + 70, y, steps=8)
            page.mouse.up()
            assert _poll(lambda: readout.inner_text() != old_text, 10), f"the z[2] readout stayed at {old_text}"
            explorer_canvas.scroll_into_view_if_needed(timeout=5_000)
            def changed_from(ref, name):
                last[name] = _shot(explorer_canvas, name)
                return _changed_fraction(ref, last[name]) > MIN_CHANGED_FRACTION

            changed = _poll(lambda: changed_from(before, "03-explorer-after-slider.png"), 15)
            after = last["03-explorer-after-slider.png"]
            assert changed, (f"the explorer's canvas did not change after the slider moved "
                             f"({_changed_fraction(before, after):.4f} of pixels changed); readout {readout.inner_text()}")

            phase("slider moved, canvas changed")
            # 3. Click the 2D pad (upper right quarter): z[0] and z[1] follow, the mesh changes again.
            r0 = page.locator(".meshvae-z0 .widget-readout").first
            r1 = page.locator(".meshvae-z1 .widget-readout").first
            old0, old1 = r0.inner_text(), r1.inner_text()
            pad_canvas.scroll_into_view_if_needed(timeout=5_000)
            pb = pad_canvas.bounding_box()
            page.mouse.click(pb["x"] + 0.8 * pb["width"], pb["y"] + 0.2 * pb["height"])
            assert _poll(lambda: r0.inner_text() != old0 and r1.inner_text() != old1, 10), \
                f"the pad click did not move z[0], z[1] (still {r0.inner_text()}, {r1.inner_text()})"
            assert float(r0.inner_text()) > 0 and float(r1.inner_text()) > 0, \
                f"upper-right click should give positive z[0], z[1]; got {r0.inner_text()}, {r1.inner_text()}"
            _shot(pad_canvas, "04-pad.png")
            explorer_canvas.scroll_into_view_if_needed(timeout=5_000)
            assert _poll(lambda: changed_from(after, "05-explorer-after-pad.png"), 15), \
                "the explorer's canvas did not change after the pad click"
            phase("pad clicked, canvas changed")
            page.screenshot(path=str(SHOTS / "06-page.png"))
        finally:
            (SHOTS / "console.log").write_text("\n".join(console))
            (SHOTS / "timings.txt").write_text("".join(f"{t:6.1f} s  {n}\n" for n, t in phases))
            context.close()
    # No error from the page or any widget (pythreejs logs "Error setting state" for lights with
    # shadows and "Cannot convert undefined..." for computeVertexNormals; the viewer avoids both).
    errors = [m for m in console if m.startswith(("pageerror", "error")) and "Failed to load resource" not in m]
    assert not errors, f"browser console errors (see {SHOTS / 'console.log'}): {errors[:5]}"
