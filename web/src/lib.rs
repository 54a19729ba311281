//! The wirepass viewer page: the built-in scene, or a mesh file dropped on the page or
//! opened with its picker (`.glb`, `.gltf` with embedded buffers, `.obj`, `.stl`, `.ply`),
//! drawn by the deferred pass straight into a WebGPU canvas. Mouse and touch: drag orbits,
//! right or middle drag (or shift-drag, or two fingers) pans, the wheel (or a pinch) zooms,
//! a click (or tap) picks: the toolbar says what the pixel shows. "Export SVG" downloads
//! the view as a technical drawing (`wirepass::drawing`: its visible and hidden lines as
//! vectors).
//! Keys: `E` cycles the edges, `O` toggles outlines, `H` cycles the hidden lines (off,
//! dashed, dotted, solid), `+`/`-` change the line width, `S` adds a section plane through
//! the orbit's centre that cuts away the half nearer the eye (up to 6), `[`/`]` move the
//! last one along its normal, `Backspace` removes it.
//!
//! `?adapter=high-performance|low-power|fallback` asks the browser for another adapter.
//! [`Viewer`] is what the page's script gets from [`start`]; its `snapshot` and `model_name`
//! are the hooks the browser tests read the page through.
#![cfg(target_arch = "wasm32")]

mod element;
mod gpu;
mod model;
mod settings;

use gpu::{Gpu, EDGES};
use model::Model;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{HtmlCanvasElement, HtmlElement, HtmlInputElement, HtmlSelectElement};
use wirepass::camera::Orbit;
use wirepass::gpu::Location;
use wirepass::{wgpu, EdgeSelection, SectionPlane, Style};

/// The page's state: what is shown, how, and the pointers on the canvas.
struct App {
    gpu: Gpu,
    canvas: HtmlCanvasElement,
    /// The page's status line, where there is one.
    status: Option<HtmlElement>,
    /// The element that gets the view's `load`, `pick` and `error` events, where there is one.
    host: Option<HtmlElement>,
    model: Model,
    orbit: Orbit,
    /// The camera the view starts from ([`settings::orbit`]), kept for `fit`.
    camera: String,
    style: Style,
    /// The edges every mesh draws; `None`: each file's own.
    edges: Option<EdgeSelection>,
    /// Which of [`HIDDEN`] the style draws.
    hidden: usize,
    /// The section planes `S` placed.
    sections: Vec<SectionPlane>,
    /// Pointers down on the canvas: id, position, button.
    pointers: Vec<(i32, f64, f64, i16)>,
    /// Where the primary button went down, to tell a click (a pick) from a drag.
    press: Option<(i32, f64, f64)>,
    /// What the last click picked, in words.
    picked: Option<String>,
    /// A frame is requested and not drawn yet.
    pending: bool,
    /// A model was shown and no frame of it drawn yet: the next frame raises `load`.
    announce: bool,
    /// Nothing is shown yet: an element draws nothing until its first model is read.
    hold: bool,
    frames: u32,
    /// The last error shown on the page.
    error: Option<String>,
}

type Shared = Rc<RefCell<App>>;

/// The viewer a page started: the hooks its script (and the browser tests) use.
#[wasm_bindgen]
pub struct Viewer {
    app: Shared,
}

/// Builds the viewer inside `root`: controls, a canvas filling the rest, the built-in
/// scene. Where the browser has no WebGPU, or gives no adapter, it says so in `root` and
/// the promise rejects with the same message.
#[wasm_bindgen]
pub async fn start(root: HtmlElement) -> Result<Viewer, JsValue> {
    console_error_panic_hook::set_once();
    match App::new(&root).await {
        Ok(app) => {
            let app = Rc::new(RefCell::new(app));
            wire_events(&app, &root)?;
            schedule(&app);
            Ok(Viewer { app })
        }
        Err(message) => {
            let p = document()?.create_element("p")?;
            p.set_class_name("wirepass-error");
            p.set_text_content(Some(&message));
            root.replace_children_with_node_1(&p);
            Err(JsValue::from_str(&message))
        }
    }
}

#[wasm_bindgen]
impl Viewer {
    /// The current view drawn again into a texture of the canvas's size and format and read
    /// back: RGBA8, sRGB, row 0 at the top (`width × height × 4` bytes).
    pub async fn snapshot(&self) -> Result<Vec<u8>, JsValue> {
        snapshot(&self.app).await
    }

    /// The canvas's width in pixels.
    pub fn width(&self) -> u32 {
        self.app.borrow().gpu.size().0
    }

    /// The canvas's height in pixels.
    pub fn height(&self) -> u32 {
        self.app.borrow().gpu.size().1
    }

    /// The name of what is shown: a file's name or "the built-in scene".
    pub fn model_name(&self) -> String {
        self.app.borrow().model.name.clone()
    }

    /// Frames drawn into the canvas so far.
    pub fn frames(&self) -> u32 {
        self.app.borrow().frames
    }

    /// The last error the page showed (a file that could not be read, a device error).
    pub fn error(&self) -> Option<String> {
        self.app.borrow().error.clone()
    }

    /// What the last click on the canvas picked, in words (also shown in the toolbar).
    pub fn picked(&self) -> Option<String> {
        self.app.borrow().picked.clone()
    }

    /// How many section planes cut the model (`S` adds one, `Backspace` removes one).
    pub fn sections(&self) -> usize {
        self.app.borrow().sections.len()
    }

    /// The hidden-line style the page draws: off, dashed, dotted or solid.
    pub fn hidden(&self) -> String {
        HIDDEN[self.app.borrow().hidden].0.into()
    }

    /// The adapter the page runs on, as the browser names it.
    pub fn adapter(&self) -> String {
        self.app.borrow().gpu.adapter.clone()
    }

    /// The current view as an SVG drawing (`wirepass::drawing`), as "Export SVG" downloads
    /// it.
    pub fn export_svg(&self) -> Result<String, JsValue> {
        self.app.borrow().drawing_svg().map_err(JsValue::from)
    }

    /// Shows a mesh file from its bytes, as a dropped file is shown.
    pub async fn load(&self, name: String, bytes: Vec<u8>) -> Result<(), JsValue> {
        show_file(&self.app, &name, &bytes).map_err(JsValue::from)
    }

    /// Shows the built-in scene again.
    pub fn load_builtin(&self) -> Result<(), JsValue> {
        let model = Model::builtin().map_err(|e| JsValue::from_str(&e.to_string()))?;
        show(&self.app, Ok(model)).map_err(JsValue::from)
    }
}

impl App {
    async fn new(root: &HtmlElement) -> Result<App, String> {
        let js = |e: JsValue| format!("{e:?}");
        let window = web_sys::window().ok_or("no window")?;
        let gpu_object = webgpu_present()?;
        let search = window.location().search().map_err(js)?;
        let params = web_sys::UrlSearchParams::new_with_str(&search).map_err(js)?;
        let options = gpu::adapter_options(params.get("adapter").as_deref())?;

        let doc = document().map_err(js)?;
        let (controls, status) = controls(&doc).map_err(js)?;
        let canvas: HtmlCanvasElement = doc.create_element("canvas").map_err(js)?.unchecked_into();
        let style = canvas.style();
        for (k, v) in [
            ("display", "block"),
            ("width", "100%"),
            ("flex", "1 1 auto"),
            ("min-height", "0"),
            ("touch-action", "none"),
        ] {
            style.set_property(k, v).map_err(js)?;
        }
        let rs = root.style();
        for (k, v) in [("display", "flex"), ("flex-direction", "column")] {
            rs.set_property(k, v).map_err(js)?;
        }
        root.replace_children_with_node_2(&controls, &canvas);

        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let mut shared = gpu::Device::open(instance, options).await?;
        if let Some(name) =
            browser_adapter_name(&gpu_object, params.get("adapter").as_deref()).await
        {
            shared.name = name;
        }
        App::on(&shared, canvas, Some(status), None)
    }

    /// A view of the built-in scene on `canvas`, drawn by `shared`'s device; `status` (the
    /// page's toolbar) says what is shown, `host` (an element) gets the view's events.
    fn on(
        shared: &gpu::Device,
        canvas: HtmlCanvasElement,
        status: Option<HtmlElement>,
        host: Option<HtmlElement>,
    ) -> Result<App, String> {
        let size = canvas_size(&canvas);
        canvas.set_width(size.0);
        canvas.set_height(size.1);
        let mut gpu = Gpu::new(shared, canvas.clone(), size)?;
        let model = Model::builtin().map_err(|e| e.to_string())?;
        gpu.upload(&model, None)?;
        let (lo, hi) = model.bounds();
        Ok(App {
            gpu,
            canvas,
            status,
            host,
            orbit: Orbit::framing(lo, hi),
            camera: String::new(),
            model,
            style: Style::default(),
            edges: None,
            hidden: 0,
            sections: Vec::new(),
            pointers: Vec::new(),
            press: None,
            picked: None,
            pending: false,
            announce: false,
            hold: false,
            frames: 0,
            error: None,
        })
    }

    /// Draws a frame into the canvas, sized to its box on the page.
    fn draw(&mut self) {
        if self.hold {
            return;
        }
        let size = canvas_size(&self.canvas);
        if (self.canvas.width(), self.canvas.height()) != size {
            self.canvas.set_width(size.0);
            self.canvas.set_height(size.1);
        }
        self.gpu.resize(size);
        // A model's first frame: its recording in the page's performance timeline.
        let timeline = web_sys::window()
            .and_then(|w| w.performance())
            .filter(|_| self.announce);
        if let Some(p) = &timeline {
            let _ = p.mark("wirepass-viewer: recording");
        }
        let drawn = self
            .gpu
            .draw(&self.model, &self.orbit, &self.style, &self.sections);
        if let Some(p) = &timeline {
            let _ = p.measure_with_start_mark(
                "wirepass-viewer: record the frame",
                "wirepass-viewer: recording",
            );
        }
        let mut errors = self.gpu.take_errors();
        if let Err(e) = drawn {
            errors.push(e);
        }
        match errors.pop() {
            Some(e) => self.show_error(&e),
            None => {
                self.frames += 1;
                if self.error.is_none() {
                    self.show_status();
                }
                if std::mem::take(&mut self.announce) {
                    let detail = js_sys::Object::new();
                    set(&detail, "name", &self.model.name.as_str().into());
                    set(
                        &detail,
                        "triangles",
                        &(self.model.triangles() as f64).into(),
                    );
                    // `load` says the model is on screen: once the GPU has drawn the frame.
                    let done = gpu::work_done(&self.gpu.queue);
                    if let Some(host) = self.host.clone() {
                        wasm_bindgen_futures::spawn_local(async move {
                            done.await;
                            dispatch(&host, "load", detail.into());
                        });
                    }
                }
            }
        }
    }

    /// Raises `event` with `detail` on the host element, once the caller's borrow of the
    /// view has ended (its listeners may call the view).
    fn emit(&self, event: &str, detail: JsValue) {
        let Some(host) = self.host.clone() else {
            return;
        };
        let event = event.to_string();
        wasm_bindgen_futures::spawn_local(async move { dispatch(&host, &event, detail) });
    }

    fn show_status(&self) {
        let Some(status) = &self.status else {
            return;
        };
        let (w, h) = self.gpu.size();
        status.set_text_content(Some(&format!(
            "{}: {} triangles, {} edges, outlines {}, hidden {}, sections {}, width {:.1}; \
             {w}×{h} on {}",
            self.model.name,
            self.model.triangles(),
            settings::edges_name(self.edges),
            if self.style.outlines { "on" } else { "off" },
            HIDDEN[self.hidden].0,
            self.sections.len(),
            self.style.line_width,
            self.gpu.adapter,
        )));
    }

    /// The view, its model, style and sections as an SVG drawing: each mesh with the edges
    /// the page uploaded it with.
    fn drawing_svg(&self) -> Result<String, String> {
        use wirepass::drawing::{Drawing, Page};
        use wirepass::world::{Object, Shot, World, WorldMesh};
        let edges = self.edges;
        let meshes = self
            .model
            .meshes
            .iter()
            .enumerate()
            .map(|(k, (mesh, own))| {
                let (mesh, selection) = mesh.clone().resolve_edges(edges.or(*own));
                WorldMesh {
                    mesh: std::sync::Arc::new(mesh),
                    edges: selection,
                    name: format!("mesh {k}"),
                }
            })
            .collect();
        let world = World {
            meshes,
            objects: (self.model.instances.iter())
                .map(|&(m, transform)| Object::new(m, transform))
                .collect(),
            sections: self.sections.clone(),
        };
        let size = self.gpu.size();
        let shot = Shot {
            world: &world,
            view: self
                .orbit
                .camera()
                .to_view(f64::from(size.0) / f64::from(size.1)),
            style: &self.style,
            size,
        };
        let drawing = Drawing::new(&shot).map_err(|e| e.to_string())?;
        Ok(drawing.to_svg(&Page::pixels()))
    }

    /// Says what went wrong: in the status line, or as the host element's `error` event.
    fn show_error(&mut self, message: &str) {
        web_sys::console::error_1(&message.into());
        if let Some(status) = &self.status {
            status.set_text_content(Some(message));
        }
        let detail = js_sys::Object::new();
        set(&detail, "message", &message.into());
        self.emit("error", detail.into());
        self.error = Some(message.into());
    }

    fn set_hidden(&mut self, hidden: usize) {
        self.hidden = hidden % HIDDEN.len();
        self.style.hidden = HIDDEN[self.hidden].1.map(|pattern| wirepass::HiddenLines {
            pattern,
            ..wirepass::HiddenLines::default()
        });
    }

    /// Draws `edges` on every mesh (`None`: each file's own).
    fn set_edges(&mut self, edges: Option<EdgeSelection>) -> Result<(), String> {
        self.gpu.upload(&self.model, edges)?;
        self.edges = edges;
        Ok(())
    }

    /// The page's edge choice `index` of [`EDGES`].
    fn choose_edges(&mut self, index: usize) {
        if let Err(e) = self.set_edges(EDGES[index % EDGES.len()].1) {
            self.show_error(&e);
        }
    }

    /// The index in [`EDGES`] of the edges drawn (0 where the page offers no such choice).
    fn edge_index(&self) -> usize {
        EDGES.iter().position(|e| e.1 == self.edges).unwrap_or(0)
    }

    fn pointer_moved(&mut self, id: i32, x: f64, y: f64, shift: bool) {
        let Some(k) = self.pointers.iter().position(|p| p.0 == id) else {
            return;
        };
        let (_, px, py, button) = self.pointers[k];
        let height = f64::from(self.canvas.client_height().max(1));
        if self.pointers.len() >= 2 {
            // Two fingers: the midpoint pans, the spread zooms.
            let other = self.pointers[1 - k.min(1)];
            let spread =
                |ax: f64, ay: f64| ((ax - other.1).powi(2) + (ay - other.2).powi(2)).sqrt();
            let (before, after) = (spread(px, py), spread(x, y));
            if before > 1.0 && after > 1.0 {
                self.orbit.zoom((after / before).ln() / 0.9f64.recip().ln());
            }
            self.orbit.pan((x - px) * 0.5, (y - py) * 0.5, height);
        } else if button == 0 && !shift {
            self.orbit.rotate(x - px, y - py);
        } else {
            self.orbit.pan(x - px, y - py, height);
        }
        self.pointers[k] = (id, x, y, button);
    }
}

/// The adapter as the browser describes it (`GPUAdapterInfo`: vendor, architecture,
/// description), which wgpu leaves unnamed; asked for with the same options.
async fn browser_adapter_name(gpu: &JsValue, choice: Option<&str>) -> Option<String> {
    use js_sys::Reflect;
    let options = js_sys::Object::new();
    match choice {
        Some("fallback") => Reflect::set(&options, &"forceFallbackAdapter".into(), &true.into()),
        Some(power @ ("high-performance" | "low-power")) => {
            Reflect::set(&options, &"powerPreference".into(), &power.into())
        }
        _ => Ok(true),
    }
    .ok()?;
    let request: js_sys::Function = Reflect::get(gpu, &"requestAdapter".into())
        .ok()?
        .dyn_into()
        .ok()?;
    let promise: js_sys::Promise = request.call1(gpu, &options).ok()?.dyn_into().ok()?;
    let adapter = wasm_bindgen_futures::JsFuture::from(promise).await.ok()?;
    let info = Reflect::get(&adapter, &"info".into()).ok()?;
    let field = |name: &str| {
        Reflect::get(&info, &name.into())
            .ok()
            .and_then(|v| v.as_string())
            .filter(|s| !s.is_empty())
    };
    let words: Vec<String> = ["vendor", "architecture", "description"]
        .into_iter()
        .filter_map(field)
        .collect();
    (!words.is_empty()).then(|| words.join(" "))
}

/// The hidden-line styles the toolbar and `H` offer.
const HIDDEN: [(&str, Option<wirepass::LinePattern>); 4] = [
    ("off", None),
    (
        "dashed",
        Some(wirepass::LinePattern::Dashed {
            dash: 6.0,
            gap: 4.0,
        }),
    ),
    (
        "dotted",
        Some(wirepass::LinePattern::Dotted { spacing: 4.0 }),
    ),
    ("solid", Some(wirepass::LinePattern::Solid)),
];

/// The toolbar: edges, outlines, hidden lines, width, a file picker, and the status line.
fn controls(doc: &web_sys::Document) -> Result<(HtmlElement, HtmlElement), JsValue> {
    let bar: HtmlElement = doc.create_element("div")?.unchecked_into();
    bar.set_class_name("wirepass-controls");
    let options: String = EDGES
        .iter()
        .map(|(name, _)| format!("<option value=\"{name}\">{name}</option>"))
        .collect();
    let hidden: String = HIDDEN
        .iter()
        .map(|(name, _)| format!("<option value=\"{name}\">{name}</option>"))
        .collect();
    bar.set_inner_html(&format!(
        "<label>Edges <select name=\"edges\">{options}</select></label> \
         <label><input type=\"checkbox\" name=\"outlines\" checked> Outlines</label> \
         <label>Hidden <select name=\"hidden\">{hidden}</select></label> \
         <label>Width <input type=\"range\" name=\"width\" min=\"0.5\" max=\"8\" step=\"0.5\" \
         value=\"{}\"></label> \
         <label>Open <input type=\"file\" name=\"file\" \
         accept=\".glb,.gltf,.obj,.stl,.ply\"></label> \
         <button type=\"button\" name=\"export\">Export SVG</button> \
         <span class=\"wirepass-status\">starting…</span>",
        wirepass::style::DEFAULT_LINE_WIDTH
    ));
    let status = bar
        .query_selector(".wirepass-status")?
        .ok_or("no status")?
        .unchecked_into();
    Ok((bar, status))
}

/// Offers `text` to the user as a file `name` of type `mime`.
fn download(name: &str, text: &str, mime: &str) -> Result<(), JsValue> {
    let parts = js_sys::Array::of1(&JsValue::from_str(text));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let blob = web_sys::Blob::new_with_str_sequence_and_options(&parts, &options)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob)?;
    let link: web_sys::HtmlAnchorElement = document()?.create_element("a")?.unchecked_into();
    link.set_href(&url);
    link.set_download(name);
    link.click();
    web_sys::Url::revoke_object_url(&url)
}

fn document() -> Result<web_sys::Document, JsValue> {
    web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| "no document".into())
}

/// The canvas's box on the page in device pixels.
fn canvas_size(canvas: &HtmlCanvasElement) -> (u32, u32) {
    let ratio = web_sys::window().map_or(1.0, |w| w.device_pixel_ratio());
    let px = |css: i32| ((f64::from(css.max(1)) * ratio).round() as u32).max(1);
    (px(canvas.client_width()), px(canvas.client_height()))
}

/// Asks for a frame on the next animation frame, once however many events ask.
fn schedule(app: &Shared) {
    if std::mem::replace(&mut app.borrow_mut().pending, true) {
        return;
    }
    let weak = Rc::downgrade(app);
    let callback = Closure::once_into_js(move || {
        if let Some(app) = weak.upgrade() {
            let mut app = app.borrow_mut();
            app.pending = false;
            app.draw();
        }
    });
    if let Some(w) = web_sys::window() {
        let _ = w.request_animation_frame(callback.unchecked_ref());
    }
}

/// Replaces the model with a file's, framed anew; an unreadable file is an error on the
/// page and leaves the model as it was.
fn show_file(app: &Shared, name: &str, bytes: &[u8]) -> Result<(), String> {
    let loaded =
        Model::from_file(name, bytes, &model::Resources::new()).map_err(|e| format!("{name}: {e}"));
    show(app, loaded)
}

/// Shows `loaded`, framed anew (by the view's camera setting), or says why not; the model
/// stays as it was then.
fn show(app: &Shared, loaded: Result<Model, String>) -> Result<(), String> {
    let result = replace_model(app, loaded);
    if let Err(e) = &result {
        app.borrow_mut().show_error(e);
    }
    schedule(app);
    result
}

/// Replaces the model with `loaded`, framed anew; an error leaves the old one, and is
/// returned, not shown.
fn replace_model(app: &Shared, loaded: Result<Model, String>) -> Result<(), String> {
    let mut a = app.borrow_mut();
    let a = &mut *a;
    let model = loaded?;
    let orbit = settings::orbit(&a.camera, model.bounds())?;
    if let Err(e) = a.gpu.upload(&model, a.edges) {
        // The old model's meshes went with the failed upload: put them back.
        a.gpu.upload(&a.model, a.edges)?;
        return Err(e);
    }
    a.orbit = orbit;
    a.model = model;
    a.error = None;
    a.announce = true;
    a.hold = false;
    Ok(())
}

/// Reads a dropped or picked file and shows it.
fn open_file(app: &Shared, file: web_sys::File) {
    let app = app.clone();
    wasm_bindgen_futures::spawn_local(async move {
        let name = file.name();
        match wasm_bindgen_futures::JsFuture::from(file.array_buffer()).await {
            Ok(buffer) => {
                let bytes = js_sys::Uint8Array::new(&buffer).to_vec();
                let _ = show_file(&app, &name, &bytes);
            }
            Err(e) => app
                .borrow_mut()
                .show_error(&format!("{name}: the browser could not read it ({e:?})")),
        }
    });
}

/// Picks what the canvas shows at CSS position `(x, y)` and says so in the toolbar.
fn pick(app: &Shared, x: f64, y: f64) {
    let (at, read) = {
        let a = app.borrow();
        let (w, h) = a.gpu.size();
        let scale = |css: f64, px: u32, client: i32| {
            ((css * f64::from(px) / f64::from(client.max(1))).floor() as u32).min(px - 1)
        };
        let at = (
            scale(x.max(0.0), w, a.canvas.client_width()),
            scale(y.max(0.0), h, a.canvas.client_height()),
        );
        (at, a.gpu.read_pick(at))
    };
    let app = app.clone();
    wasm_bindgen_futures::spawn_local(async move {
        let found = match read {
            Ok(read) => match read.await {
                Ok(ids) => {
                    let a = app.borrow();
                    a.gpu.locate_pick(&a.model, &ids, at)
                }
                Err(e) => Err(e.to_string()),
            },
            Err(e) => Err(e),
        };
        let mut a = app.borrow_mut();
        match found {
            Ok(found) => {
                let words = pick_words(at, found.as_ref());
                if let Some(status) = &a.status {
                    status.set_text_content(Some(&format!("picked {words}")));
                }
                a.emit("pick", pick_detail(at, found.as_ref()));
                a.picked = Some(words);
            }
            Err(e) => a.show_error(&format!("pick: {e}")),
        }
    });
}

/// Raises the custom event `event` with `detail` on `host`.
fn dispatch(host: &HtmlElement, event: &str, detail: JsValue) {
    let init = web_sys::CustomEventInit::new();
    init.set_detail(&detail);
    if let Ok(e) = web_sys::CustomEvent::new_with_event_init_dict(event, &init) {
        let _ = host.dispatch_event(&e);
    }
}

/// The browser's `navigator.gpu`, or why there is none.
fn webgpu_present() -> Result<JsValue, String> {
    let window = web_sys::window().ok_or("no window")?;
    let gpu = js_sys::Reflect::get(&window.navigator(), &"gpu".into()).unwrap_or_default();
    if gpu.is_undefined() {
        return Err(
            "This browser has no WebGPU (navigator.gpu is missing), which the \
                    viewer needs for its compute shaders; WebGL2 has none. Try a recent \
                    Chrome, Edge or Firefox, or Safari 26."
                .into(),
        );
    }
    Ok(gpu)
}

/// `app`'s current view drawn again into a texture of the canvas's size and format and
/// read back: RGBA8, sRGB, row 0 at the top.
async fn snapshot(app: &Shared) -> Result<Vec<u8>, JsValue> {
    let read = {
        let mut a = app.borrow_mut();
        let a = &mut *a;
        let texture = a.gpu.offscreen(a.gpu.size());
        a.gpu
            .record(&texture, &a.model, &a.orbit, &a.style, &a.sections)
            .map_err(JsValue::from)?;
        a.gpu.read(&texture)
    };
    read.await.map_err(|e| {
        // What the device reported says why a readback failed.
        let mut all = app.borrow().gpu.take_errors();
        all.insert(0, e);
        JsValue::from(all.join("; "))
    })
}

/// What a pick at pixel `at` of `app`'s canvas found, in words.
fn pick_words(at: (u32, u32), found: Option<&(usize, Location)>) -> String {
    let Some((instance, l)) = found else {
        return format!("({}, {}): background", at.0, at.1);
    };
    let mut words = format!(
        "instance {instance}, triangle {} (polygon {}) at ({:.4}, {:.4}, {:.4})",
        l.triangle, l.polygon, l.point.x, l.point.y, l.point.z
    );
    if let Some(e) = l.edge {
        let [a, b] = e.vertices;
        words += &format!("; edge {a}-{b} at {:.1} px", e.distance_px);
    }
    if let Some(v) = l.vertex {
        words += &format!("; vertex {} at {:.1} px", v.vertex, v.distance_px);
    }
    words
}

/// What a pick at pixel `at` found, as the `pick` event's `detail`: `pixel`, and for a
/// surface `instance`, `triangle`, `polygon`, `point`, `normal`, `edge` (`vertices`,
/// `point`, `distance`, in pixels) and `vertex` (`index`, `position`, `distance`), the
/// last two `null` where nothing is within 8 pixels; `instance` is `null` on the
/// background.
fn pick_detail(at: (u32, u32), found: Option<&(usize, Location)>) -> JsValue {
    let detail = js_sys::Object::new();
    let xyz = |v: wirepass::glam::DVec3| -> JsValue {
        js_sys::Array::of3(&v.x.into(), &v.y.into(), &v.z.into()).into()
    };
    set(
        &detail,
        "pixel",
        &js_sys::Array::of2(&at.0.into(), &at.1.into()),
    );
    let Some((instance, l)) = found else {
        set(&detail, "instance", &JsValue::NULL);
        return detail.into();
    };
    set(&detail, "instance", &(*instance as f64).into());
    set(&detail, "triangle", &l.triangle.into());
    set(&detail, "polygon", &l.polygon.into());
    set(&detail, "point", &xyz(l.point));
    set(&detail, "normal", &xyz(l.normal));
    let edge = l.edge.map_or(JsValue::NULL, |e| {
        let o = js_sys::Object::new();
        let [a, b] = e.vertices;
        set(&o, "vertices", &js_sys::Array::of2(&a.into(), &b.into()));
        set(&o, "point", &xyz(e.point));
        set(&o, "distance", &e.distance_px.into());
        o.into()
    });
    set(&detail, "edge", &edge);
    let vertex = l.vertex.map_or(JsValue::NULL, |v| {
        let o = js_sys::Object::new();
        set(&o, "index", &v.vertex.into());
        set(&o, "position", &xyz(v.position));
        set(&o, "distance", &v.distance_px.into());
        o.into()
    });
    set(&detail, "vertex", &vertex);
    detail.into()
}

/// Sets `object[key] = value` (on a fresh object, which cannot fail).
fn set(object: &js_sys::Object, key: &str, value: &JsValue) {
    let _ = js_sys::Reflect::set(object, &key.into(), value);
}

/// Adds `handler` for `event` on `target` for as long as the view lives (the listener holds
/// no reference that keeps a removed element's view alive).
fn listen<E: JsCast>(
    target: &web_sys::EventTarget,
    event: &str,
    app: &Shared,
    handler: impl Fn(&Shared, E) + 'static,
) -> Result<(), JsValue> {
    let app = Rc::downgrade(app);
    let closure = Closure::<dyn Fn(web_sys::Event)>::new(move |e: web_sys::Event| {
        if let Some(app) = app.upgrade() {
            handler(&app, e.unchecked_into())
        }
    });
    target.add_event_listener_with_callback(event, closure.as_ref().unchecked_ref())?;
    closure.forget();
    Ok(())
}

/// Listens to the canvas's pointer and wheel, files dropped or chosen, the toolbar, the
/// window's size and the keys.
fn wire_events(app: &Shared, root: &HtmlElement) -> Result<(), JsValue> {
    wire_pointer(app)?;
    wire_files(app, root)?;
    wire_toolbar(app, root)?;
    wire_keys(app, root)
}

/// Orbit, pan and zoom by pointer, pinch and wheel; a click picks.
fn wire_pointer(app: &Shared) -> Result<(), JsValue> {
    let canvas: web_sys::EventTarget = app.borrow().canvas.clone().into();
    listen(
        &canvas,
        "pointerdown",
        app,
        |app, e: web_sys::PointerEvent| {
            let mut a = app.borrow_mut();
            let _ = a.canvas.set_pointer_capture(e.pointer_id());
            let p = (
                e.pointer_id(),
                f64::from(e.offset_x()),
                f64::from(e.offset_y()),
                e.button(),
            );
            a.press = (p.3 == 0 && a.pointers.is_empty()).then_some((p.0, p.1, p.2));
            a.pointers.retain(|q| q.0 != p.0);
            a.pointers.push(p);
            e.prevent_default();
        },
    )?;
    listen(
        &canvas,
        "pointermove",
        app,
        |app, e: web_sys::PointerEvent| {
            let (x, y) = (f64::from(e.offset_x()), f64::from(e.offset_y()));
            let moved = {
                let mut a = app.borrow_mut();
                let before = a.orbit;
                a.pointer_moved(e.pointer_id(), x, y, e.shift_key());
                a.orbit != before
            };
            if moved {
                schedule(app);
            }
        },
    )?;
    for end in ["pointerup", "pointercancel"] {
        listen(&canvas, end, app, |app, e: web_sys::PointerEvent| {
            let (x, y) = (f64::from(e.offset_x()), f64::from(e.offset_y()));
            let click = {
                let mut a = app.borrow_mut();
                a.pointers.retain(|p| p.0 != e.pointer_id());
                let press = a.press.take();
                e.type_() == "pointerup"
                    && press.is_some_and(|(id, px, py)| {
                        id == e.pointer_id() && (x - px).abs() < 3.0 && (y - py).abs() < 3.0
                    })
            };
            if click {
                pick(app, x, y);
            }
        })?;
    }
    listen(&canvas, "wheel", app, |app, e: web_sys::WheelEvent| {
        e.prevent_default();
        let lines = match e.delta_mode() {
            web_sys::WheelEvent::DOM_DELTA_PIXEL => e.delta_y() / 100.0,
            web_sys::WheelEvent::DOM_DELTA_LINE => e.delta_y() / 3.0,
            _ => e.delta_y(),
        };
        app.borrow_mut().orbit.zoom(-lines);
        schedule(app);
    })?;
    listen(&canvas, "contextmenu", app, |_, e: web_sys::Event| {
        e.prevent_default()
    })
}

/// The control named `name` in the page's toolbar.
fn control(root: &HtmlElement, name: &str) -> Result<web_sys::EventTarget, JsValue> {
    let found = root.query_selector(&format!("[name={name}]"))?;
    found
        .map(Into::into)
        .ok_or_else(|| JsValue::from_str(&format!("no control {name}")))
}

/// A file dropped on the page or chosen in the toolbar opens.
fn wire_files(app: &Shared, root: &HtmlElement) -> Result<(), JsValue> {
    let root_target: web_sys::EventTarget = root.clone().into();
    listen(&root_target, "dragover", app, |_, e: web_sys::DragEvent| {
        e.prevent_default()
    })?;
    listen(&root_target, "drop", app, |app, e: web_sys::DragEvent| {
        e.prevent_default();
        if let Some(file) = e
            .data_transfer()
            .and_then(|d| d.files())
            .and_then(|f| f.get(0))
        {
            open_file(app, file);
        }
    })?;
    listen(
        &control(root, "file")?,
        "change",
        app,
        |app, e: web_sys::Event| {
            let input: Option<HtmlInputElement> = e.target().and_then(|t| t.dyn_into().ok());
            if let Some(file) = input.and_then(|i| i.files()).and_then(|f| f.get(0)) {
                open_file(app, file);
            }
        },
    )
}

/// The toolbar's export button, selects, check box and width slider.
fn wire_toolbar(app: &Shared, root: &HtmlElement) -> Result<(), JsValue> {
    listen(
        &control(root, "export")?,
        "click",
        app,
        |app, _: web_sys::Event| {
            let drawn = app.borrow().drawing_svg();
            let saved = drawn.and_then(|svg| {
                download("wirepass-drawing.svg", &svg, "image/svg+xml")
                    .map_err(|e| format!("the drawing could not be saved: {e:?}"))
            });
            if let Err(e) = saved {
                app.borrow_mut().show_error(&format!("Export SVG: {e}"));
            }
        },
    )?;
    // A select of the toolbar sets what `apply` sets to its selected index.
    let on_select = |name: &str, apply: fn(&mut App, usize)| {
        listen(
            &control(root, name)?,
            "change",
            app,
            move |app, e: web_sys::Event| {
                let select: Option<HtmlSelectElement> = e.target().and_then(|t| t.dyn_into().ok());
                if let Some(select) = select {
                    apply(
                        &mut app.borrow_mut(),
                        select.selected_index().max(0) as usize,
                    );
                    schedule(app);
                }
            },
        )
    };
    on_select("edges", App::choose_edges)?;
    on_select("hidden", App::set_hidden)?;
    listen(
        &control(root, "outlines")?,
        "change",
        app,
        |app, e: web_sys::Event| {
            let input: Option<HtmlInputElement> = e.target().and_then(|t| t.dyn_into().ok());
            if let Some(input) = input {
                app.borrow_mut().style.outlines = input.checked();
                schedule(app);
            }
        },
    )?;
    listen(
        &control(root, "width")?,
        "input",
        app,
        |app, e: web_sys::Event| {
            let input: Option<HtmlInputElement> = e.target().and_then(|t| t.dyn_into().ok());
            if let Some(width) = input.and_then(|i| i.value().parse::<f32>().ok()) {
                app.borrow_mut().style.line_width = width;
                schedule(app);
            }
        },
    )
}

/// A resize redraws; the keys change the style, the edges and the section planes, and keep
/// the toolbar in step.
fn wire_keys(app: &Shared, root: &HtmlElement) -> Result<(), JsValue> {
    let window: web_sys::EventTarget = web_sys::window().ok_or("no window")?.into();
    listen(&window, "resize", app, |app, _: web_sys::Event| {
        schedule(app)
    })?;
    let root_for_keys = root.clone();
    listen(
        &window,
        "keydown",
        app,
        move |app, e: web_sys::KeyboardEvent| {
            let sync = |name: &str, apply: &dyn Fn(&web_sys::Element)| {
                if let Ok(Some(el)) = root_for_keys.query_selector(&format!("[name={name}]")) {
                    apply(&el);
                }
            };
            let select = |name: &str, index: usize| {
                sync(name, &|el| {
                    el.unchecked_ref::<HtmlSelectElement>()
                        .set_selected_index(index as i32)
                })
            };
            {
                let mut a = app.borrow_mut();
                match e.key().as_str() {
                    "e" | "E" => {
                        let next = a.edge_index() + 1;
                        a.choose_edges(next);
                        select("edges", a.edge_index());
                    }
                    "h" | "H" => {
                        let next = a.hidden + 1;
                        a.set_hidden(next);
                        select("hidden", a.hidden);
                    }
                    "o" | "O" => {
                        a.style.outlines = !a.style.outlines;
                        let on = a.style.outlines;
                        sync("outlines", &|el| {
                            el.unchecked_ref::<HtmlInputElement>().set_checked(on)
                        });
                    }
                    "s" | "S" if a.sections.len() < wirepass::MAX_SECTIONS => {
                        let plane = SectionPlane::across(&a.orbit);
                        a.sections.push(plane);
                    }
                    k @ ("[" | "]") => {
                        let steps = if k == "]" { 1.0 } else { -1.0 };
                        let orbit = a.orbit;
                        if let Some(plane) = a.sections.last_mut() {
                            *plane = plane.nudged(&orbit, steps);
                        }
                    }
                    "Backspace" => {
                        a.sections.pop();
                    }
                    "+" | "=" | "-" => {
                        let step = if e.key() == "-" { -0.5 } else { 0.5 };
                        a.style.line_width = (a.style.line_width + step).clamp(0.5, 8.0);
                        let w = a.style.line_width.to_string();
                        sync("width", &|el| {
                            el.unchecked_ref::<HtmlInputElement>().set_value(&w)
                        });
                    }
                    _ => return,
                }
            }
            schedule(app);
        },
    )?;
    Ok(())
}
