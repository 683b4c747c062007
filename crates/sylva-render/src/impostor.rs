//! An impostor: the last level of a plant's detail, for trees far away. Two cards crossed
//! at the plant's axis, one facing the front (+z) and one the side (+x), each showing a
//! picture of the plant from its side, cut out by alpha: from any direction around the
//! plant, one of them faces the viewer within 45°, and the other stands edge-on. Eight
//! vertices, four triangles, one picture.
//!
//! The picture is drawn by [`Renderer::cut_out`] with the renderer's own lights, from a
//! camera so far away that the view is all but orthographic, so the cards show the plant at
//! its true size. Both views share one PNG of 512 × 512 pixels. A plant at least as tall as
//! it is wide (either way) has its front in the left half and its side in the right, each
//! cell framing a rectangle Q wide and 2Q high about its axis from its lowest point up, Q
//! the larger of its width and half its height; a wider plant has its front in the top half
//! and its side in the bottom, each framing 2Q wide and Q high, Q the larger of its height
//! and half its width (2% margins). The card's material is
//! [`Surface::Impostor`]: unlit, as its picture was lit when it was made.

use image::RgbaImage;
use sylva_core::glam::Vec3;
use sylva_core::species::Surface;
use sylva_core::{Material, MaterialKind};
use sylva_mesh::{Mesh, Primitive, Scene};

use crate::{Frame, RenderError, Renderer, View, encode_rgba_png};

/// Pixels of the picture's side; each view takes one half of it.
pub const PICTURE: u32 = 512;
/// Samples per pixel side of the picture.
const SUPERSAMPLE: u32 = 3;
/// Room left around the plant in its cells, a share of the frame's width.
const MARGIN: f32 = 0.02;

/// The impostor of `scene` (a plant at the origin, meshed at its full detail): two crossed
/// cards with its picture (see the module docs). `None` for a scene with nothing to draw.
pub fn impostor(scene: &Scene) -> Result<Option<Mesh>, RenderError> {
    let bounds = crate::scene_bounds(scene);
    if bounds.is_empty() {
        return Ok(None);
    }
    let size = bounds.size();
    let centre = bounds.center();
    let (width, height) = (size.x.max(size.z), size.y);
    // A tall plant's views side by side, each cell twice as high as wide; a wide one's one
    // above the other, each twice as wide as high. `step`: where the side's cell starts.
    let tall = height >= width;
    let (cell, step, frame_size) = if tall {
        let across = width.max(0.5 * height) * (1.0 + MARGIN);
        ((PICTURE / 2, PICTURE), [0.5, 0.0], (across, 2.0 * across))
    } else {
        let up = height.max(0.5 * width) * (1.0 + MARGIN);
        ((PICTURE, PICTURE / 2), [0.0, 0.5], (2.0 * up, up))
    };
    let (half, bottom) = (0.5 * frame_size.0, bounds.min.y);
    let top = bottom + frame_size.1;
    let mut renderer = Renderer::new();
    let mut picture = RgbaImage::new(PICTURE, PICTURE);
    // Each view's right axis: +x for the front, −z for the side.
    for (k, (view, across)) in [(View::Front, centre.x), (View::Side, -centre.z)]
        .into_iter()
        .enumerate()
    {
        let frame = Frame {
            left: across - half,
            right: across + half,
            bottom,
            top,
        };
        let drawn = renderer.cut_out(scene, view, frame, cell, SUPERSAMPLE)?;
        let (x, y) = (k as u32 * (PICTURE - cell.0), k as u32 * (PICTURE - cell.1));
        image::imageops::replace(&mut picture, &drawn, i64::from(x), i64::from(y));
    }
    let png = encode_rgba_png(&picture)?;

    // Front card: x across, facing +z; side card: −z across (its picture's right), facing +x.
    let front = [
        Vec3::new(centre.x - half, 0.0, centre.z),
        Vec3::new(centre.x + half, 0.0, centre.z),
    ];
    let side = [
        Vec3::new(centre.x, 0.0, centre.z + half),
        Vec3::new(centre.x, 0.0, centre.z - half),
    ];
    let (cu, cv) = (1.0 - step[0], 1.0 - step[1]);
    let mut mesh = Mesh::default();
    let mut indices = Vec::with_capacity(12);
    for (k, ([left, right], normal)) in [(front, Vec3::Z), (side, Vec3::X)].into_iter().enumerate()
    {
        let (u0, v0) = (k as f32 * step[0], k as f32 * step[1]);
        let base = mesh.positions.len() as u32;
        for (p, uv) in [
            (left.with_y(bottom), [u0, v0 + cv]),
            (right.with_y(bottom), [u0 + cu, v0 + cv]),
            (right.with_y(top), [u0 + cu, v0]),
            (left.with_y(top), [u0, v0]),
        ] {
            mesh.positions.push(p.to_array());
            mesh.normals.push(normal.to_array());
            mesh.uvs.push(uv);
        }
        indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    }
    mesh.primitives.push(Primitive {
        material: 0,
        indices,
    });
    mesh.materials.push(Material {
        name: "leaf-impostor".into(),
        color: [1.0; 3],
        surface: Some(Surface::Impostor),
        ..Material::of_kind(MaterialKind::Leaf)
    });
    mesh.impostor = Some(std::sync::Arc::new(png));
    Ok(Some(mesh))
}
