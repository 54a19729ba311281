//! How a wireframe looks: colours, line width, lighting, and the CPU twins of the WGSL
//! line profile and shading in `shaders/common.wgsl` (the ground truth uses these).

use crate::error::{Error, Result};
use glam::Vec3;

/// A linear-light RGBA colour.
///
/// ```
/// use wirepass::Color;
/// // #rrggbb[aa] is sRGB, as colour pickers and CSS write it; it is kept linear.
/// let c = Color::from_hex("#808080cc")?;
/// assert!((c.0[0] - 0.2158).abs() < 1e-3 && (c.0[3] - 0.8).abs() < 1e-6);
/// assert!(Color::from_hex("grey").is_err());
/// # Ok::<(), wirepass::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Color(pub [f32; 4]);

impl Color {
    /// Parses `#rgb`, `#rrggbb` or `#rrggbbaa` (the `#` optional) as sRGB and converts to linear.
    pub fn from_hex(s: &str) -> Result<Color> {
        let hex = s.strip_prefix('#').unwrap_or(s);
        let bad = || {
            Error::InvalidSetting(format!(
                "colour {s:?} is not #rgb, #rrggbb or #rrggbbaa hexadecimal"
            ))
        };
        if !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(bad());
        }
        let digits: Vec<u8> = match hex.len() {
            3 => hex.bytes().flat_map(|b| [b, b]).collect(),
            6 | 8 => hex.bytes().collect(),
            _ => return Err(bad()),
        };
        let mut c = [1.0_f32; 4];
        for (i, pair) in digits.chunks(2).enumerate() {
            let text = std::str::from_utf8(pair).map_err(|_| bad())?;
            let v = u8::from_str_radix(text, 16).map_err(|_| bad())?;
            c[i] = f32::from(v) / 255.0;
        }
        Ok(Color([
            srgb_to_linear(c[0]),
            srgb_to_linear(c[1]),
            srgb_to_linear(c[2]),
            c[3],
        ]))
    }

    /// The colour as 8-bit sRGB with straight alpha.
    pub fn to_srgb8(self) -> [u8; 4] {
        let [r, g, b, a] = self.0;
        let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        [
            q(linear_to_srgb(r)),
            q(linear_to_srgb(g)),
            q(linear_to_srgb(b)),
            q(a),
        ]
    }
}

/// Appearance settings shared by every method, so images differ only by method.
///
/// ```
/// use wirepass::{Color, HiddenLines, LinePattern, Style};
/// // CAD-style: 1 px lines, dashed hidden lines, outlines 2 px and darker.
/// let style = Style {
///     line_width: 1.0,
///     outline_width: Some(2.0),
///     outline_color: Some(Color::from_hex("#101820")?),
///     hidden: Some(HiddenLines {
///         pattern: LinePattern::Dashed { dash: 6.0, gap: 4.0 },
///         ..HiddenLines::default()
///     }),
///     ..Style::default()
/// };
/// style.validate()?;
/// // What cannot make an image is an error, never a panic.
/// assert!(Style { line_width: f32::NAN, ..Style::default() }.validate().is_err());
/// # Ok::<(), wirepass::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Style {
    /// Line width in pixels, constant at any distance and resolution.
    pub line_width: f32,
    /// Colour of the lines; its alpha scales the line's opacity
    /// ([`InstanceStyle::wire_color`](crate::InstanceStyle::wire_color) overrides it).
    pub wire_color: Color,
    /// Base colour of the shaded surface
    /// ([`InstanceStyle::fill_color`](crate::InstanceStyle::fill_color) overrides it).
    pub fill_color: Color,
    /// Opacity of the shaded surface over the background, 0..1: below 1 the visible surface
    /// is faded over the background (the "hidden lines visible" views of CAD programs, with
    /// [`hidden`](Self::hidden) lines showing through it); 1 draws it opaque.
    pub fill_opacity: f32,
    /// Colour where no triangle is visible.
    pub background: Color,
    /// Colour of the back faces seen through the cut of a section plane
    /// ([`SectionPlane`](crate::SectionPlane)), unlit: the section face of a closed part.
    pub section_color: Color,
    /// Colour of the cut lines, where a section plane meets a surface.
    pub section_line_color: Color,
    /// Width of the cut lines in pixels; `None` draws them at
    /// [`line_width`](Self::line_width).
    pub section_line_width: Option<f32>,
    /// Whether to draw intersection lines: where surfaces pass through each other (a part
    /// modelled through another, an interference fit in an assembly), the curve along which
    /// they meet, where it is visible. A mesh's own are found once, in its own coordinates,
    /// when it is uploaded ([`Mesh::intersections`](crate::Mesh::intersections)); those
    /// between two instances as a frame is prepared, for the instances whose placed bounds
    /// meet, and kept while both keep their placement.
    pub intersection_lines: bool,
    /// Colour of the intersection lines.
    pub intersection_line_color: Color,
    /// Width of the intersection lines in pixels; `None` draws them at
    /// [`line_width`](Self::line_width).
    pub intersection_line_width: Option<f32>,
    /// Share of ambient light, 0..1; the rest comes from the key light.
    pub ambient: f32,
    /// Direction towards the key light in view space (x right, y up, z towards the viewer),
    /// so the lighting follows the camera.
    pub light_view_dir: Vec3,
    /// Colour of the outlines (silhouettes and boundaries); `None` draws them in
    /// [`wire_color`](Self::wire_color)
    /// ([`InstanceStyle::outline_color`](crate::InstanceStyle::outline_color) overrides it).
    pub outline_color: Option<Color>,
    /// Width of the outlines in pixels; `None` draws them at
    /// [`line_width`](Self::line_width)
    /// ([`InstanceStyle::outline_width`](crate::InstanceStyle::outline_width) overrides it).
    pub outline_width: Option<f32>,
    /// The pattern of the drawn edges' visible lines
    /// ([`InstanceStyle::edge_pattern`](crate::InstanceStyle::edge_pattern) overrides it).
    /// Patterned edges are drawn by the trace pass (their visible runs, like an
    /// outline's), so their cost follows the number of drawn edges in view; solid edges
    /// cost nothing more. Only the deferred pass and the ground truth draw patterns.
    pub edge_pattern: LinePattern,
    /// The pattern of the outlines' visible lines
    /// ([`InstanceStyle::outline_pattern`](crate::InstanceStyle::outline_pattern) overrides
    /// it). An outline runs its pattern from its end that comes first (see [`LinePattern`]).
    pub outline_pattern: LinePattern,
    /// Draw the outline (silhouette and boundary edges) at full width, over the background
    /// and farther surfaces too, and always, whatever the edge selection. Only the deferred
    /// pass and the ground truth can; the forward baselines draw each edge inside its own
    /// triangles, so their outlines are half as wide. See `shaders/trace.wgsl`.
    pub outlines: bool,
    /// Fade lines with their distance from the eye; `None` draws every line at full strength.
    pub depth_fade: Option<DepthFade>,
    /// Draw the parts of the drawn lines (the selected edges and the outlines) that surfaces
    /// hide, in a style of their own; `None` draws only what is visible. Only the deferred
    /// pass and the ground truth draw them. See [`HiddenLines`].
    pub hidden: Option<HiddenLines>,
}

/// How the hidden parts of the drawn lines look: the "hidden lines" of technical drawings.
///
/// A point of a drawn line is hidden where a surface of the scene lies in front of it (the
/// test that ends a visible outline); the hidden and visible parts of one edge meet exactly
/// there. Hidden lines are drawn under the surfaces' visible lines, and over the surfaces
/// that hide them.
///
/// ```
/// use wirepass::{Color, HiddenLines, LinePattern, Style};
/// let style = Style {
///     hidden: Some(HiddenLines {
///         pattern: LinePattern::Dashed { dash: 6.0, gap: 4.0 },
///         ..HiddenLines::default()
///     }),
///     ..Style::default()
/// };
/// assert!(style.validate().is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HiddenLines {
    /// Solid, dashed or dotted, in pixels along the projected edge.
    pub pattern: LinePattern,
    /// Colour of the hidden lines; its alpha scales their opacity.
    pub color: Color,
    /// Width in pixels, with the same profile as the visible lines.
    pub width: f32,
    /// Also draw, as hidden, the parts the host's depth hides (a frame prepared with the
    /// host's depth); otherwise those are not drawn at all.
    pub behind_host: bool,
    /// The hidden parts of the drawn edges too (the default); `false` draws only the
    /// outline's (silhouettes and boundaries): a selected part seen through what hides it.
    pub edges: bool,
}

impl Default for HiddenLines {
    fn default() -> Self {
        HiddenLines {
            pattern: LinePattern::Dashed {
                dash: 6.0,
                gap: 4.0,
            },
            color: Color([0.2, 0.22, 0.25, 0.8]),
            width: 1.0,
            behind_host: false,
            edges: true,
        }
    }
}

/// A line pattern along an edge's projection, in pixels: of the hidden lines
/// ([`HiddenLines::pattern`]), the drawn edges ([`Style::edge_pattern`]) or the outlines
/// ([`Style::outline_pattern`]).
///
/// Patterns are anchored to the geometry, not to the screen, and run on along chains of
/// drawn edges (edges joined where exactly two drawn edges meet): a chain starts at its end
/// that comes first in (x, y, z) order of the mesh's coordinates (a closed one at its vertex
/// that comes first), and the pattern stands on each edge where the projected length of the
/// chain before it leaves it (where an edge's start lies behind the near plane, at the
/// plane). So a circle of many short edges dashes evenly, and the pattern does not crawl
/// over the image as the camera moves. An outline's visible line, and the hidden part of an
/// outline that is not a drawn edge, run their pattern from the edge's end that comes first
/// (silhouettes change with the view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LinePattern {
    /// The whole line.
    Solid,
    /// Dashes `dash` pixels long (their round ends add half the width at each end),
    /// `gap` pixels apart.
    Dashed {
        /// Length of a dash's core, pixels.
        dash: f32,
        /// Length of the gap between two dashes' cores, pixels.
        gap: f32,
    },
    /// Dots (round, as wide as the line), one every `spacing` pixels.
    Dotted {
        /// Distance between two dots' centres, pixels.
        spacing: f32,
    },
}

impl LinePattern {
    /// Parses `off` (no hidden lines: `None`), `solid`, `dashed[:DASH,GAP]` (default 6,4) or
    /// `dotted[:SPACING]` (default 4), lengths in pixels, as the CLI and scene files take a
    /// hidden-line style.
    pub fn parse(s: &str) -> Result<Option<LinePattern>> {
        let bad = || {
            Error::InvalidSetting(format!(
                "hidden-line style {s:?} is not off, solid, dashed[:DASH,GAP] or dotted[:SPACING]"
            ))
        };
        let (name, lengths) = match s.split_once(':') {
            Some((n, l)) => (n, Some(l)),
            None => (s, None),
        };
        let numbers = |l: &str| comma_separated::<f32>(l, bad);
        let pattern = match (name, lengths) {
            ("off", None) => return Ok(None),
            ("solid", None) => LinePattern::Solid,
            ("dashed", None) => LinePattern::Dashed {
                dash: 6.0,
                gap: 4.0,
            },
            ("dashed", Some(l)) => match numbers(l)?[..] {
                [dash, gap] => LinePattern::Dashed { dash, gap },
                _ => return Err(bad()),
            },
            ("dotted", None) => LinePattern::Dotted { spacing: 4.0 },
            ("dotted", Some(l)) => match numbers(l)?[..] {
                [spacing] => LinePattern::Dotted { spacing },
                _ => return Err(bad()),
            },
            _ => return Err(bad()),
        };
        Ok(Some(pattern))
    }

    /// The pattern as the shaders take it: (dash, period) in pixels; period 0 for solid.
    pub fn dash_period(self) -> [f32; 2] {
        match self {
            LinePattern::Solid => [0.0, 0.0],
            LinePattern::Dashed { dash, gap } => [dash, dash + gap],
            LinePattern::Dotted { spacing } => [0.0, spacing],
        }
    }
}

/// The class of a line: what colours a pixel (`world::Rendering::line_class` with the
/// `truth` feature, `--dump`'s `line_class.npy`), and the numbering the shaders use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum LineClass {
    /// No line colours the pixel.
    None = 0,
    /// A drawn edge (the edges the selection draws).
    Edge = 1,
    /// An outline: a silhouette or a boundary.
    Outline = 2,
    /// A hidden line ([`Style::hidden`]).
    Hidden = 3,
    /// A section's cut line ([`SectionPlane`](crate::SectionPlane)).
    Cut = 4,
    /// An intersection line ([`Style::intersection_lines`]).
    Intersection = 5,
}

/// Longest dash, gap or dot spacing a pattern may ask for, in pixels.
pub const MAX_PATTERN_LENGTH: f32 = 4096.0;

impl HiddenLines {
    /// Rejects settings that cannot produce a sensible image.
    pub fn validate(&self) -> Result<()> {
        if !(self.width > 0.0 && self.width <= MAX_LINE_WIDTH) {
            return Err(Error::InvalidSetting(format!(
                "hidden line width {} is not in (0, {MAX_LINE_WIDTH}] pixels",
                self.width
            )));
        }
        if self.color.0.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidSetting(format!(
                "hidden line colour {:?} is not finite",
                self.color.0
            )));
        }
        self.pattern.validate("hidden line")
    }
}

impl LinePattern {
    /// Rejects lengths that cannot produce a sensible line; `what` names the line in the
    /// error.
    pub fn validate(&self, what: &str) -> Result<()> {
        let ok = |v: f32| (0.0..=MAX_PATTERN_LENGTH).contains(&v);
        let fine = match *self {
            LinePattern::Solid => true,
            LinePattern::Dashed { dash, gap } => ok(dash) && ok(gap) && dash > 0.0 && gap > 0.0,
            LinePattern::Dotted { spacing } => ok(spacing) && spacing >= 1.0,
        };
        if !fine {
            return Err(Error::InvalidSetting(format!(
                "{what} pattern {self:?}: dashes and gaps must be in (0, {MAX_PATTERN_LENGTH}] \
                 pixels, dot spacing in [1, {MAX_PATTERN_LENGTH}]"
            )));
        }
        Ok(())
    }

    /// Parses a visible line's pattern: `solid`, `dashed[:DASH,GAP]` or `dotted[:SPACING]`
    /// (as [`parse`](Self::parse), without `off`).
    pub fn parse_visible(s: &str) -> Result<LinePattern> {
        let bad = || {
            Error::InvalidSetting(format!(
                "line pattern {s:?} is not solid, dashed[:DASH,GAP] or dotted[:SPACING]"
            ))
        };
        Self::parse(s).map_err(|_| bad())?.ok_or_else(bad)
    }

    /// The pattern of a glTF `BENTLEY_materials_line_style` 16-bit `pattern` (bit 0 first,
    /// one bit a pixel, repeating): its lit bits as dashes. The bits reduce to their shortest
    /// repeat; one lit run in it is a dash of the run's length and a gap of the rest (a
    /// single lit pixel, a dot). `None` where the repeat holds more than one lit run or none,
    /// which this pattern model cannot draw.
    pub fn from_bits(bits: u16) -> Option<LinePattern> {
        if bits == 0xffff {
            return Some(LinePattern::Solid);
        }
        let bit = |i: u32| (bits >> (i % 16)) & 1 == 1;
        let period = [1u32, 2, 4, 8, 16]
            .into_iter()
            .find(|&p| (0..16).all(|i| bit(i) == bit(i + p)))?;
        let lit = (0..period).filter(|&i| bit(i)).count() as u32;
        // Lit runs: places where a lit bit follows an unlit one, cyclically.
        let starts: Vec<u32> = (0..period)
            .filter(|&i| bit(i) && !bit(i + period - 1))
            .collect();
        if lit == 0 || starts.len() != 1 {
            return None;
        }
        Some(if lit == 1 {
            LinePattern::Dotted {
                spacing: period as f32,
            }
        } else {
            LinePattern::Dashed {
                dash: lit as f32,
                gap: (period - lit) as f32,
            }
        })
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Twin of `dash_nearest` in common.wgsl: of the points of the pattern's dashes (cores
/// `[j·period, j·period + dash]` for every integer j; `period` 0 for a solid line) that lie
/// in `[lo, hi]`, the one nearest `s` (positions along the line, pixels); `None` where the
/// interval holds none.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // as in WGSL: NaN takes the rejecting branch
pub fn dash_nearest(s: f64, lo: f64, hi: f64, dash: f64, period: f64) -> Option<f64> {
    if !(lo <= hi) {
        return None;
    }
    let c = s.clamp(lo, hi);
    if !(period > 0.0) {
        return Some(c);
    }
    let j = (c / period).floor();
    let start = j * period;
    if c - start <= dash {
        return Some(c);
    }
    // c lies in the gap between dash j's end and dash j + 1's start.
    let end = start + dash;
    let next = start + period;
    match (end >= lo, next <= hi) {
        (true, true) => Some(if s - end <= next - s { end } else { next }),
        (true, false) => Some(end),
        (false, true) => Some(next),
        (false, false) => None,
    }
}

/// Lines fade linearly from full strength at view depth `start` to nothing at `end` (depth
/// along the view direction, in world units), which keeps dense far geometry from turning
/// into a solid mass of line colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthFade {
    /// View depth where lines start to fade.
    pub start: f32,
    /// View depth where they have faded out; greater than `start`.
    pub end: f32,
}

/// Widest line a style may ask for, in pixels: a line's reach bounds how far the edge pass
/// and the trace pass look around a pixel.
pub const MAX_LINE_WIDTH: f32 = 256.0;

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The line width of [`Style::default`], in pixels.
pub const DEFAULT_LINE_WIDTH: f32 = 1.5;

impl Default for Style {
    fn default() -> Self {
        Style {
            line_width: DEFAULT_LINE_WIDTH,
            wire_color: Color([0.005, 0.01, 0.02, 1.0]),
            fill_color: Color([0.55, 0.62, 0.72, 1.0]),
            fill_opacity: 1.0,
            background: Color([1.0, 1.0, 1.0, 1.0]),
            // #d9a38c.
            section_color: Color([0.694, 0.366, 0.262, 1.0]),
            // #5a1e0f.
            section_line_color: Color([0.102, 0.013, 0.005, 1.0]),
            section_line_width: None,
            intersection_lines: false,
            // #e8262a.
            intersection_line_color: Color([0.807, 0.019, 0.023, 1.0]),
            intersection_line_width: None,
            ambient: 0.3,
            light_view_dir: Vec3::new(-0.4, 0.6, 1.0),
            outline_color: None,
            outline_width: None,
            edge_pattern: LinePattern::Solid,
            outline_pattern: LinePattern::Solid,
            outlines: true,
            depth_fade: None,
            hidden: None,
        }
    }
}

impl Style {
    /// The width of the cut lines: [`section_line_width`](Self::section_line_width), else
    /// the line width.
    pub fn section_width(&self) -> f32 {
        self.section_line_width.unwrap_or(self.line_width)
    }

    /// The width of the intersection lines:
    /// [`intersection_line_width`](Self::intersection_line_width), else the line width.
    pub fn intersection_width(&self) -> f32 {
        self.intersection_line_width.unwrap_or(self.line_width)
    }
}

impl Style {
    /// Rejects settings that cannot produce a sensible image.
    pub fn validate(&self) -> Result<()> {
        let widths = [
            ("line", Some(self.line_width)),
            ("outline", self.outline_width),
            ("section line", self.section_line_width),
            ("intersection line", self.intersection_line_width),
        ];
        for (what, w) in widths {
            if let Some(w) = w.filter(|w| !(*w >= 0.0 && *w <= MAX_LINE_WIDTH)) {
                return Err(Error::InvalidSetting(format!(
                    "{what} width {w} is not in 0..={MAX_LINE_WIDTH} pixels"
                )));
            }
        }
        if let Some(DepthFade { start, end }) = self.depth_fade {
            if !(start >= 0.0 && end > start && end.is_finite()) {
                return Err(Error::InvalidSetting(format!(
                    "depth fade {start}:{end} must have 0 <= start < end, both finite"
                )));
            }
        }
        if !(0.0..=1.0).contains(&self.fill_opacity) {
            return Err(Error::InvalidSetting(format!(
                "fill opacity {} is not in 0..1",
                self.fill_opacity
            )));
        }
        if !(0.0..=1.0).contains(&self.ambient) {
            return Err(Error::InvalidSetting(format!(
                "ambient {} is not in 0..1",
                self.ambient
            )));
        }
        self.edge_pattern.validate("edge")?;
        self.outline_pattern.validate("outline")?;
        if let Some(hidden) = &self.hidden {
            hidden.validate()?;
        }
        if self.light_view_dir.try_normalize().is_none() {
            return Err(Error::InvalidSetting("light direction is zero".into()));
        }
        let outline = self.outline_color.unwrap_or(self.wire_color);
        for c in [self.wire_color, outline, self.fill_color, self.background] {
            if c.0.iter().any(|v| !v.is_finite()) {
                return Err(Error::InvalidSetting(format!(
                    "colour {:?} is not finite",
                    c.0
                )));
            }
        }
        Ok(())
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Twin of `line_intensity` in common.wgsl: intensity of a `width`-pixel line at distance `d`
/// pixels from its centre. A core of `width − 2` px at full intensity, then the Gaussian
/// falloff `exp2(−2 t²)` of NVIDIA's "Solid Wireframe" over the next 2 px; lines narrower
/// than 2 px keep the falloff and fade in proportion to their width.
pub fn line_intensity(d: f64, width: f64) -> f64 {
    let t = (d - (0.5 * width - 1.0).max(0.0)).max(0.0);
    if t >= 2.0 || t.is_nan() {
        return 0.0;
    }
    (0.5 * width).min(1.0) * (-2.0 * t * t).exp2()
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Twin of `depth_fade` in common.wgsl: the strength of a line at view depth `depth` (the
/// distance in front of the eye along the view axis), for the fade `fade` = (start, end); 1
/// where `end <= start` (no fade).
#[allow(clippy::neg_cmp_op_on_partial_ord)] // as in WGSL: NaN ends mean no fade
pub fn depth_fade(depth: f64, fade: [f64; 2]) -> f64 {
    let [start, end] = fade;
    if !(end > start) {
        return 1.0;
    }
    ((end - depth) / (end - start)).clamp(0.0, 1.0)
}

impl Style {
    /// The fade as the shaders take it: (start, end), or (0, 0) for none.
    pub fn fade_range(&self) -> [f32; 2] {
        self.depth_fade.map_or([0.0; 2], |f| [f.start, f.end])
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Twin of `line_key` in common.wgsl: the rank of a line at a pixel, by its intensity in
/// 1/4095 steps and then by nearness (distance in 1/4096 px steps): the pixel takes the line
/// with the greatest key, the one that colours it most.
pub fn line_key(intensity: f64, d: f64) -> u32 {
    let level = (intensity.clamp(0.0, 1.0) * 4095.0).round() as u32;
    let q = (d * KEY_DISTANCE_STEPS).clamp(0.0, f64::from(KEY_DISTANCE_MAX)) as u32;
    (level << 20) | (KEY_DISTANCE_MAX - q)
}

/// The largest distance a line key holds, in its steps (the key's low 20 bits).
pub(crate) const KEY_DISTANCE_MAX: u32 = 0xf_ffff;
/// Steps of a line key's distance per pixel.
pub(crate) const KEY_DISTANCE_STEPS: f64 = 4096.0;

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// How far from an edge its line can colour a pixel, in pixels.
pub fn line_reach(width: f64) -> f64 {
    (0.5 * width - 1.0).max(0.0) + 2.0
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Twin of `shade` in common.wgsl: diffuse key light plus ambient, with the normal turned
/// towards the viewer (`facing` is the normal dotted with the direction to the eye).
pub fn shade(
    base: [f64; 3],
    normal: glam::DVec3,
    facing: f64,
    light: glam::DVec3,
    ambient: f64,
) -> [f64; 3] {
    let n = if facing < 0.0 { -normal } else { normal };
    let k = ambient + (1.0 - ambient) * n.dot(light).max(0.0);
    base.map(|c| c * k)
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// sRGB transfer function, linear → encoded.
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// sRGB transfer function, encoded → linear.
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The numbers of `s`, separated by commas (spaces around each allowed); `bad` is the error
/// where one is not a number. Settings of the command line, scene files and the web element
/// are read with it.
pub(crate) fn comma_separated<T: std::str::FromStr>(
    s: &str,
    bad: impl Fn() -> Error,
) -> Result<Vec<T>> {
    s.split(',')
        .map(|t| t.trim().parse::<T>().map_err(|_| bad()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bit_patterns_become_one_dash_a_repeat() {
        let dashed = |dash, gap| Some(LinePattern::Dashed { dash, gap });
        assert_eq!(LinePattern::from_bits(0xffff), Some(LinePattern::Solid));
        assert_eq!(LinePattern::from_bits(0xf0f0), dashed(4.0, 4.0));
        // Lit bits 0, 1, 6 and 7 of each byte: one run of 4 across the repeat's end.
        assert_eq!(LinePattern::from_bits(0xc3c3), dashed(4.0, 4.0));
        assert_eq!(LinePattern::from_bits(0x00ff), dashed(8.0, 8.0));
        assert_eq!(LinePattern::from_bits(0x3fff), dashed(14.0, 2.0));
        assert_eq!(
            LinePattern::from_bits(0xaaaa),
            Some(LinePattern::Dotted { spacing: 2.0 })
        );
        assert_eq!(
            LinePattern::from_bits(0x0001),
            Some(LinePattern::Dotted { spacing: 16.0 })
        );
        // Two runs in the repeat, or none.
        assert_eq!(LinePattern::from_bits(0x0505), None);
        assert_eq!(LinePattern::from_bits(0x0000), None);
    }

    #[test]
    fn hex_colours() {
        assert_eq!(Color::from_hex("#ffffff").unwrap().to_srgb8(), [255; 4]);
        assert_eq!(Color::from_hex("f00").unwrap().to_srgb8(), [255, 0, 0, 255]);
        assert_eq!(
            Color::from_hex("#12345680").unwrap().to_srgb8(),
            [0x12, 0x34, 0x56, 0x80]
        );
        for bad in ["", "#12", "#gggggg", "#1234567", "red"] {
            assert!(Color::from_hex(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn profile_shape() {
        // Full intensity on the centre of a wide line, zero beyond its reach.
        assert_eq!(line_intensity(0.0, 4.0), 1.0);
        assert_eq!(line_intensity(1.0, 4.0), 1.0);
        assert_eq!(line_intensity(line_reach(4.0), 4.0), 0.0);
        // NVIDIA's "Solid Wireframe" exp2(-2 d^2) is the 2 px case.
        assert!((line_intensity(0.7, 2.0) - (-2.0_f64 * 0.49).exp2()).abs() < 1e-12);
        // Thin lines fade rather than vanish.
        assert!((line_intensity(0.0, 0.5) - 0.25).abs() < 1e-12);
        assert_eq!(line_intensity(0.0, 0.0), 0.0);
        // Monotone in distance.
        let mut last = 2.0;
        for i in 0..100 {
            let v = line_intensity(f64::from(i) * 0.05, 3.0);
            assert!(v <= last);
            last = v;
        }
    }

    #[test]
    fn fade_is_linear_between_its_ends() {
        assert_eq!(depth_fade(5.0, [0.0, 0.0]), 1.0);
        assert_eq!(depth_fade(1.0, [2.0, 4.0]), 1.0);
        assert_eq!(depth_fade(3.0, [2.0, 4.0]), 0.5);
        assert_eq!(depth_fade(9.0, [2.0, 4.0]), 0.0);
    }

    #[test]
    fn dash_nearest_is_the_nearest_dash_point() {
        // Brute force over a fine grid of the interval.
        let cases = [
            (3.0, 0.0, 20.0, 2.0, 5.0),
            (7.4, 6.0, 9.0, 2.0, 5.0),
            (-4.0, 1.0, 3.0, 1.0, 4.0),
            (30.0, 2.5, 12.5, 0.0, 2.5),
            (5.0, 2.1, 2.9, 1.0, 5.0),
            (1.0, -3.0, 3.0, 0.0, 0.0),
        ];
        for (s, lo, hi, dash, period) in cases {
            let in_dash = |x: f64| {
                period == 0.0 || {
                    let r = x - (x / period).floor() * period;
                    r <= dash + 1e-9 || r >= period - 1e-9
                }
            };
            let brute = (0..=100_000)
                .map(|k| lo + (hi - lo) * f64::from(k) / 100_000.0)
                .filter(|&x| in_dash(x))
                .min_by(|a, b| (a - s).abs().total_cmp(&(b - s).abs()));
            let got = dash_nearest(s, lo, hi, dash, period);
            match (got, brute) {
                (Some(g), Some(b)) => assert!(
                    (g - s).abs() <= (b - s).abs() + 1e-4,
                    "{s} {lo} {hi}: {g} vs {b}"
                ),
                (None, None) => {}
                _ => panic!("{s} {lo} {hi} {dash} {period}: {got:?} vs {brute:?}"),
            }
        }
    }

    #[test]
    fn hidden_styles_parse_and_validate() {
        assert_eq!(LinePattern::parse("off").unwrap(), None);
        assert_eq!(
            LinePattern::parse("solid").unwrap(),
            Some(LinePattern::Solid)
        );
        assert_eq!(
            LinePattern::parse("dashed:8,3").unwrap(),
            Some(LinePattern::Dashed {
                dash: 8.0,
                gap: 3.0
            })
        );
        assert_eq!(
            LinePattern::parse("dotted").unwrap(),
            Some(LinePattern::Dotted { spacing: 4.0 })
        );
        for bad in [
            "",
            "dash",
            "dashed:1",
            "dashed:a,b",
            "dotted:1,2",
            "solid:3",
        ] {
            assert!(LinePattern::parse(bad).is_err(), "{bad}");
        }
        let with = |pattern, width| Style {
            hidden: Some(HiddenLines {
                pattern,
                width,
                ..HiddenLines::default()
            }),
            ..Style::default()
        };
        assert!(with(LinePattern::Solid, 1.0).validate().is_ok());
        assert!(with(LinePattern::Solid, 0.0).validate().is_err());
        assert!(with(LinePattern::Solid, f32::NAN).validate().is_err());
        for bad in [
            LinePattern::Dashed {
                dash: 0.0,
                gap: 3.0,
            },
            LinePattern::Dashed {
                dash: 3.0,
                gap: -1.0,
            },
            LinePattern::Dashed {
                dash: f32::INFINITY,
                gap: 1.0,
            },
            LinePattern::Dotted { spacing: 0.5 },
            LinePattern::Dotted { spacing: f32::NAN },
        ] {
            assert!(with(bad, 1.0).validate().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn rejects_bad_style() {
        let s = Style {
            line_width: -1.0,
            ..Style::default()
        };
        assert!(s.validate().is_err());
        for line_width in [f32::NAN, f32::INFINITY, MAX_LINE_WIDTH * 2.0] {
            let s = Style {
                line_width,
                ..Style::default()
            };
            assert!(s.validate().is_err());
        }
        for (start, end) in [(2.0, 1.0), (1.0, 1.0), (-1.0, 1.0), (0.0, f32::NAN)] {
            let s = Style {
                depth_fade: Some(DepthFade { start, end }),
                ..Style::default()
            };
            assert!(s.validate().is_err(), "{start}:{end}");
        }
    }
}
