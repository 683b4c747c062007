//! Experiments, a capability a model may offer ([`Experiments`]): a config names genome
//! files and how to grow them (the L-system's herbs under a tree, lateral light, breeding
//! from empty rules), and the model hands back what it measured and grew. The library's
//! `experiment` module reads the config, estimates the work, runs it and meshes the plants,
//! for whichever model says, in its registry line, that it offers this.

use std::error::Error;
use std::path::Path;

use serde::de::DeserializeOwned;
use sylva_core::Plant;
use sylva_core::glam::{Quat, Vec3};
use sylva_core::par::Pool;

use crate::{Model, Work};

/// A plant an experiment grew, where it grew.
#[derive(Clone, Debug)]
pub struct ExperimentPlant<G> {
    /// Its name in the scene.
    pub label: String,
    /// Its genome (with its seed, it grows the plant alone again).
    pub genome: G,
    /// Where its foot stood, metres.
    pub position: Vec3,
    /// Its geometry, foot at the origin.
    pub plant: Plant,
    /// Its biomass at the end, grams.
    pub biomass: f64,
}

/// A plant set in a scene for a picture: turned by `rotation`, then moved by `translation`.
#[derive(Clone, Debug)]
pub struct Posed {
    /// Its name in the scene.
    pub name: String,
    /// Its geometry, foot at the origin.
    pub plant: Plant,
    /// Where its foot stands, metres.
    pub translation: Vec3,
    /// Its turn.
    pub rotation: Quat,
}

/// What an experiment measured and grew.
#[derive(Clone, Debug)]
pub struct ExperimentOutcome<G> {
    /// `report.txt`: the measured outcome, one figure a line.
    pub report: String,
    /// `records.csv`: per plant and step records.
    pub records_csv: String,
    /// The plants, where they grew.
    pub plants: Vec<ExperimentPlant<G>>,
    /// Plants to be seen side by side, when the experiment compares some (the L-system's
    /// tree under lateral light beside the same tree under vertical light).
    pub side: Option<Vec<Posed>>,
}

/// A model that runs experiments from config files. It says so in its registry line
/// (`ModelEntry::of::<M>().with_experiments()`), and the library's experiment module finds
/// it there.
pub trait Experiments: Model {
    /// An experiment config, as its TOML file reads.
    type Experiment: DeserializeOwned + Send + Sync + 'static;

    /// What a person changes to grow smaller plants, when an experiment's scene is too
    /// large to write (said in the error, after "grow smaller plants").
    const SMALLER: &'static str;

    /// The genome files `experiment` names, relative to its config, in the order
    /// [`Experiments::run_experiment`] takes their genomes.
    fn genome_files(experiment: &Self::Experiment) -> Vec<&Path>;

    /// The experiment's work at the plants' bounds, before it starts.
    fn experiment_work(
        &self,
        experiment: &Self::Experiment,
        genomes: &[Self::Genome],
    ) -> Result<Work, Box<dyn Error + Send + Sync>>;

    /// Runs the experiment on `pool`, calling `on_step` with the steps done.
    fn run_experiment(
        &self,
        experiment: &Self::Experiment,
        genomes: &[Self::Genome],
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<ExperimentOutcome<Self::Genome>, Box<dyn Error + Send + Sync>>;
}
