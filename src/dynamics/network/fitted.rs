//! Fitted curves of a one-DOF network (`docs/model.md#fitted-curves-of-a-network`): every
//! crease's Chebyshev fit against one driving crease, their evaluation with derivatives and
//! what a run states of them. Built by [`super::reduced::reduce`]; moved on by
//! [`super::reduced::ReducedPlant`].

use crate::constraints::chebyshev::Chebyshev;
use crate::error::{NanofoldError, Result};
use serde::Serialize;

/// Trial states of an integrator step may pass the fitted domain by this fraction of its
/// width before an evaluation fails (the curves are extrapolated there); a recorded state
/// outside the domain is an error.
const DOMAIN_MARGIN: f64 = 0.1;

/// A network reduced to one driving crease by fitted curves.
#[derive(Debug, Clone)]
pub struct FittedReduction {
    /// The driver's column.
    pub driver: usize,
    /// Every column's curve against the driver (None for the driver itself).
    pub curves: Vec<Option<Chebyshev>>,
    /// The fitted range of the driver, rad.
    pub domain: [f64; 2],
    /// Σ over the creases of |f′| (largest over the domain), the driver's 1 included: how
    /// fast the creases move per unit driver rate.
    pub total_slope: f64,
    /// What a run reports of the curves.
    pub report: ReducedReport,
}

/// The fitted curves a reduced run moved on, with their errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReducedReport {
    /// The driving crease (FOLD edge index).
    pub driver_edge: usize,
    /// Chebyshev degree.
    pub degree: usize,
    /// Sweep points fitted.
    pub samples: usize,
    /// The driver's fitted range, degrees.
    pub domain_deg: [f64; 2],
    /// Largest |fit − exact sweep| over every crease and sweep point (fitted and held out), rad.
    pub max_fit_error_rad: f64,
    /// Largest vertex closure residual of the fitted curves over the domain, rad: how far
    /// the reduced model's panels are from closing their loops.
    pub curves_closure_residual_rad: f64,
    /// The balance of the reduced equation with every drive at its final angle: the
    /// driver there, rad, and the reduced equation's natural frequency about it, Hz.
    pub balance_driver_rad: f64,
    /// The same frequency, Hz.
    pub balance_frequency_hz: f64,
}

impl FittedReduction {
    /// The fold angles at driver angle q (extrapolated outside the domain).
    pub fn angles(&self, q: f64, out: &mut [f64]) {
        for (c, curve) in self.curves.iter().enumerate() {
            out[c] = curve.as_ref().map_or(q, |f| f.eval(q));
        }
    }

    /// ρ = f(q), Z = f′(q), H = f″(q); an error when q lies past the domain's margin.
    pub(crate) fn evaluate(
        &self,
        q: f64,
        angles: &mut [f64],
        slopes: &mut [f64],
        curvatures: &mut [f64],
    ) -> Result<()> {
        let [a, b] = self.domain;
        let margin = DOMAIN_MARGIN * (b - a);
        if !(q >= a - margin && q <= b + margin) {
            return Err(self.outside(q));
        }
        for (c, curve) in self.curves.iter().enumerate() {
            (angles[c], slopes[c], curvatures[c]) =
                curve.as_ref().map_or((q, 1.0, 0.0), |f| f.eval_with_derivatives(q));
        }
        Ok(())
    }

    pub(crate) fn outside(&self, q: f64) -> NanofoldError {
        NanofoldError::invalid(
            "constraint.range_deg",
            format!("[{:.4}, {:.4}]", self.report.domain_deg[0], self.report.domain_deg[1]),
            format!(
                "the driver (edge {}) reached {:.4}°, outside the fitted range: widen it",
                self.report.driver_edge,
                q.to_degrees()
            ),
        )
    }
}
