//! The pass on the GPU: the mesh store, a frame's scene data and targets, and the passes.
//! [`DeferredPass`] orchestrates a frame's sub-passes, each in a file of its own
//! (`visibility`, `host_depth`, the trace and edge dispatches, `composite`); the
//! forward methods it is measured against are in `baselines` (feature `diagnostics`). It uses the frame's terms
//! (camera, scene, style, edge math) and the meshes, nothing of the loaders, the ground truth
//! or the tools.

// The forward methods the pass is measured against: public for the tools that measure.
#[cfg(feature = "diagnostics")]
pub mod baselines;
#[cfg(not(feature = "diagnostics"))]
#[allow(dead_code, unused_imports)]
mod baselines;
mod bindings;
mod canvas;
mod composite;
#[cfg(all(feature = "tools", not(target_arch = "wasm32")))]
mod context;
mod deferred;
#[cfg(feature = "diagnostics")]
mod deferred_diagnostics;
#[cfg(feature = "diagnostics")]
mod diagnostics;
mod edge_pass;
mod frame;
mod host_depth;
mod instance_crossings;
mod loop_budget;
mod mesh_records;
mod mesh_store;
mod options;
mod pick;
mod readback;
mod trace_pass;
// The WGSL sources and their assembly: public for the tests that validate them.
#[cfg(feature = "diagnostics")]
pub mod shaders;
#[cfg(not(feature = "diagnostics"))]
mod shaders;
mod targets;
#[cfg_attr(not(feature = "diagnostics"), allow(dead_code))]
mod timing;
mod validation;
mod variants;
mod visibility;

pub use crate::scene::MAX_INSTANCES;
#[cfg(feature = "diagnostics")]
pub use baselines::MAPS_DIAGNOSTIC_FORMAT;
#[cfg(feature = "diagnostics")]
pub use baselines::{drawn_edges, EdgeLines, ForwardPass, RasterFrame, TwoPass};
pub use canvas::{Canvas, HostDepth, Region};
pub use composite::{Composite, RenderTarget};
// An adapter and device for the command line, the tools and the tests.
#[cfg(all(feature = "tools", not(target_arch = "wasm32")))]
pub use context::GpuContext;
pub use deferred::{DeferredPass, PreparedFrame, WarmUp};
#[cfg(feature = "diagnostics")]
pub use deferred_diagnostics::EdgeWork;
#[cfg(feature = "diagnostics")]
pub use diagnostics::EncodeOptions;
// For the ground truth, which shades and reads host depth as the pass does.
#[cfg(feature = "truth")]
pub(crate) use frame::light_world_dir;
#[cfg(feature = "truth")]
pub(crate) use host_depth::depth_quantum;
pub use mesh_records::UploadReport;
pub use mesh_store::{MeshId, MeshStore};
// For the tools' OpenGL baseline, which draws the same store and records.
pub use options::{OutputTarget, PassOptions, TriangleIds, Tuning};
pub use pick::{
    EdgeSnap, InstanceHit, Location, PickView, Picked, PickedIds, RectPick, SnapVertices,
    VertexSnap,
};
#[cfg(not(target_arch = "wasm32"))]
pub use readback::read_texture;
pub use readback::read_texture_async;
pub use targets::{check_size, texture_2d, BACKGROUND_ID, DEPTH_FORMAT, HOST_ID, ID_FORMAT};
#[cfg(feature = "diagnostics")]
pub use targets::{DIAGNOSTIC_FORMAT, RESOLVED_ID_FORMAT};
#[cfg(feature = "diagnostics")]
pub use timing::GpuTimer;
#[cfg(not(feature = "diagnostics"))]
use timing::GpuTimer;
#[cfg(feature = "diagnostics")]
pub use variants::shader_modules;
#[cfg(all(feature = "tools", not(target_arch = "wasm32")))]
pub(crate) use {
    frame::{FrameRecords, INSTANCE_BYTES, UNIFORM_INSTANCE_CAPACITY},
    mesh_store::VERTEX_BYTES,
    readback::read_buffer,
    shaders::NO_EDGE,
};
