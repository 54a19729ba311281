//! A CAD-style host, single-sampled: the host draws its ground and a pillar with its own
//! pipeline into its own `Rgba8UnormSrgb` colour and `Depth32Float` depth; wirepass shades
//! the parts (a cow and a monkey) itself and draws their lines into the host's render pass
//! (`Composite::Shaded`), hidden by the host's depth. Then the host picks the pixel at the
//! cow's middle: which instance and triangle it shows, the exact point and normal, and the
//! drawn edge and vertex to snap to; and draws the next frame with that instance
//! highlighted. Headless, on a device with the WebGPU default limits; writes a PNG.
//!
//! `cargo run --release --example cad_host -- [OUT.png]`

#[path = "../host_scene/host.rs"]
#[allow(dead_code)]
mod host;

use host::{HostFormats, HostRenderer, HostScene, HostTargets};
use wirepass::gpu::{
    Canvas, Composite, HostDepth, MeshStore, OutputTarget, PassOptions, PickView, Picked,
    RenderTarget, SnapVertices,
};
use wirepass::{
    wgpu, DeferredPass, DepthRange, EdgeSelection, Highlight, Instance, InstanceStyle, Scene, Style,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "cad_host.png".into());
    let size = (800, 600);
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
        required_limits: wgpu::Limits::default(),
        ..Default::default()
    }))?;

    // The host: its formats (one sample), its renderer and targets, its scene.
    let formats = HostFormats {
        color: wgpu::TextureFormat::Rgba8UnormSrgb,
        depth: wgpu::TextureFormat::Depth32Float,
        samples: 1,
    };
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes");
    let scene = HostScene::new(
        wirepass::mesh::load(&data.join("spot.obj"))?,
        wirepass::mesh::load(&data.join("suzanne.obj"))?,
    );
    let host = HostRenderer::new(&device, formats, DepthRange::Standard);
    let targets = HostTargets::new(&device, size, formats);
    let host_meshes = scene.upload(&device);
    let view = scene.view(f64::from(size.0) / f64::from(size.1), DepthRange::Standard);

    // wirepass: the parts, and a pass that shades them into the host's render pass.
    let mut store = MeshStore::new(&device);
    let edges = EdgeSelection::Polygon;
    let cow = store.insert(&device, &queue, &scene.cow, edges)?;
    let monkey = store.insert(&device, &queue, &scene.monkey, edges)?;
    let mut pass = DeferredPass::new(
        &device,
        PassOptions {
            render_target: Some(RenderTarget {
                format: formats.color,
                sample_count: 1,
                depth_stencil: Some(formats.depth),
                content: Composite::Shaded,
            }),
            ..Default::default()
        },
    )?;
    let style = Style::default();
    let mut parts = [
        Instance::new(cow, scene.cow_at),
        Instance::new(monkey, scene.monkey_at),
    ];

    // A frame: the host draws its own geometry (not the parts), then wirepass reads the
    // host's depth and draws the shaded parts and their lines into the host's pass.
    let draw_frame = |pass: &mut DeferredPass, parts: &[Instance]| {
        let wire_scene = Scene::borrowed(view, parts);
        let mut encoder = device.create_command_encoder(&Default::default());
        host.draw(
            &device,
            &mut encoder,
            &targets,
            HostScene::SKY,
            view.view_projection(),
            &scene.draws(&host_meshes)[..2],
        );
        let canvas = Canvas::new(size).with_host_depth(HostDepth {
            texture: &targets.depth,
            matrices: view,
        });
        let frame = pass.prepare(&device, &store, &wire_scene, &style, canvas)?;
        pass.encode(
            &device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::RenderPass,
        )?;
        pass.render(&mut targets.overlay_pass(&mut encoder), &frame)?;
        queue.submit([encoder.finish()]);
        Ok::<_, wirepass::Error>(frame)
    };
    let frame = draw_frame(&mut pass, &parts)?;

    // The host's click: along the row through the cow's origin (the pillar stands in front
    // of it), the first pixel that shows the cow.
    let (x0, y) = {
        let c = view.view_projection() * scene.cow_at.w_axis;
        let ndc = c.truncate().truncate() / c.w;
        (
            ((ndc.x + 1.0) * 0.5 * f64::from(size.0)) as u32,
            ((1.0 - ndc.y) * 0.5 * f64::from(size.1)) as u32,
        )
    };
    let picked_scene = Scene::borrowed(view, &parts);
    let mut hit = None;
    for x in (x0..size.0).step_by(4) {
        if let Picked::Instance(h) = frame.pick(&device, &queue, &store, &picked_scene, (x, y))? {
            hit = Some((h, (x, y)));
            break;
        }
    }
    let (hit, at) = hit.ok_or("no pixel of the row shows a part")?;
    // A CAD host snaps to the corners of the lines it shows.
    let pick_view = PickView::new(&picked_scene, size).snapping_to(SnapVertices::OnDrawnEdges);
    let mesh = [&scene.cow, &scene.monkey][hit.instance];
    let location = hit.locate(mesh, &pick_view, at, 8.0)?;
    println!(
        "pixel {at:?}: instance {}, triangle {} (polygon {}), point {:.4}, normal {:.3}",
        hit.instance, location.triangle, location.polygon, location.point, location.normal
    );
    match location.edge {
        Some(e) => println!(
            "  snaps to edge {:?}, {:.2} px away, at {:.4}",
            e.vertices, e.distance_px, e.point
        ),
        None => println!("  no drawn edge within 8 px"),
    }
    match location.vertex {
        Some(v) => println!(
            "  snaps to vertex {}, {:.2} px away, at {:.4}",
            v.vertex, v.distance_px, v.position
        ),
        None => println!("  no vertex within 8 px"),
    }

    // The next frame shows the picked part highlighted.
    parts[hit.instance].style = InstanceStyle::default().highlighted(&Highlight::default(), &style);
    draw_frame(&mut pass, &parts)?;
    let rgba =
        wirepass::gpu::read_texture(&device, &queue, targets.image(), wgpu::TextureAspect::All)?;
    image::save_buffer(&out, &rgba, size.0, size.1, image::ColorType::Rgba8)?;
    println!("wrote {out}");
    Ok(())
}
