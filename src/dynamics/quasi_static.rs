//! The quasi-static path of any [`Plant`] (`docs/model.md#quasi-static`): inertia dropped,
//! the hinges balance the drive at every instant. Contacts depend on the configuration only,
//! so they are located along the drive (a fraction u of the way) and mapped back to time.

use super::contact::{gaps_at, locate, Collision};
use super::plant::{Plant, Sample};
use crate::error::Result;
use std::cell::RefCell;

/// Contact scanning: largest change of a drive angle between checks, rad.
const DRIVE_STEP: f64 = 2e-3;

/// The quasi-static response.
#[derive(Debug, Clone)]
pub struct QuasiStaticPath {
    /// At the output times before the first contact, and at the contact.
    pub samples: Vec<Sample>,
    /// The first contact along the path.
    pub collision: Option<Collision>,
    /// Contact checks along the drive.
    pub scans: usize,
}

/// The quasi-static response at `output_times`, scanned for contacts.
pub fn quasi_static_path<P: Plant>(plant: &P, output_times: &[f64]) -> Result<QuasiStaticPath> {
    let forcing = plant.forcing();
    let hinges = forcing.hinges.len();
    let n = plant.dof();
    let mut ws = plant.workspace();
    let t_last = output_times.last().copied().unwrap_or(0.0);
    let mut drive = vec![0.0; hinges];
    forcing.drive_along(1.0, t_last, &mut drive);
    let largest = drive.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let scans = ((largest / DRIVE_STEP).ceil() as usize).max(1);
    let start = plant.initial_coordinates();
    // A contact in the start configuration stops the run at once.
    if let Some(c) = plant.touching(0.0, &start, &mut ws) {
        let sample = plant.sample(0.0, &start, &vec![0.0; n], &[], &mut ws)?;
        return Ok(QuasiStaticPath {
            samples: vec![sample],
            collision: Some(c),
            scans: 0,
        });
    }
    // From there the chain settles at once to the balance with no drive (a start its passive
    // hinges do not hold moves; that jump is not scanned for contacts).
    let mut settled = start.clone();
    plant.balance(&vec![0.0; hinges], &mut settled, &mut ws)?;
    // The first contact and the fraction u of the drive where it happens.
    let mut contact: Option<(f64, Collision)> = None;
    if plant.contact_count() > 0 {
        contact = plant.touching(0.0, &settled, &mut ws).map(|c| (0.0, c));
        if contact.is_none() {
            let mut solver_ws = plant.workspace();
            let warm = RefCell::new(settled.clone());
            let mut along = vec![0.0; hinges];
            let mut path = |u: f64, q: &mut [f64]| {
                forcing.drive_along(u, t_last, &mut along);
                q.copy_from_slice(&warm.borrow());
                match plant.balance(&along, q, &mut solver_ws) {
                    Ok(()) => warm.borrow_mut().copy_from_slice(q),
                    // A configuration the plant cannot reach: its gaps read as no contact.
                    Err(_) => q.iter_mut().for_each(|v| *v = f64::NAN),
                }
            };
            let mut q = settled.clone();
            let count = plant.contact_count();
            let (mut gaps, mut scratch) = (vec![0.0; count], vec![0.0; count]);
            let mut probe = plant.probe(&mut ws, &mut q, &mut path);
            gaps_at(probe.as_mut(), 0.0, &mut gaps);
            contact =
                locate(probe.as_mut(), 0.0, 1.0, f64::INFINITY, scans, &mut gaps, &mut scratch).map(|c| (c.time, c));
        }
    }
    let collision = contact.as_ref().map(|(u, c)| Collision {
        time: forcing.time_along(*u, t_last),
        ..c.clone()
    });
    let stop = collision.as_ref().map_or(f64::INFINITY, |c| c.time);
    let mut samples = Vec::new();
    let mut q = settled;
    let mut rates = vec![0.0; hinges];
    let mut q_rates = vec![0.0; n];
    let mut record = |t: f64, contact_at: Option<f64>, samples: &mut Vec<Sample>| -> Result<()> {
        match contact_at {
            Some(u) => forcing.drive_along(u, t_last, &mut drive),
            None => forcing.drive_angles(t, &mut drive),
        }
        plant.balance(&drive, &mut q, &mut ws)?;
        forcing.drive_rates(t, &mut rates);
        plant.balance_rates(&q, &drive, &rates, &mut q_rates, &mut ws)?;
        samples.push(plant.sample(t, &q, &q_rates, &[], &mut ws)?);
        Ok(())
    };
    for &t in output_times.iter().filter(|&&t| t < stop) {
        record(t, None, &mut samples)?;
    }
    if let Some((u, _)) = &contact {
        // The configuration at contact (for a step, part-way along its jump at t = 0⁺).
        record(forcing.time_along(*u, t_last), Some(*u), &mut samples)?;
    }
    plant.check_samples(&samples)?;
    Ok(QuasiStaticPath {
        samples,
        collision,
        scans,
    })
}

/// max over samples and output angles of |θ − θ_quasi-static(t)|, rad: how far a response
/// strays from the quasi-static path.
pub fn quasi_static_deviation<P: Plant>(plant: &P, samples: &[Sample]) -> Result<f64> {
    let forcing = plant.forcing();
    let mut ws = plant.workspace();
    let mut q = plant.initial_coordinates();
    let zeros = vec![0.0; plant.dof()];
    let mut drive = vec![0.0; forcing.hinges.len()];
    let mut worst: f64 = 0.0;
    for sample in samples {
        forcing.drive_angles(sample.time, &mut drive);
        plant.balance(&drive, &mut q, &mut ws)?;
        let balanced = plant.sample(sample.time, &q, &zeros, &[], &mut ws)?;
        for (a, b) in sample.angles.iter().zip(balanced.angles.iter()) {
            worst = worst.max((a - b).abs());
        }
    }
    Ok(worst)
}
