//! Frames placed on a computed folding path (`docs/model.md#folding-paths`): states at
//! evenly spaced progress, interpolated between the path's accepted steps (a cubic in the
//! path's chord length) and polished by Newton onto every closure, so a frame costs a
//! Newton solve, not a path step.

use super::closure::{closure_jacobian, closure_residual, worst_of, ClosureJacobian};
use super::model::FoldingModel;
use super::normal::{NormalFactor, NormalSolver};
use super::path::{
    assigned_signs, fold_path, fold_path_observed, progress, progress_by_crease, progress_crease, Drive, FoldPath,
    FoldSettings, PathStep, StopReason, CHORD_CONTRACTION,
};
use crate::error::{NanofoldError, Result};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The closure a frame is polished towards, rad: below rounding, so the polish goes on
/// while chord steps still halve the residual. A residual r at each vertex moves the last
/// panels of a tree of depth d by about d·r of the pattern's size, and at depth 100 the
/// edge lengths hold to 1e-12 only from about 1e-15.
pub const FRAME_CLOSURE: f64 = 1e-16;

/// Below this residual, rad, a frame's polish takes only chord steps.
const CHORD_ONLY: f64 = 1e-13;

/// Most frames one call places.
pub const MAX_FRAMES: usize = 100_000;

/// Most frames × vertices of a fold's animation: its frames, their FOLD text and its 3D
/// page are all held in memory before anything is written, about 90 MB a frame of 100 000
/// vertices; 12 such frames stay within 2 GiB (`docs/guide/limits.md`).
pub const MAX_FRAME_POINTS: usize = 1_200_000;

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
/// last (to the goal, progress 1, where the path reached it), both included. Between steps a
/// frame starts from the cubic through the four nearest steps (in cumulative chord length),
/// placed where its progress is the target, and Newton moves it onto every closure (to
/// [`FRAME_CLOSURE`], or as close as rounding allows) with the crease that sets progress
/// held, so the frame keeps its progress. Where Newton finds no rigid state near it the
/// nearer step is the frame. Frames are independent: on a large pattern they are placed on
/// the machine's cores (at most [`MAX_FRAME_THREADS`]), with the same result as one at a
/// time.
pub fn path_frames(model: &FoldingModel, path: &FoldPath, count: usize) -> Result<Vec<PathFrame>> {
    path_frames_on(model, path, count, frame_threads(model, count))
}

/// The threads [`path_frames`] uses: the machine's cores from [`PARALLEL_FROM_CREASES`].
fn frame_threads(model: &FoldingModel, count: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if model.crease_count() >= PARALLEL_FROM_CREASES {
        cores.min(MAX_FRAME_THREADS).min(count / 2).max(1)
    } else {
        1
    }
}

/// Most threads [`path_frames`] uses.
pub const MAX_FRAME_THREADS: usize = 8;

/// Creases from which [`path_frames`] spreads frames over threads (below, a frame takes a
/// millisecond or less and one thread is as quick).
const PARALLEL_FROM_CREASES: usize = 500;

fn check_frame_count(count: usize) -> Result<()> {
    if !(2..=MAX_FRAMES).contains(&count) {
        return Err(NanofoldError::invalid(
            "frames",
            count,
            format!("must lie in [2, {MAX_FRAMES}]"),
        ));
    }
    Ok(())
}

/// [`path_frames`] on `threads` threads (at least 1; more than `count` are not used), each
/// taking a run of consecutive frames with its own factorisation workspace.
pub fn path_frames_on(model: &FoldingModel, path: &FoldPath, count: usize, threads: usize) -> Result<Vec<PathFrame>> {
    check_frame_count(count)?;
    if threads == 0 {
        return Err(NanofoldError::invalid("threads", threads, "must be at least 1"));
    }
    let placer = FramePlacer::new(model, &path.drive, count);
    let chord = chord_lengths(&path.steps);
    let last = end_progress(path);
    let polished = polish_frames(&placer, &path.steps, &chord, last, 0..count, threads)?;
    Ok(polished
        .into_iter()
        .map(|p| placer.judged(p, &path.steps, path_tolerance(path)))
        .collect())
}

/// Frames `ks`, polished on `threads` threads (runs of consecutive frames).
fn polish_frames(
    placer: &FramePlacer,
    steps: &[PathStep],
    chord: &[f64],
    last: f64,
    ks: std::ops::Range<usize>,
    threads: usize,
) -> Result<Vec<Polished>> {
    let threads = threads.min(ks.len()).max(1);
    if threads == 1 {
        let mut solver = NormalSolver::new(1e-10);
        return ks
            .map(|k| placer.polished(steps, chord, last, k, &mut solver))
            .collect();
    }
    let runs: Vec<std::ops::Range<usize>> = (0..threads)
        .map(|t| (ks.start + t * ks.len() / threads)..(ks.start + (t + 1) * ks.len() / threads))
        .collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = runs
            .into_iter()
            .map(|run| {
                scope.spawn(move || {
                    let mut solver = NormalSolver::new(1e-10);
                    run.map(|k| placer.polished(steps, chord, last, k, &mut solver))
                        .collect::<Result<Vec<_>>>()
                })
            })
            .collect();
        let mut frames = Vec::with_capacity(ks.len());
        for handle in handles {
            let run = handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
            frames.extend(run);
        }
        Ok(frames)
    })
}

/// A folding path and `count` frames on it, as [`fold_path`] and [`path_frames`] give them,
/// with the frames placed while the path goes on: on a large pattern a second thread places
/// each frame as soon as the steps its cubic needs are accepted (a path that reaches its
/// goal ends at progress 1, so the frames' targets are known from the start), and what is
/// left when the path ends is shared by both threads (and more cores, where there are
/// more). A path that stops short of its goal has its frames placed afterwards, on its own
/// end. The frames are those of [`path_frames`], bit for bit, either way.
pub fn fold_path_and_frames(
    model: &FoldingModel,
    start: &[f64],
    settings: &FoldSettings,
    count: usize,
) -> Result<(FoldPath, Vec<PathFrame>)> {
    check_frame_count(count)?;
    let threads = frame_threads(model, count);
    if threads == 1 {
        let path = fold_path(model, start, settings)?;
        let frames = path_frames_on(model, &path, count, 1)?;
        return Ok((path, frames));
    }
    let placer = FramePlacer::new(model, &settings.drive, count);
    let claims = Claims {
        next: AtomicUsize::new(0),
        count,
    };
    let (sender, receiver) = std::sync::mpsc::channel::<Accepted>();
    let (path, mut polished) = std::thread::scope(|scope| -> Result<(FoldPath, Vec<(usize, Polished)>)> {
        let (placer, claims) = (&placer, &claims);
        let worker = scope.spawn(move || early_frames(placer, claims, &receiver));
        let walked = fold_path_observed(model, start, settings, &mut |step| {
            // A worker that stopped (on an error) has no use for more steps.
            let _ = sender.send(Accepted::Step(step.clone()));
        });
        let reached = walked.as_ref().is_ok_and(|(path, _)| path.stop == StopReason::Reached);
        let _ = sender.send(Accepted::End { reached });
        drop(sender);
        let (path, mut solver) = match walked {
            Ok(walked) => walked,
            Err(e) => {
                let _ = worker.join();
                return Err(e);
            }
        };
        let mut polished = Vec::new();
        if reached {
            // The rest is shared: this thread (with the path's solver), the worker, and
            // the other cores.
            let chord = chord_lengths(&path.steps);
            let (steps, chord) = (&path.steps, &chord);
            std::thread::scope(|helping| -> Result<()> {
                let helpers: Vec<_> = (2..threads)
                    .map(|_| {
                        helping
                            .spawn(move || claimed_frames(placer, claims, steps, chord, &mut NormalSolver::new(1e-10)))
                    })
                    .collect();
                polished.extend(claimed_frames(placer, claims, steps, chord, &mut solver)?);
                for helper in helpers {
                    polished.extend(helper.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))?);
                }
                Ok(())
            })?;
        }
        let early = worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        if reached {
            polished.extend(early?);
        }
        Ok((path, polished))
    })?;
    if path.stop != StopReason::Reached {
        let chord = chord_lengths(&path.steps);
        let all = polish_frames(&placer, &path.steps, &chord, end_progress(&path), 0..count, threads)?;
        polished = all.into_iter().enumerate().collect();
    }
    polished.sort_by_key(|(k, _)| *k);
    let frames = polished
        .into_iter()
        .map(|(_, p)| placer.judged(p, &path.steps, path_tolerance(&path)))
        .collect();
    Ok((path, frames))
}

/// What the path tells the frame worker.
enum Accepted {
    Step(PathStep),
    End { reached: bool },
}

/// The frames not yet placed, claimed one at a time by whichever thread is free.
struct Claims {
    next: AtomicUsize,
    count: usize,
}

impl Claims {
    /// The next frame, if any is left and `ready` says it can be placed.
    fn claim(&self, ready: impl Fn(usize) -> bool) -> Option<usize> {
        self.next
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |k| {
                (k < self.count && ready(k)).then_some(k + 1)
            })
            .ok()
    }
}

/// Frames claimed on a whole path that reached its goal, until none is left.
fn claimed_frames(
    placer: &FramePlacer,
    claims: &Claims,
    steps: &[PathStep],
    chord: &[f64],
    solver: &mut NormalSolver,
) -> Result<Vec<(usize, Polished)>> {
    let mut polished = Vec::new();
    while let Some(k) = claims.claim(|_| true) {
        polished.push((k, placer.polished(steps, chord, GOAL, k, solver)?));
    }
    Ok(polished)
}

/// The frames placed while the path goes on: frame k once the steps its cubic uses are all
/// accepted; once the path has reached its goal, the frames left are claimed with the other
/// threads. A path that ends short of its goal ends the worker.
fn early_frames(
    placer: &FramePlacer,
    claims: &Claims,
    receiver: &std::sync::mpsc::Receiver<Accepted>,
) -> Result<Vec<(usize, Polished)>> {
    let mut steps: Vec<PathStep> = Vec::new();
    let mut chord: Vec<f64> = Vec::new();
    let mut polished = Vec::new();
    let mut solver = NormalSolver::new(1e-10);
    // Some(reached) once the path has ended.
    let mut ended = None;
    let take =
        |message: Accepted, steps: &mut Vec<PathStep>, chord: &mut Vec<f64>, ended: &mut Option<bool>| match message {
            Accepted::Step(step) => {
                let length = steps.last().map_or(0.0, |before| {
                    chord.last().copied().unwrap_or(0.0) + distance(&before.fold_angles, &step.fold_angles)
                });
                chord.push(length);
                steps.push(step);
            }
            Accepted::End { reached } => *ended = Some(reached),
        };
    loop {
        while let Ok(message) = receiver.try_recv() {
            take(message, &mut steps, &mut chord, &mut ended);
        }
        match ended {
            Some(false) => return Ok(Vec::new()),
            Some(true) => {
                polished.extend(claimed_frames(placer, claims, &steps, &chord, &mut solver)?);
                return Ok(polished);
            }
            None => {}
        }
        if let Some(k) = claims.claim(|k| placer.ready(&steps, GOAL, k)) {
            polished.push((k, placer.polished(&steps, &chord, GOAL, k, &mut solver)?));
            continue;
        }
        match receiver.recv() {
            Ok(message) => take(message, &mut steps, &mut chord, &mut ended),
            Err(_) => return Ok(polished),
        }
    }
}

/// The progress of a path that reached its goal.
const GOAL: f64 = 1.0;

/// The progress the frames span to: the goal where the path reached it (its last step is
/// there to within the landing's rounding), else its last step's.
fn end_progress(path: &FoldPath) -> f64 {
    if path.stop == StopReason::Reached {
        GOAL
    } else {
        path.steps.last().map_or(0.0, |s| s.progress)
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

/// Cumulative chord length at each step: the cubic's parameter.
fn chord_lengths(steps: &[PathStep]) -> Vec<f64> {
    let mut chord = vec![0.0];
    for pair in steps.windows(2) {
        chord.push(chord.last().copied().unwrap_or(0.0) + distance(&pair[0].fold_angles, &pair[1].fold_angles));
    }
    chord.truncate(steps.len());
    chord
}

/// What every frame of one call shares.
struct FramePlacer<'a> {
    model: &'a FoldingModel,
    drive: &'a Drive,
    signs: Vec<f64>,
    count: usize,
}

/// A frame polished, not yet judged against the path's closure.
struct Polished {
    target: f64,
    segment: usize,
    fold_angles: Vec<f64>,
    residual: f64,
}

impl<'a> FramePlacer<'a> {
    fn new(model: &'a FoldingModel, drive: &'a Drive, count: usize) -> Self {
        FramePlacer {
            model,
            drive,
            signs: assigned_signs(model),
            count,
        }
    }

    fn target(&self, first: f64, last: f64, k: usize) -> f64 {
        first + (last - first) * k as f64 / (self.count - 1) as f64
    }

    /// The segment whose steps bracket the target (the last one where progress is flat).
    fn segment(steps: &[PathStep], target: f64) -> Option<usize> {
        (0..steps.len().saturating_sub(1)).find(|&i| steps[i + 1].progress >= target)
    }

    /// Whether frame k, of a path ending at progress `last`, is placed on `steps` (the
    /// accepted ones so far) as on the whole path: its segment found, with the two steps
    /// after it that its cubic uses. The last frame waits for the path's end.
    fn ready(&self, steps: &[PathStep], last: f64, k: usize) -> bool {
        let Some(first) = steps.first() else {
            return false;
        };
        if k == 0 {
            return true;
        }
        if k + 1 >= self.count {
            return false;
        }
        Self::segment(steps, self.target(first.progress, last, k)).is_some_and(|i| i + 2 < steps.len())
    }

    /// Frame `k` of `count` on a path ending at progress `last`, polished.
    fn polished(
        &self,
        steps: &[PathStep],
        chord: &[f64],
        last: f64,
        k: usize,
        solver: &mut NormalSolver,
    ) -> Result<Polished> {
        let (drive, count) = (self.drive, self.count);
        let signs = &self.signs;
        let start = &steps[0].fold_angles;
        let progress_of = |rho: &[f64]| progress(drive, start, rho, signs);
        let target = self.target(steps[0].progress, last, k);
        let segment = Self::segment(steps, target).unwrap_or(steps.len().saturating_sub(2).min(steps.len() - 1));
        let guess = if k == 0 || steps.len() == 1 {
            steps[0].fold_angles.clone()
        } else if k == count - 1 {
            steps[steps.len() - 1].fold_angles.clone()
        } else {
            // Bisection on the crease that sets progress at the segment's end, checked on the
            // whole state (and redone on it where another crease sets progress).
            let end = &steps[(segment + 1).min(steps.len() - 1)].fold_angles;
            let setter = progress_crease(drive, end, signs)
                .map(|c| (c, move |value: f64| progress_by_crease(drive, start, c, value)));
            let by_setter = setter
                .as_ref()
                .map(|(c, f)| place(steps, chord, segment, target, &Placement::Crease(*c, f)))
                .filter(|guess| (progress_of(guess) - target).abs() <= 1e-12);
            by_setter.unwrap_or_else(|| place(steps, chord, segment, target, &Placement::State(&progress_of)))
        };
        let mut rho = guess;
        // The crease that sets progress keeps its angle, so the frame stays at its target.
        let held = if k == 0 || k == count - 1 {
            None
        } else {
            progress_crease(drive, &rho, signs)
        };
        let residual = polish(self.model, &mut rho, held, solver)?;
        Ok(Polished {
            target,
            segment,
            fold_angles: rho,
            residual,
        })
    }

    /// The frame: the polished state where it closes within `tolerance`, else the nearer
    /// step, as the path accepted it (no rigid state near the cubic).
    fn judged(&self, polished: Polished, steps: &[PathStep], tolerance: f64) -> PathFrame {
        let Polished {
            target,
            segment,
            fold_angles,
            residual,
        } = polished;
        let (fold_angles, max_residual) = if residual <= tolerance {
            (fold_angles, residual)
        } else {
            let next = (segment + 1).min(steps.len() - 1);
            let nearer = if (target - steps[segment].progress).abs() <= (steps[next].progress - target).abs() {
                segment
            } else {
                next
            };
            (steps[nearer].fold_angles.clone(), steps[nearer].max_residual)
        };
        PathFrame {
            progress: progress(self.drive, &steps[0].fold_angles, &fold_angles, &self.signs),
            fold_angles,
            max_residual,
            after_step: segment,
        }
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
fn place(steps: &[PathStep], chord: &[f64], segment: usize, target: f64, by: &Placement) -> Vec<f64> {
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
