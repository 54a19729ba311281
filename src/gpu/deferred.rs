//! The deferred wireframe pass: the visibility pass, the outline pass (with outlines on) and
//! the edge pass, for a whole scene of instances at once.

use super::bindings::{self, store_resources, Compute, Res, Sources};
use super::composite::{Composite, CompositePipeline, RenderTarget};
use super::frame::{Canvas, FrameData};
use super::host_depth::{HostFrame, HostImport};
use super::mesh_store::MeshStore;
use super::targets::{self, TargetSpec, Targets, LIST_HEADER, RESULT_FORMAT};
use super::variants::{Mode, Variant};
use super::visibility::Visibility;
#[cfg(feature = "diagnostics")]
use super::EncodeOptions;
use super::{shaders, GpuTimer};
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::style::Style;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use wgpu::util::DeviceExt;

/// Edge-pass workgroup side (8 × 8 pixels).
const TILE: u32 = 8;
/// Workgroup size of the outline pass and of the refine dispatch.
const GROUP: u32 = 64;

/// Construction options.
#[derive(Clone, Copy, Debug)]
pub struct PassOptions {
    /// Format of the storage texture that [`OutputTarget::Shaded`] and
    /// [`OutputTarget::Overlay`] write: `Rgba8Unorm` (written sRGB-encoded), `Rgba16Float`
    /// or `Rgba32Float` (linear). It needs `STORAGE_BINDING` usage; with
    /// `RENDER_ATTACHMENT` as well (and one mip level), [`OutputTarget::Shaded`] clears the
    /// background (one fill) instead of writing it pixel by pixel, with the same result. An
    /// `Rgba16Float` output takes the background as its nearest half.
    pub output_format: wgpu::TextureFormat,
    /// The host's render pass that [`DeferredPass::render`] draws into, if it is used.
    pub render_target: Option<RenderTarget>,
    /// How the visibility pass learns which triangle a pixel shows.
    pub triangle_ids: TriangleIds,
}

impl Default for PassOptions {
    fn default() -> Self {
        Self {
            output_format: wgpu::TextureFormat::Rgba8Unorm,
            render_target: None,
            triangle_ids: TriangleIds::Auto,
        }
    }
}

/// How the visibility pass learns which triangle each pixel shows. Every choice gives the
/// same ids; they differ in what the device needs and in speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TriangleIds {
    /// [`VertexPulling`](TriangleIds::VertexPulling) on a CPU adapter, whose rasterizer
    /// takes a slower path for a fragment shader that reads the primitive index (the README's
    /// speed section has lavapipe's figures), and on a device without
    /// `Features::PRIMITIVE_INDEX`;
    /// [`PrimitiveIndex`](TriangleIds::PrimitiveIndex) elsewhere.
    #[default]
    Auto,
    /// An indexed draw whose fragment shader reads `@builtin(primitive_index)`. Needs
    /// `Features::PRIMITIVE_INDEX`.
    PrimitiveIndex,
    /// A draw of three vertices a triangle, each reading its corner from the store's
    /// buffers, that passes the triangle as a flat varying. Needs storage buffers in the
    /// vertex stage.
    VertexPulling,
}

/// Where the edge pass writes.
pub enum OutputTarget<'a> {
    /// Shade the surface and draw the lines over it, into a storage texture of the pass's
    /// output format and the frame's size.
    Shaded(&'a wgpu::TextureView),
    /// Post-process: blend the lines over the host's colour image `host` (a sampled
    /// texture of the frame's size) into `output`; pixels without a line copy `host`. A
    /// float or sRGB host format holds what it says; an 8-bit host format without sRGB is
    /// taken to hold sRGB-encoded values, like the pass's own `Rgba8Unorm` output.
    Overlay {
        /// The host's rendered colour, read as a float texture.
        host: &'a wgpu::TextureView,
        /// Where the blended image goes (the pass's output format).
        output: &'a wgpu::TextureView,
    },
    /// Diagnostics for tools and tests into the pass's own textures (needs
    /// [`DeferredPass::with_diagnostics`]): the distance in pixels to the line and the
    /// reverse depth of the visible point, and the (instance slot, triangle) after the exact
    /// coverage test.
    #[cfg(feature = "diagnostics")]
    Diagnostic,
    /// The benchmark floor: reads each pixel's id and writes the fill or background colour
    /// into the output, doing none of the edge work. What a deferred pass cannot go below.
    #[cfg(feature = "diagnostics")]
    Floor(&'a wgpu::TextureView),
    /// The frame's own result, which [`DeferredPass::render`] then draws into the host's
    /// render pass (needs [`PassOptions::render_target`]).
    RenderPass,
}

struct EdgePipelines {
    /// Writes the pixels without a triangle, where no clear lays them down.
    background: Compute,
    classify: Compute,
    /// Lines over the background of the tiles the outline pass lists; with outlines only.
    outlined: Option<Compute>,
    border: Compute,
    tiles: Compute,
    refine: Compute,
}

struct OutlinePipelines {
    cull: Compute,
    /// Lists the pieces of the listed clusters' outline edges.
    draw: Compute,
    /// Draws the listed pieces, one a lane.
    pieces: Compute,
}

/// Where the piece dispatch's size lies in a frame's cluster list buffer: after the cluster
/// list (header, then two words per cluster).
fn piece_size_at(data: &FrameData) -> u64 {
    LIST_HEADER + 8 * u64::from(data.uniforms_clusters().max(1))
}

/// A frame ready to encode: its scene data on the GPU and the targets it draws with.
/// Several frames may be prepared and encoded before one submit; each encodes what its own
/// [`DeferredPass::prepare`] saw.
pub struct PreparedFrame {
    pass: u32,
    pub(crate) data: FrameData,
    pub(crate) targets: Targets,
    cull: wgpu::Buffer,
    host: Option<HostFrame>,
    /// The composite's bind group over this frame's result, with a render target.
    composite: Option<wgpu::BindGroup>,
    /// Which of the pass's encodes last wrote this frame's result (0: none yet).
    encoded: AtomicU64,
}

/// How much of a frame the edge pass's later dispatches took on (see
/// [`PreparedFrame::edge_work`]).
#[cfg(feature = "diagnostics")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeWork {
    /// 8×8 output tiles holding foreground, which the tile dispatch visited.
    pub tiles: u32,
    /// Output tiles the outline pass's lines reach, whose background the edge pass's
    /// outlined dispatch visited (0 where the outline pass did not run).
    pub outlined_tiles: u32,
    /// Output tiles in all.
    pub all_tiles: u32,
    /// Pixels the refine dispatch decided: centres the exact test could not settle from the
    /// rasterizer's triangle, and background next to foreground.
    pub refined: u32,
    /// Output pixels in all.
    pub pixels: u32,
    /// Clusters of 64 triangles the outline pass's cull listed (those that may hold an
    /// outline edge from the eye, or a drawn edge of a large patch), 0 where it did not run.
    pub outline_clusters: u32,
    /// Pieces (up to 16 px) of outline edges the outline pass listed or found beyond its
    /// list's room, 0 where it did not run.
    pub outline_pieces: u32,
    /// How many of them its piece list has room for; it draws the others where it finds
    /// them.
    pub piece_room: u32,
}

#[cfg(feature = "diagnostics")]
impl PreparedFrame {
    /// What the outline pass and the edge pass's tile and refine dispatches took on in the
    /// last encode of this frame, read back from the GPU (it waits for the work submitted so
    /// far): for tools, tests and benchmarks.
    pub fn edge_work(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<EdgeWork> {
        let count = |buffer: &wgpu::Buffer, at: u64| -> Result<u32> {
            let bytes = super::readback::read_buffer(device, queue, buffer, at + 12, 4)?;
            Ok(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
        };
        let (w, h) = self.targets.output;
        let t = &self.targets;
        Ok(EdgeWork {
            tiles: count(&t.tiles, 0)?,
            outlined_tiles: if self.data.outlines {
                count(&t.acc, t.acc_tiles)?
            } else {
                0
            },
            all_tiles: w.div_ceil(TILE) * h.div_ceil(TILE),
            refined: count(&t.work, 0)?,
            pixels: w * h,
            outline_clusters: if self.data.outlines {
                count(&self.cull, 0)?
            } else {
                0
            },
            outline_pieces: if self.data.outlines {
                count(&t.acc, t.acc_pieces)?
            } else {
                0
            },
            piece_room: t.piece_room(),
        })
    }
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

    /// The (instance slot, triangle) each output pixel centre sees after the exact coverage
    /// test, written by [`OutputTarget::Diagnostic`].
    #[cfg(feature = "diagnostics")]
    pub fn resolved_id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.diagnostic.as_ref().map(|d| &d.1)
    }

    /// The diagnostic map written by [`OutputTarget::Diagnostic`].
    #[cfg(feature = "diagnostics")]
    pub fn diagnostic_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.diagnostic.as_ref().map(|d| &d.0)
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
/// ```no_run
/// use wirepass::gpu::{Canvas, Composite, HostDepth, OutputTarget, PassOptions, RenderTarget};
/// use wirepass::{wgpu, DeferredPass, MeshStore, Scene, Style};
///
/// # fn frame(
/// #     device: &wgpu::Device,
/// #     queue: &wgpu::Queue,
/// #     meshes: &MeshStore,
/// #     scene: &Scene,
/// #     color: &wgpu::TextureView,
/// #     depth: &wgpu::Texture,
/// # ) -> wirepass::Result<()> {
/// // Once: a pass for the host's attachments (4x MSAA sRGB colour, its depth-stencil).
/// let mut pass = DeferredPass::new(
///     device,
///     PassOptions {
///         render_target: Some(RenderTarget {
///             format: wgpu::TextureFormat::Rgba8UnormSrgb,
///             sample_count: 4,
///             depth_stencil: Some(wgpu::TextureFormat::Depth24PlusStencil8),
///             content: Composite::Lines,
///         }),
///         ..Default::default()
///     },
/// )?;
///
/// // Each frame, after the host has drawn its scene into `color` and `depth` with the
/// // scene's view: the lines, hidden where the host's surfaces are in front.
/// let size = (depth.width(), depth.height());
/// let canvas = Canvas::new(size).with_host_depth(HostDepth { texture: depth, view: scene.view });
/// let frame = pass.prepare(device, meshes, scene, &Style::default(), canvas)?;
/// let mut encoder = device.create_command_encoder(&Default::default());
/// pass.encode(device, &mut encoder, meshes, &frame, OutputTarget::RenderPass)?;
/// {
///     let mut overlay = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
///         color_attachments: &[Some(wgpu::RenderPassColorAttachment {
///             view: color,
///             depth_slice: None,
///             resolve_target: None,
///             ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
///         })],
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
    edge: Mutex<HashMap<(Mode, Variant), Arc<EdgePipelines>>>,
    outline: Mutex<HashMap<Variant, Arc<OutlinePipelines>>>,
    /// The benchmark floor's pipeline ([`OutputTarget::Floor`]).
    #[cfg(feature = "diagnostics")]
    floor: Compute,
    composite: Option<(CompositePipeline, Composite)>,
    /// Counts the encodes that write a result for [`render`](Self::render).
    results: AtomicU64,
    /// Header every list starts a frame with: no work, one workgroup row.
    reset: wgpu::Buffer,
    diagnostics: bool,
    targets: Option<Targets>,
    cull: Option<wgpu::Buffer>,
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
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let visibility = Visibility::new(device, pulled)?;
        #[cfg(feature = "diagnostics")]
        let floor = Compute::new(
            device,
            &edge_module(device, format, super::variants::FLOOR_FLAGS),
            "floor_main",
            vec![Res::Frame, Res::Ids, Res::OutColor],
            format,
        )?;
        let composite = match &options.render_target {
            Some(t) => Some((CompositePipeline::new(device, t)?, t.content)),
            None => None,
        };
        let reset = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass list reset"),
            contents: bytemuck::cast_slice(&[0u32, 1, 1, 0]),
            usage: wgpu::BufferUsages::COPY_SRC,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("creating the deferred pass: {e}")));
        }
        Ok(Self {
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            format,
            visibility,
            host: HostImport::new(),
            edge: Mutex::default(),
            outline: Mutex::default(),
            #[cfg(feature = "diagnostics")]
            floor,
            composite,
            results: AtomicU64::new(0),
            reset,
            diagnostics: false,
            targets: None,
            cull: None,
        })
    }

    /// Enables [`OutputTarget::Diagnostic`], which needs 24 more bytes of targets per pixel;
    /// tools and tests use it, a renderer does not need it.
    #[cfg(feature = "diagnostics")]
    pub fn with_diagnostics(mut self) -> Self {
        self.diagnostics = true;
        self.targets = None;
        self
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
        let data = FrameData::new(device, store, scene, style, region, true)?;
        let host = match &canvas.host_depth {
            Some(h) => Some(self.host.prepare(device, h, &scene.view, region.image)?),
            None => None,
        };
        let spec = TargetSpec {
            size: data.target_size(),
            output: region.size,
            acc_colors: data.mixed_colors,
            result: self.composite.is_some(),
            diagnostic: self.diagnostics,
            host: host.is_some(),
        };
        if self.targets.as_ref().map(Targets::spec) != Some(spec) {
            self.targets = Some(Targets::new(device, spec)?);
        }
        // The cluster list, then the piece dispatch's size.
        let cull_bytes = piece_size_at(&data) + LIST_HEADER;
        if self.cull.as_ref().map_or(0, wgpu::Buffer::size) < cull_bytes {
            let limit = device.limits().max_storage_buffer_binding_size;
            if cull_bytes > limit {
                return Err(Error::OverLimit {
                    what: "the outline pass's cluster list for this scene, in bytes".into(),
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
        self.visibility.prepare(device, split)?;
        let targets = self
            .targets
            .clone()
            .ok_or_else(|| Error::Device("no targets".into()))?;
        let cull = self
            .cull
            .clone()
            .ok_or_else(|| Error::Device("no cluster list".into()))?;
        let composite = match (&self.composite, &targets.result) {
            (Some((pipeline, _)), Some(result)) => Some(pipeline.bind(device, result)),
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

    /// The value every output pixel without a triangle or a line gets, as a clear colour,
    /// where that is one value (Shade: the background, encoded as store_pixel encodes it;
    /// Result: transparent) and the output `texture` can be cleared whole (RENDER_ATTACHMENT
    /// usage, one mip level: the storage view writes that level).
    fn background_clear(
        &self,
        mode: Mode,
        texture: &wgpu::Texture,
        frame: &PreparedFrame,
    ) -> Option<wgpu::Color> {
        let usage = texture.usage();
        if !usage.contains(wgpu::TextureUsages::RENDER_ATTACHMENT) || texture.mip_level_count() != 1
        {
            return None;
        }
        match mode {
            Mode::Shade => Some(background_value(
                self.format,
                frame.data.uniforms.background(),
            )),
            Mode::Result { .. } => Some(wgpu::Color::TRANSPARENT),
            Mode::Overlay { .. } => None,
            #[cfg(feature = "diagnostics")]
            Mode::Diagnostic => None,
        }
    }

    fn variant(&self, frame: &PreparedFrame) -> Variant {
        Variant {
            split: frame.data.split(),
            outlines: frame.data.outlines,
            patches: frame.data.patches,
            colors: frame.data.outlines && frame.data.mixed_colors,
            host: frame.host.is_some(),
            uniform_instances: frame.data.uniform_instances,
            one_instance: frame.data.uniforms.instances() == 1,
        }
    }

    fn edge_pipelines(
        &self,
        device: &wgpu::Device,
        mode: Mode,
        v: Variant,
    ) -> Result<Arc<EdgePipelines>> {
        let mut cache = self
            .edge
            .lock()
            .map_err(|_| Error::Device("pipeline cache poisoned".into()))?;
        if let Some(p) = cache.get(&(mode, v)) {
            return Ok(p.clone());
        }
        let mut flags = v.flags();
        flags.extend_from_slice(mode.flags());
        let (out, color) = match mode {
            Mode::Shade => (vec![Res::OutColor], self.format),
            Mode::Overlay { .. } => (vec![Res::OutColor, Res::HostColor], self.format),
            Mode::Result { .. } => (vec![Res::OutColor], RESULT_FORMAT),
            #[cfg(feature = "diagnostics")]
            Mode::Diagnostic => (vec![Res::OutDiagnostic, Res::OutIds], self.format),
        };
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = edge_module(device, self.format, &flags);
        let mut common = store_resources(v.split, false, v.uniform_instances);
        common.push(Res::Ids);
        if v.host {
            common.push(Res::HostDepth);
        }
        if v.outlines {
            common.push(Res::Acc);
        }
        let with = |extra: &[Res]| {
            let mut r = common.clone();
            r.extend_from_slice(extra);
            r.extend_from_slice(&out);
            r
        };
        let background = Compute::new(device, &module, "background_main", with(&[]), color)?;
        let classify = Compute::new(
            device,
            &module,
            "classify_main",
            vec![Res::Frame, Res::Ids, Res::TilesRw, Res::WorkRw],
            color,
        )?;
        let outlined = if v.outlines {
            Some(Compute::new(
                device,
                &module,
                "outlined_main",
                with(&[]),
                color,
            )?)
        } else {
            None
        };
        let border = Compute::new(device, &module, "border_main", with(&[Res::WorkRw]), color)?;
        let mut tile_res = vec![Res::Tiles, Res::WorkRw];
        let mut neighbours = vec![Res::Neighbours];
        if v.split {
            neighbours.push(Res::NeighboursHi);
        }
        if v.patches {
            // A quad's search crosses its diagonal.
            tile_res.extend_from_slice(&neighbours);
        }
        let tiles = Compute::new(device, &module, "tile_main", with(&tile_res), color)?;
        let mut refine_res = with(&[Res::Work]);
        refine_res.extend_from_slice(&neighbours);
        let refine = Compute::new(device, &module, "refine_main", refine_res, color)?;
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("building the edge pass: {e}")));
        }
        let p = Arc::new(EdgePipelines {
            background,
            classify,
            outlined,
            border,
            tiles,
            refine,
        });
        cache.insert((mode, v), p.clone());
        Ok(p)
    }

    fn outline_pipelines(
        &self,
        device: &wgpu::Device,
        v: Variant,
    ) -> Result<Arc<OutlinePipelines>> {
        let mut cache = self
            .outline
            .lock()
            .map_err(|_| Error::Device("pipeline cache poisoned".into()))?;
        if let Some(p) = cache.get(&v) {
            return Ok(p.clone());
        }
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let source = shaders::outline_source(&v.flags());
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass outline pass"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let cull = Compute::new(
            device,
            &module,
            "outline_cull",
            vec![
                Res::Frame,
                bindings::instances(v.uniform_instances),
                Res::Clusters,
                Res::CullRw,
            ],
            self.format,
        )?;
        let mut draw_res = store_resources(v.split, true, v.uniform_instances);
        draw_res.extend([Res::Ids, Res::AccRw]);
        if v.host {
            draw_res.push(Res::HostDepth);
        }
        let pieces = Compute::new(
            device,
            &module,
            "outline_pieces_main",
            draw_res.clone(),
            self.format,
        )?;
        draw_res.push(Res::Cull);
        let draw = Compute::new(device, &module, "outline_main", draw_res, self.format)?;
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("building the outline pass: {e}")));
        }
        let p = Arc::new(OutlinePipelines { cull, draw, pieces });
        cache.insert(v, p.clone());
        Ok(p)
    }

    /// Records the visibility pass, the outline pass (where an instance draws its outline)
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

    /// [`encode`](Self::encode) with what tools add (see [`EncodeOptions`]): timestamps
    /// around each pass, or a second output over the ids the last encode of this frame
    /// rasterized.
    #[cfg(feature = "diagnostics")]
    pub fn encode_with(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &PreparedFrame,
        target: OutputTarget<'_>,
        options: EncodeOptions<'_>,
    ) -> Result<()> {
        let visibility = !options.reuse_ids;
        self.encode_inner(
            device,
            encoder,
            store,
            frame,
            target,
            options.timer,
            visibility,
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn encode_inner(
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
        let result_view;
        let (mode, out_color, host_color) = match &target {
            OutputTarget::Shaded(v) => {
                check_storage_output(v, self.format, t.output, "the output texture")?;
                (Some(Mode::Shade), Some(*v), None)
            }
            OutputTarget::Overlay { host, output } => {
                check_storage_output(output, self.format, t.output, "the output texture")?;
                check_sampled(host, t.output, "the host colour texture")?;
                let f = host.texture().format();
                let encoded = !f.is_srgb() && f.target_component_alignment() == Some(1);
                (Some(Mode::Overlay { encoded }), Some(*output), Some(*host))
            }
            OutputTarget::RenderPass => {
                let (Some((_, content)), Some(result)) = (&self.composite, &t.result) else {
                    return Err(Error::Misuse(
                        "OutputTarget::RenderPass needs PassOptions::render_target".into(),
                    ));
                };
                result_view = result.create_view(&Default::default());
                let shaded = *content == Composite::Shaded;
                (Some(Mode::Result { shaded }), Some(&result_view), None)
            }
            #[cfg(feature = "diagnostics")]
            OutputTarget::Floor(v) => {
                check_storage_output(v, self.format, t.output, "the output texture")?;
                (None, Some(*v), None)
            }
            #[cfg(feature = "diagnostics")]
            OutputTarget::Diagnostic => {
                if t.diagnostic.is_none() {
                    return Err(Error::Misuse(
                        "diagnostics were not enabled (DeferredPass::with_diagnostics)".into(),
                    ));
                }
                (Some(Mode::Diagnostic), None, None)
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
            out_color,
            host_color,
            out_diagnostic: diag.as_ref(),
            out_ids: resolved.as_ref(),
            from_host: !matches!(target, OutputTarget::RenderPass),
            ..Sources::frame(&frame.data)
        };
        let (w, h) = t.output;
        // Only the floor has no edge mode.
        #[cfg(feature = "diagnostics")]
        let Some(mode) = mode
        else {
            let group = self.floor.bind(device, &sources)?;
            let names = ("wirepass floor", "edge.floor");
            let size = Size::Grid(w.div_ceil(TILE), h.div_ceil(TILE));
            dispatch(encoder, timer, names, (&self.floor, &group), size);
            return Ok(());
        };
        #[cfg(not(feature = "diagnostics"))]
        let Some(mode) = mode
        else {
            return Err(Error::Misuse(
                "the floor needs the diagnostics feature".into(),
            ));
        };
        let variant = self.variant(frame);
        if variant.outlines {
            self.outline_pass(
                device,
                encoder,
                frame,
                &sources,
                variant,
                timer.as_deref_mut(),
            )?;
        }
        let edge = self.edge_pipelines(device, mode, variant)?;
        if let Mode::Result { .. } = mode {
            let n = self.results.fetch_add(1, Ordering::Relaxed) + 1;
            frame.encoded.store(n, Ordering::Relaxed);
        }
        // Where the background is one colour and the output can be cleared, a clear lays it
        // down at the speed of a fill; elsewhere a dispatch writes it.
        let clear = out_color.and_then(|v| self.background_clear(mode, v.texture(), frame));
        let (columns, rows) = (w.div_ceil(TILE), h.div_ceil(TILE));
        // The lists first, then the background (the clear or its dispatch), then the passes
        // that write the output: a software rasterizer runs a clear when a later pass reads
        // its texture, and a dispatch between the two would be timed in neither span.
        let mut dispatches = vec![
            (
                "wirepass edge classify",
                "edge.classify",
                &edge.classify,
                Size::Grid(columns.div_ceil(TILE), rows.div_ceil(TILE)),
            ),
            (
                "wirepass edge border",
                "edge.border",
                &edge.border,
                Size::Grid((2 * (w + h)).div_ceil(64), 1),
            ),
        ];
        let lists = dispatches.len();
        if clear.is_none() {
            dispatches.push((
                "wirepass edge background",
                "edge.background",
                &edge.background,
                Size::Grid(columns, rows),
            ));
        }
        if let Some(outlined) = &edge.outlined {
            let size = Size::Indirect(&t.acc, t.acc_tiles);
            dispatches.push(("wirepass edge outlined", "edge.outlined", outlined, size));
        }
        dispatches.extend([
            (
                "wirepass edge tiles",
                "edge.tiles",
                &edge.tiles,
                Size::Indirect(&t.tiles, 0),
            ),
            (
                "wirepass edge refine",
                "edge.refine",
                &edge.refine,
                Size::Indirect(&t.work, 0),
            ),
        ]);
        // Bound before anything is recorded, so a failure leaves the encoder as it was.
        let groups = dispatches
            .iter()
            .map(|d| d.2.bind(device, &sources))
            .collect::<Result<Vec<_>>>()?;
        encoder.copy_buffer_to_buffer(&self.reset, 0, &t.tiles, 0, LIST_HEADER);
        encoder.copy_buffer_to_buffer(&self.reset, 0, &t.work, 0, LIST_HEADER);
        // Each dispatch is a pass of its own, timed on its own (the benchmark sums the
        // `edge.*` spans into the edge pass).
        for (k, ((label, span, pipeline, size), group)) in
            dispatches.into_iter().zip(groups).enumerate()
        {
            if k == lists {
                if let (Some(color), Some(view)) = (clear, out_color) {
                    // A view of its own: the host's may leave out RENDER_ATTACHMENT usage.
                    let whole = view.texture().create_view(&Default::default());
                    clear_output(encoder, timer.as_deref_mut(), &whole, color);
                }
            }
            let timer = timer.as_deref_mut();
            dispatch(encoder, timer, (label, span), (pipeline, &group), size);
        }
        Ok(())
    }

    /// Draws `frame`'s result into the host's render pass, whose attachments match
    /// [`PassOptions::render_target`]: the lines over the host's image, or the shaded surface
    /// and its lines. The frame must have been encoded with [`OutputTarget::RenderPass`],
    /// and no other frame of this pass encoded since (each frame's result lives in the
    /// pass's one result texture until the next encode).
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
        pass.set_pipeline(&pipeline.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// The outline pass: `outline_cull` lists the (instance, cluster) pairs that may hold
    /// an outline edge, on a 2D grid of workgroups (huge scenes need more than one dimension
    /// allows); `outline_main` then visits their triangles, dispatched indirectly with the
    /// size the cull leaves, and lists the pieces (up to 16 px) of their outline edges;
    /// `outline_pieces_main` draws those, one a lane.
    fn outline_pass(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        frame: &PreparedFrame,
        sources: &Sources<'_>,
        variant: Variant,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let p = self.outline_pipelines(device, variant)?;
        let cull = p.cull.bind(device, sources)?;
        let draw = p.draw.bind(device, sources)?;
        let pieces = p.pieces.bind(device, sources)?;
        let t = &frame.targets;
        encoder.clear_buffer(&t.acc, 0, Some(t.acc_pieces));
        encoder.copy_buffer_to_buffer(&self.reset, 0, &t.acc, t.acc_tiles, LIST_HEADER);
        encoder.copy_buffer_to_buffer(&self.reset, 0, &t.acc, t.acc_pieces, LIST_HEADER);
        encoder.copy_buffer_to_buffer(&self.reset, 0, &frame.cull, 0, LIST_HEADER);
        let groups = frame.data.uniforms_clusters().div_ceil(GROUP);
        let max = device.limits().max_compute_workgroups_per_dimension.max(1);
        let (x, y) = (groups.clamp(1, max), groups.div_ceil(max).max(1));
        let names = ("wirepass outline cull", "outline.cull");
        let size = Size::Grid(x, y);
        dispatch(encoder, timer.as_deref_mut(), names, (&p.cull, &cull), size);
        let names = ("wirepass outline pass", "outline.draw");
        let size = Size::Indirect(&frame.cull, 0);
        dispatch(encoder, timer.as_deref_mut(), names, (&p.draw, &draw), size);
        // The piece dispatch's size, where no pass binding `acc` for writing reads it.
        let size_at = piece_size_at(&frame.data);
        encoder.copy_buffer_to_buffer(&t.acc, t.acc_pieces, &frame.cull, size_at, LIST_HEADER);
        let names = ("wirepass outline pieces", "outline.pieces");
        let size = Size::Indirect(&frame.cull, size_at);
        dispatch(encoder, timer, names, (&p.pieces, &pieces), size);
        Ok(())
    }
}

/// How a dispatch is sized: a grid of workgroups, or by the size an earlier dispatch left in
/// a buffer, at a byte offset.
enum Size<'b> {
    Grid(u32, u32),
    Indirect(&'b wgpu::Buffer, u64),
}

/// Clears `view` to `color` in a render pass of its own, timed as `edge.clear`.
fn clear_output(
    encoder: &mut wgpu::CommandEncoder,
    timer: Option<&mut GpuTimer>,
    view: &wgpu::TextureView,
    color: wgpu::Color,
) {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("wirepass edge clear"),
        color_attachments: &[targets::cleared(view, color)],
        depth_stencil_attachment: None,
        timestamp_writes: timer.and_then(|t| t.render_span("edge.clear")),
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// Records one dispatch as a compute pass of its own, labelled `names.0` and timed as the
/// span `names.1`.
fn dispatch(
    encoder: &mut wgpu::CommandEncoder,
    timer: Option<&mut GpuTimer>,
    names: (&str, &'static str),
    (pipeline, group): (&Compute, &wgpu::BindGroup),
    size: Size<'_>,
) {
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(names.0),
        timestamp_writes: timer.and_then(|t| t.compute_span(names.1)),
    });
    pass.set_pipeline(&pipeline.pipeline);
    pass.set_bind_group(0, group, &[]);
    match size {
        Size::Grid(x, y) => pass.dispatch_workgroups(x, y, 1),
        Size::Indirect(buffer, offset) => pass.dispatch_workgroups_indirect(buffer, offset),
    }
}

/// What store_pixel writes into an output of `format` for a pixel of background colour
/// `background` (linear) without a line, as a clear colour: the baselines' clear colour of
/// it (encode_output's encoding) with alpha at least 0, and an 8-bit one on the format's own
/// steps (a clear converts exactly what the format holds exactly; an Rgba16Float output's
/// background already is a half, see `prepare`).
fn background_value(format: wgpu::TextureFormat, background: [f32; 4]) -> wgpu::Color {
    let [r, g, b, a] = background;
    let c = targets::clear_color(format, [r, g, b, a.max(0.0)]);
    if format != wgpu::TextureFormat::Rgba8Unorm {
        return c;
    }
    let unorm = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() / 255.0;
    wgpu::Color {
        r: unorm(c.r),
        g: unorm(c.g),
        b: unorm(c.b),
        a: unorm(c.a),
    }
}

/// `x` rounded to the nearest IEEE half-precision value (ties to even), as f32.
fn round_to_half(x: f32) -> f32 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    // A half has 10 fraction bits; below 2^-14 its spacing stays 2^-24.
    let exponent = (((x.to_bits() >> 23) & 0xff) as i32 - 127).max(-14);
    let step = 2f32.powi(exponent - 10);
    let r = (x / step).round_ties_even() * step;
    if r.abs() > 65504.0 {
        return f32::INFINITY.copysign(x);
    }
    r
}

fn edge_module(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    flags: &[&str],
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("wirepass edge pass"),
        source: wgpu::ShaderSource::Wgsl(shaders::edge_source(format, flags).into()),
    })
}

/// Checks a storage texture the pass writes: format, size, usage, one sample, 2D.
pub(crate) fn check_storage_output(
    view: &wgpu::TextureView,
    format: wgpu::TextureFormat,
    size: (u32, u32),
    what: &str,
) -> Result<()> {
    let t = view.texture();
    if t.format() != format {
        return Err(Error::Misuse(format!(
            "{what} is {:?}, but the pass was built for {format:?}",
            t.format()
        )));
    }
    check_texture(t, size, wgpu::TextureUsages::STORAGE_BINDING, what)
}

/// Checks a texture the pass samples: size, usage, one sample, 2D, a float format.
pub(crate) fn check_sampled(view: &wgpu::TextureView, size: (u32, u32), what: &str) -> Result<()> {
    let t = view.texture();
    let float = matches!(
        t.format().sample_type(None, None),
        Some(wgpu::TextureSampleType::Float { .. })
    );
    if !float {
        return Err(Error::Misuse(format!(
            "{what} is {:?}, which is not a colour format read as float",
            t.format()
        )));
    }
    check_texture(t, size, wgpu::TextureUsages::TEXTURE_BINDING, what)
}

fn check_texture(
    t: &wgpu::Texture,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
    what: &str,
) -> Result<()> {
    if (t.width(), t.height()) != size {
        return Err(Error::Misuse(format!(
            "{what} is {}x{}, but the frame was prepared for {}x{}",
            t.width(),
            t.height(),
            size.0,
            size.1
        )));
    }
    if !t.usage().contains(usage) {
        return Err(Error::Misuse(format!(
            "{what} lacks the usage {usage:?} (it has {:?})",
            t.usage()
        )));
    }
    if t.sample_count() != 1 {
        return Err(Error::Misuse(format!(
            "{what} has {} samples; the pass writes single-sampled textures (draw into a \
             multisampled target with the render-pass entry instead)",
            t.sample_count()
        )));
    }
    if t.dimension() != wgpu::TextureDimension::D2 || t.depth_or_array_layers() != 1 {
        return Err(Error::Misuse(format!("{what} is not a single 2D texture")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_to_half_is_the_nearest_half() {
        let mut x = 1.0e-9_f32;
        while x < 70000.0 {
            for v in [x, -x, x * 1.000_3, x * 0.999_7] {
                let want = half::f16::from_f32(v).to_f32();
                assert_eq!(round_to_half(v).to_bits(), want.to_bits(), "{v:e}");
            }
            x *= 1.013;
        }
        // Ties go to even, as a conversion does.
        for v in [
            1.0 + 1.0 / 2048.0,
            1.0 + 3.0 / 2048.0,
            2.0_f32.powi(-24) * 2.5,
        ] {
            assert_eq!(round_to_half(v), half::f16::from_f32(v).to_f32(), "{v:e}");
        }
    }

    #[test]
    fn the_background_value_is_what_the_shader_stores() {
        let rgba = |c: wgpu::Color| [c.r, c.g, c.b, c.a];
        let c = [0.1, 0.5, 1.0, 0.25];
        let srgb = background_value(wgpu::TextureFormat::Rgba8Unorm, c);
        let want = [89.0, 188.0, 255.0, 64.0].map(|b: f64| b / 255.0);
        assert_eq!(rgba(srgb), want);
        // Alpha at least 0; float formats hold linear values.
        let f = background_value(wgpu::TextureFormat::Rgba32Float, [0.1, 0.2, 0.3, -1.0]);
        assert_eq!(rgba(f), [0.1, 0.2, 0.3, 0.0].map(|v: f32| f64::from(v)));
    }
}
