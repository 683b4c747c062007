//! Contact sheets: many small captioned renders in a grid, for comparing a population.
//!
//! Cells are rendered on a [`Pool`] (each worker keeps one [`Renderer`]) and pasted in
//! order, so the sheet is byte-identical to rendering the cells one by one.
//!
//! ```
//! use sylva_render::{SheetCell, SheetOptions, contact_sheet};
//! use sylva_mesh::Scene;
//! use sylva_core::par::Pool;
//!
//! let cells: Vec<SheetCell> = (0..5)
//!     .map(|i| SheetCell { scene: Scene::default(), caption: format!("#{i}  fit 0.00") })
//!     .collect();
//! let options = SheetOptions { cell_width: 64, cell_height: 80, ..Default::default() };
//! let sheet = contact_sheet(&cells, &options, &Pool::Serial)?;
//! assert_eq!(sheet.dimensions(), (3 * 64, 2 * 80)); // 5 cells: 3 columns, 2 rows
//! # Ok::<(), sylva_render::RenderError>(())
//! ```

use image::{Rgb, RgbImage};
use sylva_core::par::Pool;
use sylva_mesh::scene::Scene;

use super::text::{GLYPH, draw_text, fit_text, text_width};
use super::{MAX_SIZE, MIN_SIZE, RenderError, RenderOptions, Renderer, View};

/// Height of the caption strip under each picture: an 8-pixel line with 4 pixels above and
/// below.
pub const CAPTION_HEIGHT: u32 = GLYPH + 8;
/// Height of the title bar: text at twice the size with 6 pixels above and below.
const TITLE_HEIGHT: u32 = 2 * GLYPH + 12;
/// Most pixels a sheet may have (64 M, 192 MB of RGB).
const MAX_SHEET_PIXELS: u64 = 1 << 26;
/// Caption strip and title bar colour.
const PAPER: [u8; 3] = [248, 247, 242];
/// Text colour.
const INK: [u8; 3] = [34, 34, 34];
/// Lines between cells.
const RULE: [u8; 3] = [190, 192, 196];

/// One picture of a contact sheet.
#[derive(Clone, Debug)]
pub struct SheetCell<'a> {
    /// What to draw.
    pub scene: Scene<'a>,
    /// One line under the picture, e.g. `"#12  fit 3.41"`; cut with `..` when too long.
    pub caption: String,
}

/// How to lay out a contact sheet.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SheetOptions {
    /// Cells per row; 0 chooses a near-square grid (the smallest `c` with `c * c >= n`).
    /// Default 0.
    pub columns: u32,
    /// Cell width in pixels, [`MIN_SIZE`]`..=`[`MAX_SIZE`]. Default 240.
    pub cell_width: u32,
    /// Cell height in pixels including the caption strip ([`CAPTION_HEIGHT`]), so at least
    /// `MIN_SIZE + CAPTION_HEIGHT`. Default 260.
    pub cell_height: u32,
    /// The view every cell is drawn from. Default [`View::Iso`].
    pub view: View,
    /// A title bar across the top, in double-size text. Default none.
    pub title: Option<String>,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            columns: 0,
            cell_width: 240,
            cell_height: 260,
            view: View::Iso,
            title: None,
        }
    }
}

/// Renders every cell with the default [`RenderOptions`] (ground, shadows, 2x supersampling)
/// and lays them out row by row, each with its caption underneath.
pub fn contact_sheet(
    cells: &[SheetCell],
    options: &SheetOptions,
    pool: &Pool,
) -> Result<RgbImage, RenderError> {
    if cells.is_empty() {
        return Err(RenderError::EmptySheet);
    }
    let (cw, ch) = (options.cell_width, options.cell_height);
    let min_height = MIN_SIZE + CAPTION_HEIGHT;
    if !(MIN_SIZE..=MAX_SIZE).contains(&cw) || !(min_height..=MAX_SIZE).contains(&ch) {
        return Err(RenderError::InvalidCell {
            width: cw,
            height: ch,
            min_height,
        });
    }
    let n = cells.len() as u64;
    let columns = match u64::from(options.columns) {
        0 => (1..).find(|c| c * c >= n).unwrap_or(1),
        c => c,
    }
    .min(n);
    let rows = n.div_ceil(columns);
    let title_height = if options.title.is_some() {
        TITLE_HEIGHT
    } else {
        0
    };
    let width = columns * u64::from(cw);
    let height = u64::from(title_height) + rows * u64::from(ch);
    let too_large = RenderError::SheetTooLarge {
        width,
        height,
        max: MAX_SHEET_PIXELS,
    };
    if width.saturating_mul(height) > MAX_SHEET_PIXELS {
        return Err(too_large);
    }
    let (Ok(width), Ok(height)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(too_large);
    };

    let picture = RenderOptions {
        width: cw,
        height: ch - CAPTION_HEIGHT,
        view: options.view,
        ..RenderOptions::default()
    };
    let pictures: Vec<Result<RgbImage, RenderError>> =
        pool.map_init(cells.len(), Renderer::new, |r, i| {
            r.render(&cells[i].scene, &picture)
        });

    let mut sheet = RgbImage::from_pixel(width, height, Rgb(PAPER));
    if let Some(title) = &options.title {
        let text = fit_text(title, width.saturating_sub(12), 2);
        draw_text(&mut sheet, 6, 6, &text, 2, INK);
    }
    let columns = columns as u32;
    for (k, pic) in pictures.into_iter().enumerate() {
        let pic = pic?;
        let k = k as u32;
        let (x0, y0) = ((k % columns) * cw, title_height + (k / columns) * ch);
        image::imageops::replace(&mut sheet, &pic, i64::from(x0), i64::from(y0));
        let caption = fit_text(&cells[k as usize].caption, cw.saturating_sub(8), 1);
        let tx = x0 + (cw - text_width(&caption, 1)) / 2;
        draw_text(&mut sheet, tx, y0 + picture.height + 4, &caption, 1, INK);
    }
    // Hairlines between cells, drawn last so they sit on top of the pictures' edges.
    for c in 1..columns {
        for y in title_height..height {
            sheet.put_pixel(c * cw, y, Rgb(RULE));
        }
    }
    for r in 0..rows as u32 {
        let y = title_height + r * ch;
        if y > 0 {
            for x in 0..width {
                sheet.put_pixel(x, y, Rgb(RULE));
            }
        }
    }
    Ok(sheet)
}
