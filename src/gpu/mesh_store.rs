//! GPU mesh storage: every mesh in one arena of buffers, so that one dispatch of a pass can
//! reach the triangles of any instance of any mesh.
//!
//! Per vertex (16 bytes): the position relative to the mesh's centre, scaled by a power of
//! two so the mesh spans about ±1 (meshes of any extent, 1e-30 or 1e30, and far from the
//! origin keep f32's precision; the model matrix takes the offset and scale back in f64),
//! and the unit normal packed octahedrally into 32 bits. Per triangle: three vertex indices
//! (12 bytes, also the index buffer), the triangle across each edge and which of its corners
//! lies off that edge (12 bytes), and 4 bytes of edge data; `mesh_records.rs` makes these
//! records from a mesh. Per cluster of 64 triangles: the trace pass's bounds
//! (32 bytes).
//!
//! A mesh's triangles are stored in its clusters' order (a Morton curve through the
//! triangles, [`Mesh::traced_clusters`]), so a cluster is a run of 64 consecutive triangles
//! and nearby triangles sit together in memory; [`MeshStore::file_triangle`] maps a stored
//! triangle back to the file's numbering.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::mesh_records::{
    cluster_records, EdgeData, MeshData, MeshLines, StoredCrossing, UploadReport,
    MAX_MESH_TRIANGLES,
};
use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use glam::{DMat4, DVec3, Vec3};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;
use web_time::Instant;

/// Bytes per stored vertex: position (3 × f32) and packed normal.
pub(crate) const VERTEX_BYTES: u64 = 16;
/// Bytes per triangle of the index and neighbour buffers.
pub(crate) const TRIANGLE_BYTES: u64 = 12;
/// Bytes per cluster bound.
pub(crate) const CLUSTER_BYTES: u64 = 32;
/// Bytes per chain record (`mesh_records::ChainRecords`).
pub(crate) const CHAIN_BYTES: u64 = 16;
/// Storage buffers per shader stage that the pipelines reading a mesh split over two
/// bindings need (`wgpu::Limits::default()` allows 8; without them, such a mesh is an error
/// naming the binding limit).
pub(crate) const SPLIT_STORAGE_BUFFERS: u32 = 11;

pub use crate::scene::MeshId;

/// Where one mesh lives in the arena, and how its stored coordinates map to its own.
#[derive(Clone, Debug)]
pub(crate) struct MeshRecord {
    pub vertex_base: u32,
    pub vertices: u32,
    pub triangle_base: u32,
    pub triangles: u32,
    pub cluster_base: u32,
    pub clusters: u32,
    /// Its chain records (`mesh_records::ChainRecords`): where they start, how many, how many of them
    /// head a chain, and log2 of the slots of its phase table.
    pub chain_base: u32,
    pub chain_records: u32,
    pub chains: u32,
    pub table_log2: u32,
    /// Mesh coordinates of a stored position `q`: `origin + scale · q`.
    pub origin: DVec3,
    pub scale: f64,
    /// Stored triangle → the mesh's own triangle id.
    pub order: Arc<[u32]>,
    /// The mesh's bounds, in its own coordinates.
    pub bounds: (DVec3, DVec3),
    /// Which of its edges are drawn, and what that asks of the passes.
    pub edges: EdgeSelection,
    pub lines: MeshLines,
    /// Per cluster, its bounds without the splat flag (see [`cluster_records`]).
    pub bounds_of_clusters: Arc<[[f32; 8]]>,
    /// Its crossing triangles and their intersection lines.
    pub intersections: Arc<[StoredCrossing]>,
    /// Its positions (in its own coordinates) and its triangles in stored order: where
    /// instances pass through each other, their intersection lines are found from these
    /// (`instance_crossings.rs`).
    pub positions: Arc<[Vec3]>,
    pub indices: Arc<[[u32; 3]]>,
    /// What inserting it took.
    pub report: UploadReport,
}

impl MeshRecord {
    /// The record of `data` placed at `bases` (vertices, triangles, clusters, chain records),
    /// of `counts` each.
    fn new(
        data: MeshData,
        edges: EdgeSelection,
        bases: [u32; 4],
        counts: [u32; 4],
        report: UploadReport,
    ) -> MeshRecord {
        let [vertex_base, triangle_base, cluster_base, chain_base] = bases;
        let [vertices, triangles, clusters, chain_records] = counts;
        MeshRecord {
            vertex_base,
            vertices,
            triangle_base,
            triangles,
            cluster_base,
            clusters,
            chain_base,
            chain_records,
            chains: data.chains.chains,
            table_log2: data.chains.table_log2,
            origin: data.origin,
            scale: data.scale,
            order: data.order,
            bounds: data.bounds,
            edges,
            lines: data.lines,
            bounds_of_clusters: data.bounds_of_clusters,
            intersections: data.intersections,
            positions: data.positions,
            indices: data.indices,
            report,
        }
    }

    /// The record of `mesh` as the store would make it, at the start of empty buffers.
    #[cfg(test)]
    pub fn unstored(mesh: &Mesh) -> MeshRecord {
        let (data, report) = MeshData::new(mesh, EdgeSelection::All);
        let counts = [
            data.vertices.len(),
            data.indices.len(),
            data.clusters.len(),
            data.chains.records.len(),
        ]
        .map(|n| n as u32);
        MeshRecord::new(data, EdgeSelection::All, [0; 4], counts, report)
    }

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
    Chain,
}

/// All meshes' GPU buffers. Insert meshes once; instances of them are then drawn by any
/// pass of the same device.
///
/// The store also keeps each mesh's positions and triangles in CPU memory (12 bytes a vertex
/// and 12 a triangle), from which a frame with intersection lines finds where two instances
/// pass through each other ([`Style::intersection_lines`](crate::Style::intersection_lines)).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # use wirepass::wgpu;
/// # let instance =
/// #     wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
/// # let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
/// # let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
/// # let (device, queue) = (&device, &queue);
/// use wirepass::gpu::MeshStore;
/// use wirepass::EdgeSelection;
///
/// let mut meshes = MeshStore::new(device);
/// let sphere = wirepass::mesh::sphere(20_000)?;
/// let id = meshes.insert(device, queue, &sphere, EdgeSelection::Feature(30.0))?;
/// assert_eq!(meshes.triangle_count(id)?, sphere.triangle_count() as u32);
/// // Switch which edges are drawn without uploading the mesh again.
/// meshes.set_edges(device, queue, id, &sphere, EdgeSelection::All)?;
/// # Ok(()) }
/// ```
pub struct MeshStore {
    id: u32,
    limits: wgpu::Limits,
    vertices: FreeList,
    triangles: FreeList,
    clusters: FreeList,
    chains: FreeList,
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
            chains: FreeList::default(),
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
                pool(
                    Kind::Chain,
                    "wirepass chains",
                    CHAIN_BYTES,
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
        let clusters = triangles.div_ceil(crate::mesh::clusters::CLUSTER_TRIANGLES as u32);
        self.check_capacity(
            self.vertices.used() + u64::from(vertices),
            self.triangles.used() + u64::from(triangles),
            triangles,
        )?;
        let (data, mut report) = MeshData::new(mesh, edges);
        let start = Instant::now();

        let vertex_base = self.alloc(device, queue, Kind::Vertex, vertices)?;
        let triangle_base = self.alloc(device, queue, Kind::Triangle, triangles)?;
        let cluster_base = self.alloc(device, queue, Kind::Cluster, clusters)?;
        let chains = &data.chains;
        let chain_records = count(chains.records.len(), "chain records")?;
        let chain_base = self.alloc(device, queue, Kind::Chain, chain_records)?;
        let write = |pool: &Pool, base: u32, bytes: &[u8]| {
            if !bytes.is_empty() {
                queue.write_buffer(&pool.buffer, u64::from(base) * pool.stride, bytes);
            }
        };
        let [v, i, n, t, c, h] = [0, 1, 2, 3, 4, 5].map(|k| &self.pools[k].1);
        write(v, vertex_base, bytemuck::cast_slice(&data.vertices));
        write(i, triangle_base, bytemuck::cast_slice(&data.indices));
        write(n, triangle_base, bytemuck::cast_slice(&data.neighbours));
        write(t, triangle_base, bytemuck::cast_slice(&data.info));
        write(c, cluster_base, bytemuck::cast_slice(&data.clusters));
        write(h, chain_base, bytemuck::cast_slice(&chains.records));
        report.upload = start.elapsed();
        let bytes: [&[u8]; 6] = [
            bytemuck::cast_slice(&data.vertices),
            bytemuck::cast_slice(&data.indices),
            bytemuck::cast_slice(&data.neighbours),
            bytemuck::cast_slice(&data.info),
            bytemuck::cast_slice(&data.clusters),
            bytemuck::cast_slice(&chains.records),
        ];
        report.gpu_bytes = bytes.iter().map(|b| b.len() as u64).sum();

        let record = MeshRecord::new(
            data,
            edges,
            [vertex_base, triangle_base, cluster_base, chain_base],
            [vertices, triangles, clusters, chain_records],
            report,
        );
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
        self.chains.release(record.chain_base, record.chain_records);
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
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        id: MeshId,
        mesh: &Mesh,
        edges: EdgeSelection,
    ) -> Result<()> {
        let record = self.record(id)?.clone();
        if mesh.triangle_count() as u64 != u64::from(record.triangles) {
            return Err(Error::Misuse(format!(
                "set_edges got a mesh of {} triangles for a stored mesh of {}",
                mesh.triangle_count(),
                record.triangles
            )));
        }
        let selection = edges;
        let edges = EdgeData::new(mesh, selection, &record.order);
        let clusters = cluster_records(&record.bounds_of_clusters, &edges.info);
        // The chains change with the selection: their records move to a region of their size.
        let (old_base, old_records) = (record.chain_base, record.chain_records);
        let chain_records = count(edges.chains.records.len(), "chain records")?;
        let chain_base = self.alloc(device, queue, Kind::Chain, chain_records)?;
        self.chains.release(old_base, old_records);
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
        let chain = &self.pools[5].1;
        if !edges.chains.records.is_empty() {
            queue.write_buffer(
                &chain.buffer,
                u64::from(chain_base) * chain.stride,
                bytemuck::cast_slice(&edges.chains.records),
            );
        }
        let slot = id.slot as usize;
        if let Some(record) = self.slots[slot].1.as_mut() {
            record.edges = selection;
            record.lines = edges.lines;
            record.chain_base = chain_base;
            record.chain_records = chain_records;
            record.chains = edges.chains.chains;
            record.table_log2 = edges.chains.table_log2;
        }
        self.version += 1;
        Ok(())
    }

    /// What inserting `id` took, step by step.
    pub fn upload_report(&self, id: MeshId) -> Result<UploadReport> {
        Ok(self.record(id)?.report)
    }

    /// Which edges of `id` are drawn: as inserted, or as last [set](Self::set_edges).
    pub fn edges(&self, id: MeshId) -> Result<EdgeSelection> {
        Ok(self.record(id)?.edges)
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
            chains: b(5),
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
            Kind::Chain => &mut self.chains,
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
        // The chain records are bound whole, never split.
        let (limit_name, limit) = match kind {
            Kind::Chain => (
                "max_storage_buffer_binding_size",
                self.limits.max_storage_buffer_binding_size,
            ),
            _ => ("max_buffer_size", self.limits.max_buffer_size),
        };
        let most = limit / stride;
        let capacity = capacity.min(most).min(u64::from(u32::MAX - 1)) as u32;
        if capacity < old + n {
            return Err(Error::OverLimit {
                what: format!("the elements of kind {kind:?} in the mesh store"),
                value: u64::from(old) + u64::from(n),
                limit_name,
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
    pub chains: wgpu::Buffer,
    pub split: Split,
}

/// First element of the second binding of the vertex and per-triangle buffers; equal to
/// the capacity (no second binding) when one binding holds them all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Split {
    pub vertices: u32,
    pub triangles: u32,
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
}
