//! Library use: a two-plate strip built from numbers (a 200 µm plate and a 50 µm tip on
//! SiN/Cr hinges), its natural frequencies at the folded state, its response to a step and
//! to an etch ramp. Run: `cargo run --release --example simulate_a_strip`

use nanofold::dynamics::modes::modes;
use nanofold::prelude::*;
use nanofold::read::scene_spec::{HingeSpec, LayerSpec, MaterialSpec, StripSpec};

fn strip(ramp: bool) -> StripSpec {
    let bilayer = || vec![LayerSpec::new("SiN", 0.2), LayerSpec::new("Cr", 0.1)];
    let spec = StripSpec::new(if ramp { "strip_ramp" } else { "strip_step" })
        .material("SiN", MaterialSpec::new(300.0, 0.28, 3.27))
        .material("Cr", MaterialSpec::new(140.0, 0.21, 7.19))
        .plate(200.0, 100.0, 0.2, "SiN")
        .plate(50.0, 100.0, 0.2, "SiN")
        .hinge(HingeSpec::actuated(32.0, bilayer(), 90.0, Some(20.0)))
        .hinge(HingeSpec::actuated(32.0, bilayer(), 90.0, Some(20.0)))
        .with_drag();
    if ramp {
        spec.ramp(1.5).t_end_s(3000.0)
    } else {
        spec.t_end_s(2e-3)
    }
}

fn main() -> Result<()> {
    let step = strip(false).build()?;
    let chain = step.strip().expect("a strip");
    let folded = modes(&chain.model, chain.target_angles().as_slice())?;
    println!(
        "modes at the folded state: {:?} Hz, stable: {}",
        folded.frequencies_hz, folded.stable
    );
    for scene in [step, strip(true).build()?] {
        let run = simulate_scene(&scene, &SimulationSettings::default())?;
        let response = &run.response;
        print!(
            "{}: {:?} model (time-scale ratio {:.1e}), {} steps",
            scene.name, response.model, response.time_scales.ratio, response.steps
        );
        match &response.collision {
            Some(c) => println!(
                "; first contact at t = {:.4e} s: {} with {}",
                c.time, c.pair[0], c.pair[1]
            ),
            None => println!("; no contact up to t = {:.4e} s", response.t_end),
        }
    }
    Ok(())
}
