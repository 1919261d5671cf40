//! First contact of a panel network (`docs/model.md#panel-networks`), as signed gaps along
//! a path for [`crate::dynamics::contact::locate`]:
//! - a crease folding flat: π − |ρ| reaches 0;
//! - panels that share a vertex but no crease: the angle between their corners at that
//!   vertex (great-circle arcs on the unit sphere about it) closes to within
//!   [`ANGLE_MARGIN`] (for convex panels any meeting shows there first). SPEC §11 reads 1°;
//!   a margin that wide reports a flap folding flat, whose edge then meets its neighbour's,
//!   1.4° before the crease reaches 180° (the corner cube's step 1), so the margin here is
//!   the crease's own, 1e-9 rad: it still catches edges that only meet as a ramp ends;
//! - panels that share no vertex: the smallest distance between them, from the folding
//!   layer's broad phase and exact triangle tests, reaches the clearance (negative once two
//!   cross);
//! - with the substrate on, a vertex reaching z = 0 outside the paper's flat outline.
//!
//! A pair that already touches at the start (the layers of a flat-folded flap) is left out,
//! as the unfolding's barrier leaves out stacked layers: it did not close, it was closed.

use super::algorithms::{update_poses, NetworkData};
use super::model::NetworkModel;
use crate::dynamics::contact::{Collision, ContactProbe};
use crate::folding::contact::nearest_points;
use crate::folding::{panel_contacts, ContactReport, ContactSettings, Pose};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Panels that share a vertex touch when their corners there close to within this, rad.
pub const ANGLE_MARGIN: f64 = 1e-9;
/// A crease touches when |ρ| reaches π to within this, rad.
const FOLD_TOUCH: f64 = 1e-9;

/// One panel's corner at a vertex: the arc from `first` counter-clockwise (about the panel's
/// normal) to `second`, directions in the flat sheet.
#[derive(Debug, Clone, Copy)]
struct Corner {
    panel: usize,
    first: Vector3<f64>,
    second: Vector3<f64>,
    /// FOLD edges along `first` and `second`.
    edges: [usize; 2],
}

#[derive(Debug, Clone)]
enum Candidate {
    Fold {
        column: usize,
    },
    Vertex {
        vertex: usize,
        a: Vec<Corner>,
        b: Vec<Corner>,
    },
    Panels,
    Substrate {
        vertex: usize,
        panel: usize,
    },
}

/// The contact candidates of a network.
#[derive(Debug, Clone)]
pub struct NetworkContacts {
    candidates: Vec<Candidate>,
    /// Pairs left out because they touch at the start.
    dropped: Vec<[String; 2]>,
    /// The paper's flat outline, m (substrate gate).
    outline: Vec<[f64; 2]>,
    settings: ContactSettings,
}

impl NetworkContacts {
    /// Every candidate of `model` (none without collisions).
    pub fn new(model: &NetworkModel, collisions: bool) -> NetworkContacts {
        let pattern = &model.folding.pattern;
        let unit = model.unit;
        let mut candidates = Vec::new();
        let outline = pattern
            .outline
            .iter()
            .map(|&v| [pattern.vertices[v][0] * unit, pattern.vertices[v][1] * unit])
            .collect();
        if collisions {
            candidates.extend(
                (0..model.columns())
                    .filter(|&c| !model.locked(c))
                    .map(|column| Candidate::Fold { column }),
            );
            let mut edge_of: HashMap<(usize, usize), usize> = HashMap::new();
            for (e, &[a, b]) in pattern.edges.iter().enumerate() {
                edge_of.insert((a.min(b), a.max(b)), e);
            }
            let edge = |a: usize, b: usize| edge_of[&(a.min(b), a.max(b))];
            // Panels joined by a crease meet only at that crease (the fold candidate).
            let mut hinged: std::collections::HashSet<(usize, usize)> = std::collections::HashSet::new();
            for &e in &pattern.creases {
                if let [Some(l), Some(r)] = pattern.edge_faces[e] {
                    let (a, b) = (pattern.panel_of_face[l], pattern.panel_of_face[r]);
                    hinged.insert((a.min(b), a.max(b)));
                }
            }
            let flat = |v: usize| Vector3::new(pattern.vertices[v][0], pattern.vertices[v][1], 0.0);
            let mut corners: Vec<Vec<Corner>> = vec![Vec::new(); pattern.vertices.len()];
            for (f, face) in pattern.faces.iter().enumerate() {
                let k = face.len();
                for i in 0..k {
                    let (u, v, w) = (face[(i + k - 1) % k], face[i], face[(i + 1) % k]);
                    corners[v].push(Corner {
                        panel: pattern.panel_of_face[f],
                        first: (flat(w) - flat(v)).normalize(),
                        second: (flat(u) - flat(v)).normalize(),
                        edges: [edge(v, w), edge(v, u)],
                    });
                }
            }
            for (vertex, list) in corners.iter().enumerate() {
                let mut panels: Vec<usize> = list.iter().map(|c| c.panel).collect();
                panels.sort_unstable();
                panels.dedup();
                for (i, &a) in panels.iter().enumerate() {
                    for &b in &panels[i + 1..] {
                        if hinged.contains(&(a, b)) {
                            continue;
                        }
                        let of = |p: usize| list.iter().filter(|c| c.panel == p).copied().collect();
                        candidates.push(Candidate::Vertex {
                            vertex,
                            a: of(a),
                            b: of(b),
                        });
                    }
                }
            }
            if model.panels() > 2 {
                candidates.push(Candidate::Panels);
            }
            if model.substrate_contact {
                for (vertex, list) in corners.iter().enumerate() {
                    if let Some(c) = list.iter().find(|c| c.panel != model.anchored_panel) {
                        if !list.iter().any(|c| c.panel == model.anchored_panel) {
                            candidates.push(Candidate::Substrate { vertex, panel: c.panel });
                        }
                    }
                }
            }
        }
        let mut contacts = NetworkContacts {
            candidates,
            outline,
            // Past the pair budget a test is not decided: the run stops there and says so
            // (a contact event named for the budget), rather than measuring every pair.
            settings: ContactSettings {
                search: 0.5,
                ..ContactSettings::default()
            },
            dropped: Vec::new(),
        };
        contacts.drop_touching_at_start(model);
        contacts
    }

    /// Leaves out the panel pairs at a shared vertex that touch at the start.
    fn drop_touching_at_start(&mut self, model: &NetworkModel) {
        let mut data = NetworkData::new(model);
        update_poses(model, &model.start, &mut data);
        let start = &model.start;
        let mut kept = Vec::with_capacity(self.candidates.len());
        for k in 0..self.candidates.len() {
            let touching =
                matches!(self.candidates[k], Candidate::Vertex { .. }) && self.gap(model, k, start, &data, None) <= 0.0;
            if touching {
                self.dropped
                    .push(self.collision(model, k, 0.0, start, &data, None).pair);
            } else {
                kept.push(self.candidates[k].clone());
            }
        }
        self.candidates = kept;
    }

    /// Pairs left out because they touch at the start.
    pub fn touching_at_start(&self) -> &[[String; 2]] {
        &self.dropped
    }

    /// Number of candidates.
    pub fn count(&self) -> usize {
        self.candidates.len()
    }

    /// A contact present at `q` (a crease folded flat, panels crossing), for the start.
    pub fn touching(&self, model: &NetworkModel, t: f64, q: &[f64], data: &mut NetworkData) -> Option<Collision> {
        update_poses(model, q, data);
        let report = self.panel_report(model, data);
        (0..self.count())
            .find(|&k| {
                let gap = self.gap(model, k, q, data, report.as_ref());
                gap <= 0.0 && self.gate(model, k, data)
            })
            .map(|k| self.collision(model, k, t, q, data, report.as_ref()))
    }

    /// Every pair that meets at `q` to within `tolerance` (rad for angles, a fraction of the
    /// pattern's size for distances): at a first contact, the pairs that touch together (a
    /// cube's walls closing at once).
    pub fn meeting(&self, model: &NetworkModel, q: &[f64], data: &mut NetworkData, tolerance: f64) -> Vec<[String; 2]> {
        update_poses(model, q, data);
        let mut pairs = Vec::new();
        for k in 0..self.count() {
            match &self.candidates[k] {
                Candidate::Panels => {
                    let wide = ContactSettings {
                        clearance: tolerance,
                        ..self.settings
                    };
                    let report = panel_contacts(&model.folding, &self.poses(model, data), &wide);
                    if let Some(found) = report.overflow {
                        pairs.push([
                            format!("contact budget: more than {found} pairs of panels overlap"),
                            "whether panels cross was not decided".to_string(),
                        ]);
                    }
                    for contact in &report.contacts {
                        pairs.push([
                            Self::face_name(model, contact.panels[0]),
                            Self::face_name(model, contact.panels[1]),
                        ]);
                    }
                }
                Candidate::Substrate { .. } => {
                    let gap = self.gap(model, k, q, data, None);
                    if gap <= tolerance * model.size() && self.gate(model, k, data) {
                        pairs.push(self.collision(model, k, 0.0, q, data, None).pair);
                    }
                }
                _ => {
                    let margin = match &self.candidates[k] {
                        Candidate::Fold { .. } => FOLD_TOUCH,
                        _ => ANGLE_MARGIN,
                    };
                    if self.gap(model, k, q, data, None) + margin <= tolerance {
                        pairs.push(self.collision(model, k, 0.0, q, data, None).pair);
                    }
                }
            }
        }
        pairs
    }

    fn poses(&self, model: &NetworkModel, data: &NetworkData) -> Vec<Pose> {
        (0..model.panels())
            .map(|p| Pose {
                rotation: data.rotation[p],
                translation: data.translation[p] / model.unit,
            })
            .collect()
    }

    fn panel_report(&self, model: &NetworkModel, data: &NetworkData) -> Option<ContactReport> {
        if !self.candidates.iter().any(|c| matches!(c, Candidate::Panels)) {
            return None;
        }
        Some(panel_contacts(&model.folding, &self.poses(model, data), &self.settings))
    }

    fn gap(
        &self,
        model: &NetworkModel,
        k: usize,
        q: &[f64],
        data: &NetworkData,
        report: Option<&ContactReport>,
    ) -> f64 {
        match &self.candidates[k] {
            Candidate::Fold { column } => PI - q[*column].abs() - FOLD_TOUCH,
            Candidate::Vertex { a, b, .. } => {
                let (distance, crossing) = corner_distance(a, b, data);
                if crossing {
                    -distance - ANGLE_MARGIN
                } else {
                    distance - ANGLE_MARGIN
                }
            }
            Candidate::Panels => {
                let Some(report) = report else { return f64::INFINITY };
                let clearance = self.settings.clearance * model.folding.size;
                if report.crossing().next().is_some() || report.overflow.is_some() {
                    -clearance.max(f64::MIN_POSITIVE)
                } else {
                    report
                        .min_clearance
                        .map_or(self.settings.search * model.folding.size, |d| d - clearance)
                }
            }
            Candidate::Substrate { vertex, panel } => {
                let x = self.world_vertex(model, *vertex, *panel, data);
                x.z + 1e-12 * model.size()
            }
        }
    }

    fn gate(&self, model: &NetworkModel, k: usize, data: &NetworkData) -> bool {
        match &self.candidates[k] {
            Candidate::Substrate { vertex, panel } => {
                let x = self.world_vertex(model, *vertex, *panel, data);
                !inside(&self.outline, [x.x, x.y])
            }
            _ => true,
        }
    }

    fn world_vertex(&self, model: &NetworkModel, vertex: usize, panel: usize, data: &NetworkData) -> Vector3<f64> {
        let v = model.folding.pattern.vertices[vertex];
        data.place(panel, &Vector3::new(v[0] * model.unit, v[1] * model.unit, 0.0))
    }

    fn face_name(model: &NetworkModel, panel: usize) -> String {
        model.panel_names[panel].clone()
    }

    fn collision(
        &self,
        model: &NetworkModel,
        k: usize,
        t: f64,
        q: &[f64],
        data: &NetworkData,
        report: Option<&ContactReport>,
    ) -> Collision {
        let pattern = &model.folding.pattern;
        match &self.candidates[k] {
            Candidate::Fold { column } => {
                let e = pattern.creases[*column];
                let [a, b] = pattern.edges[e];
                let panel = model.carried[*column].unwrap_or(model.anchored_panel);
                let mid = |v: usize| {
                    let p = pattern.vertices[v];
                    Vector3::new(p[0] * model.unit, p[1] * model.unit, 0.0)
                };
                Collision {
                    time: t,
                    pair: [
                        format!("edges[{e}] folded flat"),
                        format!("{:.6}°", q[*column].to_degrees()),
                    ],
                    point: data.place(panel, &((mid(a) + mid(b)) * 0.5)),
                }
            }
            Candidate::Vertex { vertex, a, b } => {
                let (ea, eb) = nearest_edges(a, b, data);
                let panel = a[0].panel;
                Collision {
                    time: t,
                    pair: [
                        format!("{} (edges[{ea}])", Self::face_name(model, a[0].panel)),
                        format!(
                            "{} (edges[{eb}]) at vertex {vertex}",
                            Self::face_name(model, b[0].panel)
                        ),
                    ],
                    point: self.world_vertex(model, *vertex, panel, data),
                }
            }
            Candidate::Panels if report.is_some_and(|r| r.overflow.is_some()) => {
                let found = report.and_then(|r| r.overflow).unwrap_or(0);
                Collision {
                    time: t,
                    pair: [
                        format!(
                            "the contact budget ({} pairs of panels measured at most)",
                            self.settings.pair_budget(model.panels())
                        ),
                        format!("more than {found} overlapping pairs (layers stacked deep; whether panels cross was not decided)"),
                    ],
                    point: data.translation[model.anchored_panel],
                }
            }
            Candidate::Panels => {
                let pair = report
                    .and_then(|r| {
                        r.contacts
                            .iter()
                            .min_by(|x, y| {
                                (!x.crossing, x.distance)
                                    .partial_cmp(&(!y.crossing, y.distance))
                                    .expect("finite")
                            })
                            .map(|c| c.panels)
                    })
                    .unwrap_or([0, 0]);
                // Midway between the two panels' nearest points (pattern units → m).
                let (x, y) = nearest_points(&model.folding, &self.poses(model, data), pair[0], pair[1]);
                Collision {
                    time: t,
                    pair: [Self::face_name(model, pair[0]), Self::face_name(model, pair[1])],
                    point: (x + y) * (0.5 * model.unit),
                }
            }
            Candidate::Substrate { vertex, panel } => Collision {
                time: t,
                pair: [
                    format!("{} (vertex {vertex})", Self::face_name(model, *panel)),
                    "substrate".to_string(),
                ],
                point: self.world_vertex(model, *vertex, *panel, data),
            },
        }
    }
}

/// Whether a flat point lies inside a counter-clockwise polygon (crossing number).
fn inside(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// A corner placed: its two unit directions and its plane's normal, in the world.
fn placed(corner: &Corner, data: &NetworkData) -> [Vector3<f64>; 3] {
    let r = data.rotation[corner.panel];
    [r * corner.first, r * corner.second, r.column(2).into_owned()]
}

/// Whether unit `p` (on the arc's great circle) lies on the arc from `first` turning about
/// `normal` to `second`.
fn on_arc(p: &Vector3<f64>, [first, second, normal]: &[Vector3<f64>; 3]) -> bool {
    let turn = |x: &Vector3<f64>| {
        let a = first.cross(x).dot(normal).atan2(first.dot(x));
        if a < 0.0 {
            a + 2.0 * PI
        } else {
            a
        }
    };
    turn(p) <= turn(second) + 1e-15
}

/// Angular distance of unit `p` from an arc.
fn point_arc(p: &Vector3<f64>, arc: &[Vector3<f64>; 3]) -> f64 {
    let normal = arc[2];
    let off = p.dot(&normal);
    let along = p - normal * off;
    if along.norm() > 1e-15 && on_arc(&along.normalize(), arc) {
        return off.abs().atan2(along.norm());
    }
    angle(p, &arc[0]).min(angle(p, &arc[1]))
}

/// The smallest angle between two panels' corners at a shared vertex, and whether their arcs
/// cross (the panels pass through each other there).
fn corner_distance(a: &[Corner], b: &[Corner], data: &NetworkData) -> (f64, bool) {
    let mut best = f64::INFINITY;
    let mut crossing = false;
    for ca in a {
        let arc_a = placed(ca, data);
        for cb in b {
            let arc_b = placed(cb, data);
            let line = arc_a[2].cross(&arc_b[2]);
            if line.norm() > 1e-12 {
                let d = line.normalize();
                for x in [d, -d] {
                    if on_arc(&x, &arc_a) && on_arc(&x, &arc_b) {
                        // A crossing only if it lies inside both arcs, not at an end of one.
                        let interior = |arc: &[Vector3<f64>; 3]| angle(&x, &arc[0]).min(angle(&x, &arc[1])) > 1e-12;
                        if interior(&arc_a) && interior(&arc_b) {
                            crossing = true;
                        }
                    }
                }
            }
            for p in [arc_a[0], arc_a[1]] {
                best = best.min(point_arc(&p, &arc_b));
            }
            for p in [arc_b[0], arc_b[1]] {
                best = best.min(point_arc(&p, &arc_a));
            }
        }
    }
    (best, crossing)
}

/// The two edges (one per panel) whose directions at the vertex are nearest each other.
fn nearest_edges(a: &[Corner], b: &[Corner], data: &NetworkData) -> (usize, usize) {
    let mut best = (f64::INFINITY, (0, 0));
    for ca in a {
        let arc_a = placed(ca, data);
        for cb in b {
            let arc_b = placed(cb, data);
            for (i, x) in arc_a[..2].iter().enumerate() {
                for (j, y) in arc_b[..2].iter().enumerate() {
                    let d = angle(x, y);
                    if d < best.0 {
                        best = (d, (ca.edges[i], cb.edges[j]));
                    }
                }
            }
        }
    }
    best.1
}

/// A path of fold angles: writes the angles at a path parameter.
pub type AnglePath<'a> = Box<dyn FnMut(f64, &mut [f64]) + 'a>;

/// The candidates along an integrator's or a drive's path.
pub struct NetworkProbe<'a> {
    model: &'a NetworkModel,
    contacts: &'a NetworkContacts,
    data: &'a mut NetworkData,
    q: &'a mut [f64],
    path: AnglePath<'a>,
    report: Option<ContactReport>,
    failed: bool,
}

impl<'a> NetworkProbe<'a> {
    /// A probe over `path` (which writes the fold angles at a path parameter into `q`).
    pub fn new(
        model: &'a NetworkModel,
        contacts: &'a NetworkContacts,
        data: &'a mut NetworkData,
        q: &'a mut [f64],
        path: AnglePath<'a>,
    ) -> Self {
        NetworkProbe {
            model,
            contacts,
            data,
            q,
            path,
            report: None,
            failed: false,
        }
    }
}

impl ContactProbe for NetworkProbe<'_> {
    fn count(&self) -> usize {
        self.contacts.count()
    }

    fn move_to(&mut self, t: f64) {
        (self.path)(t, self.q);
        self.failed = self.q.iter().any(|v| !v.is_finite());
        if !self.failed {
            update_poses(self.model, self.q, self.data);
            self.report = self.contacts.panel_report(self.model, self.data);
        }
    }

    fn gap(&self, k: usize) -> f64 {
        if self.failed {
            return f64::INFINITY;
        }
        self.contacts
            .gap(self.model, k, self.q, self.data, self.report.as_ref())
    }

    fn gate(&self, k: usize) -> bool {
        !self.failed && self.contacts.gate(self.model, k, self.data)
    }

    fn collision(&self, k: usize, t: f64) -> Collision {
        self.contacts
            .collision(self.model, k, t, self.q, self.data, self.report.as_ref())
    }
}
