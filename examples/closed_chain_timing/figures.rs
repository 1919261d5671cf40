//! The closed chain's timing figures, drawn from the report the example measures (so a kept
//! report redraws them exactly: `tests/docs_figures.rs` checks the docs' copy).

use nanofold::plot::{error_by_parameter_svg, work_precision_svg, ErrorSeries, WorkPoint, WorkSeries};
use serde_json::Value;

fn number(row: &Value, key: &str) -> f64 {
    row[key]
        .as_f64()
        .unwrap_or_else(|| panic!("report row without {key}: {row}"))
}

/// `poly_vs_exact.svg` and `ramp.svg` of the report: (file name, SVG).
pub fn figures(report: &Value) -> Vec<(&'static str, String)> {
    let rows = report["step"]["rows"].as_array().expect("step rows");
    let exact = rows.iter().find(|row| row["source"] == "exact").expect("the exact run");
    let exact_contact = number(exact, "contact_time_s");
    let polys: Vec<&Value> = rows.iter().filter(|row| row["source"] == "poly").collect();
    // Error against degree: the fits all take about the same time (stated in the title), so
    // a time axis piled their labels on each other.
    let by_degree = |error: &dyn Fn(&Value) -> f64| -> Vec<(f64, f64)> {
        polys.iter().map(|row| (number(row, "degree"), error(row))).collect()
    };
    let times: Vec<f64> = polys.iter().map(|row| number(row, "seconds") * 1e3).collect();
    let (fastest, slowest) = times
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    let poly_vs_exact = error_by_parameter_svg(
        &format!(
            "corner cube step 1: f = poly against f = exact (poly runs {fastest:.1}–{slowest:.1} ms, exact {:.0} ms)",
            number(exact, "seconds") * 1e3
        ),
        "degree of the fitted polynomial f",
        "error against the exact run",
        &[
            ErrorSeries {
                name: "max loop-closure residual (rad)".into(),
                points: by_degree(&|row| number(row, "max_closure_residual")),
            },
            ErrorSeries {
                name: "angles at contact − exact (rad)".into(),
                points: by_degree(&|row| number(row, "contact_angle_error_rad")),
            },
            ErrorSeries {
                name: "|contact time − exact| / contact time".into(),
                points: by_degree(&|row| number(row, "contact_time_error_s").abs() / exact_contact),
            },
        ],
        &[(
            "exact's own loop-closure residual (rad)".to_string(),
            number(exact, "max_closure_residual"),
        )],
    )
    .expect("figure");
    let ramp_points = report["ramp"]["rows"]
        .as_array()
        .expect("ramp rows")
        .iter()
        .map(|row| {
            if row["model"] == "quasi_static" {
                WorkPoint {
                    label: "quasi-static".into(),
                    seconds: number(row, "seconds"),
                    error: number(row, "error_bound_rad"),
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
    let ramp = work_precision_svg(
        "corner cube step 1 etch ramp: quasi-static (its error bound) against dynamic (its distance from it)",
        "error (rad)",
        &[WorkSeries {
            name: "ramp models".into(),
            points: ramp_points,
        }],
    )
    .expect("figure");
    vec![("poly_vs_exact.svg", poly_vs_exact), ("ramp.svg", ramp)]
}
