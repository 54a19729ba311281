#!/usr/bin/env python3
"""<wirepass-viewer> as an outside page uses it: the package that `web/package.sh` builds,
served over HTTP with the repository's meshes, opened in headless Chromium on WebGPU through
chromedriver (the W3C WebDriver protocol, from the standard library).

One page holds four elements: two models by URL (an OBJ, and a .gltf whose buffer is fetched
beside it), a URL that answers 404 and a file that is not a model. Checked:
- both models raise `load` and their `snapshot()` PNGs match the native frames of the same
  views (`web/tests/reference/element-*.png`, which `web/tests/native.rs` holds to the
  ground truth): at most 0.2 % of the pixels differ by more than 8/255, mean ≤ 0.002;
- the 404 and the broken file each raise exactly one `error`, whose message the element shows,
  and so does an attribute it cannot read (the view stays as it was);
- a click raises `pick` with the ground truth's instance and triangle at that pixel
  (`web/tests/reference/element.json`);
- setting `hidden="dashed"` redraws with hidden lines (the native frame of that view);
- a drag turns the view and `fit()` brings the camera's view back; `exportSvg()` draws lines;
- nothing is drawn while nothing changes; an element removed while it starts raises nothing,
  and put back it loads; the package's demo page draws;
- on a page without WebGPU an element raises `error` and says so in its box.

    python3 web/tests/element.py [--package web/package] [--chromedriver /usr/bin/chromedriver]
    python3 web/tests/element.py --first-frame 1000000   # a sphere of that many triangles as a
                                                          # GLB (written to --out): time from
                                                          # `src` set to its first frame
    python3 web/tests/element.py --first-frame 1000000 --compile-times
        # and how long the browser's GPU process takes to compile each pipeline that frame
        # built: recorded as the element creates them, then created again one at a time
        # (createComputePipelineAsync) on a new browser's device, where nothing is cached

Exits non-zero with one line saying what failed.
"""

import argparse
import base64
import functools
import http.server
import json
import os
import struct
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from page import browser, call  # noqa: E402

WEB = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(WEB)


def sphere_glb(triangles):
    """A closed UV sphere of about `triangles` triangles (one vertex at each pole) as a GLB:
    float positions, u32 indices, counter-clockwise seen from outside."""
    import array
    import math
    rows = max(2, int(math.sqrt(triangles / 4)))
    cols = max(3, triangles // (2 * (rows - 1)))
    positions = array.array("f", (0, 1, 0))
    for r in range(1, rows):
        theta = math.pi * r / rows
        for c in range(cols):
            phi = 2 * math.pi * c / cols
            positions.extend((math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)))
    positions.extend((0, -1, 0))
    south = len(positions) // 3 - 1
    ring = lambda r, c: 1 + (r - 1) * cols + c % cols  # noqa: E731
    indices = array.array("I")
    for c in range(cols):
        indices.extend((0, ring(1, c), ring(1, c + 1)))
        indices.extend((south, ring(rows - 1, c + 1), ring(rows - 1, c)))
    for r in range(1, rows - 1):
        for c in range(cols):
            a, b, d, e = ring(r, c), ring(r, c + 1), ring(r + 1, c), ring(r + 1, c + 1)
            indices.extend((a, d, e, a, e, b))
    pos, ind = positions.tobytes(), indices.tobytes()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(pos) + len(ind)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(ind)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions) // 3, "type": "VEC3",
                       "min": [-1, -1, -1], "max": [1, 1, 1]},
                      {"bufferView": 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"}],
    }
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    body = pos + ind
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(body), 0x004E4942) + body
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks, len(indices) // 3


def page(views):
    """The test page: an element per view and the two that fail, each event logged."""
    elements = []
    for k, view in enumerate(views):
        attributes = " ".join(f'{a["name"]}="{a["value"]}"' for a in view["attributes"])
        elements.append(f'<wirepass-viewer id="v{k}" src="/{view["src"]}" {attributes}></wirepass-viewer>')
    elements.append('<wirepass-viewer id="missing" src="/no/such/model.obj"></wirepass-viewer>')
    elements.append('<wirepass-viewer id="broken" src="/test/broken.glb"></wirepass-viewer>')
    return f"""<!doctype html>
<html><head><meta charset="utf-8">
<style>body {{ margin: 0; }} wirepass-viewer {{ width: 320px; height: 240px; display: inline-block; }}</style>
</head><body>
{chr(10).join(elements)}
<script>
  window.events = [];
  for (const el of document.querySelectorAll("wirepass-viewer")) {{
    for (const type of ["load", "pick", "error"]) {{
      el.addEventListener(type, (e) => events.push({{id: el.id, type, detail: e.detail}}));
    }}
  }}
</script>
<script type="module" src="/web/package/wirepass-viewer.js"></script>
</body></html>
"""


NO_WEBGPU = """<!doctype html>
<html><head><meta charset="utf-8"></head><body>
<script>
  Object.defineProperty(navigator, "gpu", {value: undefined, configurable: true});
  window.events = [];
</script>
<wirepass-viewer id="lone" style="width: 200px; height: 100px"></wirepass-viewer>
<script>
  document.getElementById("lone").addEventListener("error", (e) => events.push(e.detail.message));
</script>
<script type="module" src="/web/package/wirepass-viewer.js"></script>
</body></html>
"""

# The page's first element, removed while the WebAssembly and the device start (it must not
# draw or raise anything while out of the page), put back 1.5 s later.
REMOVED = """<!doctype html>
<html><head><meta charset="utf-8"></head><body>
<script type="module">
  const events = [];
  const el = document.createElement("wirepass-viewer");
  el.setAttribute("src", "/tests/data/meshes/suzanne.obj");
  for (const type of ["load", "error"]) el.addEventListener(type, () => events.push(type));
  document.body.append(el);
  await import("/web/package/wirepass-viewer.js");
  el.remove();
  await new Promise((done) => setTimeout(done, 1500));
  const before = events.splice(0);
  const frames = el.frames;
  document.body.append(el);
  await new Promise((done) => el.addEventListener("load", done, {once: true}));
  window.removed = {before, frames, after: events};
</script>
</body></html>
"""

# Records every pipeline the page creates (its WGSL and entry points, and a render
# pipeline's fixed state) in `window.pipelines`, before the element's module runs.
RECORD_PIPELINES = """<script>
  const codes = new WeakMap();
  window.pipelines = [];
  const device = GPUDevice.prototype;
  const module = device.createShaderModule;
  device.createShaderModule = function (d) {
    const m = module.call(this, d);
    codes.set(m, d.code);
    return m;
  };
  const compute = device.createComputePipeline;
  device.createComputePipeline = function (d) {
    window.pipelines.push({label: d.label, code: codes.get(d.compute.module), entry: d.compute.entryPoint});
    return compute.call(this, d);
  };
  const render = device.createRenderPipeline;
  device.createRenderPipeline = function (d) {
    const stage = (s) => s && {code: codes.get(s.module), entry: s.entryPoint};
    window.pipelines.push({label: d.label, vertex: {...stage(d.vertex), buffers: d.vertex.buffers},
      fragment: d.fragment && {...stage(d.fragment), targets: d.fragment.targets},
      primitive: d.primitive, depthStencil: d.depthStencil, multisample: d.multisample});
    return render.call(this, d);
  };
</script>"""

# Compiles the pipelines of /test/pipelines.json one after another on a new device, and
# leaves each one's time from the call to its promise resolving in `window.compiled`.
COMPILE = """<!doctype html>
<html><head><meta charset="utf-8"></head><body>
<script type="module">
  try {
    const pipelines = await (await fetch("/test/pipelines.json")).json();
    const adapter = await navigator.gpu.requestAdapter();
    const device = await adapter.requestDevice();
    const stage = (s) => s && {module: device.createShaderModule({code: s.code}), entryPoint: s.entry};
    const times = [];
    for (const p of pipelines) {
      const start = performance.now();
      if (p.code) {
        await device.createComputePipelineAsync({layout: "auto", compute: stage(p)});
      } else {
        const d = {layout: "auto", vertex: {...stage(p.vertex), buffers: p.vertex.buffers}};
        for (const k of ["primitive", "depthStencil", "multisample"]) {
          if (p[k]) d[k] = p[k];
        }
        if (p.fragment) d.fragment = {...stage(p.fragment), targets: p.fragment.targets};
        await device.createRenderPipelineAsync(d);
      }
      times.push([p.entry ?? p.vertex.entry, p.label, performance.now() - start]);
    }
    window.compiled = times;
  } catch (e) {
    window.failed = String(e);
  }
</script>
</body></html>
"""

FIRST_FRAME = """<!doctype html>
<html><head><meta charset="utf-8">
<style>wirepass-viewer { width: 640px; height: 480px; display: block; }</style></head><body>
<script type="module">
  // Cold: the element made with its src (the module's WebAssembly, the device and the
  // pipelines included); then warm: the same file again by a new src on that element.
  const loaded = (el) => new Promise((done, fail) => {
    el.addEventListener("load", done, {once: true});
    el.addEventListener("error", (e) => fail(e.detail.message), {once: true});
  });
  try {
    let start = performance.now();
    const el = document.createElement("wirepass-viewer");
    el.src = "/test/model.glb";
    document.body.append(el);
    await import("/web/package/wirepass-viewer.js");
    await loaded(el);
    const cold = performance.now() - start;
    start = performance.now();
    el.src = "/test/model.glb?again";
    await loaded(el);
    const warm = performance.now() - start;
    const steps = performance.getEntriesByType("measure")
      .filter((m) => m.name.startsWith("wirepass-viewer"))
      .map((m) => `${m.name.slice(17)} ${m.duration.toFixed(0)} ms`);
    window.firstFrame = {cold, warm, steps: steps.join(", ")};
  } catch (e) {
    window.failed = String(e);
  }
</script>
</body></html>
"""

# The RGBA of a PNG blob or URL, decoded by the browser without colour conversion.
DECODE = """
async function rgba(source) {
  const blob = typeof source === "string" ? await (await fetch(source)).blob() : source;
  const bitmap = await createImageBitmap(blob, {colorSpaceConversion: "none", premultiplyAlpha: "none"});
  const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
  const context = canvas.getContext("2d");
  context.drawImage(bitmap, 0, 0);
  return context.getImageData(0, 0, bitmap.width, bitmap.height);
}
"""

# An element's snapshot against a reference: the share of pixels off by more than 8/255 in
# a channel and the mean difference (web/tests/browser.rs measures the same).
COMPARE = DECODE + """
const [id, reference, done] = arguments;
(async () => {
  const el = document.getElementById(id);
  const shot = await rgba(await el.snapshot());
  const ref = await rgba(reference);
  if (shot.width !== ref.width || shot.height !== ref.height) {
    return {error: `snapshot ${shot.width}x${shot.height}, reference ${ref.width}x${ref.height}`};
  }
  let over = 0, sum = 0;
  for (let i = 0; i < shot.data.length; i += 4) {
    let most = 0;
    for (let k = 0; k < 3; k++) {
      const d = Math.abs(shot.data[i + k] - ref.data[i + k]);
      most = Math.max(most, d);
      sum += d;
    }
    if (most > 8) over++;
  }
  const pixels = shot.data.length / 4;
  const png = await el.snapshot();
  const bytes = new Uint8Array(await png.arrayBuffer());
  let binary = "";
  for (const b of bytes) binary += String.fromCharCode(b);
  return {over: over / pixels, mean: sum / (3 * 255 * pixels), png: btoa(binary)};
})().then(done, (e) => done({error: String(e)}));
"""

POINTER = """
const [id, x, y, moves] = arguments;
const canvas = document.getElementById(id).shadowRoot.querySelector("canvas");
const r = canvas.getBoundingClientRect();
const at = (type, dx, buttons) => canvas.dispatchEvent(new PointerEvent(type, {
  pointerId: 7, clientX: r.left + x + dx, clientY: r.top + y, button: 0, buttons,
  bubbles: true, cancelable: true, isPrimary: true}));
at("pointerdown", 0, 1);
for (let k = 1; k <= moves; k++) at("pointermove", 15 * k, 1);
at("pointerup", 15 * moves, 0);
"""


def poll(base, s, what, script, seconds):
    """Runs `script` in the session's page until it returns something, for `what`; exits
    naming it after `seconds`."""
    start = time.time()
    while True:
        value = call(base, "POST", s + "/execute/sync", {"script": script, "args": []})
        if value:
            return value
        if time.time() - start > seconds:
            sys.exit(f"element: timed out waiting for {what}")
        time.sleep(0.1)


def first_frame(args, handler, served):
    """--first-frame: the time from `src` set to the first frame, and with --compile-times
    each pipeline's compile time on a new browser's device."""
    with browser(handler, args.chromedriver, 300) as (base, s, origin):
        call(base, "POST", s + "/url", {"url": origin + "/test/first-frame.html"})
        ms = poll(base, s, "the model's first frame", "return window.firstFrame || window.failed", 600)
        if isinstance(ms, str):
            sys.exit(f"element: {ms}")
        print(f"element: {args.out}/sphere.glb, 640x480, from src set to the first frame drawn: "
              f"{ms['cold']:.0f} ms on a new element (module, device and pipelines included), "
              f"{ms['warm']:.0f} ms as a new src of a drawing element (cold, then warm: {ms['steps']})")
        if not args.compile_times:
            return
        # The pipelines, recorded in a page of their own (its first frame is not timed).
        call(base, "POST", s + "/url", {"url": origin + "/test/first-frame-recorded.html"})
        poll(base, s, "the recorded page's first frame", "return window.firstFrame || window.failed", 600)
        pipelines = call(base, "POST", s + "/execute/sync", {"script": "return window.pipelines", "args": []})
    served["/test/pipelines.json"] = ("application/json", json.dumps(pipelines).encode())
    with browser(handler, args.chromedriver, 300) as (base, s, origin):
        call(base, "POST", s + "/url", {"url": origin + "/test/compile.html"})
        times = poll(base, s, "the pipelines to compile", "return window.compiled || window.failed", 600)
        if isinstance(times, str):
            sys.exit(f"element: compiling the pipelines: {times}")
        total = sum(t for _, _, t in times)
        print(f"element: the first frame's {len(times)} pipelines compile in {total:.0f} ms, one after "
              "another on a new device: "
              + ", ".join(f"{entry} {t:.0f} ms" for entry, _, t in sorted(times, key=lambda t: -t[2])))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--package", default=os.path.join(WEB, "package"))
    parser.add_argument("--chromedriver", default=os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver"))
    parser.add_argument("--out", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "wirepass-element"),
                        help="where a snapshot that fails its comparison is saved")
    parser.add_argument("--first-frame", metavar="TRIANGLES", type=int,
                        help="time a sphere GLB of this many triangles from `src` set to its first frame")
    parser.add_argument("--compile-times", action="store_true",
                        help="with --first-frame: time the GPU process compiling each pipeline of that frame")
    args = parser.parse_args()
    if args.compile_times and not args.first_frame:
        sys.exit("element: --compile-times times the pipelines of --first-frame's frame: give both")
    package = os.path.abspath(args.package)
    if not os.path.exists(os.path.join(package, "wirepass-viewer.js")):
        sys.exit(f"element: {package}/wirepass-viewer.js is missing: run web/package.sh first")
    with open(os.path.join(WEB, "tests", "reference", "element.json")) as f:
        views = json.load(f)
    big = b""
    if args.first_frame:
        big, triangles = sphere_glb(args.first_frame)
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "sphere.glb"), "wb") as f:
            f.write(big)
        print(f"element: {args.out}/sphere.glb: {triangles} triangles, {len(big)} bytes")
    served = {
        "/test/page.html": ("text/html", page(views).encode()),
        "/test/no-webgpu.html": ("text/html", NO_WEBGPU.encode()),
        "/test/first-frame.html": ("text/html", FIRST_FRAME.encode()),
        "/test/first-frame-recorded.html": ("text/html", FIRST_FRAME.replace("<body>", "<body>" + RECORD_PIPELINES, 1).encode()),
        "/test/compile.html": ("text/html", COMPILE.encode()),
        "/test/removed.html": ("text/html", REMOVED.encode()),
        "/test/broken.glb": ("model/gltf-binary", b"glTF\x02\x00\x00\x00this is not a model"),
        "/test/model.glb": ("model/gltf-binary", big),
    }

    class Handler(http.server.SimpleHTTPRequestHandler):
        extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".js": "text/javascript", ".wasm": "application/wasm"}

        def translate_path(self, path):
            # /web/package/… is the package wherever it was built; the rest is the repository.
            prefix = "/web/package/"
            if path.startswith(prefix):
                return os.path.join(package, path[len(prefix):].split("?")[0])
            return super().translate_path(path)

        def do_GET(self):
            path = self.path.split("?")[0]
            if path in served:
                kind, body = served[path]
                self.send_response(200)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)
            else:
                super().do_GET()

        def log_message(self, *args):
            pass

    if args.first_frame:
        first_frame(args, functools.partial(Handler, directory=ROOT), served)
        return

    with browser(functools.partial(Handler, directory=ROOT), args.chromedriver, 300) as (base, s, origin):
        def run(script, *arguments):
            return call(base, "POST", s + "/execute/sync", {"script": script, "args": list(arguments)})

        def run_async(script, *arguments):
            return call(base, "POST", s + "/execute/async", {"script": script, "args": list(arguments)})

        def wait(what, script, seconds=240):
            return poll(base, s, what, script, seconds)

        call(base, "POST", s + "/url", {"url": origin + "/test/page.html"})
        events = "return window.events.filter(e => e.id === arguments[0] && e.type === arguments[1])"

        def of(id, kind):
            return run(events.replace("arguments[0]", json.dumps(id)).replace("arguments[1]", json.dumps(kind)))

        ids = [f"v{k}" for k in range(len(views))]
        for id, view in zip(ids, views):
            loaded = wait(f"{view['name']} to load",
                          f"return window.events.find(e => e.id === '{id}' && (e.type === 'load' || e.type === 'error'))")
            if loaded["type"] == "error":
                sys.exit(f"element: {view['name']}: {loaded['detail']['message']}")
            print(f"element: {view['name']}: loaded {loaded['detail']['name']}, {loaded['detail']['triangles']} triangles")
        for id in ["missing", "broken"]:
            wait(f"an error from #{id}", f"return window.events.some(e => e.id === '{id}' && e.type === 'error')")
        time.sleep(1.0)
        for id in ["missing", "broken"]:
            errors = of(id, "error")
            shown = run(f"return document.getElementById('{id}').shadowRoot.querySelector('.message.shown')?.textContent")
            message = errors[0]["detail"]["message"]
            print(f"element: #{id}: {len(errors)} error event: {message}")
            if len(errors) != 1 or of(id, "load"):
                sys.exit(f"element: #{id} raised {len(errors)} error events and {len(of(id, 'load'))} load events, not one error")
            if shown != message:
                sys.exit(f"element: #{id} shows {shown!r}, not its error {message!r}")
        if "404" not in of("missing", "error")[0]["detail"]["message"]:
            sys.exit("element: the 404's message does not say 404")
        if "broken.glb" not in of("broken", "error")[0]["detail"]["message"]:
            sys.exit("element: the broken file's message does not name it")

        def compare(id, name):
            d = run_async(COMPARE, id, f"/web/tests/reference/{name}.png")
            if "error" in d:
                sys.exit(f"element: {name}: {d['error']}")
            print(f"element: {name}: {d['over'] * 100:.3f} % of the pixels off by > 8/255, mean {d['mean']:.5f}")
            if d["over"] > 0.002 or d["mean"] > 0.002:
                saved = os.path.join(args.out, f"{name}-snapshot.png")
                os.makedirs(args.out, exist_ok=True)
                with open(saved, "wb") as f:
                    f.write(base64.b64decode(d["png"]))
                sys.exit(f"element: {name}: the snapshot differs from the native frame (saved to {saved})")

        for id, view in zip(ids, views):
            if not any(a["name"] == "hidden" for a in view["attributes"]):
                compare(id, view["name"])

        # A click at the listed pixel picks the ground truth's triangle.
        view = views[0]
        x, y = view["pick"]["pixel"]
        run(POINTER, ids[0], x + 0.5, y + 0.5, 0)
        pick = wait("a pick event", f"return window.events.find(e => e.id === '{ids[0]}' && e.type === 'pick')", 60)["detail"]
        print(f"element: pick at ({x}, {y}): instance {pick['instance']}, triangle {pick['triangle']}, point {pick.get('point')}")
        if [pick["instance"], pick["triangle"]] != [view["pick"]["instance"], view["pick"]["triangle"]]:
            sys.exit(f"element: picked {pick['instance']}/{pick['triangle']}, the ground truth shows {view['pick']['instance']}/{view['pick']['triangle']}")
        if len(pick["point"]) != 3 or len(pick["normal"]) != 3 or pick["pixel"] != [x, y]:
            sys.exit(f"element: the pick's detail lacks its point, normal or pixel: {pick}")

        # An attribute change redraws: hidden lines, as natively.
        for id, view in zip(ids, views):
            hidden = [a["value"] for a in view["attributes"] if a["name"] == "hidden"]
            if hidden:
                frames = run(f"return document.getElementById('{ids[0]}').frames")
                run(f"document.getElementById('{ids[0]}').setAttribute('hidden', '{hidden[0]}')")
                wait("a frame after the attribute change", f"return document.getElementById('{ids[0]}').frames > {frames}", 60)
                compare(ids[0], view["name"])

        # A drag turns the view; fit() brings the camera's view back.
        last = len(views) - 1
        frames = run(f"return document.getElementById('{ids[last]}').frames")
        run(POINTER, ids[last], 100, 100, 6)
        wait("a frame after a drag", f"return document.getElementById('{ids[last]}').frames > {frames}", 60)
        frames = run(f"return document.getElementById('{ids[last]}').frames")
        run(f"document.getElementById('{ids[last]}').fit()")
        wait("a frame after fit()", f"return document.getElementById('{ids[last]}').frames > {frames}", 60)
        compare(ids[last], views[last]["name"])

        svg = run_async("const done = arguments[0]; document.getElementById('v0').exportSvg().then(done, e => done(String(e)))")
        if "<path" not in svg:
            sys.exit(f"element: exportSvg() drew no lines: {svg[:200]!r}")

        # Nothing changes, nothing is drawn.
        count = "return [...document.querySelectorAll('wirepass-viewer')].map(e => e.frames)"
        before = run(count)
        time.sleep(1.5)
        after = run(count)
        print(f"element: frames drawn {after}; 1.5 s later the same: {before == after}")
        if before != after:
            sys.exit(f"element: frames were drawn while nothing changed: {before} -> {after}")

        # An attribute it cannot read: one error, saying which, and the view as it was.
        frames = run("return document.getElementById('v0').frames")
        run("document.getElementById('v0').setAttribute('line-width', '-2')")
        wait("an error for line-width=-2", "return window.events.some(e => e.id === 'v0' && e.type === 'error')", 30)
        time.sleep(0.5)
        errors = of("v0", "error")
        print(f"element: line-width=-2: {errors[0]['detail']['message']}")
        if len(errors) != 1 or "line-width" not in errors[0]["detail"]["message"]:
            sys.exit(f"element: line-width=-2 raised {errors}, not one error naming it")
        if run("return document.getElementById('v0').frames") != frames:
            sys.exit("element: an attribute it could not read redrew the view")

        # An element removed while the page's device opens raises nothing; put back, it
        # starts again and loads.
        call(base, "POST", s + "/url", {"url": origin + "/test/removed.html"})
        removed = wait("the element removed and put back", "return window.removed", 120)
        print(f"element: removed while starting: {removed['before']} events, {removed['frames']} frames; "
              f"put back: {removed['after']}")
        if removed["before"] != [] or removed["frames"] != 0 or removed["after"] != ["load"]:
            sys.exit(f"element: removed while starting it drew {removed['frames']} frames and raised "
                     f"{removed['before']}; put back, {removed['after']}")

        # The package's demo page, as a visitor opens it, with a model by ?model=.
        call(base, "POST", s + "/url", {"url": origin + f"/web/package/index.html?model=/{views[0]['src']}"})
        wait("the demo's two elements to draw",
             "const v = [...document.querySelectorAll('wirepass-viewer')]; "
             "return v.length === 2 && v.every(e => e.frames > 0)", 120)
        print("element: the demo page draws both its elements")

        # Without WebGPU: an error event and a message in the box.
        call(base, "POST", s + "/url", {"url": origin + "/test/no-webgpu.html"})
        message = wait("an error without WebGPU", "return window.events[0]", 60)
        shown = run("return document.getElementById('lone').shadowRoot.querySelector('.message.shown')?.textContent")
        print(f"element: without WebGPU: {message}")
        if "WebGPU" not in message or shown != message:
            sys.exit(f"element: without WebGPU the element said {message!r} and shows {shown!r}")
        print("element: ok")


if __name__ == "__main__":
    main()
