//! A world drawn on the GPU into textures and read back as a [`Rendering`] (feature
//! `diagnostics`), without blocking: the tools' offline frames wait on these futures
//! natively, and the browser tests await them on the page's event loop. Everything goes
//! through the caller's device and queue.

use super::{Rendering, Shot, World, BACKGROUND, HOST};
use crate::camera::View;
use crate::error::{Error, Result};
use crate::gpu::{
    read_texture_async, texture_2d, Canvas, DeferredPass, EdgeLines, EncodeOptions, MeshId,
    MeshStore, OutputTarget, PreparedFrame,
};
use crate::scene::{Instance, Scene};

/// A world uploaded to the GPU: its meshes in one store.
pub struct Uploaded {
    /// The store.
    pub store: MeshStore,
    /// The store's id of each world mesh.
    pub ids: Vec<MeshId>,
}

impl Uploaded {
    /// Uploads every mesh of `world` once.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, world: &World) -> Result<Uploaded> {
        world.validate()?;
        let mut store = MeshStore::new(device);
        let ids = world
            .meshes
            .iter()
            .map(|m| store.insert(device, queue, &m.mesh, m.edges))
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
        Scene::new(view, instances).with_sections(world.sections.clone())
    }

    /// The two-pass method's edge lists of every mesh.
    pub fn edge_lines(&self, device: &wgpu::Device, world: &World) -> Result<EdgeLines> {
        let mut lines = EdgeLines::new();
        for (m, &id) in world.meshes.iter().zip(&self.ids) {
            lines.insert(device, &self.store, id, &m.mesh, m.edges)?;
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

/// Renders `shot` with the deferred pass (made `with_diagnostics`) onto `canvas` (the
/// shot's whole image, a region of it, or over the host's depth) into a storage texture,
/// and reads back the image and all maps: what
/// [`tools::offline::draw_deferred_on`](crate::tools::offline::draw_deferred_on) waits on.
pub async fn draw_deferred_on_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    shot: &Shot<'_>,
    up: &Uploaded,
    pass: &mut DeferredPass,
    canvas: Canvas<'_>,
) -> Result<Rendering> {
    let (frame, output) = encode_shaded(device, queue, shot, up, pass, canvas)?;
    read_deferred(device, queue, shot, up, pass, &frame, &output).await
}

/// Prepares `shot` on `canvas` and encodes it with `pass` into a new storage texture of the
/// canvas's size (`OutputTarget::Shaded`), and submits: the frame and its image.
pub fn encode_shaded(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    shot: &Shot<'_>,
    up: &Uploaded,
    pass: &mut DeferredPass,
    canvas: Canvas<'_>,
) -> Result<(PreparedFrame, wgpu::Texture)> {
    let (frame, output) = prepare_shaded(device, shot, up, pass, canvas)?;
    let view = output.create_view(&Default::default());
    encode_prepared(device, queue, up, pass, &frame, &view)?;
    Ok((frame, output))
}

/// The first half of [`encode_shaded`]: prepares `shot` on `canvas` and makes the storage
/// texture it is drawn into.
pub fn prepare_shaded(
    device: &wgpu::Device,
    shot: &Shot<'_>,
    up: &Uploaded,
    pass: &mut DeferredPass,
    canvas: Canvas<'_>,
) -> Result<(PreparedFrame, wgpu::Texture)> {
    let region = canvas.region;
    if region.image != shot.size {
        return Err(Error::Misuse(format!(
            "the canvas is {region:?}, a region of another image than the shot's {}x{}",
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
        region.size,
        pass.output_format(),
        usage,
    );
    Ok((frame, output))
}

/// The second half of [`encode_shaded`]: encodes a prepared frame into `view` and submits.
pub fn encode_prepared(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    up: &Uploaded,
    pass: &DeferredPass,
    frame: &PreparedFrame,
    view: &wgpu::TextureView,
) -> Result<()> {
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode(
        device,
        &mut encoder,
        &up.store,
        frame,
        OutputTarget::Shaded(view),
    )?;
    queue.submit([encoder.finish()]);
    Ok(())
}

/// Reads back a deferred frame that `pass` has encoded and submitted, wherever its output
/// went: `output` (a storage texture, or the host's target the frame was rendered into),
/// and the frame's id and distance maps, which this encodes over the frame's ids.
pub async fn read_deferred(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    shot: &Shot<'_>,
    up: &Uploaded,
    pass: &mut DeferredPass,
    frame: &PreparedFrame,
    output: &wgpu::Texture,
) -> Result<Rendering> {
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_with(
        device,
        &mut encoder,
        &up.store,
        frame,
        OutputTarget::Diagnostic,
        EncodeOptions {
            reuse_ids: true,
            ..Default::default()
        },
    )?;
    queue.submit([encoder.finish()]);
    let missing = || Error::Device("the frame has no diagnostic maps".into());
    let maps = (
        frame.resolved_id_texture().ok_or_else(missing)?,
        frame.diagnostic_texture().ok_or_else(missing)?,
    );
    let size = (output.width(), output.height());
    read_rendering(
        device,
        queue,
        shot,
        (size, up),
        frame.instance_order(),
        output,
        maps,
    )
    .await
}

/// Reads a rendered frame back: the 8-bit output, the `Rg32Uint` (slot, triangle) ids and
/// the diagnostic map, four f32 per pixel (`Rgba32Float`, or their bits in `Rgba32Uint` for
/// the forward passes; r = distance in pixels, ≥ 1e38 meaning none; g = reverse depth; b =
/// distance to the hidden line, ≥ 1e38 meaning none; a = the line's class, as the deferred
/// pass writes it), converted to [`Rendering`]'s conventions.
pub async fn read_rendering(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    shot: &Shot<'_>,
    (size, up): ((u32, u32), &Uploaded),
    order: &[u32],
    output: &wgpu::Texture,
    (ids, diagnostic): (&wgpu::Texture, &wgpu::Texture),
) -> Result<Rendering> {
    let all = wgpu::TextureAspect::All;
    let rgba = read_texture_async(device, queue, output, all).await?;
    let ids = read_texture_async(device, queue, ids, all).await?;
    let diagnostic = read_texture_async(device, queue, diagnostic, all).await?;
    let diagnostic: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&diagnostic);
    // (slot, triangle) pairs, from an Rg32Uint map or the first two channels of an
    // Rgba32Uint one.
    let per_pixel = ids.len() / diagnostic.len().max(1);
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&ids);
    let raw: Vec<[u32; 2]> = words
        .chunks_exact(per_pixel / 4)
        .map(|w| [w[0], w[1]])
        .collect();
    let mut r = maps_rendering(shot, (size, up), order, rgba, &raw, &diagnostic)?;
    // The a channel: 0..=5 as `LineClass`.
    r.line_class = diagnostic
        .iter()
        .map(|t| t[3].clamp(0.0, 5.0) as u8)
        .collect();
    Ok(r)
}

/// A frame read back as the forward passes' maps hold it (the 8-bit output, (slot,
/// triangle) ids, and per pixel the distance, ≥ 1e38 meaning none, and the reverse depth),
/// converted to [`Rendering`]'s conventions.
pub fn maps_rendering(
    shot: &Shot<'_>,
    (size, up): ((u32, u32), &Uploaded),
    order: &[u32],
    rgba: Vec<u8>,
    raw: &[[u32; 2]],
    diagnostic: &[[f32; 4]],
) -> Result<Rendering> {
    Ok(Rendering {
        size,
        rgba,
        ids: up.global_ids(shot.world, order, raw)?,
        // Reverse depth back to the standard convention.
        depth: diagnostic
            .iter()
            .map(|t| (1.0 - f64::from(t[1])) as f32)
            .collect(),
        edge_distance: diagnostic
            .iter()
            .map(|t| if t[0] >= 1e38 { f32::INFINITY } else { t[0] })
            .collect(),
        hidden_distance: diagnostic
            .iter()
            .map(|t| if t[2] >= 1e38 { f32::INFINITY } else { t[2] })
            .collect(),
        line_class: Vec::new(),
    })
}
