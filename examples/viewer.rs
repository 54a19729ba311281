//! A mesh viewer in a window: wirepass draws the shaded mesh and its lines straight into the
//! surface's render pass (the deferred method), or the forward baseline draws into a texture
//! that is blitted to the surface, for comparison. The device has the WebGPU default limits.
//!
//! Mouse: left drag orbits, right or middle drag pans, the wheel zooms, a left click picks
//! (the window title says what the pixel shows: the triangle, its polygon, the exact point,
//! and the nearest drawn edge and vertex) and selects the mesh (a `Highlight`: its outline
//! in orange, dashed where it hides itself; a click on the background clears it).
//! Keys: `E` cycles the edges (polygon, all, feature), `O` toggles outlines, `H` cycles the
//! hidden lines (off, dashed, dotted, solid; deferred only), `S` adds a section plane
//! through the orbit's centre facing the way the camera looks (what is nearer is cut away;
//! up to 6), `[`/`]` move the last one along its normal, `Backspace` removes it (deferred
//! only), `D` writes the view as a technical drawing (`wirepass-drawing.svg`: its visible
//! and hidden lines as vectors), `M` switches the method, `+`/`-` change the line width,
//! `Esc` quits.
//!
//! `cargo run --release --example viewer -- [MESH] [--method deferred|forward]
//! [--edges polygon|all|feature] [--hidden off|dashed|dotted|solid] [--cut] [--frames N]
//! [--screenshot OUT.png] [--pick X,Y] [--drawing OUT.svg]`
//!
//! `--cut` presses `S` once before the first frame.
//!
//! With `--frames N` the viewer orbits a little each frame and closes after N frames; with
//! `--screenshot` it reads the last frame back from the surface, checks that it shows the
//! background, the shaded mesh and its lines, and writes it as a PNG (CI runs it so under
//! Xvfb). With `--pick X,Y` it prints what pixel X,Y of the last frame shows, selecting
//! the mesh there as a click does, and draws one more frame so. With `--drawing` it writes
//! the last frame's view as a drawing there, as `D` does.

use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop, OwnedDisplayHandle};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};
use wirepass::camera::Orbit;
use wirepass::glam::DMat4;
use wirepass::gpu::{
    Composite, DeferredPass, ForwardPass, MeshId, MeshStore, OutputTarget, PassOptions,
    RenderTarget,
};
use wirepass::{
    wgpu, EdgeSelection, HiddenLines, Highlight, Instance, InstanceStyle, LinePattern, Mesh, Scene,
    SectionPlane, Style,
};

type AnyError = Box<dyn std::error::Error>;

const EDGES: [(&str, EdgeSelection); 3] = [
    ("polygon", EdgeSelection::Polygon),
    ("all", EdgeSelection::All),
    (
        "feature",
        EdgeSelection::Feature(wirepass::mesh::DEFAULT_FEATURE_ANGLE),
    ),
];

#[derive(Clone, Copy, PartialEq, Debug)]
enum Method {
    Deferred,
    Forward,
}

/// What the command line asks for.
struct Options {
    mesh: std::path::PathBuf,
    method: Method,
    edges: usize,
    hidden: usize,
    frames: Option<u64>,
    screenshot: Option<std::path::PathBuf>,
    pick: Option<(u32, u32)>,
    /// `--cut`: a section plane from the start.
    cut: bool,
    /// `--drawing`: the last frame's view as a drawing.
    drawing: Option<std::path::PathBuf>,
}

/// The hidden-line styles `H` cycles through.
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

/// The style with hidden lines in `HIDDEN[k]`'s pattern.
fn with_hidden(style: &Style, k: usize) -> Style {
    Style {
        hidden: HIDDEN[k].1.map(|pattern| HiddenLines {
            pattern,
            ..HiddenLines::default()
        }),
        ..style.clone()
    }
}

fn options() -> Result<Options, AnyError> {
    let mut o = Options {
        mesh: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/spot.obj"),
        method: Method::Deferred,
        edges: 0,
        hidden: 0,
        frames: None,
        screenshot: None,
        pick: None,
        cut: false,
        drawing: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--method" => {
                o.method = match value()?.as_str() {
                    "deferred" => Method::Deferred,
                    "forward" => Method::Forward,
                    m => return Err(format!("--method {m:?} is not deferred or forward").into()),
                }
            }
            "--edges" => {
                let e = value()?;
                o.edges = EDGES
                    .iter()
                    .position(|(name, _)| *name == e)
                    .ok_or(format!("--edges {e:?} is not polygon, all or feature"))?;
            }
            "--hidden" => {
                let h = value()?;
                o.hidden = HIDDEN
                    .iter()
                    .position(|(name, _)| *name == h)
                    .ok_or(format!(
                        "--hidden {h:?} is not off, dashed, dotted or solid"
                    ))?;
            }
            "--frames" => o.frames = Some(value()?.parse()?),
            "--screenshot" => o.screenshot = Some(value()?.into()),
            "--cut" => o.cut = true,
            "--drawing" => o.drawing = Some(value()?.into()),
            "--pick" => {
                let v = value()?;
                let bad = || format!("--pick {v:?} is not X,Y");
                let (x, y) = v.split_once(',').ok_or_else(bad)?;
                o.pick = Some((x.parse().map_err(|_| bad())?, y.parse().map_err(|_| bad())?));
            }
            flag if flag.starts_with("--") => return Err(format!("unknown flag {flag}").into()),
            path => o.mesh = path.into(),
        }
    }
    Ok(o)
}

/// The window's GPU side: the surface, the passes and the mesh in each edge selection.
struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The sRGB view of the surface's format, the one every pass draws into.
    view_format: wgpu::TextureFormat,
    device: wgpu::Device,
    queue: wgpu::Queue,
    store: MeshStore,
    meshes: [MeshId; 3],
    deferred: DeferredPass,
    /// The forward baseline, if the device can run it, and its blit to the surface.
    forward: Option<(ForwardPass, Blit)>,
    orbit: Orbit,
    style: Style,
    method: Method,
    edges: usize,
    /// Which of HIDDEN the style draws.
    hidden: usize,
    drag: Option<MouseButton>,
    cursor: (f64, f64),
    /// Where the left button went down, to tell a click from a drag.
    press: Option<(f64, f64)>,
    /// The mesh on the CPU, for the exact point of a pick.
    mesh: Mesh,
    /// The last deferred frame and its scene, which a click picks from.
    last: Option<(wirepass::PreparedFrame, Scene<'static>)>,
    /// Whether a click selected the mesh.
    selected: bool,
    /// The section planes `S` placed.
    sections: Vec<SectionPlane>,
}

impl Viewer {
    fn new(
        window: Arc<Window>,
        display: OwnedDisplayHandle,
        mesh: &Mesh,
        o: &Options,
    ) -> Result<Viewer, AnyError> {
        let instance = wgpu::Instance::new(
            wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(display)),
        );
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))?;
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
                required_limits: wgpu::Limits::default(),
                ..Default::default()
            }))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or("the surface cannot be presented to by this adapter")?;
        let caps = surface.get_capabilities(&adapter);
        // Draw through an sRGB view whatever the surface's own format, so that the colours
        // are the same as in the PNGs the tools write.
        config.format = caps
            .formats
            .iter()
            .copied()
            .find(|f| f.is_srgb())
            .unwrap_or(config.format);
        let view_format = config.format.add_srgb_suffix();
        if view_format != config.format {
            config.view_formats.push(view_format);
        }
        if o.screenshot.is_some() {
            if !caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
                return Err("--screenshot: the surface cannot be copied from".into());
            }
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        surface.configure(&device, &config);

        let mut store = MeshStore::new(&device);
        let mut meshes = Vec::new();
        for (_, edges) in EDGES {
            meshes.push(store.insert(&device, &queue, mesh, edges)?);
        }
        let deferred = DeferredPass::new(
            &device,
            PassOptions {
                render_target: Some(RenderTarget {
                    format: view_format,
                    sample_count: 1,
                    depth_stencil: None,
                    content: Composite::Shaded,
                }),
                ..Default::default()
            },
        )?;
        let forward = match ForwardPass::new(&device, wgpu::TextureFormat::Rgba8UnormSrgb) {
            Ok(pass) => Some((pass, Blit::new(&device, view_format))),
            Err(e) => {
                eprintln!("viewer: the forward method is unavailable: {e}");
                None
            }
        };
        if o.method == Method::Forward && forward.is_none() {
            return Err("--method forward: this device cannot run the forward pass".into());
        }
        let mut viewer = Viewer {
            window,
            surface,
            config,
            view_format,
            device,
            queue,
            store,
            meshes: meshes.try_into().expect("one mesh per edge selection"),
            deferred,
            forward,
            orbit: {
                let (lo, hi) = mesh.bounds_f64();
                Orbit::framing(lo, hi)
            },
            style: with_hidden(&Style::default(), o.hidden),
            method: o.method,
            edges: o.edges,
            hidden: o.hidden,
            drag: None,
            cursor: (0.0, 0.0),
            press: None,
            mesh: mesh.clone(),
            last: None,
            selected: false,
            sections: Vec::new(),
        };
        if o.cut {
            viewer.add_section();
        }
        viewer.title();
        Ok(viewer)
    }

    fn title(&self) {
        self.window.set_title(&format!(
            "wirepass viewer: {:?}, {} edges, outlines {}, hidden {}, sections {}, width {:.1} \
             (E, O, H, S, [, ], Backspace, D, M, +/-)",
            self.method,
            EDGES[self.edges].0,
            if self.style.outlines { "on" } else { "off" },
            HIDDEN[self.hidden].0,
            self.sections.len(),
            self.style.line_width
        ));
    }

    /// A section plane through the orbit's centre, its normal the way the camera looks: the
    /// half nearer the eye is cut away.
    fn add_section(&mut self) {
        if self.sections.len() < wirepass::MAX_SECTIONS {
            self.sections.push(SectionPlane::across(&self.orbit));
        }
    }

    fn resize(&mut self, size: PhysicalSize<u32>) {
        if size.width > 0 && size.height > 0 {
            self.config.width = size.width;
            self.config.height = size.height;
            self.surface.configure(&self.device, &self.config);
        }
    }

    fn key(&mut self, key: &Key) {
        match key.as_ref() {
            Key::Character("e" | "E") => self.edges = (self.edges + 1) % EDGES.len(),
            Key::Character("o" | "O") => self.style.outlines = !self.style.outlines,
            Key::Character("h" | "H") => {
                self.hidden = (self.hidden + 1) % HIDDEN.len();
                self.style = with_hidden(&self.style, self.hidden);
            }
            Key::Character("s" | "S") => self.add_section(),
            Key::Character(c @ ("[" | "]")) => {
                if let Some(s) = self.sections.last_mut() {
                    *s = s.nudged(&self.orbit, if c == "]" { 1.0 } else { -1.0 });
                }
            }
            Key::Named(NamedKey::Backspace) => {
                self.sections.pop();
            }
            Key::Character("m" | "M") if self.forward.is_some() => {
                self.method = match self.method {
                    Method::Deferred => Method::Forward,
                    Method::Forward => Method::Deferred,
                }
            }
            Key::Character("d" | "D") => {
                let path = std::path::Path::new("wirepass-drawing.svg");
                let said = match self.write_drawing(path) {
                    Ok(paths) => format!("wrote {} ({paths} paths)", path.display()),
                    Err(e) => format!("the drawing failed: {e}"),
                };
                println!("{said}");
                self.window.set_title(&format!("wirepass viewer: {said}"));
                return;
            }
            Key::Character("+" | "=") => {
                self.style.line_width = (self.style.line_width + 0.5).min(16.0)
            }
            Key::Character("-") => self.style.line_width = (self.style.line_width - 0.5).max(0.5),
            _ => return,
        }
        self.title();
        self.window.request_redraw();
    }

    /// Writes the view, as drawn, as a drawing (SVG, PDF or DXF by `path`'s extension);
    /// returns how many paths it has.
    fn write_drawing(&self, path: &std::path::Path) -> Result<usize, AnyError> {
        use wirepass::drawing::{Drawing, Page};
        use wirepass::world::{Shot, World};
        let mut world = World::single(self.mesh.clone(), EDGES[self.edges].1);
        world.sections = self.sections.clone();
        if self.selected {
            world.objects[0].style =
                InstanceStyle::default().highlighted(&Highlight::default(), &self.style);
        }
        let size = (self.config.width, self.config.height);
        let shot = Shot {
            world: &world,
            view: self
                .orbit
                .camera()
                .to_view(f64::from(size.0) / f64::from(size.1)),
            style: &self.style,
            size,
        };
        let drawing = Drawing::new(&shot)?;
        drawing.write(path, &Page::pixels())?;
        Ok(drawing.paths.len())
    }

    fn mouse_moved(&mut self, x: f64, y: f64) {
        let (dx, dy) = (x - self.cursor.0, y - self.cursor.1);
        self.cursor = (x, y);
        match self.drag {
            Some(MouseButton::Left) => self.orbit.rotate(dx, dy),
            Some(MouseButton::Right | MouseButton::Middle) => {
                self.orbit.pan(dx, dy, f64::from(self.config.height))
            }
            _ => return,
        }
        self.window.request_redraw();
    }

    /// Draws one frame and presents it, read back as RGBA8 (sRGB) when `read_back`.
    fn draw(&mut self, read_back: bool) -> Result<Drawn, AnyError> {
        let surface = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(Drawn::Skipped);
            }
            other => return Err(format!("the surface gave no frame: {other:?}").into()),
        };
        self.record(&surface.texture)?;
        let rgba = if read_back {
            Some(self.read(&surface.texture)?)
        } else {
            None
        };
        self.window.pre_present_notify();
        self.queue.present(surface);
        Ok(Drawn::Presented(rgba))
    }

    /// The frame [`draw`](Self::draw) presents, drawn into a texture of the surface's
    /// format instead, and read back.
    fn draw_offscreen(&mut self) -> Result<Vec<u8>, AnyError> {
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("viewer offscreen"),
            size: wgpu::Extent3d {
                width: self.config.width,
                height: self.config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[self.view_format],
        });
        self.record(&texture)?;
        self.read(&texture)
    }

    /// Draws the scene into `texture` (of the surface's size and format) and submits.
    fn record(&mut self, texture: &wgpu::Texture) -> Result<(), AnyError> {
        let target = texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.view_format),
            ..Default::default()
        });
        let size = (self.config.width, self.config.height);
        let aspect = f64::from(size.0) / f64::from(size.1);
        let mut instance = Instance::new(self.meshes[self.edges], DMat4::IDENTITY);
        if self.selected {
            instance.style =
                InstanceStyle::default().highlighted(&Highlight::default(), &self.style);
        }
        let instances = [instance];
        let scene = Scene::borrowed(self.orbit.camera().to_view(aspect), &instances)
            .with_sections(self.sections.clone());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let clear = {
            let [r, g, b, a] = self.style.background.0.map(f64::from);
            wgpu::Color { r, g, b, a }
        };
        match (self.method, &mut self.forward) {
            (Method::Forward, Some((forward, blit))) => {
                let frame =
                    forward.prepare(&self.device, &self.store, &scene, &self.style, size)?;
                let output = wirepass::gpu::texture_2d(
                    &self.device,
                    "viewer forward",
                    size,
                    forward.output_format(),
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                );
                let output = output.create_view(&Default::default());
                forward.encode(&self.device, &mut encoder, &self.store, &frame, &output)?;
                blit.draw(&self.device, &mut encoder, &output, &target);
            }
            _ => {
                let frame =
                    self.deferred
                        .prepare(&self.device, &self.store, &scene, &self.style, size)?;
                self.deferred.encode(
                    &self.device,
                    &mut encoder,
                    &self.store,
                    &frame,
                    OutputTarget::RenderPass,
                )?;
                // The host's own render pass on the surface; wirepass draws into it.
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("viewer"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(clear),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    ..Default::default()
                });
                self.deferred.render(&mut pass, &frame)?;
                drop(pass);
                self.last = Some((
                    frame,
                    Scene::new(scene.view, instances.to_vec()).with_sections(scene.sections),
                ));
            }
        }
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// What pixel `at` of the last deferred frame shows, in words; selects the mesh there,
    /// or clears the selection on the background.
    fn pick(&mut self, at: (u32, u32)) -> Result<String, AnyError> {
        use wirepass::gpu::{PickView, Picked};
        let (frame, scene) = self
            .last
            .as_ref()
            .ok_or("picking needs the deferred method")?;
        let picked = frame.pick(&self.device, &self.queue, &self.store, scene, at)?;
        self.selected = matches!(picked, Picked::Instance(_));
        let hit = match picked {
            Picked::Background => return Ok("background".into()),
            Picked::Host => return Ok("the host's geometry".into()),
            Picked::Instance(hit) => hit,
        };
        let view = PickView {
            view: scene.view,
            image: frame.output_size(),
            vertices: wirepass::gpu::SnapVertices::Any,
            sections: scene.sections.clone(),
        };
        let l = hit.locate(&self.mesh, &view, at, 8.0)?;
        let mut words = format!(
            "triangle {} (polygon {}) at ({:.4}, {:.4}, {:.4})",
            l.triangle, l.polygon, l.point.x, l.point.y, l.point.z
        );
        if let Some(e) = l.edge {
            let [a, b] = e.vertices;
            words += &format!(", edge {a}-{b} {:.1} px", e.distance_px);
        }
        if let Some(v) = l.vertex {
            words += &format!(", vertex {} {:.1} px", v.vertex, v.distance_px);
        }
        Ok(words)
    }

    /// Reads `texture` back as RGBA8.
    fn read(&self, texture: &wgpu::Texture) -> Result<Vec<u8>, AnyError> {
        let mut bytes = wirepass::gpu::read_texture(
            &self.device,
            &self.queue,
            texture,
            wgpu::TextureAspect::All,
        )?;
        if texture.format().remove_srgb_suffix() == wgpu::TextureFormat::Bgra8Unorm {
            bytes.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        Ok(bytes)
    }
}

/// What became of a frame.
enum Drawn {
    /// The surface had to be configured again; draw again.
    Skipped,
    /// Presented, with its pixels if they were asked for.
    Presented(Option<Vec<u8>>),
}

/// Copies a texture onto the surface: a full-screen triangle that loads each texel.
struct Blit {
    pipeline: wgpu::RenderPipeline,
}

impl Blit {
    const SHADER: &str = "
        @group(0) @binding(0) var source: texture_2d<f32>;
        @vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
            let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
            return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
        }
        @fragment fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
            return textureLoad(source, vec2<i32>(p.xy), 0);
        }";

    fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Blit {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer blit"),
            source: wgpu::ShaderSource::Wgsl(Self::SHADER.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("viewer blit"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Blit { pipeline }
    }

    fn draw(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) {
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("viewer blit"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(source),
            }],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("viewer blit"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// Checks a frame read back from the surface: it is the frame the same passes draw into a
/// texture of the surface's format, and it shows the background around the mesh, the shaded
/// surface, and lines.
fn check_frame(presented: &[u8], offscreen: &[u8], style: &Style) -> Result<(), String> {
    let differing = presented
        .chunks_exact(4)
        .zip(offscreen.chunks_exact(4))
        .filter(|(a, b)| (0..3).any(|k| a[k].abs_diff(b[k]) > 1))
        .count();
    if differing > 0 {
        return Err(format!(
            "{differing} pixels of the presented frame differ from the same frame drawn offscreen"
        ));
    }
    let pixels = presented.len() / 4;
    let share = |f: &dyn Fn(&[u8]) -> bool| {
        presented.chunks_exact(4).filter(|p| f(p)).count() as f64 / pixels as f64
    };
    let sky = style.background.to_srgb8();
    let background = share(&|p| (0..3).all(|k| p[k].abs_diff(sky[k]) <= 2));
    // The fill is never darker than its ambient share; the line cores are.
    let dark = style.fill_color.0.map(|c| c * style.ambient * 0.5);
    let dark = wirepass::Color(dark).to_srgb8();
    let lines = share(&|p| (0..3).all(|k| p[k] < dark[k]));
    let surface = 1.0 - background - lines;
    println!(
        "frame: the same as offscreen; {:.1} % background, {:.1} % surface, {:.1} % lines",
        100.0 * background,
        100.0 * surface,
        100.0 * lines
    );
    if background < 0.05 || surface < 0.05 || lines < 0.002 {
        return Err(format!(
            "the frame does not show background, surface and lines \
             ({background:.3}, {surface:.3}, {lines:.4} of its pixels)"
        ));
    }
    Ok(())
}

struct App {
    options: Options,
    mesh: Mesh,
    display: OwnedDisplayHandle,
    viewer: Option<Viewer>,
    frames: u64,
    error: Option<AnyError>,
}

impl App {
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<(), AnyError> {
        let Some(viewer) = self.viewer.as_mut() else {
            return Ok(());
        };
        let Some(limit) = self.options.frames else {
            viewer.draw(false)?;
            return Ok(());
        };
        let last = self.frames + 1 >= limit;
        let read_back = last && self.options.screenshot.is_some();
        let Drawn::Presented(rgba) = viewer.draw(read_back)? else {
            viewer.window.request_redraw();
            return Ok(());
        };
        self.frames += 1;
        if !last {
            viewer.orbit.rotate(4.0, 0.0);
            viewer.window.request_redraw();
            return Ok(());
        }
        if let (Some(path), Some(rgba)) = (&self.options.screenshot, rgba) {
            let (w, h) = (viewer.config.width, viewer.config.height);
            image::save_buffer(path, &rgba, w, h, image::ColorType::Rgba8)?;
            println!("wrote {} ({w}x{h}, {} frames)", path.display(), self.frames);
            let offscreen = viewer.draw_offscreen()?;
            check_frame(&rgba, &offscreen, &viewer.style)?;
        }
        if let Some(path) = &self.options.drawing {
            let paths = viewer.write_drawing(path)?;
            println!("wrote {} ({paths} paths)", path.display());
            if paths == 0 {
                return Err("the drawing of the view has no paths".into());
            }
        }
        if let Some(at) = self.options.pick {
            println!("pick {},{}: {}", at.0, at.1, viewer.pick(at)?);
            // The selection drawn: the mesh's outline in the highlight's colour.
            let rgba = viewer.draw_offscreen()?;
            if viewer.selected {
                let orange = rgba
                    .chunks_exact(4)
                    .filter(|p| p[0] > 200 && p[1] > 90 && p[1] < 190 && p[2] < 90)
                    .count();
                println!("selected: {orange} pixels of its outline");
                if orange == 0 {
                    return Err("the selected mesh shows no highlighted outline".into());
                }
            }
        }
        event_loop.exit();
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("wirepass viewer")
            .with_inner_size(PhysicalSize::new(960, 640));
        let made = event_loop
            .create_window(attributes)
            .map_err(AnyError::from)
            .and_then(|w| {
                Viewer::new(Arc::new(w), self.display.clone(), &self.mesh, &self.options)
            });
        match made {
            Ok(v) => {
                v.window.request_redraw();
                self.viewer = Some(v);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            event => {
                if let Some(v) = self.viewer.as_mut() {
                    match event {
                        WindowEvent::Resized(size) => {
                            v.resize(size);
                            v.window.request_redraw();
                        }
                        WindowEvent::KeyboardInput { event, .. }
                            if event.state == ElementState::Pressed =>
                        {
                            if event.logical_key == Key::Named(NamedKey::Escape) {
                                event_loop.exit();
                            }
                            v.key(&event.logical_key);
                        }
                        WindowEvent::MouseInput { state, button, .. } => {
                            v.drag = (state == ElementState::Pressed).then_some(button);
                            let pressed = state == ElementState::Pressed;
                            if button == MouseButton::Left && pressed {
                                v.press = Some(v.cursor);
                            } else if button == MouseButton::Left {
                                let (x, y) = v.cursor;
                                let click = v.press.take().is_some_and(|(px, py)| {
                                    (x - px).abs() < 3.0 && (y - py).abs() < 3.0
                                });
                                if click && x >= 0.0 && y >= 0.0 {
                                    let words = v
                                        .pick((x as u32, y as u32))
                                        .unwrap_or_else(|e| format!("no pick: {e}"));
                                    v.window.set_title(&format!("wirepass viewer: {words}"));
                                }
                            }
                        }
                        WindowEvent::CursorMoved { position, .. } => {
                            v.mouse_moved(position.x, position.y)
                        }
                        WindowEvent::MouseWheel { delta, .. } => {
                            v.orbit.zoom(match delta {
                                MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                                MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                            });
                            v.window.request_redraw();
                        }
                        _ => {}
                    }
                }
                Ok(())
            }
        };
        if let Err(e) = result {
            self.error = Some(e);
            event_loop.exit();
        }
    }
}

fn main() {
    if let Err(e) = run() {
        eprintln!("viewer: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), AnyError> {
    let options = options()?;
    let mesh = wirepass::mesh::load(&options.mesh)?;
    let event_loop = EventLoop::new()?;
    let mut app = App {
        display: event_loop.owned_display_handle(),
        options,
        mesh,
        viewer: None,
        frames: 0,
        error: None,
    };
    event_loop.run_app(&mut app)?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
