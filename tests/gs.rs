//! `gs`, the published geometry-shader method on OpenGL (through EGL: llvmpipe here), against
//! `forward`, its vertex-pulling emulation on wgpu: both draw the same triangles with the
//! same altitudes, profile and shading, so on ordinary cameras their images are the same.
//!
//! What may differ, and why: the two run on different drivers of the same rasterizer
//! (llvmpipe's GL and lavapipe's Vulkan, or wgpu's GL), with shaders compiled from GLSL and
//! from WGSL, so an f32 operation may be fused or ordered differently; a pixel centre lying
//! within rounding of a shared edge can then go to the other triangle (an id differs), and a
//! colour can round to the neighbouring byte. Measured (lavapipe and llvmpipe's GL against
//! llvmpipe's GL): no id differs; the distances where both show the same triangle differ by
//! about 1e-4 px at most (f32 rounding of the same altitudes), which moves a line pixel's colour by
//! one byte on 0.02–0.08 % of the pixels; FLIP mean ≤ 8e-5. Bounds: ids on 1 pixel in 10,000,
//! colours by 2 bytes on 1 % of pixels, distances 1e-3 px, FLIP mean 0.001 (the issue's).

use std::path::PathBuf;
use std::sync::OnceLock;
use wirepass::gpu::GpuContext;
use wirepass::tools::compare::flip_map;
use wirepass::tools::offline::{self, Method};
use wirepass::world::{Object, Rendering, Shot, World, BACKGROUND};
use wirepass::{Camera, EdgeSelection, InstanceStyle, Mesh, Style};

/// One device per test binary; no adapter is a failure, never a skip.
fn gpu() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| GpuContext::new().unwrap_or_else(|e| panic!("no GPU adapter: {e}")))
}

fn load(name: &str) -> Mesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/meshes")
        .join(name);
    wirepass::mesh::load_obj(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Draws `world` with `method`; an OpenGL context is required (CI has llvmpipe's).
fn draw(world: &World, camera: Camera, size: (u32, u32), method: Method) -> Rendering {
    let style = Style::default();
    let shot = Shot {
        world,
        view: camera.to_view(f64::from(size.0) / f64::from(size.1)),
        style: &style,
        size,
    };
    offline::draw(gpu(), &shot, method).unwrap_or_else(|e| panic!("{}: {e}", method.name()))
}

/// How two frames differ.
#[derive(Debug)]
struct Difference {
    /// Pixels whose ids differ, and the first few of them.
    ids: usize,
    where_ids: Vec<(u32, u32)>,
    /// Pixels with a colour byte apart, and the largest byte difference.
    colors: usize,
    max_byte: u8,
    /// Largest distance difference where both show the same triangle (px).
    distance: f32,
    flip_mean: f64,
    /// Foreground pixels.
    foreground: usize,
}

fn difference(a: &Rendering, b: &Rendering) -> Difference {
    let width = a.size.0;
    let mut d = Difference {
        ids: 0,
        where_ids: Vec::new(),
        colors: 0,
        max_byte: 0,
        distance: 0.0,
        flip_mean: 0.0,
        foreground: a.ids.iter().filter(|&&i| i != BACKGROUND).count(),
    };
    for i in 0..a.ids.len() {
        if a.ids[i] != b.ids[i] {
            d.ids += 1;
            if d.where_ids.len() < 8 {
                d.where_ids.push((i as u32 % width, i as u32 / width));
            }
        } else if a.edge_distance[i].is_finite() || b.edge_distance[i].is_finite() {
            d.distance = d
                .distance
                .max((a.edge_distance[i] - b.edge_distance[i]).abs());
        }
        let bytes = (0..4).map(|c| a.rgba[4 * i + c].abs_diff(b.rgba[4 * i + c]));
        let most = bytes.max().unwrap_or(0);
        d.colors += usize::from(most > 0);
        d.max_byte = d.max_byte.max(most);
    }
    let flip = flip_map(a, b).unwrap();
    d.flip_mean = flip.iter().map(|&v| f64::from(v)).sum::<f64>() / flip.len() as f64;
    d
}

fn assert_equal(what: &str, forward: &Rendering, gs: &Rendering) {
    let d = difference(forward, gs);
    eprintln!("{what}: {d:?}");
    let pixels = forward.ids.len();
    assert!(
        d.foreground > pixels / 10,
        "{what}: too little drawn: {d:?}"
    );
    assert!(d.flip_mean <= 0.001, "{what}: FLIP mean {}", d.flip_mean);
    assert!(
        d.ids * 10_000 <= pixels,
        "{what}: ids differ on {} pixels, first at {:?}",
        d.ids,
        d.where_ids
    );
    assert!(d.colors * 100 <= pixels && d.max_byte <= 2, "{what}: {d:?}");
    assert!(
        d.distance <= 1e-3,
        "{what}: distances differ by {}",
        d.distance
    );
}

/// The test: the shared meshes, an ordinary camera, pixel for pixel.
#[test]
fn gs_draws_what_forward_draws_on_the_shared_meshes() {
    let size = (320, 240);
    for name in [
        "stanford-bunny.obj",
        "fandisk.obj",
        "spot.obj",
        "suzanne.obj",
        "teapot.obj",
    ] {
        let mesh = load(name);
        let (lo, hi) = mesh.bounds_f64();
        let camera = Camera::framing(lo, hi, 320.0 / 240.0);
        // Polygon edges: the quads' diagonals are masked, as forward masks them.
        let world = World::single(mesh, EdgeSelection::Polygon);
        let forward = draw(&world, camera, size, Method::Forward);
        let gs = draw(&world, camera, size, Method::Gs);
        assert_equal(name, &forward, &gs);
    }
}

/// More instances than one draw's uniform block holds (256), mirrored ones among them, of
/// two meshes, with per-instance line and fill colours and widths and one without edges: the
/// draws are split, and every instance keeps its own record.
#[test]
fn gs_draws_many_instances_as_forward_does() {
    let sphere = wirepass::mesh::sphere(200).unwrap();
    let torus = wirepass::mesh::torus(300).unwrap();
    let mut world = World::single(sphere, EdgeSelection::All);
    world.meshes.push(wirepass::world::WorldMesh {
        mesh: std::sync::Arc::new(torus),
        edges: EdgeSelection::Polygon,
        name: "torus".into(),
    });
    world.objects.clear();
    for k in 0..300u32 {
        let (x, y) = (f64::from(k % 20), f64::from(k / 20));
        let mirror = if k % 3 == 0 { -1.0 } else { 1.0 };
        let transform = glam::DMat4::from_translation(glam::DVec3::new(x * 2.5, y * 2.5, 0.0))
            * glam::DMat4::from_scale(glam::DVec3::new(mirror, 1.0, 1.0));
        world.objects.push(Object {
            mesh: (k % 2) as usize,
            transform,
            style: InstanceStyle {
                wire_color: (k % 5 == 0).then(|| wirepass::Color::from_hex("#c81e1e").unwrap()),
                fill_color: (k % 4 == 1).then(|| wirepass::Color::from_hex("#d0a040").unwrap()),
                line_width: (k % 7 == 0).then_some(3.0),
                edges: (k == 42).then_some(false),
                outlines: None,
                ..InstanceStyle::default()
            },
        });
    }
    let (lo, hi) = world.bounds();
    let size = (480, 360);
    let camera = Camera::framing(lo, hi, 480.0 / 360.0);
    let forward = draw(&world, camera, size, Method::Forward);
    let gs = draw(&world, camera, size, Method::Gs);
    assert_equal("300 instances", &forward, &gs);
}

/// As on OpenGL 3.3: without `glClipControl` the vertex stage maps depth to -w..w and turns
/// the image upside down itself, and without storage buffers the geometry stage reads the
/// drawn edges from a buffer texture. The image is the same (the rasterizer's fill rule now
/// sees the triangles mirrored, which may move a pixel centre lying exactly on an edge to its
/// neighbour).
#[test]
fn gs_as_on_opengl_3_3_draws_the_same() {
    let mesh = load("suzanne.obj");
    let (lo, hi) = mesh.bounds_f64();
    let size = (320, 240);
    let camera = Camera::framing(lo, hi, 320.0 / 240.0);
    let world = World::single(mesh, EdgeSelection::Polygon);
    let forward = draw(&world, camera, size, Method::Forward);
    let style = Style::default();
    let shot = Shot {
        world: &world,
        view: camera.to_view(320.0 / 240.0),
        style: &style,
        size,
    };
    let pass = wirepass::tools::gs::GsPass::as_on_opengl_3_3().unwrap();
    let gs = offline::draw_gs_with(gpu(), &shot, pass).unwrap();
    assert_equal("suzanne as on OpenGL 3.3", &forward, &gs);
}
