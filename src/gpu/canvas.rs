//! What a frame draws onto: an image or a region of a larger one, and optionally the host's
//! depth buffer.

use crate::camera::View;
use crate::error::{Error, Result};

/// Which part of a full image the targets cover: all of it, or a tile of it, with a guard
/// band of `guard` pixels around the output on every side (so lines just outside the output
/// are found). Every pixel is addressed in full-image coordinates, so a tile computes
/// exactly what the whole image computes there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// The full image the projection maps onto, in pixels.
    pub image: (u32, u32),
    /// The output's first pixel in the full image.
    pub origin: (u32, u32),
    /// The output's size in pixels.
    pub size: (u32, u32),
}

impl Region {
    /// The whole image.
    pub fn whole(size: (u32, u32)) -> Region {
        Region {
            image: size,
            origin: (0, 0),
            size,
        }
    }

    /// Checks that the region lies inside its image.
    pub fn validate(&self) -> Result<()> {
        let (w, h) = self.size;
        let (x, y) = self.origin;
        let (iw, ih) = self.image;
        if w == 0 || h == 0 || iw == 0 || ih == 0 {
            return Err(Error::InvalidSetting(format!(
                "image size {iw}x{ih} or region size {w}x{h} has a zero side"
            )));
        }
        if u64::from(x) + u64::from(w) > u64::from(iw)
            || u64::from(y) + u64::from(h) > u64::from(ih)
        {
            return Err(Error::InvalidSetting(format!(
                "the region {w}x{h} at ({x}, {y}) reaches past the {iw}x{ih} image"
            )));
        }
        Ok(())
    }
}

/// What a frame draws onto: an image, or a region of a larger one, and optionally the
/// host's depth buffer. An image size converts into one: `pass.prepare(.., (800, 600))`.
#[derive(Clone, Copy, Debug)]
pub struct Canvas<'a> {
    /// The image, or the part of it the frame draws.
    pub region: Region,
    /// The host's depth: host geometry nearer than a wireframed surface hides its lines.
    pub host_depth: Option<HostDepth<'a>>,
}

impl<'a> Canvas<'a> {
    /// A whole image of `size` pixels.
    pub fn new(size: (u32, u32)) -> Canvas<'a> {
        Region::whole(size).into()
    }

    /// This canvas over the host's depth buffer.
    pub fn with_host_depth(self, host_depth: HostDepth<'a>) -> Canvas<'a> {
        Canvas {
            host_depth: Some(host_depth),
            ..self
        }
    }
}

impl From<Region> for Canvas<'_> {
    fn from(region: Region) -> Self {
        Canvas {
            region,
            host_depth: None,
        }
    }
}

impl From<(u32, u32)> for Canvas<'_> {
    fn from(size: (u32, u32)) -> Self {
        Canvas::new(size)
    }
}

/// The host's depth buffer, with the view it was rendered with.
///
/// Any depth format works (`Depth16Unorm`, `Depth24Plus`, `Depth24PlusStencil8`,
/// `Depth32Float`, `Depth32FloatStencil8`), single- or multisampled; the texture needs
/// `TEXTURE_BINDING` usage, and its size is the image's.
#[derive(Clone, Copy, Debug)]
pub struct HostDepth<'a> {
    /// The host's depth texture.
    pub texture: &'a wgpu::Texture,
    /// The matrices and depth convention the host rendered it with (usually the scene's
    /// view).
    pub matrices: View,
}
