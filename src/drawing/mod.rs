//! Technical drawings: the lines of a [`Shot`] as vector paths, their visible and hidden
//! runs decided in object space in f64, written as SVG, PDF or DXF. No GPU is needed.
//!
//! A drawing has every line the raster draws ([`PathClass`]): the drawn edges, the outlines
//! (silhouettes and boundaries), the hidden parts of both where the style asks for them,
//! the cut lines of section planes and the intersection lines, in the same colours, widths
//! and patterns. Where a run ends is found exactly, not sampled (see `occlusion`): it ends
//! where its line passes behind a surface however thin, leaves a section plane's kept side,
//! or leaves the image. Runs are chained into one path along chains of drawn edges and
//! along silhouette loops, with the pattern's position at the path's start, so a dashed
//! hidden line is one path with one dash phase.
//!
//! ```
//! use wirepass::drawing::{Drawing, Page};
//! use wirepass::world::{default_world, Shot};
//! use wirepass::{Camera, EdgeSelection, HiddenLines, Style};
//!
//! let world = default_world(EdgeSelection::Feature(30.0));
//! let style = Style { hidden: Some(HiddenLines::default()), ..Style::default() };
//! let (lo, hi) = world.bounds();
//! let camera = Camera::framing(lo, hi, 4.0 / 3.0);
//! let shot = Shot { world: &world, view: camera.to_view(4.0 / 3.0), style: &style, size: (400, 300) };
//! let drawing = Drawing::new(&shot)?;
//! let svg = drawing.to_svg(&Page::pixels());
//! assert!(svg.starts_with("<?xml") && svg.contains("stroke-dasharray"));
//! # Ok::<(), wirepass::Error>(())
//! ```

mod dxf;
mod lines;
mod occlusion;
mod pdf;
mod svg;

use crate::camera::View;
use crate::error::{Error, Result};
use crate::style::Color;
use crate::world::Shot;
use glam::{DVec2, DVec3};
use std::path::Path as FilePath;
use web_time::{Duration, Instant};

/// The longest side a drawing's view may have, in pixels: a drawing scales to any page
/// ([`Page`]), so more adds nothing but work.
pub const MAX_SIZE: u32 = 1 << 16;

/// What a path draws, in the order a drawing paints them (later over earlier).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PathClass {
    /// A hidden part of a drawn edge or an outline ([`Style::hidden`](crate::Style::hidden)).
    Hidden,
    /// A visible part of a drawn edge.
    Edge,
    /// A visible part of an outline: a silhouette or a boundary.
    Outline,
    /// A section plane's cut line.
    Cut,
    /// An intersection line.
    Intersection,
}

impl PathClass {
    /// Every class, in painting order.
    pub const ALL: [PathClass; 5] = [
        PathClass::Hidden,
        PathClass::Edge,
        PathClass::Outline,
        PathClass::Cut,
        PathClass::Intersection,
    ];

    /// Its name in files: the SVG group's id, the DXF layer.
    pub fn name(self) -> &'static str {
        match self {
            PathClass::Hidden => "hidden",
            PathClass::Edge => "edges",
            PathClass::Outline => "outlines",
            PathClass::Cut => "cuts",
            PathClass::Intersection => "intersections",
        }
    }
}

/// One stroked polyline of a drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    /// What it draws.
    pub class: PathClass,
    /// The object it belongs to (an intersection line between two: the lower).
    pub object: u32,
    /// Its points, pixels of the view (x right, y down, (0, 0) the image's top-left corner).
    pub points: Vec<DVec2>,
    /// The world points they are the projections of: each two consecutive ones lie on one
    /// straight piece of the line.
    pub world_points: Vec<DVec3>,
    /// Stroke colour; its alpha is the stroke's opacity.
    pub color: Color,
    /// Stroke width, pixels, with round caps and joins (the raster's line profile).
    pub width: f64,
    /// Its pattern: dashes `[0]` pixels long every `[1]` pixels (a dot: no length); `[1]`
    /// is 0 for a solid line.
    pub pattern: [f64; 2],
    /// The pattern's position at the first point, in `[0, pattern[1])`: a dash covers
    /// positions `[j·period, j·period + dash]`.
    pub offset: f64,
}

impl Path {
    /// Its length, pixels.
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
}

/// Where the time of [`Drawing::new`] went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DrawingTimings {
    /// Placing the triangles in the world, cutting them by the near, far and section
    /// planes, and binning their screen boxes.
    pub occluders: Duration,
    /// Finding every line (drawn edges and their chains, outlines, cut and intersection
    /// lines), their visible and hidden runs, and making paths of them.
    pub lines: Duration,
}

/// The lines of a shot as vector paths; see the [module](self).
#[derive(Clone, Debug, PartialEq)]
pub struct Drawing {
    /// The view's size, pixels: the page, before [`Page`] scales it.
    pub size: (u32, u32),
    /// The page's colour.
    pub background: Color,
    /// The paths, in painting order ([`PathClass`]).
    pub paths: Vec<Path>,
    /// Where the time went.
    pub timings: DrawingTimings,
}

impl Drawing {
    /// The drawing of `shot`: its world through its view, in its style, at its size.
    /// Depth fade and surface colours are not drawn.
    pub fn new(shot: &Shot<'_>) -> Result<Drawing> {
        let (width, height) = shot.size;
        if width == 0 || height == 0 || width.max(height) > MAX_SIZE {
            return Err(Error::InvalidSetting(format!(
                "drawing size {width}x{height}: each side must be 1 to {MAX_SIZE} pixels"
            )));
        }
        shot.validate()?;
        let world = shot.world;
        let start = Instant::now();
        let rows = shot.view.clip_rows(glam::DMat4::IDENTITY);
        let frame = occlusion::Frame::new(world, rows, shot.view.eye(), shot.size);
        let occluders = start.elapsed();
        let start = Instant::now();
        let mut paths = lines::paths(&frame, shot.style);
        paths.sort_by_key(|p| p.class);
        if paths.is_empty() {
            return Err(if world.objects.is_empty() {
                Error::InvalidScene("nothing to draw: the scene has no objects".into())
            } else {
                Error::InvalidSetting(format!(
                    "nothing to draw: no line of the scene's {} objects ({} triangles) lies \
                     in the view with this style",
                    world.objects.len(),
                    world.triangle_count()
                ))
            });
        }
        Ok(Drawing {
            size: shot.size,
            background: shot.style.background,
            paths,
            timings: DrawingTimings {
                occluders,
                lines: start.elapsed(),
            },
        })
    }

    /// The paths of one class.
    pub fn of_class(&self, class: PathClass) -> impl Iterator<Item = &Path> + '_ {
        self.paths.iter().filter(move |p| p.class == class)
    }

    /// The drawing as an SVG document: a group per class, one `<path>` per path, with
    /// `stroke-dasharray` and `stroke-dashoffset` giving each pattern's phase.
    pub fn to_svg(&self, page: &Page) -> String {
        svg::write(self, page)
    }

    /// The drawing as a one-page PDF, vector paths with their dash phases.
    pub fn to_pdf(&self, page: &Page) -> Vec<u8> {
        pdf::write(self, page)
    }

    /// The drawing as a DXF (R12) file: a layer per class, a polyline per path, a linetype
    /// per pattern and phase (a linetype has no phase of its own: its elements are rotated
    /// to start where the path's pattern does).
    pub fn to_dxf(&self, page: &Page) -> String {
        dxf::write(self, page)
    }

    /// Writes the drawing to `path` as SVG, PDF or DXF, by its extension.
    pub fn write(&self, path: &FilePath, page: &Page) -> Result<()> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let bytes = match ext.as_deref() {
            Some("svg") => self.to_svg(page).into_bytes(),
            Some("pdf") => self.to_pdf(page),
            Some("dxf") => self.to_dxf(page).into_bytes(),
            _ => {
                return Err(Error::InvalidSetting(format!(
                    "{}: a drawing is written as .svg, .pdf or .dxf",
                    path.display()
                )))
            }
        };
        std::fs::write(path, bytes).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// The unit a page is measured in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PageUnit {
    /// CSS pixels (1/96 inch).
    Pixel,
    /// Millimetres.
    Millimetre,
}

/// The page a drawing is written on: its unit, and how many of them one pixel of the view
/// is. Coordinates, widths and patterns all scale by it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Page {
    /// The page's unit.
    pub unit: PageUnit,
    /// Page units per pixel of the view.
    pub per_pixel: f64,
}

impl Page {
    /// One page pixel per pixel of the view.
    pub fn pixels() -> Page {
        Page {
            unit: PageUnit::Pixel,
            per_pixel: 1.0,
        }
    }

    /// An orthographic `view`'s drawing to scale 1:`scale` (1:10 draws 10 mm of the world
    /// as 1 mm), for an image of `size` pixels and a world whose unit is `unit_mm`
    /// millimetres.
    pub fn to_scale(view: &View, size: (u32, u32), unit_mm: f64, scale: f64) -> Result<Page> {
        if !view.is_orthographic() {
            return Err(Error::InvalidSetting(
                "a drawing to scale needs an orthographic view: a perspective one has no \
                 single scale"
                    .into(),
            ));
        }
        if !(scale > 0.0 && scale.is_finite() && unit_mm > 0.0 && unit_mm.is_finite()) {
            return Err(Error::InvalidSetting(format!(
                "scale 1:{scale} with a unit of {unit_mm} mm: both must be finite and > 0"
            )));
        }
        // Pixels per world unit along x and y: the projection's scale times half the image.
        let m = view.view_projection();
        let per_unit =
            |row: usize, pixels: u32| m.row(row).truncate().length() * 0.5 * f64::from(pixels);
        let (x, y) = (per_unit(0, size.0), per_unit(1, size.1));
        if !(x > 0.0 && (x / y - 1.0).abs() < 1e-6) {
            return Err(Error::InvalidSetting(format!(
                "the view draws {x} pixels per unit across and {y} up: a drawing to scale \
                 needs one scale"
            )));
        }
        Ok(Page {
            unit: PageUnit::Millimetre,
            per_pixel: unit_mm / scale / x,
        })
    }

    /// The page's width and height in its unit, for a drawing of `size` pixels.
    pub fn extent(&self, size: (u32, u32)) -> DVec2 {
        DVec2::new(f64::from(size.0), f64::from(size.1)) * self.per_pixel
    }
}
