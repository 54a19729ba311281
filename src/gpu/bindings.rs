//! One scaffolding for every pass's bindings. Each shader resource has one fixed binding
//! number in group 0 (the WGSL files declare the same numbers); a pipeline lists the
//! resources its entry point reads, and its layout and bind groups are built from that list
//! alone. So a pipeline binds only what it uses, which keeps every pipeline within
//! `wgpu::Limits::default()` (8 storage buffers per stage), and no two passes spell out the
//! same layout.

use super::frame::{FrameData, INSTANCE_BYTES, UNIFORM_INSTANCE_CAPACITY};
use super::mesh_store::{TRIANGLE_BYTES, VERTEX_BYTES};
use super::GpuTimer;
use crate::error::{Error, Result};

/// A shader resource and its binding number in group 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Res {
    Frame = 0,
    Instances = 1,
    Vertices = 2,
    VerticesHi = 3,
    Indices = 4,
    IndicesHi = 5,
    Neighbours = 6,
    NeighboursHi = 7,
    Info = 8,
    Clusters = 9,
    Ids = 10,
    AccRw = 11,
    Acc = 12,
    CullRw = 13,
    Cull = 14,
    WorkRw = 15,
    Work = 16,
    /// The host's depth (reverse depth bits per target pixel).
    HostDepth = 17,
    /// The instance records as a uniform array (frames with few instances).
    UniformInstances = 18,
    /// The output colour (a storage texture of the pass's format, or the frame's result).
    OutColor = 20,
    /// The host's colour image, for overlay.
    HostColor = 21,
    // The diagnostic maps: written only with the diagnostics feature.
    #[cfg_attr(not(feature = "diagnostics"), allow(dead_code))]
    OutDiagnostic = 22,
    #[cfg_attr(not(feature = "diagnostics"), allow(dead_code))]
    OutIds = 23,
    /// The edge pass's list of tiles for `tile_main`.
    TilesRw = 24,
    Tiles = 25,
    /// The mesh store's chain records (`mesh_records::ChainRecords`).
    Chains = 26,
    /// The frame's instances whose chains `chain_phases` visits (`frame::ChainWork`).
    ChainWork = 27,
    /// The frame's intersection segments (`frame::IntersectionRecord`).
    Intersections = 28,
    /// The host's own depth texture, which the host-depth pass resolves into [`Res::HostDepth`]
    /// (read as unfilterable float; multisampled or not).
    HostSource = 30,
    /// The host-depth pass's parameters.
    HostParams = 31,
    /// The host-depth pass's output, the target [`Res::HostDepth`] then reads.
    HostOut = 32,
    /// The host-depth pass's seed depth for a multisampled host (host_depth.wgsl).
    HostSeedOut = 33,
    /// A frame's result, which the composite draws into the host's render pass.
    Result = 34,
    /// The visibility pass's depth target (reverse depth), which the composite tests the
    /// host's depth samples against.
    Depth = 35,
    /// The output tiles the composite draws, which the edge pass lists in its result mode.
    CompositeRw = 36,
}

impl Res {
    /// The layout entry of this resource, visible to `stages`; `color` is the format of
    /// [`Res::OutColor`].
    pub(crate) fn layout_entry(
        self,
        stages: wgpu::ShaderStages,
        color: wgpu::TextureFormat,
    ) -> wgpu::BindGroupLayoutEntry {
        let buffer = |ty| wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let read = buffer(wgpu::BufferBindingType::Storage { read_only: true });
        let write = buffer(wgpu::BufferBindingType::Storage { read_only: false });
        let storage_texture = |format| wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let texture = |sample_type| wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        };
        use Res::*;
        let ty = match self {
            Frame | UniformInstances | HostParams => buffer(wgpu::BufferBindingType::Uniform),
            AccRw | CullRw | WorkRw | TilesRw | CompositeRw => write,
            Ids | HostDepth => texture(wgpu::TextureSampleType::Uint),
            // Unfilterable float: what every backend can load a depth texture as.
            HostColor | HostSource | Result | Depth => {
                texture(wgpu::TextureSampleType::Float { filterable: false })
            }
            OutColor => storage_texture(color),
            HostOut | HostSeedOut => storage_texture(super::targets::HOST_FORMAT),
            OutDiagnostic => storage_texture(super::targets::DIAGNOSTIC_FORMAT),
            OutIds => storage_texture(super::targets::RESOLVED_ID_FORMAT),
            _ => read,
        };
        wgpu::BindGroupLayoutEntry {
            binding: self as u32,
            visibility: stages,
            ty,
            count: None,
        }
    }

    /// Storage buffers among `resources`.
    pub fn storage_buffers(resources: &[Res]) -> u32 {
        use Res::*;
        resources
            .iter()
            .filter(|r| {
                !matches!(
                    r,
                    Frame
                        | UniformInstances
                        | Ids
                        | HostDepth
                        | HostColor
                        | OutColor
                        | OutDiagnostic
                        | OutIds
                        | HostSource
                        | HostParams
                        | HostOut
                        | Result
                )
            })
            .count() as u32
    }
}

/// The instance records' binding: uniform where the frame's few instances allow it
/// (`UNIFORM_INSTANCES` in `scene.wgsl`).
pub(crate) fn instances(uniform: bool) -> Res {
    if uniform {
        Res::UniformInstances
    } else {
        Res::Instances
    }
}

/// The scene resources a pass over the mesh store reads, with the second halves of the
/// split buffers where the store is split.
pub(crate) fn store_resources(split: bool, neighbours: bool, uniform_instances: bool) -> Vec<Res> {
    let mut r = vec![
        Res::Frame,
        instances(uniform_instances),
        Res::Vertices,
        Res::Indices,
        Res::Info,
    ];
    if neighbours {
        r.push(Res::Neighbours);
    }
    if split {
        r.extend([Res::VerticesHi, Res::IndicesHi]);
        if neighbours {
            r.push(Res::NeighboursHi);
        }
    }
    r
}

/// A bind group layout for `resources`, checked against the device's storage buffer limit.
pub(crate) fn layout(
    device: &wgpu::Device,
    label: &str,
    resources: &[Res],
    stages: wgpu::ShaderStages,
    color: wgpu::TextureFormat,
) -> Result<wgpu::BindGroupLayout> {
    let storage = Res::storage_buffers(resources);
    let limit = device.limits().max_storage_buffers_per_shader_stage;
    if storage > limit {
        return Err(Error::OverLimit {
            what: format!("the storage buffers of the {label} pipeline"),
            value: u64::from(storage),
            limit_name: "max_storage_buffers_per_shader_stage",
            limit: u64::from(limit),
        });
    }
    let entries: Vec<_> = resources
        .iter()
        .map(|r| r.layout_entry(stages, color))
        .collect();
    Ok(
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &entries,
        }),
    )
}

/// A compute pipeline with the resources it binds.
pub(crate) struct Compute {
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
    pub resources: Vec<Res>,
}

impl Compute {
    /// Builds entry point `entry` of `module`, binding `resources`.
    pub fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        entry: &str,
        resources: Vec<Res>,
        color: wgpu::TextureFormat,
        cache: Option<&wgpu::PipelineCache>,
    ) -> Result<Compute> {
        let label = format!("wirepass {entry}");
        let layout = layout(
            device,
            &label,
            &resources,
            wgpu::ShaderStages::COMPUTE,
            color,
        )?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&label),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&label),
            layout: Some(&pipeline_layout),
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache,
        });
        Ok(Compute {
            pipeline,
            layout,
            resources,
        })
    }

    /// The bind group of this pipeline for `sources`.
    pub fn bind(&self, device: &wgpu::Device, sources: &Sources<'_>) -> Result<wgpu::BindGroup> {
        bind_group(device, &self.layout, &self.resources, sources)
    }
}

/// Everything a binding may refer to in one frame.
pub(crate) struct Sources<'a> {
    pub frame: &'a FrameData,
    pub ids: Option<&'a wgpu::TextureView>,
    pub host_depth: Option<&'a wgpu::TextureView>,
    pub acc: Option<&'a wgpu::Buffer>,
    pub cull: Option<&'a wgpu::Buffer>,
    pub work: Option<&'a wgpu::Buffer>,
    pub tiles: Option<&'a wgpu::Buffer>,
    pub composite: Option<&'a wgpu::Buffer>,
    pub out_color: Option<&'a wgpu::TextureView>,
    pub host_color: Option<&'a wgpu::TextureView>,
    pub out_diagnostic: Option<&'a wgpu::TextureView>,
    pub out_ids: Option<&'a wgpu::TextureView>,
    /// `out_color` and `host_color` are the host's views, which wgpu may reject (another
    /// device's, say): a bind group holding them is checked under an error scope.
    pub from_host: bool,
}

impl<'a> Sources<'a> {
    /// Sources with only the frame's scene.
    pub fn frame(frame: &'a FrameData) -> Sources<'a> {
        Sources {
            frame,
            ids: None,
            host_depth: None,
            acc: None,
            cull: None,
            work: None,
            tiles: None,
            composite: None,
            out_color: None,
            host_color: None,
            out_diagnostic: None,
            out_ids: None,
            from_host: false,
        }
    }
}

/// The first or second binding of a store buffer split after `split` elements of `stride`
/// bytes; unsplit (`split` at or past the end), the first binds it whole.
fn half(buffer: &wgpu::Buffer, split: u32, stride: u64, second: bool) -> wgpu::BindingResource<'_> {
    let at = u64::from(split) * stride;
    if at >= buffer.size() {
        return buffer.as_entire_binding();
    }
    let (offset, size) = if second {
        (at, None)
    } else {
        (0, wgpu::BufferSize::new(at))
    };
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset,
        size,
    })
}

/// A bind group of `layout` binding `resources` from `sources`.
pub(crate) fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    resources: &[Res],
    sources: &Sources<'_>,
) -> Result<wgpu::BindGroup> {
    let f = sources.frame;
    let store = &f.store;
    let missing = |r: Res| Error::Device(format!("no source for the {r:?} binding"));
    let mut entries = Vec::with_capacity(resources.len());
    for &r in resources {
        use Res::*;
        let resource = match r {
            Frame => f.frame.as_entire_binding(),
            Instances => f.instances.as_entire_binding(),
            UniformInstances => wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &f.instances,
                offset: 0,
                size: wgpu::BufferSize::new(u64::from(UNIFORM_INSTANCE_CAPACITY) * INSTANCE_BYTES),
            }),
            Vertices => half(&store.vertices, store.split.vertices, VERTEX_BYTES, false),
            VerticesHi => half(&store.vertices, store.split.vertices, VERTEX_BYTES, true),
            Indices => half(&store.indices, store.split.triangles, TRIANGLE_BYTES, false),
            IndicesHi => half(&store.indices, store.split.triangles, TRIANGLE_BYTES, true),
            Neighbours => half(
                &store.neighbours,
                store.split.triangles,
                TRIANGLE_BYTES,
                false,
            ),
            NeighboursHi => half(
                &store.neighbours,
                store.split.triangles,
                TRIANGLE_BYTES,
                true,
            ),
            Info => store.info.as_entire_binding(),
            Clusters => store.clusters.as_entire_binding(),
            Chains => store.chains.as_entire_binding(),
            ChainWork => f.chain_work.as_entire_binding(),
            Intersections => f.intersections.as_entire_binding(),
            Ids => wgpu::BindingResource::TextureView(sources.ids.ok_or_else(|| missing(r))?),
            HostDepth => {
                wgpu::BindingResource::TextureView(sources.host_depth.ok_or_else(|| missing(r))?)
            }
            AccRw | Acc => sources.acc.ok_or_else(|| missing(r))?.as_entire_binding(),
            CullRw | Cull => sources.cull.ok_or_else(|| missing(r))?.as_entire_binding(),
            WorkRw | Work => sources.work.ok_or_else(|| missing(r))?.as_entire_binding(),
            TilesRw | Tiles => sources.tiles.ok_or_else(|| missing(r))?.as_entire_binding(),
            CompositeRw => sources
                .composite
                .ok_or_else(|| missing(r))?
                .as_entire_binding(),
            OutColor => {
                wgpu::BindingResource::TextureView(sources.out_color.ok_or_else(|| missing(r))?)
            }
            HostColor => {
                wgpu::BindingResource::TextureView(sources.host_color.ok_or_else(|| missing(r))?)
            }
            OutDiagnostic => wgpu::BindingResource::TextureView(
                sources.out_diagnostic.ok_or_else(|| missing(r))?,
            ),
            OutIds => {
                wgpu::BindingResource::TextureView(sources.out_ids.ok_or_else(|| missing(r))?)
            }
            // Bound by the host-depth pass and the composite themselves.
            HostSource | HostParams | HostOut | HostSeedOut | Result | Depth => {
                return Err(missing(r))
            }
        };
        entries.push(wgpu::BindGroupEntry {
            binding: r as u32,
            resource,
        });
    }
    let desc = wgpu::BindGroupDescriptor {
        label: Some("wirepass"),
        layout,
        entries: &entries,
    };
    let holds_host = resources
        .iter()
        .any(|r| matches!(r, Res::OutColor | Res::HostColor));
    if sources.from_host && holds_host {
        bind_host_resources(device, &desc)
    } else {
        // The pass's own resources only: nothing wgpu could reject.
        Ok(device.create_bind_group(&desc))
    }
}

/// How a dispatch is sized: a grid of workgroups, or by the size an earlier dispatch left in
/// a buffer, at a byte offset.
pub(crate) enum Size<'b> {
    Grid(u32, u32),
    Indirect(&'b wgpu::Buffer, u64),
}

/// Records one dispatch as a compute pass of its own, labelled `names.0` and timed as the
/// span `names.1`.
pub(crate) fn dispatch(
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

/// Creates a bind group that may hold the host's resources, turning wgpu's validation of
/// them (a view from another device, say) into an [`Error::Misuse`] before anything uses
/// the group.
pub(crate) fn bind_host_resources(
    device: &wgpu::Device,
    desc: &wgpu::BindGroupDescriptor<'_>,
) -> Result<wgpu::BindGroup> {
    let scope = crate::gpu::validation::Validation::begin(device);
    let group = device.create_bind_group(desc);
    match scope.end() {
        None => Ok(group),
        Some(e) => Err(Error::Misuse(format!(
            "a texture given to the pass cannot be bound (from another device?): {e}"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::Res;

    /// The resource a WGSL global of this name is, and so its binding number.
    fn resource(name: &str, uniform: bool) -> Option<Res> {
        use Res::*;
        Some(match name {
            "frame" => Frame,
            "instances" if uniform => UniformInstances,
            "instances" => Instances,
            "vertices" => Vertices,
            "vertices_hi" => VerticesHi,
            "indices" => Indices,
            "indices_hi" => IndicesHi,
            "neighbours" => Neighbours,
            "neighbours_hi" => NeighboursHi,
            "info" => Info,
            "clusters" => Clusters,
            "ids" => Ids,
            "acc_rw" => AccRw,
            "acc" => Acc,
            "cull_rw" => CullRw,
            "cull" => Cull,
            "work_rw" => WorkRw,
            "work" => Work,
            "host_depth" => HostDepth,
            "out_color" => OutColor,
            "host_color" => HostColor,
            "out_diagnostic" => OutDiagnostic,
            "out_ids" => OutIds,
            "tiles_rw" => TilesRw,
            "tiles" => Tiles,
            "chains" => Chains,
            "chain_work" => ChainWork,
            "intersections" => Intersections,
            "host_source" => HostSource,
            "host" => HostParams,
            "host_out" => HostOut,
            "seed_out" => HostSeedOut,
            "result" => Result,
            "depth" => Depth,
            "composite_rw" => CompositeRw,
            _ => return None,
        })
    }

    /// Every binding of every module the crate builds is the number `Res` gives its
    /// resource: the WGSL files and the Rust layouts cannot disagree.
    #[test]
    fn every_wgsl_binding_is_its_resource_number() {
        let mut seen = std::collections::HashSet::new();
        for (name, source) in super::super::variants::shader_modules() {
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
            for (_, var) in module.global_variables.iter() {
                let Some(binding) = &var.binding else {
                    continue;
                };
                let var_name = var.name.as_deref().unwrap_or("?");
                let uniform = var.space == naga::AddressSpace::Uniform;
                let res = resource(var_name, uniform)
                    .unwrap_or_else(|| panic!("{name}: no resource for the global {var_name}"));
                assert_eq!(binding.group, 0, "{name}: {var_name}");
                assert_eq!(binding.binding, res as u32, "{name}: {var_name} is {res:?}");
                seen.insert(res);
            }
        }
        assert!(
            seen.len() >= 31,
            "every resource is bound somewhere: {seen:?}"
        );
    }
}
