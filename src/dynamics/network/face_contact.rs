//! Contact between the convex faces of a panel network (`docs/model.md#contact-forces`):
//! the features where two faces can touch (a corner of one on the other's interior, an
//! edge of one across an edge of the other), each feature's signed gap and its row in the
//! fold angles. A feature's side is the one it was on when it came over the other face;
//! a gap below zero on that side is penetration.

use super::algorithms::NetworkData;
use super::model::NetworkModel;
use nalgebra::{DVector, Vector3};

/// A feature counts as over the other face only this far (a fraction of the size) inside
/// its outline: at the outline another feature (an edge across an edge) takes over.
const GATE_MARGIN: f64 = 1e-9;
/// Edges more nearly parallel than this (the sine of their angle) have no crossing normal:
/// a corner on a face measures them.
const PARALLEL_SINE: f64 = 1e-6;
/// Copies of one point this close (a fraction of the size) have met: the edges from them
/// measure contact there, and the corner and edge features at them (degenerate there)
/// stand down.
const MET: f64 = 1e-4;

/// Where two faces can touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// Corner `vertex` (a pattern vertex) of face `face` on the interior of face `other`.
    CornerOnFace {
        /// The face the corner belongs to.
        face: usize,
        /// The corner (pattern vertex).
        vertex: usize,
        /// The face it may touch.
        other: usize,
        /// The other face's copy of the corner, if it has one: once they have met, the
        /// edges from it measure the contact there.
        copy: Option<usize>,
    },
    /// The edge from corner `corner` to `far` of face `face` against the plane of face
    /// `other` at its corner `apex`, the same point (the same pattern vertex, or a copy of
    /// it that has met it): the edge turning into the other face's corner (a corner the
    /// faces share turns no gap of the corners or edges above).
    EdgeOnCorner {
        /// The face the edge belongs to.
        face: usize,
        /// The edge's corner at the shared point (pattern vertex).
        corner: usize,
        /// The edge's far end.
        far: usize,
        /// The face sharing the point.
        other: usize,
        /// Its corner there.
        apex: usize,
    },
    /// Edge `edge` of face `face` across edge `other_edge` of face `other`.
    EdgeOnEdge {
        /// The first face.
        face: usize,
        /// Its edge (pattern vertices).
        edge: [usize; 2],
        /// The second face.
        other: usize,
        /// Its edge.
        other_edge: [usize; 2],
        /// An end of each edge that are copies of one point, if any: once they have met,
        /// the edges from it measure the contact there.
        copy: Option<[usize; 2]>,
    },
    /// The middle of edge `edge` of face `face`, both of whose ends are copies of corners
    /// of face `other` (`copies`, in order): a seam's edge, as long as the face it may cross
    /// is wide, whose corners stay on that face's outline and whose partner edge runs
    /// parallel to it, so that neither a corner nor an edge crossing sees it go through.
    EdgeMiddleOnFace {
        /// The face the edge belongs to.
        face: usize,
        /// The edge (pattern vertices).
        edge: [usize; 2],
        /// The face it may cross.
        other: usize,
        /// The other face's copies of the edge's ends.
        copies: [usize; 2],
    },
}

impl Feature {
    /// The two faces: the first pushed along the normal, the second against it.
    pub fn faces(&self) -> [usize; 2] {
        match *self {
            Feature::CornerOnFace { face, other, .. }
            | Feature::EdgeOnCorner { face, other, .. }
            | Feature::EdgeOnEdge { face, other, .. }
            | Feature::EdgeMiddleOnFace { face, other, .. } => [face, other],
        }
    }
}

/// A feature where it is now: the point of touch, the unit normal from the second face
/// towards the first, the distance along it (m), and whether the feature is over the other
/// face (a corner inside its outline, an edge crossing inside both edges).
#[derive(Debug, Clone, Copy)]
pub struct FeatureState {
    /// The point on the first face, m.
    pub point: Vector3<f64>,
    /// The point on the second face, m.
    pub other_point: Vector3<f64>,
    /// From the second face towards the first.
    pub normal: Vector3<f64>,
    /// normal · (point − other_point), m.
    pub distance: f64,
    /// Whether the feature is over the other face.
    pub over: bool,
}

/// Whether `point`'s foot lies inside the face of `corners` (counter-clockwise about
/// `normal`) by at least `margin` from every edge.
fn inside_outline(corners: &[Vector3<f64>], normal: &Vector3<f64>, point: &Vector3<f64>, margin: f64) -> bool {
    (0..corners.len()).all(|i| {
        let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
        let along = b - a;
        along.cross(&(point - a)).dot(normal) >= margin * along.norm()
    })
}

impl FeatureState {
    /// A point `distance` from a plane of unit `normal`, its foot there the other point.
    fn on_plane(point: Vector3<f64>, normal: Vector3<f64>, distance: f64, over: bool) -> FeatureState {
        FeatureState {
            point,
            other_point: point - normal * distance,
            normal,
            distance,
            over,
        }
    }
}

/// Every face's corners (in its loop's order) and unit normal at one set of poses, m.
#[derive(Debug, Clone)]
pub struct PlacedFaces {
    /// Every face's corners, face after face ([`FaceContacts`]' `corner_start` says where
    /// each face's begin).
    corners: Vec<Vector3<f64>>,
    normals: Vec<Vector3<f64>>,
}

/// The faces of a network and their contact features.
#[derive(Debug, Clone)]
pub struct FaceContacts {
    /// Each face's corners (pattern vertices), counter-clockwise in the flat sheet.
    pub faces: Vec<Vec<usize>>,
    /// Each face's panel.
    pub face_panel: Vec<usize>,
    /// Each pattern vertex in the flat sheet, m.
    pub flat: Vec<Vector3<f64>>,
    /// Every feature.
    pub features: Vec<Feature>,
    /// Each pair of faces that may touch (the lower face first).
    pub pairs: Vec<[usize; 2]>,
    /// Each pair's features.
    pub pair_features: Vec<Vec<usize>>,
    /// Each feature's pair.
    pub feature_pair: Vec<usize>,
    /// Each face's centre in the flat sheet and the radius of its corners about it, m.
    bounds: Vec<(Vector3<f64>, f64)>,
    /// Each panel's tree columns to the anchored panel.
    paths: Vec<Vec<usize>>,
    /// Where each face's corners begin among the placed corners (one more entry than faces).
    corner_start: Vec<usize>,
    /// Each feature's corners among the placed corners, in the order its state reads them.
    slots: Vec<[usize; 6]>,
    size: f64,
}

impl FaceContacts {
    /// The features of every pair of faces of `model` on different panels that share no
    /// crease (a crease's panels touch only by folding flat, which its own limit watches),
    /// and whose `keep` says they may touch. `copies` names each pattern vertex's point of
    /// the made object (a net's solid vertex; the vertex itself otherwise): a corner that
    /// is a copy of one of the other face's corners meets it only there, at its outline,
    /// so neither it nor an edge from it is a feature (the seam's latch decides there).
    pub fn new(model: &NetworkModel, copies: &[usize], keep: impl Fn(usize, usize) -> bool) -> FaceContacts {
        let pattern = &model.folding.pattern;
        let unit = model.unit;
        let flat: Vec<Vector3<f64>> = pattern
            .vertices
            .iter()
            .map(|p| Vector3::new(p[0] * unit, p[1] * unit, 0.0))
            .collect();
        let faces: Vec<Vec<usize>> = pattern
            .faces
            .iter()
            .map(|face| {
                let area: f64 = (0..face.len())
                    .map(|k| {
                        let (a, b) = (flat[face[k]], flat[face[(k + 1) % face.len()]]);
                        a.x * b.y - a.y * b.x
                    })
                    .sum();
                let mut face = face.clone();
                if area < 0.0 {
                    face.reverse();
                }
                face
            })
            .collect();
        let face_panel: Vec<usize> = (0..faces.len()).map(|f| pattern.panel_of_face[f]).collect();
        let mut hinged = std::collections::HashSet::new();
        for &e in &pattern.creases {
            if let [Some(l), Some(r)] = pattern.edge_faces[e] {
                let (a, b) = (face_panel[l], face_panel[r]);
                hinged.insert((a.min(b), a.max(b)));
            }
        }
        let mut features = Vec::new();
        let edges = |f: usize| {
            let loop_ = &faces[f];
            (0..loop_.len())
                .map(|k| [loop_[k], loop_[(k + 1) % loop_.len()]])
                .collect::<Vec<_>>()
        };
        for f in 0..faces.len() {
            for g in 0..faces.len() {
                let (p, q) = (face_panel[f], face_panel[g]);
                if p == q || hinged.contains(&(p.min(q), p.max(q))) || !keep(f, g) {
                    continue;
                }
                // Corners of f on g, both ways round (g's on f come with the pair (g, f)).
                let loop_ = &faces[f];
                for (k, &vertex) in loop_.iter().enumerate() {
                    let copy = faces[g].iter().copied().find(|&w| copies[w] == copies[vertex]);
                    if copy != Some(vertex) {
                        features.push(Feature::CornerOnFace {
                            face: f,
                            vertex,
                            other: g,
                            copy,
                        });
                    }
                    match copy {
                        None => {}
                        Some(apex) => {
                            for far in [loop_[(k + 1) % loop_.len()], loop_[(k + loop_.len() - 1) % loop_.len()]] {
                                features.push(Feature::EdgeOnCorner {
                                    face: f,
                                    corner: vertex,
                                    far,
                                    other: g,
                                    apex,
                                });
                            }
                        }
                    }
                }
                for edge in edges(f) {
                    let copy = |v: usize| faces[g].iter().copied().find(|&w| copies[w] == copies[v] && w != v);
                    if let (Some(a), Some(b)) = (copy(edge[0]), copy(edge[1])) {
                        features.push(Feature::EdgeMiddleOnFace {
                            face: f,
                            edge,
                            other: g,
                            copies: [a, b],
                        });
                    }
                }
                if f < g {
                    for edge in edges(f) {
                        for other_edge in edges(g) {
                            if edge.iter().any(|v| other_edge.contains(v)) {
                                continue;
                            }
                            let copy = edge
                                .iter()
                                .find_map(|&v| other_edge.iter().find(|&&w| copies[w] == copies[v]).map(|&w| [v, w]));
                            features.push(Feature::EdgeOnEdge {
                                face: f,
                                edge,
                                other: g,
                                other_edge,
                                copy,
                            });
                        }
                    }
                }
            }
        }
        let paths = (0..model.panels()).map(|p| model.path_columns(p).collect()).collect();
        let mut pairs: Vec<[usize; 2]> = Vec::new();
        let mut pair_features: Vec<Vec<usize>> = Vec::new();
        for (k, feature) in features.iter().enumerate() {
            let [f, g] = feature.faces();
            let pair = [f.min(g), f.max(g)];
            match pairs.iter().position(|&p| p == pair) {
                Some(i) => pair_features[i].push(k),
                None => {
                    pairs.push(pair);
                    pair_features.push(vec![k]);
                }
            }
        }
        let mut feature_pair = vec![0; features.len()];
        for (i, members) in pair_features.iter().enumerate() {
            for &k in members {
                feature_pair[k] = i;
            }
        }
        let bounds = faces
            .iter()
            .map(|face| {
                let centre = face.iter().map(|&v| flat[v]).sum::<Vector3<f64>>() / face.len() as f64;
                let radius = face.iter().map(|&v| (flat[v] - centre).norm()).fold(0.0, f64::max);
                (centre, radius)
            })
            .collect();
        let mut corner_start = vec![0];
        for face in &faces {
            corner_start.push(corner_start.last().copied().unwrap_or(0) + face.len());
        }
        let slot =
            |f: usize, v: usize| corner_start[f] + faces[f].iter().position(|&w| w == v).expect("a corner of the face");
        // A slot no state reads.
        const UNUSED: usize = usize::MAX;
        let slots = features
            .iter()
            .map(|feature| match *feature {
                Feature::CornerOnFace {
                    face,
                    vertex,
                    other,
                    copy,
                } => [
                    slot(face, vertex),
                    copy.map_or(UNUSED, |w| slot(other, w)),
                    UNUSED,
                    UNUSED,
                    UNUSED,
                    UNUSED,
                ],
                Feature::EdgeMiddleOnFace {
                    face,
                    edge,
                    other,
                    copies,
                } => [
                    slot(face, edge[0]),
                    slot(face, edge[1]),
                    slot(other, copies[0]),
                    slot(other, copies[1]),
                    UNUSED,
                    UNUSED,
                ],
                Feature::EdgeOnCorner {
                    face,
                    corner,
                    far,
                    other,
                    apex,
                } => {
                    let loop_ = &faces[other];
                    let k = loop_.iter().position(|&v| v == apex).expect("a corner of the face");
                    let (next, previous) = (loop_[(k + 1) % loop_.len()], loop_[(k + loop_.len() - 1) % loop_.len()]);
                    [
                        slot(other, apex),
                        slot(face, far),
                        slot(face, corner),
                        slot(other, next),
                        slot(other, previous),
                        UNUSED,
                    ]
                }
                Feature::EdgeOnEdge {
                    face,
                    edge,
                    other,
                    other_edge,
                    copy,
                } => {
                    let [v, w] = copy.map_or([UNUSED; 2], |[v, w]| [slot(face, v), slot(other, w)]);
                    [
                        slot(face, edge[0]),
                        slot(face, edge[1]),
                        slot(other, other_edge[0]),
                        slot(other, other_edge[1]),
                        v,
                        w,
                    ]
                }
            })
            .collect();
        FaceContacts {
            faces,
            face_panel,
            flat,
            features,
            pairs,
            pair_features,
            feature_pair,
            bounds,
            paths,
            corner_start,
            slots,
            size: model.size(),
        }
    }

    /// Face `f`'s corners among the `placed` ones.
    fn corners_of<'p>(&self, placed: &'p PlacedFaces, f: usize) -> &'p [Vector3<f64>] {
        &placed.corners[self.corner_start[f]..self.corner_start[f + 1]]
    }

    /// Where pattern vertex `v` of face `f` is, m.
    pub fn corner(&self, data: &NetworkData, f: usize, v: usize) -> Vector3<f64> {
        data.place(self.face_panel[f], &self.flat[v])
    }

    /// Where flat point `x` of face `f` is, m.
    fn place(&self, data: &NetworkData, f: usize, x: &Vector3<f64>) -> Vector3<f64> {
        data.place(self.face_panel[f], x)
    }

    /// Face `f`'s unit normal (its flat +z carried by its panel).
    pub fn normal(&self, data: &NetworkData, f: usize) -> Vector3<f64> {
        data.rotation[self.face_panel[f]] * Vector3::z()
    }

    /// How far apart pair `pair`'s faces are at least (their bounding spheres' gap), m: a
    /// lower bound on the distance between any two of their points.
    pub fn pair_gap(&self, data: &NetworkData, pair: usize) -> f64 {
        let [f, g] = self.pairs[pair];
        let ((cf, rf), (cg, rg)) = (self.bounds[f], self.bounds[g]);
        (self.place(data, f, &cf) - self.place(data, g, &cg)).norm() - rf - rg
    }

    /// Every face's corners and normal at the poses `data` holds.
    pub fn placed(&self, data: &NetworkData) -> PlacedFaces {
        PlacedFaces {
            corners: (0..self.faces.len())
                .flat_map(|f| self.faces[f].iter().map(move |&v| self.corner(data, f, v)))
                .collect(),
            normals: (0..self.faces.len()).map(|f| self.normal(data, f)).collect(),
        }
    }

    /// Whether pair `pair`'s faces are apart across a plane of one of them: every corner of
    /// the other farther than `tolerance` from it, all on one side. Then no feature of the
    /// pair touches or crosses (a point of one face is in its own plane, every point of the
    /// other beyond the tolerance from it).
    pub fn plane_separated(&self, placed: &PlacedFaces, pair: usize, tolerance: f64) -> bool {
        let [f, g] = self.pairs[pair];
        let apart = |plane: usize, other: usize| {
            let (normal, origin) = (placed.normals[plane], self.corners_of(placed, plane)[0]);
            let mut sides = self.corners_of(placed, other).iter().map(|x| normal.dot(&(x - origin)));
            let first = sides.next().unwrap_or(0.0);
            first.abs() > tolerance && sides.all(|d| d.abs() > tolerance && d.signum() == first.signum())
        };
        apart(f, g) || apart(g, f)
    }

    /// Feature `k` with the faces `placed`.
    pub fn state(&self, placed: &PlacedFaces, k: usize) -> FeatureState {
        let margin = GATE_MARGIN * self.size;
        let slots = &self.slots[k];
        let at = |i: usize| placed.corners[slots[i]];
        match self.features[k] {
            Feature::CornerOnFace { other, copy, .. } => {
                let point = at(0);
                let normal = placed.normals[other];
                let corners = self.corners_of(placed, other);
                let distance = normal.dot(&(point - corners[0]));
                let apart = copy.is_none_or(|_| (at(1) - point).norm() > MET * self.size);
                let over = apart && inside_outline(corners, &normal, &point, margin);
                FeatureState::on_plane(point, normal, distance, over)
            }
            Feature::EdgeMiddleOnFace { other, .. } => {
                let point = (at(0) + at(1)) * 0.5;
                let normal = placed.normals[other];
                let corners = self.corners_of(placed, other);
                let distance = normal.dot(&(point - corners[0]));
                let middle = (at(2) + at(3)) * 0.5;
                let over =
                    (middle - point).norm() > MET * self.size && inside_outline(corners, &normal, &point, margin);
                FeatureState::on_plane(point, normal, distance, over)
            }
            Feature::EdgeOnCorner { other, .. } => {
                let (apex, point) = (at(0), at(1));
                let met = (at(2) - apex).norm() <= MET * self.size;
                let normal = placed.normals[other];
                let distance = normal.dot(&(point - apex));
                let first = at(3) - apex;
                let second = at(4) - apex;
                let within = point - normal * distance - apex;
                let reach = margin * within.norm();
                // Counter-clockwise about the normal from the corner's next edge to its
                // previous one: the face's corner.
                let over = met
                    && first.normalize().cross(&within).dot(&normal) >= reach
                    && within.cross(&second.normalize()).dot(&normal) >= reach;
                FeatureState::on_plane(point, normal, distance, over)
            }
            Feature::EdgeOnEdge { copy, .. } => {
                let (p0, p1) = (at(0), at(1));
                let (q0, q1) = (at(2), at(3));
                let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
                let cross = d1.cross(&d2);
                let (l1, l2) = (d1.norm(), d2.norm());
                if cross.norm() <= PARALLEL_SINE * l1 * l2 {
                    return FeatureState {
                        point: p0,
                        other_point: q0,
                        normal: Vector3::z(),
                        distance: f64::INFINITY,
                        over: false,
                    };
                }
                // Closest points of the two lines: p0 + s d1, q0 + t d2.
                let (a, b, c, d, e) = (d1.dot(&d1), d1.dot(&d2), d2.dot(&d2), d1.dot(&r), d2.dot(&r));
                let denominator = a * c - b * b;
                let s = (b * e - c * d) / denominator;
                let t = (a * e - b * d) / denominator;
                let (point, other_point) = (p0 + d1 * s, q0 + d2 * t);
                // The normal towards the first edge's side: the side is read from the sign
                // of the distance, so its orientation only has to be fixed by the edges.
                let normal = cross.normalize();
                let (ms, mt) = (margin / l1, margin / l2);
                FeatureState {
                    point,
                    other_point,
                    normal,
                    distance: normal.dot(&(point - other_point)),
                    over: s > ms
                        && s < 1.0 - ms
                        && t > mt
                        && t < 1.0 - mt
                        && copy.is_none_or(|_| (at(4) - at(5)).norm() > MET * self.size),
                }
            }
        }
    }

    /// d(distance)/dθ of feature `k` at `state` (poses and twists in `data`): the normal
    /// component of the first face's velocity at the point less the second's.
    pub fn row(&self, data: &NetworkData, k: usize, state: &FeatureState, out: &mut DVector<f64>) {
        self.row_along(data, k, state, &state.normal, out);
    }

    /// The rate of the feature's two points' relative motion along `direction` per fold
    /// angle (m/rad): its gap's row along the normal, its slip's rows across it.
    pub fn row_along(
        &self,
        data: &NetworkData,
        k: usize,
        state: &FeatureState,
        direction: &Vector3<f64>,
        out: &mut DVector<f64>,
    ) {
        out.fill(0.0);
        let [f, g] = self.features[k].faces();
        for (face, point, sign) in [(f, state.point, 1.0), (g, state.other_point, -1.0)] {
            for &c in &self.paths[self.face_panel[face]] {
                out[c] += sign * direction.dot(&data.twist[c].point_velocity(&point));
            }
        }
    }
}
