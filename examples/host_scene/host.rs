//! A small host renderer of its own, as a program that uses wirepass has one: its own
//! pipeline, its own multisampled colour and depth targets, its own camera. It draws shaded
//! meshes and knows nothing of wireframes. The `host_scene` example and the host tests use it.

use wirepass::glam::{DMat4, Mat4, Vec3};
use wirepass::wgpu::util::DeviceExt;
use wirepass::{wgpu, DepthRange, Mesh};

/// The host's target formats and sample count.
#[derive(Clone, Copy, Debug)]
pub struct HostFormats {
    pub color: wgpu::TextureFormat,
    pub depth: wgpu::TextureFormat,
    pub samples: u32,
}

impl HostFormats {
    /// What the example draws into: sRGB colour, as most surfaces and images are, a
    /// depth-stencil buffer, 4× multisampling.
    pub const EXAMPLE: HostFormats = HostFormats {
        color: wgpu::TextureFormat::Rgba8UnormSrgb,
        depth: wgpu::TextureFormat::Depth24PlusStencil8,
        samples: 4,
    };
}

const SHADER: &str = r#"
struct Draw {
    clip: mat4x4<f32>,
    model: mat4x4<f32>,
    color: vec4<f32>,
}
@group(0) @binding(0) var<uniform> draw: Draw;

struct Out {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
}

@vertex
fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> Out {
    return Out(draw.clip * vec4<f32>(p, 1.0), (draw.model * vec4<f32>(n, 0.0)).xyz);
}

@fragment
fn fs(in: Out) -> @location(0) vec4<f32> {
    let l = normalize(vec3<f32>(0.4, 0.9, 0.5));
    let k = 0.35 + 0.65 * abs(dot(normalize(in.normal), l));
    return vec4<f32>(draw.color.rgb * k, 1.0);
}
"#;

/// A mesh on the GPU, as the host draws it: unindexed positions and normals.
pub struct HostMesh {
    vertices: wgpu::Buffer,
    count: u32,
}

impl HostMesh {
    pub fn new(device: &wgpu::Device, mesh: &Mesh) -> HostMesh {
        let mut data: Vec<[f32; 6]> = Vec::with_capacity(3 * mesh.triangle_count());
        for t in mesh.triangles() {
            for &v in t {
                let (p, n) = (mesh.positions()[v as usize], mesh.normals()[v as usize]);
                data.push([p.x, p.y, p.z, n.x, n.y, n.z]);
            }
        }
        HostMesh {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("host mesh"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            count: data.len() as u32,
        }
    }
}

/// One thing the host draws: a mesh, where, in which colour (linear RGB).
pub struct HostDraw<'a> {
    pub mesh: &'a HostMesh,
    pub transform: DMat4,
    pub color: Vec3,
}

/// The host's renderer: shaded meshes into multisampled colour and depth.
pub struct HostRenderer {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    formats: HostFormats,
    pub depth: DepthRange,
}

impl HostRenderer {
    pub fn new(device: &wgpu::Device, formats: HostFormats, depth: DepthRange) -> HostRenderer {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("host"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("host"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let compare = match depth {
            DepthRange::Standard => wgpu::CompareFunction::Less,
            DepthRange::Reversed => wgpu::CompareFunction::Greater,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("host"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: formats.depth,
                depth_write_enabled: Some(true),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: formats.samples,
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(formats.color.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        HostRenderer {
            pipeline,
            layout,
            formats,
            depth,
        }
    }

    /// The value the depth target clears to: the far plane.
    pub fn far(&self) -> f32 {
        match self.depth {
            DepthRange::Standard => 1.0,
            DepthRange::Reversed => 0.0,
        }
    }

    /// Records a render pass that clears `color` (linear RGB) and `depth` and draws `draws`
    /// seen through `view_projection`.
    pub fn draw(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &HostTargets,
        clear: Vec3,
        view_projection: DMat4,
        draws: &[HostDraw<'_>],
    ) {
        let groups: Vec<wgpu::BindGroup> = draws
            .iter()
            .map(|d| {
                let mut uniform = [0.0f32; 36];
                uniform[..16]
                    .copy_from_slice(&(view_projection * d.transform).as_mat4().to_cols_array());
                let normal: Mat4 = d.transform.inverse().transpose().as_mat4();
                uniform[16..32].copy_from_slice(&normal.to_cols_array());
                uniform[32..35].copy_from_slice(&d.color.to_array());
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("host draw"),
                    contents: bytemuck::cast_slice(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("host draw"),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buffer.as_entire_binding(),
                    }],
                })
            })
            .collect();
        let (color, depth, resolved) = targets.views();
        let mut pass =
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &color,
                    depth_slice: None,
                    resolve_target: resolved.as_ref(),
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(clear.x),
                            g: f64::from(clear.y),
                            b: f64::from(clear.z),
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(self.far()),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: self.formats.depth.has_stencil_aspect().then_some(
                        wgpu::Operations {
                            load: wgpu::LoadOp::Clear(0),
                            store: wgpu::StoreOp::Store,
                        },
                    ),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
        pass.set_pipeline(&self.pipeline);
        for (d, group) in draws.iter().zip(&groups) {
            pass.set_bind_group(0, group, &[]);
            pass.set_vertex_buffer(0, d.mesh.vertices.slice(..));
            pass.draw(0..d.mesh.count, 0..1);
        }
    }
}

/// The host's targets at one size: colour and depth (multisampled or not), and with
/// multisampling the single-sampled colour they resolve to.
pub struct HostTargets {
    pub color: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub resolved: Option<wgpu::Texture>,
}

impl HostTargets {
    pub fn new(device: &wgpu::Device, size: (u32, u32), formats: HostFormats) -> HostTargets {
        let texture = |label, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        use wgpu::TextureUsages as U;
        let image = U::RENDER_ATTACHMENT | U::COPY_SRC | U::TEXTURE_BINDING;
        let samples = formats.samples;
        let multisampled = samples > 1;
        HostTargets {
            color: texture(
                "host colour",
                formats.color,
                samples,
                if multisampled {
                    U::RENDER_ATTACHMENT
                } else {
                    image
                },
            ),
            depth: texture(
                "host depth",
                formats.depth,
                samples,
                U::RENDER_ATTACHMENT | U::TEXTURE_BINDING,
            ),
            resolved: multisampled.then(|| texture("host resolved", formats.color, 1, image)),
        }
    }

    /// The finished single-sampled image.
    pub fn image(&self) -> &wgpu::Texture {
        self.resolved.as_ref().unwrap_or(&self.color)
    }

    /// Views of the colour and depth attachments and of the resolve target.
    pub fn views(
        &self,
    ) -> (
        wgpu::TextureView,
        wgpu::TextureView,
        Option<wgpu::TextureView>,
    ) {
        (
            self.color.create_view(&Default::default()),
            self.depth.create_view(&Default::default()),
            self.resolved
                .as_ref()
                .map(|r| r.create_view(&Default::default())),
        )
    }

    /// A render pass over the host's finished colour and depth, as a host opens one to draw
    /// overlays (text, gizmos, wirepass's lines) after its scene; it resolves again at its end.
    pub fn overlay_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder) -> wgpu::RenderPass<'e> {
        let (color, depth, resolved) = self.views();
        let load = wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        };
        let stencil = self.depth.format().has_stencil_aspect();
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host overlay"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color,
                depth_slice: None,
                resolve_target: resolved.as_ref(),
                ops: load,
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: stencil.then_some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }
}

/// The host's scene: a ground plane, a pillar in front of a cow, and a monkey half sunk into
/// the ground. The cow and the monkey are the meshes to wireframe; the ground and the pillar
/// are the host's own.
pub struct HostScene {
    pub cow: Mesh,
    pub cow_at: DMat4,
    pub monkey: Mesh,
    pub monkey_at: DMat4,
    pub ground: Mesh,
    pub pillar: Mesh,
    pub pillar_at: DMat4,
}

impl HostScene {
    /// The scene from the cow (Spot) and monkey (Suzanne) meshes.
    pub fn new(cow: Mesh, monkey: Mesh) -> HostScene {
        use wirepass::glam::{DQuat, DVec3};
        let ground = wirepass::mesh::grid(2).expect("a grid");
        let (lo, hi) = monkey.bounds_f64();
        let centre = (lo + hi) * 0.5;
        HostScene {
            cow,
            cow_at: DMat4::from_translation(DVec3::new(-0.9, 0.72, 0.0))
                * DMat4::from_quat(DQuat::from_rotation_y(-0.5)),
            monkey,
            // Its centre a little above the ground: the lower half of the head is buried.
            monkey_at: DMat4::from_translation(DVec3::new(1.1, 0.1, 0.3))
                * DMat4::from_quat(DQuat::from_rotation_y(-0.4))
                * DMat4::from_scale(DVec3::splat(0.55))
                * DMat4::from_translation(-centre),
            ground: transformed(
                &ground,
                DMat4::from_scale(DVec3::new(6.0, 1.0, 6.0))
                    * DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2),
            ),
            pillar: box_mesh(),
            pillar_at: DMat4::from_translation(DVec3::new(-0.55, 0.8, 1.3))
                * DMat4::from_scale(DVec3::new(0.18, 0.8, 0.18)),
        }
    }

    /// The host's meshes on the GPU, in the order of [`draws`](Self::draws).
    pub fn upload(&self, device: &wgpu::Device) -> [HostMesh; 4] {
        [&self.ground, &self.pillar, &self.cow, &self.monkey].map(|m| HostMesh::new(device, m))
    }

    /// Everything the host draws: the ground, the pillar, and its own shaded copies of the
    /// cow and the monkey.
    pub fn draws<'a>(&self, meshes: &'a [HostMesh; 4]) -> [HostDraw<'a>; 4] {
        let placed = [
            (DMat4::IDENTITY, Vec3::new(0.35, 0.42, 0.3)),
            (self.pillar_at, Vec3::new(0.6, 0.45, 0.35)),
            (self.cow_at, Vec3::new(0.8, 0.75, 0.7)),
            (self.monkey_at, Vec3::new(0.75, 0.6, 0.45)),
        ];
        std::array::from_fn(|i| HostDraw {
            mesh: &meshes[i],
            transform: placed[i].0,
            color: placed[i].1,
        })
    }

    /// The sky colour the host clears to (linear RGB).
    pub const SKY: Vec3 = Vec3::new(0.55, 0.65, 0.8);

    /// The host's view for an image of `aspect`, in depth convention `depth`.
    pub fn view(&self, aspect: f64, depth: DepthRange) -> wirepass::View {
        let camera = self.camera();
        match depth {
            DepthRange::Standard => camera.to_view(aspect),
            DepthRange::Reversed => wirepass::View::new(
                camera.view(),
                wirepass::glam::dcamera::rh::proj::directx::perspective(
                    f64::from(camera.fov_y_deg).to_radians(),
                    aspect,
                    f64::from(camera.far),
                    f64::from(camera.near),
                ),
                DepthRange::Reversed,
            ),
        }
    }

    /// The camera everything is seen through.
    pub fn camera(&self) -> wirepass::Camera {
        wirepass::Camera {
            eye: Vec3::new(0.6, 1.7, 4.6),
            target: Vec3::new(0.1, 0.45, 0.0),
            up: Vec3::Y,
            fov_y_deg: 45.0,
            near: 0.1,
            far: 30.0,
        }
    }
}

/// `mesh` with its positions moved by `m` (normals recomputed).
fn transformed(mesh: &Mesh, m: DMat4) -> Mesh {
    let p = mesh
        .positions()
        .iter()
        .map(|p| m.transform_point3(p.as_dvec3()).as_vec3())
        .collect();
    Mesh::new(p, None, mesh.triangles().to_vec(), None).expect("a transformed mesh")
}

/// A unit cube, −1..1.
fn box_mesh() -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let corners = |axis: usize, side: f32| {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| {
            let mut p = [0.0f32; 3];
            p[axis] = side;
            p[u] = a;
            p[v] = b;
            Vec3::from(p)
        })
    };
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let base = positions.len() as u32;
            let mut c = corners(axis, side);
            if side < 0.0 {
                c.reverse();
            }
            positions.extend(c);
            triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
    }
    Mesh::new(positions, None, triangles, None).expect("a cube")
}
