//! STL loading, binary and ASCII, through `stl_io`.
//!
//! Which of the two a file is comes from its size first: a binary STL is exactly
//! `84 + 50 × n` bytes for the `n` triangles its header declares, and many binary files
//! start their free-form header with "solid" too, so that word alone decides nothing. An
//! ASCII file cannot match the formula below 7 GB, since its bytes 80..84 are text and read
//! as a count of at least 0x09090909. The length is checked before any triangle is read, so
//! a header that declares more triangles than the file holds fails at once.

use super::read::{build, file_error, io_error, open};
use crate::error::Result;
use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// Bytes before the first triangle of a binary STL: an 80-byte header and the count.
const HEADER: u64 = 84;
/// Bytes of one binary triangle: normal, three corners, attribute count.
const RECORD: u64 = 50;
/// Bytes looked at to tell an ASCII file from a binary one whose header says "solid".
const SNIFF: u64 = 512;

/// Loads a binary or ASCII STL file as one mesh.
///
/// STL stores every triangle with its own three corners, so corners are welded by exact
/// position (−0.0 equal to 0.0) into shared vertices: without that, every edge would be a
/// boundary, outlines would trace every triangle and normals could not be smoothed. The
/// facet normals of the file are ignored and smooth normals computed from the welded
/// triangles: facet normals are flat per triangle (and often zero or stale in real files),
/// so keeping them would need unwelded corners. Every triangle edge is a polygon edge.
/// An ASCII file is read up to its first `endsolid` (or its end, if that is missing).
pub fn load_stl(path: &Path) -> Result<Mesh> {
    let (file, len) = open(path, "an STL")?;
    let reopen = || -> Option<Box<dyn BufRead>> {
        let file = std::fs::File::open(path).ok()?;
        Some(Box::new(BufReader::new(file)))
    };
    read_stl(path, BufReader::new(file), len, &reopen)
}

/// [`load_stl`] from the bytes of a file (a browser's files come as bytes); `name` names
/// the file in errors, which are the same as from a file.
pub fn load_stl_bytes(name: &Path, bytes: &[u8]) -> Result<Mesh> {
    let reopen = || -> Option<Box<dyn BufRead + '_>> { Some(Box::new(bytes)) };
    read_stl(
        name,
        std::io::Cursor::new(bytes),
        bytes.len() as u64,
        &reopen,
    )
}

/// Reads the text of the file again from its start, to say where an ASCII error is.
type Reopen<'r, 'b> = &'r dyn Fn() -> Option<Box<dyn BufRead + 'b>>;

/// Reads an STL of `len` bytes from `reader`; `path` names it in errors.
fn read_stl<R: BufRead + Seek>(
    path: &Path,
    mut reader: R,
    len: u64,
    reopen: Reopen<'_, '_>,
) -> Result<Mesh> {
    let fail = |line, message| file_error(path, line, message);
    if len == 0 {
        return Err(fail(None, "empty file: not an STL file".into()));
    }
    // The header, the count and what follows, to tell text from binary.
    let mut head = Vec::with_capacity(SNIFF as usize);
    (&mut reader)
        .take(SNIFF)
        .read_to_end(&mut head)
        .map_err(|e| io_error(path, e))?;
    reader
        .seek(SeekFrom::Start(0))
        .map_err(|e| io_error(path, e))?;
    let declared = head
        .get(80..84)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let expected = declared.map(|n| HEADER + RECORD * u64::from(n));
    // Control characters other than whitespace mean binary data.
    let text = head.starts_with(b"solid") && !head.iter().any(|&b| b < 9 || (14..32).contains(&b));

    if let (Some(n), Some(size)) = (declared, expected) {
        if size == len {
            if n == 0 {
                return Err(fail(
                    None,
                    "binary STL with 0 triangles: nothing to draw".into(),
                ));
            }
            return read_binary(path, reader, n);
        }
        if !text {
            let what = if size > len {
                "truncated"
            } else {
                "extra data after the last triangle"
            };
            return Err(fail(
                None,
                format!(
                    "binary STL header declares {n} triangles, {size} bytes, but the file \
                     has {len} bytes ({what})"
                ),
            ));
        }
    }
    if text {
        return read_ascii(path, reader, reopen);
    }
    Err(fail(
        None,
        format!(
            "{len} bytes: too short for a binary STL (84-byte header) and not an ASCII STL, \
             which starts with 'solid'"
        ),
    ))
}

/// `prefix`, then the bytes of `inner` from `skip` on, as one seekable stream. It replaces
/// a file's first bytes so that `stl_io`, which picks ASCII for any file that starts with
/// "solid " and otherwise binary, reads the format decided here.
struct Spliced<R> {
    prefix: &'static [u8],
    inner: R,
    skip: u64,
    pos: u64,
}

impl<R: Read + Seek> Spliced<R> {
    fn new(prefix: &'static [u8], mut inner: R, skip: u64) -> std::io::Result<Self> {
        inner.seek(SeekFrom::Start(skip))?;
        Ok(Self {
            prefix,
            inner,
            skip,
            pos: 0,
        })
    }
}

impl<R: Read> Read for Spliced<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = if let Some(rest) = self
            .prefix
            .get(self.pos as usize..)
            .filter(|r| !r.is_empty())
        {
            let n = rest.len().min(buf.len());
            buf[..n].copy_from_slice(&rest[..n]);
            n
        } else {
            self.inner.read(buf)?
        };
        self.pos += n as u64;
        Ok(n)
    }
}

impl<R: Seek> Seek for Spliced<R> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let SeekFrom::Start(pos) = to else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Unsupported,
                "only seeks from the start",
            ));
        };
        let prefix = self.prefix.len() as u64;
        self.inner
            .seek(SeekFrom::Start(self.skip + pos.saturating_sub(prefix)))?;
        self.pos = pos;
        Ok(pos)
    }
}

/// Welds corners by exact position: −0.0 and 0.0 are one key.
#[derive(Default)]
struct Welder {
    positions: Vec<Vec3>,
    index: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn vertex(&mut self, p: [f32; 3]) -> u32 {
        let key = p.map(|c| (c + 0.0).to_bits());
        let next = self.positions.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(Vec3::from(p));
            next
        })
    }
}

fn read_binary<R: Read + Seek>(path: &Path, reader: R, count: u32) -> Result<Mesh> {
    // The header becomes a newline and zeros: stl_io's ASCII probe then reads one empty
    // line, rather than searching a binary file for a newline.
    const BLANK: [u8; 80] = {
        let mut h = [0u8; 80];
        h[0] = b'\n';
        h
    };
    let mut spliced = Spliced::new(&BLANK, reader, 80).map_err(|e| io_error(path, e))?;
    let triangles_in = stl_io::create_stl_reader(&mut spliced).map_err(|e| io_error(path, e))?;
    // The count is checked against the file's length, so reserving for it is safe.
    let count = count as usize;
    let mut welder = Welder {
        positions: Vec::with_capacity(count / 2 + 3),
        index: HashMap::with_capacity(count / 2 + 3),
    };
    let mut triangles = Vec::with_capacity(count);
    for (t, triangle) in triangles_in.enumerate() {
        let triangle = triangle.map_err(|e| io_error(path, e))?;
        let mut corners = [0u32; 3];
        for (k, v) in triangle.vertices.iter().enumerate() {
            if let Some(c) = v.0.iter().position(|c| !c.is_finite()) {
                let at = HEADER + RECORD * t as u64 + 12 + 12 * k as u64 + 4 * c as u64;
                return Err(file_error(
                    path,
                    None,
                    format!(
                        "at byte {at}: triangle {} of {count} has coordinate {} = {}, which \
                         is not finite",
                        t + 1,
                        ["x", "y", "z"][c],
                        v.0[c]
                    ),
                ));
            }
            corners[k] = welder.vertex(v.0);
        }
        triangles.push(corners);
    }
    build(path, welder.positions, None, triangles, None)
}

fn read_ascii<R: Read + Seek>(path: &Path, reader: R, reopen: Reopen<'_, '_>) -> Result<Mesh> {
    // "solid" becomes "solid ": stl_io needs the space, which a file without a solid name
    // may lack.
    let mut spliced = Spliced::new(b"solid ", reader, 5).map_err(|e| io_error(path, e))?;
    let facets = stl_io::create_stl_reader(&mut spliced).map_err(|e| io_error(path, e))?;
    let mut welder = Welder::default();
    let mut triangles = Vec::new();
    for (t, facet) in facets.enumerate() {
        let facet = match facet {
            Ok(f) => f,
            // The file ends after a whole facet without `endsolid`, as some writers leave it.
            Err(e)
                if e.kind() == std::io::ErrorKind::UnexpectedEof
                    && e.to_string()
                        .starts_with("EOF while expecting facet or endsolid") =>
            {
                break;
            }
            Err(e)
                if e.kind() == std::io::ErrorKind::InvalidData
                    || e.kind() == std::io::ErrorKind::UnexpectedEof =>
            {
                let (line, message) = locate_ascii_error(reopen, t, &e.to_string());
                return Err(file_error(path, line, message));
            }
            Err(e) => return Err(io_error(path, e)),
        };
        let corners = facet.vertices.map(|v| welder.vertex(v.0));
        triangles.push(corners);
    }
    if triangles.is_empty() {
        return Err(file_error(
            path,
            None,
            "ASCII STL with no facets: nothing to draw".into(),
        ));
    }
    build(path, welder.positions, None, triangles, None)
}

/// The line and a message for an ASCII STL that `stl_io` rejected in facet `t` (0-based)
/// with `message`. stl_io reads a facet as 7 non-blank lines after the `solid` line; this
/// finds the first of facet `t`'s lines that breaks the layout and says what it expected.
/// Where that finds nothing (an I/O error while reading), the facet's first line and
/// stl_io's message are used.
fn locate_ascii_error(reopen: Reopen<'_, '_>, t: usize, message: &str) -> (Option<usize>, String) {
    let fallback = (None, format!("facet {}: {message}", t + 1));
    let Some(text) = reopen() else {
        return fallback;
    };
    // (line number, words) of the non-blank lines, the `solid` line first.
    let mut lines = text
        .split(b'\n')
        .enumerate()
        .map_while(|(i, l)| l.ok().map(|l| (i + 1, l)))
        .filter_map(|(i, l)| {
            let text = String::from_utf8_lossy(&l).into_owned();
            let words: Vec<String> = text.split_whitespace().map(str::to_owned).collect();
            (!words.is_empty()).then_some((i, words))
        })
        .skip(1 + 7 * t);
    let number = |w: &str, what: &str| -> std::result::Result<(), String> {
        match w.parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(()),
            Ok(_) => Err(format!("{what} '{w}' is not finite")),
            Err(_) => Err(format!("{what} '{w}' is not a number")),
        }
    };
    let numbers = |words: &[String], what: &str| -> std::result::Result<(), String> {
        words.iter().try_for_each(|w| number(w, what))
    };
    let facet = t + 1;
    let mut last = None;
    for step in 0..7 {
        let Some((line, words)) = lines.next() else {
            let message = match step {
                0 => "the file ends without 'endsolid'".to_owned(),
                _ => format!("the file ends inside facet {facet}"),
            };
            return (last, message);
        };
        last = Some(line);
        let w: Vec<&str> = words.iter().map(String::as_str).collect();
        let problem = match step {
            0 if w[0] == "endsolid" => return fallback,
            0 if w.len() != 5 || w[0] != "facet" || w[1] != "normal" => Err(format!(
                "expected 'facet normal NX NY NZ', found '{}'",
                w.join(" ")
            )),
            0 => numbers(&words[2..], "facet normal component"),
            1 if w != ["outer", "loop"] => {
                Err(format!("expected 'outer loop', found '{}'", w.join(" ")))
            }
            2..=4 if w.len() != 4 || w[0] != "vertex" => {
                Err(format!("expected 'vertex X Y Z', found '{}'", w.join(" ")))
            }
            2..=4 => numbers(&words[1..], "vertex coordinate"),
            5 if w != ["endloop"] => Err(format!("expected 'endloop', found '{}'", w.join(" "))),
            6 if w != ["endfacet"] => Err(format!("expected 'endfacet', found '{}'", w.join(" "))),
            _ => Ok(()),
        };
        if let Err(problem) = problem {
            return (Some(line), format!("facet {facet}: {problem}"));
        }
    }
    fallback
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spliced_stream_replaces_the_first_bytes_and_seeks_back() {
        let inner = std::io::Cursor::new(b"solid\nfacet".to_vec());
        let mut s = Spliced::new(b"solid ", inner, 5).unwrap();
        let mut text = String::new();
        s.read_to_string(&mut text).unwrap();
        assert_eq!(text, "solid \nfacet");
        s.seek(SeekFrom::Start(0)).unwrap();
        let mut first = [0u8; 7];
        s.read_exact(&mut first).unwrap();
        assert_eq!(&first, b"solid \n");
    }

    #[test]
    fn welding_joins_signed_zeros() {
        let mut w = Welder::default();
        assert_eq!(w.vertex([0.0, 1.0, -0.0]), 0);
        assert_eq!(w.vertex([-0.0, 1.0, 0.0]), 0);
        assert_eq!(w.vertex([0.0, 1.0, 1e-45]), 1);
        assert_eq!(w.positions.len(), 2);
    }
}
