// <wirepass-viewer>: exact mesh wireframes on WebGPU in one tag.
//
//   <script type="module" src="wirepass-viewer/wirepass-viewer.js"></script>
//   <wirepass-viewer src="part.glb" edges="feature:30" hidden="dashed"></wirepass-viewer>
//
// Attributes (a change redraws): src, edges, outlines, hidden, line-width, line-color,
// background, camera, sections. Events: load, pick, error. Methods: snapshot(), exportSvg(),
// fit(). Every element of a page shares one GPU device, and draws only when something changed.
import init, { ElementView, ViewerDevice } from "./wirepass_web.js";

// The module's WebAssembly and the page's device, started by the first element and shared.
let device;
function sharedDevice() {
  device ??= init().then(() => ViewerDevice.open());
  return device;
}

const ATTRIBUTES = [
  "edges", "outlines", "hidden", "line-width", "line-color", "background", "camera", "sections",
];

const STYLE = `
/* \`hidden\` names the hidden-line style here: the element stays shown with it. */
:host, :host([hidden]) { display: block; position: relative; width: 300px; height: 150px;
  overflow: hidden; }
canvas { display: block; width: 100%; height: 100%; touch-action: none; }
.message { position: absolute; inset: 0; display: none; padding: 1em; box-sizing: border-box;
  font: 14px system-ui, sans-serif; color: #a00; background: rgba(255, 255, 255, 0.9); }
.message.shown { display: block; }
.progress { position: absolute; left: 0; bottom: 0; height: 3px; width: 0; background: #357;
  display: none; }
.progress.shown { display: block; }
`;

// Reads `url`'s body, reporting the bytes read and the total (0 where unknown).
async function fetchBytes(url, signal, progress) {
  const response = await fetch(url, { signal });
  if (!response.ok) {
    throw new Error(`${url}: ${response.status} ${response.statusText || "error"}`.trim());
  }
  const total = Number(response.headers.get("Content-Length")) || 0;
  if (!response.body) {
    return new Uint8Array(await response.arrayBuffer());
  }
  const reader = response.body.getReader();
  const parts = [];
  let read = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    parts.push(value);
    read += value.length;
    progress(read, total);
  }
  const bytes = new Uint8Array(read);
  let at = 0;
  for (const part of parts) {
    bytes.set(part, at);
    at += part.length;
  }
  return bytes;
}

// The external buffers a .gltf names (not `data:` URIs), fetched relative to it.
async function gltfBuffers(bytes, base, signal, progress) {
  let json;
  try {
    json = JSON.parse(new TextDecoder().decode(bytes));
  } catch (e) {
    throw new Error(`${base}: not glTF JSON (${e.message})`);
  }
  const uris = (json.buffers ?? [])
    .map((b) => b.uri)
    .filter((uri) => typeof uri === "string" && !uri.startsWith("data:"));
  const buffers = await Promise.all(
    uris.map((uri) => fetchBytes(new URL(uri, base), signal, progress)),
  );
  return [uris, buffers];
}

export class WirepassViewer extends HTMLElement {
  static observedAttributes = ["src", ...ATTRIBUTES];

  #view = null;
  #starting = null;
  #canvas;
  #message;
  #progress;
  #resize;
  #load = null;

  constructor() {
    super();
    const root = this.attachShadow({ mode: "open" });
    root.innerHTML = `<style>${STYLE}</style><canvas part="canvas"></canvas>` +
      `<div class="progress" part="progress"></div><div class="message" part="message"></div>`;
    this.#canvas = root.querySelector("canvas");
    this.#message = root.querySelector(".message");
    this.#progress = root.querySelector(".progress");
    this.#resize = new ResizeObserver(() => this.#view?.resize());
    // Every error, the view's and the element's, shows in the element's box.
    this.addEventListener("error", (e) => this.#say(e.detail?.message ?? "error"));
  }

  connectedCallback() {
    // A `src` set on the element before this module defined it is an own property that
    // hides the class's: pass it on.
    if (Object.hasOwn(this, "src")) {
      const src = this.src;
      delete this.src;
      this.src = src;
    }
    this.#resize.observe(this);
    this.#starting ??= this.#start();
  }

  disconnectedCallback() {
    this.#resize.disconnect();
    // Moved, not removed: it is connected again before this runs.
    queueMicrotask(() => {
      if (!this.isConnected && this.#view) {
        this.#load?.abort();
        this.#view.free();
        this.#view = null;
        this.#starting = null;
      }
    });
  }

  async #start() {
    // The download starts at once, beside the WebAssembly and the device.
    const src = this.getAttribute("src");
    const download = src === null ? null : this.#download(src);
    let gpu;
    try {
      const starting = performance.now();
      gpu = await sharedDevice();
      const opened = performance.now();
      performance.measure("wirepass-viewer: WebAssembly and device", { start: starting, end: opened });
      if (!this.isConnected) {
        // Removed while the device opened: a later connection starts again.
        download?.load.abort();
        this.#starting = null;
        return;
      }
      this.#view = new ElementView(gpu, this, this.#canvas);
      performance.measure("wirepass-viewer: view", { start: opened });
    } catch (e) {
      download?.load.abort();
      this.#fail(e);
      return;
    }
    for (const name of ATTRIBUTES) {
      if (this.hasAttribute(name)) this.#set(name, this.getAttribute(name));
    }
    const now = this.getAttribute("src");
    if (now === null) {
      download?.load.abort();
      this.#builtin();
    } else {
      // The GPU compiles the pipelines while the file arrives and is read.
      try {
        this.#view.warm_up(new URL(now, document.baseURI).pathname);
      } catch (e) {
        console.warn(e);
      }
      // `src` may have changed while the device opened.
      this.#show(now === src ? download : this.#download(now));
    }
  }

  #builtin() {
    try {
      this.#view.load_builtin();
    } catch (e) {
      this.#fail(e);
    }
  }

  attributeChangedCallback(name, old, value) {
    if (!this.#view || old === value) return;
    if (name === "src") {
      if (value === null) {
        this.#load?.abort();
        this.#builtin();
      } else {
        this.#open(value);
      }
    } else {
      this.#set(name, value);
    }
  }

  #set(name, value) {
    try {
      this.#view.set(name, value);
    } catch (e) {
      this.#fail(e);
    }
  }

  #open(src) {
    this.#show(this.#download(src));
  }

  // Starts fetching `src` (and a .gltf's buffers), ending any download before.
  #download(src) {
    this.#load?.abort();
    const load = (this.#load = new AbortController());
    this.#message.classList.remove("shown");
    const progress = (read, total) => {
      this.#progress.classList.add("shown");
      this.#progress.style.width = total ? `${(100 * read) / total}%` : "50%";
    };
    const files = (async () => {
      const url = new URL(src, document.baseURI);
      // Where the time to the first image goes, in the browser's performance timeline.
      const fetching = performance.now();
      const bytes = await fetchBytes(url, load.signal, progress);
      const name = decodeURIComponent(url.pathname.split("/").pop() || "model");
      const [uris, buffers] = name.toLowerCase().endsWith(".gltf")
        ? await gltfBuffers(bytes, url, load.signal, progress)
        : [[], []];
      performance.measure("wirepass-viewer: fetch", { start: fetching });
      return { name, bytes, uris, buffers };
    })();
    // Its failure is reported when it is shown (or not at all, once aborted).
    files.catch(() => {});
    return { load, files };
  }

  // Shows a download once it has arrived.
  async #show({ load, files }) {
    try {
      const { name, bytes, uris, buffers } = await files;
      if (load.signal.aborted || !this.#view) return;
      const reading = performance.now();
      this.#view.load(name, bytes, uris, buffers);
      const drawing = performance.now();
      performance.measure("wirepass-viewer: read and upload", { start: reading, end: drawing });
      // The preprocessing's steps end the reading, one after the other.
      const steps = this.#view.upload_steps();
      let start = drawing - steps.reduce((sum, [, ms]) => sum + ms, 0);
      for (const [step, ms] of steps) {
        performance.measure(`wirepass-viewer: ${step}`, { start, duration: ms });
        start += ms;
      }
      this.addEventListener(
        "load",
        () => performance.measure("wirepass-viewer: first frame", { start: drawing }),
        { once: true },
      );
    } catch (e) {
      if (!load.signal.aborted) this.#fail(e);
    } finally {
      if (this.#load === load) this.#progress.classList.remove("shown");
    }
  }

  #fail(e) {
    const message = e instanceof Error ? e.message : String(e);
    this.dispatchEvent(new CustomEvent("error", { detail: { message } }));
  }

  #say(message) {
    this.#message.textContent = message;
    this.#message.classList.add("shown");
  }

  async #ready() {
    await this.#starting;
    if (!this.#view) throw new Error("<wirepass-viewer> has no WebGPU view");
    return this.#view;
  }

  /** The current view as a PNG image. */
  async snapshot() {
    const view = await this.#ready();
    const rgba = await view.snapshot();
    const [w, h] = [view.width(), view.height()];
    const canvas = new OffscreenCanvas(w, h);
    canvas.getContext("2d").putImageData(new ImageData(new Uint8ClampedArray(rgba.buffer), w, h), 0, 0);
    return canvas.convertToBlob({ type: "image/png" });
  }

  /** The current view as an SVG drawing: its visible and hidden lines as vectors. */
  async exportSvg() {
    return (await this.#ready()).export_svg();
  }

  /** Frames the model again as the `camera` attribute has it. */
  fit() {
    this.#view?.fit();
  }

  /** Frames drawn so far (the element draws only when something changed). */
  get frames() {
    return this.#view?.frames() ?? 0;
  }

  get src() {
    return this.getAttribute("src");
  }

  set src(value) {
    if (value === null) this.removeAttribute("src");
    else this.setAttribute("src", value);
  }
}

if (!customElements.get("wirepass-viewer")) {
  customElements.define("wirepass-viewer", WirepassViewer);
}
