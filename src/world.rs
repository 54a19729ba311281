//! The CPU description of what tools draw and compare: a [`World`] of meshes placed as
//! objects, a [`Shot`] of it (view, style, size), and the [`Rendering`] a method makes of a
//! shot (image, ids, depth, edge distances). The ground truth and the offline GPU
//! frames both speak in these terms.
//!
//! Triangle ids in every map are **global**: objects are numbered in the world's order, each
//! object's triangles consecutive in the order its mesh file lists them.

use crate::camera::View;
use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use crate::scene::{InstanceStyle, SectionPlane};
use crate::style::Style;
use glam::{DMat4, DVec3};
use std::sync::Arc;

#[cfg(feature = "diagnostics")]
pub mod offscreen;

/// Id of pixels that show no triangle (the id target's [`crate::gpu::BACKGROUND_ID`]).
pub const BACKGROUND: u32 = crate::gpu::BACKGROUND_ID;
/// Id of pixels where the host's own geometry is in front ([`crate::gpu::HOST_ID`]).
pub const HOST: u32 = crate::gpu::HOST_ID;

/// A mesh of a world, with the edges drawn on it.
#[derive(Clone, Debug)]
pub struct WorldMesh {
    /// The mesh, in its own coordinates.
    pub mesh: Arc<Mesh>,
    /// Which of its edges are drawn.
    pub edges: EdgeSelection,
    /// Where it came from, for messages.
    pub name: String,
}

/// One placement of a world mesh.
#[derive(Clone, Debug)]
pub struct Object {
    /// Index into [`World::meshes`].
    pub mesh: usize,
    /// Model → world.
    pub transform: DMat4,
    /// Style overrides.
    pub style: InstanceStyle,
}

impl Object {
    /// World mesh `mesh` at `transform`, in the frame's style.
    pub fn new(mesh: usize, transform: DMat4) -> Object {
        Object {
            mesh,
            transform,
            style: InstanceStyle::default(),
        }
    }
}

/// Meshes and their placements: what tools render, compare and time.
#[derive(Clone, Debug, Default)]
pub struct World {
    /// The distinct meshes (each uploaded once).
    pub meshes: Vec<WorldMesh>,
    /// The objects, in order; several may share a mesh.
    pub objects: Vec<Object>,
    /// Section planes cutting the whole world (see [`SectionPlane`]).
    pub sections: Vec<SectionPlane>,
}

impl World {
    /// One mesh, placed once at the origin.
    pub fn single(mesh: Mesh, edges: EdgeSelection) -> World {
        World {
            sections: Vec::new(),
            meshes: vec![WorldMesh {
                mesh: Arc::new(mesh),
                edges,
                name: "mesh".into(),
            }],
            objects: vec![Object {
                mesh: 0,
                transform: DMat4::IDENTITY,
                style: InstanceStyle::default(),
            }],
        }
    }

    /// Checks the objects' meshes and that every global id fits the id maps.
    pub fn validate(&self) -> Result<()> {
        crate::scene::validate_sections(&self.sections)?;
        for (i, o) in self.objects.iter().enumerate() {
            if o.mesh >= self.meshes.len() {
                return Err(Error::InvalidScene(format!(
                    "object {i} refers to mesh {} of {}",
                    o.mesh,
                    self.meshes.len()
                )));
            }
        }
        let total = self.triangle_count();
        if total >= u64::from(HOST) {
            return Err(Error::InvalidScene(format!(
                "{total} triangles over all objects: global ids must stay below {HOST}"
            )));
        }
        Ok(())
    }

    /// Triangles over all objects.
    pub fn triangle_count(&self) -> u64 {
        self.objects
            .iter()
            .map(|o| self.meshes[o.mesh].mesh.triangle_count() as u64)
            .sum()
    }

    /// The global id of each object's first triangle.
    pub fn first_ids(&self) -> Vec<u32> {
        let mut next = 0u64;
        self.objects
            .iter()
            .map(|o| {
                let first = next;
                next += self.meshes[o.mesh].mesh.triangle_count() as u64;
                first as u32
            })
            .collect()
    }

    /// The object and triangle of global id `id`.
    pub fn locate(&self, first_ids: &[u32], id: u32) -> (usize, u32) {
        let o = first_ids.partition_point(|&f| f <= id).saturating_sub(1);
        (o, id - first_ids[o])
    }

    /// Axis-aligned world bounds of every object (its mesh's bounding box, transformed).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let placed = self
            .objects
            .iter()
            .map(|o| self.meshes[o.mesh].mesh.placed_bounds(o.transform));
        placed.fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        )
    }
}

#[cfg(feature = "formats")]
impl World {
    /// A glTF scene as a world: each glTF mesh once, an object per instance in node order,
    /// with the file's line width and pattern where it gives them. Each mesh draws `edges`, or, when that
    /// is `None`, its authored edges where it has them (polygon edges otherwise); see
    /// [`Mesh::resolve_edges`] for what an explicit selection does to the file's outline mask.
    pub fn from_gltf(
        doc: crate::mesh::formats::gltf::Document,
        edges: Option<EdgeSelection>,
    ) -> World {
        let styles: Vec<InstanceStyle> = doc
            .meshes
            .iter()
            .map(|m| InstanceStyle {
                line_width: m.line_width,
                edge_pattern: m.line_pattern,
                ..InstanceStyle::default()
            })
            .collect();
        let meshes = doc
            .meshes
            .into_iter()
            .map(|m| {
                let (mesh, edges) = m.mesh.resolve_edges(edges.or(m.edges));
                WorldMesh {
                    mesh: Arc::new(mesh),
                    edges,
                    name: m.name,
                }
            })
            .collect();
        let objects = doc
            .instances
            .into_iter()
            .map(|(mesh, transform)| Object {
                mesh,
                transform,
                style: styles[mesh],
            })
            .collect();
        World {
            meshes,
            objects,
            sections: Vec::new(),
        }
    }
}

/// The outline edges of `mesh` seen from `eye` (homogeneous, in the mesh's coordinates), as
/// (triangle, edge) with edge `i` running from corner `i` to corner `i + 1`; an edge shared by
/// two triangles appears once, under the lower id. Only the edges the mesh allows as outlines
/// ([`Mesh::outline_mask`](crate::Mesh::outline_mask)) are listed.
pub fn outline_edges(mesh: &Mesh, eye: glam::DVec4) -> Vec<(u32, u32)> {
    use crate::mesh::par::*;
    let p = mesh.positions();
    let tris = mesh.triangles();
    let neighbours = mesh.edge_neighbours();
    let allowed = mesh.outline_mask();
    let corner = |t: u32, k: usize| p[tris[t as usize][k % 3] as usize].as_dvec3();
    (0..tris.len() as u32)
        .into_par_iter()
        .flat_map_iter(|t| {
            let allowed = allowed[t as usize];
            (0..3).filter_map(move |i| {
                if allowed & (1 << i) == 0 {
                    return None;
                }
                let n = neighbours[t as usize][i];
                let outline = n == crate::mesh::adjacency::NO_NEIGHBOUR
                    || (t < n && {
                        let d = (corner(n, 0) + corner(n, 1) + corner(n, 2)) / 3.0;
                        let (a, b, c) = (corner(t, i), corner(t, i + 1), corner(t, i + 2));
                        crate::edge_math::is_silhouette(a, b, c, d, eye)
                    });
                outline.then_some((t, i as u32))
            })
        })
        .collect()
}

/// The outline chains of `edges` (outline edges `(t, i)` of `mesh`, a shared one listed
/// once) seen from `eye` (homogeneous, in the mesh's own coordinates), along which an
/// outline's patterns run: each edge runs with the side that faces the eye on its left
/// ([`outline_forward`](crate::edge_math::outline_forward)), the edges joined as
/// [`directed_chains`](crate::mesh::chains::directed_chains) joins them at welded
/// vertices, a closed chain starting at its edge whose start comes first in (x, y, z) order
/// ([`comes_first`](crate::mesh::chains::comes_first)). `outline_chain_ends` in trace.wgsl
/// finds the same chains on the GPU each frame.
pub(crate) fn outline_chains(
    mesh: &crate::Mesh,
    edges: &[(u32, u32)],
    eye: glam::DVec4,
) -> Vec<Vec<crate::mesh::chains::ChainEdge>> {
    use crate::mesh::chains::comes_first;
    let p = mesh.positions();
    let tris = mesh.triangles();
    let neighbours = mesh.edge_neighbours();
    let weld = mesh.welded();
    let corner = |t: u32, k: usize| p[tris[t as usize][k % 3] as usize].as_dvec3();
    let oriented: Vec<crate::mesh::chains::ChainEdge> = edges
        .iter()
        .map(|&(t, i)| {
            let k = i as usize;
            let n = neighbours[t as usize][k];
            let d = (n != crate::mesh::adjacency::NO_NEIGHBOUR)
                .then(|| (corner(n, 0) + corner(n, 1) + corner(n, 2)) / 3.0);
            let (a, b, c) = (corner(t, k), corner(t, k + 1), corner(t, k + 2));
            crate::mesh::chains::ChainEdge {
                t,
                i: i as u8,
                forward: crate::edge_math::outline_forward(a, b, c, d, eye),
            }
        })
        .collect();
    let ends: Vec<(u32, u32)> = oriented
        .iter()
        .map(|e| {
            let corners = tris[e.t as usize];
            let a = weld[corners[usize::from(e.i)] as usize];
            let b = weld[corners[(usize::from(e.i) + 1) % 3] as usize];
            if e.forward {
                (a, b)
            } else {
                (b, a)
            }
        })
        .collect();
    // Each start's rank in (x, y, z) order, the key a closed chain starts at the least of.
    let mut starts: Vec<u32> = ends.iter().map(|e| e.0).collect();
    starts.sort_unstable_by(|&a, &b| {
        let (a, b) = (p[a as usize], p[b as usize]);
        match (comes_first(a, b), comes_first(b, a)) {
            (true, _) => std::cmp::Ordering::Less,
            (_, true) => std::cmp::Ordering::Greater,
            _ => std::cmp::Ordering::Equal,
        }
    });
    starts.dedup();
    let rank: std::collections::HashMap<u32, u32> = (0..starts.len() as u32)
        .map(|k| (starts[k as usize], k))
        .collect();
    let keys: Vec<u32> = ends.iter().map(|e| rank[&e.0]).collect();
    crate::mesh::chains::directed_chains(&ends, &keys)
        .into_iter()
        .map(|chain| chain.into_iter().map(|e| oriented[e]).collect())
        .collect()
}

/// The built-in scene: a torus and a sphere, two meshes drawing `edges`.
pub fn default_world(edges: EdgeSelection) -> World {
    let mut world = World::default();
    // The parts are constant and valid (tests check it); an error cannot occur here.
    for (i, (mesh, transform)) in crate::mesh::default_parts()
        .into_iter()
        .flatten()
        .enumerate()
    {
        world.meshes.push(WorldMesh {
            mesh: Arc::new(mesh),
            edges,
            name: ["torus", "sphere"][i].into(),
        });
        world.objects.push(Object {
            mesh: i,
            transform,
            style: InstanceStyle::default(),
        });
    }
    world
}

/// What one render draws: a world, through a view, in a style, at a size.
#[derive(Clone, Copy, Debug)]
pub struct Shot<'a> {
    /// The meshes and objects.
    pub world: &'a World,
    /// How they are seen.
    pub view: View,
    /// Colours, line width, lighting.
    pub style: &'a Style,
    /// Image size in pixels.
    pub size: (u32, u32),
}

impl Shot<'_> {
    /// Checks the view, the style, the world and every object's transform and style (not
    /// the size: each consumer has its own limits).
    pub fn validate(&self) -> Result<()> {
        self.view.validate()?;
        self.style.validate()?;
        self.world.validate()?;
        for (i, o) in self.world.objects.iter().enumerate() {
            crate::scene::check_transform(&o.transform, i)?;
            o.style.validate(i)?;
        }
        Ok(())
    }
}

/// What one method drew of a shot, on the CPU. Maps are row-major, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Rendering {
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// 8-bit sRGB RGBA image.
    pub rgba: Vec<u8>,
    /// Global id of the visible triangle per pixel: [`BACKGROUND`] where none is.
    pub ids: Vec<u32>,
    /// Depth in the standard convention: 0 at the near plane, 1 at the far plane and on
    /// background.
    pub depth: Vec<f32>,
    /// Pixels to the line that colours the pixel most (a drawn edge of the visible triangle,
    /// or, with outlines, an outline within reach; background pixels included): with lines
    /// of one width and no depth fade, the nearest line. `inf` where there is none.
    /// The forward method reports its interpolated altitudes as they come (NaN where they
    /// are NaN); the two-pass method measures no distance and reports 0 where it drew a line
    /// fragment, `inf` elsewhere.
    pub edge_distance: Vec<f32>,
    /// Pixels to the hidden line that colours the pixel most ([`Style::hidden`]: the
    /// nearest point of a dash of a hidden part of a drawn line, within reach); `inf` where
    /// there is none, and everywhere for methods that draw no hidden lines.
    ///
    /// [`Style::hidden`]: crate::Style::hidden
    pub hidden_distance: Vec<f32>,
    /// The class of the line that colours each pixel most ([`LineClass`] as a byte; the
    /// visible line where a visible and a hidden one colour it alike); empty for methods
    /// that do not tell line classes apart (the baselines).
    pub line_class: Vec<u8>,
}

pub use crate::style::LineClass;

/// Narrows `range` to the parameters s where f0 + s (f1 − f0) ≥ 0 (empty where either is
/// NaN): a segment clipped to a plane's kept side, given its two ends' values.
pub(crate) fn keep_positive(range: &mut (f64, f64), f0: f64, f1: f64) {
    if f0 < 0.0 && f1 < 0.0 {
        *range = (1.0, 0.0);
    } else if f0 < 0.0 {
        range.0 = range.0.max(f0 / (f0 - f1));
    } else if f1 < 0.0 {
        range.1 = range.1.min(f0 / (f0 - f1));
    } else if f0.is_nan() || f1.is_nan() {
        *range = (1.0, 0.0);
    }
}

/// Whether the eye sees a line on a cut solid's surface from inside the solid, where no
/// other surface tells (twin of `capped` in trace.wgsl, for the ground truth and the
/// drawings): a line between two back faces, a back face's boundary (`beyond` is `None`),
/// a silhouette where the surface folds inwards. `own`: the line's triangle (its corners,
/// its outward normal, whether it faces away from the eye); `beyond`: the neighbour across
/// the line (its corners, whether it faces away).
pub(crate) fn seen_from_inside(
    (corners, outward, away): ([DVec3; 3], DVec3, bool),
    beyond: Option<([DVec3; 3], bool)>,
) -> bool {
    let Some((other, other_away)) = beyond else {
        return away;
    };
    match (away, other_away) {
        (true, true) => true,
        (false, false) => false,
        // A silhouette: inside where the neighbour lies on the outward side (concave).
        _ => outward.dot((other[0] + other[1] + other[2]) / 3.0 - corners[0]) > 0.0,
    }
}
