"""A headless Chromium driven through its WebDriver (W3C protocol, Debian's `chromedriver`),
with nothing but the standard library: enough to open a page, run scripts in it, read its
console log and take screenshots.

    with Browser() as b:
        b.open(path)
        b.script("return window.fotonReport.tabs")
"""

from __future__ import annotations

import base64
import json
import shutil
import socket
import subprocess
import tempfile
import time
import urllib.error
import urllib.request
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"


def missing() -> str | None:
    """Why no browser can be driven here, or None."""
    if shutil.which("chromedriver") is None:
        return "chromedriver is not installed (Debian: apt-get install chromium chromium-driver)"
    if not Path(CHROMIUM).exists() and shutil.which("chromium") is None:
        return "chromium is not installed (Debian: apt-get install chromium chromium-driver)"
    return None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Browser:
    def __init__(self, width: int = 1280, height: int = 900):
        self.port = _free_port()
        self.profile = tempfile.TemporaryDirectory(prefix="foton-chromium-")
        self.driver = subprocess.Popen(
            [shutil.which("chromedriver"), f"--port={self.port}"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        deadline = time.monotonic() + 30
        while True:
            try:
                self._call("GET", "/status")
                break
            except (urllib.error.URLError, ConnectionError):
                if time.monotonic() > deadline:
                    self.driver.kill()
                    raise RuntimeError("chromedriver did not start within 30 s")
                time.sleep(0.1)
        binary = CHROMIUM if Path(CHROMIUM).exists() else shutil.which("chromium")
        # The flags that keep Chromium from reaching for the network on its own (no
        # background networking, updates or sync), headless, as root without a sandbox.
        args = [
            "--headless=new",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-dev-shm-usage",
            f"--user-data-dir={self.profile.name}",
            f"--window-size={width},{height}",
        ]
        caps = {
            "capabilities": {
                "alwaysMatch": {
                    "browserName": "chrome",
                    "goog:chromeOptions": {"binary": binary, "args": args},
                    "goog:loggingPrefs": {"browser": "ALL"},
                }
            }
        }
        self.session = self._call("POST", "/session", caps)["sessionId"]

    def _call(self, method: str, path: str, body: dict | None = None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(
            f"http://127.0.0.1:{self.port}{path}",
            data=data,
            method=method,
            headers={"Content-Type": "application/json"},
        )
        try:
            with urllib.request.urlopen(req, timeout=120) as r:
                return json.loads(r.read())["value"]
        except urllib.error.HTTPError as e:
            value = json.loads(e.read()).get("value", {})
            raise RuntimeError(f"WebDriver {method} {path}: {value.get('message', value)}") from None

    def open(self, path: Path) -> None:
        self._call("POST", f"/session/{self.session}/url", {"url": Path(path).resolve().as_uri()})

    def script(self, source: str, *args):
        return self._call(
            "POST", f"/session/{self.session}/execute/sync", {"script": source, "args": list(args)}
        )

    def log(self) -> list[dict]:
        """The console's entries since the last call (level, message)."""
        return self._call("POST", f"/session/{self.session}/se/log", {"type": "browser"})

    def key(self, keys: str) -> None:
        """Types `keys` into the page (as a user pressing them)."""
        actions = [{"type": "keyDown", "value": k} for k in keys]
        actions = [a for k in keys for a in ({"type": "keyDown", "value": k}, {"type": "keyUp", "value": k})]
        self._call(
            "POST",
            f"/session/{self.session}/actions",
            {"actions": [{"type": "key", "id": "keyboard", "actions": actions}]},
        )

    def screenshot(self, path: Path) -> None:
        png = self._call("GET", f"/session/{self.session}/screenshot")
        Path(path).write_bytes(base64.b64decode(png))

    def close(self) -> None:
        try:
            self._call("DELETE", f"/session/{self.session}")
        finally:
            self.driver.terminate()
            try:
                self.driver.wait(10)
            except subprocess.TimeoutExpired:
                self.driver.kill()
            self.profile.cleanup()

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
