//! Thornley's two-substrate transport-resistance model (Thornley 1972, 1998), as the paper
//! runs it inside each plant.
//!
//! A plant has two compartments, shoot (`s`) and root (`r`). Each holds structural biomass
//! `W` (grams) and two substrate pools, carbon `C` and minerals `N` (grams); concentrations
//! are `c = C/W` and `n = N/W`. One step (`dt = 1`) of one plant, in this order:
//!
//! 1. **Assimilation.** `C_s += ε·Λ/(1 + c_s/J_C)`, where `Λ` is the light its leaves
//!    absorbed (see [`sylva_core::environment`]), `ε` is
//!    [`photosynthesis`](Physiology::photosynthesis) and `J_C`
//!    [`carbon_inhibition`](Physiology::carbon_inhibition); `N_r += U`, the minerals its fine
//!    roots took up. A fine root of surface `a` in a soil voxel of concentration `m` asks for
//!    `u·a·m/(1 + n_r/J_N)` ([`uptake`](Physiology::uptake),
//!    [`mineral_inhibition`](Physiology::mineral_inhibition)), served in full unless the
//!    voxel is short (then every root in it is served the same fraction). The inhibition
//!    terms are Thornley's: a full pool slows its own filling, so a plant short of carbon
//!    does not hoard minerals without end (and the other way round).
//! 2. **Transport.** Carbon moves shoot → root by `(c_s - c_r)/R` and minerals root → shoot
//!    by `(n_r - n_s)/R`, with Thornley's size-scaled resistance `R = ρ·(1/W_s + 1/W_r)`
//!    ([`carbon_resistance`](Physiology::carbon_resistance),
//!    [`mineral_resistance`](Physiology::mineral_resistance)). The flux is then `1/ρ` of what
//!    would make the two concentrations equal, so `ρ ≥ 1` never overshoots and the explicit
//!    step is stable.
//! 3. **Maintenance and growth.** Each compartment first pays maintenance, `m·W` carbon
//!    from its pool (as much as the pool holds; [`maintenance`](Physiology::maintenance)),
//!    shed as litter: the paper names only "a certain loss to litter"; this is the part of
//!    it that grows with the plant (Thornley's models carry it too), and it slows a plant
//!    whose light no longer pays for its size. Then each compartment that has an apex to
//!    grow (a sink) makes `G = k·C·N/W` new biomass
//!    ([`growth_rate`](Physiology::growth_rate)), limited by its pools and by what its
//!    apexes can take, `a·Σw` ([`apex_capacity`](Physiology::apex_capacity); `w` the
//!    allocation weights of step 4), so a plant whose apexes all sit in deep shade grows
//!    slowly however rich it is. A gram of biomass holds `f_C` carbon and `f_N` minerals
//!    ([`carbon_content`](Physiology::carbon_content),
//!    [`mineral_content`](Physiology::mineral_content)); making it spends `f_C/(1-λ)`
//!    carbon, of which `λ·f_C/(1-λ)` is lost to litter
//!    ([`growth_loss`](Physiology::growth_loss)), and `f_N` minerals.
//! 4. **Allocation.** New biomass goes to the compartment's apexes (those with a rule) in
//!    proportion to `(q + q₀)^γ`, where `q` is the quality of the apex's voxel — light over
//!    the unshaded intensity for shoot apexes, mineral concentration over the soil's
//!    starting concentration for root apexes — `q₀` is
//!    [`allocation_floor`](Physiology::allocation_floor) and `γ`
//!    [`allocation_exponent`](Physiology::allocation_exponent).
//! 5. **Development.** An apex whose biomass reaches its rule's cost — `δ` times the volume
//!    of the modules its successor adds ([`module_density`](Physiology::module_density)),
//!    at least [`min_cost`](Physiology::min_cost) — is rewritten by its rule. What it holds
//!    beyond the cost is shared among the apexes the rule creates, which fire in the same
//!    step if that pays for them (see [`crate::growth`]).
//! 6. **Death.** After [`life_span`](Physiology::life_span) steps the plant dies: its carbon
//!    (pools and biomass) becomes litter at its foot, its minerals return to the soil where
//!    its roots are.
//!
//! A seed starts with a small embryo ([`seed_biomass`](Physiology::seed_biomass)) and
//! reserves ([`seed_carbon`](Physiology::seed_carbon),
//! [`seed_minerals`](Physiology::seed_minerals)), half in each compartment.
//!
//! A plant's **biomass**, as gardens record and breeding selects it, is its dry mass:
//! structure and pools, `W + C + N`. Counting the pools lets a plant that fixes carbon but
//! has nowhere yet to grow it outweigh one that does not (evolution from empty rules needs
//! that gradient).
//!
//! The defaults are calibrated for the default world (voxels of 0.125 m) and module sizes
//! of a few centimetres: the example tree (`examples/lsystem/tree.json`) forms its crown in
//! about 150 steps, the example herb completes its rosette in about 60 in full light.
//!
//! Conservation: carbon comes only from seeds and photosynthesis and ends in pools, biomass
//! (`f_C·W`) or litter; minerals come only from seeds and the soil and end in pools,
//! biomass (`f_N·W`) or back in the soil. Tests check both balances.
//!
//! Runaway growth is bounded by [`max_symbols`](Physiology::max_symbols) per compartment's
//! string and [`max_modules`](Physiology::max_modules) per plant: a rewrite that would pass
//! either is refused and counted (the garden reports it).

use serde::{Deserialize, Serialize};
use sylva_core::ranged;

/// Shoot, index 0 of the per-compartment arrays.
pub const SHOOT: usize = 0;
/// Root, index 1 of the per-compartment arrays.
pub const ROOT: usize = 1;

/// The physiological constants of a plant. All fixed, not evolved (section 3.3). Masses
/// are grams, times are steps, lengths metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Physiology {
    /// Structural mass of the seed's embryo, 1e-4 to 10 g, half shoot, half root.
    /// Default 0.02.
    #[serde(deserialize_with = "seed_biomass")]
    pub seed_biomass: f64,
    /// Carbon reserve of the seed, 0 to 100 g. Default 0.5.
    #[serde(deserialize_with = "seed_carbon")]
    pub seed_carbon: f64,
    /// Mineral reserve of the seed, 0 to 100 g. Default 0.04.
    #[serde(deserialize_with = "seed_minerals")]
    pub seed_minerals: f64,
    /// `f_C`: carbon in a gram of biomass, 0.01 to 1. Default 0.45.
    #[serde(deserialize_with = "carbon_content")]
    pub carbon_content: f64,
    /// `f_N`: minerals in a gram of biomass, 0.001 to 1. Default 0.03.
    #[serde(deserialize_with = "mineral_content")]
    pub mineral_content: f64,
    /// `ε`: carbon fixed per unit of absorbed light (one unit is a square metre of
    /// unshaded light for one step), 0 to 100 g. Default 1.
    #[serde(deserialize_with = "photosynthesis")]
    pub photosynthesis: f64,
    /// `u`: soil volume a square metre of fine-root surface draws on per step, 0 to 100 m.
    /// Default 0.02.
    #[serde(deserialize_with = "uptake")]
    pub uptake: f64,
    /// `J_C`: shoot carbon concentration (g/g) at which photosynthesis is halved,
    /// 1e-4 to 1e4. Default 0.5.
    #[serde(deserialize_with = "inhibition")]
    pub carbon_inhibition: f64,
    /// `J_N`: root mineral concentration (g/g) at which uptake is halved, 1e-4 to 1e4.
    /// Default 0.05.
    #[serde(deserialize_with = "inhibition")]
    pub mineral_inhibition: f64,
    /// `k` of `G = k·C·N/W`, 0 to 1e4 per step. Default 40.
    #[serde(deserialize_with = "growth_rate")]
    pub growth_rate: f64,
    /// `ρ` of the carbon transport resistance, 1 to 1000. Default 2.
    #[serde(deserialize_with = "resistance")]
    pub carbon_resistance: f64,
    /// `ρ` of the mineral transport resistance, 1 to 1000. Default 2.
    #[serde(deserialize_with = "resistance")]
    pub mineral_resistance: f64,
    /// `λ`: fraction of the carbon spent on growth that is lost to litter, 0 to 0.9.
    /// Default 0.25.
    #[serde(deserialize_with = "growth_loss")]
    pub growth_loss: f64,
    /// `m`: carbon a gram of biomass costs to maintain each step, paid from its
    /// compartment's carbon pool before growth and shed as litter; 0 to 1 g/g.
    /// Default 0.005.
    #[serde(deserialize_with = "maintenance")]
    pub maintenance: f64,
    /// `δ`: biomass per cubic metre of module, 1 to 1e6 g/m³. Default 200.
    #[serde(deserialize_with = "module_density")]
    pub module_density: f64,
    /// Least biomass any rewrite costs, so rules without modules are not free,
    /// 1e-5 to 100 g. Default 0.01.
    #[serde(deserialize_with = "min_cost")]
    pub min_cost: f64,
    /// Most biomass an apex of weight 1 can take in one step, 1e-4 to 1e3 g (an apex of
    /// weight `w` takes at most `w` times this). Growth in a compartment is capped at the
    /// sum over its apexes, so a plant whose apexes all sit in the dark stops growing.
    /// Default 0.5.
    #[serde(deserialize_with = "apex_capacity")]
    pub apex_capacity: f64,
    /// `γ`: how sharply allocation favours well-placed apexes, 0 to 8. Default 2.
    #[serde(deserialize_with = "allocation_exponent")]
    pub allocation_exponent: f64,
    /// `q₀`: added to every apex's quality, so apexes in the dark still get a little,
    /// 0 to 1. Default 0.05.
    #[serde(deserialize_with = "allocation_floor")]
    pub allocation_floor: f64,
    /// Steps a plant lives, 1 to 1e6. Default 1000.
    #[serde(deserialize_with = "life_span")]
    pub life_span: u32,
    /// Longest string of a compartment, 8 to 1e6 symbols. Default 20000.
    #[serde(deserialize_with = "max_symbols")]
    pub max_symbols: u32,
    /// Most modules of a plant, 1 to 1e6. Default 4000.
    #[serde(deserialize_with = "max_modules")]
    pub max_modules: u32,
}

ranged!(seed_biomass: f64, "seed_biomass", 1e-4, 10.0, " g");
ranged!(seed_carbon: f64, "seed_carbon", 0.0, 100.0, " g");
ranged!(seed_minerals: f64, "seed_minerals", 0.0, 100.0, " g");
ranged!(carbon_content: f64, "carbon_content", 0.01, 1.0, "");
ranged!(mineral_content: f64, "mineral_content", 0.001, 1.0, "");
ranged!(photosynthesis: f64, "photosynthesis", 0.0, 100.0, " g");
ranged!(uptake: f64, "uptake", 0.0, 100.0, " m");
ranged!(inhibition: f64, "inhibition", 1e-4, 1e4, " g/g");
ranged!(growth_rate: f64, "growth_rate", 0.0, 1e4, " per step");
ranged!(resistance: f64, "resistance", 1.0, 1000.0, "");
ranged!(growth_loss: f64, "growth_loss", 0.0, 0.9, "");
ranged!(maintenance: f64, "maintenance", 0.0, 1.0, " g/g");
ranged!(module_density: f64, "module_density", 1.0, 1e6, " g/m³");
ranged!(min_cost: f64, "min_cost", 1e-5, 100.0, " g");
ranged!(apex_capacity: f64, "apex_capacity", 1e-4, 1e3, " g");
ranged!(allocation_exponent: f64, "allocation_exponent", 0.0, 8.0, "");
ranged!(allocation_floor: f64, "allocation_floor", 0.0, 1.0, "");

sylva_core::ranged!(life_span: u32, "life_span", 1, 1_000_000);
sylva_core::ranged!(max_symbols: u32, "max_symbols", 8, 1_000_000);
sylva_core::ranged!(max_modules: u32, "max_modules", 1, 1_000_000);

impl Default for Physiology {
    fn default() -> Self {
        Physiology {
            seed_biomass: 0.02,
            seed_carbon: 0.5,
            seed_minerals: 0.04,
            carbon_content: 0.45,
            mineral_content: 0.03,
            photosynthesis: 1.0,
            uptake: 0.02,
            carbon_inhibition: 0.5,
            mineral_inhibition: 0.05,
            growth_rate: 40.0,
            carbon_resistance: 2.0,
            mineral_resistance: 2.0,
            growth_loss: 0.25,
            maintenance: 0.005,
            module_density: 200.0,
            min_cost: 0.01,
            apex_capacity: 0.5,
            allocation_exponent: 2.0,
            allocation_floor: 0.05,
            life_span: 1000,
            max_symbols: 20_000,
            max_modules: 4000,
        }
    }
}

/// A value of a [`Physiology`] built in code is outside its range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("physiology `{field}` is {value}, expected {min} to {max}")]
pub struct PhysiologyError {
    /// Which field.
    pub field: &'static str,
    /// Its value.
    pub value: f64,
    /// Smallest allowed.
    pub min: f64,
    /// Largest allowed.
    pub max: f64,
}

impl Physiology {
    /// True when every field has its default (genome files leave such a block out).
    pub fn is_default(&self) -> bool {
        *self == Physiology::default()
    }

    /// Checks the ranges serde checks, for values built in code.
    pub fn validate(&self) -> Result<(), PhysiologyError> {
        let fields: [(&'static str, f64, f64, f64); 22] = [
            ("seed_biomass", self.seed_biomass, 1e-4, 10.0),
            ("seed_carbon", self.seed_carbon, 0.0, 100.0),
            ("seed_minerals", self.seed_minerals, 0.0, 100.0),
            ("carbon_content", self.carbon_content, 0.01, 1.0),
            ("mineral_content", self.mineral_content, 0.001, 1.0),
            ("photosynthesis", self.photosynthesis, 0.0, 100.0),
            ("uptake", self.uptake, 0.0, 100.0),
            ("carbon_inhibition", self.carbon_inhibition, 1e-4, 1e4),
            ("mineral_inhibition", self.mineral_inhibition, 1e-4, 1e4),
            ("growth_rate", self.growth_rate, 0.0, 1e4),
            ("carbon_resistance", self.carbon_resistance, 1.0, 1000.0),
            ("mineral_resistance", self.mineral_resistance, 1.0, 1000.0),
            ("growth_loss", self.growth_loss, 0.0, 0.9),
            ("maintenance", self.maintenance, 0.0, 1.0),
            ("module_density", self.module_density, 1.0, 1e6),
            ("min_cost", self.min_cost, 1e-5, 100.0),
            ("apex_capacity", self.apex_capacity, 1e-4, 1e3),
            ("allocation_exponent", self.allocation_exponent, 0.0, 8.0),
            ("allocation_floor", self.allocation_floor, 0.0, 1.0),
            ("life_span", f64::from(self.life_span), 1.0, 1e6),
            ("max_symbols", f64::from(self.max_symbols), 8.0, 1e6),
            ("max_modules", f64::from(self.max_modules), 1.0, 1e6),
        ];
        for (field, value, min, max) in fields {
            if !(value.is_finite() && (min..=max).contains(&value)) {
                return Err(PhysiologyError {
                    field,
                    value,
                    min,
                    max,
                });
            }
        }
        Ok(())
    }

    /// The pools of a fresh seed.
    pub fn seed(&self) -> Pools {
        Pools {
            carbon: [self.seed_carbon * 0.5; 2],
            minerals: [self.seed_minerals * 0.5; 2],
            structure: [self.seed_biomass * 0.5; 2],
        }
    }

    /// Carbon a seed brings into the world (reserve and embryo).
    pub fn seed_carbon_total(&self) -> f64 {
        self.seed_carbon + self.carbon_content * self.seed_biomass
    }

    /// Minerals a seed brings into the world (reserve and embryo).
    pub fn seed_minerals_total(&self) -> f64 {
        self.seed_minerals + self.mineral_content * self.seed_biomass
    }

    /// The factor `1/(1 + n_r/J_N)` by which a full root mineral pool slows uptake.
    pub fn uptake_factor(&self, pools: &Pools) -> f64 {
        1.0 / (1.0 + pools.minerals[ROOT] / pools.structure[ROOT] / self.mineral_inhibition)
    }

    /// The allocation weight of an apex of quality `q`.
    #[inline]
    pub fn weight(&self, quality: f64) -> f64 {
        (quality.max(0.0) + self.allocation_floor).powf(self.allocation_exponent)
    }

    /// Steps 1 to 3 (assimilation, transport, growth) for one plant. `absorbed` is the
    /// light its leaves absorbed, `uptake` the minerals its roots were granted, `weights`
    /// the sum of the allocation weights of each compartment's apexes (0: no sink).
    pub fn step(&self, pools: &mut Pools, absorbed: f64, uptake: f64, weights: [f64; 2]) -> Flows {
        let inhibition =
            1.0 + pools.carbon[SHOOT] / pools.structure[SHOOT] / self.carbon_inhibition;
        let mut flows = Flows {
            photosynthesis: self.photosynthesis * absorbed.max(0.0) / inhibition,
            uptake: uptake.max(0.0),
            ..Flows::default()
        };
        pools.carbon[SHOOT] += flows.photosynthesis;
        pools.minerals[ROOT] += flows.uptake;

        // Transport: a fraction 1/ρ of the equalising exchange.
        let [ws, wr] = pools.structure;
        let equalise = |s: f64, r: f64| (s * wr - r * ws) / (ws + wr);
        let carbon = equalise(pools.carbon[SHOOT], pools.carbon[ROOT]) / self.carbon_resistance;
        pools.carbon[SHOOT] -= carbon;
        pools.carbon[ROOT] += carbon;
        let minerals =
            -equalise(pools.minerals[SHOOT], pools.minerals[ROOT]) / self.mineral_resistance;
        pools.minerals[ROOT] -= minerals;
        pools.minerals[SHOOT] += minerals;
        flows.carbon_to_root = carbon;
        flows.minerals_to_shoot = minerals;
        for x in [SHOOT, ROOT] {
            pools.carbon[x] = pools.carbon[x].max(0.0);
            pools.minerals[x] = pools.minerals[x].max(0.0);
        }

        // Maintenance, then growth.
        let carbon_per_gram = self.carbon_content / (1.0 - self.growth_loss);
        for x in [SHOOT, ROOT] {
            let upkeep = (self.maintenance * pools.structure[x]).min(pools.carbon[x]);
            pools.carbon[x] -= upkeep;
            flows.maintenance += upkeep;
            flows.litter += upkeep;
            if weights[x] <= 0.0 {
                continue;
            }
            let (c, n, w) = (pools.carbon[x], pools.minerals[x], pools.structure[x]);
            let g = (self.growth_rate * c * n / w)
                .min(c / carbon_per_gram)
                .min(n / self.mineral_content)
                .min(self.apex_capacity * weights[x])
                .max(0.0);
            let spent = g * carbon_per_gram;
            pools.carbon[x] = (c - spent).max(0.0);
            pools.minerals[x] = (n - g * self.mineral_content).max(0.0);
            pools.structure[x] = w + g;
            flows.growth[x] = g;
            flows.litter += spent - g * self.carbon_content;
        }
        flows
    }
}

/// The substrate pools and structural biomass of one plant, `[shoot, root]`, grams.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pools {
    /// Carbon pools `C`.
    pub carbon: [f64; 2],
    /// Mineral pools `N`.
    pub minerals: [f64; 2],
    /// Structural biomass `W` (modules, apex reserves, embryo).
    pub structure: [f64; 2],
}

impl Pools {
    /// Structural biomass `W_s + W_r`.
    pub fn structure_total(&self) -> f64 {
        self.structure[SHOOT] + self.structure[ROOT]
    }

    /// Dry mass: structure and the substrate pools, `W + C + N` over both compartments.
    /// This is what Sylva calls a plant's biomass.
    pub fn dry_mass(&self) -> f64 {
        self.structure_total()
            + self.carbon[SHOOT]
            + self.carbon[ROOT]
            + self.minerals[SHOOT]
            + self.minerals[ROOT]
    }

    /// All carbon held: pools and biomass.
    pub fn carbon_total(&self, p: &Physiology) -> f64 {
        self.carbon[SHOOT] + self.carbon[ROOT] + p.carbon_content * self.structure_total()
    }

    /// All minerals held: pools and biomass.
    pub fn minerals_total(&self, p: &Physiology) -> f64 {
        self.minerals[SHOOT] + self.minerals[ROOT] + p.mineral_content * self.structure_total()
    }
}

/// What one physiology step moved, grams.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flows {
    /// Carbon fixed.
    pub photosynthesis: f64,
    /// Minerals taken up.
    pub uptake: f64,
    /// Carbon moved from shoot to root (negative: root to shoot).
    pub carbon_to_root: f64,
    /// Minerals moved from root to shoot.
    pub minerals_to_shoot: f64,
    /// New biomass, `[shoot, root]`.
    pub growth: [f64; 2],
    /// Carbon spent on maintenance (part of `litter`).
    pub maintenance: f64,
    /// Carbon lost to litter by maintenance and growth.
    pub litter: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_conserves_carbon_and_minerals() {
        let p = Physiology::default();
        let mut pools = p.seed();
        let (c0, n0) = (pools.carbon_total(&p), pools.minerals_total(&p));
        let (mut fixed, mut taken, mut litter) = (0.0, 0.0, 0.0);
        for i in 0..200 {
            let f = p.step(
                &mut pools,
                0.01 * f64::from(i % 7),
                0.0005,
                [1.0, if i % 3 == 0 { 0.0 } else { 2.0 }],
            );
            fixed += f.photosynthesis;
            taken += f.uptake;
            litter += f.litter;
            let c = pools.carbon_total(&p) + litter;
            let n = pools.minerals_total(&p);
            assert!((c - c0 - fixed).abs() < 1e-9 * (1.0 + c), "carbon at {i}");
            assert!((n - n0 - taken).abs() < 1e-9 * (1.0 + n), "minerals at {i}");
            assert!(
                pools
                    .carbon
                    .iter()
                    .chain(&pools.minerals)
                    .all(|&v| v >= 0.0)
            );
        }
        assert!(
            pools.structure_total() > p.seed_biomass * 5.0,
            "it grew: {pools:?}"
        );
    }

    #[test]
    fn transport_follows_the_gradient_without_overshoot() {
        let p = Physiology {
            carbon_resistance: 1.0,
            ..Physiology::default()
        };
        let mut pools = Pools {
            carbon: [1.0, 0.0],
            minerals: [0.0, 1.0],
            structure: [1.0, 3.0],
        };
        let f = p.step(&mut pools, 0.0, 0.0, [0.0, 0.0]);
        assert!(f.carbon_to_root > 0.0 && f.minerals_to_shoot > 0.0);
        // ρ = 1 equalises carbon concentrations exactly.
        assert!((pools.carbon[0] / 1.0 - pools.carbon[1] / 3.0).abs() < 1e-12);
        // ρ = 2 goes half way for minerals.
        assert!(pools.minerals[0] / 1.0 < pools.minerals[1] / 3.0 + 1e-12);
    }

    #[test]
    fn no_sink_no_growth() {
        let p = Physiology::default();
        let mut pools = p.seed();
        let f = p.step(&mut pools, 1.0, 0.0, [0.0, 0.0]);
        assert_eq!(f.growth, [0.0, 0.0]);
        assert_eq!(pools.structure_total(), p.seed_biomass);
    }

    #[test]
    fn defaults_validate_and_read_back() {
        let p = Physiology::default();
        p.validate().unwrap();
        let json = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<Physiology>(&json).unwrap(), p);
        let e = serde_json::from_str::<Physiology>(r#"{"growth_loss": 2}"#).unwrap_err();
        assert!(e.to_string().contains("growth_loss"), "{e}");
        assert!(
            Physiology {
                carbon_resistance: 0.5,
                ..p
            }
            .validate()
            .is_err()
        );
    }
}
