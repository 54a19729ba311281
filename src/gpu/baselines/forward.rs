//! The forward single-pass baseline (Bærentzen et al. 2006, NVIDIA "Solid Wireframe" 2007):
//! each fragment gets its distance to the triangle's edges from three screen-space altitudes
//! interpolated without perspective. wgpu has no geometry shader, so a non-indexed draw of
//! `3 × triangles` vertices per instance pulls each triangle's three vertices from the mesh
//! store instead.

use super::raster::{
    check_vertex_storage, color_targets, depth_state, encode_snippet, pipeline_layout, slot_layout,
    RasterFrame,
};
use crate::error::{Error, Result};
#[cfg(feature = "diagnostics")]
use crate::gpu::EncodeOptions;
use crate::gpu::{shaders, GpuTimer, MeshStore};
use crate::scene::Scene;
use crate::style::Style;
use std::sync::atomic::{AtomicU32, Ordering};

/// The forward single-pass module for an output of `format`: common.wgsl, scene.wgsl and
/// forward.wgsl.
pub(crate) fn forward_source(format: wgpu::TextureFormat, split: bool) -> Option<String> {
    let encode = encode_snippet(format)?;
    let flags: &[&str] = if split { &["SPLIT"] } else { &[] };
    Some(shaders::assemble(
        &[shaders::SCENE, shaders::FORWARD, encode],
        flags,
    ))
}

struct Pipelines {
    layout: wgpu::BindGroupLayout,
    color_only: wgpu::RenderPipeline,
    with_maps: wgpu::RenderPipeline,
}

/// The forward single-pass wireframe, a baseline for the deferred pass.
///
/// Each triangle's vertices are pulled from the [`MeshStore`] by a non-indexed instanced
/// draw of `3 × triangles` vertices per mesh; each vertex invocation projects its triangle's
/// three corners, divides by `w` and computes its own corner's altitude in pixels with the
/// published geometry shader's `WIN_SCALE`, corrected to half the image size. The
/// fragment's distance to the nearest drawn edge is the minimum of the three altitudes
/// interpolated without perspective; masked edges carry a large constant distance, as in
/// NVIDIA's "Solid Wireframe" for quads. Shading, the line profile and
/// reverse depth are the deferred pass's, so on ordinary cameras both draw the same pixels.
///
/// **The division by `w` is kept on purpose**: it is the published method, and it breaks
/// for triangles that cross the near plane (a corner at or behind the eye projects to the
/// wrong side or to infinity; distances become wrong, infinite or NaN). That failure is part
/// of what the comparison with the deferred pass and the ground truth measures. So is its
/// reliance on `noperspective` varyings surviving clipping: on Mesa's lavapipe and llvmpipe
/// some clipped triangles get NaN distances and lose their lines (tests/forward.rs pins how
/// many on two hard cameras). It draws no trace pass: outlines get half their width.
///
/// Use: [`new`](Self::new) once, [`prepare`](Self::prepare) each frame, then
/// [`encode`](Self::encode) (colour only) into the host's encoder; with the `diagnostics`
/// feature, `encode_with` also writes ids and the diagnostic map, for tools and tests.
pub struct ForwardPass {
    id: u32,
    format: wgpu::TextureFormat,
    pipelines: [Option<Pipelines>; 2],
}

impl ForwardPass {
    /// Builds the pipelines for an output of `format`: `Rgba8Unorm` (written
    /// sRGB-encoded by the shader, as the deferred pass does), `Rgba8UnormSrgb` (encoded by
    /// the hardware), `Rgba16Float` or `Rgba32Float` (linear). The output needs
    /// `RENDER_ATTACHMENT` usage.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<Self> {
        static NEXT: AtomicU32 = AtomicU32::new(1);
        if encode_snippet(format).is_none() {
            return Err(Error::InvalidSetting(format!(
                "output format {format:?} is not one the forward pass can render to \
                 (Rgba8Unorm, Rgba8UnormSrgb, Rgba16Float, Rgba32Float)"
            )));
        }
        check_vertex_storage(device, &device.adapter_info().name)?;
        let mut pass = Self {
            id: NEXT.fetch_add(1, Ordering::Relaxed) | 0x8000_0000,
            format,
            pipelines: [None, None],
        };
        pass.pipelines[0] = Some(pass.build(device, false)?);
        Ok(pass)
    }

    fn build(&self, device: &wgpu::Device, split: bool) -> Result<Pipelines> {
        let format = self.format;
        let source = forward_source(format, split)
            .ok_or_else(|| Error::InvalidSetting(format!("{format:?}")))?;
        let scope = crate::gpu::validation::Validation::begin(device);
        let (layout, pipeline_layout) = pipeline_layout(device, "wirepass forward", split)?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass forward"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = |fs: &str, maps: bool| {
            let targets = color_targets(
                format.into(),
                maps,
                wgpu::ColorWrites::ALL,
                wgpu::ColorWrites::ALL,
            );
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("wirepass forward"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(slot_layout())],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(depth_state(
                    wgpu::CompareFunction::Greater,
                    true,
                    Default::default(),
                )),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let color_only = pipeline("fs_main", false);
        let with_maps = pipeline("fs_maps", true);
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("creating the forward pass: {e}")));
        }
        Ok(Pipelines {
            layout,
            color_only,
            with_maps,
        })
    }

    /// The output format chosen at construction.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Validates the scene, style and size and uploads the frame.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        size: (u32, u32),
    ) -> Result<RasterFrame> {
        let frame = RasterFrame::new(self.id, device, store, scene, style, size)?;
        let split = frame.data.split();
        if split && self.pipelines[1].is_none() {
            self.pipelines[1] = Some(self.build(device, true)?);
        }
        Ok(frame)
    }

    /// Records the pass: clears `output` to the background and draws the shaded, wireframed
    /// scene into it. `output` has the frame's size and the pass's output format.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &RasterFrame,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, store, frame, output, false, None)
    }

    /// [`encode`](Self::encode) with what tools add: timestamps around the pass (the span
    /// `"draw"`), and the id and diagnostic maps.
    #[cfg(feature = "diagnostics")]
    pub fn encode_with(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &RasterFrame,
        output: &wgpu::TextureView,
        options: EncodeOptions<'_>,
    ) -> Result<()> {
        let (maps, timer) = (options.maps, options.timer);
        self.record(device, encoder, store, frame, output, maps, timer)
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &RasterFrame,
        output: &wgpu::TextureView,
        maps: bool,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        frame.check(self.id, store)?;
        frame.check_output(output, self.format)?;
        let p = self.pipelines[usize::from(frame.data.split())]
            .as_ref()
            .ok_or_else(|| Error::Misuse("the frame was not prepared by this pass".into()))?;
        let group = frame.bind(device, &p.layout)?;
        let writes = timer.and_then(|t| t.render_span("draw"));
        let mut pass = frame.begin(
            encoder,
            "wirepass forward",
            (output, self.format),
            maps,
            writes,
        );
        pass.set_pipeline(if maps { &p.with_maps } else { &p.color_only });
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, frame.data.instances.slice(..));
        for d in &frame.data.draws {
            pass.draw(0..3 * d.triangles, d.instances.clone());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::targets::clear_color;
    use crate::style::linear_to_srgb;

    #[test]
    fn clear_colour_is_encoded_only_for_unorm() {
        let bg = [0.5, 0.0, 1.0, 1.0];
        let srgb = clear_color(wgpu::TextureFormat::Rgba8Unorm, bg);
        assert!((srgb.r - f64::from(linear_to_srgb(0.5))).abs() < 1e-7);
        let linear = clear_color(wgpu::TextureFormat::Rgba8UnormSrgb, bg);
        assert_eq!(linear.r, 0.5);
        assert!(forward_source(wgpu::TextureFormat::Bgra8Unorm, false).is_none());
    }
}
