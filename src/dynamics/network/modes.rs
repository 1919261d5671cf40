//! The folded equilibrium of a network and its modes (`docs/model.md#panel-networks`): the
//! step torques on, drag off, every lock released (a locked hinge becomes a spring at rest
//! at its lock angle, as for closed chains). The equilibrium is followed from the start
//! (from the branch a flat start leaves along) as the drive grows from 0 to its full value,
//! so it lies on the start's branch; the modes are the manifold's about it.

use super::hessian::HessianSystem;
use super::manifold::{equilibrium, modes, Equilibrium, ManifoldModes};
use super::model::NetworkModel;
use super::start::leave_flat;
use crate::error::{NumericalError, Result};

/// Continuation steps of the drive from 0 to its full value (halved where Newton fails).
const DRIVE_STEPS: usize = 20;

/// The folded equilibrium and its modes.
#[derive(Debug, Clone)]
pub struct NetworkModes {
    /// The locks released: (column, rest angle).
    pub released: Vec<(usize, f64)>,
    /// The rest angle of every hinge: the target of an actuated one, a released lock's
    /// angle, 0 for a passive one, rad.
    pub rest_angles: Vec<f64>,
    /// Where the continuation started (the start, or a flat start's branch point), rad.
    pub from: Vec<f64>,
    /// The modes (with the equilibrium).
    pub modes: ManifoldModes,
}

/// The equilibrium with every drive at its target and every lock released, on the start's
/// branch, and the modes about it.
pub fn folded_modes(model: &NetworkModel) -> Result<NetworkModes> {
    let from = match leave_flat(model)? {
        Some(branch) => branch.angles,
        None => model.start.clone(),
    };
    let mut free = model.clone();
    let released: Vec<(usize, f64)> = (0..model.columns())
        .filter(|&c| model.locked(c))
        .map(|c| (c, model.start[c]))
        .collect();
    free.folding.locked_columns.iter_mut().for_each(|l| *l = false);
    let rest: Vec<f64> = (0..model.columns())
        .map(|c| {
            if model.locked(c) {
                model.start[c]
            } else if model.forcing.hinges[c].actuated {
                model.forcing.hinges[c].target
            } else {
                0.0
            }
        })
        .collect();
    let equilibrium = follow_drive(&free, &rest, &from)?;
    Ok(NetworkModes {
        released,
        rest_angles: rest,
        from,
        modes: modes(&free, equilibrium)?,
    })
}

/// The balance at the full drive `rest`, reached from `from` by growing the actuated hinges'
/// rest angles from where they start.
pub fn follow_drive(model: &NetworkModel, rest: &[f64], from: &[f64]) -> Result<Equilibrium> {
    let mut kkt = HessianSystem::new(model)?;
    let actuated: Vec<bool> = (0..model.columns()).map(|c| model.forcing.hinges[c].actuated).collect();
    let rest_at = |u: f64| -> Vec<f64> {
        rest.iter()
            .zip(&actuated)
            .map(|(r, &a)| if a { u * r } else { *r })
            .collect()
    };
    let mut state = from.to_vec();
    let (mut u, mut step) = (0.0, 1.0 / DRIVE_STEPS as f64);
    let mut last = None;
    while u < 1.0 {
        let next = (u + step).min(1.0);
        match equilibrium(model, &rest_at(next), &state, &mut kkt) {
            Ok(found) => {
                state.clone_from(&found.angles);
                last = Some(found);
                u = next;
                step = (2.0 * step).min(1.0 / DRIVE_STEPS as f64);
            }
            Err(e) => {
                step *= 0.5;
                if step < 1e-6 {
                    return Err(NumericalError::NoEquilibrium {
                        what: "the folded equilibrium",
                        detail: format!("the balance was lost at {:.4}% of the drive: {e}", 100.0 * u),
                    }
                    .into());
                }
            }
        }
    }
    last.ok_or_else(|| {
        NumericalError::NoEquilibrium {
            what: "the folded equilibrium",
            detail: "no drive step was taken".into(),
        }
        .into()
    })
}
