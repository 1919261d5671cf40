//! Panels that meet (`docs/model.md#panel-contact`): a broad phase on the panels' boxes
//! (`geometry::broad_phase`), then exact triangle–triangle tests in 3D. Panels that share a vertex are
//! left to that vertex's spherical order and not tested here.

use super::model::FoldingModel;
use super::poses::Pose;
use crate::error::{NanofoldError, Result};
use nalgebra::Vector3;

type Point = Vector3<f64>;

/// How close two panels may come before they are reported.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSettings {
    /// Distance below which a pair is a contact, as a fraction of the pattern's size.
    pub clearance: f64,
    /// Pairs whose boxes come within this many median panel widths (the smaller side of a
    /// panel's flat box: long thin panels side by side are not all neighbours) of each
    /// other are measured (for the smallest clearance reported); the cost grows with its
    /// square.
    pub search: f64,
    /// Most pairs of panels measured in one test, per panel (at least `MIN_PAIR_BUDGET`
    /// in all): layers stacked deep (an accordion folded nearly flat) overlap in every pair,
    /// and past this the test stops and says so ([`ContactReport::overflow`]).
    pub pairs_per_panel: usize,
}

/// The least pair budget of a contact test, whatever the number of panels.
pub const MIN_PAIR_BUDGET: usize = 100_000;

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            clearance: 1e-9,
            search: 0.5,
            pairs_per_panel: 64,
        }
    }
}

impl ContactSettings {
    /// Checks the fractions.
    pub fn validate(&self) -> Result<()> {
        if !(self.clearance >= 0.0 && self.clearance <= 0.1) {
            return Err(NanofoldError::invalid(
                "clearance",
                self.clearance,
                "must lie in [0, 0.1] (fraction of the pattern size)",
            ));
        }
        if !(self.search >= 0.0 && self.search <= 10.0) {
            return Err(NanofoldError::invalid(
                "search",
                self.search,
                "must lie in [0, 10] (median panel sizes)",
            ));
        }
        if !(1..=1_000_000).contains(&self.pairs_per_panel) {
            return Err(NanofoldError::invalid(
                "pairs_per_panel",
                self.pairs_per_panel,
                "must lie in [1, 1e6]",
            ));
        }
        Ok(())
    }

    /// The most pairs one test of `panels` panels measures.
    pub fn pair_budget(&self, panels: usize) -> usize {
        self.pairs_per_panel.saturating_mul(panels).max(MIN_PAIR_BUDGET)
    }
}

/// Two panels that come within the clearance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PanelContact {
    /// The two panels, smaller index first.
    pub panels: [usize; 2],
    /// Their distance (0 when they touch or cross).
    pub distance: f64,
    /// Whether one passes through the other (an edge of one crosses the other's interior).
    pub crossing: bool,
}

/// The outcome of one contact test.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactReport {
    /// Pairs closer than the clearance, crossing ones included.
    pub contacts: Vec<PanelContact>,
    /// Number of pairs measured exactly.
    pub pairs_measured: usize,
    /// Smallest distance over the measured pairs (None: no pair within the search range).
    pub min_clearance: Option<f64>,
    /// Some(n): more pairs of panels overlap than the budget (n is the budget + 1, where the
    /// count stopped), so nothing was measured and whether panels cross is not decided.
    pub overflow: Option<usize>,
}

impl ContactReport {
    /// The pairs that pass through each other.
    pub fn crossing(&self) -> impl Iterator<Item = &PanelContact> {
        self.contacts.iter().filter(|c| c.crossing)
    }
}

/// Tests every pair of panels sharing no vertex, posed by `poses`.
pub fn panel_contacts(model: &FoldingModel, poses: &[Pose], settings: &ContactSettings) -> ContactReport {
    let clearance = settings.clearance * model.size;
    // Panels placed through different creases disagree by the state's closure error: a
    // crossing shallower than twice that spread is not decided by the state (stacked
    // layers whose corners land on one point).
    let depth = model.contact_tolerance().max(2.0 * placement_spread(model, poses));
    let search = settings.search * median_panel_width(model);
    let pattern = &model.pattern;
    // Every panel's triangles placed, in one array (a panel's run from `first[p]`), with
    // their boxes and planes.
    let mut first = Vec::with_capacity(poses.len() + 1);
    let mut triangles: Vec<[Point; 3]> = Vec::new();
    for (p, list) in model.panel_triangles.iter().enumerate() {
        first.push(triangles.len());
        triangles.extend(list.iter().map(|t| t.map(|v| poses[p].place(pattern.vertices[v]))));
    }
    first.push(triangles.len());
    let triangle_boxes: Vec<([f64; 3], [f64; 3])> = triangles
        .iter()
        .map(|t| {
            let lo = [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k]));
            let hi = [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k]));
            (lo, hi)
        })
        .collect();
    let planes: Vec<Option<(Point, f64)>> = triangles
        .iter()
        .map(|t| unit_normal(t).map(|n| (n, n.dot(&t[0]))))
        .collect();
    let boxes: Vec<([f64; 3], [f64; 3])> = (0..poses.len())
        .map(|p| {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for x in triangles[first[p]..first[p + 1]].iter().flatten() {
                for k in 0..3 {
                    lo[k] = lo[k].min(x[k] - search / 2.0);
                    hi[k] = hi[k].max(x[k] + search / 2.0);
                }
            }
            (lo, hi)
        })
        .collect();
    let mut report = ContactReport {
        contacts: Vec::new(),
        pairs_measured: 0,
        min_clearance: None,
        overflow: None,
    };
    // Panels that share a vertex are that vertex's to order: they neither count against
    // the budget nor get measured (a fan of thin panels meets pairwise at its centre).
    let apart = |a: usize, b: usize| !share_vertex(&model.panel_vertices[a], &model.panel_vertices[b]);
    let budget = settings.pair_budget(boxes.len());
    let pairs = match crate::geometry::broad_phase::overlapping_pairs_where(&boxes, budget, apart) {
        Ok(pairs) => pairs,
        Err(found) => {
            report.overflow = Some(found);
            return report;
        }
    };
    let placed = Placed {
        first: &first,
        triangles: &triangles,
        boxes: &triangle_boxes,
        planes: &planes,
        search,
        clearance,
        depth,
    };
    report.pairs_measured = pairs.len();
    // The pairs are independent: large tests (stacked layers) are shared among the cores.
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let chunks = cores.min(pairs.len() / PAIRS_PER_THREAD).max(1);
    let measured: Vec<Measured> = if chunks == 1 {
        vec![placed.measure(&pairs)]
    } else {
        let size = pairs.len().div_ceil(chunks);
        std::thread::scope(|scope| {
            let placed = &placed;
            let handles: Vec<_> = pairs
                .chunks(size)
                .map(|chunk| scope.spawn(move || placed.measure(chunk)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
                .collect()
        })
    };
    for part in measured {
        report.contacts.extend(part.contacts);
        report.min_clearance = match (report.min_clearance, part.min_clearance) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }
    report.contacts.sort_by_key(|c| c.panels);
    report
}

/// Pairs below which a contact test's narrow phase stays on one thread.
const PAIRS_PER_THREAD: usize = 50_000;

/// The panels' triangles as one state places them, with what the narrow phase needs.
struct Placed<'a> {
    /// A panel's run of triangles starts at `first[p]`.
    first: &'a [usize],
    triangles: &'a [[Point; 3]],
    boxes: &'a [([f64; 3], [f64; 3])],
    planes: &'a [Option<(Point, f64)>],
    search: f64,
    clearance: f64,
    depth: f64,
}

/// The narrow phase's findings over some pairs.
struct Measured {
    contacts: Vec<PanelContact>,
    min_clearance: Option<f64>,
}

impl Placed<'_> {
    /// The exact distance (or a lower bound above what matters) of every pair.
    fn measure(&self, pairs: &[(usize, usize)]) -> Measured {
        let (first, triangles, planes) = (self.first, self.triangles, self.planes);
        let mut found = Measured {
            contacts: Vec::new(),
            min_clearance: None,
        };
        for &(a, b) in pairs {
            let mut distance = f64::INFINITY;
            let mut crossing = false;
            // Triangles farther apart than this cannot be a contact nor lower the smallest
            // clearance found so far (nor matter beyond the search range): a lower bound of
            // their distance (their boxes' gap, or how far one lies on one side of the
            // other's plane) stands in for it.
            let relevant = self
                .search
                .min(found.min_clearance.unwrap_or(f64::INFINITY))
                .max(self.clearance);
            for i in first[a]..first[a + 1] {
                for j in first[b]..first[b + 1] {
                    let (s_box, t_box) = (&self.boxes[i], &self.boxes[j]);
                    let gap = (0..3)
                        .map(|k| (s_box.0[k] - t_box.1[k]).max(t_box.0[k] - s_box.1[k]))
                        .fold(0.0_f64, f64::max);
                    let bound = gap
                        .max(plane_gap(&triangles[i], planes[j]))
                        .max(plane_gap(&triangles[j], planes[i]));
                    if bound > relevant {
                        distance = distance.min(bound);
                        continue;
                    }
                    let normal = |k: usize| planes[k].map(|(n, _)| n);
                    let (d, c) = triangle_distance_with(&triangles[i], &triangles[j], normal(i), normal(j), self.depth);
                    distance = distance.min(d);
                    crossing |= c;
                }
            }
            found.min_clearance = Some(found.min_clearance.map_or(distance, |m| m.min(distance)));
            if crossing || distance <= self.clearance {
                found.contacts.push(PanelContact {
                    panels: [a.min(b), a.max(b)],
                    distance,
                    crossing,
                });
            }
        }
        found
    }
}

/// The largest distance between two placements of one vertex by the panels that hold it:
/// zero (to rounding) for a state that closes exactly.
pub(crate) fn placement_spread(model: &FoldingModel, poses: &[Pose]) -> f64 {
    let vertices = &model.pattern.vertices;
    let mut spread: f64 = 0.0;
    for (p, list) in model.panel_vertices.iter().enumerate() {
        for &v in list {
            let home = model.panel_of_vertex[v];
            if home != p {
                spread = spread.max((poses[p].place(vertices[v]) - poses[home].place(vertices[v])).norm());
            }
        }
    }
    spread
}

/// The median over panels of their flat bounding boxes' smaller side (kept in the model).
fn median_panel_width(model: &FoldingModel) -> f64 {
    model.median_panel_sides[0]
}

/// The median over panels of their flat bounding boxes' larger side (kept in the model).
pub(crate) fn median_panel_size(model: &FoldingModel) -> f64 {
    model.median_panel_sides[1]
}

pub(crate) fn share_vertex(a: &[usize], b: &[usize]) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Equal => return true,
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
        }
    }
    false
}

/// Distance between two triangles, and whether they cross: each passes through the other's
/// plane (vertices more than `tolerance` on both sides) and the two segments so cut overlap
/// along the planes' common line by more than `tolerance`. The test does not depend on how
/// a panel was cut into triangles: two panels crossing where their diagonals meet are
/// found as well as an edge through an interior. Touching (coplanar overlap, an edge lying
/// on the other) gives distance 0 without a crossing. `ns` and `nt` are the triangles'
/// unit normals (None: no area), computed once per contact test.
fn triangle_distance_with(
    s: &[Point; 3],
    t: &[Point; 3],
    ns: Option<Point>,
    nt: Option<Point>,
    tolerance: f64,
) -> (f64, bool) {
    if triangles_cross(s, t, ns, nt, tolerance) {
        return (0.0, true);
    }
    let mut best = f64::INFINITY;
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(segment_distance(&s[i], &s[(i + 1) % 3], &t[j], &t[(j + 1) % 3]));
        }
        best = best.min(point_triangle_distance(&s[i], t));
        best = best.min(point_triangle_distance(&t[i], s));
    }
    (best, false)
}

/// How far a triangle lies wholly on one side of a plane (unit normal, offset): the
/// smallest distance of its vertices from it, or 0 where it touches or straddles the plane.
/// A lower bound of its distance to anything in that plane.
fn plane_gap(triangle: &[Point; 3], plane: Option<(Point, f64)>) -> f64 {
    let Some((normal, offset)) = plane else {
        return 0.0;
    };
    let d = triangle.map(|x| normal.dot(&x) - offset);
    if d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0) {
        d.iter().fold(f64::INFINITY, |m, x| m.min(x.abs()))
    } else {
        0.0
    }
}

/// A unit vector along `v`, scaled first so that its squares neither overflow nor
/// underflow (a pattern 1e-100 across has cross products of 1e-200); None for zero.
fn unit(v: Point) -> Option<Point> {
    let largest = v.amax();
    if largest == 0.0 || !largest.is_finite() {
        return None;
    }
    let scaled = v / largest;
    Some(scaled / scaled.norm())
}

/// The unit normal of a triangle (None when it has no area).
fn unit_normal(triangle: &[Point; 3]) -> Option<Point> {
    let [a, b, c] = triangle;
    let (u, v) = (unit(b - a)?, unit(c - a)?);
    unit(u.cross(&v))
}

/// Whether two triangles pass through each other (see [`triangle_distance_with`]).
fn triangles_cross(s: &[Point; 3], t: &[Point; 3], ns: Option<Point>, nt: Option<Point>, tolerance: f64) -> bool {
    let (Some(ns), Some(nt)) = (ns, nt) else {
        return false;
    };
    let side = |triangle: &[Point; 3], normal: &Point, origin: &Point| triangle.map(|x| normal.dot(&(x - origin)));
    let (ds, dt) = (side(s, &nt, &t[0]), side(t, &ns, &s[0]));
    let straddles = |d: [f64; 3]| d.iter().any(|&x| x > tolerance) && d.iter().any(|&x| x < -tolerance);
    if !straddles(ds) || !straddles(dt) {
        return false;
    }
    let Some(line) = unit(ns.cross(&nt)) else {
        return false;
    };
    // Where each triangle meets the other's plane, as an interval along the common line.
    let interval = |triangle: &[Point; 3], d: [f64; 3]| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut take = |x: Point| {
            let along = line.dot(&x);
            lo = lo.min(along);
            hi = hi.max(along);
        };
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            if d[a].abs() <= tolerance {
                take(triangle[a]);
            }
            if (d[a] > tolerance && d[b] < -tolerance) || (d[a] < -tolerance && d[b] > tolerance) {
                take(triangle[a] + (triangle[b] - triangle[a]) * (d[a] / (d[a] - d[b])));
            }
        }
        (lo, hi)
    };
    let (a, b) = (interval(s, ds), interval(t, dt));
    a.1.min(b.1) - a.0.max(b.0) > tolerance
}

/// Closest distance between segments p1q1 and p2q2 (clamped parameters).
fn segment_distance(p1: &Point, q1: &Point, p2: &Point, q2: &Point) -> f64 {
    let (x, y) = segment_closest(p1, q1, p2, q2);
    (x - y).norm()
}

/// The nearest points of panels `a` and `b` posed by `poses` (on a, on b): over their
/// triangles, each vertex against the other triangle and each pair of edges. Where the
/// panels first touch, these are the contact.
pub fn nearest_points(model: &FoldingModel, poses: &[Pose], a: usize, b: usize) -> (Point, Point) {
    let place = |p: usize| -> Vec<[Point; 3]> {
        model.panel_triangles[p]
            .iter()
            .map(|t| t.map(|v| poses[p].place(model.pattern.vertices[v])))
            .collect()
    };
    let (ta, tb) = (place(a), place(b));
    let mut best = (f64::INFINITY, Point::zeros(), Point::zeros());
    let mut consider = |x: Point, y: Point| {
        let d = (x - y).norm();
        if d < best.0 {
            best = (d, x, y);
        }
    };
    for s in &ta {
        for t in &tb {
            for i in 0..3 {
                consider(s[i], closest_point_on_triangle(&s[i], t));
                consider(closest_point_on_triangle(&t[i], s), t[i]);
                for j in 0..3 {
                    let (x, y) = segment_closest(&s[i], &s[(i + 1) % 3], &t[j], &t[(j + 1) % 3]);
                    consider(x, y);
                }
            }
        }
    }
    (best.1, best.2)
}

/// The closest points of segments p1q1 and p2q2 (clamped parameters).
fn segment_closest(p1: &Point, q1: &Point, p2: &Point, q2: &Point) -> (Point, Point) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let (s, t) = if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        (0.0, 0.0)
    } else if a <= f64::MIN_POSITIVE {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= f64::MIN_POSITIVE {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denominator = a * e - b * b;
            let mut s = if denominator > 0.0 {
                ((b * f - c * e) / denominator).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

/// Distance from a point to a triangle.
fn point_triangle_distance(p: &Point, triangle: &[Point; 3]) -> f64 {
    (p - closest_point_on_triangle(p, triangle)).norm()
}

/// The point of a triangle nearest to p (Voronoi regions of its vertices, edges and face).
pub(crate) fn closest_point_on_triangle(p: &Point, triangle: &[Point; 3]) -> Point {
    let [a, b, c] = triangle;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = 1.0 / (va + vb + vc);
    a + ab * (vb * denominator) + ac * (vc * denominator)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle_distance(s: &[Point; 3], t: &[Point; 3], tolerance: f64) -> (f64, bool) {
        triangle_distance_with(s, t, unit_normal(s), unit_normal(t), tolerance)
    }

    fn p(x: f64, y: f64, z: f64) -> Point {
        Point::new(x, y, z)
    }

    #[test]
    fn triangle_distances_match_hand_computed_cases() {
        let base = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)];
        // Parallel copy 0.3 above: distance 0.3, no crossing.
        let above = base.map(|x| x + p(0.0, 0.0, 0.3));
        assert_eq!(triangle_distance(&base, &above, 1e-12), (0.3, false));
        // A vertical triangle piercing the base's interior.
        let pierce = [p(0.2, 0.2, -1.0), p(0.2, 0.2, 1.0), p(0.3, 0.2, 1.0)];
        assert!(triangle_distance(&base, &pierce, 1e-12).1);
        // Standing on the base (an edge lies in it): touching, not crossing.
        let standing = [p(0.2, 0.2, 0.0), p(0.3, 0.2, 0.0), p(0.25, 0.2, 1.0)];
        let (d, crossing) = triangle_distance(&base, &standing, 1e-12);
        assert!(!crossing && d < 1e-15, "{d}");
        // Off to the side and above: the edge-to-edge distance, sqrt(0.5^2 + 0.5^2).
        let aside = [p(1.5, 0.0, 0.5), p(2.5, 0.0, 0.5), p(1.5, 1.0, 0.5)];
        let (d, crossing) = triangle_distance(&base, &aside, 1e-12);
        assert!(!crossing && (d - 0.5f64.hypot(0.5)).abs() < 1e-15, "{d}");
        // Skew segments: edge (0,0,0)-(1,0,0) against a triangle whose nearest feature is a
        // point above the base's interior at height 0.4.
        let tent = [p(0.25, 0.25, 0.4), p(0.25, 0.25, 2.0), p(0.3, 0.3, 2.0)];
        let (d, _) = triangle_distance(&base, &tent, 1e-12);
        assert!((d - 0.4).abs() < 1e-15, "{d}");
    }

    #[test]
    fn triangles_crossing_where_their_edges_meet_are_crossing_at_any_scale() {
        // Planes z = x and z = -x meet along the y axis; each triangle's edge crosses it at
        // the origin, exactly where the other's does, and both have a corner at (0, 2, 0):
        // no edge passes through an interior, yet the two cut each other along 0 <= y <= 2.
        let s = [p(-1.0, 0.0, -1.0), p(1.0, 0.0, 1.0), p(0.0, 2.0, 0.0)];
        let t = [p(-1.0, 0.0, 1.0), p(1.0, 0.0, -1.0), p(0.0, 2.0, 0.0)];
        for scale in [1e-100, 1.0, 1e100] {
            let (s, t) = (s.map(|x| x * scale), t.map(|x| x * scale));
            assert_eq!(triangle_distance(&s, &t, 1e-12 * scale), (0.0, true), "scale {scale}");
        }
        // Moved along the line so the cuts only meet at a point: touching, not crossing.
        let apart = t.map(|x| x + p(0.0, 2.0, 0.0));
        let (d, crossing) = triangle_distance(&s, &apart, 1e-12);
        assert!(!crossing && d < 1e-15, "{d}");
    }

    /// The plane-separation bound that lets the contact test skip a pair of triangles never
    /// exceeds their distance, and is 0 wherever they cross (random pairs, a deterministic
    /// draw, many of them near each other).
    #[test]
    fn the_plane_bound_is_a_lower_bound_of_the_distance() {
        let mut next = crate::geometry::test_draws(0x9E37_79B9_7F4A_7C15_u64);
        let mut separated = 0;
        for _ in 0..20_000 {
            let mut corner = || p(next(), next(), next());
            let s = [corner(), corner(), corner()];
            let t = [corner(), corner(), corner()];
            let plane = |x: &[Point; 3]| unit_normal(x).map(|n| (n, n.dot(&x[0])));
            let bound = plane_gap(&s, plane(&t)).max(plane_gap(&t, plane(&s)));
            let (d, crossing) = triangle_distance(&s, &t, 1e-12);
            assert!(bound <= d * (1.0 + 1e-12) + 1e-15, "bound {bound} above distance {d}");
            if crossing {
                assert_eq!(bound, 0.0);
            }
            separated += usize::from(bound > 0.0);
        }
        assert!(separated > 1_000, "the bound is positive for {separated} pairs");
    }
}
