//! The measured tables of `docs/thesis.md`: the bridge's natural frequencies under each of
//! the thesis's readings, the corner cube with either face anchored, and the least-squares
//! quartic constraint curves of step 1. Shared by the example (which prints them and, with
//! `--write`, puts them into the document) and by `tests/thesis.rs` (which checks the
//! document is current).

use nanofold::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, Setup};
use nanofold::dynamics::modes::modes;
use nanofold::dynamics::scene::{Scene, System};
use nanofold::dynamics::simulate::{simulate_scene, SimulationSettings};
use nanofold::pattern::LoadOptions;
use nanofold::read::{load_pattern, parse_scene};
use serde_json::Value;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;

/// The thesis's bridge frequencies (eq. 5.15–5.16), kHz, as printed.
pub const THESIS_BRIDGE_KHZ: [f64; 4] = [337.6, 90.0, 40.4, 7.88];
/// Their printed decimals.
pub const THESIS_BRIDGE_DECIMALS: [usize; 4] = [1, 1, 1, 2];

/// Where the tables sit in `docs/thesis.md`.
pub const BEGIN: &str = "<!-- thesis-tables:begin (written by `cargo run --release --example thesis -- --write`) -->";
/// End marker.
pub const END: &str = "<!-- thesis-tables:end -->";

/// A scene file's JSON, to be changed before it is built.
pub fn scene_json(path: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Builds a scene from JSON read at `path` (its `pattern` resolved next to it).
pub fn build(value: &Value, path: &str) -> Scene {
    let base = Path::new(path).parent().unwrap();
    parse_scene(&value.to_string(), path, "scene", base)
        .and_then(|spec| spec.build())
        .unwrap()
}

/// A strip's natural frequencies at its folded target, kHz, highest first.
pub fn strip_khz(scene: &Scene) -> Vec<f64> {
    let System::Strip(chain) = &scene.system else {
        panic!("a strip")
    };
    let result = modes(&chain.model, chain.target_angles().as_slice()).unwrap();
    result.frequencies_hz.iter().map(|f| f / 1e3).collect()
}

/// A closed chain's released-lock frequencies at its folded equilibrium, kHz.
pub fn closed_khz(scene: &Scene) -> Vec<f64> {
    let chain = scene.closed().expect("a closed chain");
    chain
        .folded_modes()
        .unwrap()
        .modes
        .frequencies_hz
        .iter()
        .map(|f| f / 1e3)
        .collect()
}

/// First contact of the scene's run, µs.
pub fn contact_us(scene: &Scene) -> f64 {
    let run = simulate_scene(scene, &SimulationSettings::default()).unwrap();
    run.response.collision.expect("the run reaches contact").time * 1e6
}

/// The bridge with the thesis's departures from Appendix A applied cumulatively: moments
/// about the crease axis with the width, then L4 = 40 µm, then K scaled by `stiffness_scale`.
pub fn bridge_variant(width_moments: bool, long_last_plate: bool, stiffness_scale: f64) -> Scene {
    let path = "patterns/bridge_step.scene.json";
    let mut value = scene_json(path);
    let density = value["materials"]["SiN"]["density_g_cm3"].as_f64().unwrap() * 1e3;
    for (i, plate) in value["plates"].as_array_mut().unwrap().iter_mut().enumerate() {
        if long_last_plate && i == 3 {
            plate["length_um"] = 40.0.into();
        }
        if width_moments {
            let (l, w, t) = (
                plate["length_um"].as_f64().unwrap() * 1e-6,
                plate["width_um"].as_f64().unwrap() * 1e-6,
                plate["thickness_um"].as_f64().unwrap() * 1e-6,
            );
            let mass = density * l * w * t;
            plate["moment_about_crease_kg_m2"] = (mass * (w * w + t * t) / 12.0).into();
        }
    }
    for hinge in value["hinges"].as_array_mut().unwrap() {
        hinge["stiffness_scale"] = stiffness_scale.into();
    }
    build(&value, path)
}

/// The one stiffness factor that best matches the thesis's four frequencies (least squares
/// in log f) once the other two departures are made: frequencies scale as √K.
pub fn fitted_stiffness_scale() -> f64 {
    let khz = strip_khz(&bridge_variant(true, true, 1.0));
    let mean_log: f64 = khz
        .iter()
        .zip(THESIS_BRIDGE_KHZ)
        .map(|(ours, thesis)| (thesis / ours).ln())
        .sum::<f64>()
        / 4.0;
    (2.0 * mean_log).exp()
}

fn khz_row(out: &mut String, label: &str, khz: &[f64]) {
    let worst = khz
        .iter()
        .zip(THESIS_BRIDGE_KHZ)
        .map(|(ours, thesis)| (ours / thesis - 1.0).abs())
        .fold(0.0, f64::max);
    let cells: Vec<String> = khz.iter().map(|f| format!("{f:.2}")).collect();
    writeln!(out, "| {label} | {} | {:.1e} |", cells.join(" | "), worst).unwrap();
}

/// The least-squares quartic of corner-cube step 1 (crease 1 locked flat, crease 0 driven
/// over 0…180°, 201 exact samples): per free crease, its largest error and its error at 180°.
pub fn step1_quartic() -> Vec<(String, f64, f64)> {
    let pattern = load_pattern(Path::new("patterns/corner_cube.fold"), &LoadOptions::default()).unwrap();
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    let samples = sweep_samples(&pattern, &setup, [0.0, PI], 201).unwrap();
    let poly = ConstraintPoly::fit(&pattern, &samples, 4).unwrap();
    let report = ConstraintReport::new(&pattern, &samples, &poly).unwrap();
    let last = samples.fold_angles.last().unwrap();
    report
        .curves
        .iter()
        .map(|curve| {
            let c = pattern.crease_from_user_index(curve.crease).unwrap();
            let at_end = curve.coeffs_deg.iter().rev().fold(0.0, |acc, &k| acc * 180.0 + k);
            (
                curve.label.clone(),
                curve.max_fit_error_rad.to_degrees(),
                at_end - last[c].to_degrees(),
            )
        })
        .collect()
}

/// Every table of `docs/thesis.md`, as markdown.
pub fn tables() -> String {
    let mut out = String::new();
    let scale = fitted_stiffness_scale();
    writeln!(
        out,
        "**Bridge natural frequencies at the folded state (kHz, highest first)**\n"
    )
    .unwrap();
    writeln!(
        out,
        "| model | f₁ | f₂ | f₃ | f₄ | worst relative difference from the thesis |"
    )
    .unwrap();
    writeln!(out, "|---|---|---|---|---|---|").unwrap();
    let thesis: Vec<String> = THESIS_BRIDGE_KHZ
        .iter()
        .zip(THESIS_BRIDGE_DECIMALS)
        .map(|(f, d)| format!("{f:.d$}"))
        .collect();
    writeln!(out, "| thesis, eq. 5.15–5.16 | {} | — |", thesis.join(" | ")).unwrap();
    khz_row(
        &mut out,
        "Appendix A as printed, box moments (`bridge_step.scene.json`)",
        &strip_khz(&bridge_variant(false, false, 1.0)),
    );
    khz_row(
        &mut out,
        "… moment about the crease axis with the width",
        &strip_khz(&bridge_variant(true, false, 1.0)),
    );
    khz_row(
        &mut out,
        "… and L4 = 40 µm",
        &strip_khz(&bridge_variant(true, true, 1.0)),
    );
    let reading = build(
        &scene_json("patterns/thesis/bridge_thesis_reading.scene.json"),
        "patterns/thesis/bridge_thesis_reading.scene.json",
    );
    khz_row(
        &mut out,
        "… and K × 4.4113 (`thesis/bridge_thesis_reading.scene.json`)",
        &strip_khz(&reading),
    );
    khz_row(
        &mut out,
        "without L4 = 40 µm: width moments, K × 4.4113",
        &strip_khz(&bridge_variant(true, false, 4.4113)),
    );
    khz_row(
        &mut out,
        "without the width moments: L4 = 40 µm, K × 4.4113",
        &strip_khz(&bridge_variant(false, true, 4.4113)),
    );
    writeln!(
        out,
        "\nThe stiffness factor fitted to the four printed values (least squares in log f) is {scale:.4}; \
         √{scale:.4} = {:.4} scales every frequency alike.\n",
        scale.sqrt()
    )
    .unwrap();

    writeln!(out, "**Corner cube: which face is anchored**\n").unwrap();
    writeln!(
        out,
        "| anchored face | step 1 first contact (µs) | step 2 modes at the folded cube (kHz) |"
    )
    .unwrap();
    writeln!(out, "|---|---|---|").unwrap();
    writeln!(out, "| thesis (Fig. 5-10; its modes) | 40–50 | about 9.1 and 2.7 |").unwrap();
    for (label, dir, suffix) in [
        ("face 2, the square opposite the flap (bundled scenes)", "patterns", ""),
        (
            "face 4, a flap half (`thesis/*_flap_anchored`)",
            "patterns/thesis",
            "_flap_anchored",
        ),
    ] {
        let one = format!("{dir}/corner_cube_step1{suffix}.scene.json");
        let two = format!("{dir}/corner_cube_step2{suffix}.scene.json");
        let contact = contact_us(&build(&scene_json(&one), &one));
        let khz = closed_khz(&build(&scene_json(&two), &two));
        writeln!(out, "| {label} | {contact:.2} | {:.2} and {:.2} |", khz[0], khz[1]).unwrap();
    }

    writeln!(
        out,
        "\n**Corner cube step 1, least-squares quartic against exact loop closure** \
         (crease 1 locked flat, crease 0 driven over 0…180°, 201 exact samples)\n"
    )
    .unwrap();
    writeln!(out, "| crease | largest error (°) | error at θ₀ = 180° (°) |").unwrap();
    writeln!(out, "|---|---|---|").unwrap();
    for (label, worst, at_end) in step1_quartic() {
        writeln!(out, "| {label} | {worst:.3} | {at_end:+.3} |").unwrap();
    }
    out
}

/// `document` with the block between the markers replaced by `tables`.
pub fn with_tables(document: &str, tables: &str) -> Option<String> {
    let start = document.find(BEGIN)? + BEGIN.len();
    let end = document.find(END)?;
    (start <= end).then(|| format!("{}\n{}{}", &document[..start], tables, &document[end..]))
}
