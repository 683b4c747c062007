//! Writes every leaf atlas, petal cut-out and bark picture Sylva draws as PNG files, and two
//! sheets to look at them by (`atlases.png`: each kind's atlas in its summer colour over
//! white; `barks.png`: each bark in its colour above its normal map):
//! `cargo run --release -p sylva-mesh --example pictures -- OUT_DIR`.

use image::{Rgb, RgbImage, imageops};
use sylva_core::species::{BarkKind, LeafKind};
use sylva_mesh::picture::Picture;

/// A linear channel as an 8-bit sRGB one.
fn srgb(l: f32) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0 + 0.5) as u8
}

/// An 8-bit sRGB channel as linear.
fn linear(s: u8) -> f32 {
    let c = f32::from(s) / 255.0;
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/pictures".into());
    std::fs::create_dir_all(&out)?;
    let mut all: Vec<Picture> = LeafKind::ALL.into_iter().map(Picture::Leaves).collect();
    all.extend([
        Picture::Petal(None),
        Picture::Petal(Some(6)),
        Picture::Petal(Some(7)),
    ]);
    for k in BarkKind::ALL {
        all.extend([Picture::Bark(k), Picture::BarkNormal(k)]);
    }
    for p in all {
        let png = p.png()?;
        let path = format!("{out}/{}.png", p.name());
        std::fs::write(&path, png.as_slice())?;
        println!("{path}: {} bytes", png.len());
    }

    // Atlases in their colours over white, four to a row.
    let cell = 384u32;
    let mut sheet = RgbImage::from_pixel(4 * cell, 3 * cell, Rgb([255, 255, 255]));
    for (i, kind) in LeafKind::ALL.into_iter().enumerate() {
        let atlas = sylva_mesh::atlas::leaf_atlas(kind);
        let small = imageops::resize(&*atlas, cell, cell, imageops::FilterType::Triangle);
        let color = kind.spec().color;
        let (x0, y0) = ((i as u32 % 4) * cell, (i as u32 / 4) * cell);
        for (x, y, p) in small.enumerate_pixels() {
            let [g, a] = p.0;
            let a = f32::from(a) / 255.0;
            let rgb = color.map(|c| srgb(c * linear(g) * 2.2 * a + (1.0 - a)));
            sheet.put_pixel(x0 + x, y0 + y, Rgb(rgb));
        }
    }
    sheet.save(format!("{out}/atlases.png"))?;

    // Barks in their colours above their normal maps.
    let mut barks = RgbImage::from_pixel(4 * cell, 2 * cell, Rgb([255, 255, 255]));
    for (i, kind) in BarkKind::ALL.into_iter().enumerate() {
        let color = kind.spec().color;
        let grey = sylva_mesh::bark::bark_color(kind);
        let grey = imageops::resize(&*grey, cell, cell, imageops::FilterType::Triangle);
        for (x, y, p) in grey.enumerate_pixels() {
            let rgb = color.map(|c| srgb(c * linear(p.0[0])));
            barks.put_pixel(i as u32 * cell + x, y, Rgb(rgb));
        }
        let normal = sylva_mesh::bark::bark_normal(kind);
        let normal = imageops::resize(&*normal, cell, cell, imageops::FilterType::Triangle);
        imageops::replace(
            &mut barks,
            &normal,
            i64::from(i as u32 * cell),
            i64::from(cell),
        );
    }
    barks.save(format!("{out}/barks.png"))?;
    Ok(())
}
