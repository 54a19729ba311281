//! Offscreen rendering for the CLI, tools and tests: one frame into CPU images and maps.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::gpu::{
    read_texture, texture_2d, DeferredPass, EdgeLines, ForwardPass, GpuContext, GpuMesh,
    OutputTarget, PassOptions, TwoPass,
};
use crate::mesh::{EdgeSelection, Mesh};
use crate::style::Style;
use std::path::Path;

/// What to render.
#[derive(Clone, Debug)]
pub struct Scene<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The camera.
    pub camera: Camera,
    /// Colours, line width, lighting.
    pub style: Style,
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Which edges are drawn.
    pub edges: EdgeSelection,
}

/// One rendered frame on the CPU. Maps are row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// 8-bit sRGB RGBA image.
    pub rgba: Vec<u8>,
    /// Visible triangle per pixel, `u32::MAX` on background.
    pub ids: Vec<u32>,
    /// Depth in the `perspective_rh` convention: 0 at the near plane, 1 at the far plane
    /// and on background.
    pub depth: Vec<f32>,
    /// Pixels to the nearest line: a drawn edge of the visible triangle or, with
    /// [`Style::silhouettes`](crate::Style::silhouettes), an outline within the line's reach
    /// (background pixels included); `inf` where there is none. [`Method::Forward`] reports its interpolated
    /// altitudes as they come (NaN where they are NaN); [`Method::TwoPass`] measures no
    /// distance and reports 0 where it drew a line fragment, `inf` elsewhere.
    pub edge_distance: Vec<f32>,
}

/// A way of drawing the wireframe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// CPU ray cast in f64: the ground truth the other methods are measured against.
    Raycast,
    /// Visibility buffer + compute edge pass (the subject of this crate).
    Deferred,
    /// Forward single-pass baseline (Bærentzen et al. 2006): interpolated screen-space
    /// altitudes, vertex-pulled; divides by w like the seeds.
    Forward,
    /// Two-pass baseline: shaded fill with depth bias, then the drawn edges as 1 px lines.
    TwoPass,
}

impl Method {
    /// Every method, in report order.
    pub const ALL: &'static [Method] = &[
        Method::Raycast,
        Method::Deferred,
        Method::Forward,
        Method::TwoPass,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Raycast => "raycast",
            Method::Deferred => "deferred",
            Method::Forward => "forward",
            Method::TwoPass => "two-pass",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Method> {
        Method::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Method::ALL.iter().map(|m| m.name()).collect();
                Error::InvalidSetting(format!("method {s:?} is not one of {}", names.join(", ")))
            })
    }
}

/// Renders `scene` with `method` and reads back the image and all maps.
pub fn render(ctx: &GpuContext, scene: &Scene<'_>, method: Method) -> Result<Frame> {
    match method {
        Method::Raycast => crate::raycast::render_raycast(scene),
        Method::Deferred => render_deferred(ctx, scene),
        Method::Forward => render_forward(ctx, scene),
        Method::TwoPass => render_two_pass(ctx, scene),
    }
}

/// Renders `scene` with the deferred pass and reads back the image and all maps.
pub fn render_deferred(ctx: &GpuContext, scene: &Scene<'_>) -> Result<Frame> {
    let device = &ctx.device;
    let mut pass = DeferredPass::new(device, PassOptions::default())?.with_diagnostics();
    let mesh = GpuMesh::new(device, scene.mesh, scene.edges)?;
    pass.prepare(
        device,
        &ctx.queue,
        &mesh,
        &scene.camera,
        &scene.style,
        scene.size,
    )?;
    let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
    let output = texture_2d(
        device,
        "wirepass output",
        scene.size,
        pass.output_format(),
        usage,
    );
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode(device, &mut encoder, &mesh, OutputTarget::Shaded(&view))?;
    pass.encode_edges(device, &mut encoder, &mesh, OutputTarget::Diagnostic)?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;

    read_frame(
        ctx,
        scene.size,
        &output,
        pass.resolved_id_texture(),
        pass.diagnostic_texture(),
    )
}

/// Reads a rendered frame back: the 8-bit output `output`, the `R32Uint` ids and the
/// diagnostic map, four f32 per pixel (`Rgba32Float`, or their bits in `Rgba32Uint` for the
/// forward passes; r = distance in pixels, ≥ 1e38 meaning none; g = reverse-Z depth),
/// converted to [`Frame`]'s conventions.
fn read_frame(
    ctx: &GpuContext,
    size: (u32, u32),
    output: &wgpu::Texture,
    ids: Option<&wgpu::Texture>,
    diagnostic: Option<&wgpu::Texture>,
) -> Result<Frame> {
    let device = &ctx.device;
    let all = wgpu::TextureAspect::All;
    let missing = || Error::Device("the pass has no targets after prepare".into());
    let rgba = read_texture(device, &ctx.queue, output, all)?;
    let ids = read_texture(device, &ctx.queue, ids.ok_or_else(missing)?, all)?;
    let diagnostic = read_texture(device, &ctx.queue, diagnostic.ok_or_else(missing)?, all)?;
    ctx.finish()?;
    let diagnostic: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&diagnostic);
    Ok(Frame {
        size,
        rgba,
        ids: bytemuck::pod_collect_to_vec(&ids),
        // Reverse-Z back to the 0..1 convention.
        depth: diagnostic
            .iter()
            .map(|t| (1.0 - f64::from(t[1])) as f32)
            .collect(),
        edge_distance: diagnostic
            .iter()
            .map(|t| if t[0] >= 1e38 { f32::INFINITY } else { t[0] })
            .collect(),
    })
}

/// The forward baselines render to an sRGB render attachment: the hardware blends in linear
/// space and stores sRGB bytes, like the deferred pass's in-shader encoding.
const FORWARD_OUTPUT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

fn forward_output(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    texture_2d(device, "wirepass output", size, FORWARD_OUTPUT, usage)
}

/// Renders `scene` with the forward single-pass baseline and reads back the image and maps.
/// Its distance map is the interpolated altitudes' minimum (NaN where the method gives NaN).
pub fn render_forward(ctx: &GpuContext, scene: &Scene<'_>) -> Result<Frame> {
    let device = &ctx.device;
    let options = PassOptions {
        output_format: FORWARD_OUTPUT,
    };
    let mut pass = ForwardPass::new(device, options)?;
    let mesh = GpuMesh::new(device, scene.mesh, scene.edges)?;
    let style = &scene.style;
    pass.prepare(device, &ctx.queue, &mesh, &scene.camera, style, scene.size)?;
    let output = forward_output(device, scene.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with_maps(device, &mut encoder, &mesh, &view)?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;
    let (ids, diagnostic) = (pass.id_texture(), pass.diagnostic_texture());
    read_frame(ctx, scene.size, &output, ids, diagnostic)
}

/// Renders `scene` with the two-pass baseline and reads back the image and maps. It measures
/// no distance: its `edge_distance` is 0 where a line was drawn and `inf` elsewhere.
pub fn render_two_pass(ctx: &GpuContext, scene: &Scene<'_>) -> Result<Frame> {
    let device = &ctx.device;
    let options = PassOptions {
        output_format: FORWARD_OUTPUT,
    };
    let mut pass = TwoPass::new(device, options)?;
    let mesh = GpuMesh::new(device, scene.mesh, scene.edges)?;
    let lines = EdgeLines::new(device, scene.mesh, scene.edges)?;
    let style = &scene.style;
    pass.prepare(device, &ctx.queue, &mesh, &scene.camera, style, scene.size)?;
    let output = forward_output(device, scene.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with_maps(device, &mut encoder, &mesh, &lines, &view)?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;
    let (ids, diagnostic) = (pass.id_texture(), pass.diagnostic_texture());
    read_frame(ctx, scene.size, &output, ids, diagnostic)
}

/// Writes 8-bit RGBA pixels, row 0 at the top, as a PNG.
pub fn save_rgba_png(path: &Path, rgba: &[u8], (width, height): (u32, u32)) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ColorType::Rgba8).map_err(|e| {
        Error::Image {
            path: path.to_owned(),
            message: e.to_string(),
        }
    })
}

impl Frame {
    /// Writes the image as an sRGB PNG.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        save_rgba_png(path, &self.rgba, self.size)
    }

    /// Writes `ids.npy`, `depth.npy`, `edge_distance.npy` and `camera.json` into `dir`.
    pub fn dump(&self, dir: &Path, camera: &Camera) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.to_owned(),
            source,
        })?;
        let shape = [u64::from(self.size.1), u64::from(self.size.0)];
        write_npy(&dir.join("ids.npy"), &shape, &self.ids)?;
        write_npy(&dir.join("depth.npy"), &shape, &self.depth)?;
        write_npy(&dir.join("edge_distance.npy"), &shape, &self.edge_distance)?;
        let path = dir.join("camera.json");
        let text = camera_json(camera, self.size);
        std::fs::write(&path, text).map_err(|source| Error::Io { path, source })
    }
}

fn write_npy<T: npyz::Serialize + npyz::AutoSerialize + Copy>(
    path: &Path,
    shape: &[u64],
    data: &[T],
) -> Result<()> {
    use npyz::WriterBuilder;
    let io = |source| Error::Io {
        path: path.to_owned(),
        source,
    };
    let file = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let mut writer = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(file)
        .begin_nd()
        .map_err(io)?;
    writer.extend(data.iter().copied()).map_err(io)?;
    writer.finish().map_err(io)
}

/// The camera as JSON: its parameters, the size, and the view and projection matrices
/// (column-major, f64), so a reader can reproduce every pixel's ray.
pub fn camera_json(camera: &Camera, size: (u32, u32)) -> String {
    let v = |x: glam::Vec3| x.to_array().to_vec();
    let json = serde_json::json!({
        "eye": v(camera.eye),
        "target": v(camera.target),
        "up": v(camera.up),
        "fov_y_deg": camera.fov_y_deg,
        "near": camera.near,
        "far": camera.far,
        "size": [size.0, size.1],
        "view": camera.view().to_cols_array().to_vec(),
        "projection": camera.projection(f64::from(size.0) / f64::from(size.1)).to_cols_array().to_vec(),
        "conventions": "right-handed look_at; perspective_rh depth 0..1; row 0 at the top; pixel (x, y) centred at (x + 0.5, y + 0.5); matrices column-major",
    });
    serde_json::to_string_pretty(&json).unwrap_or_default()
}
