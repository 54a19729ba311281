//! The forward single-pass baseline (Bærentzen et al. 2006, NVIDIA "Solid Wireframe" 2007):
//! each fragment gets its distance to the triangle's edges from three screen-space altitudes
//! interpolated without perspective. wgpu has no geometry shader, so a non-indexed draw of
//! `3 × triangles` vertices pulls each triangle's three vertices from storage buffers instead.

use super::deferred::{DEPTH_FORMAT, ID_FORMAT};
use super::{shaders, texture_2d, FrameUniforms, GpuMesh, GpuTimer, PassOptions};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::style::{linear_to_srgb, Style};
use wgpu::util::DeviceExt;

/// The distance the shaders write where no edge is drawn (WGSL `NO_EDGE`).
const NO_EDGE: f32 = 3.0e38;

/// Format of the forward passes' diagnostic map: the **bit patterns** of `f32` values
/// (red = distance in pixels, green = reverse-Z depth), because float render targets are
/// not renderable on every backend (GL ES without `EXT_color_buffer_float`), while 32-bit
/// integer ones are. Copied out, its bytes read as `[f32; 4]` exactly like the deferred
/// pass's `Rgba32Float` map.
pub const MAPS_DIAGNOSTIC_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// Output formats the forward passes can render to, and how the shader encodes colour for
/// each: `Rgba8Unorm` gets sRGB-encoded in the shader (the deferred pass's convention, same
/// bytes), `Rgba8UnormSrgb` is encoded by the hardware, float formats stay linear.
pub(super) fn encode_snippet(format: wgpu::TextureFormat) -> Option<&'static str> {
    use wgpu::TextureFormat as F;
    match format {
        F::Rgba8Unorm => Some(
            "fn encode_output(c: vec4<f32>) -> vec4<f32> { return vec4<f32>(linear_to_srgb(c.rgb), c.a); }",
        ),
        F::Rgba8UnormSrgb | F::Rgba16Float | F::Rgba32Float => {
            Some("fn encode_output(c: vec4<f32>) -> vec4<f32> { return c; }")
        }
        _ => None,
    }
}

/// The forward single-pass module for an output of `format`: common.wgsl + forward.wgsl.
pub fn forward_source(format: wgpu::TextureFormat) -> Option<String> {
    let encode = encode_snippet(format)?;
    Some(shaders::assemble(&format!(
        "{}\n{encode}\n",
        shaders::FORWARD
    )))
}

/// The clear colour of an output of `format` for the linear background `bg`.
pub(super) fn clear_color(format: wgpu::TextureFormat, bg: [f32; 4]) -> wgpu::Color {
    let encode = format == wgpu::TextureFormat::Rgba8Unorm;
    let c = |v: f32| f64::from(if encode { linear_to_srgb(v) } else { v });
    wgpu::Color {
        r: c(bg[0]),
        g: c(bg[1]),
        b: c(bg[2]),
        a: f64::from(bg[3]),
    }
}

pub(super) fn entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    }
}

fn buffer_binding(ty: wgpu::BufferBindingType) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// The bind group layout of forward.wgsl (and two_pass.wgsl, which reuses it): frame and draw
/// uniforms, then positions, normals, indices and edge masks as storage.
pub(super) fn mesh_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let vs = wgpu::ShaderStages::VERTEX;
    let fs = wgpu::ShaderStages::FRAGMENT;
    let uniform = buffer_binding(wgpu::BufferBindingType::Uniform);
    let storage = buffer_binding(wgpu::BufferBindingType::Storage { read_only: true });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            entry(0, vs | fs, uniform),
            entry(1, vs, uniform),
            entry(2, vs, storage),
            entry(3, vs, storage),
            entry(4, vs, storage),
            entry(5, vs, storage),
            entry(6, vs, storage),
        ],
    })
}

/// The bind group for [`mesh_layout`].
pub(super) fn mesh_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    uniforms: &Uniforms,
    mesh: &GpuMesh,
) -> wgpu::BindGroup {
    let [indices, indices_hi] = mesh.halves(&mesh.indices);
    let resources = [
        uniforms.frame.as_entire_binding(),
        uniforms.draw.as_entire_binding(),
        mesh.positions.as_entire_binding(),
        mesh.normals.as_entire_binding(),
        indices,
        mesh.edge_masks.as_entire_binding(),
        indices_hi,
    ];
    let entries: Vec<_> = resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("wirepass forward mesh"),
        layout,
        entries: &entries,
    })
}

/// Vertex pulling reads storage buffers in the vertex stage, which some downlevel adapters
/// (WebGL 2, old GL ES) cannot do.
pub(super) fn check_vertex_storage(device: &wgpu::Device) -> Result<()> {
    if device.limits().max_storage_buffers_per_shader_stage < 5 {
        return Err(Error::MissingFeature {
            adapter: device.adapter_info().name,
            what:
                "five storage buffers per shader stage, read in the vertex stage (vertex pulling)"
                    .into(),
        });
    }
    Ok(())
}

/// The frame and draw uniform buffers.
pub(super) struct Uniforms {
    pub frame: wgpu::Buffer,
    pub draw: wgpu::Buffer,
}

impl Uniforms {
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            frame: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("wirepass forward frame"),
                size: std::mem::size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            draw: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("wirepass forward draw"),
                contents: bytemuck::bytes_of(&[0u32; 4]),
                usage: wgpu::BufferUsages::UNIFORM,
            }),
        }
    }
}

/// Size-dependent targets of the forward passes: depth, and the id and diagnostic maps.
pub(super) struct Targets {
    pub size: (u32, u32),
    pub ids: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub diagnostic: wgpu::Texture,
}

impl Targets {
    /// Rebuilds `slot` when the size changed.
    pub fn ensure(slot: &mut Option<Targets>, device: &wgpu::Device, size: (u32, u32)) {
        if slot.as_ref().map(|t| t.size) == Some(size) {
            return;
        }
        let make = |label, format, usage| texture_2d(device, label, size, format, usage);
        use wgpu::TextureUsages as U;
        *slot = Some(Targets {
            size,
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
        });
    }

    /// `targets` or the error for encoding before `prepare`.
    pub fn get(targets: &Option<Targets>) -> Result<&Targets> {
        targets
            .as_ref()
            .ok_or_else(|| Error::InvalidSetting("encode called before prepare".into()))
    }

    /// Checks that the host's output texture has the prepared size and the pass's format.
    pub fn check_output(
        &self,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<()> {
        let t = output.texture();
        if (t.width(), t.height()) != self.size {
            return Err(Error::InvalidSetting(format!(
                "the output texture is {}x{}, but the pass was prepared for {}x{}",
                t.width(),
                t.height(),
                self.size.0,
                self.size.1
            )));
        }
        if t.format() != format {
            return Err(Error::InvalidSetting(format!(
                "the output texture is {:?}, but the pass was built for {format:?}",
                t.format()
            )));
        }
        Ok(())
    }

    /// Records a render pass that clears the output to `background`, the depth to 0
    /// (reverse-Z far) and, with `maps`, the ids to background and the diagnostic map to
    /// (NO_EDGE, 0).
    pub fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        output: &wgpu::TextureView,
        background: wgpu::Color,
        maps: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let ids = self.ids.create_view(&Default::default());
        let diagnostic = self.diagnostic.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        let clear = |view, color| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(color),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut colors = vec![clear(output, background)];
        if maps {
            colors.push(clear(
                &ids,
                wgpu::Color {
                    r: f64::from(u32::MAX),
                    g: 0.0,
                    b: 0.0,
                    a: 0.0,
                },
            ));
            colors.push(clear(
                &diagnostic,
                wgpu::Color {
                    r: f64::from(NO_EDGE.to_bits()),
                    g: 0.0,
                    b: 0.0,
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

/// Reverse-Z depth as the visibility pass uses it: write, keep the nearer (greater) value.
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

/// The forward single-pass wireframe, a baseline for the deferred pass.
///
/// Each triangle's vertices are pulled from the [`GpuMesh`] storage buffers by a non-indexed
/// draw of `3 × triangles` vertices; each vertex invocation projects its triangle's three
/// corners, divides by `w` and computes its own corner's altitude in pixels with the seeds'
/// corrected `WIN_SCALE` (half the image size). The fragment's distance to the nearest drawn
/// edge is the minimum of the three altitudes interpolated without perspective; masked
/// edges carry a large constant distance (seed 004). Shading, the line profile and reverse-Z
/// depth are the deferred pass's, so on ordinary cameras both draw the same pixels.
///
/// **The division by `w` is kept on purpose**: it is the published method, and it breaks
/// for triangles that cross the near plane (a corner at or behind the eye projects to the
/// wrong side or to infinity; distances become wrong, infinite or NaN). That failure is part
/// of what the comparison with the deferred pass and the ground truth measures. So is its
/// reliance on `noperspective` varyings surviving clipping: on Mesa's lavapipe and llvmpipe
/// some clipped triangles get NaN distances and lose their lines (tests/forward.rs pins how
/// many on two hard cameras).
///
/// Use: [`new`](Self::new) once, [`prepare`](Self::prepare) when the camera, style or size
/// changes, then [`encode`](Self::encode) (colour only, for timing and hosts) or
/// [`encode_with_maps`](Self::encode_with_maps) (also triangle ids and the diagnostic map,
/// for tools and tests) into the host's encoder.
pub struct ForwardPass {
    format: wgpu::TextureFormat,
    layout: wgpu::BindGroupLayout,
    color_only: wgpu::RenderPipeline,
    with_maps: wgpu::RenderPipeline,
    uniforms: Uniforms,
    background: [f32; 4],
    targets: Option<Targets>,
}

impl ForwardPass {
    /// Builds the pipelines for an output of `options.output_format`: `Rgba8Unorm` (written
    /// sRGB-encoded by the shader, as the deferred pass does), `Rgba8UnormSrgb` (encoded by
    /// the hardware), `Rgba16Float` or `Rgba32Float` (linear). The output needs
    /// `RENDER_ATTACHMENT` usage.
    pub fn new(device: &wgpu::Device, options: PassOptions) -> Result<Self> {
        let format = options.output_format;
        let source = forward_source(format).ok_or_else(|| {
            Error::InvalidSetting(format!(
                "output format {format:?} is not one the forward pass can render to \
                 (Rgba8Unorm, Rgba8UnormSrgb, Rgba16Float, Rgba32Float)"
            ))
        })?;
        check_vertex_storage(device)?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let layout = mesh_layout(device, "wirepass forward");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass forward"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass forward"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
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
                    buffers: &[],
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
        let uniforms = Uniforms::new(device);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("creating the forward pass: {e}")));
        }
        Ok(Self {
            format,
            layout,
            color_only,
            with_maps,
            uniforms,
            background: [0.0; 4],
            targets: None,
        })
    }

    /// The output format chosen at construction.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Validates the camera, style and size, uploads the frame's uniforms, and (re)builds the
    /// depth, id and diagnostic targets when the size changed.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
        camera: &Camera,
        style: &Style,
        size: (u32, u32),
    ) -> Result<()> {
        let view = (camera, style, size);
        FrameUniforms::validate_and_write(device, queue, &self.uniforms.frame, mesh, view)?;
        self.background = style.background.0;
        Targets::ensure(&mut self.targets, device, size);
        Ok(())
    }

    /// The size the pass was last prepared for.
    pub fn size(&self) -> Option<(u32, u32)> {
        self.targets.as_ref().map(|t| t.size)
    }

    /// The triangle-id target (`R32Uint`, `u32::MAX` = background), written by
    /// [`encode_with_maps`](Self::encode_with_maps).
    pub fn id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.ids)
    }

    /// The reverse-Z depth target (`Depth32Float`, 1 = near plane).
    pub fn depth_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.depth)
    }

    /// The diagnostic map written by [`encode_with_maps`](Self::encode_with_maps), `f32` bits
    /// in an `Rgba32Uint` texture ([`MAPS_DIAGNOSTIC_FORMAT`]): red = distance in pixels to
    /// the nearest drawn edge as the interpolated altitudes give it (3e38 on background and
    /// where no edge is drawn; NaN where the method produces NaN), green = reverse-Z raster
    /// depth.
    pub fn diagnostic_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.diagnostic)
    }

    /// Records the pass: clears `output` to the background and draws the shaded, wireframed
    /// mesh into it. `output` has the prepared size and the pass's output format.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, mesh, output, false, None)
    }

    /// [`encode`](Self::encode) with GPU timestamps around the pass, named `"draw"`.
    pub fn encode_timed(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        output: &wgpu::TextureView,
        timer: &mut GpuTimer,
    ) -> Result<()> {
        self.record(device, encoder, mesh, output, false, Some(timer))
    }

    /// Like [`encode`](Self::encode), and also writes the triangle ids and the diagnostic map.
    pub fn encode_with_maps(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, mesh, output, true, None)
    }

    fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        output: &wgpu::TextureView,
        maps: bool,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let targets = Targets::get(&self.targets)?;
        targets.check_output(output, self.format)?;
        let group = mesh_group(device, &self.layout, &self.uniforms, mesh);
        let background = clear_color(self.format, self.background);
        let writes = timer.and_then(|t| t.render_span("draw"));
        let mut pass = targets.begin(
            encoder,
            "wirepass forward",
            output,
            background,
            maps,
            writes,
        );
        pass.set_pipeline(if maps {
            &self.with_maps
        } else {
            &self.color_only
        });
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3 * mesh.triangles, 0..1);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clear_colour_is_encoded_only_for_unorm() {
        let bg = [0.5, 0.0, 1.0, 1.0];
        let srgb = clear_color(wgpu::TextureFormat::Rgba8Unorm, bg);
        assert!((srgb.r - f64::from(linear_to_srgb(0.5))).abs() < 1e-7);
        let linear = clear_color(wgpu::TextureFormat::Rgba8UnormSrgb, bg);
        assert_eq!(linear.r, 0.5);
        assert!(forward_source(wgpu::TextureFormat::Bgra8Unorm).is_none());
    }

    /// The assembled forward and two-pass modules parse and validate (no GPU needed).
    #[test]
    fn shaders_validate_with_naga() {
        use wgpu::TextureFormat as F;
        let mut checked = 0;
        for format in [
            F::Rgba8Unorm,
            F::Rgba8UnormSrgb,
            F::Rgba16Float,
            F::Rgba32Float,
        ] {
            let sources = [
                ("forward", forward_source(format)),
                ("two-pass", super::super::two_pass_source(format)),
            ];
            for (name, source) in sources {
                let Some(source) = source else { continue };
                let module = naga::front::wgsl::parse_str(&source)
                    .unwrap_or_else(|e| panic!("{name} {format:?}: {}", e.emit_to_string(&source)));
                naga::valid::Validator::new(
                    naga::valid::ValidationFlags::all(),
                    naga::valid::Capabilities::all(),
                )
                .validate(&module)
                .unwrap_or_else(|e| panic!("{name} {format:?}: {}", e.emit_to_string(&source)));
                checked += 1;
            }
        }
        assert_eq!(checked, 7);
    }
}
