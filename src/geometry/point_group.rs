//! Finite groups of isometries fixing a point (`docs/model.md#symmetry-group`): a set of
//! orthogonal maps, already closed under composition, recognised as one of the point groups
//! (Schoenflies: Cₙ, Cₙᵥ, Cₙₕ, S₂ₙ, Dₙ, Dₙₕ, Dₙd, T, T_d, T_h, O, O_h, I, I_h), or refused:
//! no other finite group of rotations and reflections exists, so a set that names none of
//! them is not a solid's symmetry group.

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;
use std::f64::consts::PI;

/// A point group: its name, order and rotations.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PointGroup {
    /// Schoenflies symbol, ASCII (`Ih`, `D3h`, `C2v`, `S4`, `Cs`, `Ci`, `C1`).
    pub name: String,
    /// Elements.
    pub order: usize,
    /// Proper rotations among them.
    pub rotations: usize,
}

/// A rotation's order and axis (unit; for the identity, zero).
fn rotation_order_and_axis(r: &Matrix3<f64>, angle_tolerance: f64) -> Option<(usize, Vector3<f64>)> {
    let cos = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let skew = Vector3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]);
    let angle = (skew.norm() / 2.0).atan2(cos);
    if angle < angle_tolerance {
        return Some((1, Vector3::zeros()));
    }
    // The smallest n with n·angle a whole number of turns: a rotation by 2πk/n has order n
    // (orders above 128 belong to no solid nanofold reads: its prisms have at most 64 sides).
    let order = (2..=128).find(|&n| {
        let k = (n as f64 * angle / (2.0 * PI)).round();
        k >= 1.0 && (n as f64 * angle - 2.0 * PI * k).abs() < angle_tolerance * n as f64
    })?;
    let axis = if angle > PI - 1e-6 {
        // R + I = 2 a aᵀ at a half turn: its largest column is along the axis.
        let sym = r + Matrix3::identity();
        let column = (0..3)
            .max_by(|&a, &b| sym.column(a).norm().total_cmp(&sym.column(b).norm()))
            .expect("three columns");
        sym.column(column).normalize()
    } else {
        skew.normalize()
    };
    Some((order, axis))
}

/// Whether two axes are one line (either way).
fn same_axis(a: &Vector3<f64>, b: &Vector3<f64>, tolerance: f64) -> bool {
    a.cross(b).norm() < tolerance
}

/// Names the group of `matrices` (each orthogonal; the set closed under composition, as the
/// caller checked), or None when its rotations form none of Cₙ, Dₙ, T, O, I, or its other
/// elements are not one coset of them. `angle_tolerance` is how far (rad) a rotation may be
/// from an exact turn.
pub fn classify(matrices: &[Matrix3<f64>], angle_tolerance: f64) -> Option<PointGroup> {
    let (proper, improper): (Vec<&Matrix3<f64>>, Vec<&Matrix3<f64>>) =
        matrices.iter().partition(|m| m.determinant() > 0.0);
    let h = proper.len();
    if h == 0 || !(improper.is_empty() || improper.len() == h) {
        return None;
    }
    let rotations: Vec<(usize, Vector3<f64>)> = proper
        .iter()
        .map(|r| rotation_order_and_axis(r, angle_tolerance))
        .collect::<Option<_>>()?;
    if rotations.iter().filter(|(order, _)| *order == 1).count() != 1 {
        return None;
    }
    let count = |n: usize| rotations.iter().filter(|(order, _)| *order == n).count();
    let axes: Vec<&Vector3<f64>> = rotations.iter().filter(|(o, _)| *o > 1).map(|(_, a)| a).collect();
    // A fitted map's axis is off by about its turn's error over the turn's size; distinct
    // axes of a point group are at least π/64 apart for the solids read (D₆₄ₕ).
    let axis_tolerance = (10.0 * angle_tolerance).clamp(1e-6, 1e-2);
    let cyclic = axes.iter().all(|a| same_axis(a, axes[0], axis_tolerance));
    // The rotation group and, for Cₙ and Dₙ, the main axis.
    let (family, n, main_axis) = if h == 1 {
        ("C", 1, Vector3::z())
    } else if cyclic {
        // Cₙ: every order divides n, and a generator of order n.
        if rotations.iter().any(|(o, _)| h % o != 0) || count(h) == 0 {
            return None;
        }
        ("C", h, *axes[0])
    } else if h == 12 && count(3) == 8 && count(2) == 3 {
        ("T", 0, Vector3::zeros())
    } else if h == 24 && count(4) == 6 && count(3) == 8 && count(2) == 9 {
        ("O", 0, Vector3::zeros())
    } else if h == 60 && count(5) == 24 && count(3) == 20 && count(2) == 15 {
        ("I", 0, Vector3::zeros())
    } else if h % 2 == 0 && h >= 4 {
        let n = h / 2;
        // Dₙ: n rotations about one main axis (the identity among them), n half turns
        // about axes perpendicular to it.
        let main = if n == 2 {
            *axes[0]
        } else {
            **axes
                .iter()
                .zip(rotations.iter().filter(|(o, _)| *o > 1))
                .find(|(_, (o, _))| *o == n)?
                .0
        };
        let about_main = rotations
            .iter()
            .filter(|(o, a)| *o == 1 || same_axis(a, &main, axis_tolerance))
            .count();
        let perpendicular = rotations
            .iter()
            .filter(|(o, a)| *o == 2 && a.dot(&main).abs() < axis_tolerance)
            .count();
        let half_turns_off_main = if n == 2 { 2 } else { n };
        if about_main != n || perpendicular < half_turns_off_main {
            return None;
        }
        ("D", n, main)
    } else {
        return None;
    };
    let rotation_name = match family {
        "C" => format!("C{n}"),
        "D" => format!("D{n}"),
        other => other.to_string(),
    };
    if improper.is_empty() {
        return Some(PointGroup {
            name: rotation_name,
            order: h,
            rotations: h,
        });
    }
    // Each improper element is −R for a rotation R: the inversion when R = I, a mirror
    // (normal along R's axis) when R is a half turn.
    let mut inversion = false;
    let mut mirror_normals = Vec::new();
    for m in &improper {
        let (order, axis) = rotation_order_and_axis(&(-**m), angle_tolerance)?;
        match order {
            1 => inversion = true,
            2 => mirror_normals.push(axis),
            _ => {}
        }
    }
    let horizontal_mirror = mirror_normals.iter().any(|a| same_axis(a, &main_axis, axis_tolerance));
    let vertical_mirror = mirror_normals.iter().any(|a| a.dot(&main_axis).abs() < axis_tolerance);
    let name = match family {
        "C" if n == 1 && inversion => "Ci".to_string(),
        "C" if n == 1 => "Cs".to_string(),
        "C" if inversion && n % 2 == 0 => format!("C{n}h"),
        "C" if inversion => format!("S{}", 2 * n),
        "C" if horizontal_mirror => format!("C{n}h"),
        "C" if vertical_mirror => format!("C{n}v"),
        "C" => format!("S{}", 2 * n),
        "D" if n == 2 => {
            // D₂'s three axes are alike: D2h has a mirror normal to one of them.
            if inversion
                || mirror_normals
                    .iter()
                    .any(|m| axes.iter().any(|a| same_axis(m, a, axis_tolerance)))
            {
                "D2h".to_string()
            } else {
                "D2d".to_string()
            }
        }
        "D" if horizontal_mirror => format!("D{n}h"),
        "D" => format!("D{n}d"),
        "T" if inversion => "Th".to_string(),
        "T" => "Td".to_string(),
        "O" => "Oh".to_string(),
        "I" => "Ih".to_string(),
        _ => return None,
    };
    Some(PointGroup {
        name,
        order: 2 * h,
        rotations: h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// The closure of `generators` under multiplication (small groups only).
    fn generate(generators: &[Matrix3<f64>]) -> Vec<Matrix3<f64>> {
        let mut group = vec![Matrix3::identity()];
        let mut k = 0;
        while k < group.len() {
            for g in generators {
                let product = group[k] * g;
                if !group.iter().any(|m| (m - product).norm() < 1e-9) {
                    group.push(product);
                }
            }
            k += 1;
            assert!(group.len() <= 240, "not finite");
        }
        group
    }

    fn turn(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
        *Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).matrix()
    }

    fn mirror(normal: Vector3<f64>) -> Matrix3<f64> {
        let n = normal.normalize();
        Matrix3::identity() - 2.0 * n * n.transpose()
    }

    #[test]
    fn the_point_groups_are_named_from_their_generators() {
        let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
        let c = |n: f64| turn(z, 2.0 * PI / n);
        let half_x = turn(x, PI);
        let cases: Vec<(&str, Vec<Matrix3<f64>>, usize)> = vec![
            ("C1", vec![], 1),
            ("Ci", vec![-Matrix3::identity()], 2),
            ("Cs", vec![mirror(z)], 2),
            ("C5", vec![c(5.0)], 5),
            ("C3v", vec![c(3.0), mirror(x)], 6),
            ("C4h", vec![c(4.0), mirror(z)], 8),
            ("C3h", vec![c(3.0), mirror(z)], 6),
            ("S4", vec![mirror(z) * c(4.0)], 4),
            ("S6", vec![c(3.0), -Matrix3::identity()], 6),
            ("D2", vec![turn(z, PI), half_x], 4),
            ("D6", vec![c(6.0), half_x], 12),
            ("D2h", vec![turn(z, PI), half_x, -Matrix3::identity()], 8),
            ("D5h", vec![c(5.0), half_x, mirror(z)], 20),
            ("D3d", vec![c(3.0), half_x, -Matrix3::identity()], 12),
            ("D2d", vec![turn(z, PI), half_x, mirror(x + y)], 8),
            ("T", vec![turn(x + y + z, 2.0 * PI / 3.0), turn(z, PI)], 12),
            (
                "Td",
                vec![turn(x + y + z, 2.0 * PI / 3.0), turn(z, PI), mirror(x - y)],
                24,
            ),
            (
                "Th",
                vec![turn(x + y + z, 2.0 * PI / 3.0), turn(z, PI), -Matrix3::identity()],
                24,
            ),
            ("O", vec![turn(x + y + z, 2.0 * PI / 3.0), c(4.0)], 24),
            (
                "Oh",
                vec![turn(x + y + z, 2.0 * PI / 3.0), c(4.0), -Matrix3::identity()],
                48,
            ),
        ];
        for (name, generators, order) in cases {
            let group = generate(&generators);
            assert_eq!(group.len(), order, "{name}");
            let found = classify(&group, 1e-9).unwrap_or_else(|| panic!("{name} not recognised"));
            assert_eq!((found.name.as_str(), found.order), (name, order));
        }
        // The icosahedral group from a five-fold and a three-fold axis of an icosahedron.
        let phi = (1.0 + 5f64.sqrt()) / 2.0;
        let five = turn(Vector3::new(0.0, 1.0, phi), 2.0 * PI / 5.0);
        let three = turn(Vector3::new(1.0, 1.0, 1.0), 2.0 * PI / 3.0);
        let icosahedral = generate(&[five, three]);
        assert_eq!(classify(&icosahedral, 1e-9).unwrap().name, "I");
        let full = generate(&[five, three, -Matrix3::identity()]);
        assert_eq!(
            classify(&full, 1e-9).unwrap(),
            PointGroup {
                name: "Ih".into(),
                order: 120,
                rotations: 60
            }
        );
    }

    #[test]
    fn sets_that_are_no_point_group_are_refused() {
        let z = Vector3::z();
        // Rotations about two axes at an angle no finite group has.
        let odd = vec![Matrix3::identity(), turn(z, PI), turn(Vector3::new(1.0, 0.0, 0.3), PI)];
        assert!(classify(&odd, 1e-9).is_none());
        // A turn by an angle of no finite order.
        assert!(classify(&[Matrix3::identity(), turn(z, 1.0)], 1e-9).is_none());
        // Reflections that are not one coset of the rotations.
        assert!(classify(&[Matrix3::identity(), mirror(z), mirror(Vector3::x())], 1e-9).is_none());
    }
}
