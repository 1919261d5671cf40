//! Generated solids (`docs/model.md#nets-of-polyhedra`): the five Platonic solids, prisms,
//! antiprisms and pyramids of n sides, boxes a × b × c and the Archimedean solids a net
//! designer meets first (truncated tetrahedron, cuboctahedron, truncated octahedron), each
//! the convex hull of its vertices.

use super::polyhedron::{Polyhedron, MAX_SIDES};
use crate::error::{NanofoldError, Result};
use nalgebra::{Point3, Vector3};
use std::f64::consts::TAU;

/// The golden ratio.
const PHI: f64 = 1.618_033_988_749_895;

/// The convex hull's faces, each a maximal set of coplanar vertices wound counter-clockwise
/// seen from outside (brute force over vertex triples: for the generated solids' few dozen
/// vertices).
pub fn convex_hull(vertices: Vec<Point3<f64>>) -> Result<Polyhedron> {
    let n = vertices.len();
    if let Some(k) = vertices.iter().position(|p| !p.coords.iter().all(|x| x.is_finite())) {
        return Err(NanofoldError::invalid(
            format!("vertices[{k}]"),
            format!("{:?}", vertices[k].coords.as_slice()),
            "coordinates must be finite",
        ));
    }
    let centre = Point3::from(vertices.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n as f64);
    let size = vertices.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    let tolerance = 1e-9 * size;
    let mut faces: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let normal = (vertices[j] - vertices[i]).cross(&(vertices[k] - vertices[i]));
                if normal.norm() <= 1e-12 * size * size {
                    continue;
                }
                let mut unit = normal.normalize();
                let side = |p: &Point3<f64>, u: &Vector3<f64>| (p - vertices[i]).dot(u);
                if vertices.iter().any(|p| side(p, &unit) > tolerance) {
                    unit = -unit;
                    if vertices.iter().any(|p| side(p, &unit) > tolerance) {
                        continue;
                    }
                }
                let mut on: Vec<usize> = (0..n)
                    .filter(|&v| side(&vertices[v], &unit).abs() <= tolerance)
                    .collect();
                if on.len() < 3 {
                    continue; // not a plane through three vertices (rounding at a degenerate triple)
                }
                on.sort_unstable();
                if faces.iter().any(|f| {
                    let mut sorted = f.clone();
                    sorted.sort_unstable();
                    sorted == on
                }) {
                    continue;
                }
                // Counter-clockwise about the outward normal.
                let middle = on.iter().fold(Vector3::zeros(), |s, &v| s + vertices[v].coords) / on.len() as f64;
                let x = (vertices[on[0]].coords - middle).normalize();
                let y = unit.cross(&x);
                on.sort_by(|&a, &b| {
                    let angle = |v: usize| {
                        let d = vertices[v].coords - middle;
                        d.dot(&y).atan2(d.dot(&x))
                    };
                    angle(a).total_cmp(&angle(b))
                });
                faces.push(on);
            }
        }
    }
    Polyhedron::new(vertices, faces)
}

fn points(coordinates: &[[f64; 3]]) -> Vec<Point3<f64>> {
    coordinates.iter().map(|&[x, y, z]| Point3::new(x, y, z)).collect()
}

/// Every sign combination of the non-zero coordinates of each point, and its cyclic shifts
/// if `cyclic` (the way the Platonic and Archimedean solids' coordinates are given).
fn signed(generators: &[[f64; 3]], cyclic: bool) -> Vec<Point3<f64>> {
    let mut out: Vec<Point3<f64>> = Vec::new();
    for g in generators {
        let shifts = if cyclic { 3 } else { 1 };
        for shift in 0..shifts {
            let p = [g[shift % 3], g[(shift + 1) % 3], g[(shift + 2) % 3]];
            for signs in 0..8 {
                let q: Vec<f64> = (0..3).map(|k| if signs >> k & 1 == 1 { -p[k] } else { p[k] }).collect();
                let point = Point3::new(q[0], q[1], q[2]);
                if !out.iter().any(|o| (o - point).norm() < 1e-12) {
                    out.push(point);
                }
            }
        }
    }
    out
}

/// The regular tetrahedron.
pub fn tetrahedron() -> Result<Polyhedron> {
    convex_hull(points(&[
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ]))
}

/// The cube of side 2.
pub fn cube() -> Result<Polyhedron> {
    convex_hull(signed(&[[1.0, 1.0, 1.0]], false))
}

/// The regular octahedron.
pub fn octahedron() -> Result<Polyhedron> {
    convex_hull(signed(&[[1.0, 0.0, 0.0]], true))
}

/// The regular dodecahedron.
pub fn dodecahedron() -> Result<Polyhedron> {
    convex_hull(signed(&[[1.0, 1.0, 1.0], [0.0, 1.0 / PHI, PHI]], true))
}

/// The regular icosahedron.
pub fn icosahedron() -> Result<Polyhedron> {
    convex_hull(signed(&[[0.0, 1.0, PHI]], true))
}

/// The truncated tetrahedron (4 triangles, 4 hexagons).
pub fn truncated_tetrahedron() -> Result<Polyhedron> {
    // The permutations of (3, 1, 1) with an even number of minus signs.
    let vertices = signed(&[[3.0, 1.0, 1.0], [1.0, 3.0, 1.0], [1.0, 1.0, 3.0]], false)
        .into_iter()
        .filter(|p| p.coords.iter().filter(|x| **x < 0.0).count() % 2 == 0)
        .collect();
    convex_hull(vertices)
}

/// The cuboctahedron (8 triangles, 6 squares).
pub fn cuboctahedron() -> Result<Polyhedron> {
    convex_hull(signed(&[[1.0, 1.0, 0.0]], true))
}

/// The truncated octahedron (6 squares, 8 hexagons).
pub fn truncated_octahedron() -> Result<Polyhedron> {
    convex_hull(signed(&[[0.0, 1.0, 2.0], [0.0, 2.0, 1.0]], true))
}

/// A box a × b × c.
pub fn cuboid(a: f64, b: f64, c: f64) -> Result<Polyhedron> {
    for (name, x) in [("a", a), ("b", b), ("c", c)] {
        if !(x.is_finite() && x > 0.0 && x <= 1e6) {
            return Err(NanofoldError::invalid(name, x, "a box's sides are > 0 and at most 1e6"));
        }
    }
    // The solid's tolerances are 1e-9 of its size: its shortest side must stand well clear.
    let (shortest, longest) = (a.min(b).min(c), a.max(b).max(c));
    if longest > 1e6 * shortest {
        return Err(NanofoldError::invalid(
            "a, b, c",
            format!("{a} x {b} x {c}"),
            "the longest side is at most 1e6 times the shortest",
        ));
    }
    convex_hull(signed(&[[a / 2.0, b / 2.0, c / 2.0]], false))
}

fn sides(n: usize) -> Result<()> {
    if (3..=MAX_SIDES).contains(&n) {
        Ok(())
    } else {
        Err(NanofoldError::invalid("sides", n, format!("3 to {MAX_SIDES}")))
    }
}

fn ring(n: usize, z: f64, turn: f64) -> impl Iterator<Item = Point3<f64>> {
    (0..n).map(move |k| {
        let angle = TAU * (k as f64 + turn) / n as f64;
        Point3::new(angle.cos(), angle.sin(), z)
    })
}

/// The right prism over a regular n-gon of circumradius 1, of height `height`.
pub fn prism(n: usize, height: f64) -> Result<Polyhedron> {
    sides(n)?;
    positive("height", height)?;
    convex_hull(ring(n, -height / 2.0, 0.0).chain(ring(n, height / 2.0, 0.0)).collect())
}

/// The antiprism over a regular n-gon of circumradius 1, of height `height`.
pub fn antiprism(n: usize, height: f64) -> Result<Polyhedron> {
    sides(n)?;
    positive("height", height)?;
    convex_hull(ring(n, -height / 2.0, 0.0).chain(ring(n, height / 2.0, 0.5)).collect())
}

/// The right pyramid over a regular n-gon of circumradius 1, of height `height`.
pub fn pyramid(n: usize, height: f64) -> Result<Polyhedron> {
    sides(n)?;
    positive("height", height)?;
    convex_hull(ring(n, 0.0, 0.0).chain([Point3::new(0.0, 0.0, height)]).collect())
}

fn positive(name: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 && x <= 1e6 {
        Ok(())
    } else {
        Err(NanofoldError::invalid(name, x, "must be > 0 and at most 1e6"))
    }
}

/// Most unit cubes of a polycube.
pub const MAX_CUBES: usize = 1_000;

/// The surface of a polycube: unit cubes at integer positions, each square of the surface
/// its own face (coplanar neighbours stay separate faces, as the net's panels are). Refused:
/// a repeated or far cube, cubes in more than one piece, and cubes that touch only along an
/// edge or at a corner (the surface would not be a manifold there).
pub fn polycube(cubes: &[[i64; 3]]) -> Result<Polyhedron> {
    use std::collections::{HashMap, HashSet};
    if cubes.is_empty() || cubes.len() > MAX_CUBES {
        return Err(NanofoldError::invalid(
            "cubes",
            cubes.len(),
            format!("1 to {MAX_CUBES} unit cubes"),
        ));
    }
    let mut filled = HashSet::new();
    for (k, c) in cubes.iter().enumerate() {
        if c.iter().any(|x| x.abs() > 1_000_000) {
            return Err(NanofoldError::invalid(
                format!("cubes[{k}]"),
                format!("{c:?}"),
                "positions within ±1e6",
            ));
        }
        if !filled.insert(*c) {
            return Err(NanofoldError::invalid(
                format!("cubes[{k}]"),
                format!("{c:?}"),
                "a cube repeats",
            ));
        }
    }
    // Cubes that share an edge or a corner but not a face with a common neighbour pinch the
    // surface; checked on the surface itself by Polyhedron::new's edge rule and a vertex-fan
    // count below.
    let mut index: HashMap<[i64; 3], usize> = HashMap::new();
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    let mut vertex = |p: [i64; 3], vertices: &mut Vec<Point3<f64>>| {
        *index.entry(p).or_insert_with(|| {
            vertices.push(Point3::new(p[0] as f64, p[1] as f64, p[2] as f64));
            vertices.len() - 1
        })
    };
    for c in cubes {
        for axis in 0..3 {
            for side in [0i64, 1] {
                let mut neighbour = *c;
                neighbour[axis] += 2 * side - 1;
                if filled.contains(&neighbour) {
                    continue;
                }
                // The square at c[axis] + side, its corners counter-clockwise seen from
                // outside (along +axis when side is 1, −axis when 0).
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let corner = |du: i64, dv: i64| {
                    let mut p = *c;
                    p[axis] += side;
                    p[u] += du;
                    p[v] += dv;
                    p
                };
                let mut square = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                if side == 0 {
                    square.reverse();
                }
                faces.push(square.iter().map(|&p| vertex(p, &mut vertices)).collect::<Vec<_>>());
            }
        }
    }
    let solid = Polyhedron::new(vertices, faces)?;
    // Each vertex's faces must form one fan (one cycle around it), or the cubes meet at a
    // point only there.
    for v in 0..solid.vertices.len() {
        let around: Vec<usize> = (0..solid.faces.len())
            .filter(|&f| solid.faces[f].contains(&v))
            .collect();
        let mut next: HashMap<usize, usize> = HashMap::new();
        for &f in &around {
            let face = &solid.faces[f];
            let k = face.iter().position(|&w| w == v).expect("around v");
            // The edge leaving v in this face, and the one entering it: faces chain by them.
            next.insert(face[(k + face.len() - 1) % face.len()], face[(k + 1) % face.len()]);
        }
        let start = *next.keys().next().expect("a vertex has faces");
        let (mut at, mut steps) = (start, 0);
        loop {
            at = next[&at];
            steps += 1;
            if at == start || steps > around.len() {
                break;
            }
        }
        if steps != around.len() {
            return Err(NanofoldError::invalid(
                "cubes",
                format!("corner {:?}", solid.vertices[v].coords.as_slice()),
                "cubes meet only at this corner or along an edge through it: the surface is pinched there",
            ));
        }
    }
    Ok(solid)
}
