//! Which axis-aligned boxes overlap (`docs/model.md#broad-phase`): the broad phase of the
//! planarity test and of panel contact. Boxes that span a few cells of a grid sized from
//! their own median extent are hashed into those cells; the rest (long edges, a vertex far
//! from the others) are swept along the axis on which boxes overlap least. Its cost follows
//! the pairs the data has, not its bounding box: a far outlier or a 50 000-panel strip costs
//! about what an evenly spread pattern of the same size does.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiplicative hash of a cell's integer coordinates: the cells are the broad phase's
/// keys, hashed thousands of times per test, and need no defence against chosen inputs.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        // Integer slices arrive as their bytes: eight at a time.
        let mut chunks = bytes.chunks_exact(8);
        for chunk in &mut chunks {
            self.write_u64(u64::from_le_bytes(chunk.try_into().expect("eight bytes")));
        }
        for &b in chunks.remainder() {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_i64(&mut self, value: i64) {
        self.write_u64(value as u64);
    }

    fn write_usize(&mut self, value: usize) {
        self.write_u64(value as u64);
    }
}

/// Grid cells and the boxes in each.
type Cells<const D: usize> = HashMap<[i64; D], Vec<usize>, BuildHasherDefault<CellHasher>>;

/// An axis-aligned box: its lower and upper corners.
pub type Aabb<const D: usize> = ([f64; D], [f64; D]);

/// A box spanning more cells than this along any axis is swept rather than hashed.
const MAX_SPAN: i64 = 4;

/// Every pair of boxes that overlap (closed intervals on every axis), smaller index first,
/// each once, sorted. Boxes must have finite corners with lower ≤ upper.
pub fn overlapping_pairs<const D: usize>(boxes: &[Aabb<D>]) -> Vec<(usize, usize)> {
    overlapping_pairs_within(boxes, usize::MAX).unwrap_or_default()
}

/// [`overlapping_pairs`], or `Err(limit + 1)` as soon as more than `limit` pairs are found,
/// or more than 64 × `limit` pairs compared (boxes stacked on each other: the time and
/// memory stay bounded by the limit).
pub fn overlapping_pairs_within<const D: usize>(
    boxes: &[Aabb<D>],
    limit: usize,
) -> std::result::Result<Vec<(usize, usize)>, usize> {
    overlapping_pairs_where(boxes, limit, |_, _| true)
}

/// [`overlapping_pairs_within`] of the pairs `wanted` keeps: an overlapping pair it drops
/// (smaller index first) is neither returned nor counted against `limit`, though comparing
/// it still counts against the 64 × `limit` comparisons.
pub fn overlapping_pairs_where<const D: usize>(
    boxes: &[Aabb<D>],
    limit: usize,
    wanted: impl Fn(usize, usize) -> bool,
) -> std::result::Result<Vec<(usize, usize)>, usize> {
    if boxes.len() < 2 {
        return Ok(Vec::new());
    }
    let lo: [f64; D] = std::array::from_fn(|k| boxes.iter().map(|b| b.0[k]).fold(f64::INFINITY, f64::min));
    // The grid's cell starts at the boxes' median size and shrinks while a cell would hold
    // too many boxes for pairwise tests (long thin boxes side by side share few cells only
    // when the cell is about their width); boxes that then span many cells are swept.
    let mut cell = cell_size(boxes);
    let mut budget = Budget::new(limit, &wanted);
    let (large, ranges, cells) = loop {
        // Cell indices stay far inside i64 whatever the ratio of extent to cell.
        let index = |x: f64, k: usize| ((x - lo[k]) / cell).floor().clamp(0.0, 4.0e18) as i64;
        let ranges: Vec<[(i64, i64); D]> = boxes
            .iter()
            .map(|b| std::array::from_fn(|k| (index(b.0[k], k), index(b.1[k], k))))
            .collect();
        let large: Vec<bool> = ranges
            .iter()
            .map(|r| r.iter().any(|&(a, b)| b - a >= MAX_SPAN))
            .collect();
        let cells = hashed(&ranges, &large);
        let work: usize = cells.values().map(|list| list.len() * list.len()).sum();
        if work <= WORK_PER_BOX * boxes.len() || cell <= f64::MIN_POSITIVE * 1e6 {
            break (large, ranges, cells);
        }
        cell /= 4.0;
    };
    let mut pairs = Vec::new();
    grid_pairs(boxes, &ranges, &cells, &mut pairs, &mut budget)?;
    swept_pairs(boxes, &large, &mut pairs, &mut budget)?;
    pairs.sort_unstable();
    Ok(pairs)
}

/// Pairwise tests of a grid cell per box above which the cell is made smaller.
const WORK_PER_BOX: usize = 64;

/// Pairs found and pairs compared, against the caller's limit (comparisons may run to
/// [`COMPARISONS_PER_PAIR`] times it: boxes overlapping along the swept axis only).
struct Budget<'w> {
    limit: usize,
    compared: usize,
    wanted: &'w dyn Fn(usize, usize) -> bool,
}

/// How many comparisons the budget allows per pair it may find.
const COMPARISONS_PER_PAIR: usize = 64;

impl<'w> Budget<'w> {
    fn new(limit: usize, wanted: &'w dyn Fn(usize, usize) -> bool) -> Budget<'w> {
        Budget {
            limit,
            compared: 0,
            wanted,
        }
    }

    /// Adds a wanted pair, or says the limit is passed.
    fn push(&self, pairs: &mut Vec<(usize, usize)>, a: usize, b: usize) -> std::result::Result<(), usize> {
        let pair = (a.min(b), a.max(b));
        if !(self.wanted)(pair.0, pair.1) {
            return Ok(());
        }
        if pairs.len() >= self.limit {
            return Err(self.limit.saturating_add(1));
        }
        pairs.push(pair);
        Ok(())
    }

    /// One more comparison, or the limit passed.
    fn compare(&mut self) -> std::result::Result<(), usize> {
        self.compared += 1;
        if self.compared / COMPARISONS_PER_PAIR > self.limit {
            return Err(self.limit.saturating_add(1));
        }
        Ok(())
    }
}

/// The cells of every small box, odometer order within each box.
fn hashed<const D: usize>(ranges: &[[(i64, i64); D]], large: &[bool]) -> Cells<D> {
    let mut cells: Cells<D> = Cells::default();
    for (b, r) in ranges.iter().enumerate().filter(|(b, _)| !large[*b]) {
        let mut at: [i64; D] = std::array::from_fn(|k| r[k].0);
        loop {
            cells.entry(at).or_default().push(b);
            let mut k = 0;
            while k < D {
                if at[k] < r[k].1 {
                    at[k] += 1;
                    break;
                }
                at[k] = r[k].0;
                k += 1;
            }
            if k == D {
                break;
            }
        }
    }
    cells
}

/// The median of the boxes' largest sides, or where most boxes are points, the extent
/// shared out evenly; never zero.
fn cell_size<const D: usize>(boxes: &[Aabb<D>]) -> f64 {
    let mut sizes: Vec<f64> = boxes
        .iter()
        .map(|b| (0..D).map(|k| b.1[k] - b.0[k]).fold(0.0, f64::max))
        .collect();
    let middle = sizes.len() / 2;
    let median = *sizes.select_nth_unstable_by(middle, f64::total_cmp).1;
    if median > 0.0 {
        return median;
    }
    let extent = (0..D)
        .map(|k| {
            let (lo, hi) = boxes.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), b| {
                (l.min(b.0[k]), h.max(b.1[k]))
            });
            hi - lo
        })
        .fold(0.0, f64::max);
    (extent / (boxes.len() as f64).powf(1.0 / D as f64)).max(f64::MIN_POSITIVE)
}

/// Pairs of small boxes sharing a cell, each reported from the first cell both cover.
fn grid_pairs<const D: usize>(
    boxes: &[Aabb<D>],
    ranges: &[[(i64, i64); D]],
    cells: &Cells<D>,
    pairs: &mut Vec<(usize, usize)>,
    budget: &mut Budget<'_>,
) -> std::result::Result<(), usize> {
    for (at, list) in cells {
        for (x, &a) in list.iter().enumerate() {
            for &b in &list[x + 1..] {
                budget.compare()?;
                let first: [i64; D] = std::array::from_fn(|k| ranges[a][k].0.max(ranges[b][k].0));
                if &first == at && overlap(&boxes[a], &boxes[b]) {
                    budget.push(pairs, a, b)?;
                }
            }
        }
    }
    Ok(())
}

/// Pairs with at least one large box, by sweep and prune along the axis on which the boxes
/// overlap least (the sum of their lengths along it, over its extent).
fn swept_pairs<const D: usize>(
    boxes: &[Aabb<D>],
    large: &[bool],
    pairs: &mut Vec<(usize, usize)>,
    budget: &mut Budget<'_>,
) -> std::result::Result<(), usize> {
    if !large.iter().any(|&l| l) {
        return Ok(());
    }
    let crowding = |k: usize| {
        let (lo, hi) = boxes.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), b| {
            (l.min(b.0[k]), h.max(b.1[k]))
        });
        let total: f64 = boxes.iter().map(|b| b.1[k] - b.0[k]).sum();
        total / (hi - lo).max(f64::MIN_POSITIVE)
    };
    let axis = (0..D).min_by(|&a, &b| crowding(a).total_cmp(&crowding(b))).unwrap_or(0);
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0[axis].total_cmp(&boxes[b].0[axis]));
    let (mut active_small, mut active_large): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    for &b in &order {
        let start = boxes[b].0[axis];
        active_large.retain(|&a| boxes[a].1[axis] >= start);
        for &a in &active_large {
            budget.compare()?;
            if overlap(&boxes[a], &boxes[b]) {
                budget.push(pairs, a, b)?;
            }
        }
        if large[b] {
            // Small boxes are only needed when a large one starts: expire them then.
            active_small.retain(|&a| boxes[a].1[axis] >= start);
            for &a in &active_small {
                budget.compare()?;
                if overlap(&boxes[a], &boxes[b]) {
                    budget.push(pairs, a, b)?;
                }
            }
            active_large.push(b);
        } else {
            active_small.push(b);
        }
    }
    Ok(())
}

fn overlap<const D: usize>(a: &Aabb<D>, b: &Aabb<D>) -> bool {
    (0..D).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every overlapping pair, by testing them all.
    fn brute<const D: usize>(boxes: &[Aabb<D>]) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for a in 0..boxes.len() {
            for b in a + 1..boxes.len() {
                if overlap(&boxes[a], &boxes[b]) {
                    pairs.push((a, b));
                }
            }
        }
        pairs
    }

    #[test]
    fn the_pairs_are_those_of_testing_every_pair() {
        // A pseudo-random mix of small boxes, long thin ones, points and one far away.
        let mut next = crate::geometry::test_draws(0x2545_F491_4F6C_DD1D_u64);
        for round in 0..20 {
            let mut boxes2: Vec<Aabb<2>> = Vec::new();
            let mut boxes3: Vec<Aabb<3>> = Vec::new();
            for i in 0..300 {
                let long = i % 17 == 0;
                let point = i % 23 == 0;
                let size = if point {
                    0.0
                } else if long {
                    5.0 * next()
                } else {
                    0.05 * next()
                };
                let lo = [10.0 * next(), 10.0 * next(), 10.0 * next()];
                let hi = [lo[0] + size, lo[1] + if long { 0.01 } else { size }, lo[2] + size];
                boxes2.push(([lo[0], lo[1]], [hi[0], hi[1]]));
                boxes3.push((lo, hi));
            }
            if round % 2 == 0 {
                boxes2.push(([1e6, 1e6], [1e6 + 1.0, 1e6 + 1.0]));
                boxes2.push(([0.0, 0.0], [1e6, 1e6]));
            }
            assert_eq!(overlapping_pairs(&boxes2), brute(&boxes2), "round {round}, 2D");
            assert_eq!(overlapping_pairs(&boxes3), brute(&boxes3), "round {round}, 3D");
        }
    }

    #[test]
    fn a_stack_past_the_limit_is_refused_early() {
        // 2 000 boxes on top of each other: 1 999 000 pairs, refused after 10 000.
        let stack = vec![([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]); 2000];
        assert_eq!(overlapping_pairs_within(&stack, 10_000), Err(10_001));
        assert_eq!(
            overlapping_pairs_within(&stack[..100], 10_000).map(|p| p.len()),
            Ok(4950)
        );
    }

    #[test]
    fn pairs_left_out_are_neither_returned_nor_counted() {
        // 600 boxes through one point (179 700 pairs): keeping only the pairs of boxes 0..10
        // returns those 45 under a limit of 5 000, which all the pairs would pass (the
        // comparisons, 64 per pair of the limit, still bound the work).
        let fan: Vec<Aabb<2>> = (0..600)
            .map(|k| {
                let x = k as f64 * 1e-3;
                ([-x, -1.0], [1.0 + x, 0.0])
            })
            .collect();
        let kept = overlapping_pairs_where(&fan, 5000, |a, b| a < 10 && b < 10).unwrap();
        let expected: Vec<(usize, usize)> = brute(&fan).into_iter().filter(|&(a, b)| a < 10 && b < 10).collect();
        assert_eq!((kept.len(), &kept), (45, &expected));
        assert_eq!(overlapping_pairs_within(&fan, 5000), Err(5001));
    }

    #[test]
    fn points_and_single_boxes_have_no_trouble() {
        assert!(overlapping_pairs::<2>(&[]).is_empty());
        assert!(overlapping_pairs(&[([0.0, 0.0], [1.0, 1.0])]).is_empty());
        let same = [([1.0, 2.0], [1.0, 2.0]); 3];
        assert_eq!(overlapping_pairs(&same), vec![(0, 1), (0, 2), (1, 2)]);
    }
}
