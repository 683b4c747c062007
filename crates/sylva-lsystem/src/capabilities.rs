//! What the L-system offers besides growing and evolving, through `sylva_model`'s
//! capability traits: biomorph gardens ([`Biomorphs`], the design loop of [`crate::breed`])
//! and the paper's experiments ([`Experiments`], [`crate::experiments`]). The library runs
//! both for any model that offers them; the L-system's registry line says it does.

use std::error::Error;
use std::path::Path;

use sylva_core::glam::{Quat, Vec2, Vec3};
use sylva_core::par::Pool;
use sylva_core::{MaterialKind, Plant};
use sylva_model::Work;
use sylva_model::biomorphs::{self, BiomorphSettings, Biomorphs};
use sylva_model::experiments::{ExperimentOutcome, ExperimentPlant, Experiments, Posed};

use crate::breed::{BreedSettings, SpecimenStats, breeding_genomes, breeding_work};
use crate::experiments::{LateralLightOutcome, Simulation, SimulationOutcome};
use crate::garden::records_csv;
use crate::{LSystemGenome, LSystemModel};

impl From<&BiomorphSettings> for BreedSettings {
    /// The breeding garden of a biomorph loop: the paper's, with the loop's layout, light
    /// and steps.
    fn from(s: &BiomorphSettings) -> BreedSettings {
        let mut b = BreedSettings {
            children: s.children as usize,
            spacing: s.spacing,
            visible_children: s.visible_children,
            ..BreedSettings::default()
        };
        b.grow.steps = s.steps;
        b.grow.world.light.elevation = s.elevation;
        b.grow.world.light.azimuth = s.azimuth;
        b
    }
}

impl From<&SpecimenStats> for biomorphs::SpecimenStats {
    fn from(s: &SpecimenStats) -> biomorphs::SpecimenStats {
        biomorphs::SpecimenStats {
            biomass: s.biomass,
            light: s.light,
            uptake: s.uptake,
            leaves: s.leaves(),
            fine_roots: s.fine_roots(),
            germinated: s.germinated(),
            bounds: s.bounds,
        }
    }
}

/// The L-system's plants grow in biomorph gardens (section 4.1).
impl Biomorphs for LSystemModel {
    const SMALLER: &'static str = "lower `max_modules` in the mother's `physiology`";

    /// Empty rules: the paper's start, from which breeding builds a plant.
    fn first_mother(&self) -> LSystemGenome {
        LSystemGenome::empty()
    }

    fn sow(
        &self,
        mother: &LSystemGenome,
        settings: &BiomorphSettings,
        seed: u64,
    ) -> Vec<LSystemGenome> {
        let mut rng = sylva_core::rng::seeded(seed);
        breeding_genomes(mother, &settings.into(), &mut rng)
    }

    fn biomorph_work(&self, genomes: &[LSystemGenome], settings: &BiomorphSettings) -> Work {
        breeding_work(genomes, &settings.into())
    }

    fn grow_together(
        &self,
        genomes: Vec<LSystemGenome>,
        settings: &BiomorphSettings,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<Vec<biomorphs::Specimen<LSystemGenome>>, Box<dyn Error + Send + Sync>> {
        let garden = crate::breed::grow_together_with(genomes, &settings.into(), pool, on_step)?;
        Ok(garden
            .specimens
            .into_iter()
            .map(|s| biomorphs::Specimen {
                stats: (&s.stats).into(),
                genome: s.genome,
                is_mother: s.is_mother,
                position: Vec3::new(s.position.x, 0.0, s.position.y),
                plant: s.plant,
            })
            .collect())
    }
}

/// The paper's experiments (section 4): herbs under a tree, lateral light, breeding from
/// empty rules.
impl Experiments for LSystemModel {
    type Experiment = Simulation;
    const SMALLER: &'static str = "lower `max_modules` in the genomes' `physiology`";

    fn genome_files(experiment: &Simulation) -> Vec<&Path> {
        experiment.genome_files()
    }

    fn experiment_work(
        &self,
        experiment: &Simulation,
        genomes: &[LSystemGenome],
    ) -> Result<Work, Box<dyn Error + Send + Sync>> {
        Ok(experiment.work(genomes)?)
    }

    fn run_experiment(
        &self,
        experiment: &Simulation,
        genomes: &[LSystemGenome],
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentOutcome<LSystemGenome>, Box<dyn Error + Send + Sync>> {
        let outcome = experiment.run_with(genomes, pool, on_step)?;
        let plants = outcome
            .plants()
            .iter()
            .map(|p| ExperimentPlant {
                label: p.label.clone(),
                genome: p.genome.clone(),
                position: p.position,
                plant: p.plant.clone(),
                biomass: p.biomass,
            })
            .collect();
        let side = match &outcome {
            SimulationOutcome::LateralLight(o) => Some(side_by_side(o).to_vec()),
            _ => None,
        };
        Ok(ExperimentOutcome {
            report: outcome.report(),
            records_csv: records_csv(outcome.records()),
            plants,
            side,
        })
    }
}

/// Tree 1 under lateral light (left) beside tree 1 under vertical light (right), at one
/// scale, roots left out, seen across the light: both are turned so that the lateral light
/// comes from +X, the right of a front view, and set apart by their reach.
fn side_by_side(o: &LateralLightOutcome) -> [Posed; 2] {
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
    let (left, right) = (-(reach(&lateral) + gap), reach(&vertical) + gap);
    [
        ("lateral light", lateral, left),
        ("vertical light", vertical, right),
    ]
    .map(|(name, plant, x)| Posed {
        name: name.to_owned(),
        plant,
        translation: Vec3::new(x, 0.0, 0.0),
        rotation: turn,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The biomorph loop's defaults (any model's, in `sylva_model`) are the paper's
    /// breeding garden.
    #[test]
    fn biomorph_defaults_are_the_papers_breeding_garden() {
        assert_eq!(
            BreedSettings::from(&BiomorphSettings::default()),
            BreedSettings::default()
        );
    }
}
