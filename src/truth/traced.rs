//! The traced lines for the ground truth, in f64: the definition `shaders/trace.wgsl`
//! draws (outlines, and the hidden, listed, cut and intersection lines below).
//!
//! An outline edge is a boundary edge (no neighbour, or more than one) or a silhouette
//! ([`edge_math::is_silhouette`]) of an object that draws its outline, among the edges its
//! mesh allows as outlines. Pixel p lies at distance d from an outline when d is the distance
//! from p's centre to the *visible part* of an outline edge's projection: the part in front
//! of the near plane and not beyond the far one, within the line's reach of the image (an
//! edge just outside the image draws its line inside), and not hidden by another surface
//! ([`edge_math::nearer`]). Each pixel keeps the line that colours it most
//! ([`style::line_key`](crate::style::line_key)): the common profile at the object's width,
//! times the depth fade of that nearest visible point.
//!
//! The same map carries the drawn edges of large patches ([`Patches::splat`]) of objects
//! that draw their edges, by the same definition: the pixels of a large patch near an
//! undrawn edge find their lines here.
//!
//! The drawn edges of an object whose edges are patterned, or cut by section planes, are all
//! here, their visible parts drawn (in dashes; the per-pixel own-edge distance leaves them),
//! and every line ends where a section plane cuts it. A pattern of drawn edges or of their
//! hidden parts runs along each chain of drawn edges (`src/mesh/chains.rs`): an edge's
//! dashes start where the chain's projected length before it leaves the pattern.
//!
//! With intersection lines on ([`Style::intersection_lines`](crate::Style::intersection_lines)),
//! the segments along which an object's crossing triangles meet
//! ([`Mesh::intersections`](crate::Mesh::intersections)), and those along which the
//! triangles of two objects cross (found in world coordinates over all their triangles, for
//! every two objects whose placed bounds meet), are drawn where visible, hidden by any surface
//! but the two they lie on; a line between two objects is the lower object's.
//!
//! Visibility along an edge is found by casting a ray through points every 1/8 pixel of its
//! projection and bisecting each change to 2⁻³⁰ of the edge. The GPU pass does the same at
//! 1/4 pixel, testing each point against the triangles rasterized around it instead of a ray
//! cast; tests/ground_truth.rs holds the two within 0.1 px.

// `!(a <= b)` is deliberate: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::edge_math;
use crate::mesh::adjacency::NO_NEIGHBOUR;
use crate::mesh::patches::Patches;
use crate::style::{depth_fade, line_intensity, line_key, line_reach};
use crate::truth::rays::{HostMap, Line, ObjectStyle, RayCaster, Rays};
pub use crate::world::outline_edges;
use crate::world::{keep_positive, Shot};
use glam::{DVec2, DVec3, DVec4};
use rayon::prelude::*;
use std::collections::HashMap;

/// Visibility samples per pixel of projected edge length.
const SAMPLES_PER_PIXEL: f64 = 8.0;
/// Bisection steps that place each change of visibility along an edge.
const BISECTIONS: u32 = 30;

/// Per pixel, the outline line that colours it most, if any is within reach, and the hidden
/// line ([`Style::hidden`](crate::Style::hidden)) likewise.
pub struct TracedMap {
    /// Pixels, row-major.
    pub line: Vec<Option<Line>>,
    /// Pixels, row-major; all `None` without hidden lines.
    pub hidden: Vec<Option<Line>>,
}

/// A stretch of an edge on screen, visible or a dash of a hidden part: pixel coordinates at
/// both ends, and there 1/w, near/w and view depth / w (affine along the stretch).
#[derive(Clone, Copy, Debug)]
struct Stretch {
    from: DVec2,
    to: DVec2,
    inv_w: [f64; 2],
    near_w: [f64; 2],
    depth_w: [f64; 2],
    object: u32,
    width: f64,
    /// An outline's line, not an edge's (hidden lines: false).
    outline: bool,
    /// A section's cut line.
    cut: bool,
    /// An intersection line.
    intersection: bool,
    /// A hidden line drawn over the host's surface ([`HiddenLines::behind_host`]).
    ///
    /// [`HiddenLines::behind_host`]: crate::HiddenLines::behind_host
    over_host: bool,
}

/// What a listed edge draws: its visible parts (an outline, or a drawn edge of a large
/// patch), its hidden parts (a drawn edge or an outline, with hidden lines on); whether its
/// visible line is an outline's (its class, colour and width), else an edge's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Draw {
    visible: bool,
    hidden: bool,
    outline: bool,
    /// A cut line: where section plane k meets the triangle.
    cut: Option<usize>,
    /// An intersection line: crossing k of the mesh ([`crate::Mesh::intersections`]).
    crossing: Option<usize>,
    /// How the eye's ray reaches it, in a frame with section planes ([`capped`]).
    cap: Cap,
}

/// In a frame with section planes, how the eye's ray reaches a line where no other surface
/// tells (see [`RayVisibility::class`]): not asked (no planes, or a cut line), from outside the
/// solid or from inside it (from behind the section face).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Cap {
    None,
    Outside,
    Inside,
}

/// The traced map of `caster`'s world for `shot`, seen along `rays`; `masks` are each
/// mesh's drawn edges.
pub(crate) fn traced_map(
    caster: &RayCaster<'_>,
    rays: &Rays,
    shot: &Shot<'_>,
    styles: &[ObjectStyle],
    (patches, masks): (&[Patches], &[Vec<u8>]),
    host: Option<&HostMap>,
) -> TracedMap {
    let world = caster.world();
    let view = RayVisibility {
        caster,
        rays,
        fade_row: shot.view.view_depth_row(),
        host,
        eye: shot.view.eye(),
    };
    let view = &view;
    let (visible, hidden_stretches): (Vec<Vec<Stretch>>, Vec<Vec<Stretch>>) = world
        .objects
        .iter()
        .enumerate()
        .filter(|(o, _)| {
            let s = &styles[*o];
            s.outlines || s.edges || s.sectioned || shot.style.intersection_lines
        })
        .flat_map(|(o, _)| {
            let lines = listed_lines(caster, shot, o, &styles[o], (patches, masks));
            view.object_stretches(shot, o, &styles[o], masks, lines)
        })
        .unzip();
    let between = if shot.style.intersection_lines {
        view.lines_between_objects(f64::from(shot.style.intersection_width()))
    } else {
        Vec::new()
    };
    let fade = shot.style.fade_range().map(f64::from);
    let visible: Vec<Stretch> = visible.into_iter().flatten().chain(between).collect();
    let line = splat(&visible, shot.size, fade, host);
    let stretches: Vec<Stretch> = hidden_stretches.into_iter().flatten().collect();
    let hidden = splat(&stretches, shot.size, fade, host);
    TracedMap { line, hidden }
}

/// Every line of object `o` (style `style`) the map draws, each once, with all that its
/// entries ask of it: its outline edges, the drawn edges of its large patches, its drawn
/// edges where they are listed (patterned, cut, crossed) or have hidden parts, its cut
/// lines and its own intersection lines; `masks` are each mesh's drawn edges.
fn listed_lines(
    caster: &RayCaster<'_>,
    shot: &Shot<'_>,
    o: usize,
    style: &ObjectStyle,
    (patches, masks): (&[Patches], &[Vec<u8>]),
) -> Vec<((u32, u32), Draw)> {
    let world = caster.world();
    let ObjectLines {
        object,
        mesh,
        first,
        hidden,
        hidden_edges,
        listed,
    } = ObjectLines::new(caster, o, style);
    let tris = mesh.triangles();
    let neighbours = mesh.edge_neighbours();
    let eye = shot.view.eye();
    let local = edge_math::local_eye(object.transform, eye);
    let mut edges: Vec<((u32, u32), Draw)> = Vec::new();
    if style.outlines {
        let outline = Draw {
            visible: true,
            hidden: hidden.is_some(),
            outline: true,
            cut: None,
            crossing: None,
            cap: Cap::None,
        };
        edges.extend(outline_edges(mesh, local).into_iter().map(|e| (e, outline)));
    }
    if style.edges && !listed {
        let splat = &patches[object.mesh].splat;
        let draw = Draw {
            visible: true,
            hidden: hidden_edges,
            outline: false,
            cut: None,
            crossing: None,
            cap: Cap::None,
        };
        edges.extend(splat.iter().enumerate().flat_map(|(t, &bits)| {
            (0..3u32)
                .filter(move |i| bits & (1 << i) != 0)
                .map(move |i| ((t as u32, i), draw))
        }));
    }
    if style.edges && (hidden_edges || listed) {
        // Every drawn edge has hidden parts to find, or visible ones to draw in
        // their pattern; a shared one is drawn by the lower id only.
        let mask = &masks[object.mesh];
        let draw = Draw {
            visible: listed,
            hidden: hidden_edges,
            outline: false,
            cut: None,
            crossing: None,
            cap: Cap::None,
        };
        edges.extend((0..tris.len() as u32).flat_map(|t| {
            (0..3u32)
                .filter(move |&i| {
                    let n = neighbours[t as usize][i as usize];
                    mask[t as usize] & (1 << i) != 0 && (n == NO_NEIGHBOUR || t < n)
                })
                .map(move |i| ((t, i), draw))
        }));
    }
    // Cut lines, each (triangle, 3 + plane), where a section plane crosses a triangle.
    let sections = &world.sections;
    if !sections.is_empty() {
        edges.extend((0..tris.len() as u32).flat_map(|t| {
            let corners = caster.corners(first + t);
            (0..sections.len())
                .filter(move |&k| sections[k].cut_triangle(corners).is_some())
                .map(move |k| {
                    let draw = Draw {
                        visible: true,
                        hidden: false,
                        outline: false,
                        cut: Some(k),
                        crossing: None,
                        cap: Cap::None,
                    };
                    ((t, 3 + k as u32), draw)
                })
        }));
    }
    // Intersection lines, each (lower triangle, 3 + MAX_SECTIONS + crossing).
    if shot.style.intersection_lines {
        let first_key = 3 + crate::scene::MAX_SECTIONS as u32;
        edges.extend(mesh.intersections().iter().enumerate().map(|(k, c)| {
            let draw = Draw {
                visible: true,
                hidden: false,
                outline: false,
                cut: None,
                crossing: Some(k),
                cap: Cap::None,
            };
            ((c.t, first_key + k as u32), draw)
        }));
    }
    // One entry per edge, drawing all that any of its entries asks.
    edges.sort_unstable();
    let mut merged: Vec<((u32, u32), Draw)> = Vec::with_capacity(edges.len());
    for (e, d) in edges {
        match merged.last_mut() {
            Some((last, m)) if *last == e => {
                m.visible |= d.visible;
                m.hidden |= d.hidden;
                m.outline |= d.outline;
            }
            _ => merged.push((e, d)),
        }
    }
    merged
}

/// What [`listed_lines`] and [`RayVisibility::object_stretches`] read of object `o`: the
/// object, its mesh, its first global triangle id, and what its style asks of the lines.
struct ObjectLines<'a> {
    object: &'a crate::world::Object,
    mesh: &'a crate::Mesh,
    first: u32,
    hidden: Option<crate::HiddenLines>,
    /// Its drawn edges' hidden parts are drawn.
    hidden_edges: bool,
    /// Its drawn edges are all listed ([`ObjectStyle::listed_edges`]).
    listed: bool,
}

impl<'a> ObjectLines<'a> {
    fn new(caster: &'a RayCaster<'a>, o: usize, style: &ObjectStyle) -> ObjectLines<'a> {
        let world = caster.world();
        let object = &world.objects[o];
        ObjectLines {
            object,
            mesh: &world.meshes[object.mesh].mesh,
            first: caster.first_ids()[o],
            hidden: style.hidden,
            hidden_edges: style.hidden.is_some_and(|h| h.edges),
            listed: style.listed_edges(),
        }
    }
}

impl RayVisibility<'_> {
    /// The visible and hidden stretches of each of object `o`'s `lines` ([`listed_lines`]),
    /// its patterns anchored along its chains of drawn edges (`masks`: each mesh's).
    fn object_stretches(
        &self,
        shot: &Shot<'_>,
        o: usize,
        style: &ObjectStyle,
        masks: &[Vec<u8>],
        merged: Vec<((u32, u32), Draw)>,
    ) -> Vec<(Vec<Stretch>, Vec<Stretch>)> {
        let (view, caster) = (self, self.caster);
        let world = caster.world();
        let ObjectLines {
            object,
            mesh,
            first,
            hidden,
            hidden_edges,
            listed,
        } = ObjectLines::new(caster, o, style);
        let tris = mesh.triangles();
        let neighbours = mesh.edge_neighbours();
        let eye = self.eye;
        let sections = &world.sections;
        let widths = (
            style.width,
            style.outline_width,
            style.section_width,
            f64::from(shot.style.intersection_width()),
        );
        let patterns = (style.edge_pattern, style.outline_pattern);
        // The periods of the patterns that run along chains (0 where none does): the
        // hidden parts' of drawn edges, the drawn edges'.
        let hidden_period = hidden
            .filter(|_| hidden_edges)
            .map_or(0.0, |h| f64::from(h.pattern.dash_period()[1]));
        let periods = [hidden_period, if listed { patterns.0[1] } else { 0.0 }];
        // Welded vertices and the chains' anchors, where a pattern runs along them.
        let chained = (style.edges && periods.iter().any(|&p| p > 0.0)).then(|| {
            let weld = crate::mesh::adjacency::weld_by_position(mesh.positions());
            let anchors = view.chain_anchors(mesh, &weld, first, &masks[object.mesh], periods);
            (weld, anchors)
        });
        let chained = chained.as_ref();
        // The outline chains, where the outline's hidden parts are patterned.
        // The outline's patterns' periods, the hidden line's and the visible line's (0 for
        // none).
        let outline_periods = if style.outlines {
            [
                hidden.map_or(0.0, |h| f64::from(h.pattern.dash_period()[1])),
                patterns.1[1],
            ]
        } else {
            [0.0; 2]
        };
        let on_static_chain = |t: u32, i: u32| {
            chained.is_some_and(|(weld, anchors)| {
                let corners = tris[t as usize];
                let (a, b) = (corners[i as usize], corners[(i as usize + 1) % 3]);
                let (wa, wb) = (weld[a as usize], weld[b as usize]);
                periods[0] > 0.0 && anchors.contains_key(&(wa.min(wb), wa.max(wb)))
            })
        };
        let outline_anchors = outline_periods.iter().any(|&p| p > 0.0).then(|| {
            let edges: Vec<(u32, u32)> = merged
                .iter()
                .filter(|(_, d)| d.outline && d.cut.is_none() && d.crossing.is_none())
                .map(|&(e, _)| e)
                .filter(|&(t, i)| !on_static_chain(t, i))
                .collect();
            let local = edge_math::local_eye(object.transform, shot.view.eye());
            view.outline_chain_anchors(mesh, first, &edges, local, outline_periods)
        });
        let outline_anchors = outline_anchors.as_ref();
        merged
            .into_par_iter()
            .map(move |((t, i), draw)| {
                if let Some(k) = draw.crossing {
                    let c = mesh.intersections()[k];
                    let ends = c.ends.map(|p| object.transform.transform_point3(p));
                    let lines = (([0.0; 2], (0.0, true)), (0.0, true));
                    return view.stretches(
                        (first, first),
                        (c.t, c.u, (ends[0], ends[1])),
                        (o as u32, widths),
                        draw,
                        (lines, None),
                    );
                }
                if let Some(k) = draw.cut {
                    let corners = caster.corners(first + t);
                    let ends = world.sections[k].cut_triangle(corners).unwrap_or_default();
                    let lines = (([0.0; 2], (0.0, true)), (0.0, true));
                    let edge = (t, NO_NEIGHBOUR, ends);
                    return view.stretches(
                        (first, first),
                        edge,
                        (o as u32, widths),
                        draw,
                        (lines, None),
                    );
                }
                let n = neighbours[t as usize][i as usize];
                let corners = tris[t as usize];
                let p = mesh.positions();
                let (a, b) = (corners[i as usize], corners[(i as usize + 1) % 3]);
                let world_corners = caster.corners(first + t);
                let ends = (
                    world_corners[i as usize],
                    world_corners[(i as usize + 1) % 3],
                );
                let draw = Draw {
                    cap: if sections.is_empty() {
                        Cap::None
                    } else {
                        capped(
                            caster,
                            (first + t, (n != NO_NEIGHBOUR).then(|| first + n)),
                            eye,
                        )
                    },
                    ..draw
                };
                let on_chain = chained.and_then(|(weld, anchors)| {
                    let (wa, wb) = (weld[a as usize], weld[b as usize]);
                    let &(positions, entry) = anchors.get(&(wa.min(wb), wa.max(wb)))?;
                    Some((positions, entry == wa))
                });
                // Where each pattern stands: along its chain where it runs along chains;
                // an outline's visible line, and any other edge, from the end that comes
                // first.
                let own = (0.0, comes_first(p[a as usize], p[b as usize]));
                let along = |k: usize| match on_chain {
                    Some((positions, forward)) if periods[k] > 0.0 => (positions[k], forward),
                    _ => own,
                };
                let mut visible = if draw.outline {
                    (patterns.1, own)
                } else {
                    (patterns.0, along(1))
                };
                let mut hidden_anchor = along(0);
                // An outline's patterns run along the outline chains.
                if draw.outline && !on_static_chain(t, i) {
                    if let Some(&(at, forward)) = outline_anchors.and_then(|a| a.get(&(t, i))) {
                        hidden_anchor = (at[0], forward);
                        visible.1 = (at[1], forward);
                    }
                }
                let lines = (visible, hidden_anchor);
                view.stretches(
                    (first, first),
                    (t, n, ends),
                    (o as u32, widths),
                    draw,
                    (lines, hidden),
                )
            })
            .collect::<Vec<_>>()
    }
}

// Whether one point comes before another in (x, y, z) order (in the mesh's own
// coordinates): the end of an edge that anchors its line pattern. `comes_first` in
// trace.wgsl compares the store's rebased coordinates (the same order, but where rebasing
// rounds two coordinates together).
use crate::mesh::chains::comes_first;

/// Per pixel, the stretch whose line colours it most (the greatest key), skipping lines that
/// `host` hides.
fn splat(
    stretches: &[Stretch],
    (width, height): (u32, u32),
    fade: [f64; 2],
    host: Option<&HostMap>,
) -> Vec<Option<Line>> {
    let mut map: Vec<Option<Line>> = vec![None; width as usize * height as usize];
    map.par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let cy = y as f64 + 0.5;
            for s in stretches {
                let reach = line_reach(s.width);
                if (s.from.y.min(s.to.y) - reach) > cy || (s.from.y.max(s.to.y) + reach) < cy {
                    continue;
                }
                let x0 = (s.from.x.min(s.to.x) - reach).floor().max(0.0) as usize;
                let x1 = ((s.from.x.max(s.to.x) + reach).ceil() as usize).min(width as usize);
                for (x, out) in row.iter_mut().enumerate().take(x1).skip(x0) {
                    let p = DVec2::new(x as f64 + 0.5, cy);
                    let (d, at) = nearest_on_segment(p, s.from, s.to);
                    if !(d < reach + edge_math::REACH_SLACK) {
                        continue;
                    }
                    let near_w = s.near_w[0] + (s.near_w[1] - s.near_w[0]) * at;
                    // The pixel shows the host, and its surface is in front of the line's point.
                    let host = host.filter(|_| !s.over_host);
                    if host.is_some_and(|h| h.hides_line((x, y), 1.0 - near_w, d)) {
                        continue;
                    }
                    let inv_w = s.inv_w[0] + (s.inv_w[1] - s.inv_w[0]) * at;
                    let depth = (s.depth_w[0] + (s.depth_w[1] - s.depth_w[0]) * at) / inv_w;
                    let intensity = line_intensity(d, s.width) * depth_fade(depth, fade);
                    let key = line_key(intensity, d);
                    let line = Line {
                        key,
                        distance: d,
                        intensity,
                        object: s.object,
                        outline: s.outline,
                        cut: s.cut,
                        intersection: s.intersection,
                    };
                    // The greatest key gives the distance and intensity; whose line it is
                    // (object and class) goes, as the GPU's owner word does, to the greatest
                    // (intensity level, class: intersection, outline, cut, edge), the
                    // greatest key among equals.
                    let owner = |l: &Line| (l.key >> 20, l.intersection, l.outline, l.cut);
                    *out = Some(match *out {
                        None => line,
                        Some(l) => {
                            let (keep, other) = if key > l.key { (line, l) } else { (l, line) };
                            if owner(&other) > owner(&keep) {
                                Line {
                                    object: other.object,
                                    outline: other.outline,
                                    cut: other.cut,
                                    intersection: other.intersection,
                                    ..keep
                                }
                            } else {
                                keep
                            }
                        }
                    });
                }
            }
        });
    map
}

/// Distance from `p` to the segment `a → b`, and the parameter of its nearest point.
pub fn nearest_on_segment(p: DVec2, a: DVec2, b: DVec2) -> (f64, f64) {
    let seg = b - a;
    let len2 = seg.length_squared();
    let at = if len2 > 0.0 {
        ((p - a).dot(seg) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.distance(a + seg * at), at)
}

/// The visibility of points of lines, by ray casts.
struct RayVisibility<'a> {
    caster: &'a RayCaster<'a>,
    rays: &'a Rays,
    fade_row: DVec4,
    /// The host's depth, if the host gave it.
    host: Option<&'a HostMap>,
    /// The eye, homogeneous world.
    eye: DVec4,
}

/// What a point of a line is: visible, hidden by a surface (or by the host, for hidden lines
/// drawn behind it), or neither drawn (the host hides it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Visible,
    Hidden,
    Neither,
}

impl RayVisibility<'_> {
    /// The visible stretches of the intersection lines between objects, `width` wide.
    fn lines_between_objects(&self, width: f64) -> Vec<Stretch> {
        use crate::mesh::crossings::{crossings_between, pair_tolerance};
        let world = self.caster.world();
        let placed: Vec<((DVec3, DVec3), glam::DMat4)> = world
            .objects
            .iter()
            .map(|o| (world.meshes[o.mesh].mesh.bounds_f64(), o.transform))
            .collect();
        let boxes: Vec<(DVec3, DVec3)> = placed
            .iter()
            .map(|&(bounds, t)| crate::scene::world_box(bounds, t))
            .collect();
        let firsts = self.caster.first_ids();
        let corners = |o: usize| {
            let count = world.meshes[world.objects[o].mesh].mesh.triangle_count() as u32;
            (0..count)
                .map(|t| self.caster.corners(firsts[o] + t))
                .collect::<Vec<_>>()
        };
        let draw = Draw {
            visible: true,
            hidden: false,
            outline: false,
            cut: None,
            // (Any index: only a mesh's own lines look theirs up.)
            crossing: Some(0),
            cap: Cap::None,
        };
        let lines = (([0.0; 2], (0.0, true)), (0.0, true));
        let widths = (0.0, 0.0, 0.0, width);
        crate::scene::crossing_pairs(&placed)
            .into_iter()
            .flat_map(|(a, b)| {
                let tolerance = pair_tolerance(boxes[a], boxes[b]);
                crossings_between(&corners(a), &corners(b), tolerance)
                    .into_par_iter()
                    .flat_map_iter(move |c| {
                        let ends = (c.ends[0], c.ends[1]);
                        self.stretches(
                            (firsts[a], firsts[b]),
                            (c.t, c.u, ends),
                            (a as u32, widths),
                            draw,
                            (lines, None),
                        )
                        .0
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// The part of the edge `a` → `b` (world coordinates) in front of the near plane, not
    /// beyond the far one and not behind a section plane, as parameters along it, and the
    /// projections of its ends.
    fn span(
        &self,
        a: DVec3,
        b: DVec3,
        skip: Option<usize>,
    ) -> Option<((f64, f64), Projected, Projected)> {
        let (ca, cb) = (self.rays.clip(a), self.rays.clip(b));
        let depth = self.rays.rows().depth;
        let (ha, hb) = (a.extend(1.0), b.extend(1.0));
        let mut s = (0.0, 1.0);
        keep_positive(&mut s, ca.z, cb.z);
        keep_positive(&mut s, depth.dot(ha), depth.dot(hb));
        // A cut line lies on its own plane (`skip`).
        for (k, plane) in self.caster.world().sections.iter().enumerate() {
            if Some(k) != skip {
                keep_positive(&mut s, plane.side(a), plane.side(b));
            }
        }
        if !(s.0 <= s.1) {
            return None;
        }
        let at = |k: f64| {
            let c = ca.lerp(cb, k);
            let f = self.fade_row.dot(ha.lerp(hb, k));
            self.project(c, f)
        };
        Some((s, at(s.0), at(s.1)))
    }

    /// Where the patterns (of periods `periods`; 0 for none) stand on each chained drawn edge
    /// (`mask`) of `mesh`, the object whose first global id is `first`: by the edge's welded
    /// ends (lower, higher), each pattern's position where the chain enters it (modulo its
    /// period) and the welded vertex it enters at. The position is the summed length of the
    /// projections ([`Self::span`]) of the chain's edges before it.
    fn chain_anchors(
        &self,
        mesh: &crate::Mesh,
        weld: &[u32],
        first: u32,
        mask: &[u8],
        periods: [f64; 2],
    ) -> HashMap<(u32, u32), ([f64; 2], u32)> {
        let neighbours = mesh.edge_neighbours();
        let tris = mesh.triangles();
        let listed: Vec<(u32, u8)> = (0..tris.len())
            .flat_map(|t| (0..3u8).map(move |i| (t, i)))
            .filter(|&(t, i)| {
                let n = neighbours[t][usize::from(i)];
                mask[t] & (1 << i) != 0 && (n == NO_NEIGHBOUR || (t as u32) < n)
            })
            .map(|(t, i)| (t as u32, i))
            .collect();
        let chains = crate::mesh::chains::chains(mesh.positions(), weld, tris, &listed);
        let mut out = HashMap::new();
        for chain in chains.iter().filter(|c| c.len() > 1) {
            let mut position = [0.0; 2];
            for e in chain {
                let i = usize::from(e.i);
                let (a, b) = (tris[e.t as usize][i], tris[e.t as usize][(i + 1) % 3]);
                let (wa, wb) = (weld[a as usize], weld[b as usize]);
                let entry = if e.forward { wa } else { wb };
                out.insert((wa.min(wb), wa.max(wb)), (position, entry));
                self.pass_edge(first + e.t, i, &mut position, periods);
            }
        }
        out
    }

    /// The patterns' positions `position` (of periods `periods`; 0 for none) carried past
    /// edge `i` of the triangle of global id `t`: on by the length of its projection
    /// ([`Self::span`]), modulo each period.
    fn pass_edge(&self, t: u32, i: usize, position: &mut [f64; 2], periods: [f64; 2]) {
        let corners = self.caster.corners(t);
        if let Some((_, p0, p1)) = self.span(corners[i], corners[(i + 1) % 3], None) {
            let length = p0.xy.distance(p1.xy);
            for (s, &period) in position.iter_mut().zip(&periods) {
                *s = if period > 0.0 {
                    (*s + length).rem_euclid(period)
                } else {
                    0.0
                };
            }
        }
    }

    /// Where the outline's patterns (of periods `periods`, the hidden line's and the visible
    /// line's; 0 for none) stand on each outline edge `(t, i)` in `edges` of `mesh` (the
    /// object whose first global id is `first`, its eye `local` in its own coordinates), run
    /// along the outline chains ([`outline_chains`](crate::world::outline_chains)): each
    /// pattern's position where the chain enters the edge (the summed projected lengths of
    /// the chain's edges before it, modulo its period), and whether it runs from corner `i`.
    fn outline_chain_anchors(
        &self,
        mesh: &crate::Mesh,
        first: u32,
        edges: &[(u32, u32)],
        local: DVec4,
        periods: [f64; 2],
    ) -> HashMap<(u32, u32), ([f64; 2], bool)> {
        let mut out = HashMap::new();
        for chain in crate::world::outline_chains(mesh, edges, local) {
            let mut position = [0.0; 2];
            for e in chain {
                let (t, i) = (e.t, u32::from(e.i));
                out.insert((t, i), (position, e.forward));
                self.pass_edge(first + t, i as usize, &mut position, periods);
            }
        }
        out
    }

    /// The dashes of the visible stretches (where `draw.visible`, in the visible pattern
    /// (dash, period)) and of the hidden stretches (where `draw.hidden`, in `hidden`'s pattern
    /// and width) of edge `i` of triangle `t` (neighbour `n`) of the object whose first
    /// global id is `first` (`first_n`: of `n`'s object, another where an intersection line
    /// lies on two objects). Each pattern stands at its anchor's position at corner `i` when
    /// the anchor's flag is set, else at `i + 1` (or where a clip plane cuts the edge short
    /// of that end), and runs towards the other end.
    #[allow(clippy::type_complexity)]
    fn stretches(
        &self,
        (first, first_n): (u32, u32),
        (t, n, (a, b)): (u32, u32, (DVec3, DVec3)),
        (object, (edge_width, outline_width, section_width, intersection_width)): (
            u32,
            (f64, f64, f64, f64),
        ),
        draw: Draw,
        (((visible_pattern, visible_anchor), hidden_anchor), hidden): (
            (([f64; 2], (f64, bool)), (f64, bool)),
            Option<crate::HiddenLines>,
        ),
    ) -> (Vec<Stretch>, Vec<Stretch>) {
        let none = (Vec::new(), Vec::new());
        // In front of the near plane, not beyond the far plane, not cut away.
        let Some((_, p0, p1)) = self.span(a, b, draw.cut) else {
            return none;
        };
        // Within reach of the image: an edge just outside it still draws its line inside.
        let size = self.rays.size();
        let width = if draw.cut.is_some() {
            section_width
        } else if draw.crossing.is_some() {
            intersection_width
        } else if draw.outline {
            outline_width
        } else {
            edge_width
        };
        let hidden_width = hidden.filter(|_| draw.hidden).map(|h| f64::from(h.width));
        let reach = line_reach(width).max(hidden_width.map_or(0.0, line_reach));
        let d = p1.xy - p0.xy;
        let mut u = (0.0, 1.0);
        keep_between(&mut u, p0.xy.x, d.x, (-reach, size.x + reach));
        keep_between(&mut u, p0.xy.y, d.y, (-reach, size.y + reach));
        if !(u.0 <= u.1) {
            return none;
        }
        let point = |k: f64| p0.lerp(&p1, k);
        let behind_host = hidden.is_some_and(|h| draw.hidden && h.behind_host);
        // Where an edge's end is a vertex, the triangles round it meet the edge there only to
        // rounding: its class is that of the point END_INSET pixels along.
        let inset = (edge_math::END_INSET / d.length()).min(0.5);
        let class = |k: f64| {
            let q = point(k.clamp(inset, 1.0 - inset));
            let w = 1.0 / q.inv_w;
            self.class(
                q.xy,
                (q.near_w * w, w),
                (first, first_n),
                (t, n),
                behind_host,
                draw.cap,
            )
        };

        // Runs of one class, as (from, to, class) in parameters of p0 → p1.
        let length = d.length() * (u.1 - u.0);
        let steps = (length * SAMPLES_PER_PIXEL).ceil().clamp(1.0, 65536.0) as usize;
        let at = |j: usize| u.0 + (u.1 - u.0) * j as f64 / steps as f64;
        let mut runs = Vec::new();
        let mut start = u.0;
        let mut last = (u.0, class(u.0));
        for j in 1..=steps {
            let k = at(j);
            let now = class(k);
            if now != last.1 {
                // Bisect the change between last.0 and k.
                let (mut lo, mut hi) = (last.0, k);
                for _ in 0..BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    if class(mid) == last.1 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                runs.push((start, lo, last.1));
                start = hi;
            }
            last = (k, now);
        }
        runs.push((start, u.1, last.1));

        let (cut, intersection) = (draw.cut.is_some(), draw.crossing.is_some());
        let stretch = |(k0, k1): (f64, f64), width: f64, (outline, over_host): (bool, bool)| {
            let (q0, q1) = (point(k0), point(k1));
            Stretch {
                from: q0.xy,
                to: q1.xy,
                inv_w: [q0.inv_w, q1.inv_w],
                near_w: [q0.near_w, q1.near_w],
                depth_w: [q0.depth_w, q1.depth_w],
                object,
                width,
                outline,
                cut,
                intersection,
                over_host,
            }
        };
        // The patterns' positions at parameter k: pixels along the projection from the
        // anchored end (or where a clip plane cuts the edge short of it).
        let full = d.length();
        let [dash, period] = visible_pattern;
        let visible = runs
            .iter()
            .filter(|r| draw.visible && r.2 == Class::Visible)
            .flat_map(|&(k0, k1, _)| dashes((k0, k1), full, visible_anchor, (dash, period)))
            .map(|run| stretch(run, width, (draw.outline, false)))
            .collect();
        let Some(h) = hidden.filter(|_| draw.hidden) else {
            return (visible, Vec::new());
        };
        let [dash, period] = h.pattern.dash_period().map(f64::from);
        let hidden = runs
            .iter()
            .filter(|r| r.2 == Class::Hidden)
            .flat_map(|&(k0, k1, _)| dashes((k0, k1), full, hidden_anchor, (dash, period)))
            .map(|run| stretch(run, f64::from(h.width), (false, h.behind_host)))
            .collect();
        (visible, hidden)
    }

    /// Where a clip-space point with view depth `depth` lands: pixel coordinates, and 1/w,
    /// near/w and depth/w, which are affine along a screen segment.
    fn project(&self, c: DVec4, depth: f64) -> Projected {
        let inv_w = 1.0 / c.w;
        let ndc = DVec2::new(c.x, c.y) * inv_w;
        let xy = DVec2::new(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * self.rays.size();
        Projected {
            xy,
            inv_w,
            near_w: c.z * inv_w,
            depth_w: depth * inv_w,
        }
    }

    /// What the edge's point at screen point `x` (near row and w) is: where
    /// [`HostMap::hides_point`] says so hidden by the host (`behind_host`: counted as hidden,
    /// else neither drawn), hidden by a triangle other than `t` and `n` (global ids `first + t`
    /// and `first_n + n`) that covers `x` nearer than that point, else visible (twin of `class_at`
    /// in trace.wgsl).
    ///
    /// In a frame with section planes (`cap` not [`Cap::None`]) a point that the eye's ray
    /// reaches from inside a cut solid lies behind its section face, and is hidden too: where
    /// the nearest other surface in front of it (within [`edge_math::HIDDEN_MARGIN`]) faces
    /// away, the ray came out of the solid through it; where it faces the eye, the ray went
    /// in there; where none is nearer by [`edge_math::CAP_MARGIN`], `cap` tells.
    fn class(
        &self,
        x: DVec2,
        (near, w): (f64, f64),
        (first, first_n): (u32, u32),
        (t, n): (u32, u32),
        behind_host: bool,
        cap: Cap,
    ) -> Class {
        if self.host.is_some_and(|h| h.hides_point(x, 1.0 - near / w)) {
            return if behind_host {
                Class::Hidden
            } else {
                Class::Neither
            };
        }
        let (from, to) = self.rays.segment(x);
        let own = [
            first + t,
            if n == NO_NEIGHBOUR {
                u32::MAX
            } else {
                first_n + n
            },
        ];
        let front = self.caster.cast_past(from, to, own).and_then(|hit| {
            let c = self.rays.clip(hit.point);
            edge_math::nearer_by(c.z, near, w, edge_math::CAP_MARGIN).then_some((hit, c))
        });
        match front {
            Some((_, c)) if edge_math::nearer(c.z, near, w) => Class::Hidden,
            _ if cap == Cap::None => Class::Visible,
            Some((hit, _)) if self.caster.faces_away(hit.id, hit.point, self.eye) => Class::Hidden,
            Some(_) => Class::Visible,
            None if cap == Cap::Inside => Class::Hidden,
            None => Class::Visible,
        }
    }
}

/// In a frame with section planes, back faces stand for the section face of a cut solid,
/// and a line point that the eye's ray reaches from inside the solid lies behind that face
/// (see [`RayVisibility::class`]). Where no other surface lies just in front of the point, the
/// line's own triangles tell (twin of `capped` in trace.wgsl): the ray reaches from inside
/// a line between two back faces (global triangle `t` and its neighbour `n`), a back face's
/// boundary (`n` is `None`), and a silhouette where the surface folds inwards (concave);
/// facing by [`RayCaster::faces_away`], from the eye `eye` (homogeneous world).
fn capped(caster: &RayCaster<'_>, (t, n): (u32, Option<u32>), eye: DVec4) -> Cap {
    let away = |id: u32| caster.faces_away(id, caster.corners(id)[0], eye);
    let own = (caster.corners(t), caster.outward(t), away(t));
    let beyond = n.map(|n| (caster.corners(n), away(n)));
    if crate::world::seen_from_inside(own, beyond) {
        Cap::Inside
    } else {
        Cap::Outside
    }
}

/// The dashes of the pattern (dash, period; period 0 for solid) within the run `(k0, k1)` of
/// an edge's parameter, where the whole (clipped) edge is `full` pixels long on screen and
/// the pattern stands at `start` at parameter 0 (`a_first`) or 1 and runs towards the other
/// end. Dashes are the cores `[j·period, j·period + dash]` of pattern position, for every
/// integer j; a dot is a dash of no length. A dash within [`edge_math::DASH_SLACK`] of the
/// run is drawn from the run's nearest point.
fn dashes(
    (k0, k1): (f64, f64),
    full: f64,
    (start, a_first): (f64, bool),
    (dash, period): (f64, f64),
) -> Vec<(f64, f64)> {
    if !(period > 0.0) || !(full > 0.0) {
        return vec![(k0, k1)];
    }
    let position = |k: f64| start + if a_first { k * full } else { (1.0 - k) * full };
    let parameter = |s: f64| {
        let s = s - start;
        if a_first {
            s / full
        } else {
            1.0 - s / full
        }
    };
    let (s0, s1) = {
        let (a, b) = (position(k0), position(k1));
        (a.min(b), a.max(b))
    };
    let mut out = Vec::new();
    let slack = edge_math::DASH_SLACK;
    let mut j = (s0 / period).floor() - 1.0;
    while j * period <= s1 + slack {
        if j * period + dash >= s0 - slack {
            // Clamped into the run: a dash just beyond it is drawn from its nearest point.
            let from = (j * period).clamp(s0, s1);
            let to = (j * period + dash).clamp(s0, s1);
            let (ka, kb) = (parameter(from), parameter(to));
            out.push((ka.min(kb), ka.max(kb)));
        }
        j += 1.0;
    }
    out
}

/// A projected point of an edge: see [`RayVisibility::project`].
#[derive(Clone, Copy, Debug)]
struct Projected {
    xy: DVec2,
    inv_w: f64,
    near_w: f64,
    depth_w: f64,
}

impl Projected {
    fn lerp(&self, other: &Projected, k: f64) -> Projected {
        let mix = |a: f64, b: f64| a + (b - a) * k;
        Projected {
            xy: self.xy.lerp(other.xy, k),
            inv_w: mix(self.inv_w, other.inv_w),
            near_w: mix(self.near_w, other.near_w),
            depth_w: mix(self.depth_w, other.depth_w),
        }
    }
}

/// Narrows `range` to the parameters u where lo ≤ p0 + u·d ≤ hi.
fn keep_between(range: &mut (f64, f64), p0: f64, d: f64, (lo, hi): (f64, f64)) {
    if d == 0.0 {
        if !(lo..=hi).contains(&p0) {
            *range = (1.0, 0.0);
        }
        return;
    }
    let (u0, u1) = ((lo - p0) / d, (hi - p0) / d);
    range.0 = range.0.max(u0.min(u1));
    range.1 = range.1.min(u0.max(u1));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::World;
    use crate::{Camera, EdgeSelection, Mesh, Style};
    use glam::{DVec3, Vec3};

    fn camera(eye: Vec3) -> Camera {
        Camera {
            eye,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 60.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn a_quad_has_its_four_sides_as_outline() {
        let p = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let mesh = Mesh::new(p, None, vec![[0, 1, 2], [0, 2, 3]], None).unwrap();
        let edges = outline_edges(&mesh, DVec4::new(0.2, 0.1, 3.0, 1.0));
        assert_eq!(edges.len(), 4, "{edges:?}");
        // The diagonal (0, 2) is not: the two triangles lie on either side of it.
        assert!(!edges.contains(&(0, 2)));
    }

    /// The trace pass skips a triangle seen further from edge-on than its edges fold
    /// (`Mesh::outline_hints`, trace.wgsl); no skipped triangle may have a silhouette edge.
    #[test]
    fn outline_hints_never_skip_a_silhouette() {
        let meshes = [
            crate::mesh::Procedural::Sphere(2000).build().unwrap(),
            crate::mesh::Procedural::Torus(3000).build().unwrap(),
            crate::mesh::Procedural::Layers(3).build().unwrap(),
        ];
        let mut skipped = 0;
        let mut total = 0;
        for mesh in &meshes {
            let hints = mesh.outline_hints();
            let p = |v: u32| mesh.positions()[v as usize].as_dvec3();
            for eye in test_eyes() {
                let outline: std::collections::HashSet<u32> = outline_edges(mesh, eye.extend(1.0))
                    .into_iter()
                    .map(|(t, _)| t)
                    .collect();
                for (t, tri) in mesh.triangles().iter().enumerate() {
                    let [a, b, c] = tri.map(p);
                    let normal = (b - a).cross(c - a);
                    let farthest = [a, b, c]
                        .map(|v| (v - eye).length())
                        .into_iter()
                        .fold(0.0, f64::max);
                    let bound = crate::mesh::adjacency::fold_bound(hints[t] >> 1);
                    let skip = (a - eye).dot(normal).abs() > bound * farthest * normal.length();
                    let neighboured = mesh.edge_neighbours()[t].iter().any(|&n| n != NO_NEIGHBOUR);
                    total += 1;
                    if skip && hints[t] & 1 == 0 && neighboured {
                        skipped += 1;
                        // A silhouette is listed under its lower id; check both sides.
                        let has = outline.contains(&(t as u32))
                            || mesh.edge_neighbours()[t]
                                .iter()
                                .any(|&n| outline_edges_of(mesh, eye, n).contains(&(t as u32)));
                        assert!(!has, "triangle {t} skipped but has a silhouette, eye {eye}");
                    }
                }
            }
        }
        assert!(skipped * 2 > total, "only {skipped} of {total} skipped");
    }

    /// The trace pass skips a whole cluster when `clusters::may_fold` says none of its
    /// triangles can have an outline edge; no skipped cluster may hold one, whatever order
    /// the triangles come in (a sphere with its triangles shuffled clusters as well).
    #[test]
    fn skipped_clusters_hold_no_outline_edge() {
        use crate::mesh::clusters::{may_fold, CLUSTER_TRIANGLES};
        let sphere = crate::mesh::Procedural::Sphere(20000).build().unwrap();
        let mut shuffled = sphere.triangles().to_vec();
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        for i in (1..shuffled.len()).rev() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            shuffled.swap(i, (state % (i as u64 + 1)) as usize);
        }
        let shuffled = Mesh::new(sphere.positions().to_vec(), None, shuffled, None).unwrap();
        let meshes = [
            sphere,
            shuffled,
            crate::mesh::Procedural::Torus(20000).build().unwrap(),
            crate::mesh::Procedural::Grid(8000).build().unwrap(),
        ];
        for (m, mesh) in meshes.iter().enumerate() {
            let clusters = mesh.traced_clusters();
            let mut sorted = clusters.order.clone();
            sorted.sort_unstable();
            assert!(sorted.iter().copied().eq(0..mesh.triangle_count() as u32));
            assert_eq!(
                clusters.bounds.len(),
                mesh.triangle_count().div_ceil(CLUSTER_TRIANGLES)
            );
            let (mut skipped, mut total) = (0, 0);
            for eye in test_eyes() {
                let outline: std::collections::HashSet<u32> = outline_edges(mesh, eye.extend(1.0))
                    .into_iter()
                    .flat_map(|(t, i)| [t, mesh.edge_neighbours()[t as usize][i as usize]])
                    .collect();
                for (c, bounds) in clusters.bounds.iter().enumerate() {
                    total += 1;
                    if may_fold(bounds, eye.extend(1.0)) {
                        continue;
                    }
                    skipped += 1;
                    let ids = clusters.order.chunks(CLUSTER_TRIANGLES).nth(c).unwrap();
                    if let Some(t) = ids.iter().find(|t| outline.contains(t)) {
                        panic!("mesh {m}: cluster {c} skipped but triangle {t} has an outline edge, eye {eye}");
                    }
                }
            }
            // What keeps the pass cheap. The spheres skip about 60 %, the torus 30 % (its
            // tube curves faster) and the grid 50 % (clusters on its rim hold boundary edges,
            // always outlines, and the eyes near its plane see it edge-on).
            assert!(
                skipped * 4 > total,
                "mesh {m}: only {skipped} of {total} skipped"
            );
        }
    }

    /// Eyes all round the unit meshes, from just outside to five radii away.
    fn test_eyes() -> impl Iterator<Item = DVec3> {
        (0..40).map(|k| {
            let a = f64::from(k) * 0.7;
            DVec3::new(a.cos(), (0.37 * a).sin(), a.sin()) * (1.2 + 0.1 * f64::from(k))
        })
    }

    /// The neighbours of `n` across its silhouette edges.
    fn outline_edges_of(mesh: &Mesh, eye: DVec3, n: u32) -> Vec<u32> {
        if n == NO_NEIGHBOUR {
            return Vec::new();
        }
        let p = |v: u32| mesh.positions()[v as usize].as_dvec3();
        let tri = mesh.triangles()[n as usize];
        (0..3)
            .filter_map(|i| {
                let m = mesh.edge_neighbours()[n as usize][i];
                if m == NO_NEIGHBOUR {
                    return None;
                }
                let other = mesh.triangles()[m as usize].map(p);
                let d = (other[0] + other[1] + other[2]) / 3.0;
                edge_math::is_silhouette(
                    p(tri[i]),
                    p(tri[(i + 1) % 3]),
                    p(tri[(i + 2) % 3]),
                    d,
                    eye.extend(1.0),
                )
                .then_some(m)
            })
            .collect()
    }

    #[test]
    fn a_fold_is_a_silhouette_only_when_seen_folded() {
        // Two triangles hinged on the y axis, opening towards +z like a book.
        let p = vec![
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ];
        let mesh = Mesh::new(p, None, vec![[0, 1, 2], [1, 0, 3]], None).unwrap();
        let hinge = |eye: DVec3| outline_edges(&mesh, eye.extend(1.0)).contains(&(0, 0));
        // From in front of the book or behind its spine the pages show on either side of the
        // hinge.
        assert!(!hinge(DVec3::new(0.0, 0.0, 3.0)));
        assert!(!hinge(DVec3::new(0.0, 0.0, -3.0)));
        // From off to one side, past a page's plane, both fold onto one side of it.
        assert!(hinge(DVec3::new(5.0, 0.0, 0.5)));
    }

    /// The traced map of one mesh seen by `camera` at `size`.
    fn map_of(mesh: Mesh, camera: Camera, style: &Style, size: (u32, u32)) -> TracedMap {
        let world = World::single(mesh, EdgeSelection::All);
        let caster = RayCaster::new(&world);
        let shot = Shot {
            world: &world,
            view: camera.to_view(f64::from(size.0) / f64::from(size.1)),
            style,
            size,
        };
        let rays = Rays::new(&shot.view, size, &world).unwrap();
        let styles = ObjectStyle::of(&world, style);
        let mesh = &world.meshes[0].mesh;
        let masks = [mesh.edge_mask(EdgeSelection::All)];
        let patches = [Patches::new(
            mesh.edge_neighbours(),
            &masks[0],
            mesh.crossed_triangles(),
        )];
        traced_map(&caster, &rays, &shot, &styles, (&patches, &masks), None)
    }

    #[test]
    fn distances_reach_past_the_edge_over_the_background() {
        let p = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let mesh = Mesh::new(p, None, vec![[0, 1, 2], [0, 2, 3]], None).unwrap();
        let style = Style {
            line_width: 4.0,
            ..Style::default()
        };
        let cam = camera(Vec3::new(0.0, 0.0, 4.0));
        let map = map_of(mesh, cam, &style, (64, 64));
        // The right side of the quad projects to a vertical line; pixels on both sides of it
        // within reach have finite distances, symmetric about it.
        let vp = cam.view_projection(64, 64);
        let c = vp * DVec4::new(1.0, 0.0, 0.0, 1.0);
        let x_edge = 0.5 * (c.x / c.w + 1.0) * 64.0;
        let row = 32 * 64;
        for x in 0..64 {
            let line = map.line[row + x];
            let expect = (x as f64 + 0.5 - x_edge).abs();
            if expect < line_reach(4.0) - 1e-9 {
                let line = line.unwrap_or_else(|| panic!("x {x}: no line"));
                assert!(
                    (line.distance - expect).abs() < 1e-9,
                    "x {x}: {line:?} vs {expect}"
                );
                assert_eq!(line.intensity, line_intensity(expect, 4.0));
            } else if x as f64 > x_edge {
                assert!(line.is_none(), "x {x}: {line:?}");
            }
        }
    }

    #[test]
    fn hidden_stretches_are_not_drawn() {
        // A far quad's right side, half hidden behind a near quad covering y < 0.
        let p = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(-2.0, -2.0, 1.0),
            Vec3::new(2.0, -2.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(-2.0, 0.0, 1.0),
        ];
        let tris = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let mesh = Mesh::new(p, None, tris, None).unwrap();
        let world = World::single(mesh, EdgeSelection::All);
        let caster = RayCaster::new(&world);
        let cam = camera(Vec3::new(0.0, 0.0, 4.0));
        let view = cam.to_view(1.0);
        let rays = Rays::new(&view, (64, 64), &world).unwrap();
        let vis = RayVisibility {
            caster: &caster,
            rays: &rays,
            fade_row: view.view_depth_row(),
            host: None,
            eye: view.eye(),
        };
        // Triangle 0's edge 1 runs from (1, -1) to (1, 1): visible only above y = 0, i.e. on
        // screen from the middle row up, ending where the near quad's top edge crosses it.
        let draw = Draw {
            visible: true,
            hidden: true,
            outline: true,
            cut: None,
            crossing: None,
            cap: Cap::None,
        };
        let hidden = crate::HiddenLines {
            pattern: crate::LinePattern::Dashed {
                dash: 2.0,
                gap: 1.0,
            },
            ..crate::HiddenLines::default()
        };
        let corners = caster.corners(0);
        let edge = (0, NO_NEIGHBOUR, (corners[1], corners[2]));
        let lines = (([0.0; 2], (0.0, true)), (0.0, true));
        let widths = (0, (1.5, 1.5, 1.5, 1.5));
        let (s, h) = vis.stretches((0, 0), edge, widths, draw, (lines, Some(hidden)));
        assert_eq!(s.len(), 1, "{s:?}");
        let top_of_near = {
            let c = cam.view_projection(64, 64) * DVec4::new(1.0, 0.0, 1.0, 1.0);
            0.5 * (1.0 - c.y / c.w) * 64.0
        };
        let ys = [s[0].from.y, s[0].to.y];
        let lower_end = ys[0].max(ys[1]);
        assert!(
            (lower_end - top_of_near).abs() < 1e-6,
            "{ys:?} vs {top_of_near}"
        );
        // The hidden part, below, in dashes 2 px long and 1 px apart, from the edge's first
        // end in (x, y, z) order, (1, -1): the lowest dash starts at its projection.
        assert!(h.len() > 3, "{h:?}");
        let mut spans: Vec<(f64, f64)> = h
            .iter()
            .map(|d| (d.from.y.min(d.to.y), d.from.y.max(d.to.y)))
            .collect();
        spans.sort_by(|a, b| b.0.total_cmp(&a.0));
        let bottom = {
            let c = cam.view_projection(64, 64) * DVec4::new(1.0, -1.0, 0.0, 1.0);
            0.5 * (1.0 - c.y / c.w) * 64.0
        };
        assert!(
            (spans[0].1 - bottom).abs() < 1e-9,
            "{spans:?} from {bottom}"
        );
        for (k, &(lo, hi)) in spans.iter().enumerate() {
            assert!(lo >= top_of_near - 1e-9, "{spans:?}");
            assert!(hi - lo <= 2.0 + 1e-9, "{spans:?}");
            if k > 0 {
                // Whole dashes are a period apart (the last may be cut by the near quad).
                assert!((spans[k - 1].1 - hi - 3.0).abs() < 1e-6, "{spans:?}");
            }
        }
    }
}
