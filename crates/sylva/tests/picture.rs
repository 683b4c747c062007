//! Designers' pictures read as target outlines: the ink of drawings, cut-outs and photos,
//! in PNG and JPEG, and hostile files refused with errors that name them.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};

use image::{GrayImage, Luma, Rgb, RgbImage, Rgba, RgbaImage};
use sylva::InputError;
use sylva::picture::{Threshold, decode_target, load_target, otsu};
use sylva_fitness::silhouette::Bitmap;

const W: u32 = 48;
const H: u32 = 64;

/// A folder of its own for each test's pictures.
fn dir(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("picture")
        .join(test);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A tree: a round crown on a trunk, standing on the bottom row.
fn is_tree(x: u32, y: u32) -> bool {
    let (dx, dy) = (x as f32 - 24.0, y as f32 - 22.0);
    let crown = dx * dx + dy * dy <= 16.0 * 16.0;
    let trunk = (21..27).contains(&x) && y >= 36;
    crown || trunk
}

fn tree_bitmap() -> Bitmap {
    let mut bitmap = Bitmap::new(W, H);
    for y in 0..H {
        for x in 0..W {
            if is_tree(x, y) {
                bitmap.set(x, y);
            }
        }
    }
    bitmap
}

/// A black tree on white.
fn tree_drawing() -> GrayImage {
    GrayImage::from_fn(W, H, |x, y| Luma([if is_tree(x, y) { 0 } else { 255 }]))
}

/// Pixels where two bitmaps of the same size differ.
fn differing(a: &Bitmap, b: &Bitmap) -> u32 {
    let mut n = 0;
    for y in 0..a.height() {
        for x in 0..a.width() {
            n += u32::from(a.get(x, y) != b.get(x, y));
        }
    }
    n
}

/// A deterministic noise in 0..n, for photo-like pictures.
fn noise(x: u32, y: u32, n: u32) -> u32 {
    let h = (x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663)).wrapping_mul(2_654_435_761);
    (h >> 16) % n
}

/// Asserts `result` is an error about `path` whose message holds each of `expected`.
fn assert_refused(result: Result<Bitmap, InputError>, path: &Path, expected: &[&str]) {
    let e = result.unwrap_err();
    assert_eq!(e.path.as_deref(), Some(path), "{e}");
    let shown = e.to_string();
    let name = path.file_name().unwrap().to_string_lossy();
    assert!(shown.contains(&*name), "the error names the file: {shown}");
    for part in expected {
        assert!(shown.contains(part), "{part:?} in {shown:?}");
    }
}

/// A PNG chunk: length, type, data and CRC.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend(kind);
    out.extend(data);
    let mut crc = crc32fast::Hasher::new();
    crc.update(kind);
    crc.update(data);
    out.extend(crc.finalize().to_be_bytes());
    out
}

/// A PNG's signature and IHDR for a picture of `width` x `height` of `depth`-bit samples of
/// `color` (0 gray, 2 RGB, 6 RGBA), and nothing else.
fn png_header(width: u32, height: u32, depth: u8, color: u8) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([depth, color, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png
}

#[test]
fn a_black_tree_on_white_png_is_its_ink() {
    let path = dir("png").join("tree.png");
    tree_drawing().save(&path).unwrap();
    let ink = load_target(&path, Threshold::Otsu).unwrap();
    assert_eq!((ink.width(), ink.height()), (W, H));
    assert_eq!(ink, tree_bitmap());
    assert_eq!(
        load_target(&path, Threshold::Level(0.5)).unwrap(),
        tree_bitmap()
    );
}

#[test]
fn a_black_tree_on_white_jpeg_is_its_ink_but_for_edges() {
    // RGB, and named `.png`: the format comes from the content.
    let path = dir("jpeg").join("tree-really-a-jpeg.png");
    let picture = RgbImage::from_fn(W, H, |x, y| {
        Rgb(if is_tree(x, y) { [0; 3] } else { [255; 3] })
    });
    let mut file = std::fs::File::create(&path).unwrap();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut file, 90)
        .encode_image(&picture)
        .unwrap();
    drop(file);
    let ink = load_target(&path, Threshold::Otsu).unwrap();
    let tree = tree_bitmap();
    let (got, want) = (ink.ink() as f64, tree.ink() as f64);
    assert!(
        (got - want).abs() <= 0.02 * want,
        "{got} ink pixels, {want} expected"
    );
    assert!(differing(&ink, &tree) <= 30, "{}", differing(&ink, &tree));
}

#[test]
fn a_cut_out_is_its_opaque_pixels_whatever_their_colour() {
    let path = dir("alpha").join("cut-out.png");
    let mut picture = RgbaImage::from_fn(W, H, |x, y| {
        // A white tree on a transparent background (dark where no one sees it).
        Rgba(if is_tree(x, y) { [255; 4] } else { [0; 4] })
    });
    // Half opaque is ink; just under half is not.
    picture.put_pixel(2, 2, Rgba([255, 255, 255, 128]));
    picture.put_pixel(3, 2, Rgba([0, 0, 0, 127]));
    picture.save(&path).unwrap();
    let mut expected = tree_bitmap();
    expected.set(2, 2);
    assert_eq!(load_target(&path, Threshold::Otsu).unwrap(), expected);
    // The threshold is for pictures without transparency.
    assert_eq!(load_target(&path, Threshold::Level(0.0)).unwrap(), expected);
}

#[test]
fn an_opaque_alpha_channel_falls_back_to_dark_on_light() {
    let path = dir("opaque").join("opaque.png");
    let picture = RgbaImage::from_fn(W, H, |x, y| {
        Rgba(if is_tree(x, y) {
            [0, 0, 0, 255]
        } else {
            [255; 4]
        })
    });
    picture.save(&path).unwrap();
    assert_eq!(load_target(&path, Threshold::Otsu).unwrap(), tree_bitmap());
}

#[test]
fn otsu_tells_a_dark_tree_from_a_bright_sky() {
    // A photo-like picture: a sky brightening towards the horizon, with noise, and a tree of
    // dark, noisy greens and browns. Read from bytes already in memory.
    let picture = RgbImage::from_fn(W, H, |x, y| {
        let n = noise(x, y, 24) as u8;
        if is_tree(x, y) {
            Rgb([20 + n, 50 + n, 15 + n / 2])
        } else {
            let up = (y * 60 / H) as u8;
            Rgb([110 + up + n, 160 + up / 2 + n, 230 + n / 2])
        }
    });
    let mut bytes = Vec::new();
    picture
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    let ink = decode_target(Path::new("photo.png"), &bytes, Threshold::Otsu).unwrap();
    assert_eq!(ink, tree_bitmap());
}

#[test]
fn a_higher_level_is_more_ink() {
    // A left-to-right gradient from black to white.
    let path = dir("levels").join("gradient.png");
    GrayImage::from_fn(W, H, |x, _| Luma([(x * 255 / (W - 1)) as u8]))
        .save(&path)
        .unwrap();
    let total = f64::from(W * H);
    let dark = load_target(&path, Threshold::Level(0.2)).unwrap().ink() as f64 / total;
    let light = load_target(&path, Threshold::Level(0.8)).unwrap().ink() as f64 / total;
    assert!(dark < light, "{dark} {light}");
    assert!((dark - 0.2).abs() < 0.05, "{dark}");
    assert!((light - 0.8).abs() < 0.05, "{light}");
    // The ends: nothing is darker than black, everything but white is darker than white.
    assert_eq!(load_target(&path, Threshold::Level(0.0)).unwrap().ink(), 0);
    let all_but_white = load_target(&path, Threshold::Level(1.0)).unwrap().ink();
    assert_eq!(all_but_white, u64::from((W - 1) * H));
}

#[test]
fn otsu_splits_a_two_peak_histogram_between_its_peaks() {
    let mut histogram = [0u64; 256];
    for (i, n) in [
        (50, 100),
        (55, 400),
        (60, 100),
        (180, 300),
        (190, 900),
        (200, 300),
    ] {
        histogram[i] = n;
    }
    let level = otsu(&histogram) * 255.0;
    assert!(level > 60.0 && level < 180.0, "{level}");
}

#[test]
fn otsu_splits_halfway_across_the_empty_run_between_two_peaks() {
    let mut histogram = [0u64; 256];
    histogram[40] = 300;
    histogram[200] = 700;
    let level = otsu(&histogram) * 255.0;
    assert!((level - 120.0).abs() < 1e-3, "{level}");
    // Adjacent bins are split between them.
    let mut histogram = [0u64; 256];
    histogram[100] = 10;
    histogram[101] = 10;
    let level = otsu(&histogram) * 255.0;
    assert!(level > 100.0 && level < 101.0, "{level}");
}

#[test]
fn otsu_without_a_split_is_the_middle() {
    assert_eq!(otsu(&[0; 256]), 0.5);
    let mut one = [0u64; 256];
    one[17] = 5;
    assert_eq!(otsu(&one), 0.5);
}

#[test]
fn an_empty_file_is_refused() {
    let path = dir("empty").join("empty.png");
    std::fs::write(&path, b"").unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["empty", "not a PNG or JPEG picture"],
    );
}

#[test]
fn text_named_png_is_refused() {
    let path = dir("text").join("notes.png");
    std::fs::write(&path, "a tree, about 3 m tall\n").unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["not a PNG or JPEG picture"],
    );
}

#[test]
fn other_formats_are_refused_by_name() {
    let path = dir("gif").join("tree.gif");
    std::fs::write(&path, b"GIF89a\x10\x00\x10\x00\x00\x00\x00;").unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["not a PNG or JPEG picture", "GIF"],
    );
}

#[test]
fn a_truncated_png_is_refused() {
    let dir = dir("truncated");
    // Noise compresses badly, so most of the file is pixel data.
    let picture = GrayImage::from_fn(W, H, |x, y| Luma([noise(x, y, 256) as u8]));
    let whole = dir.join("whole.png");
    picture.save(&whole).unwrap();
    let bytes = std::fs::read(&whole).unwrap();
    let path = dir.join("truncated.png");
    std::fs::write(&path, &bytes[..bytes.len() * 6 / 10]).unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["the picture is truncated or damaged: "],
    );
}

#[test]
fn a_truncated_jpeg_is_refused() {
    let dir = dir("truncated-jpeg");
    let picture = GrayImage::from_fn(W, H, |x, y| Luma([noise(x, y, 256) as u8]));
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 90)
        .encode_image(&picture)
        .unwrap();
    let path = dir.join("truncated.jpg");
    // Cut inside the headers, before the frame's data.
    std::fs::write(&path, &bytes[..40]).unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["the picture is truncated or damaged: "],
    );
}

#[test]
fn a_picture_too_wide_is_refused_from_its_header() {
    let path = dir("wide").join("wide.png");
    std::fs::write(&path, png_header(100_000, 10, 8, 0)).unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["the picture is 100000 x 10 pixels; pictures up to 8192 x 8192 are read"],
    );
}

#[test]
fn a_jpeg_too_wide_is_refused_from_its_header() {
    let picture = GrayImage::from_fn(9000, 8, |x, _| Luma([(x % 256) as u8]));
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 50)
        .encode_image(&picture)
        .unwrap();
    let path = dir("wide-jpeg").join("wide.jpg");
    std::fs::write(&path, bytes).unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &["the picture is 9000 x 8 pixels; pictures up to 8192 x 8192 are read"],
    );
}

#[test]
fn a_decompression_bomb_is_refused_from_its_header() {
    // 8000 x 8000 RGBA at 16 bits a sample: 512 MB decoded, from a file of 70 bytes.
    let path = dir("bomb").join("bomb.png");
    let mut png = png_header(8000, 8000, 16, 6);
    png.extend(chunk(b"IDAT", b"\x78\x9c\x03\x00\x00\x00\x00\x01"));
    png.extend(chunk(b"IEND", b""));
    std::fs::write(&path, png).unwrap();
    assert_refused(
        load_target(&path, Threshold::Otsu),
        &path,
        &[
            "8000 x 8000 pixels",
            "pictures up to 256 MiB decoded are read",
        ],
    );
}

#[test]
fn a_file_too_large_is_refused_before_it_is_read_whole() {
    let path = dir("huge").join("huge.png");
    // Sparse: no disk is used for it.
    let file = std::fs::File::create(&path).unwrap();
    file.set_len(sylva::picture::MAX_FILE + 1).unwrap();
    drop(file);
    assert_refused(load_target(&path, Threshold::Otsu), &path, &["is over"]);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn a_missing_file_keeps_its_io_kind() {
    let path = dir("missing").join("no-such-tree.png");
    let e = load_target(&path, Threshold::Otsu).unwrap_err();
    assert_eq!(e.io, Some(ErrorKind::NotFound), "{e}");
    assert!(e.to_string().contains("no-such-tree.png"), "{e}");
}

#[test]
fn a_level_outside_zero_to_one_is_refused() {
    let path = dir("level").join("tree.png");
    tree_drawing().save(&path).unwrap();
    for level in [f32::NAN, -0.5, 2.0, f32::INFINITY] {
        assert_refused(
            load_target(&path, Threshold::Level(level)),
            &path,
            &["`threshold`", "from 0 to 1"],
        );
    }
}

#[test]
fn pictures_held_in_memory_encode_to_pngs_read_back_exactly() {
    // A mask drawn black on white, as Python's numpy masks are written.
    let grey: Vec<u8> = (0..H)
        .flat_map(|y| (0..W).map(move |x| if is_tree(x, y) { 0 } else { 255 }))
        .collect();
    let png = sylva::picture::encode_png("target", W, H, 1, grey.clone()).unwrap();
    for threshold in [
        Threshold::Otsu,
        Threshold::Level(0.1),
        Threshold::Level(1.0),
    ] {
        let ink = decode_target(Path::new("mask.png"), &png, threshold).unwrap();
        for (x, y) in (0..H).flat_map(|y| (0..W).map(move |x| (x, y))) {
            assert_eq!(ink.get(x, y), is_tree(x, y), "({x}, {y}) {threshold:?}");
        }
    }
    // RGB and RGBA pictures read as their files would be.
    let rgb: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g]).collect();
    let png = sylva::picture::encode_png("target", W, H, 3, rgb).unwrap();
    let ink = decode_target(Path::new("rgb.png"), &png, Threshold::Otsu).unwrap();
    assert!(ink.get(24, 22) && !ink.get(0, 0));
    // Bad shapes are refused naming the picture.
    for (w, h, channels, len) in [(0, 4, 1, 0), (W, H, 2, (W * H * 2) as usize), (W, H, 1, 5)] {
        let e = sylva::picture::encode_png("side", w, h, channels, vec![0; len]).unwrap_err();
        assert_eq!(e.location, "side", "{e}");
    }
}
