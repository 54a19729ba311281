//! The host's depth buffer as the deferred pass sees it: geometry the host drew itself, which
//! hides the wireframed surfaces' lines and outlines where it is nearer, and lets outlines
//! draw over it where it is farther.
//!
//! Before the visibility pass, a full-screen draw seeds the pass's depth and id targets from
//! the host's depth (each pixel's farthest sample, in the pass's reverse depth, moved back by
//! [`host_margin`](crate::edge_math::host_margin); id `HOST` where the host has geometry)
//! and keeps the host's depth alone in a target of its own for the compute passes. The rules
//! the ground truth shares: a pixel shows the host where the host's depth there is nearer
//! than every instance's surface at its centre; a point of an outline is hidden where the
//! pixel containing it shows the host and the host there is clearly nearer than the point;
//! and no line is drawn into a pixel that shows the host where the host is clearly nearer
//! than the line's point ("clearly": by twice the host's own depth change over the distance
//! and a pixel more, `edge_math::host_hides`, so outlines stay whole where an object meets
//! the ground). Where an instance shows, the host hides nothing drawn there, so a host that
//! draws its own copy of a wireframed mesh keeps that mesh's outlines whole.

use super::bindings::Res;
use super::canvas::HostDepth;
use super::frame::FrameData;
use super::targets::{Targets, DEPTH_FORMAT, HOST_FORMAT, ID_FORMAT};
use super::{shaders, GpuTimer};
use crate::camera::{DepthRange, View};
use crate::error::{Error, Result};
use glam::{DMat4, DVec4};
use wgpu::util::DeviceExt;

/// Mirror of WGSL `HostParams` (common.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HostParams {
    a: [f32; 4],
    b: [f32; 4],
    mode: u32,
    reversed: u32,
    _pad: u32,
    quantum: f32,
}

/// The seeding passes' pipelines: the resolve for single- and multisampled host depth, and
/// the draw that writes the depth and id targets.
pub(crate) struct HostImport {
    resolve: [Option<(wgpu::ComputePipeline, wgpu::BindGroupLayout)>; 2],
    seed: Option<(wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    /// The host's cache of compiled pipelines ([`PassOptions::pipeline_cache`](super::PassOptions)).
    compiled: Option<wgpu::PipelineCache>,
}

impl HostImport {
    /// How many pipelines it holds.
    pub fn built(&self) -> usize {
        self.resolve.iter().flatten().count() + usize::from(self.seed.is_some())
    }
}

/// A frame's host depth, ready to seed its targets.
pub(crate) struct HostFrame {
    view: wgpu::TextureView,
    params: wgpu::Buffer,
    multisampled: bool,
    reversed: bool,
}

impl HostFrame {
    /// The uniform mapping the host's depth to the pass's (WGSL `HostParams`).
    pub fn params(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// Whether greater host depth is nearer.
    pub fn reversed(&self) -> bool {
        self.reversed
    }

    /// Whether the host's depth has several samples per pixel (and the frame a seed target).
    pub fn multisampled(&self) -> bool {
        self.multisampled
    }
}

impl HostImport {
    pub fn new(compiled: Option<wgpu::PipelineCache>) -> Self {
        HostImport {
            resolve: [None, None],
            seed: None,
            compiled,
        }
    }

    /// Checks the host's depth against the frame and builds what seeding it needs.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        host: &HostDepth<'_>,
        scene_view: &View,
        image: (u32, u32),
    ) -> Result<HostFrame> {
        let t = host.texture;
        if !t.format().is_depth_stencil_format() || !t.format().has_depth_aspect() {
            return Err(Error::Misuse(format!(
                "the host depth texture is {:?}, not a depth format",
                t.format()
            )));
        }
        if !t.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return Err(Error::Misuse(format!(
                "the host depth texture lacks the usage TEXTURE_BINDING (it has {:?})",
                t.usage()
            )));
        }
        if (t.width(), t.height()) != image {
            return Err(Error::Misuse(format!(
                "the host depth texture is {}x{}, but the image is {}x{}",
                t.width(),
                t.height(),
                image.0,
                image.1
            )));
        }
        if t.dimension() != wgpu::TextureDimension::D2 || t.depth_or_array_layers() != 1 {
            return Err(Error::Misuse(
                "the host depth texture is not a single 2D texture".into(),
            ));
        }
        host.matrices.validate()?;
        let multisampled = t.sample_count() > 1;
        if multisampled && device.adapter_info().backend == wgpu::Backend::Gl {
            // wgpu's GL backend cannot render into a multisampled texture that can also be
            // bound (gfx-rs/wgpu#6084): such a depth holds nothing, and the host's own pass
            // with it draws nothing either.
            return Err(Error::MissingFeature {
                adapter: device.adapter_info().name,
                what: "a multisampled depth texture that can be both rendered and bound \
                       (wgpu's GL backend cannot; give a single-sampled depth)"
                    .into(),
            });
        }
        let slot = usize::from(multisampled);
        if self.resolve[slot].is_none() {
            self.resolve[slot] = Some(build_resolve(device, multisampled, self.compiled.as_ref())?);
        }
        if self.seed.is_none() {
            self.seed = Some(build_seed(device, self.compiled.as_ref())?);
        }
        let same = host.matrices.view == scene_view.view
            && host.matrices.projection == scene_view.projection;
        let reversed = host.matrices.depth == DepthRange::Reversed;
        let (mode, a, b) = if same {
            (u32::from(reversed), DVec4::ZERO, DVec4::ZERO)
        } else {
            // Host NDC (u, v, d, 1) → world → the scene's reverse depth and w.
            let inverse = (host.matrices.projection * host.matrices.view).inverse();
            let rows = scene_view.clip_rows(DMat4::IDENTITY);
            (
                2,
                inverse.transpose() * rows.depth,
                inverse.transpose() * rows.clip.row(3),
            )
        };
        let params = HostParams {
            a: a.as_vec4().to_array(),
            b: b.as_vec4().to_array(),
            mode,
            reversed: u32::from(reversed),
            _pad: 0,
            quantum: depth_quantum(t.format(), host.matrices.depth) as f32,
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass host depth"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = t.create_view(&wgpu::TextureViewDescriptor {
            label: Some("wirepass host depth"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        Ok(HostFrame {
            view,
            params,
            multisampled,
            reversed,
        })
    }

    /// Records the seeding passes: the resolve into the host target, then the draw that
    /// writes every pixel of the depth and id targets.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        frame: &FrameData,
        host: &HostFrame,
        targets: &Targets,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let unprepared = || Error::Device("the host depth pipelines were not prepared".into());
        let (resolve, resolve_layout) = self.resolve[usize::from(host.multisampled)]
            .as_ref()
            .ok_or_else(unprepared)?;
        let (seed, seed_layout) = self.seed.as_ref().ok_or_else(unprepared)?;
        let host_target = targets
            .host
            .as_ref()
            .ok_or_else(|| Error::Device("the targets have no host depth".into()))?;
        let host_view = host_target.create_view(&Default::default());
        // A multisampled host's seed depth has a target of its own; a single-sampled host's
        // is its depth.
        let seed_target = match (host.multisampled, &targets.host_seed) {
            (false, _) => None,
            (true, Some(t)) => Some(t.create_view(&Default::default())),
            (true, None) => return Err(Error::Device("the targets have no seed depth".into())),
        };
        let seed_view = seed_target.as_ref().unwrap_or(&host_view);
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: Res::Frame as u32,
                resource: frame.frame.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: Res::HostSource as u32,
                resource: wgpu::BindingResource::TextureView(&host.view),
            },
            wgpu::BindGroupEntry {
                binding: Res::HostParams as u32,
                resource: host.params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: Res::HostOut as u32,
                resource: wgpu::BindingResource::TextureView(&host_view),
            },
        ];
        if let Some(seed) = &seed_target {
            entries.push(wgpu::BindGroupEntry {
                binding: Res::HostSeedOut as u32,
                resource: wgpu::BindingResource::TextureView(seed),
            });
        }
        let resolve_group = super::bindings::bind_host_resources(
            device,
            &wgpu::BindGroupDescriptor {
                label: Some("wirepass host depth"),
                layout: resolve_layout,
                entries: &entries,
            },
        )?;
        let seed_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass host seed"),
            layout: seed_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: Res::HostDepth as u32,
                resource: wgpu::BindingResource::TextureView(seed_view),
            }],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("wirepass host depth"),
                timestamp_writes: timer
                    .as_deref_mut()
                    .and_then(|t| t.compute_span("host_depth.resolve")),
            });
            pass.set_pipeline(resolve);
            pass.set_bind_group(0, &resolve_group, &[]);
            let (w, h) = (host_target.width(), host_target.height());
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        let (ids, depth) = (
            targets.ids.create_view(&Default::default()),
            targets.depth.create_view(&Default::default()),
        );
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("wirepass host seed"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &ids,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
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
            timestamp_writes: timer.and_then(|t| t.render_span("host_depth.seed")),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(seed);
        pass.set_bind_group(0, &seed_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}

/// The smallest step of a depth format near its far end, in reverse depth (see
/// `host_margin`): 2^-bits for unorm formats; for float ones the f32 step at 1 for a standard
/// convention (its far end is 1) and a relative step, taken at its largest, for a reversed one.
pub fn depth_quantum(format: wgpu::TextureFormat, depth: DepthRange) -> f64 {
    use wgpu::TextureFormat as F;
    match (format, depth) {
        (F::Depth16Unorm, _) => 2f64.powi(-16),
        (F::Depth24Plus | F::Depth24PlusStencil8, _) => 2f64.powi(-24),
        (_, DepthRange::Standard) => 2f64.powi(-24),
        (_, DepthRange::Reversed) => 2f64.powi(-23),
    }
}

fn build_resolve(
    device: &wgpu::Device,
    multisampled: bool,
    compiled: Option<&wgpu::PipelineCache>,
) -> Result<(wgpu::ComputePipeline, wgpu::BindGroupLayout)> {
    let scope = crate::gpu::validation::Validation::begin(device);
    let cs = wgpu::ShaderStages::COMPUTE;
    let mut source = Res::HostSource.layout_entry(cs, HOST_FORMAT);
    if let wgpu::BindingType::Texture {
        multisampled: m, ..
    } = &mut source.ty
    {
        *m = multisampled;
    }
    let mut entries = vec![
        Res::Frame.layout_entry(cs, HOST_FORMAT),
        source,
        Res::HostParams.layout_entry(cs, HOST_FORMAT),
        Res::HostOut.layout_entry(cs, HOST_FORMAT),
    ];
    if multisampled {
        entries.push(Res::HostSeedOut.layout_entry(cs, HOST_FORMAT));
    }
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("wirepass host depth"),
        entries: &entries,
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wirepass host depth"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("wirepass host depth"),
        source: wgpu::ShaderSource::Wgsl(shaders::host_depth_source(multisampled).into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("wirepass host depth"),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some("resolve_main"),
        compilation_options: Default::default(),
        cache: compiled,
    });
    if let Some(e) = scope.end() {
        return Err(Error::Device(format!("building the host depth pass: {e}")));
    }
    Ok((pipeline, layout))
}

fn build_seed(
    device: &wgpu::Device,
    compiled: Option<&wgpu::PipelineCache>,
) -> Result<(wgpu::RenderPipeline, wgpu::BindGroupLayout)> {
    let scope = crate::gpu::validation::Validation::begin(device);
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("wirepass host seed"),
        entries: &[Res::HostDepth.layout_entry(wgpu::ShaderStages::FRAGMENT, HOST_FORMAT)],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wirepass host seed"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("wirepass host seed"),
        source: wgpu::ShaderSource::Wgsl(shaders::host_depth_source(false).into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("wirepass host seed"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(ID_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: compiled,
    });
    if let Some(e) = scope.end() {
        return Err(Error::Device(format!("building the host seed pass: {e}")));
    }
    Ok((pipeline, layout))
}
