//! One glTF mesh from its primitives: the triangles of every triangle mode, positions and
//! normals, and the edges the CAD extensions author (`EXT_mesh_primitive_edge_visibility`,
//! `CESIUM_primitive_outline`), with the line width `BENTLEY_materials_line_style` gives.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::buffers::Buffers;
use super::{named, FileResult, GltfMesh};
use crate::error::Error;
use crate::mesh::adjacency::NO_NEIGHBOUR;
use crate::mesh::{EdgeSelection, Mesh};
use crate::style::LinePattern;
use glam::Vec3;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use serde_json::Value;
use std::collections::{HashMap, HashSet};

/// An edge's visibility level, how much the file wants it drawn: 0 hidden, 1 silhouette
/// (the edge extension's own codes), 2 hard.
const HIDDEN: u8 = 0;
const HARD: u8 = 2;
/// Triangles of primitives without edge data.
const UNAUTHORED: u8 = u8::MAX;

/// What one glTF mesh is being turned into.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    any_normals: bool,
    triangles: Vec<[u32; 3]>,
    /// Per triangle, each edge's visibility level, once any primitive has edge data.
    levels: Option<Vec<[u8; 3]>>,
    line_width: Option<f32>,
    line_pattern: Option<LinePattern>,
}

pub(super) fn build_mesh(
    doc: &gltf::Document,
    buffers: &Buffers,
    index: usize,
    notes: &mut Vec<String>,
) -> FileResult<Option<GltfMesh>> {
    let Some(mesh) = doc.meshes().nth(index) else {
        return Err(format!("mesh {index} does not exist"));
    };
    let name = mesh
        .name()
        .map(str::to_owned)
        .unwrap_or_else(|| format!("mesh {index}"));
    let what = format!("mesh {index}{}", named(mesh.name()));
    let mut b = Builder::default();
    // Primitives that share vertex accessors share vertices.
    let mut bases: HashMap<(usize, Option<usize>), u32> = HashMap::new();
    let mut widths = Vec::new();
    let mut patterns = Vec::new();
    for p in mesh.primitives() {
        let at = format!("{what}, primitive {}", p.index());
        let mode = p.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            let name = match mode {
                Mode::Points => "POINTS",
                Mode::Lines => "LINES",
                Mode::LineLoop => "LINE_LOOP",
                _ => "LINE_STRIP",
            };
            notes.push(format!("{at}: mode {name} is not triangles; skipped"));
            continue;
        }
        if p.morph_targets().next().is_some() {
            notes.push(format!("{at}: morph targets are not applied"));
        }
        let position = p
            .get(&Semantic::Positions)
            .ok_or_else(|| format!("{at} has no POSITION"))?;
        let normal = p.get(&Semantic::Normals);
        let key = (position.index(), normal.as_ref().map(|n| n.index()));
        let vertices = position.count();
        let base = match bases.get(&key) {
            Some(&base) => base,
            None => {
                let base = b.positions.len();
                let positions = buffers
                    .read_vec3(&position, "POSITION")
                    .map_err(|m| format!("{at}: {m}"))?;
                let normals = match &normal {
                    Some(n) => {
                        let normals = buffers
                            .read_vec3(n, "NORMAL")
                            .map_err(|m| format!("{at}: {m}"))?;
                        if normals.len() != positions.len() {
                            return Err(format!(
                                "{at}: {} normals for {} positions",
                                normals.len(),
                                positions.len()
                            ));
                        }
                        Some(normals)
                    }
                    None => None,
                };
                b.positions.extend_from_slice(&positions);
                // Vertices without normals get NaN ones, filled with smooth normals once the
                // triangles are known; none are kept until some primitive has normals.
                match normals {
                    Some(n) => {
                        b.normals.resize(base, Vec3::NAN);
                        b.normals.extend(n);
                        b.any_normals = true;
                    }
                    None if b.any_normals => b.normals.resize(b.positions.len(), Vec3::NAN),
                    None => {}
                }
                let base = u32::try_from(base)
                    .ok()
                    .filter(|_| b.positions.len() <= u32::MAX as usize)
                    .ok_or_else(|| format!("{what} has more vertices than u32 indices reach"))?;
                bases.insert(key, base);
                base
            }
        };
        // The index list lives only until it is cut into triangles: on large meshes it is
        // as big as they are.
        let indices = match p.indices() {
            Some(acc) => {
                let indices = buffers
                    .read_indices(&acc, "indices")
                    .map_err(|m| format!("{at}: {m}"))?;
                if let Some((k, &v)) = indices
                    .iter()
                    .enumerate()
                    .find(|&(_, &v)| v as usize >= vertices)
                {
                    return Err(format!(
                        "{at}: index {k} refers to vertex {v}, but the primitive has {vertices} vertices"
                    ));
                }
                indices
            }
            None => (0..u32::try_from(vertices).map_err(|_| format!("{at}: too many vertices"))?)
                .collect(),
        };
        let tris = triangles(mode, &indices, &at, notes);
        drop(indices);
        let first = b.triangles.len();
        let count = tris.len();

        // Edge data of this primitive: levels per triangle edge, or none.
        let mut levels: Option<Vec<[u8; 3]>> = None;
        if let Some(ext) = p.extension_value("EXT_mesh_primitive_edge_visibility") {
            let l = edge_visibility(doc, buffers, ext, &tris, count)
                .map_err(|m| format!("{at}: EXT_mesh_primitive_edge_visibility: {m}"))?;
            levels = Some(l);
        }
        if let Some(ext) = p.extension_value("CESIUM_primitive_outline") {
            let listed = outline_pairs(doc, buffers, ext)
                .map_err(|m| format!("{at}: CESIUM_primitive_outline: {m}"))?;
            let l = levels.get_or_insert_with(|| vec![[HIDDEN; 3]; count]);
            mark_pairs(l, &tris, &listed);
        }
        if let Some(l) = levels {
            let all = b.levels.get_or_insert_with(|| vec![[UNAUTHORED; 3]; first]);
            all.extend(l);
        } else if let Some(all) = &mut b.levels {
            all.resize(first + count, [UNAUTHORED; 3]);
        }
        if first == 0 && base == 0 {
            b.triangles = tris;
        } else {
            b.triangles.extend(tris.iter().map(|t| t.map(|v| v + base)));
        }
        let (width, pattern) = line_style(doc, &p, notes, &at);
        widths.extend(width);
        patterns.extend(pattern);
    }
    if b.triangles.is_empty() {
        notes.push(format!("{what} has no triangles; its nodes are not drawn"));
        return Ok(None);
    }
    if let Some(&w) = widths.first() {
        if widths.iter().any(|&x| x != w) {
            notes.push(format!(
                "{what}: its primitives ask for line widths {widths:?}; one width is drawn per object: {w}"
            ));
        }
        b.line_width = Some(w);
    }
    if let Some(&p) = patterns.first() {
        if patterns.iter().any(|&x| x != p) {
            notes.push(format!(
                "{what}: its primitives ask for line patterns {patterns:?}; one pattern is drawn per object: {p:?}"
            ));
        }
        b.line_pattern = Some(p);
    }
    finish(b, &what, name).map(Some)
}

/// Triangles of a primitive's index list in the order §3.7.2.1 of the glTF specification
/// gives (the order the edge extensions count by): strips alternate their winding, fans
/// turn around the first vertex.
fn triangles(mode: Mode, idx: &[u32], at: &str, notes: &mut Vec<String>) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (0..idx.len().saturating_sub(2))
            .map(|i| {
                let odd = i % 2;
                [idx[i], idx[i + 1 + odd], idx[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (0..idx.len().saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => {
            if !idx.len().is_multiple_of(3) {
                notes.push(format!(
                    "{at}: {} indices are not whole triangles; the last {} are ignored",
                    idx.len(),
                    idx.len() % 3
                ));
            }
            idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
    }
}

/// An accessor named by an extension's property.
fn accessor_at<'d>(
    doc: &'d gltf::Document,
    value: &Value,
    name: &str,
) -> FileResult<gltf::Accessor<'d>> {
    let i = value
        .get(name)
        .ok_or_else(|| format!("no {name}"))?
        .as_u64()
        .ok_or_else(|| format!("{name} is not an accessor index"))?;
    usize::try_from(i)
        .ok()
        .and_then(|i| doc.accessors().nth(i))
        .ok_or_else(|| format!("{name}: accessor {i} does not exist"))
}

/// Per triangle edge, the visibility levels an `EXT_mesh_primitive_edge_visibility` object
/// gives (its `visibility` bits, and its `lineStrings` as hard edges).
fn edge_visibility(
    doc: &gltf::Document,
    buffers: &Buffers,
    ext: &Value,
    tris: &[[u32; 3]],
    count: usize,
) -> FileResult<Vec<[u8; 3]>> {
    let mut levels = vec![[HIDDEN; 3]; count];
    if ext.get("visibility").is_some() {
        let acc = accessor_at(doc, ext, "visibility")?;
        if acc.dimensions() != Dimensions::Scalar || acc.data_type() != DataType::U8 {
            return Err(format!(
                "visibility accessor {} is not unsigned byte scalars",
                acc.index()
            ));
        }
        let need = (6 * count).div_ceil(8);
        if acc.count() < need {
            return Err(format!(
                "visibility accessor {} has {} bytes; {count} triangles need {need}",
                acc.index(),
                acc.count()
            ));
        }
        let bits = buffers.read(&acc, |b| b[0])?;
        for (t, l) in levels.iter_mut().enumerate() {
            for (k, level) in l.iter_mut().enumerate() {
                let bit = 6 * t + 2 * k;
                // 3, a repeated hard edge, is hard too.
                *level = ((bits[bit / 8] >> (bit % 8)) & 3).min(HARD);
            }
        }
    }
    if let Some(strings) = ext.get("lineStrings") {
        let strings = strings.as_array().ok_or("lineStrings is not a list")?;
        let mut pairs = HashSet::new();
        for (s, string) in strings.iter().enumerate() {
            let acc = accessor_at(doc, string, "indices")
                .map_err(|m| format!("lineStrings[{s}]: {m}"))?;
            let restart = match acc.data_type() {
                DataType::U8 => u32::from(u8::MAX),
                DataType::U16 => u32::from(u16::MAX),
                _ => u32::MAX,
            };
            let idx = buffers.read_indices(&acc, "lineStrings")?;
            for w in idx.windows(2) {
                if w[0] != restart && w[1] != restart {
                    pairs.insert(edge_key(w[0], w[1]));
                }
            }
        }
        mark_pairs(&mut levels, tris, &pairs);
    } else if ext.get("visibility").is_none() {
        return Err("neither visibility nor lineStrings".into());
    }
    Ok(levels)
}

/// The vertex pairs a `CESIUM_primitive_outline` object lists.
fn outline_pairs(
    doc: &gltf::Document,
    buffers: &Buffers,
    ext: &Value,
) -> FileResult<HashSet<(u32, u32)>> {
    let acc = accessor_at(doc, ext, "indices")?;
    let idx = buffers.read_indices(&acc, "indices")?;
    if !idx.len().is_multiple_of(2) {
        return Err(format!("{} indices do not make pairs", idx.len()));
    }
    Ok(idx.chunks_exact(2).map(|p| edge_key(p[0], p[1])).collect())
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Raises the edges whose vertex pairs (the primitive's own indices) are listed to hard.
fn mark_pairs(levels: &mut [[u8; 3]], tris: &[[u32; 3]], pairs: &HashSet<(u32, u32)>) {
    if pairs.is_empty() {
        return;
    }
    for (l, t) in levels.iter_mut().zip(tris) {
        for k in 0..3 {
            if pairs.contains(&edge_key(t[k], t[(k + 1) % 3])) {
                l[k] = HARD;
            }
        }
    }
}

/// The width and pattern `BENTLEY_materials_line_style` gives the primitive's edges, if
/// any.
fn line_style(
    doc: &gltf::Document,
    p: &gltf::Primitive,
    notes: &mut Vec<String>,
    at: &str,
) -> (Option<f32>, Option<LinePattern>) {
    let edge_material = p
        .extension_value("EXT_mesh_primitive_edge_visibility")
        .and_then(|e| e.get("material"))
        .and_then(Value::as_u64)
        .and_then(|i| doc.materials().nth(usize::try_from(i).ok()?));
    let material = edge_material.unwrap_or_else(|| p.material());
    let Some(style) = material.extension_value("BENTLEY_materials_line_style") else {
        return (None, None);
    };
    let pattern = style.get("pattern").and_then(|v| {
        let bits = v.as_u64().and_then(|b| u16::try_from(b).ok());
        let pattern = bits.and_then(LinePattern::from_bits);
        if pattern.is_none() {
            notes.push(format!(
                "{at}: the line pattern {v} is not a 16-bit pattern of one dash (or dot) \
                 repeating; lines are solid"
            ));
        }
        pattern
    });
    let width = style.get("width").and_then(|v| match v.as_f64() {
        Some(w) if w > 0.0 && w <= f64::from(crate::style::MAX_LINE_WIDTH) => Some(w as f32),
        _ => {
            notes.push(format!(
                "{at}: line width {v} is not in (0, {}] pixels; ignored",
                crate::style::MAX_LINE_WIDTH
            ));
            None
        }
    });
    (width, pattern)
}

/// Builds the mesh, then its authored edge masks from the levels.
fn finish(b: Builder, what: &str, name: String) -> FileResult<GltfMesh> {
    let Builder {
        positions,
        mut normals,
        any_normals,
        triangles,
        levels,
        line_width,
        line_pattern,
    } = b;
    let invalid = |e: Error| match e {
        Error::InvalidMesh(m) => format!("{what}: {m}"),
        e => format!("{what}: {e}"),
    };
    let normals = if any_normals {
        if normals.iter().any(|n| n.x.is_nan()) {
            let smooth = crate::mesh::smooth_normals(&positions, &triangles);
            for (n, s) in normals.iter_mut().zip(smooth) {
                if n.x.is_nan() {
                    *n = s;
                }
            }
        }
        Some(normals)
    } else {
        None
    };
    let mut mesh = Mesh::new(positions, normals, triangles, None).map_err(invalid)?;
    let mut edges = None;
    if let Some(levels) = levels {
        let levels = shared_levels(&levels, mesh.edge_neighbours());
        let mask = |keep: fn(u8) -> bool| -> Vec<u8> {
            levels
                .iter()
                .map(|l| (0..3).filter(|&k| keep(l[k])).fold(0, |m, k| m | 1 << k))
                .collect()
        };
        let drawn = mask(|l| l == HARD || l == UNAUTHORED);
        let outline = mask(|l| l != HIDDEN);
        mesh = mesh
            .with_authored_edges(drawn)
            .and_then(|m| m.with_outline_mask(outline))
            .map_err(invalid)?;
        edges = Some(EdgeSelection::Authored);
    }
    Ok(GltfMesh {
        mesh,
        name,
        edges,
        line_width,
        line_pattern,
    })
}

/// Each edge's level raised to the most visible of its occurrences: the triangle across it
/// (by the mesh's adjacency) may hold the one the file wrote. Triangles without edge data
/// neither give nor take.
fn shared_levels(levels: &[[u8; 3]], neighbours: &[[u32; 3]]) -> Vec<[u8; 3]> {
    levels
        .iter()
        .enumerate()
        .map(|(t, l)| {
            let mut out = *l;
            for k in 0..3 {
                let n = neighbours[t][k];
                if l[k] == UNAUTHORED || n == NO_NEIGHBOUR {
                    continue;
                }
                for j in 0..3 {
                    let across = levels[n as usize][j];
                    if neighbours[n as usize][j] == t as u32 && across != UNAUTHORED {
                        out[k] = out[k].max(across);
                    }
                }
            }
            out
        })
        .collect()
}
