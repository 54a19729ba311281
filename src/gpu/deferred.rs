//! The deferred wireframe pass, which orchestrates a frame: the host-depth seed (with the
//! host's depth), the visibility pass, the trace pass (where an instance draws outlines)
//! and the edge pass, for a whole scene of instances at once. Each sub-pass is a type in a
//! file of its own; this file prepares frames and records the sub-passes in order.

use super::bindings::Sources;
use super::canvas::Canvas;
use super::composite::{Composite, CompositePipeline, FrameComposite, HostSamples};
use super::edge_pass::{round_to_half, EdgePass};
use super::frame::{FrameData, FrameRecords};
use super::host_depth::{HostFrame, HostImport};
use super::instance_crossings::PairCache;
use super::mesh_store::MeshStore;
use super::options::{OutputTarget, PassOptions, TriangleIds};
use super::targets::{self, check_sampled, check_storage_output, TargetSpec, Targets};
use super::trace_pass::{cluster_list_bytes, TracePass};
use super::variants::{Mode, Variant};
use super::visibility::Visibility;
use super::{shaders, GpuTimer};
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::style::Style;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use web_time::Instant;
use wgpu::util::DeviceExt;

/// A frame ready to encode: its scene data on the GPU and the targets it draws with.
/// Several frames may be prepared and encoded before one submit; each encodes what its own
/// [`DeferredPass::prepare`] saw.
pub struct PreparedFrame {
    pass: u32,
    pub(crate) data: FrameData,
    pub(crate) targets: Targets,
    pub(crate) cull: wgpu::Buffer,
    host: Option<HostFrame>,
    /// The composite's draw of this frame's result, with a render target.
    composite: Option<FrameComposite>,
    /// Which of the pass's encodes last wrote this frame's result (0: none yet).
    encoded: AtomicU64,
}

impl PreparedFrame {
    /// The output size.
    pub fn output_size(&self) -> (u32, u32) {
        self.targets.output
    }

    /// The id target (`Rg32Uint`: instance slot, triangle; [`BACKGROUND_ID`](super::BACKGROUND_ID)
    /// in the first channel on background, [`HOST_ID`](super::HOST_ID) where the host's
    /// geometry is in front), covering the output and its guard band.
    pub fn id_texture(&self) -> &wgpu::Texture {
        &self.targets.ids
    }

    /// The reverse depth target (`Depth32Float`, 1 = near plane), as the ids.
    pub fn depth_texture(&self) -> &wgpu::Texture {
        &self.targets.depth
    }

    /// For each instance slot of the id maps, the index of the instance in the scene.
    pub fn instance_order(&self) -> &[u32] {
        &self.data.order
    }

    /// Pixels of guard band around the output in the id and depth targets.
    pub fn guard(&self) -> u32 {
        self.data.guard
    }
}

/// The deferred wireframe pass. Construct once with [`DeferredPass::new`]; each frame,
/// [`prepare`](Self::prepare) the scene, then [`encode`](Self::encode) it into the host's
/// command encoder.
///
/// Into the host's own render pass, with the host's depth hiding the lines (the crate-level
/// docs show the storage-texture path):
///
/// ```
/// use wirepass::glam::DMat4;
/// use wirepass::gpu::{texture_2d, Canvas, Composite, HostDepth, OutputTarget, RenderTarget};
/// use wirepass::{wgpu, Camera, DeferredPass, EdgeSelection, Instance, MeshStore};
/// use wirepass::{PassOptions, Scene, Style};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # let instance =
/// #     wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
/// # let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
/// # let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
/// # let mut meshes = MeshStore::new(&device);
/// # let torus = wirepass::mesh::torus(2000)?;
/// # let id = meshes.insert(&device, &queue, &torus, EdgeSelection::Polygon)?;
/// # let (lo, hi) = torus.bounds_f64();
/// # let view = Camera::framing(lo, hi, 4.0 / 3.0).to_view(4.0 / 3.0);
/// # let scene = Scene::new(view, vec![Instance::new(id, DMat4::IDENTITY)]);
/// // The host's attachments: 4x MSAA sRGB colour and a depth-stencil buffer it can sample.
/// let size = (320, 240);
/// let msaa = |label, format, usage| {
///     device.create_texture(&wgpu::TextureDescriptor {
///         label: Some(label),
///         size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
///         mip_level_count: 1,
///         sample_count: 4,
///         dimension: wgpu::TextureDimension::D2,
///         format,
///         usage,
///         view_formats: &[],
///     })
/// };
/// use wgpu::TextureUsages as U;
/// let color = msaa("colour", wgpu::TextureFormat::Rgba8UnormSrgb, U::RENDER_ATTACHMENT);
/// let depth_format = wgpu::TextureFormat::Depth24PlusStencil8;
/// let depth = msaa("depth", depth_format, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING);
/// let resolved = texture_2d(&device, "resolved", size, color.format(), U::RENDER_ATTACHMENT);
/// let color_view = color.create_view(&Default::default());
/// let depth_view = depth.create_view(&Default::default());
/// let resolved_view = resolved.create_view(&Default::default());
///
/// // Once: a pass for those attachments.
/// let target = RenderTarget {
///     format: color.format(),
///     sample_count: 4,
///     depth_stencil: Some(depth_format),
///     content: Composite::Lines,
/// };
/// let options = PassOptions { render_target: Some(target), ..Default::default() };
/// let mut pass = DeferredPass::new(&device, options)?;
///
/// // Each frame, after the host has drawn its scene into `color` and `depth` with the
/// // scene's view: the lines, hidden where the host's surfaces are in front.
/// let canvas = Canvas::new(size).with_host_depth(HostDepth { texture: &depth, matrices: scene.view });
/// let frame = pass.prepare(&device, &meshes, &scene, &Style::default(), canvas)?;
/// let mut encoder = device.create_command_encoder(&Default::default());
/// pass.encode(&device, &mut encoder, &meshes, &frame, OutputTarget::RenderPass)?;
/// {
///     // The host's render pass, with the attachments the render target names: the
///     // depth-stencil attachment too, as `depth_stencil` says (kept, neither tested nor
///     // written by wirepass). A mismatch would be wgpu's validation error: check first.
///     target.check_attachments(&color_view, Some(&depth_view))?;
///     let store = wgpu::StoreOp::Store;
///     let mut overlay = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
///         color_attachments: &[Some(wgpu::RenderPassColorAttachment {
///             view: &color_view,
///             depth_slice: None,
///             resolve_target: Some(&resolved_view),
///             ops: wgpu::Operations { load: wgpu::LoadOp::Load, store },
///         })],
///         depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
///             view: &depth_view,
///             depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store }),
///             stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store }),
///         }),
///         ..Default::default()
///     });
///     // The host may draw its own overlays here too.
///     pass.render(&mut overlay, &frame)?;
/// }
/// queue.submit([encoder.finish()]);
/// # Ok(())
/// # }
/// ```
pub struct DeferredPass {
    id: u32,
    format: wgpu::TextureFormat,
    visibility: Visibility,
    host: HostImport,
    trace: TracePass,
    edge: EdgePass,
    composite: Option<(CompositePipeline, Composite)>,
    /// Counts the encodes that write a result for [`render`](Self::render).
    results: AtomicU64,
    /// Header every list starts a frame with: no work, one workgroup row.
    reset: wgpu::Buffer,
    pub(super) diagnostics: bool,
    /// Entries of the trace pass's piece list, where a test sets it.
    pub(super) piece_room: Option<u64>,
    pub(super) targets: Option<Targets>,
    cull: Option<wgpu::Buffer>,
    /// The intersection lines of instance pairs found for recent frames
    /// (`instance_crossings.rs`), kept while the pairs' placements stay.
    pairs: PairCache,
}

/// What [`DeferredPass::warm_up`] did: the pipelines it built and the time it took. A
/// driver may compile a pipeline's shaders when it is first dispatched rather than when it
/// is built (Mesa's lavapipe does), so the first frame can still take longer than the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WarmUp {
    /// Pipelines built by this call.
    pub pipelines: usize,
    /// The time it took.
    pub elapsed: std::time::Duration,
}

impl DeferredPass {
    /// Builds the pipelines, the visibility pass as `options.triangle_ids` says.
    pub fn new(device: &wgpu::Device, options: PassOptions) -> Result<Self> {
        let primitive_index = device.features().contains(wgpu::Features::PRIMITIVE_INDEX);
        let pulled = match options.triangle_ids {
            TriangleIds::Auto => {
                !primitive_index || device.adapter_info().device_type == wgpu::DeviceType::Cpu
            }
            TriangleIds::PrimitiveIndex if !primitive_index => {
                return Err(Error::MissingFeature {
                    adapter: device.adapter_info().name,
                    what: "Features::PRIMITIVE_INDEX (TriangleIds::PrimitiveIndex)".into(),
                })
            }
            TriangleIds::PrimitiveIndex => false,
            TriangleIds::VertexPulling => true,
        };
        static NEXT: AtomicU32 = AtomicU32::new(1);
        let format = options.output_format;
        if shaders::storage_format_name(format).is_none() {
            return Err(Error::InvalidSetting(format!(
                "output format {format:?} is not one the edge pass can write \
                 (Rgba8Unorm, Rgba16Float, Rgba32Float)"
            )));
        }
        let software = options.tuning.software(device);
        let scope = crate::gpu::validation::Validation::begin(device);
        let compiled = options.pipeline_cache;
        let visibility = Visibility::new(device, pulled, compiled.clone())?;
        let composite = match &options.render_target {
            Some(t) => Some((
                CompositePipeline::new(device, t, compiled.as_ref())?,
                t.content,
            )),
            None => None,
        };
        let reset = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass list reset"),
            contents: bytemuck::cast_slice(&[0u32, 1, 1, 0]),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("creating the deferred pass: {e}")));
        }
        Ok(Self {
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            format,
            visibility,
            host: HostImport::new(compiled.clone()),
            trace: TracePass::new(format, software, compiled.clone()),
            edge: EdgePass::new(device, format, software, compiled)?,
            composite,
            results: AtomicU64::new(0),
            reset,
            diagnostics: false,
            piece_room: None,
            targets: None,
            cull: None,
            pairs: PairCache::default(),
        })
    }

    /// The format [`OutputTarget::Shaded`] and [`OutputTarget::Overlay`] write.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// GPU memory of the size-dependent targets, in bytes (0 before the first prepare).
    pub fn target_bytes(&self) -> u64 {
        self.targets.as_ref().map_or(0, Targets::bytes)
    }

    /// Prepares `scene` for `canvas` (an image size, a region of a larger image, and
    /// optionally the host's depth): checks it, writes its uniforms and instance records,
    /// and makes the targets (rebuilt only when the size changes).
    pub fn prepare<'c>(
        &mut self,
        device: &wgpu::Device,
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        canvas: impl Into<Canvas<'c>>,
    ) -> Result<PreparedFrame> {
        let canvas = canvas.into();
        let region = canvas.region;
        // An Rgba16Float output holds the background as its nearest half, so that a clear and
        // the shader's store (whose conversion may round either way) give the same bits.
        let held;
        let style = if self.format == wgpu::TextureFormat::Rgba16Float {
            held = Style {
                background: crate::Color(style.background.0.map(round_to_half)),
                ..style.clone()
            };
            &held
        } else {
            style
        };
        let records = FrameRecords::new(
            device,
            store,
            scene,
            style,
            region,
            true,
            Some(&mut self.pairs),
        )?;
        let mut data = FrameData::new(device, store, records);
        // The diagnostic map names the class of each pixel's line, which the trace pass's
        // owner words tell apart (the image is the same with them; the trace buffer takes
        // twice the memory).
        data.mixed_colors |= self.diagnostics && data.traced;
        let host = match &canvas.host_depth {
            Some(h) => Some(self.host.prepare(device, h, &scene.view, region.image)?),
            None => None,
        };
        let spec = TargetSpec {
            size: data.target_size(),
            output: region.size,
            acc_colors: data.mixed_colors,
            acc_hidden: data.hidden,
            acc_phase_words: data.chain_phases().0,
            acc_overflow_room: data.overflow_room(),
            acc_pieces: self
                .piece_room
                .unwrap_or_else(|| targets::piece_room(data.target_size())),
            result: self.composite.is_some(),
            diagnostic: self.diagnostics,
            host: host.is_some(),
            host_seed: host.as_ref().is_some_and(HostFrame::multisampled),
        };
        if self.targets.as_ref().map(Targets::spec) != Some(spec) {
            self.targets = Some(Targets::new(device, spec)?);
        }
        // The cluster list, then the piece dispatch's size.
        let cull_bytes = cluster_list_bytes(&data);
        if self.cull.as_ref().map_or(0, wgpu::Buffer::size) < cull_bytes {
            let limit = device.limits().max_storage_buffer_binding_size;
            if cull_bytes > limit {
                return Err(Error::OverLimit {
                    what: "the trace pass's cluster list for this scene, in bytes".into(),
                    value: cull_bytes,
                    limit_name: "max_storage_buffer_binding_size",
                    limit,
                });
            }
            self.cull = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("wirepass cluster list"),
                size: cull_bytes.next_power_of_two().min(limit),
                // COPY_SRC: `edge_work` reads its count back.
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }));
        }
        let split = data.split();
        self.visibility.prepare(device, split, data.sections())?;
        let targets = self
            .targets
            .clone()
            .ok_or_else(|| Error::Device("no targets".into()))?;
        let cull = self
            .cull
            .clone()
            .ok_or_else(|| Error::Device("no cluster list".into()))?;
        let composite = match (&self.composite, &targets.result) {
            (Some((pipeline, _)), Some(result)) => {
                let samples = host.as_ref().map(|host| HostSamples {
                    frame: &data.frame,
                    host,
                    ids: &targets.ids,
                    depth: &targets.depth,
                });
                Some(pipeline.bind(device, result, samples))
            }
            _ => None,
        };
        Ok(PreparedFrame {
            pass: self.id,
            data,
            targets,
            cull,
            host,
            composite,
            encoded: AtomicU64::new(0),
        })
    }

    /// What the edge pass writes for `target` (`None`: the floor, which has no edge mode).
    fn mode(&self, target: &OutputTarget<'_>) -> Result<Option<Mode>> {
        Ok(match target {
            OutputTarget::Shaded(_) => Some(Mode::Shade),
            OutputTarget::Overlay { host, .. } => {
                // An 8-bit host format without sRGB holds sRGB-encoded values.
                let f = host.texture().format();
                let encoded = !f.is_srgb() && f.target_component_alignment() == Some(1);
                Some(Mode::Overlay { encoded })
            }
            OutputTarget::RenderPass => {
                let Some((_, content)) = &self.composite else {
                    return Err(Error::Misuse(
                        "OutputTarget::RenderPass needs PassOptions::render_target".into(),
                    ));
                };
                let shaded = *content == Composite::Shaded;
                Some(Mode::Result { shaded })
            }
            #[cfg(feature = "diagnostics")]
            OutputTarget::Floor(_) => None,
            #[cfg(feature = "diagnostics")]
            OutputTarget::Diagnostic => Some(Mode::Diagnostic),
        })
    }

    /// Builds now every pipeline that encoding `frame` into outputs like `target` uses, so
    /// that the first encode does not build them. The pass builds each pipeline on first use
    /// (its modules are specialised for what a frame holds: outlines, host depth, one or many
    /// instances, the output), so the first frame of each kind costs more than the next
    /// (`wirepass render --timings` shows by how much). A host calls this while loading, with
    /// a frame prepared like the ones it will draw; `prepare` has already built the
    /// visibility and host-depth pipelines, and `new` the composite.
    pub fn warm_up(
        &self,
        device: &wgpu::Device,
        frame: &PreparedFrame,
        target: &OutputTarget<'_>,
    ) -> Result<WarmUp> {
        if frame.pass != self.id {
            return Err(Error::Misuse(
                "the frame was prepared by another DeferredPass".into(),
            ));
        }
        let start = Instant::now();
        let before = self.pipelines_built();
        // The floor's pipeline is built with the pass.
        if let Some(mode) = self.mode(target)? {
            let variant = self.variant(frame);
            let extras = (
                frame.data.intersections() > 0,
                frame.data.outline_chains().0 > 0,
            );
            let trace = || match variant.traced {
                true => self.trace.warm_up(device, variant, extras),
                false => Ok(()),
            };
            let edge = || self.edge.pipelines(device, mode, variant).map(|_| ());
            // The two passes' pipelines on two threads where there are threads (wgpu's
            // error scopes, which each build opens, are per thread).
            #[cfg(not(target_arch = "wasm32"))]
            std::thread::scope(|s| {
                let traced = s.spawn(trace);
                edge()?;
                traced
                    .join()
                    .map_err(|_| Error::Device("building the trace pass panicked".into()))?
            })?;
            #[cfg(target_arch = "wasm32")]
            {
                trace()?;
                edge()?;
            }
        }
        Ok(WarmUp {
            pipelines: self.pipelines_built() - before,
            elapsed: start.elapsed(),
        })
    }

    /// How many pipelines the pass has built so far: it builds each on first use, for
    /// the kinds of frame and output it is given.
    pub fn pipelines_built(&self) -> usize {
        self.visibility.built()
            + self.host.built()
            + usize::from(self.composite.is_some())
            + self.trace.built()
            + self.edge.built()
    }

    fn variant(&self, frame: &PreparedFrame) -> Variant {
        Variant {
            split: frame.data.split(),
            traced: frame.data.traced,
            patches: frame.data.patches,
            colors: frame.data.traced && frame.data.mixed_colors,
            hidden: frame.data.hidden,
            patterns: frame.data.traced && frame.data.patterns,
            sections: frame.data.traced && frame.data.sections(),
            crossing: frame.data.traced && frame.data.crossing,
            host: frame.host.is_some(),
            uniform_instances: frame.data.uniform_instances,
            one_instance: frame.data.uniforms.instances() == 1,
        }
    }

    /// Records the visibility pass, the trace pass (where an instance draws its outline)
    /// and the edge pass into `encoder`. `store` must be the store the frame was prepared
    /// with, unchanged but for inserted meshes.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &PreparedFrame,
        target: OutputTarget<'_>,
    ) -> Result<()> {
        self.encode_inner(device, encoder, store, frame, target, None, true)
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn encode_inner(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &PreparedFrame,
        target: OutputTarget<'_>,
        mut timer: Option<&mut GpuTimer>,
        visibility: bool,
    ) -> Result<()> {
        if frame.pass != self.id {
            return Err(Error::Misuse(
                "the frame was prepared by another DeferredPass".into(),
            ));
        }
        frame.data.check_store(store)?;
        let t = &frame.targets;
        let mode = self.mode(&target)?;
        let result_view;
        let (out_color, host_color) = match &target {
            OutputTarget::Shaded(v) => {
                check_storage_output(v, self.format, t.output, "the output texture")?;
                (Some(*v), None)
            }
            OutputTarget::Overlay { host, output } => {
                check_storage_output(output, self.format, t.output, "the output texture")?;
                check_sampled(host, t.output, "the host colour texture")?;
                (Some(*output), Some(*host))
            }
            OutputTarget::RenderPass => {
                let result = t.result.as_ref().ok_or_else(|| {
                    Error::Misuse(
                        "OutputTarget::RenderPass needs PassOptions::render_target".into(),
                    )
                })?;
                result_view = result.create_view(&Default::default());
                (Some(&result_view), None)
            }
            #[cfg(feature = "diagnostics")]
            OutputTarget::Floor(v) => {
                check_storage_output(v, self.format, t.output, "the output texture")?;
                (Some(*v), None)
            }
            #[cfg(feature = "diagnostics")]
            OutputTarget::Diagnostic => {
                if t.diagnostic.is_none() {
                    return Err(Error::Misuse(
                        "diagnostics were not enabled (DeferredPass::with_diagnostics)".into(),
                    ));
                }
                (None, None)
            }
        };
        if visibility {
            if let Some(host) = &frame.host {
                self.host
                    .encode(device, encoder, &frame.data, host, t, timer.as_deref_mut())?;
            }
            let seeded = frame.host.is_some();
            self.visibility.encode(
                device,
                encoder,
                &frame.data,
                t,
                seeded,
                timer.as_deref_mut(),
            )?;
        }
        let ids = t.ids.create_view(&Default::default());
        let host_depth = t.host.as_ref().map(|h| h.create_view(&Default::default()));
        let (diag, resolved) = match &t.diagnostic {
            Some((d, r)) => (
                Some(d.create_view(&Default::default())),
                Some(r.create_view(&Default::default())),
            ),
            None => (None, None),
        };
        let sources = Sources {
            ids: Some(&ids),
            host_depth: host_depth.as_ref(),
            acc: Some(&t.acc),
            cull: Some(&frame.cull),
            work: Some(&t.work),
            tiles: Some(&t.tiles),
            composite: t.composite.as_ref(),
            out_color,
            host_color,
            out_diagnostic: diag.as_ref(),
            out_ids: resolved.as_ref(),
            from_host: !matches!(target, OutputTarget::RenderPass),
            ..Sources::frame(&frame.data)
        };
        // Only the floor has no edge mode.
        #[cfg(feature = "diagnostics")]
        let Some(mode) = mode
        else {
            return self
                .edge
                .encode_floor(device, encoder, &sources, t.output, timer);
        };
        #[cfg(not(feature = "diagnostics"))]
        let Some(mode) = mode
        else {
            return Err(Error::Misuse(
                "the floor needs the diagnostics feature".into(),
            ));
        };
        let variant = self.variant(frame);
        if variant.traced {
            let buffers = (t, &frame.cull, &self.reset);
            let timer = timer.as_deref_mut();
            self.trace
                .encode(device, encoder, buffers, &sources, variant, timer)?;
        }
        let edge = self.edge.pipelines(device, mode, variant)?;
        if let Mode::Result { .. } = mode {
            let n = self.results.fetch_add(1, Ordering::Relaxed) + 1;
            frame.encoded.store(n, Ordering::Relaxed);
        }
        let output = (mode, out_color);
        let reset = &self.reset;
        self.edge
            .encode(device, encoder, (&edge, reset), t, &sources, output, timer)
    }

    /// Draws `frame`'s result into the host's render pass, whose attachments match
    /// [`PassOptions::render_target`]: the lines over the host's image, or the shaded surface
    /// and its lines. The frame must have been encoded with [`OutputTarget::RenderPass`],
    /// and no other frame of this pass encoded since (each frame's result lives in the
    /// pass's one result texture until the next encode).
    ///
    /// The frame fills the render pass's viewport, which the host sets to the frame's size
    /// anywhere in its attachment (the whole attachment by default; a panel of an editor, or
    /// egui's paint callback, elsewhere); the host's scissor rectangle clips it.
    ///
    /// A frame prepared with the host's depth, drawn into a render pass with a depth
    /// attachment, is tested against that attachment per sample (it must hold the depth
    /// the frame was prepared with), so a multisampled host's own edges in front of an
    /// instance keep their antialiasing; the attachment is never written.
    ///
    /// wirepass cannot see the render pass's attachments: if they differ from the render
    /// target (format, sample count, a depth-stencil attachment), wgpu rejects the draw with a
    /// validation error, not a `wirepass::Error`. [`RenderTarget::check_attachments`] checks
    /// them beforehand.
    ///
    /// [`RenderTarget::check_attachments`]: super::RenderTarget::check_attachments
    pub fn render(&self, pass: &mut wgpu::RenderPass<'_>, frame: &PreparedFrame) -> Result<()> {
        if frame.pass != self.id {
            return Err(Error::Misuse(
                "the frame was prepared by another DeferredPass".into(),
            ));
        }
        let (Some((pipeline, _)), Some(group)) = (&self.composite, &frame.composite) else {
            return Err(Error::Misuse(
                "DeferredPass::render needs PassOptions::render_target".into(),
            ));
        };
        let encoded = frame.encoded.load(Ordering::Relaxed);
        if encoded == 0 {
            return Err(Error::Misuse(
                "the frame was not encoded with OutputTarget::RenderPass before render".into(),
            ));
        }
        if encoded != self.results.load(Ordering::Relaxed) {
            return Err(Error::Misuse(
                "another frame was encoded after this one and overwrote its result: render \
                 each frame before encoding the next"
                    .into(),
            ));
        }
        let tiles = frame
            .targets
            .composite
            .as_ref()
            .ok_or_else(|| Error::Device("the frame has no composite tiles".into()))?;
        pipeline.draw(pass, group, tiles)
    }
}
