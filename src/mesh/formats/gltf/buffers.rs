//! The bytes behind a glTF file's accessors: its buffers (the GLB chunk, base64 `data:`
//! URIs, files beside it), their views, and typed reads of vertex attributes and indices,
//! sparse accessors and normalized integers included.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::{FileResult, Resolver};
use glam::Vec3;
use gltf::accessor::{DataType, Dimensions};
use std::borrow::Cow;

/// The bytes of every buffer of the file.
pub(super) struct Buffers<'a> {
    data: Vec<Cow<'a, [u8]>>,
    /// All their bytes together: a bound for accessors without a buffer view.
    total: usize,
}

impl<'a> Buffers<'a> {
    pub(super) fn load(
        doc: &gltf::Document,
        blob: Option<Cow<'a, [u8]>>,
        resolve: Resolver<'_>,
    ) -> FileResult<Buffers<'a>> {
        let mut blob = blob;
        let mut data = Vec::new();
        for buffer in doc.buffers() {
            let i = buffer.index();
            let bytes: Cow<[u8]> = match buffer.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                    format!("buffer {i} is the GLB binary chunk, which the file lacks")
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    Cow::Owned(read_uri(uri, resolve).map_err(|m| format!("buffer {i}: {m}"))?)
                }
            };
            if bytes.len() < buffer.length() {
                return Err(format!(
                    "buffer {i} declares {} bytes, but has {}",
                    buffer.length(),
                    bytes.len()
                ));
            }
            data.push(bytes);
        }
        let total = data.iter().map(|d| d.len()).sum();
        Ok(Buffers { data, total })
    }

    /// The bytes of a buffer view, checked against its buffer.
    fn view(&self, view: &gltf::buffer::View) -> FileResult<&[u8]> {
        let buffer = &self.data[view.buffer().index()];
        let (start, length) = (view.offset(), view.length());
        start
            .checked_add(length)
            .and_then(|end| buffer.get(start..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {}: bytes {start} to {} run past buffer {}'s {} bytes",
                    view.index(),
                    start as u128 + length as u128,
                    view.buffer().index(),
                    buffer.len()
                )
            })
    }

    /// Every element of `accessor`, each through `convert` (given the element's bytes),
    /// with sparse substitutions applied. Sizes are checked before anything is allocated.
    pub(super) fn read<T: Clone>(
        &self,
        accessor: &gltf::Accessor,
        convert: impl Fn(&[u8]) -> T,
    ) -> FileResult<Vec<T>> {
        let a = accessor.index();
        let count = accessor.count();
        let size = accessor.size();
        let mut out = match accessor.view() {
            Some(view) => {
                let bytes = self.view(&view)?;
                let stride = view.stride().unwrap_or(size);
                if stride < size {
                    return Err(format!(
                        "accessor {a}: buffer view {} has a stride of {stride} bytes, less than an element's {size}",
                        view.index()
                    ));
                }
                let offset = accessor.offset();
                let end = if count == 0 {
                    Some(offset)
                } else {
                    (count - 1)
                        .checked_mul(stride)
                        .and_then(|b| b.checked_add(size))
                        .and_then(|b| b.checked_add(offset))
                };
                let data = end.and_then(|end| bytes.get(offset..end)).ok_or_else(|| {
                    format!(
                        "accessor {a}: {count} elements of {size} bytes (stride {stride}) from byte {offset} run past the {} bytes of buffer view {}",
                        bytes.len(),
                        view.index()
                    )
                })?;
                (0..count)
                    .map(|i| convert(&data[i * stride..i * stride + size]))
                    .collect()
            }
            None => {
                // All zeros (then the sparse values): nothing bounds the count but the
                // file's own size, as every element is worth at least a byte somewhere.
                if count > self.total.max(1 << 16) {
                    return Err(format!(
                        "accessor {a} declares {count} elements without a buffer view, more than the file's {} buffer bytes",
                        self.total
                    ));
                }
                vec![convert(&vec![0u8; size]); count]
            }
        };
        if let Some(sparse) = accessor.sparse() {
            let n = sparse.count();
            let indices = sparse.indices();
            let index_size = indices.index_type().size();
            let index_bytes = self.view(&indices.view())?;
            let value_bytes = self.view(&sparse.values().view())?;
            let slice = |bytes: &'_ [u8], offset: usize, each: usize, what: &str| {
                n.checked_mul(each)
                    .and_then(|l| l.checked_add(offset))
                    .and_then(|end| bytes.get(offset..end).map(<[u8]>::to_vec))
                    .ok_or_else(|| {
                        format!("accessor {a}: {n} sparse {what} run past their buffer view")
                    })
            };
            let ib = slice(index_bytes, indices.offset(), index_size, "indices")?;
            let vb = slice(value_bytes, sparse.values().offset(), size, "values")?;
            for k in 0..n {
                let i = read_index(&ib[k * index_size..(k + 1) * index_size]);
                let slot = out.get_mut(i as usize).ok_or_else(|| {
                    format!("accessor {a}: sparse index {i} is past its {count} elements")
                })?;
                *slot = convert(&vb[k * size..(k + 1) * size]);
            }
        }
        Ok(out)
    }

    /// A vertex attribute of three components as f32: floats, or the integer types
    /// `KHR_mesh_quantization` allows, normalized or not.
    pub(super) fn read_vec3(&self, accessor: &gltf::Accessor, what: &str) -> FileResult<Vec<Vec3>> {
        if accessor.dimensions() != Dimensions::Vec3 {
            return Err(format!(
                "{what} accessor {} is {:?}, not VEC3",
                accessor.index(),
                accessor.dimensions()
            ));
        }
        let component =
            component_reader(accessor.data_type(), accessor.normalized()).ok_or_else(|| {
                format!(
                    "{what} accessor {} has components of type {:?}{}, which glTF does not allow",
                    accessor.index(),
                    accessor.data_type(),
                    if accessor.normalized() {
                        " (normalized)"
                    } else {
                        ""
                    }
                )
            })?;
        let w = accessor.data_type().size();
        self.read(accessor, |e| {
            Vec3::new(
                component(&e[..w]),
                component(&e[w..2 * w]),
                component(&e[2 * w..]),
            )
        })
    }

    /// Unsigned integer scalars (indices), widened to u32.
    pub(super) fn read_indices(
        &self,
        accessor: &gltf::Accessor,
        what: &str,
    ) -> FileResult<Vec<u32>> {
        let ok = accessor.dimensions() == Dimensions::Scalar
            && matches!(
                accessor.data_type(),
                DataType::U8 | DataType::U16 | DataType::U32
            );
        if !ok {
            return Err(format!(
                "{what} accessor {} is {:?} of {:?}, not unsigned byte, short or int scalars",
                accessor.index(),
                accessor.dimensions(),
                accessor.data_type()
            ));
        }
        self.read(accessor, read_index)
    }
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn read_index(b: &[u8]) -> u32 {
    match *b {
        [x] => u32::from(x),
        [x, y] => u32::from(u16::from_le_bytes([x, y])),
        [x, y, z, w] => u32::from_le_bytes([x, y, z, w]),
        _ => 0,
    }
}

/// How to read one component of a vertex attribute as f32 (normalized integers as the glTF
/// specification maps them: signed ones to [−1, 1], unsigned ones to [0, 1]).
fn component_reader(ty: DataType, normalized: bool) -> Option<fn(&[u8]) -> f32> {
    Some(match (ty, normalized) {
        (DataType::F32, false) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::I8, false) => |b| f32::from(b[0] as i8),
        (DataType::I8, true) => |b| (f32::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::U8, false) => |b| f32::from(b[0]),
        (DataType::U8, true) => |b| f32::from(b[0]) / 255.0,
        (DataType::I16, false) => |b| f32::from(i16::from_le_bytes([b[0], b[1]])),
        (DataType::I16, true) => {
            |b| (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }
        (DataType::U16, false) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])),
        (DataType::U16, true) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        _ => return None,
    })
}

/// Reads a buffer's URI: a base64 `data:` URI, or a relative reference (percent-encoded,
/// as URIs are) that `resolve` turns into bytes.
fn read_uri(uri: &str, resolve: Resolver<'_>) -> FileResult<Vec<u8>> {
    use base64::Engine as _;
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data: URI that is not base64")?;
        let engine = base64::engine::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        return engine
            .decode(data.trim_end())
            .map_err(|e| format!("its data: URI is not valid base64 ({e})"));
    }
    if let Some((scheme, _)) = uri.split_once(':') {
        // A scheme is letters and digits (and + - .) before the colon; a Windows drive
        // letter alone is a path.
        if scheme.len() > 1
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        {
            return Err(format!(
                "'{uri}': {scheme}: URIs are not read, only files and data: URIs"
            ));
        }
    }
    let decoded = urlencoding::decode(uri)
        .map_err(|_| format!("'{uri}' is not UTF-8 once percent-decoded"))?;
    resolve(&decoded)
}
