//! The deferred pass's size-dependent targets, rebuilt only when the size changes: the id
//! and depth targets of the visibility pass, the trace pass's per-pixel lines, the edge
//! pass's list of pixels to refine, and, where asked for, the result for compositing and the
//! diagnostic maps.

use crate::error::{Error, Result};
use crate::style::linear_to_srgb;

/// A single-level 2D texture of `width × height`: the shape of every target and output here.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Checks an image size against the device: non-zero and within `max_texture_dimension_2d`.
pub fn check_size(device: &wgpu::Device, (width, height): (u32, u32)) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::InvalidSetting(format!(
            "image size {width}x{height} has a zero side"
        )));
    }
    let limit = device.limits().max_texture_dimension_2d;
    let side = width.max(height);
    if side > limit {
        return Err(Error::OverLimit {
            what: format!("image side of {width}x{height}"),
            value: u64::from(side),
            limit_name: "max_texture_dimension_2d",
            limit: u64::from(limit),
        });
    }
    Ok(())
}

/// The id target's first channel where no triangle is: background.
pub const BACKGROUND_ID: u32 = u32::MAX;
/// The id target's first channel where the host's own geometry is in front (with host
/// depth).
pub const HOST_ID: u32 = u32::MAX - 1;

/// Format of the id target: (instance slot, triangle of its mesh); [`BACKGROUND_ID`] in the
/// first channel marks background, [`HOST_ID`] host geometry in front.
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
/// Format of the depth target (reverse depth: 1 at the near plane, 0 at the far plane).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Format of the resolved ids the diagnostic output writes: (instance slot, triangle) in the
/// first two channels (a storage format every backend can write, which `Rg32Uint` is not).
pub const RESOLVED_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// Format of the host's own depth as the compute passes read it: the bits of the reverse
/// depth, `u32::MAX` where the host has no geometry (a 32-bit integer target renders on
/// every backend, a float one not).
pub const HOST_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Format of the diagnostic map: distance in pixels (r) and reverse depth (g).
pub const DIAGNOSTIC_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the result a frame composites into the host's render pass: premultiplied
/// linear RGBA.
pub const RESULT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Size of the header (indirect dispatch size x, y, z, then a count) of the traced-tile
/// and refine lists.
pub(crate) const LIST_HEADER: u64 = 16;

/// Tiles of one `classify_main` workgroup (edge_pass.wgsl), columns × rows: wide, because
/// the composite draws each row's run of drawn tiles within a workgroup as one quad.
pub(crate) const CLASSIFY_GROUP: (u32, u32) = (32, 2);
/// Where a composite run's length (less one) starts in its word (`list_composite_runs`):
/// above the tile column (at most 2 047 tiles, a 16 384-pixel output), below the row.
pub(crate) const COMPOSITE_RUN_SHIFT: u32 = 11;

// A run's length less one fills the bits between the column and the row (bit 16), and the
// column field holds any tile column of a 16 384-pixel output.
const _: () = assert!(CLASSIFY_GROUP.0 <= 1 << (16 - COMPOSITE_RUN_SHIFT));
const _: () = assert!(16_384 / 8 <= 1 << COMPOSITE_RUN_SHIFT);
/// Room in the trace pass's piece list: a piece per this many target pixels, and at least
/// MIN_PIECES (a piece is at most 2 px of an outline edge, 1 px on a GPU; the 1280×720 views
/// of a 200 k-triangle sphere and of stanford-bunny list 1 151 and 4 900 on lavapipe).
const PIXELS_PER_PIECE: u64 = 8;
const MIN_PIECES: u64 = 1 << 16;
/// Words per listed piece (trace.wgsl, `list_pieces`).
pub(crate) const PIECE_WORDS: u32 = 4;
const PIECE_BYTES: u64 = 4 * PIECE_WORDS as u64;

/// Entries of the trace pass's piece list for targets of `size` (before the binding limit
/// trims it).
pub(crate) fn piece_room(size: (u32, u32)) -> u64 {
    (u64::from(size.0) * u64::from(size.1) / PIXELS_PER_PIECE).max(MIN_PIECES)
}

#[derive(Clone)]
pub(crate) struct Targets {
    /// Size of the id and depth targets (the output plus the guard band).
    pub size: (u32, u32),
    /// Size of the output.
    pub output: (u32, u32),
    pub ids: wgpu::Texture,
    pub depth: wgpu::Texture,
    /// The trace buffer (`traced_tile_marks` in scene.wgsl): one u32 per target pixel,
    /// or two where instances differ in line colour, and as many more for hidden lines where
    /// they are drawn; a mark per output tile; the list of
    /// the tiles the lines reach, from byte `acc_tiles`; the phase tables of chains of drawn
    /// edges (`chain_phases` in trace.wgsl), from byte `acc_phases`; the trace pass's
    /// overflow list, from byte `acc_overflow`, and its piece list, from byte `acc_pieces`.
    pub acc: wgpu::Buffer,
    pub acc_tiles: u64,
    pub acc_phases: u64,
    pub acc_overflow: u64,
    pub acc_pieces: u64,
    /// What the targets were made for.
    spec: TargetSpec,
    /// The refine list: header, then one packed pixel per entry.
    pub work: wgpu::Buffer,
    /// The edge pass's list of 8×8 output tiles with work for its tile dispatch.
    pub tiles: wgpu::Buffer,
    /// With a result: the tiles the composite draws, after its indirect draw's arguments
    /// (`composite_rw` in edge_pass.wgsl).
    pub composite: Option<wgpu::Buffer>,
    pub result: Option<wgpu::Texture>,
    pub diagnostic: Option<(wgpu::Texture, wgpu::Texture)>,
    /// The host's depth, where the frame has one.
    pub host: Option<wgpu::Texture>,
    /// The seed depth of a multisampled host's depth (host_depth.wgsl).
    pub host_seed: Option<wgpu::Texture>,
}

/// What a set of targets must hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TargetSpec {
    pub size: (u32, u32),
    pub output: (u32, u32),
    pub acc_colors: bool,
    pub acc_hidden: bool,
    /// Words of phase tables.
    pub acc_phase_words: u32,
    /// Entries of the trace pass's overflow list.
    pub acc_overflow_room: u32,
    /// Entries of the trace pass's piece list ([`piece_room`]).
    pub acc_pieces: u64,
    pub result: bool,
    pub diagnostic: bool,
    pub host: bool,
    pub host_seed: bool,
}

impl Targets {
    pub fn spec(&self) -> TargetSpec {
        self.spec
    }

    #[cfg(feature = "diagnostics")]
    /// Pieces the trace pass's list has room for (trace.wgsl, `piece_room`).
    pub fn piece_room(&self) -> u32 {
        let room = (self.acc.size() - self.acc_pieces - LIST_HEADER) / PIECE_BYTES;
        u32::try_from(room).unwrap_or(u32::MAX)
    }

    /// Targets for `spec`, after checking them against the device's limits.
    pub fn new(device: &wgpu::Device, spec: TargetSpec) -> Result<Targets> {
        let (w, h) = spec.size;
        let pixels = u64::from(w) * u64::from(h);
        let binding = device.limits().max_storage_buffer_binding_size;
        let tiles = u64::from(spec.output.0.div_ceil(8)) * u64::from(spec.output.1.div_ceil(8));
        // The lines, the tile marks and list, the phase tables, the overflow list, then the
        // trace pass's piece list: its header, then room for a piece per PIXELS_PER_PIECE
        // target pixels (at least MIN_PIECES), less where the binding limit leaves less (the
        // overflow list takes the clusters whose pieces it has no room for).
        let words = (1 + u64::from(spec.acc_colors)) * (1 + u64::from(spec.acc_hidden));
        let acc_tiles = pixels * 4 * words + 4 * tiles;
        let acc_phases = acc_tiles + LIST_HEADER + 4 * tiles;
        let acc_overflow = acc_phases + 4 * u64::from(spec.acc_phase_words);
        let acc_pieces = acc_overflow + LIST_HEADER + 4 * u64::from(spec.acc_overflow_room);
        if acc_pieces + LIST_HEADER > binding {
            return Err(Error::OverLimit {
                what: format!("the trace buffer for a {w}x{h} target, in bytes"),
                value: acc_pieces + LIST_HEADER,
                limit_name: "max_storage_buffer_binding_size",
                limit: binding,
            });
        }
        let acc_bytes =
            (acc_pieces + LIST_HEADER + PIECE_BYTES * spec.acc_pieces).min(binding / 4 * 4);
        // The list: header, then one packed pixel per entry (a pixel is listed once).
        let work_bytes = LIST_HEADER + 4 * pixels;
        if work_bytes > binding {
            return Err(Error::OverLimit {
                what: format!(
                    "the refine list for a {}x{} output, in bytes",
                    spec.output.0, spec.output.1
                ),
                value: work_bytes,
                limit_name: "max_storage_buffer_binding_size",
                limit: binding,
            });
        }
        // The list: header, then one packed tile per entry.
        let tiles_bytes = LIST_HEADER + 4 * tiles;
        use wgpu::TextureUsages as U;
        let texture = |label, size, format, usage| texture_2d(device, label, size, format, usage);
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | usage,
                mapped_at_creation: false,
            })
        };
        Ok(Targets {
            size: spec.size,
            output: spec.output,
            ids: texture(
                "wirepass ids",
                spec.size,
                ID_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
            ),
            depth: texture(
                "wirepass depth",
                spec.size,
                DEPTH_FORMAT,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
            ),
            acc: buffer(
                "wirepass outline lines",
                acc_bytes,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC,
            ),
            acc_tiles,
            acc_phases,
            acc_overflow,
            acc_pieces,
            spec,
            // Read back by PreparedFrame::edge_work.
            work: buffer(
                "wirepass refine list",
                work_bytes,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC,
            ),
            tiles: buffer(
                "wirepass tile list",
                tiles_bytes,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC,
            ),
            composite: spec.result.then(|| {
                buffer(
                    "wirepass composite tiles",
                    tiles_bytes,
                    wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::VERTEX,
                )
            }),
            result: spec.result.then(|| {
                texture(
                    "wirepass result",
                    spec.output,
                    RESULT_FORMAT,
                    // Cleared where the edge pass lays down its background.
                    U::STORAGE_BINDING | U::TEXTURE_BINDING | U::RENDER_ATTACHMENT,
                )
            }),
            diagnostic: spec.diagnostic.then(|| {
                (
                    texture(
                        "wirepass diagnostic",
                        spec.output,
                        DIAGNOSTIC_FORMAT,
                        U::STORAGE_BINDING | U::COPY_SRC,
                    ),
                    texture(
                        "wirepass resolved ids",
                        spec.output,
                        RESOLVED_ID_FORMAT,
                        U::STORAGE_BINDING | U::COPY_SRC,
                    ),
                )
            }),
            host: spec.host.then(|| {
                texture(
                    "wirepass host depth",
                    spec.size,
                    HOST_FORMAT,
                    U::STORAGE_BINDING | U::TEXTURE_BINDING,
                )
            }),
            host_seed: spec.host_seed.then(|| {
                texture(
                    "wirepass host seed depth",
                    spec.size,
                    HOST_FORMAT,
                    U::STORAGE_BINDING | U::TEXTURE_BINDING,
                )
            }),
        })
    }

    /// GPU memory of these targets, in bytes.
    pub fn bytes(&self) -> u64 {
        let tex = |t: &wgpu::Texture| {
            let texel = t.format().block_copy_size(None).unwrap_or(4);
            u64::from(t.width()) * u64::from(t.height()) * u64::from(texel)
        };
        let mut n = tex(&self.ids) + 4 * u64::from(self.size.0) * u64::from(self.size.1);
        n += self.acc.size() + self.work.size() + self.tiles.size();
        if let Some(r) = &self.result {
            n += tex(r);
        }
        if let Some((d, i)) = &self.diagnostic {
            n += tex(d) + tex(i);
        }
        for h in self.host.iter().chain(&self.host_seed) {
            n += tex(h);
        }
        n
    }
}

/// A colour attachment cleared to `color` when the pass begins, and stored.
pub(crate) fn cleared(
    view: &wgpu::TextureView,
    color: wgpu::Color,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(color),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// The clear colour of an output of `format` for the linear background `bg`.
pub(crate) fn clear_color(format: wgpu::TextureFormat, bg: [f32; 4]) -> wgpu::Color {
    let encode = format == wgpu::TextureFormat::Rgba8Unorm;
    let c = |v: f32| f64::from(if encode { linear_to_srgb(v) } else { v });
    wgpu::Color {
        r: c(bg[0]),
        g: c(bg[1]),
        b: c(bg[2]),
        a: f64::from(bg[3]),
    }
}

/// Checks a storage texture the pass writes: format, size, usage, one sample, 2D.
pub(crate) fn check_storage_output(
    view: &wgpu::TextureView,
    format: wgpu::TextureFormat,
    size: (u32, u32),
    what: &str,
) -> Result<()> {
    let t = view.texture();
    if t.format() != format {
        return Err(Error::Misuse(format!(
            "{what} is {:?}, but the pass was built for {format:?}",
            t.format()
        )));
    }
    check_texture(t, size, wgpu::TextureUsages::STORAGE_BINDING, what)
}

/// Checks a texture the pass samples: size, usage, one sample, 2D, a float format.
pub(crate) fn check_sampled(view: &wgpu::TextureView, size: (u32, u32), what: &str) -> Result<()> {
    let t = view.texture();
    let float = matches!(
        t.format().sample_type(None, None),
        Some(wgpu::TextureSampleType::Float { .. })
    );
    if !float {
        return Err(Error::Misuse(format!(
            "{what} is {:?}, which is not a colour format read as float",
            t.format()
        )));
    }
    check_texture(t, size, wgpu::TextureUsages::TEXTURE_BINDING, what)
}

fn check_texture(
    t: &wgpu::Texture,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
    what: &str,
) -> Result<()> {
    if (t.width(), t.height()) != size {
        return Err(Error::Misuse(format!(
            "{what} is {}x{}, but the frame was prepared for {}x{}",
            t.width(),
            t.height(),
            size.0,
            size.1
        )));
    }
    if !t.usage().contains(usage) {
        return Err(Error::Misuse(format!(
            "{what} lacks the usage {usage:?} (it has {:?})",
            t.usage()
        )));
    }
    if t.sample_count() != 1 {
        return Err(Error::Misuse(format!(
            "{what} has {} samples; the pass writes single-sampled textures (draw into a \
             multisampled target with the render-pass entry instead)",
            t.sample_count()
        )));
    }
    if t.dimension() != wgpu::TextureDimension::D2 || t.depth_or_array_layers() != 1 {
        return Err(Error::Misuse(format!("{what} is not a single 2D texture")));
    }
    Ok(())
}
