//! Whether a net's device closes (`docs/model.md#closing-a-net`): its quasi-static folding
//! carried through contact by mechanics. At every instant the device rests at the minimum
//! of its hinge energy with the latched seams closed and touching faces apart (their
//! contact forces the multipliers); a seam latches where its faces meet within the
//! capture, or where its ends come closest within it. It ends when every seam is shut (`closes`), when the drives are spent with
//! faces held apart by contact forces (`jams`) or free (`stalls`), or where the balance
//! jumps (`snaps`).

use super::algorithms::update_poses;
use super::contact_balance::{solve_step, BalanceStep, FrictionRows};
use super::face_contact::{FaceContacts, Feature, FeatureState, PlacedFaces};
use super::{NetworkData, NetworkModel};
use crate::dynamics::Forcing;
use crate::error::{NanofoldError, Result};
use crate::pattern::net::NetPattern;
use nalgebra::{DMatrix, DVector, Vector3};
use serde::{Deserialize, Serialize};

/// The most any drive angle moves between two tests of the faces while contacts are held,
/// rad (0.5°): a meeting that begins and ends inside a smaller turn is not seen.
const MAX_STEP: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// The largest step while no contact is held, rad (2°): the balance is then the drives
/// (or their projection on the latched seams), crossings and a seam's closest approach
/// are located wherever the steps fall, and the step only says how finely a crossing is
/// watched for.
const FREE_STEP: f64 = 2.0 * std::f64::consts::PI / 180.0;
/// A step is halved down to this turn, rad, before a jump of the balance is called a snap.
const MIN_TURN: f64 = 1e-9;
/// A step whose balance is not found is halved at most this many times in a row.
const UNSETTLED_HALVINGS: usize = 10;
/// A balance that moves more than this many times its drives' turn (plus the floor, rad)
/// in one step has jumped.
const JUMP_RATIO: f64 = 20.0;
const JUMP_FLOOR: f64 = 1e-6;
/// A seam whose ends lie this close (a fraction of its length) has met edge to edge.
const ALIGNED: f64 = 1e-9;
/// Seams meeting together: within this of aligned at an event, they latch with it.
const ALIGNED_TOGETHER: f64 = 1e-6;
/// Faces are tested for meeting to this fraction of the net's size.
const TOLERANCE: f64 = 1e-9;
/// Pairs of faces closer than this (a fraction of the size; their bounding spheres' gap)
/// have their contact features followed.
const REACH: f64 = 0.05;
/// A contact with no force this far apart (a fraction of the size) has parted.
const PART: f64 = 1e-7;
/// Faces are held by contact when the balance without it moves a fold angle by more than
/// this, rad.
const HELD_MOVE: f64 = 1e-6;
/// A sample's rates difference the balance over this turn of the drives either side, rad
/// (its truncation error near 1e-8 of the rate, the balances' own about 1e-6).
const RATE_TURN: f64 = 1e-4;
/// The most progress differenced (where the drives barely move).
const RATE_PROGRESS: f64 = 1e-5;
/// Bisection of an event's progress stops at this width.
const LOCATE: f64 = 1e-15;
/// A run's frames are kept at least this far apart in progress (and at every event).
const FRAME_SPACING: f64 = 0.005;
/// The latched seams' equilibrium: Gauss–Newton steps and the step that ends them, rad.
const SETTLE_ITERATIONS: usize = 200;
const SETTLE_STEP: f64 = 1e-13;
/// With contacts: the QPs of one balance, and the step that ends them, rad.
const CONTACT_ITERATIONS: usize = 100;
/// A balance with contacts not found in this many QP solves (iterations and their shares)
/// is not found: constraints that the shares only creep towards do not hold together.
const SETTLE_SOLVES: usize = 300;
/// A run's QP solves in all: past these (a balance creeping along a contact at the rounding
/// floor) it stops as undecided, so a study's time is bounded (about 0.5 s a run).
const RUN_SOLVES: usize = 50_000;
/// A balance along contacts has converged once its step is below this (rad: a point moved
/// by 1e-10 of the size, a tenth of the contact slack; the hinge torques then balance to
/// about 1e-9 of a torque a drive asks). The held step's own rounding leaves steps near
/// 1e-11, so a stricter bound would only count iterations at that floor.
const CONTACT_STEP: f64 = 1e-10;
/// A balance whose steps stay below this (rad, a point moved by about 1e-8 of the size) for
/// [`FLOOR_ITERATIONS`] in a row has reached its rounding floor: contacts that nearly
/// oppose (a face pinched between two) carry forces whose rows cancel, and the step
/// wanders at the floor that leaves.
const FLOOR_STEP: f64 = 1e-8;
const FLOOR_ITERATIONS: usize = 10;
/// With friction: balances on lagged normal forces repeated at most this many times, until
/// the forces agree with those their friction was bounded by to this share of the largest.
const FRICTION_ROUNDS: usize = 30;
const FRICTION_AGREED: f64 = 1e-8;
/// Aitken's extrapolation of the rounds is trusted for change ratios below this.
const AITKEN_LARGEST: f64 = 0.995;
/// A contact may sit this share of the tolerance deep.
const CONTACT_SLACK: f64 = 0.1;
/// A settled balance's contacts hold to this many times their slack.
const LANDED_SLACK: f64 = 1.5;
/// Events closer than this in progress are the same event come back.
const REPEATED_EVENT: f64 = 1e-12;
/// How many times an event may come back before the run stops.
const MAX_REPEATS: usize = 20;
/// Rows of one pair of faces this near parallel (1 − cosine) are one contact.
const PARALLEL_ROWS: f64 = 1e-6;
/// The smallest share of a closure's or a contact's residual one step asks for.
const MIN_SHARE: f64 = 1e-6;
/// The turn of a fold angle by which the contacts' curvature is differenced, rad.
const CURVATURE_STEP: f64 = 1e-6;
/// The weight of a held row's square added across it to K + W, over the stiffest hinge's
/// and the curvature's softest share.
const ACROSS_WEIGHT: f64 = 100.0;
/// K + W of a step is kept at least this share of K (a softer balance is stepped as this
/// stiff): below zero the balance is unstable.
const STABILITY_FLOOR: f64 = 1e-3;
/// Iterations in a row found unstable along the contacts before a balance is given up as
/// passed a snap-through.
const UNSTABLE_ITERATIONS: usize = 3;
/// A contact row that misses its feature's move over a step by more than this share of
/// the rows' moves narrows the trust box to [`TRUST_NARROWING`] of that step.
const TRUST_MISS: f64 = 0.5;
const TRUST_NARROWING: f64 = 0.25;
/// Steps turning back on the last, in a row, that halve the step taken again.
/// A step at most this share of the last is converging, not turning back.
const CONVERGING: f64 = 0.1;
const MAX_TURNS: usize = 30;
/// Rounds of contacts and latches at one instant before the run says it cannot settle.
const RESOLVE_ROUNDS: usize = 50;
/// JᵀJ's eigenvalues below this share of its largest are zero (singular values below 1e-6
/// of J's largest).
const RANK_CUT: f64 = 1e-12;
/// At a singular state the balance's steps stop shrinking: held rows and steps below this
/// (rad) are accepted.
const SINGULAR_STEP: f64 = 1e-4;
/// The held rows' rank is read once their residual is below this.
const RANK_READ: f64 = 1e-6;
/// A latched seam's rows: a hinge's five.
const SEAM_ROWS: usize = 5;
/// Seams are watched for their closest approach within this many captures: a step would
/// have to carry a seam's ends across a whole capture to pass one unseen (some 6° of turn
/// a seam's length from its hinge at the default capture, twelve of the largest steps).
const NEAR_CAPTURE: f64 = 2.0;
/// The least rate at which a seam's ends approach or recede that says which they do, a
/// fraction of its length times their offsets and the fastest fold rate: below it (a seam
/// at rest, rounding) the last direction holds.
const SEAM_MOVE: f64 = 1e-9;
/// The rows count as held below this (over the net's size).
const SETTLE_HELD: f64 = 1e-10;
/// The largest turn of one settling step, rad.
const SETTLE_DAMPING: f64 = 0.3;

/// How seams latch and faces touch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClosingSettings {
    /// A seam latches when its faces meet with its two edges' ends at most this far apart,
    /// or where its ends come closest if that is this near, in % of the seam's length
    /// (above 0, at most 50): the solder or adhesive on the seam pulls them into line.
    /// Faces that meet farther apart jam.
    pub capture_percent: f64,
    /// Coulomb's coefficient of friction between touching faces (0: frictionless, the
    /// default; at most 10).
    pub friction_coefficient: f64,
}

impl Default for ClosingSettings {
    fn default() -> Self {
        ClosingSettings {
            capture_percent: 10.0,
            friction_coefficient: 0.0,
        }
    }
}

impl ClosingSettings {
    /// Refuses a capture out of range by name.
    pub fn validate(&self) -> Result<()> {
        if !(self.capture_percent > 0.0 && self.capture_percent <= 50.0) {
            return Err(NanofoldError::invalid(
                "capture_percent",
                self.capture_percent,
                "a share of the seam's length above 0 and at most 50 %",
            ));
        }
        if !(0.0..=10.0).contains(&self.friction_coefficient) {
            return Err(NanofoldError::invalid(
                "friction_coefficient",
                self.friction_coefficient,
                "Coulomb's coefficient between faces: from 0 (frictionless) to 10",
            ));
        }
        Ok(())
    }
}

/// How a closing run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Every seam latched.
    Closes,
    /// The drives reached their targets with seams open and faces held apart from closing
    /// by contact forces.
    Jams,
    /// The drives reached their targets with seams open and no contact holding them.
    Stalls,
    /// The balance jumped (the path lost its stability): a quasi-static run cannot follow a
    /// snap-through, so it stops there and says when.
    Snaps,
    /// No balance was found with the latched seams held (a singular state of their
    /// closures): the run stops there and says why; it does not count as closing.
    Undecided,
    /// A sheet with no seams to close reached the end of its drives with nothing holding
    /// it (a scene's tree of panels without `seams`; never a net's).
    Rests,
}

impl Outcome {
    /// The outcome's name in reports.
    pub fn label(self) -> &'static str {
        match self {
            Outcome::Closes => "closes",
            Outcome::Jams => "jams",
            Outcome::Stalls => "stalls",
            Outcome::Snaps => "snaps",
            Outcome::Undecided => "undecided",
            Outcome::Rests => "rests",
        }
    }
}

/// A seam latching.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Latch {
    /// The seam (its index in the net's `nanofold:seams`).
    pub seam: usize,
    /// Its two faces (FOLD face indices).
    pub faces: [usize; 2],
    /// When, s (0 for a step, whose path is followed at t = 0⁺).
    pub time_s: f64,
    /// How far along the drives' path (0 to 1).
    pub progress: f64,
    /// How far apart its edges' ends were, a fraction of its length.
    pub misalignment: f64,
}

/// Two faces coming into contact: from then on the balance keeps them apart with a force.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// The two faces (FOLD face indices): the first pushed along the normal.
    pub faces: [usize; 2],
    /// What touches: "corner on face" or "edge on edge".
    pub feature: &'static str,
    /// When, s.
    pub time_s: f64,
    /// How far along the drives' path.
    pub progress: f64,
    /// Where, µm.
    pub point_um: [f64; 3],
}

/// A contact force at the end of a run (or where it stopped).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactForce {
    /// The two faces (FOLD face indices): the force pushes the first along the normal and
    /// the second against it.
    pub faces: [usize; 2],
    /// What touches: "corner on face" or "edge on edge".
    pub feature: &'static str,
    /// The point of touch on the first face, µm.
    pub point_um: [f64; 3],
    /// The unit normal from the second face towards the first.
    pub normal: [f64; 3],
    /// How far apart the two faces are along the normal there, µm (≥ 0 up to the solver's
    /// tolerance).
    pub gap_um: f64,
    /// The force, N (≥ 0).
    pub force_n: f64,
    /// The friction across the normal on the first face, N (at most the coefficient times
    /// the force; 0 without friction).
    pub friction_n: [f64; 3],
}

/// A latched seam's force at one end, on its first face (its second feels the opposite).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeamForce {
    /// The seam (its index in the net's `nanofold:seams`).
    pub seam: usize,
    /// Its two faces (FOLD face indices).
    pub faces: [usize; 2],
    /// The end's point on the first face, µm.
    pub point_um: [f64; 3],
    /// The force on the first face there, N.
    pub force_n: [f64; 3],
}

/// Faces held from closing by contact forces when the drives were spent.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Jam {
    /// The faces pressed hardest (FOLD face indices).
    pub faces: [usize; 2],
    /// When, s.
    pub time_s: f64,
    /// How far along the drives' path.
    pub progress: f64,
    /// Every contact force then.
    pub contacts: Vec<ContactForce>,
    /// The latched seams' forces then (with the contacts they balance the hinges).
    pub seams: Vec<SeamForce>,
}

/// The fold angles at one moment of a closing run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosingFrame {
    /// s.
    pub time_s: f64,
    /// How far along the drives' path.
    pub progress: f64,
    /// One per crease column, rad.
    pub fold_angles: Vec<f64>,
}

/// A run's state at an asked time.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSample {
    /// s.
    pub time_s: f64,
    /// One per crease column, rad.
    pub fold_angles: Vec<f64>,
    /// Their rates along the path, rad/s: central differences of the balance in time with
    /// the same seams and contacts held (one-sided at the path's ends).
    pub rates: Vec<f64>,
    /// What held the faces there.
    pub held: HeldRows,
}

/// What holds the faces at a state of a run: the latched seams and the contacts pressing
/// (force > 0), each with the side it came from, so that the same rows can be read again
/// at other fold angles or on another model of the same net ([`NetClosing::held_rows`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeldRows {
    /// The latched seams, in the order they latched.
    pub latched: Vec<usize>,
    /// The pressing features: (feature, side ±1, normal reference, force N).
    pressing: Vec<(usize, f64, Vector3<f64>, f64)>,
}

impl HeldRows {
    /// How many contacts press.
    pub fn pressing_count(&self) -> usize {
        self.pressing.len()
    }

    /// The pressing contacts' forces, N.
    pub fn forces(&self) -> Vec<f64> {
        self.pressing.iter().map(|p| p.3).collect()
    }
}

/// A run with its states at asked times ([`NetClosing::run_until`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ReleasedPath {
    /// How it went.
    pub report: ClosingReport,
    /// The states at the asked times up to its end.
    pub samples: Vec<PathSample>,
    /// The QPs solved along contacts.
    pub qp_solves: usize,
}

/// A closing run.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosingReport {
    /// How it ended.
    pub outcome: Outcome,
    /// When: the last latch (closes), the end of the drives (jams, stalls), or where the
    /// path lost its stability (snaps), s.
    pub time_s: f64,
    /// How far along the drives' path that was.
    pub progress: f64,
    /// When faces first met (a latch or a contact), s.
    pub first_contact_time_s: Option<f64>,
    /// Every latch in order.
    pub latches: Vec<Latch>,
    /// Every contact as it began, in order.
    pub contacts: Vec<Contact>,
    /// The contact forces holding the faces apart at the end (outcome `jams`).
    pub jam: Option<Jam>,
    /// The contact forces at the end of the run, whatever its outcome.
    pub final_contacts: Vec<ContactForce>,
    /// Seams still open at the end, with their misalignment.
    pub open_seams: Vec<(usize, f64)>,
    /// Why the run could not go on (outcome `undecided` or `snaps`).
    pub undecided: Option<String>,
    /// The drives at the end, one per crease column, rad.
    pub final_drive: Vec<f64>,
    /// The start, every event (before and after its latches) and the end.
    pub frames: Vec<ClosingFrame>,
}

/// Where a seam stands in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SeamState {
    Open,
    Latched,
}

/// What holds the faces during a run: latched seams (closure rows) and touching features
/// (contact rows, each with the side it came from and its force).
#[derive(Debug, Clone)]
struct Holds {
    state: Vec<SeamState>,
    latched: Vec<usize>,
    /// Features in contact (indices into the net's features).
    touching: Vec<usize>,
    /// Each touching feature's force at the last balance, N.
    forces: Vec<f64>,
    /// The friction at the last balance: (feature, force across its normal on the first
    /// face, N).
    friction: Vec<(usize, Vector3<f64>)>,
    /// Where a step's slip is counted from (its start; none: where the balance starts).
    origin: Option<Vec<f64>>,
    /// The latched seams' row multipliers at the last balance with contacts, N·m.
    seam_multipliers: Vec<f64>,
    /// Seams whose capture found no balance (contact holds their faces off the pull):
    /// they latch only once they meet in line.
    blocked: Vec<bool>,
    /// Whether the last balance given up was unstable along its contacts (a snap-through).
    unstable: bool,
    /// Why the last balance with contacts was given up.
    failure: Option<SettleFailure>,
}

/// Why a balance with contacts was given up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SettleFailure {
    /// Its QP solves ran out (this balance's or the run's).
    Solves,
    /// No share of the rows' residuals gave a QP step (the linearised rows cannot all hold).
    NoStep,
    /// Its iterations ran out with steps still above the floor.
    Iterations,
}

impl SettleFailure {
    fn describe(self) -> &'static str {
        match self {
            SettleFailure::Solves => "its QP solves ran out",
            SettleFailure::NoStep => "the linearised closures and contacts cannot all hold",
            SettleFailure::Iterations => "its steps did not settle",
        }
    }
}

impl Holds {
    fn new(seams: usize) -> Holds {
        Holds {
            state: vec![SeamState::Open; seams],
            blocked: vec![false; seams],
            unstable: false,
            failure: None,
            latched: Vec::new(),
            touching: Vec::new(),
            friction: Vec::new(),
            origin: None,
            forces: Vec::new(),
            seam_multipliers: Vec::new(),
        }
    }

    fn latch(&mut self, k: usize, faces: [usize; 2], features: &[Feature]) {
        self.state[k] = SeamState::Latched;
        self.latched.push(k);
        // The seam's rows hold its faces now: their contacts go.
        let apart = |f: usize| {
            let [a, b] = features[self.touching[f]].faces();
            (a == faces[0] && b == faces[1]) || (a == faces[1] && b == faces[0])
        };
        let keep: Vec<usize> = (0..self.touching.len()).filter(|&f| !apart(f)).collect();
        self.touching = keep.iter().map(|&f| self.touching[f]).collect();
        self.forces = keep.iter().map(|&f| self.forces[f]).collect();
    }

    fn touch(&mut self, feature: usize) {
        if !self.touching.contains(&feature) {
            self.touching.push(feature);
            self.forces.push(0.0);
        }
    }
}

/// Each feature's orientation in a run: its normal kept continuous (an edge pair's crossing
/// normal turns over as the edges pass parallel) and the side it came from (±1: where it
/// was when last off the other face's plane, kept while it is over the other face; 0: never
/// off it yet).
#[derive(Debug, Clone)]
struct Sides {
    sign: Vec<f64>,
    reference: Vec<Vector3<f64>>,
    /// Whether each pair of faces is within [`REACH`] (its features followed); a pair out
    /// of reach cannot touch, and its features' sides are read afresh when it comes back.
    watched: Vec<bool>,
    /// Whether each pair was apart across a plane at the last accepted poses: its features'
    /// sides are then those they had there, read from `last` when asked.
    separated: Vec<bool>,
    /// The faces at the last accepted poses.
    last: Option<PlacedFaces>,
    tolerance: f64,
    /// The run's QP solves so far (bounded by [`RUN_SOLVES`]).
    solves: std::cell::Cell<usize>,
    /// Coulomb's coefficient between faces (0: frictionless).
    friction: f64,
    /// Each seam's approach rate at the poses being tested, Σ o·ȯ over its ends' offsets
    /// o along the path's tangent (m² per unit of progress; positive: receding), with the
    /// least that counts (see [`SEAM_MOVE`]).
    approach: Vec<(f64, f64)>,
    /// Whether each seam's ends were approaching at the last accepted poses (the step's
    /// end, read on that step's path): one that now recedes has passed its closest approach.
    approaching: Vec<bool>,
}

impl Sides {
    fn new(contacts: &FaceContacts, tolerance: f64) -> Sides {
        Sides {
            sign: vec![0.0; contacts.features.len()],
            reference: vec![Vector3::zeros(); contacts.features.len()],
            watched: vec![false; contacts.pairs.len()],
            separated: vec![false; contacts.pairs.len()],
            last: None,
            tolerance,
            solves: std::cell::Cell::new(0),
            friction: 0.0,
            approach: Vec::new(),
            approaching: Vec::new(),
        }
    }

    /// Feature `k`'s side and normal reference: as carried, or, for a pair that was apart
    /// across a plane, as read where it last was (apart, every feature is on its own side).
    fn orientation(&self, contacts: &FaceContacts, k: usize) -> (f64, Vector3<f64>) {
        match &self.last {
            Some(last) if self.separated[contacts.feature_pair[k]] => {
                let raw = contacts.state(last, k);
                if !raw.distance.is_finite() {
                    (0.0, Vector3::zeros())
                } else if raw.distance.abs() > self.tolerance {
                    (raw.distance.signum(), raw.normal)
                } else {
                    (0.0, raw.normal)
                }
            }
            _ => (self.sign[k], self.reference[k]),
        }
    }

    /// Stores feature `k`'s orientation as carried, for a feature that starts touching:
    /// from here on its pair is open and its side is no longer read where it was apart.
    fn commit(&mut self, contacts: &FaceContacts, k: usize) {
        let (sign, reference) = self.orientation(contacts, k);
        self.sign[k] = sign;
        self.reference[k] = reference;
    }

    /// The features of the pairs of faces within reach.
    fn watched<'c>(&'c self, contacts: &'c FaceContacts) -> impl Iterator<Item = usize> + 'c {
        (0..contacts.pairs.len())
            .filter(|&p| self.watched[p])
            .flat_map(move |p| contacts.pair_features[p].iter().copied())
    }

    /// Feature `k` at its `raw` state with its normal continuous.
    fn continuous(&self, contacts: &FaceContacts, k: usize, mut state: FeatureState) -> FeatureState {
        self.continuous_from(contacts, k, self.orientation(contacts, k).1, &mut state);
        state
    }

    fn continuous_from(&self, contacts: &FaceContacts, k: usize, reference: Vector3<f64>, state: &mut FeatureState) {
        if matches!(contacts.features[k], Feature::EdgeOnEdge { .. }) && state.normal.dot(&reference) < 0.0 {
            state.normal = -state.normal;
            state.distance = -state.distance;
        }
    }

    /// Feature `k` at its `raw` state turned to the side it came from: its distance is its
    /// gap.
    fn oriented(&self, contacts: &FaceContacts, k: usize, raw: FeatureState) -> FeatureState {
        let (sign, reference) = self.orientation(contacts, k);
        let mut state = raw;
        self.continuous_from(contacts, k, reference, &mut state);
        if sign < 0.0 {
            state.normal = -state.normal;
            state.distance = -state.distance;
        }
        state
    }

    /// Feature `k` with the faces `placed`, turned to the side it came from.
    fn state(&self, contacts: &FaceContacts, placed: &PlacedFaces, k: usize) -> FeatureState {
        self.oriented(contacts, k, contacts.state(placed, k))
    }

    /// Feature `k`'s orientation read afresh from its `raw` state (its pair was out of
    /// reach, so it is on the side it is on).
    fn refresh(&mut self, k: usize, raw: FeatureState, tolerance: f64) {
        self.sign[k] = 0.0;
        if !raw.distance.is_finite() {
            return;
        }
        self.reference[k] = raw.normal;
        if raw.distance.abs() > tolerance {
            self.sign[k] = raw.distance.signum();
        }
    }

    /// Carries feature `k`'s orientation to its `raw` state.
    fn update(&mut self, contacts: &FaceContacts, k: usize, raw: FeatureState, tolerance: f64) {
        let state = self.continuous(contacts, k, raw);
        if !state.distance.is_finite() {
            return;
        }
        self.reference[k] = state.normal;
        // A feature coming over the other face exactly on its plane, as an edge turning in
        // through the other face's edge does, keeps the side it came from.
        if (!state.over || self.sign[k] == 0.0) && state.distance.abs() > tolerance {
            self.sign[k] = state.distance.signum();
        }
    }
}

/// What a test for events reads: only the happenings a step found (bisecting it), or
/// every watched feature, each one's raw state kept in the list.
enum EventScan<'r> {
    Among(&'r [Happening]),
    Every(&'r mut [Option<FeatureState>]),
}

/// Something that happens in a step: a seam meets, or a feature crosses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Happening {
    Seam(usize),
    Feature(usize),
}

/// Stiffnesses over the largest.
fn scaled(stiffness: &[f64]) -> DVector<f64> {
    let largest = stiffness.iter().fold(0.0_f64, |m, &k| m.max(k));
    DVector::from_iterator(stiffness.len(), stiffness.iter().map(|k| k / largest))
}

/// A matrix's row space as JᵀJ's eigenpairs.
type RowSpace = Vec<(f64, DVector<f64>)>;

#[derive(Debug, Clone)]
struct SeamEnds {
    faces: [usize; 2],
    /// Each end: the pattern vertex on the first face and its copy on the second.
    ends: [[usize; 2]; 2],
    length: f64,
}

/// A net's faces, seams and contact features as a closing run tests them, for one network
/// model of the net (built once, run for every sample).
#[derive(Debug, Clone)]
pub struct NetClosing {
    contacts: FaceContacts,
    file_face: Vec<usize>,
    seams: Vec<SeamEnds>,
    /// Each panel's tree columns to the anchored panel.
    paths: Vec<Vec<usize>>,
    size: f64,
    unit: f64,
    /// The largest step while no contact is held ([`FREE_STEP`]; varied by the tests that
    /// show outcomes do not depend on it).
    free_step: f64,
}

impl NetClosing {
    /// The tests of `net` for `model`, a network built from `net.pattern`.
    pub fn new(net: &NetPattern, model: &NetworkModel) -> Result<NetClosing> {
        let pattern = &model.folding.pattern;
        if pattern.vertices.len() != net.pattern.vertices.len() || pattern.faces.len() != net.pattern.faces.len() {
            return Err(NanofoldError::invalid(
                "pattern",
                &model.folding.pattern.name,
                "the network was not built from this net",
            ));
        }
        Self::with_copies(model, &net.seams, &net.solid_vertex)
    }

    /// The tests of a scene's tree of panels `model` with its named seams (none: faces
    /// only push on each other).
    pub fn of_scene(model: &NetworkModel) -> Result<NetClosing> {
        match &model.seams {
            Some(gluing) => Self::with_copies(model, &gluing.edges, &gluing.point),
            None => {
                let own: Vec<usize> = (0..model.folding.pattern.vertices.len()).collect();
                Self::with_copies(model, &[], &own)
            }
        }
    }

    /// The tests with `seams` (pattern edge pairs) and each vertex's point once they are
    /// shut (`copies`).
    fn with_copies(model: &NetworkModel, seams: &[[usize; 2]], copies: &[usize]) -> Result<NetClosing> {
        let pattern = &model.folding.pattern;
        if !model.folding.stars.is_empty() {
            return Err(NanofoldError::invalid(
                "pattern",
                &pattern.name,
                "seams latch on a net (a tree of panels); this pattern closes loops of its own",
            ));
        }
        let contacts = FaceContacts::new(model, copies, |_, _| true);
        let flat = &contacts.flat;
        let face_of_edge = |e: usize| {
            pattern.edge_faces[e]
                .iter()
                .flatten()
                .copied()
                .next()
                .expect("a seam edge bounds a face")
        };
        let solid = copies;
        let seams: Vec<SeamEnds> = seams
            .iter()
            .map(|&[e, f]| {
                let ([a0, a1], [b0, b1]) = (pattern.edges[e], pattern.edges[f]);
                let ends = if solid[a0] == solid[b0] {
                    [[a0, b0], [a1, b1]]
                } else {
                    [[a0, b1], [a1, b0]]
                };
                SeamEnds {
                    faces: [face_of_edge(e), face_of_edge(f)],
                    ends,
                    length: (flat[a1] - flat[a0]).norm(),
                }
            })
            .collect();
        let paths = (0..model.panels()).map(|p| model.path_columns(p).collect()).collect();
        Ok(NetClosing {
            contacts,
            file_face: pattern.file_face.clone(),
            seams,
            paths,
            size: model.size(),
            unit: model.unit,
            free_step: FREE_STEP,
        })
    }

    /// The number of seams.
    pub fn seam_count(&self) -> usize {
        self.seams.len()
    }

    fn place(&self, data: &NetworkData, face: usize, v: usize) -> Vector3<f64> {
        self.contacts.corner(data, face, v)
    }

    /// The balance's tangent dθ/du at the poses `data` holds with `holds` held, for drives
    /// moving at `drive_rate` (dr/du): the drive rates projected on the held rows' null
    /// space in the stiffness's metric, min Σ Kᵢ (θ̇ᵢ − ṙᵢ)² with J θ̇ = 0. It leaves out the
    /// rows' curvature under their forces (first order in them), so it is exact while no row
    /// is held and a function of the state, never of the step, when one is.
    fn path_tangent(
        &self,
        data: &NetworkData,
        holds: &Holds,
        sides: &Sides,
        drive_rate: &[f64],
        stiffness: &[f64],
    ) -> Vec<f64> {
        let n = drive_rate.len();
        if holds.latched.is_empty() && holds.touching.is_empty() {
            return drive_rate.to_vec();
        }
        let (_, seam_rows) = self.seam_rows(data, holds, n);
        let (_, contact_rows) = self.contact_rows(data, holds, sides, n);
        let root = scaled(stiffness).map(f64::sqrt);
        let mut rows = DMatrix::zeros(seam_rows.nrows() + contact_rows.nrows(), n);
        rows.rows_mut(0, seam_rows.nrows()).copy_from(&seam_rows);
        rows.rows_mut(seam_rows.nrows(), contact_rows.nrows())
            .copy_from(&(contact_rows / self.size));
        for c in 0..n {
            rows.column_mut(c).unscale_mut(root[c]);
        }
        let (_, null) = Self::row_and_null_space(&rows, None);
        let weighted = DVector::from_iterator(n, (0..n).map(|c| root[c] * drive_rate[c]));
        let mut projected = DVector::zeros(n);
        for direction in &null {
            projected += direction * direction.dot(&weighted);
        }
        (0..n).map(|c| projected[c] / root[c]).collect()
    }

    /// Every open seam's approach rate at the poses `data` holds along `tangent` (dθ/du),
    /// with the least that counts: Σ o·ȯ over its ends' offsets o = x − y, ȯ from the
    /// twists of the creases on each face's path.
    fn read_approach(&self, data: &NetworkData, holds: &Holds, tangent: &[f64], approach: &mut Vec<(f64, f64)>) {
        let fastest = tangent.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        approach.clear();
        approach.extend((0..self.seams.len()).map(|k| {
            if holds.state[k] != SeamState::Open {
                return (0.0, 0.0);
            }
            let seam = &self.seams[k];
            let [a, b] = seam.faces;
            let (mut rate, mut size) = (0.0, 0.0);
            for &[v, w] in &seam.ends {
                let (x, y) = (self.place(data, a, v), self.place(data, b, w));
                let offset = x - y;
                let mut moving = Vector3::zeros();
                for (point, face, sign) in [(x, a, 1.0), (y, b, -1.0)] {
                    for &c in &self.paths[self.contacts.face_panel[face]] {
                        moving += data.twist[c].point_velocity(&point) * (sign * tangent[c]);
                    }
                }
                rate += offset.dot(&moving);
                size += offset.norm();
            }
            (rate, SEAM_MOVE * seam.length * size * fastest)
        }));
    }

    /// Whether seam `k`'s ends have passed their closest approach since the last accepted
    /// poses: approaching there, receding at the poses tested. A function of the state, so
    /// wherever the steps fall it happens once per approach, located at its closest point.
    fn seam_passed(&self, sides: &Sides, k: usize) -> bool {
        sides.approaching.get(k).copied().unwrap_or(false)
            && sides.approach.get(k).is_some_and(|&(rate, floor)| rate > floor)
    }

    fn misalignment(&self, data: &NetworkData, k: usize) -> f64 {
        let seam = &self.seams[k];
        seam.ends
            .iter()
            .map(|&[v, w]| (self.place(data, seam.faces[0], v) - self.place(data, seam.faces[1], w)).norm())
            .fold(0.0, f64::max)
            / seam.length
    }

    /// The seam between faces `[f, g]`, if they have one.
    fn seam_of(&self, [f, g]: [usize; 2]) -> Option<usize> {
        self.seams.iter().position(|s| s.faces == [f, g] || s.faces == [g, f])
    }

    /// What happens at these poses (`data`, its faces `placed`): an open seam aligned, a
    /// seam whose faces touch come within the capture, a seam near the capture past its
    /// ends' closest approach, or a feature over another face
    /// crossed to the wrong side of it. Only among the happenings `scan` names (a step's
    /// events, bisected), or everything, each watched feature's raw state left in `scan`'s
    /// list for the step's bookkeeping.
    fn events(
        &self,
        (data, placed): (&NetworkData, &PlacedFaces),
        holds: &Holds,
        sides: &Sides,
        capture: f64,
        scan: EventScan<'_>,
    ) -> Vec<Happening> {
        let tolerance = TOLERANCE * self.size;
        let mut found = Vec::new();
        // A seam's closest approach near the capture is a happening wherever its ends are:
        // located, its misalignment there decides whether it latches.
        let seam_meets = |k: usize| {
            holds.state[k] == SeamState::Open && {
                let m = self.misalignment(data, k);
                m <= ALIGNED
                    || (!holds.blocked[k]
                        && ((m <= capture && self.seam_touching(holds, k))
                            || (m <= NEAR_CAPTURE * capture && self.seam_passed(sides, k))))
            }
        };
        let crosses = |k: usize, state: &FeatureState| {
            sides.orientation(&self.contacts, k).0 != 0.0
                && !holds.touching.contains(&k)
                && !self.held_by_seam(holds, k)
                && {
                    let state = sides.oriented(&self.contacts, k, *state);
                    state.over && state.distance < -tolerance
                }
        };
        match scan {
            EventScan::Among(among) => {
                for &happening in among {
                    let happens = match happening {
                        Happening::Seam(k) => seam_meets(k),
                        Happening::Feature(k) => crosses(k, &self.contacts.state(placed, k)),
                    };
                    if happens {
                        found.push(happening);
                    }
                }
            }
            EventScan::Every(raw) => {
                found.extend((0..self.seams.len()).filter(|&k| seam_meets(k)).map(Happening::Seam));
                for pair in 0..self.contacts.pairs.len() {
                    if !sides.watched[pair] || !self.pair_open(placed, holds, pair) {
                        continue;
                    }
                    for &k in &self.contacts.pair_features[pair] {
                        let state = self.contacts.state(placed, k);
                        raw[k] = Some(state);
                        if crosses(k, &state) {
                            found.push(Happening::Feature(k));
                        }
                    }
                }
            }
        }
        found
    }

    /// Whether pair `pair`'s features can touch or cross at the faces `placed`: not held by
    /// a latched seam, and either touching already or not apart across a plane.
    fn pair_open(&self, placed: &PlacedFaces, holds: &Holds, pair: usize) -> bool {
        let faces = self.contacts.pairs[pair];
        if self
            .seam_of(faces)
            .is_some_and(|s| holds.state[s] == SeamState::Latched)
        {
            return false;
        }
        holds.touching.iter().any(|&k| self.contacts.feature_pair[k] == pair)
            || !self.contacts.plane_separated(placed, pair, TOLERANCE * self.size)
    }

    /// Whether seam `k`'s faces touch.
    fn seam_touching(&self, holds: &Holds, k: usize) -> bool {
        holds
            .touching
            .iter()
            .any(|&f| self.seam_of(self.contacts.features[f].faces()) == Some(k))
    }

    /// Whether feature `k`'s faces are held by a latched seam (it no longer watches them).
    fn held_by_seam(&self, holds: &Holds, k: usize) -> bool {
        self.seam_of(self.contacts.features[k].faces())
            .is_some_and(|s| holds.state[s] == SeamState::Latched)
    }

    /// The latched seams' rows, their residual and Jacobian in the fold angles at the poses
    /// and twists `data` holds: each seam's first end on its copy (three rows) and its
    /// second end's offset across the seam's line (two rows: along face a's normal and
    /// across the edge in its plane), over the net's size, so a seam on its copy (a hinge)
    /// has five independent rows wherever it is.
    fn seam_rows(&self, data: &NetworkData, holds: &Holds, columns: usize) -> (DVector<f64>, DMatrix<f64>) {
        let rows = SEAM_ROWS * holds.latched.len();
        let mut residual = DVector::zeros(rows);
        let mut jacobian = DMatrix::zeros(rows, columns);
        for (i, &k) in holds.latched.iter().enumerate() {
            let seam = &self.seams[k];
            let [a, b] = seam.faces;
            let along = (self.place(data, a, seam.ends[1][0]) - self.place(data, a, seam.ends[0][0])).normalize();
            let normal = self.contacts.normal(data, a);
            let across = along.cross(&normal);
            let identity = nalgebra::Matrix3::identity();
            for (e, &[v, w]) in seam.ends.iter().enumerate() {
                let (row, directions): (usize, Vec<Vector3<f64>>) = if e == 0 {
                    (SEAM_ROWS * i, (0..3).map(|j| identity.column(j).into_owned()).collect())
                } else {
                    (SEAM_ROWS * i + 3, vec![normal, across])
                };
                let (x, y) = (self.place(data, a, v), self.place(data, b, w));
                for (j, d) in directions.iter().enumerate() {
                    residual[row + j] = d.dot(&(x - y)) / self.size;
                }
                for (point, face, sign) in [(x, a, 1.0), (y, b, -1.0)] {
                    for &c in &self.paths[self.contacts.face_panel[face]] {
                        let velocity = data.twist[c].point_velocity(&point);
                        for (j, d) in directions.iter().enumerate() {
                            jacobian[(row + j, c)] += sign * d.dot(&velocity) / self.size;
                        }
                    }
                }
            }
        }
        (residual, jacobian)
    }

    /// The latched seams' forces from their multipliers: a row d·(x − y)/size with
    /// multiplier μ pulls x (on the first face) by −μ d / size.
    fn seam_forces(&self, data: &NetworkData, holds: &Holds) -> Vec<SeamForce> {
        if holds.seam_multipliers.len() != SEAM_ROWS * holds.latched.len() {
            return Vec::new();
        }
        let identity = nalgebra::Matrix3::<f64>::identity();
        let mut forces = Vec::new();
        for (i, &k) in holds.latched.iter().enumerate() {
            let seam = &self.seams[k];
            let [a, _] = seam.faces;
            let along = (self.place(data, a, seam.ends[1][0]) - self.place(data, a, seam.ends[0][0])).normalize();
            let normal = self.contacts.normal(data, a);
            let across = along.cross(&normal);
            let mu = &holds.seam_multipliers[SEAM_ROWS * i..SEAM_ROWS * (i + 1)];
            let first: Vector3<f64> = (0..3).map(|j| identity.column(j) * mu[j]).sum::<Vector3<f64>>();
            let second = normal * mu[3] + across * mu[4];
            for (e, pull) in [(0, first), (1, second)] {
                let x = self.place(data, a, seam.ends[e][0]);
                let force = -pull / self.size;
                forces.push(SeamForce {
                    seam: k,
                    faces: seam.faces.map(|f| self.file_face[f]),
                    point_um: [x.x, x.y, x.z].map(|c| c * 1e6),
                    force_n: [force.x, force.y, force.z],
                });
            }
        }
        forces
    }

    /// The touching features' gaps (on their sides, m) and rows.
    fn contact_rows(
        &self,
        data: &NetworkData,
        holds: &Holds,
        sides: &Sides,
        columns: usize,
    ) -> (DVector<f64>, DMatrix<f64>) {
        let mut gaps = DVector::zeros(holds.touching.len());
        let mut rows = DMatrix::zeros(holds.touching.len(), columns);
        let mut row = DVector::zeros(columns);
        let placed = self.contacts.placed(data);
        for (i, &k) in holds.touching.iter().enumerate() {
            let state = sides.state(&self.contacts, &placed, k);
            self.contacts.row(data, k, &state, &mut row);
            gaps[i] = state.distance;
            rows.row_mut(i).copy_from(&row.transpose());
        }
        (gaps, rows)
    }

    /// Coulomb friction at the standing contacts whose meetings pressed at the last iterate
    /// (`meeting_forces`, one per standing contact): each one's
    /// two slip rows across its normal, its slip since `origin` (linearised, m), μ times its
    /// force, and (feature, its two directions); `None` when none presses.
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn friction_rows(
        &self,
        data: &NetworkData,
        holds: &Holds,
        sides: &Sides,
        standing: &[usize],
        meeting_forces: &[f64],
        theta: &[f64],
        origin: &[f64],
    ) -> Option<(
        DMatrix<f64>,
        DVector<f64>,
        DVector<f64>,
        Vec<(usize, [Vector3<f64>; 2])>,
    )> {
        let pressed: Vec<usize> = (0..standing.len()).filter(|&s| meeting_forces[s] > 0.0).collect();
        if pressed.is_empty() {
            return None;
        }
        let pressing: Vec<usize> = pressed.iter().map(|&s| standing[s]).collect();
        let n = theta.len();
        let placed = self.contacts.placed(data);
        let mut rows = DMatrix::zeros(2 * pressing.len(), n);
        let mut row = DVector::zeros(n);
        let mut frames = Vec::with_capacity(pressing.len());
        for (p, &i) in pressing.iter().enumerate() {
            let k = holds.touching[i];
            let state = sides.state(&self.contacts, &placed, k);
            let normal = state.normal;
            // Any two directions across the normal.
            let axis = if normal.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let first = normal.cross(&axis).normalize();
            let second = normal.cross(&first);
            for (j, direction) in [first, second].iter().enumerate() {
                self.contacts.row_along(data, k, &state, direction, &mut row);
                rows.row_mut(2 * p + j).copy_from(&row.transpose());
            }
            frames.push((k, [first, second]));
        }
        let moved = DVector::from_iterator(n, (0..n).map(|c| theta[c] - origin[c]));
        let slip = &rows * moved;
        let bounds = DVector::from_iterator(
            pressed.len(),
            pressed.iter().map(|&s| sides.friction * meeting_forces[s]),
        );
        Some((rows, slip, bounds, frames))
    }

    /// W = −Σ fᵢ ∇²gᵢ, the touching features' curvature weighted by their last forces (the
    /// balance's Lagrangian Hessian less K), from central differences of their rows in each
    /// fold angle; `None` while no contact pushes. With it, the balance's stiffness along
    /// the surfaces the held rows leave free: the least eigenvalue of K^-1/2 (K + W) K^-1/2
    /// there (below zero, the balance is unstable: the path has passed a snap-through). W
    /// is returned with enough of each held row's square added that K + W is positive
    /// across the rows (which leaves a held row's step unchanged), and clamped to K + W ≥
    /// [`STABILITY_FLOOR`] K.
    #[allow(clippy::too_many_arguments)]
    fn contact_curvature(
        &self,
        model: &NetworkModel,
        theta: &[f64],
        stiffness: &[f64],
        holds: &Holds,
        sides: &Sides,
        rows: &DMatrix<f64>,
        closure_rows: &DMatrix<f64>,
    ) -> Option<(DMatrix<f64>, f64)> {
        if holds.forces.iter().all(|&f| f <= 0.0) {
            return None;
        }
        let n = theta.len();
        let mut curvature = DMatrix::zeros(n, n);
        let mut data = NetworkData::new(model);
        let mut shifted = theta.to_vec();
        // Only the pushing contacts weigh in, and only the angles that move their faces; a
        // friction weighs in as a push along its own direction (its rows' curvature
        // weighted by its size: the Lagrangian's −Σ φ ∇²s).
        let weighted: Vec<(usize, Option<Vector3<f64>>, f64)> = (0..holds.forces.len())
            .filter(|&i| holds.forces[i] > 0.0)
            .map(|i| (holds.touching[i], None, holds.forces[i]))
            .chain(
                holds
                    .friction
                    .iter()
                    .filter(|(k, phi)| phi.norm() > 0.0 && holds.touching.contains(k))
                    .map(|(k, phi)| (*k, Some(phi.normalize()), phi.norm())),
            )
            .collect();
        let mut moving = vec![false; n];
        for &(k, _, _) in &weighted {
            for face in self.contacts.features[k].faces() {
                for &c in &self.paths[self.contacts.face_panel[face]] {
                    moving[c] = true;
                }
            }
        }
        let mut rows_at = |shifted: &[f64], out: &mut DMatrix<f64>| {
            update_poses(model, shifted, &mut data);
            let placed = self.contacts.placed(&data);
            let mut row = DVector::zeros(n);
            for (p, &(k, direction, _)) in weighted.iter().enumerate() {
                let state = sides.state(&self.contacts, &placed, k);
                match direction {
                    None => self.contacts.row(&data, k, &state, &mut row),
                    Some(direction) => self.contacts.row_along(&data, k, &state, &direction, &mut row),
                }
                out.row_mut(p).copy_from(&row.transpose());
            }
        };
        let (mut plus, mut minus) = (DMatrix::zeros(weighted.len(), n), DMatrix::zeros(weighted.len(), n));
        for c in (0..n).filter(|&c| moving[c]) {
            shifted[c] = theta[c] + CURVATURE_STEP;
            rows_at(&shifted, &mut plus);
            shifted[c] = theta[c] - CURVATURE_STEP;
            rows_at(&shifted, &mut minus);
            shifted[c] = theta[c];
            for (p, &(_, _, force)) in weighted.iter().enumerate() {
                for j in 0..n {
                    curvature[(j, c)] -= force * (plus[(p, j)] - minus[(p, j)]) / (2.0 * CURVATURE_STEP);
                }
            }
        }
        let mut curvature = (&curvature + curvature.transpose()) * 0.5;
        let root: Vec<f64> = stiffness.iter().map(|k| k.sqrt()).collect();
        let relative = |w: &DMatrix<f64>| DMatrix::from_fn(n, n, |i, j| w[(i, j)] / (root[i] * root[j]));
        let softest = relative(&curvature).symmetric_eigen().eigenvalues.min().min(0.0);
        let held: Vec<DVector<f64>> = (0..holds.forces.len())
            .filter(|&i| holds.forces[i] > 0.0)
            .map(|i| rows.row(i).transpose())
            .chain((0..closure_rows.nrows()).map(|i| closure_rows.row(i).transpose()))
            .filter_map(|row| {
                let norm = row.norm();
                (norm > 0.0).then(|| row / norm)
            })
            .collect();
        // The stability: the least λ of (K + W) z = λ K z over the directions z the held
        // rows leave free (Zᵀ(K + W)Z against ZᵀKZ, by its Cholesky factor).
        let held_rows = DMatrix::from_fn(held.len(), n, |i, c| held[i][c]);
        let (_, free) = Self::row_and_null_space(&held_rows, None);
        let stability = if free.is_empty() {
            1.0
        } else {
            let basis = DMatrix::from_columns(&free);
            let hessian = &curvature + DMatrix::from_diagonal(&DVector::from_column_slice(stiffness));
            let reduced = basis.transpose() * hessian * &basis;
            let weight = basis.transpose() * DMatrix::from_diagonal(&DVector::from_column_slice(stiffness)) * &basis;
            match weight.cholesky() {
                Some(factor) => {
                    let lower = factor.l();
                    let inverse = lower.clone().try_inverse()?;
                    (&inverse * reduced * inverse.transpose())
                        .symmetric_eigen()
                        .eigenvalues
                        .min()
                }
                None => return None,
            }
        };
        let stiffest = stiffness.iter().fold(0.0_f64, |m, &k| m.max(k));
        let across_weight = ACROSS_WEIGHT * (1.0 - softest) * stiffest;
        for across in &held {
            curvature += across * across.transpose() * across_weight;
        }
        let eigen = relative(&curvature).symmetric_eigen();
        let clamped = DMatrix::from_diagonal(&eigen.eigenvalues.map(|l| l.max(STABILITY_FLOOR - 1.0)));
        let clamped = &eigen.eigenvectors * clamped * eigen.eigenvectors.transpose();
        let curvature = DMatrix::from_fn(n, n, |i, j| clamped[(i, j)] * root[i] * root[j]);
        curvature
            .iter()
            .all(|x| x.is_finite())
            .then_some((curvature, stability))
    }

    /// JᵀJ's eigenvectors split: (row space with eigenvalues, null space): the null space the
    /// `null_count` smallest when given, else those below the cut. Rounding leaves JᵀJ's zero
    /// eigenvalues near 1e-16 of the largest (not its square), so the cut is well above that:
    /// singular values below 1e-6 of J's largest.
    fn row_and_null_space(
        jacobian: &DMatrix<f64>,
        null_count: impl Into<Option<usize>>,
    ) -> (RowSpace, Vec<DVector<f64>>) {
        let eigen = (jacobian.transpose() * jacobian).symmetric_eigen();
        let cutoff = RANK_CUT * eigen.eigenvalues.amax().max(f64::MIN_POSITIVE);
        let mut order: Vec<usize> = (0..eigen.eigenvalues.len()).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let nulls = null_count
            .into()
            .unwrap_or_else(|| order.iter().filter(|&&i| eigen.eigenvalues[i] <= cutoff).count());
        let (mut row, mut null) = (Vec::new(), Vec::new());
        for (rank, &i) in order.iter().enumerate() {
            let direction = eigen.eigenvectors.column(i).into_owned();
            if rank < nulls {
                null.push(direction);
            } else {
                row.push((eigen.eigenvalues[i].max(f64::MIN_POSITIVE), direction));
            }
        }
        (row, null)
    }

    /// The quasi-static balance with `holds` held: the fold angles minimising
    /// Σ ½ K (θ − r)² on the latched seams' closures with the touching faces apart, from
    /// `theta`. Without contacts, Gauss–Newton on the closures with the energy minimised in
    /// their null space (the direct path); with contacts, a sequence of Clarabel QPs whose
    /// contact multipliers are left in `holds.forces`. Returns whether it converged.
    #[allow(clippy::too_many_arguments)]
    fn settle(
        &self,
        model: &NetworkModel,
        drive: &[f64],
        stiffness: &[f64],
        holds: &mut Holds,
        sides: &Sides,
        theta: &mut [f64],
        data: &mut NetworkData,
    ) -> bool {
        if holds.touching.is_empty() {
            return self.settle_closures(model, drive, stiffness, holds, theta, data);
        }
        let n = theta.len();
        let mut at_floor = 0;
        let mut solves = 0;
        let mut previous_step: Option<DVector<f64>> = None;
        let mut turned = 0;
        // The trust box, narrowed where the contacts' rows foretold their last step badly
        // (their curvature over the step beyond their own move) and widened back as they
        // foretell it well.
        let mut trust = SETTLE_DAMPING;
        // Iterations in a row whose balance was unstable along the contacts.
        let mut unstable = 0;
        holds.unstable = false;
        holds.failure = None;
        let mut foretold: Option<(Vec<f64>, Vec<f64>, f64)> = None;
        let origin = holds.origin.take().unwrap_or_else(|| theta.to_vec());
        let mut lagged: Vec<(usize, f64)> = holds
            .touching
            .iter()
            .copied()
            .zip(holds.forces.iter().copied())
            .collect();
        let mut rounds = 0;
        // The last round's change of the forces, by feature (for Aitken's extrapolation).
        let mut last_change: Option<Vec<(usize, f64)>> = None;
        // With friction, each round of lagged forces has the iterations of one balance.
        let iterations = if sides.friction > 0.0 {
            CONTACT_ITERATIONS * FRICTION_ROUNDS
        } else {
            CONTACT_ITERATIONS
        };
        for _ in 0..iterations {
            update_poses(model, theta, data);
            let (seam_residual, seam_rows) = self.seam_rows(data, holds, n);
            // The seams' rows as their row space: latched seams that close a solid hold more
            // rows than the angles they fix (a box's 20 rows on 5 angles), and a linearised
            // residual off that space would make the equalities inconsistent. Each kept row
            // v asks v·d = −v·Eᵀe/λ, the Gauss–Newton step's share along it.
            let (row_space, _) = Self::row_and_null_space(&seam_rows, None);
            let strongest = row_space.iter().map(|(lambda, _)| *lambda).fold(0.0, f64::max);
            let kept: Vec<&(f64, DVector<f64>)> = row_space
                .iter()
                .filter(|(lambda, _)| *lambda > RANK_CUT * strongest)
                .collect();
            let pulled = seam_rows.transpose() * &seam_residual;
            let closure_rows = DMatrix::from_fn(kept.len(), n, |i, c| kept[i].1[c]);
            let closure = DVector::from_iterator(kept.len(), kept.iter().map(|(lambda, v)| v.dot(&pulled) / lambda));
            let (all_gaps, all_rows) = self.contact_rows(data, holds, sides, n);
            // One row per meeting: two touching features of one pair of faces whose rows are
            // parallel (a corner on a face and the edge from it at the same point; an edge
            // across an edge and the same edge turning into their corner) are one contact;
            // two equal rows leave the QP's multipliers undetermined and its interior point
            // stalling. The deepest of them stands for the rest.
            let mut standing: Vec<usize> = Vec::new();
            let mut stands_for = vec![usize::MAX; holds.touching.len()];
            let mut order: Vec<usize> = (0..holds.touching.len()).collect();
            // Deepest by the turn it asks (its gap over its row's size): of parallel rows the
            // same way, holding that one holds the rest to first order.
            let turn: Vec<f64> = (0..holds.touching.len())
                .map(|i| all_gaps[i] / all_rows.row(i).norm().max(f64::MIN_POSITIVE))
                .collect();
            order.sort_by(|&a, &b| turn[a].total_cmp(&turn[b]));
            if sides.friction > 0.0 {
                // With friction a meeting keeps the feature that pressed for it: its slip
                // rows are the ones its friction was bounded on.
                order.sort_by_key(|&i| holds.forces[i] <= 0.0);
            }
            for i in order {
                let faces = self.contacts.features[holds.touching[i]].faces();
                let row = all_rows.row(i);
                let same = standing.iter().position(|&j| {
                    let other = self.contacts.features[holds.touching[j]].faces();
                    let other_row = all_rows.row(j);
                    let alike = other_row.dot(&row);
                    let parallel = alike.abs() >= (1.0 - PARALLEL_ROWS) * other_row.norm() * row.norm();
                    // Of one pair of faces, parallel rows either way; of two pairs, rows
                    // the same way (one face's edge met by two faces sharing it).
                    parallel && ((other == faces || other == [faces[1], faces[0]]) || alike > 0.0)
                });
                match same {
                    Some(s) => stands_for[i] = s,
                    None => {
                        stands_for[i] = standing.len();
                        standing.push(i);
                    }
                }
            }
            if let Some((expected, moved, length)) = foretold.take() {
                let slack = CONTACT_SLACK * TOLERANCE * self.size;
                let (mut miss, mut scale) = (0.0_f64, slack);
                for i in 0..expected.len() {
                    if holds.forces[i] > 0.0 || all_gaps[i] <= slack {
                        miss = miss.max((all_gaps[i] - expected[i]).abs());
                        scale = scale.max(moved[i].abs());
                    }
                }
                if miss > TRUST_MISS * scale {
                    trust = TRUST_NARROWING * length;
                } else if miss < TRUST_MISS * TRUST_NARROWING * scale {
                    trust = (2.0 * trust).min(SETTLE_DAMPING);
                }
            }
            let gaps = DVector::from_iterator(standing.len(), standing.iter().map(|&i| all_gaps[i]));
            let contact_rows = all_rows.select_rows(&standing);
            let offset: Vec<f64> = (0..n).map(|c| theta[c] - drive[c]).collect();
            // A closure far from held (a seam just latched, pulled into line) or a contact
            // met deep is reached in parts when one linearised step cannot reach it past
            // the others: the rows ask for a share α of their residual.
            let curved = self.contact_curvature(model, theta, stiffness, holds, sides, &all_rows, &closure_rows);
            unstable = match &curved {
                Some((_, stability)) if *stability < 0.0 => unstable + 1,
                _ => 0,
            };
            holds.unstable = unstable >= UNSTABLE_ITERATIONS;
            if holds.unstable {
                update_poses(model, theta, data);
                return false;
            }
            let curvature = curved.map(|(w, _)| w);
            // A meeting's force is its features' together: which one stands for it may
            // change from one iterate to the next. Friction is bounded by the forces of the
            // last converged balance (`lagged`; a meeting new since then by its last
            // iterate's), so each balance is a convex problem the iterations converge on.
            let meeting_forces: Vec<f64> = (0..standing.len())
                .map(|s| {
                    (0..holds.touching.len())
                        .filter(|&i| stands_for[i] == s)
                        .map(|i| {
                            let feature = holds.touching[i];
                            lagged.iter().find(|l| l.0 == feature).map_or(holds.forces[i], |l| l.1)
                        })
                        .sum()
                })
                .collect();
            let friction = (sides.friction > 0.0)
                .then(|| self.friction_rows(data, holds, sides, &standing, &meeting_forces, theta, &origin))
                .flatten();
            let mut share = 1.0;
            let solution = loop {
                let asked_closure = &closure * share;
                // Faces may sit a little within each other's planes: rows that meet at one
                // point (a seam closing where a contact already holds) agree only to
                // rounding at that depth. A tenth of the tolerance, so a contact held at its
                // slack is within the tolerance however its faces' overlap is measured.
                let slack = CONTACT_SLACK * TOLERANCE * self.size;
                let asked_gaps = gaps.map(|g| if g < 0.0 { g * share + slack } else { g + slack });
                solves += 1;
                sides.solves.set(sides.solves.get() + 1);
                if solves > SETTLE_SOLVES || sides.solves.get() > RUN_SOLVES {
                    holds.failure = Some(SettleFailure::Solves);
                    return false;
                }
                match solve_step(&BalanceStep {
                    stiffness,
                    curvature: curvature.as_ref(),
                    offset: &offset,
                    closures: (&closure_rows, &asked_closure),
                    contacts: (&contact_rows, &asked_gaps),
                    trust,
                    size: self.size,
                    friction: friction.as_ref().map(|(rows, slip, bounds, _)| FrictionRows {
                        slip_rows: rows,
                        slip,
                        bounds,
                    }),
                }) {
                    Ok(solution) => break solution,
                    Err(_) => {
                        share *= 0.5;
                        if share < MIN_SHARE {
                            holds.failure = Some(SettleFailure::NoStep);
                            return false;
                        }
                    }
                }
            };
            // A step that turns back on the last (contacts that nearly oppose, each
            // linearisation overshooting the other's) is taken by half: the two-cycle closes.
            // A step far shorter than the last is converging (a Newton correction may point
            // back), not cycling.
            let back = previous_step.as_ref().is_some_and(|last: &DVector<f64>| {
                last.dot(&solution.step) < 0.0 && solution.step.amax() > CONVERGING * last.amax()
            });
            // Each further turn back halves again: a wedge of nearly parallel contacts moves
            // its corner far for a small turn of its rows, and the cycle only narrows.
            turned = if back { turned + 1 } else { 0 };
            let taken = 0.5_f64.powi(turned.min(MAX_TURNS) as i32);
            for (angle, step) in theta.iter_mut().zip(solution.step.iter()) {
                *angle += taken * step;
            }
            let moved: Vec<f64> = (0..holds.touching.len())
                .map(|i| taken * all_rows.row(i).dot(&solution.step.transpose()))
                .collect();
            let expected = (0..holds.touching.len()).map(|i| all_gaps[i] + moved[i]).collect();
            foretold = Some((expected, moved, taken * solution.step.amax()));
            previous_step = Some(solution.step.clone());
            // The force on a meeting is its standing row's; the rows it stands for carry none.
            for (i, force) in holds.forces.iter_mut().enumerate() {
                *force = if standing[stands_for[i]] == i {
                    solution.forces[stands_for[i]]
                } else {
                    0.0
                };
            }
            holds.friction = match &friction {
                Some((_, _, _, frames)) => frames
                    .iter()
                    .enumerate()
                    .map(|(p, (k, [t1, t2]))| {
                        let phi = &solution.friction_forces;
                        (*k, t1 * phi[2 * p] + t2 * phi[2 * p + 1])
                    })
                    .collect(),
                None => Vec::new(),
            };
            // The seams' own multipliers: μ_E = E Σ v μ_v / λ, the least-norm μ_E with
            // Eᵀμ_E = Σ v μ_v.
            let through = kept
                .iter()
                .zip(solution.closure_multipliers.iter())
                .fold(DVector::zeros(n), |sum, ((lambda, v), mu)| sum + v * (mu / lambda));
            holds.seam_multipliers = (&seam_rows * through).iter().copied().collect();
            let settled = share == 1.0 && !solution.at_trust;
            at_floor = if settled && solution.step.amax() <= FLOOR_STEP {
                at_floor + 1
            } else {
                0
            };
            if settled && (solution.step.amax() <= CONTACT_STEP || at_floor >= FLOOR_ITERATIONS) {
                update_poses(model, theta, data);
                // Where it lands, the contacts hold to their slack (a half step of a two-cycle
                // may leave one deeper: iterate on).
                let (landed, _) = self.contact_rows(data, holds, sides, n);
                if standing
                    .iter()
                    .all(|&i| landed[i] >= -LANDED_SLACK * CONTACT_SLACK * TOLERANCE * self.size)
                {
                    // With friction, balanced on the forces it was bounded by: again on the
                    // new ones until they agree.
                    // Against the largest force, or one that a hinge's torque over a drive
                    // step gives at the net's size (a contact just met presses at rounding).
                    let stiffest = stiffness.iter().fold(0.0_f64, |m, &k| m.max(k));
                    let largest = holds
                        .forces
                        .iter()
                        .fold(stiffest * MAX_STEP / self.size, |m, &f| m.max(f));
                    let moved = holds
                        .touching
                        .iter()
                        .zip(&holds.forces)
                        .map(|(k, f)| (f - lagged.iter().find(|l| l.0 == *k).map_or(0.0, |l| l.1)).abs())
                        .fold(0.0_f64, f64::max);
                    if sides.friction == 0.0 || moved <= FRICTION_AGREED * largest {
                        return true;
                    }
                    rounds += 1;
                    if rounds >= FRICTION_ROUNDS {
                        break;
                    }
                    // The rounds converge linearly (a wedge's friction raising its own
                    // normal force: changes shrinking by 2 % a round were seen), so the
                    // next forces are extrapolated along the change by Aitken's Δ²: by
                    // 1/(1 − r), r the ratio of this round's change to the last's.
                    let change: Vec<(usize, f64)> = holds
                        .touching
                        .iter()
                        .zip(&holds.forces)
                        .map(|(&k, &f)| (k, f - lagged.iter().find(|l| l.0 == k).map_or(0.0, |l| l.1)))
                        .collect();
                    let ratio = last_change.as_ref().and_then(|last| {
                        let same = last.len() == change.len() && last.iter().zip(&change).all(|(a, b)| a.0 == b.0);
                        let (dot, norm) = last
                            .iter()
                            .zip(&change)
                            .fold((0.0, 0.0), |(d, m), (a, b)| (d + a.1 * b.1, m + a.1 * a.1));
                        (same && norm > 0.0).then_some(dot / norm)
                    });
                    let reach = match ratio {
                        Some(r) if r > 0.0 && r < AITKEN_LARGEST => 1.0 / (1.0 - r),
                        _ => 1.0,
                    };
                    lagged = change
                        .iter()
                        .map(|&(k, d)| {
                            let before = lagged.iter().find(|l| l.0 == k).map_or(0.0, |l| l.1);
                            (k, (before + reach * d).max(0.0))
                        })
                        .collect();
                    last_change = Some(change);
                }
                at_floor = 0;
            }
        }
        holds.failure = Some(SettleFailure::Iterations);
        update_poses(model, theta, data);
        false
    }

    /// [`Self::settle`] with no contact: the direct path.
    fn settle_closures(
        &self,
        model: &NetworkModel,
        drive: &[f64],
        stiffness: &[f64],
        holds: &Holds,
        theta: &mut [f64],
        data: &mut NetworkData,
    ) -> bool {
        let n = theta.len();
        if holds.latched.is_empty() {
            theta.copy_from_slice(drive);
            update_poses(model, theta, data);
            return true;
        }
        let stiff = scaled(stiffness);
        let mut last_turn = f64::INFINITY;
        // The rows' rank is read once they are nearly held and kept from then on: converging
        // on a point where they lose rank (seams closing a vertex at a singular state), the
        // direction they lose would pass into the null space, and an energy step along it
        // breaks them at second order, over and over.
        let mut null_count = None;
        for _ in 0..SETTLE_ITERATIONS {
            update_poses(model, theta, data);
            let (residual, jacobian) = self.seam_rows(data, holds, n);
            let (row, null) = Self::row_and_null_space(&jacobian, null_count);
            if null_count.is_none() && residual.amax() <= RANK_READ {
                null_count = Some(null.len());
            }
            let pulled = jacobian.transpose() * &residual;
            // The least-norm step onto the rows: −(JᵀJ)⁺ Jᵀ c, over the directions the rows
            // still see (one they have lost at a singular state takes no step at all).
            let largest = row.iter().map(|(lambda, _)| *lambda).fold(0.0, f64::max);
            let mut step = DVector::zeros(n);
            for (lambda, direction) in row.iter().filter(|(lambda, _)| *lambda > RANK_CUT * largest) {
                step -= direction * (direction.dot(&pulled) / lambda);
            }
            if !null.is_empty() {
                let z = DMatrix::from_columns(&null);
                let moved = DVector::from_iterator(n, (0..n).map(|c| theta[c] + step[c] - drive[c]));
                let gradient = z.transpose() * stiff.component_mul(&moved);
                let hessian = z.transpose() * DMatrix::from_diagonal(&stiff) * &z;
                if let Some(y) = hessian.cholesky().map(|ch| ch.solve(&gradient)) {
                    step -= z * y;
                }
            }
            last_turn = step.amax();
            if last_turn > SETTLE_DAMPING {
                step *= SETTLE_DAMPING / last_turn;
            }
            for c in 0..n {
                theta[c] += step[c];
            }
            if last_turn <= SETTLE_STEP {
                update_poses(model, theta, data);
                return true;
            }
        }
        update_poses(model, theta, data);
        // Slow (linear) convergence at a rank-deficient point: held, and the steps small.
        last_turn <= SINGULAR_STEP && self.seam_rows(data, holds, n).0.amax() <= SETTLE_HELD
    }

    /// Runs a net's device with `forcing` and `stiffness` (one per crease column; a sample
    /// may vary both) from flat to its drives' end.
    pub fn run(
        &self,
        model: &NetworkModel,
        forcing: &Forcing,
        stiffness: &[f64],
        settings: &ClosingSettings,
    ) -> Result<ClosingReport> {
        Ok(self
            .run_until(model, forcing, stiffness, settings, f64::INFINITY, None)?
            .report)
    }

    /// As [`NetClosing::run`], with the drives stopped at `t_end` (s) and, when
    /// `sample_times` are given (s, ascending), the state at each of them up to the run's
    /// end (its frames then the events and those times, not every 0.5 % of the path).
    pub fn run_until(
        &self,
        model: &NetworkModel,
        forcing: &Forcing,
        stiffness: &[f64],
        settings: &ClosingSettings,
        t_end: f64,
        sample_times: Option<&[f64]>,
    ) -> Result<ReleasedPath> {
        self.run_sampled(model, forcing, stiffness, settings, t_end, sample_times, false)
    }

    /// The state at every one of `times` (s, ascending, the last > 0) the device reaches
    /// in balance: as [`NetClosing::run_until`] up to its end, then, past a closing, the
    /// closed device following its drives with every seam held, and past the drives' end
    /// (closed, jammed, stalled or at rest) the last balance, which nothing moves any more.
    /// A run that snaps or cannot decide gives no state past where it stopped.
    pub fn states_at(
        &self,
        model: &NetworkModel,
        forcing: &Forcing,
        stiffness: &[f64],
        settings: &ClosingSettings,
        times: &[f64],
    ) -> Result<ReleasedPath> {
        let t_end = times.last().copied().unwrap_or(0.0);
        self.run_sampled(model, forcing, stiffness, settings, t_end, Some(times), true)
    }

    #[allow(clippy::too_many_arguments)]
    fn run_sampled(
        &self,
        model: &NetworkModel,
        forcing: &Forcing,
        stiffness: &[f64],
        settings: &ClosingSettings,
        t_end: f64,
        sample_times: Option<&[f64]>,
        held_on: bool,
    ) -> Result<ReleasedPath> {
        settings.validate()?;
        if t_end.is_nan() || t_end <= 0.0 {
            return Err(NanofoldError::invalid("t_end", t_end, "must be a time > 0 s"));
        }
        let path = DrivePath::new(forcing, t_end);
        let stops: Vec<(f64, f64)> = match sample_times {
            Some(times) if path.span > 0.0 => {
                if let Some(w) = times
                    .windows(2)
                    .find(|w| w[0] >= w[1] || w[0].is_nan() || w[1].is_nan())
                {
                    return Err(NanofoldError::invalid(
                        "sample_times",
                        format!("{} then {}", w[0], w[1]),
                        "must rise",
                    ));
                }
                times
                    .iter()
                    .filter(|&&t| t >= 0.0 && t <= path.span)
                    .map(|&t| (t / path.span, t))
                    .collect()
            }
            _ => Vec::new(),
        };
        let n = model.columns();
        if stiffness.len() != n || forcing.hinges.len() != n {
            return Err(NanofoldError::invalid(
                "hinges",
                format!("{} stiffnesses, {} drives", stiffness.len(), forcing.hinges.len()),
                format!("one per crease ({n})"),
            ));
        }
        let mut run = Run {
            net: self,
            model,
            spaced: sample_times.is_none(),
            stops,
            samples: Vec::new(),
            located: Vec::new(),
            drive_rate: Vec::new(),
            path,
            stiffness,
            capture: settings.capture_percent / 100.0,
            data: NetworkData::new(model),
            drive: vec![0.0; n],
            theta: vec![0.0; n],
            sides: Sides {
                friction: settings.friction_coefficient,
                ..Sides::new(&self.contacts, TOLERANCE * self.size)
            },
            raw: vec![None; self.contacts.features.len()],
            holds: Holds::new(self.seams.len()),
            previous: None,
            report: ClosingReport {
                outcome: Outcome::Stalls,
                time_s: 0.0,
                progress: 0.0,
                first_contact_time_s: None,
                latches: Vec::new(),
                contacts: Vec::new(),
                jam: None,
                final_contacts: Vec::new(),
                open_seams: Vec::new(),
                undecided: None,
                final_drive: Vec::new(),
                frames: Vec::new(),
            },
        };
        match run.drive_through() {
            Ok(()) => {}
            Err(Stop::Snap(u, why)) => {
                run.end(Outcome::Snaps, u);
                run.report.undecided = Some(why);
            }
            Err(Stop::NoBalance(u, why)) => {
                // No balance holds the seams and contacts here: the run cannot say what the
                // device does next, and says so (counted as not closing).
                run.end(Outcome::Undecided, u);
                run.report.undecided = Some(why);
            }
        }
        let u_end = run.report.progress;
        if held_on {
            if run.report.outcome == Outcome::Closes {
                run.follow_closed();
            }
            let spent = run.stops.is_empty() && run.path.span >= forcing.duration();
            if spent && !matches!(run.report.outcome, Outcome::Snaps | Outcome::Undecided) {
                let span = run.path.span;
                for &t in sample_times.unwrap_or(&[]).iter().filter(|&&t| t > span) {
                    run.push_sample(t, vec![0.0; n]);
                }
            }
        } else if sample_times.is_some() && run.samples.last().is_none_or(|s| s.time_s < run.path.time(u_end)) {
            // The state where the run ended, when it ended before the last asked time.
            run.stops = vec![(u_end, run.path.time(u_end))];
            run.sample_stops(u_end);
        }
        update_poses(model, &run.theta, &mut run.data);
        run.report.open_seams = self.open(&run.data, &run.holds);
        run.report.final_contacts = self.forces(&run.data, &run.holds, &run.sides);
        run.report.final_drive = run.drive.clone();
        Ok(ReleasedPath {
            qp_solves: run.sides.solves.get(),
            report: run.report,
            samples: run.samples,
        })
    }

    fn open(&self, data: &NetworkData, holds: &Holds) -> Vec<(usize, f64)> {
        (0..self.seams.len())
            .filter(|&k| holds.state[k] != SeamState::Latched)
            .map(|k| (k, self.misalignment(data, k)))
            .collect()
    }

    /// The touching features' forces as reported.
    fn forces(&self, data: &NetworkData, holds: &Holds, sides: &Sides) -> Vec<ContactForce> {
        let placed = self.contacts.placed(data);
        holds
            .touching
            .iter()
            .zip(&holds.forces)
            .map(|(&k, &force)| {
                let state = sides.state(&self.contacts, &placed, k);
                let feature = self.contacts.features[k];
                let normal = state.normal;
                ContactForce {
                    faces: feature.faces().map(|f| self.file_face[f]),
                    feature: feature_name(&feature),
                    point_um: [state.point.x, state.point.y, state.point.z].map(|x| x * 1e6),
                    normal: [normal.x, normal.y, normal.z],
                    gap_um: state.distance * 1e6,
                    force_n: force,
                    friction_n: holds
                        .friction
                        .iter()
                        .find(|f| f.0 == k)
                        .map_or([0.0; 3], |f| [f.1.x, f.1.y, f.1.z]),
                }
            })
            .collect()
    }

    /// The quasi-static balance with the seams `latched` held (no contact), from the fold
    /// angles `start`: the angles minimising Σ ½ K (θ − r)² (r = `drive`) on the seams'
    /// closures.
    pub fn balance(
        &self,
        model: &NetworkModel,
        drive: &[f64],
        stiffness: &[f64],
        latched: &[usize],
        start: &[f64],
    ) -> Result<Vec<f64>> {
        let n = model.columns();
        if drive.len() != n || stiffness.len() != n || start.len() != n {
            return Err(NanofoldError::invalid(
                "fold_angles",
                format!(
                    "{} drives, {} stiffnesses, {} angles",
                    drive.len(),
                    stiffness.len(),
                    start.len()
                ),
                format!("one per crease ({n})"),
            ));
        }
        if let Some(&k) = latched.iter().find(|&&k| k >= self.seams.len()) {
            return Err(NanofoldError::invalid(
                "latched",
                k,
                format!("the net has seams 0 to {}", self.seams.len() - 1),
            ));
        }
        let mut theta = start.to_vec();
        let mut data = NetworkData::new(model);
        let mut holds = Holds::new(self.seams.len());
        latched
            .iter()
            .for_each(|&k| holds.latch(k, self.seams[k].faces, &self.contacts.features));
        if !self.settle_closures(model, drive, stiffness, &holds, &mut theta, &mut data) {
            return Err(NanofoldError::invalid(
                "latched",
                format!("{latched:?}"),
                "the latched seams hold no balance near the start",
            ));
        }
        Ok(theta)
    }

    /// The rows `held` holds at fold angles `theta`: each latched seam's five rows (over
    /// the size), then each pressing contact's gap on its side (over the size), with their
    /// derivatives in the fold angles (one column per crease). Pressing contacts whose rows
    /// are parallel to one already read (one meeting seen by two features) are left out,
    /// as the balance leaves them: (residuals, rows, the contacts kept).
    pub fn held_rows(
        &self,
        model: &NetworkModel,
        theta: &[f64],
        held: &HeldRows,
    ) -> Result<(DVector<f64>, DMatrix<f64>, Vec<usize>)> {
        let n = model.columns();
        if theta.len() != n {
            return Err(NanofoldError::invalid(
                "fold_angles",
                theta.len(),
                format!("one per crease ({n})"),
            ));
        }
        if let Some(&k) = held.latched.iter().find(|&&k| k >= self.seams.len()) {
            return Err(NanofoldError::invalid(
                "latched",
                k,
                format!("the net has {} seams", self.seams.len()),
            ));
        }
        if let Some(p) = held.pressing.iter().find(|p| p.0 >= self.contacts.features.len()) {
            return Err(NanofoldError::invalid(
                "pressing",
                p.0,
                format!("the net has {} contact features", self.contacts.features.len()),
            ));
        }
        let mut data = NetworkData::new(model);
        update_poses(model, theta, &mut data);
        let mut holds = Holds::new(self.seams.len());
        held.latched
            .iter()
            .for_each(|&k| holds.latch(k, self.seams[k].faces, &self.contacts.features));
        let (seam_residual, seam_rows) = self.seam_rows(&data, &holds, n);
        let mut sides = Sides::new(&self.contacts, TOLERANCE * self.size);
        for &(k, side, reference, force) in &held.pressing {
            sides.sign[k] = side;
            sides.reference[k] = reference;
            holds.touching.push(k);
            holds.forces.push(force);
        }
        let (gaps, rows) = self.contact_rows(&data, &holds, &sides, n);
        let mut kept: Vec<usize> = Vec::new();
        for i in 0..rows.nrows() {
            let row = rows.row(i);
            let parallel = kept.iter().any(|&j| {
                let other = rows.row(j);
                other.dot(&row).abs() >= (1.0 - PARALLEL_ROWS) * other.norm() * row.norm()
            });
            if !parallel && row.norm() > 0.0 {
                kept.push(i);
            }
        }
        let count = seam_rows.nrows() + kept.len();
        let mut residual = DVector::zeros(count);
        let mut jacobian = DMatrix::zeros(count, n);
        residual.rows_mut(0, seam_rows.nrows()).copy_from(&seam_residual);
        jacobian.rows_mut(0, seam_rows.nrows()).copy_from(&seam_rows);
        for (r, &i) in kept.iter().enumerate() {
            let at = seam_rows.nrows() + r;
            residual[at] = gaps[i] / self.size;
            jacobian.row_mut(at).copy_from(&(rows.row(i) / self.size));
        }
        Ok((residual, jacobian, kept))
    }

    /// Where a run's faces first met: (time s, the two panels' names, the point in m): the
    /// first contact's point, or the middle of the first latching seam's first edge.
    pub fn first_meeting(
        &self,
        model: &NetworkModel,
        report: &ClosingReport,
    ) -> Option<(f64, [String; 2], Vector3<f64>)> {
        let time = report.first_contact_time_s?;
        let name = |file_face: usize| {
            let face = self.file_face.iter().position(|&f| f == file_face).unwrap_or(0);
            model.panel_names[self.contacts.face_panel[face]].clone()
        };
        if let Some(c) = report.contacts.iter().find(|c| c.time_s == time) {
            let point = Vector3::new(c.point_um[0], c.point_um[1], c.point_um[2]) * 1e-6;
            return Some((time, c.faces.map(name), point));
        }
        let latch = report.latches.iter().find(|l| l.time_s == time)?;
        let frame = report.frames.iter().find(|f| f.time_s == time)?;
        let mut data = NetworkData::new(model);
        update_poses(model, &frame.fold_angles, &mut data);
        let seam = &self.seams[latch.seam];
        let [a, _] = seam.faces;
        let point = (self.place(&data, a, seam.ends[0][0]) + self.place(&data, a, seam.ends[1][0])) * 0.5;
        Some((time, latch.faces.map(name), point))
    }

    /// Every pattern vertex's place at fold angles `theta`, in units of the pattern (for
    /// checks against the solid).
    pub fn vertex_places(&self, model: &NetworkModel, theta: &[f64]) -> Vec<[f64; 3]> {
        let mut data = NetworkData::new(model);
        update_poses(model, theta, &mut data);
        let mut places = vec![[f64::NAN; 3]; self.contacts.flat.len()];
        for (f, face) in self.contacts.faces.iter().enumerate() {
            for &v in face {
                let x = self.place(&data, f, v) / self.unit;
                places[v] = [x.x, x.y, x.z];
            }
        }
        places
    }
}

fn feature_name(feature: &Feature) -> &'static str {
    match feature {
        Feature::CornerOnFace { .. } => "corner on face",
        Feature::EdgeOnCorner { .. } => "edge on a shared corner",
        Feature::EdgeOnEdge { .. } => "edge on edge",
        Feature::EdgeMiddleOnFace { .. } => "seam edge across a face",
    }
}

/// Why a run stopped before the end of its drives (at a progress).
enum Stop {
    /// The balance jumped: the path lost its stability there.
    Snap(f64, String),
    /// No balance was found.
    NoBalance(f64, String),
}

/// One closing run's state: the angles, what holds the faces, the report so far.
struct Run<'a> {
    net: &'a NetClosing,
    model: &'a NetworkModel,
    path: DrivePath<'a>,
    stiffness: &'a [f64],
    capture: f64,
    data: NetworkData,
    drive: Vec<f64>,
    theta: Vec<f64>,
    sides: Sides,
    holds: Holds,
    /// Each feature's raw state at the poses last tested for events, if read there.
    raw: Vec<Option<FeatureState>>,
    /// The progress and angles one step back along the same holds (none past an event):
    /// the path's secant from it starts the next balance.
    previous: Option<(f64, Vec<f64>)>,
    report: ClosingReport,
    /// Frames every [`FRAME_SPACING`] of the path (else only at events and `stops`).
    spaced: bool,
    /// Progresses still to sample, ascending, with the times asked (recorded as asked, not
    /// as the progress maps back).
    stops: Vec<(f64, f64)>,
    samples: Vec<PathSample>,
    /// The seams whose closest approach the last bisection located (see [`Run::locate`]).
    located: Vec<usize>,
    /// The drives' rates dr/du over the step being taken (they are linear in u between
    /// the path's breaks, and no step crosses one).
    drive_rate: Vec<f64>,
}

impl Run<'_> {
    /// From flat to the end of the drives, the report filled.
    fn drive_through(&mut self) -> std::result::Result<(), Stop> {
        let net = self.net;
        self.settle_at(0.0)?;
        self.drive_rate = vec![0.0; self.theta.len()];
        self.path.rates(0.0, &mut self.drive_rate);
        self.read_approach(&self.holds.clone());
        self.keep_approach();
        self.keep_frame(0.0);
        self.sample_stops(0.0);
        let mut last_frame = 0.0;
        let mut u = 0.0;
        let mut turn = MAX_STEP;
        let (mut last_event, mut repeats) = (f64::NEG_INFINITY, 0);
        let mut unsettled = 0;
        let mut unpredicted = false;
        while u < 1.0 {
            // A step that starts with contacts held is a held step, whatever the last was.
            if !self.holds.touching.is_empty() {
                turn = turn.min(MAX_STEP);
            }
            let next = match self.stops.first().map(|s| s.0) {
                Some(stop) if stop > u => self.path.next(u, turn).min(stop),
                _ => self.path.next(u, turn),
            };
            let mut trial = self.theta.clone();
            // Along contacts, from the path's secant: the balance then starts a step's
            // curvature away, not its slope. A start so predicted that does not settle, or
            // settles far off, is tried again from the last balance before anything else.
            let predicted = match self.previous.as_ref() {
                Some((before, angles)) if !self.holds.touching.is_empty() && !unpredicted => {
                    let ahead = (next - u) / (u - before);
                    for c in 0..trial.len() {
                        trial[c] += ahead * (self.theta[c] - angles[c]);
                    }
                    true
                }
                _ => false,
            };
            unpredicted = false;
            let mut holds = self.holds.clone();
            // The step's slip counts from the last balance, not from its predicted start.
            holds.origin = Some(self.theta.clone());
            self.path.drive(u, &mut self.drive);
            let before = self.drive.clone();
            self.path.drive(next, &mut self.drive);
            self.path.rates(u, &mut self.drive_rate);
            // A drive may itself jump (a hinge released with a step); the balance is
            // measured against what its drives did.
            let driven = (0..before.len())
                .map(|c| (self.drive[c] - before[c]).abs())
                .fold(turn, f64::max);
            let settled = net.settle(
                self.model,
                &self.drive,
                self.stiffness,
                &mut holds,
                &self.sides,
                &mut trial,
                &mut self.data,
            );
            let jump = (0..trial.len())
                .map(|c| (trial[c] - self.theta[c]).abs())
                .fold(0.0, f64::max);
            if predicted && (!settled || jump > JUMP_RATIO * driven + JUMP_FLOOR) {
                unpredicted = true;
                continue;
            }
            unsettled = if settled { 0 } else { unsettled + 1 };
            if !settled || jump > JUMP_RATIO * driven + JUMP_FLOOR {
                // A balance that moves far more than its drives: halve the step until it
                // follows, or the step is too small to say anything but that it jumped. A
                // balance not found at all is tried on steps down to 1/1024 of the first.
                if turn > MIN_TURN && unsettled <= UNSETTLED_HALVINGS {
                    turn *= 0.5;
                    continue;
                }
                return Err(if !settled && holds.unstable {
                    Stop::Snap(
                        u,
                        format!(
                            "the balance along the contacts turns unstable at progress {u:.9} (time {:.6e} s): the path passes a snap-through",
                            self.path.time(u)
                        ),
                    )
                } else if settled {
                    Stop::Snap(
                        u,
                        format!(
                            "the balance jumped by {jump:.3e} rad for a drive step of {turn:.1e} rad at progress {u:.9}: the path loses its stability (a snap-through)"
                        ),
                    )
                } else {
                    self.no_balance(next, holds.failure)
                });
            }
            // A pair out of reach must not come to touch in one step unseen: shorten the step
            // until it lands within reach first.
            let unseen = (0..net.contacts.pairs.len())
                .any(|p| !self.sides.watched[p] && net.contacts.pair_gap(&self.data, p) <= 0.0);
            if unseen && turn > MIN_TURN {
                turn *= 0.5;
                continue;
            }
            let largest = if holds.touching.is_empty() {
                net.free_step
            } else {
                MAX_STEP
            };
            turn = (turn * 2.0).min(largest);
            let mut raw = std::mem::take(&mut self.raw);
            raw.iter_mut().for_each(|r| *r = None);
            let placed = net.contacts.placed(&self.data);
            self.read_approach(&holds);
            let happenings = net.events(
                (&self.data, &placed),
                &holds,
                &self.sides,
                self.capture,
                EventScan::Every(&mut raw),
            );
            if happenings.is_empty() {
                let before = std::mem::replace(&mut self.theta, trial);
                self.previous = (self.holds.touching == holds.touching && self.holds.latched == holds.latched)
                    .then_some((u, before));
                self.holds = holds;
                self.raw = raw;
                self.after_step_at(placed);
                self.keep_approach();
                u = next;
                self.sample_stops(u);
                if self.spaced && u - last_frame >= FRAME_SPACING {
                    self.keep_frame(u);
                    last_frame = u;
                }
                continue;
            }
            // Read at `next`, not where the event is located.
            raw.iter_mut().for_each(|r| *r = None);
            self.raw = raw;
            self.previous = None;
            u = self.locate(u, next, trial, holds, &happenings);
            // Events that come back at once with nothing new resolved (a contact let go that
            // crosses again) would step the run along by rounding for ever: past a few,
            // the run stops and says where.
            if u - last_event < REPEATED_EVENT {
                repeats += 1;
                if repeats > MAX_REPEATS {
                    return Err(Stop::NoBalance(
                        u,
                        format!("contacts keep meeting again without settling at progress {u:.9}"),
                    ));
                }
            } else {
                repeats = 0;
            }
            last_event = u;
            self.keep_frame(u);
            let closed = self.resolve(u)?;
            self.sample_stops(u);
            if closed {
                return Ok(());
            }
            last_frame = u;
        }
        update_poses(self.model, &self.theta, &mut self.data);
        let holding = self.held_by_contact();
        let free = if net.seams.is_empty() {
            Outcome::Rests
        } else {
            Outcome::Stalls
        };
        self.end(if holding { Outcome::Jams } else { free }, 1.0);
        if holding {
            let contacts = net.forces(&self.data, &self.holds, &self.sides);
            let hardest = contacts
                .iter()
                .max_by(|a, b| a.force_n.total_cmp(&b.force_n))
                .map(|c| c.faces)
                .unwrap_or_default();
            self.report.jam = Some(Jam {
                faces: hardest,
                time_s: self.path.time(1.0),
                progress: 1.0,
                contacts,
                seams: net.seam_forces(&self.data, &self.holds),
            });
        }
        self.keep_frame(1.0);
        Ok(())
    }

    /// Whether the contacts hold the faces where they are: without them (the latched seams
    /// still held) the balance would move. Forces on contacts that hold nothing (a face
    /// resting flush on another, or one of several rows sharing a load the seams carry) are
    /// a split of a load that statics leaves open, not a jam.
    fn held_by_contact(&self) -> bool {
        if !self.holds.forces.iter().any(|&f| f > 0.0) {
            return false;
        }
        let mut free = self.theta.clone();
        let mut holds = self.holds.clone();
        holds.touching.clear();
        holds.forces.clear();
        let mut data = NetworkData::new(self.model);
        let settled = self
            .net
            .settle_closures(self.model, &self.drive, self.stiffness, &holds, &mut free, &mut data);
        !settled || (0..free.len()).any(|c| (free[c] - self.theta[c]).abs() > HELD_MOVE)
    }

    /// After a step: features that parted or slid off the other face let go; features that
    /// came over another face take the side they are on.
    fn after_step(&mut self) {
        let placed = self.net.contacts.placed(&self.data);
        self.after_step_at(placed);
    }

    /// [`Run::after_step`] with the faces already `placed` at the accepted poses.
    fn after_step_at(&mut self, placed: PlacedFaces) {
        let net = self.net;
        let tolerance = TOLERANCE * net.size;
        let mut keep = Vec::new();
        for (i, &k) in self.holds.touching.iter().enumerate() {
            let state = self.sides.state(&net.contacts, &placed, k);
            // A contact lets go once its faces part. One that slides off the other face's
            // outline while still touching stays until they part (its plane held a little
            // past the outline): let go at the outline, it would cross again at once.
            if state.distance <= PART * net.size {
                keep.push(i);
            }
        }
        self.holds.forces = keep.iter().map(|&i| self.holds.forces[i]).collect();
        self.holds.touching = keep.iter().map(|&i| self.holds.touching[i]).collect();
        let reach = REACH * net.size;
        for pair in 0..net.contacts.pairs.len() {
            let near = net.contacts.pair_gap(&self.data, pair) <= reach;
            let (was, was_separated) = (self.sides.watched[pair], self.sides.separated[pair]);
            self.sides.watched[pair] = near;
            self.sides.separated[pair] = false;
            if !near {
                continue;
            }
            if !net.pair_open(&placed, &self.holds, pair) {
                // Apart (or held by a seam): its sides stay as they are here.
                self.sides.separated[pair] = true;
                continue;
            }
            for &k in &net.contacts.pair_features[pair] {
                if self.holds.touching.contains(&k) {
                    continue;
                }
                // The step's events read every open pair's features at these poses already.
                let raw = match self.raw[k].take() {
                    Some(raw) => raw,
                    None => net.contacts.state(&placed, k),
                };
                if !was || was_separated {
                    // Its sides as they were at the last accepted poses, where the pair was
                    // out of reach or apart (no crossing there; a latch's pull since may
                    // have carried it across), then carried here.
                    match self.sides.last.as_ref() {
                        Some(last) => {
                            let before = net.contacts.state(last, k);
                            self.sides.refresh(k, before, tolerance);
                        }
                        None => {
                            self.sides.refresh(k, raw, tolerance);
                            continue;
                        }
                    }
                }
                self.sides.update(&net.contacts, k, raw, tolerance);
            }
        }
        self.sides.last = Some(placed);
        self.raw.iter_mut().for_each(|r| *r = None);
    }

    /// The open seams' approach rates at the poses `self.data` holds, along the balance's
    /// tangent with `holds` held on this step's drives.
    fn read_approach(&mut self, holds: &Holds) {
        let net = self.net;
        let tangent = net.path_tangent(&self.data, holds, &self.sides, &self.drive_rate, self.stiffness);
        let mut approach = std::mem::take(&mut self.sides.approach);
        net.read_approach(&self.data, holds, &tangent, &mut approach);
        self.sides.approach = approach;
    }

    /// At accepted poses: whether each seam approaches there on the step that reached them
    /// (as it was, for one at rest).
    fn keep_approach(&mut self) {
        self.sides.approaching.resize(self.net.seams.len(), false);
        for (approaching, &(rate, floor)) in self.sides.approaching.iter_mut().zip(&self.sides.approach) {
            if rate < -floor {
                *approaching = true;
            } else if rate > floor {
                *approaching = false;
            }
        }
    }

    /// The state at every asked progress reached by `u`, with its rates.
    fn sample_stops(&mut self, u: f64) {
        while let Some(&(stop, time_s)) = self.stops.first() {
            if stop > u {
                break;
            }
            self.stops.remove(0);
            let rates = self.rates_at(u);
            self.push_sample(time_s, rates);
        }
    }

    /// Past a closing, the closed device at every stop still asked, its drives going on
    /// with every seam held, while a balance is found.
    fn follow_closed(&mut self) {
        while let Some(&(stop, _)) = self.stops.first() {
            self.path.drive(stop, &mut self.drive);
            let mut trial = self.theta.clone();
            let mut holds = self.holds.clone();
            let settled = self.net.settle(
                self.model,
                &self.drive,
                self.stiffness,
                &mut holds,
                &self.sides,
                &mut trial,
                &mut self.data,
            );
            if !settled {
                return;
            }
            self.theta = trial;
            self.holds = holds;
            self.sample_stops(stop);
        }
    }

    /// Records the state as the sample at `time_s`.
    fn push_sample(&mut self, time_s: f64, rates: Vec<f64>) {
        let pressing = (0..self.holds.touching.len())
            .filter(|&i| self.holds.forces[i] > 0.0)
            .map(|i| {
                let k = self.holds.touching[i];
                let (side, reference) = self.sides.orientation(&self.net.contacts, k);
                (k, side, reference, self.holds.forces[i])
            })
            .collect();
        self.samples.push(PathSample {
            time_s,
            fold_angles: self.theta.clone(),
            rates,
            held: HeldRows {
                latched: self.holds.latched.clone(),
                pressing,
            },
        });
    }

    /// dθ/dt at progress `u`: the balance with the same holds settled a small turn of the
    /// drives either side, differenced; one-sided where a drive starts or stops within
    /// that turn (the path's slope jumps there), at the path's ends, or where one side
    /// finds no balance; the secant from the last sample where neither does.
    fn rates_at(&self, u: f64) -> Vec<f64> {
        let n = self.theta.len();
        let ahead = (self.path.next(u, RATE_TURN) - u).min(RATE_PROGRESS);
        let last_break = self.path.breaks.iter().copied().filter(|&b| b <= u).fold(0.0, f64::max);
        let behind = (u - last_break).min(RATE_PROGRESS);
        let settled_at = |v: f64| -> Option<Vec<f64>> {
            let mut drive = vec![0.0; n];
            self.path.drive(v, &mut drive);
            let mut theta = self.theta.clone();
            let mut holds = self.holds.clone();
            let mut data = NetworkData::new(self.model);
            self.net
                .settle(
                    self.model,
                    &drive,
                    self.stiffness,
                    &mut holds,
                    &self.sides,
                    &mut theta,
                    &mut data,
                )
                .then_some(theta)
        };
        let h = ahead.min(behind);
        let central = (h > 0.0 && h >= 0.5 * ahead.max(behind))
            .then(|| settled_at(u - h).zip(settled_at(u + h)))
            .flatten()
            .map(|(before, after)| (u - h, before, u + h, after));
        let differenced = central
            .or_else(|| {
                (ahead > 0.0)
                    .then(|| settled_at(u + ahead))
                    .flatten()
                    .map(|a| (u, self.theta.clone(), u + ahead, a))
            })
            .or_else(|| {
                (behind > 0.0)
                    .then(|| settled_at(u - behind))
                    .flatten()
                    .map(|b| (u - behind, b, u, self.theta.clone()))
            });
        if let Some((from_u, from, to_u, to)) = differenced {
            let dt = self.path.time(to_u) - self.path.time(from_u);
            if dt > 0.0 {
                return (0..n).map(|c| (to[c] - from[c]) / dt).collect();
            }
        }
        match self.samples.last() {
            Some(last) if self.path.time(u) > last.time_s => {
                let dt = self.path.time(u) - last.time_s;
                (0..n).map(|c| (self.theta[c] - last.fold_angles[c]) / dt).collect()
            }
            _ => vec![0.0; n],
        }
    }

    fn keep_frame(&mut self, u: f64) {
        self.report.frames.push(ClosingFrame {
            time_s: self.path.time(u),
            progress: u,
            fold_angles: self.theta.clone(),
        });
    }

    fn no_balance(&self, u: f64, failure: Option<SettleFailure>) -> Stop {
        if self.sides.solves.get() > RUN_SOLVES {
            return Stop::NoBalance(
                u,
                format!(
                    "the balance with {} latched seams and {} contacts still creeping after {RUN_SOLVES} QP solves at progress {u:.9}",
                    self.holds.latched.len(),
                    self.holds.touching.len()
                ),
            );
        }
        Stop::NoBalance(
            u,
            format!(
                "no balance holds the {} latched seams and {} contacts at progress {u:.9}{}",
                self.holds.latched.len(),
                self.holds.touching.len(),
                failure.map_or(String::new(), |f| format!(" ({})", f.describe()))
            ),
        )
    }

    /// The balance at progress `u` from the current angles.
    fn settle_at(&mut self, u: f64) -> std::result::Result<(), Stop> {
        self.path.drive(u, &mut self.drive);
        let net = self.net;
        if net.settle(
            self.model,
            &self.drive,
            self.stiffness,
            &mut self.holds,
            &self.sides,
            &mut self.theta,
            &mut self.data,
        ) {
            Ok(())
        } else {
            Err(self.no_balance(u, self.holds.failure))
        }
    }

    /// The first progress in (u, next] where something happens, `at_next` its balance at
    /// `next`: bisected to [`LOCATE`]; the angles are left at it.
    /// Only the `happenings` found at `next` are watched: what happens first in the step
    /// is among what has happened by its end.
    fn locate(&mut self, u: f64, next: f64, at_next: Vec<f64>, holds_next: Holds, happenings: &[Happening]) -> f64 {
        let net = self.net;
        let (mut lo, mut hi, mut at_hi, mut holds_hi) = (u, next, at_next, holds_next);
        let mut found_at_hi = happenings.to_vec();
        let mut approach_hi = self.sides.approach.clone();
        while hi - lo > LOCATE * (1.0 + hi.abs()) {
            let mid = 0.5 * (lo + hi);
            let mut state = self.theta.clone();
            let mut holds = self.holds.clone();
            self.path.drive(mid, &mut self.drive);
            net.settle(
                self.model,
                &self.drive,
                self.stiffness,
                &mut holds,
                &self.sides,
                &mut state,
                &mut self.data,
            );
            let placed = net.contacts.placed(&self.data);
            self.read_approach(&holds);
            let found = net.events(
                (&self.data, &placed),
                &holds,
                &self.sides,
                self.capture,
                EventScan::Among(happenings),
            );
            if !found.is_empty() {
                hi = mid;
                at_hi = state;
                holds_hi = holds;
                found_at_hi = found;
                approach_hi.clone_from(&self.sides.approach);
            } else {
                lo = mid;
                self.theta = state;
                self.holds = holds;
            }
        }
        self.theta = at_hi;
        self.holds = holds_hi;
        // The located poses are accepted: each seam's direction there on the step's path
        // (where another's latch turns the path, one still approaching meets it there).
        self.sides.approach = approach_hi;
        self.keep_approach();
        self.located = found_at_hi
            .iter()
            .filter_map(|h| match h {
                Happening::Seam(k) => Some(*k),
                Happening::Feature(_) => None,
            })
            .collect();
        hi
    }

    /// Latches what meets in line (or touches within the capture), puts what crossed into
    /// contact, and balances again until nothing new happens. Returns whether the run is
    /// over (closed).
    fn resolve(&mut self, u: f64) -> std::result::Result<bool, Stop> {
        let net = self.net;
        let tolerance = TOLERANCE * net.size;
        // Whether a round's contacts have yet to be balanced (its latches were undone).
        let mut unbalanced = false;
        for _ in 0..RESOLVE_ROUNDS {
            self.path.drive(u, &mut self.drive);
            update_poses(self.model, &self.theta, &mut self.data);
            let mut touched = Vec::new();
            let placed = net.contacts.placed(&self.data);
            for k in self.sides.watched(&net.contacts) {
                if self.sides.orientation(&net.contacts, k).0 == 0.0
                    || self.holds.touching.contains(&k)
                    || net.held_by_seam(&self.holds, k)
                {
                    continue;
                }
                let state = self.sides.state(&net.contacts, &placed, k);
                if state.over && state.distance <= tolerance {
                    touched.push((k, state));
                }
            }
            for &(k, state) in &touched {
                // The side it touches from is the one it held (read where its pair was last
                // apart, if it was): carried from here on.
                self.sides.commit(&net.contacts, k);
                self.holds.touch(k);
                let feature = net.contacts.features[k];
                self.report.first_contact_time_s.get_or_insert(self.path.time(u));
                self.report.contacts.push(Contact {
                    faces: feature.faces().map(|f| net.file_face[f]),
                    feature: feature_name(&feature),
                    time_s: self.path.time(u),
                    progress: u,
                    point_um: [state.point.x, state.point.y, state.point.z].map(|x| x * 1e6),
                });
            }
            let new: Vec<(usize, f64)> = (0..net.seams.len())
                .filter(|&k| self.holds.state[k] == SeamState::Open)
                .filter_map(|k| {
                    let m = net.misalignment(&self.data, k);
                    (m <= ALIGNED_TOGETHER
                        || (m <= self.capture
                            && !self.holds.blocked[k]
                            && (net.seam_touching(&self.holds, k) || self.located.contains(&k))))
                    .then_some((k, m))
                })
                .collect();
            if new.is_empty() && touched.is_empty() && !unbalanced {
                // Nothing more happens: the run goes on from here, and a seam whose closest
                // approach was located here recedes from it.
                for k in std::mem::take(&mut self.located) {
                    self.sides.approaching[k] = false;
                }
                return Ok(false);
            }
            unbalanced = false;
            let before = (self.holds.clone(), self.theta.clone());
            for &(k, _) in &new {
                self.holds.latch(k, net.seams[k].faces, &net.contacts.features);
            }
            if let Err(stop) = self.settle_at(u) {
                // A capture's pull that contact holds off is no latch: the seams stay open,
                // caught no more until they meet in line, and the balance is taken without.
                let captured: Vec<usize> = new
                    .iter()
                    .filter(|&&(_, m)| m > ALIGNED_TOGETHER)
                    .map(|&(k, _)| k)
                    .collect();
                if captured.is_empty() {
                    return Err(stop);
                }
                (self.holds, self.theta) = before;
                for &k in &captured {
                    self.holds.blocked[k] = true;
                }
                update_poses(self.model, &self.theta, &mut self.data);
                unbalanced = true;
                continue;
            }
            for &(k, m) in &new {
                self.report.first_contact_time_s.get_or_insert(self.path.time(u));
                self.report.latches.push(Latch {
                    seam: k,
                    faces: net.seams[k].faces.map(|f| net.file_face[f]),
                    time_s: self.path.time(u),
                    progress: u,
                    misalignment: m,
                });
            }
            self.after_step();
            self.keep_frame(u);
            if !net.seams.is_empty() && self.holds.latched.len() == net.seams.len() {
                self.end(Outcome::Closes, u);
                return Ok(true);
            }
        }
        Err(Stop::NoBalance(
            u,
            format!("contacts and latches still changing after {RESOLVE_ROUNDS} rounds at progress {u:.9}"),
        ))
    }

    fn end(&mut self, outcome: Outcome, u: f64) {
        self.report.outcome = outcome;
        self.report.time_s = self.path.time(u);
        self.report.progress = u;
    }
}

/// The drives' path as a progress u ∈ [0, 1]: a ramp's time over its whole duration (or up
/// to an end time before that), a step's straight path at t = 0⁺.
struct DrivePath<'a> {
    forcing: &'a Forcing,
    /// The time the path ends at: the drives' duration, or an earlier end, s.
    span: f64,
    /// The end time the forcing is read with (∞: the drives' end), s.
    t_end: f64,
    /// Progresses where a drive starts or stops moving.
    breaks: Vec<f64>,
}

impl<'a> DrivePath<'a> {
    fn new(forcing: &'a Forcing, t_end: f64) -> Self {
        let span = forcing.duration().min(t_end);
        let breaks = if span > 0.0 {
            forcing
                .breakpoints()
                .iter()
                .filter(|&&t| t < span)
                .map(|t| t / span)
                .collect()
        } else {
            Vec::new()
        };
        DrivePath {
            forcing,
            span,
            t_end,
            breaks,
        }
    }

    fn drive(&self, u: f64, out: &mut [f64]) {
        self.forcing.drive_along(u, self.t_end, out);
    }

    fn time(&self, u: f64) -> f64 {
        self.forcing.time_along(u, self.t_end)
    }

    /// The drives' rates dr/du on the steps from `u` (constant up to the next break: the
    /// drives are linear in u between breaks, and no step crosses one), read from the
    /// forcing inside the stretch, never at its ends, and not differenced (a step may be a
    /// rounding's width).
    fn rates(&self, u: f64, out: &mut [f64]) {
        if self.span > 0.0 {
            let t = 0.5 * (u + self.stretch_end(u)) * self.span;
            for (i, rate) in out.iter_mut().enumerate() {
                *rate = self.forcing.drive_rate(i, t) * self.span;
            }
        } else {
            for (rate, hinge) in out.iter_mut().zip(&self.forcing.hinges) {
                *rate = hinge.target;
            }
        }
    }

    /// The progress where the stretch of the path from `u` ends: its next break, or 1.
    fn stretch_end(&self, u: f64) -> f64 {
        self.breaks
            .iter()
            .copied()
            .find(|&b| b > u + 1e-15)
            .unwrap_or(1.0)
            .min(1.0)
    }

    /// The next progress to test from `u`: no drive turns more than `turn` on the way, and
    /// no break is passed.
    fn next(&self, u: f64, turn: f64) -> f64 {
        let next_break = self.stretch_end(u);
        let rate = if self.span > 0.0 {
            // The rates hold between breaks: read them inside the stretch, not at its start
            // (a ramp starting exactly there reads zero, rounded a hair before it).
            let t = 0.5 * (u + next_break) * self.span;
            (0..self.forcing.hinges.len())
                .map(|i| (self.forcing.drive_rate(i, t) * self.span).abs())
                .fold(0.0, f64::max)
        } else {
            self.forcing.hinges.iter().map(|h| h.target.abs()).fold(0.0, f64::max)
        };
        if rate == 0.0 {
            next_break
        } else {
            (u + turn / rate).min(next_break)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::nets::{best_net_patterns, net_device, nets, open_solid, NetsOptions};
    use crate::dynamics::forcing::{Actuation, HingeDrive};

    /// Every contact feature's row (the gap's derivative in the fold angles that the balance
    /// and the contacts' curvature are built on) against central differences of its gap,
    /// on the octahedron's two best nets at random fold angles.
    #[test]
    fn every_contact_row_is_its_gaps_derivative() {
        let (name, solid) = open_solid("octahedron").unwrap();
        let options = NetsOptions {
            top: 2,
            unit_um: 50.0,
            ..NetsOptions::default()
        };
        let report = nets(&name, &solid, &options).unwrap();
        let mut seed = 2024_u64;
        let mut uniform = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut checked, mut worst) = (0, 0.0_f64);
        for (_, made) in best_net_patterns(&solid, &report, 2).unwrap() {
            let scene = net_device(&made, "octahedron", &options).unwrap();
            let model = scene.network().unwrap();
            let closing = NetClosing::new(&made, model).unwrap();
            let contacts = &closing.contacts;
            let n = model.stiffness().len();
            let mut data = NetworkData::new(model);
            let mut row = DVector::zeros(n);
            let h = 1e-6;
            for _ in 0..20 {
                let theta: Vec<f64> = (0..n).map(|_| 0.2 + 1.6 * uniform()).collect();
                update_poses(model, &theta, &mut data);
                let placed = contacts.placed(&data);
                let shifted = |c: usize, by: f64| {
                    let mut t = theta.clone();
                    t[c] += by;
                    let mut d = NetworkData::new(model);
                    update_poses(model, &t, &mut d);
                    contacts.placed(&d)
                };
                let around: Vec<(PlacedFaces, PlacedFaces)> = (0..n).map(|c| (shifted(c, h), shifted(c, -h))).collect();
                for k in 0..contacts.features.len() {
                    let state = contacts.state(&placed, k);
                    if !state.distance.is_finite() {
                        continue;
                    }
                    contacts.row(&data, k, &state, &mut row);
                    // The same side's distance at the shifted angles (an edge pair's
                    // normal turned back to this one's).
                    let gap = |at: &PlacedFaces| {
                        let s = contacts.state(at, k);
                        if s.normal.dot(&state.normal) < 0.0 {
                            -s.distance
                        } else {
                            s.distance
                        }
                    };
                    for (c, (plus, minus)) in around.iter().enumerate() {
                        let difference = (gap(plus) - gap(minus)) / (2.0 * h);
                        // The rows are of the order of the faces' size (m/rad); differences
                        // lose about 1e-16 · size / h to rounding.
                        let error = (row[c] - difference).abs() / model.size();
                        worst = worst.max(error);
                        assert!(
                            error <= 1e-7,
                            "feature {k} {:?} column {c}: row {:e}, differences {difference:e}",
                            contacts.features[k],
                            row[c]
                        );
                        checked += 1;
                    }
                }
            }
        }
        eprintln!("{checked} derivatives checked (worst {worst:e})");
        assert!(checked > 10_000, "{checked} derivatives checked (worst {worst:e})");
    }

    /// Walking a ramp's path with [`DrivePath::next`], no drive turns more than the asked
    /// turn in one step, wherever a hinge's ramp starts: a ramp released at a break must not
    /// be stepped over whole (its rate read at the break's start rounds to before the
    /// release). Release times from 0.013 s to 2.6 s; the drives' own change is the check.
    /// Devices whose outcome the step decided under the earlier latches (a seam latched as
    /// its ends' offsets turned back within one step, or at its closest approach read from
    /// chords): the cube's nets released along a front, varied as the yield study varies
    /// them, run with the largest free step at 0.5° and at 2°, end alike.
    #[test]
    fn where_the_steps_fall_decides_no_outcome() {
        let (name, solid) = open_solid("cube").unwrap();
        let options = NetsOptions {
            top: 10,
            fronts: 16,
            yield_samples: 50,
            unit_um: 50.0,
            ..NetsOptions::default()
        };
        let report = nets(&name, &solid, &options).unwrap();
        let made = best_net_patterns(&solid, &report, 10).unwrap();
        // (net's rank from 1, front in degrees, device)
        let devices = [
            (1, 270.0, 8),
            (1, 270.0, 14),
            (1, 90.0, 0),
            (1, 90.0, 24),
            (2, 270.0, 10),
            (2, 90.0, 17),
            (2, 135.0, 33),
            (3, 90.0, 14),
            (4, 135.0, 17),
            (5, 90.0, 12),
            (10, 270.0, 0),
        ];
        let variation = options.variation();
        for (rank, front, sample) in devices {
            let (_, net) = &made[rank - 1];
            let released = NetsOptions {
                front_deg: Some(front),
                ..options.clone()
            };
            let scene = net_device(net, "cube", &released).unwrap();
            let model = scene.network().unwrap();
            let (forcing, stiffness) = variation.device(&model.forcing, &model.stiffness(), sample);
            let settings = ClosingSettings {
                capture_percent: options.closing().capture_percent,
                ..ClosingSettings::default()
            };
            let runs: Vec<ClosingReport> = [0.5_f64, 2.0]
                .map(|step| {
                    let mut closing = NetClosing::new(net, model).unwrap();
                    closing.free_step = step.to_radians();
                    closing.run(model, &forcing, &stiffness, &settings).unwrap()
                })
                .into();
            let device = format!("net {rank}, front {front}°, device {sample}");
            assert_eq!(runs[0].outcome, runs[1].outcome, "{device}");
            let seams = |run: &ClosingReport| {
                let mut latched: Vec<usize> = run.latches.iter().map(|l| l.seam).collect();
                latched.sort_unstable();
                latched
            };
            assert_eq!(seams(&runs[0]), seams(&runs[1]), "{device}");
            for (fine, coarse) in runs[0].latches.iter().zip(&runs[1].latches) {
                assert!(
                    (fine.time_s - coarse.time_s).abs() <= 1e-6 * fine.time_s,
                    "{device}: seam {} latches at {} s and {} s",
                    fine.seam,
                    fine.time_s,
                    coarse.time_s
                );
            }
        }
    }

    #[test]
    fn no_step_of_a_ramps_path_turns_a_drive_more_than_asked() {
        let turn = 0.5_f64.to_radians();
        let mut checked = 0;
        for k in 1..=200 {
            let release = 0.013 * k as f64;
            let forcing = Forcing {
                actuation: Actuation::Ramp { etch_rate: 1e-6 },
                hinges: vec![
                    HingeDrive {
                        target: 1.2,
                        radius_of_curvature: 1e-6 * release / 1.2,
                        actuated: true,
                        release_time: 0.0,
                    },
                    HingeDrive {
                        target: -1.5,
                        radius_of_curvature: 2e-6,
                        actuated: true,
                        release_time: release,
                    },
                ],
            };
            let path = DrivePath::new(&forcing, f64::INFINITY);
            let (mut before, mut after) = (vec![0.0; 2], vec![0.0; 2]);
            let mut u = 0.0;
            while u < 1.0 {
                let next = path.next(u, turn);
                assert!(next > u, "release {release} s: the path stops at {u}");
                path.drive(u, &mut before);
                path.drive(next, &mut after);
                let moved = (0..2).map(|i| (after[i] - before[i]).abs()).fold(0.0, f64::max);
                assert!(
                    moved <= turn * (1.0 + 1e-9),
                    "release {release} s: from progress {u} to {next} a drive turns {moved} rad"
                );
                u = next;
                checked += 1;
            }
        }
        assert!(checked > 10_000, "{checked} steps");
    }
}
