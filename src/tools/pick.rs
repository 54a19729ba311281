//! `wirepass pick`: what one pixel of a shot's deferred frame shows, as JSON: the object,
//! its mesh, the file's triangle and polygon, the exact point and normal, and the drawn edge
//! and vertex to snap to ([`PreparedFrame::pick`](crate::gpu::PreparedFrame::pick),
//! [`InstanceHit::locate`](crate::gpu::InstanceHit::locate)).

use crate::error::Result;
use crate::gpu::{Canvas, DeferredPass, GpuContext, PassOptions, PickView, Picked};
use crate::tools::offline::{encode_shaded, Uploaded};
use crate::world::Shot;
use serde::Serialize;

/// What a pixel shows, for people and scripts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PickReport {
    /// The pixel, `[x, y]`, row 0 at the top.
    pub pixel: [u32; 2],
    /// `"background"`, `"host"` or `"object"`.
    pub shows: &'static str,
    /// The object's index in the scene (its node order for a glTF file).
    pub object: Option<usize>,
    /// The object's mesh, by name.
    pub mesh: Option<String>,
    /// The triangle in the mesh file's order, exact at the pixel's centre.
    pub triangle: Option<u32>,
    /// Whether the pixel's centre lies on that triangle (false: just off a silhouette the
    /// rasterizer covered).
    pub inside: Option<bool>,
    /// The polygon (face) in the mesh file's order.
    pub polygon: Option<u32>,
    /// Where the pixel centre's ray meets the triangle, world space.
    pub point: Option<[f64; 3]>,
    /// The triangle's unit normal on the side the eye sees.
    pub normal: Option<[f64; 3]>,
    /// The nearest drawn edge within the snap radius.
    pub edge: Option<EdgeReport>,
    /// The nearest vertex within the snap radius.
    pub vertex: Option<VertexReport>,
}

/// A drawn edge to snap to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EdgeReport {
    /// Its two vertices, indices into the mesh file's vertices.
    pub vertices: [u32; 2],
    /// On-screen distance from the pixel centre, in pixels.
    pub distance_px: f64,
    /// Where on the edge, 0 at the first vertex, 1 at the second.
    pub t: f64,
    /// That point, world space.
    pub point: [f64; 3],
}

/// A vertex to snap to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VertexReport {
    /// Index into the mesh file's vertices.
    pub vertex: u32,
    /// On-screen distance from the pixel centre, in pixels.
    pub distance_px: f64,
    /// The vertex, world space.
    pub position: [f64; 3],
}

impl PickReport {
    /// The report as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// Draws `shot` with the deferred pass and picks pixel `at`, snapping within `snap`
/// pixels.
pub fn pick(ctx: &GpuContext, shot: &Shot<'_>, at: (u32, u32), snap: f64) -> Result<PickReport> {
    let (device, queue) = (&ctx.device, &ctx.queue);
    let up = Uploaded::new(device, queue, shot.world)?;
    let scene = up.scene(shot.world, shot.view);
    let mut pass = DeferredPass::new(device, PassOptions::default())?;
    let canvas = Canvas::new(shot.size);
    let (frame, _image) = encode_shaded(device, queue, shot, &up, &mut pass, canvas)?;
    let picked = frame.pick(device, queue, &up.store, &scene, at);
    ctx.finish()?;
    let mut report = PickReport {
        pixel: [at.0, at.1],
        shows: "background",
        object: None,
        mesh: None,
        triangle: None,
        inside: None,
        polygon: None,
        point: None,
        normal: None,
        edge: None,
        vertex: None,
    };
    let hit = match picked? {
        Picked::Background => return Ok(report),
        Picked::Host => {
            report.shows = "host";
            return Ok(report);
        }
        Picked::Instance(hit) => hit,
    };
    let object = &shot.world.objects[hit.instance];
    let mesh = &shot.world.meshes[object.mesh];
    let pick_view = PickView {
        view: shot.view,
        image: shot.size,
        vertices: crate::gpu::SnapVertices::Any,
        sections: shot.world.sections.clone(),
    };
    let at = hit.locate(&mesh.mesh, &pick_view, at, snap)?;
    report.shows = "object";
    report.object = Some(hit.instance);
    report.mesh = Some(mesh.name.clone());
    report.triangle = Some(at.triangle);
    report.inside = Some(at.inside);
    report.polygon = Some(at.polygon);
    report.point = Some(at.point.to_array());
    report.normal = Some(at.normal.to_array());
    report.edge = at.edge.map(|e| EdgeReport {
        vertices: e.vertices,
        distance_px: e.distance_px,
        t: e.t,
        point: e.point.to_array(),
    });
    report.vertex = at.vertex.map(|v| VertexReport {
        vertex: v.vertex,
        distance_px: v.distance_px,
        position: v.position.to_array(),
    });
    Ok(report)
}
