//! The unfolding solver's settings, validated when a run starts (Clarabel-style).

use super::energy::EnergyKind;
use super::qp::QpMethod;
use crate::error::{NanofoldError, Result};
use serde::Serialize;

/// Which steps a run keeps for its trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Recording {
    /// Every recorded step (memory grows with the iterations × nodes).
    Every,
    /// At most this many, evenly thinned as the run grows (the first and last kept).
    Thinned(usize),
    /// Only the start and the end.
    Ends,
}

/// Largest accepted `max_iterations` (a run's time is bounded by it).
pub const MAX_ITERATIONS_LIMIT: usize = 10_000_000;

/// Solver settings (plain data; [`UnfoldSettings::validate`] checks them and every entry
/// point calls it).
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct UnfoldSettings {
    /// Which repulsive energy.
    pub energy: EnergyKind,
    /// Exponent p in [0.5, 16]; `None` takes the energy's default (2 separable, 4
    /// non-separable).
    pub p: Option<f64>,
    /// How the direction is computed.
    pub qp: QpMethod,
    /// Flat when every fold angle is at most this, radians, in (0, 0.1].
    pub flat_tol: f64,
    /// Iterations spent past `flat_tol` polishing towards the exact flat state, until the
    /// line search is stationary (U resolves ρ only to about √ε ≈ 1e-8 there).
    pub polish_iterations: usize,
    /// Recorded steps at most, 1 ..= `MAX_ITERATIONS_LIMIT`.
    pub max_iterations: usize,
    /// Constraints are restored to this residual after every step, radians, in [1e-15, 1e-6].
    pub restore_tol: f64,
    /// Armijo sufficient-decrease constant, in (0, 0.5).
    pub armijo: f64,
    /// Largest node displacement per step, radians, in (0, π] (keeps trial steps off barriers).
    pub max_step_rad: f64,
    /// Finish with Newton onto ρ = 0 once within `flat_tol`, or when stalled within 1e-4 rad
    /// of flat; off, the line search polishes as far as it can.
    pub newton_flatten: bool,
    /// Weight κ ∈ [0, 100] of the bending metric: the direction minimises ½ yᵀ(I + SᵀS)y + ∇U·y
    /// where S takes second differences of the node displacements along the chain, scaled by
    /// √κ/ᾱ² (ᾱ the mean sector). The energy is stiff against short-wavelength bending
    /// (stiffness ~k⁴ for mode k) and soft against long-wavelength; this preconditions that
    /// spread. 0 is the plain QP (M = I) of `docs/model.md#projected-gradient`.
    pub bending_metric: f64,
    /// Restarts from perturbed states when stuck, before a verdict (at most 100).
    pub restarts: usize,
    /// Size of the restart perturbation, radians, in (0, 1].
    pub restart_kick_rad: f64,
    /// Seed of the restart kicks.
    pub seed: u64,
    /// Which steps the report's trajectory keeps.
    pub recording: Recording,
}

impl Default for UnfoldSettings {
    fn default() -> Self {
        UnfoldSettings {
            energy: EnergyKind::Separable,
            p: None,
            qp: QpMethod::Direct,
            flat_tol: 1e-6,
            polish_iterations: 500,
            max_iterations: 20_000,
            restore_tol: 1e-13,
            armijo: 1e-4,
            max_step_rad: 0.2,
            newton_flatten: true,
            bending_metric: 0.01,
            restarts: 3,
            restart_kick_rad: 0.05,
            seed: 1,
            recording: Recording::Thinned(4096),
        }
    }
}

/// `value` in [lo, hi] (finite), or an error naming `field`.
fn within(field: &str, value: f64, lo: f64, hi: f64, open_low: bool) -> Result<()> {
    let above = if open_low { value > lo } else { value >= lo };
    if value.is_finite() && above && value <= hi {
        Ok(())
    } else {
        let bracket = if open_low { "(" } else { "[" };
        Err(NanofoldError::invalid(
            field,
            value,
            format!("must lie in {bracket}{lo}, {hi}]"),
        ))
    }
}

impl UnfoldSettings {
    /// Every setting in its range; the error names the setting and its value.
    pub fn validate(&self) -> Result<()> {
        if let Some(p) = self.p {
            within("p", p, 0.5, 16.0, false)?;
        }
        within("flat_tol", self.flat_tol, 0.0, 0.1, true)?;
        if self.max_iterations == 0 || self.max_iterations > MAX_ITERATIONS_LIMIT {
            return Err(NanofoldError::invalid(
                "max_iterations",
                self.max_iterations,
                format!("must lie in 1..={MAX_ITERATIONS_LIMIT}"),
            ));
        }
        within("restore_tol", self.restore_tol, 1e-15, 1e-6, false)?;
        within("armijo", self.armijo, 0.0, 0.5, true)?;
        if self.armijo >= 0.5 {
            return Err(NanofoldError::invalid("armijo", self.armijo, "must lie in (0, 0.5)"));
        }
        within("max_step_rad", self.max_step_rad, 0.0, std::f64::consts::PI, true)?;
        within("bending_metric", self.bending_metric, 0.0, 100.0, false)?;
        if self.restarts > 100 {
            return Err(NanofoldError::invalid("restarts", self.restarts, "must be at most 100"));
        }
        within("restart_kick_rad", self.restart_kick_rad, 0.0, 1.0, true)?;
        if let Recording::Thinned(0 | 1) = self.recording {
            return Err(NanofoldError::invalid(
                "recording",
                format!("{:?}", self.recording),
                "a thinned trajectory keeps at least 2 steps (the start and the end)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_settings_are_refused_by_name() {
        let bad: [(&str, UnfoldSettings); 9] = [
            (
                "p",
                UnfoldSettings {
                    p: Some(-1.0),
                    ..Default::default()
                },
            ),
            (
                "p",
                UnfoldSettings {
                    p: Some(1e-300),
                    ..Default::default()
                },
            ),
            (
                "flat_tol",
                UnfoldSettings {
                    flat_tol: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "max_step_rad",
                UnfoldSettings {
                    max_step_rad: 0.0,
                    ..Default::default()
                },
            ),
            (
                "bending_metric",
                UnfoldSettings {
                    bending_metric: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "bending_metric",
                UnfoldSettings {
                    bending_metric: -1.0,
                    ..Default::default()
                },
            ),
            (
                "bending_metric",
                UnfoldSettings {
                    bending_metric: 1e300,
                    ..Default::default()
                },
            ),
            (
                "max_iterations",
                UnfoldSettings {
                    max_iterations: 0,
                    ..Default::default()
                },
            ),
            (
                "recording",
                UnfoldSettings {
                    recording: Recording::Thinned(1),
                    ..Default::default()
                },
            ),
        ];
        for (field, settings) in bad {
            let message = settings.validate().unwrap_err().to_string();
            assert!(message.contains(&format!("`{field}`")), "{field}: {message}");
        }
        assert!(UnfoldSettings::default().validate().is_ok());
    }
}
