//! The page's GPU side: a WebGPU device with the default limits, the canvas surface, the
//! deferred pass drawing into the canvas's own render pass, and offscreen frames for the
//! page's read-back hook and its frame timer. Nothing here waits on the device.

use crate::model::Model;
use std::sync::{Arc, Mutex};
use wirepass::camera::Orbit;
use wirepass::gpu::{
    Composite, Location, MeshId, PickView, Picked, PickedIds, RenderTarget, UploadReport,
};
use wirepass::{
    wgpu, DeferredPass, EdgeSelection, Instance, MeshStore, OutputTarget, PassOptions, Scene,
    SectionPlane, Style,
};

/// The edge choices the page offers: the file's own (authored edges where a glTF has them,
/// polygon edges otherwise), or one selection for every mesh.
pub const EDGES: [(&str, Option<EdgeSelection>); 4] = [
    ("file", None),
    ("polygon", Some(EdgeSelection::Polygon)),
    (
        "feature",
        Some(EdgeSelection::Feature(
            wirepass::mesh::DEFAULT_FEATURE_ANGLE,
        )),
    ),
    ("all", Some(EdgeSelection::All)),
];

/// Which adapter to ask the browser for, from the page's `?adapter=` parameter.
pub fn adapter_options(
    choice: Option<&str>,
) -> Result<wgpu::RequestAdapterOptions<'static, 'static>, String> {
    let mut options = wgpu::RequestAdapterOptions::default();
    match choice {
        None | Some("") | Some("default") => {}
        Some("high-performance") => {
            options.power_preference = wgpu::PowerPreference::HighPerformance
        }
        Some("low-power") => options.power_preference = wgpu::PowerPreference::LowPower,
        Some("fallback") => options.force_fallback_adapter = true,
        Some(other) => {
            return Err(format!(
                "?adapter={other} is not default, high-performance, low-power or fallback"
            ))
        }
    }
    Ok(options)
}

/// Resolves once the GPU has finished the work submitted to `queue` so far.
pub fn work_done(queue: &wgpu::Queue) -> impl std::future::Future<Output = ()> {
    use std::task::{Poll, Waker};
    #[derive(Default)]
    struct State {
        done: bool,
        waker: Option<Waker>,
    }
    let state = Arc::new(Mutex::new(State::default()));
    let signal = state.clone();
    queue.on_submitted_work_done(move || {
        if let Ok(mut s) = signal.lock() {
            s.done = true;
            if let Some(w) = s.waker.take() {
                w.wake();
            }
        }
    });
    std::future::poll_fn(move |cx| match state.lock() {
        Ok(s) if s.done => Poll::Ready(()),
        Ok(mut s) => {
            s.waker = Some(cx.waker().clone());
            Poll::Pending
        }
        Err(_) => Poll::Ready(()),
    })
}

/// One WebGPU device and what every view on the page shares of it: the adapter it came
/// from, and the errors it reported on its own (WebGPU reports validation errors there,
/// since a page cannot wait on an error scope), for the views to show.
pub struct Device {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter, as the page names it.
    pub name: String,
    pub errors: Arc<Mutex<Vec<String>>>,
}

impl Device {
    /// Opens a device with `wgpu::Limits::default()` on the adapter `options` ask for.
    pub async fn open(
        instance: wgpu::Instance,
        options: wgpu::RequestAdapterOptions<'_, '_>,
    ) -> Result<Device, String> {
        let adapter = instance.request_adapter(&options).await.map_err(|e| {
            format!(
                "This browser has WebGPU but gave no adapter ({e}): it may be switched off \
                 for this GPU or driver."
            )
        })?;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("wirepass page"),
                required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
                required_limits: wgpu::Limits::default(),
                ..Default::default()
            })
            .await
            .map_err(|e| format!("the adapter gave no device: {e}"))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            web_sys::console::error_1(&format!("wirepass: {e}").into());
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let sink = errors.clone();
        device.set_device_lost_callback(move |reason, message| {
            let e = format!("the device was lost ({reason:?}): {message}");
            web_sys::console::error_1(&e.clone().into());
            if let Ok(mut v) = sink.lock() {
                v.push(e);
            }
        });
        let info = adapter.get_info();
        let name = [
            info.name.as_str(),
            info.driver.as_str(),
            info.driver_info.as_str(),
        ]
        .into_iter()
        .find(|s| !s.is_empty())
        .unwrap_or("unnamed adapter")
        .to_string();
        Ok(Device {
            instance,
            adapter,
            device,
            queue,
            name,
            errors,
        })
    }
}

/// A canvas of the page, the device's surface on it, and what draws into it.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter, as the page names it.
    pub adapter: String,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The sRGB view of the canvas's format, which the pass draws into.
    view_format: wgpu::TextureFormat,
    pass: DeferredPass,
    store: MeshStore,
    /// The store's id of each model mesh, uploaded with the current edge choice, and the
    /// edges it draws.
    ids: Vec<(MeshId, EdgeSelection)>,
    /// The last frame drawn and its scene, which a click picks from.
    last: Option<(wirepass::PreparedFrame, Scene<'static>)>,
    /// The device's own error reports, shared by every canvas on it.
    pub errors: Arc<Mutex<Vec<String>>>,
}

impl Gpu {
    /// Shows `shared`'s device on `canvas`, `size` pixels.
    pub fn new(
        shared: &Device,
        canvas: web_sys::HtmlCanvasElement,
        size: (u32, u32),
    ) -> Result<Gpu, String> {
        let surface = shared
            .instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| format!("the canvas cannot show WebGPU: {e}"))?;
        let device = shared.device.clone();
        let mut config = surface
            .get_default_config(&shared.adapter, size.0.max(1), size.1.max(1))
            .ok_or("the canvas cannot be drawn to by this adapter")?;
        // Draw through an sRGB view of the canvas's format (WebGPU canvases have no sRGB
        // format of their own), so colours match the native tools' PNGs.
        let view_format = config.format.add_srgb_suffix();
        if view_format != config.format {
            config.view_formats.push(view_format);
        }
        config.usage |= wgpu::TextureUsages::COPY_SRC;
        surface.configure(&device, &config);
        let pass = DeferredPass::new(
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
        )
        .map_err(|e| e.to_string())?;
        Ok(Gpu {
            store: MeshStore::new(&device),
            device,
            queue: shared.queue.clone(),
            adapter: shared.name.clone(),
            surface,
            config,
            view_format,
            pass,
            ids: Vec::new(),
            last: None,
            errors: shared.errors.clone(),
        })
    }

    /// The canvas's size in pixels, as configured.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// Uploads `model`'s meshes drawing `edges` (`None`: the file's own), replacing those
    /// uploaded before.
    pub fn upload(&mut self, model: &Model, edges: Option<EdgeSelection>) -> Result<(), String> {
        self.last = None;
        for (id, _) in self.ids.drain(..) {
            self.store.remove(id).map_err(|e| e.to_string())?;
        }
        for (mesh, own) in &model.meshes {
            let (mesh, selection) = mesh.resolved_edges(edges.or(*own));
            let id = self
                .store
                .insert(&self.device, &self.queue, &mesh, selection)
                .map_err(|e| e.to_string())?;
            self.ids.push((id, selection));
        }
        Ok(())
    }

    /// What the last upload's preprocessing took, step by step over its meshes, as
    /// `step ms` pairs (`MeshStore::upload_report`).
    pub fn upload_steps(&self) -> Vec<(&'static str, f64)> {
        let mut steps = UploadReport::default().steps().map(|(name, _)| (name, 0.0));
        for &(id, _) in &self.ids {
            let Ok(report) = self.store.upload_report(id) else {
                continue;
            };
            for (step, (_, d)) in steps.iter_mut().zip(report.steps()) {
                step.1 += d.as_secs_f64() * 1e3;
            }
        }
        steps.to_vec()
    }

    /// Configures the canvas again when its size changed.
    pub fn resize(&mut self, size: (u32, u32)) {
        let max = self.device.limits().max_texture_dimension_2d;
        let size = (size.0.clamp(1, max), size.1.clamp(1, max));
        if size != self.size() {
            self.config.width = size.0;
            self.config.height = size.1;
            self.surface.configure(&self.device, &self.config);
        }
    }

    /// Draws the model, cut by `sections`, into the canvas and presents it.
    pub fn draw(
        &mut self,
        model: &Model,
        orbit: &Orbit,
        style: &Style,
        sections: &[SectionPlane],
    ) -> Result<(), String> {
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
            other => return Err(format!("the canvas gave no frame: {other:?}")),
        };
        self.record(&texture.texture, model, orbit, style, sections)?;
        self.queue.present(texture);
        Ok(())
    }

    /// A texture of the canvas's size and format that frames can be drawn into and read.
    pub fn offscreen(&self, size: (u32, u32)) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("wirepass page offscreen"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[self.view_format],
        })
    }

    /// Draws the model into `texture` (of the canvas's format, any size) through the host
    /// render-pass entry, and submits.
    pub fn record(
        &mut self,
        texture: &wgpu::Texture,
        model: &Model,
        orbit: &Orbit,
        style: &Style,
        sections: &[SectionPlane],
    ) -> Result<(), String> {
        let target = texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.view_format),
            ..Default::default()
        });
        let size = (texture.width(), texture.height());
        let aspect = f64::from(size.0) / f64::from(size.1);
        let instances: Vec<Instance> = model
            .instances
            .iter()
            .map(|&(m, transform)| Instance::new(self.ids[m].0, transform))
            .collect();
        let scene = Scene::borrowed(orbit.camera().to_view(aspect), &instances)
            .with_sections(sections.to_vec());
        let err = |e: wirepass::Error| e.to_string();
        let frame = self
            .pass
            .prepare(&self.device, &self.store, &scene, style, size)
            .map_err(err)?;
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.pass
            .encode(
                &self.device,
                &mut encoder,
                &self.store,
                &frame,
                OutputTarget::RenderPass,
            )
            .map_err(err)?;
        {
            let [r, g, b, a] = style.background.0.map(f64::from);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("wirepass page"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            self.pass.render(&mut pass, &frame).map_err(err)?;
        }
        self.queue.submit([encoder.finish()]);
        self.last = Some((frame, Scene::new(scene.view, instances)));
        Ok(())
    }

    /// Draws a frame of `model`'s first instance in `style`, its meshes drawing `edges`, into
    /// a small offscreen texture, so that the browser's GPU process builds and compiles the
    /// pipelines that frames of one mesh (most files) use while the page fetches and reads a
    /// file; `model` is uploaded again as it was after. The shaders compile at their first
    /// dispatch, so asking for the pipelines alone (`DeferredPass::warm_up`) saves less; and
    /// the GPU process compiles one pipeline after another, so a warm-up of frames the file
    /// will not draw delays the ones it will (a 1 M-triangle GLB's first frame took longer
    /// with two warm-up frames than with none).
    pub fn warm_up(
        &mut self,
        model: &Model,
        edges: (Option<EdgeSelection>, EdgeSelection),
        orbit: &Orbit,
        style: &Style,
    ) -> Result<(), String> {
        let Some(&first) = model.instances.first() else {
            return Ok(());
        };
        let one = Model {
            name: String::new(),
            meshes: Vec::new(),
            instances: vec![first],
        };
        let texture = self.offscreen((64, 48));
        self.upload(model, Some(edges.1))?;
        let drawn = self.record(&texture, &one, orbit, style, &[]);
        self.last = None;
        self.upload(model, edges.0)?;
        drawn
    }

    /// Starts reading what pixel `at` of the last frame shows; the future holds no borrow
    /// of the page's state.
    pub fn read_pick(
        &self,
        at: (u32, u32),
    ) -> Result<impl std::future::Future<Output = wirepass::Result<PickedIds>> + 'static, String>
    {
        let (frame, _) = self.last.as_ref().ok_or("nothing is drawn yet")?;
        frame
            .read_ids(&self.device, &self.queue, at, (1, 1))
            .map_err(|e| e.to_string())
    }

    /// What pixel `at` of the last frame shows, from its ids read back: the instance and
    /// where its surface is, exactly (the triangle, point and normal, and the drawn edge
    /// and vertex within 8 pixels to snap to); `None` for the background.
    pub fn locate_pick(
        &self,
        model: &Model,
        ids: &PickedIds,
        at: (u32, u32),
    ) -> Result<Option<(usize, Location)>, String> {
        let (frame, scene) = self.last.as_ref().ok_or("nothing is drawn yet")?;
        let err = |e: wirepass::Error| e.to_string();
        let hit = match ids.first(&self.store, scene).map_err(err)? {
            Picked::Background | Picked::Host => return Ok(None),
            Picked::Instance(hit) => hit,
        };
        let (m, _) = model.instances[hit.instance];
        let view = PickView {
            view: scene.view,
            image: frame.output_size(),
            vertices: wirepass::gpu::SnapVertices::Any,
            sections: scene.sections.clone(),
        };
        let l = hit
            .locate(&model.meshes[m].0, &view, at, 8.0)
            .map_err(err)?;
        Ok(Some((hit.instance, l)))
    }

    /// Reads `texture` (of the canvas's format) back as RGBA8, sRGB.
    pub fn read(
        &self,
        texture: &wgpu::Texture,
    ) -> impl std::future::Future<Output = Result<Vec<u8>, String>> {
        let (device, queue, texture) = (self.device.clone(), self.queue.clone(), texture.clone());
        async move {
            let mut bytes = wirepass::gpu::read_texture_async(
                &device,
                &queue,
                &texture,
                wgpu::TextureAspect::All,
            )
            .await
            .map_err(|e| e.to_string())?;
            if texture.format().remove_srgb_suffix() == wgpu::TextureFormat::Bgra8Unorm {
                bytes.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
            }
            Ok(bytes)
        }
    }

    /// Errors the device reported since the last call.
    pub fn take_errors(&self) -> Vec<String> {
        self.errors
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }
}
