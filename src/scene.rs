//! What a frame draws: instances of uploaded meshes, each with its own model transform and
//! style overrides, seen through one [`View`].

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::{Orbit, View};
use crate::error::{Error, Result};
use crate::style::{comma_separated, Color, HiddenLines, LinePattern, MAX_LINE_WIDTH};
use glam::{DMat4, DVec3};

/// Most instances a frame may hold: instance slots must fit 18 bits of the trace pass's
/// per-pixel owner word, whose next two say whether the line is an outline, a section's cut
/// line or an edge.
pub const MAX_INSTANCES: u32 = 1 << 18;

/// A mesh in a [`MeshStore`](crate::gpu::MeshStore). Copy it into as many [`Instance`]s as
/// you like: instances of one mesh share its storage and are drawn instanced. (Defined here,
/// below the pass, so that a scene names meshes without depending on the store.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId {
    /// The store that holds it (`MeshStore`'s own id).
    pub(crate) store: u32,
    pub(crate) slot: u32,
    /// The slot's generation when the mesh went in: an id outlives its removal harmlessly.
    pub(crate) generation: u32,
}

#[cfg(test)]
impl MeshId {
    /// An id of slot `slot` in no store.
    pub(crate) fn unstored(slot: u32) -> MeshId {
        MeshId {
            store: 0,
            slot,
            generation: 0,
        }
    }
}

/// Per-instance departures from the frame's [`Style`](crate::Style); `None` keeps the
/// style's setting.
///
/// ```
/// use wirepass::{Color, InstanceStyle, Style};
/// // This part in red with wider lines and no outline; everything else as the frame's.
/// let part = InstanceStyle {
///     wire_color: Some(Color::from_hex("#c02020")?),
///     line_width: Some(2.5),
///     outlines: Some(false),
///     ..InstanceStyle::default()
/// };
/// let style = Style::default();
/// assert_eq!(part.outline_width_in(&style), 2.5);
/// assert!(part.validate(0).is_ok());
/// # Ok::<(), wirepass::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InstanceStyle {
    /// Colour of this instance's lines (its edges and its outline).
    pub wire_color: Option<Color>,
    /// Colour of this instance's shaded surface, before lighting (its alpha is unused:
    /// surfaces are opaque).
    pub fill_color: Option<Color>,
    /// Width of this instance's lines, in pixels.
    pub line_width: Option<f32>,
    /// `Some(false)` draws none of this instance's edges; it still occludes, and still has
    /// its outline unless `outlines` is `Some(false)` too.
    pub edges: Option<bool>,
    /// Whether this instance's outline (silhouettes and boundaries) is drawn; the style's
    /// [`outlines`](crate::Style::outlines) otherwise.
    pub outlines: Option<bool>,
    /// Colour of this instance's outline; otherwise the style's
    /// [`outline_color`](crate::Style::outline_color), else this instance's line colour.
    pub outline_color: Option<Color>,
    /// Width of this instance's outline, in pixels; otherwise the style's
    /// [`outline_width`](crate::Style::outline_width), else this instance's line width.
    pub outline_width: Option<f32>,
    /// The pattern of this instance's drawn edges; otherwise the style's
    /// [`edge_pattern`](crate::Style::edge_pattern).
    pub edge_pattern: Option<LinePattern>,
    /// The pattern of this instance's outline; otherwise the style's
    /// [`outline_pattern`](crate::Style::outline_pattern).
    pub outline_pattern: Option<LinePattern>,
    /// This instance's hidden lines: the style's [`hidden`](crate::Style::hidden), none, or
    /// its own.
    pub hidden: HiddenOverride,
}

/// An instance's hidden lines ([`InstanceStyle::hidden`]) against the frame's
/// [`Style::hidden`](crate::Style::hidden).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum HiddenOverride {
    /// As the frame's style draws them (or not).
    #[default]
    Style,
    /// None, whatever the style says.
    Off,
    /// These, also in a frame whose style draws none (a selected part seen through what
    /// hides it).
    Lines(HiddenLines),
}

/// A selection highlight: the instance's outline as an object (its silhouettes and
/// boundaries, exact where they are visible) in a colour and width of its own, its hidden
/// part in a pattern where other surfaces hide it, and a tint of its surface.
/// [`InstanceStyle::highlighted`] applies it; an instance without one costs nothing more.
///
/// ```
/// use wirepass::{Highlight, InstanceStyle, Style};
/// let style = Style::default();
/// let selected = InstanceStyle::default().highlighted(&Highlight::default(), &style);
/// assert_eq!(selected.outlines, Some(true));
/// assert!(selected.hidden_in(&style).is_some());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Highlight {
    /// Colour of the outline (linear RGBA), and of its hidden part.
    pub color: Color,
    /// Width of the outline, pixels.
    pub width: f32,
    /// The pattern of the outline's hidden part; `None` leaves the instance's hidden lines
    /// as they are.
    pub hidden: Option<LinePattern>,
    /// Mixed into the instance's fill colour by its alpha; `None` keeps the fill.
    pub fill_tint: Option<Color>,
}

impl Default for Highlight {
    fn default() -> Self {
        Highlight {
            // #ff8c1a, in linear RGB.
            color: Color([1.0, 0.262, 0.010, 1.0]),
            width: 3.0,
            hidden: Some(LinePattern::Dashed {
                dash: 6.0,
                gap: 4.0,
            }),
            fill_tint: Some(Color([1.0, 0.262, 0.010, 0.25])),
        }
    }
}

/// One placement of a mesh: which mesh, where (any affine model → world transform,
/// non-uniform scale and mirroring included), and how it looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// The mesh, as [`MeshStore::insert`](crate::gpu::MeshStore::insert) returned it.
    pub mesh: MeshId,
    /// Model → world, in f64 (precision is kept until the matrix reaches the GPU).
    pub transform: DMat4,
    /// Style overrides.
    pub style: InstanceStyle,
}

impl Instance {
    /// An instance of `mesh` at `transform`, in the frame's style.
    pub fn new(mesh: MeshId, transform: DMat4) -> Instance {
        Instance {
            mesh,
            transform,
            style: InstanceStyle::default(),
        }
    }

    /// This instance with `style` overrides.
    pub fn with_style(self, style: InstanceStyle) -> Instance {
        Instance { style, ..self }
    }

    /// Checks the transform and overrides; `index` names the instance in errors.
    pub fn validate(&self, index: usize) -> Result<()> {
        check_transform(&self.transform, index)?;
        self.style.validate(index)
    }
}

impl InstanceStyle {
    /// The colour of the instance's outline in `style`: its own, the style's, or its line
    /// colour.
    pub fn outline_color_in(&self, style: &crate::Style) -> Color {
        self.outline_color
            .or(style.outline_color)
            .unwrap_or(self.wire_color.unwrap_or(style.wire_color))
    }

    /// The width of the instance's outline in `style`: its own, the style's, or its line
    /// width.
    pub fn outline_width_in(&self, style: &crate::Style) -> f32 {
        self.outline_width
            .or(style.outline_width)
            .unwrap_or(self.line_width.unwrap_or(style.line_width))
    }

    /// The pattern of the instance's drawn edges in `style`: its own, or the style's.
    pub fn edge_pattern_in(&self, style: &crate::Style) -> LinePattern {
        self.edge_pattern.unwrap_or(style.edge_pattern)
    }

    /// The pattern of the instance's outline in `style`: its own, or the style's.
    pub fn outline_pattern_in(&self, style: &crate::Style) -> LinePattern {
        self.outline_pattern.unwrap_or(style.outline_pattern)
    }

    /// The instance's hidden lines in `style`: its own, or the style's.
    pub fn hidden_in(&self, style: &crate::Style) -> Option<HiddenLines> {
        match self.hidden {
            HiddenOverride::Style => style.hidden,
            HiddenOverride::Off => None,
            HiddenOverride::Lines(h) => Some(h),
        }
    }

    /// This style with the highlight `h` (in the frame's `style`): its outline drawn in the
    /// highlight's colour and width; where `h.hidden` is given, the outline's hidden part in
    /// that pattern, a thinner line of the same colour (the hidden parts of its drawn edges
    /// too where its hidden lines already draw them); its fill tinted.
    pub fn highlighted(self, h: &Highlight, style: &crate::Style) -> InstanceStyle {
        let hidden = match h.hidden {
            None => self.hidden,
            Some(pattern) => HiddenOverride::Lines(HiddenLines {
                pattern,
                color: h.color,
                width: (0.5 * h.width).max(1.0),
                behind_host: false,
                edges: self.hidden_in(style).is_some_and(|l| l.edges),
            }),
        };
        let fill_color = match h.fill_tint {
            None => self.fill_color,
            Some(t) => {
                let base = self.fill_color.unwrap_or(style.fill_color).0;
                let k = t.0[3];
                Some(Color([0, 1, 2, 3].map(|i| {
                    if i == 3 {
                        base[3]
                    } else {
                        base[i] + (t.0[i] - base[i]) * k
                    }
                })))
            }
        };
        InstanceStyle {
            outlines: Some(true),
            outline_color: Some(h.color),
            outline_width: Some(h.width),
            hidden,
            fill_color,
            ..self
        }
    }

    /// Checks the overrides; `index` names the instance in errors.
    pub fn validate(&self, index: usize) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidScene(format!("instance {index}: {m}")));
        // Colours first: a highlight's colour is the outline's and its hidden part's, and
        // is named as the outline's.
        for (what, c) in [("wire", self.wire_color), ("outline", self.outline_color)] {
            if let Some(c) = c {
                if c.0.iter().any(|v| !v.is_finite()) {
                    return bad(format!("{what} colour {:?} is not finite", c.0));
                }
            }
        }
        if self.outlines == Some(true) && self.outline_width == Some(0.0) {
            return bad(
                "outline width 0 with outlines on draws no outline (turn outlines off instead)"
                    .into(),
            );
        }
        if let HiddenOverride::Lines(h) = self.hidden {
            if let Err(e) = h.validate() {
                return bad(e.to_string());
            }
        }
        for (what, p) in [
            ("edge", self.edge_pattern),
            ("outline", self.outline_pattern),
        ] {
            if let Err(e) = p.map_or(Ok(()), |p| p.validate(what)) {
                return bad(e.to_string());
            }
        }
        for (what, w) in [("line", self.line_width), ("outline", self.outline_width)] {
            if let Some(w) = w {
                if !(0.0..=MAX_LINE_WIDTH).contains(&w) {
                    return bad(format!(
                        "{what} width {w} is not in 0..={MAX_LINE_WIDTH} pixels"
                    ));
                }
            }
        }
        if let Some(c) = self.fill_color {
            if c.0.iter().any(|v| !v.is_finite()) {
                return bad(format!("fill colour {:?} is not finite", c.0));
            }
        }
        Ok(())
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Checks a model transform: finite, affine (last row 0, 0, 0, 1) and not singular.
/// `index` names the instance in errors.
pub fn check_transform(t: &DMat4, index: usize) -> Result<()> {
    let bad = |m: String| Err(Error::InvalidScene(format!("instance {index}: {m}")));
    if !t.is_finite() {
        return bad("the transform has a non-finite entry".into());
    }
    if t.row(3) != glam::DVec4::W {
        return bad(format!(
            "the transform's last row is {}, not (0, 0, 0, 1): model transforms are affine",
            t.row(3)
        ));
    }
    if !(t.determinant().abs() > 0.0) {
        return bad("the transform is singular (a zero scale)".into());
    }
    Ok(())
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The world-space bounds of model-space bounds `(lo, hi)` placed by `transform`: the box
/// round its eight transformed corners.
pub fn world_box((lo, hi): (DVec3, DVec3), transform: DMat4) -> (DVec3, DVec3) {
    (0..8).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), k| {
        let corner = DVec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
        let p = transform.transform_point3(corner);
        (a.min(p), b.max(p))
    })
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The pairs `(a, b)`, `a < b`, of placed objects (model-space bounds and model → world
/// transform) whose surfaces may cross: their world bounds, each grown by its share of the
/// pair's crossing tolerance (`mesh::crossings::pair_tolerance`),
/// meet. Sorted.
pub fn crossing_pairs(placed: &[((DVec3, DVec3), DMat4)]) -> Vec<(usize, usize)> {
    let grown: Vec<(DVec3, DVec3)> = placed
        .iter()
        .map(|&(bounds, t)| {
            let (lo, hi) = world_box(bounds, t);
            let grow = crate::mesh::crossings::pair_tolerance((lo, hi), (lo, hi));
            (lo - grow, hi + grow)
        })
        .collect();
    meeting_pairs(&grown)
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The pairs `(a, b)`, `a < b`, of boxes that meet (touching counts), sorted.
pub fn meeting_pairs(boxes: &[(DVec3, DVec3)]) -> Vec<(usize, usize)> {
    // Sweep along x.
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
    let mut pairs = Vec::new();
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if boxes[b].0.x > boxes[a].1.x {
                break;
            }
            if boxes[a].0.cmple(boxes[b].1).all() && boxes[b].0.cmple(boxes[a].1).all() {
                pairs.push((a.min(b), a.max(b)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// A frame's scene: the instances to draw and the view to draw them through.
///
/// Every instance goes through one visibility pass and one edge pass, so instances occlude
/// each other exactly, and each pixel knows which instance and which of its mesh's
/// triangles it shows.
///
/// ```
/// use wirepass::glam::DMat4;
/// use wirepass::{Instance, Scene, View};
/// # fn scene(bunny: wirepass::gpu::MeshId, view: View) -> Scene<'static> {
/// let instances = vec![
///     Instance::new(bunny, DMat4::IDENTITY),
///     // A mirrored, stretched copy beside it.
///     Instance::new(bunny, DMat4::from_translation((2.0, 0.0, 0.0).into())
///         * DMat4::from_scale((-1.0, 1.5, 1.0).into())),
/// ];
/// Scene::new(view, instances)
/// # }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Scene<'a> {
    /// How the scene is seen.
    pub view: View,
    /// What is drawn, in order (the order numbers instances in dumps and ids).
    pub instances: std::borrow::Cow<'a, [Instance]>,
    /// Section planes, at most [`MAX_SECTIONS`]: what lies behind any of them is cut away.
    pub sections: Vec<SectionPlane>,
}

/// Most section planes a scene may hold.
pub const MAX_SECTIONS: usize = 6;

/// A section plane in world space: the half-space behind it (where
/// `(x − point) · normal < 0`) is cut away, surfaces and lines alike, as a section view of a
/// CAD program cuts a part open.
///
/// Surfaces are cut at each pixel centre (by the plane's distance, interpolated over the
/// triangle from its corners, not by a depth guess); a drawn edge or an outline that crosses
/// a plane ends where it meets it; back faces seen through the cut are drawn in
/// [`Style::section_color`](crate::Style::section_color), so a closed part shows a solid
/// section face. Only the deferred pass and the ground truth cut.
///
/// ```
/// use wirepass::glam::DVec3;
/// use wirepass::SectionPlane;
/// // Keep x >= 0.5.
/// let plane = SectionPlane::new(DVec3::new(0.5, 0.0, 0.0), DVec3::X);
/// assert!(plane.validate(0).is_ok());
/// assert!(plane.side(DVec3::new(1.0, 2.0, 3.0)) > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionPlane {
    /// A point of the plane.
    pub point: DVec3,
    /// Its normal, towards what is kept; any non-zero length.
    pub normal: DVec3,
}

impl SectionPlane {
    /// The plane through `point` with `normal` pointing into the kept half-space.
    pub fn new(point: DVec3, normal: DVec3) -> SectionPlane {
        SectionPlane { point, normal }
    }

    /// Parses `PX,PY,PZ,NX,NY,NZ`: a point on the plane and its normal, towards what is kept
    /// (the command line's `--section`, the web element's `sections`). Not validated: call
    /// [`validate`](Self::validate).
    pub fn parse(s: &str) -> Result<SectionPlane> {
        let bad = || Error::InvalidSetting(format!("{s:?} is not PX,PY,PZ,NX,NY,NZ, six numbers"));
        let n: Vec<f64> = comma_separated(s, bad)?;
        let [px, py, pz, nx, ny, nz] = n[..] else {
            return Err(bad());
        };
        Ok(SectionPlane::new(
            DVec3::new(px, py, pz),
            DVec3::new(nx, ny, nz),
        ))
    }

    /// The plane through the point `orbit` circles, its normal the way the camera looks: the
    /// half nearer the eye is cut away, so the cut faces the viewer (a viewer's `S` key).
    pub fn across(orbit: &Orbit) -> SectionPlane {
        let eye = orbit.camera().eye.as_dvec3();
        SectionPlane::new(orbit.target, orbit.target - eye)
    }

    /// The plane moved along its normal by `steps` twentieths of `orbit`'s framed radius
    /// (negative steps move it back; a viewer's `[`/`]` keys).
    pub fn nudged(self, orbit: &Orbit, steps: f64) -> SectionPlane {
        let along = self.normal.normalize_or_zero() * (0.05 * steps * orbit.radius);
        SectionPlane::new(self.point + along, self.normal)
    }

    /// The plane's function at `p`: `(p − point) · normal / |normal|`, the signed distance,
    /// negative where `p` is cut away.
    pub fn side(&self, p: DVec3) -> f64 {
        (p - self.point).dot(self.normal) / self.normal.length()
    }

    /// Where the plane crosses the triangle with corners `c`: the points where its
    /// [`side`](Self::side) changes sign along the two sides it crosses (twin of
    /// `cut_segment` in trace.wgsl); `None` where all corners lie on one side.
    pub fn cut_triangle(&self, c: [DVec3; 3]) -> Option<(DVec3, DVec3)> {
        let s = c.map(|p| self.side(p));
        let mut ends = [DVec3::ZERO; 2];
        let mut found = 0;
        for j in 0..3 {
            let (a, b) = (s[j], s[(j + 1) % 3]);
            if (a < 0.0) != (b < 0.0) {
                ends[found.min(1)] = c[j].lerp(c[(j + 1) % 3], a / (a - b));
                found += 1;
            }
        }
        (found == 2).then_some((ends[0], ends[1]))
    }

    /// The plane as the coefficients `(n, −n · point)` of a unit normal n.
    pub fn coefficients(&self) -> glam::DVec4 {
        let n = self.normal / self.normal.length();
        n.extend(-n.dot(self.point))
    }

    /// Checks that the point is finite and the normal finite and not zero; `index` names
    /// the plane in errors.
    pub fn validate(&self, index: usize) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidScene(format!("section plane {index}: {m}")));
        if !self.point.is_finite() {
            return bad(format!("its point {} is not finite", self.point));
        }
        let length = self.normal.length();
        if !self.normal.is_finite() || !(length > 0.0) || !length.is_finite() {
            return bad(format!(
                "its normal {} is not a finite, non-zero vector",
                self.normal
            ));
        }
        Ok(())
    }
}

impl<'a> Scene<'a> {
    /// A scene owning its instance list.
    pub fn new(view: View, instances: Vec<Instance>) -> Scene<'static> {
        Scene {
            view,
            instances: instances.into(),
            sections: Vec::new(),
        }
    }

    /// A scene borrowing the host's instance list.
    pub fn borrowed(view: View, instances: &'a [Instance]) -> Scene<'a> {
        Scene {
            view,
            instances: instances.into(),
            sections: Vec::new(),
        }
    }

    /// This scene cut by `sections` (see [`SectionPlane`]).
    pub fn with_sections(self, sections: Vec<SectionPlane>) -> Scene<'a> {
        Scene { sections, ..self }
    }

    /// Checks the view and every instance.
    pub fn validate(&self) -> Result<()> {
        self.view.validate()?;
        if self.instances.len() >= MAX_INSTANCES as usize {
            return Err(Error::InvalidScene(format!(
                "{} instances; at most {} are supported",
                self.instances.len(),
                MAX_INSTANCES - 1
            )));
        }
        for (i, instance) in self.instances.iter().enumerate() {
            instance.validate(i)?;
        }
        validate_sections(&self.sections)
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Checks a list of section planes: at most [`MAX_SECTIONS`], each valid.
pub fn validate_sections(sections: &[SectionPlane]) -> Result<()> {
    if sections.len() > MAX_SECTIONS {
        return Err(Error::InvalidScene(format!(
            "{} section planes; at most {MAX_SECTIONS} are supported",
            sections.len()
        )));
    }
    for (i, s) in sections.iter().enumerate() {
        s.validate(i)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_highlight_that_cannot_draw_is_named_for_what_it_sets() {
        let style = crate::Style::default();
        let with = |h: Highlight| {
            InstanceStyle::default()
                .highlighted(&h, &style)
                .validate(3)
                .unwrap_err()
                .to_string()
        };
        let zero = with(Highlight {
            width: 0.0,
            ..Highlight::default()
        });
        assert!(
            zero.contains("instance 3") && zero.contains("outline width 0"),
            "{zero}"
        );
        let nan = with(Highlight {
            color: Color([f32::NAN, 0.0, 0.0, 1.0]),
            ..Highlight::default()
        });
        assert!(nan.contains("outline colour"), "{nan}");
        assert!(InstanceStyle::default()
            .highlighted(&Highlight::default(), &style)
            .validate(0)
            .is_ok());
    }

    #[test]
    fn objects_meet_where_their_placed_bounds_do() {
        let unit = (DVec3::splat(-1.0), DVec3::ONE);
        let at = |x: f64| DMat4::from_translation(DVec3::new(x, 0.0, 0.0));
        // Turned by 45°, its corners reach 1.41 from its centre.
        let turned = at(2.3) * DMat4::from_rotation_z(std::f64::consts::FRAC_PI_4);
        assert_eq!(crossing_pairs(&[(unit, at(0.0)), (unit, at(2.3))]), []);
        assert_eq!(crossing_pairs(&[(unit, at(0.0)), (unit, turned)]), [(0, 1)]);
        assert_eq!(
            crossing_pairs(&[(unit, at(0.0)), (unit, at(5.0)), (unit, at(6.5))]),
            [(1, 2)]
        );
    }

    #[test]
    fn a_plane_across_an_orbit_cuts_away_the_half_nearer_the_eye() {
        let orbit = Orbit::framing(DVec3::splat(-1.0), DVec3::splat(1.0));
        let plane = SectionPlane::across(&orbit);
        assert!(plane.side(orbit.camera().eye.as_dvec3()) < 0.0);
        assert!(plane.side(orbit.target).abs() < 1e-6);
        // Two steps on: a tenth of the radius further from the eye.
        let moved = plane.nudged(&orbit, 2.0).side(orbit.target);
        assert!((moved + 0.1 * orbit.radius).abs() < 1e-6, "{moved}");
    }
}
