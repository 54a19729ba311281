//! The trace pass (compute, `shaders/trace.wgsl`): the lines the edge pass cannot find
//! from the ids around a pixel, traced along the geometry and drawn into every pixel within
//! reach of their visible runs: outlines (silhouettes and boundaries), the drawn edges of
//! large patches, hidden lines, patterned or cut edges, cut lines and intersection lines. Three dispatches: a cull of the clusters that
//! may hold such an edge, one invocation per listed triangle listing the edges' pieces, one
//! per piece drawing it; before them, for dashed or dotted lines, one invocation per chain
//! of drawn edges finding where the patterns stand along it; with intersection lines, one
//! invocation per intersection segment listing its pieces too, before the piece dispatch;
//! where outlines or their hidden parts are patterned, after the listing, a pass of
//! indirect dispatches over the outline edges it listed finding the outline chains.
//! Pieces are short enough that a piece's loops keep under llvmpipe's cap on them
//! ([`loop_budget`](super::loop_budget)).

use super::bindings::{self, dispatch, store_resources, Compute, Res, Size, Sources};
use super::frame::FrameData;
use super::targets::{Targets, LIST_HEADER};
use super::variants::Variant;
use super::{shaders, GpuTimer};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Workgroup size of the trace pass.
const GROUP: u32 = 64;

struct TracePipelines {
    cull: Compute,
    /// Lists the pieces of the listed clusters' traced edges.
    list: Compute,
    /// Draws the listed pieces, one a lane.
    pieces: Compute,
    /// Finds the patterns' positions along every chain (PATTERNS).
    phases: Option<Compute>,
    /// Lists the intersection segments' pieces: built on first use, as few frames draw
    /// them.
    intersections: OnceLock<Intersections>,
    /// Finds the outline chains (PATTERNS): built on first use.
    outline_chains: OnceLock<OutlineChains>,
    module: wgpu::ShaderModule,
    resources: Vec<Res>,
}

/// The pipeline of a frame with intersection lines: one invocation per intersection
/// segment, listing its pieces.
struct Intersections {
    list: Compute,
}

/// The pipelines of a frame whose outlines, or their hidden parts, are patterned: the outline
/// chains' ends, their links, and the two ways of a round of looking back
/// (`outline_chain_jump_ab` and `_ba` in trace.wgsl).
struct OutlineChains {
    ends: Compute,
    start: Compute,
    jump: [Compute; 2],
}

/// Where the piece dispatch's size lies in a frame's cluster list buffer: after the cluster
/// list (header, then two words per cluster); the outline chains' dispatch size follows.
pub(crate) fn piece_size_at(data: &FrameData) -> u64 {
    LIST_HEADER + 8 * u64::from(data.uniforms_clusters().max(1))
}

/// Bytes of a frame's cluster list buffer: the list, the piece and outline chain sizes.
pub(crate) fn cluster_list_bytes(data: &FrameData) -> u64 {
    piece_size_at(data) + 2 * LIST_HEADER
}

/// The trace pass's pipelines, built for each variant on first use.
pub(crate) struct TracePass {
    /// The format the pipelines' layouts name for the (unused) colour output.
    format: wgpu::TextureFormat,
    /// Whether outline edges are drawn in pieces of 1 px, not as long as a software
    /// rasterizer's loop cap allows ([`Tuning`](super::Tuning)).
    short_pieces: bool,
    cache: Mutex<HashMap<Variant, Arc<TracePipelines>>>,
    /// The host's cache of compiled pipelines ([`PassOptions::pipeline_cache`](super::PassOptions)).
    compiled: Option<wgpu::PipelineCache>,
}

impl TracePass {
    /// Builds the pipelines of variant `v` now (with `intersections`, the intersection
    /// lines' too, and with `outline_chains` the outline chains'), if they are not built yet.
    pub(crate) fn warm_up(
        &self,
        device: &wgpu::Device,
        v: Variant,
        (intersections, outline_chains): (bool, bool),
    ) -> Result<()> {
        let p = self.pipelines(device, v)?;
        if intersections {
            self.intersections(device, &p)?;
        }
        if outline_chains && v.patterns {
            self.outline_chains(device, &p)?;
        }
        Ok(())
    }

    /// The outline chains' pipelines of the set `p`, built on first use.
    fn outline_chains<'p>(
        &self,
        device: &wgpu::Device,
        p: &'p TracePipelines,
    ) -> Result<&'p OutlineChains> {
        if let Some(c) = p.outline_chains.get() {
            return Ok(c);
        }
        let entries = [
            "outline_chain_ends",
            "outline_chain_start",
            "outline_chain_jump_ab",
            "outline_chain_jump_ba",
        ];
        let [ends, start, ab, ba] = self.build_extras(device, p, entries, "the outline chains")?;
        let c = OutlineChains {
            ends,
            start,
            jump: [ab, ba],
        };
        Ok(p.outline_chains.get_or_init(|| c))
    }

    /// The intersection lines' pipeline of the set `p`, built on first use.
    fn intersections<'p>(
        &self,
        device: &wgpu::Device,
        p: &'p TracePipelines,
    ) -> Result<&'p Intersections> {
        if let Some(c) = p.intersections.get() {
            return Ok(c);
        }
        let [list] =
            self.build_extras(device, p, ["intersection_main"], "the intersection lines")?;
        Ok(p.intersections.get_or_init(|| Intersections { list }))
    }

    /// Pipelines of the set `p`'s module for `entries`, with its resources, that only some
    /// frames use (`what` names them in an error).
    fn build_extras<const N: usize>(
        &self,
        device: &wgpu::Device,
        p: &TracePipelines,
        entries: [&str; N],
        what: &str,
    ) -> Result<[Compute; N]> {
        let scope = crate::gpu::validation::Validation::begin(device);
        let mut built = Vec::with_capacity(N);
        for entry in entries {
            built.push(Compute::new(
                device,
                &p.module,
                entry,
                p.resources.clone(),
                self.format,
                self.compiled.as_ref(),
            )?);
        }
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("building {what}: {e}")));
        }
        built
            .try_into()
            .map_err(|_| Error::Device(format!("building {what}: a pipeline is missing")))
    }

    /// How many pipelines the pass holds.
    pub(crate) fn built(&self) -> usize {
        self.cache.lock().map_or(0, |c| {
            c.values()
                .map(|p| {
                    3 + usize::from(p.phases.is_some())
                        + usize::from(p.intersections.get().is_some())
                        + 4 * usize::from(p.outline_chains.get().is_some())
                })
                .sum()
        })
    }

    /// The pass, drawing outline edges in pieces for a software rasterizer (`software`) or
    /// for a GPU.
    pub(crate) fn new(
        format: wgpu::TextureFormat,
        software: bool,
        compiled: Option<wgpu::PipelineCache>,
    ) -> Self {
        Self {
            format,
            short_pieces: !software,
            cache: Mutex::default(),
            compiled,
        }
    }

    fn pipelines(&self, device: &wgpu::Device, v: Variant) -> Result<Arc<TracePipelines>> {
        let mut cache = self
            .cache
            .lock()
            .map_err(|_| Error::Device("pipeline cache poisoned".into()))?;
        if let Some(p) = cache.get(&v) {
            return Ok(p.clone());
        }
        let scope = crate::gpu::validation::Validation::begin(device);
        let source = shaders::trace_source(&v.trace_flags(self.short_pieces));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass trace list"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let cull = Compute::new(
            device,
            &module,
            "trace_cull",
            vec![
                Res::Frame,
                bindings::instances(v.uniform_instances),
                Res::Clusters,
                Res::CullRw,
            ],
            self.format,
            self.compiled.as_ref(),
        )?;
        // Both the listing and the piece dispatch read the cluster list (the pieces for the
        // overflow list's clusters), and the pieces and the intersection lines' listing the
        // intersection segments.
        let mut list_res = store_resources(v.split, true, v.uniform_instances);
        list_res.extend([Res::Ids, Res::AccRw, Res::Cull]);
        if v.host {
            list_res.push(Res::HostDepth);
        }
        let mut resources = list_res.clone();
        resources.push(Res::Intersections);
        let pieces = Compute::new(
            device,
            &module,
            "trace_pieces_main",
            resources.clone(),
            self.format,
            self.compiled.as_ref(),
        )?;
        let compiled = self.compiled.as_ref();
        let list = Compute::new(
            device,
            &module,
            "trace_list_main",
            list_res,
            self.format,
            compiled,
        )?;
        let phases = if v.patterns {
            let mut res = vec![
                Res::Frame,
                bindings::instances(v.uniform_instances),
                Res::Vertices,
            ];
            if v.split {
                res.push(Res::VerticesHi);
            }
            res.extend([Res::Chains, Res::ChainWork, Res::AccRw]);
            Some(Compute::new(
                device,
                &module,
                "chain_phases",
                res,
                self.format,
                compiled,
            )?)
        } else {
            None
        };
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("building the trace pass: {e}")));
        }
        let p = Arc::new(TracePipelines {
            cull,
            list,
            pieces,
            phases,
            intersections: OnceLock::new(),
            outline_chains: OnceLock::new(),
            module,
            resources,
        });
        cache.insert(v, p.clone());
        Ok(p)
    }

    /// The trace pass: `trace_cull` lists the (instance, cluster) pairs that may hold
    /// an outline edge, on a 2D grid of workgroups (huge scenes need more than one dimension
    /// allows); `trace_list_main` then visits their triangles, dispatched indirectly with the
    /// size the cull leaves, and lists the pieces of their outline edges (and
    /// `intersection_main` those of the intersection segments); `trace_pieces_main` draws
    /// those, one a lane.
    pub(crate) fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (t, list, reset): (&Targets, &wgpu::Buffer, &wgpu::Buffer),
        sources: &Sources<'_>,
        variant: Variant,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let p = self.pipelines(device, variant)?;
        let cull = p.cull.bind(device, sources)?;
        let listing = p.list.bind(device, sources)?;
        let data = sources.frame;
        encoder.clear_buffer(&t.acc, 0, Some(t.acc_phases));
        encoder.copy_buffer_to_buffer(reset, 0, &t.acc, t.acc_tiles, LIST_HEADER);
        encoder.copy_buffer_to_buffer(reset, 0, &t.acc, t.acc_overflow, LIST_HEADER);
        encoder.copy_buffer_to_buffer(reset, 0, &t.acc, t.acc_pieces, LIST_HEADER);
        encoder.copy_buffer_to_buffer(reset, 0, list, 0, LIST_HEADER);
        let max = device.limits().max_compute_workgroups_per_dimension.max(1);
        let grid = |n: u32| {
            let groups = n.div_ceil(GROUP);
            Size::Grid(groups.clamp(1, max), groups.div_ceil(max).max(1))
        };
        // The outline chains' area: cleared, its dispatch size reset, before the listing
        // appends to it.
        let (outline_capacity, outline_at, outline_words) = data.outline_chains();
        let outline_at = t.acc_phases + 4 * u64::from(outline_at);
        if outline_capacity > 0 {
            encoder.clear_buffer(&t.acc, outline_at, Some(4 * u64::from(outline_words)));
            encoder.copy_buffer_to_buffer(reset, 0, &t.acc, outline_at, LIST_HEADER);
        }
        let chains = data.chain_phases().1;
        if let (Some(phases), true) = (&p.phases, chains > 0) {
            let group = phases.bind(device, sources)?;
            let names = ("wirepass chain phases", "trace.chains");
            dispatch(
                encoder,
                timer.as_deref_mut(),
                names,
                (phases, &group),
                grid(chains),
            );
        }
        let names = ("wirepass trace cull", "trace.cull");
        let size = grid(data.uniforms_clusters());
        dispatch(encoder, timer.as_deref_mut(), names, (&p.cull, &cull), size);
        let names = ("wirepass trace list", "trace.list");
        let size = Size::Indirect(list, 0);
        dispatch(
            encoder,
            timer.as_deref_mut(),
            names,
            (&p.list, &listing),
            size,
        );
        // With intersection lines, their segments' pieces join the list, and the piece
        // dispatch draws both kinds.
        let segments = data.intersections();
        if segments > 0 {
            let crossing = self.intersections(device, &p)?;
            let group = crossing.list.bind(device, sources)?;
            let names = ("wirepass intersection lines", "trace.intersections");
            let pipeline = (&crossing.list, &group);
            dispatch(
                encoder,
                timer.as_deref_mut(),
                names,
                pipeline,
                grid(segments),
            );
        }
        if outline_capacity > 0 && variant.patterns {
            let chains = self.outline_chains(device, &p)?;
            let size_at = piece_size_at(data) + LIST_HEADER;
            encoder.copy_buffer_to_buffer(&t.acc, outline_at, list, size_at, LIST_HEADER);
            let groups = [
                chains.ends.bind(device, sources)?,
                chains.start.bind(device, sources)?,
                chains.jump[0].bind(device, sources)?,
                chains.jump[1].bind(device, sources)?,
            ];
            // Rounds enough for a chain as long as the capacity, an even number so that the
            // looks back end where `outline_chain_anchor` reads them.
            let rounds = outline_capacity.trailing_zeros().next_multiple_of(2);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("wirepass outline chains"),
                timestamp_writes: timer
                    .as_deref_mut()
                    .and_then(|t| t.compute_span("trace.outline_chains")),
            });
            let steps = [(&chains.ends, &groups[0]), (&chains.start, &groups[1])];
            let jumps =
                (0..rounds).map(|r| (&chains.jump[r as usize % 2], &groups[2 + r as usize % 2]));
            for (pipeline, group) in steps.into_iter().chain(jumps) {
                pass.set_pipeline(&pipeline.pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups_indirect(list, size_at);
            }
        }
        let group = p.pieces.bind(device, sources)?;
        // The piece dispatch's size, where no pass binding `acc` for writing reads it.
        let size_at = piece_size_at(data);
        encoder.copy_buffer_to_buffer(&t.acc, t.acc_pieces, list, size_at, LIST_HEADER);
        let names = ("wirepass trace pieces", "trace.pieces");
        let size = Size::Indirect(list, size_at);
        dispatch(encoder, timer, names, (&p.pieces, &group), size);
        Ok(())
    }
}
