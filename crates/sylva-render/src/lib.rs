//! A software z-buffer renderer: a [`Scene`] to a shaded picture and PNG, with no GPU.
//!
//! - [`render`] (or a reusable [`Renderer`]) draws a scene from a [`View`] into an
//!   [`image::RgbImage`], framed automatically so the whole scene fills the picture.
//! - [`contact_sheet`] lays out many small captioned renders in a grid.
//! - [`overlay`] draws two outlines over each other (a plant on its target).
//! - [`map`] draws a variety map: a thumbnail per filled cell, empty cells left empty.
//! - [`impostor`] makes a plant's last level of detail: crossed cards showing its picture,
//!   drawn by [`Renderer::cut_out`].
//! - [`encode_png`] and [`write_png`] (atomic) save the result; [`encode_rgba_png`] a
//!   picture with alpha.
//!
//! How a picture is made: a mild perspective camera looks at the scene from the chosen view
//! and is framed on the projected points (every plant vertex, and the ground up to where it
//! fades out) with a 5 % margin. A depth map
//! is drawn from the key light for shadows. A ground disc at y = 0 is drawn first, then
//! every front-facing triangle, with fixed-point edge functions, a depth buffer and
//! per-sample Lambert shading from perspective-correct interpolated vertex normals (hemisphere
//! ambient, shadowed key light from the upper front-left, cool fill). A material with a
//! texture id multiplies its colour by that [`texture`](sylva_mesh::texture), sampled at the
//! perspective-correct texture coordinates with trilinear filtering; the renderer makes each
//! texture once and keeps it. The picture is drawn
//! at `supersample` times the size and box-filtered down in linear light. Invalid input never
//! panics: vertices that are not finite (or beyond ±1e15 m) drop their triangles, zero-area
//! and back-facing triangles are skipped, an empty scene gives the ground alone.
//!
//! How it fits: it draws the scenes, meshes and textures of `sylva-mesh` and depends on
//! nothing else of Sylva's but `sylva-core`: it neither writes nor reads model files (a
//! picture of a GLB file is its scene read back by `sylva-gltf`'s reader, then drawn here).
//! The `sylva` library re-exports it as `sylva::render`.
//!
//! ```
//! use sylva_render::{RenderOptions, View, render};
//! use sylva_mesh::{Mesh, Primitive, Scene, SceneNode};
//! use sylva_core::{Material, MaterialKind};
//!
//! // One upward-facing triangle a metre above the ground.
//! let mesh = Mesh {
//!     positions: vec![[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, -1.0]],
//!     normals: vec![[0.0, 1.0, 0.0]; 3],
//!     uvs: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
//!     primitives: vec![Primitive { material: 0, indices: vec![0, 1, 2] }],
//!     // Texture 3 is a veined leaf (see sylva_mesh::texture).
//!     materials: vec![Material { texture: Some(3), ..Material::of_kind(MaterialKind::Leaf) }],
//!     impostor: None,
//! };
//! let scene = Scene::single(SceneNode::new("leaf", &mesh));
//! let options = RenderOptions { width: 64, height: 48, view: View::Iso, ..Default::default() };
//! let image = render(&scene, &options)?;
//! assert_eq!(image.dimensions(), (64, 48));
//! let png = sylva_render::encode_png(&image)?;
//! assert!(png.starts_with(b"\x89PNG"));
//! # Ok::<(), sylva_render::RenderError>(())
//! ```

mod camera;
pub mod impostor;
pub mod map;
pub mod overlay;
mod raster;
mod shade;
mod sheet;
mod texel;
mod text;

#[cfg(test)]
mod test_meshes;
#[cfg(test)]
mod tests;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use image::{RgbImage, RgbaImage};
use serde::{Deserialize, Serialize};
use sylva_core::{
    Aabb,
    glam::{Vec2, Vec3},
    species::Surface,
};
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::{Scene, SceneNode};

use camera::{Camera, Fit};
use raster::{Cull, ScreenVert, Tri};
use shade::{GROUND_SEGMENTS, Ground, Lights, ShadowMap};
use texel::TextureCache;

pub use sheet::{CAPTION_HEIGHT, SheetCell, SheetOptions, contact_sheet};

/// Smallest image side accepted, pixels.
pub const MIN_SIZE: u32 = 16;
/// Largest image side accepted, pixels.
pub const MAX_SIZE: u32 = 8192;
/// Largest supersampling factor accepted.
pub const MAX_SUPERSAMPLE: u32 = 4;
/// Most samples one render holds (8192 x 8192); above it the supersampling factor is
/// lowered automatically, so memory stays bounded (8 bytes a sample).
pub const MAX_SAMPLES: u64 = 1 << 26;
/// Coordinates beyond this (metres, after placing the node) are treated like NaN.
const MAX_COORD: f32 = 1e15;
/// Picture margin on every side, as a fraction of the side.
const MARGIN: f32 = 0.05;

/// Where the camera looks from. Y is up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// From +Z looking along -Z; +X is to the right.
    Front,
    /// From +X looking along -X; -Z is to the right.
    Side,
    /// From above looking down -Y, -Z at the top of the picture; +X is to the right.
    Top,
    /// A three-quarter view from above: 45 degrees round from the front towards +X,
    /// 30 degrees up.
    #[default]
    Iso,
}

impl View {
    /// Every view, in the order front, side, top, iso.
    pub const ALL: [View; 4] = [View::Front, View::Side, View::Top, View::Iso];

    /// The lower-case name, as parsed by [`FromStr`].
    pub fn name(self) -> &'static str {
        match self {
            View::Front => "front",
            View::Side => "side",
            View::Top => "top",
            View::Iso => "iso",
        }
    }
}

impl fmt::Display for View {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for View {
    type Err = RenderError;

    /// Parses `front`, `side`, `top` or `iso` (any case, surrounding spaces ignored).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        View::ALL
            .into_iter()
            .find(|v| v.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| RenderError::UnknownView(s.to_owned()))
    }
}

/// How to draw one picture.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Picture width in pixels, [`MIN_SIZE`]`..=`[`MAX_SIZE`]. Default 800.
    pub width: u32,
    /// Picture height in pixels, [`MIN_SIZE`]`..=`[`MAX_SIZE`]. Default 800.
    pub height: u32,
    /// Where the camera looks from. Default [`View::Iso`].
    pub view: View,
    /// Draw a round ground at y = 0 under the plants (a soft checker whose squares are a
    /// round number of metres: 1, 2 or 5 times a power of ten), sized to the plants and
    /// fading into the background at its rim. It is in the depth buffer and faces up: parts
    /// of plants below y = 0 (roots) are hidden by it where it lies in front of them, and it
    /// is not drawn when seen from below. Default true.
    pub ground: bool,
    /// Plants cast shadows from the key light onto the ground and onto themselves.
    /// Default true.
    pub shadows: bool,
    /// Background colour, sRGB. Default `[221, 232, 242]`, a pale sky.
    pub background: [u8; 3],
    /// Samples per pixel along each axis, `1..=`[`MAX_SUPERSAMPLE`]; the picture is drawn
    /// this many times larger and box-filtered down, which smooths edges. Lowered
    /// automatically when the samples would exceed [`MAX_SAMPLES`]. Default 2.
    pub supersample: u32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 800,
            view: View::Iso,
            ground: true,
            shadows: true,
            background: [221, 232, 242],
            supersample: 2,
        }
    }
}

impl RenderOptions {
    /// Checks sizes and the supersampling factor.
    pub fn validate(&self) -> Result<(), RenderError> {
        let side = MIN_SIZE..=MAX_SIZE;
        if !side.contains(&self.width) || !side.contains(&self.height) {
            return Err(RenderError::InvalidSize {
                width: self.width,
                height: self.height,
            });
        }
        if !(1..=MAX_SUPERSAMPLE).contains(&self.supersample) {
            return Err(RenderError::InvalidSupersample(self.supersample));
        }
        Ok(())
    }

    /// The supersampling factor actually used: `supersample`, lowered until the samples
    /// fit [`MAX_SAMPLES`].
    pub fn effective_supersample(&self) -> u32 {
        let pixels = u64::from(self.width) * u64::from(self.height);
        let mut s = self.supersample.clamp(1, MAX_SUPERSAMPLE);
        while s > 1 && pixels * u64::from(s * s) > MAX_SAMPLES {
            s -= 1;
        }
        s
    }
}

/// What can go wrong while rendering or saving a picture.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The picture size is outside [`MIN_SIZE`]`..=`[`MAX_SIZE`] on a side.
    #[error(
        "image size {width}x{height} is not allowed: each side must be {MIN_SIZE}..={MAX_SIZE} pixels"
    )]
    InvalidSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The supersampling factor is outside `1..=`[`MAX_SUPERSAMPLE`].
    #[error("supersample factor {0} is not allowed: use 1..={MAX_SUPERSAMPLE}")]
    InvalidSupersample(u32),
    /// A contact-sheet cell is too small for a picture and its caption, or too large.
    #[error(
        "contact sheet cell {width}x{height} is not allowed: width {MIN_SIZE}..={MAX_SIZE}, height {min_height}..={MAX_SIZE}"
    )]
    InvalidCell {
        /// Requested cell width.
        width: u32,
        /// Requested cell height.
        height: u32,
        /// Smallest height that leaves room for the caption.
        min_height: u32,
    },
    /// The whole contact sheet would be too large.
    #[error("contact sheet of {width}x{height} pixels is too large (at most {max} pixels)")]
    SheetTooLarge {
        /// Sheet width.
        width: u64,
        /// Sheet height.
        height: u64,
        /// Largest pixel count allowed.
        max: u64,
    },
    /// A contact sheet was asked for with no cells.
    #[error("a contact sheet needs at least one cell")]
    EmptySheet,
    /// A view name that is not one of the four.
    #[error("unknown view {0:?}: choose one of front, side, top, iso")]
    UnknownView(String),
    /// PNG encoding failed.
    #[error("PNG encoding failed")]
    Png(#[from] image::ImageError),
    /// Writing the file failed.
    #[error("cannot write {}", path.display())]
    Io {
        /// The file being written.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Renders a scene into a new picture. For many pictures, keep a [`Renderer`] instead: it
/// reuses its buffers.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RgbImage, RenderError> {
    Renderer::new().render(scene, options)
}

/// Encodes a picture as PNG bytes.
pub fn encode_png(image: &RgbImage) -> Result<Vec<u8>, RenderError> {
    encode(image, image::ExtendedColorType::Rgb8)
}

/// Encodes a picture with alpha (a cut-out's) as PNG bytes.
pub fn encode_rgba_png(image: &RgbaImage) -> Result<Vec<u8>, RenderError> {
    encode(image, image::ExtendedColorType::Rgba8)
}

fn encode<P: image::Pixel<Subpixel = u8>>(
    image: &image::ImageBuffer<P, Vec<u8>>,
    color: image::ExtendedColorType,
) -> Result<Vec<u8>, RenderError> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes).write_image(
        image.as_raw(),
        image.width(),
        image.height(),
        color,
    )?;
    Ok(bytes)
}

/// Writes a picture as a PNG file, atomically (a reader sees the old file or the new one).
pub fn write_png(path: &Path, image: &RgbImage) -> Result<(), RenderError> {
    let bytes = encode_png(image)?;
    sylva_core::io::write_atomic(path, &bytes).map_err(|source| RenderError::Io {
        path: path.to_owned(),
        source,
    })
}

/// What [`Renderer::cut_out`] frames: a rectangle across the view, metres along the view's
/// right and up axes (for the front view, x and y; for the side view, −z and y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Least coordinate along the view's right axis.
    pub left: f32,
    /// Greatest coordinate along the view's right axis.
    pub right: f32,
    /// Least coordinate along the view's up axis.
    pub bottom: f32,
    /// Greatest coordinate along the view's up axis.
    pub top: f32,
}

/// Eye distance of [`Renderer::cut_out`], in bounding radii: the nearest and farthest points
/// of the scene differ in scale by about 1.3%.
const CUT_OUT_DISTANCE: f32 = 150.0;

/// A vertex after placement and projection.
#[derive(Clone, Copy, Debug, Default)]
struct Vtx {
    /// World position.
    p: Vec3,
    /// World unit normal, zero when the mesh has none usable.
    n: Vec3,
    /// Texture coordinates, zero when the mesh has none.
    uv: Vec2,
    /// Position in the sample grid.
    s: ScreenVert,
    /// 1 / depth from the eye (the depth buffer holds this: larger is nearer).
    iz: f32,
    /// False when the vertex cannot be drawn (NaN, huge, or not projectable).
    ok: bool,
}

/// A renderer that keeps its sample, depth and shadow buffers, and the textures it has made,
/// between pictures.
#[derive(Default)]
pub struct Renderer {
    /// Packed sRGB per sample.
    color: Vec<u32>,
    /// 1 / depth per sample, 0 where nothing is drawn.
    depth: Vec<f32>,
    shadow: ShadowMap,
    /// One node's vertices.
    verts: Vec<Vtx>,
    /// Textures made so far, by id.
    textures: TextureCache,
}

impl fmt::Debug for Renderer {
    // The buffers hold millions of samples: show their sizes, not their contents.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Renderer")
            .field("samples", &self.color.len())
            .field("shadow_size", &self.shadow.size)
            .finish_non_exhaustive()
    }
}

/// A node's vertex placed in the world, `None` when unusable.
#[inline]
fn place(node: &SceneNode, p: [f32; 3]) -> Option<Vec3> {
    let w = node.transform_point(Vec3::from_array(p));
    // `max_element` skips NaN, so finiteness is checked first.
    (w.is_finite() && w.abs().max_element() <= MAX_COORD).then_some(w)
}

/// Bounds of every usable vertex in the scene.
fn scene_bounds(scene: &Scene) -> Aabb {
    let mut b = Aabb::EMPTY;
    for node in &scene.nodes {
        for &p in &node.mesh.positions {
            if let Some(w) = place(node, p) {
                b.grow(w, 0.0);
            }
        }
    }
    b
}

impl Renderer {
    /// A renderer with empty buffers.
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// Renders a scene; the result depends only on `scene` and `options`.
    pub fn render(
        &mut self,
        scene: &Scene,
        options: &RenderOptions,
    ) -> Result<RgbImage, RenderError> {
        options.validate()?;
        let ss = options.effective_supersample();
        let (sw, sh) = (options.width * ss, options.height * ss);
        let (w, h) = (sw as usize, sh as usize);
        let background = shade::pack_srgb(options.background);
        self.color.clear();
        self.color.resize(w * h, background);
        self.depth.clear();
        self.depth.resize(w * h, 0.0);

        let plants = scene_bounds(scene);
        let ground = options.ground.then(|| Ground::for_plants(&plants));
        let all = match &ground {
            Some(g) => plants.union(&g.bounds()),
            None => plants,
        };
        if !all.is_empty() {
            let centre = all.center();
            let radius = (0.5 * all.size().length()).max(1e-6);
            let camera = frame(scene, ground.as_ref(), options.view, centre, radius, sw, sh);
            let lights = Lights::for_camera(&camera);
            let shadow_size = if options.shadows {
                // Three texels for every four samples is plenty under the filtered lookup.
                (sw.max(sh) as usize * 3 / 4).clamp(256, 2048)
            } else {
                0
            };
            self.shadow.reset(lights.key, centre, radius, shadow_size);
            if shadow_size > 0 {
                for node in &scene.nodes {
                    self.draw_shadow(node);
                }
            }
            let bg = shade::srgb_to_linear3(options.background);
            if let Some(g) = &ground {
                self.draw_ground(g, &camera, &lights, bg, w, h);
            }
            for node in &scene.nodes {
                self.draw_node(node, &camera, &lights, w, h);
            }
        }
        Ok(self.resolve(options.width, options.height, ss))
    }

    /// A picture of `scene` seen from `view` whose edges are exactly `frame`, on a clear
    /// background (alpha is the share of each pixel's samples drawn), through a camera so
    /// far away that the view is all but orthographic: what an impostor card shows. No
    /// ground; the plant shadows itself; `supersample` as [`RenderOptions::supersample`].
    pub fn cut_out(
        &mut self,
        scene: &Scene,
        view: View,
        frame: Frame,
        (width, height): (u32, u32),
        supersample: u32,
    ) -> Result<RgbaImage, RenderError> {
        let options = RenderOptions {
            width,
            height,
            view,
            supersample,
            ..RenderOptions::default()
        };
        options.validate()?;
        let ss = options.effective_supersample();
        let (sw, sh) = (width * ss, height * ss);
        let (w, h) = (sw as usize, sh as usize);
        self.color.clear();
        self.color.resize(w * h, 0);
        self.depth.clear();
        self.depth.resize(w * h, 0.0);
        let plants = scene_bounds(scene);
        if !plants.is_empty() {
            let centre = plants.center();
            let radius = (0.5 * plants.size().length()).max(1e-6);
            let camera = Camera::looking_from(view, centre, radius, CUT_OUT_DISTANCE);
            // The frame's corners in the plane through the scene's centre.
            let depth = camera.forward * camera.forward.dot(centre);
            let mut fit = camera::Fit::default();
            for (u, v) in [
                (frame.left, frame.bottom),
                (frame.right, frame.bottom),
                (frame.left, frame.top),
                (frame.right, frame.top),
            ] {
                fit.add(camera.view_xy(camera.right * u + camera.up * v + depth));
            }
            let camera = camera.framed(&fit, sw, sh, 0.0);
            let lights = Lights::for_camera(&camera);
            let shadow_size = (sw.max(sh) as usize * 3 / 4).clamp(256, 2048);
            self.shadow.reset(lights.key, centre, radius, shadow_size);
            for node in &scene.nodes {
                self.draw_shadow(node);
            }
            for node in &scene.nodes {
                self.draw_node(node, &camera, &lights, w, h);
            }
        }
        Ok(self.resolve_clear(width, height, ss))
    }

    /// Box-filters the samples down to a picture with alpha: each pixel's colour the mean of
    /// its drawn samples (in linear light), its alpha their share; clear pixels take the
    /// mean colour of the drawn ones, so filtering never darkens an edge.
    fn resolve_clear(&self, width: u32, height: u32, ss: u32) -> RgbaImage {
        let (w, ss) = (width as usize, ss as usize);
        let sw = w * ss;
        let srgb = shade::to_srgb_table();
        let linear = shade::to_linear_table();
        let colour = |c: u32| {
            Vec3::new(
                linear[(c & 0xff) as usize],
                linear[(c >> 8 & 0xff) as usize],
                linear[(c >> 16 & 0xff) as usize],
            )
        };
        let (mut total, mut drawn) = (Vec3::ZERO, 0usize);
        for (c, d) in self.color.iter().zip(&self.depth) {
            if *d > 0.0 {
                total += colour(*c);
                drawn += 1;
            }
        }
        let fill = if drawn > 0 {
            total / drawn as f32
        } else {
            Vec3::ONE
        };
        let mut img = RgbaImage::new(width, height);
        for (k, px) in img.chunks_exact_mut(4).enumerate() {
            let (x, y) = (k % w, k / w);
            let (mut sum, mut n) = (Vec3::ZERO, 0usize);
            for sy in 0..ss {
                let row = (y * ss + sy) * sw + x * ss;
                for i in row..row + ss {
                    if self.depth[i] > 0.0 {
                        sum += colour(self.color[i]);
                        n += 1;
                    }
                }
            }
            let c = if n > 0 { sum / n as f32 } else { fill };
            let c = shade::pack(srgb, c);
            let alpha = (255 * n / (ss * ss)) as u8;
            px.copy_from_slice(&[c as u8, (c >> 8) as u8, (c >> 16) as u8, alpha]);
        }
        img
    }

    /// Draws a node's depth into the shadow map. Only faces turned to the light are drawn:
    /// meshes are closed or double-sided (see [`sylva_mesh::mesh`]), so they are enough;
    /// but cut-out cards, one-sided, are drawn from both sides and cast only their shapes.
    fn draw_shadow(&mut self, node: &SceneNode) {
        let Renderer {
            shadow,
            verts,
            textures,
            ..
        } = self;
        verts.clear();
        verts.extend(node.mesh.positions.iter().enumerate().map(|(k, &p)| {
            let mut v = Vtx::default();
            if let Some(w) = place(node, p) {
                let l = shadow.to_light(w);
                if let Some(s) = ScreenVert::from_samples(l.x, l.y) {
                    // The shadow pass keeps light depth where the colour pass keeps 1/z.
                    (v.s, v.iz, v.ok) = (s, l.z, true);
                    v.uv = node
                        .mesh
                        .uvs
                        .get(k)
                        .map_or(Vec2::ZERO, |&uv| Vec2::from_array(uv));
                }
            }
            v
        }));
        let size = shadow.size;
        for prim in &node.mesh.primitives {
            let cut = texture_of(
                textures,
                node.mesh,
                cut_out(node.mesh.materials.get(prim.material)),
            );
            let cull = if cut.is_some() {
                Cull::None
            } else {
                Cull::Back
            };
            for t in prim.indices.chunks_exact(3) {
                let Some([a, b, c]) = triangle(verts, t) else {
                    continue;
                };
                let Some(tri) = Tri::new([a.s, b.s, c.s], cull, size, size) else {
                    continue;
                };
                let (b, c) = if tri.flipped { (c, b) } else { (b, c) };
                let (d0, d1, d2) = (a.iz, b.iz - a.iz, c.iz - a.iz);
                let lod = cut.map_or(0.0, |tex| {
                    let uv_area = 0.5 * (b.uv - a.uv).perp_dot(c.uv - a.uv).abs();
                    tex.lod(uv_area / tri.sample_area())
                });
                let (u0, u1, u2) = (a.uv, b.uv - a.uv, c.uv - a.uv);
                tri.for_each(|i, l1, l2| {
                    let d = d0 + l1 * d1 + l2 * d2;
                    if d < shadow.depth[i] {
                        // The light's view is orthographic: uvs interpolate linearly.
                        if let Some(tex) = cut {
                            let uv = u0 + u1 * l1 + u2 * l2;
                            if tex.alpha(lod, uv.x, uv.y) < ALPHA_CUTOFF {
                                return;
                            }
                        }
                        shadow.depth[i] = d;
                    }
                });
            }
        }
    }

    /// Draws the ground disc as a fan of triangles.
    fn draw_ground(
        &mut self,
        ground: &Ground,
        camera: &Camera,
        lights: &Lights,
        background: Vec3,
        w: usize,
        h: usize,
    ) {
        let srgb = shade::to_srgb_table();
        let Renderer {
            color,
            depth,
            shadow,
            ..
        } = self;
        let vertex = |p: Vec3| -> Option<Vtx> {
            let (x, y, iz) = camera.project(p)?;
            Some(Vtx {
                p,
                n: Vec3::Y,
                uv: Vec2::ZERO,
                s: ScreenVert::from_samples(x, y)?,
                iz,
                ok: true,
            })
        };
        let Some(centre) = vertex(ground.centre) else {
            return;
        };
        for i in 0..GROUND_SEGMENTS {
            let (Some(b), Some(c)) = (vertex(ground.rim(i)), vertex(ground.rim(i + 1))) else {
                continue;
            };
            let a = centre;
            let Some(tri) = Tri::new([a.s, b.s, c.s], Cull::Back, w, h) else {
                continue;
            };
            let (b, c) = if tri.flipped { (c, b) } else { (b, c) };
            let (pa, pb, pc) = (a.p * a.iz, b.p * b.iz, c.p * c.iz);
            tri.for_each(|i, l1, l2| {
                let l0 = 1.0 - l1 - l2;
                let iz = l0 * a.iz + l1 * b.iz + l2 * c.iz;
                if iz <= depth[i] {
                    return;
                }
                depth[i] = iz;
                let p = (pa * l0 + pb * l1 + pc * l2) / iz;
                let (albedo, fade) = ground.albedo(p);
                let lit = shadow.lit(shadow.to_light(p), Vec3::Y);
                let c = (albedo * lights.shade(Vec3::Y, lit)).lerp(background, fade);
                color[i] = shade::pack(srgb, c);
            });
        }
    }

    /// Draws a node's front-facing triangles with per-sample shading.
    fn draw_node(
        &mut self,
        node: &SceneNode,
        camera: &Camera,
        lights: &Lights,
        w: usize,
        h: usize,
    ) {
        let srgb = shade::to_srgb_table();
        let Renderer {
            color,
            depth,
            shadow,
            verts,
            textures,
        } = self;
        let mesh = node.mesh;
        verts.clear();
        verts.extend(mesh.positions.iter().enumerate().map(|(k, &p)| {
            let v = Vtx::default();
            let Some(world) = place(node, p) else {
                return v;
            };
            let Some((x, y, iz)) = camera.project(world) else {
                return v;
            };
            let Some(s) = ScreenVert::from_samples(x, y) else {
                return v;
            };
            let n = mesh.normals.get(k).map_or(Vec3::ZERO, |&n| {
                (node.rotation * Vec3::from_array(n)).normalize_or_zero()
            });
            Vtx {
                p: world,
                n,
                uv: mesh
                    .uvs
                    .get(k)
                    .map_or(Vec2::ZERO, |&uv| Vec2::from_array(uv)),
                s,
                iz,
                ok: true,
            }
        }));
        for prim in &mesh.primitives {
            let material = mesh.materials.get(prim.material);
            let albedo = material.map_or(Vec3::splat(0.5), |m| shade::albedo(m.color));
            let cut = cut_out(material).is_some();
            // An impostor's picture was lit when it was made: it shows as it is.
            let unlit = material.and_then(|m| m.surface) == Some(Surface::Impostor);
            let texture = texture_of(textures, mesh, material.and_then(Picture::base_of));
            let cull = if cut { Cull::None } else { Cull::Back };
            for t in prim.indices.chunks_exact(3) {
                let Some([a, b, c]) = triangle(verts, t) else {
                    continue;
                };
                let Some(tri) = Tri::new([a.s, b.s, c.s], cull, w, h) else {
                    continue;
                };
                // A vertex without a usable normal makes the triangle flat-shaded.
                let face = (b.p - a.p).cross(c.p - a.p).normalize_or(-camera.forward);
                let smooth = a.n != Vec3::ZERO && b.n != Vec3::ZERO && c.n != Vec3::ZERO;
                // A card seen from behind shows its back: normals turned to the viewer.
                let side = if tri.flipped { 1.0 } else { -1.0 };
                let (b, c) = if tri.flipped { (c, b) } else { (b, c) };
                let normal = |v: &Vtx| if smooth { v.n * side } else { face * side };
                // Attributes divided by depth interpolate linearly on screen.
                let (na, nb, nc) = (normal(&a) * a.iz, normal(&b) * b.iz, normal(&c) * c.iz);
                let shadows = shadow.size > 0;
                let (la, lb, lc) = if shadows {
                    (
                        shadow.to_light(a.p) * a.iz,
                        shadow.to_light(b.p) * b.iz,
                        shadow.to_light(c.p) * c.iz,
                    )
                } else {
                    (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO)
                };
                // Texture coordinates over depth, and the level of detail from the
                // triangle's texture area per screen sample.
                let sampler = texture.map(|tex| {
                    let uv_area = 0.5 * (b.uv - a.uv).perp_dot(c.uv - a.uv).abs();
                    let lod = tex.lod(uv_area / tri.sample_area());
                    (tex, lod, a.uv * a.iz, b.uv * b.iz, c.uv * c.iz)
                });
                tri.for_each(|i, l1, l2| {
                    let l0 = 1.0 - l1 - l2;
                    let iz = l0 * a.iz + l1 * b.iz + l2 * c.iz;
                    if iz <= depth[i] {
                        return;
                    }
                    let albedo = match sampler {
                        // Untextured pictures are exactly what they were before textures.
                        None => albedo,
                        Some((tex, lod, ua, ub, uc)) => {
                            let uv = (ua * l0 + ub * l1 + uc * l2) / iz;
                            if cut && tex.alpha(lod, uv.x, uv.y) < ALPHA_CUTOFF {
                                return;
                            }
                            albedo * tex.sample_color(lod, uv.x, uv.y)
                        }
                    };
                    depth[i] = iz;
                    if unlit {
                        color[i] = shade::pack(srgb, albedo);
                        return;
                    }
                    let n = (na * l0 + nb * l1 + nc * l2).normalize_or(face);
                    let shade = if cut {
                        // Leaves and petals are lit through from behind as well.
                        let towards = if n.dot(lights.key) >= 0.0 { n } else { -n };
                        let lit = if shadows {
                            shadow.lit((la * l0 + lb * l1 + lc * l2) / iz, towards)
                        } else {
                            1.0
                        };
                        lights.shade_thin(n, lit)
                    } else {
                        let lit = if shadows && n.dot(lights.key) > 0.0 {
                            shadow.lit((la * l0 + lb * l1 + lc * l2) / iz, n)
                        } else {
                            1.0
                        };
                        lights.shade(n, lit)
                    };
                    color[i] = shade::pack(srgb, albedo * shade);
                });
            }
        }
    }

    /// Box-filters the samples down to the picture, averaging in linear light.
    fn resolve(&self, width: u32, height: u32, ss: u32) -> RgbImage {
        let mut img = RgbImage::new(width, height);
        let (w, ss) = (width as usize, ss as usize);
        let sw = w * ss;
        let srgb = shade::to_srgb_table();
        let linear = shade::to_linear_table();
        let inv = 1.0 / (ss * ss) as f32;
        for (k, px) in img.chunks_exact_mut(3).enumerate() {
            let (x, y) = (k % w, k / w);
            if ss == 1 {
                let c = self.color[k];
                px.copy_from_slice(&[c as u8, (c >> 8) as u8, (c >> 16) as u8]);
                continue;
            }
            let mut sum = Vec3::ZERO;
            for sy in 0..ss {
                let row = (y * ss + sy) * sw + x * ss;
                for &c in &self.color[row..row + ss] {
                    sum += Vec3::new(
                        linear[(c & 0xff) as usize],
                        linear[(c >> 8 & 0xff) as usize],
                        linear[(c >> 16 & 0xff) as usize],
                    );
                }
            }
            let c = shade::pack(srgb, sum * inv);
            px.copy_from_slice(&[c as u8, (c >> 8) as u8, (c >> 16) as u8]);
        }
        img
    }
}

/// The alpha below which a cut-out shows nothing (as the GLB writer's `alphaCutoff`).
const ALPHA_CUTOFF: f32 = 0.5;

/// The picture a material cuts its shape out of, if it is a cut-out (leaves, petals,
/// impostors).
fn cut_out(material: Option<&sylva_core::Material>) -> Option<Picture> {
    let m = material?;
    m.surface
        .filter(|s| s.is_cut_out())
        .and(Picture::base_of(m))
}

/// The texture of a primitive's material in `mesh`, made the first time (an impostor's
/// from the mesh's own picture; `None` when it has none).
fn texture_of<'t>(
    textures: &'t mut TextureCache,
    mesh: &sylva_mesh::Mesh,
    picture: Option<Picture>,
) -> Option<&'t texel::MipTexture> {
    match picture? {
        Picture::Impostor => Some(textures.impostor(mesh.impostor.as_ref()?)),
        p => Some(textures.get(p)),
    }
}

/// The three vertices of a triangle, if its indices are in range and all are drawable.
#[inline]
fn triangle(verts: &[Vtx], t: &[u32]) -> Option<[Vtx; 3]> {
    let get = |i: u32| verts.get(i as usize).filter(|v| v.ok).copied();
    Some([get(t[0])?, get(t[1])?, get(t[2])?])
}

/// A camera for `view`, framed on every usable vertex and most of the ground.
fn frame(
    scene: &Scene,
    ground: Option<&Ground>,
    view: View,
    centre: Vec3,
    radius: f32,
    width: u32,
    height: u32,
) -> Camera {
    let camera = Camera::looking(view, centre, radius);
    let mut fit = Fit::default();
    for node in &scene.nodes {
        for &p in &node.mesh.positions {
            if let Some(w) = place(node, p) {
                fit.add(camera.view_xy(w));
            }
        }
    }
    if let Some(g) = ground {
        // The rim fades out from 0.7 radii; cutting the faint outer part off at the frame's
        // edge is invisible and leaves more room for the plants.
        for i in 0..GROUND_SEGMENTS {
            fit.add(camera.view_xy(g.centre + (g.rim(i) - g.centre) * 0.85));
        }
    }
    camera.framed(&fit, width, height, MARGIN)
}
