//! Whether a net's device closes (`docs/model.md#closing-a-net`): its quasi-static folding
//! carried past the first contact, each seam latching where its two edges meet, until every
//! seam is shut (`closes`), faces meet where no seam is (`jams`), or the drives are spent
//! (`stalls`).

use crate::dynamics::network::algorithms::update_poses;
use crate::dynamics::network::{NetworkData, NetworkModel};
use crate::dynamics::Forcing;
use crate::error::{NanofoldError, Result};
use crate::geometry::surface_intersection::convex_faces_meet;
use crate::pattern::net::NetPattern;
use nalgebra::{DMatrix, DVector, Point3, Vector3};
use serde::{Deserialize, Serialize};

/// The most any drive angle moves between two tests of the faces, rad (0.5°): a meeting
/// that begins and ends inside a smaller turn is not seen.
const MAX_STEP: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// A seam whose ends lie this close (a fraction of its length) has met edge to edge.
const ALIGNED: f64 = 1e-9;
/// Seams meeting together: within this of aligned at an event, they latch with it.
const ALIGNED_TOGETHER: f64 = 1e-6;
/// Faces are tested for meeting to this fraction of the net's size.
const TOLERANCE: f64 = 1e-9;
/// Bisection of an event's progress stops at this width.
const LOCATE: f64 = 1e-15;
/// A seam's ray within this of the other face's plane (the sine of their angle) has reached
/// it: the faces met there.
const PRESS_REACH: f64 = 1e-6;
/// A run's frames are kept at least this far apart in progress (and at every event).
const FRAME_SPACING: f64 = 0.005;
/// The latched seams' equilibrium: Gauss–Newton steps and the step that ends them, rad.
const SETTLE_ITERATIONS: usize = 200;
const SETTLE_STEP: f64 = 1e-13;
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
/// The rows count as held below this (over the net's size, or the sine of a press's angle).
const SETTLE_HELD: f64 = 1e-10;
/// The largest turn of one settling step, rad.
const SETTLE_DAMPING: f64 = 0.3;

/// How seams latch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClosingSettings {
    /// A seam latches when its faces meet with its two edges' ends at most this far apart,
    /// in % of the seam's length (above 0, at most 50): the solder or adhesive on the seam
    /// pulls them into line. Faces that meet farther apart jam.
    pub capture_percent: f64,
}

impl Default for ClosingSettings {
    fn default() -> Self {
        ClosingSettings { capture_percent: 10.0 }
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
        Ok(())
    }
}

/// How a closing run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Every seam latched.
    Closes,
    /// Two faces met where no seam joins them (or a seam's edges too far apart to latch).
    Jams,
    /// The drives reached their targets with seams still open.
    Stalls,
    /// No balance was found with the latched seams held (a singular state of their
    /// closures): the run stops there and says why; it does not count as closing.
    Undecided,
}

impl Outcome {
    /// The outcome's name in reports.
    pub fn label(self) -> &'static str {
        match self {
            Outcome::Closes => "closes",
            Outcome::Jams => "jams",
            Outcome::Stalls => "stalls",
            Outcome::Undecided => "undecided",
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

/// Faces that met at a corner they share and press on each other.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// The two faces (FOLD face indices).
    pub faces: [usize; 2],
    /// Their open seam, if they share one.
    pub seam: Option<usize>,
    /// When, s.
    pub time_s: f64,
    /// How far along the drives' path.
    pub progress: f64,
    /// The seam's misalignment then.
    pub misalignment: Option<f64>,
}

/// Faces meeting where no seam latches them.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Jam {
    /// The two faces (FOLD face indices).
    pub faces: [usize; 2],
    /// When, s.
    pub time_s: f64,
    /// How far along the drives' path.
    pub progress: f64,
    /// A point where they meet, µm.
    pub point_um: [f64; 3],
    /// Their seam's misalignment when they share one that was too far out of line to latch.
    pub seam_misalignment: Option<f64>,
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

/// A closing run.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosingReport {
    /// How it ended.
    pub outcome: Outcome,
    /// When: the last latch (closes), the jam, or the end of the drives (stalls), s.
    pub time_s: f64,
    /// How far along the drives' path that was.
    pub progress: f64,
    /// When faces first met (a latch or a jam), s.
    pub first_contact_time_s: Option<f64>,
    /// Every latch in order.
    pub latches: Vec<Latch>,
    /// Faces that met at a corner they share and pressed on (one face's edge resting on the
    /// other face), in order: across a seam out of line (it latches if they slide within
    /// the capture), or around a solid vertex.
    pub presses: Vec<Contact>,
    /// The jam.
    pub jam: Option<Jam>,
    /// Seams still open at the end, with their misalignment.
    pub open_seams: Vec<(usize, f64)>,
    /// Why the run could not go on (outcome `undecided`).
    pub undecided: Option<String>,
    /// The start, every event (before and after its latches) and the end.
    pub frames: Vec<ClosingFrame>,
}

/// One release of a simulated net: its nominal device's closing and its yield.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReleaseResult {
    /// The etch front's direction, degrees (None: every hinge at once).
    pub front_deg: Option<f64>,
    /// How the nominal device's run ended.
    pub outcome: Outcome,
    /// When (see [`ClosingReport::time_s`]), s.
    pub time_s: f64,
    /// Seams latched by then.
    pub latched: usize,
    /// The faces that jammed (FOLD face indices).
    pub jam_faces: Option<[usize; 2]>,
    /// The share of sampled devices that close (None: none sampled).
    #[serde(rename = "yield")]
    pub yield_estimate: Option<crate::design::fabrication::YieldEstimate>,
}

/// A simulated net: every release tried and the best.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetClosingSummary {
    /// The anchored face (FOLD face index).
    pub anchored_face: usize,
    /// Every release tried.
    pub releases: Vec<ReleaseResult>,
    /// The best release (index into `releases`): the highest yield, then a nominal device
    /// that closes, then the earliest closing.
    pub best: usize,
    /// Releases whose nominal device closes.
    pub closes_in: usize,
}

impl NetClosingSummary {
    /// The summary of `releases` (at least one), the best chosen.
    pub fn new(anchored_face: usize, releases: Vec<ReleaseResult>) -> NetClosingSummary {
        let key = |r: &ReleaseResult| {
            (
                r.yield_estimate.map_or(0.0, |y| y.fraction),
                r.outcome == Outcome::Closes,
                -r.time_s,
            )
        };
        let best = (0..releases.len())
            .max_by(|&a, &b| {
                let (ka, kb) = (key(&releases[a]), key(&releases[b]));
                ka.0.total_cmp(&kb.0)
                    .then(ka.1.cmp(&kb.1))
                    .then(ka.2.total_cmp(&kb.2))
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        let closes_in = releases.iter().filter(|r| r.outcome == Outcome::Closes).count();
        NetClosingSummary {
            anchored_face,
            releases,
            best,
            closes_in,
        }
    }

    /// The best release's yield (its nominal outcome, 1 or 0, when none was sampled).
    pub fn best_yield(&self) -> f64 {
        let best = &self.releases[self.best];
        best.yield_estimate
            .map_or(if best.outcome == Outcome::Closes { 1.0 } else { 0.0 }, |y| y.fraction)
    }
}

/// Where a seam stands in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SeamState {
    Open,
    /// Its faces press on each other out of line (see [`Press`]).
    Pressed,
    Latched,
}

/// Two faces pressing at a corner they share: one face's edge from it (a ray) rests on the
/// other face's plane (`sign` · n · ray ≥ 0 keeps it out). Across a seam met out of line,
/// or faces around a solid vertex that meet there.
#[derive(Debug, Clone, Copy)]
struct Press {
    /// The seam between the faces, when they have one still open.
    seam: Option<usize>,
    ray_face: usize,
    /// The ray's pattern vertices on `ray_face`: the shared corner, then the edge's far end.
    ray: [usize; 2],
    plane_face: usize,
    sign: f64,
}

/// What holds the faces during a run.
#[derive(Debug, Clone)]
struct Holds {
    state: Vec<SeamState>,
    latched: Vec<usize>,
    pressed: Vec<Press>,
}

impl Holds {
    fn new(seams: usize) -> Holds {
        Holds {
            state: vec![SeamState::Open; seams],
            latched: Vec::new(),
            pressed: Vec::new(),
        }
    }

    fn is_empty(&self) -> bool {
        self.latched.is_empty() && self.pressed.is_empty()
    }

    fn latch(&mut self, k: usize) {
        self.pressed.retain(|p| p.seam != Some(k));
        self.state[k] = SeamState::Latched;
        self.latched.push(k);
    }

    fn press(&mut self, press: Press) {
        if let Some(k) = press.seam {
            self.state[k] = SeamState::Pressed;
        }
        self.pressed.push(press);
    }

    /// Lets go of the presses at `indices` (into `pressed`).
    fn part(&mut self, indices: &[usize]) {
        for &i in indices {
            if let Some(k) = self.pressed[i].seam {
                self.state[k] = SeamState::Open;
            }
        }
        let mut k = 0;
        self.pressed.retain(|_| {
            k += 1;
            !indices.contains(&(k - 1))
        });
    }

    /// Whether the faces are a pressed seam's.
    fn pressing(&self, [f, g]: [usize; 2]) -> bool {
        self.pressed
            .iter()
            .any(|p| (p.ray_face == f && p.plane_face == g) || (p.ray_face == g && p.plane_face == f))
    }
}

/// A matrix's row space as JᵀJ's eigenpairs.
type RowSpace = Vec<(f64, DVector<f64>)>;

/// Stiffnesses over the largest.
fn scaled(stiffness: &[f64]) -> DVector<f64> {
    let largest = stiffness.iter().fold(0.0_f64, |m, &k| m.max(k));
    DVector::from_iterator(stiffness.len(), stiffness.iter().map(|k| k / largest))
}

#[derive(Debug, Clone)]
struct SeamEnds {
    faces: [usize; 2],
    /// Each end: the pattern vertex on the first face and its copy on the second.
    ends: [[usize; 2]; 2],
    length: f64,
}

#[derive(Debug, Clone)]
struct FacePair {
    faces: [usize; 2],
    /// Corners that are copies of one solid vertex: (vertex of the first, of the second).
    common: Vec<[usize; 2]>,
    seam: Option<usize>,
}

/// A net's faces, seams and face pairs as a closing run tests them, for one network model
/// of the net (built once, run for every sample).
#[derive(Debug, Clone)]
pub struct NetClosing {
    faces: Vec<Vec<usize>>,
    face_panel: Vec<usize>,
    file_face: Vec<usize>,
    flat: Vec<Vector3<f64>>,
    seams: Vec<SeamEnds>,
    pairs: Vec<FacePair>,
    /// Each panel's tree columns to the anchored panel.
    paths: Vec<Vec<usize>>,
    size: f64,
    unit: f64,
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
        if !model.folding.stars.is_empty() {
            return Err(NanofoldError::invalid(
                "pattern",
                &pattern.name,
                "seams latch on a net (a tree of panels); this pattern closes loops of its own",
            ));
        }
        let unit = model.unit;
        let flat: Vec<Vector3<f64>> = pattern
            .vertices
            .iter()
            .map(|p| Vector3::new(p[0] * unit, p[1] * unit, 0.0))
            .collect();
        let face_of_edge = |e: usize| {
            pattern.edge_faces[e]
                .iter()
                .flatten()
                .copied()
                .next()
                .expect("a seam edge bounds a face")
        };
        let solid = &net.solid_vertex;
        let seams: Vec<SeamEnds> = net
            .seams
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
        let faces = pattern.faces.clone();
        let face_panel: Vec<usize> = (0..faces.len()).map(|f| pattern.panel_of_face[f]).collect();
        let mut pairs = Vec::new();
        for f in 0..faces.len() {
            for g in f + 1..faces.len() {
                if face_panel[f] == face_panel[g] {
                    continue;
                }
                let common: Vec<[usize; 2]> = faces[f]
                    .iter()
                    .flat_map(|&v| {
                        faces[g]
                            .iter()
                            .filter(move |&&w| solid[v] == solid[w])
                            .map(move |&w| [v, w])
                    })
                    .collect();
                let seam = seams.iter().position(|s| s.faces == [f, g] || s.faces == [g, f]);
                pairs.push(FacePair {
                    faces: [f, g],
                    common,
                    seam,
                });
            }
        }
        let paths = (0..model.panels()).map(|p| model.path_columns(p).collect()).collect();
        Ok(NetClosing {
            faces,
            face_panel,
            file_face: pattern.file_face.clone(),
            flat,
            seams,
            pairs,
            paths,
            size: model.size(),
            unit,
        })
    }

    /// The number of seams.
    pub fn seam_count(&self) -> usize {
        self.seams.len()
    }

    fn place(&self, data: &NetworkData, face: usize, v: usize) -> Vector3<f64> {
        data.place(self.face_panel[face], &self.flat[v])
    }

    /// How far apart seam `k`'s edges' ends are, a fraction of its length.
    fn misalignment(&self, data: &NetworkData, k: usize) -> f64 {
        let seam = &self.seams[k];
        seam.ends
            .iter()
            .map(|&[v, w]| (self.place(data, seam.faces[0], v) - self.place(data, seam.faces[1], w)).norm())
            .fold(0.0, f64::max)
            / seam.length
    }

    /// The face pairs whose interiors meet (with a point of each meeting), at the poses
    /// `data` holds.
    fn meeting_pairs(&self, data: &NetworkData) -> Vec<(usize, Point3<f64>)> {
        let tolerance = TOLERANCE * self.size;
        let corners: Vec<Vec<Point3<f64>>> = (0..self.faces.len())
            .map(|f| {
                self.faces[f]
                    .iter()
                    .map(|&v| Point3::from(self.place(data, f, v)))
                    .collect()
            })
            .collect();
        let boxes: Vec<([f64; 3], [f64; 3])> = corners
            .iter()
            .map(|points| {
                points
                    .iter()
                    .fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
                        ([0, 1, 2].map(|i| lo[i].min(p[i])), [0, 1, 2].map(|i| hi[i].max(p[i])))
                    })
            })
            .collect();
        let mut meeting = Vec::new();
        for (k, pair) in self.pairs.iter().enumerate() {
            let [f, g] = pair.faces;
            if (0..3).any(|i| boxes[f].0[i] > boxes[g].1[i] + tolerance || boxes[g].0[i] > boxes[f].1[i] + tolerance) {
                continue;
            }
            let shared = pair
                .common
                .iter()
                .filter(|&&[v, w]| (self.place(data, f, v) - self.place(data, g, w)).norm() <= tolerance)
                .count();
            if let Some(point) = convex_faces_meet(&corners[f], &corners[g], shared, tolerance) {
                meeting.push((k, point));
            }
        }
        meeting
    }

    /// Whether anything happens at these poses: faces meeting (other than a pressed seam's),
    /// an open seam aligned, or a pressed one come within the capture.
    fn event(&self, data: &NetworkData, holds: &Holds, capture: f64) -> bool {
        (0..self.seams.len()).any(|k| {
            let m = || self.misalignment(data, k);
            match holds.state[k] {
                SeamState::Open => m() <= ALIGNED,
                SeamState::Pressed => m() <= capture,
                SeamState::Latched => false,
            }
        }) || self
            .meeting_pairs(data)
            .iter()
            .any(|&(pair, _)| !holds.pressing(self.pairs[pair].faces))
    }

    /// The rows that hold the faces, their residual and Jacobian in the fold angles at the
    /// poses and twists `data` holds: each latched seam's first end on its copy (three rows)
    /// and its second end's offset across the seam's line (two rows: along face a's normal
    /// and across the edge in its plane), over the net's size, so a seam on its copy (a
    /// hinge) has five independent rows wherever it is; each pressed seam's ray on the other
    /// face's plane (one row).
    fn hold_rows(&self, data: &NetworkData, holds: &Holds, columns: usize) -> (DVector<f64>, DMatrix<f64>) {
        let rows = SEAM_ROWS * holds.latched.len() + holds.pressed.len();
        let mut residual = DVector::zeros(rows);
        let mut jacobian = DMatrix::zeros(rows, columns);
        for (i, &k) in holds.latched.iter().enumerate() {
            let seam = &self.seams[k];
            let [a, b] = seam.faces;
            let along = (self.place(data, a, seam.ends[1][0]) - self.place(data, a, seam.ends[0][0])).normalize();
            let normal = data.rotation[self.face_panel[a]] * Vector3::z();
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
                    for &c in &self.paths[self.face_panel[face]] {
                        let twist = &data.twist[c];
                        let velocity = twist.angular.cross(&point) + twist.linear;
                        for (j, d) in directions.iter().enumerate() {
                            jacobian[(row + j, c)] += sign * d.dot(&velocity) / self.size;
                        }
                    }
                }
            }
        }
        for (i, press) in holds.pressed.iter().enumerate() {
            let row = SEAM_ROWS * holds.latched.len() + i;
            let (normal, ray) = self.press_vectors(data, press);
            residual[row] = press.sign * normal.dot(&ray);
            for &c in &self.paths[self.face_panel[press.plane_face]] {
                jacobian[(row, c)] += press.sign * data.twist[c].angular.cross(&normal).dot(&ray);
            }
            for &c in &self.paths[self.face_panel[press.ray_face]] {
                jacobian[(row, c)] += press.sign * normal.dot(&data.twist[c].angular.cross(&ray));
            }
        }
        (residual, jacobian)
    }

    /// A pressed seam's plane normal and unit ray, in the world.
    fn press_vectors(&self, data: &NetworkData, press: &Press) -> (Vector3<f64>, Vector3<f64>) {
        let normal = data.rotation[self.face_panel[press.plane_face]] * Vector3::z();
        let [from, to] = press.ray;
        let ray = (self.place(data, press.ray_face, to) - self.place(data, press.ray_face, from)).normalize();
        (normal, ray)
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
    /// Σ ½ K (θ − r)² on their rows, from `theta` (Gauss–Newton on the rows, the energy
    /// minimised in their null space). Returns whether it converged.
    fn settle(
        &self,
        model: &NetworkModel,
        drive: &[f64],
        stiffness: &[f64],
        holds: &Holds,
        theta: &mut [f64],
        data: &mut NetworkData,
    ) -> bool {
        let n = theta.len();
        if holds.is_empty() {
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
            let (residual, jacobian) = self.hold_rows(data, holds, n);
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
        last_turn <= SINGULAR_STEP && self.hold_rows(data, holds, n).0.amax() <= SETTLE_HELD
    }

    /// The presses (indices into `holds.pressed`) whose faces the balance would rather part: moving along the
    /// contact's gradient (within the other rows) lowers the hinges' energy.
    fn parting(
        &self,
        data: &NetworkData,
        holds: &Holds,
        drive: &[f64],
        stiffness: &[f64],
        theta: &[f64],
    ) -> Vec<usize> {
        let n = theta.len();
        let (_, jacobian) = self.hold_rows(data, holds, n);
        let stiff = scaled(stiffness);
        let gradient = DVector::from_iterator(n, (0..n).map(|c| stiff[c] * (theta[c] - drive[c])));
        let first = SEAM_ROWS * holds.latched.len();
        (0..holds.pressed.len())
            .filter(|&i| {
                let others: Vec<usize> = (0..jacobian.nrows()).filter(|&r| r != first + i).collect();
                let contact = jacobian.row(first + i).transpose();
                let apart = if others.is_empty() {
                    contact.clone()
                } else {
                    let (_, null) = Self::row_and_null_space(&jacobian.select_rows(&others), None);
                    null.iter().fold(DVector::zeros(n), |d, z| d + z * z.dot(&contact))
                };
                gradient.dot(&apart) < -1e-12 * gradient.norm() * apart.norm()
            })
            .collect()
    }

    /// Whether faces `pair` meeting are pressing at a corner they share: an edge of one from
    /// that corner has reached the other's plane (the ray nearest it, within
    /// [`PRESS_REACH`]), kept on the side it came from (its side at `before`).
    fn press_of(
        &self,
        pair: &FacePair,
        open_seam: Option<usize>,
        before: &NetworkData,
        now: &NetworkData,
    ) -> Option<Press> {
        let tolerance = TOLERANCE * self.size;
        let [f, g] = pair.faces;
        let edges_from = |face: usize, v: usize| {
            let loop_ = &self.faces[face];
            let k = loop_.iter().position(|&x| x == v).expect("a corner of the face");
            [loop_[(k + 1) % loop_.len()], loop_[(k + loop_.len() - 1) % loop_.len()]]
        };
        pair.common
            .iter()
            .filter(|&&[v, w]| (self.place(now, f, v) - self.place(now, g, w)).norm() <= tolerance)
            .flat_map(|&[v, w]| {
                let from_f = edges_from(f, v).map(|far| (f, [v, far], g));
                let from_g = edges_from(g, w).map(|far| (g, [w, far], f));
                from_f.into_iter().chain(from_g)
            })
            .map(|(ray_face, ray, plane_face)| {
                let candidate = Press {
                    seam: open_seam,
                    ray_face,
                    ray,
                    plane_face,
                    sign: 1.0,
                };
                let side_of = |data: &NetworkData| {
                    let (normal, ray) = self.press_vectors(data, &candidate);
                    normal.dot(&ray)
                };
                let (was, is) = (side_of(before), side_of(now));
                let sign = if was != 0.0 { was.signum() } else { (was - is).signum() };
                (is.abs(), Press { sign, ..candidate })
            })
            .filter(|(reach, _)| *reach <= PRESS_REACH)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, press)| press)
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
        settings.validate()?;
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
            path: DrivePath::new(forcing),
            stiffness,
            capture: settings.capture_percent / 100.0,
            data: NetworkData::new(model),
            before: NetworkData::new(model),
            drive: vec![0.0; n],
            theta: vec![0.0; n],
            holds: Holds::new(self.seams.len()),
            report: ClosingReport {
                outcome: Outcome::Stalls,
                time_s: 0.0,
                progress: 0.0,
                first_contact_time_s: None,
                latches: Vec::new(),
                presses: Vec::new(),
                jam: None,
                open_seams: Vec::new(),
                undecided: None,
                frames: Vec::new(),
            },
        };
        if let Err(why) = run.drive_through() {
            // No balance holds the latched seams here: the run cannot say what the device
            // does next, and says so (counted as not closing).
            let u = run.report.frames.last().map_or(0.0, |f| f.progress);
            run.end(Outcome::Undecided, u);
            run.report.undecided = Some(why.to_string());
            update_poses(model, &run.theta, &mut run.data);
            run.report.open_seams = self.open(&run.data, &run.holds);
        }
        Ok(run.report)
    }

    fn open(&self, data: &NetworkData, holds: &Holds) -> Vec<(usize, f64)> {
        (0..self.seams.len())
            .filter(|&k| holds.state[k] != SeamState::Latched)
            .map(|k| (k, self.misalignment(data, k)))
            .collect()
    }

    /// The quasi-static balance with the seams `latched` held, from the fold angles `start`:
    /// the angles minimising Σ ½ K (θ − r)² (r = `drive`) on the seams' closures.
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
        latched.iter().for_each(|&k| holds.latch(k));
        if !self.settle(model, drive, stiffness, &holds, &mut theta, &mut data) {
            return Err(NanofoldError::invalid(
                "latched",
                format!("{latched:?}"),
                "the latched seams hold no balance near the start",
            ));
        }
        Ok(theta)
    }

    /// Every pattern vertex's place at fold angles `theta`, in units of the pattern (for
    /// checks against the solid).
    pub fn vertex_places(&self, model: &NetworkModel, theta: &[f64]) -> Vec<[f64; 3]> {
        let mut data = NetworkData::new(model);
        update_poses(model, theta, &mut data);
        let mut places = vec![[f64::NAN; 3]; self.flat.len()];
        for (f, face) in self.faces.iter().enumerate() {
            for &v in face {
                let x = self.place(&data, f, v) / self.unit;
                places[v] = [x.x, x.y, x.z];
            }
        }
        places
    }
}

/// One closing run's state: the angles, what holds the faces, the report so far.
struct Run<'a> {
    net: &'a NetClosing,
    model: &'a NetworkModel,
    path: DrivePath<'a>,
    stiffness: &'a [f64],
    capture: f64,
    data: NetworkData,
    /// The poses just before the event being resolved (which side a pressing edge came from).
    before: NetworkData,
    drive: Vec<f64>,
    theta: Vec<f64>,
    holds: Holds,
    report: ClosingReport,
}

impl Run<'_> {
    /// From flat to the end of the drives, the report filled; an error when no balance holds
    /// the latched seams somewhere on the way.
    fn drive_through(&mut self) -> Result<()> {
        let net = self.net;
        self.settle_at(0.0)?;
        self.keep_frame(0.0);
        let mut last_frame = 0.0;
        let mut u = 0.0;
        while u < 1.0 {
            let next = self.path.next(u, MAX_STEP);
            let mut trial = self.theta.clone();
            self.path.drive(next, &mut self.drive);
            if !net.settle(
                self.model,
                &self.drive,
                self.stiffness,
                &self.holds,
                &mut trial,
                &mut self.data,
            ) {
                return Err(self.no_balance(next));
            }
            if !net.event(&self.data, &self.holds, self.capture) {
                self.let_go_of_parting(&mut trial, next)?;
                self.theta = trial;
                u = next;
                if u - last_frame >= FRAME_SPACING {
                    self.keep_frame(u);
                    last_frame = u;
                }
                continue;
            }
            u = self.locate(u, next, trial);
            self.report.first_contact_time_s.get_or_insert(self.path.time(u));
            self.keep_frame(u);
            if self.resolve(u)? {
                return Ok(());
            }
            last_frame = u;
        }
        update_poses(self.model, &self.theta, &mut self.data);
        self.end(Outcome::Stalls, 1.0);
        self.report.open_seams = net.open(&self.data, &self.holds);
        self.keep_frame(1.0);
        Ok(())
    }

    fn keep_frame(&mut self, u: f64) {
        self.report.frames.push(ClosingFrame {
            time_s: self.path.time(u),
            progress: u,
            fold_angles: self.theta.clone(),
        });
    }

    fn no_balance(&self, u: f64) -> NanofoldError {
        NanofoldError::invalid(
            "seams",
            format!("latched {:?}, {} pressed", self.holds.latched, self.holds.pressed.len()),
            format!("the seams held hold no balance at progress {u:.6}"),
        )
    }

    /// The balance at progress `u` from the current angles.
    fn settle_at(&mut self, u: f64) -> Result<()> {
        self.path.drive(u, &mut self.drive);
        let net = self.net;
        if net.settle(
            self.model,
            &self.drive,
            self.stiffness,
            &self.holds,
            &mut self.theta,
            &mut self.data,
        ) {
            Ok(())
        } else {
            Err(self.no_balance(u))
        }
    }

    /// Presses whose faces would rather part let go, and the balance `trial` at `u` (the
    /// drives already set) is found again without them.
    fn let_go_of_parting(&mut self, trial: &mut [f64], u: f64) -> Result<()> {
        let net = self.net;
        let parting = net.parting(&self.data, &self.holds, &self.drive, self.stiffness, trial);
        if parting.is_empty() {
            return Ok(());
        }
        self.holds.part(&parting);
        if net.settle(
            self.model,
            &self.drive,
            self.stiffness,
            &self.holds,
            trial,
            &mut self.data,
        ) {
            Ok(())
        } else {
            Err(self.no_balance(u))
        }
    }

    /// The first progress in (u, next] where something happens, `at_next` its balance at
    /// `next`: bisected to [`LOCATE`]; the angles are left at it, `before` just short of it.
    fn locate(&mut self, u: f64, next: f64, at_next: Vec<f64>) -> f64 {
        let net = self.net;
        let (mut lo, mut hi, mut at_hi) = (u, next, at_next);
        while hi - lo > LOCATE * (1.0 + hi.abs()) {
            let mid = 0.5 * (lo + hi);
            let mut state = self.theta.clone();
            self.path.drive(mid, &mut self.drive);
            net.settle(
                self.model,
                &self.drive,
                self.stiffness,
                &self.holds,
                &mut state,
                &mut self.data,
            );
            if net.event(&self.data, &self.holds, self.capture) {
                hi = mid;
                at_hi = state;
            } else {
                lo = mid;
                self.theta = state;
            }
        }
        update_poses(self.model, &self.theta, &mut self.before);
        self.theta = at_hi;
        hi
    }

    /// Latches what meets in line, presses what meets at a shared corner, stops at anything
    /// else (a jam). A latch moves the faces (they snap into line), so it looks again until
    /// nothing new meets. Returns whether the run is over (closed or jammed).
    fn resolve(&mut self, u: f64) -> Result<bool> {
        let net = self.net;
        loop {
            self.path.drive(u, &mut self.drive);
            update_poses(self.model, &self.theta, &mut self.data);
            let mut new: Vec<(usize, f64)> = (0..net.seams.len())
                .filter_map(|k| {
                    let m = net.misalignment(&self.data, k);
                    let latches = match self.holds.state[k] {
                        SeamState::Open => m <= ALIGNED_TOGETHER,
                        SeamState::Pressed => m <= self.capture,
                        SeamState::Latched => false,
                    };
                    latches.then_some((k, m))
                })
                .collect();
            let mut pressed_now = false;
            for (pair, point) in net.meeting_pairs(&self.data) {
                let faces = net.pairs[pair].faces;
                if self.holds.pressing(faces) {
                    continue;
                }
                let seam = net.pairs[pair].seam.filter(|&k| self.holds.state[k] == SeamState::Open);
                let misalignment = seam.map(|k| net.misalignment(&self.data, k));
                let press = net.press_of(&net.pairs[pair], seam, &self.before, &self.data);
                match (seam, misalignment, press) {
                    (Some(k), Some(m), _) if m <= self.capture => {
                        if !new.iter().any(|&(j, _)| j == k) {
                            new.push((k, m));
                        }
                    }
                    (_, _, Some(press)) if press.seam.is_none_or(|k| !new.iter().any(|&(j, _)| j == k)) => {
                        self.holds.press(press);
                        self.report.presses.push(Contact {
                            faces: faces.map(|f| net.file_face[f]),
                            seam,
                            time_s: self.path.time(u),
                            progress: u,
                            misalignment,
                        });
                        pressed_now = true;
                    }
                    _ => {
                        self.end(Outcome::Jams, u);
                        self.report.jam = Some(Jam {
                            faces: faces.map(|f| net.file_face[f]),
                            time_s: self.path.time(u),
                            progress: u,
                            point_um: [point.x, point.y, point.z].map(|x| x * 1e6),
                            seam_misalignment: misalignment,
                        });
                        self.report.open_seams = net.open(&self.data, &self.holds);
                        return Ok(true);
                    }
                }
            }
            if new.is_empty() && !pressed_now {
                return Ok(false);
            }
            new.sort_by_key(|&(k, _)| k);
            for (k, m) in new {
                self.holds.latch(k);
                self.report.latches.push(Latch {
                    seam: k,
                    faces: net.seams[k].faces.map(|f| net.file_face[f]),
                    time_s: self.path.time(u),
                    progress: u,
                    misalignment: m,
                });
            }
            update_poses(self.model, &self.theta, &mut self.before);
            self.settle_at(u)?;
            self.keep_frame(u);
            if self.holds.latched.len() == net.seams.len() {
                self.end(Outcome::Closes, u);
                return Ok(true);
            }
        }
    }

    fn end(&mut self, outcome: Outcome, u: f64) {
        self.report.outcome = outcome;
        self.report.time_s = self.path.time(u);
        self.report.progress = u;
    }
}

/// The drives' path as a progress u ∈ [0, 1]: a ramp's time over its whole duration, a
/// step's straight path at t = 0⁺.
struct DrivePath<'a> {
    forcing: &'a Forcing,
    duration: f64,
    /// Progresses where a drive starts or stops moving.
    breaks: Vec<f64>,
}

impl<'a> DrivePath<'a> {
    fn new(forcing: &'a Forcing) -> Self {
        let duration = forcing.duration();
        let breaks = if duration > 0.0 {
            forcing.breakpoints().iter().map(|t| t / duration).collect()
        } else {
            Vec::new()
        };
        DrivePath {
            forcing,
            duration,
            breaks,
        }
    }

    fn drive(&self, u: f64, out: &mut [f64]) {
        self.forcing.drive_along(u, f64::INFINITY, out);
    }

    fn time(&self, u: f64) -> f64 {
        self.forcing.time_along(u, f64::INFINITY)
    }

    /// The next progress to test from `u`: no drive turns more than `turn` on the way, and
    /// no break is passed.
    fn next(&self, u: f64, turn: f64) -> f64 {
        let next_break = self
            .breaks
            .iter()
            .copied()
            .find(|&b| b > u + 1e-15)
            .unwrap_or(1.0)
            .min(1.0);
        let rate = if self.duration > 0.0 {
            // The rates hold between breaks: read them inside the stretch, not at its start
            // (a ramp starting exactly there reads zero, rounded a hair before it).
            let t = 0.5 * (u + next_break) * self.duration;
            (0..self.forcing.hinges.len())
                .map(|i| (self.forcing.drive_rate(i, t) * self.duration).abs())
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
    use crate::dynamics::forcing::{Actuation, HingeDrive};

    /// Walking a ramp's path with [`DrivePath::next`], no drive turns more than the asked
    /// turn in one step, wherever a hinge's ramp starts: a ramp released at a break must not
    /// be stepped over whole (its rate read at the break's start rounds to before the
    /// release). Release times from 0.013 s to 2.6 s; the drives' own change is the check.
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
            let path = DrivePath::new(&forcing);
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
