use nanofold::commands::nets::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape = &args[1];
    let rank: usize = args[2].parse().unwrap();
    let front: Option<f64> = args.get(3).and_then(|s| s.parse().ok());
    let overdrive: f64 = args.get(4).map_or(5.0, |s| s.parse().unwrap());
    let capture: f64 = args.get(5).map_or(10.0, |s| s.parse().unwrap());
    let (name, solid) = open_solid(shape).unwrap();
    let options = NetsOptions {
        top: rank,
        unit_um: 50.0,
        overdrive_deg: overdrive,
        front_deg: front,
        ..NetsOptions::default()
    };
    let report = nets(&name, &solid, &options).unwrap();
    let made = best_net_patterns(&solid, &report, rank).unwrap().remove(rank - 1).1;
    let t = std::time::Instant::now();
    let run = net_closing(
        &made,
        shape,
        &options,
        &ClosingSettings {
            capture_percent: capture,
        },
    )
    .unwrap();
    println!(
        "{:?} in {:?} at {} ({}): {:?}",
        run.outcome,
        t.elapsed(),
        run.time_s,
        run.progress,
        run.undecided
    );
    for l in &run.latches {
        println!("latch {:?}", l);
    }
    for c in &run.contacts {
        println!("contact {:?}", c);
    }
    for c in &run.final_contacts {
        println!("force {:?}", c);
    }
    println!("open {:?}", run.open_seams);
    println!(
        "angles {:?}",
        run.frames
            .last()
            .unwrap()
            .fold_angles
            .iter()
            .map(|a| a.to_degrees())
            .collect::<Vec<_>>()
    );
    println!(
        "drive {:?}",
        run.final_drive.iter().map(|a| a.to_degrees()).collect::<Vec<_>>()
    );
}
