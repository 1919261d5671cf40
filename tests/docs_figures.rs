//! The figures under docs/ are current: each deterministic one is drawn again by the command
//! `scripts/figures.sh` uses and compared with the committed file, text exactly and every
//! number to within one pixel (so a last-digit difference of another CPU's rounding does not
//! count). The timing figures are drawn again from their kept measurements,
//! `docs/work_precision_report.json` and `docs/closed_chain_timing_report.json`. After a change that moves a figure, run
//! `bash scripts/figures.sh --keep-timings`.

#[allow(dead_code)]
#[path = "../examples/work_precision/figures.rs"]
mod work_precision_figures;

#[allow(dead_code)]
#[path = "../examples/closed_chain_timing/figures.rs"]
mod closed_chain_figures;

use std::path::Path;
use std::process::Command;

/// Splits an SVG into text runs and numbers.
fn tokens(svg: &str) -> Vec<Result<f64, String>> {
    let mut out = Vec::new();
    let mut text = String::new();
    let mut chars = svg.chars().peekable();
    while let Some(c) = chars.next() {
        if c.is_ascii_digit() || (c == '-' && chars.peek().is_some_and(|d| d.is_ascii_digit())) {
            let mut number = c.to_string();
            while let Some(&d) = chars.peek() {
                if d.is_ascii_digit() || d == '.' || d == 'e' {
                    number.push(d);
                    chars.next();
                } else {
                    break;
                }
            }
            if !text.is_empty() {
                out.push(Err(std::mem::take(&mut text)));
            }
            out.push(number.parse::<f64>().map_err(|_| number.clone()));
        } else {
            text.push(c);
        }
    }
    if !text.is_empty() {
        out.push(Err(text));
    }
    out
}

fn same_figure(drawn: &Path, committed: &str) {
    let (a, b) = (
        std::fs::read_to_string(drawn).unwrap(),
        std::fs::read_to_string(committed).unwrap(),
    );
    let (ta, tb) = (tokens(&a), tokens(&b));
    assert_eq!(
        ta.len(),
        tb.len(),
        "{committed} is not current: run bash scripts/figures.sh --keep-timings"
    );
    for (x, y) in ta.iter().zip(&tb) {
        let same = match (x, y) {
            (Ok(p), Ok(q)) => (p - q).abs() <= 1.0 + 1e-9 * p.abs().max(q.abs()),
            (Err(s), Err(t)) => s == t,
            _ => false,
        };
        assert!(
            same,
            "{committed} is not current ({x:?} against {y:?}): run bash scripts/figures.sh --keep-timings"
        );
    }
}

#[test]
fn the_docs_figures_are_current() {
    let dir = std::env::temp_dir().join(format!("nanofold-figures-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let run = |args: &[&str], out: &str| {
        let status = Command::new(env!("CARGO_BIN_EXE_nanofold"))
            .args(args)
            .arg("--out")
            .arg(dir.join(out))
            .output()
            .unwrap();
        assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    };
    run(&["unfold", "patterns/corner_cube.fold"], "unfold");
    same_figure(&dir.join("unfold/unfold.svg"), "docs/unfold_corner_cube.svg");
    run(
        &[
            "constraints",
            "patterns/corner_cube.fold",
            "--drive",
            "0",
            "--lock",
            "1=0",
            "--range",
            "0:180",
        ],
        "constraints",
    );
    same_figure(
        &dir.join("constraints/constraints.svg"),
        "docs/constraints_corner_cube.svg",
    );
    run(&["fold", "patterns/many/miura_4x4.fold", "--to", "90"], "fold");
    same_figure(&dir.join("fold/fold.svg"), "docs/fold_miura_4x4.svg");
    for scene in [
        "bridge_step",
        "bridge_ramp",
        "corner_cube_step1",
        "corner_cube_step1_ramp",
        "corner_cube_step2",
    ] {
        run(&["simulate", &format!("patterns/{scene}.scene.json")], scene);
        same_figure(
            &dir.join(scene).join("response.svg"),
            &format!("docs/{scene}_response.svg"),
        );
        let snapshots = format!("docs/{scene}_snapshots.svg");
        if Path::new(&snapshots).exists() {
            same_figure(&dir.join(scene).join("snapshots.svg"), &snapshots);
        }
    }
    run(
        &[
            "fit",
            "patterns/bridge_step.scene.json",
            "patterns/measurements/bridge_step_measured.csv",
            "--free",
            "environment.drag_coefficient=0.2:5",
            "--free",
            "hinges.*.target_angle_deg=45:135",
        ],
        "fit",
    );
    same_figure(&dir.join("fit/fit.svg"), "docs/fit_bridge_step.svg");
    // The gallery draws the nets and their scores, not the closing study (which takes
    // minutes for the octahedron's ten best nets): none is simulated.
    run(
        &[
            "nets",
            "octahedron",
            "--top",
            "11",
            "--unit-um",
            "50",
            "--simulate",
            "0",
        ],
        "nets",
    );
    same_figure(&dir.join("nets/gallery.svg"), "docs/nets_octahedron_gallery.svg");
    // Devices of many panels.
    for (scene, figure) in [
        ("cube_closes", "snapshots"),
        ("cube_lid_first", "snapshots"),
        ("miura_sheet", "response"),
    ] {
        run(&["simulate", &format!("patterns/devices/{scene}.scene.json")], scene);
        same_figure(
            &dir.join(scene).join(format!("{figure}.svg")),
            &format!("docs/{scene}_{figure}.svg"),
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The timing figures are their kept reports'.
#[test]
fn the_work_precision_figures_are_the_kept_reports() {
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("docs/work_precision_report.json").unwrap()).unwrap();
    let dir = std::env::temp_dir().join(format!("nanofold-wp-figures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let figures = work_precision_figures::figures(&report);
    assert_eq!(figures.len(), 10);
    for (name, svg) in figures {
        let drawn = dir.join(name);
        std::fs::write(&drawn, svg).unwrap();
        same_figure(&drawn, &format!("docs/work_precision_{name}"));
    }
    // The closed chain's poly-against-exact figure, from its kept report.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("docs/closed_chain_timing_report.json").unwrap()).unwrap();
    let (name, svg) = closed_chain_figures::figures(&report).remove(0);
    assert_eq!(name, "poly_vs_exact.svg");
    let drawn = dir.join(name);
    std::fs::write(&drawn, svg).unwrap();
    same_figure(&drawn, "docs/corner_cube_poly_vs_exact.svg");
    let _ = std::fs::remove_dir_all(&dir);
}
