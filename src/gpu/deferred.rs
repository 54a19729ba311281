//! The deferred wireframe pass: a visibility raster pass (triangle id + depth) followed by a
//! compute pass that reconstructs each pixel's distance to its triangle's edges.

use super::{shaders, texture_2d, FrameUniforms, GpuMesh, GpuTimer};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::style::Style;
use wgpu::util::DeviceExt;

/// Format of the triangle-id target; `u32::MAX` marks background.
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Format of the depth target (reverse-Z: 1 at the near plane, 0 at the far plane).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the diagnostic map: distance in pixels (r) and reverse-Z depth (g) of the
/// visible point.
pub const DIAGNOSTIC_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the resolved-id map the diagnostic mode writes.
pub const RESOLVED_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Edge-pass workgroup side (8 × 8 pixels).
const TILE: u32 = 8;
/// Outline-pass workgroup size and triangles per cluster, as in outline.wgsl.
const OUTLINE_GROUP: u32 = crate::mesh::clusters::CLUSTER_TRIANGLES as u32;

/// Construction options.
#[derive(Clone, Copy, Debug)]
pub struct PassOptions {
    /// Format of the texture the pass writes: `Rgba8Unorm` (written sRGB-encoded),
    /// `Rgba16Float` or `Rgba32Float` (linear). It needs `STORAGE_BINDING` usage.
    pub output_format: wgpu::TextureFormat,
}

impl Default for PassOptions {
    fn default() -> Self {
        Self {
            output_format: wgpu::TextureFormat::Rgba8Unorm,
        }
    }
}

/// Where the edge pass writes.
pub enum OutputTarget<'a> {
    /// Shade the surface and draw the lines over it.
    Shaded(&'a wgpu::TextureView),
    /// Post-process: blend the lines over the host's colour image `host` (a sampled
    /// texture of the same size) into `output`. Background pixels copy `host`.
    Overlay {
        /// The host's rendered colour, read as a float texture.
        host: &'a wgpu::TextureView,
        /// Where the blended image goes (the pass's output format).
        output: &'a wgpu::TextureView,
    },
    /// Diagnostics for tools and tests into the pass's own textures: the edge distance in
    /// pixels (red) and reverse-Z depth (green) of [`DeferredPass::diagnostic_texture`], and
    /// the triangle ids after the exact coverage test, [`DeferredPass::resolved_id_texture`].
    Diagnostic,
    /// The benchmark floor: reads each pixel's id and writes the fill or background colour
    /// into the output, doing none of the edge work. What a deferred pass cannot go below.
    Floor(&'a wgpu::TextureView),
}

/// Size-dependent targets, rebuilt only when the size changes.
struct Targets {
    size: (u32, u32),
    ids: wgpu::Texture,
    depth: wgpu::Texture,
    /// Present when diagnostics are enabled: (distance + depth map, resolved ids).
    diagnostic: Option<(wgpu::Texture, wgpu::Texture)>,
    /// One u32 per pixel: what the outline pass leaves for the edge pass.
    outline: wgpu::Buffer,
}

/// The deferred wireframe pass. Construct once with [`DeferredPass::new`], call
/// [`prepare`](Self::prepare) when the camera, style or size changes, then
/// [`encode`](Self::encode) into the host's command encoder each frame.
pub struct DeferredPass {
    format: wgpu::TextureFormat,
    pulled: bool,
    visibility: wgpu::RenderPipeline,
    visibility_layout: wgpu::BindGroupLayout,
    mesh_layout: wgpu::BindGroupLayout,
    shade: (wgpu::ComputePipeline, wgpu::BindGroupLayout),
    overlay: (wgpu::ComputePipeline, wgpu::BindGroupLayout),
    diagnostic: (wgpu::ComputePipeline, wgpu::BindGroupLayout),
    floor: (wgpu::ComputePipeline, wgpu::BindGroupLayout),
    /// The outline pass.
    outline: OutlinePipelines,
    /// Layout of the edge pass's read-only view of the outline buffer.
    outline_read: wgpu::BindGroupLayout,
    /// Whether the last prepared style draws outlines (runs the outline pass).
    silhouettes: bool,
    frame: wgpu::Buffer,
    draw: wgpu::Buffer,
    diagnostics: bool,
    targets: Option<Targets>,
}

fn entry(
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

fn uniform() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

fn storage() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

fn texture(sample_type: wgpu::TextureSampleType) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type,
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}

fn storage_texture(format: wgpu::TextureFormat) -> wgpu::BindingType {
    wgpu::BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format,
        view_dimension: wgpu::TextureViewDimension::D2,
    }
}

impl DeferredPass {
    /// Builds the pipelines. Uses `@builtin(primitive_index)` where the device has
    /// `Features::PRIMITIVE_INDEX`, and a vertex-pulling visibility pass otherwise.
    pub fn new(device: &wgpu::Device, options: PassOptions) -> Result<Self> {
        let pulled = !device.features().contains(wgpu::Features::PRIMITIVE_INDEX);
        Self::build(device, options, pulled)
    }

    /// Builds the pipelines with the vertex-pulling visibility pass even where the device
    /// has `PRIMITIVE_INDEX`, e.g. to test the path other adapters take.
    pub fn with_vertex_pulling(device: &wgpu::Device, options: PassOptions) -> Result<Self> {
        Self::build(device, options, true)
    }

    fn build(device: &wgpu::Device, options: PassOptions, pulled: bool) -> Result<Self> {
        let format = options.output_format;
        let edge_source = shaders::edge_pass(format).ok_or_else(|| {
            Error::InvalidSetting(format!(
                "output format {format:?} is not one the edge pass can write (Rgba8Unorm, Rgba16Float, Rgba32Float)"
            ))
        })?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);

        let vs = wgpu::ShaderStages::VERTEX;
        let fs = wgpu::ShaderStages::FRAGMENT;
        let cs = wgpu::ShaderStages::COMPUTE;
        let mut vis_entries = vec![entry(0, vs, uniform()), entry(1, fs | vs, uniform())];
        if pulled {
            vis_entries.extend([2, 3, 4].map(|b| entry(b, vs, storage())));
        }
        let visibility_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wirepass visibility"),
            entries: &vis_entries,
        });
        let vis_source = shaders::assemble(if pulled {
            shaders::VISIBILITY_PULLED
        } else {
            shaders::VISIBILITY
        });
        let vis_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass visibility"),
            source: wgpu::ShaderSource::Wgsl(vis_source.into()),
        });
        let vis_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass visibility"),
            bind_group_layouts: &[Some(&visibility_layout)],
            immediate_size: 0,
        });
        let position_layout = wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let buffers = if pulled {
            vec![]
        } else {
            vec![Some(position_layout)]
        };
        let visibility = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("wirepass visibility"),
            layout: Some(&vis_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &vis_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &vis_module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(ID_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });

        let mesh_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wirepass edge pass mesh"),
            entries: &[
                entry(0, cs, uniform()),
                entry(1, cs, storage()),
                entry(2, cs, storage()),
                entry(3, cs, storage()),
                entry(4, cs, storage()),
                entry(5, cs, texture(wgpu::TextureSampleType::Uint)),
                entry(6, cs, storage()),
                entry(7, cs, storage()),
                entry(8, cs, storage()),
            ],
        });
        let edge_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass edge pass"),
            source: wgpu::ShaderSource::Wgsl(edge_source.into()),
        });
        let outline_read = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wirepass outline read"),
            entries: &[entry(0, cs, storage())],
        });
        let pipeline = |name: &str, groups: &[Option<&wgpu::BindGroupLayout>]| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(name),
                bind_group_layouts: groups,
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(&layout),
                module: &edge_module,
                entry_point: Some(name),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let compute = |name: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            let out_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(name),
                entries,
            });
            let groups = [Some(&mesh_layout), Some(&out_layout), Some(&outline_read)];
            (pipeline(name, &groups), out_layout)
        };
        let shade = compute("shade_main", &[entry(0, cs, storage_texture(format))]);
        let overlay = compute(
            "overlay_main",
            &[
                entry(1, cs, storage_texture(format)),
                entry(
                    2,
                    cs,
                    texture(wgpu::TextureSampleType::Float { filterable: false }),
                ),
            ],
        );
        let diagnostic = compute(
            "diagnostic_main",
            &[
                entry(3, cs, storage_texture(DIAGNOSTIC_FORMAT)),
                entry(4, cs, storage_texture(RESOLVED_ID_FORMAT)),
            ],
        );
        let floor = compute("floor_main", &[entry(5, cs, storage_texture(format))]);
        let read_write = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        let cull_layout = layout(
            "wirepass outline cull",
            &[
                entry(7, cs, storage()),
                entry(8, cs, read_write),
                entry(9, cs, read_write),
            ],
        );
        let draw_layout = layout(
            "wirepass outline draw",
            &[
                entry(6, cs, read_write),
                entry(8, cs, read_write),
                entry(10, cs, storage()),
            ],
        );
        let outline = OutlinePipelines {
            cull: pipeline("outline_cull", &[Some(&mesh_layout), Some(&cull_layout)]),
            draw: pipeline("outline_main", &[Some(&mesh_layout), Some(&draw_layout)]),
            cull_layout,
            draw_layout,
        };

        let frame = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wirepass frame"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let draw = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass draw"),
            contents: bytemuck::bytes_of(&[0u32; 4]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("creating the deferred pass: {e}")));
        }
        Ok(Self {
            format,
            pulled,
            visibility,
            visibility_layout,
            mesh_layout,
            shade,
            overlay,
            diagnostic,
            floor,
            outline,
            outline_read,
            silhouettes: false,
            frame,
            draw,
            diagnostics: false,
            targets: None,
        })
    }

    /// Enables [`OutputTarget::Diagnostic`], which needs 20 more bytes of targets per pixel;
    /// tools and tests use it, a renderer does not need it.
    pub fn with_diagnostics(mut self) -> Self {
        self.diagnostics = true;
        self.targets = None;
        self
    }

    /// GPU memory of the size-dependent targets, in bytes (0 before the first prepare).
    pub fn target_bytes(&self) -> u64 {
        let Some(t) = &self.targets else { return 0 };
        let mut textures = vec![&t.ids, &t.depth];
        if let Some((d, r)) = &t.diagnostic {
            textures.extend([d, r]);
        }
        let texels: u64 = textures
            .iter()
            .map(|x| {
                let texel = x.format().block_copy_size(None).unwrap_or(4);
                u64::from(x.width()) * u64::from(x.height()) * u64::from(texel)
            })
            .sum();
        texels + t.outline.size()
    }

    /// True when the visibility pass pulls vertices because the device lacks
    /// `PRIMITIVE_INDEX`.
    pub fn uses_vertex_pulling(&self) -> bool {
        self.pulled
    }

    /// The output format chosen at construction.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Validates the camera, style and size, uploads the frame's uniforms, and (re)builds the
    /// id, depth and diagnostic targets when the size changed.
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
        FrameUniforms::validate_and_write(device, queue, &self.frame, mesh, view)?;
        self.silhouettes = style.silhouettes;
        if self.targets.as_ref().map(|t| t.size) != Some(size) {
            let outline_bytes = u64::from(size.0) * u64::from(size.1) * 4;
            let limit = device.limits().max_storage_buffer_binding_size;
            if outline_bytes > limit {
                return Err(Error::OverLimit {
                    what: format!(
                        "the size in bytes of the outline buffer of a {}x{} image",
                        size.0, size.1
                    ),
                    value: outline_bytes,
                    limit_name: "max_storage_buffer_binding_size",
                    limit,
                });
            }
            let make = |label, format, usage| texture_2d(device, label, size, format, usage);
            use wgpu::TextureUsages as U;
            self.targets = Some(Targets {
                size,
                ids: make(
                    "wirepass ids",
                    ID_FORMAT,
                    U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
                ),
                depth: make("wirepass depth", DEPTH_FORMAT, U::RENDER_ATTACHMENT),
                diagnostic: self.diagnostics.then(|| {
                    (
                        make(
                            "wirepass diagnostic",
                            DIAGNOSTIC_FORMAT,
                            U::STORAGE_BINDING | U::COPY_SRC,
                        ),
                        make(
                            "wirepass resolved ids",
                            RESOLVED_ID_FORMAT,
                            U::STORAGE_BINDING | U::COPY_SRC,
                        ),
                    )
                }),
                outline: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("wirepass outline"),
                    size: u64::from(size.0) * u64::from(size.1) * 4,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            });
        }
        Ok(())
    }

    fn targets(&self) -> Result<&Targets> {
        self.targets
            .as_ref()
            .ok_or_else(|| Error::InvalidSetting("encode called before prepare".into()))
    }

    /// The size the pass was last prepared for.
    pub fn size(&self) -> Option<(u32, u32)> {
        self.targets.as_ref().map(|t| t.size)
    }

    /// The triangle-id target (`R32Uint`, `u32::MAX` = background) of the last frame.
    pub fn id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.ids)
    }

    /// The reverse-Z depth target (`Depth32Float`, 1 = near plane) of the last frame.
    pub fn depth_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.depth)
    }

    /// The triangle each pixel centre sees, after the edge pass's exact coverage test
    /// (see `resolve` in `edge_pass.wgsl`), written by [`OutputTarget::Diagnostic`]; `None`
    /// unless diagnostics are enabled.
    pub fn resolved_id_texture(&self) -> Option<&wgpu::Texture> {
        Some(&self.targets.as_ref()?.diagnostic.as_ref()?.1)
    }

    /// The diagnostic map written by [`OutputTarget::Diagnostic`]; `None` unless
    /// diagnostics are enabled.
    pub fn diagnostic_texture(&self) -> Option<&wgpu::Texture> {
        Some(&self.targets.as_ref()?.diagnostic.as_ref()?.0)
    }

    /// Records the visibility pass and the edge pass into `encoder`.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        target: OutputTarget<'_>,
    ) -> Result<()> {
        self.visibility(device, encoder, mesh, None)?;
        self.edges(device, encoder, mesh, target, None)
    }

    /// [`encode`](Self::encode) with GPU timestamps around each pass, named `"visibility"`,
    /// `"outline"` (when the style draws outlines) and `"edge"` in `timer`.
    pub fn encode_timed(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        target: OutputTarget<'_>,
        timer: &mut GpuTimer,
    ) -> Result<()> {
        self.visibility(device, encoder, mesh, Some(&mut *timer))?;
        self.edges(device, encoder, mesh, target, Some(timer))
    }

    /// Records only the visibility pass (triangle ids and depth).
    pub fn encode_visibility(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
    ) -> Result<()> {
        self.visibility(device, encoder, mesh, None)
    }

    fn visibility(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let targets = self.targets()?;
        let ids = targets.ids.create_view(&Default::default());
        let depth = targets.depth.create_view(&Default::default());
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: self.frame.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: self.draw.as_entire_binding(),
            },
        ];
        if self.pulled {
            let [indices, indices_hi] = mesh.halves(&mesh.indices);
            let pulled = [mesh.positions.as_entire_binding(), indices, indices_hi];
            entries.extend(
                pulled
                    .into_iter()
                    .zip(2..)
                    .map(|(resource, binding)| wgpu::BindGroupEntry { binding, resource }),
            );
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass visibility"),
            layout: &self.visibility_layout,
            entries: &entries,
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("wirepass visibility"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &ids,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: f64::from(u32::MAX),
                        g: 0.0,
                        b: 0.0,
                        a: 0.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.and_then(|t| t.render_span("visibility")),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.visibility);
        pass.set_bind_group(0, &group, &[]);
        if self.pulled {
            pass.draw(0..3 * mesh.triangles, 0..1);
        } else {
            pass.set_vertex_buffer(0, mesh.positions.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..3 * mesh.triangles, 0, 0..1);
        }
        Ok(())
    }

    /// Records only the edge pass (and the outline pass before it, when the style draws
    /// outlines); the visibility pass of this frame must precede it.
    pub fn encode_edges(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        target: OutputTarget<'_>,
    ) -> Result<()> {
        self.edges(device, encoder, mesh, target, None)
    }

    fn edges(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        target: OutputTarget<'_>,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let targets = self.targets()?;
        let ids = targets.ids.create_view(&Default::default());
        let [indices, indices_hi] = mesh.halves(&mesh.indices);
        let [neighbours, neighbours_hi] = mesh.halves(&mesh.neighbours);
        let resources = [
            self.frame.as_entire_binding(),
            mesh.positions.as_entire_binding(),
            mesh.normals.as_entire_binding(),
            indices,
            mesh.edge_masks.as_entire_binding(),
            wgpu::BindingResource::TextureView(&ids),
            neighbours,
            indices_hi,
            neighbours_hi,
        ];
        let mesh_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass edge pass mesh"),
            layout: &self.mesh_layout,
            entries: &resources
                .into_iter()
                .zip(0..)
                .map(|(resource, binding)| wgpu::BindGroupEntry { binding, resource })
                .collect::<Vec<_>>(),
        });
        let check = |view: &wgpu::TextureView, what: &str| -> Result<()> {
            let t = view.texture();
            if (t.width(), t.height()) != targets.size {
                return Err(Error::InvalidSetting(format!(
                    "{what} is {}x{}, but the pass was prepared for {}x{}",
                    t.width(),
                    t.height(),
                    targets.size.0,
                    targets.size.1
                )));
            }
            Ok(())
        };
        let (diagnostic_view, resolved_view);
        let floor = matches!(target, OutputTarget::Floor(_));
        let (pipeline, layout, entries) = match target {
            OutputTarget::Shaded(out) => {
                check(out, "the output texture")?;
                (
                    &self.shade.0,
                    &self.shade.1,
                    vec![wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(out),
                    }],
                )
            }
            OutputTarget::Overlay { host, output } => {
                check(output, "the output texture")?;
                check(host, "the host colour texture")?;
                (
                    &self.overlay.0,
                    &self.overlay.1,
                    vec![
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(output),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(host),
                        },
                    ],
                )
            }
            OutputTarget::Floor(out) => {
                check(out, "the output texture")?;
                (
                    &self.floor.0,
                    &self.floor.1,
                    vec![wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::TextureView(out),
                    }],
                )
            }
            OutputTarget::Diagnostic => {
                let (diagnostic, resolved) = targets.diagnostic.as_ref().ok_or_else(|| {
                    Error::InvalidSetting(
                        "diagnostics were not enabled (DeferredPass::with_diagnostics)".into(),
                    )
                })?;
                diagnostic_view = diagnostic.create_view(&Default::default());
                resolved_view = resolved.create_view(&Default::default());
                (
                    &self.diagnostic.0,
                    &self.diagnostic.1,
                    vec![
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: wgpu::BindingResource::TextureView(&diagnostic_view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: wgpu::BindingResource::TextureView(&resolved_view),
                        },
                    ],
                )
            }
        };
        let out_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass edge pass output"),
            layout,
            entries: &entries,
        });
        let mut timer = timer;
        if self.silhouettes && !floor {
            encoder.clear_buffer(&targets.outline, 0, None);
            self.outline_pass(device, encoder, mesh, &mesh_group, timer.as_deref_mut())?;
        }
        let outline_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass outline read"),
            layout: &self.outline_read,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: targets.outline.as_entire_binding(),
            }],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("wirepass edge pass"),
            timestamp_writes: timer.and_then(|t| t.compute_span("edge")),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &mesh_group, &[]);
        pass.set_bind_group(1, &out_group, &[]);
        pass.set_bind_group(2, &outline_group, &[]);
        pass.dispatch_workgroups(
            targets.size.0.div_ceil(TILE),
            targets.size.1.div_ceil(TILE),
            1,
        );
        Ok(())
    }

    /// The outline pass (outline.wgsl): `outline_cull` lists the clusters of triangles that
    /// may hold an outline edge, one invocation per cluster on a 2D grid of workgroups (huge
    /// meshes need more than one dimension allows); `outline_main` then visits their
    /// triangles, dispatched indirectly with the size the cull leaves.
    fn outline_pass(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        mesh_group: &wgpu::BindGroup,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let targets = self.targets()?;
        let group = |label, layout, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<_> = entries
                .iter()
                .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            })
        };
        let cull_group = group(
            "wirepass outline cull",
            &self.outline.cull_layout,
            &[
                (7, &mesh.clusters),
                (8, &mesh.outline_list),
                (9, &mesh.outline_args),
            ],
        );
        let draw_group = group(
            "wirepass outline draw",
            &self.outline.draw_layout,
            &[
                (6, &targets.outline),
                (8, &mesh.outline_list),
                (10, &mesh.cluster_triangles),
            ],
        );
        encoder.clear_buffer(&mesh.outline_args, 0, None);
        encoder.clear_buffer(&mesh.outline_list, 0, Some(4));
        let groups = mesh
            .triangles
            .div_ceil(OUTLINE_GROUP)
            .div_ceil(OUTLINE_GROUP);
        let max = device.limits().max_compute_workgroups_per_dimension.max(1);
        let (x, y) = (groups.min(max), groups.div_ceil(max));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("wirepass outline pass"),
            timestamp_writes: timer.and_then(|t| t.compute_span("outline")),
        });
        pass.set_bind_group(0, mesh_group, &[]);
        pass.set_bind_group(1, &cull_group, &[]);
        pass.set_pipeline(&self.outline.cull);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_bind_group(1, &draw_group, &[]);
        pass.set_pipeline(&self.outline.draw);
        pass.dispatch_workgroups_indirect(&mesh.outline_args, 0);
        Ok(())
    }
}

/// The two entry points of the outline pass and the layouts of their own bindings: the
/// mesh's cluster bounds, list and dispatch size for the cull; the pixel accumulator, the
/// list and the clusters' triangles for the draw.
struct OutlinePipelines {
    cull: wgpu::ComputePipeline,
    draw: wgpu::ComputePipeline,
    cull_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
}
