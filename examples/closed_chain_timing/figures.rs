//! The closed chain's timing figures, drawn from the report the example measures (so a kept
//! report redraws them exactly: `tests/docs_figures.rs` checks the docs' copy).

use nanofold::plot::work_precision::{work_precision_svg, WorkPoint, WorkSeries};
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
    let series = |error: &dyn Fn(&Value) -> f64| -> Vec<WorkPoint> {
        polys
            .iter()
            .map(|row| WorkPoint {
                label: format!("{}", row["degree"]),
                seconds: number(row, "seconds"),
                error: error(row),
            })
            .collect()
    };
    let mut drift = series(&|row| number(row, "max_closure_residual"));
    // Exact last: the line runs from the cheapest fit to the reference.
    drift.push(WorkPoint {
        label: "exact".into(),
        seconds: number(exact, "seconds"),
        error: number(exact, "max_closure_residual"),
    });
    let poly_vs_exact = work_precision_svg(
        "corner cube step 1: f = poly (degree beside each point) against f = exact",
        "error against the exact run",
        &[
            WorkSeries {
                name: "max loop-closure residual (rad; exact at its own)".into(),
                points: drift,
            },
            WorkSeries {
                name: "angles at contact − exact (rad)".into(),
                points: series(&|row| number(row, "contact_angle_error_rad")),
            },
            WorkSeries {
                name: "|contact time − exact| / contact time".into(),
                points: series(&|row| number(row, "contact_time_error_s").abs() / exact_contact),
            },
        ],
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
