//! The two-pass baseline, the "standard" approach the single-pass paper set out to beat: a
//! shaded fill pushed back with a depth bias, then the drawn edges as hardware lines over it.
//!
//! The issue allows `PolygonMode::Line` for the second pass, but that draws every triangle
//! edge, polygon diagonals included, and needs `Features::POLYGON_MODE_LINE`, which WebGPU and
//! GL lack. This pass draws a `LineList` of the **unique drawn edges** instead ([`EdgeLines`],
//! built once per mesh and edge selection on the CPU): masked edges are never drawn, each
//! shared edge is drawn once (so a translucent wire colour is not blended twice), and it runs
//! on every adapter. So it needs no optional feature and never returns
//! [`Error::MissingFeature`] for one.

use super::forward::{
    check_vertex_storage, clear_color, color_targets, depth_state, encode_snippet, mesh_group,
    mesh_layout, Targets, Uniforms,
};
use super::{shaders, FrameUniforms, GpuMesh, GpuTimer, PassOptions};
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use crate::style::Style;
use std::collections::{BTreeSet, HashMap};
use wgpu::util::DeviceExt;

/// The fill's depth bias: the customary `glPolygonOffset(1, 1)`, mirrored for reverse-Z, where
/// nearer is *greater*, so pushing the fill back means a **negative** bias. The slope term
/// covers the difference between where a line and the fill sample the same edge (up to about
/// a pixel apart); without it about an eighth of the edge pixels lose their line (Suzanne at
/// 512²). Its cost is the method's known artefact: at grazing angles the slope term pushes a
/// triangle behind the surface behind it, so near silhouettes the fill's ids differ from the
/// deferred pass's (0.4 % of Suzanne's pixels at 256²) and hidden lines can show through.
pub const FILL_DEPTH_BIAS: wgpu::DepthBiasState = wgpu::DepthBiasState {
    constant: -1,
    slope_scale: -1.0,
    clamp: 0.0,
};

/// The two-pass module for an output of `format`: common.wgsl + forward.wgsl + two_pass.wgsl.
pub fn two_pass_source(format: wgpu::TextureFormat) -> Option<String> {
    if !two_pass_format(format) {
        return None;
    }
    let encode = encode_snippet(format)?;
    Some(shaders::assemble(&format!(
        "{}\n{}\n{encode}\n",
        shaders::FORWARD,
        shaders::TWO_PASS
    )))
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

/// A mesh's drawn edges as a `LineList` index buffer over its [`GpuMesh`] positions, for
/// [`TwoPass`]. Build it once per mesh and edge selection (and again after
/// [`GpuMesh::set_edges`]).
pub struct EdgeLines {
    indices: Option<wgpu::Buffer>,
    edges: u32,
    triangles: u32,
    vertices: u32,
}

impl EdgeLines {
    /// Builds the index buffer of [`drawn_edges`].
    pub fn new(device: &wgpu::Device, mesh: &Mesh, edges: EdgeSelection) -> Result<Self> {
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
        Ok(Self {
            indices,
            edges: list.len() as u32,
            triangles: mesh.triangle_count() as u32,
            vertices: mesh.positions().len() as u32,
        })
    }

    /// GPU memory of the line index buffer, in bytes.
    pub fn gpu_bytes(&self) -> u64 {
        u64::from(self.edges) * 8
    }

    /// Number of lines drawn.
    pub fn edge_count(&self) -> u32 {
        self.edges
    }

    fn check(&self, mesh: &GpuMesh) -> Result<()> {
        let vertices = mesh.positions.size() / 12;
        if self.triangles != mesh.triangles || u64::from(self.vertices) != vertices {
            return Err(Error::InvalidMesh(format!(
                "edge lines built for {} triangles and {} vertices used with a mesh of {} and {vertices}",
                self.triangles, self.vertices, mesh.triangles
            )));
        }
        Ok(())
    }
}

/// The two-pass wireframe baseline: a shaded fill (the deferred pass's shading) with a depth
/// bias ([`FILL_DEPTH_BIAS`]), then the drawn edges ([`EdgeLines`]) as 1-pixel hardware lines
/// in the wire colour, alpha-blended, depth-tested against the fill.
///
/// Hardware lines are one pixel wide whatever the style's line width (wgpu has no wide
/// lines) and are not antialiased; a line width of 0 draws no lines. With an `Rgba8Unorm`
/// output the shader encodes sRGB itself, so a translucent wire colour blends in encoded
/// space; `Rgba8UnormSrgb` and `Rgba16Float` blend in linear space.
///
/// Maps ([`encode_with_maps`](Self::encode_with_maps)): ids and depth come from the fill. No
/// distance is measured, so the diagnostic map's distance (red) is honest rather than
/// estimated: 0 where a line fragment was drawn (background included, where a silhouette
/// line spills over), 3e38 (no edge) everywhere else.
pub struct TwoPass {
    format: wgpu::TextureFormat,
    layout: wgpu::BindGroupLayout,
    fill: wgpu::RenderPipeline,
    fill_maps: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
    lines_maps: wgpu::RenderPipeline,
    uniforms: Uniforms,
    background: [f32; 4],
    draw_lines: bool,
    targets: Option<Targets>,
}

impl TwoPass {
    /// Builds the pipelines for an output of `options.output_format`: `Rgba8Unorm`,
    /// `Rgba8UnormSrgb` or `Rgba16Float` (the line pass blends, which `Rgba32Float` cannot
    /// without an extra feature). The output needs `RENDER_ATTACHMENT` usage.
    pub fn new(device: &wgpu::Device, options: PassOptions) -> Result<Self> {
        let format = options.output_format;
        let source = two_pass_source(format).ok_or_else(|| {
            Error::InvalidSetting(format!(
                "output format {format:?} is not one the two-pass method can render to \
                 (Rgba8Unorm, Rgba8UnormSrgb, Rgba16Float)"
            ))
        })?;
        check_vertex_storage(device)?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let layout = mesh_layout(device, "wirepass two-pass");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass two-pass"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass two-pass"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let position_layout = wgpu::VertexBufferLayout {
            array_stride: 12,
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
                (false, false) => ("vs_fill", "fs_fill"),
                (false, true) => ("vs_fill", "fs_fill_maps"),
                (true, false) => ("vs_line", "fs_line"),
                (true, true) => ("vs_line", "fs_line_maps"),
            };
            let buffers = if line {
                vec![Some(position_layout.clone())]
            } else {
                vec![]
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
        let fill = pipeline(false, false);
        let fill_maps = pipeline(false, true);
        let lines = pipeline(true, false);
        let lines_maps = pipeline(true, true);
        let uniforms = Uniforms::new(device);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Device(format!("creating the two-pass method: {e}")));
        }
        Ok(Self {
            format,
            layout,
            fill,
            fill_maps,
            lines,
            lines_maps,
            uniforms,
            background: [0.0; 4],
            draw_lines: true,
            targets: None,
        })
    }

    /// The output format chosen at construction.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Validates the camera, style and size, uploads the frame's uniforms, and (re)builds the
    /// depth, id and diagnostic targets when the size changed.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &GpuMesh,
        camera: &Camera,
        style: &Style,
        size: (u32, u32),
    ) -> Result<()> {
        let view = (camera, style, size);
        FrameUniforms::validate_and_write(device, queue, &self.uniforms.frame, mesh, view)?;
        self.background = style.background.0;
        self.draw_lines = style.line_width > 0.0;
        Targets::ensure(&mut self.targets, device, size);
        Ok(())
    }

    /// The size the pass was last prepared for.
    pub fn size(&self) -> Option<(u32, u32)> {
        self.targets.as_ref().map(|t| t.size)
    }

    /// The triangle-id target (`R32Uint`, `u32::MAX` = background) from the fill, written by
    /// [`encode_with_maps`](Self::encode_with_maps).
    pub fn id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.ids)
    }

    /// The reverse-Z depth target (`Depth32Float`, 1 = near plane), biased by the fill.
    pub fn depth_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.depth)
    }

    /// The diagnostic map written by [`encode_with_maps`](Self::encode_with_maps), `f32` bits
    /// in an `Rgba32Uint` texture (see [`MAPS_DIAGNOSTIC_FORMAT`](super::MAPS_DIAGNOSTIC_FORMAT)):
    /// red = 0 where a line was drawn and 3e38 elsewhere, green = the fill's reverse-Z raster
    /// depth as `@builtin(position).z` reports it, which includes the depth bias on Mesa's
    /// lavapipe and llvmpipe (the depth the method really tests lines against).
    pub fn diagnostic_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.diagnostic)
    }

    /// Records both passes into `output` (cleared to the background first).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        lines: &EdgeLines,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, mesh, (lines, output), false, None)
    }

    /// [`encode`](Self::encode) with GPU timestamps around the pass (fill and lines share
    /// one render pass), named `"draw"`.
    pub fn encode_timed(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        lines: &EdgeLines,
        output: &wgpu::TextureView,
        timer: &mut GpuTimer,
    ) -> Result<()> {
        self.record(device, encoder, mesh, (lines, output), false, Some(timer))
    }

    /// Like [`encode`](Self::encode), and also writes the triangle ids and the diagnostic map.
    pub fn encode_with_maps(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        lines: &EdgeLines,
        output: &wgpu::TextureView,
    ) -> Result<()> {
        self.record(device, encoder, mesh, (lines, output), true, None)
    }

    fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        mesh: &GpuMesh,
        (lines, output): (&EdgeLines, &wgpu::TextureView),
        maps: bool,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let targets = Targets::get(&self.targets)?;
        targets.check_output(output, self.format)?;
        lines.check(mesh)?;
        let group = mesh_group(device, &self.layout, &self.uniforms, mesh);
        let background = clear_color(self.format, self.background);
        let writes = timer.and_then(|t| t.render_span("draw"));
        let mut pass = targets.begin(
            encoder,
            "wirepass two-pass",
            output,
            background,
            maps,
            writes,
        );
        pass.set_pipeline(if maps { &self.fill_maps } else { &self.fill });
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3 * mesh.triangles, 0..1);
        if let (true, Some(indices)) = (self.draw_lines, &lines.indices) {
            pass.set_pipeline(if maps { &self.lines_maps } else { &self.lines });
            pass.set_vertex_buffer(0, mesh.positions.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..2 * lines.edges, 0, 0..1);
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
        assert!(two_pass_source(wgpu::TextureFormat::Rgba32Float).is_none());
        assert!(two_pass_source(wgpu::TextureFormat::Rgba8UnormSrgb).is_some());
    }
}
