//! Probe (branch only): one closing run repeated, for profiling.
use nanofold::commands::nets::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape = &args[1];
    let rank: usize = args[2].parse().unwrap();
    let front: Option<f64> = args.get(3).and_then(|s| s.parse().ok());
    let sample: usize = args.get(4).map_or(0, |s| s.parse().unwrap());
    let repeats: usize = args.get(5).map_or(100, |s| s.parse().unwrap());
    let (name, solid) = open_solid(shape).unwrap();
    let options = NetsOptions {
        top: rank,
        unit_um: 50.0,
        front_deg: front,
        yield_samples: 50,
        ..NetsOptions::default()
    };
    let report = nets(&name, &solid, &options).unwrap();
    let (_, made) = best_net_patterns(&solid, &report, rank).unwrap().remove(rank - 1);
    let scene = net_device(&made, shape, &options).unwrap();
    let model = scene.network().unwrap();
    let closing = NetClosing::new(&made, model).unwrap();
    let variation = options.variation();
    let (forcing, stiffness) = variation.device(&model.forcing, &model.stiffness(), sample);
    let t = std::time::Instant::now();
    let mut last = None;
    for _ in 0..repeats {
        last = Some(closing.run(model, &forcing, &stiffness, &options.closing()).unwrap());
    }
    let run = last.unwrap();
    println!(
        "{:?} {:?} in {:.3} ms a run; {} frames, {} contacts, {} latches",
        run.outcome,
        run.undecided,
        t.elapsed().as_secs_f64() * 1e3 / repeats as f64,
        run.frames.len(),
        run.contacts.len(),
        run.latches.len()
    );
}
