//! Drawing a frame into the host's own render pass: the lines over the host's image, or the
//! shaded surface with its lines, in any renderable colour format (sRGB ones included),
//! with the host's sample count and depth-stencil format.

use super::bindings::Res;
use super::host_depth::HostFrame;
use super::shaders;
use super::targets::{LIST_HEADER, RESULT_FORMAT};
use crate::error::{Error, Result};

/// What [`DeferredPass::render`](super::DeferredPass::render) draws over the host's image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Composite {
    /// The lines only, over whatever the host drew (wirepass as a post-process).
    #[default]
    Lines,
    /// The shaded surface of the instances and their lines; the host's image shows only where
    /// no instance is (or where the host's own depth is nearer).
    Shaded,
}

/// The host's render pass as [`DeferredPass::render`](super::DeferredPass::render) draws
/// into it, given at construction (as egui-wgpu's and glyphon's renderers take theirs).
///
/// Blending happens in linear light for sRGB formats (the hardware decodes and encodes) and
/// float formats. `Rgba8Unorm` and `Bgra8Unorm` are taken to hold sRGB-encoded values, as
/// the storage output's `Rgba8Unorm` does and as egui and most UI toolkits draw into such a
/// surface: the draw encodes its colours and blends on the encoded values. For blending in
/// linear light over such a texture, give the render pass an sRGB view of it
/// (`TextureDescriptor::view_formats`) and this target the sRGB format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderTarget {
    /// Format of the colour attachment.
    pub format: wgpu::TextureFormat,
    /// Samples per pixel of the render pass's attachments.
    pub sample_count: u32,
    /// Format of the render pass's depth-stencil attachment, if it has one. The draw never
    /// writes it; for a frame prepared with the host's depth
    /// ([`Canvas::with_host_depth`](super::Canvas::with_host_depth)) it tests each sample's
    /// depth, so that the host's own antialiased edges in front of a shaded instance keep
    /// their samples (the attachment must then hold that same depth).
    pub depth_stencil: Option<wgpu::TextureFormat>,
    /// What to draw.
    pub content: Composite,
}

impl RenderTarget {
    /// Checks the attachments the host's render pass will have against this target, before
    /// [`DeferredPass::render`](super::DeferredPass::render) draws into it: wirepass cannot
    /// see a render pass's attachments, and wgpu reports a mismatch as a validation error
    /// (a panic with its default handler). `color` is the colour attachment (an sRGB view of
    /// a texture without sRGB, or the other way round, counts as its format), and
    /// `depth_stencil` the depth-stencil attachment, if the pass has one.
    pub fn check_attachments(
        &self,
        color: &wgpu::TextureView,
        depth_stencil: Option<&wgpu::TextureView>,
    ) -> Result<()> {
        let c = color.texture();
        if c.format().remove_srgb_suffix() != self.format.remove_srgb_suffix() {
            return Err(Error::Misuse(format!(
                "the colour attachment is {:?}, but the render target says {:?}",
                c.format(),
                self.format
            )));
        }
        if c.sample_count() != self.sample_count {
            return Err(Error::Misuse(format!(
                "the colour attachment has {} samples per pixel, but the render target says {}",
                c.sample_count(),
                self.sample_count
            )));
        }
        match (
            depth_stencil.map(wgpu::TextureView::texture),
            self.depth_stencil,
        ) {
            (None, None) => Ok(()),
            (Some(d), None) => Err(Error::Misuse(format!(
                "the render pass has a {:?} depth-stencil attachment, but the render target \
                 says none (RenderTarget::depth_stencil)",
                d.format()
            ))),
            (None, Some(f)) => Err(Error::Misuse(format!(
                "the render target says a {f:?} depth-stencil attachment, but the render pass \
                 has none"
            ))),
            (Some(d), Some(f)) if d.format() != f => Err(Error::Misuse(format!(
                "the depth-stencil attachment is {:?}, but the render target says {f:?}",
                d.format()
            ))),
            (Some(d), Some(_)) if d.sample_count() != self.sample_count => {
                Err(Error::Misuse(format!(
                    "the depth-stencil attachment has {} samples per pixel, but the render \
                     target says {}",
                    d.sample_count(),
                    self.sample_count
                )))
            }
            _ => Ok(()),
        }
    }
}

/// Whether a target of `format` holds sRGB-encoded values the draw must encode: the 8-bit
/// RGBA formats without sRGB ([`RenderTarget`] says why).
fn encodes_srgb(format: wgpu::TextureFormat) -> bool {
    matches!(
        format,
        wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Bgra8Unorm
    )
}

/// The composite's pipelines for one render target: the plain draw, and where the render
/// pass has a depth attachment, the draws that test the host's depth per sample (for a
/// standard and a reversed host depth; composite.wgsl says why).
pub(crate) struct CompositePipeline {
    plain: Draw,
    tested: Option<[Draw; 2]>,
}

struct Draw {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

/// A frame's composite draw: its bind group, and which of the pipelines it binds for.
pub(crate) struct FrameComposite {
    group: wgpu::BindGroup,
    /// `Some(reversed)`: a tested draw over a host depth of that convention.
    tested: Option<bool>,
}

/// What a tested draw reads besides the result: the frame's uniforms, the host depth's
/// mapping, and the visibility pass's ids and depth.
pub(crate) struct HostSamples<'a> {
    pub frame: &'a wgpu::Buffer,
    pub host: &'a HostFrame,
    pub ids: &'a wgpu::Texture,
    pub depth: &'a wgpu::Texture,
}

impl CompositePipeline {
    /// Checks `target` against the device and builds its pipelines.
    pub fn new(
        device: &wgpu::Device,
        target: &RenderTarget,
        compiled: Option<&wgpu::PipelineCache>,
    ) -> Result<Self> {
        let features = target.format.guaranteed_format_features(device.features());
        if !features
            .allowed_usages
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
            || target.format.is_depth_stencil_format()
        {
            return Err(Error::Misuse(format!(
                "{:?} is not a colour format a render pass can draw into",
                target.format
            )));
        }
        if !features
            .flags
            .contains(wgpu::TextureFormatFeatureFlags::BLENDABLE)
        {
            return Err(Error::Misuse(format!(
                "{:?} cannot be blended into on this device",
                target.format
            )));
        }
        if target.sample_count != 1 && !features.flags.sample_count_supported(target.sample_count) {
            return Err(Error::Misuse(format!(
                "{:?} with {} samples per pixel is not supported on this device",
                target.format, target.sample_count
            )));
        }
        if let Some(ds) = target.depth_stencil {
            if !ds.is_depth_stencil_format() {
                return Err(Error::Misuse(format!(
                    "the render target's depth-stencil format {ds:?} is not a depth or stencil format"
                )));
            }
        }
        let scope = crate::gpu::validation::Validation::begin(device);
        let plain = Draw::new(device, target, None, compiled);
        let tested = target
            .depth_stencil
            .filter(|f| f.has_depth_aspect())
            .map(|_| {
                [
                    Draw::new(
                        device,
                        target,
                        Some(wgpu::CompareFunction::LessEqual),
                        compiled,
                    ),
                    Draw::new(
                        device,
                        target,
                        Some(wgpu::CompareFunction::GreaterEqual),
                        compiled,
                    ),
                ]
            });
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!(
                "building the composite pipeline: {e}"
            )));
        }
        Ok(Self { plain, tested })
    }

    /// A frame's bind group over its result texture, for the tested draw where the render
    /// pass has a depth attachment and the frame has the host's depth (`samples`).
    pub fn bind(
        &self,
        device: &wgpu::Device,
        result: &wgpu::Texture,
        samples: Option<HostSamples<'_>>,
    ) -> FrameComposite {
        debug_assert_eq!(result.format(), RESULT_FORMAT);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let result = view(result);
        let entry = |res: Res, resource| wgpu::BindGroupEntry {
            binding: res as u32,
            resource,
        };
        let (draw, samples) = match (&self.tested, samples) {
            (Some(tested), Some(s)) => (&tested[usize::from(s.host.reversed())], Some(s)),
            _ => (&self.plain, None),
        };
        let tested = samples.as_ref().map(|s| s.host.reversed());
        let mut entries = vec![entry(
            Res::Result,
            wgpu::BindingResource::TextureView(&result),
        )];
        let views = samples.as_ref().map(|s| (view(s.ids), view(s.depth)));
        if let (Some(s), Some((ids, depth))) = (&samples, &views) {
            entries.extend([
                entry(Res::Frame, s.frame.as_entire_binding()),
                entry(Res::HostParams, s.host.params().as_entire_binding()),
                entry(Res::Ids, wgpu::BindingResource::TextureView(ids)),
                entry(Res::Depth, wgpu::BindingResource::TextureView(depth)),
            ]);
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass composite"),
            layout: &draw.layout,
            entries: &entries,
        });
        FrameComposite { group, tested }
    }

    /// Records a frame's draw into the host's render pass: a quad for each output tile the
    /// edge pass listed in `tiles` (`composite_rw` in edge_pass.wgsl, its own indirect
    /// arguments).
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        frame: &FrameComposite,
        tiles: &wgpu::Buffer,
    ) -> Result<()> {
        let draw = match (&self.tested, frame.tested) {
            (_, None) => &self.plain,
            (Some(tested), Some(reversed)) => &tested[usize::from(reversed)],
            (None, Some(_)) => {
                return Err(Error::Device(
                    "a tested composite without its pipeline".into(),
                ))
            }
        };
        pass.set_pipeline(&draw.pipeline);
        pass.set_bind_group(0, &frame.group, &[]);
        pass.set_vertex_buffer(0, tiles.slice(LIST_HEADER..));
        pass.draw_indirect(tiles, 0);
        Ok(())
    }
}

impl Draw {
    /// The plain draw (`compare` None), or a tested one comparing the fragment's depth with
    /// the host's by `compare`.
    fn new(
        device: &wgpu::Device,
        target: &RenderTarget,
        compare: Option<wgpu::CompareFunction>,
        compiled: Option<&wgpu::PipelineCache>,
    ) -> Draw {
        let stage = wgpu::ShaderStages::FRAGMENT;
        // The vertex stage reads the result's size.
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let mut entries = vec![Res::Result.layout_entry(both, RESULT_FORMAT)];
        if compare.is_some() {
            entries.extend(
                [Res::Frame, Res::HostParams, Res::Ids, Res::Depth]
                    .map(|r| r.layout_entry(stage, RESULT_FORMAT)),
            );
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wirepass composite"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass composite"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass composite"),
            source: wgpu::ShaderSource::Wgsl(
                shaders::composite_source(compare.is_some(), encodes_srgb(target.format)).into(),
            ),
        });
        let premultiplied = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
            operation: wgpu::BlendOperation::Add,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("wirepass composite"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                // The tile of each instance.
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 4,
                    step_mode: wgpu::VertexStepMode::Instance,
                    attributes: &wgpu::vertex_attr_array![0 => Uint32],
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
            // Neither draw writes the host's depth or stencil.
            depth_stencil: target.depth_stencil.map(|format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(false),
                depth_compare: Some(compare.unwrap_or(wgpu::CompareFunction::Always)),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: target.sample_count,
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target.format,
                    blend: Some(wgpu::BlendState {
                        color: premultiplied,
                        alpha: premultiplied,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: compiled,
        });
        Draw { pipeline, layout }
    }
}
