//! The pass on the GPU: the mesh store, a frame's scene data and targets, and the passes.
//! [`DeferredPass`] orchestrates a frame's sub-passes, each in a file of its own
//! (`visibility`, `host_depth`, the outline and edge dispatches, `composite`); the
//! forward methods it is measured against are in [`baselines`]. It uses the frame's terms
//! (camera, scene, style, edge math) and the meshes, nothing of the loaders, the ground truth
//! or the tools.

pub mod baselines;
mod bindings;
mod composite;
mod context;
mod deferred;
#[cfg(feature = "diagnostics")]
mod diagnostics;
mod edge_pass;
mod frame;
mod host_depth;
mod mesh_records;
mod mesh_store;
mod options;
mod outline_pass;
mod readback;
pub mod shaders;
mod targets;
#[cfg_attr(not(feature = "diagnostics"), allow(dead_code))]
mod timing;
mod variants;
mod visibility;

pub use baselines::{
    drawn_edges, EdgeLines, ForwardPass, RasterFrame, TwoPass, MAPS_DIAGNOSTIC_FORMAT,
};
pub use composite::{Composite, RenderTarget};
pub use context::GpuContext;
#[cfg(feature = "diagnostics")]
pub use deferred::EdgeWork;
pub use deferred::{DeferredPass, PreparedFrame};
#[cfg(feature = "diagnostics")]
pub use diagnostics::EncodeOptions;
pub use frame::{light_world_dir, Canvas, Region, MAX_INSTANCES};
pub use host_depth::{depth_quantum, HostDepth};
pub use mesh_store::{MeshId, MeshStore};
pub use options::{OutputTarget, PassOptions, TriangleIds};
pub use readback::read_texture;
pub use targets::{
    BACKGROUND_ID, DEPTH_FORMAT, DIAGNOSTIC_FORMAT, HOST_FORMAT, HOST_ID, ID_FORMAT,
    RESOLVED_ID_FORMAT, RESULT_FORMAT,
};
#[cfg(feature = "diagnostics")]
pub use timing::GpuTimer;
#[cfg(not(feature = "diagnostics"))]
use timing::GpuTimer;

use crate::error::{Error, Result};

/// Creates a bind group that may hold the host's resources, turning wgpu's validation of
/// them (a view from another device, say) into an [`Error::Misuse`] before anything uses
/// the group.
pub(crate) fn bind_host_resources(
    device: &wgpu::Device,
    desc: &wgpu::BindGroupDescriptor<'_>,
) -> Result<wgpu::BindGroup> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let group = device.create_bind_group(desc);
    match pollster::block_on(scope.pop()) {
        None => Ok(group),
        Some(e) => Err(Error::Misuse(format!(
            "a texture given to the pass cannot be bound (from another device?): {e}"
        ))),
    }
}

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
