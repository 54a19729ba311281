//! # wirepass
//!
//! Mesh wireframes drawn as a **deferred, compute-shader post-process** on wgpu: a visibility
//! pass writes a triangle id and depth per pixel, and a compute pass reconstructs, per pixel,
//! the exact screen-space distance to the visible triangle's edges and composites the shaded
//! colour with the line. Its cost depends on the pixel count, not on the triangle count.
//!
//! The pass lives in the host's frame: the host owns the device, the encoder and the
//! targets; meshes are uploaded once into a [`MeshStore`]; each frame is a [`Scene`] of
//! [`Instance`]s seen through a [`View`] (the host's own matrices, or a [`Camera`]), which
//! [`DeferredPass::prepare`] checks and uploads and [`DeferredPass::encode`] records. The
//! result goes to a storage texture ([`OutputTarget::Shaded`], [`OutputTarget::Overlay`]) or
//! into the host's own render pass ([`DeferredPass::render`], any colour format, MSAA, with
//! the host's depth hiding lines through [`Canvas::with_host_depth`]). Everything runs on a
//! device opened with `wgpu::Limits::default()`, and every misuse is an [`Error`].
//!
//! ## A frame, headless
//!
//! ```
//! use wirepass::glam::DMat4;
//! use wirepass::gpu::texture_2d;
//! use wirepass::{
//!     wgpu, Camera, DeferredPass, EdgeSelection, Instance, MeshStore, OutputTarget,
//!     PassOptions, Scene, Style,
//! };
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // The host's device: here a headless one with the WebGPU default limits.
//! let instance =
//!     wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
//! let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
//! let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
//!
//! // Once: the pass, and the meshes.
//! let mut pass = DeferredPass::new(&device, PassOptions::default())?;
//! let mut meshes = MeshStore::new(&device);
//! let torus = wirepass::mesh::torus(2000)?;
//! let id = meshes.insert(&device, &queue, &torus, EdgeSelection::Polygon)?;
//!
//! // Each frame: instances, a view, a style; prepare, then encode into the host's encoder.
//! let size = (320, 240);
//! let (lo, hi) = torus.bounds_f64();
//! let view = Camera::framing(lo, hi, 320.0 / 240.0).to_view(320.0 / 240.0);
//! let instances = [Instance::new(id, DMat4::IDENTITY)];
//! let scene = Scene::borrowed(view, &instances);
//! let frame = pass.prepare(&device, &meshes, &scene, &Style::default(), size)?;
//!
//! // RENDER_ATTACHMENT lets the pass clear the background instead of writing it.
//! use wgpu::TextureUsages as U;
//! let usage = U::STORAGE_BINDING | U::COPY_SRC | U::RENDER_ATTACHMENT;
//! let output = texture_2d(&device, "output", size, pass.output_format(), usage);
//! let mut encoder = device.create_command_encoder(&Default::default());
//! let target = output.create_view(&Default::default());
//! pass.encode(&device, &mut encoder, &meshes, &frame, OutputTarget::Shaded(&target))?;
//! queue.submit([encoder.finish()]);
//!
//! let rgba = wirepass::gpu::read_texture(&device, &queue, &output, wgpu::TextureAspect::All)?;
//! assert_eq!(rgba.len(), 4 * 320 * 240);
//! # Ok(())
//! # }
//! ```
//!
//! ## Features
//!
//! By default the crate is the pass alone (wgpu without backends, which the host picks
//! through its own wgpu dependency, glam, bytemuck, thiserror, pollster). `formats` adds the
//! mesh loaders (OBJ, STL, PLY, glTF), `parallel` preprocessing on all cores, `regression`
//! FLIP image comparison, `diagnostics` what tools measure the pass with (the benchmark
//! floor, diagnostic maps, timestamps: `gpu::EncodeOptions`), `truth` the ray-cast ground
//! truth, `drawing` the technical drawings (the exact visible and hidden lines as SVG, PDF
//! and DXF, on the CPU), and `tools` all of them with offline frames, compare and bench. The `wirepass`
//! command is the workspace's `wirepass-cli` package.
//!
//! ## Layers
//!
//! Each depends only on those before it (a test checks every file): [`error`]; the frame's
//! terms ([`camera`], [`style`]) and [`mesh`]; `edge_math`; the loaders
//! (`mesh::formats`); the pass ([`scene`], [`gpu`]); the world of meshes tools draw
//! (`world`); the ground truth (`truth`) and the drawings (`drawing`); the tools (`tools`).

#![warn(missing_docs)]

pub mod camera;
// The f64 twins of the shaders' edge math: public for the ground truth and the tests.
#[cfg(feature = "truth")]
pub mod edge_math;
#[cfg(not(feature = "truth"))]
#[allow(dead_code, unused_imports)]
pub(crate) mod edge_math;
pub mod error;
pub mod gpu;
pub mod mesh;
pub mod scene;
pub mod style;

#[cfg(any(feature = "truth", feature = "drawing"))]
pub mod world;

#[cfg(feature = "truth")]
pub mod truth;

#[cfg(feature = "drawing")]
pub mod drawing;

#[cfg(any(feature = "tools", feature = "regression"))]
pub mod tools;

pub use camera::{Camera, DepthRange, View};
pub use error::{Error, Result};
pub use gpu::{
    Canvas, Composite, DeferredPass, HostDepth, MeshId, MeshStore, OutputTarget, PassOptions,
    PreparedFrame, RenderTarget, TriangleIds, Tuning,
};
pub use mesh::{EdgeSelection, Mesh};
pub use scene::{
    HiddenOverride, Highlight, Instance, InstanceStyle, Scene, SectionPlane, MAX_SECTIONS,
};
pub use style::{Color, HiddenLines, LinePattern, Style};

/// The wgpu this crate is built against: use it (`wirepass::wgpu`) so the host's types match.
pub use wgpu;

/// The glam this crate's API uses for vectors and matrices.
pub use glam;
