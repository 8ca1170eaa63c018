"""A small W3C WebDriver client over chromedriver (Debian's chromium-driver), standard library
only: start a headless Chromium, open a page, run scripts in it, click elements."""

import json
import os
import socket
import subprocess
import time
import urllib.error
import urllib.request

ELEMENT_KEY = "element-6066-11e4-a52e-4f735466cecf"


class Unavailable(Exception):
    """Chromium or chromedriver is missing or cannot start here."""


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Browser:
    def __init__(self, chromium="/usr/bin/chromium", driver="/usr/bin/chromedriver"):
        for path in (chromium, driver):
            if not os.access(path, os.X_OK):
                raise Unavailable(f"{path} not found (Debian packages chromium, chromium-driver)")
        self.port = _free_port()
        self.driver = subprocess.Popen(
            [driver, f"--port={self.port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.base = f"http://127.0.0.1:{self.port}"
        self.session = None
        deadline = time.time() + 20
        while True:
            try:
                if self._call("GET", "/status")["value"].get("ready"):
                    break
            except (OSError, urllib.error.URLError):
                pass
            if time.time() > deadline or self.driver.poll() is not None:
                self.close()
                raise Unavailable("chromedriver did not start")
            time.sleep(0.1)
        args = ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                "--window-size=1400,1000", "--enable-unsafe-swiftshader", "--use-angle=swiftshader"]
        try:
            value = self._call("POST", "/session", {"capabilities": {"alwaysMatch": {
                "browserName": "chrome",
                "goog:chromeOptions": {"binary": chromium, "args": args}}}})["value"]
        except (OSError, urllib.error.URLError, KeyError) as e:
            self.close()
            raise Unavailable(f"Chromium did not start: {e}") from e
        if "sessionId" not in value:
            self.close()
            raise Unavailable(f"Chromium did not start: {value.get('message', value)}")
        self.session = value["sessionId"]

    def _call(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(self.base + path, data=data, method=method,
                                         headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=60) as response:
                return json.loads(response.read())
        except urllib.error.HTTPError as e:
            return json.loads(e.read())

    def _session_call(self, method, path, body=None):
        value = self._call(method, f"/session/{self.session}{path}", body)["value"]
        if isinstance(value, dict) and "error" in value:
            raise RuntimeError(f"WebDriver {path}: {value['error']}: {value.get('message')}")
        return value

    def open(self, url):
        self._session_call("POST", "/url", {"url": url})

    def run(self, script, *args):
        """The value of `script` (a function body: use return) in the page."""
        return self._session_call("POST", "/execute/sync", {"script": script, "args": list(args)})

    def click(self, css):
        element = self._session_call("POST", "/element", {"using": "css selector", "value": css})
        self._session_call("POST", f"/element/{element[ELEMENT_KEY]}/click", {})

    def screenshot(self, path):
        import base64
        with open(path, "wb") as f:
            f.write(base64.b64decode(self._session_call("GET", "/screenshot")))

    def wait(self, script, timeout, what):
        """Polls `script` until it returns a truthy value; that value, or an AssertionError."""
        deadline = time.time() + timeout
        while True:
            value = self.run(script)
            if value:
                return value
            if time.time() > deadline:
                raise AssertionError(f"timed out after {timeout} s waiting for {what}")
            time.sleep(0.2)

    def close(self):
        if self.session:
            try:
                self._call("DELETE", f"/session/{self.session}")
            except (OSError, urllib.error.URLError):
                pass
            self.session = None
        if self.driver.poll() is None:
            self.driver.terminate()
            self.driver.wait(timeout=10)
