//! The second-order test at flat (`folding::second_order`, `docs/model.md#second-order-at-flat`):
//! it never excludes the signs of a real motion (exact closures of small folds of random
//! vertices), it excludes every all-valley vertex (a vertex cannot fold with one sign: its
//! folded image would be a convex spherical polygon of perimeter 2π), it leaves low degrees
//! to the one-sign rule, its exclusions agree with the witness search, and it decides
//! lattices of degree-6 vertices that were `unknown`.

use nanofold::folding::{check_pattern, CheckSettings, FoldingModel, PatternVerdict, Star};
use nanofold::folding::{cone_range, quadratic_form, second_order, SecondOrder};
use nanofold::geometry::kinematics::solve_closure;
use nanofold::read::parse_crease_pattern;
use serde_json::json;
use std::f64::consts::TAU;

fn star(sectors: &[f64]) -> Star {
    Star {
        vertex: 0,
        columns: (0..sectors.len()).collect(),
        sector_angles: sectors.to_vec(),
    }
}

/// A deterministic sequence in [0, 1).
struct Draws(u64);
impl Draws {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// n sector angles summing to 2π, each at least 0.25 rad.
fn sectors(n: usize, draws: &mut Draws) -> Vec<f64> {
    let weights: Vec<f64> = (0..n).map(|_| 0.3 + draws.next()).collect();
    let total: f64 = weights.iter().sum();
    weights.iter().map(|w| w / total * TAU).collect()
}

fn q(m: &nalgebra::DMatrix<f64>, a: &[f64]) -> f64 {
    let v = nalgebra::DVector::from_column_slice(a);
    (v.transpose() * m * &v)[(0, 0)]
}

#[test]
fn the_signs_of_real_motions_are_never_excluded() {
    let mut draws = Draws(7);
    let mut tested = 0;
    for n in 5..=8 {
        for _ in 0..40 {
            let sector_angles = sectors(n, &mut draws);
            let eps = 1e-4;
            // Drive n − 3 creases by small amounts; Newton closes the vertex with the rest.
            let mut rho: Vec<f64> = (0..n)
                .map(|i| {
                    if i < n - 3 {
                        eps * (2.0 * draws.next() - 1.0)
                    } else {
                        0.0
                    }
                })
                .collect();
            let free: Vec<usize> = (n - 3..n).collect();
            if solve_closure(&sector_angles, &mut rho, &free, 1e-16, 60).is_err() {
                continue;
            }
            let size = rho.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
            let residual = nanofold::geometry::kinematics::closure_residual(&sector_angles, &rho);
            // A closed state near flat on a branch through flat, every crease folded.
            if residual > 1e-14 || size > 20.0 * eps || rho.iter().any(|r| r.abs() < 1e-3 * eps) {
                continue;
            }
            // Its direction satisfies the second order: Q(ρ/|ρ|) is of the order of |ρ|.
            let a: Vec<f64> = rho.iter().map(|r| r / size).collect();
            let form = quadratic_form(&sector_angles);
            assert!(q(&form, &a).abs() < 50.0 * size, "Q = {} at |ρ| = {size}", q(&form, &a));
            let signs: Vec<f64> = rho.iter().map(|r| r.signum()).collect();
            let found = second_order(&star(&sector_angles), &signs).unwrap();
            assert!(
                !found.excludes_motion(1e-9),
                "degree {n}: signs {signs:?} of a real motion excluded ({found:?})"
            );
            tested += 1;
        }
    }
    assert!(tested >= 40, "only {tested} motions found");
}

#[test]
fn a_vertex_of_one_sign_is_excluded_and_the_quadratic_form_is_not_trivial() {
    let mut draws = Draws(11);
    for n in 3..=10 {
        for _ in 0..10 {
            let sector_angles = sectors(n, &mut draws);
            for sign in [1.0, -1.0] {
                let found = second_order(&star(&sector_angles), &vec![sign; n]).unwrap();
                assert_eq!(found, SecondOrder::OneSign);
                // The polytope test alone agrees where no two creases are collinear (a
                // straight line folds with one sign, the other creases flat, and Q = 0 there).
                if n < 5 {
                    assert!(cone_range(&star(&sector_angles), &vec![sign; n]).is_none());
                    continue;
                }
                let found = cone_range(&star(&sector_angles), &vec![sign; n]).unwrap();
                assert!(found.excludes_motion(1e-9), "degree {n}, all {sign}: {found:?}");
            }
        }
    }
    // Alternating signs at a flat-foldable degree-6 vertex (equal sectors): a real motion
    // exists (the symmetric one), so Q takes both signs or 0 on the cone.
    let found = second_order(&star(&[TAU / 6.0; 6]), &[1.0, -1.0, 1.0, -1.0, 1.0, -1.0]).unwrap();
    match found {
        SecondOrder::Range { min, max } => assert!(min <= 1e-12 && max >= -1e-12, "{min} {max}"),
        other => panic!("alternating signs move at first order: {other:?}"),
    }
    // Unassigned creases and degrees above the limit are not tested.
    assert!(second_order(&star(&[TAU / 6.0; 6]), &[1.0, 0.0, 1.0, -1.0, 1.0, -1.0]).is_none());
}

/// Below degree 5 only the one-sign rule applies (degree 4 has its exact modes; at degree 2
/// or 3 the sign row can be a combination of the closure rows): a straight crease through
/// a vertex of degree 2 is never excluded.
#[test]
fn low_degrees_get_only_the_one_sign_rule() {
    use std::f64::consts::PI;
    assert!(second_order(&star(&[PI, PI]), &[-1.0, -1.0]).is_none());
    let t = star(&[PI / 2.0, PI / 2.0, PI]);
    assert!(second_order(&t, &[1.0, -1.0, 1.0]).is_none());
    assert_eq!(second_order(&t, &[1.0, 1.0, 1.0]), Some(SecondOrder::OneSign));
    assert!(second_order(&star(&[PI / 2.0; 4]), &[1.0, -1.0, 1.0, 1.0]).is_none());
}

/// A lattice of equilateral triangles (every interior vertex of degree 6) with `letter` the
/// assignment of each crease by its direction (horizontal, rising, falling) and its ends.
fn triangle_lattice(n: usize, letter: impl Fn(char, usize, usize) -> &'static str) -> FoldingModel {
    let index = |i: usize, j: usize| j * (n + 1) + i;
    let vertices: Vec<[f64; 2]> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| [i as f64 + 0.5 * j as f64, j as f64 * 3f64.sqrt() / 2.0]))
        .collect();
    let (mut edges, mut assignment, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    let mut add = |a: usize, b: usize, boundary: bool, kind: char| {
        edges.push([a, b]);
        assignment.push(if boundary { "B" } else { letter(kind, a, b) });
    };
    for j in 0..=n {
        for i in 0..n {
            add(index(i, j), index(i + 1, j), j == 0 || j == n, 'h');
        }
    }
    for i in 0..=n {
        for j in 0..n {
            add(index(i, j), index(i, j + 1), i == 0 || i == n, 'r');
        }
    }
    for j in 0..n {
        for i in 0..n {
            add(index(i + 1, j), index(i, j + 1), false, 'f');
            faces.push([index(i, j), index(i + 1, j), index(i, j + 1)]);
            faces.push([index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]);
        }
    }
    let value = json!({
        "file_spec": 1.1,
        "vertices_coords": vertices,
        "edges_vertices": edges,
        "edges_assignment": assignment,
        "faces_vertices": faces,
    });
    FoldingModel::new(parse_crease_pattern(&value.to_string(), "lattice", "lattice.fold").unwrap()).unwrap()
}

#[test]
fn lattices_of_degree_6_vertices_are_decided() {
    let settings = CheckSettings::default();
    // Every crease a valley: was `unknown`.
    let valleys = triangle_lattice(4, |_, _, _| "V");
    let report = check_pattern(&valleys, &settings).unwrap();
    assert_eq!(
        report.verdict,
        PatternVerdict::NotRigidlyFoldable,
        "{}",
        report.evidence
    );
    assert!(report.evidence.contains("one sign"), "{}", report.evidence);
    // The lines of one direction mountains, the rest valleys (that folds, below), but the
    // middle vertex (12) with mountains on its three creases towards +x, +60°, +120° and
    // valleys on the rest: no velocities with those signs close it in the plane.
    let middle = 12;
    let one_vertex = triangle_lattice(4, |kind, a, b| {
        let other = if a == middle {
            b
        } else if b == middle {
            a
        } else {
            return if kind == 'h' { "M" } else { "V" };
        };
        if [middle + 1, middle + 5, middle + 4].contains(&other) {
            "M"
        } else {
            "V"
        }
    });
    let report = check_pattern(&one_vertex, &settings).unwrap();
    assert_eq!(
        report.verdict,
        PatternVerdict::NotRigidlyFoldable,
        "{}",
        report.evidence
    );
    assert!(
        report.evidence.starts_with("vertex 12")
            && report.evidence.contains("MMMVVV")
            && report.evidence.contains("no motion from flat"),
        "{}",
        report.evidence
    );
    // One direction folded the other way folds (along those lines): not excluded.
    let lines = triangle_lattice(4, |kind, _, _| if kind == 'h' { "M" } else { "V" });
    let report = check_pattern(&lines, &settings).unwrap();
    assert_eq!(report.verdict, PatternVerdict::RigidlyFoldable, "{}", report.evidence);
    assert!(
        report.tried.iter().any(|t| t.contains("second-order test")),
        "{:?}",
        report.tried
    );
}

/// Random assignments of the lattice: where the second-order test excludes one, the witness
/// search (a folding path from flat with the assigned signs) must not find a path either.
#[test]
fn exclusions_agree_with_the_witness_search() {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    let settings = CheckSettings::default();
    let mut draws = Draws(2026);
    let (mut excluded, mut others) = (0, 0);
    for _ in 0..12 {
        let letters: Vec<&'static str> = (0..200).map(|_| if draws.next() < 0.5 { "M" } else { "V" }).collect();
        let counter = std::cell::Cell::new(0);
        let model = triangle_lattice(4, |_, _, _| {
            let k = counter.get();
            counter.set(k + 1);
            letters[k]
        });
        let report = check_pattern(&model, &settings).unwrap();
        if report.verdict == PatternVerdict::NotRigidlyFoldable && report.evidence.contains("(degree 6)") {
            excluded += 1;
            let drive = FoldSettings {
                drive: Drive::Assignment { to: 100.0 },
                ..FoldSettings::default()
            };
            let path = fold_path(&model, &model.given_fold_angles(), &drive).unwrap();
            let reached = path.steps.last().map_or(0.0, |s| s.progress);
            assert!(
                path.steps.len() <= 2 || reached <= 0.0,
                "excluded ({}) but a path reaches {reached} ({})",
                report.evidence,
                path.evidence
            );
        } else {
            others += 1;
        }
    }
    eprintln!("random lattice assignments: {excluded} excluded at second order, {others} otherwise");
    assert!(excluded >= 6, "{excluded} of 12");
}
