//! Whether a closed surface passes through itself (`docs/model.md#nets-of-polyhedra`): its
//! convex faces tested in pairs, each pair along the line where their planes meet.

use super::broad_phase::overlapping_pairs;
use nalgebra::{Point3, Vector3};

/// The interval of the line (origin + s·direction) that a convex face covers, or None when
/// the face does not reach the line's plane `normal · x = offset` (within `tolerance`).
fn cut(
    points: &[Point3<f64>],
    (normal, offset): (&Vector3<f64>, f64),
    (origin, direction): (&Point3<f64>, &Vector3<f64>),
    tolerance: f64,
) -> Option<(f64, f64)> {
    let distance: Vec<f64> = points.iter().map(|p| normal.dot(&p.coords) - offset).collect();
    if distance.iter().all(|&d| d > tolerance) || distance.iter().all(|&d| d < -tolerance) {
        return None;
    }
    let along = |p: Point3<f64>| (p - origin).dot(direction);
    let mut interval = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |s: f64| interval = (interval.0.min(s), interval.1.max(s));
    for k in 0..points.len() {
        let (a, b) = (points[k], points[(k + 1) % points.len()]);
        let (da, db) = (distance[k], distance[(k + 1) % points.len()]);
        if da.abs() <= tolerance {
            take(along(a));
        }
        if (da > tolerance && db < -tolerance) || (da < -tolerance && db > tolerance) {
            take(along(a + (b - a) * (da / (da - db))));
        }
    }
    (interval.0 <= interval.1).then_some(interval)
}

/// A polygon's area vector (Newell): its normal, as long as twice its area; `corner(k)` is
/// its k-th of `count` corners.
pub fn newell_normal(count: usize, corner: impl Fn(usize) -> Point3<f64>) -> Vector3<f64> {
    (0..count).fold(Vector3::zeros(), |n, k| {
        n + corner(k).coords.cross(&corner((k + 1) % count).coords)
    })
}

/// The first pair of faces (f < g) of the surface (`vertices`, `faces`) whose interiors
/// meet: faces that share an edge or a corner may touch there, nowhere else. Faces must be
/// planar and convex. `tolerance` is a length.
pub fn first_self_intersection(
    vertices: &[Point3<f64>],
    faces: &[Vec<usize>],
    tolerance: f64,
) -> Option<(usize, usize)> {
    let corners: Vec<Vec<Point3<f64>>> = faces
        .iter()
        .map(|face| face.iter().map(|&v| vertices[v]).collect())
        .collect();
    let boxes: Vec<([f64; 3], [f64; 3])> = corners
        .iter()
        .map(|points| {
            let mut bounds = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in points {
                for i in 0..3 {
                    bounds.0[i] = bounds.0[i].min(p[i] - tolerance);
                    bounds.1[i] = bounds.1[i].max(p[i] + tolerance);
                }
            }
            bounds
        })
        .collect();
    let planes: Vec<(Vector3<f64>, f64)> = corners
        .iter()
        .map(|points| {
            let normal = newell_normal(points.len(), |k| points[k]).normalize();
            let centre = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64;
            (normal, normal.dot(&centre))
        })
        .collect();
    overlapping_pairs(&boxes).into_iter().find(|&(f, g)| {
        let shared = faces[f].iter().filter(|v| faces[g].contains(v)).count();
        faces_meet((&corners[f], &planes[f]), (&corners[g], &planes[g]), shared, tolerance).is_some()
    })
}

/// Where two convex, planar faces' interiors meet (a point of both), or None when they
/// only touch: at up to `shared` corners they have in common (two: an edge), as faces of
/// one surface do. `tolerance` is a length.
pub fn convex_faces_meet(a: &[Point3<f64>], b: &[Point3<f64>], shared: usize, tolerance: f64) -> Option<Point3<f64>> {
    let plane = |points: &[Point3<f64>]| {
        let normal = newell_normal(points.len(), |k| points[k]).normalize();
        let centre = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64;
        (normal, normal.dot(&centre))
    };
    faces_meet((a, &plane(a)), (b, &plane(b)), shared, tolerance)
}

/// Where two convex faces' interiors meet, `shared` the corners they have in common.
fn faces_meet(
    (a, plane_a): (&[Point3<f64>], &(Vector3<f64>, f64)),
    (b, plane_b): (&[Point3<f64>], &(Vector3<f64>, f64)),
    shared: usize,
    tolerance: f64,
) -> Option<Point3<f64>> {
    let direction = plane_a.0.cross(&plane_b.0);
    // Planes at an angle that moves no corner by more than the tolerance are one plane (the
    // faces of a rounded file that lie in one plane are at such angles).
    let centre = a.iter().chain(b).fold(Vector3::zeros(), |s, p| s + p.coords) / (a.len() + b.len()) as f64;
    let extent = a
        .iter()
        .chain(b)
        .map(|p| (p.coords - centre).norm())
        .fold(0.0, f64::max);
    if direction.norm() < 1e-9 || direction.norm() * extent <= tolerance {
        // Parallel planes: apart, or one plane, where the faces meet if their outlines
        // overlap with area (faces glued back to back, or folded flat onto each other).
        if (plane_a.1 - plane_a.0.dot(&plane_b.0) * plane_b.1).abs() > tolerance {
            return None;
        }
        let mean =
            |points: &[Point3<f64>]| points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64;
        return coplanar_overlap(a, b, &plane_a.0, tolerance).then(|| Point3::from((mean(a) + mean(b)) / 2.0));
    }
    if shared >= 2 {
        // Two faces on one edge, at an angle: they meet only along it.
        return None;
    }
    let direction = direction.normalize();
    // A point on both planes: the least-norm solution of the two plane equations.
    let (n1, n2) = (&plane_a.0, &plane_b.0);
    let c = n1.dot(n2);
    let det = 1.0 - c * c;
    let origin = Point3::from((n1 * (plane_a.1 - c * plane_b.1) + n2 * (plane_b.1 - c * plane_a.1)) / det);
    let line = (&origin, &direction);
    let (on_a, on_b) = (
        cut(a, (&plane_b.0, plane_b.1), line, tolerance)?,
        cut(b, (&plane_a.0, plane_a.1), line, tolerance)?,
    );
    let (from, to) = (on_a.0.max(on_b.0), on_a.1.min(on_b.1));
    // A shared corner is a point both intervals hold: meeting there alone is touching.
    let meets = if shared == 1 {
        to - from > tolerance
    } else {
        to - from >= -tolerance
    };
    meets.then(|| origin + direction * (0.5 * (from + to)))
}

/// Whether two convex polygons in one plane (normal `normal`) overlap with area: separating
/// axes in the plane.
fn coplanar_overlap(a: &[Point3<f64>], b: &[Point3<f64>], normal: &Vector3<f64>, tolerance: f64) -> bool {
    for polygon in [a, b] {
        for k in 0..polygon.len() {
            let edge = polygon[(k + 1) % polygon.len()] - polygon[k];
            let axis = normal.cross(&edge);
            if axis.norm() == 0.0 {
                continue;
            }
            let axis = axis.normalize();
            let span = |points: &[Point3<f64>]| {
                points
                    .iter()
                    .map(|p| p.coords.dot(&axis))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
            };
            let ((a0, a1), (b0, b1)) = (span(a), span(b));
            if a1.min(b1) - a0.max(b0) <= tolerance {
                return false;
            }
        }
    }
    true
}
