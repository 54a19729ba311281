//! The Rust side of the `<wirepass-viewer>` custom element (`web/element/wirepass-viewer.js`
//! defines the element): one [`ViewerDevice`] for every element of a page, and one
//! [`ElementView`] per element, drawing into the canvas of its shadow root. The element's
//! script fetches files and sets attributes; the view parses them ([`crate::settings`]),
//! draws only when something changed, and raises `load`, `pick` and `error` on the element.

use crate::gpu::Device;
use crate::model::{Model, Resources};
use crate::settings;
use crate::{canvas_size, replace_model, schedule, wire_pointer, App, Shared};
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use web_sys::{HtmlCanvasElement, HtmlElement};
use wirepass::camera::Orbit;
use wirepass::{wgpu, EdgeSelection};

/// The WebGPU device the page's elements share: one adapter, one device, one queue.
#[wasm_bindgen]
pub struct ViewerDevice {
    device: Rc<Device>,
}

#[wasm_bindgen]
impl ViewerDevice {
    /// Opens the browser's default adapter with `wgpu::Limits::default()`; rejects, saying
    /// why, where the browser has no WebGPU or gives no adapter.
    pub async fn open() -> Result<ViewerDevice, JsValue> {
        console_error_panic_hook::set_once();
        crate::webgpu_present().map_err(|e| JsValue::from_str(&e))?;
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let device = Device::open(instance, wgpu::RequestAdapterOptions::default()).await?;
        Ok(ViewerDevice {
            device: Rc::new(device),
        })
    }

    /// The adapter, as the browser names it.
    pub fn adapter(&self) -> String {
        self.device.name.clone()
    }
}

/// One element's view: its canvas, model, camera and style.
#[wasm_bindgen]
pub struct ElementView {
    app: Shared,
}

#[wasm_bindgen]
impl ElementView {
    /// A view drawn into `canvas` (sized by its box) on `device`, raising its events on
    /// `host`; it draws nothing until it is given a model ([`load`](Self::load) or
    /// [`load_builtin`](Self::load_builtin)).
    #[wasm_bindgen(constructor)]
    pub fn new(
        device: &ViewerDevice,
        host: HtmlElement,
        canvas: HtmlCanvasElement,
    ) -> Result<ElementView, JsValue> {
        let mut app = App::on(&device.device, canvas, None, Some(host))?;
        app.hold = true;
        let app = Rc::new(RefCell::new(app));
        wire_pointer(&app)?;
        Ok(ElementView { app })
    }

    /// Shows the file `name` from its bytes (a `.gltf`'s external buffers in `uris` and
    /// `buffers`, pairwise), framed by the camera setting; `load` follows its first frame.
    /// An unreadable file rejects with one line saying why, and the model stays.
    pub fn load(
        &self,
        name: &str,
        bytes: &[u8],
        uris: Vec<String>,
        buffers: Vec<js_sys::Uint8Array>,
    ) -> Result<(), JsValue> {
        let resources: Resources = uris
            .into_iter()
            .zip(buffers.iter().map(|b| b.to_vec()))
            .collect();
        let loaded = Model::from_file(name, bytes, &resources).map_err(|e| e.to_string());
        let shown = replace_model(&self.app, loaded);
        schedule(&self.app);
        Ok(shown?)
    }

    /// Shows the built-in scene again.
    pub fn load_builtin(&self) -> Result<(), JsValue> {
        let shown = replace_model(&self.app, Model::builtin().map_err(|e| e.to_string()));
        schedule(&self.app);
        Ok(shown?)
    }

    /// Sets attribute `name` (`edges`, `outlines`, `hidden`, `line-width`, `line-color`,
    /// `background`, `camera`, `sections`) to `value` (`None`: removed, the default) and
    /// redraws; a value it cannot read rejects with one line and changes nothing.
    pub fn set(&self, name: &str, value: Option<String>) -> Result<(), JsValue> {
        let set = {
            let mut a = self.app.borrow_mut();
            let v = value.as_deref();
            let text = v.unwrap_or("");
            match name {
                "edges" => settings::edges(text).and_then(|e| a.set_edges(e)),
                "camera" => settings::orbit(text, a.model.bounds()).map(|orbit| {
                    a.orbit = orbit;
                    a.camera = text.to_string();
                }),
                "sections" => settings::sections(text).map(|s| a.sections = s),
                other => settings::apply_style(&mut a.style, other, v).unwrap_or_else(|| {
                    Err(format!("{other} is not an attribute of <wirepass-viewer>"))
                }),
            }
        };
        set?;
        schedule(&self.app);
        Ok(())
    }

    /// Draws a small frame in the current style offscreen, so that the browser builds and
    /// compiles the pipelines while the element fetches and reads the file `name`: with the
    /// edges such a file likely draws (each triangle's own where its format has no polygons
    /// and the element draws the file's edges, which decides which pipelines a frame uses).
    pub fn warm_up(&self, name: &str) -> Result<(), JsValue> {
        let mut a = self.app.borrow_mut();
        let a = &mut *a;
        let ext = name.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
        let likely = a.edges.unwrap_or(match ext.as_str() {
            "glb" | "gltf" | "stl" => EdgeSelection::All,
            _ => EdgeSelection::Polygon,
        });
        Ok(a.gpu
            .warm_up(&a.model, (a.edges, likely), &a.orbit, &a.style)?)
    }

    /// Frames the model again as the camera setting has it, undoing orbit, pan and zoom.
    pub fn fit(&self) -> Result<(), JsValue> {
        {
            let mut a = self.app.borrow_mut();
            a.orbit = settings::orbit(&a.camera, a.model.bounds())
                .unwrap_or_else(|_| Orbit::framing(a.model.bounds().0, a.model.bounds().1));
        }
        schedule(&self.app);
        Ok(())
    }

    /// Redraws at the canvas's new size (the element's `ResizeObserver` calls it).
    pub fn resize(&self) {
        let (size, drawn) = {
            let a = self.app.borrow();
            (canvas_size(&a.canvas), a.gpu.size())
        };
        if size != drawn {
            schedule(&self.app);
        }
    }

    /// The current view read back: RGBA8, sRGB, row 0 at the top (`width × height × 4`
    /// bytes).
    pub async fn snapshot(&self) -> Result<Vec<u8>, JsValue> {
        crate::snapshot(&self.app).await
    }

    /// The canvas's width in pixels.
    pub fn width(&self) -> u32 {
        self.app.borrow().gpu.size().0
    }

    /// The canvas's height in pixels.
    pub fn height(&self) -> u32 {
        self.app.borrow().gpu.size().1
    }

    /// The current view as an SVG drawing (`wirepass::drawing`): its visible and hidden
    /// lines as vectors.
    pub fn export_svg(&self) -> Result<String, JsValue> {
        Ok(self.app.borrow().drawing_svg()?)
    }

    /// Where the model's preprocessing went: `[step, milliseconds]` pairs in order.
    pub fn upload_steps(&self) -> js_sys::Array {
        let a = self.app.borrow();
        a.gpu
            .upload_steps()
            .into_iter()
            .map(|(name, ms)| js_sys::Array::of2(&name.into(), &ms.into()))
            .collect()
    }

    /// Frames drawn so far: the element draws only when something changed.
    pub fn frames(&self) -> u32 {
        self.app.borrow().frames
    }
}
