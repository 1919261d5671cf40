//! First contact (SPEC §7): a plate corner — the end of a crease line or of a free edge —
//! reaching the substrate where it is still there (z ≤ 0, y ≤ edge), or crossing the face of a
//! non-adjacent plate.
//!
//! Each candidate has a signed gap that changes sign at contact. Face gaps are the distance
//! to the other plate's plane and count only where the corner lies inside that rectangle, so
//! the caller locates sign changes itself on the solver's dense output (bisection) and checks
//! the gate at the root: a root finder that stops at the first sign change of any function
//! would let an ungated crossing hide a true contact later in the same step.

use super::{Data, Model};
use nalgebra::{Point3, Vector3};

/// What touched what.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Candidate {
    /// Corner `corner` of plate `plate` against the substrate.
    Substrate { plate: usize, corner: usize },
    /// Corner `corner` of plate `plate` against the face of plate `face`.
    Face { face: usize, plate: usize, corner: usize },
}

/// A located first contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// s.
    pub time: f64,
    /// Names of the two bodies, e.g. ["plate 2", "substrate"] (plates numbered from 0).
    pub pair: [String; 2],
    /// Contact point in the world frame, m.
    pub point: Vector3<f64>,
}

/// All contact candidates of a chain.
#[derive(Debug, Clone)]
pub struct ContactSet {
    candidates: Vec<Candidate>,
    /// Where each plate's corners start in [`Data::corners`].
    corner_start: Vec<usize>,
    substrate_edge_y: f64,
    /// Gaps within this distance count as touching, m (1e-9 of the chain's length).
    touch_tolerance: f64,
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

impl ContactSet {
    /// Every plate corner against the substrate, except corners on the anchoring hinge's
    /// line (they sit on the substrate edge by construction); every corner against the face
    /// of every plate at least two links away.
    pub fn new(model: &Model, substrate_edge_y: f64) -> Self {
        let n = model.dof();
        let chain_length: f64 = model.plates.iter().map(|p| 2.0 * p.radius()).sum();
        let touch_tolerance = 1e-9 * chain_length;
        let mut candidates = Vec::new();
        let anchor = &model.joints[0];
        for (i, plate) in model.plates.iter().enumerate() {
            for (c, corner) in plate.outline.iter().enumerate() {
                let world = plate.reference_pose * corner;
                let offset = world - anchor.point;
                let off_axis = offset - anchor.axis.into_inner() * offset.dot(&anchor.axis);
                if off_axis.norm() > touch_tolerance {
                    candidates.push(Candidate::Substrate { plate: i, corner: c });
                }
            }
        }
        for face in 0..n {
            for plate in 0..n {
                if face.abs_diff(plate) >= 2 {
                    for corner in 0..model.plates[plate].outline.len() {
                        candidates.push(Candidate::Face { face, plate, corner });
                    }
                }
            }
        }
        ContactSet {
            candidates,
            corner_start: (0..n).map(|i| model.corner_index(i, 0)).collect(),
            substrate_edge_y,
            touch_tolerance,
        }
    }

    pub fn len(&self) -> usize {
        self.candidates.len()
    }

    pub fn is_empty(&self) -> bool {
        self.candidates.is_empty()
    }

    fn corner_world(&self, data: &Data, plate: usize, corner: usize) -> Point3<f64> {
        data.corners[self.corner_start[plate] + corner]
    }

    /// Signed gap of candidate k (needs kinematics): negative means penetration.
    fn gap(&self, k: usize, data: &Data) -> f64 {
        match self.candidates[k] {
            Candidate::Substrate { plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let (dy, dz) = (p.y - self.substrate_edge_y, p.z);
                // Signed distance to the quarter-space {y ≤ edge, z ≤ 0}, minus the touch tolerance.
                let distance = if dy > 0.0 && dz > 0.0 { dy.hypot(dz) } else { dy.max(dz) };
                distance - self.touch_tolerance
            }
            Candidate::Face { face, plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let pose = &data.poses[face];
                let normal = pose.rotation * Vector3::z();
                normal.dot(&(p - pose.translation.vector).coords)
            }
        }
    }

    /// Whether a zero of candidate k's gap is a real contact (the corner lies on the face).
    fn gate(&self, k: usize, model: &Model, data: &Data) -> bool {
        match self.candidates[k] {
            Candidate::Substrate { .. } => true,
            Candidate::Face { face, plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let local = data.poses[face].inverse_transform_point(&p);
                model.plates[face].contains(&local, self.touch_tolerance)
            }
        }
    }

    /// Fills `gaps` with every candidate's signed gap at the configuration in `data`.
    pub fn gaps(&self, data: &Data, gaps: &mut [f64]) {
        for (k, gap) in gaps.iter_mut().enumerate() {
            *gap = self.gap(k, data);
        }
    }

    /// A contact already present in `data`'s configuration (e.g. at t = 0).
    pub fn touching(&self, time: f64, data: &Data) -> Option<Collision> {
        (0..self.len())
            .find(|&k| matches!(self.candidates[k], Candidate::Substrate { .. }) && self.gap(k, data) <= 0.0)
            .map(|k| self.collision(k, time, data))
    }

    fn collision(&self, k: usize, time: f64, data: &Data) -> Collision {
        let (pair, plate, corner) = match self.candidates[k] {
            Candidate::Substrate { plate, corner } => ([format!("plate {plate}"), "substrate".into()], plate, corner),
            Candidate::Face { face, plate, corner } => {
                ([format!("plate {plate}"), format!("plate {face}")], plate, corner)
            }
        };
        Collision {
            time,
            pair,
            point: self.corner_world(data, plate, corner).coords,
        }
    }

    /// An upper bound on how far any corner can be from any hinge axis upstream of it, m:
    /// the sum of the plates' diagonals. A corner moves at most this × Σ|θ̇_j|.
    pub fn lever(model: &Model) -> f64 {
        model.plates.iter().map(|p| 2.0 * p.radius()).sum()
    }
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

/// An open chain's [`ContactSet`] along a path of joint angles.
pub struct ChainProbe<'a> {
    pub contacts: &'a ContactSet,
    pub model: &'a Model,
    pub data: &'a mut Data,
    pub angles: &'a mut [f64],
    /// Joint angles at a path parameter.
    pub path: &'a mut dyn FnMut(f64, &mut [f64]),
}

impl ContactProbe for ChainProbe<'_> {
    fn count(&self) -> usize {
        self.contacts.len()
    }

    fn move_to(&mut self, t: f64) {
        (self.path)(t, self.angles);
        self.model.update_poses(self.angles, self.data);
        self.model.update_corners(self.data);
    }

    fn gap(&self, k: usize) -> f64 {
        self.contacts.gap(k, self.data)
    }

    fn gate(&self, k: usize) -> bool {
        self.contacts.gate(k, self.model, self.data)
    }

    fn collision(&self, k: usize, t: f64) -> Collision {
        self.contacts.collision(k, t, self.data)
    }
}
