//! The lines of a drawing: every line the raster draws (drawn edges, outlines, cut lines,
//! intersection lines), chained, and each chain's visible and hidden runs made into paths.
//!
//! Drawn edges chain as the pass chains them (`crate::mesh::chains::chains`), and the
//! outline edges that are not drawn edges (a silhouette loop of a smooth part) as the pass
//! chains outlines each frame (`outline_chains`), so a pattern runs on along a chain as one
//! path with one phase. A run of one class that
//! reaches the vertex where the next edge of its chain starts with a run of the same class
//! goes on in the same path. An outline edge between two triangles seen edge-on is left
//! out: the edge-on part's own outline covers its projection.

use super::occlusion::{Frame, JOIN};
use super::{Path, PathClass};
use crate::edge_math::{is_edge_on, local_eye};
use crate::mesh::adjacency::NO_NEIGHBOUR;
use crate::mesh::chains::{chains, Chains};
use crate::mesh::par::*;
use crate::style::{Color, Style};
use crate::world::outline_chains;
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// A stroke: colour, width, and pattern (dash, period; period 0 for solid).
type Stroke = (Color, f64, [f64; 2]);

/// How one object's lines look.
#[derive(Clone, Copy, Debug)]
struct Look {
    edges: bool,
    outlines: bool,
    edge: Stroke,
    outline: Stroke,
    /// The hidden lines, and whether drawn edges have them (outlines always do).
    hidden: Option<(Stroke, bool)>,
    cut: Stroke,
    intersection: Stroke,
}

impl Look {
    fn of(object: &crate::world::Object, style: &Style) -> Look {
        let s = &object.style;
        let edges = s.edges.unwrap_or(true);
        let outlines = s.outlines.unwrap_or(style.outlines);
        let pattern = |p: crate::LinePattern| p.dash_period().map(f64::from);
        Look {
            edges,
            outlines,
            edge: (
                s.wire_color.unwrap_or(style.wire_color),
                f64::from(s.line_width.unwrap_or(style.line_width)),
                pattern(s.edge_pattern_in(style)),
            ),
            outline: (
                s.outline_color_in(style),
                f64::from(s.outline_width_in(style)),
                pattern(s.outline_pattern_in(style)),
            ),
            hidden: s
                .hidden_in(style)
                .filter(|_| edges || outlines)
                .map(|h| ((h.color, f64::from(h.width), pattern(h.pattern)), h.edges)),
            cut: (
                style.section_line_color,
                f64::from(style.section_width()),
                [0.0; 2],
            ),
            intersection: (
                style.intersection_line_color,
                f64::from(style.intersection_width()),
                [0.0; 2],
            ),
        }
    }

    fn of_class(&self, class: PathClass) -> Stroke {
        match class {
            PathClass::Edge => self.edge,
            PathClass::Outline => self.outline,
            PathClass::Hidden => self.hidden.map_or(self.edge, |h| h.0),
            PathClass::Cut => self.cut,
            PathClass::Intersection => self.intersection,
        }
    }
}

/// A straight piece of a line, in its chain's direction.
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// Its ends, world coordinates.
    ends: (DVec3, DVec3),
    /// The triangles it lies on, which do not hide it (global ids; `u32::MAX` for none).
    own: [u32; 2],
    /// Its visible runs' class.
    class: PathClass,
    /// Whether its hidden runs are drawn.
    hidden: bool,
    /// The section plane a cut line lies on.
    on_plane: Option<usize>,
    /// Seen from inside a cut solid, so behind its section face, where nothing else is in
    /// front (see [`inside_cut_solid`]).
    inside: bool,
}

/// Segments joined end to end, of one object.
struct Chain {
    object: u32,
    segments: Vec<Segment>,
}

/// The paths of every line of `frame`'s world in `style`.
pub(super) fn paths(frame: &Frame<'_>, style: &Style) -> Vec<Path> {
    let world = frame.world;
    let looks: Vec<Look> = world.objects.iter().map(|o| Look::of(o, style)).collect();
    let listed = list(frame, style, &looks);
    let mut paths: Vec<Path> = listed
        .par_iter()
        .flat_map_iter(|chain| paths_of(frame, chain, &looks[chain.object as usize]))
        .collect();
    // Cut and intersection lines come a segment each: join those that meet end to end.
    let (mut joined, rest): (Vec<Path>, Vec<Path>) = paths
        .drain(..)
        .partition(|p| matches!(p.class, PathClass::Cut | PathClass::Intersection));
    joined = join_at_ends(joined);
    let mut all = rest;
    all.extend(joined);
    all
}

/// Every line of the world, as chains of segments.
fn list(frame: &Frame<'_>, style: &Style, looks: &[Look]) -> Vec<Chain> {
    let world = frame.world;
    // Each mesh's drawn edges, chained once for all its objects.
    let drawn: Vec<Option<(Vec<u8>, Chains)>> = world
        .meshes
        .par_iter()
        .enumerate()
        .map(|(m, wm)| {
            let draws = world
                .objects
                .iter()
                .zip(looks)
                .any(|(o, l)| o.mesh == m && l.edges);
            draws.then(|| {
                let mesh = &wm.mesh;
                let mask = mesh.edge_mask(wm.edges);
                let listed = listed_edges(mesh, |t, i| mask[t as usize] & (1 << i) != 0);
                let chained = chains(mesh.positions(), mesh.welded(), mesh.triangles(), &listed);
                (mask, chained)
            })
        })
        .collect();
    let mut out = Vec::new();
    for (o, object) in world.objects.iter().enumerate() {
        let look = &looks[o];
        let mesh = &world.meshes[object.mesh].mesh;
        let tris = mesh.triangles();
        let neighbours = mesh.edge_neighbours();
        let first = frame.first(o);
        let positions = frame.positions(o);
        // Seen edge-on (within the silhouettes' EDGE_ON): such a triangle draws as a line.
        let edge_on =
            |t: u32| is_edge_on(tris[t as usize].map(|v| positions[v as usize]), frame.eye);
        // The outline edges, but those between two triangles seen edge-on: such an edge lies
        // on the projection of the edge-on part, which the part's own outline covers (a
        // box's side in a front view is drawn by its edges with the front and back, not
        // also by every edge of its triangulation).
        let mut outline: Vec<(u32, u32)> = if look.outlines {
            let local = local_eye(object.transform, frame.eye);
            let mut all = crate::world::outline_edges(mesh, local);
            all.retain(|&(t, i)| {
                let n = neighbours[t as usize][i as usize];
                n == NO_NEIGHBOUR || !(edge_on(t) && edge_on(n))
            });
            all
        } else {
            Vec::new()
        };
        outline.sort_unstable();
        let is_outline = |t: u32, i: u8| outline.binary_search(&(t, u32::from(i))).is_ok();
        let sectioned = !world.sections.is_empty();
        let segment = |t: u32, i: u8, forward: bool, class: PathClass, hidden: bool| {
            let corner = |k: u8| positions[tris[t as usize][usize::from(k % 3)] as usize];
            let (a, b) = (corner(i), corner(i + 1));
            let n = neighbours[t as usize][usize::from(i)];
            let own = [
                first + t,
                if n == NO_NEIGHBOUR {
                    u32::MAX
                } else {
                    first + n
                },
            ];
            Segment {
                ends: if forward { (a, b) } else { (b, a) },
                own,
                class,
                hidden,
                on_plane: None,
                inside: sectioned && inside_cut_solid(frame, own),
            }
        };
        let hidden_outlines = look.hidden.is_some();
        let hidden_edges = look.hidden.is_some_and(|h| h.1);
        let drawn_here = drawn[object.mesh].as_ref().filter(|_| look.edges);
        if let Some((_, chained)) = drawn_here {
            out.extend(chained.iter().map(|edges| {
                Chain {
                    object: o as u32,
                    segments: edges
                        .iter()
                        .map(|e| {
                            if is_outline(e.t, e.i) {
                                let hidden = hidden_outlines || hidden_edges;
                                segment(e.t, e.i, e.forward, PathClass::Outline, hidden)
                            } else {
                                segment(e.t, e.i, e.forward, PathClass::Edge, hidden_edges)
                            }
                        })
                        .collect(),
                }
            }));
        }
        // Outline edges that are not drawn edges, chained among themselves.
        let undrawn: Vec<(u32, u8)> = outline
            .iter()
            .map(|&(t, i)| (t, i as u8))
            .filter(|&(t, i)| drawn_here.is_none_or(|(mask, _)| mask[t as usize] & (1 << i) == 0))
            .collect();
        if !undrawn.is_empty() {
            let undrawn: Vec<(u32, u32)> =
                undrawn.iter().map(|&(t, i)| (t, u32::from(i))).collect();
            let local = local_eye(object.transform, frame.eye);
            let chained = outline_chains(mesh, &undrawn, local);
            out.extend(chained.iter().map(|edges| {
                Chain {
                    object: o as u32,
                    segments: edges
                        .iter()
                        .map(|e| segment(e.t, e.i, e.forward, PathClass::Outline, hidden_outlines))
                        .collect(),
                }
            }));
        }
        // Cut lines: a segment where a section plane crosses a triangle.
        for (k, plane) in world.sections.iter().enumerate() {
            let cuts: Vec<Chain> = (0..tris.len() as u32)
                .into_par_iter()
                .filter_map(|t| {
                    let corners = tris[t as usize].map(|v| positions[v as usize]);
                    let ends = plane.cut_triangle(corners)?;
                    Some(Chain {
                        object: o as u32,
                        segments: vec![Segment {
                            ends,
                            own: [first + t, u32::MAX],
                            class: PathClass::Cut,
                            hidden: false,
                            on_plane: Some(k),
                            inside: false,
                        }],
                    })
                })
                .collect();
            out.extend(cuts);
        }
        // The mesh's own intersection lines.
        if style.intersection_lines {
            out.extend(mesh.intersections().iter().map(|c| Chain {
                object: o as u32,
                segments: vec![intersection(
                    c.ends.map(|p| object.transform.transform_point3(p)),
                    [first + c.t, first + c.u],
                )],
            }));
        }
    }
    if style.intersection_lines {
        out.extend(lines_between_objects(frame));
    }
    out
}

/// The intersection lines along which two objects' surfaces cross: the lower object's.
fn lines_between_objects(frame: &Frame<'_>) -> Vec<Chain> {
    use crate::mesh::crossings::{crossings_between, pair_tolerance};
    let world = frame.world;
    let placed: Vec<_> = world
        .objects
        .iter()
        .map(|o| (world.meshes[o.mesh].mesh.bounds_f64(), o.transform))
        .collect();
    let corners = |o: usize| {
        let count = world.meshes[world.objects[o].mesh].mesh.triangle_count() as u32;
        (0..count)
            .map(|t| frame.corners(frame.first(o) + t))
            .collect::<Vec<_>>()
    };
    crate::scene::crossing_pairs(&placed)
        .into_iter()
        .flat_map(|(a, b)| {
            let boxes = (
                crate::scene::world_box(placed[a].0, placed[a].1),
                crate::scene::world_box(placed[b].0, placed[b].1),
            );
            let tolerance = pair_tolerance(boxes.0, boxes.1);
            crossings_between(&corners(a), &corners(b), tolerance)
                .into_iter()
                .map(move |c| Chain {
                    object: a as u32,
                    segments: vec![intersection(
                        c.ends,
                        [frame.first(a) + c.t, frame.first(b) + c.u],
                    )],
                })
        })
        .collect()
}

fn intersection(ends: [DVec3; 2], own: [u32; 2]) -> Segment {
    Segment {
        ends: (ends[0], ends[1]),
        own,
        class: PathClass::Intersection,
        hidden: false,
        on_plane: None,
        inside: false,
    }
}

/// The edges `(t, i)` of `mesh` that `drawn` selects, each shared one once (from its lower
/// triangle), as the pass lists them.
fn listed_edges(mesh: &crate::Mesh, drawn: impl Fn(u32, u8) -> bool) -> Vec<(u32, u8)> {
    let neighbours = mesh.edge_neighbours();
    (0..mesh.triangle_count() as u32)
        .flat_map(|t| (0..3u8).map(move |i| (t, i)))
        .filter(|&(t, i)| {
            let n = neighbours[t as usize][usize::from(i)];
            drawn(t, i) && (n == NO_NEIGHBOUR || t < n)
        })
        .collect()
}

/// In a frame with section planes, back faces stand for the section face of a cut solid,
/// and a line whose triangles (global ids `own`) the eye sees from inside the solid lies
/// behind it where no other surface is in front: a line between two back faces, a back
/// face's boundary, a silhouette where the surface folds inwards (the pass's and the ground
/// truth's rule).
fn inside_cut_solid(frame: &Frame<'_>, [t, n]: [u32; 2]) -> bool {
    let own = (frame.corners(t), frame.outward(t), frame.faces_away(t));
    let beyond = (n != u32::MAX).then(|| (frame.corners(n), frame.faces_away(n)));
    crate::world::seen_from_inside(own, beyond)
}

/// A chain's paths: each run of one class (visible in the segment's class, or hidden),
/// going on across vertices while the class holds. A pattern's position is the projected
/// length of the chain before it (each segment's part in front of the near plane, before
/// the far one and not cut away), as in the pass.
fn paths_of(frame: &Frame<'_>, chain: &Chain, look: &Look) -> Vec<Path> {
    let mut out = Vec::new();
    let mut open: Option<Path> = None;
    // Whether the open path ends where the next segment starts.
    let mut at_vertex = false;
    let mut position = 0.0;
    let mut scratch = Vec::new();
    for seg in &chain.segments {
        let continuing = std::mem::replace(&mut at_vertex, false);
        let (a, b) = seg.ends;
        let Some(span) = frame.span(seg.ends, seg.on_plane) else {
            continue;
        };
        let start = frame.project(a.lerp(b, span.0));
        let length = start.distance(frame.project(a.lerp(b, span.1)));
        let runs = frame.in_image(seg.ends, span).map_or(Vec::new(), |range| {
            let hidden = if seg.inside {
                vec![range]
            } else {
                frame.hidden_parts(seg.ends, range, seg.own, &mut scratch)
            };
            runs_of(range, &hidden)
        });
        for (k, &(s0, s1, hidden)) in runs.iter().enumerate() {
            if hidden && !seg.hidden {
                at_vertex = false;
                continue;
            }
            let class = if hidden { PathClass::Hidden } else { seg.class };
            let (q0, q1) = (frame.project(a.lerp(b, s0)), frame.project(a.lerp(b, s1)));
            let joins = k == 0 && continuing && s0 == 0.0;
            match open.as_mut() {
                Some(path) if joins && path.class == class => {
                    path.points.push(q1);
                    path.world_points.push(a.lerp(b, s1));
                }
                _ => {
                    out.extend(open.take());
                    let (color, width, [dash, period]) = look.of_class(class);
                    let offset = position + q0.distance(start);
                    open = Some(Path {
                        class,
                        object: chain.object,
                        points: vec![q0, q1],
                        world_points: vec![a.lerp(b, s0), a.lerp(b, s1)],
                        color,
                        width,
                        pattern: [dash, period],
                        offset: if period > 0.0 {
                            offset.rem_euclid(period)
                        } else {
                            0.0
                        },
                    });
                }
            }
            at_vertex = s1 == 1.0;
        }
        if !at_vertex {
            out.extend(open.take());
        }
        position += length;
    }
    out.extend(open);
    out
}

/// `range` in runs (from, to, hidden), given its hidden parts.
fn runs_of(range: (f64, f64), hidden: &[(f64, f64)]) -> Vec<(f64, f64, bool)> {
    let mut runs = Vec::with_capacity(2 * hidden.len() + 1);
    let mut at = range.0;
    for &(h0, h1) in hidden {
        let (h0, h1) = (h0.max(range.0), h1.min(range.1));
        if h0 > at {
            runs.push((at, h0, false));
        }
        if h1 > h0 {
            runs.push((h0, h1, true));
            at = h1;
        }
    }
    if range.1 > at {
        runs.push((at, range.1, false));
    }
    // A visible speck between two hidden parts is rounding: it joins them.
    let runs: Vec<(f64, f64, bool)> = runs
        .into_iter()
        .filter(|r| r.1 - r.0 > JOIN || r.2)
        .collect();
    let mut out: Vec<(f64, f64, bool)> = Vec::with_capacity(runs.len());
    for r in runs {
        match out.last_mut() {
            Some(last) if last.2 == r.2 => last.1 = r.1,
            _ => out.push(r),
        }
    }
    out
}

/// Solid paths of one look joined where one ends exactly where another starts or ends
/// (to a millionth of a pixel), where only two ends meet.
fn join_at_ends(paths: Vec<Path>) -> Vec<Path> {
    let key = |p: DVec2| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64);
    let look = |p: &Path| {
        (
            p.class,
            p.object,
            p.color.0.map(f32::to_bits),
            p.width.to_bits(),
        )
    };
    let mut ends: HashMap<_, Vec<(usize, bool)>> = HashMap::new();
    for (k, p) in paths.iter().enumerate() {
        ends.entry((look(p), key(p.points[0])))
            .or_default()
            .push((k, false));
        let last = *p.points.last().unwrap_or(&p.points[0]);
        ends.entry((look(p), key(last)))
            .or_default()
            .push((k, true));
    }
    let other = |k: usize, at_end: bool, paths: &[Path]| {
        let p = &paths[k];
        let point = if at_end {
            *p.points.last()?
        } else {
            p.points[0]
        };
        let list = ends.get(&(look(p), key(point)))?;
        if list.len() != 2 {
            return None;
        }
        list.iter().copied().find(|&e| e != (k, at_end))
    };
    let mut used = vec![false; paths.len()];
    let mut out = Vec::new();
    for start in 0..paths.len() {
        if used[start] {
            continue;
        }
        // Walk back to where the line begins (or round a closed loop), then forwards.
        let (mut k, mut at_end) = (start, false);
        let mut steps = 0;
        while let Some((j, j_end)) = other(k, at_end, &paths) {
            if j == start || steps > paths.len() {
                break;
            }
            (k, at_end) = (j, !j_end);
            steps += 1;
        }
        // (k, at_end): the path and end where the line begins; it runs from that end.
        let mut line = paths[k].clone();
        if at_end {
            line.points.reverse();
            line.world_points.reverse();
        }
        used[k] = true;
        let mut tail = (k, !at_end);
        while let Some((j, j_end)) = other(tail.0, tail.1, &paths) {
            if used[j] {
                break;
            }
            used[j] = true;
            let (mut points, mut world) = (paths[j].points.clone(), paths[j].world_points.clone());
            if j_end {
                points.reverse();
                world.reverse();
            }
            line.points.extend(points.into_iter().skip(1));
            line.world_points.extend(world.into_iter().skip(1));
            tail = (j, !j_end);
        }
        out.push(line);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_alternate_and_cover_the_range() {
        let runs = runs_of((0.0, 1.0), &[(0.2, 0.4), (0.4 + 1e-12, 0.5)]);
        assert_eq!(
            runs,
            vec![(0.0, 0.2, false), (0.2, 0.5, true), (0.5, 1.0, false)]
        );
        assert_eq!(runs_of((0.1, 0.9), &[]), vec![(0.1, 0.9, false)]);
    }

    fn solid(points: &[(f64, f64)]) -> Path {
        Path {
            class: PathClass::Cut,
            object: 0,
            points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            world_points: points.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect(),
            color: Color([0.0, 0.0, 0.0, 1.0]),
            width: 1.0,
            pattern: [0.0; 2],
            offset: 0.0,
        }
    }

    #[test]
    fn segments_meeting_end_to_end_join_into_one_path() {
        // Three pieces of one polyline, in any order and direction, and a stray one.
        let paths = vec![
            solid(&[(2.0, 0.0), (1.0, 0.0)]),
            solid(&[(0.0, 0.0), (1.0, 0.0)]),
            solid(&[(2.0, 0.0), (3.0, 1.0)]),
            solid(&[(9.0, 9.0), (8.0, 8.0)]),
        ];
        let joined = join_at_ends(paths);
        assert_eq!(joined.len(), 2);
        let long = joined.iter().find(|p| p.points.len() == 4).unwrap();
        let xs: Vec<f64> = long.points.iter().map(|p| p.x).collect();
        assert!(
            xs == [0.0, 1.0, 2.0, 3.0] || xs == [3.0, 2.0, 1.0, 0.0],
            "{xs:?}"
        );
        // A closed loop of three stays one path.
        let triangle = vec![
            solid(&[(0.0, 0.0), (1.0, 0.0)]),
            solid(&[(1.0, 0.0), (0.0, 1.0)]),
            solid(&[(0.0, 1.0), (0.0, 0.0)]),
        ];
        let joined = join_at_ends(triangle);
        assert_eq!(joined.len(), 1);
        assert_eq!(joined[0].points.len(), 4);
    }
}
