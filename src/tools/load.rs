//! Scenes from what a person names: a mesh file, a scene file, a glTF scene, a procedural
//! mesh or the built-in scene; image sizes and vectors from text; the camera placed from
//! the values given and the scene's bounds.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::{Camera, View};
use crate::error::{Error, Result};
use crate::mesh::{self, EdgeSelection, Mesh, Procedural};
use crate::tools::scene_file::{FileCamera, FileStyle};
use crate::world::World;
use glam::{DVec3, Vec3};
use std::path::Path;

/// Loads one mesh from `spec`: a procedural name (`sphere:N`, `grid:N`, `torus:N`, `cube:N`,
/// `layers:K`), a mesh file (OBJ, STL, PLY or glTF, by extension: see [`mesh::load`]), or,
/// when `None`, the built-in default scene as one mesh.
pub fn load_mesh(spec: Option<&str>) -> Result<Mesh> {
    match spec {
        None => Ok(mesh::builtin_mesh()),
        Some(s) => mesh_spec(s),
    }
}

/// A procedural name or a mesh file.
fn mesh_spec(s: &str) -> Result<Mesh> {
    if !Path::new(s).exists() && s.contains(':') && !s.contains(['/', '\\']) {
        return s.parse::<Procedural>()?.build();
    }
    mesh::load(Path::new(s))
}

/// What the command line asks of the scene it loads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorldOptions {
    /// `--edges`: the edges to draw; `None` draws a file's own edges where it has them
    /// (glTF edge extensions), else polygon edges.
    pub edges: Option<EdgeSelection>,
    /// `--camera N`: the file's N-th camera (a glTF file's, in node order, or a scene
    /// file's only one); `None` takes the first the file has, if any.
    pub camera: Option<usize>,
    /// `--line-width`, when given: it overrides the widths a glTF file gives its meshes
    /// (a scene file's per-object widths still override it, as they say).
    pub line_width: Option<f32>,
}

/// A loaded scene: the world, the file's camera (the one picked), and notes on what the
/// file had that is not drawn, for stderr.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The meshes and objects.
    pub world: World,
    /// The file's camera, if it has one.
    pub camera: Option<FileCamera>,
    /// Notes from the loader (glTF: skipped primitives, unused cameras, …).
    pub notes: Vec<String>,
    /// A scene file's frame style (empty for other files).
    pub style: FileStyle,
    /// The objects a scene file highlights (`"highlight": true`), in order.
    pub highlight: Vec<usize>,
}

/// Loads what `spec` names as a world: a scene file (`.json`, with its camera if it has
/// one), a glTF file (`.gltf`, `.glb`: its scene, every mesh once and placed by its nodes,
/// and its cameras), one mesh (procedural or another mesh file), or, when `None`, the
/// built-in scene (a torus and a sphere). An out-of-range `options.camera` is an error.
pub fn load_world(spec: Option<&str>, options: &WorldOptions) -> Result<Loaded> {
    let edges = options.edges;
    let lower = spec.map(str::to_ascii_lowercase).unwrap_or_default();
    let mut style = FileStyle::default();
    let mut highlight = Vec::new();
    let (world, cameras, notes) = match spec {
        None => (
            crate::world::default_world(edges.unwrap_or_default()),
            Vec::new(),
            Vec::new(),
        ),
        Some(s) if lower.ends_with(".json") => {
            let file = crate::tools::scene_file::load_scene(Path::new(s), edges, &mesh_spec)?;
            style = file.style;
            highlight = file.highlight;
            (file.world, file.camera.into_iter().collect(), Vec::new())
        }
        Some(s) if lower.ends_with(".gltf") || lower.ends_with(".glb") => {
            let doc = mesh::formats::gltf::load_gltf(Path::new(s))?;
            let cameras = doc.cameras.iter().map(|&c| FileCamera::Gltf(c)).collect();
            let notes = doc.notes.clone();
            let mut world = World::from_gltf(doc, edges);
            if options.line_width.is_some() {
                for o in &mut world.objects {
                    o.style.line_width = None;
                }
            }
            (world, cameras, notes)
        }
        Some(s) => {
            let (mesh, edges) = mesh_spec(s)?.resolve_edges(edges);
            (World::single(mesh, edges), Vec::new(), Vec::new())
        }
    };
    let camera = match options.camera {
        None => cameras.first().copied(),
        Some(n) => Some(*cameras.get(n).ok_or_else(|| {
            let name = spec.unwrap_or("the built-in scene");
            Error::InvalidSetting(match cameras.len() {
                0 => format!("--camera {n}: {name} has no cameras"),
                1 => format!("--camera {n}: {name} has one camera, --camera 0"),
                k => format!("--camera {n}: {name} has {k} cameras, 0 to {}", k - 1),
            })
        })?),
    };
    Ok(Loaded {
        world,
        camera,
        notes,
        style,
        highlight,
    })
}

/// Parses `WxH`.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::InvalidSetting(format!("size {s:?} is not WIDTHxHEIGHT, e.g. 640x480"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 {
        return Err(Error::InvalidSetting(format!("size {s:?} has a zero side")));
    }
    Ok((w, h))
}

/// Parses `x,y,z`.
pub fn parse_vec3(s: &str) -> Result<Vec3> {
    let bad = || Error::InvalidSetting(format!("{s:?} is not three numbers x,y,z"));
    let v: Vec<f32> = crate::style::comma_separated(s, bad)?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

/// Where the camera goes, as a person gives it (the CLI's camera options): unset values
/// come from the automatic framing.
#[derive(Clone, Debug, Default)]
pub struct CameraPlacement {
    /// Eye position x,y,z; without it the camera frames the mesh automatically.
    pub eye: Option<Vec3>,
    /// Point looked at, x,y,z (default: centre of the mesh bounds).
    pub target: Option<Vec3>,
    /// Up direction x,y,z (default 0,1,0).
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees (default 40).
    pub fov: Option<f32>,
    /// Near plane distance.
    pub near: Option<f32>,
    /// Far plane distance.
    pub far: Option<f32>,
    /// Use the file's N-th camera (a glTF file's, counting from 0 in node order); without
    /// it and the options above, the file's first camera, if it has one.
    pub camera: Option<usize>,
}

impl CameraPlacement {
    /// True when no camera placement option (eye, target, up, fov, near, far) is given.
    pub fn is_empty(&self) -> bool {
        self.eye.is_none()
            && self.target.is_none()
            && self.up.is_none()
            && self.fov.is_none()
            && self.near.is_none()
            && self.far.is_none()
    }

    /// The view of `world` at `size`: the options given, else the scene file's camera, else
    /// a camera framing the world.
    pub fn view(&self, world: &World, file: Option<&FileCamera>, size: (u32, u32)) -> Result<View> {
        let aspect = f64::from(size.0) / f64::from(size.1);
        let view = match file {
            Some(c) if self.is_empty() => c.view(aspect),
            _ => self.camera(world.bounds(), size)?.to_view(aspect),
        };
        view.validate()?;
        Ok(view)
    }

    /// The perspective camera for a world with bounds `(lo, hi)` at `size`: explicit values
    /// where given, framing otherwise. With an explicit eye, near and far default to values
    /// that enclose the world.
    pub fn camera(&self, (lo, hi): (DVec3, DVec3), size: (u32, u32)) -> Result<Camera> {
        // Finite coordinates can still span more than f32 holds; framing such a world would
        // overflow to an infinite eye, which the camera check reports in confusing terms.
        if !((hi - lo).length() <= f64::from(f32::MAX)) {
            return Err(Error::InvalidMesh(format!(
                "the scene spans {lo} to {hi}, more than f32 coordinates can hold"
            )));
        }
        let framed = Camera::framing(lo, hi, f64::from(size.0) / f64::from(size.1));
        let mut cam = framed;
        if let Some(eye) = self.eye {
            cam.eye = eye;
            cam.target = self.target.unwrap_or(framed.target);
            // Near and far that enclose the world seen from this eye, in f64: the squares in
            // an f32 length overflow for a far eye such as 1e30,1e30,1e30.
            let radius = (hi - lo).length() * 0.5;
            let dist = ((lo + hi) * 0.5 - eye.as_dvec3()).length();
            let far = (dist + radius) * 1.5 + 1e-3 * radius.max(f64::MIN_POSITIVE);
            cam.far = far as f32;
            cam.near = ((dist - radius).max(far * 1e-5) * 0.5) as f32;
        } else if let Some(target) = self.target {
            cam.eye += target - cam.target;
            cam.target = target;
        }
        if let Some(up) = self.up {
            cam.up = up;
        }
        if let Some(fov) = self.fov {
            cam.fov_y_deg = fov;
        }
        if let Some(near) = self.near {
            cam.near = near;
        }
        if let Some(far) = self.far {
            cam.far = far;
        }
        cam.validate()?;
        Ok(cam)
    }
}

/// The orthographic views of technical drawings, each named for where it looks from (y is
/// up): `front` (+z), `back`, `top` (+y, with −z up), `bottom`, `right` (+x), `left`, and
/// `iso` (from +x, +y, +z).
pub const NAMED_VIEWS: [&str; 7] = ["front", "back", "top", "bottom", "right", "left", "iso"];

/// The orthographic view `name` (one of [`NAMED_VIEWS`]) of the whole of `world` at `size`:
/// its bounds' corners fill the image less a 5 % margin.
pub fn named_view(world: &World, name: &str, size: (u32, u32)) -> Result<View> {
    let (towards, up) = match name {
        "front" => (DVec3::Z, DVec3::Y),
        "back" => (DVec3::NEG_Z, DVec3::Y),
        "top" => (DVec3::Y, DVec3::NEG_Z),
        "bottom" => (DVec3::NEG_Y, DVec3::Z),
        "right" => (DVec3::X, DVec3::Y),
        "left" => (DVec3::NEG_X, DVec3::Y),
        "iso" => (DVec3::ONE.normalize(), DVec3::Y),
        _ => {
            return Err(Error::InvalidSetting(format!(
                "view {name:?} is not one of {}",
                NAMED_VIEWS.join(", ")
            )))
        }
    };
    let (lo, hi) = world.bounds();
    let span = (hi - lo).length();
    if !(span.is_finite() && span > 0.0) {
        return Err(Error::InvalidScene(format!(
            "the scene spans {lo} to {hi}: no view frames it"
        )));
    }
    let centre = 0.5 * (lo + hi);
    let right = up.cross(towards).normalize();
    let up = towards.cross(right);
    let corners = (0..8).map(|k| {
        let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
        DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        ) - centre
    });
    let (half_x, half_y) = corners.fold((0.0f64, 0.0f64), |(x, y), c| {
        (x.max(c.dot(right).abs()), y.max(c.dot(up).abs()))
    });
    let aspect = f64::from(size.0) / f64::from(size.1);
    let height = 2.0 * half_y.max(half_x / aspect).max(1e-9 * span) * 1.05;
    let eye = centre + towards * span;
    let view = View::orthographic((eye, centre, up), height, aspect, (0.0, 2.0 * span));
    view.validate()?;
    Ok(view)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_named_view_frames_the_world_from_its_side() {
        let world = crate::world::default_world(crate::EdgeSelection::All);
        let (lo, hi) = world.bounds();
        for name in NAMED_VIEWS {
            let view = named_view(&world, name, (400, 300)).unwrap();
            assert!(view.is_orthographic(), "{name}");
            let m = view.view_projection();
            for k in 0..8 {
                let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
                let p = DVec3::new(
                    pick(1, lo.x, hi.x),
                    pick(2, lo.y, hi.y),
                    pick(4, lo.z, hi.z),
                );
                let c = m * p.extend(1.0);
                let ndc = c.truncate() / c.w;
                assert!(
                    ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0,
                    "{name}: {p} at {ndc}"
                );
                assert!(ndc.z > 0.0 && ndc.z < 1.0, "{name}: {p} at depth {}", ndc.z);
            }
        }
        assert!(named_view(&world, "sideways", (400, 300)).is_err());
    }

    #[test]
    fn sizes_and_vectors() {
        assert_eq!(parse_size("640x480").unwrap(), (640, 480));
        for bad in ["640", "0x10", "x", "-1x5", "10x10x10"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_vec3("1,-2, 3.5").unwrap(), Vec3::new(1.0, -2.0, 3.5));
        for bad in ["1,2", "1,2,3,4", "a,b,c", "nan,0,0", "inf,1,1"] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }
}
