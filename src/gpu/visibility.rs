//! The visibility pass: every instance of the frame rasterized once into the id target
//! (instance slot, triangle) and the reverse depth target, one instanced draw per mesh.

use super::bindings::{self, Res, Sources};
use super::frame::{FrameData, INSTANCE_BASES_OFFSET, INSTANCE_INDEX_OFFSET};
use super::mesh_store::VERTEX_BYTES;
use super::targets::{Targets, BACKGROUND_ID, DEPTH_FORMAT, ID_FORMAT};
use super::{shaders, GpuTimer};
use crate::error::Result;

/// The visibility pipelines: instanced with `@builtin(primitive_index)`, or vertex-pulled
/// (`TriangleIds`; then also in a variant for a split store); each also cutting by section
/// planes, built for the first frame that has some. Indexed by `split + 2 · sections`.
pub(crate) struct Visibility {
    pulled: bool,
    pipelines: [Option<Raster>; 4],
    /// The host's cache of compiled pipelines ([`PassOptions::pipeline_cache`](super::PassOptions)).
    compiled: Option<wgpu::PipelineCache>,
}

fn index(split: bool, sections: bool) -> usize {
    usize::from(split) + 2 * usize::from(sections)
}

struct Raster {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    resources: Vec<Res>,
}

fn instance_layout() -> wgpu::VertexBufferLayout<'static> {
    const ATTRIBUTES: [wgpu::VertexAttribute; 7] = [
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 0,
            shader_location: 1,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 16,
            shader_location: 2,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 32,
            shader_location: 3,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 48,
            shader_location: 4,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 64,
            shader_location: 5,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Uint32x2,
            offset: INSTANCE_BASES_OFFSET,
            shader_location: 6,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Uint32,
            offset: INSTANCE_INDEX_OFFSET,
            shader_location: 7,
        },
    ];
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<super::frame::InstanceRecord>() as u64,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &ATTRIBUTES,
    }
}

impl Visibility {
    pub fn new(
        device: &wgpu::Device,
        pulled: bool,
        compiled: Option<wgpu::PipelineCache>,
    ) -> Result<Visibility> {
        let mut v = Visibility {
            pulled,
            pipelines: [None, None, None, None],
            compiled,
        };
        v.pipelines[0] = Some(v.build(device, false, false)?);
        Ok(v)
    }

    fn build(&self, device: &wgpu::Device, split: bool, sections: bool) -> Result<Raster> {
        let source = shaders::visibility_source(self.pulled, split, sections);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass visibility"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let mut resources = vec![Res::Frame];
        if self.pulled {
            resources.extend([Res::Vertices, Res::Indices]);
            if split {
                resources.extend([Res::VerticesHi, Res::IndicesHi]);
            }
        }
        let layout = bindings::layout(
            device,
            "wirepass visibility",
            &resources,
            wgpu::ShaderStages::VERTEX,
            ID_FORMAT,
        )?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass visibility"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let position = wgpu::VertexBufferLayout {
            array_stride: VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let buffers = if self.pulled {
            vec![Some(instance_layout())]
        } else {
            vec![Some(position), Some(instance_layout())]
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("wirepass visibility"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(ID_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: self.compiled.as_ref(),
        });
        Ok(Raster {
            pipeline,
            layout,
            resources,
        })
    }

    /// How many pipelines it holds.
    pub fn built(&self) -> usize {
        self.pipelines.iter().flatten().count()
    }

    /// Builds what a frame with a split store, or with section planes, needs, before it is
    /// encoded.
    pub fn prepare(&mut self, device: &wgpu::Device, split: bool, sections: bool) -> Result<()> {
        let split = split && self.pulled;
        let at = index(split, sections);
        if self.pipelines[at].is_none() {
            self.pipelines[at] = Some(self.build(device, split, sections)?);
        }
        Ok(())
    }

    /// Records the visibility pass: clears the targets (ids to background, depth to the far
    /// plane), unless the host's depth `seeded` them, and draws every instance.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        frame: &FrameData,
        targets: &Targets,
        seeded: bool,
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let split = frame.split() && self.pulled;
        let raster = self.pipelines[index(split, frame.sections())]
            .as_ref()
            .ok_or_else(|| crate::Error::Device("visibility pipeline was not prepared".into()))?;
        let group = bindings::bind_group(
            device,
            &raster.layout,
            &raster.resources,
            &Sources::frame(frame),
        )?;
        let ids = targets.ids.create_view(&Default::default());
        let depth = targets.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("wirepass visibility"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &ids,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: if seeded {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(BACKGROUND_ID),
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        })
                    },
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: if seeded {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(0.0)
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.and_then(|t| t.render_span("visibility")),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&raster.pipeline);
        pass.set_bind_group(0, &group, &[]);
        let slot = if self.pulled {
            0
        } else {
            pass.set_vertex_buffer(0, frame.store.vertices.slice(..));
            pass.set_index_buffer(frame.store.indices.slice(..), wgpu::IndexFormat::Uint32);
            1
        };
        pass.set_vertex_buffer(slot, frame.instances.slice(..));
        for d in &frame.draws {
            if self.pulled {
                pass.draw(0..3 * d.triangles, d.instances.clone());
            } else {
                pass.draw_indexed(
                    d.first_index..d.first_index + d.index_count,
                    d.base_vertex,
                    d.instances.clone(),
                );
            }
        }
        Ok(())
    }
}
