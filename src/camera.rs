//! How the scene is seen: the host's own [`View`] (view and projection matrices of any
//! standard kind) and [`Camera`], the look-at perspective convenience.
//!
//! Conventions every method shares: clip space as wgpu has it (x right, y up, visible
//! points have `w > 0` and depth `z/w` in 0..1), image row 0 at the top, pixel `(x, y)`
//! centred at `(x + 0.5, y + 0.5)`. Which end of the depth range is near is the view's
//! [`DepthRange`]; perspective and orthographic projections, finite or infinite far
//! planes and off-centre (jittered) frusta are all taken as given.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use glam::dcamera::rh::{proj::directx as proj, view::look_at_mat4};
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

/// Which end of the 0..1 depth range a projection puts at the near plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DepthRange {
    /// Depth 0 at the near plane, 1 at the far plane (`perspective_rh`, `orthographic_rh`).
    #[default]
    Standard,
    /// Depth 1 at the near plane, 0 at the far plane (reverse-Z).
    Reversed,
}

/// The host's view of the scene: world → view and view → clip matrices, exactly as it
/// renders with them, and its depth convention.
///
/// wirepass derives everything else from these: the eye (a point for perspective
/// projections, a direction for orthographic ones), the near and far planes, and the light
/// direction (given in view space by [`Style`](crate::Style)). Nothing divides by `w`, so
/// vertices at or behind the eye stay exact.
///
/// ```
/// use wirepass::glam::dcamera::rh::{proj::directx as proj, view::look_at_mat4};
/// use wirepass::glam::DVec3;
/// use wirepass::{DepthRange, View};
///
/// let view = look_at_mat4(DVec3::new(0.0, 1.0, 4.0), DVec3::ZERO, DVec3::Y);
/// // A CAD-style orthographic view 3 units tall, reverse-Z.
/// let projection = proj::orthographic(-2.0, 2.0, -1.5, 1.5, 10.0, 0.1);
/// let v = View::new(view, projection, DepthRange::Reversed);
/// assert!(v.validate().is_ok());
/// assert!(v.is_orthographic());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// World → view space.
    pub view: DMat4,
    /// View → clip space.
    pub projection: DMat4,
    /// Which end of the depth range is near.
    pub depth: DepthRange,
}

#[cfg_attr(not(feature = "truth"), doc(hidden))]
/// A view's clip transform in the form the passes use, for one model matrix: the rows
/// giving clip x, y and w, a row that is ≥ 0 exactly in front of the near plane, and a
/// reverse depth row that is ≥ 0 exactly before the far plane, with (reverse depth)/w equal
/// to 1 at the near plane and 0 at the far plane, whatever the view's [`DepthRange`].
/// Each row is formed in f64 from the matrices, so neither loses precision to a
/// subtraction in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipRows {
    /// Rows x, y, near, w: clip position with the near-distance row in place of z.
    pub clip: DMat4,
    /// The reverse depth row.
    pub depth: DVec4,
}

impl View {
    /// A view from the host's matrices.
    pub fn new(view: DMat4, projection: DMat4, depth: DepthRange) -> View {
        View {
            view,
            projection,
            depth,
        }
    }

    /// A view from f32 matrices, as many renderers keep them.
    pub fn from_f32(view: Mat4, projection: Mat4, depth: DepthRange) -> View {
        View::new(view.as_dmat4(), projection.as_dmat4(), depth)
    }

    /// An orthographic view looking from `eye` at `target`, showing `height` world units
    /// from the bottom to the top of the image at `aspect` (width / height), with depth
    /// from `near` to `far` along the view direction (`near` may be negative).
    pub fn orthographic(
        (eye, target, up): (DVec3, DVec3, DVec3),
        height: f64,
        aspect: f64,
        (near, far): (f64, f64),
    ) -> View {
        let (h, w) = (0.5 * height, 0.5 * height * aspect);
        View::new(
            look_at_mat4(eye, target, up.normalize_or_zero()),
            proj::orthographic(-w, w, -h, h, near, far),
            DepthRange::Standard,
        )
    }

    /// [`View::orthographic`] with reversed depth (1 at `near`, 0 at `far`), as reverse-Z
    /// hosts draw orthographic views.
    pub fn orthographic_reversed(
        at: (DVec3, DVec3, DVec3),
        height: f64,
        aspect: f64,
        (near, far): (f64, f64),
    ) -> View {
        View {
            depth: DepthRange::Reversed,
            ..View::orthographic(at, height, aspect, (far, near))
        }
    }

    /// World → clip.
    pub fn view_projection(&self) -> DMat4 {
        self.projection * self.view
    }

    /// True when the projection is affine (orthographic): clip w does not depend on the point.
    pub fn is_orthographic(&self) -> bool {
        self.projection.row(3).truncate() == DVec3::ZERO
    }

    /// The eye in homogeneous world coordinates: `(eye, 1)` for a perspective projection,
    /// `(direction towards the viewer, 0)`, unit length, for an orthographic one. It is the
    /// point every pixel's ray passes through (the one clip x, y and w all vanish at).
    pub fn eye(&self) -> DVec4 {
        let inv_view = self.view.inverse();
        if self.is_orthographic() {
            // Parallel rays: towards the viewer is where the near-distance row falls.
            let rows = self.clip_rows(DMat4::IDENTITY);
            let near_dir = rows.clip.row(2).truncate();
            let d = -near_dir.normalize_or_zero();
            return d.extend(0.0);
        }
        let e = null_vector(self.projection);
        let e = if e.w != 0.0 { e / e.w } else { e };
        let world = inv_view * e;
        if world.w != 0.0 {
            world / world.w
        } else {
            world
        }
    }

    /// The clip-space w that every point of the near plane has, where the projection gives
    /// them one (a perspective projection whose near plane is a plane of constant view
    /// depth, or an orthographic one), else `None`. The trace pass projects an edge's cut by
    /// the near plane with it: interpolated between the edge's ends, w there loses its
    /// leading digits where the ends lie far from the plane, and a cut that projects far
    /// off-screen moved by pixels.
    pub(crate) fn near_plane_w(&self) -> Option<f64> {
        let rows = self.clip_rows(DMat4::IDENTITY);
        let (near, w) = (rows.clip.row(2), rows.clip.row(3));
        if w.truncate() == DVec3::ZERO {
            return Some(w.w);
        }
        // near = a w + b (0, 0, 0, 1): then near = 0 where w = -b / a.
        let a = near.truncate().dot(w.truncate()) / w.truncate().length_squared();
        let off = (near.truncate() - a * w.truncate()).length();
        let b = near.w - a * w.w;
        let at = -b / a;
        (off <= 1e-9 * near.truncate().length() && at.is_finite() && at > 0.0).then_some(at)
    }

    /// The clip rows of this view for a model matrix (object → world).
    pub fn clip_rows(&self, model: DMat4) -> ClipRows {
        let m = self.projection * self.view * model;
        let (z, w) = (m.row(2), m.row(3));
        let (near, depth) = match self.depth {
            DepthRange::Standard => (z, w - z),
            DepthRange::Reversed => (w - z, z),
        };
        ClipRows {
            clip: DMat4::from_cols(m.row(0), m.row(1), near, w).transpose(),
            depth,
        }
    }

    /// View depth of a world point: its distance in front of the eye along the view axis
    /// (−z in view space, as `look_at_rh` has it). The depth fade works on it.
    pub fn view_depth_row(&self) -> DVec4 {
        -self.view.row(2)
    }

    /// Checks that the view defines a projection wirepass can draw: finite, invertible
    /// matrices, and a depth convention the projection agrees with.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidCamera(m));
        if !self.view.is_finite() || !self.projection.is_finite() {
            return bad("the view or projection matrix has a non-finite entry".into());
        }
        let det = |m: DMat4| m.determinant();
        if !(det(self.view).abs() > 0.0) {
            return bad("the view matrix is singular".into());
        }
        // The projection's x, y and w rows must be independent (it may have no z row to
        // speak of, as an infinite-far one nearly does).
        let p = self.projection;
        let (x, y, w) = (p.row(0), p.row(1), p.row(3));
        if null_vector(p).length() == 0.0 || x.truncate().cross(y.truncate()) == DVec3::ZERO {
            return bad("the projection matrix's x, y and w rows are not independent".into());
        }
        if w == DVec4::ZERO {
            return bad("the projection matrix's w row is zero".into());
        }
        if self.is_orthographic() {
            if !(w.w > 0.0) {
                return bad("the orthographic projection gives w <= 0 everywhere".into());
            }
            let rows = self.clip_rows(DMat4::IDENTITY);
            let near = rows.clip.row(2).truncate();
            if near == DVec3::ZERO {
                return bad("the orthographic projection has no depth axis".into());
            }
            // An affine projection does not say which side the viewer is on: the depth
            // convention does (depth grows away from the viewer). Read against the image's
            // axes, a mislabelled one shows the scene from behind, mirrored. So the image's
            // x and y axes and the direction towards the viewer must make a right-handed
            // frame, as they do for every camera that is not a mirror.
            let unit = |v: DVec3| v / v.abs().max_element();
            let (x, y) = (rows.clip.row(0).truncate(), rows.clip.row(1).truncate());
            let facing = unit(x).cross(unit(y)).dot(-unit(near));
            if !(facing > 0.0) {
                let fix = match self.depth {
                    DepthRange::Standard => "declare DepthRange::Reversed",
                    DepthRange::Reversed => "declare DepthRange::Standard",
                };
                return bad(format!(
                    "the orthographic projection's depth grows towards the viewer that its x \
                     and y axes imply (x right, y up, depth away from the viewer): {fix} (a \
                     mirror image is drawn by mirroring the instances, not the view)"
                ));
            }
            return Ok(());
        }
        // Perspective: along the eye's forward axis, depth must grow (standard) or fall
        // (reversed) with distance, as the convention says. At distance s along it, clip w
        // is w1·s (w vanishes at the eye) and z is z_e + z1·s, so NDC depth is
        // z_e / (w1·s) + z1 / w1: it grows with s exactly when z_e < 0. Deciding on the sign
        // rather than on sampled depths keeps a camera 1e-30 across as exact as a unit one.
        let eye = null_vector(p);
        let eye = eye / eye.w;
        let z_e = p.row(2).dot(eye);
        if !z_e.is_finite() || z_e == 0.0 {
            return bad("the projection gives no depth along the view axis".into());
        }
        let depth_grows = z_e < 0.0;
        match (self.depth, depth_grows) {
            (DepthRange::Standard, false) => bad(
                "the projection puts nearer points at greater depth, as a reverse-Z one does: \
                 declare DepthRange::Reversed"
                    .into(),
            ),
            (DepthRange::Reversed, true) => bad(
                "the projection puts nearer points at smaller depth: declare DepthRange::Standard"
                    .into(),
            ),
            _ => Ok(()),
        }
    }
}

/// The homogeneous point where a projection's clip x, y and w all vanish: the centre of
/// projection (w = 0 for an affine projection). Cofactors of the 3×4 matrix of those rows.
fn null_vector(p: DMat4) -> DVec4 {
    let (a, b, c) = (p.row(0), p.row(1), p.row(3));
    let minor = |i: usize, j: usize, k: usize| {
        DVec3::new(a[i], a[j], a[k])
            .dot(DVec3::new(b[i], b[j], b[k]).cross(DVec3::new(c[i], c[j], c[k])))
    };
    DVec4::new(
        minor(1, 2, 3),
        -minor(0, 2, 3),
        minor(0, 1, 3),
        -minor(0, 1, 2),
    )
}

/// A perspective look-at camera: the convenience the tools and the CLI use. Angles in
/// degrees; `near`/`far` are view-space distances, and `far` may be infinite. A host with
/// its own camera passes its matrices as a [`View`] instead.
///
/// ```
/// use wirepass::glam::DVec3;
/// use wirepass::{Camera, DepthRange};
/// // Frame a box at a 16:9 aspect; the view is standard depth (0 near, 1 far).
/// let camera = Camera::framing(DVec3::splat(-1.0), DVec3::ONE, 16.0 / 9.0);
/// let view = camera.to_view(16.0 / 9.0);
/// assert_eq!(view.depth, DepthRange::Standard);
/// // The box's centre lies in front of the eye, in the middle of the image.
/// let c = view.view_projection() * DVec3::ZERO.extend(1.0);
/// assert!(c.w > 0.0 && (c.x / c.w).abs() < 1e-9 && (c.y / c.w).abs() < 1e-9);
/// ```
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
    /// Distance of the far clipping plane, > `near`; `f32::INFINITY` for none.
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
        // Relative to the camera's own scale, so a camera framing a mesh 1e-30 across is
        // as valid as one framing a unit mesh.
        let scale = self
            .eye
            .as_dvec3()
            .length()
            .max(self.target.as_dvec3().length());
        if dir.length() <= 1e-12 * scale {
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
            return bad(format!("near {} must be > 0 and finite", self.near));
        }
        if !(self.far > self.near) {
            return bad(format!(
                "far {} must be > near {} (or infinite)",
                self.far, self.near
            ));
        }
        Ok(())
    }

    /// Frames an axis-aligned box: looks at its centre from the front-right-above, at the
    /// smallest distance where all eight corners are in view (plus a 5 % margin), with near
    /// and far hugging the box's bounding sphere. Works in f64 throughout, so boxes of any
    /// extent (1e-30 or 1e30) frame as well as a unit one.
    pub fn framing(lo: DVec3, hi: DVec3, aspect: f64) -> Camera {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(centre.abs().max_element() * 1e-6);
        let radius = if radius > 0.0 { radius } else { 1.0 };
        let fov_y = 40.0_f64;
        let tan_y = (fov_y.to_radians() * 0.5).tan();
        let tan_x = tan_y * aspect;
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
        look_at_mat4(
            self.eye.as_dvec3(),
            self.target.as_dvec3(),
            self.up.as_dvec3().normalize(),
        )
    }

    /// Projection matrix (view → clip, depth 0..1: glam's `perspective_rh`, or
    /// `perspective_infinite_rh` for an infinite far plane), in f64.
    pub fn projection(&self, aspect: f64) -> DMat4 {
        let fov = f64::from(self.fov_y_deg).to_radians();
        let near = f64::from(self.near);
        if self.far.is_infinite() {
            proj::perspective_infinite(fov, aspect, near)
        } else {
            proj::perspective(fov, aspect, near, f64::from(self.far))
        }
    }

    /// Combined world → clip matrix for an image of `width × height` pixels.
    pub fn view_projection(&self, width: u32, height: u32) -> DMat4 {
        self.projection(f64::from(width) / f64::from(height)) * self.view()
    }

    /// The camera as a [`View`] for an image of aspect `width / height`.
    pub fn to_view(&self, aspect: f64) -> View {
        View::new(self.view(), self.projection(aspect), DepthRange::Standard)
    }
}

/// An orbit camera for viewers: it circles a target at a distance, pans in the view plane
/// and zooms towards the target, with a near plane just before what it frames (or close to
/// the eye once inside it) and an infinite far plane.
///
/// ```
/// use wirepass::camera::Orbit;
/// use wirepass::glam::DVec3;
///
/// let mut orbit = Orbit::framing(DVec3::splat(-1.0), DVec3::splat(1.0));
/// orbit.rotate(40.0, 0.0); // a drag of 40 pixels to the right
/// orbit.zoom(2.0); // two wheel steps closer
/// let view = orbit.camera().to_view(16.0 / 9.0);
/// assert!(view.validate().is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The point circled.
    pub target: DVec3,
    /// The radius of what is framed: it scales the near plane and the closest zoom.
    pub radius: f64,
    /// From the eye to the target.
    pub distance: f64,
    /// Turn about the vertical axis, in radians.
    pub yaw: f64,
    /// Elevation above the horizontal plane, in radians, within ±1.5.
    pub pitch: f64,
}

impl Orbit {
    /// The vertical field of view of [`camera`](Self::camera), in degrees.
    pub const FOV_Y_DEG: f64 = 40.0;

    /// Frames the box `lo..hi` (its bounding sphere fills the view), seen a little from
    /// above and to the side.
    pub fn framing(lo: DVec3, hi: DVec3) -> Orbit {
        let radius = ((hi - lo).length() * 0.5).max(f64::MIN_POSITIVE);
        Orbit {
            target: (lo + hi) * 0.5,
            radius,
            distance: 2.8 * radius,
            yaw: 0.5,
            pitch: 0.35,
        }
    }

    fn forward(&self) -> DVec3 {
        -DVec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        )
    }

    /// A perspective camera with an infinite far plane and a near plane just before the
    /// framed sphere (or close to the eye once inside it).
    pub fn camera(&self) -> Camera {
        let eye = self.target - self.forward() * self.distance;
        let near = ((self.distance - self.radius) * 0.5).max(self.distance * 1e-3);
        Camera {
            eye: eye.as_vec3(),
            target: self.target.as_vec3(),
            up: Vec3::Y,
            fov_y_deg: Self::FOV_Y_DEG as f32,
            near: near as f32,
            far: f32::INFINITY,
        }
    }

    /// Turns by a drag of `(dx, dy)` pixels: right turns the view to the left of the
    /// object, down raises the eye.
    pub fn rotate(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * 0.01;
        self.pitch = (self.pitch + dy * 0.01).clamp(-1.5, 1.5);
    }

    /// Moves the target in the view plane by a drag of `(dx, dy)` pixels of a view
    /// `height` pixels tall, so the point under the cursor follows it.
    pub fn pan(&mut self, dx: f64, dy: f64, height: f64) {
        let forward = self.forward();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        let per_pixel =
            2.0 * self.distance * (0.5 * Self::FOV_Y_DEG).to_radians().tan() / height.max(1.0);
        self.target += (-right * dx + up * dy) * per_pixel;
    }

    /// Moves `steps` wheel steps towards the target (away for negative steps), each 10 %
    /// of the distance; never past a thousandth of the radius.
    pub fn zoom(&mut self, steps: f64) {
        self.distance = (self.distance * 0.9f64.powf(steps)).max(self.radius * 1e-3);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_near_plane_has_one_w_where_the_projection_gives_it_one() {
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12 * b);
        let c = cam();
        assert!(close(c.to_view(1.5).near_plane_w(), f64::from(c.near)));
        let look = look_at_mat4(DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y);
        let reversed = View::new(
            look,
            proj::perspective_infinite_reverse(0.8, 1.5, 0.01),
            DepthRange::Reversed,
        );
        assert!(close(reversed.near_plane_w(), 0.01));
        let at = (DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y);
        let ortho = View::orthographic(at, 2.0, 1.5, (0.1, 10.0));
        assert!(close(ortho.near_plane_w(), 1.0));
        // An oblique near plane (tilted by a clip plane, as for a mirror): w varies on it.
        let mut oblique = c.projection(1.5);
        oblique.x_axis.z += 0.3;
        let tilted = View::new(c.view(), oblique, DepthRange::Standard);
        assert_eq!(tilted.near_plane_w(), None);
    }

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
        assert!(Camera {
            far: f32::INFINITY,
            ..cam()
        }
        .validate()
        .is_ok());
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
                far: f32::NAN,
                ..cam()
            },
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
        let (lo, hi) = (DVec3::new(-1.0, -2.0, -0.5), DVec3::new(3.0, 1.0, 0.5));
        for aspect in [0.5, 1.0, 2.0] {
            let c = Camera::framing(lo, hi, aspect);
            c.validate().unwrap();
            let m = c.projection(aspect) * c.view();
            for i in 0..8 {
                let p = DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                );
                let clip = m * p.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "{ndc}");
            }
        }
    }

    fn look() -> DMat4 {
        look_at_mat4(DVec3::new(1.0, 2.0, 5.0), DVec3::ZERO, DVec3::Y)
    }

    #[test]
    fn the_eye_of_every_kind_of_projection() {
        let eye = DVec3::new(1.0, 2.0, 5.0);
        let persp = [
            View::new(
                look(),
                proj::perspective(0.8, 1.5, 0.1, 100.0),
                DepthRange::Standard,
            ),
            View::new(
                look(),
                proj::perspective_infinite(0.8, 1.5, 0.1),
                DepthRange::Standard,
            ),
            View::new(
                look(),
                proj::perspective_infinite_reverse(0.8, 1.5, 0.1),
                DepthRange::Reversed,
            ),
            View::new(
                look(),
                proj::perspective(0.8, 1.5, 100.0, 0.1),
                DepthRange::Reversed,
            ),
        ];
        for v in persp {
            v.validate().unwrap();
            assert!(!v.is_orthographic());
            let e = v.eye();
            assert!((e.truncate() - eye).length() < 1e-9 && e.w == 1.0, "{e}");
        }
        let ortho = View::orthographic((eye, DVec3::ZERO, DVec3::Y), 4.0, 1.5, (0.1, 20.0));
        ortho.validate().unwrap();
        let e = ortho.eye();
        assert_eq!(e.w, 0.0);
        assert!((e.truncate() - eye.normalize()).length() < 1e-12, "{e}");
        // Reversed ortho: the same direction.
        let rev = View::new(
            ortho.view,
            proj::orthographic(-3.0, 3.0, -2.0, 2.0, 20.0, 0.1),
            DepthRange::Reversed,
        );
        rev.validate().unwrap();
        assert!((rev.eye().truncate() - eye.normalize()).length() < 1e-12);
        let made = View::orthographic_reversed((eye, DVec3::ZERO, DVec3::Y), 4.0, 1.5, (0.1, 20.0));
        made.validate().unwrap();
        assert!(made.projection.abs_diff_eq(rev.projection, 1e-12));
        assert!((made.eye().truncate() - eye.normalize()).length() < 1e-12);
    }

    /// An orthographic projection labelled with the other depth convention shows the scene
    /// from behind, mirrored: an error, for either label, as it is for a perspective one.
    /// So is a mirrored orthographic view.
    #[test]
    fn a_mislabelled_orthographic_depth_is_an_error() {
        let eye = DVec3::new(1.0, 2.0, 5.0);
        let at = (eye, DVec3::ZERO, DVec3::Y);
        let standard = View::orthographic(at, 4.0, 1.5, (0.1, 20.0));
        let reversed = View::orthographic_reversed(at, 4.0, 1.5, (0.1, 20.0));
        for (view, label) in [
            (standard, DepthRange::Reversed),
            (reversed, DepthRange::Standard),
        ] {
            let wrong = View::new(view.view, view.projection, label);
            let e = wrong.validate().unwrap_err().to_string();
            assert!(e.contains("towards the viewer"), "{e}");
        }
        let mut mirrored = standard;
        mirrored.projection.x_axis.x = -mirrored.projection.x_axis.x;
        assert!(mirrored.validate().is_err());
        // Cameras 1e-30 and 1e30 across decide the same way.
        for scale in [1e-30, 1e30] {
            let small = View::orthographic(
                (eye * scale, DVec3::ZERO, DVec3::Y),
                4.0 * scale,
                1.5,
                (0.1 * scale, 20.0 * scale),
            );
            small.validate().unwrap();
            assert!(
                View::new(small.view, small.projection, DepthRange::Reversed)
                    .validate()
                    .is_err()
            );
        }
    }

    #[test]
    fn clip_rows_agree_across_depth_conventions() {
        let standard = View::new(
            look(),
            proj::perspective(0.8, 1.5, 0.1, 100.0),
            DepthRange::Standard,
        );
        let reversed = View::new(
            look(),
            proj::perspective(0.8, 1.5, 100.0, 0.1),
            DepthRange::Reversed,
        );
        let (a, b) = (
            standard.clip_rows(DMat4::IDENTITY),
            reversed.clip_rows(DMat4::IDENTITY),
        );
        for p in [DVec3::new(0.3, -0.2, 0.1), DVec3::new(9.0, 1.0, -40.0)] {
            let h = p.extend(1.0);
            let (ca, cb) = (a.clip * h, b.clip * h);
            assert!((ca - cb).length() < 1e-9 * ca.length(), "{ca} {cb}");
            assert!((a.depth.dot(h) - b.depth.dot(h)).abs() < 1e-9);
        }
        // The near row is 0 on the near plane, the depth row/w is 1 there.
        let on_near = standard.view.inverse() * DVec4::new(0.0, 0.0, -0.1, 1.0);
        let c = a.clip * on_near;
        assert!(c.z.abs() < 1e-12 && (a.depth.dot(on_near) / c.w - 1.0).abs() < 1e-9);
    }

    #[test]
    fn rejects_impossible_views() {
        let good = View::new(
            look(),
            proj::perspective(0.8, 1.5, 0.1, 100.0),
            DepthRange::Standard,
        );
        assert!(good.validate().is_ok());
        let cases = [
            View {
                depth: DepthRange::Reversed,
                ..good
            },
            View {
                projection: DMat4::ZERO,
                ..good
            },
            View {
                view: DMat4::ZERO,
                ..good
            },
            View {
                projection: DMat4::from_cols_array(&[f64::NAN; 16]),
                ..good
            },
            View {
                projection: proj::perspective(0.8, 1.5, 100.0, 0.1),
                ..good
            },
        ];
        for v in cases {
            assert!(v.validate().is_err(), "{v:?}");
        }
    }
}
