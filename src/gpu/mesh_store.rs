//! GPU mesh storage: every mesh in one arena of buffers, so that one dispatch of a pass can
//! reach the triangles of any instance of any mesh.
//!
//! Per vertex (16 bytes): the position relative to the mesh's centre, scaled by a power of
//! two so the mesh spans about ±1 (meshes of any extent, 1e-30 or 1e30, and far from the
//! origin keep f32's precision; the model matrix takes the offset and scale back in f64),
//! and the unit normal packed octahedrally into 32 bits. Per triangle: three vertex indices
//! (12 bytes, also the index buffer), the triangle across each edge and which of its corners
//! lies off that edge (12 bytes, [`neighbour_word`]), and 4 bytes of edge data
//! ([`EdgeData`]). Per cluster of 64 triangles: the outline pass's bounds
//! (32 bytes).
//!
//! A mesh's triangles are stored in its clusters' order (a Morton curve through the
//! triangles, [`Mesh::outline_clusters`]), so a cluster is a run of 64 consecutive triangles
//! and nearby triangles sit together in memory; [`MeshStore::file_triangle`] maps a stored
//! triangle back to the file's numbering.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use crate::mesh::{adjacency::NO_NEIGHBOUR, patches::Patches, EdgeSelection, Mesh, ALL_EDGES};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Bytes per stored vertex: position (3 × f32) and packed normal.
pub(crate) const VERTEX_BYTES: u64 = 16;
/// Bytes per triangle of the index and neighbour buffers.
pub(crate) const TRIANGLE_BYTES: u64 = 12;
/// Bytes per cluster bound.
pub(crate) const CLUSTER_BYTES: u64 = 32;
/// Triangles per cluster.
pub(crate) const CLUSTER: u32 = crate::mesh::clusters::CLUSTER_TRIANGLES as u32;
/// The packed normal of a vertex without one (a zero normal, next to degenerate triangles
/// only): both components at the snorm code that unpacking clamps, which no unit vector
/// packs to.
pub(crate) const NO_NORMAL: u32 = 0x8000_8000;
/// Storage buffers per shader stage that the pipelines reading a mesh split over two
/// bindings need (`wgpu::Limits::default()` allows 8; without them, such a mesh is an error
/// naming the binding limit).
pub(crate) const SPLIT_STORAGE_BUFFERS: u32 = 11;

/// A mesh in a [`MeshStore`]. Copy it into as many [`Instance`](crate::Instance)s as you
/// like: instances of one mesh share its storage and are drawn instanced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId {
    store: u32,
    slot: u32,
    generation: u32,
}

/// Where one mesh lives in the arena, and how its stored coordinates map to its own.
#[derive(Clone, Debug)]
pub(crate) struct MeshRecord {
    pub vertex_base: u32,
    pub vertices: u32,
    pub triangle_base: u32,
    pub triangles: u32,
    pub cluster_base: u32,
    pub clusters: u32,
    /// Mesh coordinates of a stored position `q`: `origin + scale · q`.
    pub origin: DVec3,
    pub scale: f64,
    /// Stored triangle → the mesh's own triangle id.
    pub order: Arc<[u32]>,
    /// The mesh's bounds, in its own coordinates.
    pub bounds: (DVec3, DVec3),
    /// What its edge selection asks of the passes.
    pub lines: MeshLines,
    /// Per cluster, its bounds without the splat flag (see [`cluster_records`]).
    pub bounds_of_clusters: Arc<[[f32; 8]]>,
}

/// What a mesh's edge selection asks of the passes beyond each triangle's own edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MeshLines {
    /// Some triangle of a small patch has an undrawn edge: pixels near one search their
    /// patch (`patch_distance`).
    pub small_patches: bool,
    /// Some drawn edge borders a large patch: the outline pass draws it.
    pub splat: bool,
}

impl MeshRecord {
    /// Stored (rebased, scaled) coordinates → the mesh's own coordinates.
    pub fn local_to_mesh(&self) -> DMat4 {
        DMat4::from_translation(self.origin) * DMat4::from_scale(DVec3::splat(self.scale))
    }
}

/// First-fit free list over `0..capacity` of one kind of element.
#[derive(Clone, Debug, Default)]
struct FreeList {
    /// Free `(start, end)` ranges, sorted and never adjacent.
    free: Vec<(u32, u32)>,
    capacity: u32,
}

impl FreeList {
    fn alloc(&mut self, n: u32) -> Option<u32> {
        if n == 0 {
            return Some(0);
        }
        let k = self.free.iter().position(|&(s, e)| e - s >= n)?;
        let (s, e) = self.free[k];
        if e - s == n {
            self.free.remove(k);
        } else {
            self.free[k].0 = s + n;
        }
        Some(s)
    }

    fn release(&mut self, start: u32, n: u32) {
        if n == 0 {
            return;
        }
        let end = start + n;
        let k = self.free.partition_point(|&(s, _)| s < start);
        self.free.insert(k, (start, end));
        // Merge with the next, then the previous.
        if k + 1 < self.free.len() && self.free[k + 1].0 == end {
            self.free[k].1 = self.free[k + 1].1;
            self.free.remove(k + 1);
        }
        if k > 0 && self.free[k - 1].1 == start {
            self.free[k - 1].1 = self.free[k].1;
            self.free.remove(k);
        }
    }

    fn grow(&mut self, capacity: u32) {
        let old = self.capacity;
        self.capacity = capacity;
        self.release(old, capacity - old);
    }

    fn used(&self) -> u64 {
        u64::from(self.capacity)
            - self
                .free
                .iter()
                .map(|&(s, e)| u64::from(e - s))
                .sum::<u64>()
    }
}

/// One buffer of the arena and the bytes each element takes in it.
struct Pool {
    label: &'static str,
    stride: u64,
    usage: wgpu::BufferUsages,
    buffer: wgpu::Buffer,
}

/// The element kinds of the arena, each with its own free list and buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Vertex,
    Triangle,
    Cluster,
}

/// All meshes' GPU buffers. Insert meshes once; instances of them are then drawn by any
/// pass of the same device.
///
/// ```no_run
/// # fn demo(device: &wgpu::Device, queue: &wgpu::Queue) -> wirepass::Result<()> {
/// use wirepass::gpu::MeshStore;
/// use wirepass::EdgeSelection;
///
/// let mut meshes = MeshStore::new(device);
/// let sphere = wirepass::mesh::sphere(20_000)?;
/// let id = meshes.insert(device, queue, &sphere, EdgeSelection::Feature(30.0))?;
/// assert_eq!(meshes.triangle_count(id)?, sphere.triangle_count() as u32);
/// // Switch which edges are drawn without uploading the mesh again.
/// meshes.set_edges(queue, id, &sphere, EdgeSelection::All)?;
/// # Ok(()) }
/// ```
pub struct MeshStore {
    id: u32,
    limits: wgpu::Limits,
    vertices: FreeList,
    triangles: FreeList,
    clusters: FreeList,
    pools: Vec<(Kind, Pool)>,
    slots: Vec<(u32, Option<MeshRecord>)>,
    free_slots: Vec<u32>,
    /// Bumped whenever stored data may be overwritten under frames prepared earlier.
    version: u64,
}

impl MeshStore {
    /// An empty store on `device`.
    pub fn new(device: &wgpu::Device) -> MeshStore {
        static NEXT: AtomicU32 = AtomicU32::new(1);
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let pool = |kind, label, stride, usage| {
            (
                kind,
                Pool {
                    label,
                    stride,
                    usage: storage | usage,
                    buffer: empty_buffer(device, label, storage | usage),
                },
            )
        };
        MeshStore {
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            limits: device.limits(),
            vertices: FreeList::default(),
            triangles: FreeList::default(),
            clusters: FreeList::default(),
            pools: vec![
                pool(
                    Kind::Vertex,
                    "wirepass vertices",
                    VERTEX_BYTES,
                    wgpu::BufferUsages::VERTEX,
                ),
                pool(
                    Kind::Triangle,
                    "wirepass indices",
                    TRIANGLE_BYTES,
                    wgpu::BufferUsages::INDEX,
                ),
                pool(
                    Kind::Triangle,
                    "wirepass neighbours",
                    TRIANGLE_BYTES,
                    wgpu::BufferUsages::empty(),
                ),
                pool(
                    Kind::Triangle,
                    "wirepass triangle info",
                    4,
                    wgpu::BufferUsages::empty(),
                ),
                pool(
                    Kind::Cluster,
                    "wirepass clusters",
                    CLUSTER_BYTES,
                    wgpu::BufferUsages::empty(),
                ),
            ],
            slots: Vec::new(),
            free_slots: Vec::new(),
            version: 0,
        }
    }

    /// Uploads `mesh`, drawing the edges `edges` selects. Fails, before allocating
    /// anything, when the mesh would take the arena past a device limit.
    pub fn insert(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &Mesh,
        edges: EdgeSelection,
    ) -> Result<MeshId> {
        let vertices = count(mesh.positions().len(), "vertices")?;
        let triangles = count(mesh.triangle_count(), "triangles")?;
        if triangles > MAX_MESH_TRIANGLES {
            return Err(Error::InvalidMesh(format!(
                "{triangles} triangles are more than the {MAX_MESH_TRIANGLES} one mesh of the \
                 store can hold (its adjacency indexes a triangle in 29 bits)"
            )));
        }
        let clusters = triangles.div_ceil(CLUSTER);
        self.check_capacity(
            self.vertices.used() + u64::from(vertices),
            self.triangles.used() + u64::from(triangles),
            triangles,
        )?;
        let data = MeshData::new(mesh, edges);

        let vertex_base = self.alloc(device, queue, Kind::Vertex, vertices)?;
        let triangle_base = self.alloc(device, queue, Kind::Triangle, triangles)?;
        let cluster_base = self.alloc(device, queue, Kind::Cluster, clusters)?;
        let write = |pool: &Pool, base: u32, bytes: &[u8]| {
            if !bytes.is_empty() {
                queue.write_buffer(&pool.buffer, u64::from(base) * pool.stride, bytes);
            }
        };
        let [v, i, n, t, c] = [0, 1, 2, 3, 4].map(|k| &self.pools[k].1);
        write(v, vertex_base, bytemuck::cast_slice(&data.vertices));
        write(i, triangle_base, bytemuck::cast_slice(&data.indices));
        write(n, triangle_base, bytemuck::cast_slice(&data.neighbours));
        write(t, triangle_base, bytemuck::cast_slice(&data.info));
        write(c, cluster_base, bytemuck::cast_slice(&data.clusters));

        let record = MeshRecord {
            vertex_base,
            vertices,
            triangle_base,
            triangles,
            cluster_base,
            clusters,
            origin: data.origin,
            scale: data.scale,
            order: data.order,
            bounds: data.bounds,
            lines: data.lines,
            bounds_of_clusters: data.bounds_of_clusters,
        };
        let slot = match self.free_slots.pop() {
            Some(s) => s,
            None => {
                self.slots.push((0, None));
                (self.slots.len() - 1) as u32
            }
        };
        let entry = &mut self.slots[slot as usize];
        entry.1 = Some(record);
        Ok(MeshId {
            store: self.id,
            slot,
            generation: entry.0,
        })
    }

    /// Removes a mesh; its storage is reused by later inserts. Frames prepared before this
    /// call must not be encoded after it (encode reports that as an error).
    pub fn remove(&mut self, id: MeshId) -> Result<()> {
        let record = self.record(id)?.clone();
        self.vertices.release(record.vertex_base, record.vertices);
        self.triangles
            .release(record.triangle_base, record.triangles);
        self.clusters.release(record.cluster_base, record.clusters);
        let entry = &mut self.slots[id.slot as usize];
        entry.0 = entry.0.wrapping_add(1);
        entry.1 = None;
        self.free_slots.push(id.slot);
        self.version += 1;
        Ok(())
    }

    /// Re-uploads which edges of `id` are drawn; `mesh` is the mesh it was inserted from.
    /// Frames prepared before this call must be prepared again (encode reports one that is
    /// not as an error): the selection decides which pipelines draw the mesh.
    pub fn set_edges(
        &mut self,
        queue: &wgpu::Queue,
        id: MeshId,
        mesh: &Mesh,
        edges: EdgeSelection,
    ) -> Result<()> {
        let record = self.record(id)?;
        if mesh.triangle_count() as u64 != u64::from(record.triangles) {
            return Err(Error::Misuse(format!(
                "set_edges got a mesh of {} triangles for a stored mesh of {}",
                mesh.triangle_count(),
                record.triangles
            )));
        }
        let edges = EdgeData::new(mesh, edges, &record.order);
        let clusters = cluster_records(&record.bounds_of_clusters, &edges.info);
        let (info, cluster) = (&self.pools[3].1, &self.pools[4].1);
        queue.write_buffer(
            &info.buffer,
            u64::from(record.triangle_base) * info.stride,
            bytemuck::cast_slice(&edges.info),
        );
        if !clusters.is_empty() {
            queue.write_buffer(
                &cluster.buffer,
                u64::from(record.cluster_base) * cluster.stride,
                bytemuck::cast_slice(&clusters),
            );
        }
        let slot = id.slot as usize;
        if let Some(record) = self.slots[slot].1.as_mut() {
            record.lines = edges.lines;
        }
        self.version += 1;
        Ok(())
    }

    /// Number of triangles of `id`.
    pub fn triangle_count(&self, id: MeshId) -> Result<u32> {
        Ok(self.record(id)?.triangles)
    }

    /// The mesh's own id of the triangle stored at `stored` (what the id maps hold).
    pub fn file_triangle(&self, id: MeshId, stored: u32) -> Result<u32> {
        let record = self.record(id)?;
        record.order.get(stored as usize).copied().ok_or_else(|| {
            Error::Misuse(format!(
                "triangle {stored} of a mesh of {} triangles",
                record.triangles
            ))
        })
    }

    /// The mesh's axis-aligned bounds in its own coordinates.
    pub fn bounds(&self, id: MeshId) -> Result<(DVec3, DVec3)> {
        Ok(self.record(id)?.bounds)
    }

    /// GPU memory the arena's buffers take, in bytes (capacity, not only what is used).
    pub fn gpu_bytes(&self) -> u64 {
        self.pools.iter().map(|(_, p)| p.buffer.size()).sum()
    }

    pub(crate) fn record(&self, id: MeshId) -> Result<&MeshRecord> {
        if id.store != self.id {
            return Err(Error::Misuse(
                "the mesh belongs to another MeshStore".into(),
            ));
        }
        match self.slots.get(id.slot as usize) {
            Some((generation, Some(record))) if *generation == id.generation => Ok(record),
            _ => Err(Error::Misuse("the mesh was removed from the store".into())),
        }
    }

    pub(crate) fn version(&self) -> u64 {
        self.version
    }

    pub(crate) fn store_id(&self) -> u32 {
        self.id
    }

    /// The buffers, for binding: vertices, indices, neighbours, triangle info, clusters.
    pub(crate) fn buffers(&self) -> StoreBuffers {
        let b = |k: usize| self.pools[k].1.buffer.clone();
        StoreBuffers {
            vertices: b(0),
            indices: b(1),
            neighbours: b(2),
            info: b(3),
            clusters: b(4),
            split: self.split(),
        }
    }

    /// Where the vertex and per-triangle buffers split into two bindings.
    fn split(&self) -> Split {
        let binding = self.limits.max_storage_buffer_binding_size;
        let align = u64::from(self.limits.min_storage_buffer_offset_alignment.max(4));
        let at = |stride: u64, capacity: u32| {
            let unit = align / gcd(align, stride);
            let first = binding / stride / unit * unit;
            (first as u32).min(capacity)
        };
        Split {
            vertices: at(VERTEX_BYTES, self.vertices.capacity),
            triangles: at(TRIANGLE_BYTES, self.triangles.capacity),
        }
    }

    /// Errors naming the limit the arena would pass with `vertices` and `triangles` in all.
    fn check_capacity(&self, vertices: u64, triangles: u64, mesh_triangles: u32) -> Result<()> {
        let l = &self.limits;
        let over = |what: &str, value, limit_name, limit| Error::OverLimit {
            what: format!(
                "the {what} of the mesh store with a {mesh_triangles}-triangle mesh added"
            ),
            value,
            limit_name,
            limit,
        };
        for (what, bytes) in [
            ("vertex buffer size in bytes", vertices * VERTEX_BYTES),
            ("index buffer size in bytes", triangles * TRIANGLE_BYTES),
        ] {
            if bytes > l.max_buffer_size {
                return Err(over(what, bytes, "max_buffer_size", l.max_buffer_size));
            }
            let binding = l.max_storage_buffer_binding_size;
            if bytes > binding {
                if l.max_storage_buffers_per_shader_stage < SPLIT_STORAGE_BUFFERS {
                    return Err(over(
                        &format!(
                            "{what} (past one binding, which needs {SPLIT_STORAGE_BUFFERS} \
                             storage buffers per shader stage to split, and the device allows {})",
                            l.max_storage_buffers_per_shader_stage
                        ),
                        bytes,
                        "max_storage_buffer_binding_size",
                        binding,
                    ));
                }
                if bytes > 2 * binding - 2 * u64::from(l.min_storage_buffer_offset_alignment) {
                    return Err(over(
                        &format!("{what} (split over two bindings)"),
                        bytes,
                        "max_storage_buffer_binding_size × 2",
                        2 * binding,
                    ));
                }
            }
        }
        Ok(())
    }

    /// Allocates `n` elements of `kind`, growing its buffers (and copying what they hold)
    /// when no free range is large enough.
    fn alloc(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kind: Kind,
        n: u32,
    ) -> Result<u32> {
        let list = match kind {
            Kind::Vertex => &mut self.vertices,
            Kind::Triangle => &mut self.triangles,
            Kind::Cluster => &mut self.clusters,
        };
        if let Some(at) = list.alloc(n) {
            return Ok(at);
        }
        let old = list.capacity;
        let capacity = (u64::from(old) * 2)
            .max(u64::from(old) + u64::from(n))
            .max(1024);
        // Keep the doubling within the largest buffer the device takes.
        let stride = self
            .pools
            .iter()
            .filter(|(k, _)| *k == kind)
            .map(|(_, p)| p.stride)
            .max()
            .unwrap_or(4);
        let most = self.limits.max_buffer_size / stride;
        let capacity = capacity.min(most).min(u64::from(u32::MAX - 1)) as u32;
        if capacity < old + n {
            return Err(Error::OverLimit {
                what: format!("the elements of kind {kind:?} in the mesh store"),
                value: u64::from(old) + u64::from(n),
                limit_name: "max_buffer_size",
                limit: most,
            });
        }
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("wirepass mesh store growth"),
        });
        for (k, pool) in &mut self.pools {
            if *k != kind {
                continue;
            }
            let bigger = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(pool.label),
                size: u64::from(capacity) * pool.stride,
                usage: pool.usage,
                mapped_at_creation: false,
            });
            let used = u64::from(old) * pool.stride;
            if used > 0 {
                encoder.copy_buffer_to_buffer(&pool.buffer, 0, &bigger, 0, used);
            }
            pool.buffer = bigger;
        }
        queue.submit([encoder.finish()]);
        list.grow(capacity);
        list.alloc(n).ok_or_else(|| {
            Error::Device("the mesh store did not grow as far as it should have".into())
        })
    }
}

fn empty_buffer(device: &wgpu::Device, label: &str, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    // Bindings need a non-empty buffer; 256 bytes hold a few elements of every kind.
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: 256,
        usage,
        mapped_at_creation: false,
    })
}

fn count(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n)
        .ok()
        .filter(|&n| n < u32::MAX)
        .ok_or_else(|| Error::InvalidMesh(format!("{n} {what} exceed u32 indexing")))
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The arena's buffers as a frame binds them.
#[derive(Clone)]
pub(crate) struct StoreBuffers {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub neighbours: wgpu::Buffer,
    pub info: wgpu::Buffer,
    pub clusters: wgpu::Buffer,
    pub split: Split,
}

/// First element of the second binding of the vertex and per-triangle buffers; equal to
/// the capacity (no second binding) when one binding holds them all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Split {
    pub vertices: u32,
    pub triangles: u32,
}

/// One mesh as the arena stores it.
struct MeshData {
    vertices: Vec<[f32; 4]>,
    indices: Vec<[u32; 3]>,
    neighbours: Vec<[u32; 3]>,
    info: Vec<u32>,
    clusters: Vec<[f32; 8]>,
    bounds_of_clusters: Arc<[[f32; 8]]>,
    lines: MeshLines,
    origin: DVec3,
    scale: f64,
    order: Arc<[u32]>,
    bounds: (DVec3, DVec3),
}

impl MeshData {
    fn new(mesh: &Mesh, edges: EdgeSelection) -> MeshData {
        let (lo, hi) = mesh.bounds_f64();
        let origin = (lo + hi) * 0.5;
        let extent = (hi - lo).max_element() * 0.5;
        // A power of two, so scaling is exact; 1 for a mesh of one point.
        let scale = if extent > 0.0 && extent.is_finite() {
            extent.log2().round().exp2()
        } else {
            1.0
        };
        let vertices = mesh
            .positions()
            .iter()
            .zip(mesh.normals())
            .map(|(p, n)| {
                let q = ((p.as_dvec3() - origin) / scale).as_vec3();
                [q.x, q.y, q.z, f32::from_bits(pack_normal(*n))]
            })
            .collect();
        let clusters = mesh.outline_clusters();
        let order: Arc<[u32]> = clusters.order.clone().into();
        let mut stored = vec![0u32; order.len()];
        for (s, &t) in order.iter().enumerate() {
            stored[t as usize] = s as u32;
        }
        let tris = mesh.triangles();
        let indices = order.iter().map(|&t| tris[t as usize]).collect();
        let neighbours = order
            .iter()
            .map(|&t| [0, 1, 2].map(|i| neighbour_word(mesh, &stored, t as usize, i)))
            .collect();
        let bounds: Vec<[f32; 8]> = clusters
            .bounds
            .iter()
            .map(|c| {
                let center = (c.center - origin) / scale;
                let radius = c.radius / scale * (1.0 + 1e-6) + center.length() * 1e-6;
                let [x, y, z] = center.as_vec3().to_array();
                let [ax, ay, az] = c.axis.as_vec3().to_array();
                [x, y, z, radius as f32, ax, ay, az, c.spread as f32]
            })
            .collect();
        let bounds: Arc<[[f32; 8]]> = bounds.into();
        let edges = EdgeData::new(mesh, edges, &order);
        MeshData {
            vertices,
            indices,
            neighbours,
            clusters: cluster_records(&bounds, &edges.info),
            bounds_of_clusters: bounds,
            info: edges.info,
            lines: edges.lines,
            origin,
            scale,
            order,
            bounds: (lo, hi),
        }
    }
}

/// Most triangles in one mesh: a neighbour word holds the neighbour's index in 29 bits, and
/// the all-ones word means no neighbour.
pub(crate) const MAX_MESH_TRIANGLES: u32 = (1 << 29) - 1;
/// The neighbour word's bits below this hold the neighbour's stored index (relative to its
/// mesh); the next two its corner off the shared edge.
const NEIGHBOUR_CORNER_SHIFT: u32 = 29;
/// Bit of a neighbour word: the neighbour runs along the shared edge the same way as this
/// triangle (the two are wound oppositely); clear, the other way.
const NEIGHBOUR_SAME_WAY: u32 = 1 << 31;

/// What the passes read of the triangle across edge `i` of triangle `t` (`scene.wgsl`,
/// `neighbour_word`): its stored index, its corner k off the shared edge and whether its
/// corners k + 1 and k + 2 are that edge's start and end (the same way) or its end and start.
/// A step of a walk across the edge then reads one corner, not three; `u32::MAX` where there
/// is no neighbour. The shared corners are found by position, as the adjacency welds them.
fn neighbour_word(mesh: &Mesh, stored: &[u32], t: usize, i: usize) -> u32 {
    let n = mesh.edge_neighbours()[t][i];
    if n == NO_NEIGHBOUR {
        return u32::MAX;
    }
    let tris = mesh.triangles();
    let at = |v: u32| {
        (mesh.positions()[v as usize] + Vec3::ZERO)
            .to_array()
            .map(f32::to_bits)
    };
    let (a, b) = (at(tris[t][i]), at(tris[t][(i + 1) % 3]));
    let other = tris[n as usize];
    let back = (0..3).find(|&j| {
        let (p, q) = (at(other[j]), at(other[(j + 1) % 3]));
        mesh.edge_neighbours()[n as usize][j] == t as u32 && ((p, q) == (a, b) || (p, q) == (b, a))
    });
    // The adjacency pairs the two sides of an edge with the same welded ends, so `back` is
    // always found; without it the edge reads as a boundary.
    let Some(j) = back else {
        return u32::MAX;
    };
    let k = (j as u32 + 2) % 3;
    let same_way = if at(other[j]) == a {
        NEIGHBOUR_SAME_WAY
    } else {
        0
    };
    stored[n as usize] | k << NEIGHBOUR_CORNER_SHIFT | same_way
}

/// Bit of [`EdgeData::info`]: the triangle's patch is large ([`Patches::large`]).
const INFO_LARGE_PATCH: u32 = 1 << 11;
/// First of the three bits of [`EdgeData::info`] that mark the edges the outline pass draws
/// for a large patch ([`Patches::splat`]).
const INFO_SPLAT_SHIFT: u32 = 12;
/// Bit of [`EdgeData::info`]: the triangle's patch is a quad (two triangles), which the edge
/// pass searches without a queue.
const INFO_QUAD: u32 = 1 << 15;

/// First bit of [`EdgeData::info`] of a quad: its diagonal (edge 0–2, two bits), then the
/// other triangle's corner off the diagonal (two bits), whether that triangle's next corner
/// is the diagonal's start (one bit) and its drawn edges (three bits): `quad_of` in
/// edge_pass.wgsl reads the other triangle from these, its id and one corner's position.
const QUAD_SHIFT: u32 = 16;

/// Bits of [`EdgeData::info`] of a quad: its other triangle is stored right after this one
/// ([`QUAD_NEXT`]) or right before it ([`QUAD_PREVIOUS`]), as the cluster order keeps the
/// halves of a source quad ([`Mesh::quad_partners`]); with neither, `quad_of` reads it from
/// the adjacency.
const QUAD_NEXT: u32 = 1 << 24;
const QUAD_PREVIOUS: u32 = 1 << 25;

/// [`INFO_QUAD`] and the bits after [`QUAD_SHIFT`] for triangle `t` of a two-triangle patch
/// under edge mask `mask` (`stored` maps triangles to their stored places), or 0 (the
/// triangle is then searched as any small patch is) where the other triangle does not meet
/// it across the diagonal at bit-identical positions (so that the diagonal's ends read from
/// either triangle are the same numbers) or draws the diagonal from its side.
fn quad_bits(mesh: &Mesh, mask: &[u8], stored: &[u32], t: usize) -> u32 {
    let neighbours = mesh.edge_neighbours();
    let (tris, positions) = (mesh.triangles(), mesh.positions());
    let at = |v: u32| positions[v as usize].to_array().map(f32::to_bits);
    // The last undrawn edge with a neighbour, as the search would take it.
    let Some(e) = (0..3)
        .rev()
        .find(|&e| mask[t] & (1 << e) == 0 && neighbours[t][e] != NO_NEIGHBOUR)
    else {
        return 0;
    };
    let n = neighbours[t][e] as usize;
    let (a, b) = (at(tris[t][e]), at(tris[t][(e + 1) % 3]));
    let shared = (0..3).find_map(|j| {
        let (p, q) = (at(tris[n][j]), at(tris[n][(j + 1) % 3]));
        let back = neighbours[n][j] as usize == t && mask[n] & (1 << j) == 0;
        (back && ((p, q) == (a, b) || (p, q) == (b, a))).then_some((j, p == a))
    });
    let Some((j, same)) = shared else {
        return 0;
    };
    let k = (j + 2) % 3;
    let place = if stored[n] == stored[t] + 1 {
        QUAD_NEXT
    } else if stored[n] + 1 == stored[t] {
        QUAD_PREVIOUS
    } else {
        0
    };
    INFO_QUAD
        | place
        | (e as u32) << QUAD_SHIFT
        | (k as u32) << (QUAD_SHIFT + 2)
        | u32::from(same) << (QUAD_SHIFT + 4)
        | u32::from(mask[n] & ALL_EDGES) << (QUAD_SHIFT + 5)
}

/// A mesh's edge data under one edge selection, in stored order.
pub(crate) struct EdgeData {
    /// Per stored triangle, the 4 bytes the passes read (`triangle_info` in common.wgsl):
    /// bits 0–2 the drawn edges, bit 3 a boundary edge, bits 4–7 the fold code of
    /// [`Mesh::outline_hints`], bits 8–10 the edges that may be drawn as outlines, bit 11
    /// a large patch, bits 12–14 the drawn edges the outline pass draws, bit 15 a patch of
    /// two triangles, bits 16–25 that quad's other triangle ([`quad_bits`]).
    pub info: Vec<u32>,
    pub lines: MeshLines,
}

impl EdgeData {
    pub fn new(mesh: &Mesh, edges: EdgeSelection, order: &[u32]) -> EdgeData {
        let mask = mesh.edge_mask(edges);
        let neighbours = mesh.edge_neighbours();
        // Each edge splatted from the side with the lower stored id, the side the outline
        // pass draws a silhouette from.
        let mut stored = vec![0u32; order.len()];
        for (s, &t) in order.iter().enumerate() {
            stored[t as usize] = s as u32;
        }
        let patches = Patches::ordered(neighbours, &mask, |t, u| stored[t] < stored[u]);
        let hints = mesh.outline_hints();
        let outline = mesh.outline_mask();
        let info = order
            .iter()
            .map(|&t| {
                let t = t as usize;
                let large = if patches.large[t] {
                    INFO_LARGE_PATCH
                } else {
                    0
                };
                let quad = if patches.size[t] == 2 {
                    quad_bits(mesh, &mask, &stored, t)
                } else {
                    0
                };
                u32::from(mask[t])
                    | u32::from(hints[t]) << 3
                    | u32::from(outline[t]) << 8
                    | large
                    | u32::from(patches.splat[t]) << INFO_SPLAT_SHIFT
                    | quad
            })
            .collect();
        let lines = MeshLines {
            small_patches: mask
                .iter()
                .zip(&patches.large)
                .any(|(&m, &large)| m != ALL_EDGES && !large),
            splat: patches.splat.iter().any(|&b| b != 0),
        };
        EdgeData { info, lines }
    }
}

/// The cluster records the outline pass reads: `bounds` with the spread of each cluster
/// holding an edge to splat (`info`, stored order) stored as −1 − spread, so the outline
/// pass visits it whatever the eye (`cluster_splats` in common.wgsl).
pub(crate) fn cluster_records(bounds: &[[f32; 8]], info: &[u32]) -> Vec<[f32; 8]> {
    bounds
        .iter()
        .zip(info.chunks(CLUSTER as usize))
        .map(|(b, tris)| {
            let mut b = *b;
            if tris.iter().any(|i| i >> INFO_SPLAT_SHIFT & 7 != 0) {
                b[7] = -1.0 - b[7];
            }
            b
        })
        .collect()
}

/// A unit normal packed octahedrally into two 16-bit snorms (`unpack_normal` in
/// common.wgsl is the inverse); a zero normal packs to `NO_NORMAL`.
pub(crate) fn pack_normal(n: Vec3) -> u32 {
    let sum = n.x.abs() + n.y.abs() + n.z.abs();
    if !(sum > 0.0) {
        return NO_NORMAL;
    }
    let mut p = Vec2::new(n.x, n.y) / sum;
    if n.z < 0.0 {
        let sign = Vec2::new(p.x.signum(), p.y.signum());
        p = (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign;
    }
    let q = |v: f32| (v.clamp(-1.0, 1.0) * 32767.0).round() as i16 as u16 as u32;
    q(p.x) | q(p.y) << 16
}

/// Twin of `unpack_normal` in common.wgsl: the unit normal of a packed one (zero for
/// `NO_NORMAL`).
#[cfg(test)]
pub(crate) fn unpack_normal(packed: u32) -> Vec3 {
    if packed == NO_NORMAL {
        return Vec3::ZERO;
    }
    let s = |v: u32| (f32::from(v as u16 as i16) / 32767.0).max(-1.0);
    let (x, y) = (s(packed & 0xffff), s(packed >> 16));
    let mut n = Vec3::new(x, y, 1.0 - x.abs() - y.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_list_reuses_and_merges() {
        let mut f = FreeList::default();
        f.grow(100);
        assert_eq!(f.alloc(30), Some(0));
        assert_eq!(f.alloc(30), Some(30));
        assert_eq!(f.alloc(50), None);
        f.release(0, 30);
        assert_eq!(f.alloc(20), Some(0));
        f.release(30, 30);
        // 20..100 is one range again.
        assert_eq!(f.free, vec![(20, 100)]);
        assert_eq!(f.used(), 20);
        f.grow(200);
        assert_eq!(f.free, vec![(20, 200)]);
    }

    /// The quad (0,0)-(1,0)-(1,1)-(0,1) split along 0-2, the second triangle's corners
    /// given by `second` over positions `p`, with the diagonal undrawn on both sides.
    fn quad_info(p: Vec<Vec3>, second: [u32; 3]) -> [u32; 2] {
        let shared = (0..3)
            .find(|&j| {
                let e = [second[j], second[(j + 1) % 3]].map(|v| p[v as usize]);
                e.contains(&p[0]) && e.contains(&p[2])
            })
            .unwrap();
        let mask = vec![0b011, ALL_EDGES & !(1 << shared)];
        let mesh = Mesh::new(p, None, vec![[0, 1, 2], second], Some(mask)).unwrap();
        let mask = mesh.edge_mask(EdgeSelection::Polygon);
        [0, 1].map(|t| quad_bits(&mesh, &mask, &[0, 1], t))
    }

    fn square() -> Vec<Vec3> {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| Vec3::new(x, y, 0.0))
            .to_vec()
    }

    /// Decodes quad_bits as quad_distance does: the diagonal, the other triangle's corner
    /// off it, whether its next corner is the diagonal's start, its drawn edges.
    fn decode(bits: u32) -> (u32, u32, bool, u32) {
        assert_ne!(bits & INFO_QUAD, 0);
        let b = bits >> QUAD_SHIFT;
        (b & 3, b >> 2 & 3, b >> 4 & 1 == 1, b >> 5 & 7)
    }

    #[test]
    fn quad_bits_name_the_other_triangle_s_fourth_corner() {
        // Consistently wound: the diagonal is edge 2 (2 -> 0) of the first triangle and
        // edge 0 (0 -> 2) of the second, whose corner off it is 3 (corner 2).
        let [first, second] = quad_info(square(), [0, 2, 3]);
        assert_eq!(decode(first), (2, 2, false, 0b110));
        assert_eq!(decode(second), (0, 1, false, 0b011));
        // Stored side by side, each says where the other is.
        assert_eq!(first & (QUAD_NEXT | QUAD_PREVIOUS), QUAD_NEXT);
        assert_eq!(second & (QUAD_NEXT | QUAD_PREVIOUS), QUAD_PREVIOUS);
        // The second triangle wound the other way (its next corner after 3 is the first
        // triangle's diagonal start, 2), and with split vertices at the same positions.
        let mut p = square();
        p.extend([p[0], p[2]]);
        let [first, second] = quad_info(p, [3, 5, 4]);
        assert_eq!(decode(first), (2, 0, true, 0b101));
        assert_eq!(decode(second), (1, 1, true, 0b011));
    }

    #[test]
    fn neighbour_words_give_the_corner_off_the_edge_and_the_way_round() {
        let mut split = square();
        split.extend([split[0], split[2]]);
        // The second triangle wound against the first, with it, and on split vertices.
        for (p, second) in [
            (square(), [0, 2, 3]),
            (square(), [0, 3, 2]),
            (split, [3, 5, 4]),
        ] {
            let mesh = Mesh::new(p.clone(), None, vec![[0, 1, 2], second], None).unwrap();
            let tris = mesh.triangles();
            for (t, i) in (0..2).flat_map(|t| (0..3).map(move |i| (t, i))) {
                let word = neighbour_word(&mesh, &[0, 1], t, i);
                let n = mesh.edge_neighbours()[t][i];
                if n == NO_NEIGHBOUR {
                    assert_eq!(word, u32::MAX);
                    continue;
                }
                assert_eq!(word & MAX_MESH_TRIANGLES, n);
                // The neighbour's corners as beyond_edge (scene.wgsl) rebuilds them: corner k
                // read, the next two the edge's ends.
                let k = (word >> NEIGHBOUR_CORNER_SHIFT & 3) as usize;
                let (a, b) = (p[tris[t][i] as usize], p[tris[t][(i + 1) % 3] as usize]);
                let same = word & NEIGHBOUR_SAME_WAY != 0;
                let mut q = [p[tris[n as usize][k] as usize]; 3];
                q[(k + 1) % 3] = if same { a } else { b };
                q[(k + 2) % 3] = if same { b } else { a };
                assert_eq!(q, tris[n as usize].map(|v| p[v as usize]), "{t} {i}");
            }
        }
    }

    #[test]
    fn quads_joined_at_unequal_bits_are_searched_instead() {
        // 0.0 and -0.0 weld into one edge, but read from the two triangles they would be
        // different numbers: the triangles are left to the patch search.
        let mut p = square();
        p.extend([Vec3::new(-0.0, 0.0, 0.0), p[2]]);
        assert_eq!(quad_info(p, [4, 5, 3]), [0, 0]);
    }

    #[test]
    fn normals_survive_packing() {
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let a = i as f32 * 0.731;
            let b = (i as f32 * 0.377).sin() * 1.5;
            let n = Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos()).normalize();
            let m = unpack_normal(pack_normal(n));
            let cos = n.as_dvec3().dot(m.as_dvec3());
            let sin = n.as_dvec3().cross(m.as_dvec3()).length();
            worst = worst.max(sin.atan2(cos));
        }
        assert!(worst < 1e-4, "{worst}");
        for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            assert!(unpack_normal(pack_normal(n)).distance(n) < 1e-6, "{n}");
        }
        assert_eq!(pack_normal(Vec3::ZERO), NO_NORMAL);
        assert_eq!(unpack_normal(NO_NORMAL), Vec3::ZERO);
        // No unit normal packs to the marker.
        assert_ne!(
            pack_normal(Vec3::new(-1.0, -1.0, 0.0).normalize()),
            NO_NORMAL
        );
    }
}
