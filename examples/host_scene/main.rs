//! wirepass inside a host's own frame: the host draws its scene (a ground plane, a pillar in
//! front of a cow, a monkey half sunk into the ground) with its own pipeline into its own 4×
//! multisampled sRGB colour target and `Depth24PlusStencil8` depth; wirepass takes the host's
//! depth, so the pillar hides the cow's lines and the ground the monkey's chin, and draws
//! the cow's and the monkey's lines and outlines into the host's render pass. Headless, on a
//! device with the WebGPU default limits; writes a PNG.
//!
//! `cargo run --release --example host_scene -- [OUT.png]`

mod host;

use host::{HostDraw, HostMesh, HostRenderer, HostScene, HostTargets};
use wirepass::glam::{DMat4, Vec3};
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
    let samples = 4;
    let host = HostRenderer::new(device, samples, depth);
    let targets = HostTargets::new(device, size, samples);
    let meshes =
        [&scene.ground, &scene.pillar, &scene.cow, &scene.monkey].map(|m| HostMesh::new(device, m));
    let camera = scene.camera();
    let aspect = f64::from(size.0) / f64::from(size.1);
    let view = match depth {
        DepthRange::Standard => camera.to_view(aspect),
        DepthRange::Reversed => wirepass::View::new(
            camera.view(),
            wirepass::glam::dcamera::rh::proj::directx::perspective(
                f64::from(camera.fov_y_deg).to_radians(),
                aspect,
                f64::from(camera.far),
                f64::from(camera.near),
            ),
            DepthRange::Reversed,
        ),
    };

    // wirepass: the meshes to wireframe, and a pass that draws into the host's render pass.
    let mut store = MeshStore::new(device);
    let cow = store.insert(device, queue, &scene.cow, EdgeSelection::Polygon)?;
    let monkey = store.insert(device, queue, &scene.monkey, EdgeSelection::Polygon)?;
    let mut pass = DeferredPass::new(
        device,
        PassOptions {
            render_target: Some(RenderTarget {
                format: host::COLOR_FORMAT,
                sample_count: samples,
                depth_stencil: Some(host::DEPTH_FORMAT),
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
    let color = targets.color.create_view(&Default::default());
    let depth_view = targets.depth.create_view(&Default::default());
    let resolved = targets.resolved.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    let draws = [
        (0, DMat4::IDENTITY, Vec3::new(0.35, 0.42, 0.3)),
        (1, scene.pillar_at, Vec3::new(0.6, 0.45, 0.35)),
        (2, scene.cow_at, Vec3::new(0.8, 0.75, 0.7)),
        (3, scene.monkey_at, Vec3::new(0.75, 0.6, 0.45)),
    ]
    .map(|(m, transform, color)| HostDraw {
        mesh: &meshes[m],
        transform,
        color,
    });
    host.draw(
        device,
        &mut encoder,
        (&color, &depth_view),
        Vec3::new(0.55, 0.65, 0.8),
        view.view_projection(),
        &draws,
    );
    let canvas = wirepass::gpu::Canvas::new(size).with_host_depth(HostDepth {
        texture: &targets.depth,
        view,
    });
    let frame = pass.prepare(device, &store, &wire_scene, &style, canvas)?;
    pass.encode(
        device,
        &mut encoder,
        &store,
        &frame,
        OutputTarget::RenderPass,
    )?;
    {
        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host overlay"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color,
                depth_slice: None,
                resolve_target: Some(&resolved),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.render(&mut rp, &frame)?;
    }
    queue.submit([encoder.finish()]);
    let rgba =
        wirepass::gpu::read_texture(device, queue, &targets.resolved, wgpu::TextureAspect::All)?;
    Ok(rgba)
}
