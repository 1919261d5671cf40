//! The actuation law of the hinges (`docs/model.md#actuation`): a stressed layer drives its
//! hinge towards a target angle, all at once (a step) or released by an etch front
//! (a ramp θ(t) = a t / ρ_c up to the target, then held). One law for every chain.

use serde::Serialize;

/// How the hinges are released.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Actuation {
    /// τ = K θ_target from t = 0.
    Step,
    /// An etch front frees the hinges at `etch_rate` (m/s).
    Ramp {
        /// a, m/s.
        etch_rate: f64,
    },
}

/// What drives one hinge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HingeDrive {
    /// θ_target, rad (valley positive); 0 for a passive hinge.
    pub target: f64,
    /// ρ_c of the released hinge, m (needed by a ramp; infinite when passive).
    pub radius_of_curvature: f64,
    /// Whether a stressed layer drives this hinge.
    pub actuated: bool,
    /// When an etch front reaches the hinge and its ramp starts, s (0: at once, the thesis's
    /// ramp; a step ignores it).
    pub release_time: f64,
}

impl HingeDrive {
    /// A hinge nothing drives.
    pub const PASSIVE: HingeDrive = HingeDrive {
        target: 0.0,
        radius_of_curvature: f64::INFINITY,
        actuated: false,
        release_time: 0.0,
    };
}

/// The forcing of every hinge of a chain: its drive angles θ_drive(t) and the torques
/// τ = K θ_drive(t) they give.
#[derive(Debug, Clone, PartialEq)]
pub struct Forcing {
    /// Step or ramp.
    pub actuation: Actuation,
    /// One per hinge (per crease of a closed chain).
    pub hinges: Vec<HingeDrive>,
}

impl Forcing {
    /// The angle hinge i's stressed layer drives to at time t, rad.
    pub fn drive_angle(&self, i: usize, t: f64) -> f64 {
        let hinge = &self.hinges[i];
        match self.actuation {
            Actuation::Step => hinge.target,
            Actuation::Ramp { etch_rate } => {
                let released = etch_rate * (t - hinge.release_time).max(0.0) / hinge.radius_of_curvature;
                hinge.target.signum() * released.min(hinge.target.abs())
            }
        }
    }

    /// Every hinge's drive angle at time t, rad.
    pub fn drive_angles(&self, t: f64, out: &mut [f64]) {
        for (i, angle) in out.iter_mut().enumerate() {
            *angle = self.drive_angle(i, t);
        }
    }

    /// dθ_drive/dt of hinge i, rad/s: a/ρ_c (with the target's sign) while a ramp releases
    /// it, else 0.
    pub fn drive_rate(&self, i: usize, t: f64) -> f64 {
        let hinge = &self.hinges[i];
        let since = t - hinge.release_time;
        match self.actuation {
            Actuation::Ramp { etch_rate }
                if hinge.target != 0.0
                    && since >= 0.0
                    && etch_rate * since / hinge.radius_of_curvature < hinge.target.abs() =>
            {
                hinge.target.signum() * etch_rate / hinge.radius_of_curvature
            }
            _ => 0.0,
        }
    }

    /// Every hinge's drive rate at time t, rad/s.
    pub fn drive_rates(&self, t: f64, out: &mut [f64]) {
        for (i, rate) in out.iter_mut().enumerate() {
            *rate = self.drive_rate(i, t);
        }
    }

    /// The time hinge i's ramp reaches its target, s (0 for a step or a passive hinge).
    pub fn ramp_time(&self, i: usize) -> f64 {
        let hinge = &self.hinges[i];
        match self.actuation {
            Actuation::Ramp { etch_rate } if hinge.actuated && hinge.target != 0.0 => {
                hinge.release_time + hinge.radius_of_curvature * hinge.target.abs() / etch_rate
            }
            _ => 0.0,
        }
    }

    /// Times where τ(t) has a kink (a ramp starting after t = 0 or reaching its target),
    /// sorted, s.
    pub fn breakpoints(&self) -> Vec<f64> {
        let starts = self
            .hinges
            .iter()
            .filter(|h| h.actuated && h.target != 0.0 && matches!(self.actuation, Actuation::Ramp { .. }))
            .map(|h| h.release_time);
        let mut times: Vec<f64> = (0..self.hinges.len())
            .map(|i| self.ramp_time(i))
            .chain(starts)
            .filter(|&t| t > 0.0)
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// The slowest forcing time scale, s: 0 for a step, the longest ramp time t_p = ρ_c θ / a.
    pub fn duration(&self) -> f64 {
        (0..self.hinges.len()).map(|i| self.ramp_time(i)).fold(0.0, f64::max)
    }

    /// "step" or "ramp".
    pub fn kind(&self) -> &'static str {
        match self.actuation {
            Actuation::Step => "step",
            Actuation::Ramp { .. } => "ramp",
        }
    }

    /// The drive at fraction u ∈ [0, 1] of a quasi-static path that ends at `t_last`: a step
    /// jumps at t = 0⁺, so its path runs straight from 0 to the targets; a ramp follows its
    /// own law up to min(duration, t_last).
    pub fn drive_along(&self, u: f64, t_last: f64, out: &mut [f64]) {
        match self.actuation {
            Actuation::Step => {
                for (o, hinge) in out.iter_mut().zip(&self.hinges) {
                    *o = u * hinge.target;
                }
            }
            Actuation::Ramp { .. } => self.drive_angles(self.time_along(u, t_last), out),
        }
    }

    /// The time at fraction u of the quasi-static path (see [`Forcing::drive_along`]), s.
    pub fn time_along(&self, u: f64, t_last: f64) -> f64 {
        match self.actuation {
            Actuation::Step => 0.0,
            Actuation::Ramp { .. } => u * self.duration().min(t_last),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ramp_rises_at_a_over_rho_and_holds_at_its_target() {
        let forcing = Forcing {
            actuation: Actuation::Ramp { etch_rate: 2.0 },
            hinges: vec![
                HingeDrive {
                    target: -1.0,
                    radius_of_curvature: 4.0,
                    actuated: true,
                    release_time: 0.0,
                },
                HingeDrive::PASSIVE,
            ],
        };
        // θ = a t / ρ = t / 2 up to |θ| = 1 at t = 2.
        assert_eq!(forcing.drive_angle(0, 1.0), -0.5);
        assert_eq!(forcing.drive_angle(0, 3.0), -1.0);
        assert_eq!(forcing.drive_rate(0, 1.0), -0.5);
        assert_eq!(forcing.drive_rate(0, 3.0), 0.0);
        assert_eq!(forcing.drive_angle(1, 1.0), 0.0);
        assert_eq!(forcing.breakpoints(), vec![2.0]);
        assert_eq!(forcing.duration(), 2.0);
        let mut along = [0.0; 2];
        forcing.drive_along(0.5, 10.0, &mut along);
        assert_eq!(along, [-0.5, 0.0]);
        assert_eq!(forcing.time_along(0.5, 1.0), 0.5);
    }
}
