//! The WGSL `edge_eval` and `line_intensity` (shaders/common.wgsl, f32 on the GPU) against
//! their Rust twins (`edge_math::edge_eval`, `style::line_intensity`, f64), on a table of
//! cases that includes the hard ones: a vertex behind the eye, a vertex at w = 0, an edge
//! entirely behind the near plane, edge-on and sub-pixel triangles, huge coordinates far from
//! the pixel, and masked edges. Both sides get bit-identical f32 inputs.

// `!(a < b)` is deliberate throughout: NaN must fail the test, not pass it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod common;

use common::gpu;
use glam::{DMat4, DVec2, DVec3, DVec4, Vec4};
use wgpu::util::DeviceExt;
use wirepass::edge_math;
use wirepass::gpu::shaders;
use wirepass::style::line_intensity;

/// WGSL's NO_EDGE is 3e38; anything at or above 1e38 means "no edge" (Rust: inf).
const NO_EDGE_GPU: f32 = 1e38;

const SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if 5u * i >= arrayLength(&cases) {
        return;
    }
    let c0 = cases[5u * i];
    let c1 = cases[5u * i + 1u];
    let c2 = cases[5u * i + 2u];
    let pixel_size = cases[5u * i + 3u];
    let extra = cases[5u * i + 4u];
    let mask = bitcast<u32>(extra.x);
    let e = edge_eval(c0, c1, c2, mask, pixel_size.xy, pixel_size.zw);
    results[2u * i] = vec4<f32>(e.distance, line_intensity(extra.z, extra.y));
    results[2u * i + 1u] = vec4<f32>(e.bary, 0.0);
}
"#;

/// One row of the table.
#[derive(Clone, Debug)]
struct Case {
    name: String,
    clip: [Vec4; 3],
    mask: u32,
    pixel: [f32; 2],
    size: [f32; 2],
    /// Line-profile inputs: distance and width.
    d: f32,
    width: f32,
}

fn perspective(eye: DVec3, target: DVec3, near: f64, size: [f32; 2]) -> DMat4 {
    let aspect = f64::from(size[0]) / f64::from(size[1]);
    glam::dcamera::rh::proj::directx::perspective(1.0, aspect, near, near * 1e4)
        * glam::dcamera::rh::view::look_at_mat4(eye, target, DVec3::Y)
}

fn clip_of(m: DMat4, world: [DVec3; 3]) -> [Vec4; 3] {
    world.map(|p| (m * p.extend(1.0)).as_vec4())
}

/// Clip coordinates of a screen point at depth w (in front of the near plane).
fn at(size: [f32; 2], sx: f64, sy: f64, w: f64) -> Vec4 {
    let (wd, ht) = (f64::from(size[0]), f64::from(size[1]));
    DVec4::new(
        (2.0 * sx / wd - 1.0) * w,
        (1.0 - 2.0 * sy / ht) * w,
        0.5 * w,
        w,
    )
    .as_vec4()
}

fn cases() -> Vec<Case> {
    let size = [640.0_f32, 480.0];
    let profile = [
        (0.0, 1.5),
        (0.3, 1.5),
        (1.0, 1.0),
        (1.99, 2.0),
        (2.5, 4.0),
        (3.0, 4.0),
        (0.2, 0.5),
        (0.0, 0.0),
        (7.25, 12.0),
        (3e38, 1.5),
    ];
    let mut out = Vec::new();
    let mut push = |name: &str, clip: [Vec4; 3], mask: u32, pixel: [f32; 2]| {
        let (d, width) = profile[out.len() % profile.len()];
        out.push(Case {
            name: name.to_string(),
            clip,
            mask,
            pixel,
            size,
            d,
            width,
        });
    };

    let tri = [
        at(size, 10.0, 10.0, 1.0),
        at(size, 110.0, 10.0, 2.0),
        at(size, 10.0, 110.0, 3.0),
    ];
    push("screen triangle, inside", tri, 7, [20.5, 30.5]);
    push("screen triangle, outside", tri, 7, [200.5, 300.5]);
    push("screen triangle, on an edge", tri, 7, [60.5, 10.0]);
    push("masked: edge 1 only", tri, 0b010, [20.5, 30.5]);
    push("masked: edges 0 and 2", tri, 0b101, [20.5, 30.5]);
    push("masked: none", tri, 0, [20.5, 30.5]);

    // A vertex behind the eye (w < 0) and one exactly at w = 0.
    let m = perspective(
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
        0.1,
        size,
    );
    let behind = clip_of(
        m,
        [
            DVec3::new(0.5, 0.2, -2.0),
            DVec3::new(-0.3, 0.1, 1.0),
            DVec3::new(0.0, -1.0, -3.0),
        ],
    );
    assert!(behind[1].w < 0.0);
    push("vertex behind the eye", behind, 7, [330.5, 250.5]);
    push("vertex behind the eye, far pixel", behind, 7, [5.5, 470.5]);
    let mut at_eye = clip_of(
        m,
        [
            DVec3::new(0.5, 0.2, -2.0),
            DVec3::new(-0.3, 0.4, 0.0),
            DVec3::new(0.0, -1.0, -3.0),
        ],
    );
    at_eye[1].w = 0.0;
    push("vertex at w = 0", at_eye, 7, [300.5, 200.5]);
    // Both ends of edge 0 behind the near plane (clip z < 0), the third in front.
    let near_cut = clip_of(
        m,
        [
            DVec3::new(0.5, 0.2, -0.05),
            DVec3::new(-0.3, 0.1, -0.02),
            DVec3::new(0.0, -1.0, -3.0),
        ],
    );
    assert!(near_cut[0].z < 0.0 && near_cut[1].z < 0.0 && near_cut[2].z > 0.0);
    push("edge 0 behind the near plane", near_cut, 7, [320.5, 240.5]);
    push(
        "edge 0 behind the near plane, masked 0b001",
        near_cut,
        1,
        [320.5, 240.5],
    );

    // Edge-on: the eye lies in the triangle's plane (zero screen area).
    let edge_on = clip_of(
        m,
        [
            DVec3::new(-1.0, 0.3, -2.0),
            DVec3::new(1.0, 0.3, -4.0),
            DVec3::new(0.5, 0.3, -1.5),
        ],
    );
    push("edge-on triangle", edge_on, 7, [320.5, 200.5]);
    // Collinear screen points at different depths, pixel off the line.
    let collinear = [
        at(size, 10.0, 10.0, 1.0),
        at(size, 60.0, 60.0, 2.0),
        at(size, 110.0, 110.0, 5.0),
    ];
    push("collinear screen points", collinear, 7, [40.5, 20.5]);

    // Sub-pixel triangles: the pixel near them and far from them.
    let tiny = [
        at(size, 100.2, 100.2, 3.0),
        at(size, 100.21, 100.2, 3.0),
        at(size, 100.2, 100.215, 3.0),
    ];
    push(
        "sub-pixel triangle, pixel 0.3 px away",
        tiny,
        7,
        [100.5, 100.5],
    );
    push(
        "sub-pixel triangle, pixel 300 px away",
        tiny,
        7,
        [400.5, 300.5],
    );
    let tiny_far = clip_of(
        perspective(DVec3::new(0.0, 0.0, 500.0), DVec3::ZERO, 1.0, size),
        [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.001, 0.0, 0.0),
            DVec3::new(0.0, 0.001, 0.0005),
        ],
    );
    push(
        "sub-pixel triangle 500 units away",
        tiny_far,
        7,
        [320.5, 240.5],
    );

    // Huge coordinates: a mesh 1e6 units from the origin, seen from 3000 units away; the
    // pixel is hundreds of pixels from every vertex.
    let base = DVec3::new(1e6, -2e6, 5e5);
    let huge_m = perspective(base + DVec3::new(0.0, 1000.0, 3000.0), base, 1.0, size);
    let huge = clip_of(
        huge_m,
        [
            base + DVec3::new(-50.0, 0.0, 10.0),
            base + DVec3::new(40.0, 30.0, -20.0),
            base + DVec3::new(0.0, -60.0, 0.0),
        ],
    );
    push("huge coordinates, pixel far away", huge, 7, [5.5, 5.5]);
    push("huge coordinates, pixel inside", huge, 7, [320.5, 240.5]);

    // All corners the same point: every edge is degenerate.
    let p = at(size, 50.0, 50.0, 1.0);
    push("degenerate point triangle", [p, p, p], 7, [50.5, 50.5]);

    // Random triangles around a camera, some crossing the eye plane and the near plane.
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let cam = perspective(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, 0.05, size);
    for k in 0..200 {
        let mut v = || DVec3::new(rand() * 6.0 - 3.0, rand() * 6.0 - 3.0, rand() * 6.0 - 3.5);
        let world = [v(), v(), v()];
        let pixel = [
            (rand() * 640.0).floor() as f32 + 0.5,
            (rand() * 480.0).floor() as f32 + 0.5,
        ];
        let mask = (rand() * 8.0) as u32;
        push(&format!("random {k}"), clip_of(cam, world), mask, pixel);
    }
    out
}

/// Runs the table through `edge_eval` and `line_intensity` on the GPU.
fn run_gpu(cases: &[Case]) -> Vec<[Vec4; 2]> {
    let input: Vec<Vec4> = cases
        .iter()
        .flat_map(|c| {
            [
                c.clip[0],
                c.clip[1],
                c.clip[2],
                Vec4::new(c.pixel[0], c.pixel[1], c.size[0], c.size[1]),
                Vec4::new(f32::from_bits(c.mask), c.width, c.d, 0.0),
            ]
        })
        .collect();
    let data = run_shader(SHADER, &input, cases.len() * 2);
    data.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

/// Runs `body` (assembled after common.wgsl; entry point `main`, storage `cases` in and
/// `results` out, both arrays of vec4<f32>) over `input`, returning `outputs` vec4s.
fn run_shader(body: &str, input: &[Vec4], outputs: usize) -> Vec<Vec4> {
    let ctx = gpu();
    let device = &ctx.device;
    let source = shaders::assemble(&[body], &[]);
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("common.wgsl test"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("common.wgsl test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("cases"),
        contents: bytemuck::cast_slice(input),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (outputs * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.as_entire_binding(),
            },
        ],
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        panic!("test shader: {e}");
    }
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((outputs as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
    ctx.queue.submit([encoder.finish()]);
    readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
    ctx.finish().unwrap_or_else(|e| panic!("{e}"));
    bytemuck::pod_collect_to_vec(&readback.get_mapped_range(..).unwrap())
}

/// A small deterministic generator of numbers in [-1, 1) (xorshift): random cases that do
/// not change between runs.
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

const OUTLINE_SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if 6u * i >= arrayLength(&cases) {
        return;
    }
    let a = cases[6u * i].xyz;
    let b = cases[6u * i + 1u].xyz;
    let c = cases[6u * i + 2u].xyz;
    let d = cases[6u * i + 3u].xyz;
    let eye = cases[6u * i + 4u];
    let line = cases[6u * i + 5u];
    let fold = select(0.0, 1.0, is_silhouette(a, b, c, d, eye));
    results[i] = vec4<f32>(fold, depth_fade(line.x, line.yz), line_reach(line.w), 0.0);
}
"#;

/// `is_silhouette`, `depth_fade` and `line_reach` in WGSL against their Rust twins, on
/// random folds seen from random eyes, a fifth of them orthographic (a direction, w = 0),
/// with classification margins well above f32 rounding, and hand-picked ones: a flat pair, a
/// fold seen edge-on, an eye far away.
#[test]
fn wgsl_outline_math_matches_rust() {
    let mut next = uniform(0x2545_f491_4f6c_dd1d);
    let mut rows: Vec<[DVec3; 5]> = vec![
        // Flat: the two triangles on either side of the edge, eye above.
        [
            DVec3::X * -1.0,
            DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z * 3.0,
        ],
        // A closed fold (both on one side), eye above.
        [
            DVec3::X * -1.0,
            DVec3::X,
            DVec3::new(0.0, 1.0, 0.1),
            DVec3::new(0.0, 1.0, -0.1),
            DVec3::Z * 3.0,
        ],
        // An open book seen from far away along its bisector.
        [
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::Y,
            DVec3::new(-1.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::Z * 1e4,
        ],
    ];
    let points = rows.len() + 500;
    for k in 0..600 {
        let mut v = || DVec3::new(next(), next(), next());
        let row = [v(), v(), v(), v(), v() * 10.0];
        let [a, b, c, d, e] = row;
        let eye = if k < 500 {
            e.extend(1.0)
        } else {
            e.normalize().extend(0.0)
        };
        let side = |p: DVec3| edge_math::towards_eye(a, eye).dot((b - a).cross(p - a));
        let scale = edge_math::towards_eye(a, eye).length() * (b - a).length();
        // Keep cases whose sides are clear of rounding.
        if side(c).abs() > 1e-3 * scale * (c - a).length()
            && side(d).abs() > 1e-3 * scale * (d - a).length()
        {
            rows.push(row);
        }
    }
    let fades: Vec<[f64; 4]> = (0..rows.len())
        .map(|i| {
            let w = 10.0 * (next() + 1.0);
            let start = 5.0 * (next() + 1.0);
            let end = if i % 5 == 0 {
                start
            } else {
                start + 4.0 * (next() + 1.0)
            };
            [w, start, end, 8.0 * (next() + 1.0)]
        })
        .collect();
    // Rows from `points` on see the fold along a direction (an orthographic eye).
    let eye_w = |k: usize| if k < points { 1.0 } else { 0.0 };
    let input: Vec<Vec4> = rows
        .iter()
        .zip(&fades)
        .enumerate()
        .flat_map(|(k, (r, f))| {
            let mut v: Vec<Vec4> = r.iter().map(|p| p.as_vec3().extend(0.0)).collect();
            v[4].w = eye_w(k);
            v.push(glam::DVec4::from_array(*f).as_vec4());
            v
        })
        .collect();
    let got = run_shader(OUTLINE_SHADER, &input, rows.len());
    let mut folded = 0;
    for (k, ((row, fade), g)) in rows.iter().zip(&fades).zip(&got).enumerate() {
        // The Rust side gets the same f32-rounded inputs.
        let [a, b, c, d, eye] = row.map(|p| p.as_vec3().as_dvec3());
        let eye = if k < points {
            eye.extend(1.0)
        } else {
            eye.as_vec3().extend(0.0).as_dvec4()
        };
        let want = edge_math::is_silhouette(a, b, c, d, eye);
        folded += usize::from(want);
        assert_eq!(g.x == 1.0, want, "case {k}: is_silhouette");
        let f = fade.map(|x| f64::from(x as f32));
        let want_fade = wirepass::style::depth_fade(f[0], [f[1], f[2]]);
        assert!((want_fade - f64::from(g.y)).abs() < 1e-6, "case {k}: fade");
        let want_reach = wirepass::style::line_reach(f[3]);
        assert!(
            (want_reach - f64::from(g.z)).abs() < 1e-6,
            "case {k}: reach"
        );
    }
    assert!(!edge_math::is_silhouette(
        rows[0][0],
        rows[0][1],
        rows[0][2],
        rows[0][3],
        rows[0][4].extend(1.0)
    ));
    assert!(edge_math::is_silhouette(
        rows[1][0],
        rows[1][1],
        rows[1][2],
        rows[1][3],
        rows[1][4].extend(1.0)
    ));
    assert!(
        folded > 50 && folded + 50 < rows.len(),
        "{folded} of {}",
        rows.len()
    );
}

const CLUSTER_SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if 3u * i >= arrayLength(&cases) {
        return;
    }
    let c = Cluster(cases[3u * i].xyz, cases[3u * i].w, cases[3u * i + 1u].xyz, cases[3u * i + 1u].w);
    results[i] = vec4<f32>(select(0.0, 1.0, cluster_may_fold(c, cases[3u * i + 2u])));
}
"#;

/// `cluster_may_fold` in WGSL against `clusters::may_fold`, on random clusters and eyes, a
/// fifth of them orthographic (the angles clear of the 90° threshold by more than f32
/// rounding), and hand-picked ones: the eye inside the sphere, a cluster that may fold from
/// anywhere, a patch seen face-on and edge-on.
#[test]
fn wgsl_cluster_test_matches_rust() {
    use wirepass::mesh::clusters::{may_fold, ClusterBounds, ALWAYS};
    let mut next = uniform(0x51_7cc1_b727_220a);
    let patch = |spread| ClusterBounds {
        center: DVec3::ZERO,
        radius: 0.1,
        axis: DVec3::Z,
        spread,
    };
    let point = |v: DVec3| v.extend(1.0);
    let mut rows: Vec<(ClusterBounds, glam::DVec4)> = vec![
        (patch(0.1), point(DVec3::new(0.0, 0.05, 0.0))),
        (patch(ALWAYS), point(DVec3::Z * 5.0)),
        (patch(0.1), point(DVec3::Z * 5.0)),
        (patch(0.1), point(DVec3::X * 5.0)),
        (patch(0.1), DVec3::Z.extend(0.0)),
        (patch(0.1), DVec3::X.extend(0.0)),
    ];
    let quarter = std::f64::consts::FRAC_PI_2;
    while rows.len() < 500 {
        let r: [f64; 11] = std::array::from_fn(|_| next());
        let bounds = ClusterBounds {
            center: DVec3::new(r[0], r[1], r[2]),
            radius: 0.2 * (r[3] + 1.0),
            axis: DVec3::new(r[4], r[5], r[6]).normalize(),
            spread: 0.5 * (r[7] + 1.0),
        };
        let ortho = rows.len().is_multiple_of(5);
        let e = DVec3::new(r[8], r[9], r[10]) * 4.0;
        let eye = if ortho {
            e.normalize().as_vec3().as_dvec3().extend(0.0)
        } else {
            e.extend(1.0)
        };
        let (d, beta) = if ortho {
            (-eye.truncate(), 0.0)
        } else {
            let d = bounds.center - e;
            (d, (bounds.radius / d.length()).asin())
        };
        let gamma = d.angle_between(bounds.axis);
        let reach = beta + bounds.spread;
        if (gamma + reach - quarter).abs() > 1e-4 && (gamma - reach - quarter).abs() > 1e-4 {
            rows.push((bounds, eye));
        }
    }
    let input: Vec<Vec4> = rows
        .iter()
        .flat_map(|(b, eye)| {
            [
                b.center.as_vec3().extend(b.radius as f32),
                b.axis.as_vec3().extend(b.spread as f32),
                eye.as_vec4(),
            ]
        })
        .collect();
    let got = run_shader(CLUSTER_SHADER, &input, rows.len());
    let mut folds = 0;
    for (k, ((b, eye), g)) in rows.iter().zip(&got).enumerate() {
        let want = may_fold(b, *eye);
        folds += usize::from(want);
        assert_eq!(g.x == 1.0, want, "case {k}: {b:?} from {eye}");
    }
    assert_eq!(
        rows[..6]
            .iter()
            .map(|(b, e)| may_fold(b, *e))
            .collect::<Vec<_>>(),
        [true, true, false, true, false, true]
    );
    assert!(
        folds > 50 && folds + 50 < rows.len(),
        "{folds} of {}",
        rows.len()
    );
}

const EPS32: f64 = f32::EPSILON as f64;

#[test]
fn wgsl_edge_eval_and_line_intensity_match_rust() {
    let table = cases();
    let gpu_results = run_gpu(&table);
    let mut failures = Vec::new();
    // Largest |diff| / tolerance seen, printed to show the margin.
    let mut worst: f64 = 0.0;
    for (case, got) in table.iter().zip(&gpu_results) {
        let clip = case.clip.map(|c| c.as_dvec4());
        let pixel = DVec2::new(f64::from(case.pixel[0]), f64::from(case.pixel[1]));
        let size = DVec2::new(f64::from(case.size[0]), f64::from(case.size[1]));
        let want = edge_math::edge_eval(clip, case.mask as u8, pixel, size);
        let gpu_distance = got[0].truncate().as_dvec3().to_array();
        let gpu_bary = got[1].truncate().as_dvec3().to_array();

        // The scale of the case, from a first-order rounding analysis of the f32 evaluation.
        // Each homogeneous pixel point P = (x·W/2 + w·(W/2 − px), w·(H/2 − py) − y·H/2, w) is
        // a sum of terms whose magnitudes M = (|x|·W/2 + |w|·|W/2 − px|, |w|·|H/2 − py| +
        // |y|·H/2, |w|) bound its rounding error by about ε·M, ε = 2^-23. A component of a
        // line L = Pa × Pb, e.g. L.z = Pa.x·Pb.y − Pa.y·Pb.x, is then off by about
        // ε·B.z with B.z = Ma.x·|Pb.y| + |Pa.x|·Mb.y + Ma.y·|Pb.x| + |Pa.y|·Mb.x. So:
        //   distance d = |L.z| / |L.xy|:   tolerance 8ε·(B.z + d·|B.xy|) / |L.xy| + 1e-6 px;
        //   barycentric b_i = e_i / Σe:    tolerance 8ε·(B(e_i) + |b_i|·ΣB(e)) / |Σe| + 1e-7.
        // The factor 8 covers the few roundings per term and fused or reordered arithmetic.
        // Ill-conditioned cases (sub-pixel triangles seen from far pixels, edge-on triangles)
        // get a correspondingly large tolerance: there f32 cannot do better.
        let half = 0.5 * size;
        let p = clip.map(|c| edge_math::pixel_relative(c, pixel, size));
        let m = clip.map(|c| {
            DVec3::new(
                c.x.abs() * half.x + c.w.abs() * (half.x - pixel.x).abs(),
                c.w.abs() * (half.y - pixel.y).abs() + c.y.abs() * half.y,
                c.w.abs(),
            )
        });
        let bound = |a: usize, b: usize| {
            let (pa, pb, ma, mb) = (p[a].abs(), p[b].abs(), m[a], m[b]);
            DVec3::new(
                ma.y * pb.z + pa.y * mb.z + ma.z * pb.y + pa.z * mb.y,
                ma.z * pb.x + pa.z * mb.x + ma.x * pb.z + pa.x * mb.z,
                ma.x * pb.y + pa.x * mb.y + ma.y * pb.x + pa.y * mb.x,
            )
        };
        let lines = [p[0].cross(p[1]), p[1].cross(p[2]), p[2].cross(p[0])];
        let bounds = [bound(0, 1), bound(1, 2), bound(2, 0)];
        for i in 0..3 {
            let (w, g) = (want.distance[i], gpu_distance[i]);
            if g.is_nan() {
                failures.push(format!("{}: GPU distance {i} is NaN", case.name));
                continue;
            }
            let g_inf = g >= f64::from(NO_EDGE_GPU);
            if w.is_infinite() || g_inf {
                if w.is_infinite() != g_inf {
                    failures.push(format!(
                        "{}: edge {i}: Rust {w}, GPU {g} (one side says no edge)",
                        case.name
                    ));
                }
                continue;
            }
            let b = bounds[i];
            let tol = 8.0 * EPS32 * (b.z + w * b.truncate().length())
                / lines[i].truncate().length()
                + 1e-6;
            worst = worst.max((w - g).abs() / tol);
            if !((w - g).abs() <= tol) {
                failures.push(format!(
                    "{}: edge {i}: Rust {w}, GPU {g}, |diff| {:.3e} > tol {tol:.3e}",
                    case.name,
                    (w - g).abs()
                ));
            }
        }
        // Corner i's weight is the line of the opposite edge: e = (L1.z, L2.z, L0.z).
        let e_bound = [bounds[1].z, bounds[2].z, bounds[0].z];
        let sum: f64 = lines.iter().map(|l| l.z).sum();
        let sum_bound: f64 = e_bound.iter().sum();
        for i in 0..3 {
            let (w, g) = (want.bary[i], gpu_bary[i]);
            let tol = 8.0 * EPS32 * (e_bound[i] + w.abs() * sum_bound) / sum.abs() + 1e-7;
            if !g.is_finite() {
                failures.push(format!("{}: GPU barycentric {i} is {g}", case.name));
                continue;
            }
            worst = worst.max((w - g).abs() / tol);
            if !((w - g).abs() <= tol) {
                failures.push(format!(
                    "{}: barycentric {i}: Rust {w}, GPU {g}, tol {tol:.3e}",
                    case.name
                ));
            }
        }
        // The line profile: intensities are 0..1 and WGSL's exp2 is good to a few ulp, so an
        // absolute 1e-5 covers it (the inputs are bit-identical).
        let want_i = line_intensity(f64::from(case.d), f64::from(case.width));
        let got_i = f64::from(got[0].w);
        if !((want_i - got_i).abs() <= 1e-5) {
            failures.push(format!(
                "{}: line_intensity({}, {}): Rust {want_i}, GPU {got_i}",
                case.name, case.d, case.width
            ));
        }
    }
    println!("largest |GPU − Rust| / tolerance: {worst:.3}");
    assert!(
        failures.is_empty(),
        "{} of {} cases differ:\n{}",
        failures.len(),
        table.len(),
        failures.join("\n")
    );
}

#[test]
fn hard_cases_are_what_they_claim() {
    // Guards the table itself: the near-plane case really has no edge 0 on both sides, and
    // the masked case has only edge 1.
    let table = cases();
    let find = |name: &str| table.iter().find(|c| c.name == name).unwrap();
    let eval = |c: &Case| {
        edge_math::edge_eval(
            c.clip.map(|v| v.as_dvec4()),
            c.mask as u8,
            DVec2::new(f64::from(c.pixel[0]), f64::from(c.pixel[1])),
            DVec2::new(f64::from(c.size[0]), f64::from(c.size[1])),
        )
    };
    let e = eval(find("edge 0 behind the near plane"));
    assert!(e.distance[0].is_infinite() && e.distance[1].is_finite());
    let e = eval(find("masked: edge 1 only"));
    assert!(e.distance[0].is_infinite() && e.distance[2].is_infinite());
    let e = eval(find("degenerate point triangle"));
    assert!(e.distance.iter().all(|d| d.is_infinite()));
    let w = find("vertex at w = 0").clip[1].w;
    assert_eq!(w, 0.0);
}

const SEGMENT_SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if 3u * i >= arrayLength(&cases) {
        return;
    }
    let p = cases[3u * i + 2u];
    results[i] = vec4<f32>(segment_distance(cases[3u * i], cases[3u * i + 1u], p.xy, p.zw), 0.0, 0.0, 0.0);
}
"#;

/// `segment_distance` in WGSL against `edge_math::segment_distance`: random segments seen
/// by a perspective camera, a quarter of them reaching behind the eye (cut at the near
/// plane), and hand-picked ones: both ends behind, a point, a pixel on the segment, a pixel
/// beyond an end.
#[test]
fn wgsl_segment_distance_matches_rust() {
    let size = [320f32, 240.0];
    let m = perspective(DVec3::new(0.3, 0.2, 4.0), DVec3::ZERO, 0.1, size);
    let mut next = uniform(0x9e37_79b9_7f4a_7c15);
    let mut segments: Vec<([DVec3; 2], [f32; 2])> = Vec::new();
    for k in 0..600 {
        let a = DVec3::new(next(), next(), next()) * 3.0;
        let mut b = DVec3::new(next(), next(), next()) * 3.0;
        if k % 4 == 0 {
            // The eye is at z = 4, looking down -z.
            b.z = 4.5 + 3.0 * (next() + 1.0);
        }
        let pixel = [(next() + 1.0) as f32 * 160.0, (next() + 1.0) as f32 * 120.0];
        segments.push(([a, b], pixel));
    }
    let behind = DVec3::new(0.0, 0.0, 6.0);
    segments.push(([behind, behind + DVec3::X], [100.5, 100.5]));
    segments.push(([DVec3::ZERO, DVec3::ZERO], [160.5, 120.5]));
    let input: Vec<Vec4> = segments
        .iter()
        .flat_map(|([a, b], p)| {
            let clip = |q: DVec3| (m * q.extend(1.0)).as_vec4();
            [clip(*a), clip(*b), Vec4::new(p[0], p[1], size[0], size[1])]
        })
        .collect();
    let got = run_shader(SEGMENT_SHADER, &input, segments.len());
    let mut worst: f64 = 0.0;
    for (k, g) in got.iter().enumerate() {
        let [ca, cb, p] = [0, 1, 2].map(|j| input[3 * k + j].as_dvec4());
        let want = edge_math::segment_distance(ca, cb, DVec2::new(p.x, p.y), DVec2::new(p.z, p.w));
        let g = f64::from(g.x);
        if !want.is_finite() {
            assert!(g >= f64::from(NO_EDGE_GPU), "case {k}: {g} for no segment");
            continue;
        }
        let error = (g - want).abs();
        worst = worst.max(error / (1.0 + want));
        assert!(error <= 2e-3 + 1e-5 * want, "case {k}: {g} against {want}");
    }
    println!("worst relative error {worst:.2e}");
    assert!(!edge_math::segment_distance(
        input[3 * 600].as_dvec4(),
        input[3 * 600 + 1].as_dvec4(),
        DVec2::ZERO,
        DVec2::new(320.0, 240.0)
    )
    .is_finite());
}

const DASH_SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if 2u * i >= arrayLength(&cases) {
        return;
    }
    let a = cases[2u * i];
    let b = cases[2u * i + 1u];
    results[i] = vec4<f32>(dash_nearest(a.x, a.y, a.z, b.x, b.y), 0.0, 0.0, 0.0);
}
"#;

/// `dash_nearest` in WGSL against `style::dash_nearest`: random points and intervals along
/// dashed, dotted and solid lines, and an empty interval.
#[test]
fn wgsl_dash_nearest_matches_rust() {
    let mut next = uniform(0x2545_f491_4f6c_dd1d);
    let mut cases: Vec<[f32; 5]> = Vec::new();
    for k in 0..1200 {
        let lo = (next() * 200.0) as f32;
        let hi = lo + ((next() + 1.0) * 12.0) as f32;
        let s = lo + ((next() * 1.5) * f64::from(hi - lo)) as f32;
        let (dash, period) = match k % 3 {
            0 => (((next() + 1.0) * 4.0) as f32, 0.0),
            1 => (0.0, ((next() + 1.0) * 3.0 + 1.0) as f32),
            _ => (0.0, 0.0),
        };
        let period = if k % 3 == 0 {
            dash + ((next() + 1.0) * 3.0) as f32
        } else {
            period
        };
        cases.push([s, lo, hi, dash, period]);
    }
    cases.push([1.0, 5.0, 4.0, 1.0, 3.0]);
    let input: Vec<Vec4> = cases
        .iter()
        .flat_map(|c| {
            [
                Vec4::new(c[0], c[1], c[2], 0.0),
                Vec4::new(c[3], c[4], 0.0, 0.0),
            ]
        })
        .collect();
    let got = run_shader(DASH_SHADER, &input, cases.len());
    let (mut none, mut worst) = (0, 0.0_f64);
    for (k, (g, c)) in got.iter().zip(&cases).enumerate() {
        let [s, lo, hi, dash, period] = c.map(f64::from);
        match wirepass::style::dash_nearest(s, lo, hi, dash, period) {
            None => {
                none += 1;
                assert!(g.x >= NO_EDGE_GPU, "case {k} {c:?}: {} for none", g.x);
            }
            // The point's distance from s, which is what a pixel's line distance takes.
            Some(want) => {
                let error = ((f64::from(g.x) - s).abs() - (want - s).abs()).abs();
                worst = worst.max(error);
                assert!(error <= 1e-4, "case {k} {c:?}: {} against {want}", g.x);
            }
        }
    }
    println!("{none} cases without a dash point; worst error {worst:.2e} px");
    assert!(none > 10);
}
