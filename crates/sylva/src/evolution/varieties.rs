//! A MAP-Elites run of any model ([`Varieties`]): a map of the fittest plant of every kind,
//! the erased face of a typed map run (`typed_map.rs`).

use std::path::Path;

use sylva_core::Plant;
use sylva_core::par::{Pool, Stop, Stopped};
use sylva_evolve::map::{Axis, MapStats};
use sylva_fitness::descriptors::Descriptor;

use crate::error::Error;
use crate::genome::Genome;

use super::config::Config;
use super::face::MapFace;
pub use super::typed_map::Variety;

/// A MAP-Elites run of any model: a map of the fittest plant of every kind
/// ([docs/varieties.md]).
pub struct Varieties {
    run: Box<dyn MapFace>,
}

impl std::fmt::Debug for Varieties {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Varieties")
            .field("model", &self.title())
            .field("generation", &self.generation())
            .field("filled", &self.stats().last().map(|s| s.filled))
            .finish()
    }
}

impl Varieties {
    /// Starts a map run of `config` (whatever its `[run] strategy`; its `[map]`, or the
    /// default map): generation 0 made, evaluated and placed. `start` holds the first
    /// genomes (of the config's model); the rest are random.
    pub fn start(config: &Config, start: Vec<Genome>, pool: Pool) -> Result<Varieties, Error> {
        let run = config.face().start_map(&config.at()?, start, pool)?;
        Ok(Varieties { run })
    }

    /// Resumes the map run saved in a checkpoint's `text` (read from `path`), which must
    /// have been written by the same config (but for the run's length, threads and
    /// checkpoint interval). The run continues exactly as if it had never stopped.
    pub fn resume(
        config: &Config,
        path: &Path,
        text: &str,
        pool: Pool,
    ) -> Result<Varieties, Error> {
        let run = config
            .face()
            .resume_map(&config.at()?, (path, text), pool)?;
        Ok(Varieties { run })
    }

    /// The effective config (its `[map]` filled in).
    pub fn config(&self) -> Config {
        Config::of(self.run.config())
    }

    /// The model's title, for plots.
    pub fn title(&self) -> &'static str {
        self.run.title()
    }

    /// Breeds one generation, offers it to the map, and returns its statistics.
    pub fn step(&mut self) -> &MapStats {
        self.run.step()
    }

    /// [`Varieties::step`], cut short once `stop` is set (within one offspring's
    /// evaluation): then `Err(Stopped)`, and the map is as it was before the step.
    pub fn step_until(&mut self, stop: &Stop) -> Result<&MapStats, Stopped> {
        stop.watch(|| {
            self.run.step();
        })?;
        Ok(self
            .stats()
            .last()
            .expect("a map has generation 0's statistics"))
    }

    /// The last completed generation.
    pub fn generation(&self) -> u32 {
        self.stats().last().map_or(0, |s| s.generation)
    }

    /// Statistics of every generation so far, one row each.
    pub fn stats(&self) -> &[MapStats] {
        self.run.stats()
    }

    /// Names of the fitness terms, in the order of each member's terms.
    pub fn term_names(&self) -> &[String] {
        self.run.term_names()
    }

    /// The map's descriptors, one per axis.
    pub fn descriptors(&self) -> &[Descriptor] {
        self.run.descriptors()
    }

    /// The map's axes: each descriptor's range and cells.
    pub fn axes(&self) -> &[Axis] {
        &self.run.settings().axes
    }

    /// Cells in the map.
    pub fn cells(&self) -> usize {
        self.run.settings().cells()
    }

    /// The filled cells' elites, in cell order.
    pub fn varieties(&self) -> Vec<Variety> {
        self.run.varieties()
    }

    /// The elite of `cell`, if it is filled.
    pub fn variety(&self, cell: usize) -> Option<Variety> {
        self.run.variety(cell)
    }

    /// The fittest elite (ties go to the lower cell), if the map holds any.
    pub fn best(&self) -> Option<Variety> {
        self.varieties().into_iter().reduce(|best, v| {
            if v.member.total() > best.member.total() {
                v
            } else {
                best
            }
        })
    }

    /// The checkpoint file's text (JSON): the effective config and everything needed to
    /// resume.
    pub fn checkpoint(&self) -> Result<String, Error> {
        self.run.checkpoint()
    }

    /// Guides drawn beside plants in pictures (a target surface, forbidden cells), if the
    /// model's fitness has any.
    pub fn guides(&self) -> Option<Plant> {
        self.run.guides()
    }
}
