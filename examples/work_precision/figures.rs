//! The work-precision figures, drawn from the report the example measures (so a committed
//! report redraws them exactly: `tests/docs_figures.rs` checks the docs' copies).

use nanofold::plot::{scaling_svg, work_precision_svg, ScalingSeries, WorkPoint, WorkSeries};
use serde_json::Value;

/// The step cap every unfolding figure is drawn at (the default; the other caps are rows of
/// the table only).
const DEFAULT_STEP_CAP: f64 = 0.2;

fn number(row: &Value, key: &str) -> f64 {
    row[key]
        .as_f64()
        .unwrap_or_else(|| panic!("report row without {key}: {row}"))
}

fn rows<'a>(part: &'a Value, what: &str) -> &'a [Value] {
    part["rows"]
        .as_array()
        .unwrap_or_else(|| panic!("report without {what} rows"))
}

/// The unfolding line a row belongs to: direction solver, metric, finish.
pub fn unfold_series(row: &Value) -> String {
    let qp = row["qp"].as_str().unwrap_or("?").to_lowercase();
    let finish = if row["newton_flatten"].as_bool() == Some(true) {
        "newton finish"
    } else {
        "line search only"
    };
    if number(row, "bending_metric") == 0.0 {
        format!("{qp}, plain QP, {finish}")
    } else {
        format!("{qp}, {finish}")
    }
}

/// Every figure of the report: (file name, SVG).
pub fn figures(report: &Value) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    // Unfolding: one figure per family, a line per pattern and (direction, finish), a point
    // per flat tolerance.
    let families: [(&str, &str, &[&str]); 4] = [
        ("unfold_two_creases.svg", "two creases", &["half_paper", "sheet_corner"]),
        (
            "unfold_degree4.svg",
            "degree 4",
            &["degree4_generic", "degree4_native", "miura_vertex"],
        ),
        ("unfold_corner_cube.svg", "corner cube", &["corner_cube"]),
        (
            "unfold_degree6_to_16.svg",
            "degree 6 to 16",
            &["degree6_asymmetric", "waterbomb", "symmetric16"],
        ),
    ];
    let unfolding: Vec<&Value> = rows(&report["unfolding"], "unfolding")
        .iter()
        .filter(|row| row.get("seconds").is_some() && number(row, "max_step_rad") == DEFAULT_STEP_CAP)
        .collect();
    for (file, family, members) in families {
        let mut series = Vec::new();
        for &member in members {
            let mine: Vec<&&Value> = unfolding.iter().filter(|row| row["pattern"] == member).collect();
            let mut lines: Vec<String> = mine.iter().map(|row| unfold_series(row)).collect();
            lines.dedup();
            for line in lines {
                series.push(WorkSeries {
                    name: format!("{member}: {line}"),
                    points: mine
                        .iter()
                        .filter(|row| unfold_series(row) == line)
                        .map(|row| WorkPoint {
                            label: format!("{:.0e}", number(row, "flat_tol")),
                            seconds: number(row, "seconds"),
                            // Exactly on the layout cannot be drawn on a log axis.
                            error: number(row, "flat_layout_error").max(1e-17),
                        })
                        .collect(),
                });
            }
        }
        let svg = work_precision_svg(
            &format!("unfolding, {family}: distance from the exact flat layout (points: --flat-tol)"),
            "max node distance from the flat layout",
            &series,
        )
        .expect("figure");
        out.push((file, svg));
    }

    // Constraint fits: f and G per degree.
    let fits = rows(&report["constraint_fits"], "constraint fit");
    let points = |seconds: &str, error: &str| -> Vec<WorkPoint> {
        fits.iter()
            .map(|row| WorkPoint {
                label: format!("{}", row["degree"]),
                seconds: number(row, seconds),
                error: number(row, error),
            })
            .collect()
    };
    let svg = work_precision_svg(
        "constraint fits, corner cube step 1: error against one evaluation (points: degree)",
        "max error (rad; slope: rad/rad)",
        &[
            WorkSeries {
                name: "f: fit error vs the exact sweep".into(),
                points: points("f_seconds_per_eval", "max_fit_error_rad"),
            },
            WorkSeries {
                name: "G = f′: slope error vs the implicit function theorem".into(),
                points: points("g_seconds_per_eval", "max_slope_error"),
            },
        ],
    )
    .expect("figure");
    out.push(("fits.svg", svg));

    // The bridge's step response per method: angle errors, then relative contact-time errors.
    let step = &report["dynamics"]["step"];
    let contact = number(&step["reference"], "contact_time_s");
    let step_rows = rows(step, "step response");
    let mut methods: Vec<&str> = step_rows.iter().filter_map(|row| row["method"].as_str()).collect();
    methods.dedup();
    let mut series = Vec::new();
    for angle in [true, false] {
        for &method in &methods {
            series.push(WorkSeries {
                name: if angle {
                    format!("{method}: max |Δθ| at contact (rad)")
                } else {
                    format!("{method}: |Δt contact| / t contact")
                },
                points: step_rows
                    .iter()
                    .filter(|row| row["method"] == method)
                    .map(|row| WorkPoint {
                        label: format!("{:.0e}", number(row, "rtol")),
                        seconds: number(row, "seconds"),
                        error: if angle {
                            number(row, "angle_error_at_contact_rad")
                        } else {
                            // Relative to the contact time, so both errors share one axis.
                            number(row, "contact_time_error_s") / contact
                        },
                    })
                    .collect(),
            });
        }
    }
    let svg = work_precision_svg(
        "bridge step response to first contact: error against Tsit45 at rtol 1e-13 (points: rtol)",
        "error",
        &series,
    )
    .expect("figure");
    out.push(("bridge_step.svg", svg));

    // The etch ramp: quasi-static with its measured error, dynamic runs by their distance.
    let ramp_points = rows(&report["dynamics"]["ramp"], "ramp")
        .iter()
        .map(|row| {
            if row["model"] == "quasi_static" {
                WorkPoint {
                    label: "quasi-static (measured error)".into(),
                    seconds: number(row, "seconds"),
                    error: number(row, "measured_error_rad"),
                }
            } else {
                WorkPoint {
                    label: format!("ESDIRK34 {:.0e}", number(row, "rtol")),
                    seconds: number(row, "seconds"),
                    error: number(row, "deviation_from_quasi_static_rad"),
                }
            }
        })
        .collect();
    let svg = work_precision_svg(
        "bridge etch ramp: quasi-static (its measured error) and dynamic (its distance from quasi-static)",
        "error (rad)",
        &[WorkSeries {
            name: "ramp models".into(),
            points: ramp_points,
        }],
    )
    .expect("figure");
    out.push(("bridge_ramp.svg", svg));

    // One unfold iteration against n, split into its parts.
    let scaling = rows(&report["scaling"], "scaling");
    let cost = |key: &str| -> Vec<(f64, f64)> {
        scaling
            .iter()
            .map(|row| (number(row, "creases"), number(row, key)))
            .collect()
    };
    let svg = scaling_svg(
        "cost of one unfold iteration against the number of creases (random vertices)",
        "creases n",
        &[
            ScalingSeries {
                name: "one iteration".into(),
                points: cost("iteration_seconds"),
            },
            ScalingSeries {
                name: "direction (factorisations, solve)".into(),
                points: cost("direction_seconds"),
            },
            ScalingSeries {
                name: "U + ∇U".into(),
                points: cost("energy_and_gradient_seconds"),
            },
        ],
    )
    .expect("figure");
    out.push(("scaling.svg", svg));
    if let Some(networks) = report.get("networks") {
        out.extend(network_figures(networks));
    }
    out
}

/// The Miura sheets: time against error per size (nanofold by rtol, MuJoCo by step), and
/// the cost of each part against the number of panels.
fn network_figures(networks: &Value) -> Vec<(&'static str, String)> {
    let sizes = rows(networks, "network");
    let mut series = Vec::new();
    for size in sizes {
        let n = size["n"].as_u64().unwrap_or(0);
        series.push(WorkSeries {
            name: format!("nanofold {n}×{n} (points: rtol)"),
            points: size["runs"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|row| WorkPoint {
                    label: format!("{:.0e}", number(row, "rtol")),
                    seconds: number(row, "seconds"),
                    error: number(row, "max_angle_error_rad"),
                })
                .collect(),
        });
        let mujoco: Vec<WorkPoint> = size["mujoco"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|row| WorkPoint {
                label: format!("{:.0} ns", number(row, "timestep_s") * 1e9),
                seconds: number(row, "seconds"),
                error: number(row, "max_angle_error_rad"),
            })
            .collect();
        if !mujoco.is_empty() {
            series.push(WorkSeries {
                name: format!("MuJoCo {n}×{n} (points: RK4 step)"),
                points: mujoco,
            });
        }
    }
    let mut out = Vec::new();
    let svg = work_precision_svg(
        "folded Miura sheet, 20 µs of its step response: largest crease error against wall time",
        "max |Δθ| at 20 µs against rtol 1e-12 (rad)",
        &series,
    )
    .expect("figure");
    out.push(("networks_work_precision.svg", svg));
    // Each part at rtol 1e-8 against panels; MuJoCo's whole run at its coarsest step.
    let at = |size: &Value, key: &str| -> Option<f64> {
        size["runs"]
            .as_array()?
            .iter()
            .find(|row| row["rtol"].as_f64() == Some(1e-8))
            .and_then(|row| row[key].as_f64())
    };
    let part = |key: &str| -> Vec<(f64, f64)> {
        sizes
            .iter()
            .filter_map(|size| Some((number(size, "panels"), at(size, key)?)))
            .collect()
    };
    let mut scaling = vec![
        ScalingSeries {
            name: "nanofold, whole run (rtol 1e-8)".into(),
            points: part("seconds"),
        },
        ScalingSeries {
            name: "set-up (branch, periods, final balance)".into(),
            points: part("setup_seconds"),
        },
        ScalingSeries {
            name: "integration".into(),
            points: part("integrate_seconds"),
        },
        ScalingSeries {
            name: "output samples (401, projected)".into(),
            points: part("sampling_seconds"),
        },
    ];
    let coarsest: Vec<(f64, f64)> = sizes
        .iter()
        .filter_map(|size| {
            let first = size["mujoco"].as_array()?.first()?;
            Some((number(size, "panels"), number(first, "seconds")))
        })
        .collect();
    if !coarsest.is_empty() {
        scaling.push(ScalingSeries {
            name: "MuJoCo, whole run (RK4 40 ns)".into(),
            points: coarsest,
        });
    }
    let svg = scaling_svg(
        "folded Miura sheet, 20 µs of its step response: wall time against panels",
        "panels",
        &scaling,
    )
    .expect("figure");
    out.push(("networks_scaling.svg", svg));
    out
}
