//! How far apart two convex plates (flat convex polygons) are, by the separating axis test
//! (`docs/model.md#contact-forces`): the largest gap between their shadows on the axes that
//! can separate two convex polygons in space (either plane's normal, either outline's
//! in-plane edge normals, and the cross products of an edge of each). Positive: apart by at
//! least that much; zero: touching (an edge on the other face, a shared corner); negative:
//! they cross, and its size is the shortest shift along those axes that parts them. One
//! number per pair, whatever part of the plates meets.

use nalgebra::Vector3;

/// Axes shorter than this (a fraction of the product of the edges' lengths) are left out:
/// parallel edges have no cross axis.
const DEGENERATE: f64 = 1e-12;

/// Which axis separates best.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeparatingAxis {
    /// The first plate's normal.
    NormalOfFirst,
    /// The second plate's normal.
    NormalOfSecond,
    /// The in-plane normal of the first plate's edge k (from corner k to k + 1).
    EdgeOfFirst(usize),
    /// The in-plane normal of the second plate's edge k.
    EdgeOfSecond(usize),
    /// The cross product of the first plate's edge i and the second's edge j.
    Edges(usize, usize),
}

/// Two plates' separation.
#[derive(Debug, Clone, Copy)]
pub struct Separation {
    /// The largest gap between the shadows, in the corners' units (negative: crossing).
    pub gap: f64,
    /// The axis it is on, unit, pointing from the first plate towards the second.
    pub axis: Vector3<f64>,
    /// Which axis that is.
    pub kind: SeparatingAxis,
}

/// The separation of convex plates `first` and `second` (corners in order around each).
pub fn plate_separation(first: &[Vector3<f64>], second: &[Vector3<f64>]) -> Separation {
    let normal = |p: &[Vector3<f64>]| {
        (0..p.len())
            .map(|k| p[k].cross(&p[(k + 1) % p.len()]))
            .sum::<Vector3<f64>>()
            .normalize()
    };
    let (na, nb) = (normal(first), normal(second));
    let edge = |p: &[Vector3<f64>], k: usize| p[(k + 1) % p.len()] - p[k];
    let mut best = Separation {
        gap: f64::NEG_INFINITY,
        axis: na,
        kind: SeparatingAxis::NormalOfFirst,
    };
    let mut try_axis = |axis: Vector3<f64>, kind: SeparatingAxis| {
        let shadow = |p: &[Vector3<f64>]| {
            p.iter()
                .map(|x| axis.dot(x))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| (lo.min(s), hi.max(s)))
        };
        let ((a_lo, a_hi), (b_lo, b_hi)) = (shadow(first), shadow(second));
        let (forward, backward) = (b_lo - a_hi, a_lo - b_hi);
        let (gap, axis) = if forward >= backward {
            (forward, axis)
        } else {
            (backward, -axis)
        };
        if gap > best.gap {
            best = Separation { gap, axis, kind };
        }
    };
    try_axis(na, SeparatingAxis::NormalOfFirst);
    try_axis(nb, SeparatingAxis::NormalOfSecond);
    for k in 0..first.len() {
        try_axis(na.cross(&edge(first, k)).normalize(), SeparatingAxis::EdgeOfFirst(k));
    }
    for k in 0..second.len() {
        try_axis(nb.cross(&edge(second, k)).normalize(), SeparatingAxis::EdgeOfSecond(k));
    }
    for i in 0..first.len() {
        for j in 0..second.len() {
            let (e, f) = (edge(first, i), edge(second, j));
            let cross = e.cross(&f);
            if cross.norm() > DEGENERATE * e.norm() * f.norm() {
                try_axis(cross.normalize(), SeparatingAxis::Edges(i, j));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(centre: Vector3<f64>, u: Vector3<f64>, v: Vector3<f64>) -> Vec<Vector3<f64>> {
        vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v]
    }

    /// The closest distance between two plates, by sampling both densely (a bound from
    /// above on the true distance, within the sampling's spacing).
    fn sampled_distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
        let points = |p: &[Vector3<f64>]| {
            let mut out = Vec::new();
            let n = 40;
            for i in 0..=n {
                for j in 0..=n {
                    let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                    // Bilinear over the quad's corners.
                    out.push(
                        p[0] * ((1.0 - s) * (1.0 - t))
                            + p[1] * (s * (1.0 - t))
                            + p[2] * (s * t)
                            + p[3] * ((1.0 - s) * t),
                    );
                }
            }
            out
        };
        let (pa, pb) = (points(a), points(b));
        pa.iter()
            .flat_map(|x| pb.iter().map(move |y| (x - y).norm()))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn plates_apart_touching_and_crossing_are_told_apart() {
        let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
        let floor = square(Vector3::zeros(), x, y);
        // A wall standing 0.5 above the floor's plane over its middle: apart by 0.5.
        let above = square(Vector3::new(0.0, 0.0, 1.5), x, z);
        let s = plate_separation(&floor, &above);
        assert!((s.gap - 0.5).abs() <= 1e-12, "{s:?}");
        // Standing on it: touching.
        let on = square(Vector3::new(0.0, 0.0, 1.0), x, z);
        assert!(plate_separation(&floor, &on).gap.abs() <= 1e-12);
        // Pushed 0.25 through it: crossing by 0.25 (the shortest shift that parts them).
        let through = square(Vector3::new(0.0, 0.0, 0.75), x, z);
        let s = plate_separation(&floor, &through);
        assert!((s.gap + 0.25).abs() <= 1e-12, "{s:?}");
        // Beside it, past its edge, at the same height: apart by 1 in the plane.
        let beside = square(Vector3::new(0.0, 3.0, 0.0), x, y);
        assert!((plate_separation(&floor, &beside).gap - 1.0).abs() <= 1e-12);
        // Sharing a corner only: touching.
        let corner = square(Vector3::new(2.0, 1.0, 1.0), x, z);
        assert!(plate_separation(&floor, &corner).gap.abs() <= 1e-12);
    }

    #[test]
    fn a_positive_gap_never_exceeds_the_distance_and_crossing_plates_are_negative() {
        // Seeded pseudo-random tilted squares.
        let mut state = 12345_u64;
        let mut random = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut apart = 0;
        let mut crossing = 0;
        for _ in 0..300 {
            let mut plate = || {
                let centre = Vector3::new(random(), random(), random()) * 1.5;
                let u = Vector3::new(random(), random(), random()).normalize();
                let w = Vector3::new(random(), random(), random());
                let v = (w - u * u.dot(&w)).normalize();
                square(centre, u * 0.8, v * 0.6)
            };
            let (a, b) = (plate(), plate());
            let s = plate_separation(&a, &b);
            let distance = sampled_distance(&a, &b);
            if s.gap > 0.0 {
                apart += 1;
                // SAT's gap is a lower bound on the distance (the sampling adds at most
                // its spacing's diagonal).
                assert!(s.gap <= distance + 1e-12, "{} against {distance}", s.gap);
            } else if s.gap < -1e-9 {
                crossing += 1;
                // Crossing plates share points: the sampling finds them within its spacing.
                assert!(distance <= 0.06, "gap {} but sampled distance {distance}", s.gap);
            }
        }
        assert!(apart > 50 && crossing > 20, "{apart} apart, {crossing} crossing");
    }
}
