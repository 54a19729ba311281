//! A small glTF writer for tests and benches: accessors over one binary buffer, meshes,
//! nodes, cameras, and the three ways to store the buffer (GLB chunk, base64 data URI,
//! external .bin file).
#![allow(dead_code)]

use serde_json::{json, Value};

/// glTF component types.
pub const BYTE: u32 = 5120;
pub const UNSIGNED_BYTE: u32 = 5121;
pub const SHORT: u32 = 5122;
pub const UNSIGNED_SHORT: u32 = 5123;
pub const UNSIGNED_INT: u32 = 5125;
pub const FLOAT: u32 = 5126;

/// Primitive modes.
pub const LINES: u32 = 1;
pub const TRIANGLES: u32 = 4;
pub const TRIANGLE_STRIP: u32 = 5;
pub const TRIANGLE_FAN: u32 = 6;

/// A glTF document being written: its JSON and its one binary buffer.
pub struct GltfFile {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Default for GltfFile {
    fn default() -> Self {
        Self::new()
    }
}

fn push(list: &mut Value, item: Value) -> usize {
    let list = list.as_array_mut().expect("a JSON list");
    list.push(item);
    list.len() - 1
}

impl GltfFile {
    pub fn new() -> GltfFile {
        GltfFile {
            json: json!({
                "asset": {"version": "2.0", "generator": "wirepass tests"},
                "buffers": [], "bufferViews": [], "accessors": [], "meshes": [],
                "nodes": [], "scenes": [], "cameras": [], "materials": []
            }),
            bin: Vec::new(),
        }
    }

    /// Appends `bytes` (4-byte aligned) as a buffer view; returns its index.
    pub fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(s) = stride {
            view["byteStride"] = json!(s);
        }
        push(&mut self.json["bufferViews"], view)
    }

    /// An accessor over a new view of `bytes`.
    pub fn accessor(
        &mut self,
        bytes: &[u8],
        component: u32,
        count: usize,
        kind: &str,
        normalized: bool,
    ) -> usize {
        let view = self.view(bytes, None);
        let mut a =
            json!({"bufferView": view, "componentType": component, "count": count, "type": kind});
        if normalized {
            a["normalized"] = json!(true);
        }
        push(&mut self.json["accessors"], a)
    }

    /// Float VEC3 positions, with the min and max glTF requires.
    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let a = self.accessor(&bytes, FLOAT, p.len(), "VEC3", false);
        self.bounds(a, p);
        a
    }

    /// Sets an accessor's min and max from `p`.
    pub fn bounds(&mut self, accessor: usize, p: &[[f32; 3]]) {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for q in p {
            for k in 0..3 {
                if q[k].is_finite() {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
        }
        let a = &mut self.json["accessors"][accessor];
        a["min"] = json!(lo);
        a["max"] = json!(hi);
    }

    /// Float VEC3 normals.
    pub fn normals(&mut self, n: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = n.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        self.accessor(&bytes, FLOAT, n.len(), "VEC3", false)
    }

    /// Indices as u8, u16 or u32 (`component`).
    pub fn indices(&mut self, idx: &[u32], component: u32) -> usize {
        let bytes: Vec<u8> = match component {
            UNSIGNED_BYTE => idx.iter().map(|&i| i as u8).collect(),
            UNSIGNED_SHORT => idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
            _ => idx.iter().flat_map(|&i| i.to_le_bytes()).collect(),
        };
        self.accessor(&bytes, component, idx.len(), "SCALAR", false)
    }

    /// Unsigned byte scalars (an edge visibility bitfield).
    pub fn bytes(&mut self, b: &[u8]) -> usize {
        self.accessor(b, UNSIGNED_BYTE, b.len(), "SCALAR", false)
    }

    pub fn mesh(&mut self, primitives: Vec<Value>) -> usize {
        push(&mut self.json["meshes"], json!({"primitives": primitives}))
    }

    pub fn node(&mut self, node: Value) -> usize {
        push(&mut self.json["nodes"], node)
    }

    pub fn camera(&mut self, camera: Value) -> usize {
        push(&mut self.json["cameras"], camera)
    }

    pub fn material(&mut self, material: Value) -> usize {
        push(&mut self.json["materials"], material)
    }

    /// Scene 0 (the default) with these root nodes.
    pub fn scene(&mut self, roots: &[usize]) {
        push(&mut self.json["scenes"], json!({"nodes": roots}));
        self.json["scene"] = json!(0);
    }

    /// The JSON with the buffer given by `uri` (none when there is no binary data).
    fn json_with(&self, uri: Option<String>) -> Value {
        let mut json = self.json.clone();
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        json["buffers"] = json!([buffer]);
        json
    }

    /// A `.glb`: JSON chunk, then the binary chunk.
    pub fn glb(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.json_with(None)).unwrap();
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }

    /// A `.gltf` with the buffer embedded as a base64 data URI.
    pub fn embedded(&self) -> Vec<u8> {
        use base64::Engine as _;
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        let uri = format!("data:application/octet-stream;base64,{data}");
        serde_json::to_vec_pretty(&self.json_with(Some(uri))).unwrap()
    }

    /// A `.gltf` naming an external buffer file `bin_name`, and that file's bytes.
    pub fn external(&self, bin_name: &str) -> (Vec<u8>, Vec<u8>) {
        let json = serde_json::to_vec_pretty(&self.json_with(Some(bin_name.to_owned()))).unwrap();
        (json, self.bin.clone())
    }

    /// A triangle primitive of `positions` and `indices` (u32), with `extensions`.
    pub fn triangles(
        &mut self,
        positions: &[[f32; 3]],
        indices: &[u32],
        extensions: Option<Value>,
    ) -> Value {
        let p = self.positions(positions);
        let i = self.indices(indices, UNSIGNED_INT);
        let mut prim = json!({"attributes": {"POSITION": p}, "indices": i, "mode": TRIANGLES});
        if let Some(e) = extensions {
            prim["extensions"] = e;
        }
        prim
    }
}

/// Packs per-triangle edge visibility codes (edges v0:v1, v1:v2, v2:v0; 2 bits each, from
/// the low bits of the first byte up) as `EXT_mesh_primitive_edge_visibility` stores them.
pub fn visibility_bits(codes: &[[u8; 3]]) -> Vec<u8> {
    let mut out = vec![0u8; (6 * codes.len()).div_ceil(8)];
    for (t, c) in codes.iter().enumerate() {
        for (k, &code) in c.iter().enumerate() {
            let bit = 6 * t + 2 * k;
            out[bit / 8] |= (code & 3) << (bit % 8);
        }
    }
    out
}

/// Visibility codes for triangles from each edge's wanted level (0 hidden, 1 silhouette, 2
/// hard) as `level(triangle, edge)` gives it, written as the specification wants: a shared
/// edge (by corner positions) carries its level at its first occurrence, and 3 (hard) or 0
/// (silhouette) at later ones.
pub fn codes_for(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    level: impl Fn(usize, usize) -> u8,
) -> Vec<[u8; 3]> {
    let key = |p: [f32; 3]| p.map(f32::to_bits);
    let mut seen = std::collections::HashSet::new();
    triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut c = [0u8; 3];
            for k in 0..3 {
                let (a, b) = (
                    key(positions[tri[k] as usize]),
                    key(positions[tri[(k + 1) % 3] as usize]),
                );
                let first = seen.insert(if a < b { (a, b) } else { (b, a) });
                c[k] = match (level(t, k), first) {
                    (0, _) => 0,
                    (1, true) => 1,
                    (1, false) => 0,
                    (_, true) => 2,
                    (_, false) => 3,
                };
            }
            c
        })
        .collect()
}
