//! The frames the browser tests draw, defined once for both sides: the browser (WebGPU) and
//! the machine's native adapter (lavapipe in CI), which draws the references the browser's
//! frames are held against. Each is drawn by the deferred pass and read back with its id and
//! distance maps through futures only, so the same code runs in a page and natively.

#![allow(dead_code)]

#[path = "../../../examples/host_scene/host.rs"]
mod host;

use host::{HostFormats, HostRenderer, HostScene, HostTargets};
use std::path::Path;
use std::sync::Arc;
use wirepass::camera::{Camera, View};
use wirepass::glam::{DMat4, DQuat, DVec3};
use wirepass::gpu::{texture_2d, Canvas, Composite, HostDepth, OutputTarget, RenderTarget};
use wirepass::truth::{draw_raycast, draw_raycast_over, HostOccluders};
use wirepass::world::offscreen::{draw_deferred_on_async, read_deferred, Uploaded};
use wirepass::world::{default_world, Object, Rendering, Shot, World, WorldMesh};
use wirepass::{
    wgpu, DeferredPass, DepthRange, EdgeSelection, InstanceStyle, Mesh, PassOptions, PreparedFrame,
};
use wirepass::{Result, Style};

/// Every frame is this size: small enough for the ray cast to run in a page in seconds.
pub const SIZE: (u32, u32) = (320, 240);
const ASPECT: f64 = 320.0 / 240.0;

/// Where a case's frame goes.
pub enum Output {
    /// A storage texture (`OutputTarget::Shaded`).
    Storage,
    /// The host's render pass on a target of this format (`DeferredPass::render`).
    RenderPass(wgpu::TextureFormat),
}

/// One frame of the browser tests.
pub struct Case {
    /// Its name, and the name of its reference image.
    pub name: &'static str,
    pub world: World,
    pub view: View,
    pub style: Style,
    pub output: Output,
    /// The host scene whose depth hides lines, and everything it draws.
    pub host: Option<(HostScene, World)>,
}

impl Case {
    pub fn shot(&self) -> Shot<'_> {
        Shot {
            world: &self.world,
            view: self.view,
            style: &self.style,
            size: SIZE,
        }
    }

    /// The reference image the native adapter drew, in `web/tests/reference/`.
    pub fn reference(&self) -> String {
        format!("{}.png", self.name)
    }
}

fn mesh(name: &str, bytes: &[u8]) -> Mesh {
    wirepass::mesh::load_bytes(Path::new(name), bytes).unwrap_or_else(|e| panic!("{e}"))
}

fn suzanne() -> Mesh {
    mesh(
        "suzanne.obj",
        include_bytes!("../../../tests/data/meshes/suzanne.obj"),
    )
}

fn spot() -> Mesh {
    mesh(
        "spot.obj",
        include_bytes!("../../../tests/data/meshes/spot.obj"),
    )
}

fn framed(world: &World) -> View {
    let (lo, hi) = world.bounds();
    Camera::framing(lo, hi, ASPECT).to_view(ASPECT)
}

fn world(meshes: Vec<Mesh>, objects: Vec<(usize, DMat4)>) -> World {
    World {
        sections: Vec::new(),
        meshes: meshes
            .into_iter()
            .map(|mesh| WorldMesh {
                mesh: Arc::new(mesh),
                edges: EdgeSelection::Polygon,
                name: "case".into(),
            })
            .collect(),
        objects: objects
            .into_iter()
            .map(|(mesh, transform)| Object {
                mesh,
                transform,
                style: InstanceStyle::default(),
            })
            .collect(),
    }
}

/// The built-in scene; Suzanne's quads; a torus beside its mirror image, orthographic; the
/// cow and the monkey behind the host's pillar and in its ground (host depth); the built-in
/// scene through the render-pass entry into a `Bgra8Unorm` target, a canvas's format.
pub fn all() -> Vec<Case> {
    let style = Style::default();
    let builtin = default_world(EdgeSelection::Polygon);
    let quads = World::single(suzanne(), EdgeSelection::Polygon);

    let torus = wirepass::mesh::torus(1500).unwrap_or_else(|e| panic!("{e}"));
    let tilt = DQuat::from_rotation_x(0.9) * DQuat::from_rotation_y(0.4);
    let left = DMat4::from_rotation_translation(tilt, DVec3::new(-1.3, 0.0, 0.0));
    // Mirrored in x: its triangles wind the other way on screen.
    let right = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) * left;
    let mirrored = world(vec![torus], vec![(0, left), (0, right)]);
    let (lo, hi) = mirrored.bounds();
    let centre = (lo + hi) * 0.5;
    let eye = centre + DVec3::new(0.3, 0.5, 4.0);
    let ortho = View::orthographic(
        (eye, centre, DVec3::Y),
        1.15 * (hi - lo).y.max((hi - lo).x / ASPECT),
        ASPECT,
        (0.5, 10.0),
    );

    let mut scene = HostScene::new(spot(), suzanne());
    // The cow's hooves stand exactly on the ground, where whether the host hides an
    // outline point is a tie that each rasterizer's depth rounding decides its own way
    // (lavapipe and SwiftShader disagree there): lifted a little, every point is decided
    // by the geometry. The monkey stays sunk into the ground.
    scene.cow_at = DMat4::from_translation(DVec3::new(0.0, 0.03, 0.0)) * scene.cow_at;
    let wire = world(
        vec![scene.cow.clone(), scene.monkey.clone()],
        vec![(0, scene.cow_at), (1, scene.monkey_at)],
    );
    let occluders = world(
        vec![
            scene.ground.clone(),
            scene.pillar.clone(),
            scene.cow.clone(),
            scene.monkey.clone(),
        ],
        vec![
            (0, DMat4::IDENTITY),
            (1, scene.pillar_at),
            (2, scene.cow_at),
            (3, scene.monkey_at),
        ],
    );
    let host_view = scene.view(ASPECT, DepthRange::Standard);
    let wide = Style {
        line_width: 2.0,
        ..Style::default()
    };

    vec![
        Case {
            name: "default-scene",
            view: framed(&builtin),
            world: builtin.clone(),
            style: style.clone(),
            output: Output::Storage,
            host: None,
        },
        Case {
            name: "suzanne-quads",
            view: framed(&quads),
            world: quads,
            style: style.clone(),
            output: Output::Storage,
            host: None,
        },
        Case {
            name: "mirrored-orthographic",
            world: mirrored,
            view: ortho,
            style: style.clone(),
            output: Output::Storage,
            host: None,
        },
        Case {
            name: "host-depth",
            world: wire,
            view: host_view,
            style: wide,
            output: Output::Storage,
            host: Some((scene, occluders)),
        },
        Case {
            name: "render-pass-bgra8unorm",
            view: framed(&builtin),
            world: builtin,
            style,
            output: Output::RenderPass(wgpu::TextureFormat::Bgra8Unorm),
            host: None,
        },
    ]
}

/// Draws `case` on `device` and reads it back as RGBA8 with its maps.
pub async fn draw(device: &wgpu::Device, queue: &wgpu::Queue, case: &Case) -> Result<Rendering> {
    let shot = case.shot();
    let up = Uploaded::new(device, queue, &case.world)?;
    match (&case.output, &case.host) {
        (Output::Storage, None) => {
            let mut pass = DeferredPass::new(device, PassOptions::default())?.with_diagnostics();
            draw_deferred_on_async(device, queue, &shot, &up, &mut pass, Canvas::new(SIZE)).await
        }
        (Output::Storage, Some((scene, _))) => {
            let formats = HostFormats {
                color: wgpu::TextureFormat::Rgba8UnormSrgb,
                depth: wgpu::TextureFormat::Depth32Float,
                samples: 1,
            };
            let renderer = HostRenderer::new(device, formats, case.view.depth);
            let targets = HostTargets::new(device, SIZE, formats);
            let meshes = scene.upload(device);
            let mut encoder = device.create_command_encoder(&Default::default());
            renderer.draw(
                device,
                &mut encoder,
                &targets,
                HostScene::SKY,
                case.view.view_projection(),
                &scene.draws(&meshes),
            );
            queue.submit([encoder.finish()]);
            let canvas = Canvas::new(SIZE).with_host_depth(HostDepth {
                texture: &targets.depth,
                matrices: case.view,
            });
            let mut pass = DeferredPass::new(device, PassOptions::default())?.with_diagnostics();
            draw_deferred_on_async(device, queue, &shot, &up, &mut pass, canvas).await
        }
        (Output::RenderPass(format), _) => {
            let mut pass = DeferredPass::new(device, canvas_pass(*format))?.with_diagnostics();
            let scene = up.scene(&case.world, case.view);
            let frame = pass.prepare(device, &up.store, &scene, &case.style, SIZE)?;
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
            let target = texture_2d(device, "canvas-format target", SIZE, *format, usage);
            let view = target.create_view(&Default::default());
            let [r, g, b, a] = case.style.background.0.map(f64::from);
            let clear = wgpu::Color { r, g, b, a };
            let encoder = encode_into(device, &mut pass, &up, &frame, &view, clear)?;
            queue.submit([encoder.finish()]);
            let mut frame =
                read_deferred(device, queue, &shot, &up, &mut pass, &frame, &target).await?;
            if format.remove_srgb_suffix() == wgpu::TextureFormat::Bgra8Unorm {
                frame.rgba.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
            }
            Ok(frame)
        }
    }
}

/// The ground truth of `case`: its ray cast in f64, over the host's geometry where it has one.
pub fn truth(case: &Case) -> Result<Rendering> {
    match &case.host {
        None => draw_raycast(&case.shot()),
        Some((_, occluders)) => {
            let host = HostOccluders::single(occluders)
                .with_format(wgpu::TextureFormat::Depth32Float)
                .with_view(case.view);
            draw_raycast_over(&case.shot(), Some(&host))
        }
    }
}

/// Id agreement and distance error against the truth, within the project's bounds:
/// id agreement ≥ 0.999, distance error p99 ≤ 0.01 px and max ≤ 0.1 px.
pub fn check_accuracy(name: &str, truth: &Rendering, frame: &Rendering) -> String {
    use wirepass::truth::accuracy::{distance_error, id_agreement};
    let (ids, _) = id_agreement(truth, frame).unwrap_or_else(|e| panic!("{name}: {e}"));
    let d = distance_error(truth, frame).unwrap_or_else(|e| panic!("{name}: {e}"));
    let line = format!(
        "{name}: id agreement {ids:.5}, distance error p99 {:.2e} px, max {:.2e} px over {} px",
        d.p99.unwrap_or(f64::NAN),
        d.max.unwrap_or(f64::NAN),
        d.pixels
    );
    assert!(ids >= 0.999, "{line}");
    assert!(d.pixels > 1000, "{line}: too few pixels measured");
    assert!(d.p99.is_some_and(|v| v <= 0.01), "{line}");
    assert!(
        d.max.is_some_and(|v| v <= 0.1),
        "{line}{}",
        worst(truth, frame)
    );
    line
}

/// The pixels whose distance error is over 0.1 px, for a failure's message.
fn worst(truth: &Rendering, frame: &Rendering) -> String {
    let errors = wirepass::truth::accuracy::distance_errors(truth, frame).unwrap_or_default();
    let w = truth.size.0 as usize;
    errors
        .iter()
        .enumerate()
        .filter(|(_, e)| e.is_some_and(|e| e > 0.1))
        .take(8)
        .map(|(i, e)| {
            format!(
                "\n  pixel ({}, {}): id {} (frame {}), distance {} (frame {}), error {:?}",
                i % w,
                i / w,
                truth.ids[i],
                frame.ids[i],
                truth.edge_distance[i],
                frame.edge_distance[i],
                e
            )
        })
        .collect()
}

/// The median time of `frames` frames of the built-in scene at `size`, in milliseconds,
/// each from recording it to the GPU finishing it (a texel of the result read back: a page
/// cannot wait on the queue otherwise), drawn as a page draws into its canvas: the
/// render-pass entry into a `Bgra8Unorm` target, outlines on. `clock` reads milliseconds.
pub async fn frame_time(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    size: (u32, u32),
    frames: usize,
    clock: impl Fn() -> f64,
) -> Result<f64> {
    let format = wgpu::TextureFormat::Bgra8Unorm;
    let world = default_world(EdgeSelection::Polygon);
    let up = Uploaded::new(device, queue, &world)?;
    let (lo, hi) = world.bounds();
    let aspect = f64::from(size.0) / f64::from(size.1);
    let scene = up.scene(&world, Camera::framing(lo, hi, aspect).to_view(aspect));
    let mut pass = DeferredPass::new(device, canvas_pass(format))?;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(device, "frame timer", size, format, usage);
    let view = target.create_view(&Default::default());
    let probe_usage = wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC;
    let probe = texture_2d(device, "frame timer probe", (1, 1), format, probe_usage);
    let style = Style::default();
    let mut times = Vec::new();
    // Two more than asked: the first frames build pipelines.
    for _ in 0..frames + 2 {
        let start = clock();
        let frame = pass.prepare(device, &up.store, &scene, &style, size)?;
        let mut encoder = encode_into(device, &mut pass, &up, &frame, &view, wgpu::Color::WHITE)?;
        let one = wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        };
        encoder.copy_texture_to_texture(target.as_image_copy(), probe.as_image_copy(), one);
        queue.submit([encoder.finish()]);
        wirepass::gpu::read_texture_async(device, queue, &probe, wgpu::TextureAspect::All).await?;
        times.push(clock() - start);
    }
    let mut times = times.split_off(2);
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// A pass that composites into a page canvas's render pass of `format`.
fn canvas_pass(format: wgpu::TextureFormat) -> PassOptions {
    PassOptions {
        render_target: Some(RenderTarget {
            format,
            sample_count: 1,
            depth_stencil: None,
            content: Composite::Shaded,
        }),
        ..Default::default()
    }
}

/// Encodes `frame` and draws it into the host's render pass on `view`, cleared to `clear`,
/// as a page draws into its canvas; the encoder is the caller's to finish.
fn encode_into(
    device: &wgpu::Device,
    pass: &mut DeferredPass,
    up: &Uploaded,
    frame: &PreparedFrame,
    view: &wgpu::TextureView,
    clear: wgpu::Color,
) -> Result<wgpu::CommandEncoder> {
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode(
        device,
        &mut encoder,
        &up.store,
        frame,
        OutputTarget::RenderPass,
    )?;
    let mut host = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear),
                store: wgpu::StoreOp::Store,
            },
        })],
        ..Default::default()
    });
    pass.render(&mut host, frame)?;
    drop(host);
    Ok(encoder)
}
