//! Offscreen frames for the CLI, tools and tests: a [`Shot`] of a world drawn with any
//! [`Method`] into a [`Rendering`] (CPU image and maps, global triangle ids), and its dumps.
//! The one offscreen module natively: it waits on the futures of
//! [`world::offscreen`](crate::world::offscreen), their non-blocking core, which the browser
//! tests await on the page's event loop instead.

use crate::camera::View;
use crate::error::{Error, Result};
use crate::gpu::{
    texture_2d, Canvas, DeferredPass, EncodeOptions, ForwardPass, GpuContext, PassOptions, TwoPass,
    UploadReport, WarmUp,
};
use crate::tools::pipeline_cache::CacheUse;
use crate::world::offscreen;
use crate::world::{Rendering, Shot};
use std::path::Path;
use std::time::{Duration, Instant};

pub use crate::world::offscreen::{encode_shaded, Uploaded};

/// A way of drawing the wireframe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// CPU ray cast in f64: the ground truth the other methods are measured against.
    Raycast,
    /// Visibility buffer + compute edge pass (the subject of this crate).
    Deferred,
    /// Forward single-pass baseline (Bærentzen et al. 2006): interpolated screen-space
    /// altitudes, vertex-pulled; divides by w as the published method does.
    Forward,
    /// Two-pass baseline: shaded fill with depth bias, then the drawn edges as 1 px lines.
    TwoPass,
    /// The forward single-pass method as published, with its geometry shader over an
    /// indexed draw, on native OpenGL ([`gs`](crate::tools::gs)); it draws what `forward`
    /// draws.
    Gs,
}

impl Method {
    /// Every method, in report order.
    pub const ALL: &'static [Method] = &[
        Method::Raycast,
        Method::Deferred,
        Method::Forward,
        Method::TwoPass,
        Method::Gs,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Raycast => "raycast",
            Method::Deferred => "deferred",
            Method::Forward => "forward",
            Method::TwoPass => "two-pass",
            Method::Gs => "gs",
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

/// Renders `shot` with `method` and reads back the image and all maps.
pub fn draw(ctx: &GpuContext, shot: &Shot<'_>, method: Method) -> Result<Rendering> {
    match method {
        Method::Raycast => crate::truth::draw_raycast(shot),
        Method::Deferred => draw_deferred(ctx, shot),
        Method::Forward => draw_forward(ctx, shot),
        Method::TwoPass => draw_two_pass(ctx, shot),
        Method::Gs => draw_gs(ctx, shot),
    }
}

/// Renders `shot` with the deferred pass and reads back the image and all maps.
pub fn draw_deferred(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Rendering> {
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let pass = DeferredPass::new(&ctx.device, PassOptions::default())?.with_diagnostics();
    draw_deferred_on(ctx, shot, &up, pass, Canvas::new(shot.size))
}

/// Where the time to a first deferred image goes ([`draw_deferred_timed`]; `wirepass
/// render --timings`).
#[derive(Clone, Debug)]
pub struct FirstImage {
    /// Each mesh's upload, step by step.
    pub uploads: Vec<UploadReport>,
    /// All uploads, as the wall clock saw them.
    pub upload: Duration,
    /// Making the pass.
    pub pass: Duration,
    /// Preparing the frame: its records, targets and the visibility pipelines.
    pub prepare: Duration,
    /// Building the frame's other pipelines.
    pub warm_up: WarmUp,
    /// Encoding the frame and waiting for the GPU: where a driver that compiles shaders on
    /// first use (lavapipe) compiles them.
    pub frame: Duration,
    /// Reading the image and maps back.
    pub readback: Duration,
    /// What the pass's pipelines were built with: wgpu's pipeline cache from an earlier
    /// run ([`pipeline_cache`](crate::tools::pipeline_cache)), or why none.
    pub pipeline_cache: CacheUse,
}

/// [`draw_deferred`], timing each step ([`FirstImage`]).
pub fn draw_deferred_timed(ctx: &GpuContext, shot: &Shot<'_>) -> Result<(Rendering, FirstImage)> {
    let (drawn, timings) = first_image(ctx, shot, true)?;
    match drawn {
        Drawn::Rendering(r) => Ok((r, timings)),
        Drawn::Image(_) => Err(Error::Device("the frame read back no maps".into())),
    }
}

/// The deferred image of `shot` alone (8-bit sRGB RGBA), without the maps the tools read
/// back, by a pass without diagnostics, timing each step: what `wirepass render` needs.
pub fn draw_deferred_image(ctx: &GpuContext, shot: &Shot<'_>) -> Result<(Vec<u8>, FirstImage)> {
    let (drawn, timings) = first_image(ctx, shot, false)?;
    match drawn {
        Drawn::Image(rgba) => Ok((rgba, timings)),
        Drawn::Rendering(r) => Ok((r.rgba, timings)),
    }
}

/// What [`first_image`] read back.
enum Drawn {
    Rendering(Rendering),
    Image(Vec<u8>),
}

/// Uploads `shot`'s world, draws it with a new deferred pass and reads back the image, and
/// with `maps` every map ([`Rendering`]), timing each step.
fn first_image(ctx: &GpuContext, shot: &Shot<'_>, maps: bool) -> Result<(Drawn, FirstImage)> {
    let (device, queue) = (&ctx.device, &ctx.queue);
    let start = Instant::now();
    let up = Uploaded::new(device, queue, shot.world)?;
    let upload = start.elapsed();
    let uploads = up
        .ids
        .iter()
        .map(|&id| up.store.upload_report(id))
        .collect::<Result<Vec<_>>>()?;
    let start = Instant::now();
    let stored = crate::tools::pipeline_cache::open(ctx);
    let options = PassOptions {
        pipeline_cache: stored.as_ref().ok().map(|s| s.cache.clone()),
        ..PassOptions::default()
    };
    let mut pass = DeferredPass::new(device, options)?;
    if maps {
        pass = pass.with_diagnostics();
    }
    let pass_time = start.elapsed();
    let start = Instant::now();
    let canvas = Canvas::new(shot.size);
    let (frame, output) = offscreen::prepare_shaded(device, shot, &up, &mut pass, canvas)?;
    let prepare = start.elapsed();
    let view = output.create_view(&Default::default());
    let warm_up = pass.warm_up(device, &frame, &crate::gpu::OutputTarget::Shaded(&view))?;
    let start = Instant::now();
    offscreen::encode_prepared(device, queue, &up, &pass, &frame, &view)?;
    ctx.finish()?;
    let frame_time = start.elapsed();
    let start = Instant::now();
    let drawn = if maps {
        let read = offscreen::read_deferred(device, queue, shot, &up, &mut pass, &frame, &output);
        Drawn::Rendering(pollster::block_on(read)?)
    } else {
        let all = wgpu::TextureAspect::All;
        let rgba = crate::gpu::read_texture_async(device, queue, &output, all);
        Drawn::Image(pollster::block_on(rgba)?)
    };
    ctx.finish()?;
    let readback = start.elapsed();
    let pipeline_cache = match stored {
        Ok(file) => file.used(file.save()?),
        Err(why) => CacheUse::Unused(why),
    };
    let timings = FirstImage {
        uploads,
        upload,
        pass: pass_time,
        prepare,
        warm_up,
        frame: frame_time,
        readback,
        pipeline_cache,
    };
    Ok((drawn, timings))
}

/// [`draw_deferred`] with a pass and upload of the caller's (a pass with lowered limits, or
/// vertex pulling, say) onto a canvas of the caller's: the whole image
/// (`Canvas::new(shot.size)`), the image over the host's depth buffer (its pixels where the
/// host is in front get the id [`HOST`](crate::world::HOST)), or a region of it (a tile: the
/// frame is the region's size).
pub fn draw_deferred_on(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    up: &Uploaded,
    mut pass: DeferredPass,
    canvas: Canvas<'_>,
) -> Result<Rendering> {
    let (device, queue) = (&ctx.device, &ctx.queue);
    let drawn = pollster::block_on(offscreen::draw_deferred_on_async(
        device, queue, shot, up, &mut pass, canvas,
    ));
    // A device error makes whatever was read back meaningless: it comes first.
    ctx.finish()?;
    drawn
}

/// Reads back a baseline's frame ([`offscreen::read_rendering`]), then checks the device.
fn read_frame(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    out: ((u32, u32), &Uploaded),
    order: &[u32],
    output: &wgpu::Texture,
    maps: (&wgpu::Texture, &wgpu::Texture),
) -> Result<Rendering> {
    let (device, queue) = (&ctx.device, &ctx.queue);
    let read = pollster::block_on(offscreen::read_rendering(
        device, queue, shot, out, order, output, maps,
    ));
    ctx.finish()?;
    // The baselines tell no line classes apart.
    read.map(|r| Rendering {
        line_class: Vec::new(),
        ..r
    })
}

/// The forward baselines render to an sRGB render attachment: the hardware blends in linear
/// space and stores sRGB bytes, like the deferred pass's in-shader encoding.
const FORWARD_OUTPUT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

fn forward_output(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    texture_2d(device, "wirepass output", size, FORWARD_OUTPUT, usage)
}

/// Renders `shot` with the forward single-pass baseline and reads back the image and maps.
/// Its distance map is the interpolated altitudes' minimum (NaN where the method gives NaN).
pub fn draw_forward(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Rendering> {
    let device = &ctx.device;
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let mut pass = ForwardPass::new(device, FORWARD_OUTPUT)?;
    let scene = up.scene(shot.world, shot.view);
    let frame = pass.prepare(device, &up.store, &scene, shot.style, shot.size)?;
    let output = forward_output(device, shot.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with(
        device,
        &mut encoder,
        &up.store,
        &frame,
        &view,
        EncodeOptions {
            maps: true,
            ..Default::default()
        },
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;
    let maps = (frame.id_texture(), frame.diagnostic_texture());
    read_frame(
        ctx,
        shot,
        (shot.size, &up),
        frame.instance_order(),
        &output,
        maps,
    )
}

/// Renders `shot` with the two-pass baseline and reads back the image and maps. It measures
/// no distance: its `edge_distance` is 0 where a line was drawn and `inf` elsewhere.
pub fn draw_two_pass(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Rendering> {
    let device = &ctx.device;
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let lines = up.edge_lines(&ctx.device, shot.world)?;
    let mut pass = TwoPass::new(device, FORWARD_OUTPUT)?;
    let scene = up.scene(shot.world, shot.view);
    let frame = pass.prepare(device, &up.store, &scene, shot.style, shot.size)?;
    let output = forward_output(device, shot.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with(
        device,
        &mut encoder,
        (&up.store, &lines),
        &frame,
        &view,
        EncodeOptions {
            maps: true,
            ..Default::default()
        },
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;
    let maps = (frame.id_texture(), frame.diagnostic_texture());
    read_frame(
        ctx,
        shot,
        (shot.size, &up),
        frame.instance_order(),
        &output,
        maps,
    )
}

/// Renders `shot` with the published geometry-shader method on OpenGL and reads back the
/// image and maps, which hold what the forward method's hold. An
/// [`Error::NoAdapter`] where no OpenGL context with geometry shaders can be made.
pub fn draw_gs(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Rendering> {
    draw_gs_with(ctx, shot, crate::tools::gs::GsPass::new()?)
}

/// [`draw_gs`] with a pass of the caller's.
pub fn draw_gs_with(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    mut pass: crate::tools::gs::GsPass,
) -> Result<Rendering> {
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world)?;
    let scene = up.scene(shot.world, shot.view);
    let gpu = (&ctx.device, &ctx.queue);
    let frame = pass.prepare(gpu, &up.store, &scene, shot.style, (shot.size, true))?;
    pass.draw(&frame, true)?;
    let pixels = pass.read(&frame)?;
    let order = frame.instance_order().to_vec();
    pass.release(frame);
    offscreen::maps_rendering(
        shot,
        (shot.size, &up),
        &order,
        pixels.rgba,
        &pixels.ids,
        &pixels.diagnostic,
    )
}

impl Rendering {
    /// Writes the image as an sRGB PNG.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        crate::tools::regression::save_rgba_png(path, &self.rgba, self.size)
    }

    /// Writes `ids.npy`, `depth.npy`, `edge_distance.npy`, `hidden_distance.npy`,
    /// `line_class.npy` (for methods that report it: [`crate::world::LineClass`] per pixel)
    /// and `camera.json` into `dir`.
    pub fn dump(&self, dir: &Path, view: &View) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.to_owned(),
            source,
        })?;
        let shape = [u64::from(self.size.1), u64::from(self.size.0)];
        write_npy(&dir.join("ids.npy"), &shape, &self.ids)?;
        write_npy(&dir.join("depth.npy"), &shape, &self.depth)?;
        write_npy(&dir.join("edge_distance.npy"), &shape, &self.edge_distance)?;
        write_npy(
            &dir.join("hidden_distance.npy"),
            &shape,
            &self.hidden_distance,
        )?;
        if !self.line_class.is_empty() {
            write_npy(&dir.join("line_class.npy"), &shape, &self.line_class)?;
        }
        let path = dir.join("camera.json");
        let text = camera_json(view, self.size);
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

/// The view as JSON: the view and projection matrices actually used (column-major, f64),
/// the depth convention, the eye and the size, so a reader can reproduce every pixel's ray.
pub fn camera_json(view: &View, size: (u32, u32)) -> String {
    let json = serde_json::json!({
        "size": [size.0, size.1],
        "view": view.view.to_cols_array().to_vec(),
        "projection": view.projection.to_cols_array().to_vec(),
        "depth": match view.depth {
            crate::camera::DepthRange::Standard => "standard",
            crate::camera::DepthRange::Reversed => "reversed",
        },
        "orthographic": view.is_orthographic(),
        "eye": view.eye().to_array().to_vec(),
        "conventions": "clip = projection * view * world; visible points have w > 0 and depth z/w in 0..1 (standard: 0 at near; reversed: 1 at near); row 0 at the top; pixel (x, y) centred at (x + 0.5, y + 0.5); matrices column-major; eye homogeneous (w = 0: towards the viewer of an orthographic view)",
    });
    serde_json::to_string_pretty(&json).unwrap_or_default()
}
