//! Triangle meshes as every method sees them: positions, smooth normals, triangles, and the
//! per-triangle mask that says which triangle edges were edges of the source polygons; and
//! what is computed from them once (adjacency, patches, traced clusters). The loaders are
//! in `formats` (feature `formats`). It uses only the crate's error type.

pub(crate) mod chains;
#[cfg(feature = "formats")]
pub mod formats;
pub(crate) mod par;

// What is computed from a mesh once, for the pass: public for the ground truth and the
// tests, which check it against its definitions.
#[cfg(feature = "truth")]
pub mod adjacency;
#[cfg(not(feature = "truth"))]
#[allow(dead_code, unused_imports)]
pub(crate) mod adjacency;
#[cfg(feature = "truth")]
pub mod clusters;
#[cfg(not(feature = "truth"))]
#[allow(dead_code, unused_imports)]
pub(crate) mod clusters;
#[cfg(feature = "truth")]
pub mod crossings;
#[cfg(not(feature = "truth"))]
#[allow(dead_code, unused_imports)]
pub(crate) mod crossings;
#[cfg(feature = "truth")]
pub mod patches;
#[cfg(not(feature = "truth"))]
#[allow(dead_code, unused_imports)]
pub(crate) mod patches;
#[cfg(feature = "formats")]
pub(crate) mod polygon;
mod procedural;

#[cfg(feature = "formats")]
pub use formats::{
    format_of, load, load_bytes, load_gltf, load_gltf_mesh, load_obj, load_ply, load_stl, Format,
    FORMATS,
};
pub use procedural::{
    builtin_mesh, cube, default_parts, grid, layers, sphere, torus, Procedural, LAYER_TRIANGLES,
};

use crate::error::{Error, Result};
use glam::Vec3;
use std::borrow::Cow;

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// All three edges of a triangle. Edge `i` runs from corner `i` to corner `(i + 1) % 3`.
pub const ALL_EDGES: u8 = 0b111;

/// Which triangle edges are drawn.
///
/// ```
/// use wirepass::{EdgeSelection, Mesh};
/// // A unit square as two triangles: a quad whose diagonal is masked out.
/// let mesh = wirepass::mesh::grid(2)?;
/// assert_eq!(mesh.triangle_count(), 2);
/// let drawn = |s| mesh.edge_mask(s).iter().map(|m: &u8| m.count_ones()).sum::<u32>();
/// assert_eq!(drawn(EdgeSelection::All), 6);
/// assert_eq!(drawn(EdgeSelection::Polygon), 4); // the square, not its diagonal
/// assert_eq!(drawn(EdgeSelection::Feature(30.0)), 4); // flat: the boundary only
/// # Ok::<(), wirepass::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum EdgeSelection {
    /// Every triangle edge, diagonals of triangulated polygons included.
    All,
    /// Only edges of the source polygons: the diagonals a triangulation adds are left out.
    #[default]
    Polygon,
    /// Feature edges: where the faces on the two sides meet at a dihedral angle above the
    /// threshold in degrees, plus boundary and non-manifold edges (vertices welded by
    /// position). Three.js `EdgesGeometry` uses 1°.
    Feature(f32),
    /// The edges the file itself says to draw (glTF's `EXT_mesh_primitive_edge_visibility`
    /// or `CESIUM_primitive_outline`: see [`Mesh::with_authored_edges`]); [`Polygon`]
    /// for a mesh without them. Only with this selection does a file's outline mask
    /// ([`Mesh::with_outline_mask`]) apply: see [`Mesh::resolve_edges`].
    ///
    /// [`Polygon`]: EdgeSelection::Polygon
    Authored,
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Default threshold of [`EdgeSelection::Feature`], in degrees.
pub const DEFAULT_FEATURE_ANGLE: f32 = 1.0;

impl std::str::FromStr for EdgeSelection {
    type Err = Error;

    /// Parses `all`, `polygon`, `authored`, `feature` or `feature:DEGREES`.
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            Error::InvalidSetting(format!(
                "edges {s:?} is not all, polygon, authored, feature or feature:DEGREES (0 to 180)"
            ))
        };
        match s.split_once(':') {
            None if s == "all" => Ok(EdgeSelection::All),
            None if s == "polygon" => Ok(EdgeSelection::Polygon),
            None if s == "authored" => Ok(EdgeSelection::Authored),
            None if s == "feature" => Ok(EdgeSelection::Feature(DEFAULT_FEATURE_ANGLE)),
            Some(("feature", deg)) => match deg.trim().parse::<f32>() {
                Ok(d) if (0.0..=180.0).contains(&d) => Ok(EdgeSelection::Feature(d)),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        }
    }
}

/// A validated triangle mesh. All objects and groups of a file form one mesh, so triangle
/// ids (the index into [`Mesh::triangles`]) are global across the scene.
///
/// ```
/// use wirepass::glam::Vec3;
/// use wirepass::Mesh;
///
/// // A unit quad as two triangles; the mask keeps the diagonal (edge 2 of each triangle:
/// // from its third vertex back to its first) out of the polygon edges.
/// let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
/// let quad = Mesh::new(positions, None, vec![[0, 1, 2], [2, 3, 0]], Some(vec![0b011, 0b011]))?;
/// assert_eq!(quad.triangle_count(), 2);
///
/// // Bad input is an error, never a panic.
/// let nan = vec![Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)];
/// assert!(Mesh::new(nan, None, vec![[0, 1, 2]], None).is_err());
/// assert!(Mesh::new(vec![Vec3::ZERO; 3], None, vec![[0, 1, 3]], None).is_err());
/// # Ok::<(), wirepass::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Mesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    polygon_edges: Vec<u8>,
    /// Edges that may be outlines, when the file restricts them.
    outline_mask: Option<Vec<u8>>,
    /// The edges the file says to draw, when it says.
    authored_edges: Option<Vec<u8>>,
    /// Each vertex's first vertex at its position, computed on first use.
    weld: std::sync::OnceLock<Vec<u32>>,
    /// Edge adjacency, computed on first use.
    neighbours: std::sync::OnceLock<Vec<[u32; 3]>>,
    /// Per triangle, what lets the trace pass skip it: see [`Mesh::outline_hints`].
    outline_hints: std::sync::OnceLock<Vec<u8>>,
    /// Per cluster of triangles, what lets the trace pass skip it: see
    /// [`Mesh::traced_clusters`].
    traced_clusters: std::sync::OnceLock<clusters::Clusters>,
    /// The crossing pairs, and per triangle whether it crosses another: see
    /// [`Mesh::crossed_triangles`].
    crossings: std::sync::OnceLock<(Vec<crossings::Crossing>, Vec<bool>)>,
    /// A point the surface is star-shaped from, if one was found: see
    /// [`crossings::star_centre`].
    star: std::sync::OnceLock<Option<glam::DVec3>>,
}

/// The value in `cell`, computed by `compute` if no thread has stored one yet.
///
/// Unlike `OnceLock::get_or_init`, no thread waits while another computes: the computations
/// run on rayon's workers, and a worker that blocked on a cell another worker fills could
/// hold, queued beneath it, the very job that computation waits for (two threads inserting
/// one mesh can deadlock so). Threads that race compute the same value; the first one stored
/// is kept.
fn computed_once<T>(cell: &std::sync::OnceLock<T>, compute: impl FnOnce() -> T) -> &T {
    if let Some(value) = cell.get() {
        return value;
    }
    let value = compute();
    // Storing moves a finished value: the wait, if another thread stores at that moment,
    // is for a move, never for a computation.
    let _ = cell.set(value);
    cell.get().expect("the cell was just filled")
}

impl Mesh {
    /// Builds a mesh, checking that every coordinate is finite and every index in range.
    ///
    /// `normals`, when given, has one entry per position; otherwise area-weighted smooth
    /// normals are computed. `polygon_edges`, when given, has one 3-bit mask per triangle
    /// (bit `i` set: edge `i` is a polygon edge); otherwise every edge is a polygon edge.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        triangles: Vec<[u32; 3]>,
        polygon_edges: Option<Vec<u8>>,
    ) -> Result<Self> {
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::InvalidMesh(format!(
                "vertex {i} has a non-finite coordinate {:?}",
                positions[i]
            )));
        }
        if triangles.is_empty() {
            return Err(Error::InvalidMesh("the mesh has no triangles".into()));
        }
        let n = positions.len();
        if n > u32::MAX as usize {
            return Err(Error::InvalidMesh(format!(
                "{n} vertices exceed u32 indexing"
            )));
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidMesh(format!(
                    "triangle {t} refers to vertex {v}, but there are only {n} vertices"
                )));
            }
        }
        if triangles.len() >= u32::MAX as usize {
            return Err(Error::InvalidMesh(format!(
                "{} triangles exceed the id range (u32::MAX is the background id)",
                triangles.len()
            )));
        }
        let polygon_edges = match polygon_edges {
            Some(mask) if mask.len() != triangles.len() => {
                return Err(Error::InvalidMesh(format!(
                    "{} edge masks for {} triangles",
                    mask.len(),
                    triangles.len()
                )))
            }
            Some(mask) => mask.into_iter().map(|m| m & ALL_EDGES).collect(),
            None => vec![ALL_EDGES; triangles.len()],
        };
        let normals = match normals {
            Some(normals) if normals.len() != n => {
                return Err(Error::InvalidMesh(format!(
                    "{} normals for {n} vertices",
                    normals.len()
                )))
            }
            Some(normals) => {
                if let Some(i) = normals.iter().position(|v| !v.is_finite()) {
                    return Err(Error::InvalidMesh(format!(
                        "normal {i} has a non-finite component"
                    )));
                }
                normals
                    .into_iter()
                    .map(|v| v.try_normalize().unwrap_or(Vec3::ZERO))
                    .collect()
            }
            None => smooth_normals(&positions, &triangles),
        };
        Ok(Self {
            positions,
            normals,
            triangles,
            polygon_edges,
            outline_mask: None,
            authored_edges: None,
            weld: Default::default(),
            neighbours: Default::default(),
            outline_hints: Default::default(),
            traced_clusters: Default::default(),
            crossings: Default::default(),
            star: Default::default(),
        })
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Unit vertex normals (zero where a vertex touches only degenerate triangles).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Triangles as vertex indices; a triangle's position in this slice is its id.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The per-triangle 3-bit mask of edges to draw for `selection`.
    pub fn edge_mask(&self, selection: EdgeSelection) -> Vec<u8> {
        match selection {
            EdgeSelection::All => vec![ALL_EDGES; self.triangles.len()],
            EdgeSelection::Polygon => self.polygon_edges.clone(),
            EdgeSelection::Feature(degrees) => self.feature_edges(degrees),
            EdgeSelection::Authored => self
                .authored_edges
                .clone()
                .unwrap_or_else(|| self.polygon_edges.clone()),
        }
    }

    /// The per-triangle mask of edges the file says to draw, if it says
    /// ([`Mesh::with_authored_edges`]).
    pub fn authored_edges(&self) -> Option<&[u8]> {
        self.authored_edges.as_deref()
    }

    /// This mesh with the file's own choice of drawn edges (bit `i` of each triangle's mask
    /// for edge `i`), which [`EdgeSelection::Authored`] draws.
    pub fn with_authored_edges(mut self, mask: Vec<u8>) -> Result<Mesh> {
        if mask.len() != self.triangles.len() {
            return Err(Error::InvalidMesh(format!(
                "{} authored edge masks for {} triangles",
                mask.len(),
                self.triangles.len()
            )));
        }
        self.authored_edges = Some(mask.into_iter().map(|m| m & ALL_EDGES).collect());
        Ok(self)
    }

    /// This mesh with every edge allowed as an outline again (see [`Mesh::outline_mask`]).
    pub fn without_outline_mask(mut self) -> Mesh {
        self.outline_mask = None;
        self
    }

    /// The mesh and edge selection to draw when `requested` was asked for (`None`: nothing
    /// was): by default the file's own edges ([`EdgeSelection::Authored`]) where the mesh
    /// has them, else [`EdgeSelection::Polygon`].
    ///
    /// A file's outline mask belongs with its authored edges: it says which edges may be
    /// silhouettes and boundaries *when the file's edges are drawn*. Any other selection
    /// asks for the geometry's own edges, so the mask is dropped and every edge may be an
    /// outline again.
    pub fn resolve_edges(self, requested: Option<EdgeSelection>) -> (Mesh, EdgeSelection) {
        let (drops_mask, edges) = self.resolution(requested);
        if drops_mask {
            (self.without_outline_mask(), edges)
        } else {
            (self, edges)
        }
    }

    /// [`Mesh::resolve_edges`] for a mesh the caller keeps (to pick on it, or to draw it
    /// again with other edges): the mesh itself where it draws as it is, a copy only where
    /// the selection drops the file's outline mask.
    pub fn resolved_edges(
        &self,
        requested: Option<EdgeSelection>,
    ) -> (Cow<'_, Mesh>, EdgeSelection) {
        let (drops_mask, edges) = self.resolution(requested);
        if drops_mask {
            (Cow::Owned(self.clone().without_outline_mask()), edges)
        } else {
            (Cow::Borrowed(self), edges)
        }
    }

    /// Whether `requested` drops the outline mask, and the selection it draws.
    fn resolution(&self, requested: Option<EdgeSelection>) -> (bool, EdgeSelection) {
        match requested {
            None if self.authored_edges.is_some() => (false, EdgeSelection::Authored),
            None => (false, EdgeSelection::Polygon),
            Some(EdgeSelection::Authored) => (false, EdgeSelection::Authored),
            Some(other) => (self.outline_mask.is_some(), other),
        }
    }

    /// Mask of edges whose dihedral angle exceeds `degrees`, plus boundary and non-manifold
    /// edges. An edge next to a zero-area triangle, whose normal is undefined, is drawn only
    /// when it is a boundary.
    fn feature_edges(&self, degrees: f32) -> Vec<u8> {
        let normals: Vec<_> = (0..self.triangles.len())
            .map(|t| self.face_normal(t))
            .collect();
        (0..self.triangles.len())
            .map(|t| self.feature_mask(t, degrees, &|u| normals[u]))
            .collect()
    }

    /// The unit normal of triangle `t`'s plane (its winding's side), `None` for a
    /// zero-area triangle.
    fn face_normal(&self, t: usize) -> Option<glam::DVec3> {
        let [a, b, c] = self.triangles[t].map(|v| self.positions[v as usize].as_dvec3());
        (b - a).cross(c - a).try_normalize()
    }

    /// Triangle `t`'s mask of [`feature_edges`](Self::feature_edges), given every
    /// triangle's [`face_normal`](Self::face_normal).
    fn feature_mask(
        &self,
        t: usize,
        degrees: f32,
        normal: &dyn Fn(usize) -> Option<glam::DVec3>,
    ) -> u8 {
        let cos_limit = f64::from(degrees).to_radians().cos();
        let mut mask = 0;
        for (i, &u) in self.edge_neighbours()[t].iter().enumerate() {
            let feature = u == adjacency::NO_NEIGHBOUR
                || match (normal(t), normal(u as usize)) {
                    (Some(n), Some(m)) => n.dot(m) < cos_limit,
                    _ => false,
                };
            if feature {
                mask |= 1 << i;
            }
        }
        mask
    }

    /// Triangle `t`'s 3-bit mask of edges drawn for `selection` (bit `i`: the edge from
    /// corner `i` to `i + 1`), as [`edge_mask`](Self::edge_mask) has it, without computing
    /// the whole mesh's.
    pub fn triangle_edge_mask(&self, t: usize, selection: EdgeSelection) -> u8 {
        match selection {
            EdgeSelection::All => ALL_EDGES,
            EdgeSelection::Polygon => self.polygon_edges[t],
            EdgeSelection::Feature(degrees) => {
                self.feature_mask(t, degrees, &|u| self.face_normal(u))
            }
            EdgeSelection::Authored => self
                .authored_edges
                .as_ref()
                .map_or(self.polygon_edges[t], |mask| mask[t]),
        }
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// The triangle across each triangle edge (edge `i` runs from corner `i` to `i + 1`),
    /// with vertices welded by position, or `adjacency::NO_NEIGHBOUR` on boundary and
    /// non-manifold edges. Computed once, on first use.
    pub fn edge_neighbours(&self) -> &[[u32; 3]] {
        computed_once(&self.neighbours, || {
            adjacency::welded_neighbours(self.welded(), &self.triangles)
        })
        .as_slice()
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// Each vertex's first vertex of bit-identical position
    /// (`adjacency::weld_by_position`), which the adjacency and the chains of drawn edges
    /// join vertices by. Computed once, on first use.
    pub fn welded(&self) -> &[u32] {
        computed_once(&self.weld, || adjacency::weld_by_position(&self.positions)).as_slice()
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// Per triangle, 5 bits that let the GPU trace pass skip triangles that cannot have an
    /// outline edge: bit 0 set when an edge has no neighbour (a boundary, always an outline),
    /// bits 1–4 a code q bounding how far the surface folds at its edges: a neighboured edge
    /// can be a silhouette only while the eye sees the triangle within
    /// asin(`adjacency::fold_bound`\(q\)) of edge-on.
    /// See `adjacency::outline_hints`. Computed once, on first use.
    pub fn outline_hints(&self) -> &[u8] {
        computed_once(&self.outline_hints, || {
            adjacency::outline_hints(&self.positions, &self.triangles, self.edge_neighbours())
        })
        .as_slice()
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// Per triangle, whether it crosses another triangle of the mesh (the mesh passes through
    /// itself there): see `crossings::crossing_triangles`. Computed once, on first use.
    pub fn crossed_triangles(&self) -> &[bool] {
        &self.crossing_pairs().1
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// The pairs of triangles that cross, and the segments along which they meet: the
    /// mesh's intersection lines (`crossings::crossings`). Computed once, on first use.
    pub fn intersections(&self) -> &[crossings::Crossing] {
        &self.crossing_pairs().0
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// A point every triangle faces alike and from which they cover each direction once,
    /// if one was found (`crossings::star_centre`): with a closed, oriented surface, the
    /// proof that the mesh does not cross itself. Computed once, on first use.
    pub fn star_centre(&self) -> Option<glam::DVec3> {
        *computed_once(&self.star, || {
            crossings::star_centre(&self.positions, &self.triangles)
        })
    }

    fn crossing_pairs(&self) -> &(Vec<crossings::Crossing>, Vec<bool>) {
        computed_once(&self.crossings, || {
            // A closed star-shaped surface cannot cross itself: a test linear in its size.
            let star = self.star_centre().is_some()
                && crossings::closed_and_oriented(
                    &self.triangles,
                    self.welded(),
                    self.edge_neighbours(),
                );
            let pairs = if star {
                Vec::new()
            } else {
                crossings::crossings(&self.positions, &self.triangles)
            };
            let flags = crossings::flag_crossing(self.triangles.len(), &pairs);
            (pairs, flags)
        })
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// The triangles in clusters of `clusters::CLUSTER_TRIANGLES` nearby ones, with bounds
    /// that let the GPU trace pass skip a cluster when, from the current eye, none of its
    /// triangles can have an outline edge. See `clusters::clusters`. Computed once, on
    /// first use.
    pub fn traced_clusters(&self) -> &clusters::Clusters {
        computed_once(&self.traced_clusters, || {
            clusters::clusters(
                &self.positions,
                &self.triangles,
                self.outline_hints(),
                &self.quad_partners(),
            )
        })
    }

    // What the pass computes from the mesh: for the ground truth and the tests.
    #[cfg_attr(not(feature = "truth"), doc(hidden))]
    /// Per triangle, the other triangle of its quad, or `adjacency::NO_NEIGHBOUR`: two
    /// triangles whose only edges that are not polygon edges are the one they share, the
    /// two halves of a source polygon of four corners.
    pub fn quad_partners(&self) -> Vec<u32> {
        let neighbours = self.edge_neighbours();
        // The one edge of t that is not a polygon edge, if it has exactly one.
        let diagonal = |t: usize| {
            let open = !self.polygon_edges[t] & ALL_EDGES;
            (open.count_ones() == 1).then(|| open.trailing_zeros() as usize)
        };
        (0..self.triangles.len())
            .map(|t| {
                let Some(e) = diagonal(t) else {
                    return adjacency::NO_NEIGHBOUR;
                };
                let n = neighbours[t][e];
                let back = n != adjacency::NO_NEIGHBOUR
                    && n != t as u32
                    && diagonal(n as usize).is_some_and(|j| neighbours[n as usize][j] == t as u32);
                if back {
                    n
                } else {
                    adjacency::NO_NEIGHBOUR
                }
            })
            .collect()
    }

    /// Per triangle, the edges that may be drawn as outlines (bit `i` for edge `i`): all of
    /// them unless the file says otherwise (see [`Mesh::with_outline_mask`]).
    pub fn outline_mask(&self) -> std::borrow::Cow<'_, [u8]> {
        match &self.outline_mask {
            Some(mask) => mask.as_slice().into(),
            None => vec![ALL_EDGES; self.triangles.len()].into(),
        }
    }

    /// This mesh with only the edges `mask` sets (bit `i` for edge `i` of each triangle) drawn
    /// as outlines where they are silhouettes or boundaries; files that say which edges are
    /// silhouette edges (glTF's `EXT_mesh_primitive_edge_visibility`) give it.
    pub fn with_outline_mask(mut self, mask: Vec<u8>) -> Result<Mesh> {
        if mask.len() != self.triangles.len() {
            return Err(Error::InvalidMesh(format!(
                "{} outline masks for {} triangles",
                mask.len(),
                self.triangles.len()
            )));
        }
        self.outline_mask = Some(mask.into_iter().map(|m| m & ALL_EDGES).collect());
        Ok(self)
    }

    /// Axis-aligned bounds `(min, max)` of the positions that triangles use, in f64.
    pub fn bounds_f64(&self) -> (glam::DVec3, glam::DVec3) {
        let (lo, hi) = self.bounds();
        (lo.as_dvec3(), hi.as_dvec3())
    }

    /// Axis-aligned bounds `(min, max)` of [`bounds_f64`](Self::bounds_f64)'s box placed by
    /// `transform` (model → world): the box around its eight transformed corners.
    pub fn placed_bounds(&self, transform: glam::DMat4) -> (glam::DVec3, glam::DVec3) {
        let (a, b) = self.bounds_f64();
        let mut lo = glam::DVec3::splat(f64::INFINITY);
        let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
        for corner in 0..8 {
            let pick = |bit: u32, a: f64, b: f64| if corner & bit == 0 { a } else { b };
            let c = glam::DVec3::new(pick(1, a.x, b.x), pick(2, a.y, b.y), pick(4, a.z, b.z));
            let p = transform.transform_point3(c);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    }

    /// Axis-aligned bounds `(min, max)` of the positions that triangles use.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for tri in &self.triangles {
            for &v in tri {
                let p = self.positions[v as usize];
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo, hi)
    }

    /// Concatenates meshes into one scene; ids of later meshes follow those of earlier ones.
    /// Outline masks and authored edges are kept where any mesh has them (the others
    /// allowing every outline, and drawing their polygon edges as authored ones).
    pub fn merge(meshes: &[Mesh]) -> Result<Mesh> {
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut triangles = Vec::new();
        let mut polygon_edges = Vec::new();
        let any_outline = meshes.iter().any(|m| m.outline_mask.is_some());
        let any_authored = meshes.iter().any(|m| m.authored_edges.is_some());
        let (mut outline, mut authored) = (Vec::new(), Vec::new());
        for m in meshes {
            let base = positions.len() as u32;
            positions.extend_from_slice(&m.positions);
            normals.extend_from_slice(&m.normals);
            triangles.extend(m.triangles.iter().map(|t| t.map(|v| v + base)));
            polygon_edges.extend_from_slice(&m.polygon_edges);
            if any_outline {
                outline.extend_from_slice(&m.outline_mask());
            }
            if any_authored {
                authored.extend_from_slice(m.authored_edges().unwrap_or(&m.polygon_edges));
            }
        }
        let mut merged = Mesh::new(positions, Some(normals), triangles, Some(polygon_edges))?;
        if any_outline {
            merged = merged.with_outline_mask(outline)?;
        }
        if any_authored {
            merged = merged.with_authored_edges(authored)?;
        }
        Ok(merged)
    }
}

/// Area-weighted vertex normals: each triangle adds its unnormalised cross product, whose
/// length is twice its area, to its three corners.
pub fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![glam::DVec3::ZERO; positions.len()];
    par::in_blocks(triangles.len(), |range| {
        for tri in &triangles[range] {
            let [a, b, c] = tri.map(|v| positions[v as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            for &v in tri {
                acc[v as usize] += n;
            }
        }
    });
    let mut normals = Vec::with_capacity(acc.len());
    par::in_blocks(acc.len(), |range| {
        normals.extend(
            acc[range]
                .iter()
                .map(|n| n.try_normalize().unwrap_or(glam::DVec3::ZERO).as_vec3()),
        )
    });
    normals
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        Mesh::new(
            p,
            None,
            vec![[0, 1, 2], [0, 2, 3]],
            Some(vec![0b011, 0b110]),
        )
        .unwrap()
    }

    /// Threads that prepare one mesh at once, each as an upload does (the crossings beside
    /// the adjacency, hints and clusters, on rayon's workers), all finish with the same
    /// records: none waits on a cache another fills while holding work that filling needs.
    #[test]
    fn threads_preparing_one_mesh_at_once_all_finish() {
        use std::sync::{mpsc, Arc};
        use std::time::Duration;
        for round in 0..8 {
            let mesh = Arc::new(procedural::sphere(20_000).unwrap());
            let (done, finished) = mpsc::channel();
            for _ in 0..3 {
                let (mesh, done) = (mesh.clone(), done.clone());
                std::thread::spawn(move || {
                    let (clusters, crossings) = par::join(
                        || {
                            mesh.edge_neighbours();
                            mesh.outline_hints();
                            mesh.traced_clusters().clone()
                        },
                        || mesh.intersections().len(),
                    );
                    let _ = done.send((clusters, crossings));
                });
            }
            let results: Vec<_> = (0..3)
                .map(|_| {
                    finished
                        .recv_timeout(Duration::from_secs(120))
                        .unwrap_or_else(|_| panic!("round {round}: a thread never finished"))
                })
                .collect();
            for (clusters, crossings) in &results {
                assert_eq!(clusters, mesh.traced_clusters());
                assert_eq!(*crossings, mesh.intersections().len());
            }
        }
    }

    #[test]
    fn smooth_normals_of_a_flat_quad_point_up() {
        for n in quad().normals() {
            assert!((*n - Vec3::Z).length() < 1e-6);
        }
    }

    #[test]
    fn rejects_bad_indices_and_nan() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(Mesh::new(p.clone(), None, vec![[0, 1, 3]], None).is_err());
        assert!(Mesh::new(p.clone(), None, vec![], None).is_err());
        let mut bad = p;
        bad[1].y = f32::NAN;
        assert!(Mesh::new(bad, None, vec![[0, 1, 2]], None).is_err());
    }

    #[test]
    fn one_triangle_s_mask_is_the_whole_mesh_s() {
        let sphere = procedural::sphere(500).unwrap();
        let scene = procedural::builtin_mesh();
        let authored = quad().with_authored_edges(vec![0b001, 0b110]).unwrap();
        for mesh in [&sphere, &scene, &authored] {
            for selection in [
                EdgeSelection::All,
                EdgeSelection::Polygon,
                EdgeSelection::Feature(15.0),
                EdgeSelection::Authored,
            ] {
                let whole = mesh.edge_mask(selection);
                for (t, &m) in whole.iter().enumerate() {
                    assert_eq!(
                        mesh.triangle_edge_mask(t, selection),
                        m,
                        "{selection:?} {t}"
                    );
                }
            }
        }
    }

    #[test]
    fn feature_edges_of_a_folded_quad() {
        // Two triangles folded 90 degrees along their shared edge (0-2 / 2-0).
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let m = Mesh::new(p, None, vec![[0, 1, 2], [2, 3, 0]], None).unwrap();
        // Shared edge: triangle 0 edge 2 (2->0), triangle 1 edge 2 (0->2).
        assert_eq!(
            m.edge_mask(EdgeSelection::Feature(30.0)),
            vec![0b111, 0b111]
        );
        assert_eq!(
            m.edge_mask(EdgeSelection::Feature(95.0)),
            vec![0b011, 0b011]
        );
        // A flat quad's diagonal is never a feature.
        assert_eq!(
            quad().edge_mask(EdgeSelection::Feature(0.5)),
            vec![0b011, 0b110]
        );
    }

    #[test]
    fn parses_edge_selections() {
        assert_eq!("all".parse::<EdgeSelection>().unwrap(), EdgeSelection::All);
        assert_eq!(
            "feature".parse::<EdgeSelection>().unwrap(),
            EdgeSelection::Feature(1.0)
        );
        assert_eq!(
            "feature:30".parse::<EdgeSelection>().unwrap(),
            EdgeSelection::Feature(30.0)
        );
        assert_eq!(
            "authored".parse::<EdgeSelection>().unwrap(),
            EdgeSelection::Authored
        );
        for bad in [
            "",
            "feature:",
            "feature:-1",
            "feature:200",
            "features",
            "polygon:3",
        ] {
            assert!(bad.parse::<EdgeSelection>().is_err(), "{bad}");
        }
    }

    #[test]
    fn authored_edges_and_their_outline_mask_go_together() {
        // Without authored edges, Authored is Polygon and nothing is asked of the mask.
        assert_eq!(
            quad().edge_mask(EdgeSelection::Authored),
            vec![0b011, 0b110]
        );
        let (_, edges) = quad().resolve_edges(None);
        assert_eq!(edges, EdgeSelection::Polygon);
        let authored = || {
            quad()
                .with_authored_edges(vec![0b001, 0b100])
                .and_then(|m| m.with_outline_mask(vec![0b011, 0b100]))
                .unwrap()
        };
        assert_eq!(
            authored().edge_mask(EdgeSelection::Authored),
            vec![0b001, 0b100]
        );
        let (m, edges) = authored().resolve_edges(None);
        assert_eq!(edges, EdgeSelection::Authored);
        assert_eq!(m.outline_mask().to_vec(), vec![0b011, 0b100]);
        let (m, edges) = authored().resolve_edges(Some(EdgeSelection::All));
        assert_eq!(edges, EdgeSelection::All);
        assert_eq!(
            m.outline_mask().to_vec(),
            vec![ALL_EDGES; 2],
            "the mask is dropped"
        );
        // Kept by the caller: borrowed unless the mask is dropped, then a copy without it.
        let kept = authored();
        let (m, edges) = kept.resolved_edges(None);
        assert!(matches!(m, Cow::Borrowed(_)));
        assert_eq!(edges, EdgeSelection::Authored);
        let (m, edges) = kept.resolved_edges(Some(EdgeSelection::All));
        assert_eq!(edges, EdgeSelection::All);
        assert_eq!(m.outline_mask().to_vec(), vec![ALL_EDGES; 2]);
        assert_eq!(kept.outline_mask().to_vec(), vec![0b011, 0b100]);
        // Without a mask there is nothing to drop: no copy.
        let plain = quad();
        let (m, _) = plain.resolved_edges(Some(EdgeSelection::All));
        assert!(matches!(m, Cow::Borrowed(_)));
        // Merging keeps both, the plain quad drawing its polygon edges.
        let merged = Mesh::merge(&[authored(), quad()]).unwrap();
        assert_eq!(
            merged.edge_mask(EdgeSelection::Authored),
            vec![0b001, 0b100, 0b011, 0b110]
        );
        assert_eq!(merged.outline_mask().to_vec(), vec![0b011, 0b100, 7, 7]);
        assert!(quad().with_authored_edges(vec![1]).is_err());
    }

    #[test]
    fn merge_offsets_indices() {
        let m = Mesh::merge(&[quad(), quad()]).unwrap();
        assert_eq!(m.triangles()[2], [4, 5, 6]);
        assert_eq!(
            m.edge_mask(EdgeSelection::Polygon),
            vec![0b011, 0b110, 0b011, 0b110]
        );
        assert_eq!(m.edge_mask(EdgeSelection::All), vec![ALL_EDGES; 4]);
    }
}
