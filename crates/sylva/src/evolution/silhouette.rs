//! The `[match]` term: how closely a plant's silhouette matches target pictures
//! ([`sylva_fitness::silhouette`]), joined to any model's evolution as one more term
//! ([`sylva_evolve::WithTerm`]), and the overlay picture that shows it.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sylva_evolve::{Added, Problem, Term};
pub use sylva_fitness::silhouette::Outline;
use sylva_fitness::silhouette::{Bitmap, SPACE_ROWS, Scratch, Side};
pub use sylva_fitness::silhouette::{prune, score_pruned};
use sylva_model::Evolve;

use crate::error::{Error, InputError};
use crate::genome::Genome;
use crate::picture::{self, Threshold};

use super::schema::MatchConfig;

/// The term's name, a column of `stats.csv`.
pub const TERM: &str = "iou";

thread_local! {
    /// Per-thread canvas; it carries nothing between plants.
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// What each figure of the plausibility report ([`crate::inspect::Report`]) that a plant
/// fails does to its score: halves it. A trunk no tree has (a log, slenderness under 5; a
/// post, over 180; a foot flared past three times its breast-height width), a crown or
/// leaves of a size no tree of its height has, stems thicker than their parents: such a
/// plant cannot win against one that passes and matches more than half as well.
pub const IMPLAUSIBLE: f64 = 0.5;

/// [`IMPLAUSIBLE`] to the power of the figures `plant` fails.
pub fn realism(plant: &sylva_core::Plant) -> f64 {
    let failed = crate::inspect::Report::of(plant, None).failures().len();
    IMPLAUSIBLE.powi(failed as i32)
}

/// Model `M`'s plants against target outlines: the mean over the views of the IoU times
/// the plant's stem plausibility ([`Outline::score`]), halved for each figure of the
/// plausibility report the plant fails ([`realism`]).
struct OutlineTerm<M> {
    model: M,
    outlines: Vec<Outline>,
    /// Weight of closeness beside the IoU (`[match] closeness`).
    closeness: f64,
    /// The outlines the plant is pruned to, if it is (`[match] prune`).
    space: Option<Arc<[Outline]>>,
}

impl<M: Evolve> Term<M::Problem> for OutlineTerm<M> {
    fn name(&self) -> &str {
        TERM
    }

    /// Grows the genome with its own seed; a genome that fails to grow scores 0.
    fn score(&self, problem: &M::Problem, evolved: &<M::Problem as Problem>::Genome) -> f64 {
        let genome = self.model.genome_file(problem, evolved);
        let seed = self.model.default_seed(&genome);
        let Ok(mut plant) = self.model.develop(&genome, seed) else {
            return 0.0;
        };
        // What is scored is what the run writes: dressed as the genome names (the
        // self-organising model's foliage; the papers' models name none).
        let dress = self.model.dress(&genome);
        if !dress.is_plain() {
            match sylva_core::dress::dress(&plant, &dress, seed) {
                Ok((dressed, _)) => plant = dressed,
                Err(_) => return 0.0,
            }
        }
        let outline = SCRATCH.with(|scratch| {
            let scratch = &mut scratch.borrow_mut();
            if let Some(space) = &self.space {
                return score_pruned(space, &self.outlines, &plant, self.closeness, scratch);
            }
            let sum: f64 = (self.outlines.iter())
                .map(|o| o.score_with_closeness(&plant, self.closeness, scratch))
                .sum();
            sum / self.outlines.len() as f64
        });
        // The report is the plant's, whether pruned to the outlines or not.
        if outline > 0.0 {
            outline * realism(&plant)
        } else {
            outline
        }
    }
}

/// A match's target pictures, each read, decoded and thresholded once, then carried by value
/// (a clone shares them) through the problem's term, the pruning space, the overlay and the
/// outputs. Which files and threshold it holds are [`MatchConfig`]'s `front`, `side` and
/// `threshold`; its outlines are made at whatever rows are asked.
#[derive(Clone, Debug)]
pub struct Target {
    /// The front view, then the side view if there is one: each picture's path (named in
    /// errors) and its ink.
    views: Arc<[(Side, PathBuf, Bitmap)]>,
    threshold: Threshold,
    /// The folder the config's file names were found in.
    base: PathBuf,
}

impl Target {
    /// Reads the pictures `config` names, relative to `base`.
    pub fn read(config: &MatchConfig, base: &Path) -> Result<Target, InputError> {
        let views = [
            (Side::Front, Some(&config.front)),
            (Side::Side, config.side.as_ref()),
        ];
        let mut read: Vec<(Side, PathBuf, Bitmap)> = Vec::new();
        for (side, path) in views
            .into_iter()
            .filter_map(|(side, file)| file.map(|f| (side, base.join(f))))
        {
            // A side view of the front's own picture (`sylva match`'s default) is read once.
            let ink = match read.iter().find(|(_, p, _)| *p == path) {
                Some((_, _, ink)) => ink.clone(),
                None => picture::load_target(&path, config.threshold)?,
            };
            read.push((side, path, ink));
        }
        let views = read;
        Ok(Target {
            views: views.into(),
            threshold: config.threshold,
            base: base.to_owned(),
        })
    }

    /// Whether these are the pictures `config` names, at its threshold (its file names
    /// found in the folder these were read from).
    pub fn is_of(&self, config: &MatchConfig) -> bool {
        let files = [Some(&config.front), config.side.as_ref()];
        let wanted = files.iter().flatten().map(|f| self.base.join(f));
        self.threshold == config.threshold
            && self.views.len() == wanted.clone().count()
            && self
                .views
                .iter()
                .zip(wanted)
                .all(|((_, path, _), w)| *path == w)
    }

    /// The outlines of the views at `rows` rows.
    pub fn outlines(&self, rows: u32) -> Result<Vec<Outline>, InputError> {
        self.views
            .iter()
            .map(|(side, path, ink)| {
                Outline::new(ink, *side, rows).map_err(|e| InputError::file(path, e))
            })
            .collect()
    }

    /// The pictures as a model may grow into them ([`sylva_model::TargetProfile`]): each
    /// view's stretches of ink, row by row from its foot, at [`PROFILE_ROWS`] rows; a target without a
    /// side view is seen from the side as from the front.
    pub fn profile(&self) -> Result<sylva_model::TargetProfile, InputError> {
        let outlines = self.outlines(PROFILE_ROWS)?;
        let rows_of = |o: &Outline| {
            let (ink, rows) = (o.normalised(), o.rows());
            let share = |x: u32| (x as f32 - o.foot()) / rows as f32;
            (0..rows)
                .rev()
                .map(|y| {
                    let mut stretches = Vec::new();
                    let mut x = 0;
                    while x < ink.width() {
                        if !ink.get(x, y) {
                            x += 1;
                            continue;
                        }
                        let left = x;
                        while x < ink.width() && ink.get(x, y) {
                            x += 1;
                        }
                        stretches.push([share(left), share(x)]);
                    }
                    stretches
                })
                .collect::<Vec<_>>()
        };
        let front = rows_of(&outlines[0]);
        let side = match outlines.iter().find(|o| o.side() == Side::Side) {
            Some(side) if outlines.len() > 1 => rows_of(side),
            _ => front.clone(),
        };
        Ok(sylva_model::TargetProfile { front, side })
    }

    /// The outlines plants grow inside (at [`SPACE_ROWS`] rows) when `config` prunes
    /// (`[match] prune`); none when it does not.
    pub fn space(&self, config: &MatchConfig) -> Result<Option<Arc<[Outline]>>, InputError> {
        if !config.prunes() {
            return Ok(None);
        }
        Ok(Some(self.outlines(SPACE_ROWS)?.into()))
    }

    /// The term `config` adds to model `M`'s problem.
    pub(super) fn added<M: Evolve>(
        &self,
        model: &M,
        config: &MatchConfig,
    ) -> Result<Added<M::Problem>, InputError> {
        Ok(Added {
            term: Arc::new(OutlineTerm {
                model: model.clone(),
                outlines: self.outlines(config.rows)?,
                closeness: config.closeness,
                space: self.space(config)?,
            }),
            weight: config.weight,
            beside: config.beside,
        })
    }

    /// `overlay.png`: the front target and `genome`'s silhouette (grown with its own seed,
    /// pruned as `config` prunes) over each other, normalised as the term compares them, with
    /// their IoU; and that IoU.
    pub fn overlay(&self, config: &MatchConfig, genome: &Genome) -> Result<(Vec<u8>, f64), Error> {
        let (side, path, ink) = &self.views[0];
        let target =
            Outline::new(ink, *side, OVERLAY_ROWS).map_err(|e| InputError::file(path, e))?;
        let seed = genome.default_seed();
        let mut plant = genome.develop(seed)?;
        if let Some(space) = self.space(config)? {
            plant = prune(&space, &plant);
        }
        let dress = genome.own_dress();
        if !dress.is_plain() {
            plant = sylva_core::dress::dress(&plant, &dress, seed)?.0;
        }
        let mut scratch = Scratch::default();
        let iou = target.iou(&plant, &mut scratch);
        let (canvas, wanted) = (scratch.canvas(), target.normalised());
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let caption =
            format!("IoU {iou:.3} (front)   blue: {name}   orange: the plant   green: both");
        let image = sylva_render::overlay::overlay(
            wanted.width(),
            wanted.height(),
            2,
            |x, y| wanted.get(x, y),
            |x, y| canvas.get(x, y),
            &caption,
        );
        Ok((sylva_render::encode_png(&image)?, iou))
    }
}

/// The targets of `config`, read from pictures relative to `base`.
pub fn outlines(config: &MatchConfig, base: &Path) -> Result<Vec<Outline>, InputError> {
    Target::read(config, base)?.outlines(config.rows)
}

/// The outlines of `config` that its plants grow inside (at [`SPACE_ROWS`] rows), read
/// from pictures relative to `base`; none when it does not prune (`[match] prune`).
pub fn space(config: &MatchConfig, base: &Path) -> Result<Option<Arc<[Outline]>>, InputError> {
    if !config.prunes() {
        return Ok(None);
    }
    Target::read(config, base)?.space(config)
}

/// Rows of a target's profile ([`Target::profile`]).
pub const PROFILE_ROWS: u32 = 128;

/// Rows of the overlay picture's outlines.
const OVERLAY_ROWS: u32 = 256;

/// `overlay.png` of `genome` against the pictures of `outline`, read relative to `base`
/// ([`Target::overlay`]).
pub fn overlay(
    outline: &MatchConfig,
    base: &Path,
    genome: &Genome,
) -> Result<(Vec<u8>, f64), Error> {
    let front = MatchConfig {
        side: None,
        ..outline.clone()
    };
    Target::read(&front, base)?.overlay(outline, genome)
}
