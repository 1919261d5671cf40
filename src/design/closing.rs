//! A net's yield study per release (`docs/model.md#closing-a-net`): each release's nominal
//! closing and its sampled devices' yield and failures, and a net's best release. The
//! closing runs themselves are the quasi-static contact engine's
//! ([`crate::dynamics::network::closing`]).

pub use crate::dynamics::network::closing::*;
use serde::{Deserialize, Serialize};

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
    /// How the sampled devices that did not close ended (None: none sampled).
    #[serde(default)]
    pub failures: Option<Failures>,
}

/// The sampled devices that did not close, by how they ended.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Failures {
    /// Held apart by contact forces with the drives spent.
    pub jams: usize,
    /// Drives spent with seams open, nothing holding them.
    pub stalls: usize,
    /// The path lost its stability.
    pub snaps: usize,
    /// No balance found.
    pub undecided: usize,
}

impl Failures {
    /// Counts one more device that ended with `outcome` (a closing counts nowhere).
    pub fn count(&mut self, outcome: Outcome) {
        match outcome {
            Outcome::Closes => {}
            Outcome::Jams => self.jams += 1,
            // A net has seams, so its devices never rest; one that did would be stalled.
            Outcome::Stalls | Outcome::Rests => self.stalls += 1,
            Outcome::Snaps => self.snaps += 1,
            Outcome::Undecided => self.undecided += 1,
        }
    }

    /// Every count added.
    pub fn add(&mut self, other: &Failures) {
        self.jams += other.jams;
        self.stalls += other.stalls;
        self.snaps += other.snaps;
        self.undecided += other.undecided;
    }
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
    /// The best release's yield from fresh devices, independent of those it was chosen
    /// on (None: none sampled, and left out of the JSON): the yield to report, free of the
    /// choice's optimism.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fresh_yield: Option<crate::design::fabrication::YieldEstimate>,
    /// The same fresh devices latched with half and twice the capture (those within its
    /// range, above 0 and at most 50 %): how the yield moves with that stated parameter, a
    /// paired comparison (empty when none were sampled, and left out of the JSON).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub capture_yields: Vec<CaptureYield>,
}

/// The best release's fresh devices at another capture.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CaptureYield {
    /// The capture, % of a seam's length.
    pub capture_percent: f64,
    /// The share of the fresh devices that close with it.
    #[serde(rename = "yield")]
    pub yield_estimate: crate::design::fabrication::YieldEstimate,
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
            fresh_yield: None,
            capture_yields: Vec::new(),
        }
    }

    /// The best release's yield: from fresh devices when they were run, else from those it
    /// was chosen on (its nominal outcome, 1 or 0, when none was sampled).
    pub fn best_yield(&self) -> f64 {
        let best = &self.releases[self.best];
        self.fresh_yield
            .or(best.yield_estimate)
            .map_or(if best.outcome == Outcome::Closes { 1.0 } else { 0.0 }, |y| y.fraction)
    }
}
