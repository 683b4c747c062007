//! The picture of a variety map: one thumbnail per filled cell of a grid, empty cells left
//! empty, the two axes labelled with their descriptors and ranges (the second's name above
//! the grid).
//!
//! The first axis runs left to right, the second bottom to top (a map of one axis is one
//! row). Cells are rendered on a [`Pool`] and pasted in order, so the picture does not
//! depend on the number of threads.
//!
//! ```
//! use sylva_render::map::{MapAxis, MapPicture, map_picture};
//! use sylva_mesh::Scene;
//! use sylva_core::par::Pool;
//!
//! let axis = |name: &str| MapAxis { name: name.into(), min: 0.0, max: 1.0, cells: 2 };
//! let picture = MapPicture {
//!     x: axis("porosity"),
//!     y: Some(axis("lean")),
//!     cell_size: 32,
//!     title: "4 cells".into(),
//!     ..MapPicture::default()
//! };
//! // Cells row by row from the bottom: (x 0, y 0), (x 1, y 0), (x 0, y 1), (x 1, y 1).
//! let cells = vec![Some(Scene::default()), None, None, Some(Scene::default())];
//! let image = map_picture(&cells, &picture, &Pool::Serial)?;
//! assert_eq!(image.width(), picture.size().0);
//! # Ok::<(), sylva_render::RenderError>(())
//! ```

use image::{Rgb, RgbImage};
use sylva_core::par::Pool;
use sylva_mesh::scene::Scene;

use super::text::{GLYPH, draw_text, fit_text, text_width};
use super::{MAX_SIZE, MIN_SIZE, RenderError, RenderOptions, Renderer, View};

/// Margin left of the grid, for the second axis's ticks and name.
const LEFT: u32 = 5 * GLYPH + 14;
/// Margin below the grid, for the first axis's ticks and name.
const BOTTOM: u32 = 3 * GLYPH + 14;
/// Title bar height: double-size text with 6 pixels above and below, then a line for the
/// second axis's name.
const TITLE: u32 = 3 * GLYPH + 18;
/// Margin right of the grid.
const RIGHT: u32 = 12;
/// Most pixels a map picture may have (64 M).
const MAX_PIXELS: u64 = 1 << 26;
/// Page, empty cells, lines and text.
const PAPER: [u8; 3] = [248, 247, 242];
const EMPTY: [u8; 3] = [232, 232, 228];
const RULE: [u8; 3] = [190, 192, 196];
const INK: [u8; 3] = [34, 34, 34];

/// One axis of the map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapAxis {
    /// The descriptor's name.
    pub name: String,
    /// Lower end of its range.
    pub min: f64,
    /// Upper end of its range.
    pub max: f64,
    /// Cells across it.
    pub cells: u32,
}

/// How to draw a map.
#[derive(Clone, Debug, PartialEq)]
pub struct MapPicture {
    /// The axis left to right.
    pub x: MapAxis,
    /// The axis bottom to top; none for a map of one row.
    pub y: Option<MapAxis>,
    /// Side of a cell's thumbnail in pixels, [`MIN_SIZE`] to 512. Default 96.
    pub cell_size: u32,
    /// The view thumbnails are drawn from. Default front.
    pub view: View,
    /// The title across the top.
    pub title: String,
}

impl Default for MapPicture {
    fn default() -> Self {
        MapPicture {
            x: MapAxis {
                name: String::new(),
                min: 0.0,
                max: 1.0,
                cells: 1,
            },
            y: None,
            cell_size: 96,
            view: View::Front,
            title: String::new(),
        }
    }
}

impl MapPicture {
    fn rows(&self) -> u32 {
        self.y.as_ref().map_or(1, |y| y.cells)
    }

    /// The picture's width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        let c = self.cell_size;
        (
            LEFT + self.x.cells.saturating_mul(c) + RIGHT,
            TITLE + self.rows().saturating_mul(c) + BOTTOM,
        )
    }
}

/// Draws the map: `cells` holds one entry per cell, row by row from the bottom
/// (`x + y * x.cells`), a scene for a filled cell and `None` for an empty one.
pub fn map_picture(
    cells: &[Option<Scene>],
    picture: &MapPicture,
    pool: &Pool,
) -> Result<RgbImage, RenderError> {
    let c = picture.cell_size;
    if !(MIN_SIZE..=512).contains(&c) {
        return Err(RenderError::InvalidSize {
            width: c,
            height: c,
        });
    }
    let (columns, rows) = (picture.x.cells, picture.rows());
    let (width, height) = picture.size();
    if u64::from(width) * u64::from(height) > MAX_PIXELS
        || width > MAX_SIZE * 4
        || cells.len() != (columns as usize) * (rows as usize)
    {
        return Err(RenderError::SheetTooLarge {
            width: u64::from(width),
            height: u64::from(height),
            max: MAX_PIXELS,
        });
    }
    let options = RenderOptions {
        width: c,
        height: c,
        view: picture.view,
        supersample: 2,
        ..RenderOptions::default()
    };
    let filled: Vec<usize> = (0..cells.len()).filter(|&i| cells[i].is_some()).collect();
    let thumbnails: Vec<Result<RgbImage, RenderError>> =
        pool.map_init(filled.len(), Renderer::new, |r, k| {
            let scene = cells[filled[k]].as_ref().expect("filled cells have scenes");
            r.render(scene, &options)
        });

    let mut image = RgbImage::from_pixel(width, height, Rgb(PAPER));
    // Double size if the whole title fits so, else single size in the same bar.
    let room = width.saturating_sub(12);
    let scale = if text_width(&picture.title, 2) <= room {
        2
    } else {
        1
    };
    let title = fit_text(&picture.title, room, scale);
    draw_text(
        &mut image,
        6,
        6 + (2 - scale) * GLYPH / 2,
        &title,
        scale,
        INK,
    );
    let origin = |x: u32, y: u32| (LEFT + x * c, TITLE + (rows - 1 - y) * c);
    for y in 0..rows {
        for x in 0..columns {
            let (x0, y0) = origin(x, y);
            fill(&mut image, x0, y0, c, c, EMPTY);
        }
    }
    for (k, thumbnail) in thumbnails.into_iter().enumerate() {
        let cell = filled[k] as u32;
        let (x0, y0) = origin(cell % columns, cell / columns);
        image::imageops::replace(&mut image, &thumbnail?, i64::from(x0), i64::from(y0));
    }
    // Lines between cells, on top of the thumbnails' edges.
    let (grid_right, grid_bottom) = (LEFT + columns * c, TITLE + rows * c);
    for x in 0..=columns {
        fill(&mut image, LEFT + x * c, TITLE, 1, rows * c, RULE);
    }
    for y in 0..=rows {
        fill(&mut image, LEFT, TITLE + y * c, columns * c + 1, 1, RULE);
    }
    // The first axis: its range's ends under the grid's ends, its name between.
    let below = grid_bottom + 4;
    let x = &picture.x;
    draw_text(&mut image, LEFT, below, &number(x.min), 1, INK);
    let high = number(x.max);
    let high_x = grid_right.saturating_sub(text_width(&high, 1));
    draw_text(&mut image, high_x, below, &high, 1, INK);
    let name = fit_text(&format!("{} ->", x.name), columns * c, 1);
    let name_x = LEFT + (columns * c).saturating_sub(text_width(&name, 1)) / 2;
    draw_text(&mut image, name_x, below + GLYPH + 6, &name, 1, INK);
    // The second axis: its ends by the grid's bottom and top, its name at the top left.
    if let Some(y) = &picture.y {
        let low = number(y.min);
        let right_aligned = |t: &str| (LEFT - 4).saturating_sub(text_width(t, 1));
        draw_text(
            &mut image,
            right_aligned(&low),
            grid_bottom - GLYPH,
            &low,
            1,
            INK,
        );
        let high = number(y.max);
        draw_text(&mut image, right_aligned(&high), TITLE, &high, 1, INK);
        let name = fit_text(&format!("^ {}", y.name), columns * c, 1);
        draw_text(&mut image, LEFT, TITLE - GLYPH - 4, &name, 1, INK);
    }
    Ok(image)
}

/// A tick label: a short number.
fn number(v: f64) -> String {
    let text = format!("{v:.2}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text.is_empty() || text == "-" {
        "0".to_owned()
    } else {
        text.to_owned()
    }
}

/// Fills a rectangle, clipped to the image.
fn fill(image: &mut RgbImage, x0: u32, y0: u32, w: u32, h: u32, rgb: [u8; 3]) {
    for y in y0..(y0 + h).min(image.height()) {
        for x in x0..(x0 + w).min(image.width()) {
            image.put_pixel(x, y, Rgb(rgb));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_cells_stay_empty_and_filled_cells_are_drawn() {
        let axis = |cells| MapAxis {
            name: "a".into(),
            min: 0.0,
            max: 2.5,
            cells,
        };
        let picture = MapPicture {
            x: axis(3),
            y: Some(axis(2)),
            cell_size: 32,
            title: "map".into(),
            ..MapPicture::default()
        };
        let mut cells = vec![None; 6];
        // Bottom right: x 2, y 0.
        cells[2] = Some(Scene::default());
        let image = map_picture(&cells, &picture, &Pool::Serial).unwrap();
        assert_eq!(image.dimensions(), picture.size());
        let centre = |x: u32, y: u32| {
            let (x0, y0) = (LEFT + x * 32 + 16, TITLE + (1 - y) * 32 + 16);
            image.get_pixel(x0, y0).0
        };
        assert_eq!(centre(0, 0), EMPTY);
        assert_eq!(centre(2, 1), EMPTY);
        // An empty scene renders as background: not the empty cells' grey.
        assert_ne!(centre(2, 0), EMPTY);
        assert_eq!(number(2.5), "2.5");
        assert_eq!(number(10.0), "10");
        assert_eq!(number(0.0), "0");
        let wrong = map_picture(&cells[..5], &picture, &Pool::Serial);
        assert!(wrong.is_err());
    }
}
