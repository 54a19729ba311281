// Types of the <wirepass-viewer> element (wirepass-viewer.js).

/** `detail` of the `pick` event: what the clicked pixel shows, exactly. */
export interface WirepassPickDetail {
  /** The pixel of the canvas, x and y from the top left. */
  pixel: [number, number];
  /** The picked instance (its index in the file's scene), `null` on the background. */
  instance: number | null;
  /** The triangle, in the file's order. */
  triangle?: number;
  /** The file's polygon (face) that triangle belongs to. */
  polygon?: number;
  /** Where the ray through the pixel's centre meets the triangle, world space. */
  point?: [number, number, number];
  /** The triangle's unit normal on the side the eye sees. */
  normal?: [number, number, number];
  /** The drawn edge nearest the pixel within 8 pixels: its two vertices, its nearest point
   * (world space) and its distance on screen in pixels. */
  edge?: { vertices: [number, number]; point: [number, number, number]; distance: number } | null;
  /** The vertex nearest the pixel within 8 pixels. */
  vertex?: { index: number; position: [number, number, number]; distance: number } | null;
}

/** `detail` of the `load` event: the model now shown, after its first frame. */
export interface WirepassLoadDetail {
  name: string;
  triangles: number;
}

/** `detail` of the `error` event: one line saying what went wrong (also shown in the box). */
export interface WirepassErrorDetail {
  message: string;
}

export interface WirepassViewerEventMap extends HTMLElementEventMap {
  load: CustomEvent<WirepassLoadDetail>;
  pick: CustomEvent<WirepassPickDetail>;
  error: CustomEvent<WirepassErrorDetail>;
}

/**
 * `<wirepass-viewer>`: attributes `src` (.glb, .gltf with its buffers beside it, .obj, .stl,
 * .ply), `edges` (file, polygon, feature[:DEG], all), `outlines` (present: on; "false" or
 * "off": off), `hidden` (off, solid, dashed[:D,G], dotted[:S]), `line-width` (pixels),
 * `line-color` and `background` (#rrggbb[aa]), `camera` (front, back, left, right, top,
 * bottom, iso, or "YAW PITCH [DISTANCE]"), `sections` ("PX,PY,PZ,NX,NY,NZ; …").
 */
export class WirepassViewer extends HTMLElement {
  /** The model's URL (the `src` attribute). */
  src: string | null;
  /** Frames drawn so far: the element draws only when something changed. */
  readonly frames: number;
  /** The current view as a PNG image. */
  snapshot(): Promise<Blob>;
  /** The current view as an SVG drawing of its visible and hidden lines. */
  exportSvg(): Promise<string>;
  /** Frames the model again as the `camera` attribute has it. */
  fit(): void;

  addEventListener<K extends keyof WirepassViewerEventMap>(
    type: K,
    listener: (this: WirepassViewer, ev: WirepassViewerEventMap[K]) => unknown,
    options?: boolean | AddEventListenerOptions,
  ): void;
  addEventListener(
    type: string,
    listener: EventListenerOrEventListenerObject,
    options?: boolean | AddEventListenerOptions,
  ): void;
  removeEventListener<K extends keyof WirepassViewerEventMap>(
    type: K,
    listener: (this: WirepassViewer, ev: WirepassViewerEventMap[K]) => unknown,
    options?: boolean | EventListenerOptions,
  ): void;
  removeEventListener(
    type: string,
    listener: EventListenerOrEventListenerObject,
    options?: boolean | EventListenerOptions,
  ): void;
}

declare global {
  interface HTMLElementTagNameMap {
    "wirepass-viewer": WirepassViewer;
  }
}
