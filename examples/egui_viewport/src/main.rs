//! wirepass in an egui app: the deferred pass draws a mesh with its exact wireframe into the
//! central panel of an eframe window through egui-wgpu's paint callback — the pass's compute
//! work in `prepare`, its composite into egui's own render pass in `paint` — with a side
//! panel of the frame's settings. Drag to orbit, right or middle drag to pan, scroll to zoom.
//!
//! ```sh
//! cargo run --release -p wirepass-egui-viewport -- [MESH] [--frames N --screenshot OUT.png]
//! ```
//!
//! `MESH` is an OBJ, STL, PLY or glTF file (default: the built-in scene). With `--frames N`
//! the app closes after N frames; with `--screenshot` it first saves the window and checks
//! the panel's pixels against the same frame drawn offscreen into a texture of egui's format.

use eframe::egui;
use egui_wgpu::{CallbackResources, CallbackTrait, ScreenDescriptor};
use std::path::PathBuf;
use wirepass::camera::Orbit;
use wirepass::glam::{DMat4, DVec3};
use wirepass::gpu::{Composite, MeshId, RenderTarget};
use wirepass::{
    wgpu, DeferredPass, EdgeSelection, HiddenLines, Instance, LinePattern, Mesh, MeshStore,
    OutputTarget, PassOptions, PreparedFrame, Scene, Style,
};

type AnyError = Box<dyn std::error::Error>;

/// The command line.
#[derive(Default)]
struct Args {
    mesh: Option<PathBuf>,
    frames: Option<u64>,
    screenshot: Option<PathBuf>,
}

fn args() -> Result<Args, String> {
    let mut a = Args::default();
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--frames" => {
                let v = value()?;
                a.frames = Some(
                    v.parse()
                        .map_err(|_| format!("--frames {v:?}: not a count"))?,
                )
            }
            "--screenshot" => a.screenshot = Some(value()?.into()),
            flag if flag.starts_with("--") => return Err(format!("unknown option {flag}")),
            path => a.mesh = Some(path.into()),
        }
    }
    if a.screenshot.is_some() && a.frames.is_none() {
        return Err("--screenshot needs --frames N".into());
    }
    Ok(a)
}

/// The meshes and their placements, as loaded.
struct Model {
    meshes: Vec<Mesh>,
    placed: Vec<(usize, DMat4)>,
}

impl Model {
    fn load(path: Option<&PathBuf>) -> Result<Model, AnyError> {
        Ok(match path {
            None => {
                let parts = wirepass::mesh::default_parts()?;
                Model {
                    placed: (0..parts.len()).map(|i| (i, parts[i].1)).collect(),
                    meshes: parts.into_iter().map(|(m, _)| m).collect(),
                }
            }
            Some(p) => Model {
                meshes: vec![wirepass::mesh::load(p)?],
                placed: vec![(0, DMat4::IDENTITY)],
            },
        })
    }

    fn bounds(&self) -> (DVec3, DVec3) {
        let boxes = (self.placed.iter()).map(|&(m, t)| self.meshes[m].placed_bounds(t));
        boxes.fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        )
    }

    fn triangles(&self) -> usize {
        let count = |&(m, _): &(usize, DMat4)| self.meshes[m].triangle_count();
        self.placed.iter().map(count).sum()
    }
}

/// What lives with egui's renderer (its callback resources): the pass, the meshes on the
/// GPU, and the frame `prepare` encoded for `paint` to draw.
struct Viewport {
    pass: DeferredPass,
    store: MeshStore,
    ids: Vec<MeshId>,
    instances: Vec<Instance>,
    frame: Option<PreparedFrame>,
    error: Option<String>,
}

impl Viewport {
    /// Uploads `model`'s meshes drawing `edges`, replacing those uploaded before.
    fn upload(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &Model,
        edges: EdgeSelection,
    ) -> wirepass::Result<()> {
        self.frame = None;
        for id in self.ids.drain(..) {
            self.store.remove(id)?;
        }
        for mesh in &model.meshes {
            let id = self.store.insert(device, queue, mesh, edges)?;
            self.ids.push(id);
        }
        self.instances = (model.placed.iter())
            .map(|&(m, transform)| Instance::new(self.ids[m], transform))
            .collect();
        Ok(())
    }

    /// Prepares and encodes the frame of `shot` at `size` pixels for the host's render pass.
    fn encode(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        shot: &Shot,
        size: (u32, u32),
    ) -> wirepass::Result<PreparedFrame> {
        let aspect = f64::from(size.0) / f64::from(size.1);
        let view = shot.orbit.camera().to_view(aspect);
        let scene = Scene::borrowed(view, &self.instances);
        let frame = self
            .pass
            .prepare(device, &self.store, &scene, &shot.style, size)?;
        let target = OutputTarget::RenderPass;
        self.pass
            .encode(device, encoder, &self.store, &frame, target)?;
        Ok(frame)
    }
}

/// What one frame of the panel shows.
#[derive(Clone)]
struct Shot {
    orbit: Orbit,
    style: Style,
}

/// The paint callback of the central panel's rectangle.
struct Draw {
    rect: egui::Rect,
    shot: Shot,
}

impl CallbackTrait for Draw {
    fn prepare(
        &self,
        device: &wgpu::Device,
        _queue: &wgpu::Queue,
        screen: &ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(viewport) = resources.get_mut::<Viewport>() else {
            return Vec::new();
        };
        // The pixels egui's paint callback gives the panel: its viewport, exactly.
        let px = egui::epaint::ViewportInPixels::from_points(
            &self.rect,
            screen.pixels_per_point,
            screen.size_in_pixels,
        );
        let size = (px.width_px.max(0) as u32, px.height_px.max(0) as u32);
        viewport.frame = None;
        if size.0 == 0 || size.1 == 0 {
            return Vec::new();
        }
        match viewport.encode(device, encoder, &self.shot, size) {
            Ok(frame) => {
                viewport.frame = Some(frame);
                viewport.error = None;
            }
            Err(e) => viewport.error = Some(e.to_string()),
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        if let Some(Viewport {
            pass,
            frame: Some(frame),
            ..
        }) = resources.get::<Viewport>()
        {
            // Errors were found in `prepare`; the draw has nothing left to refuse.
            let _ = pass.render(render_pass, frame);
        }
    }
}

/// The edge choices of the side panel.
const EDGES: [(&str, EdgeSelection); 3] = [
    ("polygon", EdgeSelection::Polygon),
    ("feature", EdgeSelection::Feature(30.0)),
    ("all", EdgeSelection::All),
];

/// The hidden-line choices of the side panel.
const HIDDEN: [(&str, Option<LinePattern>); 4] = [
    ("off", None),
    (
        "dashed",
        Some(LinePattern::Dashed {
            dash: 6.0,
            gap: 4.0,
        }),
    ),
    ("dotted", Some(LinePattern::Dotted { spacing: 4.0 })),
    ("solid", Some(LinePattern::Solid)),
];

struct App {
    args: Args,
    model: Model,
    shot: Shot,
    edges: usize,
    hidden: usize,
    frames: u64,
    /// The panel's rectangle in the last frame, for the screenshot's check.
    rect: egui::Rect,
    pixels_per_point: f32,
    screenshot_asked: bool,
    /// The window's screenshot, once egui has taken it.
    shot_taken: std::sync::Arc<std::sync::Mutex<Option<std::sync::Arc<egui::ColorImage>>>>,
    /// The exit status: an error makes the app exit non-zero.
    failed: std::sync::Arc<std::sync::Mutex<Option<String>>>,
}

impl App {
    fn new(
        cc: &eframe::CreationContext<'_>,
        args: Args,
        failed: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    ) -> Result<App, AnyError> {
        let rs = cc
            .wgpu_render_state
            .as_ref()
            .ok_or("eframe did not start its wgpu renderer")?;
        let model = Model::load(args.mesh.as_ref())?;
        let pass = DeferredPass::new(
            &rs.device,
            PassOptions {
                // egui's render pass: its surface's format, one sample, no depth.
                render_target: Some(RenderTarget {
                    format: rs.target_format,
                    sample_count: 1,
                    depth_stencil: None,
                    content: Composite::Shaded,
                }),
                ..Default::default()
            },
        )?;
        let mut viewport = Viewport {
            pass,
            store: MeshStore::new(&rs.device),
            ids: Vec::new(),
            instances: Vec::new(),
            frame: None,
            error: None,
        };
        viewport.upload(&rs.device, &rs.queue, &model, EDGES[0].1)?;
        rs.renderer.write().callback_resources.insert(viewport);
        let (lo, hi) = model.bounds();
        Ok(App {
            args,
            shot: Shot {
                orbit: Orbit::framing(lo, hi),
                style: Style::default(),
            },
            model,
            edges: 0,
            hidden: 0,
            frames: 0,
            rect: egui::Rect::NOTHING,
            pixels_per_point: 1.0,
            screenshot_asked: false,
            shot_taken: Default::default(),
            failed,
        })
    }

    fn side_panel(&mut self, ui: &mut egui::Ui, frame: &eframe::Frame) {
        ui.heading("wirepass");
        let edges = self.edges;
        egui::ComboBox::from_label("edges")
            .selected_text(EDGES[self.edges].0)
            .show_ui(ui, |ui| {
                for (k, (name, _)) in EDGES.iter().enumerate() {
                    ui.selectable_value(&mut self.edges, k, *name);
                }
            });
        if edges != self.edges {
            if let Some(rs) = frame.wgpu_render_state() {
                let mut renderer = rs.renderer.write();
                if let Some(v) = renderer.callback_resources.get_mut::<Viewport>() {
                    let uploaded =
                        v.upload(&rs.device, &rs.queue, &self.model, EDGES[self.edges].1);
                    v.error = uploaded.err().map(|e| e.to_string());
                }
            }
        }
        ui.checkbox(&mut self.shot.style.outlines, "outlines");
        egui::ComboBox::from_label("hidden lines")
            .selected_text(HIDDEN[self.hidden].0)
            .show_ui(ui, |ui| {
                for (k, (name, _)) in HIDDEN.iter().enumerate() {
                    ui.selectable_value(&mut self.hidden, k, *name);
                }
            });
        self.shot.style.hidden = HIDDEN[self.hidden].1.map(|pattern| HiddenLines {
            pattern,
            ..HiddenLines::default()
        });
        ui.add(egui::Slider::new(&mut self.shot.style.line_width, 0.5..=6.0).text("line width"));
        if ui.button("fit").clicked() {
            let (lo, hi) = self.model.bounds();
            self.shot.orbit = Orbit::framing(lo, hi);
        }
        ui.separator();
        ui.label(format!("{} triangles", self.model.triangles()));
        let error = frame.wgpu_render_state().and_then(|rs| {
            let renderer = rs.renderer.read();
            renderer.callback_resources.get::<Viewport>()?.error.clone()
        });
        if let Some(e) = error {
            ui.colored_label(egui::Color32::RED, e);
        }
    }

    fn central_panel(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), egui::Sense::drag());
        let height = f64::from(rect.height().max(1.0));
        let d = response.drag_delta();
        if response.dragged_by(egui::PointerButton::Primary) {
            self.shot.orbit.rotate(f64::from(d.x), f64::from(d.y));
        } else if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            self.shot.orbit.pan(f64::from(d.x), f64::from(d.y), height);
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.shot.orbit.zoom(f64::from(scroll) / 50.0);
            }
        }
        // The pass's background under the frame: its composite draws only where an
        // instance or a line is.
        let sky = self.shot.style.background.to_srgb8();
        ui.painter()
            .rect_filled(rect, 0.0, egui::Color32::from_rgb(sky[0], sky[1], sky[2]));
        ui.painter().add(egui_wgpu::Callback::new_paint_callback(
            rect,
            Draw {
                rect,
                shot: self.shot.clone(),
            },
        ));
        self.rect = rect;
        self.pixels_per_point = ui.ctx().pixels_per_point();
    }

    /// Checks the window's screenshot: the panel shows the frame the pass draws offscreen
    /// into a texture of egui's format, and that frame shows background, surface and lines.
    fn check(&self, image: &egui::ColorImage, frame: &eframe::Frame) -> Result<String, AnyError> {
        let rs = frame.wgpu_render_state().ok_or("no wgpu renderer")?;
        let px = egui::epaint::ViewportInPixels::from_points(
            &self.rect,
            self.pixels_per_point,
            [image.size[0] as u32, image.size[1] as u32],
        );
        let size = (px.width_px as u32, px.height_px as u32);
        let offscreen = {
            let mut renderer = rs.renderer.write();
            let v = (renderer.callback_resources.get_mut::<Viewport>()).ok_or("no viewport")?;
            draw_offscreen(v, &rs.device, &rs.queue, rs.target_format, &self.shot, size)?
        };
        let (mut differing, mut lines, mut background) = (0, 0, 0);
        let sky = self.shot.style.background.to_srgb8();
        let dark = self
            .shot
            .style
            .fill_color
            .0
            .map(|c| c * self.shot.style.ambient * 0.5);
        let dark = wirepass::Color(dark).to_srgb8();
        for y in 0..size.1 as usize {
            for x in 0..size.0 as usize {
                let shown = image.pixels
                    [(px.top_px as usize + y) * image.size[0] + px.left_px as usize + x]
                    .to_array();
                let drawn = &offscreen[4 * (y * size.0 as usize + x)..][..4];
                // egui dithers its own fill (the background) by up to one step.
                differing += usize::from((0..3).any(|k| shown[k].abs_diff(drawn[k]) > 2));
                lines += usize::from((0..3).all(|k| shown[k] < dark[k]));
                background += usize::from((0..3).all(|k| shown[k].abs_diff(sky[k]) <= 2));
            }
        }
        let pixels = (size.0 * size.1) as f64;
        let (lines, background) = (lines as f64 / pixels, background as f64 / pixels);
        if differing > 0 {
            return Err(format!(
                "{differing} pixels of the panel differ from the same frame drawn offscreen"
            )
            .into());
        }
        if background < 0.05 || lines < 0.002 || background + lines > 0.95 {
            return Err(format!(
                "the panel does not show background, surface and lines ({:.1} % background, \
                 {:.2} % lines)",
                100.0 * background,
                100.0 * lines
            )
            .into());
        }
        Ok(format!(
            "panel {}x{} at ({}, {}) of egui's {:?} surface: the same as offscreen; {:.1} % \
             background, {:.2} % lines",
            size.0,
            size.1,
            px.left_px,
            px.top_px,
            rs.target_format,
            100.0 * background,
            100.0 * lines
        ))
    }
}

/// The frame of `shot` at `size` drawn into a texture of egui's `format` cleared to the
/// style's background, as the panel draws it, and read back as RGBA8.
fn draw_offscreen(
    viewport: &mut Viewport,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    format: wgpu::TextureFormat,
    shot: &Shot,
    size: (u32, u32),
) -> Result<Vec<u8>, AnyError> {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let texture = wirepass::gpu::texture_2d(device, "egui_viewport offscreen", size, format, usage);
    let view = texture.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    let frame = viewport.encode(device, &mut encoder, shot, size)?;
    {
        // The background as egui fills the panel: the sRGB bytes in egui's format.
        let sky = shot
            .style
            .background
            .to_srgb8()
            .map(|c| f64::from(c) / 255.0);
        // An sRGB format encodes the clear colour; any other 8-bit format holds it encoded.
        let linear = |c: f64| {
            if format.is_srgb() {
                f64::from(wirepass::style::srgb_to_linear(c as f32))
            } else {
                c
            }
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui_viewport offscreen"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: linear(sky[0]),
                        g: linear(sky[1]),
                        b: linear(sky[2]),
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        viewport.pass.render(&mut pass, &frame)?;
    }
    queue.submit([encoder.finish()]);
    let mut rgba = wirepass::gpu::read_texture(device, queue, &texture, wgpu::TextureAspect::All)?;
    if format.remove_srgb_suffix() == wgpu::TextureFormat::Bgra8Unorm {
        rgba.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
    }
    Ok(rgba)
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        egui::Panel::left("settings")
            .exact_size(250.0)
            .show(ui, |ui| self.side_panel(ui, frame));
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.central_panel(ui));
        self.frames += 1;
        let Some(last) = self.args.frames else {
            return;
        };
        let ctx = ui.ctx().clone();
        ctx.request_repaint();
        let shot = self.shot_taken.lock().ok().and_then(|mut s| s.take());
        if let Some(image) = shot {
            let result = self.save_and_check(&image, frame);
            if let Err(e) = &result {
                if let Ok(mut failed) = self.failed.lock() {
                    *failed = Some(e.to_string());
                }
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else if self.frames >= last {
            if self.args.screenshot.is_none() {
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            } else if !self.screenshot_asked {
                self.screenshot_asked = true;
                let taken = self.shot_taken.clone();
                let callback = egui::ScreenshotCallback::new(move |image| {
                    if let Ok(mut t) = taken.lock() {
                        *t = Some(image);
                    }
                });
                ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(callback));
            }
        }
    }
}

impl App {
    fn save_and_check(
        &self,
        image: &egui::ColorImage,
        frame: &eframe::Frame,
    ) -> Result<(), AnyError> {
        let path = self.args.screenshot.as_ref().ok_or("no --screenshot")?;
        let rgba: Vec<u8> = image.pixels.iter().flat_map(|p| p.to_array()).collect();
        image::save_buffer(
            path,
            &rgba,
            image.size[0] as u32,
            image.size[1] as u32,
            image::ColorType::Rgba8,
        )?;
        println!(
            "wrote {} ({}x{})",
            path.display(),
            image.size[0],
            image.size[1]
        );
        println!("{}", self.check(image, frame)?);
        Ok(())
    }
}

fn main() {
    let args = match args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("egui_viewport: {e}");
            std::process::exit(2);
        }
    };
    let failed = std::sync::Arc::new(std::sync::Mutex::new(None));
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1000.0, 700.0])
            .with_title("wirepass in egui"),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    let app_failed = failed.clone();
    let run = eframe::run_native(
        "wirepass egui viewport",
        options,
        Box::new(move |cc| {
            App::new(cc, args, app_failed)
                .map(|app| Box::new(app) as Box<dyn eframe::App>)
                .map_err(|e| e.to_string().into())
        }),
    );
    if let Err(e) = run {
        eprintln!("egui_viewport: {e}");
        std::process::exit(1);
    }
    let failure = failed.lock().ok().and_then(|mut f| f.take());
    if let Some(e) = failure {
        eprintln!("egui_viewport: {e}");
        std::process::exit(1);
    }
}
