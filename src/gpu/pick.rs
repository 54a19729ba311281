//! Picking: what a pixel of an encoded frame shows, read back from its id target (a few
//! bytes, not the frame), and, for an instance's triangle, where exactly: the ray through
//! the pixel's centre met with the triangle in f64, and for snapping the drawn edge and the
//! vertex nearest the pixel on screen.
//!
//! The id target holds, per pixel, an instance slot and the triangle in the mesh store's
//! order, inside a guard band; [`PreparedFrame::pick`] turns that into the scene's instance,
//! its [`MeshId`] and the triangle in the mesh's own (the file's) order, so a host never
//! handles the raw values. Reserved slot values: [`BACKGROUND_ID`] where no triangle is and
//! [`HOST_ID`] where the host's own geometry is in front (with host depth).

use super::readback::read_region_async;
use super::{MeshId, MeshStore, PreparedFrame, BACKGROUND_ID, HOST_ID};
use crate::camera::View;
use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use crate::scene::Scene;
use glam::{DMat4, DVec2, DVec3, DVec4};

/// What one pixel of a frame shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Picked {
    /// No instance: the background.
    Background,
    /// The host's own geometry, nearer than any instance there (a frame over host depth).
    Host,
    /// A triangle of an instance.
    Instance(InstanceHit),
}

/// An instance's triangle that a pixel shows, with what [`locate`](Self::locate) needs of
/// the instance and its mesh as they were picked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InstanceHit {
    /// The index of the instance in the scene the frame was prepared from.
    pub instance: usize,
    /// Its mesh.
    pub mesh: MeshId,
    /// The triangle the rasterizer put at the pixel, in the order of the [`Mesh`] that was
    /// inserted (a loaded file's order). On a pixel whose centre lies on or next to an edge
    /// the rasterizer's rounding may give the neighbour; [`InstanceHit::locate`] finds the
    /// exact one ([`Location::triangle`]).
    pub triangle: u32,
    /// The instance's transform in the scene the frame was prepared from.
    pub transform: DMat4,
    /// Which edges of the mesh the store draws.
    pub edges: EdgeSelection,
}

/// What a rectangle of a frame shows.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RectPick {
    /// The scene's instances that some pixel shows, in increasing order.
    pub instances: Vec<usize>,
    /// Every (instance, triangle) some pixel shows, sorted, triangles in the mesh's order;
    /// empty unless asked for.
    pub triangles: Vec<(usize, u32)>,
    /// Whether some pixel shows the host's own geometry.
    pub host: bool,
}

impl PreparedFrame {
    /// What output pixel `(x, y)` (row 0 at the top) shows in this frame, once it has been
    /// encoded and submitted; `scene` and `store` are those it was prepared with. It reads
    /// back one texel of the id target and completes when the GPU has written it, without
    /// blocking (a browser's event loop drives it); [`pick`](Self::pick) waits for it.
    pub async fn pick_async(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        store: &MeshStore,
        scene: &Scene<'_>,
        (x, y): (u32, u32),
    ) -> Result<Picked> {
        let ids = self.read_ids(device, queue, (x, y), (1, 1))?.await?;
        ids.first(store, scene)
    }

    /// [`pick_async`](Self::pick_async), waiting for the GPU: for native hosts and tools.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn pick(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        store: &MeshStore,
        scene: &Scene<'_>,
        at: (u32, u32),
    ) -> Result<Picked> {
        pollster::block_on(self.pick_async(device, queue, store, scene, at))
    }

    /// What the `size` output pixels at `origin` show: the instances (a selection
    /// rectangle), and with `triangles` every instance triangle too. Reads back that
    /// rectangle of the id target only; as [`pick_async`](Self::pick_async) otherwise.
    #[allow(clippy::too_many_arguments)]
    pub async fn pick_rect_async(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        store: &MeshStore,
        scene: &Scene<'_>,
        origin: (u32, u32),
        size: (u32, u32),
        triangles: bool,
    ) -> Result<RectPick> {
        let ids = self.read_ids(device, queue, origin, size)?.await?;
        ids.resolve(store, scene, triangles)
    }

    /// Starts reading back the id target under the `size` output pixels at `origin`. The
    /// future owns what it needs (not the frame, the store or the scene), so a host whose
    /// state lives behind a `RefCell` can await it without holding a borrow, and
    /// [`resolve`](PickedIds::resolve) the result afterwards.
    pub fn read_ids(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        origin: (u32, u32),
        size: (u32, u32),
    ) -> Result<impl std::future::Future<Output = Result<PickedIds>> + 'static> {
        let (w, h) = self.output_size();
        let fits =
            |at: u32, len: u32, of: u32| len > 0 && at.checked_add(len).is_some_and(|e| e <= of);
        if !fits(origin.0, size.0, w) || !fits(origin.1, size.1, h) {
            return Err(Error::InvalidSetting(format!(
                "the {}x{} pixels at ({}, {}) are not inside the {w}x{h} frame",
                size.0, size.1, origin.0, origin.1
            )));
        }
        let g = self.guard();
        let texels = (origin.0 + g, origin.1 + g);
        let order = self.instance_order().to_vec();
        let (device, queue) = (device.clone(), queue.clone());
        let texture = self.id_texture().clone();
        Ok(async move {
            let bytes = read_region_async(
                &device,
                &queue,
                &texture,
                wgpu::TextureAspect::All,
                texels,
                size,
            )
            .await?;
            Ok(PickedIds {
                order,
                words: bytemuck::pod_collect_to_vec(&bytes),
            })
        })
    }
}

/// The id target under some pixels of a frame, read back by
/// [`PreparedFrame::read_ids`], with the frame's instance order.
#[derive(Clone, Debug)]
pub struct PickedIds {
    order: Vec<u32>,
    /// (instance slot, stored triangle) per pixel, row by row.
    words: Vec<u32>,
}

impl PickedIds {
    /// What the pixels show, in the terms of the scene and store the frame was prepared
    /// with (an error if the scene has another number of instances, or a mesh has left the
    /// store since).
    pub fn resolve(
        &self,
        store: &MeshStore,
        scene: &Scene<'_>,
        triangles: bool,
    ) -> Result<RectPick> {
        if scene.instances.len() != self.order.len() {
            return Err(Error::Misuse(format!(
                "the scene has {} instances, but the frame was prepared from one with {}",
                scene.instances.len(),
                self.order.len()
            )));
        }
        let mut pick = RectPick::default();
        for pair in self.words.chunks_exact(2) {
            let (slot, stored) = (pair[0], pair[1]);
            if slot == BACKGROUND_ID {
                continue;
            }
            if slot == HOST_ID {
                pick.host = true;
                continue;
            }
            let instance =
                *self.order.get(slot as usize).ok_or_else(|| {
                    Error::Device(format!("the id target holds instance slot {slot}"))
                })? as usize;
            pick.instances.push(instance);
            if triangles {
                let mesh = scene.instances[instance].mesh;
                pick.triangles
                    .push((instance, store.file_triangle(mesh, stored)?));
            }
        }
        pick.instances.sort_unstable();
        pick.instances.dedup();
        pick.triangles.sort_unstable();
        pick.triangles.dedup();
        Ok(pick)
    }

    /// What the first pixel shows (the one pixel of a single-pixel read).
    pub fn first(&self, store: &MeshStore, scene: &Scene<'_>) -> Result<Picked> {
        let one = PickedIds {
            order: self.order.clone(),
            words: self.words.iter().copied().take(2).collect(),
        };
        let rect = one.resolve(store, scene, true)?;
        Ok(match (rect.triangles.first(), rect.host) {
            (Some(&(instance, triangle)), _) => {
                let placed = &scene.instances[instance];
                Picked::Instance(InstanceHit {
                    instance,
                    mesh: placed.mesh,
                    triangle,
                    transform: placed.transform,
                    edges: store.edges(placed.mesh)?,
                })
            }
            (None, true) => Picked::Host,
            (None, false) => Picked::Background,
        })
    }
}

/// Where exactly a pixel's ray meets a picked triangle, and what is near it on screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    /// The triangle the pixel's centre shows exactly, in the mesh's order: the picked one,
    /// or, where the rasterizer's rounding put a neighbour at a pixel on their shared edge,
    /// that neighbour (the triangle around the picked one's corners that the ray meets
    /// first).
    pub triangle: u32,
    /// Whether the ray meets that triangle itself. False where the rasterizer covered a
    /// pixel whose centre lies just off the surface (beside a silhouette or a boundary, a
    /// hair's breadth away): the pixel then shows what is behind, and `point` lies on the
    /// triangle's plane, outside it.
    pub inside: bool,
    /// The world-space point where the ray through the pixel's centre meets the
    /// triangle's plane, in f64.
    pub point: DVec3,
    /// The triangle's unit world-space normal, on the side the eye sees.
    pub normal: DVec3,
    /// The polygon of the mesh the triangle belongs to, numbered as the file's faces: the
    /// triangles of a polygon are consecutive and joined by edges that are not polygon
    /// edges.
    pub polygon: u32,
    /// The nearest drawn edge within the snap radius, if any.
    pub edge: Option<EdgeSnap>,
    /// The nearest vertex within the snap radius, if any.
    pub vertex: Option<VertexSnap>,
}

/// A drawn edge near the picked pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeSnap {
    /// Its two vertices, indices into the mesh's positions.
    pub vertices: [u32; 2],
    /// The on-screen distance from the pixel's centre to the edge, in pixels.
    pub distance_px: f64,
    /// Where on the edge the nearest screen point lies: 0 at `vertices[0]`, 1 at
    /// `vertices[1]`, measured along the edge in world space.
    pub t: f64,
    /// That point, in world space.
    pub point: DVec3,
}

/// A vertex near the picked pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexSnap {
    /// Index into the mesh's positions.
    pub vertex: u32,
    /// The on-screen distance from the pixel's centre, in pixels.
    pub distance_px: f64,
    /// The vertex in world space.
    pub position: DVec3,
}

/// What [`InstanceHit::locate`] needs of the frame: how the image was seen.
#[derive(Clone, Debug)]
pub struct PickView {
    /// The scene's view.
    pub view: View,
    /// The whole image's size in pixels (a tile's frame: the image it is a tile of).
    pub image: (u32, u32),
    /// The scene's section planes ([`Scene::sections`](crate::Scene::sections)): what they
    /// cut away is neither located nor snapped to.
    pub sections: Vec<crate::SectionPlane>,
    /// Which vertices [`Location::vertex`] snaps to.
    pub vertices: SnapVertices,
}

/// Which vertices a pick snaps to ([`PickView::vertices`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SnapVertices {
    /// Any vertex of the surface round the picked triangle.
    #[default]
    Any,
    /// Only the ends of drawn edges (the edge selection the mesh was inserted with), as a
    /// CAD host snaps to the corners of the lines it shows.
    OnDrawnEdges,
}

impl PickView {
    /// How `scene` is seen in an image of `image` pixels: its view and its section planes,
    /// snapping to any vertex.
    pub fn new(scene: &Scene<'_>, image: (u32, u32)) -> PickView {
        PickView {
            view: scene.view,
            image,
            sections: scene.sections.clone(),
            vertices: SnapVertices::Any,
        }
    }

    /// This view, snapping to `vertices`.
    pub fn snapping_to(self, vertices: SnapVertices) -> PickView {
        PickView { vertices, ..self }
    }

    /// The pixel position, in image pixels, of world point `p` (x right, y down), or `None`
    /// behind the eye.
    fn screen(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let c = self.view.view_projection() * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let (w, h) = (f64::from(self.image.0), f64::from(self.image.1));
        let ndc = c.truncate().truncate() / c.w;
        Some((
            DVec2::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h),
            c.w,
        ))
    }

    /// The ray through image position `pixel`: a point on it and its direction away from
    /// the eye.
    fn ray(&self, pixel: DVec2) -> Result<(DVec3, DVec3)> {
        let (w, h) = (f64::from(self.image.0), f64::from(self.image.1));
        let ndc = DVec2::new(2.0 * pixel.x / w - 1.0, 1.0 - 2.0 * pixel.y / h);
        let inv = self.view.view_projection().inverse();
        let on = inv * DVec4::new(ndc.x, ndc.y, 0.5, 1.0);
        let eye = self.view.eye();
        if !inv.is_finite() || on.w == 0.0 {
            return Err(Error::InvalidCamera(
                "the view-projection matrix is not invertible".into(),
            ));
        }
        let on = on.truncate() / on.w;
        let dir = if eye.w == 0.0 {
            -eye.truncate()
        } else {
            on - eye.truncate() / eye.w
        };
        Ok((on, dir))
    }
}

impl InstanceHit {
    /// Where the centre of image pixel `pixel` (the image's `(x, y)`, a frame's output
    /// pixel plus its region's origin) meets this triangle of `mesh` (the host's copy of
    /// the mesh inserted as [`mesh`](Self::mesh): the store keeps no f64-ready copy) placed
    /// by the instance's [`transform`](Self::transform), and the drawn edge and the vertex
    /// nearest the pixel on screen, within `snap_radius` pixels, among the triangles around
    /// this one's corners that face the eye as it does. It scans the mesh once (a few
    /// milliseconds for millions of triangles), keeping no adjacency between picks.
    pub fn locate(
        &self,
        mesh: &Mesh,
        view: &PickView,
        pixel: (u32, u32),
        snap_radius: f64,
    ) -> Result<Location> {
        let (transform, edges) = (self.transform, self.edges);
        let t = self.triangle as usize;
        let mut exact = t;
        let mut inside = false;
        if t >= mesh.triangle_count() {
            return Err(Error::Misuse(format!(
                "triangle {t} of a mesh with {} triangles: not the mesh that was picked",
                mesh.triangle_count()
            )));
        }
        let world = |v: u32| transform.transform_point3(mesh.positions()[v as usize].as_dvec3());
        let kept = |p: DVec3| view.sections.iter().all(|s| s.side(p) >= 0.0);
        let centre = DVec2::new(f64::from(pixel.0) + 0.5, f64::from(pixel.1) + 0.5);
        let (origin, dir) = view.ray(centre)?;

        // The triangles around this one's corners (by position, across split vertices) that
        // face the eye as it does: the surface the pixel shows around it, without the
        // hidden far side of a silhouette. They hold the exact triangle where the
        // rasterizer's rounding put a neighbour at the pixel, and the snapping candidates.
        let eye = view.view.eye();
        let facing = |u: usize| {
            let [p, q, r] = mesh.triangles()[u].map(world);
            (q - p).cross(r - p).dot(eye.truncate() - p * eye.w)
        };
        let side = facing(t).signum();
        let corners = mesh.triangles()[t].map(|v| mesh.positions()[v as usize]);
        let near: Vec<usize> = (0..mesh.triangle_count())
            .filter(|&u| {
                u == t
                    || (mesh.triangles()[u]
                        .iter()
                        .any(|&v| corners.contains(&mesh.positions()[v as usize]))
                        && facing(u) * side > 0.0)
            })
            .collect();

        // Where the ray meets triangle u's plane, along the ray, and whether inside it.
        let meet = |u: usize| -> Option<(f64, DVec3, DVec3, bool)> {
            let [a, b, c] = mesh.triangles()[u].map(world);
            let normal = (b - a).cross(c - a);
            let along = normal.dot(dir);
            if along == 0.0 || !along.is_finite() {
                return None;
            }
            let s = normal.dot(a - origin) / along;
            let p = origin + dir * s;
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(e0, e1)| (e1 - e0).cross(p - e0).dot(normal) >= 0.0)
                && kept(p);
            Some((s, p, normal, inside))
        };
        let (_, point, normal, _) = near
            .iter()
            .filter_map(|&u| meet(u).filter(|m| m.3).map(|m| (u, m)))
            .min_by(|x, y| x.1 .0.total_cmp(&y.1 .0))
            .map(|(u, m)| {
                exact = u;
                inside = true;
                m
            })
            .or_else(|| meet(t))
            .ok_or_else(|| {
                Error::InvalidSetting(format!(
                    "triangle {t} has no area, or the pixel's ray runs in its plane"
                ))
            })?;
        let normal = normal.normalize();
        let normal = if normal.dot(dir) > 0.0 {
            -normal
        } else {
            normal
        };

        let mut edge: Option<EdgeSnap> = None;
        let mut vertex: Option<VertexSnap> = None;
        for &u in &near {
            let tri = mesh.triangles()[u];
            let mask = mesh.triangle_edge_mask(u, edges);
            for i in 0..3 {
                let (p, q) = (tri[i], tri[(i + 1) % 3]);
                // Corner i ends edges i and i + 2.
                let on_drawn = mask & (1 << i | 1 << ((i + 2) % 3)) != 0;
                let snappable = on_drawn || view.vertices == SnapVertices::Any;
                if let Some((sp, _)) = view
                    .screen(world(p))
                    .filter(|_| snappable && kept(world(p)))
                {
                    let d = sp.distance(centre);
                    if d <= snap_radius && vertex.is_none_or(|v| d < v.distance_px) {
                        vertex = Some(VertexSnap {
                            vertex: p,
                            distance_px: d,
                            position: world(p),
                        });
                    }
                }
                if mask & (1 << i) == 0 {
                    continue;
                }
                // The part of the edge no plane cuts away, as parameters along it.
                let mut kept_part = (0.0_f64, 1.0_f64);
                for plane in &view.sections {
                    let (a, b) = (plane.side(world(p)), plane.side(world(q)));
                    if a < 0.0 && b < 0.0 {
                        kept_part = (1.0, 0.0);
                    } else if a < 0.0 {
                        kept_part.0 = kept_part.0.max(a / (a - b));
                    } else if b < 0.0 {
                        kept_part.1 = kept_part.1.min(a / (a - b));
                    }
                }
                if kept_part.0 > kept_part.1 {
                    continue;
                }
                let (from, to) = (
                    world(p).lerp(world(q), kept_part.0),
                    world(p).lerp(world(q), kept_part.1),
                );
                let (Some((sp, wp)), Some((sq, wq))) = (view.screen(from), view.screen(to)) else {
                    continue;
                };
                let seg = sq - sp;
                let s = if seg.length_squared() > 0.0 {
                    ((centre - sp).dot(seg) / seg.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d = (sp + seg * s).distance(centre);
                if d <= snap_radius && edge.is_none_or(|e| d < e.distance_px) {
                    // Screen parameter s to the edge's own: perspective divides by w.
                    let t = s / wq / ((1.0 - s) / wp + s / wq);
                    let t = kept_part.0 + (kept_part.1 - kept_part.0) * t;
                    edge = Some(EdgeSnap {
                        vertices: [p, q],
                        distance_px: d,
                        t,
                        point: world(p).lerp(world(q), t),
                    });
                }
            }
        }
        Ok(Location {
            triangle: exact as u32,
            inside,
            point,
            normal,
            polygon: polygon_of(mesh, exact),
            edge,
            vertex,
        })
    }
}

/// The polygon index of triangle `t`: triangles of one polygon are consecutive, and a
/// triangle starts a new polygon unless an edge that is not a polygon edge joins it to the
/// one before.
fn polygon_of(mesh: &Mesh, t: usize) -> u32 {
    let neighbours = mesh.edge_neighbours();
    let joined = |s: usize| {
        let polygon_edges = mesh.triangle_edge_mask(s, EdgeSelection::Polygon);
        (0..3).any(|i| polygon_edges & (1 << i) == 0 && neighbours[s][i] as usize == s - 1)
    };
    (1..=t).filter(|&s| !joined(s)).count() as u32
}
