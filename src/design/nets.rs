//! Ranking a solid's nets (`docs/model.md#nets-of-polyhedra`): every distinct edge
//! unfolding (or those met in a uniform sample), laid flat, tested for overlap, scored and
//! ranked, the best that can be made checked for touching themselves.

use crate::design::closing::{ClosingSettings, Failures, NetClosingSummary};
use crate::design::fabrication::Variation;
use crate::error::{NanofoldError, Result};
use crate::geometry::mesh::{MergeCoplanar, MeshReading};
use crate::geometry::nets::NetLayout;
use crate::geometry::polyhedron::{Polyhedron, SymmetrySummary};
use crate::geometry::unfoldings::{
    check_orbits, distinct_among, distinct_nets, edge_map, sample_trees, spanning_trees, Tree,
};
use crate::pattern::net::{net_pattern, NetPattern};
use serde::{Deserialize, Serialize};

/// The most trees enumerated; above it the trees are sampled.
pub const MAX_ENUMERATED_TREES: usize = 10_000_000;
/// The most trees sampled.
pub const MAX_SAMPLED_TREES: usize = 1_000_000;
/// The most nets written as files (and simulated).
pub const MAX_WRITTEN_NETS: usize = 100;
/// The most etch-front directions tried per net.
pub const MAX_FRONTS: usize = 360;

/// The score nets are ranked by (smallest first); every ranking puts the nets that can be
/// made (no overlap, not touching themselves) first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RankBy {
    /// Compactness: the flat net's radius of gyration.
    #[default]
    RadiusOfGyration,
    /// The total length of the seams that must meet again.
    SeamLength,
    /// The area of the smallest rectangle holding the net.
    Footprint,
    /// The simulated yield of the net's best release, highest first (then the releases
    /// whose nominal device closes, most first); the nets not simulated follow by radius of
    /// gyration, which also chooses the nets simulated.
    Yield,
}

impl RankBy {
    /// The score's name in words.
    pub fn label(self) -> &'static str {
        match self {
            RankBy::RadiusOfGyration => "radius of gyration",
            RankBy::SeamLength => "seam length",
            RankBy::Footprint => "footprint",
            RankBy::Yield => "simulated yield",
        }
    }
}

/// `nets`' options, as the command line and Python give them.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NetsOptions {
    /// Enumerate every tree when the solid has at most this many; else sample.
    pub max_trees: usize,
    /// Trees drawn uniformly when they are too many to enumerate.
    pub samples: usize,
    /// The sampler's seed.
    pub seed: u64,
    /// The ranking.
    pub rank_by: RankBy,
    /// How many of the best nets are written as crease patterns and drawn.
    pub top: usize,
    /// The length of the solid's unit in µm (scales the lengths reported).
    pub unit_um: f64,
    /// Each written scene's hinges drive this far past the turn that closes the solid, so
    /// the faces press shut (degrees, 0 to 45).
    pub overdrive_deg: f64,
    /// The written scenes' release: None for every hinge at once (a step); Some(φ) for an
    /// etch front crossing the wafer along φ degrees (0 along +x, 90 along +y), freeing each
    /// hinge once it has passed its crease.
    pub front_deg: Option<f64>,
    /// The etch front's speed.
    pub etch_rate_um_per_min: f64,
    /// The face each written scene anchors (a FOLD face index of the net; None: the face at
    /// the centre of the net's tree).
    pub anchored_face: Option<usize>,
    /// How many of the best nets that can be made are simulated closing (0: none).
    pub simulate: usize,
    /// The etch-front directions each simulated net is released along, k·360°/fronts
    /// (0: every hinge at once, a step); `front_deg` given tries that one alone.
    pub fronts: usize,
    /// Devices sampled per net and release for the yield (0: the nominal device only).
    pub yield_samples: usize,
    /// Standard deviation of each hinge's stiffness across devices, % of its value.
    pub stiffness_spread_percent: f64,
    /// Standard deviation of each hinge's residual stress across devices, %.
    pub stress_spread_percent: f64,
    /// A seam latches when its edges meet within this share of its length, %.
    pub capture_percent: f64,
    /// How a solid file's faces in one plane are read ([`MergeCoplanar`]).
    pub merge_coplanar: MergeCoplanar,
}

impl Default for NetsOptions {
    fn default() -> Self {
        NetsOptions {
            max_trees: MAX_ENUMERATED_TREES,
            samples: 20_000,
            seed: 1,
            rank_by: RankBy::RadiusOfGyration,
            top: 10,
            unit_um: 1.0,
            overdrive_deg: 5.0,
            front_deg: None,
            etch_rate_um_per_min: 1.5,
            anchored_face: None,
            simulate: 10,
            fronts: 16,
            yield_samples: 50,
            stiffness_spread_percent: 2.0,
            stress_spread_percent: 2.0,
            capture_percent: 10.0,
            merge_coplanar: MergeCoplanar::Auto,
        }
    }
}

impl NetsOptions {
    /// Refuses options out of range by name.
    pub fn validate(&self) -> Result<()> {
        if self.max_trees == 0 || self.max_trees > MAX_ENUMERATED_TREES {
            return Err(NanofoldError::invalid(
                "max_trees",
                self.max_trees,
                format!("from 1 to {MAX_ENUMERATED_TREES}"),
            ));
        }
        if self.samples == 0 || self.samples > MAX_SAMPLED_TREES {
            return Err(NanofoldError::invalid(
                "samples",
                self.samples,
                format!("from 1 to {MAX_SAMPLED_TREES}"),
            ));
        }
        if self.top > MAX_WRITTEN_NETS {
            return Err(NanofoldError::invalid(
                "top",
                self.top,
                format!("at most {MAX_WRITTEN_NETS}"),
            ));
        }
        // The scenes made of the nets take the lengths and speeds any scene takes.
        use crate::read::scene_spec::{limits, within};
        within("unit_um", self.unit_um, limits::LENGTH_UNIT_UM, "µm")?;
        within(
            "etch_rate_um_per_min",
            self.etch_rate_um_per_min,
            limits::ETCH_RATE_UM_PER_MIN,
            "µm/min",
        )?;
        if !(0.0..=45.0).contains(&self.overdrive_deg) {
            return Err(NanofoldError::invalid(
                "overdrive_deg",
                self.overdrive_deg,
                "from 0 to 45 degrees",
            ));
        }
        if let Some(phi) = self.front_deg.filter(|phi| !phi.is_finite()) {
            return Err(NanofoldError::invalid(
                "front_deg",
                phi,
                "a finite direction in degrees",
            ));
        }
        if self.simulate > MAX_WRITTEN_NETS {
            return Err(NanofoldError::invalid(
                "simulate",
                self.simulate,
                format!("at most {MAX_WRITTEN_NETS} nets"),
            ));
        }
        if self.fronts > MAX_FRONTS {
            return Err(NanofoldError::invalid(
                "fronts",
                self.fronts,
                format!("at most {MAX_FRONTS} directions"),
            ));
        }
        if self.rank_by == RankBy::Yield && self.simulate == 0 {
            return Err(NanofoldError::invalid(
                "rank_by",
                "yield",
                "ranking by yield needs nets simulated (simulate ≥ 1)",
            ));
        }
        self.variation().validate()?;
        self.closing().validate()
    }

    /// How these options read a solid file.
    pub fn solid_options(&self) -> crate::read::solid::SolidOptions {
        crate::read::solid::SolidOptions {
            merge_coplanar: self.merge_coplanar,
        }
    }

    /// The fabrication variation these options ask for.
    pub fn variation(&self) -> Variation {
        Variation {
            samples: self.yield_samples,
            stiffness_spread_percent: self.stiffness_spread_percent,
            stress_spread_percent: self.stress_spread_percent,
            seed: self.seed,
        }
    }

    /// The captures a best release's fresh devices are run with, %: the chosen one first,
    /// then half and twice it where they lie above 0 and at most 50 %.
    pub fn captures(&self) -> Vec<f64> {
        std::iter::once(self.capture_percent)
            .chain(
                [0.5 * self.capture_percent, 2.0 * self.capture_percent]
                    .into_iter()
                    .filter(|&c| c > 0.0 && c <= 50.0),
            )
            .collect()
    }

    /// How seams latch.
    pub fn closing(&self) -> ClosingSettings {
        ClosingSettings {
            capture_percent: self.capture_percent,
            ..ClosingSettings::default()
        }
    }

    /// The releases each simulated net is tried with: `front_deg` alone when given, else
    /// `fronts` directions from 0°, else a step (None).
    pub fn releases(&self) -> Vec<Option<f64>> {
        match (self.front_deg, self.fronts) {
            (Some(phi), _) => vec![Some(phi)],
            (None, 0) => vec![None],
            (None, n) => (0..n).map(|k| Some(360.0 * k as f64 / n as f64)).collect(),
        }
    }
}

/// What was done to find the nets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Search {
    /// Every spanning tree enumerated: every net is here.
    Enumerated,
    /// Trees drawn uniformly (Wilson's algorithm): the nets met among them.
    Sampled,
}

/// One distinct net and its scores, lengths in µm.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetRow {
    /// 1 for the best.
    pub rank: usize,
    /// The solid's edges (dual edges) that are folds.
    pub folds: Vec<usize>,
    /// The flat net's radius of gyration.
    pub radius_of_gyration_um: f64,
    /// Faces with one fold.
    pub leaves: usize,
    /// Total length of the cut edges.
    pub seam_length_um: f64,
    /// The smallest rectangle holding the net: (long side, short side).
    pub footprint_um: [f64; 2],
    /// Two faces of the flat net overlap: it cannot be made.
    pub overlapping: bool,
    /// The net touches itself at a point or along a seam (checked for the nets written).
    pub touching: Option<bool>,
    /// Its device's simulated closing (for the nets simulated).
    pub closing: Option<NetClosingSummary>,
}

/// The solid and its nets.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetsReport {
    /// The solid's name.
    pub solid: String,
    /// Faces, edges, vertices.
    pub faces: usize,
    /// Edges of the solid (of its dual graph).
    pub edges: usize,
    /// Vertices.
    pub vertices: usize,
    /// Order of the symmetry group (rotations and reflections).
    pub symmetry_order: usize,
    /// Rotations among them.
    pub rotations: usize,
    /// The symmetry group: its point group, the tolerance its maps were found within, and
    /// how many near-symmetries were left out so that the rest form a group.
    pub symmetry: SymmetrySummary,
    /// A file's reading: its format, welded vertices, merged faces, precision and the
    /// tolerances from it (absent for a generated solid).
    pub reading: Option<MeshReading>,
    /// What the answer should be read with (a near-symmetric solid's group).
    pub warnings: Vec<String>,
    /// Spanning trees by the matrix-tree theorem.
    pub spanning_trees: f64,
    /// Enumerated or sampled.
    pub search: Search,
    /// Trees looked at.
    pub trees_considered: usize,
    /// Distinct nets found (all of them when enumerated).
    pub distinct_nets: usize,
    /// Of those, how many overlap.
    pub overlapping: usize,
    /// The ranking.
    pub rank_by: RankBy,
    /// The length of the solid's unit in µm.
    pub unit_um: f64,
    /// The nets, best first.
    pub nets: Vec<NetRow>,
    /// What the simulated nets were run with (None: no net simulated).
    pub study: Option<Study>,
    /// Seconds taken.
    pub seconds: f64,
}

/// A release as JSON shows it: its kind, and the front's direction when it has one.
fn releases_shown<S: serde::Serializer>(
    releases: &[Option<f64>],
    serializer: S,
) -> std::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    #[serde_with::skip_serializing_none]
    #[derive(Serialize)]
    struct Shown {
        kind: &'static str,
        front_deg: Option<f64>,
    }
    let mut seq = serializer.serialize_seq(Some(releases.len()))?;
    for &front_deg in releases {
        let kind = if front_deg.is_some() { "etch_front" } else { "step" };
        seq.serialize_element(&Shown { kind, front_deg })?;
    }
    seq.end()
}

/// What a study simulated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Study {
    /// Nets simulated.
    pub nets: usize,
    /// Their releases (None: a step), written as `{"kind": "step"}` or
    /// `{"kind": "etch_front", "front_deg": φ}`.
    #[serde(serialize_with = "releases_shown")]
    pub releases: Vec<Option<f64>>,
    /// The devices' variation.
    pub variation: Variation,
    /// How seams latch.
    pub closing: ClosingSettings,
    /// Devices run: each release's nominal and sampled ones, and each net's fresh ones for
    /// its best release.
    pub devices: usize,
    /// The sampled devices that did not close, over every release, by how they ended.
    pub failures: Failures,
    /// The simulated nets' yields ranked against their compactness (None: fewer than 4
    /// nets, or yields that do not vary; filled by [`apply_study`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fidelity: Option<crate::design::fidelity::Fidelity>,
    /// Seconds the study took.
    pub seconds: f64,
}

/// Puts the simulated closings into the table (`summaries` by rank) and, when ranking by
/// yield, ranks again: the simulated nets by their best release's yield (then releases that
/// close, then the earlier rank), the others after them in their order.
pub fn apply_study(report: &mut NetsReport, summaries: Vec<(usize, NetClosingSummary)>, mut study: Study) {
    for (rank, summary) in summaries {
        if let Some(row) = report.nets.iter_mut().find(|r| r.rank == rank) {
            row.closing = Some(summary);
        }
    }
    let simulated: Vec<&NetRow> = report.nets.iter().filter(|r| r.closing.is_some()).collect();
    let yields: Vec<f64> = simulated
        .iter()
        .filter_map(|r| r.closing.as_ref().map(NetClosingSummary::best_yield))
        .collect();
    let against = |score: &dyn Fn(&NetRow) -> f64| {
        let scores: Vec<f64> = simulated.iter().map(|r| score(r)).collect();
        crate::design::fidelity::spearman(&yields, &scores)
    };
    let fidelity = crate::design::fidelity::Fidelity {
        radius_of_gyration: against(&|r| r.radius_of_gyration_um),
        leaves: against(&|r| r.leaves as f64),
    };
    study.fidelity = (fidelity.radius_of_gyration.is_some() || fidelity.leaves.is_some()).then_some(fidelity);
    if report.rank_by == RankBy::Yield {
        let score = |row: &NetRow| {
            row.closing
                .as_ref()
                .map(|c| (c.best_yield(), c.closes_in))
                .unwrap_or((-1.0, 0))
        };
        report.nets.sort_by(|a, b| {
            let (ya, ca) = score(a);
            let (yb, cb) = score(b);
            yb.total_cmp(&ya).then(cb.cmp(&ca)).then(a.rank.cmp(&b.rank))
        });
        for (k, row) in report.nets.iter_mut().enumerate() {
            row.rank = k + 1;
        }
    }
    report.study = Some(study);
}

/// Finds, lays flat, tests and ranks the distinct nets of `solid`.
pub fn nets(name: &str, solid: &Polyhedron, options: &NetsOptions) -> Result<NetsReport> {
    options.validate()?;
    let started = std::time::Instant::now();
    let group = solid.symmetry_group();
    let symmetries = &group.elements;
    let maps: Vec<Vec<usize>> = symmetries.iter().map(|s| edge_map(solid, s)).collect();
    let count = solid.spanning_tree_count();
    let (search, trees) = if count <= options.max_trees as f64 {
        (Search::Enumerated, spanning_trees(solid, options.max_trees)?)
    } else {
        (Search::Sampled, sample_trees(solid, options.samples, options.seed)?)
    };
    let distinct = match search {
        Search::Enumerated => {
            let distinct = distinct_nets(&trees, &maps);
            check_orbits(trees.len(), &distinct, &maps)?;
            distinct
        }
        Search::Sampled => distinct_among(&trees, &maps),
    };
    let layout = NetLayout::new(solid);
    let unit = options.unit_um;
    let mut rows: Vec<(Tree, NetRow)> = distinct
        .iter()
        .map(|&tree| {
            let net = layout.lay_flat(tree);
            let (long, short) = net.footprint();
            let row = NetRow {
                rank: 0,
                folds: net.folds.clone(),
                radius_of_gyration_um: net.radius_of_gyration() * unit,
                leaves: layout.leaves(tree),
                seam_length_um: layout.seam_length(tree) * unit,
                footprint_um: [long * unit, short * unit],
                overlapping: !net.overlapping_pairs().is_empty(),
                touching: None,
                closing: None,
            };
            (tree, row)
        })
        .collect();
    let key = |row: &NetRow| match options.rank_by {
        RankBy::SeamLength => row.seam_length_um,
        RankBy::Footprint => row.footprint_um[0] * row.footprint_um[1],
        RankBy::RadiusOfGyration | RankBy::Yield => row.radius_of_gyration_um,
    };
    rows.sort_by(|(ta, a), (tb, b)| {
        a.overlapping
            .cmp(&b.overlapping)
            .then(key(a).total_cmp(&key(b)))
            .then(ta.cmp(tb))
    });
    // The best nets that can be made: those touching themselves move down among the
    // overlapping ones.
    let mut checked = 0;
    for (tree, row) in rows.iter_mut() {
        if checked >= options.top.max(options.simulate) || row.overlapping {
            break;
        }
        let touching = net_pattern(solid, &layout.lay_flat(*tree), name).is_err();
        row.touching = Some(touching);
        if !touching {
            checked += 1;
        }
    }
    rows.sort_by_key(|(_, row)| row.overlapping || row.touching == Some(true));
    let overlapping = rows.iter().filter(|(_, r)| r.overlapping).count();
    let nets: Vec<NetRow> = rows
        .into_iter()
        .enumerate()
        .map(|(k, (_, mut row))| {
            row.rank = k + 1;
            row
        })
        .collect();
    Ok(NetsReport {
        solid: name.to_string(),
        faces: solid.faces.len(),
        edges: solid.dual_edges().len(),
        vertices: solid.vertices.len(),
        symmetry_order: symmetries.len(),
        rotations: symmetries.iter().filter(|s| s.is_rotation()).count(),
        symmetry: SymmetrySummary::from(&group),
        reading: None,
        warnings: group.warning().into_iter().collect(),
        spanning_trees: count,
        search,
        trees_considered: trees.len(),
        distinct_nets: nets.len(),
        overlapping,
        rank_by: options.rank_by,
        unit_um: unit,
        nets,
        study: None,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The tree of a ranked net.
fn tree_of(row: &NetRow) -> Tree {
    row.folds.iter().fold(0, |t, &k| t | 1 << k)
}

/// The best `top` nets that can be made, as crease patterns.
pub fn best_net_patterns(solid: &Polyhedron, report: &NetsReport, top: usize) -> Result<Vec<(usize, NetPattern)>> {
    let layout = NetLayout::new(solid);
    report
        .nets
        .iter()
        .filter(|row| !row.overlapping && row.touching == Some(false))
        .take(top)
        .map(|row| {
            Ok((
                row.rank,
                net_pattern(solid, &layout.lay_flat(tree_of(row)), &report.solid)?,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fresh devices' captures: the chosen one, then half and twice it within (0, 50] %.
    #[test]
    fn the_capture_study_runs_half_and_twice_the_capture_where_they_are_allowed() {
        let at = |capture_percent: f64| {
            NetsOptions {
                capture_percent,
                ..NetsOptions::default()
            }
            .captures()
        };
        assert_eq!(at(10.0), [10.0, 5.0, 20.0]);
        assert_eq!(at(25.0), [25.0, 12.5, 50.0]);
        assert_eq!(at(30.0), [30.0, 15.0]);
        for capture in [0.1, 1.0, 10.0, 25.0, 30.0, 50.0] {
            for c in at(capture) {
                assert!(
                    ClosingSettings {
                        capture_percent: c,
                        ..ClosingSettings::default()
                    }
                    .validate()
                    .is_ok(),
                    "{c}"
                );
            }
        }
    }
}
