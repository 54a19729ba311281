//! wirepass inside a host's own frame: the host draws its scene (a ground plane, a pillar in
//! front of a cow, a monkey half sunk into the ground) with its own pipeline into its own 4×
//! multisampled sRGB colour target and `Depth24PlusStencil8` depth; wirepass takes the host's
//! depth, so the pillar hides the cow's lines and the ground the monkey's chin, and draws
//! the cow's and the monkey's lines and outlines into the host's render pass. Headless, on a
//! device with the WebGPU default limits; writes a PNG.
//!
//! `cargo run --release --example host_scene -- [OUT.png]`

mod host;

use host::{HostFormats, HostRenderer, HostScene, HostTargets};
use wirepass::gpu::{Composite, HostDepth, MeshStore, OutputTarget, PassOptions, RenderTarget};
use wirepass::{wgpu, DeferredPass, DepthRange, EdgeSelection, Instance, Scene, Style};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "host_scene.png".into());
    let size = (800, 600);
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
        required_limits: wgpu::Limits::default(),
        ..Default::default()
    }))?;

    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes");
    let scene = HostScene::new(
        wirepass::mesh::load(&data.join("spot.obj"))?,
        wirepass::mesh::load(&data.join("suzanne.obj"))?,
    );
    let rgba = render(&device, &queue, &scene, size, DepthRange::Standard)?;
    image::save_buffer(&out, &rgba, size.0, size.1, image::ColorType::Rgba8)?;
    println!("wrote {out}");
    Ok(())
}

/// One frame of the host's scene with wirepass's lines in it, read back as sRGB bytes.
fn render(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &HostScene,
    size: (u32, u32),
    depth: DepthRange,
) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    // The host's renderer, targets and meshes.
    let formats = HostFormats::EXAMPLE;
    let host = HostRenderer::new(device, formats, depth);
    let targets = HostTargets::new(device, size, formats);
    let meshes = scene.upload(device);
    let view = scene.view(f64::from(size.0) / f64::from(size.1), depth);

    // wirepass: the meshes to wireframe, and a pass that draws into the host's render pass.
    let mut store = MeshStore::new(device);
    let cow = store.insert(device, queue, &scene.cow, EdgeSelection::Polygon)?;
    let monkey = store.insert(device, queue, &scene.monkey, EdgeSelection::Polygon)?;
    let mut pass = DeferredPass::new(
        device,
        PassOptions {
            render_target: Some(RenderTarget {
                format: formats.color,
                sample_count: formats.samples,
                depth_stencil: Some(formats.depth),
                content: Composite::Lines,
            }),
            ..Default::default()
        },
    )?;
    let instances = [
        Instance::new(cow, scene.cow_at),
        Instance::new(monkey, scene.monkey_at),
    ];
    let wire_scene = Scene::borrowed(view, &instances);
    let style = Style {
        line_width: 1.5,
        ..Style::default()
    };

    // Each frame: the host draws its scene, wirepass reads its depth and draws the lines
    // into the host's own render pass.
    let mut encoder = device.create_command_encoder(&Default::default());
    host.draw(
        device,
        &mut encoder,
        &targets,
        HostScene::SKY,
        view.view_projection(),
        &scene.draws(&meshes),
    );
    let canvas = wirepass::gpu::Canvas::new(size).with_host_depth(HostDepth {
        texture: &targets.depth,
        matrices: view,
    });
    let frame = pass.prepare(device, &store, &wire_scene, &style, canvas)?;
    pass.encode(
        device,
        &mut encoder,
        &store,
        &frame,
        OutputTarget::RenderPass,
    )?;
    pass.render(&mut targets.overlay_pass(&mut encoder), &frame)?;
    queue.submit([encoder.finish()]);
    let rgba =
        wirepass::gpu::read_texture(device, queue, targets.image(), wgpu::TextureAspect::All)?;
    Ok(rgba)
}
