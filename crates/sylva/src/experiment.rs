//! Bornhofen and Lattaud's experiments (herbs under a tree, lateral light, breeding from
//! empty rules) as one workflow: read the config and its genomes, estimate the work, run,
//! and hand back the report, the per-step records and the grown plants as assets.
//!
//! ```no_run
//! # fn main() -> Result<(), sylva::Error> {
//! let experiment = sylva::Experiment::load(&sylva::Registry::standard(), "examples/lsystem/herbs-under-tree.toml".as_ref())?;
//! let pool = sylva::core::par::Pool::with_threads(0)?;
//! let result = experiment.run(&pool, &mut |_step| {})?;
//! print!("{}", result.report);
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use sylva_core::glam::{Quat, Vec2, Vec3};
use sylva_core::par::Pool;
use sylva_core::{MaterialKind, Plant};
use sylva_lsystem::experiments::{LateralLightOutcome, Simulation, SimulationOutcome};
use sylva_lsystem::garden::records_csv;
use sylva_lsystem::{LSystemGenome, LSystemModel};
use sylva_model::Model;

use crate::Work;
use crate::assets::{Origin, Placed, SceneAssets, check_scene_glb};
use crate::error::{Error, InputError};
use crate::files::read_text;
use crate::genome::{Genome, expect_model};
use crate::registry::Registry;

/// An experiment config with the genomes it names, ready to run.
pub struct Experiment {
    path: PathBuf,
    simulation: Simulation,
    genomes: Vec<LSystemGenome>,
}

/// What an experiment measured and grew.
pub struct ExperimentResult {
    /// `report.txt`: the measured outcome, one figure a line.
    pub report: String,
    /// `records.csv`: per plant and step records.
    pub records_csv: String,
    /// The grown plants where they grew, each carrying its genome, seed and biomass.
    pub scene: SceneAssets,
    /// For the lateral-light experiment: tree 1 under lateral light beside tree 1 under
    /// vertical light, roots left out, turned so the light comes from +X (for a front view).
    pub side: Option<SceneAssets>,
}

impl Experiment {
    /// Reads an experiment config (`[herbs-under-tree]`, `[lateral-light]` or
    /// `[empty-rules]`) and the L-system genome files it names, relative to it.
    pub fn load(registry: &Registry, path: &Path) -> Result<Experiment, InputError> {
        let text = read_text(path)?;
        let simulation: Simulation =
            toml::from_str(&text).map_err(|e| InputError::toml(path, &text, &e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let genomes = simulation
            .genome_files()
            .iter()
            .map(|file| {
                let file = base.join(file);
                let genome = registry.load_genome(&file)?;
                expect_model::<LSystemModel>(&file, &genome, "experiments grow")
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Experiment {
            path: path.to_owned(),
            simulation,
            genomes,
        })
    }

    /// The experiment's work at the plants' bounds; its `steps` are the garden steps
    /// [`Experiment::run`] counts.
    pub fn work(&self) -> Result<Work, InputError> {
        self.simulation
            .work(&self.genomes)
            .map_err(|e| InputError::file_error(&self.path, &e))
    }

    /// Runs the experiment on `pool`, calling `on_step` with the garden steps done.
    pub fn run(
        &self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentResult, Error> {
        let path = &self.path;
        let outcome = self
            .simulation
            .run_with(&self.genomes, pool, on_step)
            .map_err(|e| InputError::file_error(path, &e))?;
        let hint = LSystemModel.mesh_hint();
        let placed: Vec<Placed> = outcome
            .plants()
            .iter()
            .map(|p| {
                // Each plant grew in a shared world; its genome and seed regrow it alone.
                let genome = Genome::new(LSystemModel, p.genome.clone());
                let mut extras = Origin::of(&genome, 0).extras();
                extras["biomass_g"] = p.biomass.into();
                Placed {
                    translation: p.position,
                    extras: Some(extras),
                    ..Placed::new(p.label.clone(), &p.plant, hint)
                }
            })
            .collect();
        check_scene_glb(
            &placed,
            false,
            path,
            "grow smaller plants (lower `max_modules` in the genomes' `physiology`)",
        )?;
        let scene = SceneAssets::mesh(&placed, None).map_err(|e| e.in_file(path))?;
        let side = match &outcome {
            SimulationOutcome::LateralLight(o) => {
                Some(side_by_side(o).map_err(|e| e.in_file(path))?)
            }
            _ => None,
        };
        Ok(ExperimentResult {
            report: crate::report::simulation_report(&outcome),
            records_csv: records_csv(outcome.records()),
            scene,
            side,
        })
    }
}

/// Tree 1 under lateral light (left) beside tree 1 under vertical light (right), at one
/// scale, roots left out, seen across the light: both are turned so that the lateral light
/// comes from +X, the right of a front view, and set apart by their reach.
fn side_by_side(o: &LateralLightOutcome) -> Result<SceneAssets, Error> {
    let t = o.towards_light;
    let turn = Quat::from_rotation_y(t.y.atan2(t.x));
    let lateral = o.plants[0].plant.without(MaterialKind::Root);
    let vertical = o.control[0].plant.without(MaterialKind::Root);
    let reach = |p: &Plant| {
        p.segments()
            .iter()
            .map(|s| Vec2::new(s.end.x, s.end.z).length())
            .fold(0.0, f32::max)
    };
    let gap = 0.25;
    let hint = LSystemModel.mesh_hint();
    let placed = [
        ("lateral light", &lateral, -(reach(&lateral) + gap)),
        ("vertical light", &vertical, reach(&vertical) + gap),
    ]
    .map(|(name, plant, x)| Placed {
        translation: Vec3::new(x, 0.0, 0.0),
        rotation: turn,
        ..Placed::new(name, plant, hint)
    });
    SceneAssets::mesh(&placed, None)
}
