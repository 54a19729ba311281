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

mod gpu;
mod model;

use gpu::{Gpu, EDGES};
use model::Model;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{HtmlCanvasElement, HtmlElement, HtmlInputElement, HtmlSelectElement};
use wirepass::camera::Orbit;
use wirepass::{wgpu, SectionPlane, Style};

/// The page's state: what is shown, how, and the pointers on the canvas.
struct App {
    gpu: Gpu,
    canvas: HtmlCanvasElement,
    status: HtmlElement,
    model: Model,
    orbit: Orbit,
    style: Style,
    edges: usize,
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
        let read = {
            let mut app = self.app.borrow_mut();
            let app = &mut *app;
            let texture = app.gpu.offscreen(app.gpu.size());
            app.gpu
                .record(&texture, &app.model, &app.orbit, &app.style, &app.sections)
                .map_err(JsValue::from)?;
            app.gpu.read(&texture)
        };
        read.await.map_err(|e| {
            // What the device reported says why a readback failed.
            let mut all = self.app.borrow().gpu.take_errors();
            all.insert(0, e);
            JsValue::from(all.join("; "))
        })
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
        let gpu_object = js_sys::Reflect::get(&window.navigator(), &"gpu".into()).map_err(js)?;
        if gpu_object.is_undefined() {
            return Err(
                "This browser has no WebGPU (navigator.gpu is missing), which the \
                        viewer needs for its compute shaders; WebGL2 has none. Try a recent \
                        Chrome, Edge or Firefox, or Safari 26."
                    .into(),
            );
        }
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
        let size = canvas_size(&canvas);
        canvas.set_width(size.0);
        canvas.set_height(size.1);

        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas.clone()))
            .map_err(|e| format!("the canvas cannot show WebGPU: {e}"))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..options
            })
            .await
            .map_err(|e| {
                format!("This browser has WebGPU but gave no adapter ({e}): it may be switched off for this GPU or driver.")
            })?;
        let mut gpu = Gpu::new(&adapter, surface, size).await?;
        if let Some(name) =
            browser_adapter_name(&gpu_object, params.get("adapter").as_deref()).await
        {
            gpu.adapter = name;
        }
        let model = Model::builtin().map_err(|e| e.to_string())?;
        gpu.upload(&model, EDGES[0].1)?;
        let (lo, hi) = model.bounds();
        Ok(App {
            gpu,
            canvas,
            status,
            orbit: Orbit::framing(lo, hi),
            model,
            style: Style::default(),
            edges: 0,
            hidden: 0,
            sections: Vec::new(),
            pointers: Vec::new(),
            press: None,
            picked: None,
            pending: false,
            frames: 0,
            error: None,
        })
    }

    /// Draws a frame into the canvas, sized to its box on the page.
    fn draw(&mut self) {
        let size = canvas_size(&self.canvas);
        if (self.canvas.width(), self.canvas.height()) != size {
            self.canvas.set_width(size.0);
            self.canvas.set_height(size.1);
        }
        self.gpu.resize(size);
        let drawn = self
            .gpu
            .draw(&self.model, &self.orbit, &self.style, &self.sections);
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
            }
        }
    }

    fn show_status(&self) {
        let (w, h) = self.gpu.size();
        self.status.set_text_content(Some(&format!(
            "{}: {} triangles, {} edges, outlines {}, hidden {}, sections {}, width {:.1}; \
             {w}×{h} on {}",
            self.model.name,
            self.model.triangles(),
            EDGES[self.edges].0,
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
        let edges = EDGES[self.edges].1;
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

    fn show_error(&mut self, message: &str) {
        web_sys::console::error_1(&message.into());
        self.status.set_text_content(Some(message));
        self.error = Some(message.into());
    }

    fn set_hidden(&mut self, hidden: usize) {
        self.hidden = hidden % HIDDEN.len();
        self.style.hidden = HIDDEN[self.hidden].1.map(|pattern| wirepass::HiddenLines {
            pattern,
            ..wirepass::HiddenLines::default()
        });
    }

    fn set_edges(&mut self, edges: usize) {
        self.edges = edges % EDGES.len();
        if let Err(e) = self.gpu.upload(&self.model, EDGES[self.edges].1) {
            self.show_error(&e);
        }
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
    let loaded = Model::from_file(name, bytes).map_err(|e| format!("{name}: {e}"));
    show(app, loaded)
}

/// Shows `loaded`, framed anew, or its error.
fn show(app: &Shared, loaded: Result<Model, String>) -> Result<(), String> {
    let result = {
        let mut a = app.borrow_mut();
        let a = &mut *a;
        match loaded.and_then(|model| {
            let edges = EDGES[a.edges].1;
            a.gpu.upload(&model, edges).map(|()| model)
        }) {
            Ok(model) => {
                let (lo, hi) = model.bounds();
                a.orbit = Orbit::framing(lo, hi);
                a.model = model;
                a.error = None;
                Ok(())
            }
            Err(e) => {
                // The old model's meshes went with the failed upload: put them back.
                let restored = a.gpu.upload(&a.model, EDGES[a.edges].1);
                a.show_error(&e);
                restored.and(Err(e))
            }
        }
    };
    schedule(app);
    result
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
        let said = match read {
            Ok(read) => match read.await {
                Ok(ids) => {
                    let a = app.borrow();
                    a.gpu.describe_pick(&a.model, &ids, at)
                }
                Err(e) => Err(e.to_string()),
            },
            Err(e) => Err(e),
        };
        let mut a = app.borrow_mut();
        match said {
            Ok(words) => {
                a.status.set_text_content(Some(&format!("picked {words}")));
                a.picked = Some(words);
            }
            Err(e) => a.show_error(&format!("pick: {e}")),
        }
    });
}

/// Adds `handler` for `event` on `target` for the page's lifetime.
fn listen<E: JsCast>(
    target: &web_sys::EventTarget,
    event: &str,
    app: &Shared,
    handler: impl Fn(&Shared, E) + 'static,
) -> Result<(), JsValue> {
    let app = app.clone();
    let closure = Closure::<dyn Fn(web_sys::Event)>::new(move |e: web_sys::Event| {
        handler(&app, e.unchecked_into())
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
    on_select("edges", App::set_edges)?;
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
                        let next = a.edges + 1;
                        a.set_edges(next);
                        select("edges", a.edges);
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
