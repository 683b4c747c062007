//! The `[match]` term: how closely a plant's silhouette matches target pictures
//! ([`sylva_fitness::silhouette`]), joined to any model's evolution as one more term
//! ([`sylva_evolve::WithTerm`]), and the overlay picture that shows it.

use std::cell::RefCell;
use std::path::Path;
use std::sync::Arc;

use sylva_evolve::{Added, Problem, Term};
pub use sylva_fitness::silhouette::Outline;
use sylva_fitness::silhouette::{SPACE_ROWS, Scratch, Side};
pub use sylva_fitness::silhouette::{prune, score_pruned};
use sylva_model::Evolve;

use crate::error::{Error, InputError};
use crate::genome::Genome;
use crate::picture;

use super::schema::MatchConfig;

/// The term's name, a column of `stats.csv`.
pub const TERM: &str = "iou";

thread_local! {
    /// Per-thread canvas; it carries nothing between plants.
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Model `M`'s plants against target outlines: the mean over the views of the IoU times
/// the plant's stem plausibility ([`Outline::score`]).
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
        let Ok(plant) = self.model.develop(&genome, seed) else {
            return 0.0;
        };
        SCRATCH.with(|scratch| {
            let scratch = &mut scratch.borrow_mut();
            if let Some(space) = &self.space {
                return score_pruned(space, &self.outlines, &plant, self.closeness, scratch);
            }
            let sum: f64 = (self.outlines.iter())
                .map(|o| o.score_with_closeness(&plant, self.closeness, scratch))
                .sum();
            sum / self.outlines.len() as f64
        })
    }
}

/// The targets of `config`, read from pictures relative to `base`.
pub fn outlines(config: &MatchConfig, base: &Path) -> Result<Vec<Outline>, InputError> {
    let threshold = config.threshold;
    let views = [
        (Side::Front, Some(&config.front)),
        (Side::Side, config.side.as_ref()),
    ];
    views
        .into_iter()
        .filter_map(|(side, file)| file.map(|f| (side, base.join(f))))
        .map(|(side, path)| {
            let picture = picture::load_target(&path, threshold)?;
            Outline::new(&picture, side, config.rows).map_err(|e| InputError::file(&path, e))
        })
        .collect()
}

/// The outlines of `config` that its plants grow inside (at [`SPACE_ROWS`] rows), read
/// from pictures relative to `base`; none when it does not prune (`[match] prune`).
pub fn space(config: &MatchConfig, base: &Path) -> Result<Option<Arc<[Outline]>>, InputError> {
    if !config.prunes() {
        return Ok(None);
    }
    let fine = MatchConfig {
        rows: SPACE_ROWS,
        ..config.clone()
    };
    Ok(Some(outlines(&fine, base)?.into()))
}

/// The term `config` adds to model `M`'s problem, its pictures read relative to `base`.
pub(super) fn added<M: Evolve>(
    model: &M,
    config: &MatchConfig,
    base: &Path,
) -> Result<Added<M::Problem>, InputError> {
    Ok(Added {
        term: Arc::new(OutlineTerm {
            model: model.clone(),
            outlines: outlines(config, base)?,
            closeness: config.closeness,
            space: space(config, base)?,
        }),
        weight: config.weight,
        beside: config.beside,
    })
}

/// Rows of the overlay picture's outlines.
const OVERLAY_ROWS: u32 = 256;

/// `overlay.png`: the front target and `genome`'s silhouette (grown with its own seed)
/// over each other, normalised as the term compares them, with their IoU; and that IoU.
pub fn overlay(
    outline: &MatchConfig,
    base: &Path,
    genome: &Genome,
) -> Result<(Vec<u8>, f64), Error> {
    let front = MatchConfig {
        side: None,
        rows: OVERLAY_ROWS,
        ..outline.clone()
    };
    let target = outlines(&front, base)?.remove(0);
    let mut plant = genome.develop(genome.default_seed())?;
    if let Some(space) = space(outline, base)? {
        plant = prune(&space, &plant);
    }
    let mut scratch = Scratch::default();
    let iou = target.iou(&plant, &mut scratch);
    let (canvas, wanted) = (scratch.canvas(), target.normalised());
    let name = outline
        .front
        .file_name()
        .unwrap_or_default()
        .to_string_lossy();
    let caption = format!("IoU {iou:.3} (front)   blue: {name}   orange: the plant   green: both");
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
