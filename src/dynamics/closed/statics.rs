//! Statics of a closed chain (`docs/model.md#quasi-static`): inertia dropped, the hinges
//! balance the drive along the loop closure,
//!   F(q) = Σ_creases K θ(q) g(q) − K_driver θ_drive = 0,
//! one equation for the driving angle q (Newton with dF/dq = Σ K (g² + θ h), safeguarded by
//! bisection over the constraint's domain).

use super::{ClosedChain, ClosedData};
use crate::error::{NumericalError, Result};

const NEWTON_ITERATIONS: usize = 30;
const BISECTION_ITERATIONS: usize = 200;
/// |Δq| at which the equilibrium counts as found, rad.
const ANGLE_TOL: f64 = 1e-13;

impl ClosedChain {
    /// F(q) and dF/dq for a drive angle (see the module's comment), N·m and N·m/rad.
    pub fn static_torque(&self, q: f64, drive_angle: f64, ws: &mut ClosedData) -> Result<(f64, f64)> {
        self.update_creases(q, ws)?;
        let mut torque = -self.crease_stiffness[self.driver] * drive_angle;
        let mut stiffness = 0.0;
        for (c, &k) in self.crease_stiffness.iter().enumerate() {
            let (angle, g, h) = (ws.crease_angles[c], ws.crease_g[c], ws.crease_h[c]);
            torque += k * angle * g;
            stiffness += k * (g * g + angle * h);
        }
        Ok((torque, stiffness))
    }

    /// The driving angle where the hinges balance `drive_angle`: Newton from `guess`, then
    /// bisection over the constraint's domain if Newton leaves it or stalls. An error when no
    /// balance lies inside the domain.
    pub fn quasi_static_angle(&self, drive_angle: f64, guess: f64, ws: &mut ClosedData) -> Result<f64> {
        let [lo, hi] = self.source.domain();
        let mut q = guess.clamp(lo, hi);
        for _ in 0..NEWTON_ITERATIONS {
            let (torque, stiffness) = self.static_torque(q, drive_angle, ws)?;
            if stiffness.is_nan() || stiffness <= 0.0 {
                break;
            }
            let step = -torque / stiffness;
            let next = q + step;
            if !(lo..=hi).contains(&next) {
                break;
            }
            q = next;
            if step.abs() <= ANGLE_TOL * (1.0 + q.abs()) {
                return Ok(q);
            }
        }
        // Bisection on the sign of F over the domain.
        let (f_lo, _) = self.static_torque(lo, drive_angle, ws)?;
        let (f_hi, _) = self.static_torque(hi, drive_angle, ws)?;
        if f_lo.signum() == f_hi.signum() {
            return Err(NumericalError::NoEquilibrium {
                what: "closed-chain quasi-static path",
                detail: format!(
                    "no balance of the hinges inside the constraint's range [{:.3}°, {:.3}°] of {} for a drive angle of {:.3}°: widen constraint.range_deg",
                    lo.to_degrees(),
                    hi.to_degrees(),
                    self.crease_labels[self.driver],
                    drive_angle.to_degrees()
                ),
            }
            .into());
        }
        let (mut a, mut b) = (lo, hi);
        for _ in 0..BISECTION_ITERATIONS {
            let mid = 0.5 * (a + b);
            if b - a <= ANGLE_TOL {
                break;
            }
            let (f_mid, _) = self.static_torque(mid, drive_angle, ws)?;
            if f_mid.signum() == f_lo.signum() {
                a = mid;
            } else {
                b = mid;
            }
        }
        Ok(0.5 * (a + b))
    }
}
