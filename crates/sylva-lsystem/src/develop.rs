//! One plant grown alone: the cost checked against the time budget before the first step
//! ([`crate::work`]), then a garden of one ([`crate::garden`]).

use sylva_core::Plant;
use sylva_core::par::Pool;
use sylva_model::DevelopError;

use crate::garden::{Garden, GardenError, GrowSettings, Sowing};
use crate::genome::LSystemGenome;
use crate::work;

impl LSystemGenome {
    /// Grows the plant alone in the default world for the default time
    /// ([`GrowSettings::default`]); `seed` is recorded in the plant (growth is
    /// deterministic).
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        self.develop_with(&GrowSettings::default(), seed)
    }

    /// Grows the plant alone with the given world and time; refused before the first step
    /// when that would take longer than the time budget ([`crate::work`]).
    pub fn develop_with(&self, settings: &GrowSettings, seed: u64) -> Result<Plant, DevelopError> {
        let sowings = vec![Sowing::new(self.clone(), sylva_core::glam::Vec2::ZERO)];
        work::garden(
            &settings.world,
            &sowings,
            settings.steps,
            work::Rules::Known,
        )
        .check(
            1,
            format_args!(
                "growing a plant {} steps, up to {}",
                settings.steps,
                work::bounds(&self.physiology)
            ),
            "lower `max_symbols` and `max_modules` in its `physiology`",
        )
        .map_err(GardenError::from)?;
        let mut garden = Garden::new(settings.world, sowings)?;
        garden.run(settings.steps, &Pool::Serial)?;
        let mut plant = garden.into_plants().swap_remove(0);
        plant.meta_mut().seed = seed;
        Ok(plant)
    }
}
