//! What every pass reads each frame: the `Frame` uniforms and the `Instance` records of
//! `common.wgsl`, built in f64 from the scene, the style and the size, and the list of
//! instanced draws. One place for all passes, so deferred, forward and two-pass draw the
//! same scene the same way.

use super::canvas::Region;
use super::instance_crossings::{
    crossing_box, union_box, PairCache, PairCrossing, CROSSING_BAND, NO_BOX, WHOLE_IMAGE,
};
use super::mesh_store::{MeshRecord, MeshStore, StoreBuffers};
use crate::camera::View;
use crate::error::{Error, Result};
use crate::scene::{Scene, MAX_SECTIONS};
use crate::style::Style;
use glam::{DMat3, DMat4, DVec3, DVec4};
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// Mirror of WGSL `struct Frame`; field order and padding match it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FrameUniforms {
    image_size: [f32; 2],
    target_origin: [f32; 2],
    target_size: [f32; 2],
    output_offset: [f32; 2],
    output_size: [f32; 2],
    fade: [f32; 2],
    crop: [f32; 4],
    light_dir: [f32; 4],
    fill_color: [f32; 4],
    background: [f32; 4],
    ambient: f32,
    instances: u32,
    vertex_split: u32,
    triangle_split: u32,
    clusters: u32,
    host_depth: u32,
    overflow_room: u32,
    fill_opacity: f32,
    hidden_color: [f32; 4],
    chain_work: [u32; 4],
    section_color: [f32; 4],
    sections: [[f32; 4]; MAX_SECTIONS],
    sections_on: u32,
    section_width: f32,
    intersections: u32,
    intersection_width: f32,
    section_line_color: [f32; 4],
    intersection_line_color: [f32; 4],
    near_w: f32,
    pad: [f32; 3],
}

/// Mirror of WGSL `struct Instance`; field order and padding match it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct InstanceRecord {
    clip: [[f32; 4]; 4],
    depth_row: [f32; 4],
    eye: [f32; 4],
    fade_row: [f32; 4],
    normal_x: [f32; 3],
    hidden_width: f32,
    normal_y: [f32; 3],
    hidden_dash: f32,
    normal_z: [f32; 3],
    hidden_period: f32,
    wire_color: [f32; 4],
    fill_color: [f32; 4],
    line_width: f32,
    flags: u32,
    vertex_base: u32,
    triangle_base: u32,
    triangles: u32,
    cluster_base: u32,
    cluster_first: u32,
    index: u32,
    outline_color: [u32; 2],
    hidden_color: [u32; 2],
    outline_width: f32,
    phase_table: u32,
    table_log2: u32,
    _pad: u32,
    /// The visible lines' patterns, (dash, period) in pixels (period 0: solid): the drawn
    /// edges', then the outline's.
    edge_pattern: [f32; 2],
    outline_pattern: [f32; 2],
    /// With [`INSTANCE_CROSSED`], the box of image pixels (min x, min y, max x, max y)
    /// where its lines are drawn the crossing way ([`Crossings`]).
    cross_box: [f32; 4],
}

/// `Instance.flags`: the instance's edges are drawn.
pub(crate) const INSTANCE_EDGES: u32 = 1;
/// `Instance.flags`: the instance's outline is drawn.
pub(crate) const INSTANCE_OUTLINES: u32 = 2;
/// `Instance.flags`: the instance's hidden lines are drawn.
pub(crate) const INSTANCE_HIDDEN: u32 = 4;
/// `Instance.flags`: the parts of its lines the host's depth hides are drawn as hidden.
pub(crate) const INSTANCE_BEHIND_HOST: u32 = 8;
/// `Instance.flags`: the hidden parts of its drawn edges are drawn, not only its outline's.
pub(crate) const INSTANCE_HIDDEN_EDGES: u32 = 16;
/// `Instance.flags`: its drawn edges are patterned or cut by section planes, so the trace
/// pass draws them (their visible runs) and the edge pass leaves them.
pub(crate) const INSTANCE_LISTED_EDGES: u32 = 32;
/// `Instance.flags`: it has a phase table (`chain_phases`).
pub(crate) const INSTANCE_PHASES: u32 = 64;
/// `Instance.flags`: another instance passes through it (`instance_pair_crossings`), so
/// within its `cross_box` the trace pass draws its edges and tests its lines' visibility
/// over a wider window ([`CROSSING_BAND`]), and the edge pass leaves its edges.
pub(crate) const INSTANCE_CROSSED: u32 = 128;
/// `Instance.flags`: its outline, or the outline's hidden parts, are patterned, so its
/// outline edges join the frame's outline chains (`outline_chain_ends` in trace.wgsl).
pub(crate) const INSTANCE_OUTLINE_PHASES: u32 = 256;
/// Words of the trace buffer's outline chain area per edge of its capacity (after a header
/// of 4): a record, two looks back, four vertex buckets and two edge slots of 8, 6, 6, 16
/// and 2 words (`outline_area` in trace.wgsl).
pub(crate) const OUTLINE_CHAIN_WORDS: u32 = 38;
/// The outline chain capacity of a frame: one edge per `OUTLINE_CHAIN_SHARE` triangles of
/// the instances that chain their outlines (a smooth mesh's outline has far fewer: about
/// 2√n edges; a noisy scan's, a few per cent of its edges), within these bounds. The area
/// is cleared each frame: 152 bytes per edge of capacity, at most 19.9 MB.
const OUTLINE_CHAIN_SHARE: u64 = 32;
const OUTLINE_CHAIN_CAPACITY: (u32, u32) = (1 << 10, 1 << 17);

/// A linear RGBA colour as WGSL's `unpack2x16float` reads it from two words.
fn pack_color(c: [f32; 4]) -> [u32; 2] {
    let h = |v: f32| u32::from(half::f16::from_f32(v).to_bits());
    [h(c[0]) | h(c[1]) << 16, h(c[2]) | h(c[3]) << 16]
}

/// Instance records a uniform buffer holds (`scene.wgsl`, `UNIFORM_INSTANCES`): frames with
/// up to this many bind them as uniforms, which software rasterizers read many times faster
/// than storage buffers: as many as fit in 64 KiB, `Limits::default()`'s largest uniform
/// binding.
pub(crate) const UNIFORM_INSTANCE_CAPACITY: u32 = (65536 / INSTANCE_BYTES) as u32;

/// Byte offset of `InstanceRecord::index`, read as an instance-rate vertex attribute.
pub(crate) const INSTANCE_INDEX_OFFSET: u64 = 220;
/// Byte offsets of `vertex_base` and `triangle_base`.
pub(crate) const INSTANCE_BASES_OFFSET: u64 = 200;
/// Size of an `InstanceRecord`.
pub(crate) const INSTANCE_BYTES: u64 = std::mem::size_of::<InstanceRecord>() as u64;

impl FrameUniforms {
    /// The background colour (linear RGBA).
    pub fn background(&self) -> [f32; 4] {
        self.background
    }

    /// Instances in the frame.
    pub fn instances(&self) -> u32 {
        self.instances
    }
}

#[cfg(test)]
impl InstanceRecord {
    /// The f32 mesh-local → clip matrix the GPU uses (rows x, y, near, w).
    pub fn clip(&self) -> glam::Mat4 {
        glam::Mat4::from_cols_array_2d(&self.clip)
    }
}

/// Pixels of guard band the deferred pass keeps around its output, from the widest line of
/// the scene: lines whose edges lie just outside the output reach into it, the trace pass
/// tests their visibility against the ids one pixel around each point (a few more in a
/// frame where surfaces may cross, which adds [`CROSSING_BAND`]), and the coverage
/// search reads the ids around each pixel. So the output is the same whether the image is
/// drawn whole or as tiles ([`Region`]). (An output within a band of the device's largest
/// texture side gets what room is left.)
pub fn guard_band(scene: &Scene<'_>, style: &Style) -> u32 {
    let widest = scene
        .instances
        .iter()
        .flat_map(|i| {
            let hidden = i.style.hidden_in(style).map(|h| h.width);
            [
                i.style.line_width,
                Some(i.style.outline_width_in(style)),
                hidden,
            ]
        })
        .flatten()
        .chain(style.outline_width)
        .chain((!scene.sections.is_empty()).then(|| style.section_width()))
        .chain(style.intersection_lines.then(|| style.intersection_width()))
        .fold(style.line_width, f32::max);
    (crate::style::line_reach(f64::from(widest)).ceil() as u32).saturating_add(2)
}

/// One instanced draw: a mesh's triangles, for a run of consecutive instance slots.
#[derive(Clone, Debug)]
pub(crate) struct DrawGroup {
    pub mesh: super::MeshId,
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    pub triangles: u32,
    pub instances: std::ops::Range<u32>,
}

/// A frame's uniforms, instance records and draw list, on the GPU.
pub(crate) struct FrameData {
    pub uniforms: FrameUniforms,
    pub frame: wgpu::Buffer,
    pub instances: wgpu::Buffer,
    pub draws: Vec<DrawGroup>,
    /// For each instance slot, the scene's instance index (slots group instances by mesh).
    pub order: Vec<u32>,
    pub store: StoreBuffers,
    pub store_version: (u32, u64),
    pub region: Region,
    /// Pixels of guard band around the output in the targets.
    pub guard: u32,
    /// Whether the trace pass runs: an instance draws outlines, or edges of a mesh with
    /// large patches, or a hidden, listed, cut or intersection line is drawn.
    pub traced: bool,
    /// Whether an instance draws the edges of a mesh with small patches (the edge pass then
    /// searches them).
    pub patches: bool,
    /// Whether hidden lines are drawn (by the trace pass, with `traced`).
    pub hidden: bool,
    /// Whether a line is dashed or dotted (the trace pass then finds the patterns'
    /// positions along chains and draws dashes, with `traced`).
    pub patterns: bool,
    /// Whether instances differ in line colour (the trace pass then keeps, per pixel,
    /// which instance's line it holds).
    pub mixed_colors: bool,
    /// Whether surfaces may cross: a mesh passes through itself, instances may pass through
    /// each other, or the frame draws intersection lines (the trace pass then looks wider
    /// round its lines' points).
    pub crossing: bool,
    /// The instances whose chains' pattern positions `chain_phases` finds ([`ChainWork`]),
    /// at least one (empty) entry, for binding.
    pub chain_work: wgpu::Buffer,
    /// The frame's intersection segments ([`IntersectionRecord`]), at least one (empty)
    /// record, for binding.
    pub intersections: wgpu::Buffer,
    /// Whether the instance buffer can be bound as a uniform array of
    /// [`UNIFORM_INSTANCE_CAPACITY`] records.
    pub uniform_instances: bool,
}

/// What a frame's GPU data is made from, on the CPU: the uniforms, one record per instance
/// slot and the draw list. The deferred pass and the baselines upload it as [`FrameData`];
/// the tools' OpenGL baseline binds the same bytes.
pub(crate) struct FrameRecords {
    pub uniforms: FrameUniforms,
    pub records: Vec<InstanceRecord>,
    pub draws: Vec<DrawGroup>,
    /// For each instance slot, the scene's instance index (slots group instances by mesh).
    pub order: Vec<u32>,
    pub store: StoreBuffers,
    pub region: Region,
    /// Pixels of guard band around the output in the targets.
    pub guard: u32,
    pub traced: bool,
    pub patches: bool,
    pub hidden: bool,
    pub patterns: bool,
    pub mixed_colors: bool,
    pub crossing: bool,
    pub chain_work: Vec<ChainWork>,
    pub intersections: Vec<IntersectionRecord>,
}

/// One intersection segment of a frame (`struct Intersection` in trace.wgsl): where
/// triangle `t` of the instance in `slot` crosses triangle `u` of the instance in `other`
/// (the same one where a mesh passes through itself), its ends `a`, `b` in the first
/// instance's local (stored) coordinates.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct IntersectionRecord {
    a: [f32; 3],
    slot: u32,
    b: [f32; 3],
    t: u32,
    u: u32,
    other: u32,
    _pad: [u32; 2],
}

/// An instance whose drawn edges' chains carry a dashed or dotted hidden-line pattern: its
/// slot, its mesh's first chain record, its number of chains, and the chains of the
/// instances before it in the list (`chain_phases` in trace.wgsl finds its chain by it).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ChainWork {
    slot: u32,
    chain_base: u32,
    chains: u32,
    before: u32,
}

impl FrameRecords {
    /// Validates the scene, style and region against the device and the store, and builds
    /// the frame's records; with `guarded`, the targets have a guard band ([`guard_band`]).
    /// The intersection lines of instance pairs are kept in `pairs` from frame to frame,
    /// where the caller keeps one (the deferred pass does).
    pub fn new(
        device: &wgpu::Device,
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        region: Region,
        guarded: bool,
        pairs: Option<&mut PairCache>,
    ) -> Result<FrameRecords> {
        region.validate()?;
        scene.validate()?;
        style.validate()?;
        super::targets::check_size(device, region.size)?;
        // Where the device's largest texture leaves no room for the whole band, a narrower one.
        let room = device.limits().max_texture_dimension_2d - region.size.0.max(region.size.1);
        let crossings = Crossings::new(store, scene, style, region.image, pairs)?;
        let guard = if guarded {
            let band = guard_band(scene, style);
            let band = band + if crossings.any { CROSSING_BAND } else { 0 };
            band.min(room / 2)
        } else {
            0
        };
        let target = (region.size.0 + 2 * guard, region.size.1 + 2 * guard);
        let order = draw_order(store, scene)?;

        let view = scene.view;
        let look = (view.eye(), view.view_depth_row());
        let light = light_world_dir(&view, style);
        let mut records = Vec::with_capacity(order.len());
        let mut hidden_styles = Vec::with_capacity(order.len());
        let mut needs = Needs::default();
        let mut clusters = 0u64;
        for (slot, &i) in order.iter().enumerate() {
            let instance = &scene.instances[i as usize];
            let mesh = store.record(instance.mesh)?;
            let placed = (slot as u32, clusters as u32);
            let crossed = crossings.instances[i as usize];
            let (mut record, hidden, asks) =
                instance_entry(scene, style, look, instance, mesh, crossed, placed);
            record.cross_box = crossings.boxes[i as usize];
            needs = needs.and(asks);
            records.push(record);
            hidden_styles.push(hidden);
            clusters += u64::from(mesh.clusters);
        }
        let draws = draw_groups(store, scene, &order)?;
        let clusters = u32::try_from(clusters)
            .map_err(|_| Error::InvalidScene(format!("{clusters} clusters over all instances")))?;
        let hidden_color = hidden_styles.iter().flatten().map(|h| h.color).next();
        let (chain_work, phase_words, chains) = phase_tables(store, scene, &order, &mut records)?;
        let outline_chains = outline_chain_capacity(store, scene, &order, &mut records)?;
        let phase_words = if chain_work.is_empty() {
            0
        } else {
            phase_words
        };
        let phase_words = outline_chains
            .map(|c| u64::from(phase_words) + 4 + u64::from(OUTLINE_CHAIN_WORDS) * u64::from(c))
            .unwrap_or(u64::from(phase_words));
        let phase_words = u32::try_from(phase_words).map_err(|_| too_many_chains())?;
        let intersections = if style.intersection_lines {
            intersection_records(store, scene, &order, &crossings.pairs)?
        } else {
            Vec::new()
        };
        let intersections_count = u32::try_from(intersections.len()).map_err(|_| {
            Error::InvalidScene(format!(
                "{} intersection segments over all instances",
                intersections.len()
            ))
        })?;
        needs.traced |= !intersections.is_empty();
        // The edge pass must know whose line, and of which class, each trace-pass pixel
        // holds where colours differ between instances or between an outline and its edges.
        // Likewise for hidden lines whose colours differ between instances.
        let mixed_colors = !scene.sections.is_empty()
            || !intersections.is_empty()
            || records
                .windows(2)
                .any(|w| w[0].wire_color != w[1].wire_color)
            || records
                .iter()
                .any(|r| r.outline_color != pack_color(r.wire_color))
            || hidden_styles
                .iter()
                .flatten()
                .any(|h| Some(h.color) != hidden_color);
        let hidden = hidden_color.is_some();

        let buffers = store.buffers();
        let (gx, gy) = (guard as f64, guard as f64);
        let (iw, ih) = (f64::from(region.image.0), f64::from(region.image.1));
        let (tw, th) = (f64::from(target.0), f64::from(target.1));
        // Clip → target NDC: target pixel (0, 0) is image pixel origin − guard.
        let (ox, oy) = (
            f64::from(region.origin.0) - gx,
            f64::from(region.origin.1) - gy,
        );
        let crop = [
            iw / tw,
            ih / th,
            (iw - 2.0 * ox) / tw - 1.0,
            1.0 - (ih - 2.0 * oy) / th,
        ];
        let uniforms = FrameUniforms {
            image_size: [iw as f32, ih as f32],
            target_origin: [ox as f32, oy as f32],
            target_size: [target.0 as f32, target.1 as f32],
            output_offset: [guard as f32; 2],
            output_size: [region.size.0 as f32, region.size.1 as f32],
            fade: style.fade_range(),
            crop: crop.map(|v| v as f32),
            light_dir: light.as_vec3().extend(0.0).to_array(),
            fill_color: style.fill_color.0,
            background: style.background.0,
            ambient: style.ambient,
            instances: records.len() as u32,
            vertex_split: buffers.split.vertices,
            triangle_split: buffers.split.triangles,
            clusters,
            host_depth: 0,
            overflow_room: overflow_room(clusters, intersections_count),
            fill_opacity: style.fill_opacity,
            hidden_color: hidden_color.map_or([0.0; 4], |c| c.0),
            chain_work: [
                phase_words,
                chains,
                chain_work.len() as u32,
                outline_chains.unwrap_or(0),
            ],
            section_color: style.section_color.0,
            sections: section_planes(&view, &scene.sections)?,
            sections_on: u32::from(!scene.sections.is_empty()),
            section_width: style.section_width(),
            intersections: intersections_count,
            intersection_width: style.intersection_width(),
            section_line_color: style.section_line_color.0,
            intersection_line_color: style.intersection_line_color.0,
            near_w: view.near_plane_w().unwrap_or(0.0) as f32,
            pad: [0.0; 3],
        };
        Ok(FrameRecords {
            uniforms,
            records,
            draws,
            order,
            store: buffers,
            region,
            guard,
            traced: needs.traced,
            patches: needs.patches,
            hidden,
            patterns: needs.patterns,
            mixed_colors,
            crossing: crossings.any || intersections_count > 0,
            chain_work,
            intersections,
        })
    }
}

/// Which instances cross others, and how: what decides how widely the frame tests its
/// lines' visibility.
struct Crossings {
    /// The intersection lines of the instance pairs whose bounds meet.
    pairs: PairCrossings,
    /// Per instance (scene order): whether it draws its lines the wide way, because it
    /// passes through another where it draws outlines (without, a line may reach past the
    /// silhouette only so), or it or the other draws hidden lines.
    instances: Vec<bool>,
    /// Per instance: the image pixels where it does (`InstanceRecord::cross_box`): round
    /// the crossings' image, or everywhere where hidden lines are drawn.
    boxes: Vec<[f32; 4]>,
    /// Whether any instance does, or any mesh passes through itself.
    any: bool,
}

impl Crossings {
    /// `image`: the size of the image the view projects onto.
    fn new(
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        image: (u32, u32),
        pairs: Option<&mut PairCache>,
    ) -> Result<Crossings> {
        let mut placed = Vec::with_capacity(scene.instances.len());
        let mut any = false;
        for i in scene.instances.iter() {
            let record = store.record(i.mesh)?;
            placed.push((record.bounds, i.transform));
            any |= record.lines.crossed;
        }
        let outlines_of =
            |i: usize| -> bool { scene.instances[i].style.outlines.unwrap_or(style.outlines) };
        let wanted = |(a, b)| style.intersection_lines || outlines_of(a) || outlines_of(b);
        let pairs = instance_pair_crossings(store, scene, &placed, wanted, pairs)?;
        // Where either draws hidden lines, a pair whose bounds meet is drawn the wide way
        // whether or not it crosses: the narrow window can miss the first fraction of a pixel
        // of a hidden run where the other's surface in front of it ends beside it.
        let hides = |i: usize| scene.instances[i].style.hidden_in(style).is_some();
        let mut instances = vec![false; scene.instances.len()];
        let mut boxes = vec![NO_BOX; scene.instances.len()];
        for ((a, b), found) in &pairs {
            if !found.is_empty() || hides(*a) || hides(*b) {
                instances[*a] = outlines_of(*a);
                instances[*b] = outlines_of(*b);
                let area = if hides(*a) || hides(*b) {
                    WHOLE_IMAGE
                } else {
                    let first = &scene.instances[*a];
                    let model = first.transform * store.record(first.mesh)?.local_to_mesh();
                    crossing_box(&scene.view, image, model, found)
                };
                for i in [*a, *b] {
                    boxes[i] = union_box(boxes[i], area);
                }
            }
        }
        any |= instances.contains(&true);
        Ok(Crossings {
            pairs,
            instances,
            boxes,
            any,
        })
    }
}

/// The scene's instances grouped by mesh (stable, so each mesh's instances keep the
/// scene's order), so that every mesh is one instanced draw: slot → instance.
fn draw_order(store: &MeshStore, scene: &Scene<'_>) -> Result<Vec<u32>> {
    let mut order: Vec<u32> = (0..scene.instances.len() as u32).collect();
    let keys: Vec<(u32, u32)> = scene
        .instances
        .iter()
        .map(|i| {
            store
                .record(i.mesh)
                .map(|r| (r.triangle_base, r.vertex_base))
        })
        .collect::<Result<_>>()?;
    order.sort_by_key(|&i| keys[i as usize]);
    Ok(order)
}

/// One instanced draw per run of slots of one mesh.
fn draw_groups(store: &MeshStore, scene: &Scene<'_>, order: &[u32]) -> Result<Vec<DrawGroup>> {
    let mut draws: Vec<DrawGroup> = Vec::new();
    for (slot, &i) in order.iter().enumerate() {
        let id = scene.instances[i as usize].mesh;
        let mesh = store.record(id)?;
        let slot = slot as u32;
        match draws.last_mut() {
            Some(d)
                if d.first_index == 3 * mesh.triangle_base
                    && d.base_vertex == mesh.vertex_base as i32 =>
            {
                d.instances.end = slot + 1;
            }
            _ => draws.push(DrawGroup {
                mesh: id,
                first_index: 3 * mesh.triangle_base,
                index_count: 3 * mesh.triangles,
                base_vertex: mesh.vertex_base as i32,
                triangles: mesh.triangles,
                instances: slot..slot + 1,
            }),
        }
    }
    Ok(draws)
}

/// Which of the frame's optional passes and modules its instances need.
#[derive(Clone, Copy, Debug, Default)]
struct Needs {
    /// The trace pass: outlines, edges of large patches, hidden, listed and cut lines.
    traced: bool,
    /// The edge pass's small-patch lookups.
    patches: bool,
    /// Dash patterns.
    patterns: bool,
}

impl Needs {
    fn and(self, other: Needs) -> Needs {
        Needs {
            traced: self.traced || other.traced,
            patches: self.patches || other.patches,
            patterns: self.patterns || other.patterns,
        }
    }
}

/// One instance's record in `slot` (its clusters from `cluster_first` in the frame's
/// list), its hidden lines, and what it needs of the frame's passes. `crossed`: it passes
/// through another instance ([`Crossings`]).
fn instance_entry(
    scene: &Scene<'_>,
    style: &Style,
    look: (DVec4, DVec4),
    instance: &crate::scene::Instance,
    mesh: &MeshRecord,
    crossed: bool,
    (slot, cluster_first): (u32, u32),
) -> (InstanceRecord, Option<crate::HiddenLines>, Needs) {
    let s = &instance.style;
    let sections = !scene.sections.is_empty();
    let draws_outline = s.outlines.unwrap_or(style.outlines);
    let draws_edges = s.edges.unwrap_or(true);
    // Hidden lines are drawn by the trace pass, from every drawn line in view; so are
    // patterned edges.
    let hidden = s.hidden_in(style).filter(|_| draws_outline || draws_edges);
    let edge_pattern = s.edge_pattern_in(style).dash_period();
    let outline_pattern = s.outline_pattern_in(style).dash_period();
    let patterned_edges = draws_edges && edge_pattern[1] > 0.0;
    // Section planes cut the drawn edges short: the trace pass draws them where they are
    // visible (and, where another instance crosses this one, those near the crossings).
    let listed_edges = patterned_edges || (draws_edges && sections);
    let needs = Needs {
        // The trace pass also draws the edges of large patches, and cut lines: every
        // instance has them where a section plane crosses it.
        traced: draws_outline
            || (draws_edges && mesh.lines.splat)
            || hidden.is_some()
            || listed_edges
            || sections,
        patches: draws_edges && mesh.lines.small_patches,
        patterns: patterned_edges
            || (draws_outline && outline_pattern[1] > 0.0)
            || hidden.is_some_and(|h| h.pattern.dash_period()[1] > 0.0),
    };
    let flag = |on: bool, bit: u32| if on { bit } else { 0 };
    let flags = flag(draws_edges, INSTANCE_EDGES)
        | flag(draws_outline, INSTANCE_OUTLINES)
        | flag(hidden.is_some(), INSTANCE_HIDDEN)
        | flag(hidden.is_some_and(|h| h.behind_host), INSTANCE_BEHIND_HOST)
        | flag(hidden.is_some_and(|h| h.edges), INSTANCE_HIDDEN_EDGES)
        | flag(listed_edges, INSTANCE_LISTED_EDGES)
        | flag(crossed, INSTANCE_CROSSED);
    let colors = [
        s.wire_color.unwrap_or(style.wire_color).0,
        s.fill_color.unwrap_or(style.fill_color).0,
        s.outline_color_in(style).0,
    ];
    let widths = [
        s.line_width.unwrap_or(style.line_width),
        s.outline_width_in(style),
    ];
    let record = instance_record(
        &scene.view,
        look,
        instance.transform,
        mesh,
        (colors, widths, flags),
        (slot, cluster_first),
    );
    let record = InstanceRecord {
        edge_pattern,
        outline_pattern,
        ..with_hidden(record, hidden)
    };
    (record, hidden, needs)
}

/// The section planes as coefficients of the points of every instance's clip space (rows
/// x, y, near, w of `View::clip_rows`): a world plane p composed with the inverse of the
/// world → clip map, in f64. Unused planes are 0, which cut nothing.
fn section_planes(
    view: &View,
    sections: &[crate::SectionPlane],
) -> Result<[[f32; 4]; MAX_SECTIONS]> {
    let mut out = [[0.0; 4]; MAX_SECTIONS];
    if sections.is_empty() {
        return Ok(out);
    }
    let clip = view.clip_rows(DMat4::IDENTITY).clip;
    let det = clip.determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err(Error::InvalidCamera(
            "the view's projection cannot be inverted to place section planes".into(),
        ));
    }
    let inverse = clip.inverse();
    for (o, s) in out.iter_mut().zip(sections) {
        // For a clip point c = C x: p · x = p · C⁻¹ c = (C⁻ᵀ p) · c.
        let c = inverse.transpose() * s.coefficients();
        // Scaled to unit size, so f32 keeps it whatever the scene's scale.
        let c = c / c.abs().max_element();
        *o = c.as_vec4().to_array();
    }
    Ok(out)
}

/// Words of a phase table entry: the edge's key, the hidden-line pattern's position and the
/// edge pattern's (`chain_phases`).
pub(crate) const PHASE_ENTRY_WORDS: u32 = 3;

/// The phase tables of a frame's patterns: a pattern runs along chains of drawn edges, so
/// each instance drawing its edges, or their hidden parts, in a dashed or dotted pattern
/// gets a phase table in the trace buffer, if its mesh has chains (its record is marked
/// `INSTANCE_PHASES` and given the table's place). Returns the tables' work, their words in
/// all (a power of two) and the chains in all.
fn phase_tables(
    store: &MeshStore,
    scene: &Scene<'_>,
    order: &[u32],
    records: &mut [InstanceRecord],
) -> Result<(Vec<ChainWork>, u32, u32)> {
    let mut chain_work = Vec::new();
    let (mut phase_words, mut chains) = (0u64, 0u64);
    for (slot, record) in records.iter_mut().enumerate() {
        let mesh = store.record(scene.instances[order[slot] as usize].mesh)?;
        let wanted = INSTANCE_EDGES | INSTANCE_HIDDEN | INSTANCE_HIDDEN_EDGES;
        let hidden = record.hidden_period > 0.0 && record.flags & wanted == wanted;
        let visible = record.flags & INSTANCE_LISTED_EDGES != 0 && record.edge_pattern[1] > 0.0;
        if !(hidden || visible) || mesh.chains == 0 {
            continue;
        }
        record.flags |= INSTANCE_PHASES;
        record.phase_table = u32::try_from(phase_words).map_err(|_| too_many_chains())?;
        chain_work.push(ChainWork {
            slot: slot as u32,
            chain_base: mesh.chain_base,
            chains: mesh.chains,
            before: u32::try_from(chains).map_err(|_| too_many_chains())?,
        });
        phase_words += u64::from(PHASE_ENTRY_WORDS) << mesh.table_log2;
        chains += u64::from(mesh.chains);
    }
    let phase_words = u32::try_from(phase_words.next_power_of_two())
        .ok()
        .filter(|_| u32::try_from(chains).is_ok())
        .ok_or_else(too_many_chains)?;
    let chains = u32::try_from(chains).map_err(|_| too_many_chains())?;
    Ok((chain_work, phase_words, chains))
}

/// The capacity of the frame's outline chains, if any instance draws its outline, or the
/// outline's hidden parts, in a pattern (each such record is marked
/// `INSTANCE_OUTLINE_PHASES`): a power of two, at least `OUTLINE_CHAIN_CAPACITY.0` and at
/// most `.1` edges; an outline edge beyond it runs its pattern from its own end, and the
/// chains break there.
fn outline_chain_capacity(
    store: &MeshStore,
    scene: &Scene<'_>,
    order: &[u32],
    records: &mut [InstanceRecord],
) -> Result<Option<u32>> {
    let mut triangles = 0u64;
    for (slot, record) in records.iter_mut().enumerate() {
        let hidden = record.hidden_period > 0.0 && record.flags & INSTANCE_HIDDEN != 0;
        let patterned = hidden || record.outline_pattern[1] > 0.0;
        if patterned && record.flags & INSTANCE_OUTLINES != 0 {
            record.flags |= INSTANCE_OUTLINE_PHASES;
            triangles += u64::from(
                store
                    .record(scene.instances[order[slot] as usize].mesh)?
                    .triangles,
            );
        }
    }
    if triangles == 0 {
        return Ok(None);
    }
    let (lo, hi) = OUTLINE_CHAIN_CAPACITY;
    let wanted = (triangles / OUTLINE_CHAIN_SHARE).clamp(u64::from(lo), u64::from(hi));
    Ok(Some(wanted.next_power_of_two() as u32))
}

/// Pairs of instances (by their index in the scene) and where their surfaces cross.
type PairCrossings = Vec<((usize, usize), Arc<[PairCrossing]>)>;

/// The pairs of instances whose surfaces may cross (their bounds, grown by the pair's
/// crossing tolerance, meet) that `wanted` asks for, and where they cross, found or kept in
/// `pairs` where the caller keeps one: an instance another passes through tests its lines'
/// visibility more widely, and intersection lines are drawn along the crossings. Pairs whose
/// bounds meet but whose surfaces do not cross (parts side by side in an assembly, one inside
/// another) are drawn as any two instances are, unless they draw hidden lines.
fn instance_pair_crossings(
    store: &MeshStore,
    scene: &Scene<'_>,
    placed: &[((DVec3, DVec3), DMat4)],
    wanted: impl Fn((usize, usize)) -> bool,
    pairs: Option<&mut PairCache>,
) -> Result<PairCrossings> {
    let mut fresh = PairCache::default();
    let cache = pairs.unwrap_or(&mut fresh);
    cache.begin_frame();
    let mut found = Vec::new();
    for (i, j) in crate::scene::crossing_pairs(placed) {
        if !wanted((i, j)) {
            continue;
        }
        let (a, b) = (&scene.instances[i], &scene.instances[j]);
        let records = (store.record(a.mesh)?, store.record(b.mesh)?);
        let pair = ((a.mesh, a.transform), (b.mesh, b.transform));
        found.push(((i, j), cache.between(pair, records)));
    }
    Ok(found)
}

/// A frame's intersection lines: every crossing pair of every instance's mesh, and of every
/// two instances that pass through each other (`pair_crossings`, by the scene's instance
/// indices). `order` maps slots to the scene's instances.
fn intersection_records(
    store: &MeshStore,
    scene: &Scene<'_>,
    order: &[u32],
    pair_crossings: &PairCrossings,
) -> Result<Vec<IntersectionRecord>> {
    let mut intersections = Vec::new();
    for (slot, &i) in order.iter().enumerate() {
        let mesh = store.record(scene.instances[i as usize].mesh)?;
        intersections.extend(mesh.intersections.iter().map(|c| IntersectionRecord {
            a: c.ends[0],
            slot: slot as u32,
            b: c.ends[1],
            t: c.t,
            u: c.u,
            other: slot as u32,
            _pad: [0; 2],
        }));
    }
    let mut slot_of = vec![0u32; order.len()];
    for (slot, &i) in order.iter().enumerate() {
        slot_of[i as usize] = slot as u32;
    }
    for ((i, j), found) in pair_crossings {
        let (slot, other) = (slot_of[*i], slot_of[*j]);
        intersections.extend(found.iter().map(|c| IntersectionRecord {
            a: c.ends[0],
            slot,
            b: c.ends[1],
            t: c.t,
            u: c.u,
            other,
            _pad: [0; 2],
        }));
    }
    Ok(intersections)
}

fn too_many_chains() -> Error {
    Error::InvalidScene(
        "the scene's chains of drawn edges need more than 2^32 phase table words".into(),
    )
}

impl FrameData {
    /// Uploads a frame's records, built for `store`.
    pub fn new(device: &wgpu::Device, store: &MeshStore, built: FrameRecords) -> FrameData {
        let FrameRecords {
            uniforms,
            records,
            draws,
            order,
            store: buffers,
            guard,
            traced,
            patches,
            hidden,
            patterns,
            region,
            mixed_colors,
            crossing,
            chain_work,
            intersections,
        } = built;
        let frame = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass frame"),
            contents: bytemuck::bytes_of(&uniforms),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        // Bindings need a non-empty buffer, even for a scene without instances; a uniform
        // binding needs the whole declared array.
        let uniform_bytes = u64::from(UNIFORM_INSTANCE_CAPACITY) * INSTANCE_BYTES;
        let uniform_instances = records.len() as u64 <= u64::from(UNIFORM_INSTANCE_CAPACITY)
            && device.limits().max_uniform_buffer_binding_size >= uniform_bytes;
        let mut contents: Vec<u8> = bytemuck::cast_slice(&records).to_vec();
        let least = if uniform_instances {
            uniform_bytes
        } else {
            INSTANCE_BYTES
        };
        contents.resize(contents.len().max(least as usize), 0);
        let mut usage =
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST;
        if uniform_instances {
            usage |= wgpu::BufferUsages::UNIFORM;
        }
        let instances = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wirepass instances"),
            contents: &contents,
            usage,
        });
        let chain_work = storage_list(device, "wirepass chain work", &chain_work);
        let intersections = storage_list(device, "wirepass intersections", &intersections);
        FrameData {
            uniforms,
            frame,
            chain_work,
            intersections,
            instances,
            draws,
            order,
            store: buffers,
            store_version: (store.store_id(), store.version()),
            region,
            guard,
            traced,
            patches,
            hidden,
            patterns,
            mixed_colors,
            crossing,
            uniform_instances,
        }
    }

    /// Clusters of all instances together.
    pub fn uniforms_clusters(&self) -> u32 {
        self.uniforms.clusters
    }

    /// Whether the frame has section planes.
    pub fn sections(&self) -> bool {
        self.uniforms.sections_on != 0
    }

    /// The frame's intersection segments.
    pub fn intersections(&self) -> u32 {
        self.uniforms.intersections
    }

    /// Entries of the trace pass's overflow list.
    pub fn overflow_room(&self) -> u32 {
        self.uniforms.overflow_room
    }

    /// Words of the trace buffer's phase tables (with the outline chains' area), and the
    /// chains `chain_phases` visits.
    pub fn chain_phases(&self) -> (u32, u32) {
        (self.uniforms.chain_work[0], self.uniforms.chain_work[1])
    }

    /// The capacity of the frame's outline chains (0: none), and their area's first word
    /// and words, counted from the phase tables' start.
    pub fn outline_chains(&self) -> (u32, u32, u32) {
        let c = self.uniforms.chain_work;
        let words = 4 + OUTLINE_CHAIN_WORDS * c[3];
        let words = if c[3] == 0 { 0 } else { words };
        (c[3], c[0] - words, words)
    }

    /// Whether the store's vertex or per-triangle buffers are bound as two halves.
    pub fn split(&self) -> bool {
        let s = &self.store;
        u64::from(s.split.vertices) * super::mesh_store::VERTEX_BYTES < s.vertices.size()
            || u64::from(s.split.triangles) * super::mesh_store::TRIANGLE_BYTES < s.indices.size()
    }

    /// Size of the id and depth targets.
    pub fn target_size(&self) -> (u32, u32) {
        (
            self.region.size.0 + 2 * self.guard,
            self.region.size.1 + 2 * self.guard,
        )
    }

    /// Errors when `store` is not the store this frame was prepared with, or changed since
    /// in a way that may have overwritten what the frame draws.
    pub fn check_store(&self, store: &MeshStore) -> Result<()> {
        if (store.store_id(), store.version()) != self.store_version {
            return Err(Error::Misuse(
                "the mesh store is another one, or had a mesh removed or its edges changed, \
                 since this frame was prepared: prepare the frame again"
                    .into(),
            ));
        }
        Ok(())
    }
}

/// One instance's record: its clip rows, eye, view depth row and normal matrix in its mesh's
/// stored coordinates, all formed in f64.
fn instance_record(
    view: &View,
    (eye, fade_row): (DVec4, DVec4),
    transform: DMat4,
    mesh: &MeshRecord,
    ([wire_color, fill_color, outline_color], [line_width, outline_width], flags): (
        [[f32; 4]; 3],
        [f32; 2],
        u32,
    ),
    (slot, cluster_first): (u32, u32),
) -> InstanceRecord {
    let model = transform * mesh.local_to_mesh();
    let mut rows = view.clip_rows(model);
    // Clip coordinates are homogeneous: every use of them (screen lines, coverage, depth,
    // the near-plane sign) is unchanged by a common positive factor. A scene 1e-30 or 1e30
    // across would under- or overflow in f32 (its edge lines are products of two clip
    // points), so far from unit size the rows are scaled by a power of two towards 1.
    let largest = rows
        .clip
        .to_cols_array()
        .iter()
        .chain(&rows.depth.to_array())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if largest > 0.0 && !(2f64.powi(-16)..=2f64.powi(16)).contains(&largest) {
        let k = 2f64.powi(-largest.log2().floor() as i32);
        rows.clip *= k;
        rows.depth *= k;
    }
    let local_eye = crate::edge_math::local_eye(model, eye);
    let normal = DMat3::from_mat4(transform).inverse().transpose();
    let row = |i: usize| normal.row(i).as_vec3().to_array();
    InstanceRecord {
        clip: rows.clip.as_mat4().to_cols_array_2d(),
        depth_row: rows.depth.as_vec4().to_array(),
        eye: local_eye.as_vec4().to_array(),
        fade_row: (model.transpose() * fade_row).as_vec4().to_array(),
        normal_x: row(0),
        hidden_width: 0.0,
        normal_y: row(1),
        hidden_dash: 0.0,
        normal_z: row(2),
        hidden_period: 0.0,
        wire_color,
        fill_color,
        line_width,
        flags,
        vertex_base: mesh.vertex_base,
        triangle_base: mesh.triangle_base,
        triangles: mesh.triangles,
        cluster_base: mesh.cluster_base,
        cluster_first,
        index: slot,
        outline_color: pack_color(outline_color),
        hidden_color: [0; 2],
        outline_width,
        phase_table: 0,
        table_log2: mesh.table_log2,
        _pad: 0,
        edge_pattern: [0.0; 2],
        outline_pattern: [0.0; 2],
        cross_box: NO_BOX,
    }
}

/// Room of the trace pass's overflow list (`overflow_list` in trace.wgsl): an entry for
/// each cluster and each group of 64 intersection segments, whose pieces the piece list may
/// have had no room for; a power of two, so that the targets, which hold the list, are
/// rebuilt only when a scene grows past it.
fn overflow_room(clusters: u32, intersections: u32) -> u32 {
    (clusters.saturating_add(intersections.div_ceil(64)))
        .max(64)
        .checked_next_power_of_two()
        .unwrap_or(1 << 31)
}

/// A read-only storage buffer holding `items`, or one zeroed item where there are none
/// (a binding needs a non-empty buffer).
fn storage_list<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, items: &[T]) -> wgpu::Buffer {
    let mut contents: Vec<u8> = bytemuck::cast_slice(items).to_vec();
    contents.resize(contents.len().max(std::mem::size_of::<T>()), 0);
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// `record` drawing the hidden lines `hidden`, if any.
fn with_hidden(record: InstanceRecord, hidden: Option<crate::HiddenLines>) -> InstanceRecord {
    let Some(h) = hidden else {
        return record;
    };
    let [dash, period] = h.pattern.dash_period();
    InstanceRecord {
        hidden_width: h.width,
        hidden_dash: dash,
        hidden_period: period,
        hidden_color: pack_color(h.color.0),
        ..record
    }
}

/// The style's view-space light direction in world axes, unit length.
pub fn light_world_dir(view: &View, style: &Style) -> DVec3 {
    let inv = view.view.inverse();
    inv.transform_vector3(style.light_view_dir.as_dvec3())
        .normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_match_their_wgsl_layout() {
        assert_eq!(std::mem::size_of::<InstanceRecord>(), 288);
        assert!(u64::from(UNIFORM_INSTANCE_CAPACITY) * INSTANCE_BYTES <= 65536);
        assert_eq!(std::mem::size_of::<FrameUniforms>(), 352);
        assert_eq!(std::mem::size_of::<IntersectionRecord>(), 48);
        let r = InstanceRecord::zeroed_for_test();
        let base = &r as *const _ as usize;
        assert_eq!(
            &r.index as *const _ as usize - base,
            INSTANCE_INDEX_OFFSET as usize
        );
        assert_eq!(
            &r.vertex_base as *const _ as usize - base,
            INSTANCE_BASES_OFFSET as usize
        );
    }

    impl InstanceRecord {
        fn zeroed_for_test() -> Self {
            bytemuck::Zeroable::zeroed()
        }
    }

    #[test]
    fn crop_maps_the_image_onto_the_targets() {
        // A 4-pixel guard band around a 100x50 region at (20, 10) of a 200x100 image: the
        // image point at pixel x lands at target pixel x - (20 - 4).
        let (iw, ih, tw, th, ox, oy): (f64, f64, f64, f64, f64, f64) =
            (200.0, 100.0, 108.0, 58.0, 16.0, 6.0);
        let crop = [
            iw / tw,
            ih / th,
            (iw - 2.0 * ox) / tw - 1.0,
            1.0 - (ih - 2.0 * oy) / th,
        ];
        for (px, py) in [(16.0, 6.0), (70.0, 33.0), (124.0, 64.0)] {
            let (ndc_x, ndc_y) = (2.0 * px / iw - 1.0, 1.0 - 2.0 * py / ih);
            let (x, y) = (ndc_x * crop[0] + crop[2], ndc_y * crop[1] + crop[3]);
            let target = ((x + 1.0) * 0.5 * tw, (1.0 - y) * 0.5 * th);
            assert!((target.0 - (px - ox)).abs() < 1e-9, "{target:?}");
            assert!((target.1 - (py - oy)).abs() < 1e-9, "{target:?}");
        }
    }

    #[test]
    fn instance_rows_fold_in_the_mesh_rebase() {
        let view = crate::camera::Camera {
            eye: glam::Vec3::new(1.0, 2.0, 6.0),
            target: glam::Vec3::ZERO,
            up: glam::Vec3::Y,
            fov_y_deg: 50.0,
            near: 0.1,
            far: 100.0,
        }
        .to_view(1.5);
        let mesh = MeshRecord {
            vertex_base: 0,
            vertices: 0,
            triangle_base: 0,
            triangles: 0,
            cluster_base: 0,
            clusters: 0,
            chain_base: 0,
            chain_records: 0,
            chains: 0,
            table_log2: 1,
            origin: DVec3::new(5.0, -3.0, 2.0),
            scale: 0.25,
            order: vec![].into(),
            bounds: (DVec3::ZERO, DVec3::ZERO),
            edges: Default::default(),
            lines: Default::default(),
            bounds_of_clusters: vec![].into(),
            intersections: vec![].into(),
            positions: vec![].into(),
            indices: vec![].into(),
            report: Default::default(),
        };
        let transform = DMat4::from_scale_rotation_translation(
            DVec3::new(-1.0, 2.0, 0.5),
            glam::DQuat::from_rotation_y(0.7),
            DVec3::new(0.3, 0.0, -1.0),
        );
        let r = instance_record(
            &view,
            (view.eye(), view.view_depth_row()),
            transform,
            &mesh,
            ([[0.0; 4]; 3], [1.0; 2], 0),
            (0, 0),
        );
        // A stored point q is the mesh point origin + scale q.
        let q = DVec3::new(0.4, -0.2, 0.9);
        let world = transform.transform_point3(mesh.origin + q * mesh.scale);
        let want = view.clip_rows(DMat4::IDENTITY).clip * world.extend(1.0);
        let got = r.clip().as_dmat4() * q.extend(1.0);
        assert!((want - got).length() < 1e-5 * want.length(), "{want} {got}");
        // The local eye maps back to the world eye.
        let e = glam::Vec4::from_array(r.eye).as_dvec4();
        let back = transform.transform_point3(mesh.origin + e.truncate() * mesh.scale);
        assert!((back - view.eye().truncate()).length() < 1e-4, "{back}");
    }
}

#[cfg(test)]
mod section_tests {
    use super::*;

    #[test]
    fn section_planes_vanish_on_their_plane() {
        let view = crate::camera::Camera {
            eye: glam::Vec3::new(2.0, 2.2, 2.6),
            target: glam::Vec3::ZERO,
            up: glam::Vec3::Y,
            fov_y_deg: 45.0,
            near: 0.05,
            far: 100.0,
        }
        .to_view(4.0 / 3.0);
        let s = crate::SectionPlane::new(DVec3::new(0.2, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0));
        let planes = section_planes(&view, &[s]).unwrap();
        let p = glam::Vec4::from_array(planes[0]).as_dvec4();
        let clip = view.clip_rows(DMat4::IDENTITY).clip;
        // On the plane: zero to f32's rounding; either side: the world side's sign.
        let on = clip * DVec3::new(0.2, 1.0, -1.0).extend(1.0);
        assert!(p.dot(on).abs() < 1e-6, "{}", p.dot(on));
        for x in [DVec3::new(0.2036, 0.99, -1.0), DVec3::new(0.1, 0.0, 0.5)] {
            let c = clip * x.extend(1.0);
            assert_eq!(p.dot(c) > 0.0, s.side(x) > 0.0, "{x}");
        }
    }
}
