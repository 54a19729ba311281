//! Drawing a frame into the host's own render pass: the lines over the host's image, or the
//! shaded surface with its lines, in any renderable colour format (sRGB ones included),
//! with the host's sample count and depth-stencil format.

use super::bindings::Res;
use super::shaders;
use super::targets::RESULT_FORMAT;
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
/// float formats. An 8-bit format without sRGB is blended on its stored values, which the
/// pass takes to be linear; to draw over an image that holds sRGB-encoded values in such a
/// texture, give the render pass an sRGB view of it (`TextureDescriptor::view_formats`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RenderTarget {
    /// Format of the colour attachment.
    pub format: wgpu::TextureFormat,
    /// Samples per pixel of the render pass's attachments.
    pub sample_count: u32,
    /// Format of the render pass's depth-stencil attachment, if it has one; the draw neither
    /// tests nor writes it.
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

/// The composite pipeline for one render target.
pub(crate) struct CompositePipeline {
    pub pipeline: wgpu::RenderPipeline,
    pub layout: wgpu::BindGroupLayout,
}

impl CompositePipeline {
    /// Checks `target` against the device and builds its pipeline.
    pub fn new(device: &wgpu::Device, target: &RenderTarget) -> Result<Self> {
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
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wirepass composite"),
            entries: &[Res::Result.layout_entry(wgpu::ShaderStages::FRAGMENT, RESULT_FORMAT)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("wirepass composite"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wirepass composite"),
            source: wgpu::ShaderSource::Wgsl(shaders::COMPOSITE.into()),
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
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: target.depth_stencil.map(|format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
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
            cache: None,
        });
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!(
                "building the composite pipeline: {e}"
            )));
        }
        Ok(Self { pipeline, layout })
    }

    /// The bind group reading a frame's result texture.
    pub fn bind(&self, device: &wgpu::Device, result: &wgpu::Texture) -> wgpu::BindGroup {
        debug_assert_eq!(result.format(), RESULT_FORMAT);
        let view = result.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wirepass composite"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: Res::Result as u32,
                resource: wgpu::BindingResource::TextureView(&view),
            }],
        })
    }
}
