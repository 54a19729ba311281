//! The benchmark comparison: every method on one scene and size, GPU time per pass from
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
    /// `edge.outlined`, `edge.tiles`, `edge.refine`; the floor's `edge.floor`),
    /// `outline` of `outline.cull`, `outline.draw` and `outline.pieces`.
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
    /// Tiles the outline pass's lines reach among all 8×8 output tiles.
    pub outlined_tiles: f64,
    /// Pixels refined among all output pixels.
    pub refined: f64,
    /// Clusters of 64 triangles the outline pass's cull listed for its triangle dispatch.
    pub outline_clusters: u32,
    /// Pieces of outline edges the outline pass's piece dispatch drew (or found beyond its
    /// list's room).
    pub outline_pieces: u32,
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
    /// The deferred method (visibility, outline and edge passes) into a storage texture.
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
    let Timing {
        frames,
        warmup,
        edges,
        methods,
    } = timing;
    if frames == 0 {
        return Err(Error::InvalidSetting("--frames must be at least 1".into()));
    }
    let timed = |m: Timed| methods.is_empty() || methods.contains(&m);
    let device = &ctx.device;
    let queue = &ctx.queue;
    let size = shot.size;
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let lines = up.edge_lines(&ctx.device, shot.world)?;
    let scene = up.scene(shot.world, shot.view);
    let storage = || {
        // RENDER_ATTACHMENT: the edge pass clears the background instead of writing it.
        let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
        texture_2d(
            device,
            "wirepass bench output",
            size,
            wgpu::TextureFormat::Rgba8Unorm,
            usage,
        )
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
    for &selection in &edges {
        let mut world = shot.world.clone();
        for m in &mut world.meshes {
            let (mesh, e) = (*m.mesh).clone().resolve_edges(Some(selection));
            m.mesh = Arc::new(mesh);
            m.edges = e;
        }
        let up = Box::new(Uploaded::new(&ctx.device, &ctx.queue, &world)?);
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
    // Where no OpenGL context with geometry shaders can be made, gs is reported skipped.
    let mut skipped = Vec::new();
    if timed(Timed::Gs) {
        let gpu = (device, queue);
        let made = GsPass::new().and_then(|mut pass| {
            let frame = pass.prepare(gpu, &up.store, &scene, shot.style, (size, false))?;
            Ok(Subject::Gs(Box::new(pass), frame))
        });
        match made {
            Ok(subject) => subjects.push(subject),
            Err(Error::NoAdapter(why)) => skipped.push(("gs", why)),
            Err(e) => return Err(e),
        }
    }
    ctx.finish()?;

    // Room for every span a frame can have (the host's depth seeding included), and more.
    let mut timer = GpuTimer::new(device, queue, 16)?;
    let mut gpu: Vec<BTreeMap<String, Vec<f64>>> = vec![BTreeMap::new(); subjects.len()];
    let mut totals = vec![Vec::new(); subjects.len()];
    let mut cpu = vec![Vec::new(); subjects.len()];
    for frame in 0..warmup + frames {
        for (i, subject) in subjects.iter().enumerate() {
            let (spans, recorded) =
                subject.time((device, queue), (&up.store, &lines), &mut timer)?;
            ctx.finish()?;
            if frame >= warmup {
                cpu[i].push(recorded);
                totals[i].push(spans.iter().map(|s| s.1).sum());
                let mut groups: BTreeMap<String, f64> = BTreeMap::new();
                for (name, ms) in spans {
                    if let Some((group, _)) = name.split_once('.') {
                        *groups.entry(group.to_owned()).or_default() += ms;
                    }
                    gpu[i].entry(name.to_owned()).or_default().push(ms);
                }
                for (group, ms) in groups {
                    gpu[i].entry(group).or_default().push(ms);
                }
            }
        }
    }
    let store_bytes = up.store.gpu_bytes();
    let mut shares = Vec::new();
    for subject in &subjects {
        shares.push(match subject {
            Subject::Deferred(_, frame, _)
            | Subject::RenderPass(_, frame, _)
            | Subject::Edges(_, _, _, frame, _) => {
                let w = frame.edge_work(device, queue)?;
                Some(EdgeShares {
                    tiles: f64::from(w.tiles) / f64::from(w.all_tiles.max(1)),
                    outlined_tiles: f64::from(w.outlined_tiles) / f64::from(w.all_tiles.max(1)),
                    refined: f64::from(w.refined) / f64::from(w.pixels.max(1)),
                    outline_clusters: w.outline_clusters,
                    outline_pieces: w.outline_pieces,
                })
            }
            _ => None,
        });
    }
    Ok(subjects
        .iter()
        .enumerate()
        .map(|(i, subject)| Run {
            scene: name.to_owned(),
            triangles: shot.world.triangle_count(),
            size: [size.0, size.1],
            method: subject.name(),
            outlines: shot.style.outlines,
            passes: gpu[i]
                .iter()
                .map(|(name, v)| (name.clone(), Stats::of(v)))
                .collect(),
            total_median_ms: Stats::of(&totals[i]).median_ms,
            cpu: Stats::of(&cpu[i]),
            gpu_bytes: match subject {
                Subject::Gs(..) => subject.bytes(&lines),
                _ => store_bytes + subject.bytes(&lines),
            },
            edge_work: shares[i],
            skipped: None,
            gl: match subject {
                Subject::Gs(pass, _) => Some(format!(
                    "{}; timed by {}",
                    pass.description(),
                    pass.timing()
                )),
                _ => None,
            },
        })
        .chain(skipped.into_iter().map(|(method, why)| Run {
            scene: name.to_owned(),
            triangles: shot.world.triangle_count(),
            size: [size.0, size.1],
            method: method.to_owned(),
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
            skipped: Some(why),
            gl: None,
        }))
        .collect())
}

/// How an edge selection is named on the command line: `all`, `polygon`, `feature:30`.
fn edges_name(e: EdgeSelection) -> String {
    match e {
        EdgeSelection::All => "edges=all".into(),
        EdgeSelection::Polygon => "edges=polygon".into(),
        EdgeSelection::Feature(d) => format!("edges=feature:{d}"),
        EdgeSelection::Authored => "edges=authored".into(),
    }
}

/// A markdown table of the deferred method's edge and outline passes under each edge
/// selection timed (`Timing::edges`), relative to the world's own selection (`deferred`) of
/// the same scene and size; empty when only one was timed.
pub fn edges_markdown(runs: &[Run]) -> String {
    let mut out = String::new();
    let median = |r: &Run, name: &str| r.passes.get(name).map_or(0.0, |s| s.median_ms);
    for base in runs.iter().filter(|r| r.method == "deferred") {
        let others: Vec<&Run> = runs
            .iter()
            .filter(|r| {
                same_shot(r, base)
                    && r.outlines == base.outlines
                    && r.method.starts_with("deferred ")
            })
            .collect();
        if others.is_empty() {
            continue;
        }
        if out.is_empty() {
            out += "| scene | size | method | edge ms | ÷ deferred | edge + outline ms | ÷ deferred |\n\
                    |---|---|---|---:|---:|---:|---:|\n";
        }
        let (edge, both) = (
            median(base, "edge"),
            median(base, "edge") + median(base, "outline"),
        );
        for r in std::iter::once(base).chain(others) {
            let (e, b) = (median(r, "edge"), median(r, "edge") + median(r, "outline"));
            out += &format!(
                "| {} | {}x{} | {} | {:.3} | {:.2}× | {:.3} | {:.2}× |\n",
                r.scene,
                r.size[0],
                r.size[1],
                r.method,
                e,
                e / edge,
                b,
                b / both
            );
        }
    }
    out
}

/// A markdown table of runs, with each method's total relative to the deferred one of the
/// same scene and size.
pub fn markdown(runs: &[Run]) -> String {
    let mut out = String::from(
        "| scene | triangles | size | outlines | method | visibility ms | edge/draw ms | total ms | vs deferred | GPU MiB |\n\
         |---|---:|---|---|---|---:|---:|---:|---:|---:|\n",
    );
    for r in runs {
        if let Some(why) = &r.skipped {
            let why = why.replace('|', "/");
            out += &format!("{} – | skipped: {why} | – | – | – |\n", row_head(r));
            continue;
        }
        let deferred = runs
            .iter()
            .find(|d| same_shot(d, r) && d.outlines == r.outlines && d.method == "deferred")
            .map(|d| d.total_median_ms);
        let pass = |name: &str| {
            r.passes
                .get(name)
                .map(|s| format!("{:.3}", s.median_ms))
                .unwrap_or_else(|| "–".into())
        };
        let mut other: Vec<_> = r
            .passes
            .iter()
            .filter(|(k, _)| k.as_str() != "visibility")
            .map(|(k, s)| format!("{k} {:.3}", s.median_ms))
            .collect();
        if let Some(w) = r.edge_work {
            other.push(format!(
                "tiles {:.1} %, outlined tiles {:.1} %, refined {:.2} % of pixels, {} outline \
                 clusters, {} outline pieces",
                100.0 * w.tiles,
                100.0 * w.outlined_tiles,
                100.0 * w.refined,
                w.outline_clusters,
                w.outline_pieces
            ));
        }
        out += &format!(
            "{} {} | {} | {:.3} | {} | {:.1} |\n",
            row_head(r),
            pass("visibility"),
            other.join(", "),
            r.total_median_ms,
            deferred
                .filter(|d| *d > 0.0)
                .map(|d| format!("{:.2}×", r.total_median_ms / d))
                .unwrap_or_else(|| "–".into()),
            r.gpu_bytes as f64 / (1024.0 * 1024.0),
        );
    }
    out
}

/// A row's first cells in [`markdown`]: scene, triangles, size, outlines and method.
fn row_head(r: &Run) -> String {
    format!(
        "| {} | {} | {}x{} | {} | {} |",
        r.scene,
        r.triangles,
        r.size[0],
        r.size[1],
        switch(r.outlines),
        r.method
    )
}

/// `on` or `off`.
fn switch(on: bool) -> &'static str {
    if on {
        "on"
    } else {
        "off"
    }
}

/// Whether two runs timed the same scene at the same size.
fn same_shot(a: &Run, b: &Run) -> bool {
    a.scene == b.scene && a.size == b.size
}

/// One row per scene and size: each method's total (the deferred method's with outlines and
/// without), the edge pass against the floor's compute pass, and the deferred method
/// against the published one (`gs`); ms, medians. Ratios are given with outlines on / off
/// where both were timed.
pub fn summary_markdown(runs: &[Run]) -> String {
    let mut out = String::from(
        "| scene | triangles | size | floor | deferred | deferred, no outlines | forward | two-pass | gs | edge ÷ floor | deferred ÷ gs |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut shots: Vec<&Run> = Vec::new();
    for r in runs {
        if !shots.iter().any(|s| same_shot(s, r)) {
            shots.push(r);
        }
    }
    for shot in shots {
        let find = |method: &str, outlines: Option<bool>| {
            runs.iter().find(|r| {
                same_shot(r, shot)
                    && r.method == method
                    && r.skipped.is_none()
                    && outlines.is_none_or(|o| r.outlines == o)
            })
        };
        let ms =
            |r: Option<&Run>| r.map_or("–".to_owned(), |r| format!("{:.2}", r.total_median_ms));
        let floor = find("floor", None);
        let on = find("deferred", Some(true));
        let off = find("deferred", Some(false));
        let gs = find("gs", None);
        let edge = |r: &Run| r.passes.get("edge").map(|s| s.median_ms);
        let ratios = |f: &dyn Fn(&Run) -> Option<f64>| {
            let parts: Vec<String> = [on, off]
                .into_iter()
                .flatten()
                .filter_map(|d| f(d).map(|v| format!("{v:.2}×")))
                .collect();
            if parts.is_empty() {
                "–".to_owned()
            } else {
                parts.join(" / ")
            }
        };
        let edge_floor = ratios(&|d| Some(edge(d)? / edge(floor?)?));
        let deferred_gs = ratios(&|d| Some(d.total_median_ms / gs?.total_median_ms));
        out += &format!(
            "| {} | {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            shot.scene,
            shot.triangles,
            shot.size[0],
            shot.size[1],
            ms(floor),
            ms(on),
            ms(off),
            ms(find("forward", None)),
            ms(find("two-pass", None)),
            match find("gs", None) {
                Some(r) => ms(Some(r)),
                None if runs.iter().any(|r| same_shot(r, shot) && r.method == "gs") => {
                    "skipped".to_owned()
                }
                None => "–".to_owned(),
            },
            edge_floor,
            deferred_gs,
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ratio more than 15 % above its baseline is flagged; one within it, or better, is
    /// not; ratios of other scenes or settings are not compared.
    #[test]
    fn against_flags_ratios_that_worsened() {
        let ratio = |scene: &str, outlines: &str, value| Ratio {
            scene: scene.into(),
            size: "1280x720".into(),
            ratio: "deferred ÷ gs".into(),
            outlines: outlines.into(),
            value,
        };
        let baseline = Baseline {
            adapter: "lavapipe".into(),
            commit: "abc1234".into(),
            date: "2026-12-06".into(),
            ratios: vec![
                ratio("a", "on", 0.6),
                ratio("a", "off", 0.5),
                ratio("b", "on", 1.0),
            ],
        };
        let now = [
            ratio("a", "on", 0.7),
            ratio("a", "off", 0.55),
            ratio("b", "on", 0.9),
            ratio("c", "on", 9.0),
        ];
        let (table, worse) = against(&baseline, &now);
        assert_eq!(worse, 1, "{table}");
        assert!(table.contains("3 ratios compared, 1 worse"), "{table}");
        assert!(
            table.contains("| a | 1280x720 | on | deferred ÷ gs | 0.60 | 0.70 | +17 % | worse |")
        );
        assert!(!table.contains("| c |"), "{table}");
    }

    #[test]
    fn nearest_rank_percentiles() {
        let s = Stats::of(&[5.0, 1.0, 3.0, 2.0, 4.0]);
        assert_eq!((s.p10_ms, s.median_ms, s.p90_ms), (1.0, 3.0, 5.0));
        let one = Stats::of(&[7.0]);
        assert_eq!((one.p10_ms, one.median_ms, one.p90_ms), (7.0, 7.0, 7.0));
    }
}

/// The adapter a benchmark ran on, for the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    /// Adapter name.
    pub name: String,
    /// wgpu backend.
    pub backend: String,
    /// Device type (discrete, integrated, CPU, …).
    pub device_type: String,
    /// Driver and its version, as reported.
    pub driver: String,
}

impl DeviceInfo {
    /// Reads the adapter's description.
    pub fn of(ctx: &GpuContext) -> DeviceInfo {
        let i = ctx.adapter.get_info();
        DeviceInfo {
            name: i.name,
            backend: format!("{:?}", i.backend),
            device_type: format!("{:?}", i.device_type),
            driver: format!("{} {}", i.driver, i.driver_info).trim().to_owned(),
        }
    }

    /// One line.
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, {}; {})",
            self.name, self.backend, self.device_type, self.driver
        )
    }
}

/// The whole report in markdown: the adapter (and the OpenGL renderer `gs` ran on), the
/// summary by scene ([`summary_markdown`]), every run's passes ([`markdown`]) and the edge
/// selections' table ([`edges_markdown`]).
pub fn report_markdown(device: &DeviceInfo, runs: &[Run]) -> String {
    let mut out = format!("{}\n\n", device.describe());
    if let Some(gl) = runs.iter().find_map(|r| r.gl.as_ref()) {
        out += &format!("gs on {gl}\n\n");
    }
    out += &summary_markdown(runs);
    out += "\n";
    out += &ratios_markdown(&ratios(runs));
    out += "\n";
    out += &markdown(runs);
    let by_edges = edges_markdown(runs);
    if !by_edges.is_empty() {
        out += "\n";
        out += &by_edges;
    }
    out
}

/// Writes `bench.md` ([`report_markdown`]), `bench.json`, `bench.csv`, `ratios.json`
/// ([`ratios`]), `time_vs_triangles.png` and `time_vs_pixels.png` into `dir`.
pub fn write_outputs(dir: &std::path::Path, device: &DeviceInfo, runs: &[Run]) -> Result<()> {
    let io = |path: std::path::PathBuf| move |source| Error::Io { path, source };
    std::fs::create_dir_all(dir).map_err(io(dir.to_owned()))?;
    let path = dir.join("bench.md");
    std::fs::write(&path, report_markdown(device, runs)).map_err(io(path.clone()))?;
    let json = serde_json::json!({ "device": device, "runs": runs });
    let path = dir.join("bench.json");
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| Error::InvalidSetting(format!("bench.json: {e}")))?;
    std::fs::write(&path, text).map_err(io(path.clone()))?;
    let path = dir.join("bench.csv");
    std::fs::write(&path, csv(runs)).map_err(io(path.clone()))?;
    let path = dir.join("ratios.json");
    let text = serde_json::to_string_pretty(&ratios(runs))
        .map_err(|e| Error::InvalidSetting(format!("ratios.json: {e}")))?;
    std::fs::write(&path, text).map_err(io(path.clone()))?;
    // Lines join procedural scenes of one kind (`sphere:N`); a mesh file is a point.
    let family = |r: &Run| match r.scene.split_once(':') {
        Some((kind, _)) if !r.scene.contains('/') => kind.to_owned(),
        _ => r.scene.clone(),
    };
    plot::time_against(
        &dir.join("time_vs_triangles.png"),
        runs,
        "triangles",
        |r| r.triangles as f64,
        (|r: &Run| format!("{}x{}", r.size[0], r.size[1]), family),
    )?;
    plot::time_against(
        &dir.join("time_vs_pixels.png"),
        runs,
        "pixels",
        |r| f64::from(r.size[0]) * f64::from(r.size[1]),
        (|r: &Run| r.scene.clone(), |_: &Run| String::new()),
    )
}

/// One row per run and pass (plus a `total` row per run).
pub fn csv(runs: &[Run]) -> String {
    let mut out = String::from(
        "scene,triangles,width,height,outlines,method,pass,median_ms,p10_ms,p90_ms,cpu_median_ms,gpu_bytes\n",
    );
    for r in runs {
        let total = Stats {
            median_ms: r.total_median_ms,
            p10_ms: f64::NAN,
            p90_ms: f64::NAN,
        };
        let rows = r.passes.iter().map(|(k, v)| (k.as_str(), v));
        for (pass, s) in rows.chain([("total", &total)]) {
            let num = |v: f64| {
                if v.is_nan() {
                    String::new()
                } else {
                    format!("{v:.6}")
                }
            };
            out += &format!(
                "{},{},{},{},{},{},{},{},{},{},{:.6},{}\n",
                r.scene.replace(',', ";"),
                r.triangles,
                r.size[0],
                r.size[1],
                switch(r.outlines),
                r.method,
                pass,
                num(s.median_ms),
                num(s.p10_ms),
                num(s.p90_ms),
                r.cpu.median_ms,
                r.gpu_bytes
            );
        }
    }
    out
}

mod plot {
    //! Log-log plots of GPU time per method (and per pass of the deferred one), with
    //! plotters and an embedded font so they draw the same on a machine without fonts.

    use super::Run;
    use crate::error::{Error, Result};
    use plotters::prelude::*;
    use std::path::Path;
    use std::sync::Once;

    fn register_font() {
        static ONCE: Once = Once::new();
        ONCE.call_once(|| {
            // The bytes are a known-good embedded TTF; a failure would only lose the text.
            let _ = plotters::style::register_font(
                "sans-serif",
                FontStyle::Normal,
                dejavu::sans::regular(),
            );
        });
    }

    const COLORS: [RGBColor; 5] = [
        RGBColor(120, 120, 120),
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
    ];
    /// The deferred method's own passes, drawn thin beside the totals.
    const PASSES: [(&str, RGBColor); 2] = [
        ("edge", RGBColor(23, 190, 207)),
        ("outline", RGBColor(148, 103, 189)),
    ];

    /// One plotted line.
    struct Line {
        /// In the legend; the first line of each method and group only.
        label: Option<String>,
        color: RGBAColor,
        /// Stroke width in pixels.
        width: u32,
        points: Vec<(f64, f64)>,
    }

    /// `20k`, `2M`, `1.5M`: tick labels that read at a glance.
    fn short(v: f64) -> String {
        let (scaled, unit) = match v.abs() {
            a if a >= 1e9 => (v / 1e9, "G"),
            a if a >= 1e6 => (v / 1e6, "M"),
            a if a >= 1e3 => (v / 1e3, "k"),
            _ => (v, ""),
        };
        let text = format!("{scaled:.1}");
        format!("{}{unit}", text.trim_end_matches(".0"))
    }

    /// Whether `r` is a deferred method (or the floor) timed without outlines: drawn as a
    /// line of its own, fainter.
    fn without_outlines(r: &Run) -> bool {
        !r.outlines && (r.method == "floor" || r.method.starts_with("deferred"))
    }

    /// Median GPU time against `x` (log-log): the total per method, one colour per method
    /// and one line per method, `group` (the variable held fixed along the line, named in
    /// the legend) and `family` (scenes whose points a line may join: the spheres of
    /// `sphere:N`, say; a mesh file is a point of its own), and thinner lines for the
    /// deferred method's edge and outline passes. The deferred methods timed without
    /// outlines are fainter lines of their own.
    pub fn time_against(
        path: &Path,
        runs: &[Run],
        x_name: &str,
        x: impl Fn(&Run) -> f64,
        (group, family): (impl Fn(&Run) -> String, impl Fn(&Run) -> String),
    ) -> Result<()> {
        register_font();
        let fail = |e: String| Error::Image {
            path: path.to_owned(),
            message: e,
        };
        let group = |r: &Run| {
            let suffix = if without_outlines(r) {
                ", no outlines"
            } else {
                ""
            };
            format!("{}{suffix}", group(r))
        };
        let mut methods: Vec<&str> = Vec::new();
        let mut keys: Vec<(&str, String, String)> = Vec::new();
        for r in runs.iter().filter(|r| r.skipped.is_none()) {
            if !methods.contains(&r.method.as_str()) {
                methods.push(&r.method);
            }
            let key = (r.method.as_str(), group(r), family(r));
            if !keys.contains(&key) {
                keys.push(key);
            }
        }
        let groups = keys
            .iter()
            .map(|l| &l.1)
            .collect::<std::collections::BTreeSet<_>>();
        let mut lines: Vec<Line> = Vec::new();
        let mut labelled = std::collections::BTreeSet::new();
        for (method, fixed, kind) in &keys {
            let chosen = || {
                runs.iter().filter(|r| {
                    r.skipped.is_none()
                        && r.method == *method
                        && group(r) == *fixed
                        && family(r) == *kind
                })
            };
            let suffix = if groups.len() > 1 {
                format!(" ({fixed})")
            } else {
                String::new()
            };
            let first = labelled.insert((*method, fixed.clone()));
            let label = |name: String| first.then_some(name);
            let faint = fixed.ends_with(", no outlines");
            let shade = |c: RGBColor| c.mix(if faint { 0.45 } else { 1.0 });
            let m = methods.iter().position(|n| n == method).unwrap_or(0);
            let total = chosen().map(|r| (x(r), r.total_median_ms)).collect();
            lines.push(Line {
                label: label(format!("{method}{suffix}")),
                color: shade(COLORS[m % COLORS.len()]),
                width: 2,
                points: total,
            });
            if *method == "deferred" {
                for (pass, color) in PASSES {
                    let points: Vec<_> = chosen()
                        .filter_map(|r| r.passes.get(pass).map(|s| (x(r), s.median_ms)))
                        .collect();
                    if !points.is_empty() {
                        lines.push(Line {
                            label: label(format!("deferred: {pass} pass{suffix}")),
                            color: shade(color),
                            width: 1,
                            points,
                        });
                    }
                }
            }
        }
        for line in &mut lines {
            line.points.retain(|p| p.0 > 0.0 && p.1 > 0.0);
            line.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let points = lines.iter().flat_map(|l| l.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(px, py) in points {
            (x0, x1, y0, y1) = (x0.min(px), x1.max(px), y0.min(py), y1.max(py));
        }
        if x0 > x1 {
            return Ok(());
        }
        let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("GPU time per frame against {x_name}"),
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.8..y1 * 1.25).log_scale(),
            )
            .map_err(|e| fail(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(x_name)
            .y_desc("median GPU ms")
            .x_label_formatter(&|v| short(*v))
            .y_label_formatter(&|v| short(*v))
            .draw()
            .map_err(|e| fail(e.to_string()))?;
        for Line {
            label,
            color,
            width,
            points: series,
        } in lines
        {
            let drawn = chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(width)))
                .map_err(|e| fail(e.to_string()))?;
            if let Some(label) = label {
                drawn.label(label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(width))
                });
            }
            chart
                .draw_series(
                    series
                        .into_iter()
                        .map(|p| Circle::new(p, 2 + width, color.filled())),
                )
                .map_err(|e| fail(e.to_string()))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))
    }
}

/// One ratio of a benchmark run, the unit the baseline keeps (`bench/baseline.json`): the
/// scene and size it was measured on, what it divides by what, and whether the deferred
/// method drew outlines. Every ratio is one where lower is better.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ratio {
    /// Scene name as given.
    pub scene: String,
    /// Image size, `WxH`.
    pub size: String,
    /// What is divided by what: `deferred ÷ gs`, `deferred ÷ forward`, `edge ÷ floor`,
    /// `render-pass ÷ deferred`, `edge ÷ edge at SCENE` (the edge pass against its time on the
    /// scene of fewest triangles of the same procedural kind and size: flat in triangles is
    /// 1).
    pub ratio: String,
    /// `on` or `off`.
    pub outlines: String,
    /// The ratio.
    pub value: f64,
}

/// The kind of a procedural scene (`sphere` of `sphere:20000`), none for a file.
fn family(r: &Run) -> Option<&str> {
    let (kind, _) = r.scene.split_once(':')?;
    (!r.scene.contains(['/', '\\', '.'])).then_some(kind)
}

/// The ratios of a run, each measured within it (the methods interleaved frame by frame).
pub fn ratios(runs: &[Run]) -> Vec<Ratio> {
    let timed = |r: &&Run| r.skipped.is_none() && r.total_median_ms > 0.0;
    let find = |shot: &Run, method: &str, outlines: Option<bool>| {
        runs.iter().filter(timed).find(|r| {
            same_shot(r, shot) && r.method == method && outlines.is_none_or(|o| r.outlines == o)
        })
    };
    let edge = |r: &Run| r.passes.get("edge").map(|s| s.median_ms);
    let mut out = Vec::new();
    let mut push = |r: &Run, ratio: String, value: Option<f64>| {
        if let Some(value) = value.filter(|v| v.is_finite()) {
            out.push(Ratio {
                scene: r.scene.clone(),
                size: format!("{}x{}", r.size[0], r.size[1]),
                ratio,
                outlines: switch(r.outlines).to_owned(),
                value,
            });
        }
    };
    for d in runs.iter().filter(timed).filter(|r| r.method == "deferred") {
        let total = |r: Option<&Run>| r.map(|r| r.total_median_ms);
        for other in ["gs", "forward"] {
            push(
                d,
                format!("deferred ÷ {other}"),
                total(find(d, other, None)).map(|t| d.total_median_ms / t),
            );
        }
        let floor = find(d, "floor", Some(d.outlines)).or_else(|| find(d, "floor", None));
        push(
            d,
            "edge ÷ floor".into(),
            floor.and_then(|f| Some(edge(d)? / edge(f)?)),
        );
        let host = total(find(d, "render-pass", Some(d.outlines)));
        push(
            d,
            "render-pass ÷ deferred".into(),
            host.map(|h| h / d.total_median_ms),
        );
        // The edge pass against the scene of fewest triangles of the same family (the
        // procedural meshes of one kind, `sphere:N`) and size.
        let fewest = runs
            .iter()
            .filter(timed)
            .filter(|r| r.method == "deferred" && r.size == d.size && r.outlines == d.outlines)
            .filter(|r| family(r).is_some() && family(r) == family(d))
            .min_by_key(|r| r.triangles);
        if let Some(f) = fewest.filter(|f| f.scene != d.scene) {
            let name = format!("edge ÷ edge at {}", f.scene);
            push(d, name, edge(d).zip(edge(f)).map(|(a, b)| a / b));
        }
    }
    out
}

/// A table of a run's ratios, one row per scene, size and setting.
pub fn ratios_markdown(ratios: &[Ratio]) -> String {
    let mut names: Vec<&str> = Vec::new();
    for r in ratios {
        if !names.contains(&r.ratio.as_str()) {
            names.push(&r.ratio);
        }
    }
    let mut out = String::from("| scene | size | outlines |");
    for n in &names {
        out += &format!(" {n} |");
    }
    out += "\n|---|---|---|";
    out += &"---:|".repeat(names.len());
    out += "\n";
    let mut rows: Vec<(&str, &str, &str)> = Vec::new();
    for r in ratios {
        let key = (r.scene.as_str(), r.size.as_str(), r.outlines.as_str());
        if !rows.contains(&key) {
            rows.push(key);
        }
    }
    for (scene, size, outlines) in rows {
        out += &format!("| {scene} | {size} | {outlines} |");
        for n in &names {
            let value = ratios.iter().find(|r| {
                r.scene == scene && r.size == size && r.outlines == outlines && r.ratio == *n
            });
            out += &value.map_or(" – |".to_owned(), |r| format!(" {:.2} |", r.value));
        }
        out += "\n";
    }
    out
}

/// The baseline of record: the ratios of a run, with where and when they were measured.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Baseline {
    /// The adapter the wgpu methods ran on, and the OpenGL renderer gs ran on.
    pub adapter: String,
    /// The commit measured.
    pub commit: String,
    /// The day it was measured.
    pub date: String,
    /// The ratios.
    pub ratios: Vec<Ratio>,
}

impl Baseline {
    /// Reads a baseline, with a clear error for a file that is not one.
    pub fn read(path: &std::path::Path) -> Result<Baseline> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_owned(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| {
            Error::InvalidSetting(format!("{}: not a bench baseline: {e}", path.display()))
        })
    }

    /// Writes the baseline as JSON.
    pub fn write(&self, path: &std::path::Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::InvalidSetting(format!("{}: {e}", path.display())))?;
        std::fs::write(path, text + "\n").map_err(|source| Error::Io {
            path: path.to_owned(),
            source,
        })
    }
}

/// How much worse than its baseline a ratio may get before `--against` flags it.
pub const WORSE: f64 = 1.15;

/// A table of this run's ratios against `baseline`'s (those measured on the same scene, size
/// and setting), each flagged where it worsened by more than [`WORSE`]; and how many were.
pub fn against(baseline: &Baseline, now: &[Ratio]) -> (String, usize) {
    let mut out = format!(
        "Against the baseline ({}, {}, {}):\n\n\
         | scene | size | outlines | ratio | baseline | now | change | |\n\
         |---|---|---|---|---:|---:|---:|---|\n",
        baseline.adapter, baseline.commit, baseline.date
    );
    let mut worse = 0;
    let mut compared = 0;
    for r in now {
        let Some(b) = baseline.ratios.iter().find(|b| {
            b.scene == r.scene && b.size == r.size && b.ratio == r.ratio && b.outlines == r.outlines
        }) else {
            continue;
        };
        compared += 1;
        let change = r.value / b.value;
        let flag = if change > WORSE {
            worse += 1;
            "worse"
        } else {
            ""
        };
        out += &format!(
            "| {} | {} | {} | {} | {:.2} | {:.2} | {:+.0} % | {flag} |\n",
            r.scene,
            r.size,
            r.outlines,
            r.ratio,
            b.value,
            r.value,
            100.0 * (change - 1.0)
        );
    }
    if compared == 0 {
        out += "| – | – | – | no ratio of this run is in the baseline | | | | |\n";
    }
    out += &format!(
        "\n{compared} ratios compared, {worse} worse by more than {:.0} %.\n",
        100.0 * (WORSE - 1.0)
    );
    (out, worse)
}
