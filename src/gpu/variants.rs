//! The settings constant over a frame that specialise the compute pipelines, and the WGSL
//! `#if` flags each one sets. The deferred pass picks its pipelines by them, and
//! [`shader_modules`] lists every module they can select (with every other pass's) for
//! validation, so the two cannot drift apart.

/// What the edge pass writes, which selects its pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Mode {
    Shade,
    Overlay {
        encoded: bool,
    },
    Result {
        shaded: bool,
    },
    #[cfg(feature = "diagnostics")]
    Diagnostic,
}

impl Mode {
    /// Every mode.
    pub(crate) fn all() -> Vec<Mode> {
        #[allow(unused_mut)]
        let mut all = vec![
            Mode::Shade,
            Mode::Overlay { encoded: false },
            Mode::Overlay { encoded: true },
            Mode::Result { shaded: false },
            Mode::Result { shaded: true },
        ];
        #[cfg(feature = "diagnostics")]
        all.push(Mode::Diagnostic);
        all
    }

    /// The WGSL flags of this mode.
    pub(crate) fn flags(self) -> &'static [&'static str] {
        match self {
            Mode::Shade => &["MODE_SHADE"],
            Mode::Overlay { encoded: false } => &["MODE_OVERLAY"],
            Mode::Overlay { encoded: true } => &["MODE_OVERLAY", "HOST_ENCODED"],
            Mode::Result { shaded: false } => &["MODE_RESULT"],
            Mode::Result { shaded: true } => &["MODE_RESULT", "SHADED"],
            #[cfg(feature = "diagnostics")]
            Mode::Diagnostic => &["MODE_DIAGNOSTIC"],
        }
    }
}

/// The WGSL flag of the benchmark floor, the edge module's one pipeline without a [`Mode`].
pub(crate) const FLOOR_FLAGS: &[&str] = &["MODE_FLOOR"];

/// Settings constant over a frame that specialise the trace and edge pipelines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Variant {
    pub split: bool,
    /// The trace pass runs ([`FrameData::traced`](super::frame::FrameData)).
    pub traced: bool,
    pub patches: bool,
    /// Outline colours differ between instances; only with `traced`.
    pub colors: bool,
    /// Hidden lines are drawn (by the trace pass); only with `traced`.
    pub hidden: bool,
    /// A line is dashed or dotted; only with `traced`, and only the trace pass reads it.
    pub patterns: bool,
    /// The frame has section planes; only with `traced`, and only the trace pass reads it
    /// (the edge pass's section colour is a select on the frame's value).
    pub sections: bool,
    /// Surfaces may cross ([`FrameData::crossing`](super::frame::FrameData)); only with
    /// `traced`. The edge pass reads it too: near where instances cross, it leaves their
    /// edges to the trace pass.
    pub crossing: bool,
    pub host: bool,
    /// The instance records are bound as a uniform array.
    pub uniform_instances: bool,
    /// The frame has exactly one instance; only with uniform instances.
    pub one_instance: bool,
}

impl Variant {
    /// This variant as the edge pass's pipelines are specialised: without the settings only
    /// the trace pass reads.
    pub(crate) fn for_edges(self) -> Variant {
        Variant {
            patterns: false,
            sections: false,
            ..self
        }
    }

    /// Every variant a frame can select: `colors`, `hidden`, `patterns`, `sections` and
    /// `crossing` need `traced`, `one_instance` needs `uniform_instances`; for validation,
    /// sections and crossings are taken each alone, and both together with patterns.
    pub(crate) fn all() -> Vec<Variant> {
        let mut all = Vec::new();
        for split in [false, true] {
            for (traced, colors, hidden) in [
                (false, false, false),
                (true, false, false),
                (true, true, false),
                (true, false, true),
                (true, true, true),
            ] {
                for patches in [false, true] {
                    for host in [false, true] {
                        for (uniform_instances, one_instance) in
                            [(false, false), (true, false), (true, true)]
                        {
                            for patterns in [false, true].into_iter().filter(|&p| traced || !p) {
                                // Sections and crossings: only with `traced`, and each
                                // alone or both, the last with patterns only.
                                let cuts: &[(bool, bool)] = match (traced, patterns) {
                                    (false, _) => &[(false, false)],
                                    (true, false) => {
                                        &[(false, false), (true, false), (false, true)]
                                    }
                                    (true, true) => &[(false, false), (true, true)],
                                };
                                for &(sections, crossing) in cuts {
                                    all.push(Variant {
                                        split,
                                        traced,
                                        patches,
                                        colors,
                                        hidden,
                                        patterns,
                                        sections,
                                        crossing,
                                        host,
                                        uniform_instances,
                                        one_instance,
                                    });
                                }
                            }
                        }
                    }
                }
            }
        }
        all
    }

    /// The WGSL flags of this variant.
    pub(crate) fn flags(self) -> Vec<&'static str> {
        [
            (self.split, "SPLIT"),
            (self.traced, "TRACED"),
            (self.patches, "PATCHES"),
            (self.colors, "COLORS"),
            (self.hidden, "HIDDEN"),
            (self.patterns, "PATTERNS"),
            (self.sections, "SECTIONS"),
            (self.crossing, "CROSSINGS"),
            // Sections and crossings both widen the window round a line's points.
            (self.sections || self.crossing, "WIDE"),
            (self.host, "HOST"),
            (self.uniform_instances, "UNIFORM_INSTANCES"),
            (self.one_instance, "ONE_INSTANCE"),
        ]
        .into_iter()
        .filter_map(|(on, flag)| on.then_some(flag))
        .collect()
    }

    /// The WGSL flags of this variant's trace module, with pieces of 1 px for a GPU
    /// (`short_pieces`, [`Tuning`](super::Tuning)).
    pub(crate) fn trace_flags(self, short_pieces: bool) -> Vec<&'static str> {
        let mut flags = self.flags();
        // With hidden lines, the visibility test's walks turn at folds (`locate`): the
        // sheet past a fold hides the lines behind it. Other frames do not pay for it.
        if self.hidden {
            flags.push("TURNS");
        }
        if short_pieces {
            flags.push("SHORT_PIECES");
        }
        flags
    }
}

/// Every module the crate builds, named by its settings: each pass in each of its
/// specialisations (the edge and trace passes in every output mode and frame variant a
/// frame can select), for validation without a GPU.
#[cfg_attr(not(feature = "diagnostics"), allow(dead_code))]
pub fn shader_modules() -> Vec<(String, String)> {
    use super::shaders::*;
    use wgpu::TextureFormat as F;
    let mut out = vec![];
    for tested in [false, true] {
        for encode in [false, true] {
            out.push((
                format!("composite tested={tested} encode_srgb={encode}"),
                composite_source(tested, encode),
            ));
        }
    }
    for multisampled in [false, true] {
        out.push((
            format!("host depth multisampled={multisampled}"),
            host_depth_source(multisampled),
        ));
    }
    for pulled in [false, true] {
        for split in [false, true] {
            for sections in [false, true] {
                out.push((
                    format!("visibility pulled={pulled} split={split} sections={sections}"),
                    visibility_source(pulled, split, sections),
                ));
            }
        }
    }
    let variants = Variant::all();
    for format in [F::Rgba8Unorm, F::Rgba16Float, F::Rgba32Float] {
        out.push((
            format!("floor {format:?}"),
            edge_source(format, FLOOR_FLAGS),
        ));
        for mode in Mode::all() {
            // The edge pass's own variants: those of the settings it reads.
            for v in variants.iter().filter(|v| v.for_edges() == **v) {
                let mut flags = v.flags();
                flags.extend_from_slice(mode.flags());
                out.push((
                    format!("edge {format:?} {flags:?}"),
                    edge_source(format, &flags),
                ));
            }
        }
    }
    for v in variants.iter().filter(|v| v.traced) {
        // Both tunings (`Tuning`).
        for short in [false, true] {
            let flags = v.trace_flags(short);
            out.push((format!("outline {flags:?}"), trace_source(&flags)));
        }
    }
    for split in [false, true] {
        for format in [
            F::Rgba8Unorm,
            F::Rgba8UnormSrgb,
            F::Rgba16Float,
            F::Rgba32Float,
        ] {
            if let Some(s) = super::baselines::forward_source(format, split) {
                out.push((format!("forward {format:?} split={split}"), s));
            }
            if let Some(s) = super::baselines::two_pass_source(format, split) {
                out.push((format!("two-pass {format:?} split={split}"), s));
            }
        }
    }
    out
}
