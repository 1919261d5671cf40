//! Locating the first contact along a path (`docs/model.md#contact`): a plate corner — the
//! end of a crease line or of a free edge — reaching the substrate where it is still there,
//! or crossing the face of a non-adjacent plate. Each chain lists its own candidates
//! ([`ContactProbe`]); this module finds the earliest one.
//!
//! Each candidate has a signed gap that changes sign at contact. Face gaps are the distance
//! to the other plate's plane and count only where the corner lies inside that rectangle, so
//! the caller locates sign changes itself on the solver's dense output (bisection) and checks
//! the gate at the root: a root finder that stops at the first sign change of any function
//! would let an ungated crossing hide a true contact later in the same step.

use nalgebra::Vector3;

/// A located first contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// When, s.
    pub time: f64,
    /// Names of the two bodies, e.g. ["plate 2", "substrate"] (plates numbered from 0).
    pub pair: [String; 2],
    /// Contact point in the world frame, m.
    pub point: Vector3<f64>,
}

/// Root-finding iterations to locate a contact inside one sub-interval.
const ROOT_ITERATIONS: usize = 100;

/// The Illinois variant of regula falsi on a bracket whose ends have gaps of opposite sign
/// (or a zero at the right end): returns the smallest time found with a gap of the right
/// end's sign, to within a few ulps of the time.
fn illinois(gap_at: &mut dyn FnMut(f64) -> f64, (mut lo, mut g_lo): (f64, f64), (mut hi, mut g_hi): (f64, f64)) -> f64 {
    let sign = g_lo.signum();
    let mut kept = 0i8;
    for _ in 0..ROOT_ITERATIONS {
        if g_hi == 0.0 || hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
            break;
        }
        let mut t = hi - g_hi * (hi - lo) / (g_hi - g_lo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let g = gap_at(t);
        if g != 0.0 && g.signum() == sign {
            lo = t;
            g_lo = g;
            if kept == 1 {
                g_hi *= 0.5;
            }
            kept = 1;
        } else {
            hi = t;
            g_hi = g;
            if kept == -1 {
                g_lo *= 0.5;
            }
            kept = -1;
        }
    }
    hi
}

/// What [`locate`] needs of a set of contact candidates along a path: the configuration at a
/// path parameter, every candidate's signed gap (negative means penetration), whether a zero
/// is a real contact, and the contact's description.
pub trait ContactProbe {
    /// Number of candidates.
    fn count(&self) -> usize;
    /// Moves to the configuration at path parameter t.
    fn move_to(&mut self, t: f64);
    /// Gap of candidate k at the current configuration.
    fn gap(&self, k: usize) -> f64;
    /// Whether a zero of candidate k's gap at the current configuration is a real contact.
    fn gate(&self, k: usize) -> bool;
    /// The description of candidate k touching at t.
    fn collision(&self, k: usize, t: f64) -> Collision;
}

/// Moves the probe to path parameter t and fills every candidate's gap there.
pub fn gaps_at(probe: &mut dyn ContactProbe, t: f64, gaps: &mut [f64]) {
    probe.move_to(t);
    for (k, gap) in gaps.iter_mut().enumerate() {
        *gap = probe.gap(k);
    }
}

/// The earliest contact in (t_start, t_end], bisecting (Illinois) each sign change of a gap
/// along the probe's path. The end of the interval is checked first; only if some gap is
/// within `reach` (a bound on how far two corners can move towards each other over the
/// interval; infinite to always subdivide) of zero without changing sign is the interval
/// scanned in `subdivisions` parts, so a gap that dips through zero and back within it is not
/// missed. `gaps_start` holds the gaps at t_start and is left holding those at t_end.
pub fn locate(
    probe: &mut dyn ContactProbe,
    t_start: f64,
    t_end: f64,
    reach: f64,
    subdivisions: usize,
    gaps_start: &mut [f64],
    gaps_scratch: &mut [f64],
) -> Option<Collision> {
    gaps_at(probe, t_end, gaps_scratch);
    let near = (0..probe.count()).any(|k| {
        let (g0, g1) = (gaps_start[k], gaps_scratch[k]);
        g0.signum() == g1.signum() && g0.abs().min(g1.abs()) < reach
    });
    let subdivisions = if near { subdivisions.max(1) } else { 1 };
    let mut t_left = t_start;
    for s in 1..=subdivisions {
        let t_right = t_start + (t_end - t_start) * s as f64 / subdivisions as f64;
        if subdivisions > 1 {
            gaps_at(probe, t_right, gaps_scratch);
        }
        let mut earliest: Option<(f64, usize)> = None;
        for k in 0..probe.count() {
            let (g0, g1) = (gaps_start[k], gaps_scratch[k]);
            let crosses = g0 != 0.0 && (g1 == 0.0 || g0.signum() != g1.signum());
            if !crosses {
                continue;
            }
            let mut gap_at = |t: f64| {
                probe.move_to(t);
                probe.gap(k)
            };
            let hi = illinois(&mut gap_at, (t_left, g0), (t_right, g1));
            probe.move_to(hi);
            if probe.gate(k) && earliest.is_none_or(|(t, _)| hi < t) {
                earliest = Some((hi, k));
            }
        }
        if let Some((time, k)) = earliest {
            probe.move_to(time);
            return Some(probe.collision(k, time));
        }
        gaps_start.copy_from_slice(gaps_scratch);
        t_left = t_right;
    }
    None
}
