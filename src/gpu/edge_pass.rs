//! The edge pass (compute, `shaders/edge_pass.wgsl`): per pixel, the exact distance to the
//! visible lines and the composited colour. Six dispatches (docs/how-it-works.md): classify
//! lists the 8×8 tiles with foreground and the background pixels next to it; border adds
//! the guard band's; the background is cleared or written; then the traced tiles, the
//! listed tiles and the refine list write the output.

use super::bindings::{dispatch, store_resources, Compute, Res, Size, Sources};
use super::frame::FrameData;
use super::targets::{self, Targets, CLASSIFY_GROUP, LIST_HEADER, RESULT_FORMAT};
use super::variants::{Mode, Variant};
use super::{shaders, GpuTimer};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Edge-pass workgroup side (8 × 8 pixels).
pub(crate) const TILE: u32 = 8;

pub(crate) struct EdgePipelines {
    /// Writes the pixels without a triangle, where no clear lays them down.
    background: Compute,
    classify: Compute,
    /// Lines over the background of the tiles the trace pass lists; with outlines only.
    traced: Option<Compute>,
    border: Compute,
    tiles: Compute,
    refine: Compute,
}

/// The edge pass's pipelines, built for each mode and variant on first use.
pub(crate) struct EdgePass {
    /// The format of the storage outputs.
    format: wgpu::TextureFormat,
    /// Whether a clear lays the background down where it can ([`Tuning`](super::Tuning)).
    clear: bool,
    cache: Mutex<HashMap<(Mode, Variant), Arc<EdgePipelines>>>,
    /// The host's cache of compiled pipelines ([`PassOptions::pipeline_cache`](super::PassOptions)).
    compiled: Option<wgpu::PipelineCache>,
    /// The benchmark floor's pipeline ([`OutputTarget::Floor`](super::OutputTarget::Floor)).
    #[cfg(feature = "diagnostics")]
    floor: Compute,
}

impl EdgePass {
    /// How many pipelines the pass holds (the floor's, in a diagnostics build, among them).
    pub(crate) fn built(&self) -> usize {
        let sets: usize = self.cache.lock().map_or(0, |c| {
            c.values()
                .map(|p| 5 + usize::from(p.traced.is_some()))
                .sum()
        });
        sets + usize::from(cfg!(feature = "diagnostics"))
    }

    /// The pass for storage outputs of `format`, clearing the background where it can
    /// (`clear`); its pipelines come on first use (the floor's, a diagnostics build's, now).
    #[cfg_attr(not(feature = "diagnostics"), allow(unused_variables))]
    pub(crate) fn new(
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        clear: bool,
        compiled: Option<wgpu::PipelineCache>,
    ) -> Result<Self> {
        Ok(Self {
            format,
            clear,
            cache: Mutex::default(),
            #[cfg(feature = "diagnostics")]
            floor: Compute::new(
                device,
                &edge_module(device, format, super::variants::FLOOR_FLAGS),
                "floor_main",
                vec![Res::Frame, Res::Ids, Res::OutColor],
                format,
                compiled.as_ref(),
            )?,
            compiled,
        })
    }

    /// The value every output pixel without a triangle or a line gets, as a clear colour,
    /// where the pass clears and that is one value (Shade: the background, encoded as
    /// store_pixel encodes it; Result: transparent) and the output `texture` can be cleared
    /// whole (RENDER_ATTACHMENT usage, one mip level: the storage view writes that level).
    fn background_clear(
        &self,
        mode: Mode,
        texture: &wgpu::Texture,
        data: &FrameData,
    ) -> Option<wgpu::Color> {
        let usage = texture.usage();
        if !self.clear
            || !usage.contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
            || texture.mip_level_count() != 1
        {
            return None;
        }
        match mode {
            Mode::Shade => Some(background_value(self.format, data.uniforms.background())),
            Mode::Result { .. } => Some(wgpu::Color::TRANSPARENT),
            Mode::Overlay { .. } => None,
            #[cfg(feature = "diagnostics")]
            Mode::Diagnostic => None,
        }
    }

    pub(crate) fn pipelines(
        &self,
        device: &wgpu::Device,
        mode: Mode,
        v: Variant,
    ) -> Result<Arc<EdgePipelines>> {
        let v = v.for_edges();
        let mut cache = self
            .cache
            .lock()
            .map_err(|_| Error::Device("pipeline cache poisoned".into()))?;
        if let Some(p) = cache.get(&(mode, v)) {
            return Ok(p.clone());
        }
        let mut flags = v.flags();
        flags.extend_from_slice(mode.flags());
        let (out, color) = match mode {
            Mode::Shade => (vec![Res::OutColor], self.format),
            Mode::Overlay { .. } => (vec![Res::OutColor, Res::HostColor], self.format),
            Mode::Result { .. } => (vec![Res::OutColor], RESULT_FORMAT),
            #[cfg(feature = "diagnostics")]
            Mode::Diagnostic => (vec![Res::OutDiagnostic, Res::OutIds], self.format),
        };
        let scope = crate::gpu::validation::Validation::begin(device);
        let compiled = self.compiled.as_ref();
        let module = edge_module(device, self.format, &flags);
        let mut common = store_resources(v.split, false, v.uniform_instances);
        common.push(Res::Ids);
        if v.host {
            common.push(Res::HostDepth);
        }
        if v.traced {
            common.push(Res::Acc);
        }
        let with = |extra: &[Res]| {
            let mut r = common.clone();
            r.extend_from_slice(extra);
            r.extend_from_slice(&out);
            r
        };
        let background = Compute::new(
            device,
            &module,
            "background_main",
            with(&[]),
            color,
            compiled,
        )?;
        let mut classify_res = vec![Res::Frame, Res::Ids, Res::TilesRw, Res::WorkRw];
        if let Mode::Result { .. } = mode {
            // It lists the tiles the composite draws, the trace pass's among them.
            classify_res.push(Res::CompositeRw);
            if v.traced {
                classify_res.push(Res::Acc);
            }
        }
        let classify = Compute::new(
            device,
            &module,
            "classify_main",
            classify_res,
            color,
            compiled,
        )?;
        let traced = if v.traced {
            Some(Compute::new(
                device,
                &module,
                "traced_main",
                with(&[]),
                color,
                compiled,
            )?)
        } else {
            None
        };
        let border = Compute::new(
            device,
            &module,
            "border_main",
            with(&[Res::WorkRw]),
            color,
            compiled,
        )?;
        let mut tile_res = vec![Res::Tiles, Res::WorkRw];
        let mut neighbours = vec![Res::Neighbours];
        if v.split {
            neighbours.push(Res::NeighboursHi);
        }
        if v.patches {
            // A quad's search crosses its diagonal.
            tile_res.extend_from_slice(&neighbours);
        }
        let tiles = Compute::new(
            device,
            &module,
            "tile_main",
            with(&tile_res),
            color,
            compiled,
        )?;
        let mut refine_res = with(&[Res::Work]);
        refine_res.extend_from_slice(&neighbours);
        let refine = Compute::new(device, &module, "refine_main", refine_res, color, compiled)?;
        if let Some(e) = scope.end() {
            return Err(Error::Device(format!("building the edge pass: {e}")));
        }
        let p = Arc::new(EdgePipelines {
            background,
            classify,
            traced,
            border,
            tiles,
            refine,
        });
        cache.insert((mode, v), p.clone());
        Ok(p)
    }

    /// Records the edge pass's dispatches for `mode` into `output`'s view (none for the
    /// diagnostic maps), with the pipelines `edge` of the frame's variant; `reset` holds the
    /// header every list starts a frame with.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        (edge, reset): (&EdgePipelines, &wgpu::Buffer),
        t: &Targets,
        sources: &Sources<'_>,
        (mode, out_color): (Mode, Option<&wgpu::TextureView>),
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let (w, h) = t.output;
        // Where the background is one colour and the output can be cleared, a clear lays it
        // down at the speed of a fill; elsewhere a dispatch writes it.
        let clear = out_color.and_then(|v| self.background_clear(mode, v.texture(), sources.frame));
        let (columns, rows) = (w.div_ceil(TILE), h.div_ceil(TILE));
        // The lists first, then the background (the clear or its dispatch), then the passes
        // that write the output: a software rasterizer runs a clear when a later pass reads
        // its texture, and a dispatch between the two would be timed in neither span.
        let mut dispatches = vec![
            (
                "wirepass edge classify",
                "edge.classify",
                &edge.classify,
                Size::Grid(
                    columns.div_ceil(CLASSIFY_GROUP.0),
                    rows.div_ceil(CLASSIFY_GROUP.1),
                ),
            ),
            (
                "wirepass edge border",
                "edge.border",
                &edge.border,
                Size::Grid((2 * (w + h)).div_ceil(64), 1),
            ),
        ];
        let lists = dispatches.len();
        if clear.is_none() {
            dispatches.push((
                "wirepass edge background",
                "edge.background",
                &edge.background,
                Size::Grid(columns, rows),
            ));
        }
        if let Some(traced) = &edge.traced {
            let size = Size::Indirect(&t.acc, t.acc_tiles);
            dispatches.push(("wirepass edge traced", "edge.traced", traced, size));
        }
        dispatches.extend([
            (
                "wirepass edge tiles",
                "edge.tiles",
                &edge.tiles,
                Size::Indirect(&t.tiles, 0),
            ),
            (
                "wirepass edge refine",
                "edge.refine",
                &edge.refine,
                Size::Indirect(&t.work, 0),
            ),
        ]);
        // Bound before anything is recorded, so a failure leaves the encoder as it was.
        let groups = dispatches
            .iter()
            .map(|d| d.2.bind(device, sources))
            .collect::<Result<Vec<_>>>()?;
        encoder.copy_buffer_to_buffer(reset, 0, &t.tiles, 0, LIST_HEADER);
        encoder.copy_buffer_to_buffer(reset, 0, &t.work, 0, LIST_HEADER);
        if let (Mode::Result { .. }, Some(composite)) = (mode, &t.composite) {
            // The draw's arguments: classify_main sets the vertex count and counts the tiles.
            encoder.clear_buffer(composite, 0, Some(LIST_HEADER));
        }
        // Each dispatch is a pass of its own, timed on its own (the benchmark sums the
        // `edge.*` spans into the edge pass).
        for (k, ((label, span, pipeline, size), group)) in
            dispatches.into_iter().zip(groups).enumerate()
        {
            if k == lists {
                if let (Some(color), Some(view)) = (clear, out_color) {
                    // A view of its own: the host's may leave out RENDER_ATTACHMENT usage.
                    let whole = view.texture().create_view(&Default::default());
                    clear_output(encoder, timer.as_deref_mut(), &whole, color);
                }
            }
            let timer = timer.as_deref_mut();
            dispatch(encoder, timer, (label, span), (pipeline, &group), size);
        }
        Ok(())
    }

    /// The benchmark floor: each pixel's id read and its fill or background colour written.
    #[cfg(feature = "diagnostics")]
    pub(crate) fn encode_floor(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        sources: &Sources<'_>,
        (w, h): (u32, u32),
        timer: Option<&mut GpuTimer>,
    ) -> Result<()> {
        let group = self.floor.bind(device, sources)?;
        let names = ("wirepass floor", "edge.floor");
        let size = Size::Grid(w.div_ceil(TILE), h.div_ceil(TILE));
        dispatch(encoder, timer, names, (&self.floor, &group), size);
        Ok(())
    }
}

/// Clears `view` to `color` in a render pass of its own, timed as `edge.clear`.
fn clear_output(
    encoder: &mut wgpu::CommandEncoder,
    timer: Option<&mut GpuTimer>,
    view: &wgpu::TextureView,
    color: wgpu::Color,
) {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("wirepass edge clear"),
        color_attachments: &[targets::cleared(view, color)],
        depth_stencil_attachment: None,
        timestamp_writes: timer.and_then(|t| t.render_span("edge.clear")),
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// What store_pixel writes into an output of `format` for a pixel of background colour
/// `background` (linear) without a line, as a clear colour: the baselines' clear colour of
/// it (encode_output's encoding) with alpha at least 0, and an 8-bit one on the format's own
/// steps (a clear converts exactly what the format holds exactly; an Rgba16Float output's
/// background already is a half, see `prepare`).
fn background_value(format: wgpu::TextureFormat, background: [f32; 4]) -> wgpu::Color {
    let [r, g, b, a] = background;
    let c = targets::clear_color(format, [r, g, b, a.max(0.0)]);
    if format != wgpu::TextureFormat::Rgba8Unorm {
        return c;
    }
    let unorm = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() / 255.0;
    wgpu::Color {
        r: unorm(c.r),
        g: unorm(c.g),
        b: unorm(c.b),
        a: unorm(c.a),
    }
}

/// `x` rounded to the nearest IEEE half-precision value (ties to even), as f32.
pub(crate) fn round_to_half(x: f32) -> f32 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    // A half has 10 fraction bits; below 2^-14 its spacing stays 2^-24.
    let exponent = (((x.to_bits() >> 23) & 0xff) as i32 - 127).max(-14);
    let step = 2f32.powi(exponent - 10);
    let r = (x / step).round_ties_even() * step;
    if r.abs() > 65504.0 {
        return f32::INFINITY.copysign(x);
    }
    r
}

fn edge_module(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    flags: &[&str],
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("wirepass edge pass"),
        source: wgpu::ShaderSource::Wgsl(shaders::edge_source(format, flags).into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_to_half_is_the_nearest_half() {
        let mut x = 1.0e-9_f32;
        while x < 70000.0 {
            for v in [x, -x, x * 1.000_3, x * 0.999_7] {
                let want = half::f16::from_f32(v).to_f32();
                assert_eq!(round_to_half(v).to_bits(), want.to_bits(), "{v:e}");
            }
            x *= 1.013;
        }
        // Ties go to even, as a conversion does.
        for v in [
            1.0 + 1.0 / 2048.0,
            1.0 + 3.0 / 2048.0,
            2.0_f32.powi(-24) * 2.5,
        ] {
            assert_eq!(round_to_half(v), half::f16::from_f32(v).to_f32(), "{v:e}");
        }
    }

    #[test]
    fn the_background_value_is_what_the_shader_stores() {
        let rgba = |c: wgpu::Color| [c.r, c.g, c.b, c.a];
        let c = [0.1, 0.5, 1.0, 0.25];
        let srgb = background_value(wgpu::TextureFormat::Rgba8Unorm, c);
        let want = [89.0, 188.0, 255.0, 64.0].map(|b: f64| b / 255.0);
        assert_eq!(rgba(srgb), want);
        // Alpha at least 0; float formats hold linear values.
        let f = background_value(wgpu::TextureFormat::Rgba32Float, [0.1, 0.2, 0.3, -1.0]);
        assert_eq!(rgba(f), [0.1, 0.2, 0.3, 0.0].map(|v: f32| f64::from(v)));
    }
}
