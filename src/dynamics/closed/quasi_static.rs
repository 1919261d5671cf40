//! The quasi-static path of a closed chain (SPEC §7, "Stiffness"): inertia dropped, the hinges
//! balance the drive at every instant along the loop closure,
//!   F(q) = Σ_creases K θ(q) g(q) − K_driver θ_drive(t) = 0,
//! one equation for the driving angle q (Newton with dF/dq = Σ K (g² + θ h), safeguarded by
//! bisection over the constraint's domain). Contacts depend on the configuration only, so they
//! are located along the drive angle and mapped back to time.

use super::{ClosedChain, ClosedData, ClosedPlant};
use crate::dynamics::contact::{gaps_at, locate, Collision};
use crate::dynamics::simulate::{Plant, Sample};
use crate::error::{NanofoldError, Result};
use crate::scene::Actuation;
use std::cell::Cell;

const NEWTON_ITERATIONS: usize = 30;
const BISECTION_ITERATIONS: usize = 200;
/// |Δq| at which the equilibrium counts as found, rad.
const ANGLE_TOL: f64 = 1e-13;
/// Contact scanning: largest change of the drive angle between checks, rad.
const DRIVE_STEP: f64 = 2e-3;

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
            return Err(NanofoldError::Numerical {
                stage: "closed-chain quasi-static path".into(),
                message: format!(
                    "no balance of the hinges inside the constraint's range [{:.3}°, {:.3}°] of {} for a drive angle of {:.3}°: widen constraint.range_deg",
                    lo.to_degrees(),
                    hi.to_degrees(),
                    self.crease_labels[self.driver],
                    drive_angle.to_degrees()
                ),
            });
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

    /// max over samples and creases of |θ − θ_quasi-static(t)|, rad.
    pub fn quasi_static_deviation(&self, samples: &[Sample]) -> Result<f64> {
        let mut ws = self.workspace();
        let mut q = self.start;
        let mut worst: f64 = 0.0;
        for sample in samples {
            q = self.quasi_static_angle(self.drive_angle(sample.time), q, &mut ws)?;
            self.update_creases(q, &mut ws)?;
            for (a, b) in sample.angles.iter().zip(&ws.crease_angles) {
                worst = worst.max((a - b).abs());
            }
        }
        Ok(worst)
    }

    /// The drive's rate θ̇_drive at time t (0 for a step after t = 0), rad/s.
    fn drive_rate(&self, t: f64) -> f64 {
        match &self.actuation {
            Actuation::Step => 0.0,
            Actuation::Ramp { etch_rate, .. } if t < self.forcing_time() => {
                self.target.signum() * etch_rate / self.radius_of_curvature
            }
            Actuation::Ramp { .. } => 0.0,
        }
    }
}

/// The quasi-static response at `output_times`, scanned for contacts; also the number of
/// contact-scan subdivisions of the drive.
pub(crate) fn quasi_static_path(
    plant: &ClosedPlant,
    output_times: &[f64],
) -> Result<(Vec<Sample>, Option<Collision>, usize)> {
    let chain = plant.chain;
    let mut ws = chain.workspace();
    let t_last = *output_times.last().unwrap_or(&0.0);
    // The drive angle runs from 0 to θ_drive(t_last); a step's jump is scanned as if at t = 0⁺.
    let drive_end = chain.drive_angle(t_last);
    let time_of = |u: f64| match chain.actuation {
        Actuation::Step => 0.0,
        Actuation::Ramp { .. } => u * chain.forcing_time().min(t_last),
    };
    let subdivisions = ((drive_end.abs() / DRIVE_STEP).ceil() as usize).max(1);
    // A contact in the scene's start configuration stops the run at once.
    if let Some(c) = plant.touching(0.0, &[chain.start], &mut ws) {
        let sample = chain.sample(0.0, chain.start, 0.0, &mut ws)?;
        return Ok((vec![sample], Some(c), 0));
    }
    // From there the chain settles at once to the balance with no drive (a start its passive
    // hinges do not hold moves; that jump is not scanned for contacts).
    let start = chain.quasi_static_angle(0.0, chain.start, &mut ws)?;
    // The first contact and the fraction u of the drive where it happens.
    let mut contact: Option<(f64, Collision)> = None;
    if plant.contact_count() > 0 {
        contact = plant.touching(0.0, &[start], &mut ws).map(|c| (0.0, c));
        if contact.is_none() {
            let mut solver_ws = chain.workspace();
            let warm = Cell::new(start);
            let mut path = |u: f64, q: &mut [f64]| {
                q[0] = chain
                    .quasi_static_angle(u * drive_end, warm.get(), &mut solver_ws)
                    .unwrap_or(f64::NAN);
                if q[0].is_finite() {
                    warm.set(q[0]);
                }
            };
            let mut q = [start];
            let count = plant.contact_count();
            let (mut gaps, mut scratch) = (vec![0.0; count], vec![0.0; count]);
            let mut probe = plant.probe(&mut ws, &mut q, &mut path);
            gaps_at(probe.as_mut(), 0.0, &mut gaps);
            contact = locate(
                probe.as_mut(),
                0.0,
                1.0,
                f64::INFINITY,
                subdivisions,
                &mut gaps,
                &mut scratch,
            )
            .map(|c| (c.time, c));
        }
    }
    let collision = contact.as_ref().map(|(u, c)| Collision {
        time: time_of(*u),
        ..c.clone()
    });
    let stop = collision.as_ref().map_or(f64::INFINITY, |c| c.time);
    let mut samples = Vec::new();
    let mut q = start;
    let mut record = |t: f64, contact_drive: Option<f64>, samples: &mut Vec<Sample>| -> Result<()> {
        let drive = contact_drive.unwrap_or_else(|| chain.drive_angle(t));
        q = chain.quasi_static_angle(drive, q, &mut ws)?;
        let (_, stiffness) = chain.static_torque(q, drive, &mut ws)?;
        let rate = chain.crease_stiffness[chain.driver] * chain.drive_rate(t) / stiffness;
        samples.push(chain.sample(t, q, rate, &mut ws)?);
        Ok(())
    };
    for &t in output_times.iter().filter(|&&t| t < stop) {
        record(t, None, &mut samples)?;
    }
    if let Some((u, _)) = &contact {
        // The configuration at contact (for a step, part-way along its jump at t = 0⁺).
        record(time_of(*u), Some(u * drive_end), &mut samples)?;
    }
    chain.check_samples(&samples)?;
    Ok((samples, collision, subdivisions))
}
