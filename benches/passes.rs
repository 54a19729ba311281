//! Whole frames of each GPU method, submitted and waited for: wall-clock time as seen by
//! the CPU. Per-pass GPU times come from timestamp queries in `wirepass bench` instead.
//! `cargo bench --bench passes`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use wirepass::gpu::{DeferredPass, GpuContext, GpuMesh, OutputTarget, PassOptions};
use wirepass::mesh::sphere;
use wirepass::{Camera, EdgeSelection, Style};

fn passes(c: &mut Criterion) {
    let ctx = GpuContext::new().expect("a GPU adapter (lavapipe or llvmpipe will do)");
    let device = &ctx.device;
    let size = (640, 360);
    let mut group = c.benchmark_group("deferred frame 640x360");
    group.sample_size(10);
    for triangles in [20_000, 200_000] {
        let mesh = sphere(triangles).expect("a valid sphere");
        let gpu_mesh = GpuMesh::new(device, &mesh, EdgeSelection::Polygon).expect("upload");
        let (lo, hi) = mesh.bounds();
        let camera = Camera::framing(lo, hi, size.0 as f32 / size.1 as f32);
        let mut pass = DeferredPass::new(device, PassOptions::default()).expect("pipelines");
        pass.prepare(
            device,
            &ctx.queue,
            &gpu_mesh,
            &camera,
            &Style::default(),
            size,
        )
        .expect("prepare");
        let usage = wgpu::TextureUsages::STORAGE_BINDING;
        let output = wirepass::gpu::texture_2d(
            device,
            "bench output",
            size,
            wgpu::TextureFormat::Rgba8Unorm,
            usage,
        );
        let view = output.create_view(&Default::default());
        for (name, floor) in [("deferred", false), ("floor", true)] {
            group.bench_function(BenchmarkId::new(name, triangles), |b| {
                b.iter(|| {
                    let mut encoder = device.create_command_encoder(&Default::default());
                    let target = if floor {
                        OutputTarget::Floor(&view)
                    } else {
                        OutputTarget::Shaded(&view)
                    };
                    pass.encode(device, &mut encoder, &gpu_mesh, target)
                        .expect("encode");
                    ctx.queue.submit([encoder.finish()]);
                    ctx.finish().expect("frame");
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, passes);
criterion_main!(benches);
