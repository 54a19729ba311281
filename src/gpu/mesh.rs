//! A mesh's GPU buffers.

use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use glam::DVec3;
use wgpu::util::DeviceExt;

/// A mesh uploaded for drawing: positions, normals, indices, the packed edge mask and the
/// edge adjacency (for the edge pass's exact coverage walk) in storage buffers (positions and indices double as vertex and index buffers).
///
/// Positions are stored relative to the centre of the mesh bounds, `origin`, so that f32
/// keeps its precision for meshes far from the world origin; the per-frame matrix adds the
/// translation back in f64.
pub struct GpuMesh {
    pub(crate) positions: wgpu::Buffer,
    pub(crate) normals: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) edge_masks: wgpu::Buffer,
    pub(crate) neighbours: wgpu::Buffer,
    /// `Cluster` bounds (common.wgsl) per
    /// [`CLUSTER_TRIANGLES`](crate::mesh::clusters::CLUSTER_TRIANGLES) triangles, for the outline
    /// pass's cull.
    pub(crate) clusters: wgpu::Buffer,
    /// Triangle ids in cluster order (`Clusters::order`).
    pub(crate) cluster_triangles: wgpu::Buffer,
    /// The outline pass's scratch: a count and a list of clusters, and the indirect
    /// dispatch size for visiting them (apart, as a buffer cannot be written and read as
    /// dispatch size in one dispatch).
    pub(crate) outline_list: wgpu::Buffer,
    pub(crate) outline_args: wgpu::Buffer,
    pub(crate) triangles: u32,
    /// Triangles in the first binding of `indices` and `neighbours`; the rest go in a second
    /// (see [`GpuMesh::halves`]). Equal to `triangles` when one binding holds them all.
    pub(crate) split: u32,
    pub(crate) origin: DVec3,
    pub(crate) bytes: u64,
}

impl GpuMesh {
    /// Uploads `mesh`, drawing the edges that `edges` selects.
    pub fn new(device: &wgpu::Device, mesh: &Mesh, edges: EdgeSelection) -> Result<Self> {
        // Limits first, from the counts alone, before any large allocation.
        let (vertices, triangles) = (mesh.positions().len() as u64, mesh.triangle_count() as u64);
        let split = split_point(&device.limits(), vertices, triangles)?;
        let (lo, hi) = mesh.bounds();
        let origin = (lo.as_dvec3() + hi.as_dvec3()) * 0.5;
        let positions: Vec<f32> = mesh
            .positions()
            .iter()
            .flat_map(|p| (p.as_dvec3() - origin).as_vec3().to_array())
            .collect();
        let normals: Vec<f32> = mesh.normals().iter().flat_map(|n| n.to_array()).collect();
        let indices: &[u32] = bytemuck::cast_slice(mesh.triangles());
        let masks = packed_masks(mesh, edges);
        let neighbours: &[u32] = bytemuck::cast_slice(mesh.edge_neighbours());
        let clusters = gpu_clusters(mesh, origin);
        let storage = wgpu::BufferUsages::STORAGE;
        let create = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let scratch = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: storage | wgpu::BufferUsages::COPY_DST | usage,
                mapped_at_creation: false,
            })
        };
        let cluster_count = mesh.outline_clusters().bounds.len() as u64;
        let outline_list = scratch(
            "wirepass outline list",
            4 + 4 * cluster_count,
            wgpu::BufferUsages::empty(),
        );
        let outline_args = scratch("wirepass outline args", 12, wgpu::BufferUsages::INDIRECT);
        let bytes = (positions.len() + normals.len() + indices.len() + neighbours.len()) as u64 * 4
            + masks.len() as u64
            + (clusters.len() * 4) as u64
            + triangles * 4
            + outline_list.size()
            + outline_args.size();
        Ok(Self {
            positions: create(
                "wirepass positions",
                bytemuck::cast_slice(&positions),
                storage | wgpu::BufferUsages::VERTEX,
            ),
            normals: create("wirepass normals", bytemuck::cast_slice(&normals), storage),
            indices: create(
                "wirepass indices",
                bytemuck::cast_slice(indices),
                storage | wgpu::BufferUsages::INDEX,
            ),
            edge_masks: create(
                "wirepass edge masks",
                &masks,
                storage | wgpu::BufferUsages::COPY_DST,
            ),
            neighbours: create(
                "wirepass edge neighbours",
                bytemuck::cast_slice(neighbours),
                storage,
            ),
            clusters: create(
                "wirepass outline clusters",
                bytemuck::cast_slice(&clusters),
                storage,
            ),
            cluster_triangles: create(
                "wirepass cluster triangles",
                bytemuck::cast_slice(&mesh.outline_clusters().order),
                storage,
            ),
            outline_list,
            outline_args,
            triangles: mesh.triangle_count() as u32,
            split,
            origin,
            bytes,
        })
    }

    /// The two bindings (first `split` triangles, then the rest) of a buffer of three u32s
    /// per triangle, `indices` or `neighbours`. A shader reads element k from the first while
    /// k < 3 × `Frame.index_split` and from the second after, so a mesh whose buffer exceeds
    /// `max_storage_buffer_binding_size` still renders. Unsplit, both bind the whole buffer.
    pub(crate) fn halves<'a>(&self, buffer: &'a wgpu::Buffer) -> [wgpu::BindingResource<'a>; 2] {
        if self.split == self.triangles {
            return [buffer.as_entire_binding(), buffer.as_entire_binding()];
        }
        let at = u64::from(self.split) * 12;
        [
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer,
                offset: 0,
                size: wgpu::BufferSize::new(at),
            }),
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer,
                offset: at,
                size: None,
            }),
        ]
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> u32 {
        self.triangles
    }

    /// The mesh-local origin its positions are stored relative to.
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// GPU memory the mesh's buffers take, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        self.bytes
    }

    /// Re-uploads the edge mask, e.g. to switch between edge selections without a new mesh.
    pub fn set_edges(&self, queue: &wgpu::Queue, mesh: &Mesh, edges: EdgeSelection) -> Result<()> {
        if mesh.triangle_count() as u32 != self.triangles {
            return Err(Error::InvalidMesh(format!(
                "edge mask for {} triangles given to a mesh of {}",
                mesh.triangle_count(),
                self.triangles
            )));
        }
        queue.write_buffer(&self.edge_masks, 0, &packed_masks(mesh, edges));
        Ok(())
    }
}

/// The mesh's cluster bounds as `Cluster`s (common.wgsl): centre relative to `origin`, radius,
/// axis and spread, eight f32s each. The radius grows by the f32 rounding of itself and the
/// centre.
fn gpu_clusters(mesh: &Mesh, origin: DVec3) -> Vec<f32> {
    mesh.outline_clusters()
        .bounds
        .iter()
        .flat_map(|c| {
            let center = c.center - origin;
            let radius = c.radius * (1.0 + 1e-6) + center.length() * 1e-6;
            let [x, y, z] = center.as_vec3().to_array();
            let [ax, ay, az] = c.axis.as_vec3().to_array();
            [x, y, z, radius as f32, ax, ay, az, c.spread as f32]
        })
        .collect()
}

/// A byte per triangle, padded to whole words: the edge mask in bits 0–2 and the outline
/// hints (`Mesh::outline_hints`) in bits 3–7.
fn packed_masks(mesh: &Mesh, edges: EdgeSelection) -> Vec<u8> {
    let mut masks: Vec<u8> = mesh
        .edge_mask(edges)
        .iter()
        .zip(mesh.outline_hints())
        .map(|(m, h)| m | (h << 3))
        .collect();
    masks.resize(masks.len().div_ceil(4) * 4, 0);
    masks
}

/// Where the per-triangle buffers (indices, neighbours: 12 bytes a triangle) split into two
/// bindings: the triangle count when one binding holds them, else the most triangles a
/// binding holds with the second binding's offset aligned. Errors name the limit a mesh
/// exceeds: per-vertex buffers must fit one binding, per-triangle buffers two, and every
/// buffer `max_buffer_size`.
pub(crate) fn split_point(limits: &wgpu::Limits, vertices: u64, triangles: u64) -> Result<u32> {
    let binding = limits.max_storage_buffer_binding_size;
    let over = |what: &str, value, limit_name, limit| Error::OverLimit {
        what: format!("the size in bytes of the {what} of a {triangles}-triangle mesh"),
        value,
        limit_name,
        limit,
    };
    for (what, len) in [
        ("vertex positions buffer", vertices * 12),
        ("vertex normals buffer", vertices * 12),
        ("triangle indices buffer", triangles * 12),
    ] {
        if len > limits.max_buffer_size {
            return Err(over(what, len, "max_buffer_size", limits.max_buffer_size));
        }
    }
    for (what, len) in [
        ("vertex positions buffer", vertices * 12),
        ("vertex normals buffer", vertices * 12),
    ] {
        if len > binding {
            return Err(over(what, len, "max_storage_buffer_binding_size", binding));
        }
    }
    if triangles * 12 <= binding {
        return Ok(triangles as u32);
    }
    // The second binding's offset must be a multiple of the alignment and of 12 bytes.
    let align = u64::from(limits.min_storage_buffer_offset_alignment.max(4));
    let unit = align / gcd(align, 12) * 12;
    let first = binding / unit * unit / 12;
    let rest = (triangles - first) * 12;
    if first == 0 || rest > binding {
        return Err(over(
            "triangle indices buffer (split over two bindings)",
            triangles * 12,
            "max_storage_buffer_binding_size × 2",
            2 * binding,
        ));
    }
    Ok(first as u32)
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(binding: u64) -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: binding,
            max_buffer_size: 1 << 40,
            min_storage_buffer_offset_alignment: 256,
            ..wgpu::Limits::default()
        }
    }

    #[test]
    fn split_only_past_the_binding_limit() {
        let l = limits(128 << 20);
        assert_eq!(split_point(&l, 10, 1000).unwrap(), 1000);
        let t = (128u64 << 20) / 12 + 1000;
        let s = u64::from(split_point(&l, 10, t).unwrap());
        assert!(s * 12 <= 128 << 20 && (s * 12) % 256 == 0 && s * 12 > (128 << 20) - 768);
        // 20 M triangles (240 MB of indices) fit two 128 MiB bindings.
        assert!(split_point(&l, 10_000_002, 20_000_000).is_ok());
    }

    #[test]
    fn past_two_bindings_is_an_error_naming_the_limit() {
        let l = limits(1 << 16);
        let e = split_point(&l, 10, 12_000).unwrap_err().to_string();
        assert!(e.contains("max_storage_buffer_binding_size × 2"), "{e}");
        let e = split_point(&l, 6000, 10).unwrap_err().to_string();
        assert!(e.contains("vertex positions"), "{e}");
    }
}
