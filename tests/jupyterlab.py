"""A JupyterLab server and a headless Chromium that clicks through it as a student would.

Used by ``tests/test_jupyterlab_browser.py``. The server serves a temporary copy of the course's
notebook folders (JupyterLab autosaves, so it never touches the committed notebooks), with
``ROBOKIT_FAST=1`` for its kernels and the app exposed as ``window.jupyterapp``, so the test drives
JupyterLab's own commands (open, Run All) and reads the notebook's cells and outputs the way the
UI holds them, plus what the page shows (scenes, sliders, widget errors).
"""
from __future__ import annotations

import base64
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

from robocourse.site.cdp import DevToolsPipe

ROOT = Path(__file__).resolve().parents[1]
#: Chromium resolves no host name (robocourse.site.cdp.FLAGS); this later flag lets 127.0.0.1 through.
_ONLY_THE_SERVER = "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LabServer:
    """``jupyter lab`` on a free local port, serving copies of ``folders`` in a temporary root."""

    def __init__(self, workdir: Path, folders=("lessons", "assignments"), timeout: float = 60.0) -> None:
        self.root = workdir / "course"
        for folder in folders:
            shutil.copytree(ROOT / folder, self.root / folder)
        self.port, self.token = _free_port(), secrets.token_hex(16)
        # every Jupyter folder of this run is its own: no user-level kernel, setting or workspace applies
        env = dict(os.environ, ROBOKIT_FAST="1", JUPYTER_RUNTIME_DIR=str(workdir / "runtime"),
                   JUPYTER_DATA_DIR=str(workdir / "data"),
                   JUPYTER_CONFIG_DIR=str(workdir / "config"), JUPYTERLAB_SETTINGS_DIR=str(workdir / "settings"),
                   JUPYTERLAB_WORKSPACES_DIR=str(workdir / "workspaces"))
        env.pop("ROBOKIT_HEADLESS", None)               # a student's kernel: live widgets
        self.log = workdir / "jupyter.log"
        with open(self.log, "wb") as log:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "jupyterlab", "--no-browser", f"--port={self.port}", "--ip=127.0.0.1",
                 f"--IdentityProvider.token={self.token}", f"--ServerApp.root_dir={self.root}",
                 "--LabApp.expose_app_in_browser=True", "--LabApp.news_url=None", "--ServerApp.port_retries=0",
                 "--LabApp.extension_manager=readonly", *(["--allow-root"] if os.geteuid() == 0 else [])],
                cwd=self.root, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + timeout
        while True:
            try:
                with urllib.request.urlopen(f"{self.url('api/status')}", timeout=2) as reply:
                    if reply.status == 200:
                        break
            except OSError:
                pass
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"jupyter lab did not start: {self.log_tail()}")
            time.sleep(0.3)

    def url(self, path: str) -> str:
        return f"http://127.0.0.1:{self.port}/{path}?token={self.token}"

    def log_tail(self, lines: int = 30) -> str:
        return "\n".join(self.log.read_text(errors="replace").splitlines()[-lines:])

    def close(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


# Open a notebook in JupyterLab, start its kernel, Run All, wait until the kernel is idle again.
_RUN_ALL_JS = """async (path) => {
  const app = window.jupyterapp;
  await app.restored;
  const panel = await app.commands.execute('docmanager:open', {path, factory: 'Notebook'});
  await panel.context.ready;
  await panel.sessionContext.ready;
  const started = performance.now();
  await app.commands.execute('notebook:run-all-cells');
  for (;;) {
    const status = panel.sessionContext.session.kernel.status;
    if (status === 'idle') break;
    if (status === 'dead' || status === 'unknown') throw new Error('the kernel is ' + status);
    await new Promise(r => setTimeout(r, 200));
  }
  return (performance.now() - started) / 1000;
}"""

# What the open notebook holds (cells, tags, outputs) and what its page shows.
_READ_JS = """() => {
  const panel = window.jupyterapp.shell.currentWidget;
  const cells = panel.content.widgets.map(c => {
    const code = c.model.type === 'code';
    return {type: c.model.type, tags: c.model.getMetadata('tags') || [],
            count: code ? c.model.executionCount : null,
            outputs: code ? c.model.outputs.toJSON().map(o => ({
              type: o.output_type, name: o.name || null, ename: o.ename || null,
              evalue: (o.evalue || '').slice(0, 300), mimes: Object.keys(o.data || {}),
              text: (Array.isArray(o.text) ? o.text.join('') : (o.text || '')).slice(0, 4000)})) : []};
  });
  const scenes = [...panel.node.querySelectorAll('iframe[title="robokit meshcat scene"]')].map(f => {
    const doc = f.contentDocument, canvas = doc && doc.querySelector('canvas');
    return {width: f.clientWidth, height: f.clientHeight, canvas: !!canvas,
            canvasWidth: canvas ? canvas.width : 0};
  });
  const sliders = [...panel.node.querySelectorAll('.widget-slider')].map(s => ({
    readout: (s.querySelector('.widget-readout') || {}).textContent || '',
    editable: !!s.querySelector('.widget-readout[contenteditable="true"]')}));
  return {cells, scenes, sliders, text: panel.node.textContent};   // off-screen cells too
}"""

# Type a value into the n-th slider's readout and press Enter, as a student would.
_TYPE_JS = """(index, value) => {
  const panel = window.jupyterapp.shell.currentWidget;
  const readout = panel.node.querySelectorAll('.widget-slider .widget-readout')[index];
  readout.focus();
  readout.textContent = value;
  readout.dispatchEvent(new KeyboardEvent('keydown', {key: 'Enter', code: 'Enter', keyCode: 13, bubbles: true}));
  readout.blur();
  return true;
}"""

# The image the n-th slider's box shows now (the figure redrawn by the kernel).
_SLIDER_IMAGE_JS = """(index) => {
  const panel = window.jupyterapp.shell.currentWidget;
  const box = panel.node.querySelectorAll('.widget-slider')[index].closest('.widget-vbox');
  const img = box && box.querySelector('img');
  return img ? img.src.slice(-200) : '';
}"""


class LabPage:
    """One Chromium tab on the JupyterLab server (network limited to the server on 127.0.0.1)."""

    def __init__(self, server: LabServer, width: int = 1400, height: int = 1000) -> None:
        self.server = server
        self.pipe = DevToolsPipe(args=(f"--window-size={width},{height}", _ONLY_THE_SERVER), timeout=30)
        target = self.pipe.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.pipe.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.pipe.call("Page.enable", session=self.session)
        self.pipe.call("Runtime.enable", session=self.session)
        self.pipe.call("Emulation.setDeviceMetricsOverride", {"width": width, "height": height,
                                                               "deviceScaleFactor": 1, "mobile": False},
                       session=self.session)
        self.pipe.call("Page.navigate", {"url": server.url("lab")}, session=self.session)
        self.wait_for("window.jupyterapp !== undefined && document.querySelector('.jp-LabShell') !== null", 90)

    def evaluate(self, function: str, *args: object, timeout: float = 30.0) -> object:
        expression = f"({function})({', '.join(json.dumps(a) for a in args)})"
        result = self.pipe.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True,
                                                     "returnByValue": True}, self.session, timeout=timeout)
        if "exceptionDetails" in result:
            details = result["exceptionDetails"]
            raise RuntimeError(f"script failed in JupyterLab: "
                               f"{details.get('exception', {}).get('description') or details.get('text')}")
        return result["result"].get("value")

    def wait_for(self, condition: str, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        while not self.evaluate(f"() => Boolean({condition})"):
            if time.monotonic() > deadline:
                raise TimeoutError(f"JupyterLab: {condition} not true within {timeout} s\n{self.server.log_tail()}")
            time.sleep(0.3)

    def run_all(self, path: str, timeout: float = 300.0) -> float:
        """Open ``path`` (relative to the server's root), Run All, wait for the kernel; seconds taken."""
        return self.evaluate(_RUN_ALL_JS, path, timeout=timeout)

    def show(self, path: str) -> None:
        """Bring the open notebook ``path`` to the front (what the other methods read)."""
        self.evaluate("async (path) => { await window.jupyterapp.commands.execute('docmanager:open', {path}); "
                      "return true; }", path)

    def read(self, settle: float = 20.0) -> dict:
        """The notebook in front: its cells (type, tags, execution count, outputs), scenes and sliders,
        read again until two reads agree on scenes and sliders (views render after the kernel is idle)."""
        deadline, last = time.monotonic() + settle, None
        while True:
            report = self.evaluate(_READ_JS)
            shape = json.dumps([report["scenes"], [s["readout"] for s in report["sliders"]]])
            if shape == last or time.monotonic() > deadline:
                return report
            last = shape
            time.sleep(1.0)

    def type_into_slider(self, index: int, value: str) -> None:
        self.evaluate(_TYPE_JS, index, value)

    def slider_image(self, index: int) -> str:
        return self.evaluate(_SLIDER_IMAGE_JS, index)

    def screenshot(self, path: Path) -> Path:
        shot = self.pipe.call("Page.captureScreenshot", {"format": "png"}, self.session, timeout=30)
        path.write_bytes(base64.b64decode(shot["data"]))
        return path

    def close(self) -> None:
        self.pipe.close()
