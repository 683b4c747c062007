//! A separable CMA-ES (Ros and Hansen 2008): an evolution strategy that samples from a
//! Gaussian around a mean and adapts the mean, one step size and a variance per entry
//! from the samples that ranked best. The search of a CMA-ME emitter ([`crate::map`]).
//!
//! Separable means the covariance is kept diagonal: sampling and updating cost O(n) per
//! sample, and the variances adapt (n + 2) / 3 times faster than a full covariance's
//! would, which is what a few hundred generations in a space of hundreds of entries (a
//! PlantMaker genome) can use. The state is plain data, so a checkpoint holds it exactly;
//! the randomness is passed in.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

/// One evolution strategy's state, in the unit cube of a coding (entries scaled to 0..1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SepCma {
    /// The mean of the sampling distribution.
    pub mean: Vec<f64>,
    /// The overall step size.
    pub sigma: f64,
    /// The variance of each entry (the covariance's diagonal), relative to `sigma`.
    pub variances: Vec<f64>,
    /// The step size's evolution path.
    pub sigma_path: Vec<f64>,
    /// The covariance's evolution path.
    pub covariance_path: Vec<f64>,
    /// Updates since it started.
    pub updates: u32,
}

/// The strategy's learning rates, from its dimension and its samples per update.
struct Rates {
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    /// The expected length of an n-dimensional standard normal vector.
    chi_n: f64,
}

impl Rates {
    /// Hansen's defaults for `n` entries and `lambda` samples, the covariance's rates
    /// raised by (n + 2) / 3 for a diagonal one.
    fn new(n: usize, lambda: usize) -> Rates {
        let nf = n as f64;
        let mu = (lambda / 2).max(1);
        let raw: Vec<f64> = (1..=mu)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
            .collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / sum).collect();
        let mu_eff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let separable = (nf + 2.0) / 3.0;
        let c_1 = (2.0 / ((nf + 1.3).powi(2) + mu_eff) * separable).min(1.0);
        let c_mu = (2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff)
            * separable)
            .clamp(0.0, 1.0 - c_1);
        let chi_n = nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf));
        Rates {
            weights,
            mu_eff,
            c_sigma,
            d_sigma,
            c_c,
            c_1,
            c_mu,
            chi_n,
        }
    }
}

impl SepCma {
    /// A strategy around `mean` with step size `sigma` and unit variances.
    pub fn new(mean: Vec<f64>, sigma: f64) -> SepCma {
        let n = mean.len();
        SepCma {
            mean,
            sigma,
            variances: vec![1.0; n],
            sigma_path: vec![0.0; n],
            covariance_path: vec![0.0; n],
            updates: 0,
        }
    }

    /// Draws a sample: fills `z` with standard normal draws and `x` with
    /// `mean + sigma * sqrt(variances) * z`. Both must have the strategy's dimension.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R, z: &mut [f64], x: &mut [f64]) {
        fill_normal(rng, z);
        for (j, (x, z)) in x.iter_mut().zip(z.iter()).enumerate() {
            *x = self.mean[j] + self.sigma * self.variances[j].sqrt() * z;
        }
    }

    /// Moves the strategy towards its best samples: `ranked` holds the normal draws (the
    /// `z` of [`SepCma::sample`]) of all `lambda` samples of one generation, best first.
    pub fn update(&mut self, ranked: &[&[f64]]) {
        let n = self.mean.len();
        let r = Rates::new(n, ranked.len());
        let (mut y_w, mut z_w) = (vec![0.0; n], vec![0.0; n]);
        for (w, z) in r.weights.iter().zip(ranked) {
            for j in 0..n {
                z_w[j] += w * z[j];
                y_w[j] += w * self.variances[j].sqrt() * z[j];
            }
        }
        for (m, y) in self.mean.iter_mut().zip(&y_w) {
            *m += self.sigma * y;
        }
        let s = (r.c_sigma * (2.0 - r.c_sigma) * r.mu_eff).sqrt();
        for (p, z) in self.sigma_path.iter_mut().zip(&z_w) {
            *p = (1.0 - r.c_sigma) * *p + s * z;
        }
        let norm = self.sigma_path.iter().map(|p| p * p).sum::<f64>().sqrt();
        let t = f64::from(self.updates) + 1.0;
        let h_sigma = norm / (1.0 - (1.0 - r.c_sigma).powf(2.0 * t)).sqrt()
            < (1.4 + 2.0 / (n as f64 + 1.0)) * r.chi_n;
        let c = (r.c_c * (2.0 - r.c_c) * r.mu_eff).sqrt();
        for (p, y) in self.covariance_path.iter_mut().zip(&y_w) {
            *p = (1.0 - r.c_c) * *p + if h_sigma { c * y } else { 0.0 };
        }
        let stalled = if h_sigma { 0.0 } else { r.c_c * (2.0 - r.c_c) };
        for j in 0..n {
            let rank_mu: f64 = (r.weights.iter().zip(ranked))
                .map(|(w, z)| w * self.variances[j] * z[j] * z[j])
                .sum();
            let p = self.covariance_path[j];
            self.variances[j] = (1.0 - r.c_1 - r.c_mu) * self.variances[j]
                + r.c_1 * (p * p + stalled * self.variances[j])
                + r.c_mu * rank_mu;
        }
        // The exponent is capped so one lucky generation cannot blow the step up.
        self.sigma *= ((r.c_sigma / r.d_sigma) * (norm / r.chi_n - 1.0))
            .min(1.0)
            .exp();
        self.updates = self.updates.saturating_add(1);
    }

    /// Whether the strategy has collapsed or diverged, and should start again: a step too
    /// small to move, too large to mean anything, or variances too unequal to sample well.
    pub fn degenerate(&self) -> bool {
        let (lo, hi) = self
            .variances
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        !(self.sigma.is_finite() && lo.is_finite() && hi.is_finite())
            || self.mean.iter().any(|m| !m.is_finite())
            || self.sigma * hi.sqrt() < 1e-12
            || self.sigma > 1e6
            || lo <= 0.0
            || hi / lo > 1e14
    }
}

/// Fills `out` with standard normal draws (Box-Muller, two per pair of uniforms).
fn fill_normal<R: Rng + ?Sized>(rng: &mut R, out: &mut [f64]) {
    for pair in out.chunks_mut(2) {
        // 1 - u is in (0, 1], so its logarithm is finite.
        let radius = (-2.0 * (1.0 - rng.random::<f64>()).ln()).sqrt();
        let angle = std::f64::consts::TAU * rng.random::<f64>();
        pair[0] = radius * angle.cos();
        if let Some(second) = pair.get_mut(1) {
            *second = radius * angle.sin();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// Minimises the sphere function: the strategy must find its centre and shrink onto it.
    fn sphere(n: usize, generations: u32) -> SepCma {
        let mut es = SepCma::new(vec![0.8; n], 0.3);
        let lambda = 12;
        let (mut zs, mut xs) = (vec![vec![0.0; n]; lambda], vec![vec![0.0; n]; lambda]);
        for g in 0..generations {
            for k in 0..lambda {
                es.sample(&mut rng::stream(7, g, k as u32), &mut zs[k], &mut xs[k]);
            }
            let f = |x: &Vec<f64>| x.iter().map(|v| (v - 0.25).powi(2)).sum::<f64>();
            let mut order: Vec<usize> = (0..lambda).collect();
            order.sort_by(|&a, &b| f(&xs[a]).total_cmp(&f(&xs[b])));
            let ranked: Vec<&[f64]> = order.iter().map(|&k| &zs[k][..]).collect();
            es.update(&ranked);
        }
        es
    }

    #[test]
    fn it_finds_the_centre_of_a_sphere() {
        let es = sphere(20, 300);
        assert!(!es.degenerate());
        for m in &es.mean {
            assert!((m - 0.25).abs() < 1e-3, "{:?}", es.mean);
        }
        assert!(es.sigma < 0.01, "{}", es.sigma);
        assert_eq!(es, sphere(20, 300), "deterministic");
    }

    #[test]
    fn normal_draws_have_unit_variance() {
        let mut z = vec![0.0; 20_001];
        fill_normal(&mut rng::stream(1, 0, 0), &mut z);
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / z.len() as f64;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
    }

    #[test]
    fn collapse_and_blow_up_are_degenerate() {
        let mut es = SepCma::new(vec![0.5; 3], 0.1);
        assert!(!es.degenerate());
        es.sigma = 1e-13;
        assert!(es.degenerate());
        es.sigma = f64::NAN;
        assert!(es.degenerate());
        es.sigma = 0.1;
        es.variances[1] = 1e-15;
        assert!(es.degenerate());
    }
}
