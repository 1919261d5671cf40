//! What the integrator and the quasi-static path need of a mechanical system ([`Plant`]):
//! its generalised coordinates, their accelerations, its balance under a drive, output
//! samples and contact candidates. A strip and a closed chain are two plants.

use super::contact::{Collision, ContactProbe};
use super::forcing::Forcing;
use crate::error::Result;
use nalgebra::DVector;

/// Natural periods (over the start and the target configurations) against the forcing.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TimeScales {
    /// The fastest natural period, s.
    pub fastest_period_s: f64,
    /// The slowest natural period, s.
    pub slowest_period_s: f64,
    /// 0 for a step, the longest ramp time t_p for a ramp, s.
    pub forcing_time_s: f64,
    /// forcing_time / fastest_period.
    pub ratio: f64,
}

/// One output time.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// s.
    pub time: f64,
    /// Every hinge's angle (every crease's, for a closed chain), rad.
    pub angles: DVector<f64>,
    /// Their rates, rad/s.
    pub rates: DVector<f64>,
    /// ½ θ̇ᵀ M θ̇, J.
    pub kinetic_energy: f64,
    /// ½ Σ K θ², J.
    pub elastic_energy: f64,
    /// −τ(t)·θ, J: with the elastic energy, the potential of a constant (step) torque.
    pub actuator_potential: f64,
    /// ∫ τ(t)·θ̇ dt since the start, J: the work of the actuation, integrated with the motion
    /// (plants that track it; None otherwise and on the quasi-static path).
    pub actuation_work: Option<f64>,
    /// −∫ Q_drag·θ̇ dt since the start (≥ 0), J: the energy the air took (plants that track it).
    pub drag_dissipation: Option<f64>,
}

impl Sample {
    /// Kinetic + elastic + actuator potential: conserved for a step without drag.
    pub fn total_energy(&self) -> f64 {
        self.kinetic_energy + self.elastic_energy + self.actuator_potential
    }

    /// Kinetic + elastic − work of the actuation + drag dissipation, J: constant along any
    /// run (step or ramp, with or without air) of a plant that tracks the work and the
    /// dissipation; None otherwise.
    pub fn energy_balance(&self) -> Option<f64> {
        Some(self.kinetic_energy + self.elastic_energy - self.actuation_work? + self.drag_dissipation?)
    }
}

/// Where an integration starts: at rest at t = 0 for most plants; a plant that must leave a
/// singular start (a flat crease pattern) first may start later, already moving.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    /// s.
    pub time: f64,
    /// q.
    pub coordinates: Vec<f64>,
    /// q̇, per s.
    pub rates: Vec<f64>,
    /// Energies accumulated before `time` (as [`Plant::accumulator_rates`] orders them), J.
    pub accumulated: Vec<f64>,
    /// How the start was reached (None: at rest at t = 0).
    pub note: Option<String>,
}

/// A mechanical system the simulation drives: generalised coordinates q (the hinge angles
/// of a strip, the driving angle of a closed chain), their dynamics and statics, samples in
/// the output space (every hinge or crease) and contacts.
pub trait Plant {
    /// Scratch buffers reused across evaluations.
    type Workspace;
    /// Fresh scratch buffers.
    fn workspace(&self) -> Self::Workspace;
    /// Number of generalised coordinates.
    fn dof(&self) -> usize;
    /// The forcing of the hinges.
    fn forcing(&self) -> &Forcing;
    /// Natural periods over the start and the target against the forcing time.
    fn time_scales(&self) -> Result<TimeScales>;
    /// Linear bound on how far the dynamics can stray from the quasi-static path, rad.
    fn quasi_static_error_estimate(&self) -> Result<f64>;
    /// The slowest natural angular frequency at the start, rad/s: the integrator's time unit.
    fn slowest_omega(&self) -> Result<f64>;
    /// q at t = 0 (at rest).
    fn initial_coordinates(&self) -> Vec<f64>;
    /// Where an integration starts (default: at rest at t = 0, at the initial coordinates).
    fn initial_state(&self) -> Result<InitialState> {
        let coordinates = self.initial_coordinates();
        Ok(InitialState {
            time: 0.0,
            rates: vec![0.0; coordinates.len()],
            coordinates,
            accumulated: vec![0.0; self.accumulators()],
            note: None,
        })
    }
    /// Energies integrated along with the motion (the work of the actuation, the drag's
    /// dissipation), 0 by default.
    fn accumulators(&self) -> usize {
        0
    }
    /// An energy that scales the accumulators to O(1) for the integrator's tolerance, J.
    fn energy_scale(&self) -> f64 {
        1.0
    }
    /// The accumulators' rates (W) at the state of the last [`Plant::accelerations`] call.
    fn accumulator_rates(&self, _ws: &Self::Workspace, _out: &mut [f64]) {}
    /// Moves a state back onto the plant's constraints after an integrator step; true when
    /// it changed anything (default: nothing to do).
    fn project(&self, _t: f64, _q: &mut [f64], _q_dot: &mut [f64], _ws: &mut Self::Workspace) -> Result<bool> {
        Ok(false)
    }
    /// q̈ at (t, q, q̇), written into `out`.
    fn accelerations(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut Self::Workspace, out: &mut [f64]) -> Result<()>;
    /// An output sample at (t, q, q̇) with the accumulators' values (empty when none are
    /// tracked, as on the quasi-static path).
    fn sample(&self, t: f64, q: &[f64], q_dot: &[f64], accumulated: &[f64], ws: &mut Self::Workspace)
        -> Result<Sample>;
    /// The coordinates where the hinges balance the drive angles `drive` (inertia dropped),
    /// Newton from `q` (which it overwrites).
    fn balance(&self, drive: &[f64], q: &mut [f64], ws: &mut Self::Workspace) -> Result<()>;
    /// dq/dt along the quasi-static path at balance q, given the drive's rates.
    fn balance_rates(
        &self,
        q: &[f64],
        drive: &[f64],
        drive_rates: &[f64],
        out: &mut [f64],
        ws: &mut Self::Workspace,
    ) -> Result<()>;
    /// The drag law's switching functions at the state of the last
    /// [`Plant::accelerations`] call: each plate's normal speed, m/s (empty when the plant
    /// keeps none; `docs/model.md#drag`).
    fn switches<'w>(&self, _ws: &'w Self::Workspace) -> &'w [f64] {
        &[]
    }
    /// Holds the drag's direction on each plate at `signs` in later evaluations (None: from
    /// the motion again), so a difference of the right-hand side stays on one side of its
    /// switches.
    fn freeze_switches(&self, _ws: &mut Self::Workspace, _signs: Option<&[f64]>) {}
    /// Switching functions the integrator locates, with a jump of the state at each crossing
    /// (0: none; a sensitivity plant's).
    fn located_switches(&self) -> usize {
        0
    }
    /// The located switching functions at (t, q, q̇): each positive until its switch is
    /// crossed; the integrator locates a fall through zero, not a rise.
    fn switch_values(
        &self,
        _t: f64,
        _q: &[f64],
        _q_dot: &[f64],
        _ws: &mut Self::Workspace,
        _out: &mut [f64],
    ) -> Result<()> {
        Ok(())
    }
    /// The jump of the state where the switching functions `switched` cross zero at (t, q,
    /// q̇), applied in place.
    fn jump(
        &self,
        _t: f64,
        _q: &mut [f64],
        _q_dot: &mut [f64],
        _switched: &[usize],
        _ws: &mut Self::Workspace,
    ) -> Result<()> {
        Ok(())
    }
    /// An error when a recorded state is not a valid answer (outside a fitted domain, NaN).
    fn check_samples(&self, samples: &[Sample]) -> Result<()>;
    /// Number of contact candidates (0 when collisions are ignored).
    fn contact_count(&self) -> usize;
    /// A contact present at the configuration q (e.g. at t = 0).
    fn touching(&self, t: f64, q: &[f64], ws: &mut Self::Workspace) -> Option<Collision>;
    /// Two contact points approach each other at most this × Σ|q̇_j| (m per rad).
    fn contact_lever(&self) -> f64;
    /// The contact candidates along a path q(u) of a parameter u.
    fn probe<'a>(
        &'a self,
        ws: &'a mut Self::Workspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a>;
}
