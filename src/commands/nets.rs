//! Nets of a solid behind the door (`docs/model.md#nets-of-polyhedra`): a shape in (a file
//! or a generated solid), its ranked nets out ([`crate::design::nets`]), and the files
//! `nanofold nets` writes (nets.json, nets.csv, the best nets as FOLD crease patterns,
//! gallery.svg).

pub use crate::design::closing::{
    CaptureYield, ClosingReport, ClosingSettings, Contact, ContactForce, Failures, Jam, NetClosing, NetClosingSummary,
    Outcome, ReleaseResult, SeamForce,
};
pub use crate::design::fabrication::{clopper_pearson, Variation, YieldEstimate};
pub use crate::design::fidelity::{spearman, Fidelity, RankCorrelation};
pub use crate::design::nets::{
    apply_study, best_net_patterns, nets, NetRow, NetsOptions, NetsReport, RankBy, Search, Study, MAX_ENUMERATED_TREES,
    MAX_SAMPLED_TREES, MAX_WRITTEN_NETS,
};
use crate::error::{NanofoldError, Result};
pub use crate::geometry::mesh::{MergeCoplanar, MeshReading};
pub use crate::geometry::polyhedron::{Polyhedron, SymmetrySummary};
pub use crate::geometry::precision::{Precision, Tolerances};
use crate::geometry::solids;
use crate::pattern::net::NetPattern;
pub use crate::read::solid::SolidOptions;
use std::path::Path;

/// A solid from a file (`.off`, `.obj`, `.stl`, `.ply`, `.fold`) or a generator's name
/// ([`open_solid_with`]), read with the default options. Returns its name and the solid.
pub fn open_solid(shape: &str) -> Result<(String, Polyhedron)> {
    let opened = open_solid_with(shape, &SolidOptions::default())?;
    Ok((opened.name, opened.solid))
}

/// A solid opened for its nets, with what reading its file did.
#[derive(Debug, Clone)]
pub struct OpenedSolid {
    /// Its name (a file's stem, or the generator's text made a plain name).
    pub name: String,
    /// The solid.
    pub solid: Polyhedron,
    /// A file's reading: its format, welding, merging, precision and tolerances.
    pub reading: Option<MeshReading>,
}

/// A solid from a file (`.off`, `.obj`, `.stl`, `.ply`, `.fold`, read with `options`) or a
/// generator's name: `tetrahedron`, `cube`, `octahedron`, `dodecahedron`, `icosahedron`,
/// `truncated_tetrahedron`, `cuboctahedron`, `truncated_octahedron`, `box:AxBxC`,
/// `prism:N[:H]`, `antiprism:N[:H]`, `pyramid:N[:H]`, `polycube:X,Y,Z;X,Y,Z;…`.
pub fn open_solid_with(shape: &str, options: &SolidOptions) -> Result<OpenedSolid> {
    let path = Path::new(shape);
    if crate::read::solid::is_solid_file(path) {
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("solid").to_string();
        let (solid, reading) = crate::read::solid::read_solid(path, options)?;
        return Ok(OpenedSolid {
            name,
            solid,
            reading: Some(reading),
        });
    }
    let (kind, rest) = shape.split_once(':').unwrap_or((shape, ""));
    let bad = |why: &str| NanofoldError::invalid("shape", shape, why.to_string());
    let number = |text: &str| -> Result<f64> {
        text.trim()
            .parse::<f64>()
            .map_err(|_| bad("a number was expected after the solid's name"))
    };
    let sides_and_height = || -> Result<(usize, f64)> {
        let mut parts = rest.split(':');
        let sides = parts
            .next()
            .and_then(|n| n.trim().parse::<usize>().ok())
            .ok_or_else(|| bad("give the number of sides, e.g. prism:6 or prism:6:2.5"))?;
        let height = parts.next().map(number).transpose()?.unwrap_or(1.0);
        Ok((sides, height))
    };
    let solid = match kind {
        "tetrahedron" => solids::tetrahedron()?,
        "cube" => solids::cube()?,
        "octahedron" => solids::octahedron()?,
        "dodecahedron" => solids::dodecahedron()?,
        "icosahedron" => solids::icosahedron()?,
        "truncated_tetrahedron" => solids::truncated_tetrahedron()?,
        "cuboctahedron" => solids::cuboctahedron()?,
        "truncated_octahedron" => solids::truncated_octahedron()?,
        "box" => {
            let sides: Vec<f64> = rest.split('x').map(number).collect::<Result<_>>()?;
            let [a, b, c] = sides[..] else {
                return Err(bad("a box is box:AxBxC"));
            };
            solids::cuboid(a, b, c)?
        }
        "prism" => {
            let (n, h) = sides_and_height()?;
            solids::prism(n, h)?
        }
        "antiprism" => {
            let (n, h) = sides_and_height()?;
            solids::antiprism(n, h)?
        }
        "pyramid" => {
            let (n, h) = sides_and_height()?;
            solids::pyramid(n, h)?
        }
        "polycube" => {
            let mut cubes = Vec::new();
            for cell in rest.split(';').filter(|c| !c.trim().is_empty()) {
                let xyz: Vec<i64> = cell
                    .split(',')
                    .map(|x| x.trim().parse::<i64>())
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| bad("a polycube is polycube:X,Y,Z;X,Y,Z;… of integer cube positions"))?;
                let [x, y, z] = xyz[..] else {
                    return Err(bad("each cube has three integer coordinates"));
                };
                cubes.push([x, y, z]);
            }
            solids::polycube(&cubes)?
        }
        _ => return Err(bad(
            "a .off, .obj, .stl, .ply or .fold file, or one of tetrahedron, cube, octahedron, dodecahedron, icosahedron, truncated_tetrahedron, cuboctahedron, truncated_octahedron, box:AxBxC, prism:N[:H], antiprism:N[:H], pyramid:N[:H], polycube:X,Y,Z;…",
        )),
    };
    Ok(OpenedSolid {
        name: shape.replace([':', ';', ',', '/'], "_"),
        solid,
        reading: None,
    })
}

/// The ranked nets of a shape: a file read as `options` say, or a generated solid; the
/// file's reading goes into the report.
pub fn nets_of_shape(shape: &str, options: &NetsOptions) -> Result<(OpenedSolid, NetsReport)> {
    let opened = open_solid_with(shape, &options.solid_options())?;
    let mut report = nets(&opened.name, &opened.solid, options)?;
    report.reading = opened.reading.clone();
    Ok((opened, report))
}

/// A ready device scene for a net whose crease pattern is the file `pattern_file` beside
/// it: 0.2 µm SiN plates on SiN/Cr bilayer hinges (as the bundled cube's), every fold
/// actuated towards its target (the turn that closes the solid) plus `options.overdrive_deg`,
/// released at once or by an etch front (`options.front_deg`), the chosen face (or the one
/// at the centre of the net's tree) anchored; lengths in `options.unit_um`.
pub fn net_scene(
    made: &NetPattern,
    name: &str,
    pattern_file: &str,
    options: &NetsOptions,
) -> Result<serde_json::Value> {
    let faces = made.pattern.faces.len();
    let anchored = options.anchored_face.unwrap_or(made.centre_face);
    if anchored >= faces {
        return Err(NanofoldError::invalid(
            "anchored_face",
            anchored,
            format!("the net has faces 0 to {}", faces - 1),
        ));
    }
    let unit_um = options.unit_um;
    let pattern = &made.pattern;
    let targets = pattern
        .target_angles
        .clone()
        .unwrap_or_else(|| vec![0.0; pattern.edges.len()]);
    let over = options.overdrive_deg;
    let degrees: Vec<(usize, f64)> = pattern
        .creases
        .iter()
        .map(|&e| (e, targets[e].to_degrees() + over * targets[e].signum()))
        .collect();
    // The commonest magnitude is the default; the others get entries of their own.
    let mut magnitudes: Vec<f64> = degrees.iter().map(|(_, d)| d.abs()).collect();
    magnitudes.sort_by(f64::total_cmp);
    let common = magnitudes
        .chunk_by(|a, b| (a - b).abs() <= 1e-9)
        .max_by_key(|run| run.len())
        .map_or(90.0, |run| run[0]);
    let hinge = |target: Option<f64>| {
        let mut entry = serde_json::json!({
            "hinge_length_um": 20,
            "layers": [{"material": "SiN", "thickness_um": 0.2}, {"material": "Cr", "thickness_um": 0.1}],
            "actuated": true,
            "radius_of_curvature_um": 20
        });
        if let Some(t) = target {
            entry["target_angle_deg"] = serde_json::json!(t);
        }
        entry
    };
    let mut defaults = hinge(Some(common));
    defaults["target_angle_deg"] = serde_json::json!(common);
    let hinges: Vec<serde_json::Value> = degrees
        .iter()
        .filter(|(_, d)| (d.abs() - common).abs() > 1e-9)
        .map(|&(e, d)| {
            let mut entry = hinge(Some(d));
            entry["crease"] = serde_json::json!(e);
            entry
        })
        .collect();
    // A front runs until it has crossed the whole net (1.2 times, for the last hinges to
    // fold); a step's hinges fold in microseconds.
    let (actuation, t_end_s) = match options.front_deg {
        None => (serde_json::json!({"kind": "step"}), 0.01),
        Some(phi) => {
            let direction = nalgebra::Vector2::new(phi.to_radians().cos(), phi.to_radians().sin());
            let along = pattern
                .vertices
                .iter()
                .map(|p| direction.dot(&nalgebra::Vector2::new(p[0], p[1])));
            let extent = along.clone().fold(f64::NEG_INFINITY, f64::max) - along.fold(f64::INFINITY, f64::min);
            (
                serde_json::json!({"kind": "front", "etch_rate_um_per_min": options.etch_rate_um_per_min, "direction_deg": phi}),
                1.2 * extent * unit_um / (options.etch_rate_um_per_min / 60.0),
            )
        }
    };
    Ok(serde_json::json!({
        "name": name,
        "description": format!("{name}: a net folded by stressed SiN/Cr hinges"),
        "pattern": pattern_file,
        "length_unit_um": unit_um,
        "materials": {
            "SiN": {"youngs_modulus_gpa": 300, "poisson_ratio": 0.28, "density_g_cm3": 3.27},
            "Cr": {"youngs_modulus_gpa": 140, "poisson_ratio": 0.21, "density_g_cm3": 7.19}
        },
        "plates": {"thickness_um": 0.2, "material": "SiN"},
        "hinge_defaults": defaults,
        "hinges": hinges,
        "anchored_face": anchored,
        "actuation": actuation,
        "environment": {"drag": true},
        "seams": made.seams,
        "time": {"t_end_s": t_end_s}
    }))
}

/// A net's device as a scene built in memory from [`net_scene`] (what `simulate` builds from
/// the written files).
pub fn net_device(made: &NetPattern, name: &str, options: &NetsOptions) -> Result<crate::dynamics::scene::Scene> {
    let value = net_scene(made, name, "net.fold", options)?;
    let file: crate::read::scene_spec::NetworkSpec<String> = crate::read::input::from_value(&value)?;
    let spec = crate::read::scene_spec::SceneSpec::Network(Box::new(file.with_pattern(|_| Ok(made.pattern.clone()))?));
    spec.build()
}

/// A net's device folded quasi-statically past its first contact, its seams latching
/// ([`crate::design::closing`]), with the scene's own drives and stiffnesses.
pub fn net_closing(
    made: &NetPattern,
    name: &str,
    options: &NetsOptions,
    settings: &ClosingSettings,
) -> Result<ClosingReport> {
    let scene = net_device(made, name, options)?;
    let model = scene.network().expect("a net's scene is a network");
    let closing = NetClosing::new(made, model)?;
    closing.run(model, &model.forcing, &model.stiffness(), settings)
}

/// One simulated net's every release: its nominal device run and `options.yield_samples`
/// varied devices per release, one after another.
pub fn study_net(
    solid: &Polyhedron,
    report: &NetsReport,
    rank: usize,
    options: &NetsOptions,
) -> Result<NetClosingSummary> {
    options.validate()?;
    let row =
        report.nets.iter().find(|r| r.rank == rank).ok_or_else(|| {
            NanofoldError::invalid("rank", rank, format!("the table ranks 1 to {}", report.nets.len()))
        })?;
    let made = net_of(solid, report, row)?;
    let releases = options
        .releases()
        .into_iter()
        .enumerate()
        .map(|(release, front)| study_release(&made, &report.solid, rank, &row.folds, release, front, options))
        .collect::<Result<Vec<_>>>()?;
    let mut summary = NetClosingSummary::new(options.anchored_face.unwrap_or(made.centre_face), releases);
    (summary.fresh_yield, summary.capture_yields) =
        fresh_yield(&made, &report.solid, rank, &row.folds, summary.best, options)?;
    Ok(summary)
}

/// A ranked net's crease pattern (refused when it cannot be made).
fn net_of(solid: &Polyhedron, report: &NetsReport, row: &NetRow) -> Result<NetPattern> {
    if row.overlapping || row.touching == Some(true) {
        return Err(NanofoldError::invalid(
            "rank",
            row.rank,
            "the net overlaps or touches itself: it cannot be made",
        ));
    }
    net_of_folds(solid, &report.solid, &row.folds)
}

/// The net whose folds are the solid's edges `folds` (a spanning tree of its faces).
fn net_of_folds(solid: &Polyhedron, name: &str, folds: &[usize]) -> Result<NetPattern> {
    let edges = solid.dual_edges().len();
    if let Some(&bad) = folds.iter().find(|&&k| k >= edges) {
        return Err(NanofoldError::invalid(
            "folds",
            bad,
            format!("the solid has edges 0 to {}", edges - 1),
        ));
    }
    if folds.len() + 1 != solid.faces.len() {
        return Err(NanofoldError::invalid(
            "folds",
            format!("{folds:?}"),
            format!(
                "a net of {} faces has {} folds",
                solid.faces.len(),
                solid.faces.len() - 1
            ),
        ));
    }
    let tree = folds.iter().fold(0u64, |t, &k| t | 1 << k);
    let layout = crate::geometry::nets::NetLayout::new(solid);
    let net = layout.lay_flat(tree);
    if !net.overlapping_pairs().is_empty() {
        return Err(NanofoldError::invalid(
            "folds",
            format!("{folds:?}"),
            "the net overlaps itself: it cannot be made",
        ));
    }
    crate::pattern::net::net_pattern(solid, &net, name)
}

/// Release `release` (an index into `options.releases()`) of the net folded along the
/// solid's edges `folds`: one job of [`study_nets`], for a cluster to run.
pub fn study_release_of(
    solid: &Polyhedron,
    name: &str,
    folds: &[usize],
    release: usize,
    options: &NetsOptions,
) -> Result<ReleaseResult> {
    options.validate()?;
    let releases = options.releases();
    let front = *releases.get(release).ok_or_else(|| {
        NanofoldError::invalid(
            "release",
            release,
            format!("the options give releases 0 to {}", releases.len() - 1),
        )
    })?;
    let made = net_of_folds(solid, name, folds)?;
    let rank = 0;
    study_release(&made, name, rank, folds, release, front, options)
}

/// A study's releases by rank from JSON (`[[rank, [release, …]], …]`), as a cluster's jobs
/// return them.
pub fn releases_from_json(value: &serde_json::Value) -> Result<Vec<(usize, Vec<ReleaseResult>)>> {
    crate::read::input::from_value(value)
}

/// Puts every simulated net's releases (by rank, in `options.releases()` order) into the
/// table as [`study_nets`] does; `seconds` is what the releases took (the fresh devices'
/// runs here are added to it).
pub fn apply_releases(
    solid: &Polyhedron,
    report: &mut NetsReport,
    by_rank: Vec<(usize, Vec<ReleaseResult>)>,
    options: &NetsOptions,
    seconds: f64,
) -> Result<()> {
    let releases = options.releases();
    let mut summaries = Vec::with_capacity(by_rank.len());
    for (rank, results) in by_rank {
        let row = report.nets.iter().find(|r| r.rank == rank).ok_or_else(|| {
            NanofoldError::invalid("rank", rank, format!("the table ranks 1 to {}", report.nets.len()))
        })?;
        if results.len() != releases.len() || results.iter().zip(&releases).any(|(r, f)| r.front_deg != *f) {
            return Err(NanofoldError::invalid(
                "releases",
                format!("{} for rank {rank}", results.len()),
                format!("one per release of the options ({}), in their order", releases.len()),
            ));
        }
        let made = net_of(solid, report, row)?;
        let anchored = options.anchored_face.unwrap_or(made.centre_face);
        summaries.push((rank, NetClosingSummary::new(anchored, results), made, row.folds.clone()));
    }
    // Each best release's yield again, from fresh devices: run here, after the choice, one
    // net per job on the machine's cores.
    let fresh_started = std::time::Instant::now();
    let fresh = on_cores(summaries.len(), &|k| {
        let (rank, summary, made, folds) = &summaries[k];
        fresh_yield(made, &report.solid, *rank, folds, summary.best, options)
    });
    let mut summaries: Vec<(usize, NetClosingSummary)> = summaries
        .into_iter()
        .map(|(rank, summary, _, _)| (rank, summary))
        .collect();
    for ((_, summary), result) in summaries.iter_mut().zip(fresh) {
        (summary.fresh_yield, summary.capture_yields) = result?;
    }
    let variation = options.variation();
    let mut failures = Failures::default();
    for (_, summary) in &summaries {
        for release in &summary.releases {
            if let Some(counted) = &release.failures {
                failures.add(counted);
            }
        }
    }
    let study = Study {
        nets: summaries.len(),
        // Every release's nominal and sampled devices, and each net's fresh ones at each
        // capture.
        devices: summaries.len()
            * (releases.len() * (1 + variation.samples) + variation.samples * options.captures().len()),
        failures,
        fidelity: None,
        releases,
        variation,
        closing: options.closing(),
        seconds: seconds + fresh_started.elapsed().as_secs_f64(),
    };
    apply_study(report, summaries, study);
    Ok(())
}

/// One release of a net: the nominal device, then the sampled ones.
#[allow(clippy::too_many_arguments)]
fn study_release(
    made: &NetPattern,
    name: &str,
    rank: usize,
    folds: &[usize],
    release: usize,
    front_deg: Option<f64>,
    options: &NetsOptions,
) -> Result<ReleaseResult> {
    let released = NetsOptions {
        front_deg,
        ..options.clone()
    };
    let scene = net_device(made, &format!("{name}_net_{rank:03}"), &released)?;
    let model = scene.network().expect("a net's scene is a network");
    let closing = NetClosing::new(made, model)?;
    let nominal = closing.run(model, &model.forcing, &model.stiffness(), &options.closing())?;
    let (yield_estimate, failures) = sampled_devices(
        &closing,
        model,
        &options.variation().for_design(folds, release, 0),
        options,
    )?;
    Ok(ReleaseResult {
        front_deg,
        outcome: nominal.outcome,
        time_s: nominal.time_s,
        latched: nominal.latches.len(),
        jam_faces: nominal.jam.map(|j| j.faces),
        yield_estimate,
        failures,
    })
}

/// The yield of `variation`'s devices and how those that did not close ended (None: none
/// sampled).
fn sampled_devices(
    closing: &NetClosing,
    model: &crate::dynamics::network::NetworkModel,
    variation: &Variation,
    options: &NetsOptions,
) -> Result<(Option<YieldEstimate>, Option<Failures>)> {
    if variation.samples == 0 {
        return Ok((None, None));
    }
    let (settings, stiffness) = (options.closing(), model.stiffness());
    let (mut closed, mut failures) = (0, Failures::default());
    for sample in 0..variation.samples {
        let (forcing, varied) = variation.device(&model.forcing, &stiffness, sample);
        let outcome = closing.run(model, &forcing, &varied, &settings)?.outcome;
        if outcome == Outcome::Closes {
            closed += 1;
        }
        failures.count(outcome);
    }
    Ok((Some(YieldEstimate::new(closed, variation.samples)), Some(failures)))
}

/// Release `best` of a net run again on fresh devices (draw set 1): its yield free of the
/// choice among releases (None: none sampled), and the same devices' at half and twice the
/// capture.
fn fresh_yield(
    made: &NetPattern,
    name: &str,
    rank: usize,
    folds: &[usize],
    best: usize,
    options: &NetsOptions,
) -> Result<(Option<YieldEstimate>, Vec<CaptureYield>)> {
    let variation = options.variation().for_design(folds, best, 1);
    if variation.samples == 0 {
        return Ok((None, Vec::new()));
    }
    let released = NetsOptions {
        front_deg: options.releases()[best],
        ..options.clone()
    };
    let scene = net_device(made, &format!("{name}_net_{rank:03}"), &released)?;
    let model = scene.network().expect("a net's scene is a network");
    let closing = NetClosing::new(made, model)?;
    let fresh = sampled_devices(&closing, model, &variation, options)?.0;
    let mut others = Vec::new();
    for &capture_percent in options.captures().iter().skip(1) {
        let captured = NetsOptions {
            capture_percent,
            ..options.clone()
        };
        if let (Some(yield_estimate), _) = sampled_devices(&closing, model, &variation, &captured)? {
            others.push(CaptureYield {
                capture_percent,
                yield_estimate,
            });
        }
    }
    Ok((fresh, others))
}

/// Jobs 0..count run on the machine's cores (each worker takes the next job left), their
/// answers in job order.
pub fn on_cores<T: Send>(count: usize, job: &(dyn Fn(usize) -> T + Sync)) -> Vec<T> {
    let answers: Vec<std::sync::Mutex<Option<T>>> = (0..count).map(|_| std::sync::Mutex::new(None)).collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(count.max(1));
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                if k >= count {
                    break;
                }
                let answer = job(k);
                *answers[k].lock().expect("no job panics holding it") = Some(answer);
            });
        }
    });
    answers
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .expect("no job panics holding it")
                .expect("every job ran")
        })
        .collect()
}

/// Simulates the best `options.simulate` nets that can be made, every release of each
/// (`options.releases()`), on the machine's cores; `progress(done, total)` hears of each
/// release finished. The table gets each net's closing (and is ranked again by yield when
/// asked).
pub fn study_nets(
    solid: &Polyhedron,
    report: &mut NetsReport,
    options: &NetsOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<()> {
    options.validate()?;
    if options.simulate == 0 {
        return Ok(());
    }
    let started = std::time::Instant::now();
    let ranks: Vec<usize> = report
        .nets
        .iter()
        .filter(|r| !r.overlapping && r.touching == Some(false))
        .take(options.simulate)
        .map(|r| r.rank)
        .collect();
    let nets: Vec<NetPattern> = ranks
        .iter()
        .map(|&rank| net_of(solid, report, &report.nets[rank - 1]))
        .collect::<Result<_>>()?;
    let releases = options.releases();
    let jobs: Vec<(usize, usize)> = (0..nets.len())
        .flat_map(|n| (0..releases.len()).map(move |r| (n, r)))
        .collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results = on_cores(jobs.len(), &|k| {
        let (n, r) = jobs[k];
        let folds = &report.nets[ranks[n] - 1].folds;
        let result = study_release(&nets[n], &report.solid, ranks[n], folds, r, releases[r], options);
        progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1, jobs.len());
        result
    });
    let mut by_net: Vec<Vec<ReleaseResult>> = vec![Vec::new(); nets.len()];
    for ((n, _), result) in jobs.iter().zip(results) {
        by_net[*n].push(result?);
    }
    let by_rank = ranks.iter().copied().zip(by_net).collect();
    apply_releases(solid, report, by_rank, options, started.elapsed().as_secs_f64())
}

/// The ranked table as CSV: the scores, and for the nets simulated their best release
/// (`step` or the front's direction), its nominal outcome, its yield on fresh devices with
/// its 95 % interval, the number of releases that close, and the yield it was chosen by.
pub fn nets_csv(report: &NetsReport) -> String {
    let mut csv = String::from(
        "rank,radius_of_gyration_um,leaves,seam_length_um,footprint_long_um,footprint_short_um,overlapping,touching,folds,best_release,outcome,yield,yield_low,yield_high,closes_in,yield_when_chosen\n",
    );
    for row in &report.nets {
        let simulated = row.closing.as_ref().map_or_else(
            || ",,,,,,".to_string(),
            |c| {
                let best = &c.releases[c.best];
                let release = best.front_deg.map_or("step".to_string(), |phi| format!("front {phi}"));
                // The yield reported is the fresh devices'; the one the release was chosen
                // by (the highest of its releases', so optimistic) beside it.
                let (fraction, [low, high]) = c
                    .fresh_yield
                    .or(best.yield_estimate)
                    .map_or((String::new(), [String::new(), String::new()]), |y| {
                        (y.fraction.to_string(), y.interval_95.map(|x| format!("{x:.6}")))
                    });
                let chosen = best.yield_estimate.map_or(String::new(), |y| y.fraction.to_string());
                format!(
                    "{release},{},{fraction},{low},{high},{},{chosen}",
                    best.outcome.label(),
                    c.closes_in
                )
            },
        );
        csv += &format!(
            "{},{:.9e},{},{:.9e},{:.9e},{:.9e},{},{},{},{simulated}\n",
            row.rank,
            row.radius_of_gyration_um,
            row.leaves,
            row.seam_length_um,
            row.footprint_um[0],
            row.footprint_um[1],
            row.overlapping,
            row.touching.map_or(String::new(), |t| t.to_string()),
            row.folds.iter().map(|k| k.to_string()).collect::<Vec<_>>().join(" ")
        );
    }
    csv
}

/// The most frames of a closing page.
const PAGE_FRAMES: usize = 121;

/// The 3D page of a net's nominal device closing along `front_deg` (None: a step): every
/// frame of the run (thinned evenly to `PAGE_FRAMES`, events kept), the anchored face
/// fixed, a jam's faces marked.
pub fn closing_page(made: &NetPattern, name: &str, front_deg: Option<f64>, options: &NetsOptions) -> Result<String> {
    let released = NetsOptions {
        front_deg,
        ..options.clone()
    };
    let scene = net_device(made, name, &released)?;
    let model = scene.network().expect("a net's scene is a network");
    let run = NetClosing::new(made, model)?.run(model, &model.forcing, &model.stiffness(), &options.closing())?;
    let events: Vec<f64> = run
        .latches
        .iter()
        .map(|l| l.progress)
        .chain(run.contacts.iter().map(|p| p.progress))
        .chain(run.jam.as_ref().map(|j| j.progress))
        .collect();
    let stride = run.frames.len().div_ceil(PAGE_FRAMES).max(1);
    let kept: Vec<&crate::design::closing::ClosingFrame> = run
        .frames
        .iter()
        .enumerate()
        .filter(|(k, f)| k % stride == 0 || k + 1 == run.frames.len() || events.contains(&f.progress))
        .map(|(_, f)| f)
        .collect();
    let labels: Vec<String> = kept
        .iter()
        .map(|f| {
            let latched = run.latches.iter().filter(|l| l.progress <= f.progress).count();
            let when = match front_deg {
                Some(_) => format!("t = {:.6e} s", f.time_s),
                None => format!("{:.2} % of the step's path", 100.0 * f.progress),
            };
            format!("{when}: {latched} of {} seams latched", made.seams.len())
        })
        .collect();
    let frames: Vec<(String, &[f64])> = labels
        .iter()
        .cloned()
        .zip(kept.iter().map(|f| f.fold_angles.as_slice()))
        .collect();
    let motion = crate::write::folding_output::network_states_fold(
        model,
        &frames,
        &format!("{name}: its device {} ({})", run.outcome.label(), scene.name),
    );
    let collision = run.jam.as_ref().and_then(|j| {
        let hardest = j.contacts.iter().max_by(|a, b| a.force_n.total_cmp(&b.force_n))?;
        Some(crate::dynamics::Collision {
            time: j.time_s,
            pair: j.faces.map(|f| format!("face {f}")),
            point: nalgebra::Vector3::from(hardest.point_um.map(|x| x * 1e-6)),
        })
    });
    crate::plot::scene_page::network_response_page(&scene.name, model, &motion, collision.as_ref())
}

/// The files `nanofold nets` writes: nets.json, nets.csv, `net_<rank>.fold` for the best
/// `options.top` that can be made with their scenes, gallery.svg of them drawn to one
/// scale, and when nets were simulated closing.html (the best net closing its best way) and
/// jam.html (the best net that jams in some release, jamming).
pub fn nets_files(solid: &Polyhedron, report: &NetsReport, options: &NetsOptions) -> Result<Vec<(String, String)>> {
    let best = best_net_patterns(solid, report, options.top)?;
    let mut files = vec![
        (
            "nets.json".to_string(),
            serde_json::to_string_pretty(report).expect("a report is plain data"),
        ),
        ("nets.csv".to_string(), nets_csv(report)),
    ];
    for (rank, made) in &best {
        let description = format!("net ranked {rank} of {} by {}", report.solid, report.rank_by.label());
        let fold = crate::write::net_output::net_fold(made, &description);
        let fold_name = format!("net_{rank:03}.fold");
        // A simulated net's scene is released its best way, unless one was asked for.
        let best_release = report.nets[rank - 1]
            .closing
            .as_ref()
            .filter(|_| options.front_deg.is_none())
            .map(|c| c.releases[c.best].front_deg);
        let released = NetsOptions {
            front_deg: best_release.unwrap_or(options.front_deg),
            ..options.clone()
        };
        let scene = net_scene(made, &format!("{}_net_{rank:03}", report.solid), &fold_name, &released)?;
        files.push((
            fold_name,
            serde_json::to_string_pretty(&fold).expect("FOLD is plain data"),
        ));
        files.push((
            format!("net_{rank:03}.scene.json"),
            serde_json::to_string_pretty(&scene).expect("a scene is plain data"),
        ));
    }
    let rows: Vec<&NetRow> = best.iter().map(|(rank, _)| &report.nets[rank - 1]).collect();
    let patterns: Vec<&NetPattern> = best.iter().map(|(_, made)| made).collect();
    files.push((
        "gallery.svg".to_string(),
        crate::plot::nets::gallery_svg(&report.solid, &patterns, &rows, report.rank_by, report.unit_um)?,
    ));
    let simulated = || report.nets.iter().filter_map(|r| r.closing.as_ref().map(|c| (r, c)));
    if let Some((row, closing)) = simulated().next() {
        let made = net_of(solid, report, row)?;
        let best = closing.releases[closing.best].front_deg;
        let name = format!("{}_net_{:03}", report.solid, row.rank);
        files.push(("closing.html".to_string(), closing_page(&made, &name, best, options)?));
    }
    let jamming = simulated().find_map(|(row, c)| {
        c.releases
            .iter()
            .find(|r| r.outcome == Outcome::Jams)
            .map(|r| (row, r.front_deg))
    });
    if let Some((row, front)) = jamming {
        let made = net_of(solid, report, row)?;
        let name = format!("{}_net_{:03}", report.solid, row.rank);
        files.push(("jam.html".to_string(), closing_page(&made, &name, front, options)?));
    }
    Ok(files)
}
