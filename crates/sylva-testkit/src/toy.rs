//! A toy fifth model, added through the model traits alone: one cylinder of a given height
//! and radius, which evolves towards a height set in its config section. Tests use it to
//! show that a model outside Sylva's four flows through every door: genome files, configs,
//! runs and their checkpoints, breeding by hand, the studio.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};
use sylva_core::Plant;
use sylva_core::glam::Vec3;
use sylva_evolve::generational::{Generational, GenerationalSettings};
use sylva_evolve::{Crossover, Fitness, Mutate, Problem};
use sylva_model::schema::{FieldSpec, Kind, Schema};
use sylva_model::{
    Bred, ConfigError, DevelopError, Evolve, FormatV1, Knobs, Model, Parent, Setup, VariationError,
    model_tag, plant_meta, two_most_dominant,
};

model_tag!(
    /// `"model": "cylinder"`.
    CylinderTag,
    "cylinder"
);

/// A cylinder's genome file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderGenome {
    /// Always `"cylinder"`.
    pub model: CylinderTag,
    /// Always 1.
    pub format: FormatV1,
    /// Height, 0.01 to 100 m.
    #[serde(deserialize_with = "height")]
    pub height: f32,
    /// Radius, 0.001 to 10 m.
    #[serde(deserialize_with = "radius")]
    pub radius: f32,
}

sylva_core::ranged!(height: f32, "height", 0.01, 100.0, " m");
sylva_core::ranged!(radius: f32, "radius", 0.001, 10.0, " m");
sylva_core::ranged!(target: f32, "target", 0.01, 100.0, " m");

/// The `[cylinder]` section: the height evolution aims for, and the files of start genomes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CylinderSettings {
    /// The height runs aim for, 0.01 to 100 m. Default 3.
    #[serde(deserialize_with = "target")]
    pub target: f32,
    /// Genome files the first generation starts from, relative to the config.
    pub start: Vec<std::path::PathBuf>,
    /// How a run breeds.
    pub breeding: GenerationalSettings,
}

impl Default for CylinderSettings {
    fn default() -> Self {
        CylinderSettings {
            target: 3.0,
            start: Vec::new(),
            breeding: GenerationalSettings::default(),
        }
    }
}

/// The cylinder model.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cylinder;

fn random_cylinder<R: Rng + ?Sized>(rng: &mut R) -> CylinderGenome {
    CylinderGenome {
        model: CylinderTag,
        format: FormatV1,
        height: rng.random_range(0.5..5.0),
        radius: rng.random_range(0.05..0.5),
    }
}

impl Model for Cylinder {
    type Genome = CylinderGenome;
    type Settings = CylinderSettings;
    const NAME: &'static str = "cylinder";
    const TITLE: &'static str = "Cylinders";

    fn develop(&self, g: &CylinderGenome, seed: u64) -> Result<Plant, DevelopError> {
        let mut plant = Plant::new(plant_meta::<Self>(g, seed));
        let top = Vec3::Y * g.height;
        plant.add_segment(
            Vec3::ZERO,
            top,
            (g.radius, g.radius),
            None,
            false,
            Plant::BARK,
        )?;
        Ok(plant)
    }

    fn hand_settings(&self, _: Knobs, base: CylinderSettings) -> CylinderSettings {
        base
    }

    fn schema(&self) -> Schema {
        let field = |path, meaning| FieldSpec::new(path, "stem", Kind::number(0.01, 10.0), meaning);
        Schema::of(vec![
            field("height", "The cylinder's height.")
                .unit(" m")
                .shaping(),
            field("radius", "The cylinder's radius.").unit(" m"),
        ])
    }

    fn random<R: Rng + ?Sized>(&self, _: &CylinderSettings, rng: &mut R) -> CylinderGenome {
        random_cylinder(rng)
    }

    fn mutate<R: Rng + ?Sized>(
        &self,
        g: &CylinderGenome,
        _: &CylinderSettings,
        rng: &mut R,
    ) -> CylinderGenome {
        let mut child = g.clone();
        Nudge.mutate(&mut child, rng);
        child
    }

    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_, CylinderGenome>],
        _: &CylinderSettings,
        _: &mut R,
    ) -> Result<Bred<CylinderGenome>, VariationError> {
        let (a, b) = two_most_dominant(parents)?;
        let genome = CylinderGenome {
            height: parents[a].genome.height,
            ..parents[b].genome.clone()
        };
        Ok(Bred {
            genome,
            parents: vec![a, b],
        })
    }
}

/// Scores a cylinder by how near its height is to the target.
#[derive(Clone, Debug)]
pub struct CylinderProblem {
    /// The height aimed for, metres.
    pub target: f32,
}

impl Problem for CylinderProblem {
    type Genome = CylinderGenome;

    fn term_names(&self) -> Vec<String> {
        vec!["height".into()]
    }

    fn evaluate(&self, g: &CylinderGenome) -> Fitness {
        let miss = -f64::from((g.height - self.target).abs());
        Fitness::new(miss, &[miss])
    }

    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> CylinderGenome {
        random_cylinder(rng)
    }
}

/// Scales the height by up to a quarter either way.
#[derive(Clone, Copy, Debug)]
pub struct Nudge;

impl Mutate<CylinderGenome> for Nudge {
    fn mutate<R: Rng + ?Sized>(&self, g: &mut CylinderGenome, rng: &mut R) {
        g.height = (g.height * rng.random_range(0.8..1.25)).clamp(0.01, 100.0);
    }
}

/// The height of one parent, the radius of the other.
#[derive(Clone, Copy, Debug)]
pub struct Swap;

impl Crossover<CylinderGenome> for Swap {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &CylinderGenome,
        b: &CylinderGenome,
        _: &mut R,
    ) -> CylinderGenome {
        CylinderGenome {
            height: a.height,
            ..b.clone()
        }
    }
}

impl Evolve for Cylinder {
    type Problem = CylinderProblem;
    type Strategy = Generational<Swap, Nudge>;

    fn start_files(&self, settings: &CylinderSettings) -> Vec<std::path::PathBuf> {
        settings.start.clone()
    }

    fn setup(
        &self,
        settings: &CylinderSettings,
        start: Vec<CylinderGenome>,
        _seed: u64,
        _population: usize,
    ) -> Result<Setup<Self>, ConfigError> {
        let strategy =
            Generational::new(Swap, Nudge, settings.breeding.clone()).map_err(|e| ConfigError {
                field: "breeding".into(),
                message: e.to_string(),
            })?;
        Ok(Setup {
            problem: CylinderProblem {
                target: settings.target,
            },
            strategy,
            first: start,
        })
    }

    fn genome_file(&self, _: &CylinderProblem, evolved: &CylinderGenome) -> CylinderGenome {
        evolved.clone()
    }
}
