//! Fitted curves of a one-DOF network (`docs/model.md#fitted-curves-of-a-network`): every
//! other crease's Chebyshev fit against one driving crease, held as the closed chain's
//! `poly` source holds its curves ([`FittedCurves`]), placed in the network's columns, and
//! what a run states of them. Built by [`super::reduced::reduce`]; moved on by
//! [`super::reduced::ReducedPlant`].

use crate::constraints::chebyshev::FittedCurves;
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
    /// Every other column's curve against the driver, in column order (the driver's
    /// column left out), on the driver's fitted range (rad).
    pub fitted: FittedCurves,
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
    /// The fitted curve of column c (None: the driver's own column).
    fn curve_of(&self, c: usize) -> Option<usize> {
        match c.cmp(&self.driver) {
            std::cmp::Ordering::Less => Some(c),
            std::cmp::Ordering::Equal => None,
            std::cmp::Ordering::Greater => Some(c - 1),
        }
    }

    /// Every column's (ρ, Z, H) at driver angle q: the driver's own (q, 1, 0), the others'
    /// fitted (f, f′, f″), extrapolated outside the domain.
    fn column(&self, c: usize, q: f64) -> (f64, f64, f64) {
        self.curve_of(c).map_or((q, 1.0, 0.0), |k| self.fitted.at(k, q))
    }

    /// The fold angles at driver angle q (extrapolated outside the domain).
    pub fn angles(&self, q: f64, out: &mut [f64]) {
        for (c, angle) in out.iter_mut().enumerate() {
            *angle = self.column(c, q).0;
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
        let [a, b] = self.fitted.domain;
        if !self.fitted.covers(q, DOMAIN_MARGIN * (b - a)) {
            return Err(self.outside(q));
        }
        for c in 0..angles.len() {
            (angles[c], slopes[c], curvatures[c]) = self.column(c, q);
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
