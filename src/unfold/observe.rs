//! Observers of an unfolding run (argmin's `Observe`): the trajectory recorder, bounded or
//! thinned as [`Recording`] says, and a progress callback that either engine's run takes.

use super::settings::Recording;
use super::state::{StepKind, UnfoldState};
use crate::geometry::sphere::Vec3;
use argmin::core::observers::Observe;
use argmin::core::KV;
use serde::Serialize;
use std::sync::{Arc, Mutex};

/// One recorded step.
#[derive(Debug, Clone, Serialize)]
pub struct StepRecord {
    /// Its number among the recorded steps (0: the start).
    pub iteration: usize,
    /// What kind of step.
    pub kind: StepKind,
    /// U.
    pub energy: f64,
    /// Per user crease, file order, radians.
    pub fold_angles: Vec<f64>,
    /// Largest |γ − α|, rad.
    pub max_arc_residual: f64,
    /// ‖d‖∞ of the direction that led here (0 for the start).
    pub direction_norm: f64,
    /// The nodes.
    #[serde(skip)]
    pub nodes: Vec<Vec3>,
}

impl StepRecord {
    fn of(state: &UnfoldState, kind: StepKind) -> StepRecord {
        StepRecord {
            iteration: state.steps,
            kind,
            energy: state.energy,
            fold_angles: state.crease_angles.clone(),
            max_arc_residual: state.max_arc_residual,
            direction_norm: state.direction_norm,
            nodes: state.nodes.clone(),
        }
    }
}

/// The steps kept so far: every `stride`-th recorded step, the last one always.
#[derive(Debug, Default)]
struct Kept {
    records: Vec<StepRecord>,
    stride: usize,
    last: Option<StepRecord>,
}

/// Records the trajectory of a run. Clone it before handing it to the executor: the clones
/// share the records, which [`TrajectoryRecorder::take`] hands back after the run.
#[derive(Debug, Clone)]
pub struct TrajectoryRecorder {
    policy: Recording,
    kept: Arc<Mutex<Kept>>,
}

impl TrajectoryRecorder {
    /// A recorder keeping what `policy` says.
    pub fn new(policy: Recording) -> Self {
        TrajectoryRecorder {
            policy,
            kept: Arc::new(Mutex::new(Kept {
                records: Vec::new(),
                stride: 1,
                last: None,
            })),
        }
    }

    fn record(&self, state: &UnfoldState, kind: StepKind) {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let first = kept.records.is_empty() && kept.last.is_none();
        match self.policy {
            Recording::Every => kept.records.push(StepRecord::of(state, kind)),
            Recording::Ends => {
                if first {
                    kept.records.push(StepRecord::of(state, kind));
                } else {
                    kept.last = Some(StepRecord::of(state, kind));
                }
            }
            Recording::Thinned(max) => {
                if first || state.steps.is_multiple_of(kept.stride) {
                    kept.records.push(StepRecord::of(state, kind));
                    kept.last = None;
                    if kept.records.len() >= max {
                        // Keep every other one (the start stays) and take half as many from now on.
                        let mut index = 0;
                        kept.records.retain(|_| {
                            index += 1;
                            (index - 1) % 2 == 0
                        });
                        kept.stride *= 2;
                    }
                } else {
                    kept.last = Some(StepRecord::of(state, kind));
                }
            }
        }
    }

    /// The recorded steps, in order, the last step included.
    pub fn take(&self) -> Vec<StepRecord> {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        let mut records = std::mem::take(&mut kept.records);
        if let Some(last) = kept.last.take() {
            records.push(last);
        }
        records
    }
}

impl Observe<UnfoldState> for TrajectoryRecorder {
    fn observe_init(&mut self, _name: &str, state: &UnfoldState, _kv: &KV) -> Result<(), argmin::core::Error> {
        self.record(state, StepKind::Start);
        Ok(())
    }

    fn observe_iter(&mut self, state: &UnfoldState, _kv: &KV) -> Result<(), argmin::core::Error> {
        if let Some(kind) = state.recorded {
            self.record(state, kind);
        }
        Ok(())
    }
}

/// Told of every recorded step: (recorded steps so far, max |ρ| in rad, U).
#[derive(Clone)]
pub struct UnfoldProgress(pub Arc<dyn Fn(usize, f64, f64) + Send + Sync>);

impl std::fmt::Debug for UnfoldProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("UnfoldProgress")
    }
}

/// What [`UnfoldProgress`] reads of a run's state, whichever engine runs: (steps so far,
/// max |ρ| in rad, energy) after a step that recorded one.
pub trait ProgressOf {
    /// None after a call that recorded no step (a decision, a restart).
    fn progress(&self) -> Option<(usize, f64, f64)>;
}

impl ProgressOf for UnfoldState {
    fn progress(&self) -> Option<(usize, f64, f64)> {
        self.recorded.map(|_| (self.steps, self.max_fold_angle, self.energy))
    }
}

impl<S: ProgressOf> Observe<S> for UnfoldProgress {
    fn observe_iter(&mut self, state: &S, _kv: &KV) -> Result<(), argmin::core::Error> {
        if let Some((steps, largest, energy)) = state.progress() {
            (self.0)(steps, largest, energy);
        }
        Ok(())
    }
}
