//! Probe (branch only): each release of one net, its devices' closing times and outcomes.
use nanofold::commands::nets::*;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape = args.get(1).map_or("cube", |s| s.as_str());
    let rank: usize = args.get(2).map_or(1, |s| s.parse().unwrap());
    let (name, solid) = open_solid(shape).unwrap();
    let options = NetsOptions {
        top: rank,
        simulate: 0,
        fronts: 16,
        yield_samples: 50,
        unit_um: 50.0,
        ..NetsOptions::default()
    };
    let report = nets(&name, &solid, &options).unwrap();
    let (_, made) = best_net_patterns(&solid, &report, rank).unwrap().remove(rank - 1);
    let only: Option<f64> = args.get(3).map(|s| s.parse().unwrap());
    for release in options.releases() {
        if only.is_some_and(|f| release != Some(f)) {
            continue;
        }
        let released = NetsOptions {
            front_deg: release,
            ..options.clone()
        };
        let scene = net_device(&made, shape, &released).unwrap();
        let model = scene.network().unwrap();
        let closing = NetClosing::new(&made, model).unwrap();
        let variation = options.variation();
        let mut times = Vec::new();
        let mut outcomes = std::collections::BTreeMap::new();
        for sample in 0..variation.samples {
            if std::env::var("ONLY_SAMPLE").is_ok_and(|v| v.parse::<usize>().unwrap() != sample) {
                continue;
            }
            let (forcing, stiffness) = variation.device(&model.forcing, &model.stiffness(), sample);
            let t = Instant::now();
            let run = closing.run(model, &forcing, &stiffness, &options.closing()).unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
            *outcomes.entry(format!("{:?}", run.outcome)).or_insert(0) += 1;
            if std::env::var("SHOW_UNDECIDED").is_ok() && run.outcome == Outcome::Undecided {
                println!("  undecided sample {sample}: {:?}", run.undecided);
            }
            if t.elapsed().as_secs_f64() > 0.2 {
                println!(
                    "  slow sample {sample}: {:?} {:.0} ms {:?}",
                    run.outcome,
                    t.elapsed().as_secs_f64() * 1e3,
                    run.undecided
                );
            }
        }
        times.sort_by(f64::total_cmp);
        println!(
            "front {release:?}: median {:.2} ms, max {:.1} ms, total {:.0} ms; {outcomes:?}",
            times.get(times.len() / 2).copied().unwrap_or(0.0),
            times.last().copied().unwrap_or(0.0),
            times.iter().sum::<f64>()
        );
    }
}
