//! Measured trajectories (`docs/model.md#calibration`): a CSV file of a header and one row
//! per time, read and validated into a [`Measurement`] (times increasing, every cell a
//! finite number or empty); what the columns name is checked against a scene by the fit.

use crate::error::{NanofoldError, Result};
use std::path::Path;

/// Largest measurement file read, bytes.
pub const MAX_MEASUREMENT_BYTES: u64 = 64 << 20;
/// Most columns a measurement may have.
pub const MAX_MEASUREMENT_COLUMNS: usize = 4096;

/// What one measured column observes.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Observed {
    /// A fold angle, degrees: `crease_<i>_deg` (FOLD edge i of a pattern, hinge i of a
    /// strip) or `hinge_<i>_deg` (hinge i of a strip).
    Angle {
        /// The index the column names.
        index: usize,
        /// Whether it was named as a hinge (`hinge_<i>_deg`) rather than a crease.
        hinge: bool,
    },
    /// One coordinate of a tracked point, µm: `panel_<p>_<u>_<v>_<axis>_um`, the point at
    /// (u, v) µm in panel p's flat coordinates (a strip's plate p), its x, y or z.
    Point {
        /// The panel (or plate) index.
        panel: usize,
        /// The point in the panel's flat coordinates, µm.
        at: [f64; 2],
        /// 0, 1, 2 for x, y, z.
        axis: usize,
    },
}

/// One measured column: what it observes and its values (None where the row left it empty).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredColumn {
    /// The header's name.
    pub name: String,
    /// What it observes.
    pub observed: Observed,
    /// One value per row, in the column's unit (degrees, µm).
    pub values: Vec<Option<f64>>,
}

/// A measured trajectory: times and observed columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// Where it was read from (for errors and reports).
    pub source: String,
    /// Sample times, s, strictly increasing and ≥ 0.
    pub times: Vec<f64>,
    /// The observed columns.
    pub columns: Vec<MeasuredColumn>,
}

impl Measurement {
    /// Number of observed values (empty cells left out).
    pub fn observations(&self) -> usize {
        self.columns.iter().map(|c| c.values.iter().flatten().count()).sum()
    }
}

/// Reads a measurement CSV file (at most [`MAX_MEASUREMENT_BYTES`]).
pub fn load_measurement(path: &Path) -> Result<Measurement> {
    let text = crate::read::input::read_text(path, MAX_MEASUREMENT_BYTES)?;
    parse_measurement(&text, &path.display().to_string())
}

/// Parses measurement CSV text; `source` names it in errors. Lines starting with `#` and
/// blank lines are skipped; cells are separated by commas; an empty cell is a missing value.
pub fn parse_measurement(text: &str, source: &str) -> Result<Measurement> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(NanofoldError::invalid(
            source,
            "no header",
            "a measurement needs a header row and data rows",
        ));
    };
    let (names, time_column, mut columns) = read_header(header, source)?;
    let mut times: Vec<f64> = Vec::new();
    for (line_index, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let row = line_index + 1;
        if cells.len() != names.len() {
            return Err(NanofoldError::invalid(
                format!("{source}: line {row}"),
                format!("{} cells", cells.len()),
                format!("the header has {} columns", names.len()),
            ));
        }
        let number = |k: usize| -> Result<Option<f64>> {
            let cell = cells[k];
            if cell.is_empty() {
                return Ok(None);
            }
            match cell.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(Some(x)),
                _ => Err(NanofoldError::invalid(
                    format!("{source}: line {row}, column {}", names[k]),
                    cell,
                    "must be a finite number (or empty where nothing was observed)",
                )),
            }
        };
        let Some(time) = number(time_column)? else {
            return Err(NanofoldError::invalid(
                format!("{source}: line {row}, column time_s"),
                "empty",
                "every row needs its time",
            ));
        };
        if time < 0.0 || times.last().is_some_and(|&last| time <= last) {
            return Err(NanofoldError::invalid(
                format!("{source}: line {row}, column time_s"),
                time,
                match times.last() {
                    Some(last) if time <= *last => format!("times must increase (the row before is at {last} s)"),
                    _ => "times start at 0 s or later".to_string(),
                },
            ));
        }
        times.push(time);
        for (k, column) in &mut columns {
            column.values.push(number(*k)?);
        }
    }
    if times.is_empty() {
        return Err(NanofoldError::invalid(
            source,
            "no data rows",
            "a measurement needs at least one row",
        ));
    }
    Ok(Measurement {
        source: source.to_string(),
        times,
        columns: columns.into_iter().map(|(_, c)| c).collect(),
    })
}

/// The header's names, the time column's place, and each observed column (its place and an
/// empty column), or an error naming the column.
#[allow(clippy::type_complexity)]
fn read_header(header: &str, source: &str) -> Result<(Vec<String>, usize, Vec<(usize, MeasuredColumn)>)> {
    let names: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
    if names.len() > MAX_MEASUREMENT_COLUMNS + 1 {
        return Err(NanofoldError::invalid(
            format!("{source}: header"),
            format!("{} columns", names.len()),
            format!("at most {MAX_MEASUREMENT_COLUMNS} observed columns and time_s"),
        ));
    }
    let time_column = match names.iter().position(|n| n == "time_s") {
        Some(k) => k,
        None => {
            return Err(NanofoldError::missing(format!("{source}: column time_s")));
        }
    };
    let mut columns = Vec::new();
    for (k, name) in names.iter().enumerate() {
        if k == time_column {
            continue;
        }
        if names[..k].contains(name) {
            return Err(NanofoldError::invalid(
                format!("{source}: column {}", k + 1),
                name,
                "this column name appears twice",
            ));
        }
        columns.push((
            k,
            MeasuredColumn {
                name: name.clone(),
                observed: observed(name)
                    .map_err(|reason| NanofoldError::invalid(format!("{source}: column {}", k + 1), name, reason))?,
                values: Vec::new(),
            },
        ));
    }
    if columns.is_empty() {
        return Err(NanofoldError::invalid(
            format!("{source}: header"),
            header.trim(),
            "no observed column besides time_s",
        ));
    }
    Ok((names, time_column, columns))
}

/// What a column name observes, or why the name is not understood.
fn observed(name: &str) -> std::result::Result<Observed, String> {
    let forms = "columns are time_s, crease_<i>_deg, hinge_<i>_deg or panel_<p>_<u>_<v>_<x|y|z>_um";
    let index = |text: &str| {
        text.parse::<usize>()
            .map_err(|_| format!("`{text}` is not an index: {forms}"))
    };
    if let Some(rest) = name.strip_suffix("_deg") {
        if let Some(i) = rest.strip_prefix("crease_") {
            return Ok(Observed::Angle {
                index: index(i)?,
                hinge: false,
            });
        }
        if let Some(i) = rest.strip_prefix("hinge_") {
            return Ok(Observed::Angle {
                index: index(i)?,
                hinge: true,
            });
        }
    }
    if let Some(rest) = name.strip_prefix("panel_").and_then(|r| r.strip_suffix("_um")) {
        let parts: Vec<&str> = rest.split('_').collect();
        if let [panel, u, v, axis] = parts[..] {
            let coordinate = |text: &str| match text.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(format!("`{text}` is not a coordinate in µm: {forms}")),
            };
            let axis = match axis {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                other => return Err(format!("axis `{other}` is not x, y or z: {forms}")),
            };
            return Ok(Observed::Point {
                panel: index(panel)?,
                at: [coordinate(u)?, coordinate(v)?],
                axis,
            });
        }
    }
    Err(format!("not a column nanofold reads: {forms}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_angles_points_and_gaps() {
        let text = "# tracked\ntime_s,crease_3_deg,panel_2_10_-5.5_z_um\n0,0,\n1e-6,1.5,2\n\n2e-6,,3\n";
        let m = parse_measurement(text, "m.csv").unwrap();
        assert_eq!(m.times, vec![0.0, 1e-6, 2e-6]);
        assert_eq!(m.columns[0].observed, Observed::Angle { index: 3, hinge: false });
        assert_eq!(
            m.columns[1].observed,
            Observed::Point {
                panel: 2,
                at: [10.0, -5.5],
                axis: 2
            }
        );
        assert_eq!(m.columns[0].values, vec![Some(0.0), Some(1.5), None]);
        assert_eq!(m.observations(), 4);
    }

    #[test]
    fn refuses_bad_input_by_name() {
        let error = |text: &str| parse_measurement(text, "m.csv").unwrap_err().to_string();
        assert!(error("time_s,crease_1_deg\n0,1\n0,2\n").contains("times must increase"));
        assert!(error("time_s,crease_1_deg\n0,NaN\n").contains("column crease_1_deg"));
        assert!(error("time_s,crease_1_deg\n0,abc\n").contains("abc"));
        assert!(error("t,crease_1_deg\n0,1\n").contains("time_s"));
        assert!(error("time_s,angle\n0,1\n").contains("angle"));
        assert!(error("time_s,panel_1_0_0_w_um\n0,1\n").contains("axis `w`"));
        assert!(error("time_s,crease_1_deg\n0,1,2\n").contains("line 2"));
        assert!(error("time_s,crease_1_deg,crease_1_deg\n0,1,2\n").contains("twice"));
    }
}
