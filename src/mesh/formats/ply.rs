//! PLY loading (ASCII, binary little and big endian) through `ply-rs-bw`: its header
//! parser, and its element readers driven one element at a time, so that faces are
//! triangulated as they arrive instead of being kept as a list per face.
//!
//! Before any element is read, the header's counts are checked against the bytes that
//! follow it (at least 2 bytes per ASCII value, the declared sizes in binary), so a header
//! that declares billions of vertices over a few bytes of data fails at once, and no
//! buffer is reserved for a count the file cannot hold.

use super::read::{build, file_error, io_error, open};
use crate::error::{Error, Result};
use crate::mesh::polygon::{polygon_edges, triangulate};
use crate::mesh::{Mesh, ALL_EDGES};
use glam::Vec3;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    BeginList, ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType,
    ScalarType,
};
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Names of the face property that lists a face's vertices; both are in use.
const INDEX_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];
/// Vertex properties read: position, then the optional normal.
const VERTEX_NAMES: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];

/// Loads a PLY file (ASCII, binary little endian or binary big endian) as one mesh.
///
/// Vertices need `x`, `y` and `z` properties of any numeric type; `nx`, `ny` and `nz`,
/// when all three are present, give the normals (otherwise smooth normals are computed).
/// Faces come from the `face` element's `vertex_indices` (or `vertex_index`) list of any
/// integer type; polygons are ear-clipped like OBJ faces, and the diagonals that adds are
/// left out of the polygon edge mask. Other elements and properties (colours, texture
/// coordinates, edges, materials) are read past and ignored.
pub fn load_ply(path: &Path) -> Result<Mesh> {
    let (file, len) = open(path, "a PLY")?;
    read_ply(path, BufReader::with_capacity(1 << 16, file), len)
}

/// [`load_ply`] from the bytes of a file (a browser's files come as bytes); `name` names the
/// file in errors, which are the same as from a file.
pub fn load_ply_bytes(name: &Path, bytes: &[u8]) -> Result<Mesh> {
    read_ply(name, bytes, bytes.len() as u64)
}

/// Reads a PLY of `len` bytes from `input`; `path` names it in errors.
fn read_ply(path: &Path, input: impl BufRead, len: u64) -> Result<Mesh> {
    if len == 0 {
        return Err(file_error(path, None, "empty file: not a PLY file".into()));
    }
    let mut reader = Reader::new(Counted {
        inner: input,
        pos: 0,
    });
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(|e| header_error(path, &e))?;
    let layout = Layout::of(&header).map_err(|m| file_error(path, None, m))?;
    let data_start = reader.get_ref().pos;
    check_sizes(&header, len.saturating_sub(data_start)).map_err(|m| file_error(path, None, m))?;

    let first_line = reader.line();
    let mut loader = Loader {
        path,
        encoding: header.encoding,
        reader,
        line: first_line,
        text: String::new(),
        vertex_count: layout.vertex_count,
        positions: Vec::new(),
        normals: layout.normals.then(Vec::new),
        triangles: Vec::new(),
        edges: Vec::new(),
        pending: Vec::new(),
        pending_sizes: Vec::new(),
        corners: Vec::new(),
        points: Vec::new(),
        local: Vec::new(),
    };
    for def in header.elements.values() {
        match def.name.as_str() {
            "vertex" if def.count > 0 => loader.read_vertices(def)?,
            "face" => loader.read_faces(def)?,
            _ => loader.skip(def)?,
        }
    }
    loader.finish()
}

/// What the header says about the vertex and face elements, checked.
struct Layout {
    vertex_count: usize,
    normals: bool,
}

impl Layout {
    fn of(header: &Header) -> std::result::Result<Self, String> {
        let find = |name: &str| header.elements.values().find(|e| e.name == name);
        let vertex = find("vertex").ok_or("the header has no vertex element")?;
        let scalar = |name: &str| {
            vertex
                .properties
                .get(name)
                .map(|p| matches!(p.data_type, PropertyType::Scalar(_)))
        };
        for name in &VERTEX_NAMES[..3] {
            match scalar(name) {
                None => return Err(format!("the vertex element has no '{name}' property")),
                Some(false) => {
                    return Err(format!(
                        "vertex property '{name}' is a list; coordinates are single numbers"
                    ))
                }
                Some(true) => {}
            }
        }
        let normals = VERTEX_NAMES[3..].iter().all(|n| scalar(n) == Some(true));
        if vertex.count > u32::MAX as usize {
            return Err(format!(
                "{} vertices exceed the u32 indices of a mesh",
                vertex.count
            ));
        }
        let face = match find("face") {
            Some(f) if f.count > 0 => f,
            Some(_) => return Err("0 faces: no faces, nothing to draw".into()),
            None => {
                return Err("no face element: no faces, nothing to draw (a point cloud?)".into())
            }
        };
        let lists: Vec<_> = INDEX_NAMES
            .iter()
            .filter_map(|n| face.properties.get(*n))
            .collect();
        match lists[..] {
            [] => {
                return Err(format!(
                    "the face element has no '{}' (or '{}') property",
                    INDEX_NAMES[0], INDEX_NAMES[1]
                ))
            }
            [p] => match &p.data_type {
                PropertyType::List(count, item) if is_integer(count) && is_integer(item) => {}
                PropertyType::List(count, item) => {
                    return Err(format!(
                        "face property '{}' is a list of {} counted by {}; both must be \
                         integer types",
                        p.name,
                        type_name(item),
                        type_name(count)
                    ))
                }
                PropertyType::Scalar(_) => {
                    return Err(format!(
                        "face property '{}' is a single number, not a list",
                        p.name
                    ))
                }
            },
            _ => {
                return Err(format!(
                    "the face element has both '{}' and '{}'",
                    INDEX_NAMES[0], INDEX_NAMES[1]
                ))
            }
        }
        Ok(Self {
            vertex_count: vertex.count,
            normals,
        })
    }
}

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

fn type_name(t: &ScalarType) -> &'static str {
    match t {
        ScalarType::Char => "char",
        ScalarType::UChar => "uchar",
        ScalarType::Short => "short",
        ScalarType::UShort => "ushort",
        ScalarType::Int => "int",
        ScalarType::UInt => "uint",
        ScalarType::Float => "float",
        ScalarType::Double => "double",
    }
}

fn type_size(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest bytes an element can take: in binary its scalars and list counts, in ASCII
/// a digit and a separator per value (lists may be empty), and a line at least.
fn min_bytes(def: &ElementDef, encoding: Encoding) -> u64 {
    match encoding {
        Encoding::Ascii => (2 * def.properties.len() as u64).max(1),
        _ => def
            .properties
            .values()
            .map(|p| match &p.data_type {
                PropertyType::Scalar(t) | PropertyType::List(t, _) => type_size(t),
            })
            .sum(),
    }
}

/// Checks that the data after the header can hold every element the header declares.
fn check_sizes(header: &Header, available: u64) -> std::result::Result<(), String> {
    let mut need: u128 = 0;
    for def in header.elements.values() {
        let bytes = u128::from(min_bytes(def, header.encoding)) * def.count as u128;
        need += bytes;
        if need > u128::from(available) {
            return Err(format!(
                "the header declares {} {} elements, at least {bytes} bytes of data, but only \
                 {available} bytes follow the header",
                def.count, def.name
            ));
        }
    }
    Ok(())
}

/// A one-line message for a header that ply-rs rejected, naming the line where it has one.
fn header_error(path: &Path, e: &ParseError) -> Error {
    let crate_message = e.to_string();
    let crate_message = crate_message
        .strip_prefix(&format!("Line {}: ", e.line().unwrap_or(0)))
        .unwrap_or(&crate_message);
    let first = crate_message.lines().next().unwrap_or_default().trim();
    let Some(line) = e.line() else {
        let message = match e.kind() {
            std::io::ErrorKind::InvalidData => "the header is not text (invalid UTF-8)".into(),
            std::io::ErrorKind::UnexpectedEof => "the file ends in its header".into(),
            _ if first.starts_with("No format line") => "the header has no format line".into(),
            _ => format!("unreadable header: {first}"),
        };
        return file_error(path, None, message);
    };
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        return file_error(
            path,
            Some(line),
            "the header has no 'end_header' line".into(),
        );
    }
    let text = header_line(path, line).unwrap_or_default();
    let words: Vec<&str> = text.split_whitespace().collect();
    const TYPES: [&str; 16] = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
        "int16", "uint16", "int32", "uint32", "float32", "float64",
    ];
    let message = match words.first().copied() {
        _ if line == 1 => "not a PLY file: it does not start with 'ply'".to_owned(),
        Some("property") => {
            let types = match words.get(1).copied() {
                Some("list") => words.get(2..4).unwrap_or(&words[2..]).to_vec(),
                Some(t) => vec![t],
                None => vec![],
            };
            match types.iter().find(|t| !TYPES.contains(t)) {
                Some(t) => format!(
                    "unknown property type '{t}'; PLY has char, uchar, short, ushort, int, \
                     uint, float and double (or int8 … float64)"
                ),
                None => format!("cannot read property line '{text}'"),
            }
        }
        Some("element") => {
            format!("cannot read element line '{text}': expected 'element NAME COUNT'")
        }
        Some("format") => format!(
            "cannot read format line '{text}': expected ascii, binary_little_endian or \
             binary_big_endian, version 1.0"
        ),
        _ if first.starts_with("Couldn't parse line") => {
            format!("unknown header line '{text}'")
        }
        _ => format!("header line '{text}': {first}"),
    };
    file_error(path, Some(line), message)
}

/// Line `n` (1-based) of the file, read again for an error message.
fn header_line(path: &Path, n: usize) -> Option<String> {
    let file = std::fs::File::open(path).ok()?;
    let line = BufReader::new(file)
        .split(b'\n')
        .nth(n.checked_sub(1)?)?
        .ok()?;
    let text = String::from_utf8_lossy(&line);
    Some(text.trim().chars().take(200).collect())
}

/// A reader that counts the bytes taken from it, for byte offsets in error messages.
struct Counted<R> {
    inner: R,
    pos: u64,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.pos += n as u64;
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counted<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, n: usize) {
        self.inner.consume(n);
        self.pos += n as u64;
    }
}

/// An element whose properties are all ignored.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// A vertex: position and normal, as f64 whatever their type in the file.
#[derive(Default)]
struct VertexIn([f64; 6]);

impl VertexIn {
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match VERTEX_NAMES.iter().position(|&n| n == name) {
            Some(k) => {
                self.0[k] = value;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

impl PropertyAccess for VertexIn {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value)
    }
}

/// A face's vertex list, filled in place in whichever integer type the file uses.
#[derive(Default)]
struct FaceIn {
    i8s: Vec<i8>,
    u8s: Vec<u8>,
    i16s: Vec<i16>,
    u16s: Vec<u16>,
    i32s: Vec<i32>,
    u32s: Vec<u32>,
}

impl FaceIn {
    /// The vertex indices, widened; only one of the lists is ever filled.
    fn indices(&self) -> impl Iterator<Item = i64> + '_ {
        self.i8s
            .iter()
            .map(|&i| i64::from(i))
            .chain(self.u8s.iter().map(|&i| i64::from(i)))
            .chain(self.i16s.iter().map(|&i| i64::from(i)))
            .chain(self.u16s.iter().map(|&i| i64::from(i)))
            .chain(self.i32s.iter().map(|&i| i64::from(i)))
            .chain(self.u32s.iter().map(|&i| i64::from(i)))
    }
}

fn fill<'a, T>(name: &str, list: &'a mut Vec<T>) -> BeginList<'a, T> {
    if INDEX_NAMES.contains(&name) {
        BeginList::Fill(list)
    } else {
        BeginList::UseSetter
    }
}

impl PropertyAccess for FaceIn {
    fn new() -> Self {
        Self::default()
    }
    fn begin_list_char(&mut self, name: &str, _len: usize) -> BeginList<'_, i8> {
        fill(name, &mut self.i8s)
    }
    fn begin_list_uchar(&mut self, name: &str, _len: usize) -> BeginList<'_, u8> {
        fill(name, &mut self.u8s)
    }
    fn begin_list_short(&mut self, name: &str, _len: usize) -> BeginList<'_, i16> {
        fill(name, &mut self.i16s)
    }
    fn begin_list_ushort(&mut self, name: &str, _len: usize) -> BeginList<'_, u16> {
        fill(name, &mut self.u16s)
    }
    fn begin_list_int(&mut self, name: &str, _len: usize) -> BeginList<'_, i32> {
        fill(name, &mut self.i32s)
    }
    fn begin_list_uint(&mut self, name: &str, _len: usize) -> BeginList<'_, u32> {
        fill(name, &mut self.u32s)
    }
}

/// The state of one load: the stream, where it is, and the mesh so far.
struct Loader<'p, R: BufRead> {
    path: &'p Path,
    encoding: Encoding,
    reader: Reader<Counted<R>>,
    /// The line of the next ASCII element.
    line: usize,
    /// One ASCII line, reused.
    text: String,
    vertex_count: usize,
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
    edges: Vec<u8>,
    /// Polygons that came before the vertices, as flat corners and sizes, triangulated once
    /// the positions are known.
    pending: Vec<u32>,
    pending_sizes: Vec<u32>,
    /// Scratch space for one face.
    corners: Vec<u32>,
    points: Vec<Vec3>,
    local: Vec<[usize; 3]>,
}

impl<R: BufRead> Loader<'_, R> {
    /// Where element `k` (0-based) of `what` starts, and an error there.
    fn error_at(&self, at: Location, what: &str, k: usize, message: &str) -> Error {
        match at {
            Location::Line(line) => file_error(
                self.path,
                Some(line),
                format!("{what} {}: {message}", k + 1),
            ),
            Location::Byte(byte) => file_error(
                self.path,
                None,
                format!("at byte {byte}: {what} {}: {message}", k + 1),
            ),
        }
    }

    fn location(&self) -> Location {
        match self.encoding {
            Encoding::Ascii => Location::Line(self.line),
            _ => Location::Byte(self.reader.get_ref().pos),
        }
    }

    /// Reads element `k` of `def`.
    fn read<E: PropertyAccess>(
        &mut self,
        parser: &Parser<E>,
        def: &ElementDef,
        k: usize,
    ) -> Result<E> {
        let at = self.location();
        let what = def.name.as_str();
        let ends = || format!("the file ends after {k} of {} {what} elements", def.count);
        let result = match self.encoding {
            Encoding::Ascii => {
                self.text.clear();
                match self.reader.get_mut().read_line(&mut self.text) {
                    Ok(0) => return Err(self.error_at(at, what, k, &ends())),
                    Ok(_) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::InvalidData => {
                        return Err(self.error_at(at, what, k, "the line is not text"))
                    }
                    Err(e) => return Err(io_error(self.path, e)),
                }
                self.line += 1;
                parser.read_ascii_element(&self.text, def).map_err(|e| {
                    let shown: String = self.text.trim().chars().take(80).collect();
                    let why = first_line(&e);
                    let why = if why.starts_with("Couldn't parse element line") {
                        "it is not a list of numbers".to_owned()
                    } else if why.starts_with("Parse error") {
                        "a value does not fit its property's type".to_owned()
                    } else {
                        why
                    };
                    format!("cannot read '{shown}': {why}")
                })
            }
            Encoding::BinaryLittleEndian => parser
                .read_little_endian_element(self.reader.get_mut(), def)
                .map_err(|e| binary_message(&e, &ends)),
            Encoding::BinaryBigEndian => parser
                .read_big_endian_element(self.reader.get_mut(), def)
                .map_err(|e| binary_message(&e, &ends)),
        };
        result.map_err(|m| self.error_at(at, what, k, &m))
    }

    fn skip(&mut self, def: &ElementDef) -> Result<()> {
        // A binary element without properties takes no bytes: nothing to read, however many.
        if def.properties.is_empty() && self.encoding != Encoding::Ascii {
            return Ok(());
        }
        let parser = Parser::<Skip>::new();
        for k in 0..def.count {
            self.read(&parser, def, k)?;
        }
        Ok(())
    }

    fn read_vertices(&mut self, def: &ElementDef) -> Result<()> {
        // The count was checked against the file's length.
        self.positions.reserve_exact(def.count);
        if let Some(n) = &mut self.normals {
            n.reserve_exact(def.count);
        }
        let parser = Parser::<VertexIn>::new();
        for k in 0..def.count {
            let at = self.location();
            let v = self.read(&parser, def, k)?.0;
            let single = v.map(|c| c as f32);
            if let Some(c) = (0..6).find(|&c| !single[c].is_finite()) {
                let message = format!(
                    "{} = {} is not finite{}",
                    VERTEX_NAMES[c],
                    v[c],
                    if v[c].is_finite() {
                        " as a 32-bit float"
                    } else {
                        ""
                    }
                );
                // Normals are checked only when they are used.
                if c < 3 || self.normals.is_some() {
                    return Err(self.error_at(at, "vertex", k, &message));
                }
            }
            self.positions
                .push(Vec3::new(single[0], single[1], single[2]));
            if let Some(n) = &mut self.normals {
                n.push(Vec3::new(single[3], single[4], single[5]));
            }
        }
        // Polygons read before the vertices.
        let (pending, sizes) = (
            std::mem::take(&mut self.pending),
            std::mem::take(&mut self.pending_sizes),
        );
        let mut start = 0;
        for &size in &sizes {
            let end = start + size as usize;
            self.add_face(&pending[start..end]);
            start = end;
        }
        Ok(())
    }

    fn read_faces(&mut self, def: &ElementDef) -> Result<()> {
        let parser = Parser::<FaceIn>::new();
        let have_positions = !self.positions.is_empty();
        let mut corners = std::mem::take(&mut self.corners);
        for k in 0..def.count {
            let at = self.location();
            let face = self.read(&parser, def, k)?;
            corners.clear();
            for i in face.indices() {
                if i < 0 {
                    return Err(self.error_at(
                        at,
                        "face",
                        k,
                        &format!("vertex index {i} is negative"),
                    ));
                }
                if i >= self.vertex_count as i64 {
                    return Err(self.error_at(
                        at,
                        "face",
                        k,
                        &format!(
                            "vertex index {i}, but there are only {} vertices",
                            self.vertex_count
                        ),
                    ));
                }
                corners.push(i as u32);
            }
            if corners.len() < 3 {
                return Err(self.error_at(
                    at,
                    "face",
                    k,
                    &format!("{} vertices; a face needs at least 3", corners.len()),
                ));
            }
            if have_positions {
                self.add_face(&corners);
            } else {
                self.pending.extend_from_slice(&corners);
                self.pending_sizes.push(corners.len() as u32);
            }
        }
        self.corners = corners;
        Ok(())
    }

    /// Triangulates one polygon whose corners index known positions.
    fn add_face(&mut self, corners: &[u32]) {
        if let &[a, b, c] = corners {
            self.triangles.push([a, b, c]);
            self.edges.push(ALL_EDGES);
            return;
        }
        self.points.clear();
        self.points
            .extend(corners.iter().map(|&v| self.positions[v as usize]));
        self.local.clear();
        triangulate(&self.points, &mut self.local);
        for &t in &self.local {
            self.triangles.push(t.map(|k| corners[k]));
            self.edges.push(polygon_edges(t, corners.len()));
        }
    }

    fn finish(self) -> Result<Mesh> {
        if !self.pending_sizes.is_empty() {
            // Faces but no vertex element with vertices: every index was out of range.
            return Err(file_error(self.path, None, "faces but no vertices".into()));
        }
        build(
            self.path,
            self.positions,
            self.normals,
            self.triangles,
            Some(self.edges),
        )
    }
}

#[derive(Clone, Copy)]
enum Location {
    Line(usize),
    Byte(u64),
}

/// The first line of a ply-rs message, which go on with indented details.
fn first_line(e: &ParseError) -> String {
    let s = e.to_string();
    let s = match e.line() {
        Some(l) => s
            .strip_prefix(&format!("Line {l}: "))
            .unwrap_or(&s)
            .to_owned(),
        None => s,
    };
    s.lines().next().unwrap_or_default().trim().to_owned()
}

fn binary_message(e: &ParseError, ends: &dyn Fn() -> String) -> String {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        ends()
    } else {
        first_line(e)
    }
}
