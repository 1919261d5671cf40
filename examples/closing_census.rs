//! A census of the closing engine on one core: every release of a solid's best nets, each
//! release's varied devices run one after another, their outcomes counted (with the reason
//! each undecided run gives) and timed. What the engine's changes are measured by, outcome
//! beside time (`docs/model.md#contact-forces`).
//!
//! `cargo run --release --example closing_census [SHAPE] [NETS] [FRONT_DEG] [FRICTION]`
//! (default the cube's 11 best nets, every front, frictionless; the octahedron's 11, one
//! front alone (`all` for every one), or Coulomb friction between faces, likewise).

use nanofold::commands::nets::*;
use std::collections::BTreeMap;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape = args.get(1).map_or("cube", String::as_str);
    let count: usize = args.get(2).map_or(11, |a| a.parse().expect("NETS: a count of nets"));
    let only: Option<f64> = args
        .get(3)
        .filter(|a| a.as_str() != "all")
        .map(|a| a.parse().expect("FRONT_DEG: an angle in degrees, or all"));
    let friction: f64 = args.get(4).map_or(0.0, |a| a.parse().expect("FRICTION: a coefficient"));
    let settings = ClosingSettings {
        friction_coefficient: friction,
        ..ClosingSettings::default()
    };
    let (name, solid) = open_solid(shape).expect("SHAPE: a solid nanofold generates");
    let options = NetsOptions {
        top: count,
        simulate: 0,
        fronts: 16,
        yield_samples: 50,
        unit_um: 50.0,
        ..NetsOptions::default()
    };
    let report = nets(&name, &solid, &options).expect("the solid's nets");
    let (mut outcomes, mut reasons) = (BTreeMap::new(), BTreeMap::new());
    let (mut total, mut runs, mut slowest) = (0.0, 0, 0.0_f64);
    for (rank, made) in best_net_patterns(&solid, &report, count)
        .expect("the nets")
        .into_iter()
        .enumerate()
    {
        let (_, made) = made;
        for release in options.releases() {
            if only.is_some_and(|f| release != Some(f)) {
                continue;
            }
            let released = NetsOptions {
                front_deg: release,
                ..options.clone()
            };
            let scene = net_device(&made, shape, &released).expect("a scene");
            let model = scene.network().expect("a network");
            let closing = NetClosing::new(&made, model).expect("the net's tests");
            let variation = options.variation();
            let mut here = BTreeMap::new();
            for sample in 0..variation.samples {
                let (forcing, stiffness) = variation.device(&model.forcing, &model.stiffness(), sample);
                if std::env::var("ONLY").is_ok_and(|o| o != format!("{} {release:?} {sample}", rank + 1)) {
                    continue;
                }
                let clock = Instant::now();
                let run = closing
                    .run(
                        model,
                        &forcing,
                        &stiffness,
                        &ClosingSettings {
                            capture_percent: options.closing().capture_percent,
                            ..settings
                        },
                    )
                    .expect("a run");
                let ms = clock.elapsed().as_secs_f64() * 1e3;
                total += ms;
                runs += 1;
                slowest = slowest.max(ms);
                if std::env::var("ONLY").is_ok_and(|o| o == format!("{} {release:?} {sample}", rank + 1)) {
                    for l in &run.latches {
                        println!("LATCH seam {} t {:.9} m {:.3e}", l.seam, l.time_s, l.misalignment);
                    }
                    for c in &run.contacts {
                        println!("CONTACT {:?} {} t {:.9}", c.faces, c.feature, c.time_s);
                    }
                    println!("{:?} {:?}", run.outcome, run.undecided);
                }
                if std::env::var("PER_RUN").is_ok() {
                    println!(
                        "RUN {} {release:?} {sample} {} {:.9} {}",
                        rank + 1,
                        run.outcome.label(),
                        run.time_s,
                        run.latches.len()
                    );
                }
                *here.entry(run.outcome.label()).or_insert(0) += 1;
                *outcomes.entry(run.outcome.label()).or_insert(0) += 1;
                if let Some(why) = run.undecided {
                    // The reason without its progress (which differs run to run).
                    let reason = why
                        .rsplit_once('(')
                        .map_or(why.clone(), |(_, r)| r.trim_end_matches(')').to_string());
                    *reasons.entry(reason).or_insert(0) += 1;
                }
            }
            println!("net {} front {release:?}: {here:?}", rank + 1);
        }
    }
    println!(
        "{shape} (friction {friction}): {runs} runs, {:.2} ms a run (slowest {slowest:.0} ms), one core; {outcomes:?}; undecided: {reasons:?}",
        total / runs.max(1) as f64
    );
}
