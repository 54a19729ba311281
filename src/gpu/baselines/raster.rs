//! What the two forward baselines share: their targets (depth, and the id and diagnostic
//! maps tools read), the render pass that clears them, pipeline state, and their prepared
//! frames. Their scene data is the deferred pass's ([`FrameData`]), bound through the same
//! scaffolding.

use crate::error::{Error, Result};
use crate::gpu::bindings::{self, store_resources, Res, Sources};
use crate::gpu::canvas::Region;
use crate::gpu::frame::{FrameData, FrameRecords};
use crate::gpu::mesh_store::MeshStore;
use crate::gpu::targets::texture_2d;
use crate::gpu::targets::{clear_color, cleared, BACKGROUND_ID, DEPTH_FORMAT, ID_FORMAT};
use crate::scene::Scene;
use crate::style::Style;

use crate::gpu::shaders::NO_EDGE;

/// Format of the forward passes' diagnostic map: the **bit patterns** of `f32` values
/// (red = distance in pixels, green = reverse depth), because float render targets are not
/// renderable on every backend (GL ES without `EXT_color_buffer_float`), while 32-bit
/// integer ones are. Copied out, its bytes read as `[f32; 4]` exactly like the deferred
/// pass's `Rgba32Float` map.
pub const MAPS_DIAGNOSTIC_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// How the shader encodes colour for an output format the baselines render to: `Rgba8Unorm`
/// gets sRGB-encoded in the shader (the deferred pass's convention, same bytes),
/// `Rgba8UnormSrgb` is encoded by the hardware, float formats stay linear.
pub(super) fn encode_snippet(format: wgpu::TextureFormat) -> Option<&'static str> {
    use wgpu::TextureFormat as F;
    match format {
        F::Rgba8Unorm | F::Rgba8UnormSrgb | F::Rgba16Float | F::Rgba32Float => {
            // Only Rgba8Unorm holds encoded values the hardware does not encode itself.
            Some(crate::gpu::shaders::encode_output(
                if format == F::Rgba8Unorm {
                    F::Rgba8Unorm
                } else {
                    F::Rgba32Float
                },
            ))
        }
        _ => None,
    }
}

/// The resources the baselines' shaders read: the scene, in the vertex and fragment stages.
pub(super) fn resources(split: bool) -> Vec<Res> {
    store_resources(split, false, false)
}

/// The bind group layout and pipeline layout for [`resources`].
pub(super) fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    split: bool,
) -> Result<(wgpu::BindGroupLayout, wgpu::PipelineLayout)> {
    let stages = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let layout = bindings::layout(device, label, &resources(split), stages, ID_FORMAT)?;
    let pipeline = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    Ok((layout, pipeline))
}

/// The instance records as an instance-rate vertex buffer holding only the slot.
pub(super) fn slot_layout() -> wgpu::VertexBufferLayout<'static> {
    const SLOT: [wgpu::VertexAttribute; 1] = [wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Uint32,
        offset: crate::gpu::frame::INSTANCE_INDEX_OFFSET,
        shader_location: 7,
    }];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<crate::gpu::frame::InstanceRecord>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &SLOT,
    }
}

/// Vertex pulling reads storage buffers in the vertex stage, which some downlevel adapters
/// (WebGL 2, old GL ES) cannot do.
pub(super) fn check_vertex_storage(device: &wgpu::Device, adapter: &str) -> Result<()> {
    if device.limits().max_storage_buffers_per_shader_stage < 5 {
        return Err(Error::MissingFeature {
            adapter: adapter.into(),
            what:
                "five storage buffers per shader stage, read in the vertex stage (vertex pulling)"
                    .into(),
        });
    }
    Ok(())
}

/// The colour targets of a pipeline: the output alone, or the output, ids and diagnostic map.
pub(super) fn color_targets(
    output: wgpu::ColorTargetState,
    maps: bool,
    ids_writes: wgpu::ColorWrites,
    diagnostic_writes: wgpu::ColorWrites,
) -> Vec<Option<wgpu::ColorTargetState>> {
    let mut targets = vec![Some(output)];
    if maps {
        targets.push(Some(wgpu::ColorTargetState {
            format: ID_FORMAT,
            blend: None,
            write_mask: ids_writes,
        }));
        targets.push(Some(wgpu::ColorTargetState {
            format: MAPS_DIAGNOSTIC_FORMAT,
            blend: None,
            write_mask: diagnostic_writes,
        }));
    }
    targets
}

/// Reverse depth as the visibility pass uses it: keep the nearer (greater) value.
pub(super) fn depth_state(
    compare: wgpu::CompareFunction,
    write: bool,
    bias: wgpu::DepthBiasState,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias,
    }
}

/// A baseline's prepared frame: the scene on the GPU and the targets it draws with.
pub struct RasterFrame {
    pass: u32,
    pub(super) data: FrameData,
    pub(super) ids: wgpu::Texture,
    pub(super) depth: wgpu::Texture,
    pub(super) diagnostic: wgpu::Texture,
    pub(super) background: [f32; 4],
}

impl RasterFrame {
    /// Validates and uploads the frame's scene and makes its targets.
    pub(super) fn new(
        pass: u32,
        device: &wgpu::Device,
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        size: (u32, u32),
    ) -> Result<RasterFrame> {
        let records = FrameRecords::new(
            device,
            store,
            scene,
            style,
            Region::whole(size),
            false,
            None,
        )?;
        let data = FrameData::new(device, store, records);
        let make = |label, format, usage| texture_2d(device, label, size, format, usage);
        use wgpu::TextureUsages as U;
        Ok(RasterFrame {
            pass,
            ids: make(
                "wirepass forward ids",
                ID_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
            ),
            depth: make(
                "wirepass forward depth",
                DEPTH_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            ),
            diagnostic: make(
                "wirepass forward diagnostic",
                MAPS_DIAGNOSTIC_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
            ),
            background: style.background.0,
            data,
        })
    }

    /// The output size.
    pub fn size(&self) -> (u32, u32) {
        self.data.region.size
    }

    /// The id map (`Rg32Uint`: instance slot, triangle; [`BACKGROUND_ID`](crate::gpu::BACKGROUND_ID) first on background).
    pub fn id_texture(&self) -> &wgpu::Texture {
        &self.ids
    }

    /// The reverse depth target (`Depth32Float`, 1 = near plane).
    pub fn depth_texture(&self) -> &wgpu::Texture {
        &self.depth
    }

    /// The diagnostic map, `f32` bits in an `Rgba32Uint` texture
    /// ([`MAPS_DIAGNOSTIC_FORMAT`]): red = distance in pixels as the method measures it
    /// (3e38 on background and where no edge is drawn), green = reverse raster depth.
    pub fn diagnostic_texture(&self) -> &wgpu::Texture {
        &self.diagnostic
    }

    /// For each instance slot of the id map, the index of the instance in the scene.
    pub fn instance_order(&self) -> &[u32] {
        &self.data.order
    }

    /// Errors unless this frame was prepared by pass `pass` with `store`, unchanged since.
    pub(super) fn check(&self, pass: u32, store: &MeshStore) -> Result<()> {
        if self.pass != pass {
            return Err(Error::Misuse(
                "the frame was prepared by another pass".into(),
            ));
        }
        self.data.check_store(store)
    }

    /// The scene's bind group for a baseline layout.
    pub(super) fn bind(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<wgpu::BindGroup> {
        bindings::bind_group(
            device,
            layout,
            &resources(self.data.split()),
            &Sources::frame(&self.data),
        )
    }

    /// Checks the host's output: the frame's size and the pass's format, a render target.
    pub(super) fn check_output(
        &self,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<()> {
        let t = output.texture();
        if (t.width(), t.height()) != self.size() {
            return Err(Error::Misuse(format!(
                "the output texture is {}x{}, but the frame was prepared for {}x{}",
                t.width(),
                t.height(),
                self.size().0,
                self.size().1
            )));
        }
        if t.format() != format {
            return Err(Error::Misuse(format!(
                "the output texture is {:?}, but the pass was built for {format:?}",
                t.format()
            )));
        }
        if !t.usage().contains(wgpu::TextureUsages::RENDER_ATTACHMENT) || t.sample_count() != 1 {
            return Err(Error::Misuse(
                "the output texture must be a single-sampled RENDER_ATTACHMENT".into(),
            ));
        }
        Ok(())
    }

    /// Records a render pass that clears the output to the background, the depth to 0
    /// (the far plane) and, with `maps`, the ids to background and the distances to none.
    pub(super) fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        (output, format): (&wgpu::TextureView, wgpu::TextureFormat),
        maps: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let ids = self.ids.create_view(&Default::default());
        let diagnostic = self.diagnostic.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        let mut colors = vec![cleared(output, clear_color(format, self.background))];
        if maps {
            let uint = |v: u32| wgpu::Color {
                r: f64::from(v),
                g: f64::from(v),
                b: 0.0,
                a: 0.0,
            };
            colors.push(cleared(&ids, uint(BACKGROUND_ID)));
            colors.push(cleared(
                &diagnostic,
                wgpu::Color {
                    r: f64::from(NO_EDGE.to_bits()),
                    g: 0.0,
                    b: f64::from(NO_EDGE.to_bits()),
                    a: 0.0,
                },
            ));
        }
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &colors,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }
}
