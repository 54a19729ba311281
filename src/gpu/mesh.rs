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
    pub(crate) triangles: u32,
    pub(crate) origin: DVec3,
    pub(crate) bytes: u64,
}

impl GpuMesh {
    /// Uploads `mesh`, drawing the edges that `edges` selects.
    pub fn new(device: &wgpu::Device, mesh: &Mesh, edges: EdgeSelection) -> Result<Self> {
        // Limits first, from the counts alone, before any large allocation.
        let limits = device.limits();
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let (vertices, triangles) = (mesh.positions().len() as u64, mesh.triangle_count() as u64);
        for (what, len) in [
            ("vertex positions", vertices * 12),
            ("vertex normals", vertices * 12),
            ("triangle indices", triangles * 12),
            ("edge neighbours", triangles * 12),
        ] {
            if len > limit {
                return Err(Error::OverLimit {
                    what: format!(
                        "the size in bytes of the {what} buffer of a {triangles}-triangle mesh"
                    ),
                    value: len,
                    limit_name: "max_storage_buffer_binding_size",
                    limit,
                });
            }
        }

        let (lo, hi) = mesh.bounds();
        let origin = (lo.as_dvec3() + hi.as_dvec3()) * 0.5;
        let positions: Vec<f32> = mesh
            .positions()
            .iter()
            .flat_map(|p| (p.as_dvec3() - origin).as_vec3().to_array())
            .collect();
        let normals: Vec<f32> = mesh.normals().iter().flat_map(|n| n.to_array()).collect();
        let indices: &[u32] = bytemuck::cast_slice(mesh.triangles());
        let mut masks = mesh.edge_mask(edges);
        masks.resize(masks.len().div_ceil(4) * 4, 0);
        let neighbours: &[u32] = bytemuck::cast_slice(mesh.edge_neighbours());
        let storage = wgpu::BufferUsages::STORAGE;
        let create = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let bytes = (positions.len() + normals.len() + indices.len() + neighbours.len()) as u64 * 4
            + masks.len() as u64;
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
            triangles: mesh.triangle_count() as u32,
            origin,
            bytes,
        })
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
        let mut masks = mesh.edge_mask(edges);
        masks.resize(masks.len().div_ceil(4) * 4, 0);
        queue.write_buffer(&self.edge_masks, 0, &masks);
        Ok(())
    }
}
