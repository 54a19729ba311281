//! Running the benchmark: every method on one scene and size, GPU time per pass from
//! timestamp queries, frames interleaved across methods so that drift on a busy machine
//! affects them alike.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::gpu::{
    texture_2d, Composite, DeferredPass, EdgeLines, EncodeOptions, ForwardPass, GpuContext,
    GpuTimer, MeshStore, OutputTarget, PassOptions, PreparedFrame, RasterFrame, RenderTarget,
    TwoPass,
};
use crate::mesh::EdgeSelection;
use crate::style::Style;
use crate::tools::gs::{GsFrame, GsPass};
use crate::tools::offline::Uploaded;
use crate::world::{Shot, World};
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

/// Median and spread of one timed quantity, in milliseconds.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Stats {
    /// Median.
    pub median_ms: f64,
    /// 10th percentile.
    pub p10_ms: f64,
    /// 90th percentile.
    pub p90_ms: f64,
}

impl Stats {
    /// Nearest-rank percentiles of `samples` (which must not be empty).
    pub fn of(samples: &[f64]) -> Stats {
        let mut v = samples.to_vec();
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
        Stats {
            median_ms: at(0.5),
            p10_ms: at(0.1),
            p90_ms: at(0.9),
        }
    }
}

/// One method on one scene at one size.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Run {
    /// Scene name as given.
    pub scene: String,
    /// Triangle count over all objects.
    pub triangles: u64,
    /// Image size.
    pub size: [u32; 2],
    /// Method name.
    pub method: String,
    /// Whether the style drew outlines (only the deferred methods draw them).
    pub outlines: bool,
    /// GPU time of each pass, and of each group of passes: `edge` is the sum of its
    /// dispatches (`edge.classify`, `edge.border`, `edge.clear` or `edge.background`,
    /// `edge.traced`, `edge.tiles`, `edge.refine`; the floor's `edge.floor`),
    /// `outline` of `trace.cull`, `trace.list` and `trace.pieces`.
    pub passes: BTreeMap<String, Stats>,
    /// Median over frames of the sum of the passes.
    pub total_median_ms: f64,
    /// CPU time to record and submit one frame.
    pub cpu: Stats,
    /// GPU memory the method allocates: mesh buffers and its targets.
    pub gpu_bytes: u64,
    /// The deferred method's edge pass: share of output tiles the tile dispatch visited and
    /// of pixels the refine dispatch decided, in the last frame.
    pub edge_work: Option<EdgeShares>,
    /// Why the method was not timed (`gs` where no OpenGL context with geometry shaders
    /// could be made); its times are then NaN.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
    /// For `gs`, which runs on OpenGL rather than the wgpu adapter: the GL renderer and
    /// version, and how its GPU time was taken.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gl: Option<String>,
}

/// The deferred edge pass's later dispatches, as shares of the output.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct EdgeShares {
    /// Tiles with foreground among all 8×8 output tiles.
    pub tiles: f64,
    /// Tiles the trace pass's lines reach among all 8×8 output tiles.
    pub traced_tiles: f64,
    /// Pixels refined among all output pixels.
    pub refined: f64,
    /// Clusters of 64 triangles the trace pass's cull listed for its triangle dispatch.
    pub traced_clusters: u32,
    /// Pieces of outline edges the trace pass's piece dispatch drew (or found beyond its
    /// list's room).
    pub traced_pieces: u32,
    /// Of them, those drawn for their hidden line alone that were found settled, every
    /// pixel in their reach holding a nearer hidden line already.
    pub settled_pieces: u32,
}

/// A method being measured: its pass, prepared frame and output.
enum Subject {
    Floor(DeferredPass, PreparedFrame, wgpu::Texture),
    Deferred(DeferredPass, PreparedFrame, wgpu::Texture),
    /// The deferred method as a host draws it into its own render pass
    /// ([`OutputTarget::RenderPass`], then `DeferredPass::render` with `Composite::Shaded`).
    RenderPass(DeferredPass, PreparedFrame, wgpu::Texture),
    /// The deferred method drawing another edge selection, on its own upload of the scene.
    Edges(
        EdgeSelection,
        Box<Uploaded>,
        DeferredPass,
        PreparedFrame,
        wgpu::Texture,
    ),
    Forward(ForwardPass, RasterFrame, wgpu::Texture),
    TwoPass(TwoPass, RasterFrame, wgpu::Texture),
    /// The published method on OpenGL, timed with GL timer queries.
    Gs(Box<GsPass>, GsFrame),
}

impl Subject {
    fn name(&self) -> String {
        match self {
            Subject::Floor(..) => "floor".into(),
            Subject::Deferred(..) => "deferred".into(),
            Subject::RenderPass(..) => "render-pass".into(),
            Subject::Edges(edges, ..) => format!("deferred {}", edges_name(*edges)),
            Subject::Forward(..) => "forward".into(),
            Subject::TwoPass(..) => "two-pass".into(),
            Subject::Gs(..) => "gs".into(),
        }
    }

    /// Draws one frame and waits for it: the GPU time of each timestamped span, and the CPU
    /// time to record and submit the frame, in milliseconds.
    fn time(
        &self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        data: (&MeshStore, &EdgeLines),
        timer: &mut GpuTimer,
    ) -> Result<(Vec<(&'static str, f64)>, f64)> {
        if let Subject::Gs(pass, frame) = self {
            let (gpu, cpu) = pass.draw_timed(frame)?;
            return Ok((vec![("draw", gpu)], cpu));
        }
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&Default::default());
        self.encode(device, &mut encoder, data, timer)?;
        timer.resolve(&mut encoder);
        queue.submit([encoder.finish()]);
        let recorded = start.elapsed().as_secs_f64() * 1e3;
        Ok((timer.read(device)?, recorded))
    }

    fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (store, lines): (&MeshStore, &EdgeLines),
        timer: &mut GpuTimer,
    ) -> Result<()> {
        match self {
            Subject::Floor(pass, frame, out) => {
                let view = out.create_view(&Default::default());
                let target = OutputTarget::Floor(&view);
                pass.encode_with(
                    device,
                    encoder,
                    store,
                    frame,
                    target,
                    EncodeOptions {
                        timer: Some(timer),
                        ..Default::default()
                    },
                )
            }
            Subject::Deferred(pass, frame, out) => {
                let view = out.create_view(&Default::default());
                let target = OutputTarget::Shaded(&view);
                pass.encode_with(
                    device,
                    encoder,
                    store,
                    frame,
                    target,
                    EncodeOptions {
                        timer: Some(timer),
                        ..Default::default()
                    },
                )
            }
            Subject::RenderPass(pass, frame, out) => {
                pass.encode_with(
                    device,
                    encoder,
                    store,
                    frame,
                    OutputTarget::RenderPass,
                    EncodeOptions {
                        timer: Some(&mut *timer),
                        ..Default::default()
                    },
                )?;
                // The host's render pass, over what the host drew (its own draws and clear
                // are the host's cost, not the method's): the frame composited.
                let view = out.create_view(&Default::default());
                let mut rpass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("wirepass bench host pass"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: timer.render_span("composite"),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.render(&mut rpass, frame)
            }
            Subject::Edges(_, up, pass, frame, out) => {
                let view = out.create_view(&Default::default());
                let target = OutputTarget::Shaded(&view);
                pass.encode_with(
                    device,
                    encoder,
                    &up.store,
                    frame,
                    target,
                    EncodeOptions {
                        timer: Some(timer),
                        ..Default::default()
                    },
                )
            }
            Subject::Forward(pass, frame, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_with(
                    device,
                    encoder,
                    store,
                    frame,
                    &view,
                    EncodeOptions {
                        timer: Some(timer),
                        ..Default::default()
                    },
                )
            }
            Subject::TwoPass(pass, frame, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_with(
                    device,
                    encoder,
                    (store, lines),
                    frame,
                    &view,
                    EncodeOptions {
                        timer: Some(timer),
                        ..Default::default()
                    },
                )
            }
            Subject::Gs(..) => Err(Error::Misuse(
                "gs draws on OpenGL, not into a wgpu encoder".into(),
            )),
        }
    }

    /// GPU memory the method allocates beyond the wgpu mesh store, which all the wgpu
    /// methods share.
    fn bytes(&self, lines: &EdgeLines) -> u64 {
        let texture = |t: &wgpu::Texture| u64::from(t.width()) * u64::from(t.height()) * 4;
        // Colour, id (8 bytes), depth and diagnostic targets of the forward methods.
        let forward = |t: &wgpu::Texture| 4 * texture(t);
        match self {
            Subject::Floor(p, _, t) | Subject::Deferred(p, _, t) | Subject::RenderPass(p, _, t) => {
                p.target_bytes() + texture(t)
            }
            Subject::Edges(_, up, p, _, t) => up.store.gpu_bytes() + p.target_bytes() + texture(t),
            Subject::Forward(_, _, t) => forward(t),
            Subject::TwoPass(_, _, t) => forward(t) + lines.gpu_bytes(),
            Subject::Gs(pass, frame) => pass.gpu_bytes() + frame.gpu_bytes(),
        }
    }
}

/// A method the benchmark can time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timed {
    /// The floor: the visibility pass and a compute pass that reads the id and writes a
    /// flat colour.
    Floor,
    /// The deferred method (visibility, trace and edge passes) into a storage texture.
    Deferred,
    /// The deferred method as a host draws it into its own render pass: the passes write
    /// the frame's result, which a draw composites (`Composite::Shaded`) into the host's
    /// colour attachment (`Rgba8UnormSrgb`).
    RenderPass,
    /// The forward single-pass method.
    Forward,
    /// The two-pass method (biased fill, then lines).
    TwoPass,
    /// The published single-pass method with its geometry shader, on OpenGL.
    Gs,
}

impl Timed {
    /// Every method, in the order they are timed within a frame.
    pub const ALL: [Timed; 6] = [
        Timed::Floor,
        Timed::Deferred,
        Timed::RenderPass,
        Timed::Forward,
        Timed::TwoPass,
        Timed::Gs,
    ];

    /// Whether the method draws outlines, and so is timed with them on and off.
    pub fn draws_outlines(self) -> bool {
        matches!(self, Timed::Floor | Timed::Deferred | Timed::RenderPass)
    }

    /// The method's name in tables and `bench.json`.
    pub fn name(self) -> &'static str {
        match self {
            Timed::Floor => "floor",
            Timed::Deferred => "deferred",
            Timed::RenderPass => "render-pass",
            Timed::Forward => "forward",
            Timed::TwoPass => "two-pass",
            Timed::Gs => "gs",
        }
    }
}

impl std::str::FromStr for Timed {
    type Err = Error;

    fn from_str(s: &str) -> Result<Timed> {
        Timed::ALL
            .into_iter()
            .find(|m| m.name() == s.trim())
            .ok_or_else(|| {
                Error::InvalidSetting(format!(
                    "unknown method {s:?}: floor, deferred, render-pass, forward, two-pass or gs"
                ))
            })
    }
}

/// How many frames a benchmark times, after how many untimed ones, and of which methods.
#[derive(Clone, Debug)]
pub struct Timing {
    /// Timed frames.
    pub frames: u32,
    /// Untimed frames first.
    pub warmup: u32,
    /// Edge selections the deferred method also draws, each timed beside the world's own
    /// (method `deferred edges=…`), so the cost of masked edges shows in one run.
    pub edges: Vec<EdgeSelection>,
    /// The methods timed (each of `Timed::ALL` when empty); the edge selections above are
    /// timed whatever this holds.
    pub methods: Vec<Timed>,
}

/// Times every method on `world` at `size`, with the framing camera and `style`: see
/// [`bench_scene`].
pub fn bench(
    ctx: &GpuContext,
    name: &str,
    world: &World,
    size: (u32, u32),
    style: &Style,
    timing: Timing,
) -> Result<Vec<Run>> {
    let (lo, hi) = world.bounds();
    let aspect = f64::from(size.0) / f64::from(size.1);
    let shot = Shot {
        world,
        view: Camera::framing(lo, hi, aspect).to_view(aspect),
        style,
        size,
    };
    bench_scene(ctx, name, &shot, timing)
}

/// Times the floor and every GPU method on `shot`: `timing.warmup` untimed frames, then
/// `timing.frames` timed frames, each frame running every method once, in turn.
pub fn bench_scene(
    ctx: &GpuContext,
    name: &str,
    shot: &Shot<'_>,
    timing: Timing,
) -> Result<Vec<Run>> {
    if timing.frames == 0 {
        return Err(Error::InvalidSetting("--frames must be at least 1".into()));
    }
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let lines = up.edge_lines(&ctx.device, shot.world)?;
    let (subjects, skipped) = subjects(ctx, shot, &up, &timing)?;
    ctx.finish()?;
    let times = time_frames(ctx, &subjects, (&up.store, &lines), &timing)?;
    let store_bytes = up.store.gpu_bytes();
    let run = |method: String| Run {
        scene: name.to_owned(),
        triangles: shot.world.triangle_count(),
        size: [shot.size.0, shot.size.1],
        method,
        outlines: shot.style.outlines,
        passes: BTreeMap::new(),
        total_median_ms: f64::NAN,
        cpu: Stats {
            median_ms: f64::NAN,
            p10_ms: f64::NAN,
            p90_ms: f64::NAN,
        },
        gpu_bytes: 0,
        edge_work: None,
        skipped: None,
        gl: None,
    };
    let mut runs = Vec::new();
    for (subject, (spans, totals, cpu)) in subjects.iter().zip(times) {
        runs.push(Run {
            passes: spans
                .iter()
                .map(|(name, v)| (name.clone(), Stats::of(v)))
                .collect(),
            total_median_ms: Stats::of(&totals).median_ms,
            cpu: Stats::of(&cpu),
            gpu_bytes: match subject {
                Subject::Gs(..) => subject.bytes(&lines),
                _ => store_bytes + subject.bytes(&lines),
            },
            edge_work: edge_shares(ctx, subject)?,
            gl: match subject {
                Subject::Gs(pass, _) => Some(format!(
                    "{}; timed by {}",
                    pass.description(),
                    pass.timing()
                )),
                _ => None,
            },
            ..run(subject.name())
        });
    }
    runs.extend(skipped.into_iter().map(|(method, why)| Run {
        skipped: Some(why),
        ..run(method.to_owned())
    }));
    Ok(runs)
}

/// A method that cannot run here, and why.
type Skipped = (&'static str, String);

/// What `timing` asks to time on `shot`, each prepared, and the methods that cannot run
/// here with why (gs where no OpenGL context with geometry shaders can be made).
fn subjects(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    up: &Uploaded,
    timing: &Timing,
) -> Result<(Vec<Subject>, Vec<Skipped>)> {
    let timed = |m: Timed| timing.methods.is_empty() || timing.methods.contains(&m);
    let (device, queue) = (&ctx.device, &ctx.queue);
    let size = shot.size;
    let scene = up.scene(shot.world, shot.view);
    let storage = || {
        // RENDER_ATTACHMENT: the edge pass clears the background instead of writing it.
        let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
        let format = wgpu::TextureFormat::Rgba8Unorm;
        texture_2d(device, "wirepass bench output", size, format, usage)
    };
    let forward_format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let attachment = || {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        texture_2d(device, "wirepass bench output", size, forward_format, usage)
    };
    let mut subjects = Vec::new();
    for floor in [true, false] {
        if !timed(if floor { Timed::Floor } else { Timed::Deferred }) {
            continue;
        }
        let mut pass = DeferredPass::new(device, PassOptions::default())?;
        let frame = pass.prepare(device, &up.store, &scene, shot.style, size)?;
        subjects.push(if floor {
            Subject::Floor(pass, frame, storage())
        } else {
            Subject::Deferred(pass, frame, storage())
        });
    }
    for &selection in &timing.edges {
        let mut world = shot.world.clone();
        for m in &mut world.meshes {
            let (mesh, e) = (*m.mesh).clone().resolve_edges(Some(selection));
            m.mesh = Arc::new(mesh);
            m.edges = e;
        }
        let up = Box::new(Uploaded::new(device, queue, &world)?);
        let scene = up.scene(&world, shot.view);
        let mut pass = DeferredPass::new(device, PassOptions::default())?;
        let frame = pass.prepare(device, &up.store, &scene, shot.style, size)?;
        subjects.push(Subject::Edges(selection, up, pass, frame, storage()));
    }
    if timed(Timed::RenderPass) {
        let target = RenderTarget {
            format: forward_format,
            sample_count: 1,
            depth_stencil: None,
            content: Composite::Shaded,
        };
        let options = PassOptions {
            render_target: Some(target),
            ..PassOptions::default()
        };
        let mut pass = DeferredPass::new(device, options)?;
        let frame = pass.prepare(device, &up.store, &scene, shot.style, size)?;
        subjects.push(Subject::RenderPass(pass, frame, attachment()));
    }
    if timed(Timed::Forward) {
        let mut forward = ForwardPass::new(device, forward_format)?;
        let frame = forward.prepare(device, &up.store, &scene, shot.style, size)?;
        subjects.push(Subject::Forward(forward, frame, attachment()));
    }
    if timed(Timed::TwoPass) {
        let mut two_pass = TwoPass::new(device, forward_format)?;
        let frame = two_pass.prepare(device, &up.store, &scene, shot.style, size)?;
        subjects.push(Subject::TwoPass(two_pass, frame, attachment()));
    }
    let mut skipped = Vec::new();
    if timed(Timed::Gs) {
        let made = GsPass::new().and_then(|mut pass| {
            let frame = pass.prepare(
                (device, queue),
                &up.store,
                &scene,
                shot.style,
                (size, false),
            )?;
            Ok(Subject::Gs(Box::new(pass), frame))
        });
        match made {
            Ok(subject) => subjects.push(subject),
            Err(Error::NoAdapter(why)) => skipped.push(("gs", why)),
            Err(e) => return Err(e),
        }
    }
    Ok((subjects, skipped))
}

/// One subject's times over the timed frames: each GPU span's, and each group's (the spans
/// before a name's first `.`), per frame; the frame's GPU total; the CPU's recording time.
type SubjectTimes = (BTreeMap<String, Vec<f64>>, Vec<f64>, Vec<f64>);

/// Runs `timing.warmup` untimed frames, then `timing.frames` timed ones, each running every
/// subject once, in turn.
fn time_frames(
    ctx: &GpuContext,
    subjects: &[Subject],
    drawn: (&MeshStore, &EdgeLines),
    timing: &Timing,
) -> Result<Vec<SubjectTimes>> {
    let (device, queue) = (&ctx.device, &ctx.queue);
    // Room for every span a frame can have (the host's depth seeding included), and more.
    let mut timer = GpuTimer::new(device, queue, 16)?;
    let mut times: Vec<SubjectTimes> = vec![Default::default(); subjects.len()];
    for frame in 0..timing.warmup + timing.frames {
        for (subject, (gpu, totals, cpu)) in subjects.iter().zip(&mut times) {
            let (spans, recorded) = subject.time((device, queue), drawn, &mut timer)?;
            ctx.finish()?;
            if frame < timing.warmup {
                continue;
            }
            cpu.push(recorded);
            totals.push(spans.iter().map(|s| s.1).sum());
            let mut groups: BTreeMap<String, f64> = BTreeMap::new();
            for (name, ms) in spans {
                if let Some((group, _)) = name.split_once('.') {
                    *groups.entry(group.to_owned()).or_default() += ms;
                }
                gpu.entry(name.to_owned()).or_default().push(ms);
            }
            for (group, ms) in groups {
                gpu.entry(group).or_default().push(ms);
            }
        }
    }
    Ok(times)
}

/// The deferred subjects' share of tiles and pixels their edge pass worked on, and their
/// trace pass's work.
fn edge_shares(ctx: &GpuContext, subject: &Subject) -> Result<Option<EdgeShares>> {
    let frame = match subject {
        Subject::Deferred(_, frame, _)
        | Subject::RenderPass(_, frame, _)
        | Subject::Edges(_, _, _, frame, _) => frame,
        _ => return Ok(None),
    };
    let w = frame.edge_work(&ctx.device, &ctx.queue)?;
    let all_tiles = f64::from(w.all_tiles.max(1));
    Ok(Some(EdgeShares {
        tiles: f64::from(w.tiles) / all_tiles,
        traced_tiles: f64::from(w.traced_tiles) / all_tiles,
        refined: f64::from(w.refined) / f64::from(w.pixels.max(1)),
        traced_clusters: w.traced_clusters,
        traced_pieces: w.traced_pieces,
        settled_pieces: w.settled_pieces,
    }))
}

/// How a run names an edge selection: `edges=all`, `edges=polygon`, `edges=feature:30`.
pub(super) fn edges_name(e: EdgeSelection) -> String {
    match e {
        EdgeSelection::All => "edges=all".into(),
        EdgeSelection::Polygon => "edges=polygon".into(),
        EdgeSelection::Feature(d) => format!("edges=feature:{d}"),
        EdgeSelection::Authored => "edges=authored".into(),
    }
}

/// `on` or `off`.
pub(super) fn switch(on: bool) -> &'static str {
    if on {
        "on"
    } else {
        "off"
    }
}

/// Whether two runs timed the same scene at the same size.
pub(super) fn same_shot(a: &Run, b: &Run) -> bool {
    a.scene == b.scene && a.size == b.size
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let s = Stats::of(&[5.0, 1.0, 3.0, 2.0, 4.0]);
        assert_eq!((s.p10_ms, s.median_ms, s.p90_ms), (1.0, 3.0, 5.0));
        let one = Stats::of(&[7.0]);
        assert_eq!((one.p10_ms, one.median_ms, one.p90_ms), (7.0, 7.0, 7.0));
    }
}
