//! Renders a mesh to a PNG with the library API only: your own device and encoder, the
//! deferred pass encoded into them, and a readback.
//!
//! `cargo run --release --example render_png -- [MESH.obj] [OUT.png]`

use wirepass::gpu::{DeferredPass, GpuMesh, OutputTarget, PassOptions};
use wirepass::{Camera, EdgeSelection, Style};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mesh = match args.next() {
        Some(path) => wirepass::mesh::load_obj(path.as_ref())?,
        None => wirepass::mesh::default_scene(),
    };
    let out = args.next().unwrap_or_else(|| "example.png".into());
    let size = (640, 480);

    // The host owns the device, the queue and the output texture. Here a headless device.
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
        ..Default::default()
    }))?;
    let output = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("output"),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });

    // Construct once, upload the mesh, prepare when camera, style or size change.
    let mut pass = DeferredPass::new(
        &device,
        PassOptions {
            output_format: output.format(),
        },
    )?;
    let gpu_mesh = GpuMesh::new(&device, &mesh, EdgeSelection::Polygon)?;
    let (lo, hi) = mesh.bounds();
    let camera = Camera::framing(lo, hi, size.0 as f32 / size.1 as f32);
    let style = Style {
        line_width: 2.0,
        ..Style::default()
    };
    pass.prepare(&device, &queue, &gpu_mesh, &camera, &style, size)?;

    // Each frame: encode into the host's encoder.
    let mut encoder = device.create_command_encoder(&Default::default());
    let view = output.create_view(&Default::default());
    pass.encode(
        &device,
        &mut encoder,
        &gpu_mesh,
        OutputTarget::Shaded(&view),
    )?;
    queue.submit([encoder.finish()]);

    let rgba = wirepass::gpu::read_texture(&device, &queue, &output, wgpu::TextureAspect::All)?;
    image::save_buffer(&out, &rgba, size.0, size.1, image::ColorType::Rgba8)?;
    println!("wrote {out}");
    Ok(())
}
