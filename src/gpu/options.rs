//! The deferred pass's options and where a frame's output goes.

use super::composite::RenderTarget;

/// Construction options.
#[derive(Clone, Debug)]
pub struct PassOptions {
    /// Format of the storage texture that [`OutputTarget::Shaded`] and
    /// [`OutputTarget::Overlay`] write: `Rgba8Unorm` (written sRGB-encoded), `Rgba16Float`
    /// or `Rgba32Float` (linear). It needs `STORAGE_BINDING` usage; with
    /// `RENDER_ATTACHMENT` as well (and one mip level), [`OutputTarget::Shaded`] on a
    /// [`Tuning::Software`] pass clears the background (one fill) instead of writing it pixel
    /// by pixel, with the same result. An `Rgba16Float` output takes the background as its
    /// nearest half.
    pub output_format: wgpu::TextureFormat,
    /// The host's render pass that [`DeferredPass::render`](super::DeferredPass::render) draws into, if it is used.
    pub render_target: Option<RenderTarget>,
    /// How the visibility pass learns which triangle a pixel shows.
    pub triangle_ids: TriangleIds,
    /// Which kind of device the passes split their work for.
    pub tuning: Tuning,
    /// wgpu's cache of what the driver compiled, given to every pipeline the pass builds:
    /// saved by the host ([`wgpu::PipelineCache::get_data`]) and made from that data on the
    /// next run, it spares the driver's compilation where the driver keeps none of its own
    /// (Vulkan only: `Features::PIPELINE_CACHE`; lavapipe's holds no code, as it compiles
    /// on first use and keeps Mesa's own disk cache).
    pub pipeline_cache: Option<wgpu::PipelineCache>,
}

impl Default for PassOptions {
    fn default() -> Self {
        Self {
            output_format: wgpu::TextureFormat::Rgba8Unorm,
            render_target: None,
            triangle_ids: TriangleIds::Auto,
            tuning: Tuning::Auto,
            pipeline_cache: None,
        }
    }
}

/// How the visibility pass learns which triangle each pixel shows. Every choice gives the
/// same ids; they differ in what the device needs and in speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TriangleIds {
    /// [`VertexPulling`](TriangleIds::VertexPulling) on a CPU adapter, whose rasterizer
    /// takes a slower path for a fragment shader that reads the primitive index, and on a
    /// device without `Features::PRIMITIVE_INDEX`;
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

/// Which kind of device the passes split their work for. A software rasterizer runs a
/// few lanes at a time, so it pays for every lane and every pass; a GPU runs thousands at
/// once, so a pass with few lanes waits on memory while most of the chip idles. Every
/// choice draws the lines to the same definition and bounds (the visible runs of an outline
/// are sampled at other points); they differ in speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tuning {
    /// [`Software`](Tuning::Software) on an adapter that reports `wgpu::DeviceType::Cpu`
    /// (lavapipe and llvmpipe do), [`Gpu`](Tuning::Gpu) elsewhere.
    #[default]
    Auto,
    /// For a software rasterizer: a clear lays the background down where the output allows
    /// one, and outline edges are drawn in pieces a lane each, as long as llvmpipe's cap on
    /// a batch's loop iterations allows (2 px, or 1 px where the trace pass looks at a
    /// wide window round each sample).
    Software,
    /// For a GPU: a dispatch writes the background (a clear of a storage texture took an
    /// NVIDIA H200 six times as long: 0.147 against 0.025 ms at 1920×1080), and outline
    /// edges are drawn in pieces of up to 1 px, so that a frame's few outline edges fill
    /// more lanes (the trace pass 2.3 → 0.34 ms for a 20 k-triangle sphere there).
    Gpu,
}

impl Tuning {
    /// Whether the passes on `device` are split for a software rasterizer.
    pub(crate) fn software(self, device: &wgpu::Device) -> bool {
        match self {
            Tuning::Auto => device.adapter_info().device_type == wgpu::DeviceType::Cpu,
            Tuning::Software => true,
            Tuning::Gpu => false,
        }
    }
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
    /// [`DeferredPass::with_diagnostics`](super::DeferredPass::with_diagnostics)): the distance in pixels to the line and the
    /// reverse depth of the visible point, and the (instance slot, triangle) after the exact
    /// coverage test.
    #[cfg(feature = "diagnostics")]
    Diagnostic,
    /// The benchmark floor: reads each pixel's id and writes the fill or background colour
    /// into the output, doing none of the edge work. What a deferred pass cannot go below.
    #[cfg(feature = "diagnostics")]
    Floor(&'a wgpu::TextureView),
    /// The frame's own result, which [`DeferredPass::render`](super::DeferredPass::render) then draws into the host's
    /// render pass (needs [`PassOptions::render_target`]).
    RenderPass,
}
