//! The outline term: how well a plant's silhouette, seen from the front or the side,
//! overlaps a target outline (a designer's picture), as intersection over union.
//!
//! Both outlines are normalised before they are compared, so the term asks for a shape, not
//! a size or a place: each is cropped to the bounding box of its ink, scaled so that box is
//! [`Outline::rows`] pixels tall with its aspect kept, stood on the bottom row and centred
//! horizontally on a canvas [`CANVAS_ASPECT`] times as wide as it is tall.
//!
//! A plant is drawn straight into that canvas, without the renderer: each stem segment of
//! the shoot is a tapered band (a quadrilateral), each leaf and flower its blade's
//! quadrilateral, filled by scanlines into a bitmap of 64-bit words; roots (root material
//! and root tips) are left out, and so is whatever else lies below the ground (y = 0).
//!
//! The term of a run, [`Outline::score`], is the IoU times [`plausibility`]: a plant
//! whose trunk has grown as wide as the crown it should carry does not pass for a tree.
//! Intersection and union are popcounts over the words. Once a [`Scratch`] is warm, scoring
//! allocates nothing.
//!
//! [`prune`] grows a plant inside outlines instead, as a topiary is clipped: what would
//! show outside their ink is cut, its leaves exactly where they meet the sky, into pieces
//! an asset carries. A match scores its plants so by default with [`score_pruned`], which
//! draws the leaves clipped pixel by pixel instead of making the pieces.

use sylva_core::Plant;
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::plant::{MaterialKind, Organ, OrganKind, Segment, SegmentId};

/// How much wider than tall the comparison canvas is: outlines up to this aspect are
/// compared whole (a target wider than this is refused as not plant-like).
pub const CANVAS_ASPECT: u32 = 3;

/// A picture of one bit per pixel: ink or not. Rows run top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bitmap {
    width: u32,
    height: u32,
    words_per_row: usize,
    words: Vec<u64>,
}

impl Bitmap {
    /// An empty (inkless) bitmap.
    pub fn new(width: u32, height: u32) -> Bitmap {
        let words_per_row = (width as usize).div_ceil(64);
        Bitmap {
            width,
            height,
            words_per_row,
            words: vec![0; words_per_row * height as usize],
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Whether pixel (`x`, `y`) is ink; pixels outside are not.
    pub fn get(&self, x: u32, y: u32) -> bool {
        x < self.width
            && y < self.height
            && self.words[y as usize * self.words_per_row + x as usize / 64] >> (x % 64) & 1 == 1
    }

    /// Inks pixel (`x`, `y`); pixels outside are ignored.
    pub fn set(&mut self, x: u32, y: u32) {
        if x < self.width && y < self.height {
            self.words[y as usize * self.words_per_row + x as usize / 64] |= 1 << (x % 64);
        }
    }

    /// Inks pixels `x0..x1` of row `y` (clipped to the bitmap).
    pub fn fill_span(&mut self, y: u32, x0: u32, x1: u32) {
        for (at, bits) in self.span_words(y, x0, x1) {
            self.words[at] |= bits;
        }
    }

    /// Inks the pixels of `x0..x1` of row `y` that `mask` inks (a bitmap of the same size).
    pub(crate) fn fill_span_masked(&mut self, y: u32, x0: u32, x1: u32, mask: &Bitmap) {
        for (at, bits) in self.span_words(y, x0, x1) {
            self.words[at] |= bits & mask.words.get(at).copied().unwrap_or(0);
        }
    }

    /// Inks, of the pixels of `x0..x1` in row `y` not inked yet (and inked in `mask`, a
    /// bitmap of the same size, if given), those `ink` picks: it is given them a word at a
    /// time, as the `x` of the word's first pixel and a bit each, and returns the bits to ink.
    pub(crate) fn ink_open(
        &mut self,
        y: u32,
        x0: u32,
        x1: u32,
        mask: Option<&Bitmap>,
        mut ink: impl FnMut(u32, u64) -> u64,
    ) {
        let first = (y as usize * self.words_per_row) as u32;
        for (at, bits) in self.span_words(y, x0, x1) {
            let mut open = bits & !self.words[at];
            if let Some(mask) = mask {
                open &= mask.words.get(at).copied().unwrap_or(0);
            }
            if open != 0 {
                self.words[at] |= ink((at as u32 - first) * 64, open) & open;
            }
        }
    }

    /// The words pixels `x0..x1` of row `y` (clipped to the bitmap) lie in, each with the
    /// bits of those pixels: (index into the words, bits).
    fn span_words(&self, y: u32, x0: u32, x1: u32) -> impl Iterator<Item = (usize, u64)> + use<> {
        let x1 = x1.min(self.width);
        let (at, first, last) = if y >= self.height || x0 >= x1 {
            (0, 1, 0)
        } else {
            (
                y as usize * self.words_per_row,
                x0 as usize / 64,
                (x1 as usize - 1) / 64,
            )
        };
        (first..=last).map(move |i| {
            let lo = if i == first { x0 % 64 } else { 0 };
            let hi = if i == last { (x1 - 1) % 64 + 1 } else { 64 };
            let bits = if hi - lo == 64 {
                u64::MAX
            } else {
                ((1u64 << (hi - lo)) - 1) << lo
            };
            (at + i, bits)
        })
    }

    /// The words of row `y`: pixel `x` is bit `x % 64` of word `x / 64`.
    pub(crate) fn row(&self, y: u32) -> &[u64] {
        &self.words[y as usize * self.words_per_row..][..self.words_per_row]
    }

    /// Clears every pixel, keeping the size.
    pub fn clear(&mut self) {
        self.words.fill(0);
    }

    /// Pixels of ink.
    pub fn ink(&self) -> u64 {
        self.words.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// The smallest box holding every pixel of ink, as `(x0, y0, x1, y1)` (ends exclusive);
    /// `None` for a bitmap without ink.
    pub fn ink_bounds(&self) -> Option<(u32, u32, u32, u32)> {
        let mut bounds: Option<(u32, u32, u32, u32)> = None;
        for y in 0..self.height {
            let row = &self.words[y as usize * self.words_per_row..][..self.words_per_row];
            let Some(first) = row.iter().position(|&w| w != 0) else {
                continue;
            };
            let last = row.iter().rposition(|&w| w != 0).unwrap_or(first);
            let x0 = first as u32 * 64 + row[first].trailing_zeros();
            let x1 = last as u32 * 64 + 64 - row[last].leading_zeros();
            bounds = Some(match bounds {
                None => (x0, y, x1, y + 1),
                Some((a, b, c, _)) => (a.min(x0), b, c.max(x1), y + 1),
            });
        }
        bounds
    }

    /// Intersection over union with `other` (of the same size): 1 for equal bitmaps, 0 for
    /// disjoint ones, and 0 when neither has ink.
    pub fn iou(&self, other: &Bitmap) -> f64 {
        debug_assert_eq!((self.width, self.height), (other.width, other.height));
        let (mut both, mut either) = (0u64, 0u64);
        for (a, b) in self.words.iter().zip(&other.words) {
            both += u64::from((a & b).count_ones());
            either += u64::from((a | b).count_ones());
        }
        if either == 0 {
            0.0
        } else {
            both as f64 / either as f64
        }
    }
}

/// Which way the plant is seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Side {
    /// Looking along -Z: +X to the right, +Y up.
    #[default]
    Front,
    /// Looking along +X: +Z to the right, +Y up.
    Side,
}

impl Side {
    /// Where a point lands in the picture plane: (right, up).
    #[inline]
    fn project(self, p: Vec3) -> Vec2 {
        match self {
            Side::Front => Vec2::new(p.x, p.y),
            Side::Side => Vec2::new(p.z, p.y),
        }
    }
}

/// Why an outline cannot be a target.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OutlineError {
    /// No pixel is ink.
    #[error("the picture has no ink: every pixel is background")]
    Empty,
    /// Every pixel is ink.
    #[error("the picture is ink from edge to edge: no background to tell the outline from")]
    Full,
    /// The ink is too small to be an outline.
    #[error(
        "the outline is {width} x {height} pixels; a target needs at least {min} pixels each way"
    )]
    TooSmall {
        /// Ink width.
        width: u32,
        /// Ink height.
        height: u32,
        /// The least of each.
        min: u32,
    },
    /// The ink is much wider than tall.
    #[error(
        "the outline is {width} x {height} pixels, more than {CANVAS_ASPECT} times as wide as \
         tall: not a plant's outline"
    )]
    TooWide {
        /// Ink width.
        width: u32,
        /// Ink height.
        height: u32,
    },
}

/// The least width and height, in pixels, of a target's ink.
pub const MIN_INK: u32 = 8;

/// A target outline, normalised for comparison at one resolution, and the view it is
/// seen from.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    side: Side,
    normalised: Bitmap,
    /// Each canvas pixel's chamfer distance to the outline's nearest ink
    /// ([`distance_transform`]).
    distance: Vec<u16>,
    /// The column (in pixels from the canvas's left edge) of the middle of the ink's bottom
    /// row: where the plant's foot stands when it is pruned to the outline ([`prune`]).
    foot: f32,
}

impl Outline {
    /// The outline of `picture`'s ink seen from `side`, normalised to `rows` pixels tall
    /// (8 to 1024).
    pub fn new(picture: &Bitmap, side: Side, rows: u32) -> Result<Outline, OutlineError> {
        let rows = rows.clamp(8, 1024);
        let (x0, y0, x1, y1) = picture.ink_bounds().ok_or(OutlineError::Empty)?;
        if picture.ink() == u64::from(picture.width) * u64::from(picture.height) {
            return Err(OutlineError::Full);
        }
        let (width, height) = (x1 - x0, y1 - y0);
        if width < MIN_INK || height < MIN_INK {
            return Err(OutlineError::TooSmall {
                width,
                height,
                min: MIN_INK,
            });
        }
        if width > CANVAS_ASPECT * height {
            return Err(OutlineError::TooWide { width, height });
        }
        // Each canvas pixel is ink when at least half the picture's pixels under it are (the
        // one under its centre, when enlarging).
        let mut normalised = Bitmap::new(rows * CANVAS_ASPECT, rows);
        let scale = f64::from(rows) / f64::from(height);
        let columns = ((f64::from(width) * scale).round() as u32).clamp(1, rows * CANVAS_ASPECT);
        let left = (rows * CANVAS_ASPECT - columns) / 2;
        // The picture's pixels under canvas pixel `c` of a run of `n` over `len` pixels.
        let under = |c: u32, n: u32, len: u32| {
            let from = u64::from(c) * u64::from(len) / u64::from(n);
            let to = (u64::from(c + 1) * u64::from(len)).div_ceil(u64::from(n));
            (from as u32, (to as u32).max(from as u32 + 1).min(len))
        };
        for cy in 0..rows {
            let (py0, py1) = under(cy, rows, height);
            for cx in 0..columns {
                let (px0, px1) = under(cx, columns, width);
                let mut ink = 0u32;
                for py in py0..py1 {
                    for px in px0..px1 {
                        ink += u32::from(picture.get(x0 + px, y0 + py));
                    }
                }
                if 2 * ink >= (py1 - py0) * (px1 - px0) {
                    normalised.set(left + cx, cy);
                }
            }
        }
        let mut distance = Vec::new();
        distance_transform(&normalised, &mut distance);
        // The lowest row with ink (a thin trunk may fall under half of every bottom pixel).
        let foot = (0..rows)
            .rev()
            .find_map(|y| {
                let ink: Vec<u32> = (0..normalised.width())
                    .filter(|&x| normalised.get(x, y))
                    .collect();
                let sum: f32 = ink.iter().map(|&x| x as f32 + 0.5).sum();
                (!ink.is_empty()).then(|| sum / ink.len() as f32)
            })
            .ok_or(OutlineError::Empty)?;
        Ok(Outline {
            side,
            normalised,
            distance,
            foot,
        })
    }

    /// The view the outline is seen from.
    pub fn side(&self) -> Side {
        self.side
    }

    /// Rows of the normalised outline.
    pub fn rows(&self) -> u32 {
        self.normalised.height()
    }

    /// The normalised outline.
    pub fn normalised(&self) -> &Bitmap {
        &self.normalised
    }

    /// The column (pixels from the normalised canvas's left edge) where the ink's foot
    /// stands: the middle of its bottom row.
    pub fn foot(&self) -> f32 {
        self.foot
    }

    /// Intersection over union of `plant`'s normalised silhouette with this outline, 0 to
    /// 1; 0 for a plant with nothing above the ground to see. Draws into `scratch`.
    pub fn iou(&self, plant: &Plant, scratch: &mut Scratch) -> f64 {
        if !draw_normalised(plant, self.side, self.rows(), scratch) {
            return 0.0;
        }
        scratch.canvas.iou(&self.normalised)
    }

    /// The outline term: [`Outline::iou`] times [`plausibility`].
    pub fn score(&self, plant: &Plant, scratch: &mut Scratch) -> f64 {
        self.iou(plant, scratch) * plausibility(plant, scratch)
    }

    /// The outline term with closeness beside the IoU: `(iou + weight * closeness) / (1 +
    /// weight)` times [`plausibility`], drawing the plant once. Weight 0 is
    /// [`Outline::score`].
    pub fn score_with_closeness(&self, plant: &Plant, weight: f64, scratch: &mut Scratch) -> f64 {
        if weight == 0.0 {
            return self.score(plant, scratch);
        }
        if !draw_normalised(plant, self.side, self.rows(), scratch) {
            return 0.0;
        }
        let iou = scratch.canvas.iou(&self.normalised);
        let closeness = self.closeness_of_canvas(scratch);
        (iou + weight * closeness) / (1.0 + weight) * plausibility(plant, scratch)
    }

    /// How near `plant`'s normalised silhouette lies to this outline, 0 to 1: `1 / (1 + 10
    /// d)`, `d` being the mean over the ink of both of the distance to the other's nearest
    /// ink, in shares of the height. Unlike the IoU it keeps rising as a silhouette that
    /// misses the outline moves towards it: a gradient for the search. 0 for a plant with
    /// nothing above the ground to see.
    pub fn closeness(&self, plant: &Plant, scratch: &mut Scratch) -> f64 {
        if !draw_normalised(plant, self.side, self.rows(), scratch) {
            return 0.0;
        }
        self.closeness_of_canvas(scratch)
    }

    fn closeness_of_canvas(&self, scratch: &mut Scratch) -> f64 {
        distance_transform(&scratch.canvas, &mut scratch.distance);
        let canvas = &scratch.canvas;
        let width = canvas.width() as usize;
        let (mut sum, mut count) = (0u64, 0u64);
        for y in 0..canvas.height() {
            for x in 0..canvas.width() {
                let i = y as usize * width + x as usize;
                let (plant, target) = (canvas.get(x, y), self.normalised.get(x, y));
                if plant {
                    sum += u64::from(self.distance[i]);
                }
                if target {
                    sum += u64::from(scratch.distance[i]);
                }
                count += u64::from(plant) + u64::from(target);
            }
        }
        if count == 0 {
            return 0.0;
        }
        // Chamfer units are a third of a pixel.
        let mean = sum as f64 / count as f64 / 3.0 / f64::from(canvas.height());
        1.0 / (1.0 + 10.0 * mean)
    }
}

/// Rows of the outlines a plant is pruned to: fine enough to keep the gaps between a
/// crown's leaf clusters, which the scoring rows ([`Outline::rows`]) may blur.
pub const SPACE_ROWS: u32 = 256;

/// `plant` grown inside `outlines` (one per view), as a topiary is clipped to its form,
/// its leaves cut exactly where they would show over sky: what [`Outline::score_pruned`]
/// scores, made into parts an asset can carry.
///
/// The stems are cut first ([`cut_stems`]); then the outlines are laid where the
/// comparison frames what is left with its leaves clipped ([`lay_clips`]), and each leaf
/// that lies partly over sky there is cut into pieces: a grid of cells no wider than
/// [`CELL_PIXELS`] over its blade (at most [`MAX_CELLS`] a side, and coarser past
/// [`MAX_ORGANS`] pieces), each kept when its middle lies on every outline's ink, the kept
/// cells merged into rectangles. The pieces are leaves of their own, one after another on
/// the leaf's stem.
pub fn prune(outlines: &[Outline], plant: &Plant) -> Plant {
    let mut scratch = Scratch::default();
    let Some(cut) = cut_stems(outlines, plant) else {
        return plant.clone();
    };
    if !lay_clips(outlines, &cut, &mut scratch) {
        return cut;
    }
    // Past MAX_ORGANS pieces, coarser cells; one cell a leaf is never more organs than the
    // plant grew.
    let mut pruned = cut.clone();
    for cells in [CELL_PIXELS, 2.0, 8.0, f32::INFINITY] {
        let mut organs = 0usize;
        pruned = cut.cut_into(
            |_, _| true,
            |o, keep| match o.kind {
                OrganKind::Leaf if cells.is_finite() && organs > MAX_ORGANS => {}
                OrganKind::Leaf => leaf_pieces(o, outlines, &scratch.clips, cells, &mut |piece| {
                    organs += 1;
                    keep(piece);
                }),
                _ => {
                    organs += 1;
                    keep(*o);
                }
            },
        );
        if organs <= MAX_ORGANS {
            break;
        }
    }
    pruned
}

/// Most leaves and flowers [`prune`] cuts a plant's leaves into before it cuts them in
/// coarser cells (2 and 8 pixels, then one a leaf: kept whole when its middle lies on
/// ink).
pub const MAX_ORGANS: usize = 500_000;

/// The outline term of `plant` grown inside `space` ([`prune`]): the mean over `outlines`
/// (the same pictures and views as `space`, compared at their own rows) of the IoU, or of
/// `(iou + closeness * nearness) / (1 + closeness)` ([`Outline::closeness`]), times
/// [`plausibility`]. The plant is not cut into pieces: its leaves are clipped as they are
/// drawn, pixel by pixel, which is what the pieces [`prune`] makes show. Once `scratch`
/// is warm, it allocates only the pruned plant.
pub fn score_pruned(
    space: &[Outline],
    outlines: &[Outline],
    plant: &Plant,
    closeness: f64,
    scratch: &mut Scratch,
) -> f64 {
    let Some(cut) = cut_stems(space, plant) else {
        return 0.0;
    };
    if outlines.is_empty() || !lay_clips(space, &cut, scratch) {
        return 0.0;
    }
    let mut sum = 0.0;
    for (view, outline) in outlines.iter().enumerate() {
        let same = space
            .get(view)
            .is_some_and(|s| s.side == outline.side && s.rows() == outline.rows());
        if same {
            std::mem::swap(&mut scratch.canvas, &mut scratch.views[view]);
        } else {
            let Some(at) = space.iter().position(|s| s.side == outline.side) else {
                return 0.0;
            };
            let (rows, width) = (outline.rows(), outline.normalised.width());
            if scratch.canvas.width() != width || scratch.canvas.height() != rows {
                scratch.canvas = Bitmap::new(width, rows);
            }
            let draw = scratch.draws[at];
            let draw = Frame {
                scale: draw.scale * rows as f32 / space[at].rows() as f32,
                half_width: width as f32 * 0.5,
                ..draw
            };
            let Scratch {
                clips,
                canvas,
                clipping,
                ..
            } = scratch;
            draw_clipped(&cut, at, space, clips, draw, canvas, clipping);
        }
        let iou = scratch.canvas.iou(&outline.normalised);
        sum += if closeness == 0.0 {
            iou
        } else {
            (iou + closeness * outline.closeness_of_canvas(scratch)) / (1.0 + closeness)
        };
        if same {
            std::mem::swap(&mut scratch.canvas, &mut scratch.views[view]);
        }
    }
    sum / outlines.len() as f64 * plausibility(&cut, scratch)
}

/// Most times the outlines are laid again on the pruned plant's own frame.
pub const REFRAMES: u32 = 3;

/// The widest a cell of a clipped leaf may be ([`prune`]), in pixels of the outlines laid
/// at [`SPACE_ROWS`]: fine enough that the pieces' outline is the one scored, pixel for
/// pixel but at the edges.
pub const CELL_PIXELS: f32 = 0.5;

/// Most cells along or across a clipped leaf ([`prune`]): a leaf 32 pixels long is cut in
/// half-pixel cells, a longer one in coarser ones.
pub const MAX_CELLS: u32 = 64;

/// Most tiles of [`MAX_CELLS`] cells along or across a clipped leaf: a leaf 64 pixels long
/// is cut in half-pixel cells, a longer one in coarser ones.
pub const MAX_TILES: u32 = 2;

/// `plant` with the stems cut that show outside `outlines`, each laid over it with its top
/// row at the plant's top ([`laid_height`]), its bottom row on the ground and its foot
/// ([`Outline::new`]) on the plant's foot (x = 0 or z = 0), and then laid again as the
/// comparison frames what is left (up to [`REFRAMES`] times): a stem whose tip lies
/// outside goes with all that grows from it; laid again, stems that carry something stay
/// (a trunk cut there would take the plant) and bare twigs over sky go. Leaves are kept
/// whole when any point of their blade (corners, edge middles, middle) lies inside, to be
/// clipped later; flowers when their middle does. `None` when nothing shows above the
/// ground.
fn cut_stems(outlines: &[Outline], plant: &Plant) -> Option<Plant> {
    let top = laid_height(plant)?;
    let inside = |p: Vec3| p.y <= 0.0 || outlines.iter().all(|o| o.holds(p, top));
    let keep_stem = |_, s: &Segment| !shoot_segment(plant, s.material) || inside(s.end);
    let mut cut = within(plant, keep_stem, &inside);
    let mut quads = Vec::new();
    for _ in 0..REFRAMES {
        let Some(again) = reframed(outlines, &cut, &mut quads) else {
            break;
        };
        let settled =
            again.organs() == cut.organs() && again.segments().len() == cut.segments().len();
        cut = again;
        if settled {
            break;
        }
    }
    Some(cut)
}

/// `cut` with the outlines laid as the comparison frames it ([`Frame::of`]): its leaves and
/// flowers judged again there ([`within`]) and its bare twigs over sky cut; `None` when a
/// view shows nothing of it.
fn reframed(outlines: &[Outline], cut: &Plant, quads: &mut Vec<[Vec2; 4]>) -> Option<Plant> {
    let mut frames = Vec::with_capacity(outlines.len());
    for outline in outlines {
        quads.clear();
        quads.extend(shapes(cut, outline.side));
        frames.push((Frame::of(quads, outline.rows(), false)?, outline));
    }
    let inside = |p: Vec3| {
        p.y <= 0.0
            || frames
                .iter()
                .all(|(frame, o)| o.ink_at(frame.on_canvas(o.side.project(p))))
    };
    // Bare twigs over sky: a shoot's stem whose tip lies outside and that carries no organ
    // and no stem that stays (children come after their parents, so one pass from the end
    // settles it). Stems that carry something stay, for a trunk cut here would take the
    // plant with it.
    let segments = cut.segments();
    let bears = &mut vec![false; segments.len()];
    for o in cut.organs() {
        if let Some(p) = o.parent {
            bears[p.index()] = true;
        }
    }
    for (i, s) in segments.iter().enumerate().rev() {
        if bears[i] || !shoot_segment(cut, s.material) || inside(s.end) {
            bears[i] = true;
            if let Some(p) = s.parent {
                bears[p.index()] = true;
            }
        }
    }
    Some(within(cut, |id, _| bears[id.index()], &inside))
}

/// `plant` cut to the stems `keep_stem` keeps; on them, root tips stay, a leaf stays whole
/// when any point of its blade (corners, edge middles, middle) lies `inside`, and a flower
/// when its middle does.
fn within(
    plant: &Plant,
    keep_stem: impl FnMut(SegmentId, &Segment) -> bool,
    inside: &impl Fn(Vec3) -> bool,
) -> Plant {
    plant.cut_into(keep_stem, |o, keep| {
        let [a, b, c, d] = blade_corners(o);
        let middle = (a + c) * 0.5;
        let kept = match o.kind {
            OrganKind::RootTip => true,
            OrganKind::Flower => inside(middle),
            OrganKind::Leaf => {
                let edges = [(a + b) * 0.5, (b + c) * 0.5, (c + d) * 0.5, (d + a) * 0.5];
                [a, b, c, d, middle].into_iter().chain(edges).any(inside)
            }
        };
        if kept {
            keep(*o);
        }
    })
}

/// Lays `outlines` over `cut` (a plant [`cut_stems`] made) where the comparison frames it
/// with its leaves clipped to them, into `scratch.clips`, and draws it so into
/// `scratch.views` (one canvas per outline), framed as the comparison frames it
/// (`scratch.draws`). They are laid first where the comparison frames the plant whole,
/// then, while the frame of the clipped plant moves by more than [`SETTLED_PIXELS`],
/// where it frames what the clip left (up to [`CLIP_ROUNDS`] times). `false` when a view
/// shows nothing.
fn lay_clips(outlines: &[Outline], cut: &Plant, scratch: &mut Scratch) -> bool {
    let Scratch {
        quads,
        clips,
        draws,
        views,
        lies,
        partial,
        clipping,
        ..
    } = scratch;
    clipping.blades.clear();
    clipping
        .blades
        .extend(cut.organs().iter().map(blade_corners));
    let blades = &clipping.blades;
    clips.clear();
    draws.clear();
    views.resize_with(outlines.len(), || Bitmap::new(0, 0));
    for (outline, canvas) in outlines.iter().zip(views.iter_mut()) {
        quads.clear();
        quads.extend(shapes(cut, outline.side));
        let Some(frame) = Frame::of(quads, outline.rows(), false) else {
            return false;
        };
        clips.push(frame);
        draws.push(frame);
        let (width, rows) = (outline.normalised.width(), outline.rows());
        if canvas.width() != width || canvas.height() != rows {
            *canvas = Bitmap::new(width, rows);
        }
    }
    if outlines.is_empty() {
        return false;
    }
    for round in 0..=CLIP_ROUNDS {
        if round > 0 {
            clips.copy_from_slice(draws);
        }
        // How each leaf lies over the outlines so laid: the same from every view.
        lies.clear();
        lies.extend(
            cut.organs()
                .iter()
                .zip(blades)
                .map(|(o, blade)| match o.kind {
                    OrganKind::RootTip => Lie::Gone,
                    OrganKind::Flower => Lie::Whole,
                    OrganKind::Leaf => match looks(blade, outlines, clips, None) {
                        None => Lie::Gone,
                        Some(0) => Lie::Whole,
                        Some(_) => Lie::Partly,
                    },
                }),
        );
        let mut settled = true;
        for (view, draw) in draws.iter_mut().enumerate() {
            let Some(frame) = clipped_frame(cut, blades, view, outlines, clips, lies, partial)
            else {
                return false;
            };
            settled &= frame.within(draw, SETTLED_PIXELS);
            *draw = frame;
        }
        if settled {
            break;
        }
    }
    for (view, (draw, canvas)) in draws.iter().zip(views.iter_mut()).enumerate() {
        draw_clipped(cut, view, outlines, clips, *draw, canvas, clipping);
    }
    true
}

/// How far (in pixels, at the top and the sides of the plant) the clipped plant's frame
/// may still move when [`lay_clips`] stops laying the outlines again.
pub const SETTLED_PIXELS: f32 = 0.5;

/// Most times [`lay_clips`] lays the outlines again where the comparison frames the
/// clipped plant. Leaves at the edge of a ragged crown may come and go as the frame moves
/// by a fraction of a pixel, so it need not settle.
pub const CLIP_ROUNDS: u32 = 2;

/// How a leaf lies over the outlines laid to clip it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lie {
    /// Over sky in some view (or a root tip, which the outline does not see).
    Gone,
    /// On ink in every view (or a flower, kept whole).
    Whole,
    /// Partly over sky.
    Partly,
}

/// Draws `plant` seen as `outlines[view]` sees it, in frame `draw`, into `canvas`: stems
/// and flowers whole, each leaf pixel where the blade's point under its centre lies on the
/// ink of every outline laid in its frame of `clips`. Blades that lie wholly on an
/// outline's ink skip its look pixel by pixel, and where the view is drawn in the frame its
/// own outline is laid in, its ink masks the spans.
fn draw_clipped(
    plant: &Plant,
    view: usize,
    outlines: &[Outline],
    clips: &[Frame],
    draw: Frame,
    canvas: &mut Bitmap,
    clipping: &mut Clipping,
) {
    let Clipping {
        blades,
        maps,
        partly,
    } = clipping;
    let own = &outlines[view];
    let side = own.side;
    let mask = (clips[view] == draw).then_some(&own.normalised);
    canvas.clear();
    for s in plant
        .segments()
        .iter()
        .filter(|s| shoot_segment(plant, s.material))
    {
        fill_quad(canvas, stem_band(s, side).map(|p| draw.on_canvas(p)));
    }
    // Whole blades first: a pixel they ink needs no look when a leaf partly over sky
    // covers it too.
    partly.clear();
    for (i, (o, corners)) in plant.organs().iter().zip(blades.iter()).enumerate() {
        let checks = match o.kind {
            OrganKind::RootTip => continue,
            OrganKind::Flower => 0,
            OrganKind::Leaf => match looks(corners, outlines, clips, mask.map(|_| view)) {
                Some(checks) => checks,
                None => continue,
            },
        };
        let quad = corners.map(|p| draw.on_canvas(side.project(p)));
        match (checks, mask) {
            (0, Some(mask)) if o.kind == OrganKind::Leaf => {
                fill_quad_spans(canvas, quad, false, |canvas, row, x0, x1| {
                    canvas.fill_span_masked(row, x0, x1, mask)
                })
            }
            (0, _) => fill_blade(canvas, quad),
            _ => partly.push((i as u32, checks)),
        }
    }
    for &(i, checks) in partly.iter() {
        let corners = &blades[i as usize];
        let quad = corners.map(|p| draw.on_canvas(side.project(p)));
        draw_partly(canvas, corners, quad, outlines, clips, checks, mask, maps);
    }
}

/// Draws into `canvas` the pixels of a blade with `corners`, seen at `quad` on it, whose
/// blade point lies below the ground or on the ink of each outline `checks` names (a bit
/// each), laid in its frame of `clips`; only pixels that `mask` inks, if given.
#[allow(clippy::too_many_arguments)] // The pieces of `draw_clipped`'s loop, kept apart.
fn draw_partly(
    canvas: &mut Bitmap,
    corners: &[Vec3; 4],
    quad: [Vec2; 4],
    outlines: &[Outline],
    clips: &[Frame],
    checks: u32,
    mask: Option<&Bitmap>,
    maps: &mut Vec<(usize, CanvasMap)>,
) {
    let Some(on_blade) = BladeMap::new(corners, quad) else {
        // Seen edge on: its middle stands for the blade.
        if inside_clips((corners[0] + corners[2]) * 0.5, outlines, clips, checks) {
            fill_blade(canvas, quad);
        }
        return;
    };
    maps.clear();
    maps.extend(
        (outlines.iter().zip(clips).enumerate())
            .filter(|(w, _)| checks >> w & 1 == 1)
            .map(|(w, (o, clip))| (w, on_blade.on(o, clip))),
    );
    fill_quad_spans(canvas, quad, false, |canvas, row, x0, x1| {
        let y = row as f32 + 0.5;
        canvas.ink_open(row, x0, x1, mask, |base, open| {
            // The pixels from the first open one to the last are looked at as a whole
            // first: most often they lie wholly on the ink or the sky of the other
            // outlines.
            let (first, last) = (open.trailing_zeros(), 63 - open.leading_zeros());
            let ends = [first, last].map(|bit| Vec2::new((base + bit) as f32 + 0.5, y));
            let looks = match run_looks(&ends, &on_blade, maps, outlines) {
                None => return 0,
                Some(0) => return open,
                Some(looks) => looks,
            };
            let mut inked = 0;
            let mut left = open;
            while left != 0 {
                let bit = left.trailing_zeros();
                left &= left - 1;
                let q = Vec2::new((base + bit) as f32 + 0.5, y);
                let on = on_blade.at(q).y <= 0.0
                    || (maps.iter())
                        .filter(|(w, _)| looks >> w & 1 == 1)
                        .all(|(w, map)| outlines[*w].ink_at(map.at(q)));
                inked |= u64::from(on) << bit;
            }
            inked
        });
    });
}

/// Which of the outlines in `maps` (a bit each) must be looked at pixel by pixel along the
/// run of canvas points from `ends[0]` to `ends[1]` of a blade: none when the blade's
/// points there lie below the ground or on the ink of all of them; `None` when they lie
/// above the ground and over one's sky.
fn run_looks(
    ends: &[Vec2; 2],
    on_blade: &BladeMap,
    maps: &[(usize, CanvasMap)],
    outlines: &[Outline],
) -> Option<u32> {
    let [low, high] = ends.map(|q| on_blade.at(q).y);
    if low.max(high) <= 0.0 {
        return Some(0);
    }
    let mut looks = 0;
    for &(w, map) in maps {
        if low.min(high) <= 0.0 {
            looks |= 1 << w;
            continue;
        }
        let [a, b] = ends.map(|q| map.at(q));
        match outlines[w].cover(a.min(b), a.max(b)) {
            Cover::None => return None,
            Cover::All => {}
            Cover::Some => looks |= 1 << w,
        }
    }
    Some(looks)
}

/// Which of `outlines` (laid in `clips`) must be looked at point by point to clip a blade
/// with `corners`, as bits: none where the blade lies wholly on an outline's ink (and
/// never `skip`); `None` when it lies wholly on one's sky, above the ground.
fn looks(
    corners: &[Vec3; 4],
    outlines: &[Outline],
    clips: &[Frame],
    skip: Option<usize>,
) -> Option<u32> {
    let mut checks = 0;
    for (w, (outline, clip)) in outlines.iter().zip(clips).enumerate() {
        if Some(w) == skip {
            continue;
        }
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for &p in corners {
            let q = clip.on_canvas(outline.side.project(p));
            (lo, hi) = (lo.min(q), hi.max(q));
        }
        match outline.cover(lo, hi) {
            Cover::None if corners.iter().all(|p| p.y > 0.0) => return None,
            Cover::All => {}
            _ => checks |= 1 << w,
        }
    }
    Some(checks)
}

/// Whether point `p` lies below the ground or on the ink of each outline that `checks`
/// names (a bit each), laid in its frame of `clips`.
fn inside_clips(p: Vec3, outlines: &[Outline], clips: &[Frame], checks: u32) -> bool {
    p.y <= 0.0
        || (outlines.iter().zip(clips).enumerate())
            .filter(|(w, _)| checks >> w & 1 == 1)
            .all(|(_, (o, clip))| o.ink_at(clip.on_canvas(o.side.project(p))))
}

/// From a point of a blade's quadrilateral in a picture back to the blade's point under
/// it: the blade is flat, so the map is affine.
struct BladeMap {
    /// The blade's plane's point seen at the canvas's corner.
    at: Vec3,
    /// The blade's point's steps per pixel right and down.
    right: Vec3,
    down: Vec3,
}

impl BladeMap {
    /// `None` when the blade is seen edge on.
    fn new(corners: &[Vec3; 4], quad: [Vec2; 4]) -> Option<BladeMap> {
        let (along, across) = (quad[1] - quad[0], quad[3] - quad[0]);
        let det = along.perp_dot(across);
        if det.abs() < 1e-9 {
            return None;
        }
        // The blade's coordinates along and across, s and t, change per pixel by these.
        let (ds, dt) = (
            Vec2::new(across.y, -across.x) / det,
            Vec2::new(-along.y, along.x) / det,
        );
        let (along3, across3) = (corners[1] - corners[0], corners[3] - corners[0]);
        let (right, down) = (
            along3 * ds.x + across3 * dt.x,
            along3 * ds.y + across3 * dt.y,
        );
        Some(BladeMap {
            at: corners[0] - right * quad[0].x - down * quad[0].y,
            right,
            down,
        })
    }

    /// The blade's point seen at `q`.
    #[inline]
    fn at(&self, q: Vec2) -> Vec3 {
        self.at + self.right * q.x + self.down * q.y
    }

    /// Where the blade's point seen at a canvas point lands on `outline`'s canvas laid in
    /// `clip`.
    fn on(&self, outline: &Outline, clip: &Frame) -> CanvasMap {
        let side = outline.side;
        let step = |v: Vec3| {
            let v = side.project(v);
            Vec2::new(v.x, -v.y) * clip.scale
        };
        CanvasMap {
            at: clip.on_canvas(side.project(self.at)),
            right: step(self.right),
            down: step(self.down),
        }
    }
}

/// An affine map between canvas points.
#[derive(Clone, Copy, Debug)]
struct CanvasMap {
    at: Vec2,
    right: Vec2,
    down: Vec2,
}

impl CanvasMap {
    #[inline]
    fn at(&self, q: Vec2) -> Vec2 {
        self.at + self.right * q.x + self.down * q.y
    }
}

/// How a leaf lies over outlines laid in their frames ([`clip_leaf`]).
// Returned by value, one leaf at a time: boxing its cells would allocate for every leaf.
#[allow(clippy::large_enum_variant)]
enum LeafClip {
    /// Wholly over one outline's sky.
    Gone,
    /// Wholly on every outline's ink.
    Whole,
    /// Partly over sky: the cells of a grid over its blade that lie on ink.
    Cells(Cells),
}

/// A grid of cells over a leaf's blade, those on ink marked: `rows[j]` holds a bit per
/// cell along the blade, row `j` counted across it from its corner `a` of
/// [`blade_corners`].
struct Cells {
    along: u32,
    across: u32,
    rows: [u64; MAX_CELLS as usize],
}

impl Cells {
    /// The corners of the box of cells `i0..i1` along and `j0..j1` across leaf `o`.
    fn corners(o: &Organ, (i0, i1): (u32, u32), (j0, j1): (u32, u32), cells: &Cells) -> [Vec3; 4] {
        let [a, b, _, d] = blade_corners(o);
        let (tip, width) = (b - a, d - a);
        let at = |i: u32, j: u32| {
            a + tip * (i as f32 / cells.along as f32) + width * (j as f32 / cells.across as f32)
        };
        [at(i0, j0), at(i1, j0), at(i1, j1), at(i0, j1)]
    }
}

/// How leaf `o` lies over `outlines` laid in `clips` ([`prune`]): a cell is no wider than
/// [`CELL_PIXELS`] in any of them (at most [`MAX_CELLS`] a side) and on ink when its
/// middle lies on every outline's ink (or below the ground; a cell across the ground is
/// judged halfway up what shows of it).
fn clip_leaf(o: &Organ, outlines: &[Outline], clips: &[Frame], cell_pixels: f32) -> LeafClip {
    clip_leaf_where(o, outlines, clips, cell_pixels, |_| true)
}

/// [`clip_leaf`], looking only at the cells whose corners `wanted` holds for (the others
/// left off).
fn clip_leaf_where(
    o: &Organ,
    outlines: &[Outline],
    clips: &[Frame],
    cell_pixels: f32,
    wanted: impl Fn(&[Vec3; 4]) -> bool,
) -> LeafClip {
    let corners = blade_corners(o);
    let mut whole = true;
    let mut cells = [1u32; 2];
    for (outline, clip) in outlines.iter().zip(clips) {
        let on = corners.map(|p| clip.on_canvas(outline.side.project(p)));
        let (lo, hi) = on.iter().fold(
            (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
            |(lo, hi), &q| (lo.min(q), hi.max(q)),
        );
        match outline.cover(lo, hi) {
            Cover::None if corners.iter().all(|p| p.y > 0.0) => return LeafClip::Gone,
            Cover::All => {}
            _ => whole = false,
        }
        for (n, edge) in cells.iter_mut().zip([on[1] - on[0], on[3] - on[0]]) {
            let wanted = (edge.length() / cell_pixels)
                .ceil()
                .clamp(1.0, MAX_CELLS as f32);
            *n = (*n).max(wanted as u32);
        }
    }
    if whole {
        return LeafClip::Whole;
    }
    let [along, across] = cells;
    let (a, tip, width) = (corners[0], corners[1] - corners[0], corners[3] - corners[0]);
    // How far above its middle a cell reaches.
    let reach = 0.5 * (tip.y.abs() / along as f32 + width.y.abs() / across as f32);
    let mut rows = [0u64; MAX_CELLS as usize];
    let (step_along, step_across) = (tip / along as f32, width / across as f32);
    let middle =
        |i: u32, j: u32| a + step_along * (i as f32 + 0.5) + step_across * (j as f32 + 0.5);
    // The cells are looked at in blocks of up to 8 by 8. A block `wanted` does not hold
    // for is passed over (the callers' tests hold for a box when they hold for a cell in
    // it); so is one whose middles all lie above the ground over an outline's sky, and one
    // whose middles all lie on every outline's ink is kept whole.
    for j0 in (0..across).step_by(8) {
        for i0 in (0..along).step_by(8) {
            let (n, m) = (8.min(along - i0), 8.min(across - j0));
            let corner = a + step_along * i0 as f32 + step_across * j0 as f32;
            let (far_along, far_across) = (step_along * n as f32, step_across * m as f32);
            if !wanted(&[
                corner,
                corner + far_along,
                corner + far_along + far_across,
                corner + far_across,
            ]) {
                continue;
            }
            let middles = [(0, 0), (n - 1, 0), (n - 1, m - 1), (0, m - 1)]
                .map(|(i, j)| middle(i0 + i, j0 + j));
            let bits = (u64::MAX >> (64 - n)) << i0;
            let keep_all = |rows: &mut [u64; MAX_CELLS as usize]| {
                rows[j0 as usize..(j0 + m) as usize]
                    .iter_mut()
                    .for_each(|r| *r |= bits);
            };
            if middles.iter().all(|p| p.y + reach <= 0.0) {
                // Below the ground, where the outline does not look.
                keep_all(&mut rows);
                continue;
            }
            if middles.iter().all(|p| p.y > 0.0) {
                match block_cover(&middles, outlines, clips) {
                    Cover::None => continue,
                    Cover::All => {
                        keep_all(&mut rows);
                        continue;
                    }
                    Cover::Some => {}
                }
            }
            for j in j0..j0 + m {
                for i in i0..i0 + n {
                    let mut p = middle(i, j);
                    if p.y <= 0.0 && p.y + reach > 0.0 {
                        p.y = (p.y + reach) * 0.5;
                    }
                    if inside_clips(p, outlines, clips, u32::MAX) {
                        rows[j as usize] |= 1 << i;
                    }
                }
            }
        }
    }
    LeafClip::Cells(Cells {
        along,
        across,
        rows,
    })
}

/// How the points with corners `points` (a flat quadrilateral's) lie over `outlines` laid
/// in `clips`: on the sky of one, on the ink of all, or some of each.
fn block_cover(points: &[Vec3; 4], outlines: &[Outline], clips: &[Frame]) -> Cover {
    let mut all = true;
    for (outline, clip) in outlines.iter().zip(clips) {
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for &p in points {
            let q = clip.on_canvas(outline.side.project(p));
            (lo, hi) = (lo.min(q), hi.max(q));
        }
        match outline.cover(lo, hi) {
            Cover::None => return Cover::None,
            Cover::All => {}
            Cover::Some => all = false,
        }
    }
    if all { Cover::All } else { Cover::Some }
}

/// Passes to `keep` what of leaf `o` lies on the ink of every outline laid in its frame
/// ([`clip_leaf`]): the whole leaf, nothing, or its cells on ink merged into rectangles,
/// each run of a row carried down the rows that hold all of it.
fn leaf_pieces(
    o: &Organ,
    outlines: &[Outline],
    clips: &[Frame],
    cell_pixels: f32,
    keep: &mut dyn FnMut(Organ),
) {
    match looks(&blade_corners(o), outlines, clips, None) {
        None => {}
        Some(0) => keep(*o),
        Some(_) => tiles(o, outlines, clips, cell_pixels, |tile| {
            tile_pieces(tile, outlines, clips, cell_pixels, keep)
        }),
    }
}

/// Calls `f` with each tile of leaf `o`: the leaf cut into as few equal tiles as keep
/// each within [`MAX_CELLS`] cells a side of at most `cell_pixels` in every view, and at
/// most [`MAX_TILES`] a side.
fn tiles(
    o: &Organ,
    outlines: &[Outline],
    clips: &[Frame],
    cell_pixels: f32,
    mut f: impl FnMut(&Organ),
) {
    let corners = blade_corners(o);
    let mut cells = [1.0f32; 2];
    for (outline, clip) in outlines.iter().zip(clips) {
        let on = corners.map(|p| clip.on_canvas(outline.side.project(p)));
        for (n, edge) in cells.iter_mut().zip([on[1] - on[0], on[3] - on[0]]) {
            *n = n.max((edge.length() / cell_pixels).ceil());
        }
    }
    // At most MAX_TILES a side: a leaf longer than that many tiles of MAX_CELLS cells is
    // cut in coarser cells, so a random plant's giant leaves cost a bounded look.
    let [along, across] =
        cells.map(|n| (n / MAX_CELLS as f32).ceil().clamp(1.0, MAX_TILES as f32) as u32);
    if along == 1 && across == 1 {
        return f(o);
    }
    let size = Vec2::new(o.size.x / along as f32, o.size.y / across as f32);
    let (x, y) = (o.orientation * Vec3::X, o.orientation * Vec3::Y);
    for i in 0..along {
        for j in 0..across {
            let offset = y * (size.x * i as f32) + x * ((j as f32 + 0.5) * size.y - 0.5 * o.size.y);
            f(&Organ {
                position: o.position + offset,
                size,
                ..*o
            });
        }
    }
}

/// Passes to `keep` what of `tile` (a leaf or a tile of one) lies on ink ([`clip_leaf`]).
fn tile_pieces(
    o: &Organ,
    outlines: &[Outline],
    clips: &[Frame],
    cell_pixels: f32,
    keep: &mut dyn FnMut(Organ),
) {
    let mut cells = match clip_leaf(o, outlines, clips, cell_pixels) {
        LeafClip::Gone => return,
        LeafClip::Whole => return keep(*o),
        LeafClip::Cells(cells) => cells,
    };
    let (x, y) = (o.orientation * Vec3::X, o.orientation * Vec3::Y);
    let (along, across) = (cells.along, cells.across as usize);
    for j in 0..across {
        while cells.rows[j] != 0 {
            let i0 = cells.rows[j].trailing_zeros();
            let run = (cells.rows[j] >> i0).trailing_ones();
            let bits = if run == 64 {
                u64::MAX
            } else {
                ((1u64 << run) - 1) << i0
            };
            let mut k = j + 1;
            while k < across && cells.rows[k] & bits == bits {
                k += 1;
            }
            for row in &mut cells.rows[j..k] {
                *row &= !bits;
            }
            let size = Vec2::new(
                o.size.x * run as f32 / along as f32,
                o.size.y * (k - j) as f32 / across as f32,
            );
            let middle = (j + k) as f32 * 0.5 / across as f32 - 0.5;
            keep(Organ {
                position: o.position
                    + y * (o.size.x * i0 as f32 / along as f32)
                    + x * (o.size.y * middle),
                size,
                ..*o
            });
        }
    }
}

/// The frame the comparison gives `cut` seen as `outlines[view]` sees it, once its leaves
/// are cut to `outlines` laid in `clips` as [`prune`] cuts them: the frame [`Frame::of`]
/// gives the pieces, worked out without making them. Stems, flowers and the leaves wholly
/// on ink set a first box; the cells of the leaves partly over sky (listed in `partial`)
/// are looked at only where their blade reaches past the box so far. `None` when nothing
/// shows.
#[allow(clippy::too_many_arguments)] // Its scratch, borrowed apart from the rest.
fn clipped_frame(
    cut: &Plant,
    blades: &[[Vec3; 4]],
    view: usize,
    outlines: &[Outline],
    clips: &[Frame],
    lies: &[Lie],
    partial: &mut Vec<(f32, u32)>,
) -> Option<Frame> {
    let outline = &outlines[view];
    let side = outline.side;
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    let add = |quad: &[Vec2; 4], lo: &mut Vec2, hi: &mut Vec2| {
        above_ground(quad, |p| (*lo, *hi) = (lo.min(p), hi.max(p)));
    };
    for s in (cut.segments().iter()).filter(|s| shoot_segment(cut, s.material)) {
        add(&stem_band(s, side), &mut lo, &mut hi);
    }
    partial.clear();
    for (i, (blade, lie)) in blades.iter().zip(lies).enumerate() {
        match lie {
            Lie::Gone => {}
            Lie::Whole => add(&blade.map(|p| side.project(p)), &mut lo, &mut hi),
            Lie::Partly => partial.push((0.0, i as u32)),
        }
    }
    // How far past the box a point lies (0 inside it).
    let past = |p: Vec2, lo: Vec2, hi: Vec2| (lo - p).max(p - hi).max_element().max(0.0);
    // The leaves whose part above the ground reaches furthest first: the box grows
    // fastest, and fewer are left.
    for (far, i) in partial.iter_mut() {
        let blade = blades[*i as usize].map(|p| side.project(p));
        *far = 0.0;
        above_ground(&blade, |p| *far = far.max(past(p, lo, hi)));
    }
    partial.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    for &(far, i) in partial.iter() {
        if far == 0.0 {
            break;
        }
        let o = &cut.organs()[i as usize];
        let (box_lo, box_hi) = (lo, hi);
        // Below the ground counts as past the box (which stands on it): such a cell is
        // looked at, and adds what of it shows.
        let reaches = |cell: &[Vec3; 4]| {
            cell.iter()
                .any(|&p| past(side.project(p), box_lo, box_hi) > 0.0)
        };
        tiles(o, outlines, clips, CELL_PIXELS, |tile| {
            if !reaches(&blade_corners(tile)) {
                return;
            }
            match clip_leaf_where(tile, outlines, clips, CELL_PIXELS, reaches) {
                LeafClip::Gone => {}
                LeafClip::Whole => add(
                    &blade_corners(tile).map(|p| side.project(p)),
                    &mut lo,
                    &mut hi,
                ),
                LeafClip::Cells(cells) => {
                    for j in 0..cells.across {
                        let row = cells.rows[j as usize];
                        if row == 0 {
                            continue;
                        }
                        // The cells of a row are steps along a line: where all of them
                        // between its first and last kept one stand above the ground,
                        // those two reach furthest every way.
                        // Heights change evenly along the row too: the cells wholly above
                        // the ground, those across it and those below it lie in three runs.
                        let cell = |i: u32| Cells::corners(tile, (i, i + 1), (j, j + 1), &cells);
                        let (first, last) = (row.trailing_zeros(), 63 - row.leading_zeros());
                        let ends = [first, last].map(cell);
                        if ends.iter().flatten().all(|p| p.y >= 0.0) {
                            for cell in &ends {
                                add(&cell.map(|p| side.project(p)), &mut lo, &mut hi);
                            }
                            continue;
                        }
                        if ends.iter().flatten().all(|p| p.y < 0.0) {
                            continue;
                        }
                        let mut above = None;
                        let mut left = row;
                        while left != 0 {
                            let i = left.trailing_zeros();
                            left &= left - 1;
                            let corners = cell(i);
                            if corners.iter().all(|p| p.y < 0.0) {
                                continue;
                            }
                            if corners.iter().all(|p| p.y >= 0.0) {
                                let (a, _) = above.unwrap_or((corners, corners));
                                above = Some((a, corners));
                                continue;
                            }
                            add(&corners.map(|p| side.project(p)), &mut lo, &mut hi);
                        }
                        for cell in above.iter().flat_map(|(a, b)| [a, b]) {
                            add(&cell.map(|p| side.project(p)), &mut lo, &mut hi);
                        }
                    }
                }
            }
        });
    }
    Frame::of_box(lo, hi, outline.rows())
}

/// The corners of a stem segment's tapered band seen from `side`.
fn stem_band(s: &Segment, side: Side) -> [Vec2; 4] {
    let (r0, r1) = (s.start_radius, s.end_radius);
    let (a, b) = (side.project(s.start), side.project(s.end));
    let along = b - a;
    let normal = if along.length_squared() > 0.0 {
        along.perp().normalize()
    } else {
        Vec2::X
    };
    [
        a + normal * r0,
        b + normal * r1,
        b - normal * r1,
        a - normal * r0,
    ]
}

/// The height [`prune`] lays outlines at over `plant`: the top of what the outline draws of
/// it, metres; `None` when nothing of it shows above the ground.
fn laid_height(plant: &Plant) -> Option<f32> {
    let top = shapes(plant, Side::Front)
        .flat_map(|quad| quad.map(|p| p.y))
        .fold(f32::NEG_INFINITY, f32::max);
    (top > 0.0 && top.is_finite()).then_some(top)
}

impl Outline {
    /// Whether the pixel under canvas point `q` is ink.
    fn ink_at(&self, q: Vec2) -> bool {
        let (width, height) = (self.normalised.width() as f32, self.rows() as f32);
        (0.0..width).contains(&q.x)
            && (0.0..height).contains(&q.y)
            && self.normalised.get(q.x as u32, q.y as u32)
    }

    /// Whether point `p` of a plant `top` metres tall lies on this outline's ink, the outline
    /// laid over the plant as [`prune`] lays it.
    fn holds(&self, p: Vec3, top: f32) -> bool {
        let scale = self.rows() as f32 / top;
        let q = self.side.project(p);
        let (x, y) = (q.x * scale + self.foot, (top - q.y) * scale);
        let (width, height) = (self.normalised.width() as f32, self.rows() as f32);
        (0.0..width).contains(&x)
            && (0.0..height).contains(&y)
            && self.normalised.get(x as u32, y as u32)
    }
}

/// What of a box of canvas pixels an outline inks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cover {
    None,
    Some,
    All,
}

impl Outline {
    /// How much of the pixels from `lo` to `hi` (canvas points, the box's corners) is ink;
    /// what lies off the canvas is sky.
    fn cover(&self, lo: Vec2, hi: Vec2) -> Cover {
        let (w, h) = (self.normalised.width(), self.normalised.height());
        // Pixel `v as u32` holds coordinate `v` (truncation is the floor from 0 up).
        let first = |v: f32, n: u32| (v.max(0.0) as u32).min(n);
        let end = |v: f32, n: u32| {
            if v < 0.0 {
                0
            } else {
                (v as u32).saturating_add(1).min(n)
            }
        };
        let (x0, x1) = (first(lo.x, w), end(hi.x, w));
        let (y0, y1) = (first(lo.y, h), end(hi.y, h));
        if x0 >= x1 || y0 >= y1 {
            return Cover::None;
        }
        // Off the canvas is sky: a box reaching past it is never all ink.
        let on_canvas = lo.x >= 0.0 && lo.y >= 0.0 && hi.x < w as f32 && hi.y < h as f32;
        let (mut ink, mut sky) = (false, !on_canvas);
        let words = &self.normalised.words;
        for y in y0..y1 {
            for (at, bits) in self.normalised.span_words(y, x0, x1) {
                let word = words[at] & bits;
                ink |= word != 0;
                sky |= word != bits;
            }
            if ink && sky {
                return Cover::Some;
            }
        }
        match (ink, sky) {
            (false, _) => Cover::None,
            (true, false) => Cover::All,
            (true, true) => Cover::Some,
        }
    }
}

/// The chamfer distance (3 a step across, 4 a diagonal step: a third of a pixel each unit,
/// within 6% of the Euclidean) from each pixel of `bitmap` to its nearest ink, into `out`
/// row by row; 0 on ink, and `u16::MAX` everywhere for a bitmap without ink. Two passes.
pub fn distance_transform(bitmap: &Bitmap, out: &mut Vec<u16>) {
    let (w, h) = (bitmap.width() as usize, bitmap.height() as usize);
    out.clear();
    out.resize(w * h, u16::MAX);
    for y in 0..h {
        for x in 0..w {
            if bitmap.get(x as u32, y as u32) {
                out[y * w + x] = 0;
            }
        }
    }
    let step = |d: u16, cost: u16| d.saturating_add(cost);
    for y in 0..h {
        for x in 0..w {
            let mut d = out[y * w + x];
            if x > 0 {
                d = d.min(step(out[y * w + x - 1], 3));
            }
            if y > 0 {
                let up = (y - 1) * w;
                d = d.min(step(out[up + x], 3));
                if x > 0 {
                    d = d.min(step(out[up + x - 1], 4));
                }
                if x + 1 < w {
                    d = d.min(step(out[up + x + 1], 4));
                }
            }
            out[y * w + x] = d;
        }
    }
    for y in (0..h).rev() {
        for x in (0..w).rev() {
            let mut d = out[y * w + x];
            if x + 1 < w {
                d = d.min(step(out[y * w + x + 1], 3));
            }
            if y + 1 < h {
                let down = (y + 1) * w;
                d = d.min(step(out[down + x], 3));
                if x + 1 < w {
                    d = d.min(step(out[down + x + 1], 4));
                }
                if x > 0 {
                    d = d.min(step(out[down + x - 1], 4));
                }
            }
            out[y * w + x] = d;
        }
    }
}

/// What scoring reuses between plants: the canvas a plant is drawn into, and its shapes
/// projected into the picture plane.
#[derive(Debug)]
pub struct Scratch {
    canvas: Bitmap,
    quads: Vec<[Vec2; 4]>,
    distance: Vec<u16>,
    /// Tips each stem carries ([`plausibility`]).
    tips: Vec<f32>,
    /// Where each outline is laid to clip a pruned plant's leaves ([`lay_clips`]).
    clips: Vec<Frame>,
    /// Where the comparison frames the clipped plant, a frame per outline.
    draws: Vec<Frame>,
    /// The clipped plant in each of those frames.
    views: Vec<Bitmap>,
    /// How each organ of a pruned plant lies over the outlines laid to clip it.
    lies: Vec<Lie>,
    /// The leaves that lie partly over sky, with how far they reach past the box of the
    /// rest ([`clipped_frame`]).
    partial: Vec<(f32, u32)>,
    /// What [`draw_clipped`] draws from.
    clipping: Clipping,
}

/// The corners of a pruned plant's blades, an entry per organ ([`blade_corners`]), and
/// [`draw_clipped`]'s scratch.
#[derive(Debug, Default)]
struct Clipping {
    blades: Vec<[Vec3; 4]>,
    /// Where a leaf's blade seen in one view lands on the other outlines.
    maps: Vec<(usize, CanvasMap)>,
    /// The leaves partly over sky (index, the outlines to look at as bits).
    partly: Vec<(u32, u32)>,
}

impl Default for Scratch {
    fn default() -> Self {
        Scratch {
            canvas: Bitmap::new(0, 0),
            quads: Vec::new(),
            distance: Vec::new(),
            tips: Vec::new(),
            clips: Vec::new(),
            draws: Vec::new(),
            views: Vec::new(),
            lies: Vec::new(),
            partial: Vec::new(),
            clipping: Clipping::default(),
        }
    }
}

impl Scratch {
    /// The last plant drawn, normalised.
    pub fn canvas(&self) -> &Bitmap {
        &self.canvas
    }

    /// Where the buffers are and their capacities: unchanged by a call that allocated
    /// nothing in them.
    #[cfg(test)]
    pub(crate) fn footprint(&self) -> [(usize, usize); 4] {
        [
            (
                self.canvas.words.as_ptr() as usize,
                self.canvas.words.capacity(),
            ),
            (self.quads.as_ptr() as usize, self.quads.capacity()),
            (self.distance.as_ptr() as usize, self.distance.capacity()),
            (self.tips.as_ptr() as usize, self.tips.capacity()),
        ]
    }
}

/// Whether the outline draws a segment or organ: roots and root tips are below the ground.
fn shoot_segment(plant: &Plant, material: sylva_core::plant::MaterialId) -> bool {
    plant
        .materials()
        .get(material.index())
        .is_none_or(|m| m.kind != MaterialKind::Root)
}

/// The thickest a stem may be without cost, as a share of the plant's height (a spruce's
/// trunk is about 2%, an oak's 4%): a plant should match an outline with branches and
/// leaves, not with a trunk grown as wide as the crown.
pub const MAX_RADIUS_SHARE: f32 = 0.05;

/// The height above the ground of the shoot's skeleton and organs' bases (radii and
/// blades left out).
fn shoot_height(plant: &Plant) -> f32 {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    let segments = plant
        .segments()
        .iter()
        .filter(|s| shoot_segment(plant, s.material))
        .flat_map(|s| [s.start.y, s.end.y]);
    let organs = plant
        .organs()
        .iter()
        .filter(|o| o.kind != OrganKind::RootTip)
        .map(|o| o.position.y);
    for y in segments.chain(organs) {
        lo = lo.min(y);
        hi = hi.max(y);
    }
    let lo = lo.max(0.0);
    if hi > lo { hi - lo } else { 0.0 }
}

/// The thickest the typical stem may be without cost (its radius averaged over the stems'
/// length), as a share of the plant's height. A tree's branches thin towards their tips, so
/// most of its wood by length is thin: 0.2% to 0.8% in the examples of every model. Without
/// it a match grew piles of logs as thick as the trunk allowed (4.6% of the height), every
/// one under [`MAX_RADIUS_SHARE`].
pub const MAX_MEAN_RADIUS_SHARE: f32 = 0.015;

/// The thickest a stem may be for the tips it carries, as a share of the plant's height
/// per square root of their number. By the pipe model a stem's cross-section grows with
/// the shoots and leaves above it, so its radius with the square root of their count: the
/// tree examples of every model measure at most 0.9% (a trunk, a twig), while a log
/// carrying one tip 4% of the height thick is four times over, however many thin stems
/// beside it bring the average down.
pub const MAX_PIPE_SHARE: f32 = 0.01;

/// How plausible the plant is, 0 to 1: the product of four factors, each 1 when it passes.
/// The thickest stem may be [`MAX_RADIUS_SHARE`] of the plant's height and the stems'
/// radius averaged over their length [`MAX_MEAN_RADIUS_SHARE`] (each factor what is
/// allowed over what is there); each stem may be [`MAX_PIPE_SHARE`] of the height times
/// the square root of the tips it carries (the factor is the share of the stems' side area
/// within that); and the shoot grows above the ground (the factor is the share of its
/// stems' length above y = 0 times that of its leaves and flowers: the outline does not
/// see what is below, so without it a match may hang leaves under the ground). `scratch`
/// holds the tip counts.
pub fn plausibility(plant: &Plant, scratch: &mut Scratch) -> f64 {
    let height = shoot_height(plant);
    let segments = plant.segments();
    let shoot = |s: &sylva_core::plant::Segment| shoot_segment(plant, s.material);
    // Tips carried: each organ counts on its stem, a stem with neither organs nor shoots
    // above it is a tip itself, and each stem's count joins its parent's (parents come
    // first, so one pass from the end adds them up).
    let tips = &mut scratch.tips;
    tips.clear();
    tips.resize(segments.len(), 0.0);
    let carries = |at: Option<sylva_core::plant::SegmentId>, tips: &mut Vec<f32>, n: f32| {
        if let Some(t) = at.and_then(|p| tips.get_mut(p.index())) {
            *t += n;
        }
    };
    // The pieces of a leaf [`prune`] clipped (one after another on one stem, alike but for
    // place and size) count as the one leaf they were.
    let mut previous: Option<&Organ> = None;
    for o in plant
        .organs()
        .iter()
        .filter(|o| o.kind != OrganKind::RootTip)
    {
        if !previous.is_some_and(|p| piece_of_same_leaf(p, o)) {
            carries(o.parent, tips, 1.0);
        }
        previous = Some(o);
    }
    for (i, s) in segments.iter().enumerate().rev().filter(|(_, s)| shoot(s)) {
        let n = tips[i].max(1.0);
        tips[i] = n;
        carries(s.parent, tips, n);
    }
    let (mut thickest, mut radius_length, mut length, mut within) = (0.0f32, 0.0, 0.0, 0.0);
    let mut above = 0.0f32;
    for (s, &n) in segments.iter().zip(tips.iter()).filter(|(s, _)| shoot(s)) {
        let along = s.start.distance(s.end);
        let radius = 0.5 * (s.start_radius + s.end_radius);
        thickest = thickest.max(s.start_radius.max(s.end_radius));
        radius_length += radius * along;
        length += along;
        within += radius.min(height * MAX_PIPE_SHARE * n.sqrt()) * along;
        above += along * share_above_ground(s.start.y, s.end.y);
    }
    let (mut organs, mut organs_above) = (0u32, 0u32);
    for o in plant
        .organs()
        .iter()
        .filter(|o| o.kind != OrganKind::RootTip)
    {
        organs += 1;
        organs_above += u32::from(o.position.y >= 0.0);
    }
    let factor = |allowed: f32, there: f32| {
        if there <= allowed {
            1.0
        } else {
            f64::from(allowed / there)
        }
    };
    let mean = if length > 0.0 {
        radius_length / length
    } else {
        0.0
    };
    let stems_above = if length > 0.0 { above / length } else { 1.0 };
    let organs_above = if organs > 0 {
        organs_above as f32 / organs as f32
    } else {
        1.0
    };
    factor(height * MAX_RADIUS_SHARE, thickest)
        * factor(height * MAX_MEAN_RADIUS_SHARE, mean)
        * factor(within, radius_length)
        * f64::from(stems_above * organs_above)
}

/// Whether leaf `b`, following `a` in a plant, may be a piece of the same clipped leaf: on
/// the same stem, of the same material, facing the same way, beside it (pieces tile their
/// leaf; leaves grown one on another are leaves of their own).
fn piece_of_same_leaf(a: &Organ, b: &Organ) -> bool {
    a.kind == OrganKind::Leaf
        && b.kind == OrganKind::Leaf
        && a.parent == b.parent
        && a.material == b.material
        && a.orientation == b.orientation
        && a.position != b.position
}

/// The share of a stem from height `a` to height `b` that lies above the ground (y = 0).
fn share_above_ground(a: f32, b: f32) -> f32 {
    let (lo, hi) = (a.min(b), a.max(b));
    if lo >= 0.0 {
        1.0
    } else if hi <= 0.0 {
        0.0
    } else {
        hi / (hi - lo)
    }
}

/// The corners of a segment's band and of an organ's blade, in the picture plane.
fn shapes(plant: &Plant, side: Side) -> impl Iterator<Item = [Vec2; 4]> + '_ {
    let segments = plant
        .segments()
        .iter()
        .filter(|s| shoot_segment(plant, s.material))
        .map(move |s| stem_band(s, side));
    let organs = plant
        .organs()
        .iter()
        .filter(|o| o.kind != OrganKind::RootTip)
        .map(move |o| blade_corners(o).map(|p| side.project(p)));
    segments.chain(organs)
}

/// The corners of an organ's blade, in order round it: a rectangle from its base along its
/// local +Y by its length, as wide as its width along its local X.
pub(crate) fn blade_corners(o: &Organ) -> [Vec3; 4] {
    let half = o.orientation * Vec3::X * (o.size.y * 0.5);
    let tip = o.orientation * Vec3::Y * o.size.x;
    let base = o.position;
    [
        base - half,
        base - half + tip,
        base + half + tip,
        base + half,
    ]
}

/// Draws `plant` seen from `side` into `scratch.canvas`, normalised to `rows` rows; `false`
/// when nothing of it shows.
fn draw_normalised(plant: &Plant, side: Side, rows: u32, scratch: &mut Scratch) -> bool {
    draw(plant, side, rows, false, scratch)
}

/// Draws `plant` like [`draw_normalised`], but scaled down where it is wider than the canvas
/// so all of it shows (stood on the bottom row, centred): for measures of the whole plant.
pub(crate) fn draw_fitted(plant: &Plant, side: Side, rows: u32, scratch: &mut Scratch) -> bool {
    draw(plant, side, rows, true, scratch)
}

/// [`draw_normalised`], or with `fit` [`draw_fitted`].
fn draw(plant: &Plant, side: Side, rows: u32, fit: bool, scratch: &mut Scratch) -> bool {
    let width = rows * CANVAS_ASPECT;
    if scratch.canvas.width() != width || scratch.canvas.height() != rows {
        scratch.canvas = Bitmap::new(width, rows);
    }
    scratch.canvas.clear();
    scratch.quads.clear();
    scratch.quads.extend(shapes(plant, side));
    let Some(frame) = Frame::of(&scratch.quads, rows, fit) else {
        return false;
    };
    // Stems come first ([`shapes`]).
    let stems = (plant.segments().iter())
        .filter(|s| shoot_segment(plant, s.material))
        .count();
    for (i, quad) in scratch.quads.iter().enumerate() {
        let quad = quad.map(|p| frame.on_canvas(p));
        if i < stems {
            fill_quad(&mut scratch.canvas, quad);
        } else {
            fill_blade(&mut scratch.canvas, quad);
        }
    }
    true
}

/// Where a view's shapes land on a canvas of some rows: plant units to pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frame {
    /// The plant point at the canvas's top middle.
    centre: Vec2,
    /// Pixels per plant unit.
    scale: f32,
    /// Half the canvas's width, pixels.
    half_width: f32,
}

impl Frame {
    /// The frame of a plant's `quads` (seen from one side) on a canvas of `rows`: the
    /// ink's height fills the rows, its box centred (when fitting, its top drops so its
    /// width fits and its foot stays on the bottom row). `None` when nothing shows.
    fn of(quads: &[[Vec2; 4]], rows: u32, fit: bool) -> Option<Frame> {
        let width = (rows * CANVAS_ASPECT) as f32;
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for quad in quads {
            if fit {
                quad.iter().for_each(|&p| (lo, hi) = (lo.min(p), hi.max(p)));
            } else {
                // The ground (y = 0) hides what is below it: the outline is framed on what
                // shows, stands on the ground, and rows under the bottom one are not drawn.
                above_ground(quad, |p| (lo, hi) = (lo.min(p), hi.max(p)));
            }
        }
        if !fit {
            return Frame::of_box(lo, hi, rows);
        }
        let size = hi - lo;
        if !(size.y > 0.0 && size.is_finite()) {
            return None;
        }
        let scale = (rows as f32 / size.y).min(width / size.x);
        Some(Frame {
            centre: Vec2::new((lo.x + hi.x) * 0.5, lo.y + rows as f32 / scale),
            scale,
            half_width: width * 0.5,
        })
    }

    /// The frame of a box of shapes from `lo` to `hi` on a canvas of `rows`: its height
    /// fills the rows, and it is centred. `None` when it is empty.
    fn of_box(lo: Vec2, hi: Vec2, rows: u32) -> Option<Frame> {
        let size = hi - lo;
        if !(size.y > 0.0 && size.is_finite()) {
            return None;
        }
        Some(Frame {
            centre: Vec2::new((lo.x + hi.x) * 0.5, hi.y),
            scale: rows as f32 / size.y,
            half_width: (rows * CANVAS_ASPECT) as f32 * 0.5,
        })
    }

    /// Whether this frame puts every point of a box as wide as the canvas is tall, centred
    /// on it, within `pixels` of where `other` puts it.
    fn within(&self, other: &Frame, pixels: f32) -> bool {
        let rows = other.half_width * 2.0 / CANVAS_ASPECT as f32;
        let back = |c: Vec2| {
            Vec2::new(
                other.centre.x + (c.x - other.half_width) / other.scale,
                other.centre.y - c.y / other.scale,
            )
        };
        [(-0.5, 0.0), (0.5, rows)].into_iter().all(|(x, y)| {
            let c = Vec2::new(other.half_width + x * rows, y);
            (self.on_canvas(back(c)) - c).abs().max_element() <= pixels
        })
    }

    /// Pixel coordinates (rows downwards) of plant point `p` seen in the frame's view.
    #[inline]
    fn on_canvas(&self, p: Vec2) -> Vec2 {
        Vec2::new(
            (p.x - self.centre.x) * self.scale + self.half_width,
            (self.centre.y - p.y) * self.scale,
        )
    }
}

/// Calls `visit` with the corners of the part of a convex quadrilateral at or above y = 0:
/// its corners there, and where its edges cross y = 0.
fn above_ground(quad: &[Vec2; 4], mut visit: impl FnMut(Vec2)) {
    for i in 0..4 {
        let (a, b) = (quad[i], quad[(i + 1) % 4]);
        if a.y >= 0.0 {
            visit(a);
        }
        if (a.y < 0.0) != (b.y < 0.0) {
            visit(Vec2::new(a.x + (b.x - a.x) * (a.y / (a.y - b.y)), 0.0));
        }
    }
}

/// Fills a convex quadrilateral (pixel coordinates, rows downwards): in each row, the
/// pixels whose centres it covers on the row's middle line; where it covers none of them
/// (a stem thinner than a pixel), the one under the middle of what it covers of the row, so
/// that thin stems stay seen. (Filling the whole of what it covers of each row instead drew
/// a thin, nearly level twig as thick as a row at any resolution: at 64 rows a comb of
/// such twigs filled an outline it covered a fraction of at 256.)
fn fill_quad(canvas: &mut Bitmap, quad: [Vec2; 4]) {
    fill_quad_spans(canvas, quad, true, |canvas, row, x0, x1| {
        canvas.fill_span(row, x0, x1)
    });
}

/// Fills a leaf's or flower's blade: [`fill_quad`], but only the pixels whose centres it
/// covers. A blade thinner than a pixel is not a twig to keep seen, and a leaf cut into
/// pieces ([`prune`]) would otherwise show each sliver at its edge as a pixel.
fn fill_blade(canvas: &mut Bitmap, quad: [Vec2; 4]) {
    fill_quad_spans(canvas, quad, false, |canvas, row, x0, x1| {
        canvas.fill_span(row, x0, x1)
    });
}

/// The spans [`fill_quad`] fills, passed to `span` as (canvas, row, first, end); without
/// `thin`, none in a row where it covers no pixel's centre ([`fill_blade`]).
fn fill_quad_spans(
    canvas: &mut Bitmap,
    quad: [Vec2; 4],
    thin: bool,
    mut span: impl FnMut(&mut Bitmap, u32, u32, u32),
) {
    let (mut top, mut bottom) = (f32::INFINITY, f32::NEG_INFINITY);
    for p in quad {
        top = top.min(p.y);
        bottom = bottom.max(p.y);
    }
    let height = canvas.height() as f32;
    if bottom < 0.0 || top >= height || !(top.is_finite() && bottom.is_finite()) {
        return;
    }
    let first = top.max(0.0).floor() as u32;
    let last = (bottom.min(height - 1.0)).floor() as u32;
    // Each edge from its upper end to its lower.
    let edges = [0, 1, 2, 3].map(|i| {
        let (a, b) = (quad[i], quad[(i + 1) % 4]);
        if a.y <= b.y { (a, b) } else { (b, a) }
    });
    for row in first..=last {
        // The quad's extent across its middle line and (for `thin`) across this row's
        // band, from its edges clipped to the band.
        let (band_top, band_bottom) = (row as f32, row as f32 + 1.0);
        let middle = row as f32 + 0.5;
        let (mut left, mut right) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut mid_left, mut mid_right) = (f32::INFINITY, f32::NEG_INFINITY);
        for &(a, b) in &edges {
            let (y0, y1) = (a.y.max(band_top), b.y.min(band_bottom));
            if y0 > y1 {
                continue;
            }
            let at = |y: f32| {
                if b.y > a.y {
                    a.x + (b.x - a.x) * ((y - a.y) / (b.y - a.y))
                } else if y == y0 {
                    a.x
                } else {
                    b.x
                }
            };
            if thin {
                for y in [y0, y1] {
                    let x = at(y);
                    left = left.min(x);
                    right = right.max(x);
                }
            }
            if (y0..=y1).contains(&middle) && b.y > a.y {
                let x = at(middle);
                mid_left = mid_left.min(x);
                mid_right = mid_right.max(x);
            }
        }
        let x0 = (mid_left - 0.5).ceil().max(0.0);
        let x1 = (mid_right - 0.5).floor() + 1.0;
        let (x0, x1) = if mid_left <= mid_right && x1 > x0 {
            (x0, x1)
        } else if !thin || left > right {
            continue;
        } else {
            let mid = ((left + right) * 0.5).floor().max(0.0);
            (mid, mid + 1.0)
        };
        span(canvas, row, x0 as u32, x1.max(0.0) as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::PlantMeta;

    fn rectangle(width: u32, height: u32, ink: (u32, u32, u32, u32)) -> Bitmap {
        let mut b = Bitmap::new(width, height);
        for y in ink.1..ink.3 {
            b.fill_span(y, ink.0, ink.2);
        }
        b
    }

    #[test]
    fn spans_fill_exactly_their_pixels() {
        let mut b = Bitmap::new(200, 3);
        b.fill_span(1, 3, 130);
        assert_eq!(b.ink(), 127);
        assert!(!b.get(2, 1) && b.get(3, 1) && b.get(129, 1) && !b.get(130, 1));
        assert_eq!(b.ink_bounds(), Some((3, 1, 130, 2)));
        b.fill_span(2, 0, 64);
        assert_eq!(b.ink(), 191);
        b.fill_span(0, 190, 400);
        assert_eq!(b.ink_bounds(), Some((0, 0, 200, 3)));
    }

    #[test]
    fn thin_stems_are_drawn_as_thin_as_they_are() {
        let quad = |x0: f32, y0: f32, x1: f32, y1: f32, w: f32| {
            [
                Vec2::new(x0, y0 - w),
                Vec2::new(x1, y1 - w),
                Vec2::new(x1, y1 + w),
                Vec2::new(x0, y0 + w),
            ]
        };
        // A level twig a tenth of a pixel thick, off the row's middle line: one pixel, not
        // its whole length; on the middle line, its length.
        let mut b = Bitmap::new(200, 20);
        fill_quad(&mut b, quad(10.0, 10.2, 100.0, 10.3, 0.05));
        assert_eq!(b.ink(), 1);
        b.clear();
        fill_quad(&mut b, quad(10.0, 10.5, 100.0, 10.5, 0.05));
        assert_eq!(b.ink(), 90);
        // A standing stem thinner than a pixel: one pixel a row, every row it crosses.
        b.clear();
        fill_quad(
            &mut b,
            [
                Vec2::new(50.1, 2.0),
                Vec2::new(50.2, 2.0),
                Vec2::new(50.2, 12.0),
                Vec2::new(50.1, 12.0),
            ],
        );
        assert_eq!(b.ink(), 11);
        assert!((2..=12).all(|y| b.get(50, y)));
    }

    #[test]
    fn outlines_are_normalised_for_place_and_size() {
        // The same tall box, small in one corner and large in another: the same outline.
        let small = Outline::new(&rectangle(300, 300, (10, 20, 30, 80)), Side::Front, 64);
        let large = Outline::new(&rectangle(900, 700, (400, 50, 500, 350)), Side::Front, 64);
        let (small, large) = (small.unwrap(), large.unwrap());
        assert_eq!(small.normalised().iou(large.normalised()), 1.0);
        // 64 rows tall, a third as wide (21 of 192 columns), centred.
        assert_eq!(small.normalised().ink_bounds(), Some((85, 0, 106, 64)));
    }

    #[test]
    fn bad_targets_are_refused() {
        let side = Side::Front;
        assert_eq!(
            Outline::new(&Bitmap::new(50, 50), side, 64),
            Err(OutlineError::Empty)
        );
        assert_eq!(
            Outline::new(&rectangle(50, 50, (0, 0, 50, 50)), side, 64),
            Err(OutlineError::Full)
        );
        assert!(matches!(
            Outline::new(&rectangle(50, 50, (1, 1, 4, 40)), side, 64),
            Err(OutlineError::TooSmall { .. })
        ));
        assert!(matches!(
            Outline::new(&rectangle(500, 50, (0, 10, 400, 30)), side, 64),
            Err(OutlineError::TooWide { .. })
        ));
    }

    /// A trunk 4 m tall and `2 radius` wide (a box, seen from the front), and a root below.
    fn stump(radius: f32) -> Plant {
        let mut plant = Plant::new(PlantMeta::default());
        plant
            .add_segment(
                Vec3::ZERO,
                Vec3::new(0.0, 4.0, 0.0),
                (radius, radius),
                None,
                false,
                Plant::BARK,
            )
            .unwrap();
        let root = plant
            .add_material(sylva_core::plant::Material::of_kind(MaterialKind::Root))
            .unwrap();
        plant
            .add_segment(
                Vec3::ZERO,
                Vec3::new(3.0, -2.0, 0.0),
                (0.5, 0.1),
                None,
                false,
                root,
            )
            .unwrap();
        plant
    }

    #[test]
    fn a_plant_matches_its_own_outline_and_not_another() {
        let mut scratch = Scratch::default();
        let plant = stump(0.15);
        // The target: a box 13.3 times as tall as wide, drawn at another size.
        let target = rectangle(300, 300, (141, 20, 159, 260));
        // At 256 rows the trunk is 19 pixels wide: its edges' pixels count for little.
        let outline = Outline::new(&target, Side::Front, 256).unwrap();
        let iou = outline.iou(&plant, &mut scratch);
        assert!(iou > 0.9, "{iou}");
        // From the side the trunk is the same box; a squat box is another shape.
        let squat = Outline::new(&rectangle(100, 100, (10, 40, 90, 80)), Side::Side, 64).unwrap();
        let iou = squat.iou(&plant, &mut scratch);
        assert!(iou < 0.3, "{iou}");
    }

    /// A trunk 4 m tall with a branch out to each side at 3 m, and a root.
    fn forked() -> Plant {
        let mut plant = stump(0.1);
        for x in [-1.5, 1.5] {
            plant
                .add_segment(
                    Vec3::new(0.0, 3.0, 0.0),
                    Vec3::new(x, 3.8, 0.0),
                    (0.05, 0.05),
                    Some(sylva_core::plant::SegmentId(0)),
                    true,
                    Plant::BARK,
                )
                .unwrap();
        }
        plant
    }

    #[test]
    fn pruning_cuts_what_shows_outside_the_outline() {
        // A tree whose crown leans left: a trunk with a crown on its left only. Laid over the
        // forked plant (its top on the top row, its foot on the trunk), the right branch
        // ends in the sky and goes; the left branch, the trunk and the root stay.
        let mut target = rectangle(400, 400, (195, 100, 205, 300));
        for y in 100..180 {
            target.fill_span(y, 100, 205);
        }
        let outline = Outline::new(&target, Side::Front, SPACE_ROWS).unwrap();
        let plant = forked();
        let pruned = prune(std::slice::from_ref(&outline), &plant);
        let ends: Vec<Vec3> = pruned.segments().iter().map(|s| s.end).collect();
        assert_eq!(
            ends,
            [
                plant.segments()[0].end,
                plant.segments()[1].end,
                plant.segments()[2].end
            ]
        );
        // Seen from the side the target is the same, and the branches lie in the plane
        // z = 0 over its trunk: nothing goes. An outline all sky where the plant
        // stands cuts the whole shoot and keeps the root.
        let side = Outline::new(&target, Side::Side, SPACE_ROWS).unwrap();
        assert_eq!(prune(std::slice::from_ref(&side), &plant), plant);
        let mut away = rectangle(400, 400, (100, 100, 110, 300));
        away.fill_span(299, 300, 310);
        let away = Outline::new(&away, Side::Front, SPACE_ROWS).unwrap();
        let bare = prune(&[away], &plant);
        assert_eq!(bare.segments().len(), 1);
        assert_eq!(bare.segments()[0], plant.segments()[1]);
    }

    /// A trunk 4 m tall and 0.1 m thick in `pieces` segments, its top one carrying a leaf
    /// 2 m wide and 1 m long standing across it (x from -1 to 1, y from 2.5 to 3.5).
    fn trunk_with_a_wide_leaf(pieces: usize) -> Plant {
        trunk_with_a_leaf(pieces, Vec3::new(0.0, 2.5, 0.0), Vec2::new(1.0, 2.0))
    }

    /// A trunk like [`trunk_with_a_wide_leaf`]'s carrying a leaf of `size` at `position`.
    fn trunk_with_a_leaf(pieces: usize, position: Vec3, size: Vec2) -> Plant {
        let mut plant = Plant::new(PlantMeta::default());
        let mut parent = None;
        for i in 0..pieces {
            let y = |i: usize| 4.0 * i as f32 / pieces as f32;
            let id = plant
                .add_segment(
                    Vec3::new(0.0, y(i), 0.0),
                    Vec3::new(0.0, y(i + 1), 0.0),
                    (0.05, 0.05),
                    parent,
                    false,
                    Plant::BARK,
                )
                .unwrap();
            parent = Some(id);
        }
        plant
            .add_organ(Organ {
                kind: OrganKind::Leaf,
                position,
                orientation: sylva_core::glam::Quat::IDENTITY,
                size,
                material: Plant::LEAF,
                parent,
            })
            .unwrap();
        plant
    }

    #[test]
    fn pruning_clips_a_leaf_to_the_outline() {
        // The target: a trunk 0.1 m wide (at 50 pixels a metre) with a crown over it from
        // x = -0.5 to 0.5 m and y = 2.5 to 3.5 m. The leaf's middle half lies on it, its
        // sides in the sky.
        let mut target = rectangle(400, 400, (198, 100, 203, 300));
        for y in 125..175 {
            target.fill_span(y, 175, 226);
        }
        let outline = Outline::new(&target, Side::Front, SPACE_ROWS).unwrap();
        // A bare branch of 64 segments into the sky on the right goes.
        let mut plant = trunk_with_a_wide_leaf(256);
        let mut from = sylva_core::plant::SegmentId(63);
        for i in 0..64 {
            let at = |i: usize| Vec3::new(0.5 + i as f32 / 32.0, 1.0, 0.0);
            from = plant
                .add_segment(
                    at(i),
                    at(i + 1),
                    (0.01, 0.01),
                    Some(from),
                    true,
                    Plant::BARK,
                )
                .unwrap();
        }
        let pruned = prune(std::slice::from_ref(&outline), &plant);
        // Pieces of the leaf stand for what of it lies on ink: its middle, from x = -0.51
        // to 0.51 m (the crown's edges), give or take a cell (the leaf is 128 pixels wide
        // at 256 rows, cut in two tiles of 64 cells of a pixel, 1/64 of its width).
        let leaves = pruned.organs();
        assert!(leaves.len() > 1, "{leaves:?}");
        let area: f32 = leaves.iter().map(|o| o.size.x * o.size.y).sum();
        assert!((1.02 - 0.05..=1.02 + 0.05).contains(&area), "{area}");
        for o in leaves {
            let [a, _, c, _] = blade_corners(o);
            let middle = (a + c) * 0.5;
            assert!((-0.52..0.52).contains(&middle.x), "{o:?}");
            assert_eq!(
                (o.parent, o.orientation),
                (plant.organs()[0].parent, plant.organs()[0].orientation)
            );
        }
        assert_eq!(pruned.segments(), &plant.segments()[..256]);
        // So the pruned plant's outline matches the target's; the whole leaf, half over the
        // sky, did not. The term scores the leaf clipped as it is drawn, which is what the
        // pieces show.
        let mut scratch = Scratch::default();
        let clipped = outline.iou(&pruned, &mut scratch);
        let whole = outline.iou(&plant, &mut scratch);
        assert!(clipped > 0.9 && whole < clipped - 0.1, "{clipped} {whole}");
        let outlines = std::slice::from_ref(&outline);
        let term = score_pruned(outlines, outlines, &plant, 0.0, &mut scratch);
        let pieces = outline.score(&pruned, &mut scratch);
        assert!((term - pieces).abs() < 0.01, "{term} {pieces}");
        // The pieces count as the one leaf they were: the trunk, 0.05 m thick, carries one
        // tip and may be 1% of 4 m for it (0.04 m), so the pipe-model factor is 0.8 (for
        // two tips or more it would be 1).
        let p = plausibility(&pruned, &mut scratch);
        assert!((p - 0.8).abs() < 1e-5, "{p}");
        // A leaf wholly on ink stays whole, and one wholly over sky goes.
        let inner = trunk_with_a_leaf(1, Vec3::new(-0.2, 2.8, 0.0), Vec2::new(0.4, 0.4));
        assert_eq!(prune(outlines, &inner), inner);
        let sky = trunk_with_a_leaf(1, Vec3::new(1.5, 2.8, 0.0), Vec2::new(0.4, 0.4));
        assert_eq!(prune(outlines, &sky).organs(), &[]);
    }

    #[test]
    fn laid_again_bare_twigs_over_sky_go() {
        // A trunk with a leaf on a twig to each side at 3 m, its outline the target.
        let mut plant = Plant::new(PlantMeta::default());
        let stem = |plant: &mut Plant, from: [f32; 2], to: [f32; 2], parent: Option<u32>| {
            plant
                .add_segment(
                    Vec3::new(from[0], from[1], 0.0),
                    Vec3::new(to[0], to[1], 0.0),
                    (0.02, 0.02),
                    parent.map(sylva_core::plant::SegmentId),
                    parent.is_some(),
                    Plant::BARK,
                )
                .unwrap()
        };
        stem(&mut plant, [0.0, 0.0], [0.0, 4.0], None);
        for x in [-0.75, 0.75] {
            let twig = stem(&mut plant, [0.0, 3.0], [x, 3.0], Some(0));
            plant
                .add_organ(Organ {
                    kind: OrganKind::Leaf,
                    position: Vec3::new(x, 3.0, 0.0),
                    orientation: sylva_core::glam::Quat::IDENTITY,
                    size: Vec2::new(0.5, 0.5),
                    material: Plant::LEAF,
                    parent: Some(twig),
                })
                .unwrap();
        }
        let mut scratch = Scratch::default();
        assert!(draw_normalised(
            &plant,
            Side::Front,
            SPACE_ROWS,
            &mut scratch
        ));
        let outline = Outline::new(scratch.canvas(), Side::Front, SPACE_ROWS).unwrap();
        // A bare twig ending in the sky below the right leaf goes; a bare twig into the
        // sky on the left stays, for the twig it carries ends on the left leaf.
        let mut twiggy = plant.clone();
        stem(&mut twiggy, [0.0, 2.0], [0.7, 2.5], Some(0));
        let carrier = stem(&mut twiggy, [0.0, 2.0], [-0.6, 2.4], Some(0));
        stem(&mut twiggy, [-0.6, 2.4], [-0.7, 3.2], Some(carrier.0));
        let mut quads = Vec::new();
        let again = reframed(&[outline], &twiggy, &mut quads).expect("the plant shows");
        let mut kept = twiggy.segments().to_vec();
        kept.remove(3);
        for s in &mut kept[3..] {
            s.parent = s
                .parent
                .map(|p| sylva_core::plant::SegmentId(p.0 - u32::from(p.0 > 3)));
        }
        assert_eq!(again.segments(), &kept[..]);
        assert_eq!(again.organs(), plant.organs());
    }

    #[test]
    fn a_trunk_as_wide_as_a_crown_does_not_pass_for_one() {
        // A square target and a stump as wide as tall: its outline matches, its stem does
        // not pass (a radius of half its height, ten times the 5% allowed).
        let square = Outline::new(&rectangle(100, 100, (10, 10, 90, 90)), Side::Front, 64);
        let (square, stump) = (square.unwrap(), stump(2.0));
        let mut scratch = Scratch::default();
        assert!(square.iou(&stump, &mut scratch) > 0.95);
        // 5% of 4 m over 2 m for the thickest stem, 1.5% of 4 m over 2 m for the mean, and
        // 1% of 4 m over 2 m for a stem carrying one tip (itself).
        let p = plausibility(&stump, &mut scratch);
        assert!((p - 0.1 * 0.03 * 0.02).abs() < 1e-7, "{p}");
        let score = square.score(&stump, &mut scratch);
        let iou = square.iou(&stump, &mut scratch);
        assert_eq!(score, iou * p);
        // A thin trunk costs nothing; one of 4% costs for its mean and as a lone tip.
        assert_eq!(plausibility(&super::tests::stump(0.03), &mut scratch), 1.0);
        let thick = plausibility(&super::tests::stump(0.16), &mut scratch);
        assert!(
            (thick - 0.06 / 0.16 * (0.04 / 0.16)).abs() < 1e-6,
            "{thick}"
        );
    }

    #[test]
    fn a_pile_of_logs_does_not_pass_for_a_crown() {
        // A trunk and twelve branches as thick as it (4% of the height: under the 5% any
        // stem may be) against the same trunk whose branches thin to 0.5%.
        let crown = |branch_radius: f32| {
            let mut plant = Plant::new(PlantMeta::default());
            let top = Vec3::new(0.0, 5.0, 0.0);
            let trunk =
                (plant.add_segment(Vec3::ZERO, top, (0.2, 0.2), None, false, Plant::BARK)).unwrap();
            for k in 0..12 {
                let angle = k as f32 * 0.5;
                let end =
                    top + Vec3::new(angle.cos() * 2.0, 1.0 + (k % 3) as f32, angle.sin() * 2.0);
                let r = branch_radius;
                plant
                    .add_segment(top, end, (r, r), Some(trunk), true, Plant::BARK)
                    .unwrap();
            }
            plant
        };
        let mut scratch = Scratch::default();
        let logs = plausibility(&crown(0.3), &mut scratch);
        let tree = plausibility(&crown(0.04), &mut scratch);
        assert_eq!(tree, 1.0);
        assert!(logs < 0.5, "{logs}");
    }

    #[test]
    fn thin_stems_beside_logs_do_not_pass_them_for_branches() {
        // Four logs 4% of the height thick, each carrying nothing, and a hundred thin long
        // spokes that bring the stems' mean radius under its bound: the pipe model still
        // sees the logs. Carrying leaves enough, the same logs are a plant's main stems.
        let fan = |leaves: usize| {
            let mut plant = Plant::new(PlantMeta::default());
            let up = Vec3::new(0.0, 10.0, 0.0);
            for k in 0..104 {
                let angle = k as f32 * 0.06;
                let end = up + Vec3::new(angle.cos() * 6.0, angle.sin().abs() * -8.0, 0.0);
                let (r, bark) = (if k < 4 { 0.4 } else { 0.005 }, Plant::BARK);
                let at = plant
                    .add_segment(up, end, (r, r), None, false, bark)
                    .unwrap();
                for _ in 0..if k < 4 { leaves } else { 0 } {
                    let leaf = Organ {
                        kind: OrganKind::Leaf,
                        position: end,
                        orientation: sylva_core::glam::Quat::IDENTITY,
                        size: Vec2::new(0.3, 0.2),
                        material: Plant::LEAF,
                        parent: Some(at),
                    };
                    plant.add_organ(leaf).unwrap();
                }
            }
            plant
                .add_segment(Vec3::ZERO, up, (0.1, 0.1), None, false, Plant::BARK)
                .unwrap();
            plant
        };
        let mut scratch = Scratch::default();
        let logs = plausibility(&fan(0), &mut scratch);
        assert!(logs < 0.6, "{logs}");
        assert_eq!(plausibility(&fan(16), &mut scratch), 1.0);
    }

    #[test]
    fn what_lies_below_the_ground_is_not_seen() {
        // Shoots under the ground beside the trunk: the outline is the trunk's alone,
        // framed on it.
        let mut plant = stump(0.03);
        for (start, end) in [((0.0, -2.0), (-4.0, -1.0)), ((3.0, -1.0), (0.5, -0.3))] {
            let (start, end) = (
                Vec3::new(start.0, start.1, 0.0),
                Vec3::new(end.0, end.1, 0.0),
            );
            let bark = Plant::BARK;
            plant
                .add_segment(start, end, (0.03, 0.03), None, false, bark)
                .unwrap();
        }
        let outline = Outline::new(&rectangle(300, 300, (141, 20, 159, 260)), Side::Front, 128);
        let outline = outline.unwrap();
        let (mut a, mut b) = (Scratch::default(), Scratch::default());
        outline.iou(&plant, &mut a);
        outline.iou(&stump(0.03), &mut b);
        assert!(a.canvas().ink() > 0);
        assert_eq!(a.canvas(), b.canvas());
        // The ground also bounds the height stems are judged against, and a shoot under it
        // is not plausible: of the 4 + 4.12 + 2.60 m of stems, 4 m are above it.
        assert_eq!(shoot_height(&plant), 4.0);
        assert_eq!(plausibility(&stump(0.03), &mut b), 1.0);
        let share = 4.0 / (4.0 + 17f64.sqrt() + 6.74f64.sqrt());
        let buried = plausibility(&plant, &mut a);
        assert!((buried - share).abs() < 1e-3, "{buried}");
        // Nothing at all above the ground: nothing to see.
        let mut buried = Plant::new(PlantMeta::default());
        let down = Vec3::new(0.0, -3.0, 0.0);
        buried
            .add_segment(Vec3::ZERO, down, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        assert_eq!(outline.iou(&buried, &mut a), 0.0);
    }

    #[test]
    fn nothing_above_the_ground_scores_zero() {
        let outline =
            Outline::new(&rectangle(100, 100, (40, 10, 60, 90)), Side::Front, 64).unwrap();
        let plant = Plant::new(PlantMeta::default());
        assert_eq!(outline.iou(&plant, &mut Scratch::default()), 0.0);
    }

    #[test]
    fn distances_are_chamfer_steps_to_the_nearest_ink() {
        let mut b = Bitmap::new(5, 5);
        let mut d = Vec::new();
        distance_transform(&b, &mut d);
        assert!(d.iter().all(|&v| v == u16::MAX));
        b.set(2, 2);
        distance_transform(&b, &mut d);
        let at = |x: usize, y: usize| d[y * 5 + x];
        assert_eq!(
            [at(2, 2), at(3, 2), at(3, 3), at(4, 2), at(4, 4), at(0, 1)],
            [0, 3, 4, 6, 8, 7]
        );
    }

    #[test]
    fn closeness_rewards_a_silhouette_nearer_the_outline() {
        let mut scratch = Scratch::default();
        let thin = Outline::new(&rectangle(300, 300, (141, 20, 159, 260)), Side::Front, 64);
        let thin = thin.unwrap();
        let own = thin.closeness(&stump(0.15), &mut scratch);
        assert!(own > 0.95, "{own}");
        // Wider and wider trunks lie further and further from the thin box.
        let wider = thin.closeness(&stump(0.6), &mut scratch);
        let widest = thin.closeness(&stump(1.5), &mut scratch);
        assert!(own > wider && wider > widest, "{own} {wider} {widest}");
        assert_eq!(
            thin.closeness(&Plant::new(PlantMeta::default()), &mut scratch),
            0.0
        );
        // Weight 0 is the IoU term; a weight blends the two.
        let plant = stump(0.6);
        assert_eq!(
            thin.score_with_closeness(&plant, 0.0, &mut scratch),
            thin.score(&plant, &mut scratch)
        );
        let iou = thin.iou(&plant, &mut scratch);
        let blended = thin.score_with_closeness(&plant, 1.0, &mut scratch);
        let p = plausibility(&plant, &mut scratch);
        assert!((blended - (iou + wider) / 2.0 * p).abs() < 1e-12);
        // Once warm, nothing is allocated.
        let warm = scratch.footprint();
        for radius in [0.1, 0.3, 0.9] {
            thin.score_with_closeness(&stump(radius), 1.0, &mut scratch);
            assert_eq!(scratch.footprint(), warm);
        }
    }
}
