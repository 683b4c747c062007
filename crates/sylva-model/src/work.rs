//! What growing plants together costs, estimated before it starts ([`Work`]): a model
//! that grows plants in a shared world (the L-system's voxel world) counts its steps and
//! nanoseconds, and a front end announces or refuses the work before the first step. How a
//! model counts is its own (the L-system's rates are in `sylva_lsystem::work`).

use sylva_core::budget::{OverTime, Seconds};

/// Estimated work of growing: the plants' share (which runs in parallel, plant by plant)
/// and the world's (serial), in nanoseconds on one core.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Work {
    /// Garden steps.
    pub steps: u64,
    /// Plants times the steps each grows.
    pub plant_steps: u64,
    /// The plants' work, nanoseconds on one core.
    pub plants_ns: f64,
    /// The world's work, nanoseconds.
    pub world_ns: f64,
    /// Most plants growing side by side (how many threads the plants' work can use).
    pub width: usize,
}

impl Work {
    /// Seconds on `threads` threads.
    pub fn seconds(&self, threads: usize) -> f64 {
        let spread = threads.clamp(1, self.width.max(1)) as f64;
        (self.world_ns + self.plants_ns / spread) / 1e9
    }

    /// This work, then `other`.
    pub fn then(self, other: Work) -> Work {
        Work {
            steps: self.steps.saturating_add(other.steps),
            plant_steps: self.plant_steps.saturating_add(other.plant_steps),
            plants_ns: self.plants_ns + other.plants_ns,
            world_ns: self.world_ns + other.world_ns,
            width: self.width.max(other.width),
        }
    }

    /// This work `n` times over.
    pub fn times(self, n: u64) -> Work {
        Work {
            steps: self.steps.saturating_mul(n),
            plant_steps: self.plant_steps.saturating_mul(n),
            plants_ns: self.plants_ns * n as f64,
            world_ns: self.world_ns * n as f64,
            width: self.width,
        }
    }

    /// Refuses this work on `threads` threads when it would take longer than the time
    /// budget ([`sylva_core::budget::check_time`]).
    pub fn check(
        &self,
        threads: usize,
        what: impl std::fmt::Display,
        advice: impl std::fmt::Display,
    ) -> Result<(), OverTime> {
        sylva_core::budget::check_time(self.seconds(threads), what, advice)
    }

    /// The estimate on `threads` threads, shown ("2.8 min").
    pub fn shown(&self, threads: usize) -> Seconds {
        Seconds(self.seconds(threads))
    }
}
