//! The runs behind the `sylva` command line.
//!
//! - [`config`]: the TOML config of `sylva evolve`, with documented defaults.
//! - [`problem`]: the binary tree as an evolution problem (Susinno's GA).
//! - [`commands`]: `evolve`, `grow` and `render`.
//! - [`assets`]: a genome grown, meshed, exported and pictured.
//! - [`report`]: `stats.csv` and `fitness.svg`.
//! - [`error`]: bad-input errors that point at file, line and column (exit code 2).
//! - [`guides`]: target surfaces and grid cells drawn beside plants in pictures.

pub mod assets;
pub mod commands;
pub mod config;
pub mod error;
pub mod genome;
pub mod guides;
pub mod problem;
pub mod report;
