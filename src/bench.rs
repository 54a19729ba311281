//! The benchmark comparison: every method on one scene and size, GPU time per pass from
//! timestamp queries, frames interleaved across methods so that drift on a busy machine
//! affects them alike.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::gpu::{
    DeferredPass, EdgeLines, ForwardPass, GpuContext, GpuMesh, GpuTimer, OutputTarget,
    PassOptions, TwoPass,
};
use crate::mesh::{EdgeSelection, Mesh};
use crate::render::Scene;
use crate::style::Style;
use std::collections::BTreeMap;
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
    /// Triangle count.
    pub triangles: usize,
    /// Image size.
    pub size: [u32; 2],
    /// Method name.
    pub method: String,
    /// GPU time of each pass.
    pub passes: BTreeMap<String, Stats>,
    /// Median over frames of the sum of the passes.
    pub total_median_ms: f64,
    /// CPU time to record and submit one frame.
    pub cpu: Stats,
    /// GPU memory the method allocates: mesh buffers and its targets.
    pub gpu_bytes: u64,
}

/// A method being measured: its pass and output.
enum Subject {
    Floor(DeferredPass, wgpu::Texture),
    Deferred(DeferredPass, wgpu::Texture),
    Forward(ForwardPass, wgpu::Texture),
    TwoPass(TwoPass, EdgeLines, wgpu::Texture),
}

impl Subject {
    fn name(&self) -> &'static str {
        match self {
            Subject::Floor(..) => "floor",
            Subject::Deferred(..) => "deferred",
            Subject::Forward(..) => "forward",
            Subject::TwoPass(..) => "two-pass",
        }
    }

    fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        timer: &mut GpuTimer,
    ) -> Result<()> {
        match self {
            Subject::Floor(pass, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_timed(device, encoder, mesh, OutputTarget::Floor(&view), timer)
            }
            Subject::Deferred(pass, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_timed(device, encoder, mesh, OutputTarget::Shaded(&view), timer)
            }
            Subject::Forward(pass, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_timed(device, encoder, mesh, &view, timer)
            }
            Subject::TwoPass(pass, lines, out) => {
                let view = out.create_view(&Default::default());
                pass.encode_timed(device, encoder, mesh, lines, &view, timer)
            }
        }
    }

    fn bytes(&self) -> u64 {
        let texture = |t: &wgpu::Texture| u64::from(t.width()) * u64::from(t.height()) * 4;
        // Colour, id and depth targets of the forward methods: 4 bytes per pixel each.
        let forward = |t: &wgpu::Texture| 3 * texture(t);
        match self {
            Subject::Floor(p, t) | Subject::Deferred(p, t) => p.target_bytes() + texture(t),
            Subject::Forward(_, t) => forward(t),
            Subject::TwoPass(_, lines, t) => forward(t) + lines.gpu_bytes(),
        }
    }
}

fn output(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("wirepass bench output"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Times every method on `mesh` at `size`, with the framing camera and the default style:
/// see [`bench_scene`].
pub fn bench(
    ctx: &GpuContext,
    name: &str,
    mesh: &Mesh,
    size: (u32, u32),
    frames: u32,
    warmup: u32,
) -> Result<Vec<Run>> {
    let (lo, hi) = mesh.bounds();
    let scene = Scene {
        mesh,
        camera: Camera::framing(lo, hi, size.0 as f32 / size.1 as f32),
        style: Style::default(),
        size,
        edges: EdgeSelection::Polygon,
    };
    bench_scene(ctx, name, &scene, frames, warmup)
}

/// Times the floor and every GPU method on `scene`: `warmup` untimed frames, then `frames`
/// timed frames, each frame running every method once, in turn.
pub fn bench_scene(
    ctx: &GpuContext,
    name: &str,
    scene: &Scene<'_>,
    frames: u32,
    warmup: u32,
) -> Result<Vec<Run>> {
    if frames == 0 {
        return Err(Error::InvalidSetting("--frames must be at least 1".into()));
    }
    let device = &ctx.device;
    let queue = &ctx.queue;
    let (mesh, size, camera, style) = (scene.mesh, scene.size, scene.camera, &scene.style);
    let gpu_mesh = GpuMesh::new(device, mesh, scene.edges)?;
    let storage = || {
        let usage = wgpu::TextureUsages::STORAGE_BINDING;
        output(device, size, wgpu::TextureFormat::Rgba8Unorm, usage)
    };
    let forward_options = PassOptions {
        output_format: wgpu::TextureFormat::Rgba8UnormSrgb,
    };
    let attachment = || {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        output(device, size, forward_options.output_format, usage)
    };
    let mut subjects = Vec::new();
    for floor in [true, false] {
        let mut pass = DeferredPass::new(device, PassOptions::default())?;
        pass.prepare(device, queue, &gpu_mesh, &camera, style, size)?;
        subjects.push(if floor {
            Subject::Floor(pass, storage())
        } else {
            Subject::Deferred(pass, storage())
        });
    }
    let mut forward = ForwardPass::new(device, forward_options)?;
    forward.prepare(device, queue, &gpu_mesh, &camera, style, size)?;
    subjects.push(Subject::Forward(forward, attachment()));
    let mut two_pass = TwoPass::new(device, forward_options)?;
    two_pass.prepare(device, queue, &gpu_mesh, &camera, style, size)?;
    let lines = EdgeLines::new(device, mesh, scene.edges)?;
    subjects.push(Subject::TwoPass(two_pass, lines, attachment()));
    ctx.finish()?;

    let mut timer = GpuTimer::new(device, queue, 4)?;
    let mut gpu: Vec<BTreeMap<&'static str, Vec<f64>>> = vec![BTreeMap::new(); subjects.len()];
    let mut totals = vec![Vec::new(); subjects.len()];
    let mut cpu = vec![Vec::new(); subjects.len()];
    for frame in 0..warmup + frames {
        for (i, subject) in subjects.iter().enumerate() {
            let start = Instant::now();
            let mut encoder = device.create_command_encoder(&Default::default());
            subject.encode(device, &mut encoder, &gpu_mesh, &mut timer)?;
            timer.resolve(&mut encoder);
            queue.submit([encoder.finish()]);
            let recorded = start.elapsed().as_secs_f64() * 1e3;
            let spans = timer.read(device)?;
            ctx.finish()?;
            if frame >= warmup {
                cpu[i].push(recorded);
                totals[i].push(spans.iter().map(|s| s.1).sum());
                for (name, ms) in spans {
                    gpu[i].entry(name).or_default().push(ms);
                }
            }
        }
    }
    Ok(subjects
        .iter()
        .enumerate()
        .map(|(i, subject)| Run {
            scene: name.to_owned(),
            triangles: mesh.triangle_count(),
            size: [size.0, size.1],
            method: subject.name().to_owned(),
            passes: gpu[i]
                .iter()
                .map(|(name, v)| ((*name).to_owned(), Stats::of(v)))
                .collect(),
            total_median_ms: Stats::of(&totals[i]).median_ms,
            cpu: Stats::of(&cpu[i]),
            gpu_bytes: gpu_mesh.gpu_bytes() + subject.bytes(),
        })
        .collect())
}

/// A markdown table of runs, with each method's total relative to the deferred one of the
/// same scene and size.
pub fn markdown(runs: &[Run]) -> String {
    let mut out = String::from(
        "| scene | triangles | size | method | visibility ms | edge/draw ms | total ms | vs deferred | GPU MiB |\n\
         |---|---:|---|---|---:|---:|---:|---:|---:|\n",
    );
    for r in runs {
        let deferred = runs
            .iter()
            .find(|d| d.scene == r.scene && d.size == r.size && d.method == "deferred")
            .map(|d| d.total_median_ms);
        let pass = |name: &str| {
            r.passes
                .get(name)
                .map(|s| format!("{:.3}", s.median_ms))
                .unwrap_or_else(|| "–".into())
        };
        let other: Vec<_> = r
            .passes
            .iter()
            .filter(|(k, _)| k.as_str() != "visibility")
            .map(|(k, s)| format!("{k} {:.3}", s.median_ms))
            .collect();
        out += &format!(
            "| {} | {} | {}x{} | {} | {} | {} | {:.3} | {} | {:.1} |\n",
            r.scene,
            r.triangles,
            r.size[0],
            r.size[1],
            r.method,
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
