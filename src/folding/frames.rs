//! Frames placed on a computed folding path (`docs/model.md#folding-paths`): states at
//! evenly spaced progress, interpolated between the path's accepted steps (a cubic in the
//! path's chord length) and polished by Newton onto every closure, so a frame costs a
//! Newton solve, not a path step.

use super::closure::{closure_jacobian, closure_residual, worst_of, ClosureJacobian};
use super::model::FoldingModel;
use super::normal::{NormalFactor, NormalSolver};
use super::path::{assigned_signs, progress, progress_by_crease, progress_crease, FoldPath};
use crate::error::{NanofoldError, Result};

/// The closure a frame is polished towards, rad: below rounding, so the polish goes on
/// while chord steps still halve the residual. A residual r at each vertex moves the last
/// panels of a tree of depth d by about d·r of the pattern's size, and at depth 100 the
/// edge lengths hold to 1e-12 only from about 1e-15.
pub const FRAME_CLOSURE: f64 = 1e-16;

/// The residual's fall per chord step below which a frame's polish refactorises.
const CHORD_CONTRACTION: f64 = 0.1;

/// Below this residual, rad, a frame's polish takes only chord steps.
const CHORD_ONLY: f64 = 1e-13;

/// Most frames one call places.
pub const MAX_FRAMES: usize = 100_000;

/// One frame on a path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathFrame {
    /// Progress towards the drive's goal (as the path's steps measure it).
    pub progress: f64,
    /// Fold angles, rad (one per crease).
    pub fold_angles: Vec<f64>,
    /// Largest vertex closure residual, rad.
    pub max_residual: f64,
    /// The accepted step the frame follows (its segment of the path).
    pub after_step: usize,
}

/// `count` frames (at least 2) at evenly spaced progress from the path's first state to its
/// last, both included. Between steps a frame starts from the cubic through the four
/// nearest steps (in cumulative chord length), placed where its progress is the target,
/// and Newton moves it onto every closure (to [`FRAME_CLOSURE`], or as close as rounding
/// allows) with the crease that sets progress held, so the frame keeps its progress. Where
/// Newton finds no rigid state near it the nearer step is the frame. Frames are independent:
/// on a large pattern they are placed on the machine's cores (at most [`MAX_FRAME_THREADS`]),
/// with the same result as one at a time.
pub fn path_frames(model: &FoldingModel, path: &FoldPath, count: usize) -> Result<Vec<PathFrame>> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = if model.crease_count() >= PARALLEL_FROM_CREASES {
        cores.min(MAX_FRAME_THREADS).min(count / 2).max(1)
    } else {
        1
    };
    path_frames_on(model, path, count, threads)
}

/// Most threads [`path_frames`] uses.
pub const MAX_FRAME_THREADS: usize = 8;

/// Creases from which [`path_frames`] spreads frames over threads (below, a frame takes a
/// millisecond or less and one thread is as quick).
const PARALLEL_FROM_CREASES: usize = 500;

/// [`path_frames`] on `threads` threads (at least 1; more than `count` are not used), each
/// taking a run of consecutive frames with its own factorisation workspace.
pub fn path_frames_on(model: &FoldingModel, path: &FoldPath, count: usize, threads: usize) -> Result<Vec<PathFrame>> {
    if !(2..=MAX_FRAMES).contains(&count) {
        return Err(NanofoldError::invalid(
            "frames",
            count,
            format!("must lie in [2, {MAX_FRAMES}]"),
        ));
    }
    if threads == 0 {
        return Err(NanofoldError::invalid("threads", threads, "must be at least 1"));
    }
    let placer = FramePlacer::new(model, path, count);
    let threads = threads.min(count);
    if threads == 1 {
        let mut solver = NormalSolver::new(1e-10);
        return (0..count).map(|k| placer.frame(k, &mut solver)).collect();
    }
    let runs: Vec<std::ops::Range<usize>> = (0..threads)
        .map(|t| (t * count / threads)..((t + 1) * count / threads))
        .collect();
    std::thread::scope(|scope| {
        let placer = &placer;
        let handles: Vec<_> = runs
            .into_iter()
            .map(|run| {
                scope.spawn(move || {
                    let mut solver = NormalSolver::new(1e-10);
                    run.map(|k| placer.frame(k, &mut solver)).collect::<Result<Vec<_>>>()
                })
            })
            .collect();
        let mut frames = Vec::with_capacity(count);
        for handle in handles {
            let run = handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
            frames.extend(run);
        }
        Ok(frames)
    })
}

/// What every frame of one call shares: the path, its chord lengths and progress range.
struct FramePlacer<'a> {
    model: &'a FoldingModel,
    path: &'a FoldPath,
    signs: Vec<f64>,
    /// Cumulative chord length at each step: the cubic's parameter.
    chord: Vec<f64>,
    count: usize,
}

impl<'a> FramePlacer<'a> {
    fn new(model: &'a FoldingModel, path: &'a FoldPath, count: usize) -> Self {
        let mut chord = vec![0.0];
        for pair in path.steps.windows(2) {
            let d: f64 = pair[0]
                .fold_angles
                .iter()
                .zip(&pair[1].fold_angles)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
            chord.push(chord.last().copied().unwrap_or(0.0) + d);
        }
        FramePlacer {
            model,
            path,
            signs: assigned_signs(model),
            chord,
            count,
        }
    }

    /// Frame `k` of `count`.
    fn frame(&self, k: usize, solver: &mut NormalSolver) -> Result<PathFrame> {
        let (path, steps, count) = (self.path, &self.path.steps, self.count);
        let signs = &self.signs;
        let start = &steps[0].fold_angles;
        let progress_of = |rho: &[f64]| progress(&path.drive, start, rho, signs);
        let (first, last) = (steps[0].progress, steps[steps.len() - 1].progress);
        let target = first + (last - first) * k as f64 / (count - 1) as f64;
        // The segment whose steps bracket the target (the last one where progress is flat).
        let segment = (0..steps.len().saturating_sub(1))
            .find(|&i| steps[i + 1].progress >= target)
            .unwrap_or(steps.len().saturating_sub(2).min(steps.len() - 1));
        let guess = if k == 0 || steps.len() == 1 {
            steps[0].fold_angles.clone()
        } else if k == count - 1 {
            steps[steps.len() - 1].fold_angles.clone()
        } else {
            // Bisection on the crease that sets progress at the segment's end, checked on the
            // whole state (and redone on it where another crease sets progress).
            let end = &steps[(segment + 1).min(steps.len() - 1)].fold_angles;
            let setter = progress_crease(&path.drive, end, signs)
                .map(|c| (c, move |value: f64| progress_by_crease(&path.drive, start, c, value)));
            let by_setter = setter
                .as_ref()
                .map(|(c, f)| place(steps, &self.chord, segment, target, &Placement::Crease(*c, f)))
                .filter(|guess| (progress_of(guess) - target).abs() <= 1e-12);
            by_setter.unwrap_or_else(|| place(steps, &self.chord, segment, target, &Placement::State(&progress_of)))
        };
        let mut rho = guess;
        // The crease that sets progress keeps its angle, so the frame stays at its target.
        let held = if k == 0 || k == count - 1 {
            None
        } else {
            progress_crease(&path.drive, &rho, signs)
        };
        let residual = polish(self.model, &mut rho, held, solver)?;
        let (fold_angles, max_residual) = if residual <= path_tolerance(path) {
            (rho, residual)
        } else {
            // No rigid state near the cubic: the nearer step, as the path accepted it.
            let nearer = if (target - steps[segment].progress).abs()
                <= (steps[(segment + 1).min(steps.len() - 1)].progress - target).abs()
            {
                segment
            } else {
                (segment + 1).min(steps.len() - 1)
            };
            (steps[nearer].fold_angles.clone(), steps[nearer].max_residual)
        };
        Ok(PathFrame {
            progress: progress_of(&fold_angles),
            fold_angles,
            max_residual,
            after_step: segment,
        })
    }
}

/// The closure a frame must reach to be used: the path's own worst, or 1e-10 rad.
fn path_tolerance(path: &FoldPath) -> f64 {
    path.max_closure_residual.max(1e-10)
}

/// How [`place`] measures progress on the cubic.
enum Placement<'a> {
    /// Progress of the whole state.
    State(&'a dyn Fn(&[f64]) -> f64),
    /// Progress set by one crease (its index, its progress as a function of its angle).
    Crease(usize, &'a dyn Fn(f64) -> f64),
}

/// The cubic (Lagrange, through up to four steps around `segment`, in chord length) at the
/// point of the segment where progress is `target` (bisection on the chord length).
fn place(steps: &[super::path::PathStep], chord: &[f64], segment: usize, target: f64, by: &Placement) -> Vec<f64> {
    let m = steps.len();
    let lo = segment.saturating_sub(1);
    let hi = (segment + 2).min(m - 1);
    let nodes: Vec<usize> = (lo..=hi).collect();
    let weights = |s: f64| -> Vec<f64> {
        nodes
            .iter()
            .map(|&i| {
                nodes
                    .iter()
                    .filter(|&&j| j != i)
                    .map(|&j| (s - chord[j]) / (chord[i] - chord[j]))
                    .product()
            })
            .collect()
    };
    let at = |s: f64| -> Vec<f64> {
        let weights = weights(s);
        (0..steps[0].fold_angles.len())
            .map(|c| {
                nodes
                    .iter()
                    .zip(&weights)
                    .map(|(&i, w)| w * steps[i].fold_angles[c])
                    .sum()
            })
            .collect()
    };
    let (mut a, mut b) = (chord[segment], chord[(segment + 1).min(m - 1)]);
    if b <= a {
        return steps[segment].fold_angles.clone();
    }
    let progress_at = |s: f64| match by {
        Placement::State(progress_of) => progress_of(&at(s)),
        Placement::Crease(c, progress_of) => progress_of(
            nodes
                .iter()
                .zip(weights(s))
                .map(|(&i, w)| w * steps[i].fold_angles[*c])
                .sum(),
        ),
    };
    for _ in 0..60 {
        let mid = 0.5 * (a + b);
        if progress_at(mid) < target {
            a = mid;
        } else {
            b = mid;
        }
    }
    at(0.5 * (a + b))
}

/// Newton's least-norm steps towards [`FRAME_CLOSURE`], with crease `held` (if any) kept
/// where it is, stopping when the residual no longer halves; leaves the best state found in
/// `fold_angles` and returns its residual. The factorisation is reused (chord steps) while
/// the residual falls tenfold per step: a frame starts within the cubic's small error of
/// the path, where J barely changes.
fn polish(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    held: Option<usize>,
    solver: &mut NormalSolver,
) -> Result<f64> {
    let mut best = (f64::INFINITY, fold_angles.to_vec());
    let mut factored: Option<(ClosureJacobian, NormalFactor)> = None;
    let mut fresh = false;
    let mut previous = f64::INFINITY;
    let mut residual = Vec::with_capacity(3 * model.stars.len());
    let mut step = vec![0.0; fold_angles.len()];
    for _ in 0..20 {
        // The residual alone: a chord step reuses the factorised Jacobian.
        closure_residual(model, fold_angles, &mut residual);
        let worst = worst_of(&residual);
        if !worst.is_finite() {
            break;
        }
        if worst < best.0 {
            best = (worst, fold_angles.to_vec());
        }
        if worst <= FRAME_CLOSURE {
            break;
        }
        // Near rounding the residual cannot fall tenfold: chord steps go on while it halves.
        if worst <= CHORD_ONLY && factored.is_some() && worst > 0.5 * previous {
            break;
        }
        if factored.is_none() || (worst > CHORD_CONTRACTION * previous && worst > CHORD_ONLY) {
            // A fresh matrix that could not halve the residual: as close as rounding allows.
            if fresh && worst > 0.5 * previous {
                break;
            }
            let mut jac = closure_jacobian(model, fold_angles);
            if let Some(c) = held {
                jac.hold(c);
            }
            let factor = solver.factor(&jac)?;
            factored = Some((jac, factor));
            fresh = true;
        } else {
            fresh = false;
        }
        previous = worst;
        let (matrix, factor) = factored.as_ref().expect("set above");
        matrix.apply_transpose(&residual, &mut step);
        factor.solve(&mut step);
        for (rho, d) in fold_angles.iter_mut().zip(&step) {
            *rho -= d;
        }
    }
    fold_angles.copy_from_slice(&best.1);
    Ok(best.0)
}
