//! Procedural meshes of any size, for tests, benchmarks and the built-in scene. Sphere and
//! torus use Y, the camera's up axis, as their axis. Quads are split into two triangles whose
//! shared diagonal is masked out, so polygon mode draws the quads.

use super::{Mesh, ALL_EDGES};
use crate::error::{Error, Result};
use glam::{Quat, Vec3};
use std::f64::consts::{PI, TAU};
use std::fmt;
use std::str::FromStr;

/// Largest triangle count a generator accepts, to fail cleanly instead of exhausting memory.
const MAX_TRIANGLES: usize = 200_000_000;

/// Torus radii: of the centre circle of the tube, and of the tube.
const MAJOR_RADIUS: f64 = 1.0;
const MINOR_RADIUS: f64 = 0.35;

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// A procedural mesh named on the command line as `sphere:N`, `grid:N`, `torus:N` or `cube:N`, where
/// `N` is the approximate triangle count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Procedural {
    /// [`sphere`] with about this many triangles.
    Sphere(usize),
    /// [`grid`] with about this many triangles.
    Grid(usize),
    /// [`torus`] with about this many triangles.
    Torus(usize),
    /// [`layers`]: this many parallel grids one behind the other (depth complexity).
    Layers(usize),
    /// [`cube`] with about this many triangles.
    Cube(usize),
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// Triangles in each grid of [`layers`] (8 × 8 quads).
pub const LAYER_TRIANGLES: usize = 128;

impl Procedural {
    /// Builds the mesh.
    pub fn build(&self) -> Result<Mesh> {
        match *self {
            Procedural::Sphere(n) => sphere(n),
            Procedural::Grid(n) => grid(n),
            Procedural::Torus(n) => torus(n),
            Procedural::Layers(k) => layers(k),
            Procedural::Cube(n) => cube(n),
        }
    }

    /// The requested triangle count; the mesh has about this many.
    pub fn triangle_target(&self) -> usize {
        match *self {
            Procedural::Sphere(n)
            | Procedural::Grid(n)
            | Procedural::Torus(n)
            | Procedural::Cube(n) => n,
            Procedural::Layers(k) => k.saturating_mul(LAYER_TRIANGLES),
        }
    }

    /// The number after the colon: a triangle count, or for `layers` the layer count.
    fn parameter(&self) -> usize {
        match *self {
            Procedural::Sphere(n)
            | Procedural::Grid(n)
            | Procedural::Torus(n)
            | Procedural::Layers(n)
            | Procedural::Cube(n) => n,
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Procedural::Sphere(_) => "sphere",
            Procedural::Grid(_) => "grid",
            Procedural::Torus(_) => "torus",
            Procedural::Layers(_) => "layers",
            Procedural::Cube(_) => "cube",
        }
    }

    /// Smallest triangle count the shape can be built with.
    fn min_triangles(&self) -> usize {
        match self {
            Procedural::Sphere(_) => 8,
            Procedural::Grid(_) => 2,
            Procedural::Torus(_) => 18,
            Procedural::Layers(_) => LAYER_TRIANGLES,
            Procedural::Cube(_) => 12,
        }
    }

    fn check(&self) -> Result<()> {
        let (n, min) = (self.triangle_target(), self.min_triangles());
        if (min..=MAX_TRIANGLES).contains(&n) {
            return Ok(());
        }
        Err(Error::InvalidSetting(format!(
            "{self} asks for {n} triangles; a {} needs {min} to {MAX_TRIANGLES}",
            self.name()
        )))
    }
}

impl fmt::Display for Procedural {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.name(), self.parameter())
    }
}

impl FromStr for Procedural {
    type Err = Error;

    /// Parses `sphere:N`, `grid:N`, `torus:N`, `cube:N` (N triangles) or `layers:K` (K layers); the
    /// number may use `_` separators and a `k` (thousand) or `M` (million) suffix, as in
    /// `sphere:20M` or `grid:1_000`.
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            Error::InvalidSetting(format!(
                "'{s}' is not a procedural mesh; expected sphere:N, grid:N, torus:N or cube:N with \
                 N a triangle count such as 5000, 20_000, 50k or 20M, or layers:K"
            ))
        };
        let (shape, count) = s.trim().split_once(':').ok_or_else(bad)?;
        let n = parse_count(count).ok_or_else(bad)?;
        let p = match shape.trim().to_ascii_lowercase().as_str() {
            "sphere" => Procedural::Sphere(n),
            "grid" => Procedural::Grid(n),
            "torus" => Procedural::Torus(n),
            "layers" => Procedural::Layers(n),
            "cube" => Procedural::Cube(n),
            _ => return Err(bad()),
        };
        p.check()?;
        Ok(p)
    }
}

/// `1_000` → 1000, `50k` → 50 000, `20M` → 20 000 000; `None` if malformed or overflowing.
fn parse_count(s: &str) -> Option<usize> {
    let s: String = s.trim().chars().filter(|&c| c != '_').collect();
    let (digits, scale) = if let Some(d) = s.strip_suffix(['k', 'K']) {
        (d, 1_000)
    } else if let Some(d) = s.strip_suffix('M') {
        (d, 1_000_000)
    } else {
        (s.as_str(), 1)
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse::<usize>().ok()?.checked_mul(scale)
}

/// A UV sphere of radius 1 at the origin with poles on ±Y and about `n` triangles: `stacks`
/// latitude bands of `slices ≈ 2 × stacks` segments, `2 × slices × (stacks − 1)` triangles.
/// Normals are exact. The bands are quads, the caps at the poles triangles.
pub fn sphere(n: usize) -> Result<Mesh> {
    Procedural::Sphere(n).check()?;
    let stacks = (((1.0 + (1.0 + n as f64).sqrt()) / 2.0).round() as usize).max(2);
    let slices = ((n as f64 / (2 * (stacks - 1)) as f64).round() as usize).max(3);
    uv_sphere(stacks, slices).into_mesh()
}

/// A flat square grid over [-1, 1]² in the XY plane, facing +Z, of `k × k` square cells with
/// `2k²` as close to `n` as possible; the cells' diagonals are masked out.
pub fn grid(n: usize) -> Result<Mesh> {
    Procedural::Grid(n).check()?;
    let k = ((n as f64 / 2.0).sqrt().round() as usize).max(1);
    let mut parts = Parts::with_capacity((k + 1) * (k + 1), 2 * k * k);
    let step = 2.0 / k as f64;
    for j in 0..=k {
        for i in 0..=k {
            let p = Vec3::new(
                (i as f64 * step - 1.0) as f32,
                (j as f64 * step - 1.0) as f32,
                0.0,
            );
            parts.vertex(p, Vec3::Z);
        }
    }
    let v = |i: usize, j: usize| (j * (k + 1) + i) as u32;
    for j in 0..k {
        for i in 0..k {
            parts.quad([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    parts.into_mesh()
}

/// The cube [-1, 1]³ with each face a `k × k` grid of square quads (diagonals masked), `12k²`
/// triangles as close to `n` as possible, flat normals: a tessellated CAD part, whose
/// feature edges are its 12 creases, each made of many small triangles' edges.
pub fn cube(n: usize) -> Result<Mesh> {
    Procedural::Cube(n).check()?;
    let k = ((n as f64 / 12.0).sqrt().round() as usize).max(1);
    let mut parts = Parts::with_capacity(6 * (k + 1) * (k + 1), 12 * k * k);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            // Face normal along `axis`; (u, v, normal) right-handed, so quads face outwards.
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
            u[(axis + 1) % 3] = 1.0;
            v[(axis + 2) % 3] = sign;
            let base = parts.positions.len() as u32;
            for j in 0..=k {
                for i in 0..=k {
                    let a = (2.0 * i as f64 / k as f64 - 1.0) as f32;
                    let b = (2.0 * j as f64 / k as f64 - 1.0) as f32;
                    parts.vertex(normal + u * a + v * b, normal);
                }
            }
            let at = |i: usize, j: usize| base + (j * (k + 1) + i) as u32;
            for j in 0..k {
                for i in 0..k {
                    parts.quad([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    parts.into_mesh()
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// `k` square 8 × 8-quad grids over [-1, 1]² parallel to the XY plane, one behind the other
/// between z = 0 and z = −1: every pixel that sees the stack has depth complexity up to `k`,
/// for measuring how methods cope with overdraw.
pub fn layers(k: usize) -> Result<Mesh> {
    Procedural::Layers(k).check()?;
    const CELLS: usize = 8;
    let mut parts = Parts::with_capacity(k * (CELLS + 1) * (CELLS + 1), k * LAYER_TRIANGLES);
    let step = 2.0 / CELLS as f64;
    for layer in 0..k {
        let z = -(layer as f64) / k as f64;
        let base = (layer * (CELLS + 1) * (CELLS + 1)) as u32;
        for j in 0..=CELLS {
            for i in 0..=CELLS {
                let x = i as f64 * step - 1.0;
                let y = j as f64 * step - 1.0;
                parts.vertex(Vec3::new(x as f32, y as f32, z as f32), Vec3::Z);
            }
        }
        let v = |i: usize, j: usize| base + (j * (CELLS + 1) + i) as u32;
        for j in 0..CELLS {
            for i in 0..CELLS {
                parts.quad([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
    }
    parts.into_mesh()
}

/// A torus around the Y axis (lying in the XZ plane) with major radius 1 and minor radius
/// 0.35, made of quads (diagonals masked) with about `n` triangles: the ring has about three
/// times as many segments as the tube, so the quads are roughly square. Normals are exact.
pub fn torus(n: usize) -> Result<Mesh> {
    Procedural::Torus(n).check()?;
    let minor = ((n as f64 / 6.0).sqrt().round() as usize).max(3);
    let major = ((n as f64 / (2 * minor) as f64).round() as usize).max(3);
    torus_parts(major, minor).into_mesh()
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The built-in scene, drawn when no mesh is given, as one mesh: a torus of 3 072
/// triangles, tilted towards the default camera, whose quads show polygon mode, beside a
/// small UV sphere whose pole caps are fans of thin triangles.
pub fn builtin_mesh() -> Mesh {
    let tilt = Quat::from_rotation_x(40f32.to_radians());
    let mut scene = torus_parts(64, 24).transformed(tilt, 1.0, Vec3::ZERO);
    scene.append(uv_sphere(10, 20).transformed(tilt, 0.5, Vec3::new(2.0, 0.0, 0.0)));
    // Built directly rather than through `Mesh::new`, which cannot fail on these constant
    // inputs (the test `builtin_mesh_is_a_valid_mesh` checks it) but returns a Result.
    Mesh {
        positions: scene.positions,
        normals: scene.normals,
        triangles: scene.triangles,
        polygon_edges: scene.edges,
        outline_mask: None,
        authored_edges: None,
        weld: Default::default(),
        neighbours: Default::default(),
        outline_hints: Default::default(),
        traced_clusters: Default::default(),
        crossings: Default::default(),
        star: Default::default(),
    }
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// The built-in scene's two meshes with their placements: the torus of [`builtin_mesh`],
/// tilted 40° about X, and its unit sphere, tilted, halved and moved 2 along X.
pub fn default_parts() -> Result<[(Mesh, glam::DMat4); 2]> {
    use glam::{DMat4, DQuat, DVec3};
    let tilt = DQuat::from_rotation_x(40f64.to_radians());
    Ok([
        (torus_parts(64, 24).into_mesh()?, DMat4::from_quat(tilt)),
        (
            uv_sphere(10, 20).into_mesh()?,
            DMat4::from_scale_rotation_translation(
                DVec3::splat(0.5),
                tilt,
                DVec3::new(2.0, 0.0, 0.0),
            ),
        ),
    ])
}

/// Vertex and triangle buffers that a generator fills before they become a [`Mesh`].
struct Parts {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    edges: Vec<u8>,
}

impl Parts {
    fn with_capacity(vertices: usize, triangles: usize) -> Self {
        Parts {
            positions: Vec::with_capacity(vertices),
            normals: Vec::with_capacity(vertices),
            triangles: Vec::with_capacity(triangles),
            edges: Vec::with_capacity(triangles),
        }
    }

    fn vertex(&mut self, position: Vec3, normal: Vec3) {
        self.positions.push(position);
        self.normals.push(normal);
    }

    fn triangle(&mut self, t: [u32; 3]) {
        self.triangles.push(t);
        self.edges.push(ALL_EDGES);
    }

    /// Splits the quad `a b c d` (counter-clockwise seen from outside) along `a–c`, the
    /// diagonal that is masked out: edges 0, 1 of `a b c` and 1, 2 of `a c d` are the quad's.
    fn quad(&mut self, [a, b, c, d]: [u32; 4]) {
        self.triangles.extend([[a, b, c], [a, c, d]]);
        self.edges.extend([0b011, 0b110]);
    }

    fn transformed(mut self, rotation: Quat, scale: f32, offset: Vec3) -> Self {
        for p in &mut self.positions {
            *p = rotation * (*p * scale) + offset;
        }
        for n in &mut self.normals {
            *n = rotation * *n;
        }
        self
    }

    fn append(&mut self, other: Parts) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.triangles
            .extend(other.triangles.into_iter().map(|t| t.map(|v| v + base)));
        self.edges.extend(other.edges);
    }

    fn into_mesh(self) -> Result<Mesh> {
        Mesh::new(
            self.positions,
            Some(self.normals),
            self.triangles,
            Some(self.edges),
        )
    }
}

/// Unit UV sphere around Y with `stacks ≥ 2` bands and `slices ≥ 3` segments; the poles are
/// single vertices, so the seam needs no duplicates.
fn uv_sphere(stacks: usize, slices: usize) -> Parts {
    let rings = stacks - 1;
    let mut parts = Parts::with_capacity(2 + rings * slices, 2 * slices * rings);
    let azimuth: Vec<(f64, f64)> = (0..slices)
        .map(|j| (TAU * j as f64 / slices as f64).sin_cos())
        .collect();
    parts.vertex(Vec3::Y, Vec3::Y);
    for k in 1..stacks {
        let (sin_p, cos_p) = (PI * k as f64 / stacks as f64).sin_cos();
        for &(sin_a, cos_a) in &azimuth {
            let p = Vec3::new((sin_p * sin_a) as f32, cos_p as f32, (sin_p * cos_a) as f32);
            parts.vertex(p, p);
        }
    }
    parts.vertex(Vec3::NEG_Y, Vec3::NEG_Y);
    let south = (1 + rings * slices) as u32;
    // Vertex `j` (wrapping) of ring `k`, counted from the north pole.
    let v = |k: usize, j: usize| (1 + (k - 1) * slices + j % slices) as u32;
    for j in 0..slices {
        parts.triangle([0, v(1, j), v(1, j + 1)]);
    }
    for k in 1..rings {
        for j in 0..slices {
            parts.quad([v(k, j), v(k + 1, j), v(k + 1, j + 1), v(k, j + 1)]);
        }
    }
    for j in 0..slices {
        parts.triangle([v(rings, j), south, v(rings, j + 1)]);
    }
    parts
}

/// Torus around Y with `major` segments around the ring and `minor` around the tube.
fn torus_parts(major: usize, minor: usize) -> Parts {
    let mut parts = Parts::with_capacity(major * minor, 2 * major * minor);
    let tube: Vec<(f64, f64)> = (0..minor)
        .map(|j| (TAU * j as f64 / minor as f64).sin_cos())
        .collect();
    for i in 0..major {
        let (sin_a, cos_a) = (TAU * i as f64 / major as f64).sin_cos();
        for &(sin_t, cos_t) in &tube {
            let r = MAJOR_RADIUS + MINOR_RADIUS * cos_t;
            let p = Vec3::new(
                (r * sin_a) as f32,
                (MINOR_RADIUS * sin_t) as f32,
                (r * cos_a) as f32,
            );
            let n = Vec3::new((cos_t * sin_a) as f32, sin_t as f32, (cos_t * cos_a) as f32);
            parts.vertex(p, n);
        }
    }
    let v = |i: usize, j: usize| ((i % major) * minor + j % minor) as u32;
    for i in 0..major {
        for j in 0..minor {
            parts.quad([v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::EdgeSelection;

    /// Every triangle faces the way its vertex normals point, and the normals are unit.
    fn check_normals_and_winding(m: &Mesh) {
        for n in m.normals() {
            assert!((n.length() - 1.0).abs() < 1e-5, "{n}");
        }
        for t in m.triangles() {
            let [a, b, c] = t.map(|v| m.positions()[v as usize]);
            let face = (b - a).cross(c - a);
            let normal: Vec3 = t.iter().map(|&v| m.normals()[v as usize]).sum();
            assert!(face.dot(normal) > 0.0, "triangle {t:?} faces inward");
        }
    }

    #[test]
    fn counts_are_near_the_request() {
        for n in [1000, 20_000] {
            for p in [
                Procedural::Sphere(n),
                Procedural::Grid(n),
                Procedural::Torus(n),
            ] {
                let m = p.build().unwrap();
                let got = m.triangle_count() as f64;
                assert!((got / n as f64 - 1.0).abs() < 0.1, "{p}: {got}");
                check_normals_and_winding(&m);
            }
        }
    }

    #[test]
    fn shapes_have_their_size_and_normals() {
        let s = sphere(5000).unwrap();
        for (p, n) in s.positions().iter().zip(s.normals()) {
            assert!((p.length() - 1.0).abs() < 1e-6 && (*p - *n).length() < 1e-6);
        }
        let g = grid(200).unwrap();
        assert_eq!(
            g.bounds(),
            (Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0))
        );
        assert!(g.normals().iter().all(|&n| n == Vec3::Z));
        let t = torus(3000).unwrap();
        for (p, n) in t.positions().iter().zip(t.normals()) {
            // The tube's centre lies on the unit circle in XZ, 0.35 back along the normal.
            let centre = *p - *n * MINOR_RADIUS as f32;
            assert!(centre.y.abs() < 1e-5 && (centre.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn quads_mask_their_diagonals() {
        // A 2 × 2 grid: 8 triangles, each with one masked edge; 12 unit-length quad edges.
        let g = grid(8).unwrap();
        let mask = g.edge_mask(EdgeSelection::Polygon);
        assert_eq!(mask.len(), 8);
        for (t, m) in g.triangles().iter().zip(&mask) {
            assert_eq!(m.count_ones(), 2);
            for k in 0..3 {
                let [a, b] = [t[k], t[(k + 1) % 3]].map(|v| g.positions()[v as usize]);
                let diagonal = ((a - b).length() - 2f32.sqrt()).abs() < 1e-6;
                assert_eq!(m & 1 << k == 0, diagonal);
            }
        }
        let s = sphere(8).unwrap();
        assert_eq!(s.edge_mask(EdgeSelection::Polygon), vec![ALL_EDGES; 8]);
        let t = torus(18).unwrap();
        let cleared: u32 = t
            .edge_mask(EdgeSelection::Polygon)
            .iter()
            .map(|m| 3 - m.count_ones())
            .sum();
        assert_eq!((t.triangle_count(), cleared), (18, 18));
    }

    #[test]
    fn builtin_mesh_is_a_valid_mesh() {
        let m = builtin_mesh();
        assert_eq!(m.triangle_count(), 2 * 64 * 24 + 2 * 20 * 9);
        check_normals_and_winding(&m);
        let checked = Mesh::new(
            m.positions().to_vec(),
            Some(m.normals().to_vec()),
            m.triangles().to_vec(),
            Some(m.edge_mask(EdgeSelection::Polygon)),
        )
        .unwrap();
        for (a, b) in checked.normals().iter().zip(m.normals()) {
            assert!(a.abs_diff_eq(*b, 1e-6), "normals are unit already");
        }
    }

    #[test]
    fn layers_stack_grids_one_behind_the_other() {
        let m = layers(4).unwrap();
        assert_eq!(m.triangle_count(), 4 * LAYER_TRIANGLES);
        assert_eq!(Procedural::Layers(4).triangle_target(), m.triangle_count());
        let (lo, hi) = m.bounds();
        assert_eq!((lo.z, hi.z), (-0.75, 0.0));
        // Quads: each grid shows its 8 x 8 cells, no diagonals.
        let drawn: u32 = m
            .edge_mask(crate::mesh::EdgeSelection::Polygon)
            .iter()
            .map(|b| b.count_ones())
            .sum();
        // Two drawn edges per triangle: each quad's diagonal is masked.
        assert_eq!(drawn as usize, 2 * 4 * LAYER_TRIANGLES);
    }

    #[test]
    fn a_cube_is_closed_and_its_creases_are_its_feature_edges() {
        let mesh = cube(12 * 16).unwrap();
        assert_eq!(mesh.triangle_count(), 12 * 16);
        assert!(mesh
            .edge_neighbours()
            .iter()
            .flatten()
            .all(|&n| n != crate::mesh::adjacency::NO_NEIGHBOUR));
        let drawn = |edges| -> u32 { mesh.edge_mask(edges).iter().map(|b| b.count_ones()).sum() };
        // 12 creases of 4 segments, each drawn from both sides.
        assert_eq!(drawn(crate::mesh::EdgeSelection::Feature(30.0)), 12 * 4 * 2);
        assert_eq!(drawn(crate::mesh::EdgeSelection::Polygon), 2 * 12 * 16);
        // Faces wind outwards: each face normal points away from the centre.
        for t in mesh.triangles() {
            let [a, b, c] = t.map(|v| mesh.positions()[v as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }

    #[test]
    fn parses_procedural_names() {
        let ok = [
            ("sphere:20M", Procedural::Sphere(20_000_000)),
            ("grid:1_000", Procedural::Grid(1000)),
            ("torus:50k", Procedural::Torus(50_000)),
            (" Sphere:1_5K ", Procedural::Sphere(15_000)),
            ("layers:16", Procedural::Layers(16)),
            ("cube:2M", Procedural::Cube(2_000_000)),
        ];
        for (s, p) in ok {
            assert_eq!(s.parse::<Procedural>().unwrap(), p, "{s}");
            assert_eq!(p.to_string().parse::<Procedural>().unwrap(), p);
        }
        assert_eq!(Procedural::Grid(1000).triangle_target(), 1000);
        for s in [
            "",
            "sphere",
            "sphere:",
            "box:100",
            "cube:11",
            "sphere:-5",
            "sphere:1.5M",
            "sphere:12q",
            "sphere:_",
            "grid:+100",
            "sphere:4",
            "torus:10",
            "sphere:99999999999999999999",
            "sphere:1000000M",
            "sphere:20m",
            "layers:0",
        ] {
            let e = s.parse::<Procedural>().unwrap_err();
            assert!(matches!(e, Error::InvalidSetting(_)), "{s}: {e:?}");
        }
        let e = "box:100".parse::<Procedural>().unwrap_err().to_string();
        assert!(e.contains("sphere:N, grid:N, torus:N or cube:N"), "{e}");
        assert!(sphere(7).is_err() && grid(1).is_err() && torus(17).is_err());
        assert!(sphere(8).is_ok() && grid(2).is_ok() && torus(18).is_ok());
    }
}
