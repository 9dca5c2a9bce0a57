"""A real headless Chromium driven over the DevTools protocol, for tests of HTML output.

Debian's ``chromium`` package (``tests/system-packages.sh`` installs it) is started with a private profile and
``--remote-debugging-port=0``; the page's DevTools WebSocket (the ``websockets`` package, a dependency of
viser) takes screenshots until a condition on the picture holds or time runs out.  WebGL runs on
SwiftShader (software), as on a machine without a GPU.  Nothing here skips: a missing browser is an error
that says how to install it.
"""

from __future__ import annotations

import base64
import io
import json
import os
import shutil
import subprocess
import tempfile
import time
import urllib.request
from typing import Callable

import numpy as np

BROWSERS = ("chromium", "chromium-browser", "google-chrome")


def browser() -> str:
    """The Chromium executable; AssertionError with the install command when there is none."""
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    raise AssertionError(
        "headless Chromium is needed for the HTML replay test and is not on PATH: "
        "apt-get install -y chromium (tests/system-packages.sh installs it)"
    )


def screenshot_when(
    url: str, ready: Callable[[np.ndarray], bool], timeout: float = 90.0, size: tuple[int, int] = (800, 600)
) -> tuple[np.ndarray, bool]:
    """Load ``url`` and take screenshots (RGB arrays) every half second until ``ready(picture)``; returns
    the last picture and whether it was ready before ``timeout`` seconds."""
    from PIL import Image
    from websockets.sync.client import connect

    profile = tempfile.mkdtemp(prefix="mrgc-chromium-")
    proc = subprocess.Popen(
        [
            browser(),
            "--headless=new",
            "--no-sandbox",
            "--no-first-run",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--hide-scrollbars",
            "--remote-debugging-port=0",
            "--remote-debugging-address=127.0.0.1",
            f"--user-data-dir={profile}",
            f"--window-size={size[0]},{size[1]}",
            url,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        port = _port(profile, proc, deadline=time.monotonic() + 30)
        pages = []
        for _ in range(100):
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=5) as r:
                pages = [t for t in json.load(r) if t.get("type") == "page"]
            if pages:
                break
            time.sleep(0.1)
        assert pages, "Chromium opened no page"
        picture = np.zeros((1, 1, 3), dtype=np.uint8)
        with connect(pages[0]["webSocketDebuggerUrl"], max_size=64 * 2**20, open_timeout=10) as ws:
            deadline = time.monotonic() + timeout
            n = 0
            while True:
                n += 1
                ws.send(json.dumps({"id": n, "method": "Page.captureScreenshot", "params": {"format": "png"}}))
                while True:
                    msg = json.loads(ws.recv(timeout=120))
                    if msg.get("id") == n:
                        break
                data = base64.b64decode(msg["result"]["data"])
                picture = np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))
                if ready(picture):
                    return picture, True
                if time.monotonic() > deadline:
                    return picture, False
                time.sleep(0.5)
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        shutil.rmtree(profile, ignore_errors=True)


def _port(profile: str, proc: subprocess.Popen[bytes], deadline: float) -> int:
    path = os.path.join(profile, "DevToolsActivePort")
    while time.monotonic() < deadline:
        if os.path.exists(path):
            with open(path, encoding="ascii") as fh:
                first = fh.readline().strip()
            if first.isdigit():
                return int(first)
        assert proc.poll() is None, f"Chromium exited with code {proc.returncode} before opening its DevTools port"
        time.sleep(0.1)
    raise AssertionError("Chromium did not open its DevTools port within 30 s")


def colour_share(
    picture: np.ndarray, rgb: tuple[int, int, int], hue_tolerance: float = 0.04, min_saturation: float = 0.25
) -> float:
    """The share of pixels whose hue is within ``hue_tolerance`` (of a turn) of ``rgb``'s and that are
    saturated: a colour survives the viewer's shading as its hue."""

    def hsv(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a = a.astype(float) / 255
        mx, mn = a.max(axis=-1), a.min(axis=-1)
        d = np.where(mx - mn == 0, 1, mx - mn)
        r, g, b = a[..., 0], a[..., 1], a[..., 2]
        h = np.where(mx == r, ((g - b) / d) % 6, np.where(mx == g, (b - r) / d + 2, (r - g) / d + 4)) / 6
        s = np.where(mx == 0, 0, (mx - mn) / np.where(mx == 0, 1, mx))
        return h, s

    h, s = hsv(picture)
    h0, _ = hsv(np.array(rgb, dtype=np.uint8).reshape(1, 1, 3))
    dh = np.abs(h - h0[0, 0])
    dh = np.minimum(dh, 1 - dh)
    return float(((dh <= hue_tolerance) & (s >= min_saturation)).mean())
