//! Textures Sylva makes itself: bark, leaf and petal detail, generated from a texture id.
//!
//! A [`Material`](sylva_core::Material)'s `texture: Option<u16>` names one of these. [`texture`]
//! turns an id into a [`Texture`]: a [`TEXTURE_SIZE`]² grey-scale picture that exporters embed
//! (GLB) or write next to the model (OBJ, VRML97) and the renderer samples. Grey values are
//! *multiplied* by the material's colour (glTF's `baseColorTexture` times `baseColorFactor`),
//! so a texture carries only light and shade: white shows the material colour itself, darker
//! greys shade it. Grey rather than RGB because VRML97 replaces a material's colour with an
//! RGB texture but modulates it with a one-component one, so only grey looks the same in all
//! three formats.
//!
//! | id | name | family | look |
//! | --- | --- | --- | --- |
//! | 0 | `furrowed-bark` | bark | deep vertical furrows between wandering ridges broken by cross cracks (oak, pine) |
//! | 1 | `lenticel-bark` | bark | smooth, faintly banded, with short horizontal lenticel dashes (cherry, birch) |
//! | 2 | `plated-bark` | bark | flaky plates of different tones parted by dark crevices (plane tree, old pine) |
//! | 3 | `veined-leaf` | leaf | pale midrib, paired side veins running to the tip, a fine net between them |
//! | 4 | `glossy-leaf` | leaf | smooth and waxy: a broad sheen along the middle, a faint midrib crease |
//! | 5 | `striped-leaf` | leaf | variegated bands parallel to the blade with bright margins (spider plant) |
//! | 6 | `gradient-petal` | petal | a dark eye at the base fading to the full colour towards the tip |
//! | 7 | `streaked-petal` | petal | dark nectar-guide streaks from the base, tapering out halfway |
//! | 8 | `spotted-petal` | petal | dark spots with pale halos, larger and denser near the base (foxglove) |
//!
//! Ids from [`TEXTURE_COUNT`] on reuse the design of `id % TEXTURE_COUNT` with other noise
//! (the id seeds it), so id 9 is another furrowed bark, not the same picture as id 0.
//!
//! **Mapping.** Texture `u` runs across the picture (x) and `v` down it (y, the glTF
//! convention). The mesher puts `u` around tubes and across leaves and petals, and `v` along
//! tubes and from the base (0) to the tip (1) of leaves and petals. Every texture tiles in
//! `u` (its left and right columns meet); bark also tiles in `v`, since `v` runs on along a
//! tube, while leaf and petal textures span their organ once and are clamped in `v`
//! ([`TextureFamily::repeats_v`]).
//!
//! **Determinism.** A texture is a pure function of its id: hash-based value and cell noise
//! written here, using only `+ - * /`, `sqrt` and `floor`, which IEEE 754 rounds exactly, so
//! the pixels (and the PNG bytes) are the same on every machine.
//!
//! ```
//! use sylva_mesh::texture::{TEXTURE_SIZE, TextureFamily, texture};
//!
//! let bark = texture(0);
//! assert_eq!(bark.image.dimensions(), (TEXTURE_SIZE, TEXTURE_SIZE));
//! assert_eq!(bark.info().family, TextureFamily::Bark);
//! assert_eq!(texture(0), bark); // the same every time
//! assert!(bark.png()?.starts_with(b"\x89PNG"));
//! # Ok::<(), image::ImageError>(())
//! ```

use std::collections::HashMap;
use std::sync::{Arc, LazyLock, Mutex};

use image::GrayImage;

/// Side of every texture, pixels (a power of two, so viewers can build mipmaps).
pub const TEXTURE_SIZE: u32 = 256;

/// Number of distinct designs; ids from here on vary them (see the module docs).
pub const TEXTURE_COUNT: u16 = 9;

/// What a texture is meant for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureFamily {
    /// Stems and branches: tiles both ways.
    Bark,
    /// Leaf blades: tiles across, spans the blade once from base to tip.
    Leaf,
    /// Petals: tiles across, spans the petal once from base to tip.
    Petal,
}

impl TextureFamily {
    /// Whether the texture repeats along `v`. Bark does (it runs on along a tube); leaves
    /// and petals are clamped, so their base and tip never bleed into each other.
    pub fn repeats_v(self) -> bool {
        self == TextureFamily::Bark
    }
}

/// A design's name, family and look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureInfo {
    /// Short name, kebab-case (used as the glTF image name's suffix).
    pub name: &'static str,
    /// What it is for.
    pub family: TextureFamily,
    /// One line on how it looks.
    pub look: &'static str,
}

/// Every design, indexed by `id % TEXTURE_COUNT`.
pub const TEXTURES: [TextureInfo; TEXTURE_COUNT as usize] = [
    TextureInfo {
        name: "furrowed-bark",
        family: TextureFamily::Bark,
        look: "deep vertical furrows between wandering ridges broken by cross cracks",
    },
    TextureInfo {
        name: "lenticel-bark",
        family: TextureFamily::Bark,
        look: "smooth, faintly banded, with short horizontal lenticel dashes",
    },
    TextureInfo {
        name: "plated-bark",
        family: TextureFamily::Bark,
        look: "flaky plates of different tones parted by dark crevices",
    },
    TextureInfo {
        name: "veined-leaf",
        family: TextureFamily::Leaf,
        look: "pale midrib, paired side veins running to the tip, a fine net between them",
    },
    TextureInfo {
        name: "glossy-leaf",
        family: TextureFamily::Leaf,
        look: "smooth and waxy: a broad sheen along the middle, a faint midrib crease",
    },
    TextureInfo {
        name: "striped-leaf",
        family: TextureFamily::Leaf,
        look: "variegated bands parallel to the blade with bright margins",
    },
    TextureInfo {
        name: "gradient-petal",
        family: TextureFamily::Petal,
        look: "a dark eye at the base fading to the full colour towards the tip",
    },
    TextureInfo {
        name: "streaked-petal",
        family: TextureFamily::Petal,
        look: "dark nectar-guide streaks from the base, tapering out halfway",
    },
    TextureInfo {
        name: "spotted-petal",
        family: TextureFamily::Petal,
        look: "dark spots with pale halos, larger and denser near the base",
    },
];

/// The design texture `id` uses.
pub fn texture_info(id: u16) -> &'static TextureInfo {
    &TEXTURES[usize::from(id % TEXTURE_COUNT)]
}

/// The file name exporters give texture `id` next to a model named `stem`:
/// `<stem>_tex<id>.png`.
pub fn texture_file_name(stem: &str, id: u16) -> String {
    format!("{stem}_tex{id}.png")
}

/// A generated texture: 8-bit grey, [`TEXTURE_SIZE`] square, to multiply a colour by.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Texture {
    /// The id it was made from.
    pub id: u16,
    /// The pixels, row 0 at `v = 0`.
    pub image: GrayImage,
}

impl Texture {
    /// Its design.
    pub fn info(&self) -> &'static TextureInfo {
        texture_info(self.id)
    }

    /// Encodes it as a grey-scale PNG (no colour-space chunks, so glTF viewers and the
    /// Khronos validator take it as plain sRGB).
    pub fn png(&self) -> Result<Vec<u8>, image::ImageError> {
        use image::ImageEncoder;
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new_with_quality(
            &mut bytes,
            image::codecs::png::CompressionType::Best,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(
            self.image.as_raw(),
            self.image.width(),
            self.image.height(),
            image::ExtendedColorType::L8,
        )?;
        Ok(bytes)
    }
}

/// Textures and PNGs made so far, by id: a texture is a pure function of its id, and making
/// one (noise, then the best PNG compression) costs far more than meshing a small plant.
/// The [`KEPT_TEXTURES`] used last of each are kept, so ids that come and go (a hostile
/// upload's, say) cannot push out the ones in use.
static MADE: LazyLock<Mutex<Kept<Texture>>> = LazyLock::new(Mutex::default);
static PNGS: LazyLock<Mutex<Kept<Vec<u8>>>> = LazyLock::new(Mutex::default);

/// Textures (and PNGs) kept in memory, about 64 KiB each: every id a genome can name
/// (PlantMaker's 0 to 127) with room to spare.
const KEPT_TEXTURES: usize = 160;

/// Values by id, each with the tick it was last used at.
struct Kept<T> {
    values: HashMap<u16, (Arc<T>, u64)>,
    tick: u64,
}

impl<T> Default for Kept<T> {
    fn default() -> Self {
        Kept {
            values: HashMap::new(),
            tick: 0,
        }
    }
}

impl<T> Kept<T> {
    fn recall(&mut self, id: u16) -> Option<Arc<T>> {
        self.tick += 1;
        let tick = self.tick;
        self.values.get_mut(&id).map(|(value, used)| {
            *used = tick;
            value.clone()
        })
    }

    fn remember(&mut self, id: u16, value: Arc<T>) {
        self.tick += 1;
        if self.values.len() >= KEPT_TEXTURES
            && !self.values.contains_key(&id)
            && let Some(oldest) = self.values.iter().min_by_key(|(_, (_, used))| *used)
        {
            let oldest = *oldest.0;
            self.values.remove(&oldest);
        }
        self.values.insert(id, (value, self.tick));
    }
}

fn remember<T>(cache: &Mutex<Kept<T>>, id: u16, value: Arc<T>) {
    cache
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .remember(id, value);
}

fn recall<T>(cache: &Mutex<Kept<T>>, id: u16) -> Option<Arc<T>> {
    cache.lock().unwrap_or_else(|p| p.into_inner()).recall(id)
}

/// Texture `id` (see the module docs for the designs), made once per process.
pub fn texture(id: u16) -> Texture {
    if let Some(t) = recall(&MADE, id) {
        return Texture::clone(&t);
    }
    let t = generate(id);
    remember(&MADE, id, Arc::new(t.clone()));
    t
}

/// Texture `id`'s PNG ([`Texture::png`]), encoded once per process.
pub fn texture_png(id: u16) -> Result<Arc<Vec<u8>>, image::ImageError> {
    if let Some(png) = recall(&PNGS, id) {
        return Ok(png);
    }
    let png = Arc::new(texture(id).png()?);
    remember(&PNGS, id, png.clone());
    Ok(png)
}

/// Generates texture `id`.
fn generate(id: u16) -> Texture {
    let seed = u32::from(id);
    let design = design(id);
    let size = TEXTURE_SIZE;
    let inv = 1.0 / size as f32;
    let image = GrayImage::from_fn(size, size, |x, y| {
        // Sample at pixel centres: the left and right columns are then half a pixel from the
        // seam on either side, as a tiling texture's must be.
        let (u, v) = ((x as f32 + 0.5) * inv, (y as f32 + 0.5) * inv);
        let g = design(u, v, seed).clamp(0.0, 1.0);
        image::Luma([(g * 255.0 + 0.5) as u8])
    });
    Texture { id, image }
}

/// The design texture `id` draws: `(u, v, seed)` to a grey level (see the module docs).
pub(crate) fn design(id: u16) -> fn(f32, f32, u32) -> f32 {
    match id % TEXTURE_COUNT {
        0 => furrowed_bark,
        1 => lenticel_bark,
        2 => plated_bark,
        3 => veined_leaf,
        4 => glossy_leaf,
        5 => striped_leaf,
        6 => gradient_petal,
        7 => streaked_petal,
        _ => spotted_petal,
    }
}

// ---------------------------------------------------------------------------------------
// Noise. Everything is periodic over the unit square so textures tile.

/// A 32-bit integer hash of a lattice point and a seed (murmur3's finaliser over a mix).
#[inline]
pub(crate) fn hash(x: u32, y: u32, seed: u32) -> u32 {
    let mut h = x.wrapping_mul(0x8da6_b343)
        ^ y.wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f).wrapping_add(0x9e37_79b9);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// A hash as a number in `0..1`.
#[inline]
pub(crate) fn unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Rehashes a hash, for a second independent number from one lattice point.
#[inline]
pub(crate) fn rehash(h: u32) -> u32 {
    hash(h, 0x51ed_270b, 0x2545_f491)
}

#[inline]
pub(crate) fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// Hermite smoothstep of `x` between edges `e0` and `e1` (either order).
#[inline]
pub(crate) fn smooth(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// `x` modulo `n`, as a lattice index.
#[inline]
pub(crate) fn wrap(x: i64, n: u32) -> u32 {
    x.rem_euclid(i64::from(n)) as u32
}

/// Value noise in `0..1` at `(u, v)` of the unit square, on a lattice of `px` × `py` cells
/// that wraps at the square's edges.
pub(crate) fn noise(u: f32, v: f32, px: u32, py: u32, seed: u32) -> f32 {
    let (x, y) = (u * px as f32, v * py as f32);
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (x - fx, y - fy);
    let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
    let at = |i: i64, j: i64| unit(hash(wrap(i, px), wrap(j, py), seed));
    lerp(
        lerp(at(ix, iy), at(ix + 1, iy), sx),
        lerp(at(ix, iy + 1), at(ix + 1, iy + 1), sx),
        sy,
    )
}

/// Fractal sum of `octaves` noises from `px` × `py` cells up, each twice as fine and half as
/// strong; in `0..1`, mostly near 0.5.
pub(crate) fn fbm(u: f32, v: f32, px: u32, py: u32, octaves: u32, seed: u32) -> f32 {
    let (mut sum, mut amp, mut norm) = (0.0, 1.0, 0.0);
    for o in 0..octaves {
        sum += amp * noise(u, v, px << o, py << o, seed.wrapping_add(o * 7919));
        norm += amp;
        amp *= 0.5;
    }
    sum / norm
}

/// Cell noise over `nx` × `ny` wrapping cells, one jittered point per cell. Distances are in
/// cell units, so cells taller than wide make shapes elongated along `v`. Returns the
/// distances to the nearest and second-nearest points and the nearest point's hash.
pub(crate) fn cells(u: f32, v: f32, nx: u32, ny: u32, seed: u32) -> (f32, f32, u32) {
    let (x, y) = (u * nx as f32, v * ny as f32);
    let (cx, cy) = (x.floor() as i64, y.floor() as i64);
    let (mut f1, mut f2, mut id) = (f32::INFINITY, f32::INFINITY, 0);
    for j in cy - 1..=cy + 1 {
        for i in cx - 1..=cx + 1 {
            let h = hash(wrap(i, nx), wrap(j, ny), seed);
            let px = i as f32 + 0.1 + 0.8 * unit(h);
            let py = j as f32 + 0.1 + 0.8 * unit(rehash(h));
            let d = ((x - px) * (x - px) + (y - py) * (y - py)).sqrt();
            if d < f1 {
                (f2, f1, id) = (f1, d, h);
            } else if d < f2 {
                f2 = d;
            }
        }
    }
    (f1, f2, id)
}

/// Distance from `x` to the nearest whole number (0 on a line, 0.5 between lines).
#[inline]
pub(crate) fn to_line(x: f32) -> f32 {
    let t = x - x.floor();
    t.min(1.0 - t)
}

// ---------------------------------------------------------------------------------------
// The designs: (u, v, seed) to a grey level, 1 showing the material colour unchanged.

/// Six broad ridges around, wandering with low noise and rough on top, parted by wide dark
/// furrows that open and close along the trunk; the ridges are broken into blocks by cross
/// cracks; fibres run along the axis.
pub(crate) fn furrowed_bark(u: f32, v: f32, s: u32) -> f32 {
    const RIDGES: u32 = 6;
    let warp = fbm(u, v, 3, 2, 3, s) - 0.5;
    let wiggle = fbm(u, v, 8, 6, 2, s ^ 0x11) - 0.5;
    let x = u * RIDGES as f32 + 1.6 * warp + 0.5 * wiggle;
    let ridge = wrap(x.floor() as i64, RIDGES);
    let across = (x - x.floor() - 0.5).abs() * 2.0; // 0 mid-ridge .. 1 in the furrow
    // How far the ridge's flat top reaches: the furrow widens and narrows along the trunk.
    let open = 0.2 + 0.35 * noise(v, 0.5, 6, 1, s ^ ridge.wrapping_mul(31));
    let height = 1.0 - smooth(open, 1.0, across);
    // Cross cracks at staggered heights, on some blocks only, fading out into the furrows.
    let crack_at = v * 6.0 + unit(hash(ridge, 7, s)) + 0.25 * (noise(u, v, 12, 12, s ^ 0x22) - 0.5);
    let block = wrap(crack_at.floor() as i64, 6);
    let crack = if unit(hash(ridge, block + 100, s)) < 0.35 {
        (1.0 - smooth(0.02, 0.1, to_line(crack_at))) * height
    } else {
        0.0
    };
    let rough = fbm(u, v, 16, 16, 3, s ^ 0x44) - 0.5;
    let fibre = fbm(u, v, 64, 4, 2, s ^ 0x33) - 0.5;
    // Ridge tops are light and rough, rounding off darker towards their edges.
    let top = (0.8 + 0.5 * rough + 0.35 * fibre) * (0.8 + 0.2 * (1.0 - across * across));
    let furrow = 0.22 + 0.15 * fibre;
    lerp(furrow, top, height) * (1.0 - 0.55 * crack)
}

/// Smooth and light with soft horizontal bands, and scattered horizontal lenticels: dark
/// dashes with a slightly raised (lighter) lip.
pub(crate) fn lenticel_bark(u: f32, v: f32, s: u32) -> f32 {
    const NX: u32 = 4;
    const NY: u32 = 12;
    let bands = fbm(u, v, 1, 20, 3, s) - 0.5;
    let mottle = fbm(u, v, 8, 8, 3, s ^ 0x55) - 0.5;
    let streak = fbm(u, v, 2, 64, 2, s ^ 0x57) - 0.5;
    let mut dash = 0.0f32;
    let mut lip = 0.0f32;
    let (x, y) = (u * NX as f32, v * NY as f32);
    let (cx, cy) = (x.floor() as i64, y.floor() as i64);
    for j in cy - 1..=cy + 1 {
        for i in cx - 1..=cx + 1 {
            let h = hash(wrap(i, NX), wrap(j, NY), s ^ 0x66);
            let h2 = rehash(h);
            if unit(h2) < 0.1 {
                continue; // some cells have none
            }
            let px = i as f32 + 0.15 + 0.7 * unit(h);
            let py = j as f32 + 0.2 + 0.6 * unit(rehash(h2));
            // Half-length 0.12..0.35 cells across; half-height a tenth of a row or so.
            let a = 0.12 + 0.23 * unit(h2 >> 3);
            let b = 0.09 + 0.07 * unit(h >> 5);
            let (dx, dy) = ((x - px) / a, (y - py) / b);
            let d = (dx * dx + dy * dy).sqrt();
            dash = dash.max(1.0 - smooth(0.5, 1.0, d));
            lip = lip.max(smooth(0.8, 1.05, d) * (1.0 - smooth(1.2, 1.8, d)));
        }
    }
    0.88 + 0.3 * bands + 0.12 * mottle + 0.12 * streak - 0.62 * dash + 0.08 * lip
}

/// Large plates (about twice as tall as wide, with wandering outlines), each of its own tone,
/// rough and fibrous along the axis, parted by wide dark crevices; plate edges catch a little
/// light where they curl, and some plates have shed a flake showing a darker layer.
pub(crate) fn plated_bark(u: f32, v: f32, s: u32) -> f32 {
    let (du, dv) = (
        0.05 * (fbm(u, v, 6, 6, 2, s ^ 0x77) - 0.5),
        0.05 * (fbm(u, v, 6, 6, 2, s ^ 0x88) - 0.5),
    );
    let (f1, f2, id) = cells(u + du, v + dv, 5, 2, s);
    let edge = f2 - f1;
    let crevice = 1.0 - smooth(0.03, 0.14, edge);
    let curl = smooth(0.08, 0.14, edge) * (1.0 - smooth(0.16, 0.3, edge));
    let tone = 0.62 + 0.33 * unit(id);
    let grain = fbm(u, v, 48, 6, 2, s ^ 0x99) - 0.5;
    let rough = fbm(u, v, 16, 16, 2, s ^ 0xab) - 0.5;
    let shed =
        smooth(0.55, 0.6, fbm(u, v, 8, 8, 2, s ^ 0xcd)) * (unit(rehash(id)) < 0.5) as u8 as f32;
    let plate = tone + 0.1 * curl + 0.35 * grain + 0.25 * rough - 0.22 * shed;
    plate * (1.0 - 0.78 * crevice)
}

/// The blade's mottled green with a pale midrib, side veins leaving it towards the tip in
/// pairs and fading at the margins, and a faint net of small veins between them.
fn veined_leaf(u: f32, v: f32, s: u32) -> f32 {
    let off = (u - 0.5).abs(); // 0 on the midrib .. 0.5 at the margins
    let mottle = fbm(u, v, 6, 6, 3, s) - 0.5;
    let midrib = 1.0 - smooth(0.008, 0.022, off);
    // Side veins: lines of v − k·|u − ½| = const, curving up towards the margins.
    let w = v * 7.0 - off * 5.0 - 3.0 * off * off;
    let width = 0.08 * (1.0 - 1.4 * off);
    let side = (1.0 - smooth(0.45 * width, width, to_line(w)))
        * smooth(0.0, 0.02, off)
        * (1.0 - smooth(0.3, 0.5, off));
    let (f1, f2, _) = cells(u, v, 20, 20, s ^ 0x12);
    let net = 1.0 - smooth(0.0, 0.07, f2 - f1);
    // Between the side veins the blade bulges a little: lighter mid-panel, darker by veins.
    let panel = to_line(w) * 2.0;
    let value = 0.66 + 0.25 * mottle + 0.1 * net + 0.08 * panel;
    lerp(lerp(value, 0.96, side), 1.0, midrib)
}

/// Smooth and waxy: brightest in a broad band along the middle of the blade (a convex leaf
/// catching the light), a faint darker crease on the midrib, very soft veins.
fn glossy_leaf(u: f32, v: f32, s: u32) -> f32 {
    let off = (u - 0.5).abs();
    let across = 2.0 * off; // 0 middle .. 1 margin
    let sheen = 1.0 - across * across;
    let crease = 1.0 - smooth(0.003, 0.012, off);
    let w = v * 6.0 - off * 4.0;
    let vein = (1.0 - smooth(0.02, 0.05, to_line(w))) * smooth(0.02, 0.05, off);
    let soft = fbm(u, v, 4, 4, 2, s) - 0.5;
    0.7 + 0.28 * sheen + 0.06 * soft + 0.04 * vein - 0.14 * crease
}

/// Bands parallel to the blade, symmetric about the midrib: a pale centre line, darker green
/// bands, a thin pale stripe, bright margins; edges wander and fine parallel veins run
/// through everything.
fn striped_leaf(u: f32, v: f32, s: u32) -> f32 {
    let wobble = 0.06 * (fbm(u, v, 4, 8, 3, s) - 0.5);
    let x = 2.0 * (u - 0.5).abs() + wobble; // 0 middle .. 1 margin
    let pale_centre = 1.0 - smooth(0.06, 0.12, x);
    let pale_stripe = smooth(0.36, 0.42, x) * (1.0 - smooth(0.5, 0.56, x));
    let pale_margin = smooth(0.74, 0.82, x);
    let pale = pale_centre.max(pale_stripe).max(pale_margin);
    let veins = 1.0 - smooth(0.08, 0.25, to_line(u * 48.0));
    let mottle = fbm(u, v, 8, 8, 2, s ^ 0x34) - 0.5;
    lerp(0.5 + 0.1 * mottle, 0.98, pale) - 0.05 * veins
}

/// Fine veins fanning along the petal over a dark eye at the base that fades to the full
/// colour by mid-petal.
fn petal_veins(u: f32, v: f32, s: u32) -> f32 {
    let x = u * 28.0 + 0.3 * (noise(u, v, 6, 4, s ^ 0x56) - 0.5);
    (1.0 - smooth(0.1, 0.3, to_line(x))) * (0.4 + 0.6 * v)
}

/// A dark eye at the base fading to the full colour, a faint blush at the tip, fine veins.
fn gradient_petal(u: f32, v: f32, s: u32) -> f32 {
    let eye = 1.0 - smooth(0.02, 0.6, v);
    let blush = smooth(0.8, 1.0, v);
    let soft = fbm(u, v, 6, 6, 2, s) - 0.5;
    0.97 - 0.6 * eye - 0.08 * blush + 0.05 * soft - 0.06 * petal_veins(u, v, s)
}

/// Nectar guides: dark streaks from the base along the petal, each of its own length,
/// tapering to nothing between a third and most of the way to the tip.
fn streaked_petal(u: f32, v: f32, s: u32) -> f32 {
    const STREAKS: u32 = 7;
    let x = u * STREAKS as f32 + 0.3 * (noise(u, v, 7, 3, s) - 0.5);
    let k = wrap(x.floor() as i64, STREAKS);
    let d = (x - x.floor() - 0.5).abs();
    let reach = 0.35 + 0.45 * unit(hash(k, 3, s));
    let fade = 1.0 - smooth(0.4 * reach, reach, v);
    let width = 0.26 * (1.0 - 0.8 * (v / reach).min(1.0));
    let streak = (1.0 - smooth(0.4 * width, width, d)) * fade;
    let base = 1.0 - smooth(0.0, 0.15, v);
    let soft = fbm(u, v, 6, 6, 2, s ^ 0x78) - 0.5;
    0.96 - 0.62 * streak - 0.3 * base + 0.05 * soft - 0.05 * petal_veins(u, v, s)
}

/// Dark spots with pale halos, scattered larger and denser near the base and thinning out
/// towards the tip.
fn spotted_petal(u: f32, v: f32, s: u32) -> f32 {
    const NX: u32 = 6;
    const NY: u32 = 10;
    let (x, y) = (u * NX as f32, v * NY as f32);
    let (cx, cy) = (x.floor() as i64, y.floor() as i64);
    let (mut spot, mut halo) = (0.0f32, 0.0f32);
    for j in cy - 1..=cy + 1 {
        // Leaf and petal textures do not repeat along v: rows past the edges are empty.
        if !(0..i64::from(NY)).contains(&j) {
            continue;
        }
        let row_v = (j as f32 + 0.5) / NY as f32;
        for i in cx - 1..=cx + 1 {
            let h = hash(wrap(i, NX), j as u32, s);
            let h2 = rehash(h);
            if unit(h2) > 0.95 - 0.9 * row_v {
                continue;
            }
            let px = i as f32 + 0.2 + 0.6 * unit(h);
            let py = j as f32 + 0.2 + 0.6 * unit(rehash(h2));
            let r = (0.24 + 0.14 * unit(h2 >> 4)) * (1.15 - 0.6 * row_v);
            let d = ((x - px) * (x - px) + (y - py) * (y - py)).sqrt() / r;
            spot = spot.max(1.0 - smooth(0.75, 1.0, d));
            halo = halo.max(smooth(0.9, 1.1, d) * (1.0 - smooth(1.3, 1.8, d)));
        }
    }
    let soft = fbm(u, v, 6, 6, 2, s ^ 0x9a) - 0.5;
    let body = 0.9 + 0.05 * soft - 0.05 * petal_veins(u, v, s);
    lerp(body, 1.0, halo) - 0.62 * spot
}

#[cfg(test)]
mod tests {
    #[test]
    fn textures_and_pngs_are_made_once_and_the_same() {
        let first = super::texture_png(4).unwrap();
        let again = super::texture_png(4).unwrap();
        assert!(std::sync::Arc::ptr_eq(&first, &again));
        assert_eq!(*first, super::generate(4).png().unwrap());
        assert_eq!(super::texture(4), super::generate(4));
    }

    use super::*;

    #[test]
    fn ids_that_come_and_go_do_not_push_out_those_in_use() {
        let mut kept: Kept<u16> = Kept::default();
        kept.remember(3, Arc::new(3));
        for id in 1000..1000 + 4 * KEPT_TEXTURES as u16 {
            assert_eq!(kept.recall(3).as_deref(), Some(&3));
            kept.remember(id, Arc::new(id));
            assert!(kept.values.len() <= KEPT_TEXTURES);
        }
        assert_eq!(kept.recall(3).as_deref(), Some(&3));
        assert!(kept.recall(1000).is_none());
    }

    fn mean_abs_diff(a: &GrayImage, b: &GrayImage) -> f32 {
        let sum: u64 = a
            .as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(&x, &y)| u64::from(x.abs_diff(y)))
            .sum();
        sum as f32 / a.as_raw().len() as f32
    }

    #[test]
    fn textures_are_deterministic_and_sized() {
        for id in 0..TEXTURE_COUNT + 2 {
            let t = texture(id);
            assert_eq!(t.image.dimensions(), (TEXTURE_SIZE, TEXTURE_SIZE));
            assert!(TEXTURE_SIZE.is_power_of_two());
            assert_eq!(texture(id), t, "texture {id}");
        }
    }

    #[test]
    fn textures_differ_pairwise() {
        let all: Vec<Texture> = (0..TEXTURE_COUNT).map(texture).collect();
        for a in &all {
            for b in all.iter().filter(|b| b.id > a.id) {
                let d = mean_abs_diff(&a.image, &b.image);
                assert!(
                    d > 12.0,
                    "textures {} and {} differ by only {d}",
                    a.id,
                    b.id
                );
            }
        }
        // Past the designs: the same look, other noise.
        let (a, b) = (texture(0), texture(TEXTURE_COUNT));
        assert_eq!(a.info(), b.info());
        assert!(mean_abs_diff(&a.image, &b.image) > 5.0);
    }

    #[test]
    fn textures_tile_across_and_bark_along() {
        let column = |img: &GrayImage, x: u32| -> Vec<i32> {
            (0..img.height())
                .map(|y| i32::from(img.get_pixel(x, y)[0]))
                .collect()
        };
        let row = |img: &GrayImage, y: u32| -> Vec<i32> {
            (0..img.width())
                .map(|x| i32::from(img.get_pixel(x, y)[0]))
                .collect()
        };
        // Mean step between two lines of pixels, relative to the picture's own mean step
        // between neighbouring columns: a seam would stand out as a much bigger step.
        let step = |a: &[i32], b: &[i32]| {
            a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<i32>() as f32 / a.len() as f32
        };
        let last = TEXTURE_SIZE - 1;
        for id in 0..TEXTURE_COUNT {
            let t = texture(id);
            let img = &t.image;
            let inner: f32 = (0..last)
                .map(|x| step(&column(img, x), &column(img, x + 1)))
                .sum::<f32>()
                / last as f32;
            let seam = step(&column(img, last), &column(img, 0));
            assert!(
                seam <= 2.0 * inner + 1.0,
                "texture {id}: seam step {seam} vs {inner} inside"
            );
            if t.info().family.repeats_v() {
                let inner: f32 = (0..last)
                    .map(|y| step(&row(img, y), &row(img, y + 1)))
                    .sum::<f32>()
                    / last as f32;
                let seam = step(&row(img, last), &row(img, 0));
                assert!(
                    seam <= 2.0 * inner + 1.0,
                    "texture {id}: seam step along v {seam} vs {inner} inside"
                );
            }
        }
    }

    #[test]
    fn textures_are_mostly_light_detail() {
        for id in 0..TEXTURE_COUNT {
            let t = texture(id);
            let raw = t.image.as_raw();
            let mean = raw.iter().map(|&g| f32::from(g)).sum::<f32>() / raw.len() as f32;
            let (lo, hi) = (raw.iter().min().copied(), raw.iter().max().copied());
            assert!(
                (150.0..=245.0).contains(&mean),
                "texture {id} mean grey {mean}"
            );
            // Real detail, not a flat grey.
            assert!(
                hi.unwrap_or(0) - lo.unwrap_or(0) > 60,
                "texture {id}: {lo:?}..{hi:?}"
            );
        }
    }

    #[test]
    fn png_round_trips() {
        let t = texture(5);
        let png = t.png().unwrap();
        let back = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
            .unwrap()
            .into_luma8();
        assert_eq!(back, t.image);
        assert_eq!(t.png().unwrap(), png, "same bytes every time");
    }

    #[test]
    fn names_and_files() {
        assert_eq!(texture_file_name("tree", 3), "tree_tex3.png");
        assert_eq!(texture_info(12).name, "veined-leaf");
        let families: Vec<_> = TEXTURES.iter().map(|t| t.family).collect();
        assert_eq!(
            families
                .iter()
                .filter(|&&f| f == TextureFamily::Bark)
                .count(),
            3
        );
        assert!(TextureFamily::Bark.repeats_v() && !TextureFamily::Petal.repeats_v());
    }
}
