//! Command-line parsing helpers shared by the `wirepass` binary's subcommands.

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::mesh::{self, Mesh, Procedural};
use glam::Vec3;
use std::path::Path;

/// Loads `spec`: a procedural name (`sphere:N`, `grid:N`, `torus:N`), a mesh file (OBJ, STL
/// or PLY, by extension: see [`mesh::load`]), or, when `None`, the built-in default scene.
pub fn load_mesh(spec: Option<&str>) -> Result<Mesh> {
    match spec {
        None => Ok(mesh::default_scene()),
        Some(s) if !Path::new(s).exists() && s.contains(':') && !s.contains(['/', '\\']) => {
            s.parse::<Procedural>()?.build()
        }
        Some(s) => mesh::load(Path::new(s)),
    }
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
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>().map_err(|_| bad()))
        .collect::<Result<_>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

/// Camera options as given on the command line; unset ones come from the automatic framing.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct CameraArgs {
    /// Eye position x,y,z; without it the camera frames the mesh automatically.
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point looked at, x,y,z (default: centre of the mesh bounds).
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Up direction x,y,z (default 0,1,0).
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees (default 40).
    #[arg(long, allow_hyphen_values = true)]
    pub fov: Option<f32>,
    /// Near plane distance.
    #[arg(long, allow_hyphen_values = true)]
    pub near: Option<f32>,
    /// Far plane distance.
    #[arg(long, allow_hyphen_values = true)]
    pub far: Option<f32>,
}

fn parse_vec3_arg(s: &str) -> std::result::Result<Vec3, String> {
    parse_vec3(s).map_err(|e| e.to_string())
}

impl CameraArgs {
    /// The camera for `mesh` at `size`: explicit values where given, framing otherwise.
    /// With an explicit eye, near and far default to values that enclose the mesh.
    pub fn camera(&self, mesh: &Mesh, size: (u32, u32)) -> Result<Camera> {
        let (lo, hi) = mesh.bounds();
        // Finite coordinates can still span more than f32 holds; framing such a mesh would
        // overflow to an infinite eye, which the camera check reports in confusing terms.
        if (hi.as_dvec3() - lo.as_dvec3()).length() > f64::from(f32::MAX) {
            return Err(Error::InvalidMesh(format!(
                "the mesh spans {lo} to {hi}, more than f32 coordinates can hold"
            )));
        }
        let framed = Camera::framing(lo, hi, size.0 as f32 / size.1 as f32);
        let mut cam = framed;
        if let Some(eye) = self.eye {
            cam.eye = eye;
            cam.target = self.target.unwrap_or(framed.target);
            // Near and far that enclose the mesh seen from this eye, in f64: the squares in
            // an f32 length overflow for a far eye such as 1e30,1e30,1e30.
            let (lo64, hi64) = (lo.as_dvec3(), hi.as_dvec3());
            let radius = (hi64 - lo64).length() * 0.5;
            let dist = ((lo64 + hi64) * 0.5 - eye.as_dvec3()).length();
            let far = (dist + radius) * 1.5 + 1e-3;
            cam.far = far as f32;
            cam.near = ((dist - radius).max(far * 1e-5).max(1e-6) * 0.5) as f32;
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

#[cfg(test)]
mod tests {
    use super::*;

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
