#!/usr/bin/env python3
"""The viewer page as a visitor gets it: `web/index.html` and the `wasm-bindgen` output in
`web/pkg`, served over HTTP and opened in headless Chromium through chromedriver (the W3C
WebDriver protocol, from the standard library). Checks that the page starts on WebGPU, draws
the built-in scene with lines (read back through the page's `window.wirepass.snapshot()`, not
a screenshot), says what it shows in its toolbar, and turns the view on a drag.

    python3 web/tests/page.py [--chromedriver /usr/bin/chromedriver]

Exits non-zero with one line saying what failed.
"""

import argparse
import contextlib
import functools
import http.server
import json
import os
import socket
import subprocess
import sys
import threading
import time
import urllib.request

WEB = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def call(base, method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    request = urllib.request.Request(base + path, data=data, method=method)
    request.add_header("Content-Type", "application/json")
    with urllib.request.urlopen(request, timeout=120) as response:
        value = json.load(response)["value"]
    return value


@contextlib.contextmanager
def browser(handler, chromedriver, script_seconds):
    """Serves `handler` over HTTP, starts chromedriver and a headless Chromium session with
    web/webdriver.json's options, and yields (the driver's URL, the session's path, the
    server's origin); everything is shut down after."""
    with open(os.path.join(WEB, "webdriver.json")) as f:
        capabilities = json.load(f)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", free_port()), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    port = free_port()
    driver = subprocess.Popen([chromedriver, f"--port={port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}"
    session = None
    try:
        for _ in range(100):
            try:
                call(base, "GET", "/status")
                break
            except OSError:
                time.sleep(0.1)
        options = dict(capabilities["goog:chromeOptions"], binary=os.environ.get("CHROMIUM", "/usr/bin/chromium"))
        session = call(base, "POST", "/session", {"capabilities": {"alwaysMatch": {"goog:chromeOptions": options}}})["sessionId"]
        s = f"/session/{session}"
        call(base, "POST", s + "/timeouts", {"script": script_seconds * 1000})
        yield base, s, f"http://127.0.0.1:{server.server_port}"
    finally:
        if session:
            try:
                call(base, "DELETE", f"/session/{session}")
            except OSError:
                pass
        driver.terminate()
        server.shutdown()


# The shares of background, surface and line pixels of an RGBA8 snapshot, computed in the
# page: the background is the style's (255, 255, 255); lines are darker than half the fill's
# ambient share, as the native viewer's check has it.
SNAPSHOT = """
const done = arguments[arguments.length - 1];
window.wirepass.snapshot().then(rgba => {
  let background = 0, lines = 0;
  for (let i = 0; i < rgba.length; i += 4) {
    const [r, g, b] = [rgba[i], rgba[i + 1], rgba[i + 2]];
    if (r >= 253 && g >= 253 && b >= 253) background++;
    else if (r < 80 && g < 85 && b < 92) lines++;
  }
  done({pixels: rgba.length / 4, background, lines});
}, e => done({error: String(e)}));
"""

DRAG = """
const canvas = document.querySelector("canvas");
const r = canvas.getBoundingClientRect();
const at = (type, dx, buttons) => canvas.dispatchEvent(new PointerEvent(type, {
  pointerId: 3, clientX: r.left + r.width / 2 + dx, clientY: r.top + r.height / 2,
  button: 0, buttons, bubbles: true, cancelable: true, isPrimary: true}));
at("pointerdown", 0, 1);
for (let k = 1; k <= 6; k++) at("pointermove", 20 * k, 1);
at("pointerup", 120, 0);
return window.wirepass.frames();
"""


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--chromedriver", default=os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver"))
    args = parser.parse_args()
    if not os.path.exists(os.path.join(WEB, "pkg", "wirepass_web.js")):
        sys.exit("page: web/pkg/wirepass_web.js is missing: build the page first (see the README)")

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    with browser(functools.partial(Quiet, directory=WEB), args.chromedriver, 120) as (base, s, origin):
        call(base, "POST", s + "/url", {"url": f"{origin}/index.html"})

        def run(script):
            return call(base, "POST", s + "/execute/sync", {"script": script, "args": []})

        def wait(what, script, seconds=60):
            start = time.time()
            while True:
                value = run(script)
                if value:
                    return value
                error = run("const e = document.querySelector('.wirepass-error'); return e && e.textContent;")
                if error:
                    sys.exit(f"page: {error}")
                if time.time() - start > seconds:
                    sys.exit(f"page: timed out waiting for {what}")
                time.sleep(0.1)

        wait("the viewer to start and draw", "return window.wirepass && window.wirepass.frames() > 0")
        status = run("return document.querySelector('.wirepass-status').textContent")
        print(f"page: {status}")
        if "triangles" not in status:
            sys.exit(f"page: the toolbar does not say what is shown: {status!r}")

        def snapshot():
            shot = call(base, "POST", s + "/execute/async", {"script": SNAPSHOT, "args": []})
            if "error" in shot:
                sys.exit(f"page: snapshot failed: {shot['error']}")
            return shot

        first = snapshot()
        n = first["pixels"]
        print(f"page: first frame {first['background'] / n:.3f} background, {first['lines'] / n:.4f} lines")
        if not (first["background"] > 0.05 * n and first["lines"] > 0.002 * n and first["background"] + first["lines"] < 0.95 * n):
            sys.exit("page: the first frame does not show background, surface and lines")
        frames = run(DRAG)
        wait("a frame after the drag", f"return window.wirepass.frames() > {frames}")
        turned = snapshot()
        print(f"page: after a drag {turned['background'] / n:.3f} background, {turned['lines'] / n:.4f} lines")
        if turned["background"] == first["background"] and turned["lines"] == first["lines"]:
            sys.exit("page: a drag did not change the view")
        print("page: ok")


if __name__ == "__main__":
    main()
