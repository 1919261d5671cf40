#![warn(missing_docs)]
//! # nanofold
//!
//! Rigid origami: unfolding a folded crease pattern to flat by constrained energy
//! minimisation (a single vertex on the sphere, many vertices on their closures), checking
//! and folding crease patterns of any number of vertices, the holonomic constraint curves
//! between fold angles, and the folding dynamics of plates on stress-actuated hinges
//! (strips, closed vertices, networks of panels). The model — every equation, and the
//! readings chosen where the thesis it comes from is ambiguous — is in `docs/model.md`;
//! code cites its anchors.
//!
//! ## Where to start
//!
//! Most programs need one line, `use nanofold::prelude::*;`, and the front door,
//! [`commands`]: the command line and the Python package call nothing else.
//!
//! | you want to | call |
//! |---|---|
//! | read a pattern (FOLD, a native vertex, or built in code) | [`commands::Pattern::open`], [`commands::Pattern::from`] |
//! | check, fold or unfold it | [`commands::check`], [`commands::fold_run`], [`commands::unfold`] |
//! | name options as the command line and Python do | [`commands::options`] (`FoldOptions`, `UnfoldOptions`, …) |
//! | constraint curves between fold angles | [`commands::constraints`] |
//! | generate a Miura-ori, a twist, a waterbomb, a bird base | [`commands::Generator`] |
//! | simulate a device, find its modes | [`commands::open_scene`], [`commands::simulate`], [`commands::modes`] |
//!
//! ## Which module owns what
//!
//! | module | owns |
//! |---|---|
//! | [`geometry`] | the sphere around a vertex (geodesics, fold angles from nodes) and one vertex's loop closure |
//! | [`pattern`] | the validated vertex and crease pattern, their builders and the pattern generators |
//! | [`read`] | the readers: FOLD, native vertices, scene files and the scene schema |
//! | [`folding`] | many vertices: closures and their Jacobian, rank, panel poses and contact, folding paths, verdicts |
//! | [`unfold`] | unfolding by energy descent on the sphere (one vertex) and on the closures (many) |
//! | [`constraints`] | the constraint curves: exact sweeps, polynomial fits, their errors |
//! | [`dynamics`] | plates on hinges: models, mass matrices, forcing, contact, integration, modes, sensitivities |
//! | [`calibrate`] | a scene's numbers fitted to a measured folding, with intervals and identifiability |
//! | [`design`] | from a solid to its nets: every distinct edge unfolding, laid flat, scored and ranked |
//! | [`write`](mod@write) | the writers: JSON reports, FOLD animations, MuJoCo models, output folders |
//! | [`commands`] | the front door over all of the above |
//! | `plot` | SVG figures and 3D pages (feature `plot`) |
//! | [`error`] | the one error type, [`NanofoldError`], with the numerics' failures |
//!
//! ## A pattern from numbers, unfolded
//!
//! ```
//! use nanofold::prelude::*;
//! use std::f64::consts::FRAC_PI_2;
//!
//! // A Miura-like degree-4 vertex: sectors 60°, 120°, 60°, 120°, folded by loop closure.
//! let sectors = [60f64, 120.0, 60.0, 120.0].map(f64::to_radians);
//! let mut rho = [0.8, 0.0, 0.0, 0.0];
//! nanofold::geometry::kinematics::solve_closure(&sectors, &mut rho, &[1, 2, 3], 1e-14, 50)?;
//! let pattern = rho
//!     .iter()
//!     .fold(VertexBuilder::closed("miura").sector_angles(sectors), |b, &r| {
//!         b.crease(Assignment::Unassigned, r)
//!     })
//!     .build()?;
//! // A single vertex is a pattern too: the same `unfold` takes it and a sheet of many.
//! let report = unfold(&Pattern::from(pattern), &Settings::default())?;
//! assert_eq!(report.verdict, UnfoldVerdict::Flat);
//! assert!(report.max_closure_residual_rad < 1e-10);
//! // Reversed, the engine's recorded trajectory is a folding path.
//! let Detail::VertexUnfold(engine) = &report.detail else { unreachable!() };
//! assert!(engine.trajectory.len() > 2);
//! # let _ = FRAC_PI_2;
//! # Ok::<(), NanofoldError>(())
//! ```
//!
//! ## Constraint curves and a closed chain
//!
//! ```
//! use nanofold::prelude::*;
//! let pattern = load_pattern("patterns/corner_cube.fold".as_ref(), &LoadOptions::default())?;
//! // Drive crease 0 from flat to 180° with crease 1 held flat: one degree of freedom.
//! let setup = Setup::new(&pattern, 0, &[(1, 0.0)])?;
//! let samples = sweep_samples(&pattern, &setup, [0.0, std::f64::consts::PI], 201)?;
//! let fit = ConstraintPoly::fit(&pattern, &samples, 8)?;
//! assert!(fit.max_fit_error.iter().all(|&e| e < 1e-4));
//! // A degree-8 fit drives the corner cube's dynamics in a bundled scene; the loop stays
//! // closed to about the fit's error.
//! let scene = load_scene("patterns/corner_cube_step1.scene.json".as_ref())?.build()?;
//! let run = simulate(&scene, &SimulationSettings::default())?;
//! let closed = run.simulation.closed.unwrap();
//! assert!(closed.max_closure_residual < 10.0 * closed.fit_error);
//! # Ok::<(), NanofoldError>(())
//! ```
//!
//! ## Layers
//!
//! Each depends only on those before it (a test checks): [`geometry`] → [`pattern`] →
//! [`read`] (the file readers) → [`folding`] → [`unfold`] and [`constraints`] → [`dynamics`]
//! → [`calibrate`] and [`design`] → [`write`](mod@write) (the file writers) → `plot` (the figures and pages, feature
//! `plot`) → [`commands`] (the front door, which renders each command's files) → the
//! `nanofold` binary (feature `cli`) and the Python package. [`error`]
//! sits beneath them all; [`prelude`] gathers the names most programs need.

pub mod calibrate;
pub mod commands;
pub mod constraints;
pub mod design;
pub mod dynamics;
pub mod error;
pub mod folding;
pub mod geometry;
pub(crate) mod names;
pub mod pattern;
#[cfg(feature = "plot")]
pub mod plot;
pub mod prelude;
pub mod read;
pub mod unfold;
pub mod write;

pub use error::{NanofoldError, Result};

/// README's Rust example, compiled and run as a doc-test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeExample;

/// The user guide's library chapter, its examples compiled and run as doc-tests.
#[cfg(doctest)]
#[doc = include_str!("../docs/guide/library.md")]
pub struct GuideLibraryExamples;
