//! Fabrication variation of a device (`docs/model.md#closing-a-net`): seeded samples of
//! its hinges' stiffness and residual stress, and the yield (the share that close) with its
//! exact binomial interval.

use crate::dynamics::Forcing;
use crate::error::{NanofoldError, Result};
use serde::{Deserialize, Serialize};
use statrs::distribution::{Beta, ContinuousCDF};

/// The most variation samples of one design.
pub const MAX_VARIATION_SAMPLES: usize = 10_000;
/// The widest spread, %.
pub const MAX_SPREAD_PERCENT: f64 = 30.0;
/// A sampled factor never falls below this (a Gaussian's tail past −1/spread would turn a
/// hinge's stiffness or stress negative).
const LEAST_FACTOR: f64 = 0.05;

/// How fabricated devices differ from the design: every hinge independently.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Variation {
    /// Devices sampled per design (0: the nominal device only).
    pub samples: usize,
    /// Standard deviation of each hinge's stiffness, % of its value.
    pub stiffness_spread_percent: f64,
    /// Standard deviation of each hinge's residual stress, % of its value: the stressed
    /// layer's curvature 1/ρ_c scales with it, so the angle it drives to and the ramp's rate
    /// a/ρ_c scale together.
    pub stress_spread_percent: f64,
    /// The samples' seed (sample k of a seed is the same device whatever order they run in).
    pub seed: u64,
}

impl Variation {
    /// Refuses counts and spreads out of range by name.
    pub fn validate(&self) -> Result<()> {
        if self.samples > MAX_VARIATION_SAMPLES {
            return Err(NanofoldError::invalid(
                "yield_samples",
                self.samples,
                format!("at most {MAX_VARIATION_SAMPLES}"),
            ));
        }
        for (field, value) in [
            ("stiffness_spread_percent", self.stiffness_spread_percent),
            ("stress_spread_percent", self.stress_spread_percent),
        ] {
            if !(0.0..=MAX_SPREAD_PERCENT).contains(&value) {
                return Err(NanofoldError::invalid(
                    field,
                    value,
                    format!("from 0 to {MAX_SPREAD_PERCENT} %"),
                ));
            }
        }
        Ok(())
    }

    /// This variation's draws for one design: the device population of `net` (its folds)
    /// released the `release`-th way, in draw set `set` (0: the devices a best release is
    /// chosen on; 1: fresh devices its yield is then reported from). Different designs and
    /// sets get independent draws; the same design and set, the same devices in any order.
    pub fn for_design(&self, net: &[usize], release: usize, set: u64) -> Variation {
        // FNV-1a over the design's numbers, then one splitmix64 round.
        let mut key: u64 = 0xCBF2_9CE4_8422_2325;
        for word in net.iter().map(|&f| f as u64).chain([u64::MAX, release as u64, set]) {
            for byte in word.to_le_bytes() {
                key = (key ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01B3);
            }
        }
        Variation {
            seed: Normal::new(self.seed ^ key).next_word(),
            ..*self
        }
    }

    /// Device `sample` of this variation: every hinge's stiffness times (1 + s_K z) and its
    /// drive's stress times (1 + s_σ z′), z and z′ standard normal (each factor at least
    /// 0.05).
    pub fn device(&self, forcing: &Forcing, stiffness: &[f64], sample: usize) -> (Forcing, Vec<f64>) {
        let mut normal = Normal::new(self.seed ^ (sample as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
        let (s_k, s_sigma) = (
            self.stiffness_spread_percent / 100.0,
            self.stress_spread_percent / 100.0,
        );
        let mut varied = forcing.clone();
        let mut stiffness = stiffness.to_vec();
        for (hinge, k) in varied.hinges.iter_mut().zip(stiffness.iter_mut()) {
            *k *= (1.0 + s_k * normal.draw()).max(LEAST_FACTOR);
            let stress = (1.0 + s_sigma * normal.draw()).max(LEAST_FACTOR);
            hinge.target *= stress;
            hinge.radius_of_curvature /= stress;
        }
        (varied, stiffness)
    }
}

/// Standard normal draws: splitmix64 and the Box–Muller transform.
struct Normal {
    state: u64,
    spare: Option<f64>,
}

impl Normal {
    fn new(seed: u64) -> Normal {
        Normal {
            state: seed,
            spare: None,
        }
    }

    /// splitmix64's next 64 bits.
    fn next_word(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self) -> f64 {
        // 53 random bits in (0, 1].
        ((self.next_word() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    fn draw(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u, v) = (self.uniform(), self.uniform());
        let radius = (-2.0 * u.ln()).sqrt();
        let turn = 2.0 * std::f64::consts::PI * v;
        self.spare = Some(radius * turn.sin());
        radius * turn.cos()
    }
}

/// The share of sampled devices that close.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct YieldEstimate {
    /// Devices that closed.
    pub closed: usize,
    /// Devices sampled.
    pub samples: usize,
    /// closed / samples.
    pub fraction: f64,
    /// The exact (Clopper–Pearson) 95 % interval of the fraction.
    pub interval_95: [f64; 2],
}

impl YieldEstimate {
    /// The estimate from `closed` of `samples` (at least one).
    pub fn new(closed: usize, samples: usize) -> YieldEstimate {
        YieldEstimate {
            closed,
            samples,
            fraction: closed as f64 / samples.max(1) as f64,
            interval_95: clopper_pearson(closed, samples, 0.95),
        }
    }
}

/// The Clopper–Pearson interval of a binomial fraction at `confidence`: the fractions whose
/// tails (each (1 − confidence)/2) still hold `successes` of `trials`, from the Beta
/// quantiles.
pub fn clopper_pearson(successes: usize, trials: usize, confidence: f64) -> [f64; 2] {
    if trials == 0 {
        return [0.0, 1.0];
    }
    let tail = (1.0 - confidence) / 2.0;
    let (k, n) = (successes as f64, trials as f64);
    let lower = if successes == 0 {
        0.0
    } else {
        Beta::new(k, n - k + 1.0).map_or(0.0, |b| b.inverse_cdf(tail))
    };
    let upper = if successes == trials {
        1.0
    } else {
        Beta::new(k + 1.0, n - k).map_or(1.0, |b| b.inverse_cdf(1.0 - tail))
    };
    [lower, upper]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `hinges` step drives to 1 rad with ρ_c 2.
    fn step_drives(hinges: usize) -> Forcing {
        Forcing {
            actuation: crate::dynamics::Actuation::Step,
            hinges: vec![
                crate::dynamics::HingeDrive {
                    target: 1.0,
                    radius_of_curvature: 2.0,
                    actuated: true,
                    release_time: 0.0,
                };
                hinges
            ],
        }
    }

    #[test]
    fn the_interval_holds_its_closed_forms_at_the_ends() {
        // None of n: the upper end solves (1 − p)^n = α/2; all of n: the lower p^n = α/2.
        let [lo, hi] = clopper_pearson(0, 50, 0.95);
        assert_eq!(lo, 0.0);
        assert!((hi - (1.0 - 0.025f64.powf(1.0 / 50.0))).abs() < 1e-12, "{hi}");
        let [lo, hi] = clopper_pearson(50, 50, 0.95);
        assert!((lo - 0.025f64.powf(1.0 / 50.0)).abs() < 1e-12, "{lo}");
        assert_eq!(hi, 1.0);
        // In between, each end's binomial tail is α/2: P(X ≥ k | lower) = P(X ≤ k | upper)
        // = 0.025, summed term by term.
        let (k, n) = (17usize, 40usize);
        let [lo, hi] = clopper_pearson(k, n, 0.95);
        let term = |p: f64, j: usize| {
            let ln_choose: f64 = (1..=j).map(|i| ((n - j + i) as f64 / i as f64).ln()).sum();
            (ln_choose + j as f64 * p.ln() + (n - j) as f64 * (1.0 - p).ln()).exp()
        };
        let above: f64 = (k..=n).map(|j| term(lo, j)).sum();
        let below: f64 = (0..=k).map(|j| term(hi, j)).sum();
        assert!(
            (above - 0.025).abs() < 1e-9 && (below - 0.025).abs() < 1e-9,
            "{above} {below}"
        );
    }

    #[test]
    fn sampled_factors_have_the_spread_asked_for() {
        let forcing = step_drives(4);
        let variation = Variation {
            samples: 4000,
            stiffness_spread_percent: 10.0,
            stress_spread_percent: 3.0,
            seed: 7,
        };
        let (mut k_factors, mut s_factors) = (Vec::new(), Vec::new());
        for sample in 0..variation.samples {
            let (varied, stiffness) = variation.device(&forcing, &[1.0; 4], sample);
            k_factors.extend(stiffness);
            for h in &varied.hinges {
                s_factors.push(h.target);
                assert!((h.target * h.radius_of_curvature - 2.0).abs() < 1e-12);
            }
        }
        let moments = |x: &[f64]| {
            let mean = x.iter().sum::<f64>() / x.len() as f64;
            let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
            (mean, var.sqrt())
        };
        // 16 000 draws: the mean within 4 standard errors, the deviation within 3 %.
        let (mean, sd) = moments(&k_factors);
        assert!(
            (mean - 1.0).abs() < 4.0 * 0.1 / 16000f64.sqrt() && (sd / 0.1 - 1.0).abs() < 0.03,
            "{mean} {sd}"
        );
        let (mean, sd) = moments(&s_factors);
        assert!(
            (mean - 1.0).abs() < 4.0 * 0.03 / 16000f64.sqrt() && (sd / 0.03 - 1.0).abs() < 0.03,
            "{mean} {sd}"
        );
        // The same sample is the same device.
        assert_eq!(
            variation.device(&forcing, &[1.0; 4], 9).1,
            variation.device(&forcing, &[1.0; 4], 9).1
        );
        assert!(Variation {
            stress_spread_percent: 31.0,
            ..variation
        }
        .validate()
        .is_err());
    }

    /// Designs draw independently: device k of one net and release is uncorrelated with
    /// device k of another release, another net or the fresh set, and the same design and
    /// set give the same devices.
    #[test]
    fn each_design_and_draw_set_has_its_own_devices() {
        let forcing = step_drives(5);
        let variation = Variation {
            samples: 2000,
            stiffness_spread_percent: 2.0,
            stress_spread_percent: 2.0,
            seed: 7,
        };
        let net = [1, 2, 3, 5, 8];
        let designs = [
            variation.for_design(&net, 0, 0),
            variation.for_design(&net, 1, 0),
            variation.for_design(&[1, 2, 3, 5, 9], 0, 0),
            variation.for_design(&net, 0, 1),
        ];
        let first_stiffness = |v: &Variation| -> Vec<f64> {
            (0..v.samples)
                .map(|k| v.device(&forcing, &[1.0; 5], k).1[0] - 1.0)
                .collect()
        };
        let draws: Vec<Vec<f64>> = designs.iter().map(first_stiffness).collect();
        // The correlation of device k's first hinge across designs: 2000 pairs, so
        // independent draws give |r| below 4/sqrt(2000) = 0.09 (common numbers give 1).
        let correlation = |a: &[f64], b: &[f64]| {
            let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
            dot(a, b) / (dot(a, a) * dot(b, b)).sqrt()
        };
        for i in 0..draws.len() {
            for j in 0..i {
                let r = correlation(&draws[i], &draws[j]);
                assert!(r.abs() < 0.09, "designs {i} and {j}: r = {r}");
            }
        }
        assert_eq!(variation.for_design(&net, 1, 0), designs[1]);
        assert_eq!(first_stiffness(&variation.for_design(&net, 1, 0)), draws[1]);
    }
}
