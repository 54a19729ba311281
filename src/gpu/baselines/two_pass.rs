//! The two-pass baseline, the "standard" approach the single-pass paper set out to beat: a
//! shaded fill pushed back with a depth bias, then the drawn edges as hardware lines over it.
//!
//! `PolygonMode::Line` for the second pass would draw every triangle edge, polygon diagonals
//! included, and needs `Features::POLYGON_MODE_LINE`, which WebGPU and GL lack. This pass
//! draws, per mesh, an instanced `LineList` of the mesh's **unique drawn edges** instead
//! ([`EdgeLines`], built once per mesh and edge selection on the CPU): masked edges are never
//! drawn, each shared edge is drawn once (so a translucent wire colour is not blended twice),
//! and it runs on every adapter. So it needs no optional feature and never returns
//! [`Error::MissingFeature`] for one.

use super::raster::{
    check_vertex_storage, color_targets, depth_state, encode_snippet, pipeline_layout, slot_layout,
    RasterFrame,
};
use crate::error::{Error, Result};
use crate::gpu::mesh_store::VERTEX_BYTES;
#[cfg(feature = "diagnostics")]
use crate::gpu::EncodeOptions;
use crate::gpu::{shaders, GpuTimer, MeshId, MeshStore};
use crate::mesh::{EdgeSelection, Mesh};
use crate::scene::Scene;
use crate::style::Style;
use std::collections::{BTreeSet, HashMap};
use std::sync::atomic::{AtomicU32, Ordering};
use wgpu::util::DeviceExt;

/// The fill's depth bias: the customary `glPolygonOffset(1, 1)`, mirrored for reverse depth,
/// where nearer is *greater*, so pushing the fill back means a **negative** bias. The slope
/// term covers the difference between where a line and the fill sample the same edge (up to
/// about a pixel apart); without it about an eighth of the edge pixels lose their line
/// (Suzanne at 512²). Its cost is the method's known artefact: at grazing angles the slope
/// term pushes a triangle behind the surface behind it, so near silhouettes the fill's ids
/// differ from the deferred pass's (0.4 % of Suzanne's pixels at 256²) and hidden lines can
/// show through.
pub(crate) const FILL_DEPTH_BIAS: wgpu::DepthBiasState = wgpu::DepthBiasState {
    constant: -1,
    slope_scale: -1.0,
    clamp: 0.0,
};

/// The two-pass module for an output of `format`: common.wgsl, scene.wgsl, forward.wgsl
/// and two_pass.wgsl.
pub(crate) fn two_pass_source(format: wgpu::TextureFormat, split: bool) -> Option<String> {
    if !two_pass_format(format) {
        return None;
    }
    let encode = encode_snippet(format)?;
    let flags: &[&str] = if split { &["SPLIT"] } else { &[] };
    Some(shaders::assemble(
        &[shaders::SCENE, shaders::FORWARD, shaders::TWO_PASS, encode],
        flags,
    ))
}

/// Output formats the line pass can alpha-blend into without extra features.
fn two_pass_format(format: wgpu::TextureFormat) -> bool {
    use wgpu::TextureFormat as F;
    matches!(format, F::Rgba8Unorm | F::Rgba8UnormSrgb | F::Rgba16Float)
}

/// The unique undirected edges that `edges` draws, as sorted vertex-index pairs `[a, b]`
/// with `a < b`. An edge is drawn when any triangle that has it draws it. Vertices with
/// bit-identical positions count as one (OBJ loaders split vertices by normal or texture
/// coordinate), so a seam is drawn once; each pair uses the lowest such vertex index.
pub fn drawn_edges(mesh: &Mesh, edges: EdgeSelection) -> Vec<[u32; 2]> {
    let positions = mesh.positions();
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let canonical: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let key = p.to_array().map(|c| (c + 0.0).to_bits()); // -0.0 == 0.0
            *first.entry(key).or_insert(i as u32)
        })
        .collect();
    let mask = mesh.edge_mask(edges);
    let mut set = BTreeSet::new();
    for (tri, &m) in mesh.triangles().iter().zip(&mask) {
        for i in 0..3 {
            if m & (1 << i) == 0 {
                continue;
            }
            let a = canonical[tri[i] as usize];
            let b = canonical[tri[(i + 1) % 3] as usize];
            if a != b {
                set.insert([a.min(b), a.max(b)]);
            }
        }
    }
    set.into_iter().collect()
}

/// The meshes' drawn edges as `LineList` index buffers over the [`MeshStore`]'s vertices,
/// for [`TwoPass`]: one list per mesh, built on the CPU from the mesh and its edge
/// selection (insert it again after [`MeshStore::set_edges`]).
#[derive(Default)]
pub struct EdgeLines {
    lists: HashMap<MeshId, (Option<wgpu::Buffer>, u32)>,
}

impl EdgeLines {
    /// No lists yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds the index buffer of [`drawn_edges`] for mesh `id`, inserted from `mesh`.
    pub fn insert(
        &mut self,
        device: &wgpu::Device,
        store: &MeshStore,
        id: MeshId,
        mesh: &Mesh,
        edges: EdgeSelection,
    ) -> Result<()> {
        let stored = store.triangle_count(id)?;
        if u64::from(stored) != mesh.triangle_count() as u64 {
            return Err(Error::Misuse(format!(
                "edge lines of a {}-triangle mesh for a stored mesh of {stored}",
                mesh.triangle_count(),
            )));
        }
        let list = drawn_edges(mesh, edges);
        let bytes = list.len() as u64 * 8;
        let limit = device.limits().max_buffer_size;
        if bytes > limit {
            return Err(Error::OverLimit {
                what: "the edge-list index buffer, in bytes".into(),
                value: bytes,
                limit_name: "max_buffer_size",
                limit,
            });
        }
        let indices = (!list.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("wirepass edge lines"),
                contents: bytemuck::cast_slice(&list),
                usage: wgpu::BufferUsages::INDEX,
            })
        });
        self.lists.insert(id, (indices, list.len() as u32));
        Ok(())
    }

    /// GPU memory of the line index buffers, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        self.lists.values().map(|l| u64::from(l.1) * 8).sum()
    }

    /// Lines drawn for one instance of each mesh.
    pub fn edge_count(&self) -> u32 {
        self.lists.values().map(|l| l.1).sum()
    }
}

struct Pipelines {
    layout: wgpu::BindGroupLayout,
    fill: wgpu::RenderPipeline,
    fill_maps: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
    lines_maps: wgpu::RenderPipeline,
}

/// The two-pass wireframe baseline: a shaded fill (the deferred pass's shading) with a depth
/// bias, then the drawn edges ([`EdgeLines`]) as 1-pixel hardware lines
/// in each instance's wire colour, alpha-blended, depth-tested against the fill.
///
/// Hardware lines are one pixel wide whatever the style's line width (wgpu has no wide
/// lines) and are not antialiased; a line width of 0 draws no lines. With an `Rgba8Unorm`
/// output the shader encodes sRGB itself, so a translucent wire colour blends in encoded
/// space; `Rgba8UnormSrgb` and `Rgba16Float` blend in linear space.
///
/// Maps (`encode_with` and `EncodeOptions::maps`, feature `diagnostics`): ids and depth come from the fill. No
/// distance is measured, so the diagnostic map's distance (red) is honest rather than
/// estimated: 0 where a line fragment was drawn (background included, where a silhouette
/// line spills over), 3e38 (no edge) everywhere else.
pub struct TwoPass {
    id: u32,
    format: wgpu::TextureFormat,
    pipelines: [Option<Pipelines>; 2],
}

impl TwoPass {
    /// Builds the pipelines for an output of `format`: `Rgba8Unorm`,
    /// `Rgba8UnormSrgb` or `Rgba16Float` (the line pass blends, which `Rgba32Float` cannot
    /// without an extra feature). The output needs `RENDER_ATTACHMENT` usage.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Result<Self> {
        static NEXT: AtomicU32 = AtomicU32::new(1);
        if two_pass_source(format, false).is_none() {
            return Err(Error::InvalidSetting(format!(
                "output format {format:?} is not one the two-pass method can render to \
                 (Rgba8Unorm, Rgba8UnormSrgb, Rgba16Float)"
            )));
        }
        check_vertex_storage(device, &device.adapter_info().name)?;
        let mut pass = Self {
            id: NEXT.fetch_add(1, Ordering::Relaxed) | 0x4000_0000,
            format,
            pipelines: [None, None],
        };
        pass.pipelines[0] = Some(pass.build(device, false)?);
        Ok(pass)
    }

    fn build(&self, device: &wgpu::Device, split: bool) -> Result<Pipelines> {
        let format = self.format;
        let source = two_pass_source(format, split)
            .ok_or_else(|| Error::InvalidSetting(format!("{format:?}")))?;
        let scope = crate::gpu::validation::Validation::begin(device);
        let (layout, pipeline_layout) = pipeline_layout(device, "wirepass two-pass", split)?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass two-pass"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let position_layout = wgpu::VertexBufferLayout {
            array_stride: VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let pipeline = |line: bool, maps: bool| {
            let output = wgpu::ColorTargetState {
                format,
                blend: line.then_some(wgpu::BlendState::ALPHA_BLENDING),
                write_mask: wgpu::ColorWrites::ALL,
            };
            let targets = if line {
                color_targets(
                    output,
                    maps,
                    wgpu::ColorWrites::empty(),
                    wgpu::ColorWrites::RED,
                )
            } else {
                color_targets(output, maps, wgpu::ColorWrites::ALL, wgpu::ColorWrites::ALL)
            };
            let (vs, fs) = match (line, maps) {
                (false, false) => ("vs_main", "fs_fill"),
                (false, true) => ("vs_main", "fs_fill_maps"),
                (true, false) => ("vs_line", "fs_line"),
                (true, true) => ("vs_line", "fs_line_maps"),
            };
            let buffers = if line {
                vec![Some(position_layout.clone()), Some(slot_layout())]
            } else {
                vec![Some(slot_layout())]
            };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(if line {
                    "wirepass two-pass lines"
                } else {
                    "wirepass two-pass fill"
                }),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: if line {
                        wgpu::PrimitiveTopology::LineList
                    } else {
                        wgpu::PrimitiveTopology::TriangleList
                    },
                    ..Default::default()
                },
                depth_stencil: Some(if line {
                    depth_state(
                        wgpu::CompareFunction::GreaterEqual,
                        false,
                        Default::default(),
                    )
                } else {
                    depth_state(wgpu::CompareFunction::Greater, true, FILL_DEPTH_BIAS)
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let p = Pipelines {
            layout,
            fill: pipeline(false, false),
            fill_maps: pipeline(false, true),
            lines: pipeline(true, false),
            lines_maps: pipeline(true, true),
        };
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("creating the two-pass method: {e}")));
        }
        Ok(p)
    }

    /// The output format chosen at construction.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Validates the scene, style and size and uploads the frame.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        size: (u32, u32),
    ) -> Result<RasterFrame> {
        let frame = RasterFrame::new(self.id, device, store, scene, style, size)?;
        if frame.data.split() && self.pipelines[1].is_none() {
            self.pipelines[1] = Some(self.build(device, true)?);
        }
        Ok(frame)
    }

    /// Records both passes into `output` (cleared to the background first). `lines` holds
    /// the edge list of every mesh the frame draws.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (store, lines): (&MeshStore, &EdgeLines),
        frame: &RasterFrame,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, (store, lines), frame, output, false, None)
    }

    /// [`encode`](Self::encode) with what tools add: timestamps (fill and lines share one
    /// render pass, the span `"draw"`), and the id and diagnostic maps.
    #[cfg(feature = "diagnostics")]
    pub fn encode_with(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (store, lines): (&MeshStore, &EdgeLines),
        frame: &RasterFrame,
        output: &wgpu::TextureView,
        options: EncodeOptions<'_>,
    ) -> Result<()> {
        let (maps, timer) = (options.maps, options.timer);
        self.record(device, encoder, (store, lines), frame, output, maps, timer)
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (store, lines): (&MeshStore, &EdgeLines),
        frame: &RasterFrame,
        output: &wgpu::TextureView,
        maps: bool,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        frame.check(self.id, store)?;
        frame.check_output(output, self.format)?;
        let draws = &frame.data.draws;
        let mut lists = Vec::with_capacity(draws.len());
        for d in draws {
            let list = lines.lists.get(&d.mesh).ok_or_else(|| {
                Error::Misuse("a mesh of the frame has no edge lines (EdgeLines::insert)".into())
            })?;
            lists.push(list);
        }
        let p = self.pipelines[usize::from(frame.data.split())]
            .as_ref()
            .ok_or_else(|| Error::Misuse("the frame was not prepared by this pass".into()))?;
        let group = frame.bind(device, &p.layout)?;
        let writes = timer.and_then(|t| t.render_span("draw"));
        let mut pass = frame.begin(
            encoder,
            "wirepass two-pass",
            (output, self.format),
            maps,
            writes,
        );
        pass.set_pipeline(if maps { &p.fill_maps } else { &p.fill });
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, frame.data.instances.slice(..));
        for d in draws {
            pass.draw(0..3 * d.triangles, d.instances.clone());
        }
        pass.set_pipeline(if maps { &p.lines_maps } else { &p.lines });
        pass.set_vertex_buffer(0, frame.data.store.vertices.slice(..));
        pass.set_vertex_buffer(1, frame.data.instances.slice(..));
        for (d, (indices, count)) in draws.iter().zip(lists) {
            if let Some(indices) = indices {
                pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..2 * count, d.base_vertex, d.instances.clone());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn edge_list_skips_masked_diagonals_and_duplicates() {
        // A quad as two triangles sharing the masked diagonal 0-2, and a duplicate of vertex
        // 0 (same position, index 4) used by the second triangle.
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
        ];
        let mesh = Mesh::new(
            p,
            None,
            vec![[0, 1, 2], [4, 2, 3]],
            Some(vec![0b011, 0b110]),
        )
        .unwrap();
        assert_eq!(
            drawn_edges(&mesh, EdgeSelection::Polygon),
            vec![[0, 1], [0, 3], [1, 2], [2, 3]]
        );
        assert_eq!(drawn_edges(&mesh, EdgeSelection::All).len(), 5);
    }

    #[test]
    fn float32_output_is_refused() {
        assert!(two_pass_source(wgpu::TextureFormat::Rgba32Float, false).is_none());
        assert!(two_pass_source(wgpu::TextureFormat::Rgba8UnormSrgb, false).is_some());
    }
}
