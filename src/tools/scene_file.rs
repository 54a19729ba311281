//! Scene files: a JSON description of objects (meshes with transforms and styles) and a
//! camera, for `wirepass render|compare|bench SCENE.json`.
//!
//! ```json
//! {
//!   "objects": [
//!     { "mesh": "bunny.obj", "transform": { "translate": [0, 0, 0], "rotate_deg": [0, 90, 0], "scale": 2 } },
//!     { "mesh": "sphere:20000", "transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 3,0,0,1],
//!       "edges": "feature:30", "outlines": false, "wire_color": "#c03020", "line_width": 3,
//!       "fill_color": "#d0c0a0" }
//!   ],
//!   "camera": { "eye": [4, 3, 6], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "near": 0.1, "far": 100 },
//!   "style": { "hidden": "dashed:6,4", "fill_opacity": 0.5 }
//! }
//! ```
//!
//! - `mesh`: a path relative to the scene file, or a procedural mesh (`sphere:N`, `grid:N`,
//!   `torus:N`, `cube:N`, `layers:K`). Objects naming the same mesh with the same edges share it.
//! - `transform`: 16 numbers, column-major, or `{"translate", "rotate_deg", "scale"}` (each
//!   optional): `rotate_deg` turns about X, then Y, then Z (R = Rz·Ry·Rx), `scale` is three
//!   numbers or one, and the transform is T·R·S.
//! - `edges`: `all`, `polygon`, `authored`, `feature[:DEG]` or `none` (draws none of the
//!   object's edges; it still occludes, and still has its outline unless `outlines` is
//!   false). Edge selection (feature angles, adjacency, welding) is computed per mesh in its
//!   own coordinates. Default: the command line's `--edges`, else the mesh file's own edges
//!   where it has them (glTF), else `polygon`.
//! - `outlines`, `wire_color`, `outline_color` and `fill_color` (`#rrggbb[aa]`, sRGB; the
//!   fill's alpha is unused), `line_width` and `outline_width` (pixels), `edge_pattern` and
//!   `outline_pattern` (`solid`, `dashed[:DASH,GAP]`, `dotted[:SPACING]`): per-object
//!   overrides of the command line's style.
//! - `hidden` (`off`, `solid`, `dashed[:DASH,GAP]`, `dotted[:SPACING]`), `hidden_color` and
//!   `hidden_width`: the object's own hidden lines (drawn whatever the frame's), what it
//!   leaves out taken from the file's `style`, else the defaults; `"hidden": "off"` draws
//!   none of its hidden lines. `highlight` (`true`): the object is drawn selected (its
//!   outline in orange, dashed where hidden, its fill tinted: `wirepass::Highlight`).
//! - `style` (optional): the frame's `hidden` (`off`, `solid`, `dashed[:DASH,GAP]`,
//!   `dotted[:SPACING]`), `hidden_color`, `hidden_width`, `fill_opacity`, `outline_color`,
//!   `outline_width`, `edge_pattern` and `outline_pattern`, where the command line does not
//!   set them.
//! - `sections` (optional): up to 6 section planes, `{"point": [x, y, z], "normal": [x, y,
//!   z]}` in world coordinates; what lies behind any (against its normal) is cut away
//!   (`wirepass::SectionPlane`).
//! - `camera`: `{"eye", "target", "up", "fov", "near", "far"}` (a perspective look-at;
//!   `far` may be `null` for an infinite far plane), or `{"view": [16], "projection": [16],
//!   "depth": "standard"|"reversed"}` (column-major matrices as a renderer has them), or
//!   `{"eye", "target", "up", "orthographic": {"height", "near", "far"}}` (`height` is the
//!   full height of the view volume in world units). Optional: without it the camera frames
//!   the scene.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::{Camera, DepthRange, View};
use crate::error::{Error, Result};
use crate::mesh::EdgeSelection;
use crate::scene::HiddenOverride;
use crate::scene::InstanceStyle;
use crate::style::{Color, HiddenLines, LinePattern};
use crate::world::{Object, World, WorldMesh};
use glam::{DMat4, DQuat, DVec3, EulerRot};
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// A scene file's camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FileCamera {
    /// A perspective look-at camera (its aspect comes from the image size).
    Perspective(Camera),
    /// An orthographic look-at view: eye, target, up, full height, near, far.
    Orthographic {
        /// Eye position.
        eye: DVec3,
        /// Point looked at.
        target: DVec3,
        /// Up direction.
        up: DVec3,
        /// Height of the view volume in world units.
        height: f64,
        /// Near plane distance (may be negative).
        near: f64,
        /// Far plane distance.
        far: f64,
    },
    /// The renderer's own matrices, used as they are.
    Matrices(View),
    /// A glTF file's camera.
    Gltf(crate::mesh::formats::gltf::GltfCamera),
}

impl FileCamera {
    /// The view for an image of aspect `aspect` (width / height).
    pub fn view(&self, aspect: f64) -> View {
        match *self {
            FileCamera::Perspective(c) => c.to_view(aspect),
            FileCamera::Orthographic {
                eye,
                target,
                up,
                height,
                near,
                far,
            } => View::orthographic((eye, target, up), height, aspect, (near, far)),
            FileCamera::Matrices(v) => v,
            FileCamera::Gltf(c) => c.view(aspect),
        }
    }
}

/// Loads a scene file. Objects without `edges` draw `edges`, or, where that is `None`, their
/// mesh's authored edges if it has them (polygon edges otherwise: see
/// [`Mesh::resolve_edges`](crate::Mesh::resolve_edges)); meshes named more than once (with
/// the same edges) are loaded once. `load_mesh` turns a mesh spec (procedural name or path,
/// already made relative to the scene file's folder) into a mesh.
pub fn load_scene(
    path: &Path,
    edges: Option<EdgeSelection>,
    load_mesh: &dyn Fn(&str) -> Result<crate::Mesh>,
) -> Result<SceneFile> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    let fail = |message: String| Error::SceneFile {
        path: path.to_owned(),
        message,
    };
    let json: Value = serde_json::from_str(&text).map_err(|e| fail(format!("not JSON: {e}")))?;
    let top = json
        .as_object()
        .ok_or_else(|| fail("the scene is not a JSON object".into()))?;
    for key in top.keys() {
        if !["objects", "camera", "style", "sections"].contains(&key.as_str()) {
            return Err(fail(format!(
                "unknown field {key:?} (objects, camera, style, sections)"
            )));
        }
    }
    let file_style = match top.get("style") {
        None => FileStyle::default(),
        Some(v) => file_style(v).map_err(|m| fail(format!("style{m}")))?,
    };
    let objects = top
        .get("objects")
        .ok_or_else(|| fail("no \"objects\" list".into()))?
        .as_array()
        .ok_or_else(|| fail("\"objects\" is not a list".into()))?;
    if objects.is_empty() {
        return Err(fail("\"objects\" is empty".into()));
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut world = World::default();
    let mut loaded: HashMap<(String, String), usize> = HashMap::new();
    let mut highlight = Vec::new();
    for (i, o) in objects.iter().enumerate() {
        let o = FileObject::new(o, i).map_err(fail)?;
        let (spec, object_edges, edges_off) = o.mesh(edges).map_err(fail)?;
        let resolved = resolve(base, spec);
        let key = (resolved.clone(), format!("{object_edges:?}"));
        let mesh = match loaded.get(&key) {
            Some(&m) => m,
            None => {
                let mesh = load_mesh(&resolved).map_err(|e| fail(o.says("mesh", e)))?;
                let (mesh, object_edges) = mesh.resolve_edges(object_edges);
                world.meshes.push(WorldMesh {
                    mesh: Arc::new(mesh),
                    edges: object_edges,
                    name: spec.to_owned(),
                });
                loaded.insert(key, world.meshes.len() - 1);
                world.meshes.len() - 1
            }
        };
        let transform = o.transform().map_err(fail)?;
        let style = o.style(edges_off, &file_style).map_err(fail)?;
        if o.flag("highlight").map_err(fail)? == Some(true) {
            highlight.push(i);
        }
        world.objects.push(Object {
            mesh,
            transform,
            style,
        });
    }
    if let Some(v) = top.get("sections") {
        world.sections = sections(v).map_err(|m| fail(format!("sections{m}")))?;
    }
    world.validate().map_err(|e| fail(e.to_string()))?;
    let camera = match top.get("camera") {
        None => None,
        Some(c) => Some(camera(c).map_err(|m| fail(format!("camera{m}")))?),
    };
    Ok(SceneFile {
        world,
        camera,
        style: file_style,
        highlight,
    })
}

/// The fields an object of a scene file may have.
const OBJECT_FIELDS: [&str; 15] = [
    "mesh",
    "transform",
    "edges",
    "outlines",
    "wire_color",
    "fill_color",
    "line_width",
    "outline_color",
    "outline_width",
    "edge_pattern",
    "outline_pattern",
    "hidden",
    "hidden_color",
    "hidden_width",
    "highlight",
];

/// One entry of a scene file's `objects`, read field by field; errors are messages naming
/// the field (`objects[i].name: …`).
struct FileObject<'a> {
    fields: &'a serde_json::Map<String, Value>,
    index: usize,
}

type Message<T> = std::result::Result<T, String>;

impl<'a> FileObject<'a> {
    /// Object `index` of the list, checked for unknown fields.
    fn new(value: &'a Value, index: usize) -> Message<FileObject<'a>> {
        let fields = value
            .as_object()
            .ok_or_else(|| format!("objects[{index}] is not an object"))?;
        let object = FileObject { fields, index };
        match fields.keys().find(|k| !OBJECT_FIELDS.contains(&k.as_str())) {
            Some(key) => {
                Err(object.says(key, format!("unknown field ({})", OBJECT_FIELDS.join(", "))))
            }
            None => Ok(object),
        }
    }

    /// `message` about field `name`.
    fn says(&self, name: &str, message: impl std::fmt::Display) -> String {
        format!("objects[{}].{name}: {message}", self.index)
    }

    fn text(&self, name: &str) -> Message<Option<&'a str>> {
        self.fields
            .get(name)
            .map(|v| v.as_str().ok_or_else(|| self.says(name, "not a string")))
            .transpose()
    }

    fn flag(&self, name: &str) -> Message<Option<bool>> {
        self.fields
            .get(name)
            .map(|v| {
                v.as_bool()
                    .ok_or_else(|| self.says(name, "not true or false"))
            })
            .transpose()
    }

    fn width(&self, name: &str) -> Message<Option<f32>> {
        self.fields
            .get(name)
            .map(|v| {
                v.as_f64()
                    .map(|w| w as f32)
                    .ok_or_else(|| self.says(name, "not a number"))
            })
            .transpose()
    }

    fn color(&self, name: &str) -> Message<Option<Color>> {
        self.text(name)?
            .map(|t| Color::from_hex(t).map_err(|e| self.says(name, e)))
            .transpose()
    }

    fn pattern(&self, name: &str) -> Message<Option<LinePattern>> {
        self.text(name)?
            .map(|t| LinePattern::parse_visible(t).map_err(|e| self.says(name, e)))
            .transpose()
    }

    /// Its mesh spec, the edges it asks for (`default` where it names none) and whether it
    /// draws none of them (`"edges": "none"`).
    fn mesh(
        &self,
        default: Option<EdgeSelection>,
    ) -> Message<(&'a str, Option<EdgeSelection>, bool)> {
        let spec = self
            .fields
            .get("mesh")
            .and_then(Value::as_str)
            .ok_or_else(|| self.says("mesh", "missing, or not a string"))?;
        Ok(match self.text("edges")? {
            None => (spec, default, false),
            Some("none") => (spec, default, true),
            Some(s) => {
                let edges = s
                    .parse::<EdgeSelection>()
                    .map_err(|e| self.says("edges", e))?;
                (spec, Some(edges), false)
            }
        })
    }

    /// Its placement: the identity where it gives none.
    fn transform(&self) -> Message<DMat4> {
        let t = match self.fields.get("transform") {
            None => DMat4::IDENTITY,
            Some(t) => transform(t).map_err(|m| self.says("transform", m))?,
        };
        crate::scene::check_transform(&t, self.index).map_err(|e| self.says("transform", e))?;
        Ok(t)
    }

    /// Its style; its hidden lines take what they leave out from the file's `style`, else
    /// the defaults.
    fn style(&self, edges_off: bool, file: &FileStyle) -> Message<InstanceStyle> {
        let mut style = InstanceStyle {
            edges: edges_off.then_some(false),
            outlines: self.flag("outlines")?,
            wire_color: self.color("wire_color")?,
            fill_color: self.color("fill_color")?,
            outline_color: self.color("outline_color")?,
            line_width: self.width("line_width")?,
            outline_width: self.width("outline_width")?,
            edge_pattern: self.pattern("edge_pattern")?,
            outline_pattern: self.pattern("outline_pattern")?,
            ..InstanceStyle::default()
        };
        let pattern = self
            .text("hidden")?
            .map(|t| LinePattern::parse(t).map_err(|e| self.says("hidden", e)))
            .transpose()?;
        let (color, width) = (self.color("hidden_color")?, self.width("hidden_width")?);
        if pattern.is_some() || color.is_some() || width.is_some() {
            let default = HiddenLines::default();
            let pattern = pattern.or(file.hidden).unwrap_or(Some(default.pattern));
            style.hidden = pattern.map_or(HiddenOverride::Off, |pattern| {
                HiddenOverride::Lines(HiddenLines {
                    pattern,
                    color: color.or(file.hidden_color).unwrap_or(default.color),
                    width: width.or(file.hidden_width).unwrap_or(default.width),
                    behind_host: false,
                    edges: true,
                })
            });
        }
        style
            .validate(self.index)
            .map_err(|e| format!("objects[{}]: {e}", self.index))?;
        Ok(style)
    }
}

/// What a scene file holds: its objects, its camera, and its frame style.
#[derive(Clone, Debug)]
pub struct SceneFile {
    /// The meshes and objects.
    pub world: World,
    /// The camera, if the file has one.
    pub camera: Option<FileCamera>,
    /// The frame's style settings the file gives.
    pub style: FileStyle,
    /// The objects marked `"highlight": true`, which the tools draw with a
    /// [`Highlight`](crate::Highlight).
    pub highlight: Vec<usize>,
}

/// The frame's style as a scene file's `style` gives it; `None` where it says nothing (the
/// command line's settings then hold).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FileStyle {
    /// `hidden`: `off` (`Some(None)`), `solid`, `dashed[:DASH,GAP]` or `dotted[:SPACING]`.
    pub hidden: Option<Option<LinePattern>>,
    /// `hidden_color`.
    pub hidden_color: Option<Color>,
    /// `hidden_width`, pixels.
    pub hidden_width: Option<f32>,
    /// `fill_opacity`, 0..1.
    pub fill_opacity: Option<f32>,
    /// `outline_color`.
    pub outline_color: Option<Color>,
    /// `outline_width`, pixels.
    pub outline_width: Option<f32>,
    /// `edge_pattern`: `solid`, `dashed[:DASH,GAP]` or `dotted[:SPACING]`.
    pub edge_pattern: Option<LinePattern>,
    /// `outline_pattern`, likewise.
    pub outline_pattern: Option<LinePattern>,
}

fn file_style(v: &Value) -> std::result::Result<FileStyle, String> {
    let o = v.as_object().ok_or(": not an object")?;
    const KEYS: [&str; 8] = [
        "hidden",
        "hidden_color",
        "hidden_width",
        "fill_opacity",
        "outline_color",
        "outline_width",
        "edge_pattern",
        "outline_pattern",
    ];
    if let Some(k) = o.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(format!(".{k}: unknown field ({})", KEYS.join(", ")));
    }
    let text = |k: &str| -> std::result::Result<Option<&str>, String> {
        o.get(k)
            .map(|v| v.as_str().ok_or(format!(".{k}: not a string")))
            .transpose()
    };
    let number = |k: &str| -> std::result::Result<Option<f32>, String> {
        o.get(k)
            .map(|v| {
                v.as_f64()
                    .map(|x| x as f32)
                    .ok_or(format!(".{k}: not a number"))
            })
            .transpose()
    };
    let color = |k: &str| -> std::result::Result<Option<Color>, String> {
        text(k)?
            .map(|t| Color::from_hex(t).map_err(|e| format!(".{k}: {e}")))
            .transpose()
    };
    let pattern = |k: &str| -> std::result::Result<Option<LinePattern>, String> {
        text(k)?
            .map(|t| LinePattern::parse_visible(t).map_err(|e| format!(".{k}: {e}")))
            .transpose()
    };
    Ok(FileStyle {
        hidden: text("hidden")?
            .map(|t| LinePattern::parse(t).map_err(|e| format!(".hidden: {e}")))
            .transpose()?,
        hidden_color: color("hidden_color")?,
        hidden_width: number("hidden_width")?,
        fill_opacity: number("fill_opacity")?,
        outline_color: color("outline_color")?,
        outline_width: number("outline_width")?,
        edge_pattern: pattern("edge_pattern")?,
        outline_pattern: pattern("outline_pattern")?,
    })
}

/// `sections`: a list of `{"point": [x, y, z], "normal": [x, y, z]}`.
fn sections(v: &Value) -> std::result::Result<Vec<crate::SectionPlane>, String> {
    let list = v.as_array().ok_or(": not a list")?;
    list.iter()
        .enumerate()
        .map(|(i, p)| {
            let o = p.as_object().ok_or(format!("[{i}]: not an object"))?;
            if let Some(k) = o
                .keys()
                .find(|k| !["point", "normal"].contains(&k.as_str()))
            {
                return Err(format!("[{i}].{k}: unknown field (point, normal)"));
            }
            let field = |k: &str| {
                o.get(k)
                    .ok_or(format!("[{i}].{k}: missing"))
                    .and_then(|v| vec3(v).map_err(|m| format!("[{i}].{k}: {m}")))
            };
            let plane = crate::SectionPlane::new(field("point")?, field("normal")?);
            plane.validate(i).map_err(|e| match e {
                Error::InvalidScene(m) => format!(": {m}"),
                e => format!(": {e}"),
            })?;
            Ok(plane)
        })
        .collect()
}

/// A mesh spec relative to the scene file's folder: procedural names stay as they are.
fn resolve(base: &Path, spec: &str) -> String {
    let procedural = spec.parse::<crate::mesh::Procedural>().is_ok();
    if procedural && !base.join(spec).exists() {
        return spec.to_owned();
    }
    base.join(spec).to_string_lossy().into_owned()
}

fn numbers(v: &Value, n: usize) -> std::result::Result<Vec<f64>, String> {
    let list = v
        .as_array()
        .ok_or_else(|| format!("expected a list of {n} numbers"))?;
    if list.len() != n {
        return Err(format!("expected {n} numbers, got {}", list.len()));
    }
    list.iter()
        .map(|x| {
            x.as_f64()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{x} is not a finite number"))
        })
        .collect()
}

fn vec3(v: &Value) -> std::result::Result<DVec3, String> {
    numbers(v, 3).map(|n| DVec3::new(n[0], n[1], n[2]))
}

fn transform(v: &Value) -> std::result::Result<DMat4, String> {
    if v.is_array() {
        let n = numbers(v, 16)?;
        let mut a = [0.0; 16];
        a.copy_from_slice(&n);
        return Ok(DMat4::from_cols_array(&a));
    }
    let o = v
        .as_object()
        .ok_or_else(|| "expected 16 numbers or {translate, rotate_deg, scale}".to_string())?;
    for key in o.keys() {
        if !["translate", "rotate_deg", "scale"].contains(&key.as_str()) {
            return Err(format!(
                ".{key}: unknown field (translate, rotate_deg, scale)"
            ));
        }
    }
    let translate = match o.get("translate") {
        Some(t) => vec3(t).map_err(|m| format!(".translate: {m}"))?,
        None => DVec3::ZERO,
    };
    let rotate = match o.get("rotate_deg") {
        Some(r) => vec3(r).map_err(|m| format!(".rotate_deg: {m}"))?,
        None => DVec3::ZERO,
    };
    let scale = match o.get("scale") {
        None => DVec3::ONE,
        Some(Value::Number(s)) => DVec3::splat(
            s.as_f64()
                .filter(|s| s.is_finite())
                .ok_or(".scale: not a finite number")?,
        ),
        Some(s) => vec3(s).map_err(|m| format!(".scale: {m}"))?,
    };
    // R = Rz · Ry · Rx: about X first.
    let r = DQuat::from_euler(
        EulerRot::ZYX,
        rotate.z.to_radians(),
        rotate.y.to_radians(),
        rotate.x.to_radians(),
    );
    Ok(DMat4::from_scale_rotation_translation(scale, r, translate))
}

fn camera(v: &Value) -> std::result::Result<FileCamera, String> {
    let o = v.as_object().ok_or(": not an object")?;
    let get = |k: &str| o.get(k);
    let num = |k: &str| -> std::result::Result<Option<f64>, String> {
        match get(k) {
            None | Some(Value::Null) => Ok(None),
            Some(x) => x
                .as_f64()
                .filter(|x| x.is_finite())
                .map(Some)
                .ok_or_else(|| format!(".{k}: not a finite number")),
        }
    };
    let v3 = |k: &str| -> std::result::Result<Option<DVec3>, String> {
        get(k)
            .map(|x| vec3(x).map_err(|m| format!(".{k}: {m}")))
            .transpose()
    };
    if let Some(view) = get("view") {
        for key in o.keys() {
            if !["view", "projection", "depth"].contains(&key.as_str()) {
                return Err(format!(
                    ".{key}: unknown field next to view (projection, depth)"
                ));
            }
        }
        let m = |x: &Value, k: &str| -> std::result::Result<DMat4, String> {
            let n = numbers(x, 16).map_err(|m| format!(".{k}: {m}"))?;
            let mut a = [0.0; 16];
            a.copy_from_slice(&n);
            Ok(DMat4::from_cols_array(&a))
        };
        let projection = get("projection").ok_or(".projection: missing next to view")?;
        let depth = match get("depth").map(|d| d.as_str()) {
            None | Some(Some("standard")) => DepthRange::Standard,
            Some(Some("reversed")) => DepthRange::Reversed,
            _ => return Err(".depth: not \"standard\" or \"reversed\"".into()),
        };
        let view = View::new(m(view, "view")?, m(projection, "projection")?, depth);
        view.validate().map_err(|e| format!(": {e}"))?;
        return Ok(FileCamera::Matrices(view));
    }
    let allowed = ["eye", "target", "up", "fov", "near", "far", "orthographic"];
    for key in o.keys() {
        if !allowed.contains(&key.as_str()) {
            return Err(format!(
                ".{key}: unknown field (eye, target, up, fov, near, far, orthographic, or view and projection)"
            ));
        }
    }
    let eye = v3("eye")?.ok_or(".eye: missing")?;
    let target = v3("target")?.unwrap_or(DVec3::ZERO);
    let up = v3("up")?.unwrap_or(DVec3::Y);
    if let Some(ortho) = get("orthographic") {
        let p = ortho.as_object().ok_or(".orthographic: not an object")?;
        let f = |k: &str| -> std::result::Result<f64, String> {
            p.get(k)
                .and_then(Value::as_f64)
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!(".orthographic.{k}: missing, or not a finite number"))
        };
        let (height, near, far) = (f("height")?, f("near")?, f("far")?);
        if !(height > 0.0) {
            return Err(format!(".orthographic.height: {height} is not > 0"));
        }
        if !(far > near) {
            return Err(format!(".orthographic: far {far} is not > near {near}"));
        }
        let cam = FileCamera::Orthographic {
            eye,
            target,
            up,
            height,
            near,
            far,
        };
        cam.view(1.0).validate().map_err(|e| format!(": {e}"))?;
        return Ok(cam);
    }
    let camera = Camera {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: up.as_vec3(),
        fov_y_deg: num("fov")?.unwrap_or(40.0) as f32,
        near: num("near")?.ok_or(".near: missing")? as f32,
        far: num("far")?.map_or(f32::INFINITY, |f| f as f32),
    };
    camera.validate().map_err(|e| format!(": {e}"))?;
    Ok(FileCamera::Perspective(camera))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("wirepass-scene-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    fn procedural(spec: &str) -> Result<crate::Mesh> {
        spec.parse::<crate::mesh::Procedural>()?.build()
    }

    #[test]
    fn trs_is_translate_rotate_scale_about_x_then_y_then_z() {
        let t = transform(&serde_json::json!({
            "translate": [1, 2, 3], "rotate_deg": [90, 90, 0], "scale": 2
        }))
        .unwrap();
        // x axis: scaled to 2, turned about X (stays), then about Y: to -z.
        let p = t.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 2.0, 1.0)).length() < 1e-12, "{p}");
        // y axis: about X to +z, then about Y to +x.
        let q = t.transform_point3(DVec3::Y);
        assert!((q - DVec3::new(3.0, 2.0, 3.0)).length() < 1e-12, "{q}");
    }

    #[test]
    fn objects_share_meshes_and_take_overrides() {
        let path = write(
            "two.json",
            r##"{"objects": [
                {"mesh": "sphere:200"},
                {"mesh": "sphere:200", "transform": {"translate": [3, 0, 0]}, "edges": "none",
                 "wire_color": "#ff0000", "line_width": 3, "fill_color": "#00ff00"},
                {"mesh": "sphere:200", "edges": "all", "outlines": false,
                 "edge_pattern": "dotted:3", "outline_pattern": "solid"},
                {"mesh": "sphere:200", "outline_color": "#0000ff", "outline_width": 4,
                 "hidden": "dashed:5,2", "hidden_width": 2},
                {"mesh": "sphere:200", "hidden": "off", "highlight": true}
            ],
            "camera": {"eye": [0, 0, 5], "orthographic": {"height": 4, "near": 0.1, "far": 20}},
            "style": {"hidden": "dotted:3", "fill_opacity": 0.25, "outline_width": 2,
                      "edge_pattern": "dashed:4,2"},
            "sections": [{"point": [0, 0, 0], "normal": [1, 0, 0]},
                         {"point": [0, 0.5, 0], "normal": [0, -1, 0]}]}"##,
        );
        let SceneFile {
            world,
            camera,
            style,
            highlight,
        } = load_scene(&path, Some(EdgeSelection::Polygon), &procedural).unwrap();
        assert_eq!(highlight, vec![4]);
        assert_eq!(
            style,
            FileStyle {
                hidden: Some(Some(LinePattern::Dotted { spacing: 3.0 })),
                fill_opacity: Some(0.25),
                outline_width: Some(2.0),
                edge_pattern: Some(LinePattern::Dashed {
                    dash: 4.0,
                    gap: 2.0
                }),
                ..FileStyle::default()
            }
        );
        assert_eq!(world.meshes.len(), 2, "same mesh and edges load once");
        assert_eq!(world.objects.len(), 5);
        // Its own pattern and width, the colour a default, as the file's style gives none.
        assert_eq!(
            world.objects[3].style.hidden,
            HiddenOverride::Lines(crate::HiddenLines {
                pattern: LinePattern::Dashed {
                    dash: 5.0,
                    gap: 2.0
                },
                width: 2.0,
                ..crate::HiddenLines::default()
            })
        );
        assert_eq!(world.objects[4].style.hidden, HiddenOverride::Off);
        assert_eq!(world.objects[0].style.hidden, HiddenOverride::Style);
        assert_eq!(world.objects[3].style.outline_width, Some(4.0));
        assert_eq!(
            world.objects[3].style.outline_color,
            Some(Color([0.0, 0.0, 1.0, 1.0]))
        );
        assert_eq!(world.objects[1].style.edges, Some(false));
        assert_eq!(world.objects[1].style.line_width, Some(3.0));
        assert_eq!(
            world.objects[1].style.fill_color,
            Some(Color([0.0, 1.0, 0.0, 1.0]))
        );
        assert_eq!(world.objects[0].style.fill_color, None);
        assert_eq!(world.objects[2].style.outlines, Some(false));
        assert_eq!(
            world.objects[2].style.edge_pattern,
            Some(LinePattern::Dotted { spacing: 3.0 })
        );
        assert_eq!(
            world.objects[2].style.outline_pattern,
            Some(LinePattern::Solid)
        );
        assert_eq!(world.objects[0].style.edge_pattern, None);
        assert_eq!(
            world.sections,
            vec![
                crate::SectionPlane::new(DVec3::ZERO, DVec3::X),
                crate::SectionPlane::new(DVec3::new(0.0, 0.5, 0.0), -DVec3::Y),
            ]
        );
        assert!(camera.unwrap().view(1.5).is_orthographic());
    }

    #[test]
    fn bad_scene_files_name_the_field() {
        let cases = [
            ("{", "not JSON"),
            ("[]", "not a JSON object"),
            (r#"{"objects": []}"#, "\"objects\" is empty"),
            (r#"{"objects": [{"mesh": 3}]}"#, "objects[0].mesh"),
            (
                r#"{"objects": [{"mesh": "sphere:100", "transform": [1, 2]}]}"#,
                "objects[0].transform: expected 16 numbers, got 2",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "transform": {"scale": 0}}]}"#,
                "singular",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "edges": "some"}]}"#,
                "objects[0].edges",
            ),
            (
                r##"{"objects": [{"mesh": "sphere:100", "colour": "#fff"}]}"##,
                "objects[0].colour: unknown field",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "line_width": 1000}]}"#,
                "line width 1000",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "hidden": "wavy"}]}"#,
                "objects[0].hidden",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "highlight": 1}]}"#,
                "objects[0].highlight",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "edge_pattern": "off"}]}"#,
                "objects[0].edge_pattern",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "outline_pattern": "dashed:0,3"}]}"#,
                "outline pattern",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "style": {"edge_pattern": "wavy"}}"#,
                "style.edge_pattern",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "sections": [{"point": [0, 0, 0], "normal": [0, 0, 0]}]}"#,
                "sections: section plane 0: its normal",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "sections": [{"point": [0, 0, 0]}]}"#,
                "sections[0].normal: missing",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "hidden_width": -1}]}"#,
                "hidden line width -1",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100", "fill_color": "green"}]}"#,
                "objects[0].fill_color",
            ),
            (
                r#"{"objects": [{"mesh": "missing.obj"}]}"#,
                "objects[0].mesh",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "camera": {"target": [0, 0, 0]}}"#,
                "camera.eye: missing",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "camera": {"view": [1]}}"#,
                "camera.projection",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "camera": {"eye": [0, 0, 5], "orthographic": {"height": -1, "near": 0, "far": 1}}}"#,
                "camera.orthographic.height",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "style": {"hidden": "wavy"}}"#,
                "style.hidden",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "style": {"fill_opacity": "half"}}"#,
                "style.fill_opacity",
            ),
            (
                r#"{"objects": [{"mesh": "sphere:100"}], "style": {"hiden": "solid"}}"#,
                "style.hiden",
            ),
        ];
        for (k, (text, want)) in cases.iter().enumerate() {
            let path = write(&format!("bad{k}.json"), text);
            let loader = |s: &str| match s.parse::<crate::mesh::Procedural>() {
                Ok(p) => p.build(),
                Err(_) => Err(Error::Io {
                    path: s.into(),
                    source: std::io::Error::from(std::io::ErrorKind::NotFound),
                }),
            };
            let e = load_scene(&path, Some(EdgeSelection::Polygon), &loader)
                .err()
                .unwrap_or_else(|| panic!("{text} loaded"))
                .to_string();
            assert!(e.contains(want), "{text}: {e}");
            assert!(e.contains(&format!("bad{k}.json")), "{e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
