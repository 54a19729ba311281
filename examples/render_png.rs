//! Renders two transformed instances of a mesh into a PNG with the library API only: a
//! device opened with the WebGPU default limits, your own encoder, the deferred pass encoded
//! into it, and a readback.
//!
//! `cargo run --release --example render_png -- [MESH.obj] [OUT.png]`

use wirepass::glam::{DMat4, DVec3};
use wirepass::gpu::{DeferredPass, MeshStore, OutputTarget, PassOptions};
use wirepass::{Camera, EdgeSelection, Instance, InstanceStyle, Scene, Style};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mesh = match args.next().filter(|p| !p.is_empty()) {
        Some(path) => wirepass::mesh::load_obj(path.as_ref())?,
        None => wirepass::mesh::torus(5000)?,
    };
    let out = args.next().unwrap_or_else(|| "example.png".into());
    let size = (640, 480);

    // The host owns the device, the queue and the output texture. Here a headless device
    // with the limits every WebGPU implementation has.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
        required_limits: wgpu::Limits::default(),
        ..Default::default()
    }))?;
    let output = wirepass::gpu::texture_2d(
        &device,
        "output",
        size,
        wgpu::TextureFormat::Rgba8Unorm,
        // RENDER_ATTACHMENT lets the pass clear the background instead of writing it.
        wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::RENDER_ATTACHMENT,
    );

    // Construct once and upload the mesh once.
    let mut pass = DeferredPass::new(
        &device,
        PassOptions {
            output_format: output.format(),
            ..Default::default()
        },
    )?;
    let mut meshes = MeshStore::new(&device);
    let id = meshes.insert(&device, &queue, &mesh, EdgeSelection::Polygon)?;

    // Each frame: the instances and the view. The second instance is mirrored, stretched
    // and drawn in its own colour; both occlude each other exactly.
    let (lo, hi) = mesh.bounds_f64();
    let extent = (hi - lo).max_element();
    let beside = DMat4::from_translation(DVec3::new(0.7 * extent, 0.0, -0.3 * extent))
        * DMat4::from_scale(DVec3::new(-1.0, 1.4, 1.0));
    let instances = [
        Instance::new(id, DMat4::IDENTITY),
        Instance::new(id, beside).with_style(InstanceStyle {
            wire_color: Some(wirepass::Color::from_hex("#b03020")?),
            line_width: Some(2.5),
            ..Default::default()
        }),
    ];
    let aspect = f64::from(size.0) / f64::from(size.1);
    let (lo, hi) = (
        lo.min(lo + beside.w_axis.truncate()),
        hi.max(hi + beside.w_axis.truncate()),
    );
    let camera = Camera::framing(
        lo - DVec3::splat(0.2 * extent),
        hi + DVec3::splat(0.2 * extent),
        aspect,
    );
    let scene = Scene::borrowed(camera.to_view(aspect), &instances);
    let style = Style {
        line_width: 1.5,
        ..Style::default()
    };
    let frame = pass.prepare(&device, &meshes, &scene, &style, size)?;

    // Encode into the host's encoder.
    let mut encoder = device.create_command_encoder(&Default::default());
    let view = output.create_view(&Default::default());
    pass.encode(
        &device,
        &mut encoder,
        &meshes,
        &frame,
        OutputTarget::Shaded(&view),
    )?;
    queue.submit([encoder.finish()]);

    let rgba = wirepass::gpu::read_texture(&device, &queue, &output, wgpu::TextureAspect::All)?;
    image::save_buffer(&out, &rgba, size.0, size.1, image::ColorType::Rgba8)?;
    println!("wrote {out}");
    Ok(())
}
