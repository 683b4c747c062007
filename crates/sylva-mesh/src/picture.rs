//! Which pictures a material shows, made and encoded once per process.
//!
//! A [`Material`] shows at most a base picture ([`Picture::base_of`]) and a normal map
//! ([`Picture::normal_of`]):
//!
//! | material | base picture | normal map |
//! | --- | --- | --- |
//! | a texture id, no surface | [`Picture::Design`]: the design of [`crate::texture`] | — |
//! | [`Surface::Leaves`] | [`Picture::Leaves`]: the kind's atlas ([`crate::atlas`]), cut out by alpha | — |
//! | [`Surface::Petals`] | [`Picture::Petal`]: a petal cut-out over the material's design | — |
//! | [`Surface::Bark`] | [`Picture::Bark`]: the kind's tiling bark ([`crate::bark`]) | [`Picture::BarkNormal`] |
//!
//! Writers and the renderer ask this module, never the designs themselves, so a material
//! looks the same in a GLB, an OBJ, a VRML97 file and a picture. Each picture has a stable
//! name ([`Picture::name`], the glTF image's name) that [`Picture::from_name`] reads back.

use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex};

use image::{DynamicImage, ImageEncoder};
use sylva_core::Material;
use sylva_core::species::{BarkKind, LeafKind, Surface};

use crate::{atlas, bark, texture};

/// A picture Sylva draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Picture {
    /// A texture design by id (grey).
    Design(u16),
    /// A leaf kind's atlas (grey and alpha).
    Leaves(LeafKind),
    /// A petal cut-out over a design, or plain (grey and alpha).
    Petal(Option<u16>),
    /// A bark kind's colour texture (grey).
    Bark(BarkKind),
    /// A bark kind's normal map (RGB).
    BarkNormal(BarkKind),
    /// A leaf atlas's alpha alone, as grey and as alpha (for OBJ's `map_d`).
    LeavesMask(LeafKind),
    /// A petal cut-out's alpha alone, as grey and as alpha (for OBJ's `map_d`).
    PetalMask(Option<u16>),
    /// An impostor's picture of its plant (colour and alpha): not drawn here but carried by
    /// its mesh ([`crate::Mesh::impostor`]), so [`Picture::image`] and [`Picture::png`] have
    /// none: writers and the renderer take the mesh's.
    Impostor,
}

/// The prefix of every image name Sylva writes (`sylva-texture-3`, `sylva-leaves-oak`).
pub const NAME_PREFIX: &str = "sylva-";

impl Picture {
    /// The base-colour picture `m` shows, if any.
    pub fn base_of(m: &Material) -> Option<Picture> {
        match m.surface {
            Some(Surface::Leaves(kind) | Surface::Branchlets(kind)) => Some(Picture::Leaves(kind)),
            Some(Surface::Petals) => Some(Picture::Petal(m.texture)),
            Some(Surface::Bark(kind)) => Some(Picture::Bark(kind)),
            Some(Surface::Impostor) => Some(Picture::Impostor),
            None => m.texture.map(Picture::Design),
        }
    }

    /// The normal map `m` shows, if any.
    pub fn normal_of(m: &Material) -> Option<Picture> {
        match m.surface {
            Some(Surface::Bark(kind)) => Some(Picture::BarkNormal(kind)),
            _ => None,
        }
    }

    /// The cut-out mask of `m`'s base picture, if it has one: its alpha as a picture of its
    /// own, for formats that read coverage from a separate file (OBJ's `map_d`).
    pub fn mask_of(m: &Material) -> Option<Picture> {
        match Picture::base_of(m)? {
            Picture::Leaves(kind) => Some(Picture::LeavesMask(kind)),
            Picture::Petal(design) => Some(Picture::PetalMask(design)),
            _ => None,
        }
    }

    /// Whether its alpha cuts a shape out (leaves and petals, and their masks).
    pub fn has_alpha(self) -> bool {
        matches!(
            self,
            Picture::Leaves(_)
                | Picture::Petal(_)
                | Picture::LeavesMask(_)
                | Picture::PetalMask(_)
                | Picture::Impostor
        )
    }

    /// Whether it repeats along `v` (bark does; leaves, petals and cells do not).
    pub fn repeats_v(self) -> bool {
        match self {
            Picture::Design(id) => texture::texture_info(id).family.repeats_v(),
            Picture::Bark(_) | Picture::BarkNormal(_) => true,
            _ => false,
        }
    }

    /// Whether it repeats along `u` (every picture but atlases and petal cut-outs).
    pub fn repeats_u(self) -> bool {
        !self.has_alpha()
    }

    /// Its name, as glTF images and exported files carry it: `sylva-texture-<id>`,
    /// `sylva-leaves-<kind>`, `sylva-petal` or `sylva-petal-<id>`, `sylva-bark-<kind>`,
    /// `sylva-bark-<kind>-normal`.
    pub fn name(self) -> String {
        match self {
            Picture::Design(id) => format!("{NAME_PREFIX}texture-{id}"),
            Picture::Leaves(k) => format!("{NAME_PREFIX}leaves-{}", k.name()),
            Picture::Petal(None) => format!("{NAME_PREFIX}petal"),
            Picture::Petal(Some(id)) => format!("{NAME_PREFIX}petal-{id}"),
            Picture::Bark(k) => format!("{NAME_PREFIX}bark-{}", k.name()),
            Picture::BarkNormal(k) => format!("{NAME_PREFIX}bark-{}-normal", k.name()),
            Picture::LeavesMask(k) => format!("{NAME_PREFIX}leaves-{}-mask", k.name()),
            Picture::PetalMask(None) => format!("{NAME_PREFIX}petal-mask"),
            Picture::PetalMask(Some(id)) => format!("{NAME_PREFIX}petal-{id}-mask"),
            Picture::Impostor => format!("{NAME_PREFIX}impostor"),
        }
    }

    /// The file name OBJ and VRML97 exports give it next to a model named `stem`:
    /// `<stem>_tex<id>.png` for a design (as before surfaces), `<stem>_<name>.png` for the
    /// others (`oak_leaves-oak.png`, `oak_bark-furrowed-normal.png`).
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Picture::Design(id) => texture::texture_file_name(stem, id),
            other => format!("{stem}_{}.png", &other.name()[NAME_PREFIX.len()..]),
        }
    }

    /// The picture a name of [`Picture::name`] names.
    pub fn from_name(name: &str) -> Option<Picture> {
        let rest = name.strip_prefix(NAME_PREFIX)?;
        if let Some(id) = rest.strip_prefix("texture-") {
            return id.parse().ok().map(Picture::Design);
        }
        if let Some(kind) = rest
            .strip_prefix("leaves-")
            .and_then(|k| k.strip_suffix("-mask"))
        {
            return kind.parse().ok().map(Picture::LeavesMask);
        }
        if let Some(kind) = rest.strip_prefix("leaves-") {
            return kind.parse().ok().map(Picture::Leaves);
        }
        match rest {
            "petal" => return Some(Picture::Petal(None)),
            "petal-mask" => return Some(Picture::PetalMask(None)),
            "impostor" => return Some(Picture::Impostor),
            _ => {}
        }
        if let Some(id) = rest
            .strip_prefix("petal-")
            .and_then(|k| k.strip_suffix("-mask"))
        {
            return id.parse().ok().map(|id| Picture::PetalMask(Some(id)));
        }
        if let Some(id) = rest.strip_prefix("petal-") {
            return id.parse().ok().map(|id| Picture::Petal(Some(id)));
        }
        let kind = rest.strip_prefix("bark-")?;
        match kind.strip_suffix("-normal") {
            Some(k) => k.parse().ok().map(Picture::BarkNormal),
            None => kind.parse().ok().map(Picture::Bark),
        }
    }

    /// Its pixels.
    pub fn image(self) -> DynamicImage {
        match self {
            Picture::Design(id) => DynamicImage::ImageLuma8(texture::texture(id).image),
            Picture::Leaves(k) => DynamicImage::ImageLumaA8((*atlas::leaf_atlas(k)).clone()),
            Picture::Petal(d) => DynamicImage::ImageLumaA8((*atlas::petal_picture(d)).clone()),
            Picture::Bark(k) => DynamicImage::ImageLuma8((*bark::bark_color(k)).clone()),
            Picture::BarkNormal(k) => DynamicImage::ImageRgb8((*bark::bark_normal(k)).clone()),
            Picture::LeavesMask(k) => DynamicImage::ImageLumaA8(mask(&atlas::leaf_atlas(k))),
            Picture::PetalMask(d) => DynamicImage::ImageLumaA8(mask(&atlas::petal_picture(d))),
            // Its mesh carries it: one clear texel stands for it here.
            Picture::Impostor => DynamicImage::ImageLumaA8(image::GrayAlphaImage::new(1, 1)),
        }
    }

    /// Its PNG, encoded once per process (the designs' through [`texture::texture_png`]).
    pub fn png(self) -> Result<Arc<Vec<u8>>, image::ImageError> {
        if let Picture::Design(id) = self {
            return texture::texture_png(id);
        }
        if let Some(png) = PNGS.lock().unwrap_or_else(|p| p.into_inner()).get(&self) {
            return Ok(png.clone());
        }
        let png = Arc::new(encode(&self.image())?);
        let mut kept = PNGS.lock().unwrap_or_else(|p| p.into_inner());
        if kept.len() >= 256 {
            kept.clear();
        }
        kept.insert(self, png.clone());
        Ok(png)
    }
}

/// A cut-out's alpha as both grey and alpha: readers of either channel see the outline.
fn mask(image: &image::GrayAlphaImage) -> image::GrayAlphaImage {
    let mut m = image.clone();
    for p in m.pixels_mut() {
        p.0[0] = p.0[1];
    }
    m
}

static PNGS: LazyLock<Mutex<HashMap<Picture, Arc<Vec<u8>>>>> = LazyLock::new(Mutex::default);

/// A picture as PNG, at the best compression (no colour-space chunks: plain sRGB to glTF).
fn encode(image: &DynamicImage) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut bytes,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(
        image.as_bytes(),
        image.width(),
        image.height(),
        image.color().into(),
    )?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::MaterialKind;

    #[test]
    fn names_read_back() {
        let mut all = vec![
            Picture::Design(0),
            Picture::Design(200),
            Picture::Petal(None),
        ];
        all.extend([
            Picture::Petal(Some(7)),
            Picture::PetalMask(None),
            Picture::PetalMask(Some(3)),
        ]);
        for k in LeafKind::ALL {
            all.extend([Picture::Leaves(k), Picture::LeavesMask(k)]);
        }
        for k in BarkKind::ALL {
            all.extend([Picture::Bark(k), Picture::BarkNormal(k)]);
        }
        for p in all {
            assert_eq!(Picture::from_name(&p.name()), Some(p), "{}", p.name());
        }
        assert_eq!(Picture::Design(3).name(), "sylva-texture-3");
        for bad in [
            "sylva-leaves-palm",
            "texture-3",
            "sylva-bark-",
            "sylva-texture-x",
        ] {
            assert_eq!(Picture::from_name(bad), None, "{bad}");
        }
    }

    #[test]
    fn materials_show_their_surface_or_design() {
        let mut m = Material::of_kind(MaterialKind::Leaf);
        assert_eq!(Picture::base_of(&m), None);
        m.texture = Some(4);
        assert_eq!(Picture::base_of(&m), Some(Picture::Design(4)));
        m.surface = Some(Surface::Leaves(LeafKind::Ash));
        assert_eq!(Picture::base_of(&m), Some(Picture::Leaves(LeafKind::Ash)));
        assert_eq!(Picture::normal_of(&m), None);
        m.surface = Some(Surface::Bark(BarkKind::Plated));
        assert_eq!(
            Picture::normal_of(&m),
            Some(Picture::BarkNormal(BarkKind::Plated))
        );
    }

    #[test]
    fn pngs_are_made_once_and_decode_to_the_pixels() {
        let p = Picture::Leaves(LeafKind::Oak);
        let png = p.png().unwrap();
        assert!(Arc::ptr_eq(&png, &p.png().unwrap()));
        let back = image::load_from_memory(&png).unwrap();
        assert_eq!(back, p.image());
    }
}
