//! The pinhole camera every method shares: right-handed look-at, `perspective_rh` projection
//! with depth 0..1, image row 0 at the top, pixel `(x, y)` centred at `(x + 0.5, y + 0.5)`.

use crate::error::{Error, Result};
use glam::{DMat4, DVec3, Vec3};

/// A perspective camera. Angles in degrees; `near`/`far` are view-space distances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub eye: Vec3,
    /// Point the camera looks at.
    pub target: Vec3,
    /// Approximate up direction; must not be parallel to `target - eye`.
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Distance of the near clipping plane, > 0.
    pub near: f32,
    /// Distance of the far clipping plane, > `near`.
    pub far: f32,
}

impl Camera {
    /// Checks that the camera defines a proper projection.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidCamera(m));
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return bad(format!("{name} {v} is not finite"));
            }
        }
        let dir = (self.target - self.eye).as_dvec3();
        if dir.length() <= 1e-12 * self.eye.as_dvec3().length().max(1.0) {
            return bad(format!("eye and target are the same point {}", self.eye));
        }
        let up = self.up.as_dvec3();
        if up.length() == 0.0 {
            return bad("up is the zero vector".into());
        }
        if dir.normalize().cross(up.normalize()).length() < 1e-6 {
            return bad(format!(
                "up {} is parallel to the view direction {}",
                self.up,
                dir.as_vec3()
            ));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return bad(format!("fov {} is not in (0, 180) degrees", self.fov_y_deg));
        }
        if !(self.near > 0.0 && self.near.is_finite()) {
            return bad(format!("near {} must be > 0", self.near));
        }
        if !(self.far > self.near && self.far.is_finite()) {
            return bad(format!("far {} must be > near {}", self.far, self.near));
        }
        Ok(())
    }

    /// Frames an axis-aligned box: looks at its centre from the front-right-above, at the
    /// smallest distance where all eight corners are in view (plus a 5 % margin), with near
    /// and far hugging the box's bounding sphere.
    pub fn framing(lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let fov_y = 40.0_f64;
        let tan_y = (fov_y.to_radians() * 0.5).tan();
        let tan_x = tan_y * f64::from(aspect);
        let forward = -DVec3::new(0.55, 0.35, 1.0).normalize();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        // Corner o is in view from distance d when |o·right| <= (d - o·forward) tan_x, and
        // likewise for up; the largest such d over the corners frames the box.
        let mut distance = radius * 1e-3;
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let o = corner - centre;
            let along = o.dot(forward);
            distance = distance
                .max(along + o.dot(right).abs() / tan_x)
                .max(along + o.dot(up).abs() / tan_y);
        }
        distance *= 1.05;
        Camera {
            eye: (centre - forward * distance).as_vec3(),
            target: centre.as_vec3(),
            up: Vec3::Y,
            fov_y_deg: fov_y as f32,
            near: ((distance - radius) * 0.5).max(distance * 1e-3) as f32,
            far: ((distance + radius) * 1.5) as f32,
        }
    }

    /// View matrix (world → view), in f64.
    pub fn view(&self) -> DMat4 {
        glam::dcamera::rh::view::look_at_mat4(
            self.eye.as_dvec3(),
            self.target.as_dvec3(),
            self.up.as_dvec3().normalize(),
        )
    }

    /// Projection matrix (view → clip, depth 0..1, y up: glam's `perspective_rh`), in f64.
    pub fn projection(&self, aspect: f64) -> DMat4 {
        glam::dcamera::rh::proj::directx::perspective(
            f64::from(self.fov_y_deg).to_radians(),
            aspect,
            f64::from(self.near),
            f64::from(self.far),
        )
    }

    /// Combined world → clip matrix for an image of `width × height` pixels.
    pub fn view_projection(&self, width: u32, height: u32) -> DMat4 {
        self.projection(f64::from(width) / f64::from(height)) * self.view()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 45.0,
            near: 0.1,
            far: 10.0,
        }
    }

    #[test]
    fn rejects_impossible_cameras() {
        assert!(cam().validate().is_ok());
        let cases = [
            Camera {
                target: cam().eye,
                ..cam()
            },
            Camera {
                up: Vec3::Z,
                ..cam()
            },
            Camera {
                up: Vec3::ZERO,
                ..cam()
            },
            Camera {
                fov_y_deg: 0.0,
                ..cam()
            },
            Camera {
                fov_y_deg: 180.0,
                ..cam()
            },
            Camera { near: 0.0, ..cam() },
            Camera { far: 0.05, ..cam() },
            Camera {
                eye: Vec3::NAN,
                ..cam()
            },
        ];
        for c in cases {
            assert!(c.validate().is_err(), "{c:?}");
        }
    }

    #[test]
    fn projection_is_perspective_rh() {
        let (f, n, fov, aspect) = (10.0_f64, f64::from(0.1_f32), 45f64.to_radians(), 1.5);
        let m = cam().projection(aspect);
        let h = 1.0 / (0.5 * fov).tan();
        let expect = DMat4::from_cols_array(&[
            h / aspect,
            0.0,
            0.0,
            0.0,
            0.0,
            h,
            0.0,
            0.0,
            0.0,
            0.0,
            f / (n - f),
            -1.0,
            0.0,
            0.0,
            n * f / (n - f),
            0.0,
        ]);
        assert!(m.abs_diff_eq(expect, 1e-9), "{m}");
    }

    #[test]
    fn framing_sees_the_whole_box() {
        let (lo, hi) = (Vec3::new(-1.0, -2.0, -0.5), Vec3::new(3.0, 1.0, 0.5));
        for aspect in [0.5_f32, 1.0, 2.0] {
            let c = Camera::framing(lo, hi, aspect);
            c.validate().unwrap();
            let m = c.projection(f64::from(aspect)) * c.view();
            for i in 0..8 {
                let p = DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x } as f64,
                    if i & 2 == 0 { lo.y } else { hi.y } as f64,
                    if i & 4 == 0 { lo.z } else { hi.z } as f64,
                );
                let clip = m * p.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "{ndc}");
            }
        }
    }
}
