//! Offscreen rendering for the CLI, tools and tests: a [`World`] of meshes and objects,
//! drawn through one view with any [`Method`] into CPU images and maps.
//!
//! Triangle ids in every map are **global**: objects are numbered in the world's order, each
//! object's triangles consecutive in the order its mesh file lists them.

use crate::camera::View;
use crate::error::{Error, Result};
use crate::gpu::{
    read_texture, texture_2d, Canvas, DeferredPass, EdgeLines, ForwardPass, GpuContext, MeshId,
    MeshStore, OutputTarget, PassOptions, TwoPass,
};
use crate::mesh::{EdgeSelection, Mesh};
use crate::scene::{Instance, InstanceStyle, Scene};
use crate::style::Style;
use glam::{DMat4, DVec3};
use std::path::Path;
use std::sync::Arc;

/// Id of pixels that show no triangle.
pub const BACKGROUND: u32 = u32::MAX;
/// Id of pixels where the host's own geometry is in front.
pub const HOST: u32 = u32::MAX - 1;

/// A mesh of a world, with the edges drawn on it.
#[derive(Clone, Debug)]
pub struct WorldMesh {
    /// The mesh, in its own coordinates.
    pub mesh: Arc<Mesh>,
    /// Which of its edges are drawn.
    pub edges: EdgeSelection,
    /// Where it came from, for messages.
    pub name: String,
}

/// One placement of a world mesh.
#[derive(Clone, Debug)]
pub struct Object {
    /// Index into [`World::meshes`].
    pub mesh: usize,
    /// Model → world.
    pub transform: DMat4,
    /// Style overrides.
    pub style: InstanceStyle,
}

/// Meshes and their placements: what tools render, compare and time.
#[derive(Clone, Debug, Default)]
pub struct World {
    /// The distinct meshes (each uploaded once).
    pub meshes: Vec<WorldMesh>,
    /// The objects, in order; several may share a mesh.
    pub objects: Vec<Object>,
}

impl World {
    /// One mesh, placed once at the origin.
    pub fn single(mesh: Mesh, edges: EdgeSelection) -> World {
        World {
            meshes: vec![WorldMesh {
                mesh: Arc::new(mesh),
                edges,
                name: "mesh".into(),
            }],
            objects: vec![Object {
                mesh: 0,
                transform: DMat4::IDENTITY,
                style: InstanceStyle::default(),
            }],
        }
    }

    /// Checks the objects' meshes and that every global id fits the id maps.
    pub fn validate(&self) -> Result<()> {
        for (i, o) in self.objects.iter().enumerate() {
            if o.mesh >= self.meshes.len() {
                return Err(Error::InvalidScene(format!(
                    "object {i} refers to mesh {} of {}",
                    o.mesh,
                    self.meshes.len()
                )));
            }
        }
        let total = self.triangle_count();
        if total >= u64::from(HOST) {
            return Err(Error::InvalidScene(format!(
                "{total} triangles over all objects: global ids must stay below {HOST}"
            )));
        }
        Ok(())
    }

    /// Triangles over all objects.
    pub fn triangle_count(&self) -> u64 {
        self.objects
            .iter()
            .map(|o| self.meshes[o.mesh].mesh.triangle_count() as u64)
            .sum()
    }

    /// The global id of each object's first triangle.
    pub fn first_ids(&self) -> Vec<u32> {
        let mut next = 0u64;
        self.objects
            .iter()
            .map(|o| {
                let first = next;
                next += self.meshes[o.mesh].mesh.triangle_count() as u64;
                first as u32
            })
            .collect()
    }

    /// The object and triangle of global id `id`.
    pub fn locate(&self, first_ids: &[u32], id: u32) -> (usize, u32) {
        let o = first_ids.partition_point(|&f| f <= id).saturating_sub(1);
        (o, id - first_ids[o])
    }

    /// Axis-aligned world bounds of every object (its mesh's bounding box, transformed).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for o in &self.objects {
            let (a, b) = self.meshes[o.mesh].mesh.bounds_f64();
            for i in 0..8 {
                let c = DVec3::new(
                    if i & 1 == 0 { a.x } else { b.x },
                    if i & 2 == 0 { a.y } else { b.y },
                    if i & 4 == 0 { a.z } else { b.z },
                );
                let p = o.transform.transform_point3(c);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo, hi)
    }
}

impl World {
    /// A glTF scene as a world: each glTF mesh once, an object per instance in node order,
    /// with the file's line width where it gives one. Each mesh draws `edges`, or, when that
    /// is `None`, its authored edges where it has them (polygon edges otherwise); see
    /// [`Mesh::resolve_edges`] for what an explicit selection does to the file's outline mask.
    pub fn from_gltf(doc: crate::mesh::gltf::Document, edges: Option<EdgeSelection>) -> World {
        let widths: Vec<Option<f32>> = doc.meshes.iter().map(|m| m.line_width).collect();
        let meshes = doc
            .meshes
            .into_iter()
            .map(|m| {
                let (mesh, edges) = m.mesh.resolve_edges(edges.or(m.edges));
                WorldMesh {
                    mesh: Arc::new(mesh),
                    edges,
                    name: m.name,
                }
            })
            .collect();
        let objects = doc
            .instances
            .into_iter()
            .map(|(mesh, transform)| Object {
                mesh,
                transform,
                style: InstanceStyle {
                    line_width: widths[mesh],
                    ..InstanceStyle::default()
                },
            })
            .collect();
        World { meshes, objects }
    }
}

/// The built-in scene: a torus and a sphere, two meshes drawing `edges`.
pub fn default_world(edges: EdgeSelection) -> World {
    let mut world = World::default();
    // The parts are constant and valid (tests check it); an error cannot occur here.
    for (i, (mesh, transform)) in crate::mesh::default_parts()
        .into_iter()
        .flatten()
        .enumerate()
    {
        world.meshes.push(WorldMesh {
            mesh: Arc::new(mesh),
            edges,
            name: ["torus", "sphere"][i].into(),
        });
        world.objects.push(Object {
            mesh: i,
            transform,
            style: InstanceStyle::default(),
        });
    }
    world
}

/// What one render draws: a world, through a view, in a style, at a size.
#[derive(Clone, Copy, Debug)]
pub struct Shot<'a> {
    /// The meshes and objects.
    pub world: &'a World,
    /// How they are seen.
    pub view: View,
    /// Colours, line width, lighting.
    pub style: &'a Style,
    /// Image size in pixels.
    pub size: (u32, u32),
}

/// A world uploaded to the GPU: its meshes in one store.
pub struct Uploaded {
    /// The store.
    pub store: MeshStore,
    /// The store's id of each world mesh.
    pub ids: Vec<MeshId>,
}

impl Uploaded {
    /// Uploads every mesh of `world` once.
    pub fn new(ctx: &GpuContext, world: &World) -> Result<Uploaded> {
        world.validate()?;
        let mut store = MeshStore::new(&ctx.device);
        let ids = world
            .meshes
            .iter()
            .map(|m| store.insert(&ctx.device, &ctx.queue, &m.mesh, m.edges))
            .collect::<Result<_>>()?;
        Ok(Uploaded { store, ids })
    }

    /// The world's objects as a scene of instances seen through `view`.
    pub fn scene(&self, world: &World, view: View) -> Scene<'static> {
        let instances = world
            .objects
            .iter()
            .map(|o| Instance {
                mesh: self.ids[o.mesh],
                transform: o.transform,
                style: o.style,
            })
            .collect();
        Scene::new(view, instances)
    }

    /// The two-pass method's edge lists of every mesh.
    pub fn edge_lines(&self, ctx: &GpuContext, world: &World) -> Result<EdgeLines> {
        let mut lines = EdgeLines::new();
        for (m, &id) in world.meshes.iter().zip(&self.ids) {
            lines.insert(&ctx.device, &self.store, id, &m.mesh, m.edges)?;
        }
        Ok(lines)
    }

    /// Global ids of a map of (instance slot, stored triangle) pairs, with `order` mapping
    /// slots to objects.
    pub fn global_ids(&self, world: &World, order: &[u32], raw: &[[u32; 2]]) -> Result<Vec<u32>> {
        let first = world.first_ids();
        raw.iter()
            .map(|&[slot, tri]| {
                if slot == BACKGROUND || slot == HOST {
                    return Ok(slot);
                }
                let object = *order.get(slot as usize).ok_or_else(|| {
                    Error::Device(format!("the id map holds instance slot {slot}"))
                })? as usize;
                let mesh = self.ids[world.objects[object].mesh];
                Ok(first[object] + self.store.file_triangle(mesh, tri)?)
            })
            .collect()
    }
}

/// One rendered frame on the CPU. Maps are row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// 8-bit sRGB RGBA image.
    pub rgba: Vec<u8>,
    /// Global id of the visible triangle per pixel: [`BACKGROUND`] where none is.
    pub ids: Vec<u32>,
    /// Depth in the standard convention: 0 at the near plane, 1 at the far plane and on
    /// background.
    pub depth: Vec<f32>,
    /// Pixels to the line that colours the pixel most (a drawn edge of the visible triangle,
    /// or, with outlines, an outline within reach; background pixels included): with lines
    /// of one width and no depth fade, the nearest line. `inf` where there is none.
    /// [`Method::Forward`] reports its interpolated altitudes as they come (NaN where they
    /// are NaN); [`Method::TwoPass`] measures no distance and reports 0 where it drew a line
    /// fragment, `inf` elsewhere.
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

/// Renders `shot` with `method` and reads back the image and all maps.
pub fn render(ctx: &GpuContext, shot: &Shot<'_>, method: Method) -> Result<Frame> {
    match method {
        Method::Raycast => crate::raycast::render_raycast(shot),
        Method::Deferred => render_deferred(ctx, shot),
        Method::Forward => render_forward(ctx, shot),
        Method::TwoPass => render_two_pass(ctx, shot),
    }
}

/// Renders `shot` with the deferred pass and reads back the image and all maps.
pub fn render_deferred(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Frame> {
    let up = Uploaded::new(ctx, shot.world)?;
    let pass = DeferredPass::new(&ctx.device, PassOptions::default())?.with_diagnostics();
    render_deferred_with(ctx, shot, &up, pass)
}

/// [`render_deferred`] with a pass and upload of the caller's (a pass with lowered limits,
/// or vertex pulling, say).
pub fn render_deferred_with(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    up: &Uploaded,
    pass: DeferredPass,
) -> Result<Frame> {
    render_deferred_on(ctx, shot, up, pass, Canvas::new(shot.size))
}

/// [`render_deferred_with`] onto a canvas of the caller's: over the host's depth buffer, say
/// (its pixels where the host is in front get the id [`HOST`]), or a window of the shot's
/// image (a tile: the frame is the window's size).
pub fn render_deferred_on(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    up: &Uploaded,
    mut pass: DeferredPass,
    canvas: Canvas<'_>,
) -> Result<Frame> {
    let device = &ctx.device;
    let window = canvas.window;
    if window.image != shot.size {
        return Err(Error::Misuse(format!(
            "the canvas is {window:?}, a window of another image than the shot's {}x{}",
            shot.size.0, shot.size.1
        )));
    }
    let scene = up.scene(shot.world, shot.view);
    let frame = pass.prepare(device, &up.store, &scene, shot.style, canvas)?;
    // RENDER_ATTACHMENT: the edge pass clears the background instead of writing it.
    let usage = wgpu::TextureUsages::STORAGE_BINDING
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::RENDER_ATTACHMENT;
    let output = texture_2d(
        device,
        "wirepass output",
        window.size,
        pass.output_format(),
        usage,
    );
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode(
        device,
        &mut encoder,
        &up.store,
        &frame,
        OutputTarget::Shaded(&view),
    )?;
    pass.encode_edges(
        device,
        &mut encoder,
        &up.store,
        &frame,
        OutputTarget::Diagnostic,
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.finish()?;
    let missing = || Error::Device("the frame has no diagnostic maps".into());
    let maps = (
        frame.resolved_id_texture().ok_or_else(missing)?,
        frame.diagnostic_texture().ok_or_else(missing)?,
    );
    let out = (window.size, up);
    read_frame(ctx, shot, out, frame.instance_order(), &output, maps)
}

/// Reads a rendered frame back: the 8-bit output, the `Rg32Uint` (slot, triangle) ids and
/// the diagnostic map, four f32 per pixel (`Rgba32Float`, or their bits in `Rgba32Uint` for
/// the forward passes; r = distance in pixels, ≥ 1e38 meaning none; g = reverse depth),
/// converted to [`Frame`]'s conventions.
fn read_frame(
    ctx: &GpuContext,
    shot: &Shot<'_>,
    (size, up): ((u32, u32), &Uploaded),
    order: &[u32],
    output: &wgpu::Texture,
    (ids, diagnostic): (&wgpu::Texture, &wgpu::Texture),
) -> Result<Frame> {
    let device = &ctx.device;
    let all = wgpu::TextureAspect::All;
    let rgba = read_texture(device, &ctx.queue, output, all)?;
    let ids = read_texture(device, &ctx.queue, ids, all)?;
    let diagnostic = read_texture(device, &ctx.queue, diagnostic, all)?;
    ctx.finish()?;
    let diagnostic: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&diagnostic);
    // (slot, triangle) pairs, from an Rg32Uint map or the first two channels of an
    // Rgba32Uint one.
    let per_pixel = ids.len() / diagnostic.len().max(1);
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&ids);
    let raw: Vec<[u32; 2]> = words
        .chunks_exact(per_pixel / 4)
        .map(|w| [w[0], w[1]])
        .collect();
    Ok(Frame {
        size,
        rgba,
        ids: up.global_ids(shot.world, order, &raw)?,
        // Reverse depth back to the standard convention.
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

/// Renders `shot` with the forward single-pass baseline and reads back the image and maps.
/// Its distance map is the interpolated altitudes' minimum (NaN where the method gives NaN).
pub fn render_forward(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Frame> {
    let device = &ctx.device;
    let up = Uploaded::new(ctx, shot.world)?;
    let options = PassOptions {
        output_format: FORWARD_OUTPUT,
        ..Default::default()
    };
    let mut pass = ForwardPass::new(device, options)?;
    let scene = up.scene(shot.world, shot.view);
    let frame = pass.prepare(device, &up.store, &scene, shot.style, shot.size)?;
    let output = forward_output(device, shot.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with_maps(device, &mut encoder, &up.store, &frame, &view)?;
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
pub fn render_two_pass(ctx: &GpuContext, shot: &Shot<'_>) -> Result<Frame> {
    let device = &ctx.device;
    let up = Uploaded::new(ctx, shot.world)?;
    let lines = up.edge_lines(ctx, shot.world)?;
    let options = PassOptions {
        output_format: FORWARD_OUTPUT,
        ..Default::default()
    };
    let mut pass = TwoPass::new(device, options)?;
    let scene = up.scene(shot.world, shot.view);
    let frame = pass.prepare(device, &up.store, &scene, shot.style, shot.size)?;
    let output = forward_output(device, shot.size);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with_maps(device, &mut encoder, (&up.store, &lines), &frame, &view)?;
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
    pub fn dump(&self, dir: &Path, view: &View) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.to_owned(),
            source,
        })?;
        let shape = [u64::from(self.size.1), u64::from(self.size.0)];
        write_npy(&dir.join("ids.npy"), &shape, &self.ids)?;
        write_npy(&dir.join("depth.npy"), &shape, &self.depth)?;
        write_npy(&dir.join("edge_distance.npy"), &shape, &self.edge_distance)?;
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
